//! Closing the loop: calibrated laws evaluated in their continuum setting.
//!
//! **Janssen column.** The slice balance of a 2D column of width `W` (two walls),
//! `dσ_v/dz = ρ_b g − (2 K μ_w / W) σ_v`, `σ_v(0) = 0`, `z` down from the free surface, is
//! integrated by classical RK4 ([`janssen_ode_rk4`]) and must match the closed form
//! `ρ_b g λ (1 − e^{−z/λ})`, `λ = W/(2Kμ_w)`.
//!
//! **Steady flow down a slope (Bagnold profile).** A layer of depth `H` on a rough base inclined
//! at `θ`, `z` measured up from the base. Momentum balance: `τ(z) = ρ_b g sin θ (H − z)`,
//! `P(z) = ρ_b g cos θ (H − z)` with `ρ_b = φ ρ_s`; so `μ = τ/P = tan θ` at every depth and
//! `μ(I) = tan θ` fixes a uniform `I = I₀ (tan θ − μ_s)/(μ₂ − tan θ)` (steady flow needs
//! `μ_s < tan θ < μ₂`); with `φ(I)` the solid fraction is uniform too. Then
//! `γ̇(z) = (I/d) √(P/ρ_s) = (I/d) √(φ g cos θ (H − z))` and, with no slip at the base,
//! `u(z) = (2/3) (I/d) √(φ g cos θ) (H^{3/2} − (H − z)^{3/2})`; surface velocity
//! `u(H) = (2/3)(I/d)√(φ g cos θ) H^{3/2}` and depth-averaged velocity `(3/5) u(H)`.

use serde::{Deserialize, Serialize};

use crate::error::{check_setup_positive, IdentifyError, Result};
use crate::laws::{JanssenVerticalLaw, MuILaw, PhiILaw};

/// `σ_v` on a uniform depth grid (data).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StressProfile {
    /// Depths (m).
    pub z_m: Vec<f64>,
    /// Vertical stress (Pa).
    pub sigma_v_pa: Vec<f64>,
}

/// Integrates `dσ_v/dz = ρ_b g − (2 K μ_w / W) σ_v`, `σ_v(0) = 0`, from `z = 0` to `depth_m`
/// in `steps` RK4 steps. Errors on a non-positive depth, zero steps or invalid law constants.
pub fn janssen_ode_rk4(
    law: &JanssenVerticalLaw,
    depth_m: f64,
    steps: usize,
) -> Result<StressProfile> {
    check_setup_positive("depth_m", depth_m)?;
    check_setup_positive("width_m", law.width_m)?;
    check_setup_positive("bulk_density_kg_m3", law.bulk_density_kg_m3)?;
    check_setup_positive("gravity_m_s2", law.gravity_m_s2)?;
    if !(law.k_mu_w.is_finite() && law.k_mu_w >= 0.0) {
        return Err(IdentifyError::InvalidSetup {
            field: "k_mu_w".into(),
            value: law.k_mu_w,
            expected: "a finite value ≥ 0".into(),
        });
    }
    if steps == 0 {
        return Err(IdentifyError::InvalidSetup {
            field: "steps".into(),
            value: 0.0,
            expected: "at least one step".into(),
        });
    }
    let rg = law.bulk_density_kg_m3 * law.gravity_m_s2;
    let a = law.decay_rate();
    let rhs = |s: f64| rg - a * s;
    let h = depth_m / steps as f64;
    let mut z = Vec::with_capacity(steps + 1);
    let mut sv = Vec::with_capacity(steps + 1);
    let mut s = 0.0;
    z.push(0.0);
    sv.push(0.0);
    for i in 0..steps {
        let k1 = rhs(s);
        let k2 = rhs(s + 0.5 * h * k1);
        let k3 = rhs(s + 0.5 * h * k2);
        let k4 = rhs(s + h * k3);
        s += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        z.push((i + 1) as f64 * h);
        sv.push(s);
    }
    Ok(StressProfile {
        z_m: z,
        sigma_v_pa: sv,
    })
}

/// Solid fraction of the flowing layer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SolidFraction {
    /// A given constant `φ`.
    Constant(f64),
    /// From a calibrated `φ(I)` at the flow's inertial number.
    Law(PhiILaw),
}

/// Steady uniform flow of a μ(I) material down a slope.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BagnoldFlow {
    /// Slope angle `θ` (rad).
    pub slope_rad: f64,
    /// Layer depth `H` (m).
    pub depth_m: f64,
    /// Grain diameter `d` (m).
    pub grain_diameter_m: f64,
    /// Solid fraction `φ` (1).
    pub solid_fraction: f64,
    /// Gravity `g` (m/s²).
    pub gravity_m_s2: f64,
    /// The uniform inertial number `I` with `μ(I) = tan θ` (1).
    pub inertial_number: f64,
}

