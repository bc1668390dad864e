//! What `grainlaw solve-fc PROBLEM.json [--tol T] [--out SOLUTION.json]` does: read, solve,
//! report, optionally write the solution.

use std::fmt;
use std::path::Path;
use std::time::Instant;

use super::error::FcError;
use super::measure::fc_error;
use super::method::{solve_by, MethodReport, SolverMethod};
use super::newton::NewtonParams;
use super::nsgs::{FcOptions, FcSolution};
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
    /// The method and what Newton did.
    pub method: MethodReport,
    /// The error measure recomputed from the returned `r` alone (`u = W r + q` anew), as a
    /// check of `solution.error`.
    pub verified_error: f64,
}

impl fmt::Display for SolveReport {
    /// One line: `problem=… contacts=… method=… iterations=… newton_iterations=… pivots=… error=…
    /// verified_error=… seconds=… converged=…`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "problem={} contacts={} method={} iterations={} newton_iterations={} pivots={} error={:.3e} verified_error={:.3e} tolerance={:.1e} seconds={:.4} converged={}",
            self.problem,
            self.contacts,
            self.method.method.name(),
            self.solution.iterations,
            self.method.newton.iterations,
            self.method.pivots,
            self.solution.error,
            self.verified_error,
            self.tolerance,
            self.solution.seconds,
            self.solution.converged
        )
    }
}

/// Reads the problem at `problem` (fc-problem-v1 JSON, plain or gzip), solves it with `options`
/// by `method` ([`solve_by`]) and, when `out` is given, writes the solution there atomically
/// (`{"r", "u", "iterations", "error", "seconds", "converged"}`).
///
/// The solution is written even when the solver did not converge (`converged: false` in the
/// file and in the report); the caller decides how to signal it (the CLI warns).
pub fn solve_file(
    problem: &Path,
    options: &FcOptions,
    method: SolverMethod,
    newton: &NewtonParams,
    out: Option<&Path>,
) -> Result<SolveReport, FcError> {
    let t0 = Instant::now();
    let p = read_problem(problem)?;
    let read_seconds = t0.elapsed().as_secs_f64();
    let (solution, method) = solve_by(&p, options, method, newton)?;
    let verified_error = fc_error(&p, &solution.r);
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
        method,
        verified_error,
    })
}

/// [`solve_file`] with the default options and method (`auto`) and tolerance `tol` (1e-6 when
/// `None`).
pub fn solve_fc(
    problem: &Path,
    tol: Option<f64>,
    out: Option<&Path>,
) -> Result<SolveReport, FcError> {
    let options = FcOptions {
        tolerance: tol.unwrap_or(1e-6),
        ..FcOptions::default()
    };
    solve_file(
        problem,
        &options,
        SolverMethod::default(),
        &NewtonParams::default(),
        out,
    )
}
