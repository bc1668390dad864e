//! `grainlaw run column-collapse` on small columns (a few hundred grains, seconds each): the
//! contract's files with their headers and `t*` computed right, the front, rest, mass and
//! heights of the collapse, the undisturbed top of a squat column, resume bit for bit, bad
//! values refused naming the key, and the runout table of a campaign over the aspect ratio.

use std::collections::BTreeSet;
mod common;

use std::path::Path;
use std::process::Output;

use common::{campaign, plan_dir, text, Table};
use serde_json::Value;

/// A column 10 mean diameters wide (R₀ = 5 cm), a = 2: about 190 grains, 2 s.
const SMALL: &[&str] = &[
    "--set",
    "aspect_ratio=2",
    "--set",
    "half_width_diameters=10",
    "--set",
    "floor_length=8",
];

/// `grainlaw ARGS` at the fixed date of [`common::grainlaw`].
fn grainlaw(args: &[&str]) -> Output {
    common::grainlaw(args, None)
}

/// The arguments of a quiet `column-collapse` run into `out` with suspect results allowed (the
/// verdicts are checked one by one below), then `extra`.
fn run_args<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let head = [
        "run",
        "column-collapse",
        "--out",
        out,
        "-q",
        "--allow-suspect",
    ];
    head.iter().chain(extra).copied().collect()
}

/// Runs `column-collapse` with `sets` into `dir` ([`run_args`]) and returns its summary.
fn run(dir: &Path, sets: &[&str]) -> Value {
    let args = run_args(dir.to_str().unwrap(), sets);
    let o = grainlaw(&args);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap()
}

fn f(v: &Value, k: &str) -> f64 {
    v[k].as_f64()
        .unwrap_or_else(|| panic!("key {k} missing or not a number: {v}"))
}

/// The checks a run failed (their names).
fn failed_checks(s: &Value) -> Vec<String> {
    s["verdict_reasons"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|r| r["check"].as_str().map(String::from))
                .collect()
        })
        .unwrap_or_default()
}

/// The collapse of a small column, a = 2: the contract's files and keys; `t*` = t √(g/H₀) in
/// both CSV files to 10⁻¹²; the front advancing while the column spreads (within one bin up to
/// halfway to its farthest reach: past that the tongue thins to a single layer, whose large
/// grains rise above and sink below the one-diameter threshold); the deposit at rest at the
/// end, every grain on the floor and the grains' mass unchanged; the runout beyond R₀ and the
/// final height below H₀; the deposit's profile holding the grains' area at a solid fraction
/// between 0.6 and 0.9 (mass conservation seen by the profile).
#[test]
fn a_small_column_collapses_to_rest_with_the_contract_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let s = run(dir.path(), SMALL);
    let col = &s["column"];
    for k in [
        "initial_half_width_m",
        "initial_height_m",
        "aspect_ratio",
        "mean_diameter_m",
        "gravity_m_s2",
        "grain_density_kg_m3",
        "initial_packing_fraction",
        "grain_friction",
        "floor_friction",
        "runout_m",
        "final_height_m",
        "rest_time_s",
    ] {
        assert!(col[k].is_number(), "column.{k}: {col}");
    }
    assert_eq!(
        col["reference_instants_t_star"],
        serde_json::json!([0.66, 0.95, 1.24, 1.52, 2.28])
    );
    let (r0, h0, d, g) = (
        f(col, "initial_half_width_m"),
        f(col, "initial_height_m"),
        f(col, "mean_diameter_m"),
        f(col, "gravity_m_s2"),
    );
    assert!(
        (r0 - 0.05).abs() < 1e-15 && (h0 - 0.1).abs() < 1e-15,
        "{col}"
    );
    assert!((f(col, "aspect_ratio") - h0 / r0).abs() < 1e-12);
    let scale = (g / h0).sqrt();

    // front.csv
    let front = std::fs::read_to_string(dir.path().join("front.csv")).unwrap();
    assert_eq!(front.lines().next(), Some("t_s,t_star,x_f_m"));
    let mut samples = Vec::new();
    for r in csv::Reader::from_reader(front.as_bytes()).deserialize::<(f64, f64, f64)>() {
        let (t, ts, x) = r.unwrap();
        assert!(
            (ts - t * scale).abs() <= 1e-12 * ts.abs().max(1e-3),
            "{t} {ts}"
        );
        samples.push((t, x));
    }
    assert!(samples.len() > 50, "{} samples", samples.len());
    assert_eq!(samples[0].0, 0.0);
    let reach = samples.iter().map(|s| s.1).fold(0.0, f64::max);
    let mut most: f64 = 0.0;
    for &(t, x) in &samples {
        if most >= r0 + 0.5 * (reach - r0) {
            break;
        }
        assert!(
            x >= most - d - 1e-12,
            "front receded at t = {t}: {x} after {most}"
        );
        most = most.max(x);
    }

    // at rest, mass conserved, runout and height
    assert_eq!(s["at_rest"], Value::Bool(true), "{s}");
    let fails = failed_checks(&s);
    for check in [
        "column.at_rest",
        "column.mass_conserved",
        "column.floor_length",
    ] {
        assert!(!fails.iter().any(|c| c == check), "{check} failed: {s}");
    }
    assert_eq!(f(&s, "grains_escaped"), 0.0);
    let runout = f(col, "runout_m");
    let final_height = f(col, "final_height_m");
    assert!(runout > r0 + d, "r_inf {runout} vs R0 {r0}");
    assert!(
        final_height < h0 - d,
        "final height {final_height} vs H0 {h0}"
    );
    assert!(f(col, "rest_time_s") > 0.0);
    let last = samples.last().unwrap();
    assert!(
        (last.1 - runout).abs() < 1e-12,
        "the last front sample is the runout"
    );

    // profiles.csv
    let profiles = std::fs::read_to_string(dir.path().join("profiles.csv")).unwrap();
    assert_eq!(profiles.lines().next(), Some("label,t_star,x_m,h_m"));
    let mut labels = BTreeSet::new();
    let (mut area, mut rest_t_star) = (0.0, f64::NAN);
    for r in csv::Reader::from_reader(profiles.as_bytes()).deserialize::<(String, f64, f64, f64)>()
    {
        let (label, ts, x, h) = r.unwrap();
        assert!(x > 0.0 && h >= 0.0, "{label} {x} {h}");
        if let Some(want) = label.strip_prefix('t') {
            let want: f64 = want.parse().unwrap();
            // the first step at or past the instant (steps of 2.5e-4 s)
            assert!(
                ts >= want - 1e-9 && ts < want + 2.5e-4 * scale + 1e-9,
                "{label}: {ts}"
            );
        } else {
            assert_eq!(label, "rest");
            area += h * d;
            rest_t_star = ts;
        }
        labels.insert(label);
    }
    let want: BTreeSet<String> = ["t0.66", "t0.95", "t1.24", "t1.52", "t2.28", "rest"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(labels, want);
    assert!((rest_t_star - f(col, "rest_time_s") * scale).abs() < 1e-9);
    let grain_area = f(&s, "grains_mass_kg_per_m") / f(col, "grain_density_kg_m3");
    let phi = grain_area / area;
    assert!((0.6..0.9).contains(&phi), "deposit solid fraction {phi}");
    for file in [
        "front.png",
        "profiles.png",
        "snapshot_rest.png",
        "snapshot_t0.66.png",
    ] {
        assert!(dir.path().join(file).is_file(), "{file}");
    }
}

