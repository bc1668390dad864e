//! `grainlaw solve-fc`: standalone frictional-contact problems (`formats/frictional-contact.md`)
//! solved by [`dem::fc`] (NSGS with the exact bipotential local step, Anderson-accelerated),
//! with the error measure of Siconos' fc2d. The benchmark is in [`crate::bench_cmd`].

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

/// Solves one problem ([`dem::fc::solve_file`]); prints one line (contacts, iterations, error,
/// seconds); with `out`, writes `{"r", "u", "iterations", "error", "seconds", "converged"}`
/// atomically. Non-convergence is printed and warned, and recorded in the file.
pub fn solve_fc(problem: &Path, tol: f64, max_iterations: usize, out: Option<&Path>) -> Result<()> {
    check_tol(tol)?;
    if max_iterations == 0 {
        return Err(CliError::Usage("--max-iterations must be ≥ 1".into()));
    }
    let options = FcOptions {
        tolerance: tol,
        max_iterations,
        ..Default::default()
    };
    let report = dem::fc::solve_file(problem, &options, out)?;
    println!("{report}");
    if !report.solution.converged {
        crate::progress::warn(&format!(
            "did not reach the tolerance {tol:.0e} within {max_iterations} iterations"
        ));
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
