//! Profiles of a plane shear flow across horizontal slices (inclined flow along x with the bed
//! normal along y, or a shear cell with walls along x): the inputs of μ(I) and φ(I).
//!
//! For each slice `[y_k, y_{k+1}]` (grains weighted by their area fraction in it):
//! - mean velocity `u_k = Σ w m v / Σ w m` (m/s) and solid fraction φ;
//! - mean stress Σ (with inertia, Pa), pressure `P = −tr Σ / 2`, shear stress `τ` (the invariant
//!   of [`crate::invariants`]), stress ratios `μ = τ / P` and `μ_xy = |Σ_xy| / P`;
//! - shear rate `γ̇ = |du_x/dy|` by central differences of the slices' mean velocities over
//!   their grains' mean heights `ȳ_k` (exact for a linear profile; one-sided at the ends;
//!   `None` where a neighbour slice is empty);
//! - inertial number `I = γ̇ d / √(P/ρ)` with the given grain diameter and density;
//! - fluid-like share of grains (inertia ratio above a threshold, [`crate::inertia_ratio`]).
//!
//! The slices span the sample's width (the periodic cell when x is periodic).

use dem::math::{Tensor, Vector};
use dem::snapshot::{BodyKind, Snapshot};
use serde::{Deserialize, Serialize};

use crate::error::{positive, HomogeniseError, Result};
use crate::inertia_ratio::inertia_ratios;
use crate::invariants::{inertial_number, stress_invariants};
use crate::region::Region;
use crate::stress::{mean_stress, GrainStress};

/// Grain scale of the flow, for the inertial number.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GrainScale {
    /// Grain diameter `d` (m).
    pub diameter: f64,
    /// Grain density `ρ` (kg/m³).
    pub density: f64,
}

/// One slice of a flow profile.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FlowSlice {
    /// Lower edge (m).
    pub y_min: f64,
    /// Upper edge (m).
    pub y_max: f64,
    /// Weighted number of grains.
    pub grains: f64,
    /// Mass-weighted mean velocity (m/s); zero in an empty slice.
    pub velocity: Vector,
    /// Mass-weighted mean height of the grains' centres `ȳ` (m); the middle if empty.
    pub mean_y: f64,
    /// Solid fraction.
    pub solid_fraction: f64,
    /// Mean stress with inertia (Pa).
    pub stress: Tensor,
    /// Pressure `P` (Pa).
    pub pressure: f64,
    /// Shear stress `τ` (Pa).
    pub shear_stress: f64,
    /// `τ / P` (`None` when `P ≤ 0`).
    pub stress_ratio: Option<f64>,
    /// `|Σ_xy| / P` (`None` when `P ≤ 0`).
    pub stress_ratio_xy: Option<f64>,
    /// `du_x/dy` (1/s).
    pub velocity_gradient: Option<f64>,
    /// `γ̇ = |du_x/dy|` (1/s).
    pub shear_rate: Option<f64>,
    /// Inertial number (`None` without shear rate or with `P ≤ 0`).
    pub inertial_number: Option<f64>,
    /// Share of grains (by weight) whose inertia ratio exceeds the threshold or that carry no
    /// contact force; `None` in an empty slice.
    pub fluid_fraction: Option<f64>,
}

impl FlowSlice {
    /// Middle of the slice (m).
    pub fn y(&self) -> f64 {
        0.5 * (self.y_min + self.y_max)
    }
}

/// Flow profile over the slices between consecutive `y_edges` (m, increasing); see the module
/// documentation. `fluid_threshold` is the inertia-ratio threshold of the fluid-like share.
pub fn flow_profile(
    snapshot: &Snapshot,
    grains: &[GrainStress],
    y_edges: &[f64],
    scale: &GrainScale,
    fluid_threshold: f64,
) -> Result<Vec<FlowSlice>> {
    positive("diameter", scale.diameter)?;
    positive("density", scale.density)?;
    if !(fluid_threshold.is_finite() && fluid_threshold >= 0.0) {
        return Err(HomogeniseError::InvalidParameter {
            name: "fluid_threshold",
            reason: format!("must be finite and ≥ 0, got {fluid_threshold}"),
        });
    }
    let increasing = y_edges.windows(2).all(|w| w[1] > w[0]);
    if y_edges.len() < 2 || !increasing || y_edges.iter().any(|y| !y.is_finite()) {
        return Err(HomogeniseError::InvalidParameter {
            name: "y_edges",
            reason: "needs at least two finite, strictly increasing edges".into(),
        });
    }
    let ratios = inertia_ratios(grains);
    let mut slices = Vec::with_capacity(y_edges.len() - 1);
    for w in y_edges.windows(2) {
        let region = Region::Slice {
            y_min: w[0],
            y_max: w[1],
        };
        let rect = region.resolve(snapshot)?;
        let ms = mean_stress(snapshot, grains, &region)?;
        let (mut mv, mut my, mut m) = (Vector::zeros(), 0.0, 0.0);
        for b in snapshot.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
            let f = rect.disk_fraction(&b.position, b.radius);
            mv += b.velocity * (f * b.mass);
            my += b.position.y * (f * b.mass);
            m += f * b.mass;
        }
        let (mut fluid, mut total) = (0.0, 0.0);
        for (r, g) in ratios.iter().zip(grains) {
            let f = rect.disk_fraction(&g.position, g.radius);
            total += f;
            if r.ratio.is_none_or(|x| x > fluid_threshold) {
                fluid += f;
            }
        }
        let inv = stress_invariants(&ms.total);
        let p = inv.pressure;
        slices.push(FlowSlice {
            y_min: w[0],
            y_max: w[1],
            grains: ms.grains,
            velocity: if m > 0.0 { mv / m } else { Vector::zeros() },
            mean_y: if m > 0.0 { my / m } else { 0.5 * (w[0] + w[1]) },
            solid_fraction: ms.grain_area / ms.area,
            stress: ms.total,
            pressure: p,
            shear_stress: inv.shear_stress,
            stress_ratio: inv.friction,
            stress_ratio_xy: (p > 0.0).then(|| ms.total[(0, 1)].abs() / p),
            velocity_gradient: None,
            shear_rate: None,
            inertial_number: None,
            fluid_fraction: (total > 0.0).then(|| fluid / total),
        });
    }
    let n = slices.len();
    let full: Vec<bool> = slices.iter().map(|s| s.grains > 0.0).collect();
    for k in 0..n {
        let (lo, hi) = (k.saturating_sub(1), (k + 1).min(n - 1));
        if lo == hi || !full[lo] || !full[hi] || !full[k] {
            continue;
        }
        let du = slices[hi].velocity.x - slices[lo].velocity.x;
        let dy = slices[hi].mean_y - slices[lo].mean_y;
        if dy.abs() <= f64::EPSILON * (slices[hi].mean_y.abs() + slices[lo].mean_y.abs()) {
            continue;
        }
        let grad = du / dy;
        let s = &mut slices[k];
        s.velocity_gradient = Some(grad);
        s.shear_rate = Some(grad.abs());
        s.inertial_number = (s.pressure > 0.0)
            .then(|| inertial_number(grad.abs(), scale.diameter, s.pressure, scale.density).ok())
            .flatten();
    }
    Ok(slices)
}
