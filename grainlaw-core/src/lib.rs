//! # grainlaw-core — the scenarios and everything a run needs, without a command line
//!
//! One run of one of the paper's experiments end to end: simulation ([`dem`]),
//! homogenisation ([`homogenise`]), identification ([`identify`]), figures ([`plot`]), CSV,
//! VTK and `summary.json` ([`output`]), the verdict ([`verdict`]). The scenarios' configs and
//! generators are in [`datasets`]; the one list of scenarios and their runners in
//! [`scenarios`] ([`scenarios::registry`]); readers of other codes' outputs in [`readers`];
//! campaigns of runs in [`campaign`]; the library API in [`api`].
//!
//! The command line (`grainlaw`, the root package: argument parsing and printing) and the
//! Python bindings (`python/`) are two thin layers over this crate; it depends on neither.

pub mod api;
pub mod campaign;
pub mod checkpoint;
pub mod continuum;
pub mod engine_bench;
pub mod error;
pub mod fc_bench;
pub mod fit_cmd;
pub mod floats;
pub mod homogenise_cmd;
pub mod lammps_peer;
pub mod lammps_rve_peer;
pub mod output;
pub mod plot;
pub mod progress;
pub mod provenance;
pub mod readers;
pub mod rve;
pub mod scenarios;
pub mod siconos_peer;
pub mod verdict;

pub use error::{CliError, Result};
