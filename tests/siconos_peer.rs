//! The Siconos peer of `grainlaw bench` (`grainlaw::siconos_peer`), run for real when the
//! machine has Siconos (`/usr/bin/python3 -c 'import siconos.numerics'`, or the interpreter of
//! `GRAINLAW_SICONOS_PYTHON`); each test prints why it is skipped otherwise (CI machines may
//! not have Siconos). The parsing and labelling tests that need no Siconos are unit tests of
//! `grainlaw-core/src/siconos_peer.rs`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use grainlaw::siconos_peer::{self as sp, PeerOutcome, PeerRequest};

fn python() -> Option<PathBuf> {
    match sp::detect() {
        Ok(p) => Some(p),
        Err(why) => {
            eprintln!("skipped: Siconos not available ({why})");
            None
        }
    }
}

fn pile_100() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("datasets/fc-problems/piles/pile_pert_100.json.gz")
}

fn nsgs(cap: Duration) -> PeerRequest {
    PeerRequest {
        solver: "NSGS",
        tol: 1e-6,
        max_iter: 100_000,
        repeat: 1,
        repeat_budget: 0.0,
        cap,
    }
}

/// Siconos' NSGS on the 89-contact pile: converged, and its reactions meet 10⁻⁶ on our own
/// measure (`dem::fc::fc_error`), which agrees with the script's to 10⁻⁶ relative (the same
/// formula, `docs/formats.md` §1.2).
#[test]
fn siconos_reactions_meet_the_tolerance_on_our_measure() {
    let Some(python) = python() else { return };
    let problem_file = pile_100();
    let out = tempfile::tempdir().unwrap();
    let json = out.path().join("sol.json");
    let mut child = Command::new(&python)
        .arg("-")
        .arg(&problem_file)
        .args(["--solver", "NSGS", "--tol", "1e-6", "-o"])
        .arg(&json)
        .env("OMP_NUM_THREADS", "1")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(sp::SCRIPT.as_bytes())
        .unwrap();
    let output = child.wait_with_output().unwrap();
    assert!(output.status.success());
    let stdout = String::from_utf8(output.stdout).unwrap();
    let line = stdout
        .lines()
        .find(|l| l.starts_with(sp::LINE_TAG))
        .unwrap();
    let figures = sp::parse_line(line).unwrap();
    assert!(figures.converged, "{line}");
    assert_eq!(figures.contacts, 89);

    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let r: Vec<f64> = v["reaction"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let problem = dem::fc::read_problem(&problem_file).unwrap();
    assert_eq!(r.len(), 2 * problem.contacts());
    let ours = dem::fc::fc_error(&problem, &r);
    assert!(
        ours <= 1e-6,
        "Siconos' reactions: error {ours:e} on our measure"
    );
    assert!(
        (ours - figures.error).abs() <= 1e-6 * figures.error,
        "our measure {ours:e} vs the script's {:e}",
        figures.error
    );
    // the reactions carry the weight: not the trivial r = 0
    assert!(r.iter().step_by(2).sum::<f64>() > 0.0);
}

/// `solve` reports a measured, converged run; a run over its cap as a timeout; a missing file
/// as a failure (never as figures).
#[test]
fn outcomes_of_the_peer_runs() {
    let Some(python) = python() else { return };
    match sp::solve(&python, &pile_100(), &nsgs(Duration::from_secs(120))) {
        PeerOutcome::Measured(f) => {
            assert!(f.converged && f.error <= 1e-6 && f.seconds > 0.0, "{f:?}");
            assert_eq!(f.solver, "NSGS");
        }
        other => panic!("expected figures, got {other:?}"),
    }
    // the interpreter alone takes longer than 1 ms to start and import numpy and Siconos
    assert_eq!(
        sp::solve(&python, &pile_100(), &nsgs(Duration::from_millis(1))),
        PeerOutcome::TimedOut(0.001)
    );
    let missing = Path::new(env!("CARGO_MANIFEST_DIR")).join("no-such-problem.json");
    match sp::solve(&python, &missing, &nsgs(Duration::from_secs(120))) {
        PeerOutcome::Failed(why) => assert!(why.contains("exit failure"), "{why}"),
        other => panic!("expected a failure, got {other:?}"),
    }
}
