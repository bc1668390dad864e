//! # identify — calibrated continuum laws from homogenised granular data
//!
//! Fits the laws of `DESIGN.md` §3 to homogenised DEM histories or to a user's CSV, with
//! uncertainty, and exports them as versioned JSON for continuum solvers.
//!
//! | module | holds |
//! |---|---|
//! | [`error`] | [`IdentifyError`], every way identification fails |
//! | [`stats`] | Student-t quantile, AIC/BIC, Akaike weights |
//! | [`report`] | [`FitReport`], [`Estimate`], [`ValidityRange`], [`ModelComparison`] (data) |
//! | [`lm`] | box-constrained Levenberg–Marquardt as an argmin solver |
//! | [`fit`] | generic weighted nonlinear least squares with covariance, intervals, bootstrap |
//! | [`laws`] | the closed-form laws (Janssen, μ(I), φ(I), wall laws, velocity boundary layer, Mohr–Coulomb) |
//! | [`janssen`] | Janssen profile data and its joint `(K, μ_w)` and one-parameter `K μ_w` fits |
//! | [`wall_law`] | wall friction vs slip velocity (model choice by AIC), boundary-layer thickness |
//! | [`mu_i`] | μ(I), φ(I) and their linear forms |
//! | [`mohr_coulomb`] | Mohr–Coulomb envelope from stress states at yield (conic program, Clarabel) |
//! | [`law`] | calibrated-law JSON (schema, loader, evaluation) |
//! | [`continuum`] | closing the loop: Janssen ODE (RK4), Bagnold profile on a slope |
//! | [`data`] | user tables read from CSV with typed, line-numbered errors |
//! | [`user_fit`] | fitting a law by name from a CSV file |
//!
//! Units: SI throughout. Stresses entering the fits are compressive-positive magnitudes
//! (pressure-like): with the project's tension-positive tensors, `σ_v = −Σ_yy`, `p = −tr Σ / 2`.

pub mod continuum;
pub mod data;
pub mod error;
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
