//! Running a world through a phase (deposition, relaxation, a driven run) and accounting for
//! what the contact solver did: non-converged steps and the worst error are counted, never
//! hidden.

use dem::{StepReport, World};
use serde::{Deserialize, Serialize};

/// What the contact solver and the engine did over a phase.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PhaseStats {
    /// Steps done.
    pub steps: u64,
    /// Simulated time (s).
    pub simulated_time: f64,
    /// Steps whose contact solve stopped at the sweep cap above its tolerance.
    pub unconverged_steps: u64,
    /// Largest error measure at the end of a step's solve (1).
    pub worst_error: f64,
    /// Largest number of sweeps of one step.
    pub max_sweeps: usize,
    /// Sum of sweeps over the steps.
    pub total_sweeps: u64,
    /// Largest overlap at the start of a step (m).
    pub max_penetration: f64,
    /// Whether the rest criterion was met (phases that look for rest).
    pub at_rest: bool,
    /// Translational kinetic energy over `Σ m g d` at the end (1).
    pub final_energy_ratio: f64,
}

impl PhaseStats {
    /// Accounts for one step.
    pub fn record(&mut self, r: &StepReport, dt: f64) {
        self.steps += 1;
        self.simulated_time += dt;
        if !r.solver.converged {
            self.unconverged_steps += 1;
        }
        self.worst_error = self.worst_error.max(r.solver.error);
        self.max_sweeps = self.max_sweeps.max(r.solver.iterations);
        self.total_sweeps += r.solver.iterations as u64;
        self.max_penetration = self.max_penetration.max(r.max_penetration);
    }

    /// Adds another phase's counts (the rest flag and energy are the other's).
    pub fn merge(&mut self, o: &PhaseStats) {
        self.steps += o.steps;
        self.simulated_time += o.simulated_time;
        self.unconverged_steps += o.unconverged_steps;
        self.worst_error = self.worst_error.max(o.worst_error);
        self.max_sweeps = self.max_sweeps.max(o.max_sweeps);
        self.total_sweeps += o.total_sweeps;
        self.max_penetration = self.max_penetration.max(o.max_penetration);
        self.at_rest = o.at_rest;
        self.final_energy_ratio = o.final_energy_ratio;
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
        .filter(|b| b.kind == dem::BodyKind::Grain)
        .map(|b| b.mass * g * 2.0 * b.radius)
        .sum();
    if s > 0.0 {
        s
    } else {
        1.0
    }
}

/// Translational kinetic energy of the grains `Σ ½ m |v|²` (J). The rest criterion uses it:
/// a frictionless grain may keep spinning for ever (nothing exerts a torque on it) while the
/// packing is at rest.
pub fn translational_energy(world: &World) -> f64 {
    world
        .bodies
        .iter()
        .filter(|b| b.kind == dem::BodyKind::Grain)
        .map(|b| 0.5 * b.mass * b.velocity.norm_squared())
        .sum()
}

/// How long to run and when to stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunUntilRest {
    /// Shortest run (s).
    pub min_time: f64,
    /// Longest run (s).
    pub max_time: f64,
    /// At rest when the translational kinetic energy `Σ ½ m |v|² < rest_energy · Σ m g d` for
    /// [`REST_STEPS`] consecutive steps.
    pub rest_energy: f64,
}

/// Consecutive steps the rest criterion must hold.
pub const REST_STEPS: usize = 20;

/// Steps `world` (with its current parameters) until rest or `max_time`. `on_step` is called
/// after every step with the step's report; returning `false` stops the phase early (e.g. on
/// Ctrl-C). An engine error (non-finite state) ends the phase with that error.
pub fn run_until_rest(
    world: &mut World,
    run: &RunUntilRest,
    mut on_step: impl FnMut(&World, &StepReport) -> bool,
) -> Result<PhaseStats, dem::DemError> {
    let scale = energy_scale(world);
    let dt = world.params.dt;
    let max_steps = (run.max_time / dt).ceil() as u64;
    let min_steps = (run.min_time / dt).ceil() as u64;
    let mut stats = PhaseStats::default();
    let mut quiet = 0usize;
    for s in 0..max_steps {
        let r = world.step()?;
        stats.record(&r, dt);
        let ratio = translational_energy(world) / scale;
        stats.final_energy_ratio = ratio;
        if ratio < run.rest_energy {
            quiet += 1;
        } else {
            quiet = 0;
        }
        if !on_step(world, &r) {
            break;
        }
        if s + 1 >= min_steps && quiet >= REST_STEPS {
            stats.at_rest = true;
            break;
        }
    }
    Ok(stats)
}

/// Steps `world` `steps` times, calling `on_step` after each (returning `false` stops early).
pub fn run_steps(
    world: &mut World,
    steps: u64,
    mut on_step: impl FnMut(&World, &StepReport) -> bool,
) -> Result<PhaseStats, dem::DemError> {
    let dt = world.params.dt;
    let scale = energy_scale(world);
    let mut stats = PhaseStats::default();
    for _ in 0..steps {
        let r = world.step()?;
        stats.record(&r, dt);
        if !on_step(world, &r) {
            break;
        }
    }
    stats.final_energy_ratio = translational_energy(world) / scale;
    Ok(stats)
}
