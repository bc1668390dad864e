//! The world of the `shear-cell` scenario: grains between two rough walls, periodic along x.

use datasets::error::{DatasetError, Result};
use dem::math::Vector;
use dem::{Dof, World};

use super::config::ShearCellConfig;
use crate::scenarios::common::build::{
    rough_bed, rough_row, RoughBed, BUILD_TOLERANCE, GRAIN, WALL,
};

/// A plane shear cell without gravity: x periodic (length `cell_length_diameters · 2 R̄`), a
/// fixed rough wall `bottom` (body 0) at y = 0 and a rough wall `top` (body 1) whose y is free
/// (mass `wall_mass_ratio ×` the grains' mass, applied force `−P L t` ŷ) and whose x velocity is
/// imposed (zero until the runner sets it). Grains rained between them.
pub fn shear_cell(c: &ShearCellConfig) -> Result<(World, f64)> {
    let g = &c.grain;
    let length = c.cell_length_diameters * 2.0 * g.radius_mean;
    let RoughBed {
        world: mut w,
        radii,
        centres,
        gap,
        ..
    } = rough_bed(
        c.seed,
        g,
        c.grains,
        length,
        c.dt_max,
        Vector::zeros(),
        &c.friction,
        "bottom",
    )?;
    c.solver.apply(&mut w.params);
    let top_y = centres
        .iter()
        .zip(&radii)
        .map(|(p, r)| p.y + r)
        .fold(0.0, f64::max)
        + gap
        + g.radius_mean;
    let (tc, tr) = rough_row(length, g.radius_mean, top_y);
    let top = w.add_clump("top", &tc, &tr, WALL) as usize;
    let mut grain_mass = 0.0;
    for (p, r) in centres.iter().zip(&radii) {
        let b = w.add_grain(*p, *r, g.density, GRAIN);
        grain_mass += w.bodies[b as usize].mass;
    }
    let body = &mut w.bodies[top];
    body.dofs = [Dof::Imposed, Dof::Free, Dof::Imposed];
    body.mass = c.wall_mass_ratio * grain_mass;
    body.gravity = false;
    body.applied_force = Vector::new(0.0, -c.pressure * length * body.thickness);
    if !(body.mass.is_finite() && body.mass > 0.0) {
        return Err(DatasetError::invalid(
            "wall_mass_ratio",
            "gives a top wall without positive finite mass",
        ));
    }
    w.validate(BUILD_TOLERANCE)?;
    Ok((w, length))
}
