//! A scenario's simulation as a sequence of phases over a world, whose every step-by-step
//! accumulator lives in one serialisable state: the shape that makes a run resumable.
//!
//! A runner implements [`PhasedRun`]: its `State` (serde) holds everything the phases collect
//! (histories, VTK frame lists, earlier phases' statistics, measurements taken between phases,
//! built summaries); `enter` starts phase k (sets parameters, may build a new world, returns its
//! [`PhasePlan`] or `None` to skip it); `step` records one step; `leave` closes the phase.
//! [`drive`] runs the phases in order, writes a checkpoint ([`crate::checkpoint`]) every
//! [`CheckpointPolicy`] interval and when the user stops the run (Ctrl-C, or the test-only
//! step limit), and on `--resume` restores world, state and cursor from the checkpoint and
//! continues inside the phase it was in (`enter` is not called again for it). What happens
//! after the last phase (measurements, fits, figures) is the runner's own code on the final
//! world and state; it is not checkpointed (a run stopped there resumes from the last step).
//!
//! Every phase's code must depend on nothing but the world, the state and the scenario's
//! configuration: then a resumed run does exactly what the uninterrupted run did.

use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::Instant;

use dem::{StepReport, World};
use identify::law::Provenance;
use serde::de::DeserializeOwned;
use serde::Serialize;

use super::common::run_phase;
use super::{PhaseEnv, RunContext};
use crate::checkpoint::{self, Cursor, PhasePlan, RunCheckpoint, ScenarioRecord};
use crate::error::{CliError, Result};
use crate::output::OutputDir;
use crate::scenarios::phases::{PhaseProgress, PhaseStats};

/// When periodic checkpoints are written (a checkpoint is also written when the run is
/// stopped by the user, whatever this says).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckpointPolicy {
    /// Every this many steps (all phases together); `None`: not by steps.
    pub every_steps: Option<u64>,
    /// Every this many seconds of wall-clock time; `None`: not by time.
    pub every_seconds: Option<f64>,
}

/// Default interval of periodic checkpoints: one every minute of wall-clock time (the cost of
/// a checkpoint, a fraction of a second for thousands of grains, is then negligible, and at
/// most a minute of computing is lost to a crash).
pub const DEFAULT_CHECKPOINT_SECONDS: f64 = 60.0;

impl Default for CheckpointPolicy {
    fn default() -> Self {
        CheckpointPolicy {
            every_steps: None,
            every_seconds: Some(DEFAULT_CHECKPOINT_SECONDS),
        }
    }
}

/// How a run is controlled: checkpoints, resume, stop. [`RunControl::new`] for a new run with
/// the default policy.
#[derive(Debug, Clone)]
pub struct RunControl {
    /// The `--set` overrides given (recorded in checkpoints, for messages).
    pub sets: Vec<String>,
    /// Periodic checkpoints.
    pub policy: CheckpointPolicy,
    /// Continue from the checkpoint in the output directory instead of starting.
    pub resume: bool,
    /// Behave as if the user pressed Ctrl-C after this many steps of this invocation (tests).
    pub stop_after_steps: Option<u64>,
    /// Wall-clock seconds of earlier invocations (read from the checkpoint on resume).
    pub previous_wall_seconds: f64,
    /// `--allow-suspect`: suspect laws are exported as laws (marked suspect) and the run exits
    /// with 0 ([`crate::verdict`]); recorded in checkpoints.
    pub allow_suspect: bool,
    /// Start date and input hashes of the run, for the provenance of its laws (read from the
    /// checkpoint on resume).
    pub origin: crate::provenance::RunOrigin,
    /// The phases run by this invocation, in order, with their wall-clock seconds
    /// (`grainlaw bench` times a scenario's phases apart with it).
    pub phase_times: Vec<PhaseTime>,
    started: Instant,
    last_checkpoint: Instant,
    steps_since_checkpoint: u64,
    steps_this_run: u64,
    steps_total: u64,
}

impl Default for RunControl {
    fn default() -> Self {
        Self::new(Vec::new(), CheckpointPolicy::default())
    }
}

impl RunControl {
    /// The provenance of a law fitted by the run of `ctx` under this control: scenario kind
    /// `scenario`, its seed, the `--set` overrides, the source (`builtin:NAME` or the TOML
    /// path), and the date and inputs of [`RunControl::origin`].
    pub fn law_provenance(&self, ctx: &RunContext, scenario: &str, seed: u64) -> Provenance {
        let mut p = Provenance::new(scenario, Some(seed)).with_overrides(self.sets.clone());
        p.date = self.origin.date.clone();
        p.inputs = self.origin.inputs.clone();
        p.source = Some(ctx.loaded.source.clone());
        p
    }

