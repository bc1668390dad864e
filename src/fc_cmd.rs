//! `grainlaw solve-fc` and `grainlaw bench`: standalone frictional-contact problems
//! (`formats/frictional-contact.md`) solved by `dem::fc` (NSGS with the exact bipotential local
//! solver), with the error measure of Siconos' fc2d.

use std::path::{Path, PathBuf};

use dem::fc::{read_problem, solve, FcOptions};

use crate::error::{CliError, Result};
use crate::output::dir::write_atomic;

fn check_tol(tol: f64) -> Result<()> {
    if tol.is_finite() && tol > 0.0 && tol < 1.0 {
        Ok(())
    } else {
        Err(CliError::Usage(format!(
            "--tol must be in (0, 1), got {tol}"
        )))
    }
}

/// Solves one problem; prints contacts, iterations, error and seconds; writes the solution
/// JSON `{"r": [...], "u": [...], "iterations": n, "error": e, "seconds": s, "converged": b}`.
pub fn solve_fc(problem: &Path, tol: f64, max_iterations: usize, out: Option<&Path>) -> Result<()> {
    check_tol(tol)?;
    if max_iterations == 0 {
        return Err(CliError::Usage("--max-iterations must be ≥ 1".into()));
    }
    let p = read_problem(problem)?;
    let opts = FcOptions {
        tolerance: tol,
        max_iterations,
        ..Default::default()
    };
    let s = solve(&p, &opts)?;
    println!(
        "{}: {} contacts, {} iterations, error {:.3e}, {:.4} s{}",
        problem.display(),
        p.contacts(),
        s.iterations,
        s.error,
        s.seconds,
        if s.converged { "" } else { " (NOT converged)" }
    );
    if !s.converged {
        crate::progress::warn(&format!(
            "did not reach the tolerance {tol:.0e} within {max_iterations} iterations"
        ));
    }
    if let Some(path) = out {
        let json = serde_json::json!({
            "r": s.r,
            "u": s.u,
            "iterations": s.iterations,
            "error": s.error,
            "seconds": s.seconds,
            "converged": s.converged,
        });
        write_atomic(path, (json.to_string() + "\n").as_bytes())?;
    }
    Ok(())
}

/// Siconos 4.4 fc2d NSGS reference (tolerance 1e-6, from r = 0, one core): problem stem,
/// iterations, seconds (middle of the published range).
const SICONOS: [(&str, usize, f64); 4] = [
    ("pile_pert_100", 118, 0.002),
    ("pile_pert_1000", 862, 0.255),
    ("fc2d_granularflowonwall_02020_00213", 1064, 0.16),
    ("fc2d_granularflowonwall_07002_00801", 1461, 1.45),
];

fn default_dir() -> PathBuf {
    if let Some(d) = std::env::var_os("GRAINLAW_FC_DIR") {
        return PathBuf::from(d);
    }
    for c in [
        "../shared/reference/fc-problems",
        "/work/shared/reference/fc-problems",
    ] {
        let p = PathBuf::from(c);
        if p.is_dir() {
            return p;
        }
    }
    PathBuf::from("../shared/reference/fc-problems")
}

/// Solves every 2D reference problem under `dir` (`piles/`, `siconos-2d/`) and prints a table
/// with Siconos' times where known.
pub fn bench(dir: Option<&Path>, tol: f64, repeat: usize) -> Result<()> {
    check_tol(tol)?;
    let dir = dir.map(Path::to_path_buf).unwrap_or_else(default_dir);
    let mut files = Vec::new();
    for sub in ["piles", "siconos-2d"] {
        let d = dir.join(sub);
        let rd = std::fs::read_dir(&d).map_err(|e| CliError::io(&d, e))?;
        for e in rd.flatten() {
            let p = e.path();
            let name = p.file_name().and_then(|s| s.to_str()).unwrap_or("");
            if name.ends_with(".json") || name.ends_with(".json.gz") {
                files.push(p);
            }
        }
    }
    files.sort();
    if files.is_empty() {
        return Err(CliError::io(
            &dir,
            "no .json problems under piles/ or siconos-2d/",
        ));
    }
    println!(
        "{:<42} {:>7} {:>8} {:>10} {:>10} {:>9} {:>10} {:>8}",
        "problem", "contacts", "iters", "error", "seconds", "Siconos", "Siconos s", "speed-up"
    );
    for f in files {
        let p = read_problem(&f)?;
        let opts = FcOptions {
            tolerance: tol,
            ..Default::default()
        };
        let mut best: Option<dem::fc::FcSolution> = None;
        for _ in 0..repeat.max(1) {
            let s = solve(&p, &opts)?;
            if best.as_ref().is_none_or(|b| s.seconds < b.seconds) {
                best = Some(s);
            }
        }
        let Some(s) = best else { continue };
        let stem = f
            .file_name()
            .and_then(|s| s.to_str())
            .unwrap_or("")
            .trim_end_matches(".gz")
            .trim_end_matches(".json")
            .to_string();
        let reference = SICONOS.iter().find(|r| r.0 == stem);
        let (ri, rs, sp) = match reference {
            Some(&(_, it, sec)) => (
                it.to_string(),
                format!("{sec:.3}"),
                format!("{:.1}×", sec / s.seconds.max(1e-9)),
            ),
            None => ("-".into(), "-".into(), "-".into()),
        };
        println!(
            "{:<42} {:>7} {:>8} {:>10.2e} {:>10.4} {:>9} {:>10} {:>8}{}",
            stem,
            p.contacts(),
            s.iterations,
            s.error,
            s.seconds,
            ri,
            rs,
            sp,
            if s.converged { "" } else { "  NOT converged" }
        );
    }
    Ok(())
}
