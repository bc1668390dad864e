//! # grainlaw — the command line and its pieces
//!
//! `grainlaw run [SCENARIO]` runs one of the paper's experiments end to end: simulation
//! ([`dem`]), homogenisation ([`homogenise`]), identification ([`identify`]), figures
//! ([`plot`]), CSV, VTK and `summary.json` ([`output`]). The scenarios and generators are in
//! [`datasets`]; the runners in [`scenarios`]; the command line in [`cli`].

pub mod api;
pub mod bench_cmd;
pub mod campaign;
pub mod checkpoint;
pub mod cli;
pub mod continuum;
pub mod engine_bench;
pub mod error;
pub mod fc_bench;
pub mod fc_cmd;
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
