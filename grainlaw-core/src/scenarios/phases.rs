//! Running a world through a phase (deposition, relaxation, a driven run) and accounting for
//! what the contact solver and the time stepping did: non-converged steps and the worst error,
//! steps whose mechanical energy grew, steps whose overlap went beyond a limit. Everything is
//! counted, never hidden.
//!
//! A phase can be stopped after any step and continued later from a [`PhaseProgress`] (with the
//! world restored from its checkpoint) with bit-identical results: [`continue_until_rest`] and
//! [`continue_steps`] keep every loop counter in the progress, and check their stop criterion
//! before each step, so a phase saved on the step where it ended ends at once when continued.
//!
//! ## Energy balance of a step ([`dem::energy`])
//!
//! With θ-method positions `q⁺ = q⁻ + h[(1 − θ) v⁻ + θ v⁺]`, the free degrees of freedom of a
//! step satisfy
//!
//! `ΔK = W_ext + W_drive + uᵀR − ½‖v⁺ − v⁻‖²_M + (1 − θ) h f·(v⁺ − v⁻)`,
//!
//! where `K = Σ ½ m |v|² + ½ I ω²` (free degrees of freedom), `W_ext = h Σ f·[(1 − θ) v⁻ + θ v⁺]`
//! is the work of gravity and applied loads `f` (it replaces `−ΔE_pot`, and stays right across a
//! periodic boundary where the position jumps), and `W_drive = −h Σ F_c·v` is the work that the
//! drives of imposed degrees of freedom (a wall moved at a given velocity) put in to keep their
//! velocity against the contact force `F_c` they receive. For θ = 1 and an exact contact solve,
//! `uᵀR ≤ 0` (Signorini: `u_n r_n = 0`, with the gap shift `−g r_n/(hθ) ≤ 0`; Coulomb:
//! `u_t r_t ≤ 0`), so the residual `δ = ΔK − W_ext − W_drive ≤ 0`: the scheme only dissipates.
//! [`EnergyProbe`] measures δ; a step with `δ > ENERGY_GROWTH_TOLERANCE · E_load` (see
//! [`load_energy_scale`]) is counted as an energy growth. It is flagged, not fatal: θ = 1/2, a
//! non-converged contact solve or Newton restitution between several contacts can produce one.
//!
//! ## The position correction
//!
//! After the θ-method update the engine projects the positions out of the overlaps deeper than
//! a slop (`dem::stabilise`, on by default): `q⁺ ← q⁺ + Δq_c` with `Δq_c = M⁻¹ H_nᵀ P`, velocities
//! untouched. It changes no kinetic energy, and `W_ext` above is the work of the loads along the
//! velocities, so δ does not see it: δ stays the residual of the scheme alone, and the check
//! above keeps its meaning. The correction does change the potential energy of the loads, by
//! `−W_c` with `W_c = Σ f·Δq_c` (gravity and applied loads on free degrees of freedom, reported
//! by the step as `position_correction.load_work`). That energy is accounted separately, not as
//! growth of the scheme: [`PhaseStats::position_correction_energy`] sums `−W_c` over the phase
//! (positive when the correction lifted grains or pushed a loaded platen back), and
//! [`PhaseStats::position_corrected_steps`] counts the steps where it moved something. The
//! mechanical energy of a phase therefore changes by `Σ (δ + W_drive) + position_correction_energy`.

pub use dem::energy::{load_energy_scale, EnergyProbe};
use dem::solver::worst;
use dem::step_control::{step_subdivided_checked, SubdividedStep, Subdivision};
use dem::{BodyKind, StepReport, World};
use serde::{Deserialize, Serialize};

/// A step whose energy residual δ exceeds this fraction of [`load_energy_scale`] is counted as
/// an energy growth (1). At this rate, 10⁵ steps would inject the energy of lifting every grain
/// by one diameter; the inexactness of a converged contact solve stays well below it (the
/// built-in deposits reach about 10⁻⁶ with a tolerance of 10⁻⁴), while θ = 1/2 impacts or solves
/// stopped far from convergence exceed it.
pub const ENERGY_GROWTH_TOLERANCE: f64 = 1e-5;

/// A step whose largest overlap at its start exceeds this fraction of the smallest grain radius
/// is counted as a penetration beyond the limit (1).
pub const PENETRATION_LIMIT: f64 = 0.01;

