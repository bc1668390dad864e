//! Calibrated laws as versioned JSON, for continuum solvers.
//!
//! A [`CalibratedLaw`] carries: `schema_version` ([`SCHEMA_VERSION`]), the law name, its
//! formula as text, the input and output variables with units, the parameters with units,
//! standard errors and intervals, the constants of the set-up (column width, density, ...),
//! the validity range of the data, a fit summary (n, R², AIC, BIC), the AIC ranking when a
//! model was chosen among candidates, and the provenance (scenario, seed, grainlaw version,
//! source file).
//!
//! Example (`janssen`):
//! ```json
//! {
//!   "schema_version": 1,
//!   "law": "janssen",
//!   "formula": "sigma_v(z) = rho_b*g*W/(2*K*mu_w)*(1 - exp(-2*K*mu_w*z/W)); sigma_h = K*sigma_v; tau_w = mu_w*sigma_h",
//!   "input": {"name": "z", "unit": "m"},
//!   "output": {"name": "sigma_v", "unit": "Pa"},
//!   "parameters": [{"name": "K", "unit": "1", "value": 0.61, "std_error": 0.02,
//!                   "ci_low": 0.57, "ci_high": 0.65, "at_bound": false}, ...],
//!   "constants": [{"name": "width", "unit": "m", "value": 0.03}, ...],
//!   "validity": [{"variable": "z", "unit": "m", "min": 0.01, "max": 0.3}, ...],
//!   "fit": {"n": 60, "dof": 58, "r_squared": 0.998, "aic": ..., "bic": ..., "confidence": 0.95},
//!   "model_selection": null,
//!   "provenance": {"scenario": "janssen", "seed": 1, "grainlaw_version": "0.1.0", "source": null}
//! }
//! ```
//! [`CalibratedLaw::from_json_str`] checks the schema version and that the parameters and
//! constants its law needs are present, so a loaded law can be evaluated
//! ([`CalibratedLaw::evaluate`], or typed via [`CalibratedLaw::to_law`]).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{IdentifyError, Result};
use crate::janssen::{JanssenFit, JanssenKMuFit};
use crate::laws::{
    JanssenLaw, JanssenVerticalLaw, LinearMuILaw, MohrCoulombLaw, MuILaw, PhiILaw,
    VelocityBoundaryLayer, WallFrictionLaw,
};
use crate::mohr_coulomb::MohrCoulombFit;
use crate::mu_i::{LinearMuIFit, MuIFit, PhiIFit};
use crate::report::{Estimate, FitReport, ModelComparison, ValidityRange};
use crate::wall_law::{BoundaryLayerFit, WallLawFit, WallLawForm};

/// Schema version written and read by this build.
pub const SCHEMA_VERSION: u32 = 1;

/// Version of grainlaw (the workspace version) recorded in provenance.
pub const GRAINLAW_VERSION: &str = env!("CARGO_PKG_VERSION");

/// A named variable with its unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Variable {
    /// Name.
    pub name: String,
    /// SI unit.
    pub unit: String,
}

/// A constant of the set-up.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Constant {
    /// Name.
    pub name: String,
    /// SI unit.
    pub unit: String,
    /// Value.
    pub value: f64,
}

/// Fit summary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitSummary {
    /// Observations.
    pub n: usize,
    /// Degrees of freedom.
    pub dof: usize,
    /// R².
    pub r_squared: f64,
    /// AIC.
    pub aic: f64,
    /// BIC.
    pub bic: f64,
    /// Confidence level of the intervals.
    pub confidence: f64,
}

impl FitSummary {
    fn of(report: &FitReport) -> Self {
        FitSummary {
            n: report.n,
            dof: report.dof,
            r_squared: report.r_squared,
            aic: report.aic,
            bic: report.bic,
            confidence: report.confidence,
        }
    }
}

/// Where a calibrated law comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// Scenario name (`janssen`, `shear-cell`, ...) or `user-csv`.
    pub scenario: String,
    /// Seed of the run, when there is one.
    pub seed: Option<u64>,
    /// grainlaw version.
    pub grainlaw_version: String,
    /// Source file, when fitted from a file.
    #[serde(default)]
    pub source: Option<String>,
}

impl Provenance {
    /// Provenance for `scenario` and `seed`, with this build's version.
    pub fn new(scenario: &str, seed: Option<u64>) -> Self {
        Provenance {
            scenario: scenario.to_string(),
            seed,
            grainlaw_version: GRAINLAW_VERSION.to_string(),
            source: None,
        }
    }
}

