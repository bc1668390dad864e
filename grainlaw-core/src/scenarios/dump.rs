//! `grainlaw run --dump-problems DIR [--dump-steps A..B | --dump-capped]`: the frictional-contact
//! problems of chosen steps written as fc-problem-v1 files, so that any solver (`grainlaw
//! solve-fc`, Siconos) can be compared on the exact problems a run met.
//!
//! A problem is the step's `u = W r + q` ([`dem::assemble::contact_problem`]) before the solve;
//! the file `DIR/PHASE_STEP.json.gz` (the phase name with `-` for anything but letters and
//! digits, the step on seven digits) holds it with `meta`: the scenario, the phase, the step
//! index and time, the time step, the solver's tolerance, method and sweep cap, and what the
//! engine's solve did (sweeps, Newton iterations, error, converged).

use std::path::PathBuf;

use dem::{StepReport, World};

use crate::error::{CliError, Result};

/// Which steps to write.
#[derive(Debug, Clone, PartialEq)]
pub enum DumpSteps {
    /// The steps whose solve did not converge (the default).
    Capped,
    /// The steps with global index in `first..=last` (the index counts every step of the run).
    Range(u64, u64),
}

/// Where and which problems to write.
#[derive(Debug, Clone, PartialEq)]
pub struct ProblemDump {
    /// Directory of the files (created if absent).
    pub dir: PathBuf,
    /// The steps.
    pub steps: DumpSteps,
    /// Scenario name, for `meta`.
    pub scenario: String,
}

impl ProblemDump {
    /// Parses `A..B` (inclusive, `A ≤ B`) for `--dump-steps`.
    pub fn parse_range(text: &str) -> Result<DumpSteps> {
        let bad = || {
            CliError::Usage(format!(
                "--dump-steps takes FIRST..LAST (step indices, FIRST ≤ LAST), got `{text}`"
            ))
        };
        let (a, b) = text.split_once("..").ok_or_else(bad)?;
        let a: u64 = a.trim().parse().map_err(|_| bad())?;
        let b: u64 = b.trim().parse().map_err(|_| bad())?;
        if a > b {
            return Err(bad());
        }
        Ok(DumpSteps::Range(a, b))
    }

    /// Whether the step just done (report `r`) is one to write.
    pub fn wants(&self, r: &StepReport) -> bool {
        match self.steps {
            DumpSteps::Capped => !r.solver.converged,
            DumpSteps::Range(a, b) => (a..=b).contains(&r.step),
        }
    }

    /// Writes the problem that stands for the step `r` of phase `phase`
    /// ([`World::problem_of_last_step`]: of a subdivided step, the first kept sub-step that did
    /// not converge, if one did not), when `world` recorded it; `meta` holds that (sub-)step's
    /// index, time and solve, and the whole step's sweeps and convergence.
    pub fn write(&self, phase: &str, world: &World, r: &StepReport) -> Result<()> {
        let Some((problem, last)) = world.problem_of_last_step() else {
            return Ok(());
        };
        std::fs::create_dir_all(&self.dir).map_err(|e| CliError::Io {
            path: self.dir.display().to_string(),
            reason: e.to_string(),
        })?;
        let solver = &world.params.solver;
        // The problem is one (sub-)step's, with its own time step and solve, which differ from
        // the step's `r` when the step was subdivided (`r` merges its sub-steps): the first
        // sub-step that did not converge if one did not, else the last. Kept sub-steps share
        // one time step, the contacts' `dt`.
        let meta = serde_json::json!({
            "source": "grainlaw run --dump-problems",
            "grainlaw_version": env!("CARGO_PKG_VERSION"),
            "scenario": self.scenario,
            "phase": phase,
            "step": last.step,
            "time_s": last.time,
            "dt_s": world.contacts().dt,
            "step_dt_s": world.params.dt,
            "tolerance": solver.tolerance,
            "method": solver.method.name(),
            "max_iterations": solver.max_iterations,
            "max_halvings": solver.max_halvings,
            "engine_sweeps": last.solver.iterations,
            "engine_newton_iterations": last.solver.newton_iterations,
            "engine_lemke_pivots": last.solver.pivots,
            "lemke_max_contacts": solver.lemke_max_contacts,
            "error_scale": solver.error_scale.name(),
            "engine_error": last.solver.error,
            "engine_error_without_gap_shifts": last.solver.error_without_gap_shifts,
            "engine_converged": last.solver.converged,
            "step_sweeps": r.solver.iterations,
            "step_converged": r.solver.converged,
        });
        let name: String = phase
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect();
        let path = self.dir.join(format!("{name}_{:07}.json.gz", r.step));
        dem::fc::write_problem(&path, problem, meta)?;
        Ok(())
    }
}
