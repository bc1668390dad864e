//! Homogenisation of snapshots produced by the engine itself (dem::World), not hand-built ones:
//! the stages must agree on levers, forces and accelerations.

use dem::math::{Tensor, Vector};
use dem::{BodyKind, ContactLaws, SolverParams, World, WorldParams};
use homogenise::grain_stresses;
use homogenise::tensor::{in_frame, skew_ratio, slope_frame};

const G: f64 = 9.81;

/// The rolling disk of `docs/physics.md` §2.3 simulated by the engine (θ = 1/2 so that the travelled length
/// is exactly `a t²/2`), slope made by a tilted wall and by rotated gravity: per-grain stress
/// `ρ g a [[0, sinφ/6], [sinφ/6, −cosφ]] + (ρ g L sinφ/3) 𝟙` and contact part
/// `ρ g a [[0, sinφ/3], [0, −cosφ]]` in the slope frame, to 1e-6 relative (of ‖Σ‖).
#[test]
fn engine_rolling_disk_matches_the_exact_stress() {
    for tilted in [true, false] {
        for (phi_deg, a, steps) in [
            (26.0f64, 0.01, 400usize),
            (15.0, 0.003, 900),
            (40.0, 0.05, 250),
        ] {
            let phi = phi_deg.to_radians();
            let (e1, e2) = slope_frame(phi);
            let (gravity, normal) = if tilted {
                (Vector::new(0.0, -G), e2)
            } else {
                (
                    Vector::new(G * phi.sin(), -G * phi.cos()),
                    Vector::new(0.0, 1.0),
                )
            };
            let params = WorldParams {
                dt: 1e-3,
                theta: 0.5,
                gravity,
                solver: SolverParams {
                    tolerance: 1e-12,
                    ..Default::default()
                },
                ..Default::default()
            };
            let rho = 2600.0;
            let mut w = World::new(params, ContactLaws::new(&["m"], 0.6));
            w.add_line_wall("slope", Vector::zeros(), normal, 0);
            let b = w.add_grain(normal * a, a, rho, 0) as usize;
            let x0 = w.bodies[b].position;
            for _ in 0..steps {
                assert!(w.step().unwrap().solver.converged);
            }
            let snap = w.snapshot();
            let gs = grain_stresses(&snap).unwrap();
            let (f1, f2) = if tilted {
                (e1, e2)
            } else {
                (Vector::x(), Vector::y())
            };
            let l = (snap.bodies[b].position - x0).dot(&f1);
            let total = in_frame(&gs[0].total, &f1, &f2);
            let contact = in_frame(&gs[0].contact, &f1, &f2);
            let (s, c) = phi.sin_cos();
            let exact = Tensor::new(0.0, s / 6.0, s / 6.0, -c) * (rho * G * a)
                + Tensor::identity() * (rho * G * l * s / 3.0);
            let exact_contact = Tensor::new(0.0, s / 3.0, 0.0, -c) * (rho * G * a);
            assert!(
                (total - exact).norm() <= 1e-6 * exact.norm(),
                "φ {phi_deg}°, a {a}: {total} vs {exact}"
            );
            assert!((contact - exact_contact).norm() <= 1e-6 * exact_contact.norm());
            assert!(skew_ratio(&gs[0].total) <= 1e-8);
            assert!(skew_ratio(&gs[0].contact) > 0.05);
        }
    }
}

fn deposit(n: usize, seed: u64) -> World {
    let params = WorldParams {
        dt: 2e-4,
        solver: SolverParams {
            tolerance: 1e-6,
            max_iterations: 5_000,
            ..Default::default()
        },
        detection_gap: 1e-4,
        ..Default::default()
    };
    let mut w = World::new(params, ContactLaws::new(&["grain"], 0.4));
    let width = 0.06;
    w.add_box_walls(width, 0);
    let mut s = seed;
    let mut u = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let pitch = 4.2e-3;
    let per_row = (width / pitch) as usize;
    for i in 0..n {
        let r = 1.5e-3 + 0.5e-3 * u();
        let x = pitch * ((i % per_row) as f64 + 0.5);
        let y = pitch * ((i / per_row) as f64 + 0.5);
        let g = w.add_grain(Vector::new(x, y), r, 2500.0, 0) as usize;
        w.bodies[g].velocity = Vector::new(0.1 * (u() - 0.5), 0.0);
    }
    w
}

/// Σ_p is symmetric in every dynamic state of a collapsing deposit (ω̇ is consistent with the
/// step's impulses), while the contact part alone is not.
#[test]
fn engine_grain_stress_is_symmetric_in_dynamic_states() {
    let mut w = deposit(150, 3);
    let mut worst_total = 0.0f64;
    let mut worst_contact = 0.0f64;
    for step in 0..600 {
        w.step().unwrap();
        if step % 50 == 49 {
            for g in grain_stresses(&w.snapshot()).unwrap() {
                if g.contact.norm() > 0.0 {
                    worst_total = worst_total.max(skew_ratio(&g.total));
                    worst_contact = worst_contact.max(skew_ratio(&g.contact));
                }
            }
        }
    }
    assert!(worst_total <= 1e-8, "skew/‖Σ‖ = {worst_total:e}");
    assert!(worst_contact > 1e-2, "contact part skew {worst_contact:e}");
}

/// A relaxed deposit is in static equilibrium: the bottom wall and the side walls together carry
/// the weight (vertical force balance to 1e-6 of the weight).
#[test]
fn engine_relaxed_deposit_walls_carry_the_weight() {
    let mut w = deposit(120, 9);
    for _ in 0..2500 {
        w.step().unwrap();
    }
    // Relaxation at tight tolerance.
    w.params.solver.tolerance = 1e-9;
    w.params.solver.max_iterations = 50_000;
    for _ in 0..50 {
        w.step().unwrap();
    }
    let snap = w.snapshot();
    let weight: f64 = snap
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .map(|b| b.mass * G)
        .sum();
    let carried: f64 = snap.walls.iter().map(|x| x.force.y).sum::<f64>();
    // Walls receive the grains' push: downward, total −weight.
    assert!(
        (carried + weight).abs() <= 1e-6 * weight,
        "walls carry {} N of {} N",
        -carried,
        weight
    );
    // At rest: kinetic energy below 1e-6 of weight × grain diameter (the deposit still creeps
    // at ~1e-8 of it after 0.5 s).
    let ke: f64 = w.kinetic_energy();
    assert!(ke <= 1e-6 * weight * 3.5e-3, "not at rest: KE {ke}");
}
