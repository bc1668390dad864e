//! The parallel (colour-ordered) contact solve: the same bits on any number of threads, and the
//! same physics as the natural order.

mod common;
use common::fingerprint;

use dem::colouring::ContactColouring;
use dem::{ContactLaws, SolverParams, World, WorldParams};
use nalgebra::Vector2;

const R: f64 = 1e-3;

/// A hexagonal crystal of `nx × ny` equal touching disks (radius 1 mm, 2500 kg/m³) in a box
/// whose floor and side walls touch it, μ = 0.3: about 3 contacts per grain.
fn crystal(nx: usize, ny: usize, parallel: bool) -> World {
    let params = WorldParams {
        dt: 1e-3,
        solver: SolverParams {
            tolerance: 1e-7,
            max_iterations: 20_000,
            parallel,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut w = World::new(params, ContactLaws::new(&["grain"], 0.3));
    let width = 2.0 * R * nx as f64 + R;
    w.add_box_walls(width, 0);
    for j in 0..ny {
        for i in 0..nx {
            let shift = if j % 2 == 1 { R } else { 0.0 };
            let p = Vector2::new(
                R + 2.0 * R * i as f64 + shift,
                R + j as f64 * 3f64.sqrt() * R,
            );
            w.add_grain(p, R, 2500.0, 0);
        }
    }
    w
}

fn run_on(threads: usize, steps: usize) -> (Vec<u64>, usize) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut w = crystal(60, 60, true);
        let mut sweeps = 0;
        for _ in 0..steps {
            sweeps += w.step().unwrap().solver.iterations;
        }
        (fingerprint(&w), sweeps)
    })
}

/// 3600 grains, about 10⁴ contacts, so that the colour classes and the Anderson vectors are
/// split across threads (classes above `parallel::PARALLEL_MIN` contacts, vectors above
/// `parallel::CHUNK`): one, two and three threads give bit-identical states.
#[test]
fn same_bits_on_one_two_and_three_threads() {
    let (one, sweeps) = run_on(1, 3);
    assert!(sweeps > 3, "the solve must do work: {sweeps} sweeps");
    for threads in [2, 3] {
        let (other, _) = run_on(threads, 3);
        assert!(one == other, "{threads} threads differ from one");
    }
}

/// The colouring of a real contact set is valid, uses few colours (first-fit on disks: at most
/// 11), and its classes are large enough to be split.
#[test]
fn colouring_of_a_crystal() {
    let mut w = crystal(60, 60, true);
    w.step().unwrap();
    let rows = &w.contacts().rows;
    let mobile: Vec<bool> = w.bodies.iter().map(|b| b.mass.is_finite()).collect();
    let mut c = ContactColouring::default();
    c.build(rows, &mobile);
    assert!(c.is_valid(rows, &mobile));
    assert!(c.colours() <= 11, "{} colours", c.colours());
    assert!(!c.sequential_tail);
    assert!(c.class(0).len() > dem::parallel::PARALLEL_MIN);
    assert!(
        rows.len() > 2 * dem::parallel::CHUNK,
        "{} contacts",
        rows.len()
    );
}

/// Colour order and natural order solve the same physics: the crystal stays at rest (velocities
/// below 10⁻⁷ m/s) and the walls carry the weight of every grain to 10⁻⁶ in both.
#[test]
fn colour_order_and_natural_order_agree_on_the_physics() {
    for parallel in [false, true] {
        let mut w = crystal(30, 30, parallel);
        for _ in 0..3 {
            let r = w.step().unwrap();
            assert!(r.solver.converged, "parallel {parallel}: {r:?}");
        }
        let weight: f64 = w
            .bodies
            .iter()
            .filter(|b| b.mass.is_finite())
            .map(|b| b.mass * 9.81)
            .sum();
        // walls are bodies 0, 1, 2; the force they receive is the grains' weight (the side
        // walls carry part of it by friction)
        let walls: f64 = (0..3).map(|b| w.contact_force(b).0.y).sum();
        let vmax = w
            .bodies
            .iter()
            .map(|b| b.velocity.norm())
            .fold(0.0, f64::max);
        assert!(
            (walls + weight).abs() <= 1e-6 * weight,
            "parallel {parallel}: walls {walls} weight {weight}"
        );
        assert!(vmax < 1e-7, "parallel {parallel}: |v| {vmax}");
    }
}
