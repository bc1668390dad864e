//! Calibrated laws as versioned JSON, for continuum solvers (schema version 2; version 1 is
//! still read).
//!
//! A law is one of a fixed registry ([`REGISTRY`]): its name fixes the formula, written in the
//! convention `grainlaw-expr-1` ([`crate::expr`]), whose variable names are exactly the
//! law's input, the names (keys) of its `parameters` and `constants`, its earlier outputs and
//! the names and inputs of its `where` list. A [`CalibratedLaw`] (schema 2) carries:
//!
//! - `expression`: registry name, convention, input and output with units, the formula, further
//!   outputs (`also`, e.g. `sigma_h = K*sigma_v`) and `where` definitions that turn a
//!   solver's variables into the law's input (`I = gamma_dot*d/sqrt(P/rho_s)`);
//! - `parameters` (a list, each with its `name`): unit, value, standard error, 95 % interval, `at_bound`, and for
//!   angles (unit `rad`) the same in degrees (`deg`);
//! - `covariance`: the full covariance matrix of the parameters, in the order it names;
//! - `derived` (a list): quantities computed from the parameters (`K_mu_w`, the saturation
//!   length, ...), each with `"derived": true`, its formula and its delta-method interval;
//! - `constants` (a list, each with its `name`): every constant the formulas need, with unit and description (μ(I)
//!   needs `d` and `rho_s`);
//! - `dimension` (`2D, per unit thickness`) and `geometry` (what set-up the law assumes);
//! - `validity`, `fit` (n, dof, R², AIC, BIC, confidence), `model_selection`;
//! - `provenance`: scenario, every override, seed, grainlaw version, date, and the SHA-256 of
//!   each input file (`grainlaw fit` fills its CSV's, a scenario run its `scenario.toml`).
//!
//! Example (`mu-i`, abridged):
//! ```json
//! {
//!   "schema_version": 2,
//!   "law": "mu-i",
//!   "expression": {
//!     "registry": "grainlaw", "convention": "grainlaw-expr-1",
//!     "input": {"name": "I", "unit": "1"}, "output": {"name": "mu", "unit": "1"},
//!     "formula": "mu_s + (mu_2 - mu_s)*I/(I + I_0)", "also": [],
//!     "where": [{"name": "I", "unit": "1", "formula": "gamma_dot*d/sqrt(P/rho_s)",
//!                "inputs": [{"name": "gamma_dot", "unit": "1/s"}, {"name": "P", "unit": "Pa"}]}]
//!   },
//!   "parameters": [{"name": "mu_s", "unit": "1", "value": 0.38, "std_error": 0.004,
//!                   "ci_low": 0.372, "ci_high": 0.388, "at_bound": false}, {"name": "mu_2", ...},
//!                  {"name": "I_0", ...}],
//!   "covariance": {"order": ["mu_s", "mu_2", "I_0"], "matrix": [[...], [...], [...]]},
//!   "derived": [],
//!   "constants": [{"name": "d", "unit": "m", "value": 0.002, "description": "mean grain diameter"},
//!                 {"name": "rho_s", "unit": "kg/m^3", "value": 2500.0, "description": "..."}],
//!   "dimension": "2D, per unit thickness",
//!   "geometry": "steady homogeneous simple shear at imposed pressure P ...",
//!   "validity": [{"variable": "I", "unit": "1", "min": 0.001, "max": 0.3}],
//!   "fit": {"n": 25, "dof": 22, "r_squared": 0.998, "aic": ..., "bic": ..., "confidence": 0.95},
//!   "model_selection": null,
//!   "provenance": {"scenario": "user-csv", "overrides": [], "seed": null,
//!                  "grainlaw_version": "0.1.0", "date": "2026-11-30T10:00:00Z",
//!                  "inputs": [{"path": "mu.csv", "sha256": "..."}], "source": "mu.csv"}
//! }
//! ```
//! [`CalibratedLaw::from_json_str`] reads versions 1 and 2: version 2 is checked against the
//! registry (formula, parameters, constants, covariance); version 1 is upgraded (its constants
//! renamed to the registry's names, `K_mu_w` moved to `derived`, no covariance, and a μ(I) or
//! φ(I) of version 1 lacks `d` and `rho_s`, so only the law in `I` can be evaluated).
//! [`CalibratedLaw::evaluate`] evaluates a loaded law at many inputs.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::critical_state::{CriticalStateFit, StressDilatancyFit};
use crate::error::{IdentifyError, Result};
use crate::expr::Expr;
use crate::janssen::{JanssenFit, JanssenKMuFit};
use crate::laws::{
    CriticalStateLaw, JanssenLaw, JanssenVerticalLaw, LinearMuILaw, MohrCoulombLaw, MuILaw,
    PhiILaw, StressDilatancyLaw, VelocityBoundaryLayer, WallFrictionLaw,
};
use crate::mohr_coulomb::MohrCoulombFit;
use crate::mu_i::{LinearMuIFit, MuIFit, PhiIFit};
use crate::report::{Estimate, FitReport, ModelComparison, ValidityRange};
use crate::wall_law::{BoundaryLayerFit, WallLawFit};

/// Schema version written by this build (it reads 1 and 2).
pub const SCHEMA_VERSION: u32 = 2;

/// Version of grainlaw (the workspace version) recorded in provenance.
pub const GRAINLAW_VERSION: &str = env!("CARGO_PKG_VERSION");

/// The expression convention of the formulas ([`crate::expr`]).
pub const EXPRESSION_CONVENTION: &str = "grainlaw-expr-1";

/// Name of the law registry ([`REGISTRY`]).
pub const REGISTRY_NAME: &str = "grainlaw";

/// Dimension every law of the registry assumes.
pub const DIMENSION: &str = "2D, per unit thickness";

/// A further output of a law, computed after the main one (it may use it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutputSpec {
    /// Name.
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Formula.
    pub formula: &'static str,
}

/// A `where` definition: the law's input in terms of a solver's variables.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DefinitionSpec {
    /// Defined name (the law's input).
    pub name: &'static str,
    /// Its unit.
    pub unit: &'static str,
    /// Formula.
    pub formula: &'static str,
    /// The solver's variables it uses, with units.
    pub inputs: &'static [(&'static str, &'static str)],
}

