//! Interrupted runs: `grainlaw run` stopped (the hidden `--stop-after-steps`, which behaves as
//! Ctrl-C, or a real SIGINT) writes a checkpoint and no `summary.json`; `grainlaw run --resume
//! DIR` finishes it with every output file byte for byte equal to an uninterrupted run's
//! (`wall_seconds` aside); resuming from a missing, corrupt or foreign checkpoint is refused
//! with one line and exit code 2. The numerics keys of `summary.json` are there, and a normal
//! deposit flags no energy growth.

mod common;

use common::{assert_same_outputs, stderr};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

/// A short multi-phase scenario: Janssen column of 60 grains (deposit, relax, release,
/// measure: about 900 steps, half a second).
const SCENARIO: &[&str] = &["run", "janssen", "--set", "grains=60", "-q"];

fn grainlaw(args: &[&str], extra: &[&Path]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_grainlaw"));
    // The laws record the date the run started: the same for every run compared.
    cmd.env("SOURCE_DATE_EPOCH", "1767225600").args(args);
    for p in extra {
        cmd.arg(p);
    }
    cmd.output().expect("grainlaw runs")
}

/// A run that finished: exit 0, or 3 when its verdict refused a result (the 60-grain column's
/// Janssen fit may be refused; the resume must reproduce it all the same).
fn assert_finished(o: &Output) {
    assert!(
        matches!(o.status.code(), Some(0) | Some(3)),
        "exit {:?}: {}",
        o.status.code(),
        stderr(o)
    );
}

/// The error line of a failed command (the last line of stderr; warnings come before it).
fn error_line(o: &Output) -> String {
    stderr(o)
        .lines()
        .rfind(|l| l.starts_with("error:"))
        .unwrap_or_default()
        .to_string()
}

/// An uninterrupted run of [`SCENARIO`] into `dir`.
fn reference(dir: &Path) -> Value {
    let o = grainlaw(&[SCENARIO, &["--out"]].concat(), &[dir]);
    assert_finished(&o);
    serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap()
}

/// Checks the state a stopped run leaves: exit 130, one error line that says how to resume,
/// a checkpoint, no `summary.json`.
fn assert_stopped(o: &Output, dir: &Path) {
    assert_eq!(o.status.code(), Some(130), "{}", stderr(o));
    let line = error_line(o);
    assert!(
        line.contains("interrupted at step")
            && line.contains(&format!("grainlaw run --resume {}", dir.display())),
        "{line}"
    );
    assert!(dir.join("checkpoint/run.json.gz").is_file());
    assert!(!dir.join("summary.json").exists());
}

/// Stopped twice (in the deposit, then later in the relaxation or release), resumed twice:
/// the same files, byte for byte, as the uninterrupted run. A stale `summary.json` left in the
/// directory is removed as the run starts; the checkpoint directory is removed at the end.
#[test]
fn stopped_and_resumed_runs_give_the_same_files() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    let s = reference(&a);
    // The run subdivides steps (its deposit from step 1 on), so the stops below fall where the
    // subdivision's state is in the checkpoint.
    assert!(s["solver_subdivided_steps"].as_u64().unwrap() > 0);
    assert!(
        !a.join("checkpoint").exists(),
        "a finished run keeps no checkpoint"
    );
    std::fs::create_dir_all(&b).unwrap();
    std::fs::write(b.join("summary.json"), "{\"stale\": true}\n").unwrap();
    let o = grainlaw(
        &[SCENARIO, &["--stop-after-steps", "150", "--out"]].concat(),
        &[&b],
    );
    assert_stopped(&o, &b);
    assert!(
        error_line(&o).contains("phase `deposit`"),
        "{}",
        error_line(&o)
    );
    // Second leg: periodic checkpoints every 40 steps, stopped again 450 steps later.
    let o = grainlaw(
        &[
            "run",
            "-q",
            "--checkpoint-every",
            "40",
            "--stop-after-steps",
            "450",
            "--resume",
        ],
        &[&b],
    );
    assert_stopped(&o, &b);
    let o = grainlaw(&["run", "-q", "--resume"], &[&b]);
    assert_finished(&o);
    assert!(!b.join("checkpoint").exists());
    assert_same_outputs(&a, &b);
    // The numerics keys; the deposit and the relaxation (converged solves at θ = 1) never
    // gain energy.
    for k in [
        "solver_unconverged_steps",
        "solver_first_unconverged_step",
        "solver_worst_error",
        "solver_worst_error_without_gap_shifts",
        "max_penetration_m",
        "max_penetration_over_radius",
        "penetration_flagged_steps",
        "penetration_first_step",
        "energy_growth_steps",
        "energy_growth_first_step",
        "energy_growth_worst",
    ] {
        assert!(s.get(k).is_some(), "summary.json lacks {k}");
    }
    assert_eq!(s["deposit_energy_growth_steps"], 0);
    assert_eq!(s["relax_energy_growth_steps"], 0);
    let total = s["energy_growth_steps"].as_u64().unwrap();
    assert_eq!(s["energy_growth_first_step"].is_null(), total == 0);
}

