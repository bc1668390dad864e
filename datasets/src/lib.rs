//! # datasets — grainlaw's data and the tools that make data
//!
//! - `scenarios/*.toml`: the built-in scenarios' TOML files (`janssen`, the default;
//!   `rolling`, `arrangements`, `stick-slip`, `inclined-flow`, `shear-cell`, `simple-shear`,
//!   `biaxial`, `column-collapse`), embedded in the binary by the scenario registry
//!   (`grainlaw_core::scenarios::registry`), the one list of scenarios; their typed
//!   configurations, worlds and runners are in `grainlaw-core/src/scenarios/NAME/`;
//! - `campaigns/*.toml`, `reference/` (published curves compared with), `fc-problems/`
//!   (frictional-contact problems of the solver benchmarks), `external/` (the input decks of
//!   the peer codes);
//! - [`generators`]: seeded polydisperse radii, grains rained without overlap, regular stacks
//!   (rectangular, triangular, cannonball), dense packings by deposition, spatial ordering;
//! - [`overrides`]: `--set KEY=VALUE` applied on a TOML table;
//! - [`limits`]: the ranges every scenario value is checked against;
//! - [`error`]: [`DatasetError`], the one-line errors of loading a scenario, checking its values
//!   and generating its grains (each names the key, file or line at fault).
//!
//! Units: SI throughout (m, kg, s, N, Pa). Every generator takes a seeded generator; the same
//! seed gives the same numbers.

pub mod error;
pub mod generators;
pub mod limits;
pub mod overrides;

pub use error::{DatasetError, Result};
