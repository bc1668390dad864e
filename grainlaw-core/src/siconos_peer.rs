//! Siconos 4.4 as the measured peer of `grainlaw bench`'s frictional-contact tables.
//!
//! When a Python interpreter that can `import siconos.numerics` is found (`/usr/bin/python3`,
//! where Debian's `python3-siconos` installs, or the interpreter named by
//! `GRAINLAW_SICONOS_PYTHON`; `GRAINLAW_SICONOS_PYTHON=off` disables the peer), each problem is
//! also solved by Siconos numerics' `fc2d_driver` (Acary, Brémond & Huber, "On solving contact
//! problems with Coulomb friction: formulations and numerical comparisons", in *Advanced Topics
//! in Nonsmooth Dynamics*, Springer 2018) in the same run, one core (`OMP_NUM_THREADS=1`),
//! through the repository's `scripts/siconos_solve_fc.py`, which this module embeds and feeds to
//! the interpreter on stdin (so the binary needs no path to the repository).
//!
//! What is measured: the script times the `fc2d_driver` call alone (best of its repeats from
//! `r = 0`), not the interpreter start-up, the imports, the reading of the file or the
//! conversion of `W` to Siconos' sparse block storage; the error is recomputed from the
//! returned `r` with the measure of `docs/formats.md` §1.2 (Siconos' `fc2d_compute_error`,
//! the one [`dem::fc::fc_error`] implements); "converged" is Siconos' own flag (`info = 0`)
//! and that error at or below the tolerance. A run that fails, prints nothing parsable or
//! outlasts its wall-clock cap is reported as such ([`PeerOutcome`]), never as figures.
//!
//! Without the peer the tables keep the figures quoted from an earlier measurement
//! ([`crate::fc_bench::SICONOS_REFERENCE`], [`QUOTED_HARD`]), labelled as quoted.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The solver script, embedded (`scripts/siconos_solve_fc.py`).
pub const SCRIPT: &str = include_str!("../../scripts/siconos_solve_fc.py");

/// The first word of the script's result line.
pub const LINE_TAG: &str = "siconos-fc-v1";

/// The modules the script needs, imported by [`detect`]'s probe: a Python with Siconos but
/// without numpy or scipy (Debian's `python3-siconos` does not pull `python3-scipy`) is
/// reported once as unusable, not as a failure per problem.
pub const PROBE_IMPORTS: &str =
    "siconos.numerics, numpy, scipy.sparse, scipy.sparse.csc, scipy.sparse.coo";

/// Interpreter tried when `GRAINLAW_SICONOS_PYTHON` is not set.
pub const DEFAULT_PYTHON: &str = "/usr/bin/python3";

/// Siconos' figures on one problem, as printed by the script.
#[derive(Debug, Clone, PartialEq)]
pub struct PeerFigures {
    /// Siconos solver (`NSGS` or `LEMKE`).
    pub solver: String,
    /// Number of contacts.
    pub contacts: usize,
    /// Siconos' return code (0: converged by its own test).
    pub info: i64,
    /// `info = 0` and `error ≤ tol`.
    pub converged: bool,
    /// Siconos' `SICONOS_IPARAM_ITER_DONE` (NSGS sweeps; Lemke pivots).
    pub iterations: usize,
    /// Error of `docs/formats.md` §1.2 recomputed from the returned `r`.
    pub error: f64,
    /// Seconds of the `fc2d_driver` call (best of the script's repeats).
    pub seconds: f64,
}

/// What became of one peer run.
#[derive(Debug, Clone, PartialEq)]
pub enum PeerOutcome {
    /// The script ran and printed its figures.
    Measured(PeerFigures),
    /// Killed after the wall-clock cap (seconds, start-up included).
    TimedOut(f64),
    /// The run failed; the reason (exit status and last line of stderr, or parse error).
    Failed(String),
}