/// One law of the registry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LawSpec {
    /// Registry name (the `law` field of the JSON).
    pub name: &'static str,
    /// Input variable and unit.
    pub input: (&'static str, &'static str),
    /// Output variable and unit.
    pub output: (&'static str, &'static str),
    /// Formula of the output.
    pub formula: &'static str,
    /// Further outputs.
    pub also: &'static [OutputSpec],
    /// `where` definitions.
    pub definitions: &'static [DefinitionSpec],
    /// Parameters `(name, unit)`, in covariance order.
    pub parameters: &'static [(&'static str, &'static str)],
    /// Constants `(name, unit, description)`.
    pub constants: &'static [(&'static str, &'static str, &'static str)],
    /// Derived quantities `(name, unit, formula)`.
    pub derived: &'static [(&'static str, &'static str, &'static str)],
    /// The set-up the law assumes.
    pub geometry: &'static str,
}

const I_FROM_SHEAR: &[DefinitionSpec] = &[DefinitionSpec {
    name: "I",
    unit: "1",
    formula: "gamma_dot*d/sqrt(P/rho_s)",
    inputs: &[("gamma_dot", "1/s"), ("P", "Pa")],
}];
const GRAIN_CONSTANTS: &[(&str, &str, &str)] = &[
    ("d", "m", "mean grain diameter"),
    ("rho_s", "kg/m^3", "grain material density"),
];
const SHEAR_GEOMETRY: &str = "steady homogeneous simple shear at imposed pressure P (plane Couette, no gravity); mu = |tau|/P the local stress ratio, phi the solid fraction, I the local inertial number";
const V_FROM_SLIP: &[DefinitionSpec] = &[DefinitionSpec {
    name: "V",
    unit: "1",
    formula: "V_s/sqrt(g*d)",
    inputs: &[("V_s", "m/s")],
}];
const WALL_CONSTANTS: &[(&str, &str, &str)] =
    &[("d", "m", "mean grain diameter"), ("g", "m/s^2", "gravity")];
const WALL_GEOMETRY: &str = "grains sliding along a flat rigid wall: mu_eff = tau_w/sigma_w the ratio of wall shear to wall normal stress, V_s the slip velocity of the grains along the wall";
const JANSSEN_GEOMETRY: &str = "column of width W between two parallel vertical rigid walls, filled to a free surface at z = 0, z measured downward; stresses compressive positive, averaged across the width (slice balance)";

/// A wall-friction law of `V = V_s/√(g d)`.
const fn wall_law(
    name: &'static str,
    formula: &'static str,
    parameters: &'static [(&'static str, &'static str)],
) -> LawSpec {
    LawSpec {
        name,
        input: ("V", "1"),
        output: ("mu_eff", "1"),
        formula,
        also: &[],
        definitions: V_FROM_SLIP,
        parameters,
        constants: WALL_CONSTANTS,
        derived: &[],
        geometry: WALL_GEOMETRY,
    }
}

/// A law of the inertial number `I = γ̇ d/√(P/ρ_s)` (output `mu` or `phi`).
const fn rheology(
    name: &'static str,
    output: &'static str,
    formula: &'static str,
    parameters: &'static [(&'static str, &'static str)],
) -> LawSpec {
    LawSpec {
        name,
        input: ("I", "1"),
        output: (output, "1"),
        formula,
        also: &[],
        definitions: I_FROM_SHEAR,
        parameters,
        constants: GRAIN_CONSTANTS,
        derived: &[],
        geometry: SHEAR_GEOMETRY,
    }
}