/// What the contact solver and the engine did over a phase.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PhaseStats {
    /// Steps done.
    pub steps: u64,
    /// Simulated time (s).
    #[serde(with = "dem::serde_float")]
    pub simulated_time: f64,
    /// Steps whose contact solve stopped at the sweep cap above its tolerance.
    pub unconverged_steps: u64,
    /// World step index of the first such step.
    pub first_unconverged_step: Option<u64>,
    /// Largest error measure at the end of a step's solve (1).
    #[serde(with = "dem::serde_float")]
    pub worst_error: f64,
    /// Largest error measure of a step's solve over a scale that leaves out the gap-closing
    /// shifts of open pairs (`dem::SolveReport::error_without_gap_shifts`): what `worst_error`
    /// is on the loaded contacts (1; with `solver.error_scale = "loaded"` the error includes it).
    #[serde(default, with = "dem::serde_float")]
    pub worst_error_without_gap_shifts: f64,
    /// Largest number of sweeps of one step.
    pub max_sweeps: usize,
    /// Sum of sweeps over the steps.
    pub total_sweeps: u64,
    /// Largest overlap at the start of a step (m).
    #[serde(with = "dem::serde_float")]
    pub max_penetration: f64,
    /// Largest overlap at the start of a step over the smallest grain radius (1).
    #[serde(with = "dem::serde_float")]
    pub max_penetration_ratio: f64,
    /// Steps whose overlap exceeded [`PENETRATION_LIMIT`] of the smallest grain radius.
    pub penetration_flagged_steps: u64,
    /// World step index of the first such step.
    pub first_penetration_step: Option<u64>,
    /// Steps whose energy residual δ exceeded [`ENERGY_GROWTH_TOLERANCE`] · E_load.
    pub energy_growth_steps: u64,
    /// World step index of the first such step.
    pub first_energy_growth_step: Option<u64>,
    /// Largest energy residual of a step over E_load, `max(δ / E_load, 0)` (1).
    #[serde(with = "dem::serde_float")]
    pub worst_energy_growth: f64,
    /// Energy residual of the last step over E_load, `max(δ / E_load, 0)` (1; 0 where no
    /// balance is checked): what a window following the phase step by step reads to find its
    /// own largest growth.
    #[serde(default, with = "dem::serde_float")]
    pub last_energy_growth: f64,
    /// Steps whose position correction moved something (`dem::stabilise`).
    #[serde(default)]
    pub position_corrected_steps: u64,
    /// Potential energy added by the position corrections, `−Σ W_c` over the steps (J), with
    /// `W_c` the work of gravity and the applied loads over a step's correction (module
    /// documentation). Not part of the energy residual δ.
    #[serde(default, with = "dem::serde_float")]
    pub position_correction_energy: f64,
    /// Largest predicted overlap a step's correction removed, over the smallest grain radius (1):
    /// what the step would have left without it.
    #[serde(default, with = "dem::serde_float")]
    pub max_corrected_overlap_ratio: f64,
    /// Steps done in more than one sub-step because a solve at the full step did not converge
    /// ([`dem::step_control::step_subdivided`]).
    #[serde(default)]
    pub subdivided_steps: u64,
    /// Sub-steps kept over the phase (`steps` when none was subdivided).
    #[serde(default)]
    pub substeps: u64,
    /// Largest number of halvings of a kept step.
    #[serde(default)]
    pub max_halvings_used: u32,
    /// Sweeps of the attempts undone before a subdivision (included in `total_sweeps`).
    #[serde(default)]
    pub discarded_sweeps: u64,
    /// Steps done whole during a pause of the subdivision (after repeated failures at its
    /// largest level; [`dem::step_control::FAILURES_BEFORE_BACKOFF`]).
    #[serde(default)]
    pub paused_steps: u64,
    /// Converged steps whose energy grew beyond [`ENERGY_GROWTH_TOLERANCE`] · E_load and that
    /// were solved again at a tighter tolerance, the tighter solve kept
    /// ([`dem::step_control::step_subdivided_checked`]).
    #[serde(default)]
    pub polished_steps: u64,
    /// Newton iterations of the phase's solves (`auto`'s global stage and active-set solves).
    #[serde(default)]
    pub newton_iterations: u64,
    /// Pivots of Lemke's method over the phase's solves.
    #[serde(default)]
    pub pivots: u64,
    /// Whether the rest criterion was met (phases that look for rest).
    pub at_rest: bool,
    /// Translational kinetic energy over `Σ m g d` at the end (1).
    #[serde(with = "dem::serde_float")]
    pub final_energy_ratio: f64,
}

/// Cost of one Newton iteration (a sparse LU of the step's problem) in sweeps, for
/// [`PhaseStats::mean_solve_cost`]: about 20 on 700-contact columns
/// ([`dem::fc::auto::AUTO_HORIZON`]).
pub const NEWTON_ITERATION_SWEEPS: f64 = 20.0;

