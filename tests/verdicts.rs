//! Verdicts of scenario runs, through the binary (`docs/outputs.md` §2.1, `docs/cli.md` §7):
//! inputs that make the physics meaningless are refused before any work (exit 2, no output
//! directory); a run whose result fails a check exits with 3 and writes its law as
//! `NAME_law.rejected.json`, not `NAME_law.json`; `--allow-suspect` exports a suspect law marked
//! as such with exit 0, and a resume keeps it; a run whose checks pass exits with 0 and a law
//! marked `ok`.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

fn grainlaw(args: &[&str], out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_grainlaw"))
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .expect("grainlaw runs")
}

fn json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("JSON")
}

/// A small janssen column (100 grains, a few seconds) whose checks pass.
const JANSSEN: &[&str] = &["run", "janssen", "-q", "--set", "grains=100"];

/// The same with a loose solver: the relaxation to 10⁻⁵ and the release to 10⁻², and one
/// measured step (the built-in window is 4) stopped after twenty Gauss–Seidel sweeps, whole (no
/// sub-steps: the release's `max_halvings` is 0; `auto` would finish it with Newton): its error
/// is then about 240 times its tolerance (measured 2.40e-3), and 455 times over the loaded
/// contacts' scale (4.55e-3), so suspect on both (one sweep: 705 and 1335 times, refused on
/// the second; ten: 322 and 609, forty: 187 and 354). (Without Lemke's
/// finish, as when these expectations were measured: with it the deposit ends in another,
/// exactly solved state, from which the loose release gives a column whose Janssen fit is
/// refused outright.)
const LOOSE: &[&str] = &[
    "--set",
    "deposit.solver.lemke_max_contacts=0",
    "--set",
    "relax.solver.lemke_max_contacts=0",
    "--set",
    "release.solver.lemke_max_contacts=0",
    "--set",
    "relax.solver.tolerance=1e-5",
    "--set",
    "release.solver.tolerance=1e-2",
    "--set",
    "analysis.final_max_iterations=20",
    "--set",
    "relax.solver.method=nlgs",
    "--set",
    "release.solver.max_halvings=0",
    "--set",
    "analysis.measure_steps=1",
];

struct Case {
    name: &'static str,
    /// Output directory (cases that share one run in order: a later run must remove the law
    /// file of the other name an earlier one left).
    dir: &'static str,
    args: Vec<&'static str>,
    /// Exit status.
    code: i32,
    /// Text the stderr must contain.
    stderr: &'static str,
    /// `verdict` of summary.json (None: no summary.json, nor output directory).
    verdict: Option<&'static str>,
    /// Checks that must be among `verdict_reasons`, with their verdict.
    reasons: &'static [(&'static str, &'static str)],
    /// Files that must exist, with the `verdict` their law JSON must carry.
    laws: &'static [(&'static str, &'static str)],
    /// Files that must not exist.
    absent: &'static [&'static str],
}

