//! Lemke's method (`dem::fc::lemke`) on the 2D frictional-contact problem:
//!
//! - one contact, sticking and sliding: the closed-form answer to rounding;
//! - every hard problem of `datasets/fc-problems/hard` (steps where Gauss–Seidel and Newton
//!   stall): an exact solution, its error ≤ 10⁻¹⁰ recomputed from `r` alone, every impulse in its
//!   cone;
//! - the small reference problems: the same velocities as Gauss–Seidel to 10⁻⁶ (relative);
//! - a warm start from the final basis of a nearby problem: a short path to the same accuracy;
//! - the engine with `method = lemke` on a hyperstatic stack between frictional walls: at rest,
//!   the supports carry exactly the weight.

mod common;

use std::path::Path;

use common::{problems, stack};
use dem::fc::block_csr::BlockCsr2;
use dem::fc::lemke::{self, LemkeParams, Warm};
use dem::fc::{fc_error, read_problem, solve_by, FcOptions, FcProblem, NewtonParams, SolverMethod};

/// Every impulse in its cone: `r_n ≥ 0`, `|r_t| ≤ μ r_n` (to rounding).
fn in_cones(p: &FcProblem, r: &[f64]) -> bool {
    p.mu().iter().enumerate().all(|(a, &mu)| {
        let (rn, rt) = (r[2 * a], r[2 * a + 1]);
        rn >= 0.0 && rt.abs() <= mu * rn * (1.0 + 1e-12) + 1e-300
    })
}

fn one_contact(q: [f64; 2], w: [f64; 2], mu: f64) -> FcProblem {
    let rows = vec![vec![w[0], 0.0], vec![0.0, w[1]]];
    FcProblem::new(vec![mu], q.to_vec(), BlockCsr2::from_dense(&rows).unwrap()).unwrap()
}

/// One contact, `W = diag(a, b)`, approaching (`q_n < 0`): `r_n = −q_n/a`; sticking
/// (`r_t = −q_t/b`, `u = 0`) when `|q_t| ≤ μ b r_n`, else sliding (`r_t = −μ r_n sign q_t`,
/// `u_t = q_t + b r_t`); separating (`q_n > 0`): `r = 0`.
#[test]
fn one_contact_sticks_slides_and_opens_as_coulomb_says() {
    let (a, b, mu) = (2.0, 5.0, 0.3);
    for &(qn, qt) in &[
        (-1.0, 0.5),
        (-1.0, -0.1),
        (-1.0, 2.0),
        (-1.0, -3.0),
        (0.4, 1.0),
    ] {
        let p = one_contact([qn, qt], [a, b], mu);
        let (sol, rep) = lemke::solve(&p, Warm::default(), 1e-12, &LemkeParams::default()).unwrap();
        let r = sol.expect("solved").r;
        let rn = (-qn / a).max(0.0);
        let rt = if qt.abs() <= mu * b * rn {
            -qt / b
        } else {
            -mu * rn * qt.signum()
        };
        assert!(
            (r[0] - rn).abs() <= 1e-14 && (r[1] - rt).abs() <= 1e-14,
            "q = ({qn}, {qt}): r = {r:?}, expected ({rn}, {rt}) ({rep:?})"
        );
        assert!(rep.error <= 1e-14, "{rep:?}");
    }
}

/// A complementary basis that is feasible only once `q̄` is perturbed (a residual of 10⁻¹²,
/// below the perturbation), given as the warm start: solved, no panic (found by review).
#[test]
fn a_warm_basis_feasible_to_rounding_is_the_answer() {
    let p = one_contact([-1e-12, 1.0], [1.0, 1.0], 0.5);
    for warm in [
        Warm {
            basis: Some(&[12]),
            impulses: None,
        },
        Warm {
            basis: None,
            impulses: Some(&[0.0, 0.0]),
        },
    ] {
        let (sol, rep) = lemke::solve(&p, warm, 1e-9, &LemkeParams::default()).unwrap();
        let r = sol.expect("solved").r;
        assert!(rep.error <= 1e-9, "{rep:?}");
        assert!(r.iter().all(|x| x.is_finite()) && in_cones(&p, &r), "{r:?}");
    }
}

/// Every hard problem, cold: error ≤ 10⁻¹⁰ recomputed from `r` (most end at 10⁻¹⁴–10⁻¹³).
#[test]
fn lemke_solves_every_hard_problem_exactly() {
    let files = problems("hard");
    assert!(files.len() >= 7);
    for f in &files {
        let p = read_problem(f).unwrap();
        let (sol, rep) = lemke::solve(&p, Warm::default(), 1e-10, &LemkeParams::default()).unwrap();
        let r = sol.unwrap_or_else(|| panic!("{}: {rep:?}", f.display())).r;
        let e = fc_error(&p, &r);
        assert!(e <= 1e-10, "{}: error {e:e} ({rep:?})", f.display());
        assert!(in_cones(&p, &r), "{}", f.display());
    }
}

