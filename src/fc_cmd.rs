//! `grainlaw solve-fc` and `grainlaw bench`: standalone frictional-contact problems
//! (`formats/frictional-contact.md`) solved by [`dem::fc`] (NSGS with the exact bipotential
//! local step, Anderson-accelerated), with the error measure of Siconos' fc2d; and the engine's
//! time per step ([`dem::bench`]).

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
fn default_dir() -> PathBuf {
    std::env::var_os("GRAINLAW_FC_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/datasets/fc-problems"))
        })
}

/// Solves every reference problem under `dir` (tolerance 1e-6, from r = 0, best of several
/// runs) and prints the table against Siconos' times; then times the engine on settled
/// deposits of `engine_grains` grains (time per step, contact updates per second).
pub fn bench(dir: Option<&Path>, engine_grains: &[usize]) -> Result<()> {
    let dir = dir.map(Path::to_path_buf).unwrap_or_else(default_dir);
    let rows = dem::fc::bench::run_reference_benchmarks(&dir)?;
    if rows.is_empty() {
        return Err(CliError::io(&dir, "no .json or .json.gz problems found"));
    }
    println!("frictional-contact problems ({}):", dir.display());
    print!("{}", dem::fc::bench::format_table(&rows));
    if !engine_grains.is_empty() {
        println!("\nengine, settled deposit (radius 1–2 mm, μ = 0.3, h = 0.2 ms, tolerance 1e-4):");
        println!(
            "{:>8} {:>9} {:>7} {:>12} {:>16} {:>12}",
            "grains", "contacts", "sweeps", "s/step", "updates/s", "unconverged"
        );
        for &n in engine_grains {
            let r = dem::bench::deposit_benchmark(n, 1500, 100);
            println!(
                "{:>8} {:>9.0} {:>7.1} {:>12.3e} {:>16.3e} {:>12}",
                r.grains,
                r.contacts,
                r.sweeps,
                r.seconds_per_step,
                r.contact_updates_per_second,
                r.unconverged_steps
            );
        }
    }
    let mem = dem::bench::MemoryFootprint::current(4);
    println!(
        "\nmemory: {} B per grain, {} B per contact; at 2 contacts per grain, 24 GiB hold about {:.1e} grains",
        mem.per_grain,
        mem.per_contact,
        mem.largest_sample(24 << 30, 2.0) as f64
    );
    Ok(())
}
