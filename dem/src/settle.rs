//! Settling a world to rest: [`settle`] steps it (with an optional adaptive step,
//! [`StepControl`], or the subdivision of unconverged steps, [`step_subdivided`]) until the
//! kinetic over potential energy [`energy_ratio`] falls below a target after a converged step,
//! and reports the run ([`SettleReport`]). The benchmark columns of `grainlaw_core::benchmarks`
//! (`grainlaw bench`) settle through it.

use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::step_control::{step_subdivided, StepControl, Subdivision};
use crate::World;

/// Outcome of settling a column to rest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SettleReport {
    /// Grains.
    pub grains: usize,
    /// Box width (m); NaN when unknown ([`settle`] of a given world).
    pub width: f64,
    /// Steps until rest.
    pub steps: u64,
    /// Simulated time (s).
    pub simulated_seconds: f64,
    /// Smallest and largest time step the steps used (s).
    pub dt_range: [f64; 2],
    /// Wall-clock seconds (building excluded).
    pub wall_seconds: f64,
    /// Mean sweeps per step.
    pub mean_sweeps: f64,
    /// Steps that stopped at the sweep cap.
    pub unconverged_steps: u64,
    /// Final kinetic / potential energy (potential `Σ m g y`, y above the floor).
    pub energy_ratio: f64,
    /// Whether the ratio went below the target, on a step whose solve converged, before the
    /// time limit.
    pub settled: bool,
    /// Height of the highest grain top (m).
    pub height: f64,
}

/// Kinetic energy `Σ ½ m |v|² + ½ I ω²` over potential energy `Σ m g y` of the grains (floor at
/// y = 0).
pub fn energy_ratio(w: &World) -> f64 {
    let g = w.params.gravity.norm();
    let (mut ke, mut pe) = (0.0, 0.0);
    for b in w.bodies.iter().filter(|b| b.kind == crate::BodyKind::Grain) {
        ke += 0.5 * b.mass * b.velocity.norm_squared() + 0.5 * b.inertia * b.omega * b.omega;
        pe += b.mass * g * b.position.y;
    }
    if pe > 0.0 {
        ke / pe
    } else {
        f64::INFINITY
    }
}

/// Steps `w` until [`energy_ratio`] < `target` after a step whose solve converged (or
/// `max_time` simulated seconds), timed; with
/// `control`, the time step follows [`StepControl`] (starting from `w.params.dt`); without it,
/// steps whose solve does not converge are subdivided as `w.params.solver.max_halvings` allows
/// ([`step_subdivided`]; `unconverged_steps` counts those left unconverged at the largest
/// subdivision, `dt_range` the sub-steps).
pub fn settle(
    w: &mut World,
    target: f64,
    max_time: f64,
    mut control: Option<StepControl>,
) -> SettleReport {
    let t0 = Instant::now();
    let (mut steps, mut sweeps, mut unconverged) = (0u64, 0u64, 0u64);
    let (mut simulated, mut dt_min, mut dt_max) = (0.0f64, f64::INFINITY, 0.0f64);
    let mut ratio = energy_ratio(w);
    // Rest is declared on a step whose solve converged: a capped step carries its best
    // iterate, and a packing held still by impulses that do not solve the step is not at rest
    // (a primed deposit could otherwise be declared settled after one capped step, its time
    // reported as 0).
    let mut last_converged = false;
    let mut subdivision = Subdivision::default();
    // half a step of slack: the sum of the steps must not add a step to a fixed-step run
    while simulated < max_time - 0.5 * w.params.dt {
        let h = w.params.dt;
        let (rep, sub_h) = if control.is_some() {
            let Ok(rep) = w.step() else { break };
            (rep, h)
        } else {
            let Ok(s) = step_subdivided(w, &mut subdivision) else {
                break;
            };
            (s.report, h / f64::from(1u32 << s.halvings))
        };
        steps += 1;
        simulated += h;
        dt_min = dt_min.min(sub_h);
        dt_max = dt_max.max(sub_h);
        sweeps += rep.solver.iterations as u64;
        unconverged += u64::from(!rep.solver.converged);
        ratio = energy_ratio(w);
        last_converged = rep.solver.converged;
        if ratio < target && last_converged {
            break;
        }
        if let Some(c) = control.as_mut() {
            c.after(w, &rep);
        }
    }
    let height = w
        .bodies
        .iter()
        .filter(|b| b.kind == crate::BodyKind::Grain)
        .map(|b| b.position.y + b.radius)
        .fold(0.0, f64::max);
    let grains = w
        .bodies
        .iter()
        .filter(|b| b.kind == crate::BodyKind::Grain)
        .count();
    SettleReport {
        grains,
        width: f64::NAN,
        steps,
        simulated_seconds: simulated,
        dt_range: if steps > 0 {
            [dt_min, dt_max]
        } else {
            [w.params.dt; 2]
        },
        wall_seconds: t0.elapsed().as_secs_f64(),
        mean_sweeps: sweeps as f64 / steps.max(1) as f64,
        unconverged_steps: unconverged,
        energy_ratio: ratio,
        settled: ratio < target && last_converged,
        height,
    }
}
