//! Time step control from the contact solve.
//!
//! Two rules, both driven by whether a step's contact solve converged:
//!
//! - [`step_subdivided`], for trajectories at a fixed step (every scenario phase): a step whose
//!   solve stops above its tolerance is *undone* and done again as two half steps, recursively
//!   up to `2^max_halvings` sub-steps ([`crate::SolverParams::max_halvings`]); the step as a
//!   whole still advances the time by `h`, so the phase's schedule is unchanged. The smaller
//!   step carries a smaller change of the load and of the contact network, which is what
//!   Gauss–Seidel cannot carry across a dense, hyperstatic packing within its sweep cap
//!   (measured: the Janssen release at `h` = 1 ms, 124 of 300 steps above 10⁻⁴ after 5000 sweeps,
//!   converges in 1198 of 1200 steps at `h/4` with 177 sweeps a step; docs/physics.md §1.6).
//!   The level that succeeded is kept for the next steps ([`Subdivision`]) and lowered by one
//!   after [`CALM_STEPS`] steps that converged at their first try, in the spirit of LMGC90's
//!   adaptive step on the NLGS iteration count. Each kept sub-step is an ordinary Moreau–Jean
//!   step with its own energy balance; the discarded attempts leave no trace in the state
//!   (their sweeps are counted in the step's cost). An attempt that can still be subdivided
//!   is solved by Gauss–Seidel alone (`auto` → `nlgs`): a smaller step is cheaper than the
//!   global stages, which run at the largest subdivision. Steps that fail even there (a
//!   problem without solution at any step) pause the subdivision ([`FAILURES_BEFORE_BACKOFF`],
//!   [`MAX_BACKOFF`]). With an energy limit ([`step_subdivided_checked`]), a converged step
//!   whose energy balance grew beyond it is solved again at a tenth of the tolerance
//!   ([`POLISH_FACTOR`]).
//! - [`StepControl`], for runs whose only goal is a state (settling a packing), not a
//!   trajectory: the step itself shrinks and grows.
//!
//! **StepControl.** A step whose solve stops at the sweep cap leaves its closed contacts approaching at some
//! residual speed `u_a`, so the overlap grows by `h u_a` that step; over a transient of
//! `T / h` steps the overlap left behind scales as `T u_a`, with `u_a` itself of the order of the
//! unbalanced part of `g h`: halving `h` roughly halves the overlap a transient leaves, and it
//! makes each step's load change smaller. Once the packing is quiet the step can grow again.
//! A rule in the spirit of LMGC90's adaptive step on the NLGS iteration count:
//!
//! ```text
//! solve not converged                       →  h ← max(h / 2, h_min)
//! `calm_steps` steps in a row converged in
//! at most `calm_fraction` of the sweep cap  →  h ← min(h · grow, h_max)
//! ```
//!
//! Impulses are warm-started across a change of `h` by the ratio of the steps (the world does
//! it), so a change costs nothing.

use serde::{Deserialize, Serialize};

use crate::energy::EnergyProbe;
use crate::error::DemError;
use crate::fc::SolverMethod;
use crate::stabilise::CorrectionReport;
use crate::world::{StepReport, World};

/// Steps at a level that converge at their first try before [`step_subdivided`] tries one
/// halving fewer.
pub const CALM_STEPS: u32 = 32;

/// Consecutive steps left unconverged at the largest subdivision before [`step_subdivided`]
/// stops subdividing for a while: their problems are not eased by a smaller step (a column
/// that self-locks under an imposed motion may have no solution at any step).
pub const FAILURES_BEFORE_BACKOFF: u32 = 4;

/// Longest pause of the subdivision (steps); pauses double from 1 up to it while the steps
/// after them keep failing at the largest subdivision.
pub const MAX_BACKOFF: u32 = 64;

/// [`crate::SolverParams::last_level_sweeps`] of the poured benchmark column: at the largest
/// subdivision a Gauss–Seidel solve may sweep 10 times the cap. A capped sub-step there is rare
/// (the poured 2000-grain column: 0 to 3 of about 5000 per run at a cap of 100 sweeps, over 6
/// seeds), so the budget costs little, and it removed them all.
pub const LAST_LEVEL_SWEEPS: usize = 10;

/// Factor on the solver tolerance of a step solved again because its energy grew
/// ([`step_subdivided_checked`]).
pub const POLISH_FACTOR: f64 = 0.1;

