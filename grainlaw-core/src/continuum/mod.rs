//! Closing the loop in a real continuum solver: a calibrated μ(I) law (the `mu_i_law.json` of
//! a simple-shear or shear-cell run, schema 2) written into a Gerris case, run, read back and
//! compared with DEM (`grainlaw continuum`, `docs/continuum.md`).
//!
//! - [`rheology`]: the law in Gerris' dimensionless units, the inertial number
//!   `I = I_Gerris/√φ`, the regularised viscosity as C source;
//! - [`gfs`]: the `.gfs` files of the column collapse and of the inclined plane;
//! - [`gerris`]: running `gerris2D` (missing or failing: exit 3, the case left in place);
//! - [`snapshot`]: Gerris' text snapshots, the height profile and front of the VOF tracer;
//! - [`dem_column`]: the DEM `column-collapse` run's `summary.json`, `front.csv`, `profiles.csv`;
//! - [`column`](mod@column): the column collapse end to end, its comparison with DEM, its figures;
//! - [`band`]: the law's covariance carried through the run;
//! - [`inclined`]: steady flow down a slope against Bagnold's profile and DEM;
//! - [`inputs`]: what both cases take (law, output, DEM run, φ, Gerris resolution and command).

pub mod band;
pub mod column;
pub mod dem_column;
pub mod gerris;
pub mod gfs;
pub mod inclined;
pub mod inputs;
pub mod rheology;
pub mod snapshot;

pub use column::{column_collapse, ColumnOutcome, ColumnPlan};
pub use inclined::{inclined_plane, InclinedOutcome, InclinedPlan};
pub use inputs::CaseInputs;