/// The registry of laws a calibrated-law JSON can hold (schema 2).
pub const REGISTRY: &[LawSpec] = &[
    LawSpec {
        name: "janssen",
        input: ("z", "m"),
        output: ("sigma_v", "Pa"),
        formula: "rho_b*g*W/(2*K*mu_w)*(1 - exp(-2*K*mu_w*z/W))",
        also: &[
            OutputSpec {
                name: "sigma_h",
                unit: "Pa",
                formula: "K*sigma_v",
            },
            OutputSpec {
                name: "tau_w",
                unit: "Pa",
                formula: "mu_w*sigma_h",
            },
        ],
        definitions: &[],
        parameters: &[("K", "1"), ("mu_w", "1")],
        constants: &[
            ("W", "m", "column width between the two walls"),
            ("rho_b", "kg/m^3", "bulk density phi*rho_s"),
            ("g", "m/s^2", "gravity"),
            (
                "mu_wall",
                "1",
                "grain-wall friction coefficient, upper bound of mu_w",
            ),
        ],
        derived: &[
            ("K_mu_w", "1", "K*mu_w"),
            ("saturation_length", "m", "W/(2*K*mu_w)"),
            ("mobilisation", "1", "mu_w/mu_wall"),
        ],
        geometry: JANSSEN_GEOMETRY,
    },
    LawSpec {
        name: "janssen-kmu",
        input: ("z", "m"),
        output: ("sigma_v", "Pa"),
        formula: "rho_b*g*W/(2*K_mu_w)*(1 - exp(-2*K_mu_w*z/W))",
        also: &[],
        definitions: &[],
        parameters: &[("K_mu_w", "1")],
        constants: &[
            ("W", "m", "column width between the two walls"),
            ("rho_b", "kg/m^3", "bulk density phi*rho_s"),
            ("g", "m/s^2", "gravity"),
        ],
        derived: &[("saturation_length", "m", "W/(2*K_mu_w)")],
        geometry: JANSSEN_GEOMETRY,
    },
    wall_law(
        "wall-law-exponential",
        "mu_inf - (mu_inf - mu_0)*exp(-V/V_star)",
        &[("mu_0", "1"), ("mu_inf", "1"), ("V_star", "1")],
    ),
    wall_law(
        "wall-law-hyperbolic",
        "mu_0 + (mu_inf - mu_0)*V/(V + V_star)",
        &[("mu_0", "1"), ("mu_inf", "1"), ("V_star", "1")],
    ),
    wall_law(
        "wall-law-power",
        "mu_0 + k*V^n",
        &[("mu_0", "1"), ("k", "1"), ("n", "1")],
    ),
    LawSpec {
        name: "boundary-layer",
        input: ("y", "m"),
        output: ("u", "m/s"),
        formula: "u_bulk - (u_bulk - u_slip)*exp(-y/delta)",
        also: &[],
        definitions: &[],
        parameters: &[("u_bulk", "m/s"), ("u_slip", "m/s"), ("delta", "m")],
        constants: &[("d", "m", "mean grain diameter")],
        derived: &[("delta_over_d", "1", "delta/d")],
        geometry: "velocity parallel to a flat wall against the distance y from it",
    },
    rheology(
        "mu-i",
        "mu",
        "mu_s + (mu_2 - mu_s)*I/(I + I_0)",
        &[("mu_s", "1"), ("mu_2", "1"), ("I_0", "1")],
    ),
    rheology(
        "mu-i-linear",
        "mu",
        "mu_s + b*I",
        &[("mu_s", "1"), ("b", "1")],
    ),
    rheology(
        "phi-i",
        "phi",
        "phi_max - a*I",
        &[("phi_max", "1"), ("a", "1")],
    ),
    LawSpec {
        name: "mohr-coulomb",
        input: ("sigma_n", "Pa"),
        output: ("tau", "Pa"),
        formula: "cohesion + sigma_n*tan(friction_angle)",
        also: &[],
        definitions: &[],
        parameters: &[("friction_angle", "rad"), ("cohesion", "Pa")],
        constants: &[],
        derived: &[
            ("dp_alpha", "1", "sin(friction_angle)"),
            ("dp_k", "Pa", "cohesion*cos(friction_angle)"),
        ],
        geometry: "plane strain (2D), compressive positive: shear strength tau on a plane of normal stress sigma_n; at yield the in-plane Mohr circle (centre p, radius q) touches the envelope, q = p*sin(friction_angle) + cohesion*cos(friction_angle), i.e. 2D Drucker-Prager q = dp_alpha*p + dp_k",
    },
    LawSpec {
        name: "critical-state",
        input: ("p", "Pa"),
        output: ("q", "Pa"),
        formula: "p*sin(friction_angle_c)",
        also: &[OutputSpec {
            name: "phi",
            unit: "1",
            formula: "solid_fraction_c",
        }],
        definitions: &[],
        parameters: &[("friction_angle_c", "rad"), ("solid_fraction_c", "1")],
        constants: &[],
        derived: &[("M_c", "1", "sin(friction_angle_c)")],
        geometry: "plane strain (2D), compressive positive: steady quasi-static shear at constant volume (critical state) of rigid cohesionless grains at any mean stress p = (sigma_1 + sigma_3)/2; deviator q = (sigma_1 - sigma_3)/2 = p*sin(friction_angle_c), solid fraction phi = solid_fraction_c",
    },
    LawSpec {
        name: "stress-dilatancy",
        input: ("sin_psi", "1"),
        output: ("sin_phi", "1"),
        formula: "sin_phi_c + beta*sin_psi",
        also: &[],
        definitions: &[],
        parameters: &[("sin_phi_c", "1"), ("beta", "1")],
        constants: &[],
        derived: &[],
        geometry: "plane strain (2D), compressive positive, quasi-static hardening: mobilised friction sin_phi = q/p against the dilatancy sin_psi = -rate_v/rate_gamma (rate_v = rate_1 + rate_3, rate_gamma = rate_1 - rate_3); beta = 1 is Taylor's energy form, Rowe's relation has slope 1 - sin_phi_c^2 at sin_psi = 0",
    },
];

/// The registry entry of `law`. Errors: [`IdentifyError::LawFormat`] for a name not in
/// [`REGISTRY`].
pub fn law_spec(law: &str) -> Result<&'static LawSpec> {
    REGISTRY
        .iter()
        .find(|s| s.name == law)
        .ok_or_else(|| IdentifyError::LawFormat {
            message: format!(
                "unknown law '{law}' (registry: {})",
                REGISTRY
                    .iter()
                    .map(|s| s.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        })
}

/// A named variable with its unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Variable {
    /// Name.
    pub name: String,
    /// SI unit.
    pub unit: String,
}

fn var(name: &str, unit: &str) -> Variable {
    Variable {
        name: name.into(),
        unit: unit.into(),
    }
}

/// A further output: `name = formula`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NamedFormula {
    /// Name.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Formula (`grainlaw-expr-1`).
    pub formula: String,
}

/// A `where` definition of the law's input from a solver's variables.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Definition {
    /// Defined name.
    pub name: String,
    /// Its unit.
    pub unit: String,
    /// Formula.
    pub formula: String,
    /// The solver's variables it uses.
    pub inputs: Vec<Variable>,
}

/// The machine-readable expression of a law.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Expression {
    /// The registry ([`REGISTRY_NAME`]).
    pub registry: String,
    /// The convention of the formulas ([`EXPRESSION_CONVENTION`]).
    pub convention: String,
    /// Independent variable of the formula (and of [`CalibratedLaw::evaluate`]).
    pub input: Variable,
    /// Value of the formula.
    pub output: Variable,
    /// `output = formula`.
    pub formula: String,
    /// Further outputs, in order (each may use the earlier ones).
    pub also: Vec<NamedFormula>,
    /// Definitions of the input from a solver's variables.
    #[serde(rename = "where")]
    pub definitions: Vec<Definition>,
}

impl Expression {
    fn of(spec: &LawSpec) -> Self {
        Expression {
            registry: REGISTRY_NAME.into(),
            convention: EXPRESSION_CONVENTION.into(),
            input: var(spec.input.0, spec.input.1),
            output: var(spec.output.0, spec.output.1),
            formula: spec.formula.into(),
            also: spec
                .also
                .iter()
                .map(|o| NamedFormula {
                    name: o.name.into(),
                    unit: o.unit.into(),
                    formula: o.formula.into(),
                })
                .collect(),
            definitions: spec
                .definitions
                .iter()
                .map(|d| Definition {
                    name: d.name.into(),
                    unit: d.unit.into(),
                    formula: d.formula.into(),
                    inputs: d.inputs.iter().map(|(n, u)| var(n, u)).collect(),
                })
                .collect(),
        }
    }
}

