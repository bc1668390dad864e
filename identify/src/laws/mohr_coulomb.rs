//! Mohr–Coulomb yield and its 2D Drucker–Prager equivalent.
//!
//! Compressive-positive stresses (Pa). On a plane with normal stress `σ` the shear strength is
//! `τ = c + σ tan φ` (`φ` friction angle, rad; `c ≥ 0` cohesion, Pa). For an in-plane stress
//! state with mean stress `p = (σ₁ + σ₃)/2` and radius `q = (σ₁ − σ₃)/2` of its Mohr circle,
//! tangency to the envelope gives the yield condition `q = p sin φ + c cos φ`.
//!
//! In 2D the in-plane deviator norm is `√(½ s:s) = q`, so the 2D Drucker–Prager criterion
//! `√J₂ ≤ α p + k` coincides with Mohr–Coulomb for `α = sin φ`, `k = c cos φ` (exact).
//! For a 3D continuum solver in plane strain, the usual match is
//! `√J₂ ≤ α I₁ + k` with `I₁ = σ₁ + σ₂ + σ₃`, `α = tan φ / √(9 + 12 tan² φ)`,
//! `k = 3 c / √(9 + 12 tan² φ)`.

use serde::{Deserialize, Serialize};

/// `τ = c + σ tan φ`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MohrCoulombLaw {
    /// Friction angle `φ` (rad).
    pub friction_angle_rad: f64,
    /// Cohesion `c` (Pa).
    pub cohesion_pa: f64,
}

/// Drucker–Prager `√J₂ ≤ α P + k` (meaning of `P` given by the constructor used).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DruckerPrager {
    /// Pressure coefficient `α` (1).
    pub alpha: f64,
    /// Cohesive term `k` (Pa).
    pub k_pa: f64,
}

impl MohrCoulombLaw {
    /// Shear strength on a plane of normal stress `σ` (Pa): `c + σ tan φ`.
    pub fn shear_strength(&self, sigma_n: f64) -> f64 {
        self.cohesion_pa + sigma_n * self.friction_angle_rad.tan()
    }

    /// Radius of the Mohr circle at yield for mean stress `p` (Pa): `p sin φ + c cos φ`.
    pub fn yield_q(&self, p: f64) -> f64 {
        p * self.friction_angle_rad.sin() + self.cohesion_pa * self.friction_angle_rad.cos()
    }

    /// Yield function of a 2D tension-positive stress tensor `(σ_xx, σ_yy, σ_xy)` (Pa):
    /// `F = q − p sin φ − c cos φ` with `p = −(σ_xx + σ_yy)/2`,
    /// `q = √(((σ_xx − σ_yy)/2)² + σ_xy²)`; `F ≤ 0` admissible, `F = 0` at yield.
    pub fn yield_function(&self, sxx: f64, syy: f64, sxy: f64) -> f64 {
        let (p, q) = p_q_from_tension_positive(sxx, syy, sxy);
        q - self.yield_q(p)
    }

    /// 2D Drucker–Prager with `P = p` (in-plane mean stress): `α = sin φ`, `k = c cos φ`.
    pub fn drucker_prager_2d(&self) -> DruckerPrager {
        DruckerPrager {
            alpha: self.friction_angle_rad.sin(),
            k_pa: self.cohesion_pa * self.friction_angle_rad.cos(),
        }
    }

    /// 3D plane-strain match with `P = I₁`: `α = tan φ/√(9 + 12 tan²φ)`,
    /// `k = 3c/√(9 + 12 tan²φ)`.
    pub fn drucker_prager_plane_strain(&self) -> DruckerPrager {
        let t = self.friction_angle_rad.tan();
        let s = (9.0 + 12.0 * t * t).sqrt();
        DruckerPrager {
            alpha: t / s,
            k_pa: 3.0 * self.cohesion_pa / s,
        }
    }
}

/// `(p, q)` of a 2D tension-positive stress: `p = −(σ_xx + σ_yy)/2` (compressive positive),
/// `q = √(((σ_xx − σ_yy)/2)² + σ_xy²)`.
pub fn p_q_from_tension_positive(sxx: f64, syy: f64, sxy: f64) -> (f64, f64) {
    let p = -0.5 * (sxx + syy);
    let q = (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt();
    (p, q)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mohr_circle_tangent_to_envelope_at_yield() {
        let law = MohrCoulombLaw {
            friction_angle_rad: 30f64.to_radians(),
            cohesion_pa: 200.0,
        };
        let p = 5000.0;
        let q = law.yield_q(p);
        // Closest approach of the envelope τ = c + σ tanφ to the circle centre equals q.
        let (s, c) = (law.friction_angle_rad.sin(), law.friction_angle_rad.cos());
        let distance = (law.cohesion_pa + p * s / c) * c;
        assert!((distance - q).abs() < 1e-9);
        // A tensor rotated by any angle with these p, q sits on the yield surface.
        let a: f64 = 0.3;
        let (s1, s3) = (-(p + q), -(p - q));
        let sxx = s1 * a.cos().powi(2) + s3 * a.sin().powi(2);
        let syy = s1 * a.sin().powi(2) + s3 * a.cos().powi(2);
        let sxy = (s1 - s3) * a.sin() * a.cos();
        assert!(law.yield_function(sxx, syy, sxy).abs() < 1e-9);
        let dp = law.drucker_prager_2d();
        assert!((dp.alpha * p + dp.k_pa - q).abs() < 1e-9);
    }
}
