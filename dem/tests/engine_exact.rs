//! Exact behaviours of the engine (`docs/physics.md` §1.7): rest on a plane, a column between smooth walls,
//! a disk on a slope (rolling, rolling and sliding, locked rotation), for a slope made by
//! rotated gravity and by a tilted wall.

use dem::{ContactLaws, Dof, SolverParams, World, WorldParams};
use nalgebra::Vector2;

const G: f64 = 9.81;

fn params(dt: f64, gravity: Vector2<f64>) -> WorldParams {
    WorldParams {
        dt,
        theta: 0.5,
        gravity,
        periodic_x: None,
        detection_gap: 1e-4,
        overlap_rate: 1e-4,
        position_correction: true,
        solver: SolverParams {
            tolerance: 1e-12,
            max_iterations: 100_000,
            ..Default::default()
        },
    }
}

/// A disk resting on a floor, θ = 1/2 and θ = 1, with the position correction on: the normal
/// impulse is `m g h` every step for 10⁴ steps (10⁻¹² relative), the centre does not drift
/// (10⁻¹² m), and the correction never acts (no overlap beyond the slop).
#[test]
fn disk_resting_on_a_floor_receives_mgh_every_step_without_drift() {
    let h = 1e-3;
    for theta in [0.5, 1.0] {
        let mut w = World::new(
            WorldParams {
                theta,
                ..params(h, Vector2::new(0.0, -G))
            },
            ContactLaws::new(&["m"], 0.4),
        );
        w.add_line_wall("floor", Vector2::new(0.0, 0.0), Vector2::new(0.0, 1.0), 0);
        let r = 0.01;
        let b = w.add_grain(Vector2::new(0.3, r), r, 2500.0, 0) as usize;
        let m = w.bodies[b].mass;
        for _ in 0..10_000 {
            let rep = w.step().unwrap();
            assert!(rep.solver.converged);
            assert_eq!(rep.position_correction.corrected_contacts, 0);
            assert_eq!(rep.position_correction.load_work, 0.0);
            let c = &w.contacts().rows[0];
            // Normal impulse = m g h to 1e-12 relative, no tangential impulse.
            assert!(
                (c.r[0] - m * G * h).abs() <= 1e-12 * m * G * h,
                "θ = {theta}: r_n = {}",
                c.r[0]
            );
            assert!(c.r[1].abs() <= 1e-15);
        }
        // No drift: the centre stays at y = R to 1e-12 m, the velocity at 0.
        assert!(
            (w.bodies[b].position.y - r).abs() < 1e-12,
            "y = {}",
            w.bodies[b].position.y
        );
        assert!(w.bodies[b].velocity.norm() < 1e-12);
        assert!((w.bodies[b].position.x - 0.3).abs() < 1e-15);
    }
}

#[test]
fn column_between_smooth_walls_each_contact_carries_the_weight_above() {
    let h = 1e-3;
    let r = 0.005;
    let mut w = World::new(
        params(h, Vector2::new(0.0, -G)),
        ContactLaws::new(&["m"], 0.0),
    );
    w.add_line_wall("bottom", Vector2::new(0.0, 0.0), Vector2::new(0.0, 1.0), 0);
    w.add_line_wall("left", Vector2::new(-r, 0.0), Vector2::new(1.0, 0.0), 0);
    w.add_line_wall("right", Vector2::new(r, 0.0), Vector2::new(-1.0, 0.0), 0);
    let n = 10;
    let ids: Vec<usize> = (0..n)
        .map(|k| w.add_grain(Vector2::new(0.0, r + 2.0 * r * k as f64), r, 2500.0, 0) as usize)
        .collect();
    let mg = w.bodies[ids[0]].mass * G;
    for _ in 0..50 {
        let rep = w.step().unwrap();
        assert!(rep.solver.converged, "{rep:?}");
    }
    let snap = w.snapshot();
    for c in &snap.contacts {
        let (a, b) = (c.body_a as usize, c.body_b as usize);
        // Grain k (0 at the bottom) carries the weight of the n − k grains from k upwards.
        let expected = if a == 0 {
            n as f64 * mg
        } else if a == 1 || a == 2 {
            0.0 // side walls: no load
        } else {
            let k = ids.iter().position(|&i| i == b).unwrap();
            (n - k) as f64 * mg
        };
        assert!(
            (c.force_n - expected).abs() <= 1e-9 * n as f64 * mg,
            "contact {a}-{b}: {} N vs {} N",
            c.force_n,
            expected
        );
        assert!(c.force_t.abs() <= 1e-12 * mg);
    }
    let bottom = snap.walls.iter().find(|x| x.name == "bottom").unwrap();
    assert!((bottom.force.y + n as f64 * mg).abs() <= 1e-9 * n as f64 * mg);
}

