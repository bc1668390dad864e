//! What `grainlaw solve-fc PROBLEM.json [--tol T] [--out SOLUTION.json]` does: read, solve,
//! report, optionally write the solution.

use std::fmt;
use std::path::Path;
use std::time::Instant;

use super::error::FcError;
use super::nsgs::{solve, FcOptions, FcSolution};
use super::output::write_solution;
use super::reader::read_problem;

/// Outcome of [`solve_file`].
#[derive(Debug, Clone)]
pub struct SolveReport {
    /// Problem file name (without directories).
    pub problem: String,
    /// Number of contacts.
    pub contacts: usize,
    /// Tolerance asked for.
    pub tolerance: f64,
    /// Seconds spent reading and validating the file.
    pub read_seconds: f64,
    /// The solution (with iterations, error, solve seconds and the converged flag).
    pub solution: FcSolution,
}

impl fmt::Display for SolveReport {
    /// One line: `problem=… contacts=… iterations=… error=… seconds=… converged=…`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "problem={} contacts={} iterations={} error={:.3e} tolerance={:.1e} seconds={:.4} converged={}",
            self.problem,
            self.contacts,
            self.solution.iterations,
            self.solution.error,
            self.tolerance,
            self.solution.seconds,
            self.solution.converged
        )
    }
}

/// Reads the problem at `problem` (fc-problem-v1 JSON, plain or gzip), solves it with `options`
/// and, when `out` is given, writes the solution there atomically
/// (`{"r", "u", "iterations", "error", "seconds", "converged"}`).
///
/// The solution is written even when the solver did not converge (`converged: false` in the
/// file and in the report); the caller decides how to signal it (the CLI warns).
pub fn solve_file(
    problem: &Path,
    options: &FcOptions,
    out: Option<&Path>,
) -> Result<SolveReport, FcError> {
    let t0 = Instant::now();
    let p = read_problem(problem)?;
    let read_seconds = t0.elapsed().as_secs_f64();
    let solution = solve(&p, options)?;
    if let Some(out) = out {
        write_solution(out, &solution)?;
    }
    Ok(SolveReport {
        problem: problem
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        contacts: p.contacts(),
        tolerance: options.tolerance,
        read_seconds,
        solution,
    })
}

/// [`solve_file`] with the default options and tolerance `tol` (1e-6 when `None`).
pub fn solve_fc(
    problem: &Path,
    tol: Option<f64>,
    out: Option<&Path>,
) -> Result<SolveReport, FcError> {
    let options = FcOptions {
        tolerance: tol.unwrap_or(1e-6),
        ..FcOptions::default()
    };
    solve_file(problem, &options, out)
}