    /// A new run with these overrides and checkpoint policy.
    pub fn new(sets: Vec<String>, policy: CheckpointPolicy) -> Self {
        let now = Instant::now();
        RunControl {
            sets,
            policy,
            resume: false,
            stop_after_steps: None,
            previous_wall_seconds: 0.0,
            allow_suspect: false,
            origin: Default::default(),
            phase_times: Vec::new(),
            started: now,
            last_checkpoint: now,
            steps_since_checkpoint: 0,
            steps_this_run: 0,
            steps_total: 0,
        }
    }

    /// Wall-clock seconds of the run, earlier invocations included (s).
    pub fn wall_seconds(&self) -> f64 {
        self.previous_wall_seconds + self.started.elapsed().as_secs_f64()
    }

    /// Whether a periodic checkpoint is due.
    fn due(&self) -> bool {
        self.policy
            .every_steps
            .is_some_and(|n| n > 0 && self.steps_since_checkpoint >= n)
            || self
                .policy
                .every_seconds
                .is_some_and(|s| self.last_checkpoint.elapsed().as_secs_f64() >= s)
    }
}

/// One phase as run by an invocation: its name, the steps this invocation made in it and their
/// wall-clock seconds (the phase's own `step` and `leave` included; a resumed phase counts from
/// the resume).
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseTime {
    /// The phase's name (`compress`, `I=0.01`, ...).
    pub name: String,
    /// Steps made by this invocation.
    pub steps: u64,
    /// Wall-clock seconds (s).
    pub wall_seconds: f64,
}

/// What [`PhasedRun::enter`] is given to start phase `k`.
pub struct Enter<'a> {
    /// The phase's index.
    pub k: usize,
    /// The run's environment (threads, progress, interruption flag).
    pub env: &'a PhaseEnv,
    /// The world, which the phase may replace.
    pub world: &'a mut World,
}

/// What [`PhasedRun::step`] is given after one step of phase `k`.
pub struct Step<'a> {
    /// The phase's index.
    pub k: usize,
    /// The output directory (VTK frames).
    pub out: &'a mut OutputDir,
    /// The world after the step.
    pub world: &'a World,
    /// The step's report.
    pub report: &'a StepReport,
    /// The phase's statistics and counters after the step.
    pub progress: &'a PhaseProgress,
}

/// What [`PhasedRun::leave`] is given to end phase `k`.
pub struct Leave<'a> {
    /// The phase's index.
    pub k: usize,
    /// The output directory.
    pub out: &'a mut OutputDir,
    /// The world at the end of the phase.
    pub world: &'a mut World,
    /// The phase's statistics.
    pub stats: &'a PhaseStats,
}

/// A scenario's simulation as phases over one world with a serialisable state (module doc).
pub trait PhasedRun {
    /// Everything collected step by step and between phases.
    type State: Serialize + DeserializeOwned;

    /// Number of phases (one unless the runner says otherwise).
    fn phase_count(&self) -> usize {
        1
    }