/// A calibrated law, as written to JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibratedLaw {
    /// Schema version ([`SCHEMA_VERSION`]).
    pub schema_version: u32,
    /// Law name: `janssen`, `janssen-kmu`, `wall-law-exponential`, `wall-law-hyperbolic`,
    /// `wall-law-power`, `boundary-layer`, `mu-i`, `mu-i-linear`, `phi-i`, `mohr-coulomb`.
    pub law: String,
    /// Formula as text.
    pub formula: String,
    /// Independent variable of [`CalibratedLaw::evaluate`].
    pub input: Variable,
    /// Value returned by [`CalibratedLaw::evaluate`].
    pub output: Variable,
    /// Fitted parameters.
    pub parameters: Vec<Estimate>,
    /// Set-up constants.
    pub constants: Vec<Constant>,
    /// Data range the law was calibrated on.
    pub validity: Vec<ValidityRange>,
    /// Fit summary.
    pub fit: FitSummary,
    /// AIC ranking when the law was chosen among candidates.
    #[serde(default)]
    pub model_selection: Option<ModelComparison>,
    /// Provenance.
    pub provenance: Provenance,
}

/// A calibrated law in typed form, ready to evaluate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Law {
    /// Janssen, `σ_v(z)`.
    Janssen(JanssenLaw),
    /// Janssen parametrised by `K μ_w`, `σ_v(z)`.
    JanssenKMu(JanssenVerticalLaw),
    /// Wall friction, `μ_eff(V)`.
    WallFriction(WallFrictionLaw),
    /// Boundary-layer velocity, `u(y)`.
    BoundaryLayer(VelocityBoundaryLayer),
    /// μ(I).
    MuI(MuILaw),
    /// Linear μ(I).
    MuILinear(LinearMuILaw),
    /// φ(I).
    PhiI(PhiILaw),
    /// Mohr–Coulomb, shear strength `τ(σ_n)`.
    MohrCoulomb(MohrCoulombLaw),
}

impl Law {
    /// Evaluates the law at its input variable (see [`CalibratedLaw::input`]).
    pub fn evaluate(&self, x: f64) -> f64 {
        match self {
            Law::Janssen(l) => l.sigma_v(x),
            Law::JanssenKMu(l) => l.sigma_v(x),
            Law::WallFriction(l) => l.mu_eff(x),
            Law::BoundaryLayer(l) => l.velocity(x),
            Law::MuI(l) => l.mu(x),
            Law::MuILinear(l) => l.mu(x),
            Law::PhiI(l) => l.phi(x),
            Law::MohrCoulomb(l) => l.shear_strength(x),
        }
    }
}

fn var(name: &str, unit: &str) -> Variable {
    Variable {
        name: name.into(),
        unit: unit.into(),
    }
}

fn constant(name: &str, unit: &str, value: f64) -> Constant {
    Constant {
        name: name.into(),
        unit: unit.into(),
        value,
    }
}

impl CalibratedLaw {
    #[allow(clippy::too_many_arguments)]
    fn build(
        law: &str,
        formula: &str,
        input: Variable,
        output: Variable,
        parameters: Vec<Estimate>,
        constants: Vec<Constant>,
        report: &FitReport,
        provenance: Provenance,
    ) -> Self {
        CalibratedLaw {
            schema_version: SCHEMA_VERSION,
            law: law.into(),
            formula: formula.into(),
            input,
            output,
            parameters,
            constants,
            validity: report.validity.clone(),
            fit: FitSummary::of(report),
            model_selection: None,
            provenance,
        }
    }

    /// From a joint Janssen fit: parameters `K`, `mu_w`, `K_mu_w`; constants `width`,
    /// `bulk_density`, `gravity`, `wall_friction`.
    pub fn from_janssen(fit: &JanssenFit, provenance: Provenance) -> Self {
        Self::build(
            "janssen",
            "sigma_v(z) = rho_b*g*W/(2*K*mu_w)*(1 - exp(-2*K*mu_w*z/W)); sigma_h = K*sigma_v; tau_w = mu_w*sigma_h",
            var("z", "m"),
            var("sigma_v", "Pa"),
            vec![fit.k.clone(), fit.mu_w.clone(), fit.k_mu_w.clone()],
            vec![
                constant("width", "m", fit.law.width_m),
                constant("bulk_density", "kg/m^3", fit.law.bulk_density_kg_m3),
                constant("gravity", "m/s^2", fit.law.gravity_m_s2),
                constant("wall_friction", "1", fit.wall_friction),
            ],
            &fit.report,
            provenance,
        )
    }

    /// From a one-parameter Janssen fit: parameter `K_mu_w`.
    pub fn from_janssen_k_mu(fit: &JanssenKMuFit, provenance: Provenance) -> Self {
        Self::build(
            "janssen-kmu",
            "sigma_v(z) = rho_b*g*W/(2*K_mu_w)*(1 - exp(-2*K_mu_w*z/W))",
            var("z", "m"),
            var("sigma_v", "Pa"),
            vec![fit.k_mu_w.clone()],
            vec![
                constant("width", "m", fit.law.width_m),
                constant("bulk_density", "kg/m^3", fit.law.bulk_density_kg_m3),
                constant("gravity", "m/s^2", fit.law.gravity_m_s2),
            ],
            &fit.report,
            provenance,
        )
    }

