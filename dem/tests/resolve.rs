//! The last step's problem re-solved (`World::last_step_problem`,
//! `World::snapshot_with_last_impulses`): the state the engine would have reached with other
//! impulses obeys Newton's law with them, and the run's own impulses give its own snapshot.

mod common;

use common::random_box;
use dem::fc::SolverMethod;
use dem::snapshot::BodyKind;
use nalgebra::Vector2;

/// The box after 40 steps solved loosely (Gauss–Seidel stopped at 10⁻³).
fn loose_box() -> dem::World {
    let mut w = random_box(60, 0.04, 1e-3, 1.5e-3, 0.5, 1.0, 7);
    w.params.solver.tolerance = 1e-3;
    w.params.solver.method = SolverMethod::Nlgs;
    for _ in 0..40 {
        w.step().unwrap();
    }
    w
}

#[test]
fn the_run_s_own_impulses_give_its_own_snapshot() {
    let w = loose_box();
    let (problem, r) = w.last_step_problem().expect("a step was made");
    assert_eq!(problem.contacts() * 2, r.len());
    assert!(problem.contacts() > 60, "{} contacts", problem.contacts());
    let same = w.snapshot_with_last_impulses(&r).unwrap();
    assert_eq!(same, w.snapshot(), "bit for bit");
}

/// Tolerance 10⁻⁹ relative to the largest force of a grain's balance: the re-solved state is
/// Moreau–Jean's update with the new impulses, so each grain's mean acceleration over the step
/// is its weight plus the new contact forces over its mass, and its angular acceleration their
/// torque over its inertia.
#[test]
fn a_resolved_snapshot_obeys_newton_s_law_with_the_new_impulses() {
    let w = loose_box();
    let (problem, r) = w.last_step_problem().unwrap();
    let sol = common::solve_tightly(&problem, &r, 1e-10);
    let change = sol
        .r
        .iter()
        .zip(&r)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let largest = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(change > 1e-4 * largest, "the loose solve was already exact");
    let snap = w.snapshot_with_last_impulses(&sol.r).unwrap();
    let g = w.params.gravity;
    let n = snap.bodies.len();
    let mut force = vec![Vector2::zeros(); n];
    let mut torque = vec![0.0; n];
    let mut scale = vec![0.0f64; n];
    for c in &snap.contacts {
        let t = Vector2::new(-c.normal.y, c.normal.x);
        let f = c.normal * c.force_n + t * c.force_t;
        let (a, b) = (c.body_a as usize, c.body_b as usize);
        force[b] += f;
        force[a] -= f;
        torque[b] += c.lever_b.perp(&f);
        torque[a] -= c.lever_a.perp(&f);
        scale[a] = scale[a].max(f.norm());
        scale[b] = scale[b].max(f.norm());
    }
    for (i, b) in snap.bodies.iter().enumerate() {
        if b.kind != BodyKind::Grain {
            continue;
        }
        let s = scale[i].max(b.mass * g.norm());
        let lin = (b.acceleration * b.mass - (force[i] + g * b.mass)).norm();
        assert!(lin <= 1e-9 * s, "grain {i}: {lin:.3e} N against {s:.3e} N");
        let ang = (b.angular_acceleration * b.inertia - torque[i]).abs();
        assert!(
            ang <= 1e-9 * s * b.radius,
            "grain {i}: {ang:.3e} N·m against {:.3e}",
            s * b.radius
        );
    }
    // Velocities, positions and angles moved with the accelerations: Δv = h Δa (mean
    // acceleration over the step), Δq = θ h Δv (θ = 1 here), to rounding.
    let before = w.snapshot();
    let h = w.params.dt;
    let theta = w.params.theta;
    let mut moved = 0;
    for (b0, b1) in before.bodies.iter().zip(&snap.bodies) {
        let dv = b1.velocity - b0.velocity;
        let da = b1.acceleration - b0.acceleration;
        let dw = b1.omega - b0.omega;
        let scale = 1e-12 * (b0.velocity.norm() + dv.norm() + 1e-9);
        assert!((dv - da * h).norm() <= scale, "{dv:?} vs h·{da:?}");
        assert!(
            (dw - (b1.angular_acceleration - b0.angular_acceleration) * h).abs()
                <= 1e-9 * (b0.omega.abs() + dw.abs() + 1e-9)
        );
        let dq = b1.position - b0.position;
        assert!((dq - dv * (theta * h)).norm() <= 1e-12 * (b0.position.norm() + 1e-9));
        assert!(((b1.angle - b0.angle) - theta * h * dw).abs() <= 1e-12 * (b0.angle.abs() + 1.0));
        if b0.kind != BodyKind::Grain {
            // Walls are fixed: no inverse mass, no change.
            assert_eq!((dv, dw), (Vector2::zeros(), 0.0));
        } else if dv.norm() > 0.0 {
            moved += 1;
        }
    }
    assert!(moved > 10, "{moved} grains moved");
    // Each wall's resultant is the sum of the new forces of its contacts (it receives −f),
    // to rounding.
    for wall in &snap.walls {
        let mut f = Vector2::zeros();
        for c in &snap.contacts {
            let t = Vector2::new(-c.normal.y, c.normal.x);
            let fc = c.normal * c.force_n + t * c.force_t;
            if c.body_a == wall.body {
                f -= fc;
            }
            if c.body_b == wall.body {
                f += fc;
            }
        }
        assert!(
            (wall.force - f).norm() <= 1e-9 * (f.norm() + 1e-12),
            "{}: {:?} vs {f:?}",
            wall.name,
            wall.force
        );
    }
    // The forces are the new impulses over the step, in the cone.
    for (c, x) in snap.contacts.iter().zip(sol.r.chunks_exact(2)) {
        assert_eq!(c.force_n, x[0] / w.params.dt);
        assert!(c.force_t.abs() <= c.mu * c.force_n * (1.0 + 1e-12) + 1e-300);
    }
}