/// Cost of one pivot of Lemke's method in sweeps, for [`PhaseStats::mean_solve_cost`]: the
/// shear cell's hard sub-steps (about 500 contacts) took 0.44–0.78 s for 2000–3250 pivots,
/// about 0.2 ms a pivot against some 15–20 µs a sweep.
pub const PIVOT_SWEEPS: f64 = 10.0;

/// The earlier of two optional step indices.
fn earliest(a: Option<u64>, b: Option<u64>) -> Option<u64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.min(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

impl PhaseStats {
    /// Accounts for how one step was done (its sub-steps, the attempts undone, a pause, a
    /// polish); [`PhaseStats::record`] accounts for its solve.
    pub fn record_subdivision(&mut self, step: &SubdividedStep) {
        self.substeps += step.substeps.len() as u64;
        self.paused_steps += u64::from(step.paused);
        self.polished_steps += u64::from(step.polished);
        if step.halvings > 0 {
            self.subdivided_steps += 1;
        }
        self.max_halvings_used = self.max_halvings_used.max(step.halvings);
        self.discarded_sweeps += step.discarded_sweeps as u64;
    }

    /// Accounts for one step's solve and time.
    pub fn record(&mut self, r: &StepReport, dt: f64) {
        self.steps += 1;
        self.simulated_time += dt;
        if !r.solver.converged {
            self.unconverged_steps += 1;
            self.first_unconverged_step = earliest(self.first_unconverged_step, Some(r.step));
        }
        self.worst_error = worst(self.worst_error, r.solver.error);
        self.worst_error_without_gap_shifts = worst(
            self.worst_error_without_gap_shifts,
            r.solver.error_without_gap_shifts,
        );
        self.max_sweeps = self.max_sweeps.max(r.solver.iterations);
        self.total_sweeps += r.solver.iterations as u64;
        self.newton_iterations += r.solver.newton_iterations as u64;
        self.pivots += r.solver.pivots as u64;
        self.max_penetration = self.max_penetration.max(r.max_penetration);
    }

    /// Accounts for one step's numerics checks: its overlap against [`PENETRATION_LIMIT`] of
    /// `min_radius` (m), its energy residual `growth = δ / E_load` against
    /// [`ENERGY_GROWTH_TOLERANCE`] (`None` where no balance is checked), and its position
    /// correction (steps, potential energy added, overlap removed).
    pub fn record_checks(&mut self, r: &StepReport, min_radius: f64, growth: Option<f64>) {
        let c = &r.position_correction;
        if c.corrected_contacts > 0 {
            self.position_corrected_steps += 1;
            self.position_correction_energy -= c.load_work;
            if min_radius > 0.0 {
                self.max_corrected_overlap_ratio = self
                    .max_corrected_overlap_ratio
                    .max(c.overlap_before / min_radius);
            }
        }
        if min_radius > 0.0 {
            let ratio = r.max_penetration / min_radius;
            self.max_penetration_ratio = self.max_penetration_ratio.max(ratio);
            if ratio > PENETRATION_LIMIT {
                self.penetration_flagged_steps += 1;
                self.first_penetration_step = earliest(self.first_penetration_step, Some(r.step));
            }
        }
        self.last_energy_growth = growth.map_or(0.0, |g| g.max(0.0));
        if let Some(g) = growth {
            self.worst_energy_growth = self.worst_energy_growth.max(g);
            if g > ENERGY_GROWTH_TOLERANCE {
                self.energy_growth_steps += 1;
                self.first_energy_growth_step =
                    earliest(self.first_energy_growth_step, Some(r.step));
            }
        }
    }

    /// Adds another phase's counts (the rest flag and energy are the other's).
    pub fn merge(&mut self, o: &PhaseStats) {
        self.steps += o.steps;
        self.simulated_time += o.simulated_time;
        self.unconverged_steps += o.unconverged_steps;
        self.first_unconverged_step =
            earliest(self.first_unconverged_step, o.first_unconverged_step);
        self.worst_error = worst(self.worst_error, o.worst_error);
        self.worst_error_without_gap_shifts = worst(
            self.worst_error_without_gap_shifts,
            o.worst_error_without_gap_shifts,
        );
        self.max_sweeps = self.max_sweeps.max(o.max_sweeps);
        self.total_sweeps += o.total_sweeps;
        self.max_penetration = self.max_penetration.max(o.max_penetration);
        self.max_penetration_ratio = self.max_penetration_ratio.max(o.max_penetration_ratio);
        self.penetration_flagged_steps += o.penetration_flagged_steps;
        self.first_penetration_step =
            earliest(self.first_penetration_step, o.first_penetration_step);
        self.energy_growth_steps += o.energy_growth_steps;
        self.first_energy_growth_step =
            earliest(self.first_energy_growth_step, o.first_energy_growth_step);
        self.worst_energy_growth = self.worst_energy_growth.max(o.worst_energy_growth);
        self.last_energy_growth = o.last_energy_growth;
        self.position_corrected_steps += o.position_corrected_steps;
        self.position_correction_energy += o.position_correction_energy;
        self.subdivided_steps += o.subdivided_steps;
        self.substeps += o.substeps;
        self.max_halvings_used = self.max_halvings_used.max(o.max_halvings_used);
        self.discarded_sweeps += o.discarded_sweeps;
        self.paused_steps += o.paused_steps;
        self.polished_steps += o.polished_steps;
        self.newton_iterations += o.newton_iterations;
        self.pivots += o.pivots;
        self.max_corrected_overlap_ratio = self
            .max_corrected_overlap_ratio
            .max(o.max_corrected_overlap_ratio);
        self.at_rest = o.at_rest;
        self.final_energy_ratio = o.final_energy_ratio;
    }

    /// Mean cost of a step's solve in Gauss–Seidel sweeps: sweeps, plus
    /// [`NEWTON_ITERATION_SWEEPS`] per Newton iteration and [`PIVOT_SWEEPS`] per pivot of
    /// Lemke's method (a rough model, for decisions that must not hang on wall-clock time).
    pub fn mean_solve_cost(&self) -> f64 {
        if self.steps == 0 {
            return 0.0;
        }
        (self.total_sweeps as f64
            + NEWTON_ITERATION_SWEEPS * self.newton_iterations as f64
            + PIVOT_SWEEPS * self.pivots as f64)
            / self.steps as f64
    }

    /// Mean sweeps per step.
    pub fn mean_sweeps(&self) -> f64 {
        if self.steps == 0 {
            0.0
        } else {
            self.total_sweeps as f64 / self.steps as f64
        }
    }
}

/// Energy scale of the rest criterion, `Σ m |g| d` over grains (J), d = 2R.
pub fn energy_scale(world: &World) -> f64 {
    let g = world.params.gravity.norm();
    let s: f64 = world
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .map(|b| b.mass * g * 2.0 * b.radius)
        .sum();
    if s > 0.0 {
        s
    } else {
        1.0
    }
}

/// Smallest grain radius (m), 0 without grains.
pub fn min_grain_radius(world: &World) -> f64 {
    let r = world
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .map(|b| b.radius)
        .fold(f64::INFINITY, f64::min);
    if r.is_finite() {
        r
    } else {
        0.0
    }
}

/// Translational kinetic energy of the grains `Σ ½ m |v|²` (J). The rest criterion uses it:
/// a frictionless grain may keep spinning for ever (nothing exerts a torque on it) while the
/// packing is at rest.
pub fn translational_energy(world: &World) -> f64 {
    world
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .map(|b| 0.5 * b.mass * b.velocity.norm_squared())
        .sum()
}

/// How long to run and when to stop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RunUntilRest {
    /// Shortest run (s).
    pub min_time: f64,
    /// Longest run (s).
    pub max_time: f64,
    /// At rest when the translational kinetic energy `Σ ½ m |v|² < rest_energy · Σ m g d` after
    /// each of [`REST_STEPS`] consecutive steps whose solves converged (a capped step's best
    /// iterate can hold a packing still without solving its step: it breaks the run).
    pub rest_energy: f64,
}

