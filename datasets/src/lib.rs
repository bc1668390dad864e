//! # datasets — the paper's experiments as scenarios, and packing generators
//!
//! - `scenarios/*.toml`: the built-in scenarios' TOML files (`janssen`, the default;
//!   `rolling`, `arrangements`, `stick-slip`, `inclined-flow`, `shear-cell`, `simple-shear`,
//!   `biaxial`, `column-collapse`), embedded in the binary by the root package's registry
//!   (`grainlaw::scenarios::registry`), the one list of scenarios;
//! - [`scenario`]: loading a built-in or a TOML path, `--set KEY=VALUE` overrides
//!   ([`overrides`]) applied on the TOML table, typed deserialisation with unknown keys refused
//!   and validation that names the key at fault ([`config`]), through a [`Catalogue`] of kinds;
//!   [`ScenarioConfig`], what every kind's config says ([`kinds`]);
//! - [`generators`]: seeded polydisperse radii, grains rained without overlap, regular stacks
//!   (rectangular, triangular, cannonball);
//! - [`build`]: the worlds of the scenarios (named walls, grains, contact laws);
//! - [`phases`]: running a world to rest or for a number of steps while counting what the
//!   contact solver did.
//!
//! Units: SI throughout (m, kg, s, N, Pa). Every scenario has a `seed`; the same seed gives the
//! same numbers.

pub mod benchmarks;
pub mod build;
pub mod build_cell;
pub mod config;
pub mod error;
pub mod generators;
pub mod kinds;
pub mod limits;
pub mod overrides;
pub mod phases;
pub mod scenario;

pub use error::{DatasetError, Result};
pub use scenario::{Catalogue, LoadedScenario, ScenarioConfig};
