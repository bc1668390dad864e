//! `grainlaw solve-fc`: standalone frictional-contact problems (`docs/formats.md` §1) solved by
//! [`dem::fc`] (NSGS with the exact bipotential local step, Anderson-accelerated, and a
//! proximal semismooth Newton method), with the error measure of Siconos' fc2d. The benchmark is in [`crate::bench_cmd`].

use std::path::{Path, PathBuf};

use dem::fc::FcOptions;

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
pub fn parse_method(name: &str) -> Result<dem::fc::SolverMethod> {
    match name {
        "nlgs" => Ok(dem::fc::SolverMethod::Nlgs),
        "newton" => Ok(dem::fc::SolverMethod::Newton),
        "auto" => Ok(dem::fc::SolverMethod::Auto),
        "lemke" => Ok(dem::fc::SolverMethod::Lemke),
        other => Err(CliError::Usage(format!(
            "--method must be nlgs, newton, auto or lemke, got `{other}`"
        ))),
    }
}

/// Solves one problem ([`dem::fc::solve_file`]) with `method`; prints one line (contacts,
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
    let report = dem::fc::solve_file(
        problem,
        &options,
        method,
        &dem::fc::NewtonParams::default(),
        out,
    )?;
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

/// The reference problems shipped with the repository (`datasets/fc-problems`), unless
/// `GRAINLAW_FC_DIR` names another directory.
pub fn default_dir() -> PathBuf {
    std::env::var_os("GRAINLAW_FC_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/datasets/fc-problems"))
        })
}