/// Consecutive steps the rest criterion must hold.
pub const REST_STEPS: usize = 20;

/// Where a phase stands: its statistics so far (`stats.steps` steps done) and the loop
/// counters of its stop criterion. Saved in checkpoints; a phase continued from it gives the
/// same steps as one never stopped.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PhaseProgress {
    /// What the phase did so far.
    pub stats: PhaseStats,
    /// Consecutive steps the rest criterion has held.
    pub quiet_steps: usize,
    /// Where the subdivision of non-converged steps stands
    /// ([`dem::step_control::step_subdivided`]).
    #[serde(default)]
    pub subdivision: Subdivision,
    /// The load energy scale `E_load` of the energy check ([`load_energy_scale`]), taken when
    /// the phase starts: it depends on the state (a periodic cell's volume), so a resumed
    /// phase keeps the one it started with.
    #[serde(default)]
    pub e_load: Option<f64>,
}

impl PhaseProgress {
    /// Steps done in the phase.
    pub fn steps(&self) -> u64 {
        self.stats.steps
    }
}

/// The scales a phase judges its steps by: the energy scale of the rest criterion
/// ([`energy_scale`]), the load energy scale of the energy balance (kept in the phase's
/// progress, so a resumed phase keeps its own) and the smallest grain radius.
struct PhaseScales {
    energy: f64,
    e_load: f64,
    min_radius: f64,
}

