//! The error measure of fc-problem-v1 (identical to Siconos' `fc2d_compute_error`).
//!
//! ```text
//! u = W r + q,   ū_α = (u_nα + μ_α |u_tα|, u_tα),
//! e = ‖r − proj_K(r − ū)‖₂ / max(‖q‖₂, ‖r‖₂, ‖u‖₂)
//! ```
//!
//! with ρ = 1 in the projection and all contacts stacked in one vector; when the scale
//! `max(‖q‖, ‖r‖, ‖u‖)` is not above machine epsilon the absolute residual is returned.

use super::problem::{FcProblem, ProblemCone};
use crate::cone::natural_map_error;

/// The error measure `e` and the velocity `u = W r + q` at impulses `r` (length 2 nc).
///
/// # Panics
/// If `r.len() != 2 nc` (programming error).
pub fn error_and_velocity(problem: &FcProblem, r: &[f64]) -> (f64, Vec<f64>) {
    let u = problem.velocity(r);
    (error_given_velocity(problem.mu(), problem.q(), r, &u), u)
}

/// The error measure `e` of impulses `r` (length 2 nc), recomputing `u = W r + q`.
pub fn fc_error(problem: &FcProblem, r: &[f64]) -> f64 {
    error_and_velocity(problem, r).0
}

/// The error measure from `μ`, `q`, `r` and an already computed `u = W r + q` (all interleaved
/// `(n, t)` per contact): [`natural_map_error`] on the plane cones.
pub fn error_given_velocity(mu: &[f64], q: &[f64], r: &[f64], u: &[f64]) -> f64 {
    natural_map_error(mu.len(), |a| ProblemCone { mu: mu[a] }, q, r, u)
}