/// Measured acceleration of the centre along the slope and angular acceleration after `steps`
/// steps from rest, for a disk on a slope of angle `phi` made either by rotating gravity or by
/// tilting the wall.
fn slope_run(
    phi: f64,
    mu: f64,
    lock_rotation: bool,
    tilted_wall: bool,
    steps: usize,
) -> (f64, f64, f64) {
    let h = 1e-3;
    let r = 0.02;
    let (gravity, normal, down) = if tilted_wall {
        (
            Vector2::new(0.0, -G),
            Vector2::new(phi.sin(), phi.cos()),
            Vector2::new(phi.cos(), -phi.sin()),
        )
    } else {
        (
            Vector2::new(G * phi.sin(), -G * phi.cos()),
            Vector2::new(0.0, 1.0),
            Vector2::new(1.0, 0.0),
        )
    };
    let mut w = World::new(params(h, gravity), ContactLaws::new(&["m"], mu));
    w.add_line_wall("slope", Vector2::zeros(), normal, 0);
    let b = w.add_grain(normal * r, r, 2000.0, 0) as usize;
    if lock_rotation {
        w.bodies[b].dofs[2] = Dof::Imposed;
    }
    let x0 = w.bodies[b].position;
    for _ in 0..steps {
        let rep = w.step().unwrap();
        assert!(rep.solver.converged);
    }
    let t = steps as f64 * h;
    let body = &w.bodies[b];
    let a = body.velocity.dot(&down) / t;
    let alpha = -body.omega / t; // rolling down the slope turns clockwise
    let travelled = (body.position - x0).dot(&down);
    // The centre stays on the slope.
    assert!((body.position - x0).dot(&normal).abs() < 1e-12);
    (a, alpha, travelled)
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn disk_on_a_slope_rolls_without_slipping_when_mu_exceeds_tan_phi_over_three() {
    for tilted in [false, true] {
        for (phi_deg, mu) in [(10.0f64, 0.1), (26.0, 0.5), (40.0, 0.3)] {
            let phi = phi_deg.to_radians();
            assert!(mu >= phi.tan() / 3.0);
            let (a, alpha, travelled) = slope_run(phi, mu, false, tilted, 500);
            let expected = 2.0 / 3.0 * G * phi.sin();
            assert!(
                rel(a, expected) <= 1e-6,
                "phi {phi_deg}: a = {a} vs {expected}"
            );
            // Rolling without slipping: α = a / R.
            assert!(rel(alpha, expected / 0.02) <= 1e-6);
            // θ = 1/2 integrates a constant acceleration exactly: L = a t²/2.
            assert!(rel(travelled, 0.5 * expected * 0.25) <= 1e-6);
        }
    }
}

#[test]
fn disk_on_a_slope_rolls_and_slides_when_mu_is_below_tan_phi_over_three() {
    for tilted in [false, true] {
        for (phi_deg, mu) in [(30.0f64, 0.1), (45.0, 0.2), (20.0, 0.0)] {
            let phi = phi_deg.to_radians();
            assert!(mu < phi.tan() / 3.0);
            let (a, alpha, _) = slope_run(phi, mu, false, tilted, 500);
            let expected = G * (phi.sin() - mu * phi.cos());
            assert!(
                rel(a, expected) <= 1e-6,
                "phi {phi_deg}: a = {a} vs {expected}"
            );
            // Friction torque μ m g cosφ R = I α, I = m R²/2.
            let alpha_expected = 2.0 * mu * G * phi.cos() / 0.02;
            assert!((alpha - alpha_expected).abs() <= 1e-6 * alpha_expected.max(1.0));
        }
    }
}

#[test]
fn disk_with_locked_rotation_sticks_iff_tan_phi_at_most_mu() {
    for tilted in [false, true] {
        // Sticks: no motion at all.
        let (a, _, travelled) = slope_run(20f64.to_radians(), 0.4, true, tilted, 300);
        assert!(a.abs() < 1e-12 && travelled.abs() < 1e-12, "a = {a}");
        // Slides: a = g (sin φ − μ cos φ).
        let phi = 30f64.to_radians();
        let (a, _, _) = slope_run(phi, 0.4, true, tilted, 300);
        let expected = G * (phi.sin() - 0.4 * phi.cos());
        assert!(rel(a, expected) <= 1e-6, "a = {a} vs {expected}");
    }
}

/// Changing the time step between steps keeps the warm start right: impulses are rescaled by
/// the ratio of time steps, so a resting disk needs no sweep after the change (its warm-started
/// impulse `m g h'` is already the solution).
#[test]
fn warm_start_rescales_impulses_when_the_time_step_changes() {
    let mut w = World::new(
        params(1e-3, Vector2::new(0.0, -G)),
        ContactLaws::new(&["m"], 0.4),
    );
    w.add_line_wall("floor", Vector2::new(0.0, 0.0), Vector2::new(0.0, 1.0), 0);
    let b = w.add_grain(Vector2::new(0.0, 0.01), 0.01, 2500.0, 0) as usize;
    let m = w.bodies[b].mass;
    for _ in 0..5 {
        w.step().unwrap();
    }
    w.params.dt = 2.5e-4;
    let rep = w.step().unwrap();
    assert_eq!(rep.solver.iterations, 0, "{rep:?}");
    assert!((w.contacts().rows[0].r[0] - m * G * 2.5e-4).abs() <= 1e-12 * m * G * 2.5e-4);
}
