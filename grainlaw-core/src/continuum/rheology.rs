//! A calibrated μ(I) law in Gerris' dimensionless units (`docs/continuum.md` §2).
//!
//! **Units.** Gerris solves the incompressible Navier–Stokes equations without dimensions. The
//! cases here take a length scale `L` (the column's initial half-width `R₀`, or the inclined
//! layer's thickness `H`), gravity `g` and the bulk density of the granular phase
//! `ρ_b = φ ρ_s` as units ([`Units`]): time `√(L/g)`, velocity `√(g L)`, pressure (stress)
//! `ρ_b g L`, dynamic viscosity `ρ_b √(g L³)`. The granular phase has density 1.
//!
//! **The inertial number.** The law's `I = γ̇ d/√(P/ρ_s)` is defined with the grain density
//! `ρ_s` (its JSON's `where`). Gerris' pressure comes from the unit *bulk* density: in SI,
//! `P = P_G ρ_b g L = P_G φ ρ_s g L`, with `γ̇ = γ̇_G √(g/L)` and `d = D L`, so
//!
//! ```text
//! I = γ̇_G √(g/L) · D L / √(P_G φ g L) = γ̇_G D/√(φ P_G) = I_G/√φ,   I_G = γ̇_G D/√P_G,
//! ```
//!
//! i.e. the `I` Gerris' own variables give (`I_G`, what the Gerris example computes) is
//! `√φ · I`. The strain rate is `γ̇ = √(2 D:D) = √2 · D2`, Gerris' `D2` being `√(D:D)`
//! (`gfs_2nd_principal_invariant`; for simple shear `u = γ̇ y`, `D:D = γ̇²/2`). This is the
//! project's `γ̇ = √(2 D':D')` (`docs/physics.md` §2.6) since the flow is incompressible.
//!
//! **Viscosity.** `|τ| = μ(I) P` along `D` is the viscosity `η = μ(I) P/γ̇ = μ(I) P/(√2 D2)`
//! (Jop, Forterre & Pouliquen, Nature 441, 2006), regularised ([`Regularisation`]): clamped to
//! `[η_min, η_max]`, `η_min` where `P ≤ 0` (no confinement, no shear stress), `η_max` where
//! `D2 = 0` (at rest). Across the interface with the light phase ([`LightPhase`]) the
//! viscosities are mixed by the harmonic mean weighted by the volume fraction `T`, as in the
//! Gerris example `column` (Lagrée, Staron & Popinet, J. Fluid Mech. 686, 2011).

use serde::Serialize;

use identify::expr::c_literal;
use identify::law::{CalibratedLaw, Law};

use crate::error::{CliError, Result};

/// The laws a continuum run accepts: the μ(I) laws of the registry.
pub const CONTINUUM_LAWS: [&str; 2] = ["mu-i", "mu-i-linear"];

/// Gerris' units of a case.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Units {
    /// Length unit `L` (m): `R₀` for the column, `H` for the inclined layer.
    pub length_m: f64,
    /// Gravity `g` (m/s²), the unit of acceleration.
    pub gravity_m_s2: f64,
    /// Bulk density `ρ_b = φ ρ_s` (kg/m³), the granular phase's density (1 in Gerris).
    pub bulk_density_kg_m3: f64,
}

impl Units {
    /// Time unit `√(L/g)` (s).
    pub fn time_s(&self) -> f64 {
        (self.length_m / self.gravity_m_s2).sqrt()
    }

    /// Velocity unit `√(g L)` (m/s).
    pub fn velocity_m_s(&self) -> f64 {
        (self.gravity_m_s2 * self.length_m).sqrt()
    }

    /// Pressure (stress) unit `ρ_b g L` (Pa).
    pub fn pressure_pa(&self) -> f64 {
        self.bulk_density_kg_m3 * self.gravity_m_s2 * self.length_m
    }

    /// Dynamic viscosity unit `ρ_b √(g L³)` (Pa s).
    pub fn viscosity_pa_s(&self) -> f64 {
        self.bulk_density_kg_m3 * (self.gravity_m_s2 * self.length_m.powi(3)).sqrt()
    }
}