/// An angle's estimate in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Degrees {
    /// Value (°).
    pub value: f64,
    /// Standard error (°).
    pub std_error: f64,
    /// Lower end of the interval (°).
    pub ci_low: f64,
    /// Upper end of the interval (°).
    pub ci_high: f64,
}

/// One fitted parameter: its estimate (name, unit, value, standard error, interval,
/// `at_bound`), and for an angle (unit `rad`) the same in degrees.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LawParameter {
    /// The estimate; its name is a variable of the formula.
    #[serde(flatten)]
    pub estimate: Estimate,
    /// The same in degrees, for an angle (unit `rad`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deg: Option<Degrees>,
}

impl std::ops::Deref for LawParameter {
    type Target = Estimate;
    fn deref(&self) -> &Estimate {
        &self.estimate
    }
}

impl LawParameter {
    fn of(e: &Estimate) -> Self {
        let deg = (e.unit == "rad").then(|| {
            let k = 180.0 / std::f64::consts::PI;
            Degrees {
                value: e.value * k,
                std_error: e.std_error * k,
                ci_low: e.ci_low * k,
                ci_high: e.ci_high * k,
            }
        });
        LawParameter {
            estimate: e.clone(),
            deg,
        }
    }
}

/// A quantity derived from the parameters (delta-method interval), not a parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DerivedQuantity {
    /// The estimate (`at_bound` when it is fixed, e.g. the mobilisation 1 under full
    /// mobilisation).
    #[serde(flatten)]
    pub estimate: Estimate,
    /// Always true: this is not a fitted parameter.
    pub derived: bool,
    /// Its formula (`grainlaw-expr-1`) in the parameters and constants.
    pub formula: String,
}

impl std::ops::Deref for DerivedQuantity {
    type Target = Estimate;
    fn deref(&self) -> &Estimate {
        &self.estimate
    }
}

impl DerivedQuantity {
    fn of(name: &str, unit: &str, formula: &str, e: &Estimate) -> Self {
        DerivedQuantity {
            estimate: Estimate {
                name: name.to_string(),
                unit: unit.to_string(),
                ..e.clone()
            },
            derived: true,
            formula: formula.to_string(),
        }
    }
}

/// Covariance matrix of the parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Covariance {
    /// Parameter names, in row (and column) order.
    pub order: Vec<String>,
    /// The matrix, row-major.
    pub matrix: Vec<Vec<f64>>,
}

/// A constant of the set-up.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Constant {
    /// Name, as the formulas use it.
    pub name: String,
    /// SI unit.
    pub unit: String,
    /// Value.
    pub value: f64,
    /// What it is.
    pub description: String,
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

/// An input file and its SHA-256.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InputFile {
    /// Path as given.
    pub path: String,
    /// SHA-256 of its bytes, lowercase hex.
    pub sha256: String,
}

/// Where a calibrated law comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// Scenario name (`janssen`, `shear-cell`, ...) or `user-csv`.
    pub scenario: String,
    /// Every override of the scenario's or file's settings, as `key=value`.
    #[serde(default)]
    pub overrides: Vec<String>,
    /// Seed of the run, when there is one.
    pub seed: Option<u64>,
    /// grainlaw version.
    pub grainlaw_version: String,
    /// UTC date and time (ISO 8601), when recorded: `grainlaw fit` records the time of the fit,
    /// a scenario run the time it started (kept in its checkpoint, so that a resumed run writes
    /// the law an uninterrupted one would have); `SOURCE_DATE_EPOCH` overrides both
    /// ([`epoch_seconds`]).
    #[serde(default)]
    pub date: Option<String>,
    /// Input files with their SHA-256.
    #[serde(default)]
    pub inputs: Vec<InputFile>,
    /// Source file, when fitted from a file.
    #[serde(default)]
    pub source: Option<String>,
}

impl Provenance {
    /// Provenance for `scenario` and `seed`, with this build's version.
    pub fn new(scenario: &str, seed: Option<u64>) -> Self {
        Provenance {
            scenario: scenario.to_string(),
            overrides: Vec::new(),
            seed,
            grainlaw_version: GRAINLAW_VERSION.to_string(),
            date: None,
            inputs: Vec::new(),
            source: None,
        }
    }

    /// Records the overrides (`key=value`).
    pub fn with_overrides(mut self, overrides: Vec<String>) -> Self {
        self.overrides = overrides;
        self
    }

    /// Records now ([`epoch_seconds`]) as the date (UTC, `YYYY-MM-DDTHH:MM:SSZ`).
    pub fn with_date_now(mut self) -> Self {
        self.date = Some(utc_date(epoch_seconds()));
        self
    }

    /// Records an input file read as `bytes` with its SHA-256.
    pub fn with_input(mut self, path: &str, bytes: &[u8]) -> Self {
        self.inputs.push(InputFile {
            path: path.to_string(),
            sha256: sha256_hex(bytes),
        });
        self
    }
}

/// Environment variable that fixes the date recorded in provenances (seconds since
/// 1970-01-01T00:00:00Z), the reproducible-builds convention.
pub const SOURCE_DATE_EPOCH: &str = "SOURCE_DATE_EPOCH";

/// Seconds since the epoch to record as "now": the value of `SOURCE_DATE_EPOCH` when it is set
/// to an integer, else the system clock.
pub fn epoch_seconds() -> u64 {
    std::env::var(SOURCE_DATE_EPOCH)
        .ok()
        .and_then(|s| s.trim().parse::<u64>().ok())
        .unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs())
        })
}

/// SHA-256 of `bytes` as lowercase hex (FIPS 180-4).
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// `YYYY-MM-DDTHH:MM:SSZ` of `secs` seconds after 1970-01-01T00:00:00Z (proleptic Gregorian
/// calendar, days to civil date by H. Hinnant's algorithm).
pub fn utc_date(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// Grain constants a μ(I) or φ(I) law needs to turn `I = γ̇ d/√(P/ρ_s)` into a law of the shear
/// rate and the pressure.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GrainScale {
    /// Mean grain diameter `d` (m).
    pub diameter_m: f64,
    /// Grain material density `ρ_s` (kg/m³).
    pub density_kg_m3: f64,
}

