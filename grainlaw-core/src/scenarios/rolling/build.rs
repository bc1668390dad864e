//! The world of the `rolling` scenario: one disk on a slope.

use datasets::error::Result;
use dem::math::Vector;
use dem::World;

use super::config::RollingConfig;
use crate::scenarios::common::build::{world, BUILD_TOLERANCE, GRAIN, WALL};
use crate::scenarios::common::config::FrictionSpec;

/// The rolling disk: slope through the origin descending to the right, e₁ = (cos φ, −sin φ)
/// down the slope, e₂ = (sin φ, cos φ) its outward normal; the disk touches the slope at the
/// origin, at rest. Body 0 is the wall `slope`, body 1 the disk.
pub fn rolling(c: &RollingConfig) -> Result<(World, Vector, Vector)> {
    let phi = c.slope_deg.to_radians();
    let e1 = Vector::new(phi.cos(), -phi.sin());
    let e2 = Vector::new(phi.sin(), phi.cos());
    let f = FrictionSpec {
        grain_grain: c.friction,
        grain_wall: c.friction,
    };
    let mut w = world(c.dt, Vector::new(0.0, -9.81), None, c.radius, &f);
    w.params.solver.tolerance = 1e-12;
    w.params.solver.max_iterations = 100;
    w.add_line_wall("slope", Vector::zeros(), e2, WALL);
    w.add_grain(e2 * c.radius, c.radius, c.density, GRAIN);
    w.validate(BUILD_TOLERANCE)?;
    Ok((w, e1, e2))
}