/// One peer solve: the options passed to the script.
#[derive(Debug, Clone, PartialEq)]
pub struct PeerRequest {
    /// `NSGS` or `LEMKE`.
    pub solver: &'static str,
    /// Tolerance on the error of §1.2.
    pub tol: f64,
    /// Siconos' iteration cap.
    pub max_iter: usize,
    /// Solves from `r = 0` (best time kept) …
    pub repeat: usize,
    /// … until they have taken this many seconds in all.
    pub repeat_budget: f64,
    /// Wall-clock cap of the whole run (interpreter start-up included); the run is killed after.
    pub cap: Duration,
}

/// The interpreter to use, or why the peer is off: `GRAINLAW_SICONOS_PYTHON` (`off` disables),
/// else [`DEFAULT_PYTHON`]; `Err(reason)` when it cannot import what the script imports
/// ([`PROBE_IMPORTS`]: Siconos numerics, numpy and scipy's sparse modules) within 60 s.
pub fn detect() -> Result<PathBuf, String> {
    let probe = format!("import {PROBE_IMPORTS}");
    let python = match std::env::var("GRAINLAW_SICONOS_PYTHON") {
        Ok(v) if v.trim().eq_ignore_ascii_case("off") => {
            return Err("GRAINLAW_SICONOS_PYTHON=off".into())
        }
        Ok(v) if !v.trim().is_empty() => PathBuf::from(v.trim()),
        _ => PathBuf::from(DEFAULT_PYTHON),
    };
    let mut cmd = Command::new(&python);
    cmd.args(["-c", &probe]);
    match run_capped(cmd, None, Duration::from_secs(60)) {
        Ok((true, _, _)) => Ok(python),
        Ok((false, _, err)) => Err(format!(
            "{} cannot import {PROBE_IMPORTS}{}",
            python.display(),
            last_line(&err)
                .map(|l| format!(" ({l})"))
                .unwrap_or_default()
        )),
        Err(RunError::TimedOut) => Err(format!(
            "{} -c '{probe}' took more than 60 s",
            python.display()
        )),
        Err(RunError::Spawn(e)) => Err(format!("cannot run {}: {e}", python.display())),
    }
}

/// Solves `problem` with Siconos through the embedded script (one core: `OMP_NUM_THREADS=1`).
pub fn solve(python: &Path, problem: &Path, req: &PeerRequest) -> PeerOutcome {
    let mut cmd = Command::new(python);
    cmd.arg("-")
        .arg(problem)
        .args(["--solver", req.solver])
        .args(["--tol", &format!("{:e}", req.tol)])
        .args(["--max-iter", &req.max_iter.to_string()])
        .args(["--repeat", &req.repeat.to_string()])
        .args(["--repeat-budget", &req.repeat_budget.to_string()])
        .env("OMP_NUM_THREADS", "1")
        .env("OPENBLAS_NUM_THREADS", "1");
    match run_capped(cmd, Some(SCRIPT), req.cap) {
        Err(RunError::TimedOut) => PeerOutcome::TimedOut(req.cap.as_secs_f64()),
        Err(RunError::Spawn(e)) => {
            PeerOutcome::Failed(format!("cannot run {}: {e}", python.display()))
        }
        Ok((ok, out, err)) => {
            let line = out.lines().find(|l| l.starts_with(LINE_TAG));
            match (ok, line) {
                (true, Some(l)) => match parse_line(l) {
                    Ok(f) => PeerOutcome::Measured(f),
                    Err(e) => PeerOutcome::Failed(e),
                },
                (true, None) => PeerOutcome::Failed("no result line on stdout".into()),
                (false, _) => PeerOutcome::Failed(format!(
                    "exit failure{}",
                    last_line(&err)
                        .map(|l| format!(": {l}"))
                        .unwrap_or_default()
                )),
            }
        }
    }
}