/// The regularisation of the μ(I) viscosity (Gerris units): `η` clamped to
/// `[eta_min, eta_max]`. `eta_max` bounds the viscosity of the zones at rest: below yield the
/// material creeps at `γ̇ ≈ μ P/η_max` (a layer of depth `h` at `≈ μ_s h/η_max`); `eta_min`
/// bounds it where the confinement vanishes (the free surface).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Regularisation {
    /// Smallest viscosity (Gerris units).
    pub eta_min: f64,
    /// Largest viscosity (Gerris units).
    pub eta_max: f64,
}

impl Regularisation {
    /// The Gerris example's choice (Lagrée et al. 2011): `η_min = D^{3/2}`, the viscosity
    /// scale `ρ_b √(g d³)` of a flow at `I ~ 1` one grain deep, and the cap `eta_max` (10 there).
    pub fn for_grains(d: f64, eta_max: f64) -> Self {
        Regularisation {
            eta_min: d.powf(1.5),
            eta_max,
        }
    }
}

/// The light phase around the granular column (Gerris units), present only so that the free
/// surface is a VOF interface: density `density_ratio` (× ρ_b) and viscosity `viscosity`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LightPhase {
    /// Density of the light phase over the granular phase's (1).
    pub density_ratio: f64,
    /// Dynamic viscosity of the light phase (Gerris units).
    pub viscosity: f64,
}

impl Default for LightPhase {
    /// The Gerris example's: density ratio 10⁻³ (air over sand), viscosity 10⁻⁴.
    fn default() -> Self {
        LightPhase {
            density_ratio: 1e-3,
            viscosity: 1e-4,
        }
    }
}

/// A μ(I) law made ready for Gerris: the law, where it was read, the packing fraction and
/// grain size that turn its `I` into Gerris' variables, the regularisation and units.
#[derive(Debug, Clone, PartialEq)]
pub struct GerrisRheology {
    /// The law (a μ(I) law of [`CONTINUUM_LAWS`]).
    pub law: CalibratedLaw,
    /// The file it was read from.
    pub law_path: String,
    /// Packing fraction `φ` of the continuum (its density is `φ ρ_s`).
    pub packing_fraction: f64,
    /// Units of the case.
    pub units: Units,
    /// Viscosity bounds.
    pub regularisation: Regularisation,
}

