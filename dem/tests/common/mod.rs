//! Worlds and problem lists used by several engine and solver tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use dem::fc::SolverMethod;
use dem::{ContactLaws, SolverParams, World, WorldParams};
use nalgebra::Vector2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A box `[0, width] × [0, ∞)` with floor and two side walls (line walls), filled with `n`
/// random disks of radius in `[r_min, r_max]` placed without overlap on a loose grid with small
/// random velocities. Density 2500 kg/m³, friction `mu` everywhere.
pub fn random_box(
    n: usize,
    width: f64,
    r_min: f64,
    r_max: f64,
    mu: f64,
    theta: f64,
    seed: u64,
) -> World {
    let params = WorldParams {
        dt: 1e-3,
        theta,
        gravity: Vector2::new(0.0, -9.81),
        periodic_x: None,
        detection_gap: 0.2 * r_min,
        overlap_rate: 1e-4,
        position_correction: true,
        solver: SolverParams {
            tolerance: 1e-10,
            max_iterations: 20_000,
            ..Default::default()
        },
    };
    let mut w = World::new(params, ContactLaws::new(&["grain"], mu));
    w.add_box_walls(width, 0);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let pitch = 2.0 * r_max * 1.05;
    let per_row = ((width / pitch).floor() as usize).max(1);
    for i in 0..n {
        let (ix, iy) = (i % per_row, i / per_row);
        let r = rng.random_range(r_min..=r_max);
        let x = pitch * (ix as f64 + 0.5) + rng.random_range(-0.02..0.02) * r_max;
        let y = pitch * (iy as f64 + 0.5);
        let b = w.add_grain(Vector2::new(x, y), r, 2500.0, 0);
        let body = &mut w.bodies[b as usize];
        body.velocity = Vector2::new(rng.random_range(-0.05..0.05), rng.random_range(-0.05..0.05));
        body.omega = rng.random_range(-1.0..1.0);
    }
    w
}

/// Every number of the state, bit for bit: positions, angles, velocities of every body, and the
/// impulses of every contact (for tests of bit-identical runs).
pub fn fingerprint(w: &World) -> Vec<u64> {
    w.state_bits()
}

/// The `.json.gz` problems of `datasets/fc-problems/DIR`, sorted.
pub fn problems(dir: &str) -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../datasets/fc-problems");
    let mut v: Vec<PathBuf> = std::fs::read_dir(root.join(dir))
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".json.gz"))
        .collect();
    v.sort();
    v
}

/// `cols × rows` equal disks (radius 1 mm) on a square lattice, touching each other, the floor
/// and two vertical walls, μ = 0.4 everywhere, at rest, solved with `method` to `tol` (at most
/// 10⁵ sweeps); returns the world and the weight of the grains (N per metre).
pub fn stack(cols: usize, rows: usize, method: SolverMethod, tol: f64) -> (World, f64) {
    let r = 1e-3;
    let mut params = WorldParams::default();
    params.solver.method = method;
    params.solver.tolerance = tol;
    params.solver.max_iterations = 100_000;
    let mut w = World::new(params, ContactLaws::new(&["grain"], 0.4));
    let width = 2.0 * r * cols as f64;
    w.add_line_wall("floor", Vector2::zeros(), Vector2::new(0.0, 1.0), 0);
    w.add_line_wall("left", Vector2::zeros(), Vector2::new(1.0, 0.0), 0);
    w.add_line_wall(
        "right",
        Vector2::new(width, 0.0),
        Vector2::new(-1.0, 0.0),
        0,
    );
    for j in 0..rows {
        for i in 0..cols {
            w.add_grain(
                Vector2::new(r + 2.0 * r * i as f64, r + 2.0 * r * j as f64),
                r,
                2500.0,
                0,
            );
        }
    }
    let weight: f64 = w.bodies.iter().map(|b| b.mass).sum::<f64>() * 9.81;
    (w, weight)
}

/// `disks` touching equal disks (radius 1 mm, 2500 kg/m³) stacked on a floor, at rest, μ = 0.5,
/// step 10⁻⁴ s, solved with `solver`.
pub fn column(disks: usize, solver: SolverParams) -> World {
    let params = WorldParams {
        dt: 1e-4,
        solver,
        ..Default::default()
    };
    let mut w = World::new(params, ContactLaws::new(&["grain"], 0.5));
    w.add_line_wall("floor", Vector2::zeros(), Vector2::new(0.0, 1.0), 0);
    for k in 0..disks {
        w.add_grain(
            Vector2::new(0.0, 1e-3 * (1.0 + 2.0 * k as f64)),
            1e-3,
            2500.0,
            0,
        );
    }
    w
}

/// Gauss–Seidel alone (`nlgs`) to `tolerance` with at most `sweeps` sweeps.
pub fn nlgs(tolerance: f64, sweeps: usize) -> SolverParams {
    SolverParams {
        tolerance,
        max_iterations: sweeps,
        method: SolverMethod::Nlgs,
        ..Default::default()
    }
}

/// `problem` solved from the impulses `r` to `tolerance` by `auto` (Gauss–Seidel, Newton, the
/// exact finish), which must converge: the re-solve of the solver-sensitivity tests.
pub fn solve_tightly(
    problem: &dem::fc::FcProblem,
    r: &[f64],
    tolerance: f64,
) -> dem::fc::FcSolution {
    let options = dem::fc::FcOptions {
        tolerance,
        initial_guess: Some(r.to_vec()),
        ..dem::fc::FcOptions::default()
    };
    let (sol, _) = dem::fc::solve_by(
        problem,
        &options,
        SolverMethod::Auto,
        &dem::fc::NewtonParams::default(),
    )
    .unwrap();
    assert!(sol.converged, "error {:.2e}", sol.error);
    sol
}