/// The shear cell's solver tightening resumes exactly: a 60-grain cell whose lead at I = 0.08
/// tightens the tolerance to 1e-5 (`rheology.csv`), stopped inside that run's lead stages
/// (step 240: its re-solved samples are in the checkpoint, the decision not yet made) and
/// again in its window (step 300, after the tightening), resumed twice: the same files, byte
/// for byte, as the uninterrupted run (sensitivity sums included in `summary.json`).
#[test]
fn a_shear_cell_resumed_across_its_solver_tightening_gives_the_same_files() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    let cell = &common::small_shear_cell("inertial_numbers=[0.04, 0.08, 0.15]", &[])[..];
    assert_finished(&grainlaw(&[cell, &["--out"]].concat(), &[&a]));
    let table = std::fs::read_to_string(a.join("rheology.csv")).unwrap();
    let t = common::Table::parse(&table);
    let col = t.col("solver_tolerance");
    let tolerances: Vec<&str> = t.rows.iter().map(|r| &r[col]).collect();
    assert_eq!(tolerances, ["1e-4", "1e-5", "1e-5"], "{table}");
    let o = grainlaw(
        &[cell, &["--stop-after-steps", "240", "--out"]].concat(),
        &[&b],
    );
    assert_stopped(&o, &b);
    assert!(error_line(&o).contains("I=0.08 lead"), "{}", error_line(&o));
    let o = grainlaw(
        &["run", "-q", "--stop-after-steps", "60", "--resume"],
        &[&b],
    );
    assert_stopped(&o, &b);
    assert!(
        error_line(&o).contains("phase `I=0.08`"),
        "{}",
        error_line(&o)
    );
    assert_finished(&grainlaw(&["run", "-q", "--resume"], &[&b]));
    assert_same_outputs(&a, &b);
}

/// A real SIGINT (Ctrl-C) while the run steps: a checkpoint, exit 130, no summary.json; the
/// resumed run gives the uninterrupted run's files.
#[cfg(unix)]
#[test]
fn sigint_stops_cleanly_and_the_run_resumes() {
    signal_stops_cleanly_and_the_run_resumes("-INT");
}

/// SIGTERM, what batch schedulers (Slurm, PBS) send before killing a job, does the same, and
/// the request is acknowledged on stderr.
#[cfg(unix)]
#[test]
fn sigterm_stops_cleanly_and_the_run_resumes() {
    signal_stops_cleanly_and_the_run_resumes("-TERM");
}

