//! μ(I) and φ(I) rheology (GDR MiDi; Jop, Forterre & Pouliquen).
//!
//! Inertial number `I = γ̇ d / √(P/ρ_s)` (1), `ρ_s` the grain material density.
//! - `μ(I) = μ_s + (μ₂ − μ_s) / (1 + I₀/I)` with `0 < μ_s < μ₂`, `I₀ > 0`;
//! - linear form `μ(I) = μ_s + b I`;
//! - `φ(I) = φ_max − (φ_max − φ_min) I` (φ_min is the extrapolated value at `I = 1`);
//! - linear form `φ(I) = φ_max − a I` (the same line, claiming nothing at `I = 1`).

use serde::{Deserialize, Serialize};

/// `μ(I) = μ_s + (μ₂ − μ_s)/(1 + I₀/I)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MuILaw {
    /// Static friction `μ_s = μ(0)` (1).
    pub mu_s: f64,
    /// Limiting friction `μ₂ = μ(∞)` (1).
    pub mu_2: f64,
    /// Inertial-number scale `I₀` (1).
    pub i0: f64,
}

impl MuILaw {
    /// `μ(I)`; `μ_s` at `I = 0`.
    pub fn mu(&self, i: f64) -> f64 {
        if i <= 0.0 {
            return self.mu_s;
        }
        self.mu_s + (self.mu_2 - self.mu_s) * i / (i + self.i0)
    }

    /// Inverse: the `I` with `μ(I) = μ`, `I = I₀ (μ − μ_s)/(μ₂ − μ)`; `None` unless
    /// `μ_s < μ < μ₂` (no steady flow otherwise).
    pub fn inertial_number_for(&self, mu: f64) -> Option<f64> {
        (mu > self.mu_s && mu < self.mu_2).then(|| self.i0 * (mu - self.mu_s) / (self.mu_2 - mu))
    }

    /// `∂μ/∂(μ_s, Δμ, I₀)` with `Δμ = μ₂ − μ_s`: `(1, I/(I+I₀), −Δμ I/(I+I₀)²)`.
    pub fn gradient_delta_form(&self, i: f64) -> [f64; 3] {
        let d = self.mu_2 - self.mu_s;
        let s = i + self.i0;
        [1.0, i / s, -d * i / (s * s)]
    }
}

/// `μ(I) = μ_s + b I`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LinearMuILaw {
    /// Intercept `μ_s` (1).
    pub mu_s: f64,
    /// Slope `b = dμ/dI` (1).
    pub slope: f64,
}

impl LinearMuILaw {
    /// `μ(I) = μ_s + b I`.
    pub fn mu(&self, i: f64) -> f64 {
        self.mu_s + self.slope * i
    }

    /// Inverse: the `I` with `μ(I) = μ`, `I = (μ − μ_s)/b`; `None` unless `μ > μ_s` and
    /// `b > 0` (no steady flow otherwise).
    pub fn inertial_number_for(&self, mu: f64) -> Option<f64> {
        (mu > self.mu_s && self.slope > 0.0).then(|| (mu - self.mu_s) / self.slope)
    }
}

/// `φ(I) = φ_max − a I`, the dilatancy of dense granular flow (da Cruz, Emam, Prochnow, Roux &
/// Chevoir, Phys. Rev. E 72, 021309, 2005; GDR MiDi, Eur. Phys. J. E 14, 2004), valid over the
/// `I` it was calibrated on. (It was also written `φ_max − (φ_max − φ_min) I`, naming
/// `φ_min = φ(1)` an extrapolation far beyond any dense flow; grainlaw keeps the slope.)
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PhiILaw {
    /// Solid fraction at `I = 0` (1).
    pub phi_max: f64,
    /// Dilatancy slope `a = −dφ/dI` (1).
    pub slope: f64,
}

impl PhiILaw {
    /// `φ(I) = φ_max − a I`.
    pub fn phi(&self, i: f64) -> f64 {
        self.phi_max - self.slope * i
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mu_i_limits_and_inverse() {
        let law = MuILaw {
            mu_s: 0.38,
            mu_2: 0.64,
            i0: 0.279,
        };
        assert!((law.mu(law.i0) - 0.51).abs() < 1e-15);
        assert!((law.mu(1e9) - 0.64).abs() < 1e-9);
        let i = law.inertial_number_for(0.5).unwrap();
        assert!((law.mu(i) - 0.5).abs() < 1e-15);
        assert!(law.inertial_number_for(0.3).is_none());
        assert!(law.inertial_number_for(0.7).is_none());
        let lin = LinearMuILaw {
            mu_s: 0.29,
            slope: 0.94,
        };
        let i = lin.inertial_number_for(0.4877).unwrap();
        assert!((lin.mu(i) - 0.4877).abs() < 1e-15);
        assert!(lin.inertial_number_for(0.2).is_none());
    }
}
