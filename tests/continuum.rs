//! `grainlaw continuum`: the law's conversion into a Gerris case against hand calculations, the
//! interface reader on a recorded Gerris snapshot, Bagnold's profile from Gerris at level 6,
//! the column collapse against Staron's contact dynamics, and bad input (`docs/continuum.md`).
//! The tests that run Gerris skip, saying so, when `gerris2D` is not installed (CI installs it).

mod common;

use common::grainlaw_in as grainlaw;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use grainlaw::continuum::gerris;
use grainlaw::continuum::gfs::{ColumnCase, ReferenceInstant};
use grainlaw::continuum::rheology::{load_continuum_law, GerrisRheology, LightPhase};
use grainlaw::continuum::snapshot::{front, Snapshot};
use grainlaw::continuum::{inclined_plane, InclinedPlan};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/continuum")
        .join(name)
}

/// True when gerris2D can be run; otherwise prints why the calling test is skipped.
fn gerris_or_skip(test: &str) -> bool {
    let ok = gerris::available(Path::new(gerris::DEFAULT_GERRIS));
    if !ok {
        eprintln!("{test}: SKIPPED: gerris2D is not installed (apt-get install gerris)");
    }
    ok
}

/// The number written right after `prefix` in `text` (up to a delimiter).
fn number_after(text: &str, prefix: &str) -> f64 {
    let at = text
        .find(prefix)
        .unwrap_or_else(|| panic!("`{prefix}` not in the case"))
        + prefix.len();
    let rest = &text[at..];
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-' || c == '+'))
        .unwrap_or(rest.len());
    rest[..end].parse().unwrap()
}