    /// Starts phase `at.k` (not called when a resume continues inside it): sets parameters,
    /// may replace the world; `None` skips the phase.
    fn enter(&self, state: &mut Self::State, at: Enter<'_>) -> Result<Option<PhasePlan>>;

    /// Records one step of phase `at.k` (the world after it; the phase's statistics and
    /// counters after it).
    fn step(&self, state: &mut Self::State, at: Step<'_>) -> Result<()>;

    /// Finishes what the steps left running beside the run (re-solves of sampled steps,
    /// [`super::sensitivity::ResolveQueue`]) so that `state` is complete: called before a
    /// checkpoint is written and before [`PhasedRun::leave`]. Nothing to do by default.
    fn settle(&self, _state: &mut Self::State) {}

    /// Ends phase `at.k` with its statistics.
    fn leave(&self, state: &mut Self::State, at: Leave<'_>) -> Result<()>;
}

/// The output directory as a user would type it in `--resume`.
fn shown(dir: &std::path::Path) -> String {
    let s = dir.display().to_string();
    if s.chars().any(char::is_whitespace) {
        format!("'{s}'")
    } else {
        s
    }
}

/// Runs the phases of `run` (module doc): from `fresh()` (the initial world and state) for a
/// new run, from the checkpoint in the output directory with `ctl.resume`. Returns the final
/// world and state. Stops with [`CliError::Interrupted`] after writing a checkpoint when the
/// user presses Ctrl-C (or after `ctl.stop_after_steps` steps).
pub fn drive<P: PhasedRun>(
    ctx: &mut RunContext,
    ctl: &mut RunControl,
    run: &P,
    fresh: impl FnOnce() -> Result<(World, P::State)>,
) -> Result<(World, P::State)> {
    let env = ctx.env();
    let record = ScenarioRecord {
        name: ctx.loaded.name.clone(),
        source: ctx.loaded.source.clone(),
        effective_toml: ctx.loaded.effective_toml.clone(),
        sets: ctl.sets.clone(),
        allow_suspect: ctl.allow_suspect,
    };
    let cp_path: PathBuf = checkpoint::file_of(ctx.out.path());
    let dir_shown = shown(ctx.out.path());
    let (mut world, mut state, mut cursor) = if ctl.resume {
        let cp: RunCheckpoint<P::State> = checkpoint::read(ctx.out.path())?;
        if cp.scenario.effective_toml != record.effective_toml {
            return Err(CliError::Checkpoint {
                path: cp_path.display().to_string(),
                reason: "written for another scenario".into(),
            });
        }
        if cp.cursor.phase >= run.phase_count() {
            return Err(CliError::Checkpoint {
                path: cp_path.display().to_string(),
                reason: format!(
                    "phase {} does not exist in this scenario (not a readable checkpoint)",
                    cp.cursor.phase
                ),
            });
        }
        ctl.previous_wall_seconds = cp.wall_seconds;
        ctl.origin = cp.origin.clone();
        ctl.steps_total = cp.steps_total;
        (World::from_state(cp.world), cp.state, Some(cp.cursor))
    } else {
        let (w, s) = fresh()?;
        (w, s, None)
    };
    let mut k = cursor.as_ref().map_or(0, |c| c.phase);
    while k < run.phase_count() {
        let (plan, mut progress) = match cursor.take() {
            Some(c) => (c.plan, c.progress),
            None => match run.enter(
                &mut state,
                Enter {
                    k,
                    env: &env,
                    world: &mut world,
                },
            )? {
                Some(plan) => (plan, PhaseProgress::default()),
                None => {
                    k += 1;
                    continue;
                }
            },
        };
        let out = &mut ctx.out;
        let st = &mut state;
        let (t0, steps0) = (Instant::now(), ctl.steps_this_run);
        let stats = run_phase(
            &env,
            &plan.name,
            &mut world,
            plan.stop,
            &mut progress,
            |w, r, p| {
                let at = Step {
                    k,
                    out: &mut *out,
                    world: w,
                    report: r,
                    progress: p,
                };
                run.step(st, at)?;
                ctl.steps_this_run += 1;
                ctl.steps_total += 1;
                ctl.steps_since_checkpoint += 1;
                let stop = env.interrupted.load(Ordering::Relaxed)
                    || ctl
                        .stop_after_steps
                        .is_some_and(|n| ctl.steps_this_run >= n);
                if stop || ctl.due() {
                    run.settle(st);
                    let cp = RunCheckpoint {
                        format: checkpoint::FORMAT.to_string(),
                        grainlaw_version: env!("CARGO_PKG_VERSION").to_string(),
                        scenario: record.clone(),
                        cursor: Cursor {
                            phase: k,
                            plan: plan.clone(),
                            progress: *p,
                        },
                        steps_total: ctl.steps_total,
                        wall_seconds: ctl.wall_seconds(),
                        origin: ctl.origin.clone(),
                        world: w.state(),
                        state: &*st,
                    };
                    checkpoint::write(&cp_path, &cp)?;
                    ctl.last_checkpoint = Instant::now();
                    ctl.steps_since_checkpoint = 0;
                }
                if stop {
                    return Err(CliError::Interrupted {
                        phase: plan.name.clone(),
                        step: p.steps(),
                        dir: dir_shown.clone(),
                    });
                }
                Ok(())
            },
        )?;
        run.settle(&mut state);
        let at = Leave {
            k,
            out: &mut ctx.out,
            world: &mut world,
            stats: &stats,
        };
        run.leave(&mut state, at)?;
        ctl.phase_times.push(PhaseTime {
            name: plan.name.clone(),
            steps: ctl.steps_this_run - steps0,
            wall_seconds: t0.elapsed().as_secs_f64(),
        });
        k += 1;
    }
    Ok((world, state))
}
