//! The global (Newton) solver against exact answers and against Gauss–Seidel.
//!
//! - A hyperstatic stack between frictional walls, solved by the engine with `method = newton`
//!   to 10⁻¹⁰: every grain stays at rest and the supports carry exactly the weight (statics
//!   fixes the total, not its split, which W's null space leaves free).
//! - Every reference problem (`datasets/fc-problems`) and every hard problem
//!   (`datasets/fc-problems/hard`): Newton (`auto`) and Gauss–Seidel agree on the velocities.
//! - The engine's assembled `W` has the diagonal blocks the Gauss–Seidel rows carry.

mod common;

use std::path::{Path, PathBuf};

use common::{problems, stack};
use dem::fc::{read_problem, solve_by, FcOptions, NewtonParams, SolverMethod};

#[test]
fn hyperstatic_stack_between_frictional_walls_carries_its_weight_exactly() {
    let (mut w, weight) = stack(6, 8, SolverMethod::Newton, 1e-10);
    let rep = w.step().unwrap();
    assert!(
        rep.solver.converged && rep.solver.error <= 1e-10,
        "{:?}",
        rep.solver
    );
    assert!(rep.solver.newton_iterations > 0, "{:?}", rep.solver);
    // More closed contacts than degrees of freedom: the problem is hyperstatic.
    let grains = w
        .bodies
        .iter()
        .filter(|b| b.kind == dem::BodyKind::Grain)
        .count();
    assert!(2 * rep.contacts > 3 * grains, "{rep:?}");
    // At rest: every velocity vanishes to the tolerance (scale g h = 9.81e-3 m/s).
    let vmax = w
        .bodies
        .iter()
        .map(|b| b.velocity.norm().max(b.omega.abs() * 1e-3))
        .fold(0.0, f64::max);
    assert!(
        vmax <= 1e-10 * 9.81e-3 * 50.0,
        "largest velocity {vmax:e} m/s"
    );
    // Statics: the walls and the floor carry the whole weight (relative 1e-9).
    let support: f64 = (0..3).map(|b| w.contact_force(b).0.y).sum::<f64>();
    assert!(
        (-support - weight).abs() <= 1e-9 * weight,
        "supports carry {} N of {weight} N",
        -support
    );
}

#[test]
fn newton_and_gauss_seidel_agree_on_the_stack() {
    let (mut a, _) = stack(5, 6, SolverMethod::Newton, 1e-10);
    let (mut b, _) = stack(5, 6, SolverMethod::Nlgs, 1e-10);
    let ra = a.step().unwrap();
    let rb = b.step().unwrap();
    assert!(ra.solver.converged && rb.solver.converged);
    for (x, y) in a.bodies.iter().zip(&b.bodies) {
        assert!((x.velocity - y.velocity).norm() <= 1e-12, "{x:?} {y:?}");
    }
}

/// Solves every problem of `files` to `tol` with `auto` and with Gauss–Seidel alone, each with
/// `sweeps` sweeps at most (Newton: 200 iterations). Checks that each reported error is the
/// true error of its impulses, that `auto` converges where `must_converge` and wherever
/// Gauss–Seidel alone does, that it otherwise ends within twice Gauss–Seidel's error (not
/// always below it: on the μ = 0.8 push, `stick-slip_push2_0002000`, the sweeps that follow the
/// Newton stage restart from its iterate and end at 4.5·10⁻⁴ against 2.5·10⁻⁴ after 20 000
/// sweeps), and, where both converge, that their velocities agree:
/// `‖u_auto − u_nlgs‖ / max(‖q‖, ‖u‖) ≤ 10³ tol` (velocities are unique where W is positive
/// definite on the active set; the factor allows for the conditioning of the problems).
fn compare(files: &[PathBuf], tol: f64, sweeps: usize, must_converge: bool, same_u: bool) {
    assert!(!files.is_empty());
    for f in files {
        let p = read_problem(f).unwrap();
        let opts = FcOptions {
            tolerance: tol,
            max_iterations: sweeps,
            ..FcOptions::default()
        };
        let params = NewtonParams {
            max_iterations: 200,
            ..NewtonParams::default()
        };
        let (n, rep) = solve_by(&p, &opts, SolverMethod::Auto, &params).unwrap();
        let (g, _) = solve_by(&p, &opts, SolverMethod::Nlgs, &params).unwrap();
        for (what, s) in [("auto", &n), ("nlgs", &g)] {
            let e = dem::fc::fc_error(&p, &s.r);
            assert!(
                (e - s.error).abs() <= 1e-12 + 1e-9 * e,
                "{} {what}: reported {:e}, true {e:e}",
                f.display(),
                s.error
            );
        }
        assert!(
            n.converged || !must_converge,
            "{}: auto error {:e} ({rep:?})",
            f.display(),
            n.error
        );
        let bound = if g.converged { tol } else { 2.0 * g.error };
        assert!(
            n.error <= bound,
            "{}: auto {:e} against Gauss–Seidel {:e}",
            f.display(),
            n.error,
            g.error
        );
        if !(same_u && n.converged && g.converged) {
            continue;
        }
        let norm = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let du: Vec<f64> = n.u.iter().zip(&g.u).map(|(a, b)| a - b).collect();
        let scale = norm(p.q()).max(norm(&n.u)).max(f64::MIN_POSITIVE);
        let rel = norm(&du) / scale;
        assert!(
            rel <= 1e3 * tol,
            "{}: velocities differ by {rel:e} (relative)",
            f.display()
        );
    }
}

#[test]
fn newton_and_gauss_seidel_agree_on_the_reference_problems() {
    let mut files = problems("piles");
    files.extend(problems("siconos-2d"));
    compare(&files, 1e-8, 200_000, true, true);
}