/// Where the subdivision of steps stands between steps; saved with the phase in checkpoints,
/// so a resumed run subdivides as one never stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Subdivision {
    /// Halvings the next step starts with (`2^level` sub-steps).
    pub level: u32,
    /// Consecutive steps at `level` that converged at their first try.
    pub calm: u32,
    /// Consecutive steps left unconverged at the largest subdivision.
    #[serde(default)]
    pub failures: u32,
    /// Steps left to do whole, without subdivision, after [`FAILURES_BEFORE_BACKOFF`] such
    /// failures.
    #[serde(default)]
    pub pause: u32,
    /// The pause that the next such failure sets (doubling up to [`MAX_BACKOFF`]).
    #[serde(default)]
    pub next_pause: u32,
}

/// A sub-step's problem and report ([`World::problem_of_last_step`]).
type Unconverged = (crate::fc::FcProblem, StepReport);

/// One kept sub-step of a [`SubdividedStep`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubStep {
    /// Its report.
    pub report: StepReport,
    /// Its energy residual δ (J, [`EnergyProbe::residual`]).
    pub energy_residual: f64,
}

/// The energy residual of consecutive sub-steps, `δ = Σ δ_k` (J): the balance is additive.
pub fn energy_residual(substeps: &[SubStep]) -> f64 {
    substeps.iter().map(|s| s.energy_residual).sum()
}

/// What [`step_subdivided`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct SubdividedStep {
    /// The step as a whole ([`merge_reports`] of the kept sub-steps; its sweeps include those
    /// of the discarded attempts).
    pub report: StepReport,
    /// The kept sub-steps, in order (one when the step was not subdivided).
    pub substeps: Vec<SubStep>,
    /// Halvings of the kept sub-steps (`substeps.len() == 2^halvings`).
    pub halvings: u32,
    /// Attempts undone: because a sub-step did not converge, or a converged solve whose energy
    /// grew and was solved again ([`step_subdivided_checked`]; one whichever solve is kept).
    pub retries: u32,
    /// Sweeps of the undone attempts (of the solve not kept, for a polished step).
    pub discarded_sweeps: usize,
    /// Done whole during a pause of the subdivision (after repeated failures at its largest
    /// level), so not tried in sub-steps.
    pub paused: bool,
    /// Solved again at [`POLISH_FACTOR`] times the tolerance because its energy grew beyond the
    /// limit of [`step_subdivided_checked`], and the tighter solve was kept.
    pub polished: bool,
}

impl SubdividedStep {
    /// The step's energy residual ([`energy_residual`] of its kept sub-steps, J).
    pub fn energy_residual(&self) -> f64 {
        energy_residual(&self.substeps)
    }
}

/// Advances `world` by its time step `h = world.params.dt` in `2^L` equal sub-steps, `L`
/// starting at `state.level` (capped at [`crate::SolverParams::max_halvings`]; 0 under an
/// implicit cell control, [`crate::CellControl::implicit`], whose law is written per step): when a
/// sub-step's solve does not converge and `L` is below the cap, the world is restored to its
/// state before the step and the step is done again with `L + 1` (module documentation). At the
/// cap the sub-steps are kept whatever their convergence (the merged report says so); there a
/// Gauss–Seidel (`nlgs`) solve may sweep [`crate::SolverParams::last_level_sweeps`] times the
/// sweep cap. The level
/// that was kept becomes the next step's; after [`CALM_STEPS`] steps converged at their first
/// try it drops by one. After [`FAILURES_BEFORE_BACKOFF`] consecutive steps unconverged at the
/// cap, the next steps are done whole (no subdivision) for a pause of 1, 2, 4, … up to
/// [`MAX_BACKOFF`] steps, doubling while the failures go on and reset by any step that
/// converges outside a pause. A non-finite state in an attempt that can still be halved is
/// undone like a failed solve. `world.params.dt` is `h` again on return.
///
/// The convergence test of each sub-step uses its own step: the approach-speed limit
/// `overlap_rate · R_min / (h/2^L)` lets a subdivided step's contacts creep by up to `2^L`
/// times the overlap a whole step would allow; the position correction and the overlap checks
/// of every run bound what is left.
///
/// # Errors
/// The first [`DemError`] of a sub-step that cannot be halved further (non-finite state); the
/// world is then left where that sub-step stopped, with `params.dt = h`.
pub fn step_subdivided(
    world: &mut World,
    state: &mut Subdivision,
) -> Result<SubdividedStep, DemError> {
    step_subdivided_checked(world, state, None)
}

