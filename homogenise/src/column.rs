//! Depth profiles of a granular column between two vertical walls, in the form the Janssen fit
//! consumes (`identify::janssen::JanssenProfile`): depth `z` down from the free surface and
//! **compressive-positive** stress magnitudes in Pa.
//!
//! For each depth bin `[kΔ, (k+1)Δ)`:
//! - `sigma_v`: vertical stress across horizontal planes by the method of planes
//!   ([`crate::walls::plane_stress_profile`]), `σ_v = −σ_yy`, averaged over
//!   [`PLANES_PER_BIN`] planes at depths `(k + (i + ½)/8) Δ` (the bin's middle for a linear
//!   profile; no plane falls on the centre line of a layer aligned with the bins);
//! - `sigma_v_mean`: the homogenised mean stress over the bin's slice, `−Σ_yy`
//!   ([`crate::stress::mean_stress`]), the continuum-side measure;
//! - `sigma_h`, `tau_w`: the two walls' mean normal stress `−σ_nn` and shear stress (grains
//!   dragging the walls down positive) ([`crate::walls::wall_stress_profile`]);
//! - the share of wall contacts and of bulk contacts at the Coulomb limit `m ≥ 0.99`;
//! - the solid fraction of the slice.
//!
//! Whole-column figures: the width `W` (between the walls when both are lines, else the grains'
//! extent), the bulk density `ρ_b = φ ρ` (φ over the column, ρ the grains' mass over their
//! volume), and how the weight is shared: `bottom_load_over_weight` (force across the plane at
//! the lowest grain's bottom over the weight) and `side_wall_load_over_weight` (the side walls'
//! downward load over the weight); at rest the two add up to 1.
//! The column must stand along y with gravity along −y.

use dem::math::Vector;
use dem::snapshot::{BodyKind, Snapshot, WallGeometry};
use serde::{Deserialize, Serialize};

use crate::depth::{DepthAxis, DepthBins};
use crate::error::{positive, HomogeniseError, Result};
use crate::mobilisation::{fraction_at_limit_by_depth, ContactClass, COULOMB_LIMIT};
use crate::region::{grain_extent, Region};
use crate::stress::{grain_stresses, mean_stress};
use crate::walls::{find_wall, plane_stress_profile, wall_stress_profile};

/// Number of planes averaged per bin for `sigma_v`.
pub const PLANES_PER_BIN: usize = 8;

/// Which walls bound the column and how to bin it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ColumnSpec {
    /// Name of the left wall.
    pub left: String,
    /// Name of the right wall.
    pub right: String,
    /// Depth bin width Δ (m), e.g. one mean grain diameter.
    pub bin_width: f64,
}

/// Depth profiles of a column (compressive-positive stresses, Pa).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ColumnProfile {
    /// Column width `W` (m).
    pub width: f64,
    /// Height of the free surface (m): top of the highest grain.
    pub surface_y: f64,
    /// Depth of the bins' middles (m).
    pub depth: Vec<f64>,
    /// `σ_v` across planes, averaged over each bin (Pa, compressive positive).
    pub sigma_v: Vec<f64>,
    /// `−Σ_yy` of the mean stress over each bin's slice (Pa).
    pub sigma_v_mean: Vec<f64>,
    /// Mean of the two walls' normal stress magnitudes `σ_h` (Pa).
    pub sigma_h: Vec<f64>,
    /// Mean of the two walls' shear stresses `τ_w` (Pa).
    pub tau_w: Vec<f64>,
    /// Share of the two walls' contacts at the Coulomb limit per bin (`None`: no contact).
    pub wall_fraction_at_limit: Vec<Option<f64>>,
    /// Share of grain–grain contacts at the Coulomb limit per bin (`None`: no contact).
    pub bulk_fraction_at_limit: Vec<Option<f64>>,
    /// Solid fraction of each bin's slice.
    pub solid_fraction: Vec<f64>,
    /// Solid fraction of the whole column.
    pub column_solid_fraction: f64,
    /// Bulk density `ρ_b = φ ρ` (kg/m³).
    pub bulk_density: f64,
    /// Weight of the grains (N).
    pub weight: f64,
    /// Vertical force across the plane at the lowest grain's bottom over the weight.
    pub bottom_load_over_weight: f64,
    /// Downward force of the grains on the two side walls over the weight.
    pub side_wall_load_over_weight: f64,
}