fn cases() -> Vec<Case> {
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        JANSSEN.iter().chain(extra).copied().collect()
    };
    vec![
        Case {
            name: "grain-wall friction above 1 refused at input",
            dir: "friction",
            args: with(&["--set", "friction.grain_wall=1.5"]),
            code: 2,
            stderr: "key `friction.grain_wall`: friction coefficient 1.5 is above 1",
            verdict: None,
            reasons: &[],
            laws: &[],
            absent: &[],
        },
        Case {
            name: "shear-cell grain friction above 1 refused at input",
            dir: "shear-friction",
            args: vec![
                "run",
                "shear-cell",
                "-q",
                "--set",
                "friction.grain_grain=1.2",
            ],
            code: 2,
            stderr: "key `friction.grain_grain`",
            verdict: None,
            reasons: &[],
            laws: &[],
            absent: &[],
        },
        Case {
            name: "depth bins thinner than a grain refused at input",
            dir: "bins",
            args: with(&["--set", "grains=20", "--set", "analysis.depth_bins=30"]),
            code: 2,
            stderr: "key `analysis.depth_bins`",
            verdict: None,
            reasons: &[],
            laws: &[],
            absent: &[],
        },
        Case {
            name: "a column whose checks pass: law ok, exit 0",
            dir: "column",
            args: with(&[]),
            code: 0,
            stderr: "",
            verdict: Some("ok"),
            reasons: &[],
            laws: &[("janssen_law.json", "ok")],
            absent: &["janssen_law.rejected.json"],
        },
        Case {
            name: "a time step near the gravity limit: no calibrated law (the last run's removed), exit 3",
            dir: "column",
            args: with(&["--set", "dt=3.5e-3"]),
            code: 3,
            stderr: "verdict refused",
            verdict: Some("refused"),
            reasons: &[],
            laws: &[],
            absent: &["janssen_law.json", "janssen_law.rejected.json"],
        },
        Case {
            name: "a loose solver: suspect, law rejected, exit 3",
            dir: "loose",
            args: with(LOOSE),
            code: 3,
            stderr: "verdict suspect",
            verdict: Some("suspect"),
            reasons: &[
                ("solver.worst_error_over_tolerance", "suspect"),
                ("solver.loaded_error_over_tolerance", "suspect"),
                ("solver.unconverged_fraction", "suspect"),
            ],
            laws: &[("janssen_law.rejected.json", "suspect")],
            absent: &["janssen_law.json"],
        },
        Case {
            name: "--allow-suspect: the suspect law exported, marked, exit 0",
            dir: "loose",
            args: with(LOOSE).into_iter().chain(["--allow-suspect"]).collect(),
            code: 0,
            stderr: "",
            verdict: Some("suspect"),
            reasons: &[("solver.worst_error_over_tolerance", "suspect")],
            laws: &[("janssen_law.json", "suspect")],
            absent: &["janssen_law.rejected.json"],
        },
        Case {
            // The floor withdrawn at 0.1 m/s, faster than the column can follow it (a grain
            // falls g h = 9.8 mm/s per step): the measured column is in free fall, nothing
            // carries its weight, so the force balance refuses it (measured: −100 %).
            name: "a column in free fall at the measured step: force balance refused, exit 3",
            dir: "falling",
            args: with(&["--set", "release.speed=0.1"]),
            code: 3,
            stderr: "janssen.force_balance (refused)",
            verdict: Some("refused"),
            reasons: &[("janssen.force_balance", "refused")],
            laws: &[],
            absent: &["janssen_law.json"],
        },
        Case {
            name: "shear cell whose highest target I is not reached: suspect, exit 3",
            dir: "shear",
            args: common::small_shear_cell("inertial_numbers=[0.1, 0.2, 0.4]", &[]),
            code: 3,
            stderr: "shear_cell.inertial_number_factor (suspect)",
            verdict: Some("refused"),
            reasons: &[("shear_cell.inertial_number_factor", "suspect")],
            laws: &[],
            absent: &["mu_i_law.json", "phi_i_law.json"],
        },
        Case {
            // Every window step meets the loose tolerance (worst error 4.1e-3 ≤ 1e-2), so the
            // error checks pass; solved again to 1e-8, the windows' pressure moves by 9.5–12 %
            // (the lead stages' tightening of the tolerance off).
            name: "shear cell solved at 1e-2: the re-solve of its samples refuses it, exit 3",
            dir: "loose-shear",
            args: common::small_shear_cell(
                "inertial_numbers=[0.04, 0.08, 0.15]",
                &[
                    "--set",
                    "solver.tolerance=1e-2",
                    "--set",
                    "solver_tightenings=0",
                ],
            ),
            code: 3,
            stderr: "solver.sensitivity_pressure (refused)",
            verdict: Some("refused"),
            reasons: &[("solver.sensitivity_pressure", "refused")],
            laws: &[],
            absent: &["mu_i_law.json", "phi_i_law.json"],
        },
        Case {
            name: "rolling against its exact answer: ok",
            dir: "rolling",
            args: vec!["run", "rolling", "-q"],
            code: 0,
            stderr: "",
            verdict: Some("ok"),
            reasons: &[],
            laws: &[],
            absent: &[],
        },
    ]
}