/// [`step_subdivided`] with the energy balance of the step checked: when every kept sub-step
/// converged but the step's energy residual `δ = Σ δ_k` ([`EnergyProbe::residual`], summed over
/// the sub-steps: the balance is additive) exceeds `energy_limit` (J), the step is undone and
/// solved again at the same subdivision with the tolerance multiplied by [`POLISH_FACTOR`].
///
/// For θ = 1 an exact solve gives `δ ≤ 0` (Moreau 1988); a solve accepted at a relative error
/// `ε` may leave `uᵀR > 0` of order `ε` in every sub-step, and a packing near rest whose warm
/// start already meets the tolerance (0–2 sweeps a sub-step) adds it up over the sub-steps
/// (measured: the Janssen deposit, 8 sub-steps of +1.35·10⁻⁶ E_load each). The tighter solve is
/// kept if all its sub-steps converge at the tighter tolerance (then the step is
/// [`SubdividedStep::polished`]); otherwise the first solve is kept, its growth reported by the
/// caller. At most one polish per step; its sweeps count as discarded when it is not kept, and
/// the first solve's sweeps when it is.
///
/// # Errors
/// As [`step_subdivided`].
pub fn step_subdivided_checked(
    world: &mut World,
    state: &mut Subdivision,
    energy_limit: Option<f64>,
) -> Result<SubdividedStep, DemError> {
    let h = world.params.dt;
    // The implicit law of a stress-controlled cell is written per step (its gain acts once a
    // step): applied 2^L times over h it is another, stiffer law, and it ran away on a dilute
    // sheared cell (the cell's expansion rate growing geometrically over sub-steps). Those
    // steps are not subdivided; the coupled cell already makes them converge (physics.md §7).
    let implicit_cell = world.cell_control.is_some_and(|c| c.implicit);
    let configured = if implicit_cell {
        0
    } else {
        world.params.solver.max_halvings.min(20)
    };
    let paused = state.pause > 0;
    let max = if paused {
        state.pause -= 1;
        0
    } else {
        configured
    };
    let start = state.level.min(max);
    let mut level = start;
    let (mut retries, mut discarded) = (0u32, 0usize);
    let mut backup: Option<World> = None;
    let tolerance = world.params.solver.tolerance;
    let method = world.params.solver.method;
    let gauss_seidel_attempts = world.params.solver.gauss_seidel_attempts;
    // The first solve of a step whose energy grew, while its polish is tried.
    let mut first: Option<(World, Vec<SubStep>, Option<Unconverged>)> = None;
    let max_iterations = world.params.solver.max_iterations;
    let restore = |world: &mut World| {
        world.params.dt = h;
        world.params.solver.method = method;
        world.params.solver.tolerance = tolerance;
        world.params.solver.max_iterations = max_iterations;
    };
    // The kept sub-steps, and whether they are a polish.
    let (subs, polished, unconverged) = loop {
        let polishing = first.is_some();
        let can_halve = level < max && !polishing;
        if can_halve || (energy_limit.is_some() && !polishing) {
            match backup.as_mut() {
                // State only: the work space is filled again by the next attempt.
                Some(b) => b.undo_to(world),
                None => backup = Some(world.undo_point()),
            }
        }
        let n = 1usize << level;
        world.params.dt = h / n as f64;
        // An attempt that can still be subdivided is left to Gauss–Seidel: a smaller step is
        // cheaper than the global stages of `auto`, which run at the largest subdivision. Its
        // polish is solved the same way.
        if level < max && gauss_seidel_attempts && method == SolverMethod::Auto {
            world.params.solver.method = SolverMethod::Nlgs;
        }
        if polishing {
            world.params.solver.tolerance = tolerance * POLISH_FACTOR;
        }
        if method == SolverMethod::Nlgs && configured > 0 && level == max && !paused {
            world.params.solver.max_iterations =
                max_iterations.saturating_mul(world.params.solver.last_level_sweeps.max(1));
        }
        let (mut subs, mut unconverged, failed) =
            match attempt_substeps(world, n, can_halve, polishing) {
                Ok(attempt) => attempt,
                Err(e) => {
                    restore(world);
                    return Err(e);
                }
            };
        let sweeps =
            |subs: &[SubStep]| -> usize { subs.iter().map(|s| s.report.solver.iterations).sum() };
        if let Some((first_world, first_subs, first_unconverged)) = first.take() {
            // The polish: kept if every sub-step converged at the tighter tolerance.
            let kept = !failed;
            if kept {
                discarded += sweeps(&first_subs);
                // The back-off of `auto` continues from the first solve, as if the step had
                // been solved once at the run's tolerance (a tolerance change resets it).
                world.newton_backoff = first_world.newton_backoff;
            } else {
                discarded += sweeps(&subs);
                world.undo_to(&first_world);
                subs = first_subs;
                unconverged = first_unconverged;
            }
            retries += 1;
            break (subs, kept, unconverged);
        }
        if failed && can_halve {
            discarded += sweeps(&subs);
            if let Some(b) = backup.as_ref() {
                world.undo_to(b);
            }
            retries += 1;
            level += 1;
            continue;
        }
        let all_converged = subs.iter().all(|s| s.report.solver.converged);
        if let (Some(limit), true, Some(b)) = (energy_limit, all_converged, backup.as_ref()) {
            if energy_residual(&subs) > limit {
                // Energy grew in a converged step: solve it again, tighter (doc comment).
                first = Some((world.undo_point(), subs, unconverged));
                world.undo_to(b);
                continue;
            }
        }
        break (subs, false, unconverged);
    };
    restore(world);
    world.work.unconverged_problem = unconverged;
    let all_converged = subs.iter().all(|s| s.report.solver.converged);
    if !paused && configured > 0 {
        update_subdivision(state, start, level, all_converged);
    }
    let mut report = merge_reports(subs.iter().map(|s| &s.report));
    report.solver.iterations += discarded;
    Ok(SubdividedStep {
        report,
        substeps: subs,
        halvings: level,
        retries,
        discarded_sweeps: discarded,
        paused,
        polished,
    })
}

