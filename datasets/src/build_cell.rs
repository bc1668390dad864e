//! The worlds of the `simple-shear` and `biaxial` scenarios: a loose packing in a biperiodic
//! deformable cell (`dem::cell`), no walls, no gravity.

use dem::cell::Cell;
use dem::math::Vector;
use dem::World;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::config::{BiaxialConfig, GrainSpec, SimpleShearConfig, SolverSpec};
use crate::error::Result;
use crate::generators::uniform_radii;

/// The initial loose packing of the `simple-shear` scenario ([`loose_cell`]).
pub fn simple_shear(c: &SimpleShearConfig) -> Result<World> {
    loose_cell(&LooseCell {
        seed: c.seed,
        grains: c.grains,
        grain: &c.grain,
        friction: c.friction.grain_grain,
        restitution: c.restitution,
        theta: c.theta,
        solid_fraction: c.initial_solid_fraction,
        dt: c.compression_dt(2.0 * c.grain.radius_mean),
        solver: &c.solver,
    })
}

/// The initial loose packing of the `biaxial` scenario ([`loose_cell`]), the same for every
/// confining pressure.
pub fn biaxial(c: &BiaxialConfig) -> Result<World> {
    loose_cell(&LooseCell {
        seed: c.seed,
        grains: c.grains,
        grain: &c.grain,
        friction: c.friction.grain_grain,
        restitution: 0.0,
        theta: c.theta,
        solid_fraction: c.initial_solid_fraction,
        dt: c.compression_dt(),
        solver: &c.solver,
    })
}

/// What [`loose_cell`] builds.
pub struct LooseCell<'a> {
    /// Seed of the radii and the placement.
    pub seed: u64,
    /// Number of grains.
    pub grains: usize,
    /// Radii and density.
    pub grain: &'a GrainSpec,
    /// Grain–grain friction coefficient.
    pub friction: f64,
    /// Grain–grain normal restitution coefficient `e` (Newton's law on impacts; 0: none).
    pub restitution: f64,
    /// θ of the Moreau–Jean position update `q⁺ = q⁻ + h((1 − θ) v⁻ + θ v⁺)`, in [½, 1].
    pub theta: f64,
    /// Solid fraction aimed at (1).
    pub solid_fraction: f64,
    /// Time step (s).
    pub dt: f64,
    /// Contact solver.
    pub solver: &'a SolverSpec,
}

/// The initial loose packing: `grains` disks (radii from `grain`, seeded) on a jittered
/// square lattice in a square cell at the solid fraction `solid_fraction` (lower if the
/// lattice needs it: spacing at least 2 % above the largest diameter), at rest.
pub fn loose_cell(c: &LooseCell) -> Result<World> {
    let mut rng = ChaCha8Rng::seed_from_u64(c.seed);
    let radii = uniform_radii(&mut rng, c.grains, c.grain);
    let area: f64 = radii.iter().map(|r| std::f64::consts::PI * r * r).sum();
    let n_side = (c.grains as f64).sqrt().ceil() as usize;
    let r_max = radii.iter().cloned().fold(0.0, f64::max);
    let spacing = ((area / c.solid_fraction).sqrt() / n_side as f64).max(2.04 * r_max);
    let side = spacing * n_side as f64;
    let params = dem::WorldParams {
        dt: c.dt,
        gravity: Vector::zeros(),
        detection_gap: 0.1 * c.grain.radius_min(),
        solver: c.solver.params(),
        overlap_rate: c.solver.overlap_rate,
        theta: c.theta,
        ..Default::default()
    };
    let mut laws = dem::ContactLaws::new(&["grain"], c.friction);
    if c.restitution > 0.0 {
        laws.set_restitution(0, 0, c.restitution);
    }
    let mut w = World::new(params, laws);
    let slack = 0.5 * (spacing - 2.0 * r_max) * 0.9;
    for (k, &r) in radii.iter().enumerate() {
        let (i, j) = (k % n_side, k / n_side);
        let jitter = Vector::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)) * slack;
        let x = Vector::new(i as f64 + 0.5, j as f64 + 0.5) * spacing + jitter;
        w.add_grain(x, r, c.grain.density, 0);
    }
    let cell = Cell::rectangle(side, side)?;
    w.set_cell(Some(cell))?;
    w.validate(1e-12)?;
    Ok(w)
}
