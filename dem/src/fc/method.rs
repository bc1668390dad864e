//! One entry point for the solvers of a standalone problem, chosen by [`SolverMethod`] as in
//! the engine (`nlgs`, `newton`, `auto`), with one report.

use serde::{Deserialize, Serialize};

use super::auto::{run_auto, AutoStages, Backoff};
use super::error::FcError;
use super::lemke::{self, LemkeParams};
use super::newton::{self, NewtonParams, NewtonStats};
use super::nsgs::{self, FcOptions, FcSolution};
use super::problem::FcProblem;

/// Which algorithm solves a contact problem: the engine's step ([`crate::SolverParams::method`])
/// or a standalone problem ([`solve_by`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SolverMethod {
    /// Nonlinear Gauss–Seidel only: O(1) per contact update, fast on loose and
    /// flowing packings, slow to carry a load change across a dense, hyperstatic one.
    Nlgs,
    /// The regularised semismooth Newton method of [`crate::fc::newton`] on the assembled
    /// problem, from the warm start.
    Newton,
    /// Gauss–Seidel in chunks of [`crate::SolverParams::auto_sweeps`] sweeps while it converges fast
    /// enough, then, if it has not converged, Newton from its best iterate, then the exact
    /// finish ([`exact_finish`]: the active-set solve, then Lemke's method),
    /// then Gauss–Seidel for the sweeps left if all of these failed (the default).
    #[default]
    Auto,
    /// Lemke's complementary pivoting method ([`crate::fc::lemke`]) on the assembled problem,
    /// warm-started from the statuses of the stored impulses: an exact solution at the cost of
    /// a few sparse pivots per contact, whatever the packing; Gauss–Seidel takes over if the
    /// path fails.
    Lemke,
}

impl SolverMethod {
    /// The name used in TOML files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SolverMethod::Nlgs => "nlgs",
            SolverMethod::Newton => "newton",
            SolverMethod::Auto => "auto",
            SolverMethod::Lemke => "lemke",
        }
    }
}

/// Gauss–Seidel sweeps before `auto` hands over to Newton (as the engine's default
/// [`crate::SolverParams::auto_sweeps`]).
pub const AUTO_SWEEPS: usize = 100;

/// Largest problem (contacts) that `auto` on a standalone problem ([`solve_by`]) ends with
/// Lemke's method when the other stages did not converge: about a minute for one cold path.
/// (The engine's per-step limit is [`crate::SolverParams::lemke_max_contacts`].)
pub const STANDALONE_LEMKE_MAX_CONTACTS: usize = 5000;

/// What a solve by [`solve_by`] did: Gauss–Seidel sweeps in all (`solution.iterations`), and
/// the Newton statistics when Newton ran.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodReport {
    /// The method asked for.
    pub method: SolverMethod,
    /// Newton iterations, line-search failures and smoothing sweeps (all zero if Newton did not
    /// run).
    pub newton: NewtonStats,
    /// Pivots of Lemke's method (0 if it did not run).
    pub pivots: usize,
}

/// Better impulses found by [`exact_finish`].
#[derive(Debug, Clone, PartialEq)]
pub struct Finish {
    /// The impulses (in their cones).
    pub r: Vec<f64>,
    /// Their error measure.
    pub error: f64,
    /// The final basis of Lemke's method when it gave `r` (the warm start of the next step);
    /// `None` when the active-set solve gave `r`.
    pub basis: Option<Vec<u8>>,
}

/// What [`exact_finish`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct FinishOutcome {
    /// The best impulses found, when they lower the error.
    pub better: Option<Finish>,
    /// Whether the active-set solve was done (one sparse LU).
    pub active_set: bool,
    /// Whether Lemke's method ran.
    pub lemke_ran: bool,
    /// Pivots of Lemke's method (counted whether or not its result was kept).
    pub pivots: usize,
}