impl GerrisRheology {
    /// Checks `law` (read from `path`) for a continuum run and sets its units: a μ(I) law
    /// ([`CONTINUUM_LAWS`]) with finite parameters and the constants `d` and `rho_s` finite and
    /// positive; `packing_fraction` in (0, 1]; `length_m` and `gravity_m_s2` positive;
    /// `eta_max` above the floor `D^{3/2}`. Errors: [`CliError::Input`] naming the law file,
    /// [`CliError::Usage`] for a bad setting.
    pub fn new(
        law: CalibratedLaw,
        path: &str,
        length_m: f64,
        gravity_m_s2: f64,
        packing_fraction: f64,
        eta_max: f64,
    ) -> Result<Self> {
        check_continuum_law(&law, path)?;
        let positive = |name: &str, v: f64| -> Result<()> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(CliError::Usage(format!(
                    "{name} must be a finite number > 0, got {v}"
                )))
            }
        };
        positive("the length unit (m)", length_m)?;
        positive("gravity (m/s²)", gravity_m_s2)?;
        if !(packing_fraction > 0.0 && packing_fraction <= 1.0) {
            return Err(CliError::Usage(format!(
                "--packing-fraction must lie in (0, 1], got {packing_fraction}"
            )));
        }
        let rho_s = law.constant("rho_s").map_err(|e| input(path, e))?;
        let d = law.constant("d").map_err(|e| input(path, e))? / length_m;
        let regularisation = Regularisation::for_grains(d, eta_max);
        if !(eta_max.is_finite() && eta_max > regularisation.eta_min) {
            return Err(CliError::Usage(format!(
                "--viscosity-cap must be finite and above the floor D^1.5 = {:.3e}, got {eta_max}",
                regularisation.eta_min
            )));
        }
        Ok(GerrisRheology {
            law,
            law_path: path.to_string(),
            packing_fraction,
            units: Units {
                length_m,
                gravity_m_s2,
                bulk_density_kg_m3: packing_fraction * rho_s,
            },
            regularisation,
        })
    }

    /// The same with the law's parameters set to `values` (registry order), e.g. one point of
    /// the uncertainty band. Errors: [`CliError::Input`] for a wrong count or a law the values
    /// make unphysical (`μ_s ≤ 0`, `μ₂ ≤ μ_s`, `I₀ ≤ 0`, `b < 0`).
    pub fn with_parameter_values(&self, values: &[f64]) -> Result<Self> {
        let law = self
            .law
            .with_parameter_values(values)
            .map_err(|e| input(&self.law_path, e))?;
        check_continuum_law(&law, &self.law_path)?;
        Ok(GerrisRheology {
            law,
            ..self.clone()
        })
    }

    /// Grain diameter in units of the length unit, `D = d/L`.
    pub fn grain_diameter(&self) -> f64 {
        self.law.constant("d").unwrap_or(f64::NAN) / self.units.length_m
    }

    /// Grain diameter `d` (m).
    pub fn grain_diameter_m(&self) -> f64 {
        self.law.constant("d").unwrap_or(f64::NAN)
    }

    /// Grain density `ρ_s` (kg/m³).
    pub fn grain_density_kg_m3(&self) -> f64 {
        self.law.constant("rho_s").unwrap_or(f64::NAN)
    }

    /// The law's `μ(I)` (its typed evaluation, [`CalibratedLaw::to_law`]).
    pub fn mu(&self, i: f64) -> f64 {
        self.law.to_law().map(|l| l.evaluate(i)).unwrap_or(f64::NAN)
    }

    /// The uniform `I` of steady flow on a slope, the root of `μ(I) = tan θ`: `None` when
    /// `tan θ` is outside the law's range of friction (no steady flow).
    pub fn inertial_number_for(&self, mu: f64) -> Option<f64> {
        match self.law.to_law().ok()? {
            Law::MuI(l) => l.inertial_number_for(mu),
            Law::MuILinear(l) => l.inertial_number_for(mu),
            _ => None,
        }
    }

    /// The law's `I` from Gerris' `I_G = γ̇_G D/√P_G`: `I = I_G/√φ` (module documentation).
    pub fn law_inertial_number(&self, gerris_inertial_number: f64) -> f64 {
        gerris_inertial_number / self.packing_fraction.sqrt()
    }

    /// The law's largest calibrated `I` (its validity range), when recorded.
    pub fn validity_max(&self) -> Option<f64> {
        self.law
            .validity
            .iter()
            .find(|v| v.variable == "I")
            .map(|v| v.max)
    }

    /// The law's smallest calibrated `I`, when recorded.
    pub fn validity_min(&self) -> Option<f64> {
        self.law
            .validity
            .iter()
            .find(|v| v.variable == "I")
            .map(|v| v.min)
    }

    /// C expression of the law's `I` in Gerris' variables `D2` and `P` (valid where `P > 0`):
    /// `sqrt(2.)*D2*D/sqrt(φ*P)`, the numbers as round-trip literals.
    pub fn inertial_number_c(&self) -> String {
        format!(
            "(sqrt(2.)*D2*{}/sqrt({}*P))",
            c_literal(self.grain_diameter()),
            c_literal(self.packing_fraction)
        )
    }

    /// The body of Gerris' `SourceViscosity` function: the regularised μ(I) viscosity (module
    /// documentation), mixed with the light phase by the harmonic mean in `T` when `light` is
    /// given. No braces in comments (Gerris matches braces to find the function's end) and no
    /// local name that is a Gerris variable (`gl_` prefix).
    pub fn source_viscosity_c(&self, light: Option<&LightPhase>) -> Result<String> {
        let mu = self
            .law
            .formula_in_c("gl_I")
            .map_err(|e| input(&self.law_path, e))?;
        let (lo, hi) = (
            c_literal(self.regularisation.eta_min),
            c_literal(self.regularisation.eta_max),
        );
        let ret = match light {
            Some(l) => format!(
                "  /* harmonic mean of the granular and light viscosities across the interface */\n  return 1./(T/gl_eta + (1. - T)/{});\n",
                c_literal(l.viscosity)
            ),
            None => "  return gl_eta;\n".into(),
        };
        Ok(format!(
            "{{\n  /* grainlaw: {law} of {path}; Gerris units (L = 1, g = 1, rho_b = 1) */\n  double gl_eta = {hi};\n  if (P <= 0.)\n    gl_eta = {lo};\n  else if (D2 > 0.) {{\n    /* the law's I = I_Gerris/sqrt(phi), gamma_dot = sqrt(2) D2 */\n    double gl_I = {i};\n    double gl_mu = {mu};\n    gl_eta = gl_mu*P/(sqrt(2.)*D2);\n    gl_eta = MIN(MAX(gl_eta, {lo}), {hi});\n  }}\n{ret}}}",
            law = self.law.law,
            path = sanitize_comment(&self.law_path),
            i = self.inertial_number_c(),
        ))
    }
}

