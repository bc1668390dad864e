//! The world of the `inclined-flow` scenario: grains on a rough periodic slope.

use datasets::error::Result;
use dem::math::Vector;
use dem::World;
use rand::Rng;

use super::config::InclinedFlowConfig;
use crate::scenarios::common::build::{rough_bed, RoughBed, BUILD_TOLERANCE, GRAIN};

/// A flow down a rough slope in the slope frame: x along the slope (periodic, length
/// `cell_length_diameters · 2 R̄`), y its normal, gravity `g (sin θ, −cos θ)`. Body 0 is the rough
/// bottom `base` (glued disks of the mean radius centred on y = 0), then the grains rained above.
pub fn inclined_flow(c: &InclinedFlowConfig) -> Result<World> {
    let g = &c.grain;
    let length = c.cell_length_diameters * 2.0 * g.radius_mean;
    let theta = c.slope_deg.to_radians();
    let gravity = Vector::new(9.81 * theta.sin(), -9.81 * theta.cos());
    let RoughBed {
        world: mut w,
        mut rng,
        radii,
        centres,
        ..
    } = rough_bed(
        c.seed,
        g,
        c.grains,
        length,
        c.dt,
        gravity,
        &c.friction,
        "base",
    )?;
    c.solver.apply(&mut w.params);
    for (p, r) in centres.iter().zip(&radii) {
        let b = w.add_grain(*p, *r, g.density, GRAIN);
        // A small random velocity breaks the symmetry of the start.
        w.bodies[b as usize].velocity = Vector::new(rng.random_range(-0.01..0.01), 0.0);
    }
    w.validate(BUILD_TOLERANCE)?;
    Ok(w)
}
