//! # grainlaw — the command line
//!
//! `grainlaw run [SCENARIO]` runs one of the paper's experiments end to end. This package is
//! the command line only: argument parsing and the commands' printing ([`cli`], the tables of
//! [`bench_cmd`] and [`fc_cmd`]). Everything it runs is in the library crate
//! [`grainlaw_core`] (scenarios, readers, verdicts, campaigns, plots), re-exported here so that
//! `grainlaw::scenarios`, `grainlaw::api`, … name the same items.

pub use grainlaw_core::*;

pub mod bench_cmd;
pub mod cli;
pub mod fc_cmd;
