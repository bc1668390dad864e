//! One entry point for the solvers of a standalone problem, chosen by [`SolverMethod`] as in
//! the engine (`nlgs`, `newton`, `auto`), with one report.

use serde::Serialize;

use super::error::FcError;
use super::newton::{self, NewtonParams, NewtonStats};
use super::nsgs::{self, FcOptions, FcSolution};
use super::problem::FcProblem;
pub use crate::solver::{gauss_seidel_will_finish, SolverMethod};

/// Gauss–Seidel sweeps before `auto` hands over to Newton (as the engine's default
/// [`crate::SolverParams::auto_sweeps`]).
pub const AUTO_SWEEPS: usize = 100;

/// What a solve by [`solve_by`] did: Gauss–Seidel sweeps in all (`solution.iterations`), and
/// the Newton statistics when Newton ran.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodReport {
    /// The method asked for.
    pub method: SolverMethod,
    /// Newton iterations, line-search failures and smoothing sweeps (all zero if Newton did not
    /// run).
    pub newton: NewtonStats,
}

/// Solves `problem` with `method`:
/// - `nlgs`: [`nsgs::solve`] with `options`;
/// - `newton`: [`newton::solve`] from `options.initial_guess`;
/// - `auto`: Gauss–Seidel in chunks of [`AUTO_SWEEPS`] sweeps while its rate would reach the
///   tolerance within the sweeps left ([`gauss_seidel_will_finish`]), then Newton from its best iterate, then Gauss–Seidel again for
///   the sweeps left of `options.max_iterations` if Newton did not reach the tolerance within
///   `params.max_iterations`.
///
/// `solution.iterations` counts the Gauss–Seidel sweeps (smoothing included), `seconds` the
/// whole solve.
pub fn solve_by(
    problem: &FcProblem,
    options: &FcOptions,
    method: SolverMethod,
    params: &NewtonParams,
) -> Result<(FcSolution, MethodReport), FcError> {
    params.validate()?;
    let report = |newton| MethodReport { method, newton };
    match method {
        SolverMethod::Nlgs => Ok((
            nsgs::solve(problem, options)?,
            report(NewtonStats::default()),
        )),
        SolverMethod::Newton => {
            let (s, stats) = newton::solve(problem, options, params)?;
            Ok((
                FcSolution {
                    iterations: stats.smoothing_sweeps,
                    ..s
                },
                report(stats),
            ))
        }
        SolverMethod::Auto => {
            // Gauss–Seidel in chunks while its rate would reach the tolerance in time.
            let mut reference = super::measure::fc_error(
                problem,
                options
                    .initial_guess
                    .as_deref()
                    .unwrap_or(&vec![0.0; 2 * problem.contacts()]),
            );
            let mut first = nsgs::solve(
                problem,
                &FcOptions {
                    max_iterations: options.max_iterations.min(AUTO_SWEEPS),
                    ..options.clone()
                },
            )?;
            while !first.converged
                && gauss_seidel_will_finish(
                    reference,
                    first.error,
                    AUTO_SWEEPS,
                    options.tolerance,
                    options.max_iterations - first.iterations,
                )
            {
                reference = first.error;
                let more = nsgs::solve(
                    problem,
                    &FcOptions {
                        max_iterations: AUTO_SWEEPS.min(options.max_iterations - first.iterations),
                        initial_guess: Some(first.r.clone()),
                        ..options.clone()
                    },
                )?;
                first = FcSolution {
                    iterations: first.iterations + more.iterations,
                    seconds: first.seconds + more.seconds,
                    ..more
                };
            }
            if first.converged {
                return Ok((first, report(NewtonStats::default())));
            }
            let mut left = options.max_iterations - first.iterations;
            let (second, stats) = newton::solve(
                problem,
                &FcOptions {
                    max_iterations: left,
                    initial_guess: Some(first.r),
                    ..options.clone()
                },
                params,
            )?;
            left -= stats.smoothing_sweeps;
            let sweeps = first.iterations + stats.smoothing_sweeps;
            let seconds = first.seconds + second.seconds;
            if second.converged || left == 0 {
                return Ok((
                    FcSolution {
                        iterations: sweeps,
                        seconds,
                        ..second
                    },
                    report(stats),
                ));
            }
            let third = nsgs::solve(
                problem,
                &FcOptions {
                    max_iterations: left,
                    initial_guess: Some(second.r),
                    ..options.clone()
                },
            )?;
            Ok((
                FcSolution {
                    iterations: sweeps + third.iterations,
                    seconds: seconds + third.seconds,
                    ..third
                },
                report(stats),
            ))
        }
    }
}
