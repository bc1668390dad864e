//! The solver-sensitivity measure of a sampled state ([`crate::verdict::Sensitivity`]): the
//! step that led to it solved again, from the same state, to
//! [`crate::verdict::SENSITIVITY_TOLERANCE`], and the state as that solve would have left it.
//!
//! The re-solve takes the step's problem `u = W r + q` as the run assembled it
//! ([`dem::World::last_step_problem`]), starts from the impulses the run's solver returned and
//! uses `auto` on the standalone problem ([`dem::fc::solve_by`]: Gauss–Seidel while it makes
//! progress, the proximal semismooth Newton method, then the active-set solve and Lemke's
//! method, exact for the 2D problem; Acary, Brémond & Huber 2018 for the formulations). Its
//! impulses then give the state through Moreau–Jean's velocity update
//! ([`dem::World::snapshot_with_last_impulses`]). Differences between the two states' measured
//! stresses are the run's solver residual seen by the measurement.

use dem::fc::{solve_by, FcOptions, NewtonParams, SolverMethod};
use dem::{Snapshot, World};

use crate::error::Result;
use crate::verdict::SENSITIVITY_TOLERANCE;

/// Gauss–Seidel sweeps of a re-solve before its global stages end it.
pub const SENSITIVITY_SWEEPS: usize = 2000;

/// The world's snapshot with its last step's contact problem solved to
/// [`SENSITIVITY_TOLERANCE`] (module documentation); `None` when that solve did not reach it
/// or the problem is not available (no step since an undo or a resume, a deformable cell).
///
/// # Errors
/// A malformed problem (not expected from the engine's own assembly).
pub fn resolved_snapshot(w: &World) -> Result<Option<Snapshot>> {
    let Some((problem, r)) = w.last_step_problem() else {
        return Ok(None);
    };
    let options = FcOptions {
        tolerance: SENSITIVITY_TOLERANCE,
        max_iterations: SENSITIVITY_SWEEPS,
        initial_guess: Some(r),
        ..FcOptions::default()
    };
    let (solution, _) = solve_by(
        &problem,
        &options,
        SolverMethod::Auto,
        &NewtonParams::default(),
    )?;
    if !solution.converged {
        return Ok(None);
    }
    Ok(Some(w.snapshot_with_last_impulses(&solution.r)?))
}