/// Parses the script's result line (`siconos-fc-v1 key=value …`).
pub fn parse_line(line: &str) -> Result<PeerFigures, String> {
    let mut words = line.split_whitespace();
    if words.next() != Some(LINE_TAG) {
        return Err(format!("not a {LINE_TAG} line: {line:?}"));
    }
    let pairs: Vec<(&str, &str)> = words.filter_map(|w| w.split_once('=')).collect();
    let get = |k: &str| {
        pairs
            .iter()
            .find(|(key, _)| *key == k)
            .map(|(_, v)| *v)
            .ok_or_else(|| format!("{LINE_TAG} line without `{k}`: {line:?}"))
    };
    let num = |k: &str| -> Result<f64, String> {
        let v = get(k)?;
        v.parse::<f64>()
            .map_err(|_| format!("{LINE_TAG} line: `{k}={v}` is not a number"))
    };
    let int = |k: &str| -> Result<i64, String> {
        let v = get(k)?;
        v.parse::<i64>()
            .map_err(|_| format!("{LINE_TAG} line: `{k}={v}` is not an integer"))
    };
    let count = |k: &str| -> Result<usize, String> {
        usize::try_from(int(k)?).map_err(|_| format!("{LINE_TAG} line: `{k}` is negative"))
    };
    let converged = match get("converged")? {
        "1" => true,
        "0" => false,
        v => return Err(format!("{LINE_TAG} line: `converged={v}` is not 0 or 1")),
    };
    let seconds = num("seconds")?;
    if !(seconds.is_finite() && seconds >= 0.0) {
        return Err(format!("{LINE_TAG} line: seconds = {seconds}"));
    }
    Ok(PeerFigures {
        solver: get("solver")?.to_string(),
        contacts: count("contacts")?,
        info: int("info")?,
        converged,
        iterations: count("iterations")?,
        error: num("error")?,
        seconds,
    })
}

/// Where the Siconos figures of a row come from.
#[derive(Debug, Clone, PartialEq)]
pub enum SiconosCell {
    /// Measured in this run.
    Measured(PeerOutcome),
    /// Quoted from an earlier measurement: (iterations, seconds, converged when known), when
    /// one exists.
    Quoted(Option<(usize, f64, Option<bool>)>),
}

impl SiconosCell {
    /// Label of the source: `measured` or `quoted`.
    pub fn source(&self) -> &'static str {
        match self {
            SiconosCell::Measured(_) => "measured",
            SiconosCell::Quoted(_) => "quoted",
        }
    }

    /// Siconos seconds over ours, when Siconos converged (measured) or a resolved (≥ 10⁻⁴ s)
    /// quoted time exists, and both times are resolved.
    pub fn ratio(&self, ours: f64) -> Option<f64> {
        let theirs = match self {
            SiconosCell::Measured(PeerOutcome::Measured(f)) if f.converged => f.seconds,
            SiconosCell::Quoted(Some((_, s, conv))) if *conv != Some(false) => *s,
            _ => return None,
        };
        (theirs >= 1e-4 && ours > 0.0).then(|| theirs / ours)
    }

    /// `seconds / iterations / error / converged` columns (quoted: error and flag unknown).
    pub fn columns(&self) -> [String; 4] {
        match self {
            SiconosCell::Measured(PeerOutcome::Measured(f)) => [
                if f.seconds < 1e-3 {
                    format!("{:.1e}", f.seconds)
                } else {
                    format!("{:.4}", f.seconds)
                },
                f.iterations.to_string(),
                format!("{:.2e}", f.error),
                if f.converged { "yes" } else { "NO" }.into(),
            ],
            SiconosCell::Measured(PeerOutcome::TimedOut(cap)) => [
                format!("timeout>{cap:.0}s"),
                "-".into(),
                "-".into(),
                "-".into(),
            ],
            SiconosCell::Measured(PeerOutcome::Failed(_)) => {
                ["FAILED".into(), "-".into(), "-".into(), "-".into()]
            }
            SiconosCell::Quoted(Some((it, s, conv))) => [
                if *s < 1e-4 {
                    "<1e-4".into()
                } else {
                    format!("{s:.4}")
                },
                it.to_string(),
                "-".into(),
                match conv {
                    Some(true) => "yes",
                    Some(false) => "NO",
                    None => "-",
                }
                .into(),
            ],
            SiconosCell::Quoted(None) => ["-".into(), "-".into(), "-".into(), "-".into()],
        }
    }

    /// The failure reason to print under the table, if any.
    pub fn failure(&self) -> Option<&str> {
        match self {
            SiconosCell::Measured(PeerOutcome::Failed(reason)) => Some(reason),
            _ => None,
        }
    }
}