/// The exact finish of an unconverged solve (the last stage of `auto`, in the engine and in
/// `solve-fc`), from impulses `r` whose error is `error_now`:
///
/// 1. when `error_now ≤` [`newton::FINISH_MAX_ERROR`], one active-set solve with the statuses
///    read from `r` ([`newton::active_set_finish`], one sparse LU); done if it reaches
///    `tolerance`;
/// 2. otherwise, for at most `max_contacts` contacts, Lemke's method ([`lemke::solve`]), warm
///    from `basis` (the final basis of the previous step's Lemke solve, if any), else from the
///    statuses of `r`, then cold: an exact solution of the 2D problem (every problem of
///    `datasets/fc-problems/hard/` to ≤ 10⁻¹³).
///
/// `better` holds the best impulses found when they lower the error.
pub fn exact_finish(
    problem: &FcProblem,
    r: &[f64],
    error_now: f64,
    tolerance: f64,
    max_contacts: usize,
    basis: Option<&[u8]>,
    work: &mut newton::NewtonWork,
) -> Result<FinishOutcome, FcError> {
    let mut out = FinishOutcome {
        better: None,
        active_set: newton::active_set_applies(error_now),
        lemke_ran: false,
        pivots: 0,
    };
    if let Some((r1, e1)) = newton::active_set_finish(problem, r, error_now, work)? {
        out.better = Some(Finish {
            r: r1,
            error: e1,
            basis: None,
        });
        if e1 <= tolerance {
            return Ok(out);
        }
    }
    if problem.contacts() <= max_contacts {
        let warm = lemke::Warm {
            basis,
            impulses: Some(r),
        };
        let (sol, report) = lemke::solve(problem, warm, tolerance, &LemkeParams::default())?;
        out.lemke_ran = true;
        out.pivots = report.pivots;
        let floor = out.better.as_ref().map_or(error_now, |b| b.error);
        if let Some(sol) = sol.filter(|_| report.error < floor) {
            out.better = Some(Finish {
                r: sol.r,
                error: report.error,
                basis: Some(sol.basis),
            });
        }
    }
    Ok(out)
}

/// Solves `problem` with `method`:
/// - `nlgs`: [`nsgs::solve`] with `options`;
/// - `newton`: [`newton::solve`] from `options.initial_guess`;
/// - `auto`: the engine's schedule (`fc::auto::run_auto`, without the back-off, which needs a
///   sequence of steps): Gauss–Seidel in chunks of [`AUTO_SWEEPS`] sweeps while its rate would
///   reach the tolerance in time ([`super::auto::gauss_seidel_will_finish`]), then Newton from its best
///   iterate, then Gauss–Seidel again for the sweeps left of `options.max_iterations` if Newton
///   did not reach the tolerance within `params.max_iterations`.
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
    let report = |newton| MethodReport {
        method,
        newton,
        pivots: 0,
    };
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
        SolverMethod::Lemke => {
            let t0 = std::time::Instant::now();
            let warm = lemke::Warm {
                basis: None,
                impulses: options.initial_guess.as_deref(),
            };
            let (sol, lr) =
                lemke::solve(problem, warm, options.tolerance, &LemkeParams::default())?;
            let converged = sol.is_some() && lr.error <= options.tolerance;
            let r = sol.map_or_else(|| vec![0.0; 2 * problem.contacts()], |s| s.r);
            let error = super::measure::fc_error(problem, &r);
            let u = problem.velocity(&r);
            Ok((
                FcSolution {
                    r,
                    u,
                    iterations: 0,
                    error,
                    seconds: t0.elapsed().as_secs_f64(),
                    converged,
                },
                MethodReport {
                    method,
                    newton: NewtonStats::default(),
                    pivots: lr.pivots,
                },
            ))
        }
        SolverMethod::Auto => {
            let start = options
                .initial_guess
                .clone()
                .unwrap_or_else(|| vec![0.0; 2 * problem.contacts()]);
            let start_error = super::measure::fc_error(problem, &start);
            let mut stages = FcStages {
                problem,
                options,
                params,
                r: start,
                last: None,
                stats: NewtonStats::default(),
                sweeps: 0,
                pivots: 0,
                seconds: 0.0,
            };
            run_auto(
                &mut stages,
                start_error,
                AUTO_SWEEPS,
                options.tolerance,
                options.max_iterations,
                None::<&mut Backoff<()>>,
            )?;
            let solution = stages.last.take().expect("the first stage always runs");
            Ok((
                FcSolution {
                    iterations: stages.sweeps,
                    seconds: stages.seconds,
                    ..solution
                },
                MethodReport {
                    pivots: stages.pivots,
                    ..report(stages.stats)
                },
            ))
        }
    }
}

