//! # identify — calibrated continuum laws from homogenised granular data
//!
//! Fits the laws of `docs/physics.md` §3 to homogenised DEM histories or to a user's CSV, with
//! uncertainty, and exports them as versioned JSON for continuum solvers.
//!
//! | module | holds |
//! |---|---|
//! | [`error`] | [`IdentifyError`], every way identification fails |
//! | [`accept`] | the checks a fit passes before a law is exported (scales, physical ranges, R², nested form) |
//! | [`stats`] | Student-t quantile, AIC/BIC, Akaike weights |
//! | [`report`] | [`FitReport`], [`Estimate`], [`ValidityRange`], [`ModelComparison`] (data) |
//! | [`lm`] | box-constrained Levenberg–Marquardt as an argmin solver |
//! | [`fit`] | generic weighted nonlinear least squares with covariance, intervals, bootstrap |
//! | [`laws`] | the closed-form laws (Janssen, μ(I), φ(I), wall laws, velocity boundary layer, Mohr–Coulomb) |
//! | [`janssen`] | Janssen profile data and its joint `(K, μ_w)` and one-parameter `K μ_w` fits |
//! | [`wall_law`] | wall friction vs slip velocity (model choice by AIC), boundary-layer thickness |
//! | [`mu_i`] | μ(I), φ(I) and their linear forms |
//! | [`mohr_coulomb`] | Mohr–Coulomb envelope from stress states at yield (conic program, Clarabel) |
//! | [`critical_state`] | critical state (plateau means over pressures) and stress–dilatancy of a biaxial test |
//! | [`law`] | calibrated-law JSON (schema 2, the law registry, loader of schemas 1 and 2, evaluation) |
//! | [`expr`] | the expression convention of the law formulas (parser, evaluator) |
//! | [`continuum`] | closing the loop: Janssen ODE (RK4), Bagnold profile on a slope |
//! | [`data`] | user tables read from CSV with typed, line-numbered errors |
//! | [`user_fit`] | fitting a law by name from a CSV file |
//!
//! Example: a Janssen fit, its summary keys and its export.
//! ```
//! use identify::janssen::{fit_janssen, JanssenOptions, JanssenProfile, JanssenSetup};
//! use identify::law::{CalibratedLaw, Provenance};
//! use identify::laws::JanssenLaw;
//!
//! let setup = JanssenSetup::new(0.03, 1600.0, 0.25); // W (m), ρ_b (kg/m³), μ_wall
//! let truth = JanssenLaw { k: 0.6, mu_w: 0.2, width_m: 0.03, bulk_density_kg_m3: 1600.0, gravity_m_s2: 9.81 };
//! let z: Vec<f64> = (1..=20).map(|i| 0.01 * i as f64).collect();
//! let wiggle = |i: usize| if i % 2 == 0 { 1.0 } else { -1.0 };
//! let profile = JanssenProfile {
//!     sigma_v_pa: z.iter().enumerate().map(|(i, z)| truth.sigma_v(*z) + 5.0 * wiggle(i)).collect(),
//!     sigma_h_pa: Some(z.iter().enumerate().map(|(i, z)| truth.sigma_h(*z) - 3.0 * wiggle(i)).collect()),
//!     tau_w_pa: None,
//!     z_m: z,
//! };
//! let fit = fit_janssen(&profile, &setup, &JanssenOptions::default())?;
//! assert!((fit.k.value - 0.6).abs() < 0.02);
//! let keys = fit.summary_entries(); // janssen_K, janssen_K_ci_low, ...
//! assert_eq!(keys[0].0, "janssen_K");
//! let json = CalibratedLaw::from_janssen(&fit, Provenance::new("janssen", Some(1))).to_json_string()?;
//! let law = CalibratedLaw::from_json_str(&json)?;
//! assert!((law.evaluate(&[0.1])?[0] - fit.law.sigma_v(0.1)).abs() < 1e-9);
//! # Ok::<(), identify::IdentifyError>(())
//! ```
//!
//! Units: SI throughout. Stresses entering the fits are compressive-positive magnitudes
//! (pressure-like): with the project's tension-positive tensors, `σ_v = −Σ_yy`, `p = −tr Σ / 2`.

pub mod accept;
pub mod continuum;
pub mod critical_state;
pub mod data;
pub mod error;
pub mod expr;
pub mod fit;
pub mod janssen;
pub mod law;
pub mod laws;
pub mod lm;
pub mod mohr_coulomb;
pub mod mu_i;
pub mod report;
pub mod stats;
pub mod user_fit;
pub mod wall_law;

pub use error::{IdentifyError, Result};
pub use fit::{BootstrapOptions, FitOptions};
pub use law::CalibratedLaw;
pub use report::{Estimate, FitReport, ModelComparison, ValidityRange};
