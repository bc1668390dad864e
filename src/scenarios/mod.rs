//! Running a scenario end to end: simulation phases with progress, homogenisation, fits,
//! figures, CSV, VTK and `summary.json` (written last). Every runner is a [`phased::PhasedRun`]:
//! its simulation can be checkpointed, stopped and resumed ([`run_controlled`]).

pub mod arrangements;
pub mod biaxial;
pub mod cell_base;
pub mod column_collapse;
pub mod common;
pub mod dump;
pub mod inclined_flow;
pub mod janssen;
pub mod phased;
pub mod rheology_fit;
pub mod rolling;
pub mod rows;
pub mod sensitivity;
pub mod shear_cell;
pub mod simple_shear;
pub mod stick_slip;

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use datasets::{LoadedScenario, Scenario};

use crate::error::Result;
use crate::output::{OutputDir, Summary};
use crate::progress::Verbosity;
pub use phased::{CheckpointPolicy, PhaseTime, RunControl};

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

/// One line per law the plan leaves out (`leave_out`, `datasets::config::laws`): its name,
/// and the data the plan has against what it needs.
pub fn left_out_lines(scenario: &Scenario) -> Vec<String> {
    let needs = scenario.law_needs();
    scenario
        .leave_out()
        .iter()
        .map(|law| {
            let why = needs
                .iter()
                .find(|n| n.law == law)
                .and_then(|n| {
                    n.have.map(|h| {
                        format!(
                            " (this plan has {h} {}; it needs at least {})",
                            n.key, n.needs
                        )
                    })
                })
                .unwrap_or_default();
            format!("{law} left out by the plan (leave_out): it is not fitted, no law file{why}")
        })
        .collect()
}

/// Runs the loaded scenario, writes every output and `summary.json` last, with the default
/// checkpoint policy ([`run_controlled`] with [`RunControl::default`]).
pub fn run(ctx: &mut RunContext) -> Result<RunOutcome> {
    run_controlled(ctx, &mut RunControl::default())
}

/// Runs the loaded scenario under `ctl`: a new run removes a stale checkpoint directory first;
/// with `ctl.resume` the run continues from the checkpoint in the output directory. Checkpoints
/// are written as `ctl.policy` says and when the user stops the run; `summary.json` is written
/// last, then the checkpoint directory is removed.
pub fn run_controlled(ctx: &mut RunContext, ctl: &mut RunControl) -> Result<RunOutcome> {
    if !ctl.resume && crate::checkpoint::file_of(ctx.out.path()).exists() {
        crate::progress::warn(&format!(
            "{}: removed the checkpoint of an earlier, interrupted run (a new run starts here; `--resume` continues one)",
            ctx.out.path().display()
        ));
    }
    if !ctl.resume {
        crate::checkpoint::remove(ctx.out.path())?;
        ctl.origin = crate::provenance::RunOrigin::now(&ctx.loaded);
    }
    ctx.out
        .write("scenario.toml", ctx.loaded.effective_toml.as_bytes())?;
    let scenario = ctx.loaded.scenario.clone();
    // said at the start: what the plan leaves out, and why it could not have had it
    for line in left_out_lines(&scenario) {
        crate::progress::note(&line);
    }
    // said at the start: how long the plan is, in steps
    if let Scenario::SimpleShear(c) = &scenario {
        let (compression, runs) = c.planned_steps();
        let total = compression + runs.iter().sum::<u64>();
        crate::progress::note(&format!(
            "plan: about {total} time steps (compression {compression}; {}), bound max_steps = {}",
            c.inertial_numbers
                .iter()
                .zip(&runs)
                .map(|(i, n)| format!("I = {i}: {n}"))
                .collect::<Vec<_>>()
                .join(", "),
            c.max_steps
        ));
    }
    let mut outcome = match &scenario {
        Scenario::Janssen(c) => janssen::run(c, ctx, ctl)?,
        Scenario::Rolling(c) => rolling::run(c, ctx, ctl)?,
        Scenario::Arrangements(c) => arrangements::run(c, ctx, ctl)?,
        Scenario::StickSlip(c) => stick_slip::run(c, ctx, ctl)?,
        Scenario::InclinedFlow(c) => inclined_flow::run(c, ctx, ctl)?,
        Scenario::ShearCell(c) => shear_cell::run(c, ctx, ctl)?,
        Scenario::SimpleShear(c) => simple_shear::run(c, ctx, ctl)?,
        Scenario::Biaxial(c) => biaxial::run(c, ctx, ctl)?,
        Scenario::ColumnCollapse(c) => column_collapse::run(c, ctx, ctl)?,
    };
    let mut head = Summary::new();
    head.text("scenario", scenario.kind())
        .text("source", &ctx.loaded.source)
        .int("seed", scenario.seed());
    let mut summary = head;
    for (k, v) in outcome.summary.entries() {
        summary.set(k, v.clone());
    }
    outcome.verdict.allow_suspect = ctl.allow_suspect;
    outcome.verdict.keys(&mut summary);
    summary.set(
        "laws_left_out",
        serde_json::Value::from(scenario.leave_out().to_vec()),
    );
    summary.num("wall_seconds", ctl.wall_seconds());
    summary.text("grainlaw_version", env!("CARGO_PKG_VERSION"));
    ctx.out
        .write("summary.json", summary.to_json().as_bytes())?;
    crate::checkpoint::remove(ctx.out.path())?;
    outcome.summary = summary;
    Ok(outcome)
}