/// The C program `src` compiled (`-O0`, with the maths library) in a temporary directory and
/// run: what it prints; `None`, saying that `what` is skipped, without a C compiler.
fn compile_and_run(what: &str, src: &str) -> Option<String> {
    let Some(cc) = ["cc", "gcc", "clang"]
        .into_iter()
        .find(|c| Command::new(c).arg("--version").output().is_ok())
    else {
        eprintln!("{what}: SKIPPED: no C compiler");
        return None;
    };
    let dir = tempfile::tempdir().unwrap();
    let (c, exe) = (dir.path().join("prog.c"), dir.path().join("prog"));
    std::fs::write(&c, src).unwrap();
    let out = Command::new(cc)
        .arg(&c)
        .arg("-O0")
        .arg("-o")
        .arg(&exe)
        .arg("-lm")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(String::from_utf8(Command::new(&exe).output().unwrap().stdout).unwrap())
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The simple-shear law (μ = μ_s + b I, d = 3.016 mm, ρ_s = 2500) in a column of R₀ = 0.1 m at
/// φ = 0.8: the case's constants against hand calculations, and its compiled viscosity against
/// `η = μ(I) P/(√2 D2)` clamped, with `I = √2 D2 D/√(φ P)`.
#[test]
fn gfs_writer_converts_the_law_and_the_geometry() {
    let law = load_continuum_law(&fixture("simple_shear_mu_i_law.json")).unwrap();
    let (mu_s, b) = (law.parameter("mu_s").unwrap(), law.parameter("b").unwrap());
    let d = 0.0030160438603066696; // the law's d (m)
    let r = GerrisRheology::new(law, "law.json", 0.1, 9.81, 0.8, 10.0).unwrap();
    // units: pressure φ ρ_s g R0 = 0.8·2500·9.81·0.1 = 1962 Pa; time √(0.1/9.81) = 0.100964 s;
    // viscosity 2000 √(9.81·0.1³) = 198.0909 Pa s; D = d/R0 = 0.030160; η_min = D^1.5 = 0.0052379
    assert!(rel(r.units.pressure_pa(), 1962.0) < 1e-14);
    assert!(rel(r.units.time_s(), 0.100_963_755_4) < 1e-9);
    assert!(rel(r.units.viscosity_pa_s(), 198.090_888_4) < 1e-9);
    assert!(rel(r.grain_diameter(), 0.030_160_438_603_066_7) < 1e-14);
    assert!(rel(r.regularisation.eta_min, 0.005_237_891_274_8) < 1e-10);
    // I_Gerris = √φ I: the law's I of I_Gerris = 0.4 is 0.4/√0.8
    assert!(rel(r.law_inertial_number(0.4), 0.447_213_595_5) < 1e-10);
    let case = ColumnCase {
        rheology: r.clone(),
        light: LightPhase::default(),
        aspect_ratio: 6.26,
        domain: 16.0,
        level: 8,
        end: 4.0 * 6.26f64.sqrt(),
        history_interval: 0.02 * 6.26f64.sqrt(),
        references: vec![ReferenceInstant {
            label: "t0.66".into(),
            time: 0.66 * 6.26f64.sqrt(),
        }],
        comments: vec!["test".into()],
    };
    assert_eq!(case.cell_size(), 0.0625);
    let gfs = case.to_gfs().unwrap();
    assert!(
        rel(number_after(&gfs, "sqrt(2.)*D2*"), d / 0.1) < 1e-15,
        "{gfs}"
    );
    assert!(gfs.contains("/sqrt(0.8*P))"));
    assert!(
        gfs.contains(&format!("({mu_s:?} + ({b:?} * gl_I))")),
        "{gfs}"
    );
    // t = t* √a, √6.26 = 2.50199920: the end at t* = 4 is 10.00799680, t* = 0.66 is 1.65131947
    assert!(rel(number_after(&gfs, "Time { end = "), 10.007_996_802_557_443) < 1e-12);
    assert!(
        rel(
            number_after(&gfs, "OutputSimulation { start = "),
            1.651_319_472_4
        ) < 1e-9
    );
    assert!(gfs.contains("InitFraction T (union(6.26 - y, 1. - x))"));
    assert!(gfs.contains("PhysicalParams { L = 16.0 }"));
    assert!(gfs.contains("maxlevel = 8"));
    assert!(gfs.contains("alpha = 1./(T + 0.001*(1. - T))"));
    // the light phase's hydrostatic pressure at the top, -ρ_light/ρ_b · L
    assert!(gfs.contains("BcDirichlet P (-0.016)"));
    assert!(gfs.contains("return 1./(T/gl_eta + (1. - T)/0.0001);"));

    // the viscosity function itself, compiled
    let body = r.source_viscosity_c(Some(&LightPhase::default())).unwrap();
    let points: [(f64, f64, f64); 7] = [
        (1.0, 0.5, 1.0),  // inside the bounds
        (3.0, 0.01, 1.0), // at rest: capped at 10
        (0.01, 5.0, 1.0), // little confinement: the floor D^1.5
        (-1.0, 1.0, 1.0), // P ≤ 0: the floor
        (2.0, 0.0, 1.0),  // D2 = 0: the cap
        (1.0, 0.5, 0.0),  // light phase
        (1.0, 0.5, 0.3),  // mixed cell
    ];
    let src = format!(
        "#include <math.h>\n#include <stdio.h>\n#define MIN(a,b) ((a) < (b) ? (a) : (b))\n#define MAX(a,b) ((a) > (b) ? (a) : (b))\nstatic double visc(double P, double D2, double T) {body}\nint main(void) {{\n{}  return 0;\n}}\n",
        points
            .iter()
            .map(|(p, d2, t)| format!("  printf(\"%.17g\\n\", visc({p:?}, {d2:?}, {t:?}));\n"))
            .collect::<String>()
    );
    let Some(printed) = compile_and_run(
        "gfs_writer_converts_the_law_and_the_geometry: compiled check",
        &src,
    ) else {
        return;
    };
    let (lo, hi) = (r.regularisation.eta_min, r.regularisation.eta_max);
    for ((p, d2, t), line) in points.iter().zip(printed.lines()) {
        let eta = if *p <= 0.0 {
            lo
        } else if *d2 > 0.0 {
            let i = 2f64.sqrt() * d2 * (d / 0.1) / (0.8 * p).sqrt();
            (r.mu(i) * p / (2f64.sqrt() * d2)).clamp(lo, hi)
        } else {
            hi
        };
        let want = 1.0 / (t / eta + (1.0 - t) / 1e-4);
        let got: f64 = line.parse().unwrap();
        assert!(
            rel(got, want) < 1e-12,
            "P {p} D2 {d2} T {t}: C {got}, Rust {want}"
        );
    }
}

/// The reader on a snapshot Gerris wrote (fixture `gerris/column-level6-t0.95.txt`, level 6 in
/// a domain of 16 R0, cells of 0.25): every cell with grains on the finest grid, the grains'
/// area the column's 6.26 within 1 % (VOF), the volume heights against Gerris' own
/// reconstructed interface (within a quarter cell where a column holds at most two interface
/// cells, and never above its top by more than an eighth), and the front by hand.
#[test]
fn interface_reader_on_a_recorded_gerris_snapshot() {
    let path = fixture("gerris/column-level6-t0.95.txt");
    let s = Snapshot::read(&path).unwrap();
    assert!(
        rel(s.time / 6.26f64.sqrt(), 0.95) < 1e-5,
        "t* {}",
        s.time / 6.26f64.sqrt()
    );
    assert_eq!(s.cells.len(), 208);
    let cell = 0.25;
    let prof = s.height_profile(cell, "fixture").unwrap();
    let area: f64 = prof.iter().map(|p| p.1 * cell).sum();
    assert!((area - s.grain_area(cell)).abs() < 1e-12);
    assert!(rel(area, 6.26) < 0.01, "area {area}");
    for (i, &(x, h)) in prof.iter().enumerate() {
        let iface: Vec<f64> = s
            .cells
            .iter()
            .filter(|c| (c.x - x).abs() < 1e-9 && c.interface_y.is_finite() && c.fraction < 1.0)
            .map(|c| c.interface_y)
            .collect();
        let top = iface.iter().copied().fold(f64::NAN, f64::max);
        assert!(
            h <= top + cell / 8.0,
            "column {i}: h {h} above the interface {top}"
        );
        if iface.len() <= 2 {
            assert!(
                (h - top).abs() <= cell / 4.0,
                "column {i}: h {h}, interface {top}"
            );
        }
    }
    // threshold max(d, cell) = 0.25: the last column above it is x = 2.875 (h 0.334), its face
    // 3.0, advanced by 0.25 · h(3.125)/0.25 = 0.24650 (the next column's volume height)
    let h12 = prof[12].1;
    assert!((h12 - 0.246_5).abs() < 1e-4, "{h12}");
    let xf = front(&prof, cell, cell).unwrap();
    assert!((xf - (3.0 + h12)).abs() < 1e-12, "{xf}");
    // Staron's contact dynamics: 3.245 R0 at t* = 0.95 (fixture staron2005)
    assert!(rel(xf, 3.245) < 0.02, "{xf}");
}

fn bagnold_case(law: &str, slope_deg: f64, phi: f64, out: &Path) -> (f64, usize) {
    let mut plan = InclinedPlan::new(fixture(law), out.to_path_buf());
    plan.slope_deg = Some(slope_deg);
    plan.inputs.packing_fraction = Some(phi);
    plan.inputs.level = 6;
    let o = inclined_plane(&plan).unwrap();
    println!("{}", o.lines.join("\n"));
    assert!(o.verdict.passes(), "{:?}", o.verdict.lines());
    (o.max_relative_error, o.gerris_profile.len())
}

/// Steady flow down a slope at level 6 (64 cells across the layer): Gerris' velocity profile
/// against the analytic `u ∝ H^{3/2} − (H − z)^{3/2}` of the same law, within 0.5 % of the
/// surface velocity everywhere (Gerris' own Bagnold test has 0.12 % at level 6), for the linear
/// law of the simple-shear run (26°, I = 0.21) and the saturating law of Lagrée et al.
/// (24.6°, I = 0.39).
#[test]
fn bagnold_profile_from_gerris_at_level_6() {
    if !gerris_or_skip("bagnold_profile_from_gerris_at_level_6") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (err, n) = bagnold_case(
        "simple_shear_mu_i_law.json",
        26.0,
        0.75,
        &dir.path().join("a"),
    );
    assert_eq!(n, 64);
    assert!(
        err < 5e-3,
        "linear law: largest error {err} of the surface velocity"
    );
    let (err, _) = bagnold_case("lagree2011_mu_i_law.json", 24.6, 1.0, &dir.path().join("b"));
    assert!(
        err < 5e-3,
        "saturating law: largest error {err} of the surface velocity"
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("b/summary.json")).unwrap())
            .unwrap();
    // I(θ) = I₀ (tan θ − μ_s)/(μ₂ − tan θ) = 0.4 (0.457836 − 0.32)/(0.6 − 0.457836) = 0.387821
    assert!(rel(s["inertial_number"].as_f64().unwrap(), 0.387_821) < 1e-5);
    assert!(dir.path().join("b/velocity.png").is_file());
    assert!(dir.path().join("b/gerris/inclined.gfs").is_file());
}

