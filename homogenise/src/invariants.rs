//! Scalar measures of a plane stress state and the inertial number.
//!
//! - pressure `P = −tr Σ / 2` (Pa, positive in compression);
//! - deviator `s = Σ + P 𝟙`;
//! - shear stress `τ = √(s : s / 2) = √(((Σ_xx − Σ_yy)/2)² + ((Σ_xy + Σ_yx)/2)²)` (Pa), the
//!   radius of Mohr's circle of the symmetric part;
//! - stress ratio (macroscopic friction) `μ = τ / P`;
//! - inertial number `I = γ̇ d / √(P/ρ)`.

use serde::{Deserialize, Serialize};

use crate::error::{positive, HomogeniseError, Result};
use crate::tensor::{deviator, symmetric_part};
use dem::math::Tensor;

/// Invariants of a plane stress tensor (tension positive).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StressInvariants {
    /// Pressure `P = −tr Σ / 2` (Pa), positive in compression.
    pub pressure: f64,
    /// Deviatoric part `s = Σ + P 𝟙` (Pa).
    pub deviator: Tensor,
    /// Shear stress `τ = √(s_sym : s_sym / 2)` of the symmetric deviator (Pa).
    pub shear_stress: f64,
    /// Stress ratio `μ = τ / P`; `None` when `P ≤ 0` (no compressive pressure).
    pub friction: Option<f64>,
}

/// Pressure, deviator, shear stress and stress ratio of `sigma` (Pa, tension positive).
pub fn stress_invariants(sigma: &Tensor) -> StressInvariants {
    let pressure = -sigma.trace() / 2.0;
    let dev = deviator(sigma);
    let s = symmetric_part(&dev);
    let shear_stress = (s.component_mul(&s).sum() / 2.0).sqrt();
    StressInvariants {
        pressure,
        deviator: dev,
        shear_stress,
        friction: (pressure > 0.0).then(|| shear_stress / pressure),
    }
}

/// Inertial number `I = γ̇ d / √(P/ρ)` for a shear rate `γ̇ ≥ 0` (1/s), grain diameter `d` (m),
/// pressure `P > 0` (Pa) and grain density `ρ` (kg/m³).
pub fn inertial_number(shear_rate: f64, diameter: f64, pressure: f64, density: f64) -> Result<f64> {
    if !(shear_rate.is_finite() && shear_rate >= 0.0) {
        return Err(HomogeniseError::InvalidParameter {
            name: "shear_rate",
            reason: format!("must be finite and ≥ 0, got {shear_rate}"),
        });
    }
    positive("diameter", diameter)?;
    positive("pressure", pressure)?;
    positive("density", density)?;
    Ok(shear_rate * diameter / (pressure / density).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invariants_of_a_known_state() {
        // principal stresses −3 and −1 kPa rotated by 30°: P = 2 kPa, τ = 1 kPa, μ = 0.5
        let a: f64 = 30f64.to_radians();
        let (c, s) = (a.cos(), a.sin());
        let q = Tensor::new(c, -s, s, c);
        let sigma = q * Tensor::new(-3000.0, 0.0, 0.0, -1000.0) * q.transpose();
        let inv = stress_invariants(&sigma);
        assert!((inv.pressure - 2000.0).abs() < 1e-9);
        assert!((inv.shear_stress - 1000.0).abs() < 1e-9);
        assert!((inv.friction.unwrap() - 0.5).abs() < 1e-12);
        assert!(inv.deviator.trace().abs() < 1e-9);
        // simple shear stress state: τ = |σ_xy|
        let inv = stress_invariants(&Tensor::new(-100.0, 35.0, 35.0, -100.0));
        assert!((inv.shear_stress - 35.0).abs() < 1e-12);
        assert!(stress_invariants(&Tensor::new(5.0, 0.0, 0.0, 5.0))
            .friction
            .is_none());
    }

    #[test]
    fn inertial_number_formula() {
        // γ̇ = 10 /s, d = 2 mm, P = 100 Pa, ρ = 2500 kg/m³: I = 0.02 / 0.2 = 0.1
        let i = inertial_number(10.0, 2e-3, 100.0, 2500.0).unwrap();
        assert!((i - 0.1).abs() < 1e-14);
        assert!(inertial_number(1.0, 1e-3, 0.0, 2500.0).is_err());
        assert!(inertial_number(f64::NAN, 1e-3, 1.0, 2500.0).is_err());
    }
}