/// A calibrated law, as written to JSON (schema 2; see the module documentation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibratedLaw {
    /// Schema version ([`SCHEMA_VERSION`]).
    pub schema_version: u32,
    /// Law name, a key of [`REGISTRY`].
    pub law: String,
    /// The law's expression.
    pub expression: Expression,
    /// Fitted parameters, in the registry's order; their names are variables of the formula.
    pub parameters: Vec<LawParameter>,
    /// Covariance of the parameters (absent only in a law read from schema 1).
    pub covariance: Option<Covariance>,
    /// Derived quantities (`"derived": true`).
    pub derived: Vec<DerivedQuantity>,
    /// Set-up constants; their names are variables of the formulas.
    pub constants: Vec<Constant>,
    /// [`DIMENSION`].
    pub dimension: String,
    /// The set-up the law assumes.
    pub geometry: String,
    /// Data range the law was calibrated on.
    pub validity: Vec<ValidityRange>,
    /// Fit summary.
    pub fit: FitSummary,
    /// AIC ranking when the law was chosen among candidates.
    #[serde(default)]
    pub model_selection: Option<ModelComparison>,
    /// Provenance.
    pub provenance: Provenance,
    /// Verdict of the law (`ok`, `suspect`, `refused`; `docs/outputs.md` §2.1): the `grainlaw
    /// run` that produced it judged it, or it was fitted by `grainlaw fit` or Python
    /// (`crate::user_fit`), which return only laws that passed every check: `ok`. Absent only
    /// from files written before verdicts existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verdict: Option<String>,
    /// The checks that failed for that verdict (`check`, `verdict`, `value`, `threshold`,
    /// `message`); absent when none did.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub verdict_reasons: Vec<serde_json::Value>,
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
    /// φ(I) = φ_max − a I.
    PhiI(PhiILaw),
    /// Mohr–Coulomb, shear strength `τ(σ_n)`.
    MohrCoulomb(MohrCoulombLaw),
    /// Critical state, `q(p)` (and `φ_c`).
    CriticalState(CriticalStateLaw),
    /// Stress–dilatancy, `sin φ_mob(sin ψ)`.
    StressDilatancy(StressDilatancyLaw),
}

impl Law {
    /// Evaluates the law at its input variable (see [`Expression::input`]).
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
            Law::CriticalState(l) => l.q(x),
            Law::StressDilatancy(l) => l.sin_phi(x),
        }
    }
}

impl CalibratedLaw {
    /// Builds a law of the registry from its estimates: `parameters` and `derived` by name (every
    /// name of the registry entry must be given), `constants` by name, the covariance from
    /// `report` (entries of a parameter not in the report, i.e. fixed, are 0).
    fn build(
        law: &str,
        parameters: &[&Estimate],
        derived: &[&Estimate],
        constants: &[(&str, f64)],
        report: &FitReport,
        provenance: Provenance,
    ) -> Self {
        let spec = law_spec(law).expect("a registry law");
        let order: Vec<String> = spec.parameters.iter().map(|p| p.0.to_string()).collect();
        let index = |name: &str| report.parameters.iter().position(|p| p.name == name);
        let matrix = order
            .iter()
            .map(|a| {
                order
                    .iter()
                    .map(|b| match (index(a), index(b)) {
                        (Some(i), Some(j)) => report.covariance[i][j],
                        _ => 0.0,
                    })
                    .collect()
            })
            .collect();
        CalibratedLaw {
            schema_version: SCHEMA_VERSION,
            law: law.into(),
            expression: Expression::of(spec),
            parameters: spec
                .parameters
                .iter()
                .filter_map(|(name, _)| parameters.iter().find(|e| e.name == *name))
                .map(|e| LawParameter::of(e))
                .collect(),
            covariance: Some(Covariance { order, matrix }),
            derived: spec
                .derived
                .iter()
                .zip(derived)
                .map(|((name, unit, formula), e)| DerivedQuantity::of(name, unit, formula, e))
                .collect(),
            constants: spec
                .constants
                .iter()
                .zip(constants)
                .map(|((name, unit, description), (_, value))| Constant {
                    name: name.to_string(),
                    unit: unit.to_string(),
                    value: *value,
                    description: description.to_string(),
                })
                .collect(),
            dimension: DIMENSION.into(),
            geometry: spec.geometry.into(),
            validity: report.validity.clone(),
            fit: FitSummary::of(report),
            model_selection: None,
            provenance,
            verdict: None,
            verdict_reasons: Vec::new(),
        }
    }

    /// From a joint (or full-mobilisation) Janssen fit: parameters `K`, `mu_w`; derived `K_mu_w`,
    /// `saturation_length`, `mobilisation`; constants `W`, `rho_b`, `g`, `mu_wall`.
    pub fn from_janssen(fit: &JanssenFit, provenance: Provenance) -> Self {
        Self::build(
            "janssen",
            &[&fit.k, &fit.mu_w],
            &[&fit.k_mu_w, &fit.saturation_length_m, &fit.mobilisation],
            &[
                ("W", fit.law.width_m),
                ("rho_b", fit.law.bulk_density_kg_m3),
                ("g", fit.law.gravity_m_s2),
                ("mu_wall", fit.wall_friction),
            ],
            &fit.report,
            provenance,
        )
    }

    /// From a one-parameter Janssen fit: parameter `K_mu_w`, derived `saturation_length`.
    pub fn from_janssen_k_mu(fit: &JanssenKMuFit, provenance: Provenance) -> Self {
        Self::build(
            "janssen-kmu",
            &[&fit.k_mu_w],
            &[&fit.saturation_length_m],
            &[
                ("W", fit.law.width_m),
                ("rho_b", fit.law.bulk_density_kg_m3),
                ("g", fit.law.gravity_m_s2),
            ],
            &fit.report,
            provenance,
        )
    }

