//! Running a scenario end to end: simulation phases with progress, homogenisation, fits,
//! figures, CSV, VTK and `summary.json` (written last). The scenarios are listed once, in
//! [`registry`] ([`registry::SCENARIOS`]), which loads them ([`loader`]) and runs them
//! ([`run_controlled`]). Every runner is a [`phased::PhasedRun`]: its simulation can be
//! checkpointed, stopped and resumed; its phases run the world to rest or for a number of steps
//! ([`phases`]).
//!
//! One folder per scenario (`janssen/`, `rolling/`, `arrangements/`, `stick_slip/`,
//! `inclined_flow/`, `shear_cell/`, `simple_shear/`, `biaxial/`, `column_collapse/`): `mod.rs`
//! the runner and its kind's [`loader::ScenarioConfig`], `config.rs` its typed configuration
//! (`deny_unknown_fields`, `validate`), `build.rs` its world (`janssen` and `stick-slip` build
//! the shared rained column of `common::build`), and its measure, fit and figure files where it
//! has them. What several share is in [`common`] (config pieces, laws, deposits, world
//! pieces, the runner's phase helpers), [`cell_base`], [`rows`], [`rheology_fit`] and
//! [`sensitivity`].

pub mod arrangements;
pub mod biaxial;
pub mod cell_base;
pub mod column_collapse;
pub mod common;
pub mod dump;
pub mod inclined_flow;
pub mod janssen;
pub mod loader;
pub mod phased;
pub mod phases;
pub mod registry;
pub mod rheology_fit;
pub mod rolling;
pub mod rows;
pub mod sensitivity;
pub mod shear_cell;
pub mod simple_shear;
pub mod stick_slip;

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use crate::scenarios::loader::LoadedScenario;

use crate::output::{OutputDir, Summary};
use crate::progress::Verbosity;
pub use phased::{CheckpointPolicy, PhaseTime, RunControl};
pub use registry::{left_out_lines, run, run_controlled, Scenario};

/// What a scenario run gets.
pub struct RunContext {
    /// Where the files go.
    pub out: OutputDir,
    /// How much to print.
    pub verbosity: Verbosity,
    /// The scenario as loaded.
    pub loaded: LoadedScenario,
    /// Set by Ctrl-C: the run writes a checkpoint and stops without writing `summary.json`.
    pub interrupted: Arc<AtomicBool>,
    /// Contact problems to write (`--dump-problems`).
    pub dump: Option<Arc<dump::ProblemDump>>,
}

/// What a running phase needs from the context (cheap to clone, so that step callbacks may
/// borrow the output directory mutably).
#[derive(Clone)]
pub struct PhaseEnv {
    /// How much to print.
    pub verbosity: Verbosity,
    /// Set by Ctrl-C.
    pub interrupted: Arc<AtomicBool>,
    /// Contact problems to write (`--dump-problems`).
    pub dump: Option<Arc<dump::ProblemDump>>,
}

impl RunContext {
    /// The phase environment.
    pub fn env(&self) -> PhaseEnv {
        PhaseEnv {
            verbosity: self.verbosity,
            interrupted: self.interrupted.clone(),
            dump: self.dump.clone(),
        }
    }
}

/// What a scenario run returns: the summary and the lines printed at the end.
pub struct RunOutcome {
    /// Key results (written to `summary.json` by [`run`]).
    pub summary: Summary,
    /// Headline lines for the terminal (where the report is, key numbers).
    pub headline: Vec<String>,
    /// The verdict of the run and of its laws ([`crate::verdict`]).
    pub verdict: crate::verdict::RunVerdict,
}

impl RunOutcome {
    /// The outcome of a run that exports no law: its summary, headline and own checks.
    pub fn without_laws(
        summary: Summary,
        headline: Vec<String>,
        checks: crate::verdict::Checks,
    ) -> Self {
        RunOutcome {
            summary,
            headline,
            verdict: crate::verdict::RunVerdict {
                run: checks,
                ..Default::default()
            },
        }
    }
}