impl PhaseScales {
    /// The scales of `world` for the phase of `progress`.
    fn of(world: &World, progress: &mut PhaseProgress) -> Self {
        let energy = energy_scale(world);
        let e_load = *progress
            .e_load
            .get_or_insert_with(|| load_energy_scale(world));
        Self {
            energy,
            e_load,
            min_radius: min_grain_radius(world),
        }
    }

    /// One step with its accounting ([`accounted_step`]).
    fn step(
        &self,
        world: &mut World,
        progress: &mut PhaseProgress,
    ) -> Result<StepReport, dem::DemError> {
        accounted_step(world, progress, self.e_load, self.min_radius)
    }
}

/// One step with its accounting: solve, time, overlap and energy balance. A step whose solve
/// does not converge is done again in sub-steps as the solver parameters allow
/// ([`step_subdivided_checked`]); the step's energy residual is the sum of its kept sub-steps'
/// (the balance is additive), judged against the same tolerance as a whole step's. A converged
/// step whose energy grew beyond that tolerance is solved again at a tenth of the solver
/// tolerance before it is judged.
fn accounted_step(
    world: &mut World,
    progress: &mut PhaseProgress,
    e_load: f64,
    min_radius: f64,
) -> Result<StepReport, dem::DemError> {
    let dt = world.params.dt;
    let step = step_subdivided_checked(
        world,
        &mut progress.subdivision,
        Some(ENERGY_GROWTH_TOLERANCE * e_load),
    )?;
    let r = step.report;
    progress.stats.record(&r, dt);
    progress.stats.record_subdivision(&step);
    let growth = step.energy_residual() / e_load;
    progress
        .stats
        .record_checks(&r, min_radius, growth.is_finite().then_some(growth));
    Ok(r)
}

/// Steps `world` (with its current parameters) until rest or `max_time`. `on_step` is called
/// after every step with the step's report; returning `false` stops the phase early (e.g. on
/// Ctrl-C). An engine error (non-finite state) ends the phase with that error.
pub fn run_until_rest(
    world: &mut World,
    run: &RunUntilRest,
    mut on_step: impl FnMut(&World, &StepReport) -> bool,
) -> Result<PhaseStats, dem::DemError> {
    let mut progress = PhaseProgress::default();
    continue_until_rest(world, run, &mut progress, |w, r, _| on_step(w, r))
}

/// [`run_until_rest`] continued from `progress` (default for a new phase), which it keeps up to
/// date; `on_step` also receives it, updated for the step just done. The rest criterion is
/// checked before each step, so a phase saved on the step that met it ends without stepping.
pub fn continue_until_rest(
    world: &mut World,
    run: &RunUntilRest,
    progress: &mut PhaseProgress,
    mut on_step: impl FnMut(&World, &StepReport, &PhaseProgress) -> bool,
) -> Result<PhaseStats, dem::DemError> {
    let sc = PhaseScales::of(world, progress);
    let dt = world.params.dt;
    let max_steps = (run.max_time / dt).ceil() as u64;
    let min_steps = (run.min_time / dt).ceil() as u64;
    loop {
        if progress.steps() >= min_steps && progress.quiet_steps >= REST_STEPS {
            progress.stats.at_rest = true;
            break;
        }
        if progress.steps() >= max_steps {
            break;
        }
        let r = sc.step(world, progress)?;
        let ratio = translational_energy(world) / sc.energy;
        progress.stats.final_energy_ratio = ratio;
        if ratio < run.rest_energy && r.solver.converged {
            progress.quiet_steps += 1;
        } else {
            progress.quiet_steps = 0;
        }
        if !on_step(world, &r, progress) {
            break;
        }
    }
    Ok(progress.stats)
}

/// Steps `world` `steps` times, calling `on_step` after each (returning `false` stops early).
pub fn run_steps(
    world: &mut World,
    steps: u64,
    mut on_step: impl FnMut(&World, &StepReport) -> bool,
) -> Result<PhaseStats, dem::DemError> {
    let mut progress = PhaseProgress::default();
    continue_steps(world, steps, &mut progress, |w, r, _| on_step(w, r))
}