/// A squat column (a = 0.5) collapses only at its edge: the top stays undisturbed and the
/// final height equals the initial one within one mean diameter (Lajeunesse et al. 2004: the
/// height of columns with a ≲ 0.7 is unchanged), while the runout exceeds R₀.
#[test]
fn a_squat_column_keeps_its_top() {
    let dir = tempfile::tempdir().unwrap();
    let s = run(
        dir.path(),
        &[
            "--set",
            "aspect_ratio=0.5",
            "--set",
            "half_width_diameters=16",
            "--set",
            "floor_length=5",
        ],
    );
    let col = &s["column"];
    let d = f(col, "mean_diameter_m");
    let (h_end, h_start) = (f(col, "final_height_m"), f(&s, "initial_surface_height_m"));
    assert!(
        (h_end - h_start).abs() <= d,
        "final height {h_end} vs initial {h_start} (d = {d})"
    );
    assert!(f(col, "runout_m") > f(col, "initial_half_width_m") + d);
    assert_eq!(s["at_rest"], Value::Bool(true));
}

/// A run stopped in the middle of its collapse (as by Ctrl-C: the front samples, profiles,
/// snapshots and VTK frames so far in the checkpoint) and resumed writes the same files byte for
/// byte, and the same summary (`wall_seconds` aside), as the run never stopped.
#[test]
fn a_resumed_collapse_is_bit_identical() {
    let whole = tempfile::tempdir().unwrap();
    let cut = tempfile::tempdir().unwrap();
    let small = [
        "--set",
        "aspect_ratio=2",
        "--set",
        "half_width_diameters=6",
        "--set",
        "floor_length=8",
    ];
    run(whole.path(), &small);
    let out = cut.path().to_str().unwrap();
    // the deposit takes about 490 steps: stopped in the middle of the collapse
    let args = run_args(out, &[&["--stop-after-steps", "1200"], &small[..]].concat());
    let o = grainlaw(&args);
    assert_eq!(o.status.code(), Some(130), "{}", text(&o));
    assert!(text(&o).contains("of phase `collapse`"), "{}", text(&o));
    let o = grainlaw(&["run", "--resume", out, "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let files = |d: &Path| -> Vec<(String, Vec<u8>)> {
        let mut v = Vec::new();
        let mut stack = vec![d.to_path_buf()];
        while let Some(p) = stack.pop() {
            for e in std::fs::read_dir(&p).unwrap().flatten() {
                let q = e.path();
                if q.is_dir() {
                    stack.push(q);
                } else {
                    let name = q.strip_prefix(d).unwrap().display().to_string();
                    v.push((name, std::fs::read(&q).unwrap()));
                }
            }
        }
        v.sort();
        v
    };
    let (a, b) = (files(whole.path()), files(cut.path()));
    assert_eq!(
        a.iter().map(|x| &x.0).collect::<Vec<_>>(),
        b.iter().map(|x| &x.0).collect::<Vec<_>>()
    );
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        if name == "summary.json" {
            let strip = |bytes: &[u8]| -> Vec<(String, Value)> {
                let m: serde_json::Map<String, Value> = serde_json::from_slice(bytes).unwrap();
                m.into_iter().filter(|(k, _)| k != "wall_seconds").collect()
            };
            assert_eq!(strip(x), strip(y), "summary differs");
        } else {
            assert!(x == y, "{name} differs");
        }
    }
}