/// `grainlaw continuum column-collapse` at level 7 with the fixtures `law` and `dem` (and
/// `extra` arguments) into `cwd/col`, which must succeed: the rows of its `comparison.json`.
fn column_comparison(law: &str, dem: &str, extra: &[&str], cwd: &Path) -> Vec<serde_json::Value> {
    let (law, dem) = (fixture(law), fixture(dem));
    let mut args = vec![
        "continuum",
        "column-collapse",
        "--law",
        law.to_str().unwrap(),
        "--dem",
        dem.to_str().unwrap(),
        "--level",
        "7",
        "--out",
        "col",
    ];
    args.extend_from_slice(extra);
    let out = grainlaw(&args, cwd);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(cwd.join("col/comparison.json")).unwrap())
            .unwrap();
    c["rows"].as_array().unwrap().clone()
}

/// The column of Lagrée et al. (a = 6.26, their law, φ = 1 as in their I) at level 7 against
/// Staron's contact dynamics: the fronts within 12 % at the five reference instants (measured:
/// 7 % at worst at level 7, 9.5 % at level 9, docs/continuum.md §8), mass kept, the files
/// written.
#[test]
fn column_collapse_against_staron_at_level_7() {
    if !gerris_or_skip("column_collapse_against_staron_at_level_7") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let rows = column_comparison(
        "lagree2011_mu_i_law.json",
        "staron2005",
        &["--packing-fraction", "1"],
        dir.path(),
    );
    let col = dir.path().join("col");
    for f in [
        "front.csv",
        "profiles.csv",
        "comparison.csv",
        "comparison.json",
        "front.png",
        "profiles.png",
        "summary.json",
        "gerris/column.gfs",
    ] {
        assert!(col.join(f).is_file(), "{f} missing");
    }
    assert_eq!(rows.len(), 5);
    for r in rows {
        let d = r["x_f_relative_difference"].as_f64().unwrap();
        assert!(d.abs() < 0.12, "{}: {d}", r["label"]);
    }
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(col.join("summary.json")).unwrap()).unwrap();
    assert!(s["gerris"]["grain_area_change"].as_f64().unwrap().abs() < 0.02);
    assert_eq!(s["verdict"], "ok");
}

