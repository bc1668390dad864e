//! Per-grain ratio of the inertia term to the contact term of the mean stress (the paper's
//! Fig. 4 field): `χ_p = ‖Σ_i‖_F / ‖Σ_c‖_F`. Large in fluid-like (collisional, rotating) zones,
//! small in solid-like (enduring-contact) zones of a flow.

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

use crate::error::{HomogeniseError, Result};
use crate::stress::GrainStress;
use crate::tensor::frobenius;

/// The inertia-to-contact ratio of one grain.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InertiaRatio {
    /// Index of the grain in `Snapshot::bodies`.
    pub body: usize,
    /// Centre of the grain (m), for maps.
    pub position: Vector2<f64>,
    /// `‖Σ_i‖_F / ‖Σ_c‖_F`; `None` when the grain carries no contact force (`‖Σ_c‖_F = 0`:
    /// free flight, counted as fluid-like).
    pub ratio: Option<f64>,
}

/// The ratio `‖Σ_i‖_F / ‖Σ_c‖_F` of every grain stress given.
pub fn inertia_ratios(grains: &[GrainStress]) -> Vec<InertiaRatio> {
    grains
        .iter()
        .map(|g| {
            let c = frobenius(&g.contact);
            InertiaRatio {
                body: g.body,
                position: g.position,
                ratio: (c > 0.0).then(|| frobenius(&g.inertia) / c),
            }
        })
        .collect()
}

/// Share of grains that are fluid-like: ratio above `threshold`, or no contact force.
/// Fails on a negative or non-finite threshold; 0 for an empty list.
pub fn fluid_fraction(ratios: &[InertiaRatio], threshold: f64) -> Result<f64> {
    if !(threshold.is_finite() && threshold >= 0.0) {
        return Err(HomogeniseError::InvalidParameter {
            name: "threshold",
            reason: format!("must be finite and ≥ 0, got {threshold}"),
        });
    }
    if ratios.is_empty() {
        return Ok(0.0);
    }
    let fluid = ratios
        .iter()
        .filter(|r| r.ratio.is_none_or(|x| x > threshold))
        .count();
    Ok(fluid as f64 / ratios.len() as f64)
}