    /// From a wall-law fit; `selection` is the AIC ranking it won, if any. Constants:
    /// `grain_diameter`, `gravity` (to turn `V_s` into `V = V_s/√(g d)`).
    pub fn from_wall_law(
        fit: &WallLawFit,
        grain_diameter_m: f64,
        gravity_m_s2: f64,
        selection: Option<ModelComparison>,
        provenance: Provenance,
    ) -> Self {
        let formula = match fit.form {
            WallLawForm::Exponential => {
                "mu_eff(V) = mu_inf - (mu_inf - mu_0)*exp(-V/V_star); V = V_s/sqrt(g*d)"
            }
            WallLawForm::Hyperbolic => {
                "mu_eff(V) = mu_0 + (mu_inf - mu_0)*V/(V + V_star); V = V_s/sqrt(g*d)"
            }
            WallLawForm::PowerLaw => "mu_eff(V) = mu_0 + k*V^n; V = V_s/sqrt(g*d)",
        };
        let mut law = Self::build(
            fit.form.law_name(),
            formula,
            var("V", "1"),
            var("mu_eff", "1"),
            fit.report.parameters.clone(),
            vec![
                constant("grain_diameter", "m", grain_diameter_m),
                constant("gravity", "m/s^2", gravity_m_s2),
            ],
            &fit.report,
            provenance,
        );
        law.model_selection = selection;
        law
    }

    /// From a boundary-layer fit (parameters `u_bulk`, `u_slip`, `delta`).
    pub fn from_boundary_layer(
        fit: &BoundaryLayerFit,
        grain_diameter_m: f64,
        provenance: Provenance,
    ) -> Self {
        Self::build(
            "boundary-layer",
            "u(y) = u_bulk - (u_bulk - u_slip)*exp(-y/delta)",
            var("y", "m"),
            var("u", "m/s"),
            fit.report.parameters.clone(),
            vec![constant("grain_diameter", "m", grain_diameter_m)],
            &fit.report,
            provenance,
        )
    }

    /// From a μ(I) fit (parameters `mu_s`, `mu_2`, `I_0`).
    pub fn from_mu_i(fit: &MuIFit, provenance: Provenance) -> Self {
        Self::build(
            "mu-i",
            "mu(I) = mu_s + (mu_2 - mu_s)/(1 + I_0/I); I = gamma_dot*d/sqrt(P/rho_s)",
            var("I", "1"),
            var("mu", "1"),
            fit.report.parameters.clone(),
            vec![],
            &fit.report,
            provenance,
        )
    }

    /// From a linear μ(I) fit (parameters `mu_s`, `b`).
    pub fn from_mu_i_linear(fit: &LinearMuIFit, provenance: Provenance) -> Self {
        Self::build(
            "mu-i-linear",
            "mu(I) = mu_s + b*I",
            var("I", "1"),
            var("mu", "1"),
            fit.report.parameters.clone(),
            vec![],
            &fit.report,
            provenance,
        )
    }

    /// From a φ(I) fit (parameters `phi_max`, `phi_min`).
    pub fn from_phi_i(fit: &PhiIFit, provenance: Provenance) -> Self {
        Self::build(
            "phi-i",
            "phi(I) = phi_max - (phi_max - phi_min)*I",
            var("I", "1"),
            var("phi", "1"),
            fit.report.parameters.clone(),
            vec![],
            &fit.report,
            provenance,
        )
    }

    /// From a Mohr–Coulomb fit (parameters `friction_angle` (rad), `cohesion` (Pa)).
    pub fn from_mohr_coulomb(fit: &MohrCoulombFit, provenance: Provenance) -> Self {
        Self::build(
            "mohr-coulomb",
            "tau(sigma_n) = cohesion + sigma_n*tan(friction_angle); at yield q = p*sin(friction_angle) + cohesion*cos(friction_angle); 2D Drucker-Prager: alpha = sin(friction_angle), k = cohesion*cos(friction_angle)",
            var("sigma_n", "Pa"),
            var("tau", "Pa"),
            fit.report.parameters.clone(),
            vec![],
            &fit.report,
            provenance,
        )
    }