/// The hard problems (steps where the engine's solve stopped above its tolerance, and where
/// Gauss–Seidel and Newton stall): `auto` solves every one to 10⁻⁸ (its last stage, Lemke's
/// method, is exact), and its reported errors are the true ones. Their velocities are not
/// compared: frictional problems need not have one solution, and `shear-cell_compress_0036`
/// has two, 8.4·10⁻³ apart (relative), each verified to 10⁻⁸.
#[test]
fn auto_solves_every_hard_problem() {
    compare(&problems("hard"), 1e-8, 20_000, true, false);
}

#[test]
fn assembled_delassus_diagonal_matches_the_rows() {
    let (mut w, _) = stack(4, 4, SolverMethod::Nlgs, 1e-8);
    w.record_problems = true;
    w.step().unwrap();
    let p = w.last_problem().expect("recorded");
    let rows = &w.contacts().rows;
    assert_eq!(p.contacts(), rows.len());
    for (a, c) in rows.iter().enumerate() {
        let d = p.delassus(a);
        for (x, y) in [(d.nn, c.w.nn), (d.nt, c.w.nt), (d.tt, c.w.tt)] {
            assert!((x - y).abs() <= 1e-12 * c.w.nn, "contact {a}: {x} vs {y}");
        }
    }
}

/// `auto`'s back-off after failed Newton stages: 1, 2, 4, 8, 8 stalled steps skipped, back to
/// none after a converged stage.
#[test]
fn newton_backoff_doubles_to_its_cap_and_resets() {
    use dem::solver::NewtonBackoff;
    let mut b = NewtonBackoff::default();
    let mut skips = Vec::new();
    for _ in 0..5 {
        b.record(false);
        skips.push(b.skip);
    }
    assert_eq!(skips, [1, 2, 4, 8, 8]);
    assert_eq!(NewtonBackoff::MAX_SKIP, 8);
    b.record(true);
    assert_eq!((b.skip, b.next), (0, 0));
    b.record(false);
    assert_eq!(b.skip, 1);
}

/// The active-set finish on a two-contact problem built from a known solution: contact 0
/// sticks (`r = (1, 0.1)`, `u = 0`, μ = 0.5), contact 1 slides (`r = (2, −1)` on the cone's
/// edge, `u = (0, 0.7)`), `q = u − W r` with a coupled positive definite `W`. From the solution
/// perturbed by 10⁻⁷ (statuses unchanged) one solve returns it to 10⁻¹² (relative).
#[test]
fn active_set_finish_recovers_a_known_solution() {
    let w = vec![
        vec![2.0, 0.3, 0.5, 0.1],
        vec![0.3, 3.0, 0.2, -0.4],
        vec![0.5, 0.2, 2.5, 0.3],
        vec![0.1, -0.4, 0.3, 3.5],
    ];
    let r_star = [1.0, 0.1, 2.0, -1.0];
    let u_star = [0.0, 0.0, 0.0, 0.7];
    let q: Vec<f64> = (0..4)
        .map(|i| u_star[i] - (0..4).map(|j| w[i][j] * r_star[j]).sum::<f64>())
        .collect();
    let p = dem::fc::problem::FcProblem::new(
        vec![0.5, 0.5],
        q,
        dem::fc::BlockCsr2::from_dense(&w).unwrap(),
    )
    .unwrap();
    assert!(dem::fc::fc_error(&p, &r_star) <= 1e-15);
    let eps = 1e-7;
    let start = [1.0 + eps, 0.1 - eps, 2.0 * (1.0 + eps), -(1.0 + eps)];
    let e0 = dem::fc::fc_error(&p, &start);
    assert!(
        e0 > 1e-9 && e0 <= dem::fc::newton::FINISH_MAX_ERROR,
        "{e0:e}"
    );
    let mut work = dem::fc::newton::NewtonWork::default();
    let (r, e) = dem::fc::newton::active_set_finish(&p, &start, e0, &mut work)
        .unwrap()
        .expect("the finish improves a start with the solution's statuses");
    for (a, b) in r.iter().zip(&r_star) {
        assert!((a - b).abs() <= 1e-12 * 2.0, "{r:?} vs {r_star:?}");
    }
    assert!(e <= 1e-14 && (dem::fc::fc_error(&p, &r) - e).abs() <= 1e-15);
}

/// The slow-shear hard problem (`shear-cell_I0.005_0000201`), which Gauss–Seidel, the Newton
/// stage and Siconos' NSGS leave near 10⁻⁵: `auto` with 10⁵ sweeps reaches statuses good enough
/// for the active-set finish, and the error recomputed from the returned impulses is ≤ 10⁻⁸.
#[test]
fn auto_solves_the_slow_shear_hard_problem() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../datasets/fc-problems/hard");
    let p = read_problem(root.join("shear-cell_I0.005_0000201.json.gz")).unwrap();
    let opts = FcOptions {
        tolerance: 1e-8,
        max_iterations: 100_000,
        ..FcOptions::default()
    };
    let (s, _) = solve_by(&p, &opts, SolverMethod::Auto, &NewtonParams::default()).unwrap();
    let e = dem::fc::fc_error(&p, &s.r);
    assert!(
        s.converged && e <= 1e-8,
        "error {e:e} (reported {:e})",
        s.error
    );
    for a in 0..p.contacts() {
        let (rn, rt) = (s.r[2 * a], s.r[2 * a + 1]);
        assert!(rn >= 0.0 && rt.abs() <= p.mu()[a] * rn * (1.0 + 1e-12));
    }
}