    /// From a wall-law fit; `selection` is the AIC ranking it won, if any. Constants `d`, `g`
    /// (to turn `V_s` into `V = V_s/√(g d)`).
    pub fn from_wall_law(
        fit: &WallLawFit,
        grain_diameter_m: f64,
        gravity_m_s2: f64,
        selection: Option<ModelComparison>,
        provenance: Provenance,
    ) -> Self {
        let params: Vec<&Estimate> = fit.report.parameters.iter().collect();
        let mut law = Self::build(
            fit.form.law_name(),
            &params,
            &[],
            &[("d", grain_diameter_m), ("g", gravity_m_s2)],
            &fit.report,
            provenance,
        );
        law.model_selection = selection;
        law
    }

    /// From a boundary-layer fit (parameters `u_bulk`, `u_slip`, `delta`; derived
    /// `delta_over_d`).
    pub fn from_boundary_layer(
        fit: &BoundaryLayerFit,
        grain_diameter_m: f64,
        provenance: Provenance,
    ) -> Self {
        let params: Vec<&Estimate> = fit.report.parameters.iter().collect();
        Self::build(
            "boundary-layer",
            &params,
            &[&fit.thickness_diameters],
            &[("d", grain_diameter_m)],
            &fit.report,
            provenance,
        )
    }

    fn rheology(law: &str, report: &FitReport, grain: GrainScale, provenance: Provenance) -> Self {
        let params: Vec<&Estimate> = report.parameters.iter().collect();
        Self::build(
            law,
            &params,
            &[],
            &[("d", grain.diameter_m), ("rho_s", grain.density_kg_m3)],
            report,
            provenance,
        )
    }

    /// From a μ(I) fit (parameters `mu_s`, `mu_2`, `I_0`; constants `d`, `rho_s`).
    pub fn from_mu_i(fit: &MuIFit, grain: GrainScale, provenance: Provenance) -> Self {
        Self::rheology("mu-i", &fit.report, grain, provenance)
    }

    /// From a linear μ(I) fit (parameters `mu_s`, `b`; constants `d`, `rho_s`).
    pub fn from_mu_i_linear(fit: &LinearMuIFit, grain: GrainScale, provenance: Provenance) -> Self {
        Self::rheology("mu-i-linear", &fit.report, grain, provenance)
    }

    /// From a φ(I) fit (parameters `phi_max`, `a`; constants `d`, `rho_s`).
    pub fn from_phi_i(fit: &PhiIFit, grain: GrainScale, provenance: Provenance) -> Self {
        Self::rheology("phi-i", &fit.report, grain, provenance)
    }

    /// From a Mohr–Coulomb fit (parameters `friction_angle` (rad, with degrees), `cohesion`
    /// (Pa); derived `dp_alpha = sin φ`, `dp_k = c cos φ` of the 2D Drucker–Prager equivalent).
    pub fn from_mohr_coulomb(fit: &MohrCoulombFit, provenance: Provenance) -> Self {
        let alpha = fit
            .report
            .derived("dp_alpha", "1", |p| (p[0].sin(), vec![p[0].cos(), 0.0]));
        let mut k = fit.report.derived("dp_k", "Pa", |p| {
            (p[1] * p[0].cos(), vec![-p[1] * p[0].sin(), p[0].cos()])
        });
        k.at_bound = fit.cohesion.at_bound;
        Self::build(
            "mohr-coulomb",
            &[&fit.friction_angle, &fit.cohesion],
            &[&alpha, &k],
            &[],
            &fit.report,
            provenance,
        )
    }

    /// From a critical state (parameters `friction_angle_c` (rad, with degrees),
    /// `solid_fraction_c`; derived `M_c = sin φ_c`).
    pub fn from_critical_state(fit: &CriticalStateFit, provenance: Provenance) -> Self {
        let m = fit
            .report
            .derived("M_c", "1", |p| (p[0].sin(), vec![p[0].cos(), 0.0]));
        Self::build(
            "critical-state",
            &[&fit.friction_angle, &fit.solid_fraction],
            &[&m],
            &[],
            &fit.report,
            provenance,
        )
    }