/// The stages of [`run_auto`] on a standalone problem: each continues from the last solution.
struct FcStages<'a> {
    problem: &'a FcProblem,
    options: &'a FcOptions,
    params: &'a NewtonParams,
    /// The current iterate.
    r: Vec<f64>,
    /// The last stage's solution.
    last: Option<FcSolution>,
    stats: NewtonStats,
    /// Gauss–Seidel sweeps in all (smoothing included).
    sweeps: usize,
    /// Pivots of Lemke's method.
    pivots: usize,
    seconds: f64,
}

impl FcStages<'_> {
    fn options(&self, sweeps: usize) -> FcOptions {
        FcOptions {
            max_iterations: sweeps,
            initial_guess: Some(self.r.clone()),
            ..self.options.clone()
        }
    }

    fn keep(&mut self, s: FcSolution) {
        self.seconds += s.seconds;
        self.r.clone_from(&s.r);
        self.last = Some(s);
    }
}

impl AutoStages for FcStages<'_> {
    type Error = FcError;

    fn sweeps(&mut self, sweeps: usize) -> Result<(usize, f64, bool), FcError> {
        let s = nsgs::solve(self.problem, &self.options(sweeps))?;
        let out = (s.iterations, s.error, s.converged);
        self.sweeps += s.iterations;
        self.keep(s);
        Ok(out)
    }

    fn newton(&mut self, sweeps: usize) -> Result<(usize, bool), FcError> {
        let (s, stats) = match newton::solve(self.problem, &self.options(sweeps), self.params) {
            // A cell's term too large to fold into W: Gauss–Seidel alone solves it.
            Err(FcError::LowRankTooLarge { .. }) => return Ok((0, false)),
            other => other?,
        };
        let out = (stats.smoothing_sweeps, s.converged);
        self.sweeps += stats.smoothing_sweeps;
        self.stats = stats;
        self.keep(s);
        Ok(out)
    }

    fn finish(&mut self, lemke: bool) -> Result<(bool, bool), FcError> {
        let Some(last) = self.last.as_ref() else {
            return Ok((false, false));
        };
        let t0 = std::time::Instant::now();
        let mut work = newton::NewtonWork::default();
        let max_contacts = if lemke {
            STANDALONE_LEMKE_MAX_CONTACTS
        } else {
            0
        };
        let out = match exact_finish(
            self.problem,
            &last.r,
            last.error,
            self.options.tolerance,
            max_contacts,
            None,
            &mut work,
        ) {
            Err(FcError::LowRankTooLarge { .. }) => return Ok((false, false)),
            other => other?,
        };
        self.pivots += out.pivots;
        if out.active_set {
            self.stats.iterations += 1;
        }
        let Some(Finish { r, error, .. }) = out.better else {
            self.seconds += t0.elapsed().as_secs_f64();
            return Ok((false, out.lemke_ran));
        };
        let u = self.problem.velocity(&r);
        let converged = error <= self.options.tolerance;
        self.keep(FcSolution {
            r,
            u,
            iterations: 0,
            error,
            seconds: t0.elapsed().as_secs_f64(),
            converged,
        });
        Ok((converged, out.lemke_ran))
    }
}