#[cfg(unix)]
fn signal_stops_cleanly_and_the_run_resumes(signal: &str) {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    reference(&a);
    // Checkpoints every 20 steps: the first one shows that the run is stepping (the Ctrl-C
    // handler is installed before the first step).
    let mut child = Command::new(env!("CARGO_BIN_EXE_grainlaw"))
        .env("SOURCE_DATE_EPOCH", "1767225600")
        .args(SCENARIO)
        .args(["--checkpoint-every", "20", "--out"])
        .arg(&b)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !b.join("checkpoint/run.json.gz").exists() {
        assert!(
            start.elapsed() < Duration::from_secs(30),
            "no checkpoint after 30 s"
        );
        assert!(
            child.try_wait().unwrap().is_none(),
            "the run ended before it was interrupted"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    let kill = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    assert_stopped(&o, &b);
    assert!(
        stderr(&o).contains("warning: stop requested"),
        "{}",
        stderr(&o)
    );
    let o = grainlaw(&["run", "-q", "--resume"], &[&b]);
    assert_finished(&o);
    assert_same_outputs(&a, &b);
}

/// Refused resumes, each one line and exit code 2, the checkpoint left as it was: no
/// checkpoint, a finished run, a corrupt checkpoint, another scenario, other overrides,
/// `--out` with `--resume`. A new run in the directory then removes the stale checkpoint.
#[test]
fn bad_resumes_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    let refused = |args: &[&str], extra: &[&Path], needle: &str| {
        let o = grainlaw(args, extra);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let text = stderr(&o);
        assert_eq!(text.lines().count(), 1, "{args:?}: not one line: {text}");
        assert!(text.contains(needle), "{args:?}: `{needle}` not in {text}");
    };
    std::fs::create_dir_all(&dir).unwrap();
    refused(
        &["run", "--resume"],
        &[&dir],
        "no checkpoint to resume from",
    );
    let finished = tmp.path().join("finished");
    reference(&finished);
    refused(&["run", "--resume"], &[&finished], "the run there finished");

    let o = grainlaw(
        &[SCENARIO, &["--stop-after-steps", "30", "--out"]].concat(),
        &[&dir],
    );
    assert_stopped(&o, &dir);
    let cp = dir.join("checkpoint/run.json.gz");
    let saved = std::fs::read(&cp).unwrap();
    refused(
        &["run", "rolling", "--resume"],
        &[&dir],
        "resume it with `grainlaw run --resume",
    );
    refused(
        &["run", "janssen", "--set", "grains=61", "--resume"],
        &[&dir],
        "not `builtin:janssen --set grains=61`",
    );
    refused(
        &["run", "--set", "grains=70", "--resume"],
        &[&dir],
        "builtin:janssen --set grains=60",
    );
    refused(
        &["run", "--out", "elsewhere", "--resume"],
        &[&dir],
        "cannot be used with",
    );
    assert_eq!(
        std::fs::read(&cp).unwrap(),
        saved,
        "a refusal changed the checkpoint"
    );
    // The same scenario and overrides given again are accepted.
    let o = grainlaw(
        &[
            "run",
            "janssen",
            "--set",
            "grains=60",
            "-q",
            "--stop-after-steps",
            "1",
            "--resume",
        ],
        &[&dir],
    );
    assert_stopped(&o, &dir);
    // Truncated, then not gzip at all.
    let saved = std::fs::read(&cp).unwrap();
    std::fs::write(&cp, &saved[..saved.len() / 2]).unwrap();
    refused(&["run", "--resume"], &[&dir], "not a readable checkpoint");
    std::fs::write(&cp, b"{\"format\": 1}").unwrap();
    refused(&["run", "--resume"], &[&dir], "not a readable checkpoint");
    assert!(!dir.join("summary.json").exists());
    // A new run in the directory says it removes the old checkpoint, and finishes without one.
    let o = grainlaw(&[SCENARIO, &["--out"]].concat(), &[&dir]);
    assert_finished(&o);
    assert!(stderr(&o).contains("removed the checkpoint of an earlier, interrupted run"));
    assert!(!dir.join("checkpoint").exists() && dir.join("summary.json").is_file());
}