/// Refuses a law that is not a μ(I) law, lacks a constant the conversion needs, or whose
/// parameters are not finite or make it unphysical. Errors: [`CliError::Input`] naming `path`.
pub fn check_continuum_law(law: &CalibratedLaw, path: &str) -> Result<()> {
    if !CONTINUUM_LAWS.contains(&law.law.as_str()) {
        return Err(CliError::Input {
            path: path.into(),
            reason: format!(
                "law '{}' is not a μ(I) law: a continuum run needs {} (the `mu_i_law.json` of a simple-shear or shear-cell run, or `grainlaw fit mu-i`)",
                law.law,
                CONTINUUM_LAWS.join(" or ")
            ),
        });
    }
    for c in ["d", "rho_s"] {
        match law.constant(c) {
            Ok(v) if v.is_finite() && v > 0.0 => {}
            Ok(v) => {
                return Err(CliError::Input {
                    path: path.into(),
                    reason: format!(
                        "constant '{c}' = {v} must be finite and > 0 to turn I into the shear rate and pressure"
                    ),
                })
            }
            Err(_) => {
                return Err(CliError::Input {
                    path: path.into(),
                    reason: format!(
                        "law '{}' lacks the constant '{c}' (d and rho_s turn I into the shear rate and pressure; a schema-1 μ(I) law has neither: fit it again with grainlaw fit)",
                        law.law
                    ),
                })
            }
        }
    }
    let value = |n: &str| law.parameter(n).unwrap_or(f64::NAN);
    if let Some(p) = law.parameters.iter().find(|p| !p.value.is_finite()) {
        return Err(CliError::Input {
            path: path.into(),
            reason: format!("parameter '{}' is not a finite number", p.name),
        });
    }
    let unphysical = match law.law.as_str() {
        "mu-i" => {
            let (s, m2, i0) = (value("mu_s"), value("mu_2"), value("I_0"));
            (!(s > 0.0 && m2 > s && i0 > 0.0)).then(|| {
                format!(
                    "needs 0 < mu_s < mu_2 and I_0 > 0, has mu_s = {s}, mu_2 = {m2}, I_0 = {i0}"
                )
            })
        }
        _ => {
            let (s, b) = (value("mu_s"), value("b"));
            (!(s > 0.0 && b >= 0.0))
                .then(|| format!("needs mu_s > 0 and b ≥ 0, has mu_s = {s}, b = {b}"))
        }
    };
    match unphysical {
        Some(m) => Err(CliError::Input {
            path: path.into(),
            reason: format!("law '{}' {m}", law.law),
        }),
        None => Ok(()),
    }
}

/// Loads a law for a continuum run: [`CalibratedLaw::load`] then [`check_continuum_law`].
/// Errors: [`CliError::Input`] naming the file.
pub fn load_continuum_law(path: &std::path::Path) -> Result<CalibratedLaw> {
    let shown = path.display().to_string();
    let law = CalibratedLaw::load(path).map_err(|e| input(&shown, e))?;
    check_continuum_law(&law, &shown)?;
    Ok(law)
}

fn input(path: &str, e: impl std::fmt::Display) -> CliError {
    CliError::Input {
        path: path.to_string(),
        reason: e.to_string(),
    }
}

/// `text` safe inside a C comment and a Gerris block: no comment delimiters, no braces.
pub(crate) fn sanitize_comment(text: &str) -> String {
    text.replace("*/", "* /")
        .replace("/*", "/ *")
        .replace(['{', '}'], "")
        .replace('\n', " ")
}
