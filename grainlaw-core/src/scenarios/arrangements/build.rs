//! The worlds of the `arrangements` scenario: regular stacks in a box.

use datasets::error::Result;
use datasets::generators::{lattice, Arrangement};
use dem::math::Vector;
use dem::World;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::config::ArrangementsConfig;
use crate::scenarios::common::build::{box_walls, world, BUILD_TOLERANCE, GRAIN, WALL};

/// A box with four line walls `bottom`, `left`, `right`, `top` holding a regular stack
/// ([`Arrangement`]); the top wall is one radius above the highest disk.
pub fn arrangement(c: &ArrangementsConfig, kind: Arrangement) -> Result<World> {
    let mut rng = ChaCha8Rng::seed_from_u64(c.seed);
    let r = c.radius;
    let centres = lattice(kind, c.columns, c.rows, r, c.gap, c.jitter, &mut rng);
    let width = 2.0 * r * c.columns as f64;
    let top = centres.iter().map(|p| p.y).fold(0.0, f64::max) + 2.0 * r;
    let mut w = world(c.dt, Vector::new(0.0, -9.81), None, r, &c.friction);
    c.solver.apply(&mut w.params);
    box_walls(&mut w, width);
    w.add_line_wall("top", Vector::new(0.0, top), Vector::new(0.0, -1.0), WALL);
    for p in centres {
        w.add_grain(p, r, c.density, GRAIN);
    }
    w.validate(BUILD_TOLERANCE)?;
    Ok(w)
}
