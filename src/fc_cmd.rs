//! `grainlaw solve-fc`: standalone frictional-contact problems (`docs/formats.md` §1) solved by
//! [`dem::fc`] (NSGS with the exact bipotential local step, Anderson-accelerated, and a
//! proximal semismooth Newton method), with the error measure of Siconos' fc2d: [`solve_file`] reads,
//! solves, checks and writes, [`solve_fc`] adds the command's checks and exit codes. The
//! benchmark is in [`crate::bench_cmd`] (the reference table in [`crate::fc_bench`]).

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

use dem::fc::{
    fc_error, read_problem, solve_by, write_solution, FcError, FcOptions, FcSolution, MethodReport,
    NewtonParams, SolverMethod,
};

use crate::error::{CliError, Result};

fn check_tol(tol: f64) -> Result<()> {
    if tol.is_finite() && tol > 0.0 && tol < 1.0 {
        Ok(())
    } else {
        Err(CliError::Usage(format!(
            "--tol must be in (0, 1), got {tol}"
        )))
    }
}

/// The solver named on the command line (`--method`, or `solver.method` in a scenario).
pub fn parse_method(name: &str) -> Result<SolverMethod> {
    match name {
        "nlgs" => Ok(SolverMethod::Nlgs),
        "newton" => Ok(SolverMethod::Newton),
        "auto" => Ok(SolverMethod::Auto),
        "lemke" => Ok(SolverMethod::Lemke),
        other => Err(CliError::Usage(format!(
            "--method must be nlgs, newton, auto or lemke, got `{other}`"
        ))),
    }
}

/// Solves one problem ([`solve_file`]) with `method`; prints one line (contacts,
/// method, sweeps, Newton iterations, error and the error recomputed from `r`, seconds); with
/// `out`, writes `{"r", "u", "iterations", "error", "seconds", "converged"}` atomically. A solve
/// that does not reach the tolerance is written (marked `converged: false`) and ends with
/// [`CliError::NotConverged`] (exit code 3).
pub fn solve_fc(
    problem: &Path,
    tol: f64,
    max_iterations: usize,
    method: &str,
    out: Option<&Path>,
) -> Result<()> {
    check_tol(tol)?;
    if max_iterations == 0 {
        return Err(CliError::Usage("--max-iterations must be ≥ 1".into()));
    }
    let method = parse_method(method)?;
    let options = FcOptions {
        tolerance: tol,
        max_iterations,
        ..Default::default()
    };
    let report = solve_file(problem, &options, method, &NewtonParams::default(), out)?;
    println!("{report}");
    if !report.solution.converged {
        return Err(CliError::NotConverged {
            path: problem.display().to_string(),
            reason: format!(
                "did not reach the tolerance {tol:.0e} (error {:.3e} after {} sweeps, {} Newton iterations and {} Lemke pivots)",
                report.solution.error, report.solution.iterations, report.method.newton.iterations, report.method.pivots
            ),
        });
    }
    Ok(())
}

/// Outcome of [`solve_file`].
#[derive(Debug, Clone)]
pub struct SolveFcReport {
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

impl fmt::Display for SolveFcReport {
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
/// by `method` ([`dem::fc::solve_by`]) and, when `out` is given, writes the solution there atomically
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
) -> std::result::Result<SolveFcReport, FcError> {
    let t0 = Instant::now();
    let p = read_problem(problem)?;
    let read_seconds = t0.elapsed().as_secs_f64();
    let (solution, method) = solve_by(&p, options, method, newton)?;
    let verified_error = fc_error(&p, &solution.r);
    if let Some(out) = out {
        write_solution(out, &solution)?;
    }
    Ok(SolveFcReport {
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

/// The reference problems shipped with the repository (`datasets/fc-problems`), unless
/// `GRAINLAW_FC_DIR` names another directory.
pub fn default_dir() -> PathBuf {
    std::env::var_os("GRAINLAW_FC_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/datasets/fc-problems"))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `solve_file` on the 89-contact reference pile: the report's error recomputed from `r`
    /// alone meets the tolerance, the written file holds the same solution; an unreadable
    /// problem is an error naming the path and writes nothing.
    #[test]
    fn solve_file_reports_writes_and_refuses_a_missing_problem() {
        let dir = tempfile::tempdir().unwrap();
        let problem = default_dir().join("piles/pile_pert_100.json.gz");
        let out = dir.path().join("solution.json");
        let options = FcOptions {
            tolerance: 1e-8,
            ..FcOptions::default()
        };
        let method = SolverMethod::default();
        let newton = NewtonParams::default();
        let report = solve_file(&problem, &options, method, &newton, Some(&out)).unwrap();
        assert_eq!(report.problem, "pile_pert_100.json.gz");
        assert_eq!(report.contacts, 89);
        assert!(report.solution.converged && report.solution.error <= 1e-8);
        assert!(report.verified_error <= 1e-8, "{report}");
        let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
        assert_eq!(
            v["iterations"].as_u64().unwrap() as usize,
            report.solution.iterations
        );
        assert_eq!(v["error"].as_f64().unwrap(), report.solution.error);

        let missing = dir.path().join("missing.json");
        let never = dir.path().join("never.json");
        let e = solve_file(&missing, &options, method, &newton, Some(&never)).unwrap_err();
        assert!(e.to_string().contains("missing.json"), "{e}");
        assert!(!never.exists());
    }
}
