//! The solver-sensitivity measure of a sampled state ([`crate::verdict::Sensitivity`]): the
//! step that led to it solved again, from the same state, to
//! [`crate::verdict::SENSITIVITY_TOLERANCE`], and the state as that solve would have left it.
//!
//! The re-solve takes the step's problem `u = W r + q` as the run assembled it
//! ([`dem::World::last_step_problem`]; for a subdivided step, its last sub-step's), starts from
//! the impulses the run's solver returned and uses `auto` on the standalone problem
//! ([`dem::fc::solve_by`]: Gauss–Seidel while it makes progress, the proximal semismooth Newton
//! method, then the active-set solve and Lemke's method, exact for the 2D problem; Acary,
//! Brémond & Huber 2018 for the formulations). Its impulses then give the state through
//! Moreau–Jean's velocity update ([`dem::World::snapshot_with_last_impulses`]). Differences
//! between the two states' measured stresses are the run's solver residual seen by the
//! measurement.

use dem::fc::{solve_by, FcOptions, NewtonParams, SolverMethod};
use dem::{Snapshot, World};

use crate::verdict::{Sensitivity, SENSITIVITY_TOLERANCE};

/// Gauss–Seidel sweeps of a re-solve before its global stages end it.
pub const SENSITIVITY_SWEEPS: usize = 2000;

/// The outcome of a re-solve of a sample's step.
#[derive(Debug, Clone, PartialEq)]
pub enum Resolved<T> {
    /// Solved to the tolerance: what the measure gives on the re-solved state.
    Solved(T),
    /// The re-solve did not reach the tolerance, or failed (a singular factorisation, a
    /// non-finite state): counted as unresolved, left out of the measure.
    Failed,
    /// The step's problem is not available (no step since a resume, a
    /// deformable cell): no measure, counted apart.
    Unavailable,
}

impl<T> Resolved<T> {
    /// Applies `f` to a solved state.
    pub fn and_then<U>(self, f: impl FnOnce(T) -> Resolved<U>) -> Resolved<U> {
        match self {
            Resolved::Solved(t) => f(t),
            Resolved::Failed => Resolved::Failed,
            Resolved::Unavailable => Resolved::Unavailable,
        }
    }
}

/// The world's snapshot with its last step's contact problem solved to
/// [`SENSITIVITY_TOLERANCE`] (module documentation). A failure of the re-solve is an outcome
/// of the measure, never an error of the run.
pub fn resolved_snapshot(w: &World) -> Resolved<Snapshot> {
    let Some((problem, r)) = w.last_step_problem() else {
        return Resolved::Unavailable;
    };
    let options = FcOptions {
        tolerance: SENSITIVITY_TOLERANCE,
        max_iterations: SENSITIVITY_SWEEPS,
        initial_guess: Some(r),
        ..FcOptions::default()
    };
    match solve_by(
        &problem,
        &options,
        SolverMethod::Auto,
        &NewtonParams::default(),
    ) {
        Ok((solution, _)) if solution.converged => w
            .snapshot_with_last_impulses(&solution.r)
            .map_or(Resolved::Failed, Resolved::Solved),
        _ => Resolved::Failed,
    }
}

/// Adds a sample to `s`: its bulk `[σ_xy, σ_yy]` as run and the outcome of its re-solve
/// ([`Sensitivity::add`]; an unavailable problem is counted apart).
pub fn record(s: &mut Sensitivity, run: [f64; 2], resolved: Resolved<[f64; 2]>) {
    match resolved {
        Resolved::Solved(r) => s.add(run, Some(r)),
        Resolved::Failed => s.add(run, None),
        Resolved::Unavailable => s.unavailable += 1,
    }
}