/// Nonsense values are refused before anything runs: exit 2, one line naming the key.
#[test]
fn bad_values_are_refused_naming_the_key() {
    // never written to: a refused value stops the run before it starts
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    for (set, key) in [
        ("aspect_ratio=-1", "aspect_ratio"),
        // a column lower than two mean diameters (R0 = 5 d, H0 = 1.5 d)
        ("half_width_diameters=5 aspect_ratio=0.3", "aspect_ratio"),
        ("aspect_ratio=nan", "aspect_ratio"),
        ("half_width_diameters=1", "half_width_diameters"),
        ("floor_length=0.5", "floor_length"),
        ("friction.wall=2", "friction.wall"),
        ("friction.floor=-0.1", "friction.floor"),
        ("restitution=1", "restitution"),
        (
            "analysis.reference_t_star=[1.0, 0.5]",
            "analysis.reference_t_star",
        ),
        ("analysis.reference_t_star=[]", "analysis.reference_t_star"),
        ("collapse.max_time=0", "collapse.max_time"),
        ("grain.radius_spread=3e-3", "grain.radius_spread"),
        ("aspect_ratio=0.05", "aspect_ratio"),
    ] {
        let mut args = vec!["run", "column-collapse", "--out", out];
        for one in set.split(' ') {
            args.extend(["--set", one]);
        }
        let o = grainlaw(&args);
        assert_eq!(o.status.code(), Some(2), "{set}: {}", text(&o));
        let err = String::from_utf8_lossy(&o.stderr);
        let line = err.lines().rfind(|l| l.starts_with("error:")).unwrap_or("");
        assert!(line.contains(&format!("`{key}`")), "{set}: {err}");
        assert_eq!(
            err.lines().filter(|l| l.starts_with("error:")).count(),
            1,
            "{err}"
        );
    }
}

/// A campaign sweeping the aspect ratio writes `runout.csv` (one row per run, sorted by a,
/// with the runout of each run's summary) and `runout.png`.
#[test]
fn a_campaign_over_the_aspect_ratio_gives_the_runout() {
    let dir = plan_dir(
        "scenario = \"column-collapse\"\n[set]\nhalf_width_diameters = 6.0\nfloor_length = 10.0\n[sweep]\naspect_ratio = [2.0, 0.5]\n",
    );
    let o = campaign(dir.path(), &["plan.toml", "--out", "c", "--jobs", "2"]);
    // a run whose verdict is suspect exits 3: the campaign still collects it
    assert!(
        matches!(o.status.code(), Some(0) | Some(2) | Some(3)),
        "{}",
        text(&o)
    );
    let c = dir.path().join("c");
    let table = std::fs::read_to_string(c.join("runout.csv")).unwrap_or_else(|e| {
        panic!("{e}: {}", text(&o));
    });
    let table = Table::parse(&table);
    let (col, rows) = (|n: &str| table.col(n), &table.rows);
    assert_eq!(rows.len(), 2);
    let a: Vec<f64> = rows.iter().map(|r| r[col("a")].parse().unwrap()).collect();
    assert_eq!(a, vec![0.5, 2.0]);
    for r in rows {
        let run = &r[col("run")];
        let s: Value = serde_json::from_slice(
            &std::fs::read(c.join("runs").join(run).join("summary.json")).unwrap(),
        )
        .unwrap();
        let runout: f64 = r[col("runout_m")].parse().unwrap();
        assert!((runout - f(&s["column"], "runout_m")).abs() <= 1e-12 * runout);
    }
    assert!(c.join("runout.png").is_file());
}