/// The small reference problems (piles and the Siconos problems of at most 1000 contacts): the
/// same velocities as Gauss–Seidel, `‖u_lemke − u_nlgs‖ ≤ 10⁻⁶ max(‖q‖, ‖u‖) + 10⁻¹⁵ m/s`
/// with both solved to 10⁻⁹ (the floor for `fc2d_granularflowonwall_00667_00000`, a packing at
/// rest whose `q` is 4·10⁻¹⁸).
#[test]
fn lemke_and_gauss_seidel_agree_on_the_reference_problems() {
    let mut files = problems("piles");
    files.extend(problems("siconos-2d"));
    let mut checked = 0;
    for f in &files {
        let p = read_problem(f).unwrap();
        if p.contacts() > 1000 {
            continue;
        }
        let opts = FcOptions {
            tolerance: 1e-9,
            max_iterations: 200_000,
            ..FcOptions::default()
        };
        let params = NewtonParams::default();
        let (l, rep) = solve_by(&p, &opts, SolverMethod::Lemke, &params).unwrap();
        let (g, _) = solve_by(&p, &opts, SolverMethod::Nlgs, &params).unwrap();
        assert!(l.converged && g.converged, "{}: {rep:?}", f.display());
        assert!(fc_error(&p, &l.r) <= 1e-9, "{}", f.display());
        let norm = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let du: Vec<f64> = l.u.iter().zip(&g.u).map(|(a, b)| a - b).collect();
        let scale = norm(p.q()).max(norm(&l.u)).max(f64::MIN_POSITIVE);
        assert!(
            norm(&du) <= 1e-6 * scale + 1e-15,
            "{}: velocities differ by {:e} m/s (scale {scale:e})",
            f.display(),
            norm(&du)
        );
        checked += 1;
    }
    assert!(checked >= 3, "{checked} problems checked");
}

/// A nearby problem (`q` perturbed by 10⁻⁴ ‖q‖∞) warm-started from the final basis of the
/// first: the same accuracy in a path at least 20 times shorter than the cold one.
#[test]
fn warm_start_from_the_previous_basis_is_short() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../datasets/fc-problems/hard");
    for name in ["stick-slip_push2_0002000", "shear-cell_compress_0036"] {
        let p = read_problem(root.join(format!("{name}.json.gz"))).unwrap();
        let params = LemkeParams::default();
        let (sol, cold) = lemke::solve(&p, Warm::default(), 1e-10, &params).unwrap();
        let basis = sol.unwrap().basis;
        let qn = p.q().iter().fold(0.0f64, |s, v| s.max(v.abs()));
        let q: Vec<f64> = p
            .q()
            .iter()
            .enumerate()
            .map(|(i, v)| v + 1e-4 * qn * ((i * 7919 % 101) as f64 / 50.0 - 1.0))
            .collect();
        let p2 = FcProblem::new(p.mu().to_vec(), q, p.w().clone()).unwrap();
        let warm = Warm {
            basis: Some(&basis),
            impulses: None,
        };
        let (sol2, rep) = lemke::solve(&p2, warm, 1e-10, &params).unwrap();
        let r2 = sol2.unwrap().r;
        assert!(rep.warm_solved, "{name}: {rep:?}");
        assert!(fc_error(&p2, &r2) <= 1e-10, "{name}: {rep:?}");
        assert!(
            20 * rep.pivots <= cold.pivots,
            "{name}: warm {} pivots, cold {}",
            rep.pivots,
            cold.pivots
        );
    }
}

/// `cols × rows` equal disks on a square lattice touching each other, the floor and two
/// frictional walls (μ = 0.4), at rest; one step with `method = lemke`: every velocity vanishes
/// and the supports carry exactly the weight.
#[test]
fn lemke_holds_a_hyperstatic_stack_at_rest() {
    let (cols, rows, r) = (6, 8, 1e-3);
    let (mut w, weight) = stack(cols, rows, SolverMethod::Lemke, 1e-12);
    let rep = w.step().unwrap();
    assert!(
        rep.solver.converged && rep.solver.error <= 1e-12,
        "{:?}",
        rep.solver
    );
    assert!(rep.solver.pivots > 0, "{:?}", rep.solver);
    let grains = rows * cols;
    assert!(2 * rep.contacts > 3 * grains, "hyperstatic: {rep:?}");
    let vmax = w
        .bodies
        .iter()
        .map(|b| b.velocity.norm().max(b.omega.abs() * r))
        .fold(0.0, f64::max);
    assert!(vmax <= 1e-12, "largest velocity {vmax:e} m/s");
    let support: f64 = (0..3).map(|b| w.contact_force(b).0.y).sum::<f64>();
    assert!(
        (-support - weight).abs() <= 1e-10 * weight,
        "supports carry {} N of {weight} N",
        -support
    );
}
