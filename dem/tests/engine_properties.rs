//! Invariants of the engine on random worlds (proptest): every contact impulse lies in its
//! Coulomb cone, and no grain leaves a closed box.

use dem::{ContactLaws, SolverParams, World, WorldParams};
use nalgebra::Vector2;
use proptest::prelude::*;

/// A closed box [0, w] × [0, h] with `n` random disks and random velocities.
fn closed_box(n: usize, mu: f64, e: f64, dt: f64, seed: u64) -> World {
    let (w, h) = (0.06, 0.06);
    let params = WorldParams {
        dt,
        detection_gap: 1e-4,
        solver: SolverParams {
            tolerance: 1e-6,
            max_iterations: 2_000,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut laws = ContactLaws::new(&["m"], mu);
    laws.set_restitution(0, 0, e);
    let mut world = World::new(params, laws);
    world.add_line_wall("bottom", Vector2::new(0.0, 0.0), Vector2::new(0.0, 1.0), 0);
    world.add_line_wall("top", Vector2::new(0.0, h), Vector2::new(0.0, -1.0), 0);
    world.add_line_wall("left", Vector2::new(0.0, 0.0), Vector2::new(1.0, 0.0), 0);
    world.add_line_wall("right", Vector2::new(w, 0.0), Vector2::new(-1.0, 0.0), 0);
    let mut s = seed | 1;
    let mut u = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let pitch = 6e-3;
    let per_row = 9;
    for i in 0..n {
        let r = 1.5e-3 + 1.2e-3 * u();
        let x = pitch * ((i % per_row) as f64 + 1.0);
        let y = pitch * ((i / per_row) as f64 + 1.0);
        let b = world.add_grain(Vector2::new(x, y), r, 2500.0, 0) as usize;
        world.bodies[b].velocity = Vector2::new(2.0 * (u() - 0.5), 2.0 * (u() - 0.5));
        world.bodies[b].omega = 100.0 * (u() - 0.5);
    }
    world
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, .. ProptestConfig::default() })]

    #[test]
    fn impulses_stay_in_the_cone_and_grains_in_the_box(
        n in 10usize..60,
        mu in 0.0f64..1.0,
        e in prop_oneof![Just(0.0), 0.0f64..0.9],
        dt in prop_oneof![Just(5e-5), Just(1e-4), Just(5e-4), Just(1e-3)],
        seed in any::<u64>(),
    ) {
        let mut w = closed_box(n, mu, e, dt, seed);
        w.validate(1e-12).unwrap();
        for _ in 0..150 {
            let rep = w.step().unwrap();
            for c in &w.contacts().rows {
                // r_n ≥ 0 and |r_t| ≤ μ r_n, up to rounding.
                prop_assert!(c.r[0] >= 0.0, "r_n = {}", c.r[0]);
                prop_assert!(c.r[1].abs() <= c.mu * c.r[0] * (1.0 + 1e-12) + 1e-300,
                    "|r_t| = {} > μ r_n = {}", c.r[1].abs(), c.mu * c.r[0]);
            }
            // Overlaps stay small (below 2 % of the smallest radius) when the time step
            // resolves the motion (travel per step ≤ 0.1 r_min at 1.4 m/s). With coarser steps a
            // cascade of impacts inside one step can carry a grain farther than its own swept
            // margin, and velocity-level contact laws then leave an overlap.
            if dt <= 1e-4 {
                prop_assert!(rep.max_penetration <= 0.02 * 1.5e-3, "penetration {}", rep.max_penetration);
            }
        }
        for b in w.bodies.iter().filter(|b| b.kind == dem::BodyKind::Grain) {
            // Every centre stays inside the box; with a resolving time step, every disk too
            // (within 2 % of its radius).
            let tol = if dt <= 1e-4 { 0.02 * b.radius } else { b.radius * (1.0 - 1e-9) };
            prop_assert!(b.position.x >= b.radius - tol && b.position.x <= 0.06 - b.radius + tol,
                "grain left the box: x = {}", b.position.x);
            prop_assert!(b.position.y >= b.radius - tol && b.position.y <= 0.06 - b.radius + tol,
                "grain left the box: y = {}", b.position.y);
        }
    }
}