/// [`run_steps`] continued from `progress` (default for a new phase): steps until `steps` are
/// done in the phase.
pub fn continue_steps(
    world: &mut World,
    steps: u64,
    progress: &mut PhaseProgress,
    mut on_step: impl FnMut(&World, &StepReport, &PhaseProgress) -> bool,
) -> Result<PhaseStats, dem::DemError> {
    let sc = PhaseScales::of(world, progress);
    while progress.steps() < steps {
        let r = sc.step(world, progress)?;
        progress.stats.final_energy_ratio = translational_energy(world) / sc.energy;
        if !on_step(world, &r, progress) {
            break;
        }
    }
    progress.stats.final_energy_ratio = translational_energy(world) / sc.energy;
    Ok(progress.stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use dem::math::Vector;
    use dem::{ContactLaws, WorldParams};

    #[test]
    fn the_last_step_growth_is_that_steps_own() {
        // A window reads each step's growth from here: the phase worst would hide a window's
        // step behind a larger one before it.
        let mut s = PhaseStats::default();
        let r = dem::StepReport::default();
        s.record_checks(&r, 1e-3, Some(0.22));
        assert_eq!((s.last_energy_growth, s.worst_energy_growth), (0.22, 0.22));
        s.record_checks(&r, 1e-3, Some(0.05));
        assert_eq!((s.last_energy_growth, s.worst_energy_growth), (0.05, 0.22));
        s.record_checks(&r, 1e-3, Some(-0.3));
        assert_eq!(s.last_energy_growth, 0.0, "dissipation is no growth");
        s.record_checks(&r, 1e-3, None);
        assert_eq!(s.last_energy_growth, 0.0);
        assert_eq!(s.energy_growth_steps, 2);
    }

    #[test]
    fn a_nan_error_stays_in_the_phase_worst() {
        // f64::max would drop it.
        let mut s = PhaseStats::default();
        let mut r = dem::StepReport::default();
        r.solver.error = f64::NAN;
        s.record(&r, 1e-3);
        r.solver.error = 1e-6;
        s.record(&r, 1e-3);
        assert!(s.worst_error.is_nan());
    }

    fn params(theta: f64) -> WorldParams {
        WorldParams {
            dt: 1e-3,
            theta,
            solver: dem::SolverParams {
                tolerance: 1e-10,
                max_iterations: 100_000,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// A stack of `n` disks of radius `r` above a floor, `gap` apart, the lowest touching it,
    /// every other one shifted sideways by `shift` r.
    fn stack(n: usize, r: f64, gap: f64, shift: f64, theta: f64) -> World {
        let mut w = World::new(params(theta), ContactLaws::new(&["glass"], 0.3));
        w.add_line_wall("floor", Vector::zeros(), Vector::new(0.0, 1.0), 0);
        for k in 0..n {
            let x = if k % 2 == 0 { 0.0 } else { shift * r };
            w.add_grain(Vector::new(x, r + k as f64 * (2.0 * r + gap)), r, 2500.0, 0);
        }
        w
    }

    /// Rest needs [`REST_STEPS`] quiet steps in a row that converged. Three touching disks on a
    /// floor, at rest, swept once a step: the first step, from zero impulses, stops at the cap
    /// (a single sweep cannot balance the stack to 10⁻¹⁰), and capped steps keep coming between
    /// converged ones, the grains nearly still all along (every step's KE below the rest
    /// threshold, 10⁻³ of the scale): counting still steps alone, the phase would be at rest
    /// after its first `REST_STEPS` steps. It must end on a run of `REST_STEPS` converged
    /// steps instead.
    #[test]
    fn capped_steps_do_not_count_towards_rest() {
        let mut w = stack(3, 1e-3, 0.0, 0.0, 1.0);
        w.params.dt = 1e-4;
        w.params.solver.max_iterations = 1;
        w.params.solver.method = dem::fc::SolverMethod::Nlgs;
        let run = RunUntilRest {
            min_time: 0.0,
            max_time: 0.1,
            rest_energy: 1e-3,
        };
        let scale = energy_scale(&w);
        let mut steps = Vec::new();
        let stats = run_until_rest(&mut w, &run, |w, r| {
            steps.push((r.solver.converged, translational_energy(w) / scale));
            true
        })
        .unwrap();
        assert!(stats.at_rest);
        assert!(steps.iter().all(|&(_, e)| e < run.rest_energy), "{steps:?}");
        assert!(!steps[0].0 && steps.len() > REST_STEPS, "{stats:?}");
        assert!(steps[steps.len() - REST_STEPS..].iter().all(|&(c, _)| c));
        assert!(!steps[steps.len() - REST_STEPS - 1].0);
    }

    /// Free fall: θ = 1 dissipates exactly `½ m h² g²` per step (v⁺ is used for the whole
    /// step), θ = 1/2 conserves energy exactly.
    #[test]
    fn free_fall_residual_is_the_analytic_one() {
        for (theta, expected) in [(1.0, -0.5), (0.5, 0.0)] {
            let mut w = World::new(params(theta), ContactLaws::new(&["glass"], 0.3));
            w.add_grain(Vector::new(0.0, 1.0), 1e-3, 2500.0, 0);
            w.bodies[0].velocity = Vector::new(0.3, 0.7);
            let m = w.bodies[0].mass;
            let (h, g) = (w.params.dt, w.params.gravity.norm());
            for _ in 0..5 {
                let probe = EnergyProbe::before(&w);
                w.step().unwrap();
                let delta = probe.residual(&w);
                let exact = expected * m * h * h * g * g;
                assert!(
                    (delta - exact).abs() <= 1e-9 * m * h * h * g * g,
                    "θ = {theta}: δ = {delta:e}, expected {exact:e}"
                );
            }
        }
    }

    /// A grain carried up by a floor moving at constant velocity: the floor's drive does the
    /// work `m g v h` per step that lifts the grain, the residual is zero (to the solver's
    /// tolerance), and `W_drive` has the right sign (without it δ would be `−m g v h`).
    #[test]
    fn driven_floor_work_balances_the_lift() {
        let v = 0.01;
        let mut w = World::new(params(1.0), ContactLaws::new(&["glass"], 0.3));
        let floor = w.add_line_wall("floor", Vector::zeros(), Vector::new(0.0, 1.0), 0) as usize;
        w.bodies[floor].velocity = Vector::new(0.0, v);
        let r = 1e-3;
        let g = w.add_grain(Vector::new(0.0, r), r, 2500.0, 0) as usize;
        w.bodies[g].velocity = Vector::new(0.0, v);
        let m = w.bodies[g].mass;
        let scale = load_energy_scale(&w);
        let lift = m * w.params.gravity.norm() * v * w.params.dt;
        for _ in 0..20 {
            let probe = EnergyProbe::before(&w);
            w.step().unwrap();
            let delta = probe.residual(&w);
            assert!(
                delta.abs() < 1e-6 * lift,
                "δ = {delta:e} J with a lift of {lift:e} J per step"
            );
        }
        assert!((w.bodies[g].velocity.y - v).abs() < 1e-9);
        assert!(
            lift / scale > 1e-3,
            "the check is not trivial: lift {lift:e}, scale {scale:e}"
        );
    }

    /// θ = 1/2 on a collapsing stack, without the position correction (the plain Moreau–Jean
    /// step), gains energy in some steps and lets grains overlap beyond the limit; with the
    /// correction (the default) the projection removes those overlaps (above the limit when
    /// predicted) and no step starts beyond the limit. The same stack with θ = 1 is never
    /// flagged.
    #[test]
    fn theta_half_stack_is_flagged_theta_one_is_not() {
        let mut corrected = stack(6, 1e-3, 2e-4, 0.3, 0.5);
        let s = run_steps(&mut corrected, 400, |_, _| true).unwrap();
        assert!(s.position_corrected_steps > 0, "{s:?}");
        assert!(s.max_corrected_overlap_ratio > PENETRATION_LIMIT, "{s:?}");
        assert_eq!(s.penetration_flagged_steps, 0, "{s:?}");
        let mut half = stack(6, 1e-3, 2e-4, 0.3, 0.5);
        half.params.position_correction = false;
        let s = run_steps(&mut half, 400, |_, _| true).unwrap();
        assert_eq!(s.position_corrected_steps, 0, "{s:?}");
        assert!(s.energy_growth_steps > 0, "{s:?}");
        assert!(
            s.worst_energy_growth > 10.0 * ENERGY_GROWTH_TOLERANCE,
            "{s:?}"
        );
        assert!(s
            .first_energy_growth_step
            .is_some_and(|k| (1..=400).contains(&k)));
        assert!(s.penetration_flagged_steps > 0 && s.max_penetration_ratio > PENETRATION_LIMIT);
        let mut one = stack(6, 1e-3, 2e-4, 0.3, 1.0);
        let s = run_steps(&mut one, 400, |_, _| true).unwrap();
        assert_eq!(s.energy_growth_steps, 0, "{s:?}");
        assert!(s.worst_energy_growth <= 1e-12, "{s:?}");
        assert_eq!(s.penetration_flagged_steps, 0, "{s:?}");
        assert_eq!(s.first_energy_growth_step, None);
    }

    /// A disk started 5 % of its radius inside the floor, at rest under gravity: the step's
    /// position correction lifts it to the slop without a velocity, so the energy residual δ of
    /// the step stays at round-off (no growth flagged), while the potential energy it added,
    /// `m g (0.05 R − s)`, is reported apart in `position_correction_energy` (10⁻⁹ relative) and
    /// equals the change of `World::potential_energy` over the phase (10⁻⁶ relative).
    #[test]
    fn position_correction_is_accounted_apart_from_the_residual() {
        let r = 1e-3;
        let mut w = World::new(params(1.0), ContactLaws::new(&["glass"], 0.3));
        w.add_line_wall("floor", Vector::zeros(), Vector::new(0.0, 1.0), 0);
        let g = w.add_grain(Vector::new(0.0, 0.95 * r), r, 2500.0, 0) as usize;
        let m = w.bodies[g].mass;
        let e_pot = w.potential_energy();
        let s = run_steps(&mut w, 5, |_, _| true).unwrap();
        let lift = 0.05 * r - dem::stabilise::SLOP * r;
        let added = m * w.params.gravity.norm() * lift;
        assert_eq!(s.position_corrected_steps, 1, "{s:?}");
        assert!(
            (s.position_correction_energy - added).abs() <= 1e-9 * added,
            "{s:?}, expected {added:e} J"
        );
        assert!((s.max_corrected_overlap_ratio - 0.05).abs() < 1e-9, "{s:?}");
        assert_eq!(s.energy_growth_steps, 0, "{s:?}");
        assert!(s.worst_energy_growth <= 1e-12, "{s:?}");
        let de_pot = w.potential_energy() - e_pot;
        assert!((de_pot - added).abs() <= 1e-6 * added, "ΔE_pot {de_pot:e}");
        let mut other = PhaseStats::default();
        other.merge(&s);
        other.merge(&s);
        assert_eq!(other.position_corrected_steps, 2);
        assert!((other.position_correction_energy - 2.0 * added).abs() <= 1e-9 * added);
    }

    /// Synthetic steps: counts, first step, worst value, and the earliest first step on merge.
    #[test]
    fn checks_count_and_name_the_first_step() {
        let mut s = PhaseStats::default();
        let step = |k: u64, pen: f64| StepReport {
            step: k,
            max_penetration: pen,
            ..Default::default()
        };
        s.record_checks(&step(7, 0.0), 1e-3, Some(0.5 * ENERGY_GROWTH_TOLERANCE));
        s.record_checks(&step(8, 2e-5), 1e-3, Some(3.0 * ENERGY_GROWTH_TOLERANCE));
        s.record_checks(&step(9, 5e-6), 1e-3, Some(-1.0));
        s.record_checks(&step(10, 3e-5), 1e-3, Some(2.0 * ENERGY_GROWTH_TOLERANCE));
        assert_eq!(s.energy_growth_steps, 2);
        assert_eq!(s.first_energy_growth_step, Some(8));
        assert_eq!(s.worst_energy_growth, 3.0 * ENERGY_GROWTH_TOLERANCE);
        assert_eq!(s.penetration_flagged_steps, 2);
        assert_eq!(s.first_penetration_step, Some(8));
        assert!((s.max_penetration_ratio - 0.03).abs() < 1e-15);
        let mut earlier = PhaseStats::default();
        earlier.record_checks(&step(3, 0.0), 1e-3, Some(1.0));
        earlier.merge(&s);
        assert_eq!(earlier.first_energy_growth_step, Some(3));
        assert_eq!(earlier.energy_growth_steps, 3);
        assert_eq!(earlier.first_penetration_step, Some(8));
    }

    /// A phase stopped after k steps, its world rebuilt from its state and continued from its
    /// progress, ends on the same step with the same statistics and bit-identical bodies as the
    /// phase never stopped — for every k, including the step that meets the rest criterion.
    #[test]
    fn a_continued_phase_is_bit_identical() {
        let run = RunUntilRest {
            min_time: 0.0,
            max_time: 1.0,
            rest_energy: 1e-6,
        };
        let mut whole = stack(3, 1e-3, 2e-4, 0.0, 1.0);
        let all = run_until_rest(&mut whole, &run, |_, _| true).unwrap();
        assert!(all.at_rest, "{all:?}");
        for k in [1, all.steps / 2, all.steps - 1, all.steps] {
            let mut w = stack(3, 1e-3, 2e-4, 0.0, 1.0);
            let mut p = PhaseProgress::default();
            continue_until_rest(&mut w, &run, &mut p, |_, _, p| p.steps() < k).unwrap();
            assert_eq!(p.steps(), k);
            let mut w = World::from_state(w.state());
            let s = continue_until_rest(&mut w, &run, &mut p, |_, _, _| true).unwrap();
            assert_eq!(s, all, "stopped after {k} steps");
            for (a, b) in w.bodies.iter().zip(&whole.bodies) {
                assert_eq!(a.position.x.to_bits(), b.position.x.to_bits());
                assert_eq!(a.position.y.to_bits(), b.position.y.to_bits());
                assert_eq!(a.velocity.y.to_bits(), b.velocity.y.to_bits());
            }
        }
    }
}