/// Issue 36's loop at CI size: the law calibrated on the column-collapse scenario's own grains
/// (fixture `column_grains_mu_i_linear_law.json`, the campaign
/// `datasets/campaigns/column-collapse-law.toml`) in Gerris at level 7 against the DEM
/// `column-collapse` run at its defaults (fixture `column-collapse-dem`). Measured
/// (docs/continuum.md §8): the fronts 2–7 % behind the DEM's up to t* = 1.52 (target 15 %), and the
/// run-out short of the grains' by about 20 % (the thin tongue of the DEM deposit and the law, §8):
/// asserted as within 10 % up to t* = 1.52 and between 10 % and 30 % short at rest.
#[test]
fn column_collapse_with_the_column_grains_law_against_the_dem() {
    if !gerris_or_skip("column_collapse_with_the_column_grains_law_against_the_dem") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let rows = column_comparison(
        "column_grains_mu_i_linear_law.json",
        "column-collapse-dem",
        &[],
        dir.path(),
    );
    assert_eq!(rows.len(), 6, "five instants and rest");
    for r in rows {
        let t = r["t_star"].as_f64().unwrap();
        let d = r["x_f_relative_difference"].as_f64().unwrap();
        if t <= 1.52 + 1e-9 {
            assert!(d.abs() < 0.10, "{}: {d}", r["label"]);
        }
        if r["label"] == "rest" {
            assert!((-0.30..-0.10).contains(&d), "rest: {d}");
        }
    }
}

