//! The critical state and a stress–dilatancy relation of a granular material in plane strain
//! (2D), compressive-positive stresses.
//!
//! With `p = (σ₁ + σ₃)/2` and `q = (σ₁ − σ₃)/2` (the centre and radius of the in-plane Mohr
//! circle), the mobilised friction angle is `sin φ_mob = q/p`. Strain rates are compression
//! positive: `ε̇_v = ε̇₁ + ε̇₃`, `ε̇_γ = ε̇₁ − ε̇₃`, and the 2D dilatancy angle is
//! `sin ψ = −ε̇_v/ε̇_γ` (positive when the material dilates).
//!
//! - **Critical state** (Roscoe, Schofield & Wroth 1958; in 2D DEM, e.g. Radjai & Dubois
//!   2011): steady shear at constant volume, `q = p sin φ_c`, solid fraction `φ_c`, whatever
//!   the pressure for rigid grains.
//! - **Stress–dilatancy**: `sin φ_mob = sin φ_cv + β sin ψ`. Taylor's energy balance (Taylor
//!   1948) in plane strain, plastic work `p ε̇_v + q ε̇_γ = sin φ_cv · p ε̇_γ`, gives `β = 1`;
//!   Rowe's relation (Rowe 1962; plane strain, De Josselin de Jong 1976),
//!   `sin φ_mob = (sin φ_cv + sin ψ)/(1 + sin φ_cv sin ψ)`, is close to it for small `ψ`
//!   (slope `1 − sin² φ_cv` at `ψ = 0`). `β` is fitted.

use serde::{Deserialize, Serialize};

/// The critical state: `q = p sin φ_c`, `φ = φ_c`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CriticalStateLaw {
    /// Critical-state friction angle `φ_c` (rad).
    pub friction_angle_rad: f64,
    /// Critical solid fraction `φ_c` (1).
    pub solid_fraction: f64,
}

impl CriticalStateLaw {
    /// Deviator at the critical state `q = p sin φ_c` (Pa) at the mean stress `p` (Pa).
    pub fn q(&self, p: f64) -> f64 {
        p * self.friction_angle_rad.sin()
    }
}

/// The stress–dilatancy relation `sin φ_mob = sin φ_cv + β sin ψ`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StressDilatancyLaw {
    /// `sin φ_cv`, the mobilised friction at zero dilatancy (1).
    pub sin_phi_c: f64,
    /// Slope `β` (1; Taylor: 1).
    pub beta: f64,
}

impl StressDilatancyLaw {
    /// `sin φ_mob` at the dilatancy `sin ψ`.
    pub fn sin_phi(&self, sin_psi: f64) -> f64 {
        self.sin_phi_c + self.beta * sin_psi
    }
}
