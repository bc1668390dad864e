//! Janssen's law for a 2D column of width `W` between two vertical walls.
//!
//! Depth `z` (m) is measured down from the free surface, `ρ_b = φ ρ` is the bulk density
//! (kg/m³), `K = σ_h/σ_v` the stress ratio, `μ_w = τ_w/σ_h` the mobilised wall friction.
//! The slice balance `dσ_v/dz = ρ_b g − (2 K μ_w / W) σ_v`, `σ_v(0) = 0` gives
//!
//! `σ_v(z) = ρ_b g λ (1 − exp(−z/λ))`, `λ = W / (2 K μ_w)` (saturation length),
//!
//! `σ_h = K σ_v`, `τ_w = μ_w σ_h`. Stresses are compressive-positive magnitudes (Pa).

use serde::{Deserialize, Serialize};

/// Default gravity (m/s²) when none is given.
pub const STANDARD_GRAVITY: f64 = 9.81;

/// `f(a, z) = (1 − e^{−a z}) / a` and `∂f/∂a = (z e^{−a z} − f) / a`, with `a = 2Kμ_w/W`
/// (1/m). Series for `a z < 10⁻³` (exact limit `f → z`, `∂f/∂a → −z²/2` at `a = 0`).
pub fn janssen_shape(a: f64, z: f64) -> (f64, f64) {
    let x = a * z;
    if x.abs() < 1e-3 {
        let f = z * (1.0 - x / 2.0 + x * x / 6.0 - x.powi(3) / 24.0 + x.powi(4) / 120.0);
        let df = z * z * (-0.5 + x / 3.0 - x * x / 8.0 + x.powi(3) / 30.0 - x.powi(4) / 144.0);
        (f, df)
    } else {
        let f = -(-x).exp_m1() / a;
        let df = (z * (-x).exp() - f) / a;
        (f, df)
    }
}

/// Janssen's law with its two parameters `K`, `μ_w` and the column's constants.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JanssenLaw {
    /// Stress ratio `K = σ_h/σ_v` (1).
    pub k: f64,
    /// Mobilised wall friction `μ_w = τ_w/σ_h` (1).
    pub mu_w: f64,
    /// Column width `W` (m).
    pub width_m: f64,
    /// Bulk density `ρ_b` (kg/m³).
    pub bulk_density_kg_m3: f64,
    /// Gravity `g` (m/s²).
    pub gravity_m_s2: f64,
}

impl JanssenLaw {
    /// The `σ_v` part, which depends on `K μ_w` only.
    pub fn vertical(&self) -> JanssenVerticalLaw {
        JanssenVerticalLaw {
            k_mu_w: self.k * self.mu_w,
            width_m: self.width_m,
            bulk_density_kg_m3: self.bulk_density_kg_m3,
            gravity_m_s2: self.gravity_m_s2,
        }
    }

    /// Saturation length `λ = W/(2 K μ_w)` (m).
    pub fn saturation_length(&self) -> f64 {
        self.vertical().saturation_length()
    }

    /// Vertical stress `σ_v(z) = ρ_b g λ (1 − e^{−z/λ})` (Pa).
    pub fn sigma_v(&self, z: f64) -> f64 {
        self.vertical().sigma_v(z)
    }

    /// Wall normal stress `σ_h = K σ_v` (Pa).
    pub fn sigma_h(&self, z: f64) -> f64 {
        self.k * self.sigma_v(z)
    }

    /// Wall shear stress `τ_w = μ_w K σ_v` (Pa).
    pub fn tau_w(&self, z: f64) -> f64 {
        self.mu_w * self.sigma_h(z)
    }

    /// Hydrostatic comparison line `ρ_b g z` (Pa): the vertical stress without wall friction.
    pub fn hydrostatic(&self, z: f64) -> f64 {
        self.bulk_density_kg_m3 * self.gravity_m_s2 * z
    }
}

/// The vertical-stress part of Janssen's law, parametrised by `K μ_w` alone.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JanssenVerticalLaw {
    /// `K μ_w` (1).
    pub k_mu_w: f64,
    /// Column width `W` (m).
    pub width_m: f64,
    /// Bulk density `ρ_b` (kg/m³).
    pub bulk_density_kg_m3: f64,
    /// Gravity `g` (m/s²).
    pub gravity_m_s2: f64,
}

impl JanssenVerticalLaw {
    /// Decay rate `a = 2 K μ_w / W` (1/m).
    pub fn decay_rate(&self) -> f64 {
        2.0 * self.k_mu_w / self.width_m
    }

    /// Saturation length `λ = W/(2 K μ_w)` (m).
    pub fn saturation_length(&self) -> f64 {
        self.width_m / (2.0 * self.k_mu_w)
    }

    /// `σ_v(z) = ρ_b g (1 − e^{−a z})/a` (Pa), `a = 2Kμ_w/W`; hydrostatic as `a → 0`.
    pub fn sigma_v(&self, z: f64) -> f64 {
        self.bulk_density_kg_m3 * self.gravity_m_s2 * janssen_shape(self.decay_rate(), z).0
    }

    /// Saturated vertical stress `ρ_b g λ` (Pa), reached for `z ≫ λ`.
    pub fn saturation_stress(&self) -> f64 {
        self.bulk_density_kg_m3 * self.gravity_m_s2 * self.saturation_length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_series_and_closed_form_agree_at_the_switch() {
        let z = 0.7;
        for a in [0.999e-3 / z, 1.001e-3 / z] {
            let (f, df) = janssen_shape(a, z);
            // Reference by direct formula in high-accuracy form.
            let x = a * z;
            let f_ref = -(-x).exp_m1() / a;
            let df_ref = (z * (-x).exp() - f_ref) / a;
            assert!((f - f_ref).abs() < 1e-14 * f_ref);
            assert!((df - df_ref).abs() < 1e-9 * df_ref.abs());
        }
        assert_eq!(janssen_shape(0.0, 2.0), (2.0, -2.0));
    }

    #[test]
    fn saturates_at_rho_g_lambda_and_starts_hydrostatic() {
        let law = JanssenLaw {
            k: 0.5,
            mu_w: 0.3,
            width_m: 0.03,
            bulk_density_kg_m3: 1600.0,
            gravity_m_s2: 9.81,
        };
        let lambda = law.saturation_length();
        assert!((lambda - 0.1).abs() < 1e-15);
        let sat = 1600.0 * 9.81 * lambda;
        assert!((law.sigma_v(50.0 * lambda) - sat).abs() < 1e-12 * sat);
        // Small depth: σ_v ≈ ρ g z (1 − z/(2λ)).
        let z = 1e-4;
        let approx = law.hydrostatic(z) * (1.0 - z / (2.0 * lambda));
        assert!((law.sigma_v(z) - approx).abs() < 1e-6 * approx);
        assert!((law.tau_w(0.05) - 0.15 * law.sigma_v(0.05)).abs() < 1e-12);
    }
}