    /// From a stress–dilatancy fit (parameters `sin_phi_c`, `beta`).
    pub fn from_stress_dilatancy(fit: &StressDilatancyFit, provenance: Provenance) -> Self {
        let params: Vec<&Estimate> = fit.report.parameters.iter().collect();
        Self::build(
            "stress-dilatancy",
            &params,
            &[],
            &[],
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
                width_m: c("W")?,
                bulk_density_kg_m3: c("rho_b")?,
                gravity_m_s2: c("g")?,
            }),
            "janssen-kmu" => Law::JanssenKMu(JanssenVerticalLaw {
                k_mu_w: p("K_mu_w")?,
                width_m: c("W")?,
                bulk_density_kg_m3: c("rho_b")?,
                gravity_m_s2: c("g")?,
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
                slope: p("a")?,
            }),
            "mohr-coulomb" => Law::MohrCoulomb(MohrCoulombLaw {
                friction_angle_rad: p("friction_angle")?,
                cohesion_pa: p("cohesion")?,
            }),
            "critical-state" => Law::CriticalState(CriticalStateLaw {
                friction_angle_rad: p("friction_angle_c")?,
                solid_fraction: p("solid_fraction_c")?,
            }),
            "stress-dilatancy" => Law::StressDilatancy(StressDilatancyLaw {
                sin_phi_c: p("sin_phi_c")?,
                beta: p("beta")?,
            }),
            other => return Err(law_spec(other).err().unwrap_or(unknown_law(other))),
        })
    }

    /// Evaluates the law at each `x` (its input variable, in its unit), vectorised:
    /// `[f(x₀), f(x₁), …]`.
    pub fn evaluate(&self, x: &[f64]) -> Result<Vec<f64>> {
        let law = self.to_law()?;
        Ok(x.iter().map(|&v| law.evaluate(v)).collect())
    }

    /// Evaluates the JSON's formula text at each `x` with the law's parameters and constants
    /// (parsed by [`crate::expr`]): what a solver reading only the expression computes.
    pub fn evaluate_formula(&self, x: &[f64]) -> Result<Vec<f64>> {
        let expr = Expr::parse(&self.expression.formula)?;
        let mut vars: BTreeMap<String, f64> = self
            .parameters
            .iter()
            .map(|p| (p.name.clone(), p.value))
            .chain(self.constants.iter().map(|c| (c.name.clone(), c.value)))
            .collect();
        x.iter()
            .map(|&v| {
                vars.insert(self.expression.input.name.clone(), v);
                expr.eval(&vars)
            })
            .collect()
    }

    /// The law's formula as C source (module [`crate::expr`], [`Expr::to_c`]): its input
    /// variable written `input` (a C expression of the calling code, e.g. `In`), every parameter
    /// and constant replaced by its value as a round-trip literal
    /// ([`crate::expr::c_literal`]). What a C solver (Gerris' `SourceViscosity`, a user
    /// function of another code) compiles to evaluate the law; it evaluates the same operations
    /// in the same order as [`CalibratedLaw::evaluate_formula`]. Errors:
    /// [`IdentifyError::LawFormat`] for a formula that does not parse or a variable with no
    /// value.
    pub fn formula_in_c(&self, input: &str) -> Result<String> {
        let expr = Expr::parse(&self.expression.formula)?;
        let values: BTreeMap<&str, f64> = self
            .parameters
            .iter()
            .map(|p| (p.name.as_str(), p.value))
            .chain(self.constants.iter().map(|c| (c.name.as_str(), c.value)))
            .collect();
        let input_name = self.expression.input.name.as_str();
        expr.to_c(&|n| {
            if n == input_name {
                Some(input.to_string())
            } else {
                values.get(n).map(|v| crate::expr::c_literal(*v))
            }
        })
    }

    /// The same law with the parameter values `values` (in the order of the covariance, i.e.
    /// the registry's, [`CalibratedLaw::parameters`]), e.g. a draw from its covariance;
    /// intervals and standard errors are kept as they are. Errors:
    /// [`IdentifyError::LawFormat`] when the number of values differs from the parameters'.
    pub fn with_parameter_values(&self, values: &[f64]) -> Result<Self> {
        if values.len() != self.parameters.len() {
            return Err(IdentifyError::LawFormat {
                message: format!(
                    "law '{}': {} parameter values given for {} parameters",
                    self.law,
                    values.len(),
                    self.parameters.len()
                ),
            });
        }
        let mut law = self.clone();
        for (p, v) in law.parameters.iter_mut().zip(values) {
            p.estimate.value = *v;
        }
        Ok(law)
    }

    /// True when `x` lies inside the validity range of the law's input variable (true when
    /// the range of that variable is not recorded).
    pub fn in_validity_range(&self, x: f64) -> bool {
        self.validity
            .iter()
            .find(|v| v.variable == self.expression.input.name)
            .is_none_or(|v| v.contains(x))
    }

    /// Pretty JSON.
    pub fn to_json_string(&self) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| IdentifyError::LawFormat {
            message: e.to_string(),
        })
    }

    /// Parses JSON of schema version 1 or 2 ([`IdentifyError::UnsupportedSchema`] otherwise):
    /// version 2 is checked against the registry ([`CalibratedLaw::check`]), version 1 is
    /// upgraded (module documentation); then the law must be buildable
    /// ([`CalibratedLaw::to_law`]).
    pub fn from_json_str(text: &str) -> Result<Self> {
        let value: serde_json::Value = serde_json::from_str(text).map_err(format_error)?;
        let version = value
            .get("schema_version")
            .and_then(|v| v.as_u64())
            .ok_or_else(|| IdentifyError::LawFormat {
                message: "missing or non-integer 'schema_version'".into(),
            })?;
        let law = match version {
            1 => serde_json::from_value::<LawV1>(value)
                .map_err(format_error)?
                .upgrade()?,
            2 => {
                let mut law: CalibratedLaw = serde_json::from_value(value).map_err(format_error)?;
                // `phi-i-linear` was merged into `phi-i` (the same line, same parameters)
                if law.law == "phi-i-linear" {
                    law.law = "phi-i".into();
                }
                if law.law == "phi-i" && law.parameters.iter().any(|p| p.name == "phi_min") {
                    return Err(IdentifyError::LawFormat {
                        message: "law 'phi-i' with parameter 'phi_min': the former form φ_max − (φ_max − φ_min) I; phi-i is now φ_max − a I (parameters phi_max, a): fit it again (grainlaw fit phi-i)".into(),
                    });
                }
                law.check()?;
                law
            }
            other => {
                return Err(IdentifyError::UnsupportedSchema {
                    found: other.min(u32::MAX as u64) as u32,
                    supported: SCHEMA_VERSION,
                })
            }
        };
        law.to_law()?;
        Ok(law)
    }

    /// Checks a schema-2 law against its registry entry: the same formulas, exactly the
    /// registry's parameters and constants, a covariance of matching size, the variable names
    /// of the formulas exactly the input, outputs, `where` names and inputs, parameters and
    /// constants. Errors: [`IdentifyError::LawFormat`].
    pub fn check(&self) -> Result<()> {
        let spec = law_spec(&self.law)?;
        let fail = |message: String| Err(IdentifyError::LawFormat { message });
        if self.expression != Expression::of(spec) {
            return fail(format!(
                "law '{}': the expression differs from the registry's ({})",
                self.law, spec.formula
            ));
        }
        let keys = |names: Vec<&str>| {
            let mut v: Vec<String> = names.into_iter().map(String::from).collect();
            v.sort();
            v
        };
        let want_p = keys(spec.parameters.iter().map(|p| p.0).collect());
        let have_p = keys(self.parameters.iter().map(|p| p.name.as_str()).collect());
        if want_p != have_p {
            return fail(format!(
                "law '{}': parameters {have_p:?}, the registry has {want_p:?}",
                self.law
            ));
        }
        let want_c = keys(spec.constants.iter().map(|c| c.0).collect());
        let have_c = keys(self.constants.iter().map(|c| c.name.as_str()).collect());
        if want_c != have_c {
            return fail(format!(
                "law '{}': constants {have_c:?}, the registry has {want_c:?}",
                self.law
            ));
        }
        if let Some(c) = &self.covariance {
            let mut order = c.order.clone();
            order.sort();
            if order != want_p || c.matrix.len() != order.len() {
                return fail(format!(
                    "law '{}': covariance over {:?}, not the parameters",
                    self.law, c.order
                ));
            }
            if c.matrix.iter().any(|r| r.len() != order.len()) {
                return fail(format!("law '{}': covariance is not square", self.law));
            }
        }
        check_variable_names(spec)
    }

    /// Writes pretty JSON to `path`.
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = self.to_json_string()?;
        std::fs::write(path, text + "\n").map_err(|source| IdentifyError::Io {
            path: path.display().to_string(),
            source,
        })
    }

    /// Reads and checks a law from `path` (schema 1 or 2).
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| IdentifyError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_json_str(&text)
    }
}

