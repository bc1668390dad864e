//! # grainlaw-core — the scenarios and everything a run needs, without a command line
//!
//! One run of one of the paper's experiments end to end: simulation ([`dem`]), homogenisation
//! ([`homogenise`]), identification ([`identify`]), figures ([`plot`]), CSV, VTK and `summary.json`
//! ([`output`]), the verdict ([`verdict`]). The one list of scenarios is [`scenarios::registry`];
//! each scenario is one folder of [`scenarios`] (its config, world, runner, measures, fits and
//! figures), the phase loop [`scenarios::phases`], the loader [`scenarios::loader`]; the built-in
//! TOML files and the packing generators are data, in [`datasets`]; the benchmark worlds in
//! [`benchmarks`]; readers of other codes' outputs in [`readers`]; campaigns of runs in
//! [`campaign`]; the library API in [`api`].
//!
//! The command line (`grainlaw`, the root package: argument parsing and printing) and the
//! Python bindings (`python/`) are two thin layers over this crate; it depends on neither.

pub mod api;
pub mod benchmarks;
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
