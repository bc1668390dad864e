//! The world of the `biaxial` scenario: a loose packing in a biperiodic deformable cell
//! (`dem::cell`), no walls, no gravity.

use datasets::error::Result;
use dem::World;

use super::config::BiaxialConfig;
use crate::scenarios::common::build::{loose_cell, LooseCell};

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