impl BagnoldFlow {
    /// Sets up the flow. Errors: [`IdentifyError::NoSteadyFlow`] unless
    /// `μ_s < tan θ < μ₂`; [`IdentifyError::InvalidSetup`] for non-positive depth, diameter,
    /// gravity, or a solid fraction outside `(0, 1]`.
    pub fn new(
        mu_i: &MuILaw,
        phi: SolidFraction,
        slope_rad: f64,
        depth_m: f64,
        grain_diameter_m: f64,
        gravity_m_s2: f64,
    ) -> Result<Self> {
        check_slope(slope_rad)?;
        let tan = slope_rad.tan();
        let i = mu_i
            .inertial_number_for(tan)
            .ok_or_else(|| IdentifyError::NoSteadyFlow {
                reason: format!(
                    "tan θ = {tan:.4} is outside (μ_s, μ₂) = ({:.4}, {:.4}): the layer {}",
                    mu_i.mu_s,
                    mu_i.mu_2,
                    if tan <= mu_i.mu_s {
                        "stays at rest"
                    } else {
                        "accelerates"
                    }
                ),
            })?;
        let phi = match phi {
            SolidFraction::Constant(p) => p,
            SolidFraction::Law(l) => l.phi(i),
        };
        Self::with_inertial_number(i, phi, slope_rad, depth_m, grain_diameter_m, gravity_m_s2)
    }

    /// The flow of a given uniform inertial number `I` (the root of `μ(I) = tan θ` of any μ(I)
    /// law, e.g. the linear form's `(tan θ − μ_s)/b`) and solid fraction `φ`. Errors:
    /// [`IdentifyError::InvalidSetup`] for a non-positive `I`, depth, diameter, gravity, a
    /// slope outside `(0, π/2)` or a solid fraction outside `(0, 1]`.
    pub fn with_inertial_number(
        inertial_number: f64,
        phi: f64,
        slope_rad: f64,
        depth_m: f64,
        grain_diameter_m: f64,
        gravity_m_s2: f64,
    ) -> Result<Self> {
        check_setup_positive("inertial_number", inertial_number)?;
        check_setup_positive("depth_m", depth_m)?;
        check_setup_positive("grain_diameter_m", grain_diameter_m)?;
        check_setup_positive("gravity_m_s2", gravity_m_s2)?;
        check_slope(slope_rad)?;
        let i = inertial_number;
        if !(phi > 0.0 && phi <= 1.0) {
            return Err(IdentifyError::InvalidSetup {
                field: "solid_fraction".into(),
                value: phi,
                expected: "a solid fraction in (0, 1]".into(),
            });
        }
        Ok(BagnoldFlow {
            slope_rad,
            depth_m,
            grain_diameter_m,
            solid_fraction: phi,
            gravity_m_s2,
            inertial_number: i,
        })
    }

    fn clamp_z(&self, z: f64) -> f64 {
        z.clamp(0.0, self.depth_m)
    }

    /// Pressure over grain density, `P/ρ_s = φ g cos θ (H − z)` (m²/s²).
    pub fn pressure_over_density(&self, z: f64) -> f64 {
        self.solid_fraction
            * self.gravity_m_s2
            * self.slope_rad.cos()
            * (self.depth_m - self.clamp_z(z))
    }

    /// Pressure `P(z) = φ ρ_s g cos θ (H − z)` (Pa) for grain density `ρ_s` (kg/m³).
    pub fn pressure(&self, z: f64, grain_density_kg_m3: f64) -> f64 {
        grain_density_kg_m3 * self.pressure_over_density(z)
    }

    /// Shear rate `γ̇(z) = (I/d) √(P/ρ_s)` (1/s).
    pub fn shear_rate(&self, z: f64) -> f64 {
        self.inertial_number / self.grain_diameter_m * self.pressure_over_density(z).sqrt()
    }

    /// Velocity `u(z) = (2/3)(I/d)√(φ g cos θ)(H^{3/2} − (H − z)^{3/2})` (m/s), `u(0) = 0`.
    pub fn velocity(&self, z: f64) -> f64 {
        let z = self.clamp_z(z);
        let c = self.inertial_number / self.grain_diameter_m
            * (self.solid_fraction * self.gravity_m_s2 * self.slope_rad.cos()).sqrt();
        2.0 / 3.0 * c * (self.depth_m.powf(1.5) - (self.depth_m - z).powf(1.5))
    }

    /// Surface velocity `u(H)` (m/s).
    pub fn surface_velocity(&self) -> f64 {
        self.velocity(self.depth_m)
    }

    /// Depth-averaged velocity `(1/H)∫₀ᴴ u dz = (3/5) u(H)` (m/s).
    pub fn mean_velocity(&self) -> f64 {
        0.6 * self.surface_velocity()
    }

    /// `(z, u(z))` at `points` evenly spaced heights from the base to the surface.
    pub fn profile(&self, points: usize) -> Vec<(f64, f64)> {
        let n = points.max(2);
        (0..n)
            .map(|k| {
                let z = self.depth_m * k as f64 / (n - 1) as f64;
                (z, self.velocity(z))
            })
            .collect()
    }
}

fn check_slope(slope_rad: f64) -> Result<()> {
    if !(slope_rad > 0.0 && slope_rad < std::f64::consts::FRAC_PI_2) {
        return Err(IdentifyError::InvalidSetup {
            field: "slope_rad".into(),
            value: slope_rad,
            expected: "an angle in (0, π/2)".into(),
        });
    }
    Ok(())
}