/// The sub-steps of one attempt of [`step_subdivided_checked`], `n` steps of the world's
/// current `dt`: their reports and energy residuals, the first unconverged one's problem (when
/// problems are recorded, for a dump), and whether the attempt failed (a sub-step that did not
/// converge while the step can still be halved or is a polish, or a non-finite state then: a
/// smaller step is the usual cure, so it is undone like a failed solve).
///
/// # Errors
/// The error of a sub-step when the step can neither be halved nor is a polish.
fn attempt_substeps(
    world: &mut World,
    n: usize,
    can_halve: bool,
    polishing: bool,
) -> Result<(Vec<SubStep>, Option<Unconverged>, bool), DemError> {
    let mut subs = Vec::with_capacity(n);
    let mut unconverged: Option<Unconverged> = None;
    let mut failed = false;
    for _ in 0..n {
        let probe = EnergyProbe::before(world);
        let report = match world.step() {
            Ok(r) => r,
            Err(e) if !polishing && !can_halve => return Err(e),
            Err(_) => {
                failed = true;
                break;
            }
        };
        let energy_residual = probe.residual(world);
        let converged = report.solver.converged;
        if !converged && unconverged.is_none() {
            unconverged = world.last_problem().map(|p| (p.clone(), report));
        }
        subs.push(SubStep {
            report,
            energy_residual,
        });
        if !converged && (can_halve || polishing) {
            failed = true;
            break;
        }
    }
    Ok((subs, unconverged, failed))
}

/// The level rule of [`step_subdivided`] after a step that started at `start` halvings and was
/// kept at `level` (outside a pause).
fn update_subdivision(state: &mut Subdivision, start: u32, level: u32, converged: bool) {
    if level > start || !converged {
        state.level = level;
        state.calm = 0;
    } else if level > 0 {
        state.calm += 1;
        if state.calm >= CALM_STEPS {
            state.level = level - 1;
            state.calm = 0;
        }
    }
    if converged {
        // A converged step ends a run of failures: the next burst starts its pauses at 1.
        state.failures = 0;
        state.next_pause = 0;
    } else {
        state.failures += 1;
        if state.failures >= FAILURES_BEFORE_BACKOFF {
            state.failures = 0;
            state.pause = state.next_pause.max(1);
            state.next_pause = (state.pause * 2).min(MAX_BACKOFF);
            state.level = 0;
            state.calm = 0;
        }
    }
}

/// One report for consecutive sub-steps: the last one's step index, time and contacts; the
/// sums of sweeps, Newton iterations, pivots, cell work and corrections; the largest error,
/// approach speed and overlap; converged when every sub-step converged; the position
/// corrections merged ([`merge_corrections`]).
pub fn merge_reports<'a>(reports: impl IntoIterator<Item = &'a StepReport>) -> StepReport {
    let mut it = reports.into_iter();
    let Some(first) = it.next() else {
        return StepReport::default();
    };
    let mut m = *first;
    for r in it {
        let s = &mut m.solver;
        s.iterations += r.solver.iterations;
        s.newton_iterations += r.solver.newton_iterations;
        s.pivots += r.solver.pivots;
        s.error = crate::solver::worst(s.error, r.solver.error);
        s.error_without_gap_shifts = crate::solver::worst(
            s.error_without_gap_shifts,
            r.solver.error_without_gap_shifts,
        );
        s.approach_speed = s.approach_speed.max(r.solver.approach_speed);
        s.converged &= r.solver.converged;
        m.step = r.step;
        m.time = r.time;
        m.contacts = r.contacts;
        m.active_contacts = r.active_contacts;
        m.max_penetration = m.max_penetration.max(r.max_penetration);
        m.position_correction = merge_corrections(&m.position_correction, &r.position_correction);
        m.cell_work += r.cell_work;
        m.cell_corrections += r.cell_corrections;
    }
    m
}