/// One quoted hard row: (problem, NSGS (iterations, seconds, converged), Lemke (pivots,
/// seconds) or `None` when it did not finish in 120 s).
pub type QuotedHard = (&'static str, (usize, f64, bool), Option<(usize, f64)>);

/// Siconos 4.4 fc2d on the hard problems (tolerance 10⁻⁸, NSGS at most 20 000 iterations,
/// Lemke capped at 120 s), quoted from `datasets/fc-problems/hard/README.md` (measured
/// 2026-12-02 before this module existed): (problem, NSGS (iterations, seconds, converged),
/// Lemke (pivots, seconds) or `None` when it did not finish in 120 s).
pub const QUOTED_HARD: &[QuotedHard] = &[
    (
        "janssen_deposit_0225",
        (4693, 0.66, true),
        Some((461, 4.05)),
    ),
    ("janssen_release_1408", (20000, 6.18, false), None),
    (
        "shear-cell_compress_0036",
        (6985, 1.11, true),
        Some((5395, 56.5)),
    ),
    ("shear-cell_I0.005_0000201", (20000, 6.87, false), None),
    (
        "stick-slip_deposit2_0000183",
        (1597, 0.13, true),
        Some((439, 0.90)),
    ),
];

fn last_line(s: &str) -> Option<String> {
    s.lines()
        .rev()
        .find(|l| !l.trim().is_empty())
        .map(|l| l.trim().chars().take(200).collect())
}

enum RunError {
    Spawn(std::io::Error),
    TimedOut,
}

/// Runs `cmd` with `stdin` written to its standard input, killing it after `cap`:
/// (exit success, stdout, stderr).
fn run_capped(
    mut cmd: Command,
    stdin: Option<&'static str>,
    cap: Duration,
) -> Result<(bool, String, String), RunError> {
    cmd.stdin(if stdin.is_some() {
        Stdio::piped()
    } else {
        Stdio::null()
    })
    .stdout(Stdio::piped())
    .stderr(Stdio::piped());
    let mut child = cmd.spawn().map_err(RunError::Spawn)?;
    if let (Some(text), Some(mut pipe)) = (stdin, child.stdin.take()) {
        // the script is small (a few kB, below a pipe's buffer); the pipe is closed after
        let _ = pipe.write_all(text.as_bytes());
    }
    let reader = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut s = String::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_string(&mut s);
            }
            s
        })
    };
    let out = reader(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let err = reader(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let start = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break Some(status),
            Ok(None) if start.elapsed() < cap => std::thread::sleep(Duration::from_millis(20)),
            Ok(None) => {
                let _ = child.kill();
                let _ = child.wait();
                break None;
            }
            Err(e) => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(RunError::Spawn(e));
            }
        }
    };
    let out = out.join().unwrap_or_default();
    let err = err.join().unwrap_or_default();
    match status {
        Some(s) => Ok((s.success(), out, err)),
        None => Err(RunError::TimedOut),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every module outside Python's standard library that the script imports, by its full
    /// dotted name, is imported by the probe of [`detect`] (a Python with Siconos but without
    /// scipy failed every problem one by one, 2026-12-03; a scipy without the deprecated
    /// `scipy.sparse.csc` shim would do the same).
    #[test]
    fn the_probe_imports_what_the_script_imports() {
        let stdlib = ["argparse", "gzip", "json", "os", "sys", "time", "math"];
        let probed: Vec<&str> = PROBE_IMPORTS.split(',').map(str::trim).collect();
        let mut third_party = Vec::new();
        for line in SCRIPT.lines() {
            let module = match line.split_whitespace().collect::<Vec<_>>()[..] {
                ["import", m, ..] | ["from", m, "import", ..] => m,
                _ => continue,
            };
            let top = module.split('.').next().unwrap_or(module);
            if !stdlib.contains(&top) {
                third_party.push(module.to_string());
            }
        }
        assert!(
            third_party.len() >= 3,
            "the script's imports were not found: {third_party:?}"
        );
        for m in &third_party {
            assert!(
                probed.contains(&m.as_str()),
                "the script imports {m}, which the probe ({PROBE_IMPORTS}) does not check"
            );
        }
    }

    #[test]
    fn parses_a_captured_line() {
        // captured from `/usr/bin/python3 scripts/siconos_solve_fc.py pile_pert_100.json.gz`
        let l = "siconos-fc-v1 solver=NSGS contacts=89 info=0 converged=1 iterations=118 \
                 error=9.818479e-07 error_siconos=9.818479e-07 seconds=2.149666e-03 repeats=3";
        let f = parse_line(l).unwrap();
        assert_eq!(f.solver, "NSGS");
        assert_eq!((f.contacts, f.info, f.iterations), (89, 0, 118));
        assert!(f.converged);
        assert!((f.error - 9.818479e-7).abs() < 1e-15);
        assert!((f.seconds - 2.149666e-3).abs() < 1e-12);
    }

    #[test]
    fn refuses_broken_lines() {
        assert!(parse_line("problem=x seconds=1").is_err());
        let ok = "siconos-fc-v1 solver=LEMKE contacts=2 info=1 converged=0 iterations=5 error=1e-3 seconds=0.5";
        assert!(!parse_line(ok).unwrap().converged);
        assert!(parse_line(&ok.replace("seconds=0.5", "")).is_err());
        assert!(parse_line(&ok.replace("seconds=0.5", "seconds=nan")).is_err());
        assert!(parse_line(&ok.replace("converged=0", "converged=yes")).is_err());
        assert!(parse_line(&ok.replace("iterations=5", "iterations=-5")).is_err());
    }

    #[test]
    fn labels_and_ratios() {
        let quoted = SiconosCell::Quoted(Some((862, 0.2, None)));
        assert_eq!(quoted.source(), "quoted");
        assert!((quoted.ratio(0.004).unwrap() - 50.0).abs() < 1e-9);
        assert_eq!(quoted.columns()[2], "-");
        // an unresolved quoted time gives no ratio
        assert_eq!(
            SiconosCell::Quoted(Some((266, 0.0, None))).ratio(1e-5),
            None
        );
        // nor does a quoted run that did not converge
        let stalled = SiconosCell::Quoted(Some((20000, 6.18, Some(false))));
        assert_eq!(
            (stalled.ratio(1.0), stalled.columns()[3].as_str()),
            (None, "NO")
        );
        let fig = PeerFigures {
            solver: "NSGS".into(),
            contacts: 89,
            info: 0,
            converged: true,
            iterations: 118,
            error: 9.8e-7,
            seconds: 0.002,
        };
        let measured = SiconosCell::Measured(PeerOutcome::Measured(fig.clone()));
        assert_eq!(measured.source(), "measured");
        assert!((measured.ratio(0.0001).unwrap() - 20.0).abs() < 1e-9);
        assert_eq!(measured.columns()[3], "yes");
        // an unconverged, timed-out or failed peer gives no ratio and no time
        let unconv = SiconosCell::Measured(PeerOutcome::Measured(PeerFigures {
            converged: false,
            ..fig
        }));
        assert_eq!(unconv.ratio(0.0001), None);
        assert_eq!(unconv.columns()[3], "NO");
        let t = SiconosCell::Measured(PeerOutcome::TimedOut(60.0));
        assert_eq!(
            (t.ratio(1.0), t.columns()[0].as_str()),
            (None, "timeout>60s")
        );
        let f = SiconosCell::Measured(PeerOutcome::Failed("exit failure".into()));
        assert_eq!((f.ratio(1.0), f.columns()[0].as_str()), (None, "FAILED"));
        assert_eq!(f.failure(), Some("exit failure"));
    }

    #[test]
    fn off_disables_the_peer() {
        // only this test touches the variable in this binary
        let before = std::env::var_os("GRAINLAW_SICONOS_PYTHON");
        std::env::set_var("GRAINLAW_SICONOS_PYTHON", "off");
        let r = detect();
        match before {
            Some(v) => std::env::set_var("GRAINLAW_SICONOS_PYTHON", v),
            None => std::env::remove_var("GRAINLAW_SICONOS_PYTHON"),
        }
        assert_eq!(r, Err("GRAINLAW_SICONOS_PYTHON=off".to_string()));
    }
}