/// Depth profiles of the column between the walls `spec.left` and `spec.right` (see the
/// module documentation). Bins run from the free surface down to the lowest grain's bottom.
pub fn column_profile(snapshot: &Snapshot, spec: &ColumnSpec) -> Result<ColumnProfile> {
    positive("bin_width", spec.bin_width)?;
    let g = snapshot.gravity;
    if !(g.y < 0.0 && g.x.abs() <= 1e-12 * g.y.abs()) {
        return Err(HomogeniseError::InvalidParameter {
            name: "gravity",
            reason: format!(
                "a column profile needs gravity along −y, got ({}, {})",
                g.x, g.y
            ),
        });
    }
    let grains = grain_stresses(snapshot)?; // validates the snapshot
    let (wl, wr) = (
        find_wall(snapshot, &spec.left)?,
        find_wall(snapshot, &spec.right)?,
    );
    let (x0, x1, y0, y1) = grain_extent(snapshot)
        .ok_or_else(|| HomogeniseError::EmptyRegion("the column has no grains".into()))?;
    let (xl, xr) = match (&wl.geometry, &wr.geometry) {
        (WallGeometry::Line { point: pl, .. }, WallGeometry::Line { point: pr, .. }) => {
            (pl.x.min(pr.x), pl.x.max(pr.x))
        }
        _ => (x0, x1),
    };
    let width = xr - xl;
    positive("width", width)?;
    let axis = DepthAxis::new(Vector::new(0.0, -1.0), Vector::new(0.0, y1))?;
    let height = y1 - y0;
    let count = ((height / spec.bin_width).ceil() as usize).max(1);
    let bins = DepthBins::new(axis, spec.bin_width, count)?;

    let depth: Vec<f64> = (0..count)
        .map(|k| (k as f64 + 0.5) * spec.bin_width)
        .collect();
    let levels: Vec<f64> = (0..count * PLANES_PER_BIN)
        .map(|i| y1 - (i as f64 + 0.5) * spec.bin_width / PLANES_PER_BIN as f64)
        .collect();
    let planes = plane_stress_profile(snapshot, &levels, Some(width))?;
    let sigma_v = planes
        .chunks(PLANES_PER_BIN)
        .map(|c| -c.iter().map(|p| p.sigma_yy).sum::<f64>() / PLANES_PER_BIN as f64)
        .collect();
    let mut sigma_v_mean = Vec::with_capacity(count);
    let mut solid = Vec::with_capacity(count);
    for k in 0..count {
        let (d0, d1) = bins.bounds(k);
        let region = Region::Rectangle {
            min: Vector::new(xl, y1 - d1),
            max: Vector::new(xr, y1 - d0),
        };
        let m = mean_stress(snapshot, &grains, &region)?;
        sigma_v_mean.push(-m.total[(1, 1)]);
        solid.push(m.grain_area / m.area);
    }
    let left = wall_stress_profile(snapshot, &spec.left, &bins)?;
    let right = wall_stress_profile(snapshot, &spec.right, &bins)?;
    let sigma_h = left
        .iter()
        .zip(&right)
        .map(|(a, b)| -0.5 * (a.normal_stress + b.normal_stress))
        .collect();
    let tau_w = left
        .iter()
        .zip(&right)
        .map(|(a, b)| 0.5 * (a.shear_stress + b.shear_stress))
        .collect();
    let wall_fraction_at_limit = fraction_at_limit_by_depth(
        snapshot,
        &ContactClass::WallsNamed(vec![spec.left.clone(), spec.right.clone()]),
        &bins,
        COULOMB_LIMIT,
    )?;
    let bulk_fraction_at_limit =
        fraction_at_limit_by_depth(snapshot, &ContactClass::Bulk, &bins, COULOMB_LIMIT)?;

    let gbodies: Vec<_> = snapshot
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .collect();
    let gn = g.norm();
    let weight: f64 = gbodies.iter().map(|b| b.mass * gn).sum();
    let thickness = gbodies.iter().map(|b| b.thickness).sum::<f64>() / gbodies.len() as f64;
    let rho = gbodies.iter().map(|b| b.mass).sum::<f64>()
        / gbodies.iter().map(|b| b.volume()).sum::<f64>();
    let whole = Region::Rectangle {
        min: Vector::new(xl, y0),
        max: Vector::new(xr, y1),
    };
    let column_solid_fraction = crate::state::solid_fraction(snapshot, &whole)?;
    let bottom = plane_stress_profile(snapshot, &[y0], Some(width))?[0];
    let bottom_load = bottom.force.y * thickness;
    let side = -(wl.force.y + wr.force.y);
    Ok(ColumnProfile {
        width,
        surface_y: y1,
        depth,
        sigma_v,
        sigma_v_mean,
        sigma_h,
        tau_w,
        wall_fraction_at_limit,
        bulk_fraction_at_limit,
        solid_fraction: solid,
        column_solid_fraction,
        bulk_density: column_solid_fraction * rho,
        weight,
        bottom_load_over_weight: bottom_load / weight,
        side_wall_load_over_weight: side / weight,
    })
}