#[test]
fn verdicts_of_runs() {
    let tmp = tempfile::tempdir().unwrap();
    for c in cases() {
        let out = tmp.path().join(c.dir);
        let o = grainlaw(&c.args, &out);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(c.code), "{}: {stderr}", c.name);
        assert!(stderr.contains(c.stderr), "{}: stderr {stderr}", c.name);
        assert!(!stderr.contains("panicked"), "{}: {stderr}", c.name);
        if c.code != 0 {
            let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
            assert_eq!(errors.len(), 1, "{}: one error line: {stderr}", c.name);
        }
        let Some(verdict) = c.verdict else {
            assert!(!out.exists(), "{}: refused before any work", c.name);
            continue;
        };
        let s = json(&out.join("summary.json"));
        assert_eq!(s["verdict"], verdict, "{}: {s}", c.name);
        let reasons = s["verdict_reasons"].as_array().expect("verdict_reasons");
        if verdict == "ok" {
            assert!(reasons.is_empty(), "{}: {reasons:?}", c.name);
        }
        for (check, v) in c.reasons {
            assert!(
                reasons.iter().any(|r| r["check"] == *check
                    && r["verdict"] == *v
                    && r["value"].is_number()
                    && r["threshold"].is_number()
                    && r["message"].as_str().is_some_and(|m| !m.is_empty())),
                "{}: no {check} ({v}) in {reasons:?}",
                c.name
            );
        }
        for (file, v) in c.laws {
            let law = json(&out.join(file));
            assert_eq!(law["verdict"], *v, "{}: {file}", c.name);
            assert_eq!(law["schema_version"], 2, "{}: {file}", c.name);
            let listed = s["law_verdicts"]
                .as_array()
                .unwrap()
                .iter()
                .any(|l| l["file"] == *file && l["verdict"] == *v);
            assert!(listed, "{}: {file} not in law_verdicts: {s}", c.name);
            if *v != "ok" {
                assert!(
                    !law["verdict_reasons"].as_array().unwrap().is_empty(),
                    "{}: {file} says why",
                    c.name
                );
            }
        }
        for file in c.absent {
            assert!(!out.join(file).exists(), "{}: {file} written", c.name);
        }
    }
}

/// `--allow-suspect` is recorded in the checkpoint: a run stopped and resumed without the flag
/// still exports its suspect law and exits with 0.
#[test]
fn resume_keeps_allow_suspect() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("run");
    let args: Vec<&str> = JANSSEN
        .iter()
        .chain(LOOSE)
        .chain(&["--allow-suspect", "--stop-after-steps", "300"])
        .copied()
        .collect();
    let o = grainlaw(&args, &out);
    assert_eq!(
        o.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let o = Command::new(env!("CARGO_BIN_EXE_grainlaw"))
        .args(["run", "-q", "--resume"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(json(&out.join("summary.json"))["verdict"], "suspect");
    assert_eq!(json(&out.join("janssen_law.json"))["verdict"], "suspect");
    assert!(!out.join("janssen_law.rejected.json").exists());
}

/// A rejected law's coefficients are printed under a line that says it is rejected, before
/// them: the loose column of `cases` (its Janssen law suspect, written as
/// `janssen_law.rejected.json`) prints `law janssen: REJECTED …` above `K = …`; with
/// `--allow-suspect`, `law janssen: SUSPECT …` instead. A law that passes prints no such line
/// (the `column` case's report is checked in `cases`; here the stdout of the two loose runs).
#[test]
fn rejected_coefficients_are_marked_before_they_are_printed() {
    let tmp = tempfile::tempdir().unwrap();
    let args: Vec<&str> = ["run", "janssen", "--set", "grains=100"]
        .into_iter()
        .chain(LOOSE.iter().copied())
        .collect();
    for (extra, mark) in [
        (None, "law janssen: REJECTED, not a calibrated law"),
        (
            Some("--allow-suspect"),
            "law janssen: SUSPECT (exported marked",
        ),
    ] {
        let mut a = args.clone();
        a.extend(extra);
        let o = grainlaw(&a, &tmp.path().join("loose"));
        let stdout = String::from_utf8_lossy(&o.stdout);
        let lines: Vec<&str> = stdout.lines().collect();
        let at = |p: &str| lines.iter().position(|l| l.starts_with(p));
        let (m, k) = (at(mark), at("K    ="));
        assert!(
            matches!((m, k), (Some(m), Some(k)) if m + 1 == k),
            "the mark must head the coefficients: {stdout}"
        );
    }
}