/// Before any step there is no problem; a world returned to an undo point has the problem of
/// the step that led there (the same `q` and impulses, bit for bit), not that of the step
/// undone; wrong lengths are typed errors.
#[test]
fn an_undone_step_leaves_the_problem_of_the_point_returned_to() {
    let fresh = random_box(60, 0.04, 1e-3, 1.5e-3, 0.5, 1.0, 7);
    assert!(fresh.last_step_problem().is_none());
    let err = fresh.snapshot_with_last_impulses(&[]).unwrap_err();
    assert!(err.to_string().contains("not available"), "{err}");
    let mut w = loose_box();
    let (p0, r0) = w.last_step_problem().unwrap();
    let point = w.undo_point();
    w.step().unwrap();
    let (p1, _) = w.last_step_problem().unwrap();
    assert_ne!(p1.q(), p0.q(), "the step changed the problem");
    w.undo_to(&point);
    let (pu, ru) = w.last_step_problem().unwrap();
    assert_eq!((pu.q(), &ru), (p0.q(), &r0));
    assert_eq!(point.last_step_problem().unwrap().0.q(), p0.q());
    let err = w.snapshot_with_last_impulses(&ru[1..]).unwrap_err();
    assert!(err.to_string().contains("two per contact"), "{err}");
}

/// The problem goes with the contacts it was assembled from: priming the contacts again
/// (`World::prime_with_weight`) or giving the world a cell drops it (no problem rather than one
/// whose rows are not the step's), and the next step brings one back.
#[test]
fn the_problem_is_dropped_when_the_contacts_change_outside_a_step() {
    let mut w = loose_box();
    assert!(w.last_step_problem().is_some());
    w.prime_with_weight().unwrap();
    assert!(w.last_step_problem().is_none());
    assert!(w.snapshot_with_last_impulses(&[]).is_err());
    w.step().unwrap();
    let (problem, r) = w.last_step_problem().expect("a step was made");
    assert_eq!(problem.contacts() * 2, r.len());
    assert_eq!(problem.contacts(), w.contacts().len());
}
