//! Per-grain ratio of the inertia term to the contact term of the mean stress (the paper's
//! Fig. 4 field): `χ_p = ‖Σ_i‖_F / ‖Σ_c‖_F`. Large in fluid-like (collisional, rotating) zones,
//! small in solid-like (enduring-contact) zones of a flow.

use dem::math::Vector;
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
    pub position: Vector,
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

#[cfg(test)]
mod tests {
    use super::*;
    use dem::math::Tensor;

    fn grain(body: usize, contact: Tensor, inertia: Tensor) -> GrainStress {
        GrainStress {
            body,
            position: Vector::zeros(),
            radius: 1e-3,
            volume: 1e-6,
            thickness: 1.0,
            contact,
            inertia,
            total: contact + inertia,
        }
    }

    #[test]
    fn ratio_and_fluid_share() {
        let c = Tensor::new(-3.0, 0.0, 0.0, -4.0); // ‖·‖ = 5
        let i = Tensor::new(1.0, -1.0, 1.0, 1.0); // ‖·‖ = 2
        let g = [
            grain(0, c, i),
            grain(1, c, i * 5.0),
            grain(2, Tensor::zeros(), i),
            grain(3, c, Tensor::zeros()),
        ];
        let r = inertia_ratios(&g);
        assert!((r[0].ratio.unwrap() - 0.4).abs() < 1e-15);
        assert!((r[1].ratio.unwrap() - 2.0).abs() < 1e-15);
        assert_eq!(r[2].ratio, None);
        assert_eq!(r[3].ratio, Some(0.0));
        // above 1: grain 1, and grain 2 (no contact force) → 2 of 4
        assert!((fluid_fraction(&r, 1.0).unwrap() - 0.5).abs() < 1e-15);
        assert!((fluid_fraction(&r, 0.1).unwrap() - 0.75).abs() < 1e-15);
        assert!(fluid_fraction(&r, -1.0).is_err());
    }
}