/// Two position corrections as one: the larger contact counts and overlaps, the summed sweeps
/// and load work, capped when either was.
pub fn merge_corrections(a: &CorrectionReport, b: &CorrectionReport) -> CorrectionReport {
    CorrectionReport {
        violated_contacts: a.violated_contacts.max(b.violated_contacts),
        corrected_contacts: a.corrected_contacts.max(b.corrected_contacts),
        sweeps: a.sweeps + b.sweeps,
        capped: a.capped || b.capped,
        overlap_before: a.overlap_before.max(b.overlap_before),
        overlap_after: a.overlap_after.max(b.overlap_after),
        max_displacement: a.max_displacement.max(b.max_displacement),
        load_work: a.load_work + b.load_work,
    }
}

/// The rule and its state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StepControl {
    /// Smallest time step (s).
    pub min_dt: f64,
    /// Largest time step (s).
    pub max_dt: f64,
    /// Growth factor after a calm run (> 1).
    pub grow: f64,
    /// Consecutive calm steps before the step grows.
    pub calm_steps: usize,
    /// A step is calm when it converged within this fraction of the sweep cap.
    pub calm_fraction: f64,
    calm: usize,
}

impl StepControl {
    /// Steps between `min_dt` and `max_dt` (s), growing by 2 after 5 calm steps (converged
    /// within a quarter of the sweep cap).
    pub fn new(min_dt: f64, max_dt: f64) -> Self {
        StepControl {
            min_dt,
            max_dt,
            grow: 2.0,
            calm_steps: 5,
            calm_fraction: 0.25,
            calm: 0,
        }
    }

    /// Adjust `w.params.dt` after a step that reported `report`; returns the new step (s).
    pub fn after(&mut self, w: &mut World, report: &StepReport) -> f64 {
        let h = w.params.dt;
        let cap = w.params.solver.max_iterations as f64;
        let new = if !report.solver.converged {
            self.calm = 0;
            (0.5 * h).max(self.min_dt)
        } else if (report.solver.iterations as f64) <= self.calm_fraction * cap {
            self.calm += 1;
            if self.calm >= self.calm_steps {
                self.calm = 0;
                (self.grow * h).min(self.max_dt)
            } else {
                h
            }
        } else {
            self.calm = 0;
            h
        };
        w.params.dt = new;
        new
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::SolveReport;
    use crate::{ContactLaws, WorldParams};

    fn report(converged: bool, iterations: usize) -> StepReport {
        StepReport {
            solver: SolveReport {
                iterations,
                converged,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// Halves on a capped step down to the floor, grows by 2 only after 5 calm steps in a row
    /// (a busy step resets the count), up to the ceiling.
    #[test]
    fn halves_on_failure_and_grows_after_a_calm_run() {
        let params = WorldParams {
            dt: 1e-3,
            ..Default::default()
        };
        let mut w = World::new(params, ContactLaws::new(&["m"], 0.5));
        w.params.solver.max_iterations = 100;
        let mut c = StepControl::new(1.25e-4, 1e-3);
        assert_eq!(c.after(&mut w, &report(false, 100)), 5e-4);
        assert_eq!(c.after(&mut w, &report(false, 100)), 2.5e-4);
        assert_eq!(c.after(&mut w, &report(false, 100)), 1.25e-4);
        assert_eq!(c.after(&mut w, &report(false, 100)), 1.25e-4);
        for _ in 0..4 {
            assert_eq!(c.after(&mut w, &report(true, 25)), 1.25e-4);
        }
        // a converged but busy step (more than a quarter of the cap) resets the count
        assert_eq!(c.after(&mut w, &report(true, 26)), 1.25e-4);
        for _ in 0..4 {
            assert_eq!(c.after(&mut w, &report(true, 3)), 1.25e-4);
        }
        assert_eq!(c.after(&mut w, &report(true, 3)), 2.5e-4);
        for _ in 0..20 {
            c.after(&mut w, &report(true, 0));
        }
        assert_eq!(w.params.dt, 1e-3);
    }
}