/// A law whose calibrated range the run leaves by far: a warning naming the largest I, where
/// and when, and how far; the verdict suspect (exit 3) unless --allow-suspect.
#[test]
fn leaving_the_validity_range_is_suspect() {
    if !gerris_or_skip("leaving_the_validity_range_is_suspect") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut law: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(fixture("simple_shear_mu_i_law.json")).unwrap(),
    )
    .unwrap();
    law["validity"][0]["max"] = serde_json::json!(0.01);
    std::fs::write(dir.path().join("narrow.json"), law.to_string()).unwrap();
    let args = [
        "continuum",
        "column-collapse",
        "--law",
        "narrow.json",
        "--packing-fraction",
        "0.8",
        "--level",
        "7",
        "--t-end",
        "1",
        "--out",
        "col",
    ];
    let out = grainlaw(&args, dir.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(stderr.contains("warning: the run's inertial number leaves the law's calibrated range (I ≤ 0.010): it reaches I ="), "{stderr}");
    assert!(
        stderr.contains("× the limit) at x =") && stderr.contains("t* ="),
        "{stderr}"
    );
    assert!(
        stderr.contains("continuum.validity_range (suspect)"),
        "{stderr}"
    );
    let mut allowed = args.to_vec();
    allowed.push("--allow-suspect");
    let out = grainlaw(&allowed, dir.path());
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// One line on stderr starting with `error:` and holding every needle, exit `code`.
fn check_error(out: &Output, code: i32, needles: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(out.status.code(), Some(code), "{stderr}");
    assert_eq!(errors.len(), 1, "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for n in needles {
        assert!(errors[0].contains(n), "`{n}` not in `{}`", errors[0]);
    }
}

#[test]
fn bad_input_is_one_line_and_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    let mu = fixture("simple_shear_mu_i_law.json");
    let mu = mu.to_str().unwrap();
    let phi_law = fixture("simple_shear_phi_i_law.json");
    // a law that is not μ(I)
    let out = grainlaw(
        &[
            "continuum",
            "column-collapse",
            "--law",
            phi_law.to_str().unwrap(),
            "--packing-fraction",
            "0.8",
        ],
        cwd,
    );
    check_error(
        &out,
        2,
        &["simple_shear_phi_i_law.json", "'phi-i' is not a μ(I) law"],
    );
    // a schema-1 μ(I) law: no d, no rho_s
    let v1 = r#"{"schema_version": 1, "law": "mu-i",
      "parameters": [{"name": "mu_s", "unit": "1", "value": 0.3, "std_error": 0.01, "ci_low": 0.28, "ci_high": 0.32},
                     {"name": "mu_2", "unit": "1", "value": 0.6, "std_error": 0.01, "ci_low": 0.58, "ci_high": 0.62},
                     {"name": "I_0", "unit": "1", "value": 0.3, "std_error": 0.01, "ci_low": 0.28, "ci_high": 0.32}],
      "constants": [], "validity": [{"variable": "I", "unit": "1", "min": 0.01, "max": 0.5}],
      "fit": {"n": 10, "dof": 7, "r_squared": 0.99, "aic": 0.0, "bic": 0.0, "confidence": 0.95},
      "provenance": {"scenario": "user-csv", "seed": null, "grainlaw_version": "0.1.0"}}"#;
    std::fs::write(cwd.join("v1.json"), v1).unwrap();
    let out = grainlaw(
        &[
            "continuum",
            "column-collapse",
            "--law",
            "v1.json",
            "--packing-fraction",
            "0.8",
        ],
        cwd,
    );
    check_error(&out, 2, &["v1.json", "lacks the constant 'd'"]);
    // no packing fraction and no DEM
    let out = grainlaw(&["continuum", "column-collapse", "--law", mu], cwd);
    check_error(&out, 2, &["--packing-fraction or --dem"]);
    // another solver
    let out = grainlaw(
        &[
            "continuum",
            "column-collapse",
            "--law",
            mu,
            "--solver",
            "openfoam",
        ],
        cwd,
    );
    check_error(&out, 2, &["--solver openfoam"]);
    // a DEM directory of another run
    std::fs::create_dir_all(cwd.join("notdem")).unwrap();
    std::fs::write(
        cwd.join("notdem/summary.json"),
        r#"{"scenario": "janssen"}"#,
    )
    .unwrap();
    let out = grainlaw(
        &[
            "continuum",
            "column-collapse",
            "--law",
            mu,
            "--dem",
            "notdem",
        ],
        cwd,
    );
    check_error(&out, 2, &["summary.json", "no `column` object"]);
    // a slope on which the law has no steady flow (tan 10° < μ_s)
    let out = grainlaw(
        &[
            "continuum",
            "inclined-plane",
            "--law",
            mu,
            "--slope-deg",
            "10",
            "--packing-fraction",
            "0.8",
        ],
        cwd,
    );
    check_error(&out, 2, &["no steady flow on a 10° slope"]);
    assert!(!cwd
        .join("grainlaw-out/continuum-column-collapse/summary.json")
        .exists());
    // never into a scenario run's directory (its files would be replaced)
    std::fs::create_dir_all(cwd.join("flow")).unwrap();
    std::fs::write(
        cwd.join("flow/scenario.toml"),
        "scenario = \"inclined-flow\"\n",
    )
    .unwrap();
    let out = grainlaw(
        &[
            "continuum",
            "inclined-plane",
            "--law",
            mu,
            "--slope-deg",
            "26",
            "--packing-fraction",
            "0.8",
            "--out",
            "flow",
        ],
        cwd,
    );
    check_error(&out, 2, &["--out flow", "`inclined-flow` run"]);
}