fn format_error(e: serde_json::Error) -> IdentifyError {
    IdentifyError::LawFormat {
        message: e.to_string(),
    }
}

fn unknown_law(law: &str) -> IdentifyError {
    IdentifyError::LawFormat {
        message: format!("unknown law '{law}'"),
    }
}

/// Checks that the names used by the formulas of `spec` are exactly its input, its outputs, its
/// `where` names and inputs, its parameters and its constants, each used at least once (except
/// the outputs, which need not be reused).
pub fn check_variable_names(spec: &LawSpec) -> Result<()> {
    let mut used = Vec::new();
    let formulas = std::iter::once(spec.formula)
        .chain(spec.also.iter().map(|o| o.formula))
        .chain(spec.definitions.iter().map(|d| d.formula))
        .chain(spec.derived.iter().map(|d| d.2));
    for f in formulas {
        used.extend(Expr::parse(f)?.variables());
    }
    used.sort();
    used.dedup();
    let mut must: Vec<&str> = vec![spec.input.0];
    must.extend(spec.parameters.iter().map(|p| p.0));
    must.extend(spec.constants.iter().map(|c| c.0));
    must.extend(
        spec.definitions
            .iter()
            .flat_map(|d| d.inputs.iter().map(|i| i.0)),
    );
    let mut may: Vec<&str> = vec![spec.output.0];
    may.extend(spec.also.iter().map(|o| o.name));
    let fail = |message: String| Err(IdentifyError::LawFormat { message });
    if let Some(u) = used
        .iter()
        .find(|u| !must.contains(&u.as_str()) && !may.contains(&u.as_str()))
    {
        return fail(format!(
            "law '{}': formula variable '{u}' is neither the input, a parameter nor a constant",
            spec.name
        ));
    }
    if let Some(m) = must.iter().find(|m| !used.iter().any(|u| u == *m)) {
        return fail(format!(
            "law '{}': '{m}' is not used by any formula",
            spec.name
        ));
    }
    Ok(())
}

/// The schema-2 name of a schema-1 constant.
fn v1_constant_name(name: &str) -> &str {
    match name {
        "width" => "W",
        "bulk_density" => "rho_b",
        "gravity" => "g",
        "wall_friction" => "mu_wall",
        "grain_diameter" => "d",
        other => other,
    }
}

/// Schema 1 (read only).
#[derive(Deserialize)]
struct LawV1 {
    law: String,
    parameters: Vec<Estimate>,
    constants: Vec<ConstantV1>,
    validity: Vec<ValidityRange>,
    fit: FitSummary,
    #[serde(default)]
    model_selection: Option<ModelComparison>,
    provenance: ProvenanceV1,
}

#[derive(Deserialize)]
struct ConstantV1 {
    name: String,
    value: f64,
}

#[derive(Deserialize)]
struct ProvenanceV1 {
    scenario: String,
    seed: Option<u64>,
    grainlaw_version: String,
    #[serde(default)]
    source: Option<String>,
}

impl LawV1 {
    /// The schema-2 form: constants renamed to the registry's (`width` → `W`, `bulk_density` →
    /// `rho_b`, `gravity` → `g`, `wall_friction` → `mu_wall`, `grain_diameter` → `d`), parameters
    /// not in the registry entry (`K_mu_w` of `janssen`) moved to `derived`, no covariance.
    fn upgrade(self) -> Result<CalibratedLaw> {
        let spec = law_spec(&self.law)?;
        let mut parameters = Vec::new();
        let mut derived = Vec::new();
        for e in &self.parameters {
            if spec.parameters.iter().any(|p| p.0 == e.name) {
                parameters.push(LawParameter::of(e));
            } else if let Some((name, unit, formula)) =
                spec.derived.iter().find(|d| d.0 == e.name.as_str())
            {
                derived.push(DerivedQuantity::of(name, unit, formula, e));
            }
        }
        let constants = self
            .constants
            .iter()
            .filter_map(|c| {
                let name = v1_constant_name(&c.name);
                spec.constants
                    .iter()
                    .find(|s| s.0 == name)
                    .map(|(n, unit, description)| Constant {
                        name: n.to_string(),
                        unit: unit.to_string(),
                        value: c.value,
                        description: description.to_string(),
                    })
            })
            .collect();
        Ok(CalibratedLaw {
            schema_version: 1,
            law: self.law,
            expression: Expression::of(spec),
            parameters,
            covariance: None,
            derived,
            constants,
            dimension: DIMENSION.into(),
            geometry: spec.geometry.into(),
            validity: self.validity,
            fit: self.fit,
            model_selection: self.model_selection,
            provenance: Provenance {
                scenario: self.provenance.scenario,
                overrides: Vec::new(),
                seed: self.provenance.seed,
                grainlaw_version: self.provenance.grainlaw_version,
                date: None,
                inputs: Vec::new(),
                source: self.provenance.source,
            },
            verdict: None,
            verdict_reasons: Vec::new(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_registry_formula_parses_and_uses_exactly_its_variables() {
        for spec in REGISTRY {
            check_variable_names(spec).unwrap();
        }
    }

    #[test]
    fn dates_and_digests() {
        assert_eq!(utc_date(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc_date(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc_date(1_700_000_000), "2023-11-14T22:13:20Z");
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
