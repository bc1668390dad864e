//! The world of the `simple-shear` scenario: a loose packing in a biperiodic deformable cell
//! (`dem::cell`), no walls, no gravity.

use datasets::error::Result;
use dem::World;

use super::config::SimpleShearConfig;
use crate::scenarios::common::build::{loose_cell, LooseCell};

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