/// Gerris missing, or failing: exit 3, one line quoting its stderr's last lines, the case left
/// in place to rerun by hand.
#[test]
fn gerris_missing_or_failing_exits_3_and_keeps_the_case() {
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    let mu = fixture("simple_shear_mu_i_law.json");
    let base = [
        "continuum",
        "column-collapse",
        "--law",
        mu.to_str().unwrap(),
        "--packing-fraction",
        "0.8",
        "--level",
        "6",
    ];
    let mut args = base.to_vec();
    args.extend(["--out", "missing", "--gerris", "/nonexistent/gerris2D"]);
    let out = grainlaw(&args, cwd);
    check_error(
        &out,
        3,
        &[
            "/nonexistent/gerris2D: not found",
            "apt-get install gerris",
            "the case is left in missing/gerris",
        ],
    );
    assert!(cwd.join("missing/gerris/column.gfs").is_file());
    assert!(!cwd.join("missing/summary.json").exists());

    let fake = cwd.join("fake-gerris.sh");
    std::fs::write(
        &fake,
        "#!/bin/sh\necho 'step: 10 t: 0.1' >&2\necho 'Gfs-MESSAGE **: floating-point exception in user-defined function' >&2\necho 'gerris: file column.gfs is not a valid simulation file' >&2\nexit 1\n",
    )
    .unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let mut args = base.to_vec();
    let fake = fake.to_str().unwrap().to_string();
    args.extend(["--out", "failing", "--gerris", &fake]);
    let out = grainlaw(&args, cwd);
    check_error(
        &out,
        3,
        &[
            "failed (exit status: 1)",
            "floating-point exception",
            "is not a valid simulation file",
            "rerun it there with",
        ],
    );
    assert!(cwd.join("failing/gerris/column.gfs").is_file());
    assert!(cwd.join("failing/gerris/gerris.log").is_file());
}

/// The code block after `marker` in docs/continuum.md (between its ``` fences).
fn doc_block(marker: &str) -> String {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/continuum.md"))
            .unwrap();
    let at = doc
        .find(marker)
        .unwrap_or_else(|| panic!("{marker} not in docs/continuum.md"));
    let rest = &doc[at..];
    let start = rest.find("```").unwrap();
    let body = &rest[start..];
    let body = &body[body.find('\n').unwrap() + 1..];
    body[..body.find("```").unwrap()].to_string()
}

/// docs/continuum.md §9's worked reading in C: the block is what grainlaw writes for the law
/// (`formula_in_c`), and compiled it gives the Rust evaluation of the law to 1e-12.
#[test]
fn worked_reading_in_c() {
    let block = doc_block("<!-- worked-c");
    let law = identify::CalibratedLaw::load(&fixture("lagree2011_mu_i_law.json")).unwrap();
    let expr = law.formula_in_c("I").unwrap();
    assert!(
        block.contains(&format!("return {expr};")),
        "the doc's block is not `{expr}`:\n{block}"
    );
    let is: Vec<f64> = (0..=12)
        .map(|k| 1e-3 * 2000f64.powf(k as f64 / 12.0))
        .collect();
    let src = format!(
        "#include <stdio.h>\n{block}\nint main(void) {{\n{}  return 0;\n}}\n",
        is.iter()
            .map(|i| format!("  printf(\"%.17g\\n\", mu_of_I({i:?}));\n"))
            .collect::<String>()
    );
    let Some(printed) = compile_and_run("worked_reading_in_c", &src) else {
        return;
    };
    let want = law.evaluate(&is).unwrap();
    for ((i, line), w) in is.iter().zip(printed.lines()).zip(want) {
        let got: f64 = line.parse().unwrap();
        assert!(rel(got, w) < 1e-12, "I = {i}: C {got}, Rust {w}");
    }
}
