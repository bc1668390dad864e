//! Helpers shared by the solver tests (`fc_newton`, `fc_lemke`).

use std::path::{Path, PathBuf};

use dem::fc::SolverMethod;
use dem::{ContactLaws, World, WorldParams};
use nalgebra::Vector2;

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