    /// Parameter value by name.
    pub fn parameter(&self, name: &str) -> Result<f64> {
        self.parameters
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.value)
            .ok_or_else(|| IdentifyError::LawFormat {
                message: format!("law '{}' has no parameter '{name}'", self.law),
            })
    }

    /// Constant value by name.
    pub fn constant(&self, name: &str) -> Result<f64> {
        self.constants
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.value)
            .ok_or_else(|| IdentifyError::LawFormat {
                message: format!("law '{}' has no constant '{name}'", self.law),
            })
    }

    /// The typed law (checks that every parameter and constant it needs is present).
    pub fn to_law(&self) -> Result<Law> {
        let p = |n: &str| self.parameter(n);
        let c = |n: &str| self.constant(n);
        Ok(match self.law.as_str() {
            "janssen" => Law::Janssen(JanssenLaw {
                k: p("K")?,
                mu_w: p("mu_w")?,
                width_m: c("width")?,
                bulk_density_kg_m3: c("bulk_density")?,
                gravity_m_s2: c("gravity")?,
            }),
            "janssen-kmu" => Law::JanssenKMu(JanssenVerticalLaw {
                k_mu_w: p("K_mu_w")?,
                width_m: c("width")?,
                bulk_density_kg_m3: c("bulk_density")?,
                gravity_m_s2: c("gravity")?,
            }),
            "wall-law-exponential" => Law::WallFriction(WallFrictionLaw::Exponential {
                mu_0: p("mu_0")?,
                mu_inf: p("mu_inf")?,
                v_star: p("V_star")?,
            }),
            "wall-law-hyperbolic" => Law::WallFriction(WallFrictionLaw::Hyperbolic {
                mu_0: p("mu_0")?,
                mu_inf: p("mu_inf")?,
                v_star: p("V_star")?,
            }),
            "wall-law-power" => Law::WallFriction(WallFrictionLaw::PowerLaw {
                mu_0: p("mu_0")?,
                k: p("k")?,
                n: p("n")?,
            }),
            "boundary-layer" => Law::BoundaryLayer(VelocityBoundaryLayer {
                u_bulk: p("u_bulk")?,
                u_slip: p("u_slip")?,
                delta_m: p("delta")?,
            }),
            "mu-i" => Law::MuI(MuILaw {
                mu_s: p("mu_s")?,
                mu_2: p("mu_2")?,
                i0: p("I_0")?,
            }),
            "mu-i-linear" => Law::MuILinear(LinearMuILaw {
                mu_s: p("mu_s")?,
                slope: p("b")?,
            }),
            "phi-i" => Law::PhiI(PhiILaw {
                phi_max: p("phi_max")?,
                phi_min: p("phi_min")?,
            }),
            "mohr-coulomb" => Law::MohrCoulomb(MohrCoulombLaw {
                friction_angle_rad: p("friction_angle")?,
                cohesion_pa: p("cohesion")?,
            }),
            other => {
                return Err(IdentifyError::LawFormat {
                    message: format!("unknown law '{other}'"),
                })
            }
        })
    }

    /// Evaluates the law at `x` (its `input` variable, in its unit).
    pub fn evaluate(&self, x: f64) -> Result<f64> {
        Ok(self.to_law()?.evaluate(x))
    }

    /// True when `x` lies inside the validity range of the law's input variable (true when
    /// the range of that variable is not recorded).
    pub fn in_validity_range(&self, x: f64) -> bool {
        self.validity
            .iter()
            .find(|v| v.variable == self.input.name)
            .is_none_or(|v| v.contains(x))
    }

    /// Pretty JSON.
    pub fn to_json_string(&self) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| IdentifyError::LawFormat {
            message: e.to_string(),
        })
    }

    /// Parses JSON: checks `schema_version` first ([`IdentifyError::UnsupportedSchema`]), then
    /// the structure, then that the law can be built ([`CalibratedLaw::to_law`]).
    pub fn from_json_str(text: &str) -> Result<Self> {
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| IdentifyError::LawFormat {
                message: e.to_string(),
            })?;
        let version = value
            .get("schema_version")
            .and_then(|v| v.as_u64())
            .ok_or_else(|| IdentifyError::LawFormat {
                message: "missing or non-integer 'schema_version'".into(),
            })?;
        if version != SCHEMA_VERSION as u64 {
            return Err(IdentifyError::UnsupportedSchema {
                found: version.min(u32::MAX as u64) as u32,
                supported: SCHEMA_VERSION,
            });
        }
        let law: CalibratedLaw =
            serde_json::from_value(value).map_err(|e| IdentifyError::LawFormat {
                message: e.to_string(),
            })?;
        law.to_law()?;
        Ok(law)
    }

    /// Writes pretty JSON to `path`.
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = self.to_json_string()?;
        std::fs::write(path, text + "\n").map_err(|source| IdentifyError::Io {
            path: path.display().to_string(),
            source,
        })
    }

    /// Reads and checks a law from `path`.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| IdentifyError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_json_str(&text)
    }
}
