//! The solver choice on the command line, and time steps too large for the physics: bad settings
//! are refused on one line with exit 2,
//! `solve-fc` reports non-convergence with exit 3, and `--dump-problems` writes problems that
//! read back and solve.

use std::path::Path;
use std::process::{Command, Output};

fn grainlaw(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_grainlaw"))
        .current_dir(cwd)
        .args(args)
        .output()
        .expect("grainlaw runs")
}

/// Exit code 2 and one stderr line containing `needle`.
fn refused(o: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "stderr: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(err.contains(needle), "`{needle}` not in: {err}");
    assert!(!err.contains("panicked"));
}

fn pile() -> String {
    format!(
        "{}/datasets/fc-problems/piles/pile_pert_100.json.gz",
        env!("CARGO_MANIFEST_DIR")
    )
}

#[test]
fn bad_solver_settings_are_refused_with_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = pile();
    refused(
        &grainlaw(&["solve-fc", &p, "--method", "simplex"], d),
        "--method",
    );
    refused(&grainlaw(&["solve-fc", &p, "--tol", "0"], d), "--tol");
    refused(&grainlaw(&["solve-fc", &p, "--tol=-1e-6"], d), "--tol");
    for (set, key) in [
        ("solver.method=gauss", "solver.method"),
        ("solver.tolerance=0", "solver.tolerance"),
        ("solver.tolerance=-1", "solver.tolerance"),
        ("solver.max_iterations=0", "solver.max_iterations"),
        ("solver.max_halvings=11", "solver.max_halvings"),
        ("solver.max_halvings=-1", "solver.max_halvings"),
        ("solver.check_every=1001", "solver.check_every"),
        ("solver.last_level_sweeps=0", "solver.last_level_sweeps"),
        ("solver.last_level_sweeps=1001", "solver.last_level_sweeps"),
        ("solver.error_scale=contacts", "solver.error_scale"),
        ("solver.error_scale=1", "solver.error_scale"),
    ] {
        let o = grainlaw(&["run", "shear-cell", "--out", "x", "--set", set], d);
        refused(&o, key);
    }
    let o = grainlaw(
        &[
            "run",
            "stick-slip",
            "--dump-problems",
            "p",
            "--dump-steps",
            "9..2",
        ],
        d,
    );
    refused(&o, "--dump-steps");
}

#[test]
fn solve_fc_methods_solve_a_pile_and_non_convergence_exits_3() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let p = pile();
    for m in ["nlgs", "newton", "auto", "lemke"] {
        let o = grainlaw(&["solve-fc", &p, "--tol", "1e-10", "--method", m], d);
        let out = String::from_utf8_lossy(&o.stdout);
        assert_eq!(o.status.code(), Some(0), "{m}: {out}");
        assert!(out.contains(&format!("method={m}")) && out.contains("converged=true"));
    }
    // Two sweeps cannot solve the pile to 1e-12: the solution is written, marked, exit 3.
    let sol = d.join("s.json");
    let o = grainlaw(
        &[
            "solve-fc",
            &p,
            "--tol",
            "1e-12",
            "--method",
            "nlgs",
            "--max-iterations",
            "2",
            "--out",
            sol.to_str().unwrap(),
        ],
        d,
    );
    assert_eq!(o.status.code(), Some(3));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sol).unwrap()).unwrap();
    assert_eq!(v["converged"], serde_json::Value::Bool(false));
}

/// `--dump-steps` writes exactly the steps asked for, as problems `dem::fc` reads, and the
/// engine's recorded error is what solving them from zero reaches to the same tolerance or
/// better.
#[test]
fn dumped_problems_read_back_and_solve() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let o = grainlaw(
        &[
            "run",
            "stick-slip",
            "--quiet",
            "--out",
            "run",
            "--set",
            "grains=60",
            "--set",
            "push_duration=0.1",
            "--dump-problems",
            "p",
            "--dump-steps",
            "40..42",
        ],
        d,
    );
    // A finished run: 0, or 3 when the verdict refuses (the μ = 0.8 push of so short a run is
    // mostly unconverged, and its forces are refused); the dumps are written either way.
    assert!(
        matches!(o.status.code(), Some(0) | Some(3)),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let mut files: Vec<_> = std::fs::read_dir(d.join("p"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    // Each world of the scenario counts its own steps: 3 files per world that reached step 42.
    assert!(!files.is_empty() && files.len() % 3 == 0, "{files:?}");
    for f in &files {
        let p = dem::fc::read_problem(f).unwrap();
        assert!(p.contacts() > 0);
        let o = grainlaw(&["solve-fc", f.to_str().unwrap(), "--tol", "1e-8"], d);
        assert_eq!(o.status.code(), Some(0), "{}", f.display());
    }
}

/// A time step under which gravity moves a resting grain by more than a quarter of the smallest
/// radius in one step is refused before any work, naming `dt` (janssen with `dt = 0.1` used to
/// run to 42 % overlaps and exit 0); the defaults pass the check.
#[test]
fn time_steps_too_large_for_gravity_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for sc in ["janssen", "inclined-flow", "stick-slip"] {
        let o = grainlaw(&["run", sc, "--out", "x", "--set", "dt=0.1"], d);
        refused(&o, "key `dt`");
        assert!(String::from_utf8_lossy(&o.stderr).contains("quarter of the smallest radius"));
        assert!(!d.join("x/summary.json").exists());
    }
    // janssen: R_min = 0.5 mm, so the bound is √(0.25 · 5e-4 / 9.81) = 3.57 ms.
    let o = grainlaw(&["run", "janssen", "--out", "y", "--set", "dt=3.6e-3"], d);
    refused(&o, "use at most 3.570e-3 s");
}

/// `--out` naming a file, or a directory that holds another scenario's outputs, is refused on
/// one line (exit 2) and nothing is written there; the same scenario may reuse its directory.
#[test]
fn out_directory_of_another_scenario_or_a_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("afile"), "x").unwrap();
    refused(
        &grainlaw(&["run", "rolling", "-q", "--out", "afile"], d),
        "is a file, not a directory",
    );
    let o = grainlaw(&["run", "rolling", "-q", "--out", "r"], d);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let before: Vec<_> = std::fs::read_dir(d.join("r")).unwrap().collect();
    let o = grainlaw(
        &[
            "run",
            "arrangements",
            "-q",
            "--out",
            "r",
            "--set",
            "columns=3",
            "--set",
            "rows=3",
        ],
        d,
    );
    refused(&o, "holds the outputs of a `rolling` run");
    let after: Vec<_> = std::fs::read_dir(d.join("r")).unwrap().collect();
    assert_eq!(before.len(), after.len(), "nothing added");
    let o = grainlaw(&["run", "rolling", "-q", "--out", "r"], d);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}
