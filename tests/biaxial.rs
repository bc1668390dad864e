//! The `biaxial` scenario (biperiodic cell): inputs validated (one line naming the key, exit
//! code 2); the stress control reaches the confining pressure and holds the lateral stress;
//! frictionless disks reach the known frictionless critical state; a run stopped and resumed
//! writes the same files, byte for byte, as an uninterrupted one.

mod common;

use common::{assert_same_outputs, grainlaw, run_stopped_and_resumed, stderr};
use std::path::Path;

/// The laws one pressure cannot identify (Mohr–Coulomb needs 3, the critical state 2 as replicas:
/// `grainlaw::scenarios::common::laws`), left out so that a one-pressure plan runs; the
/// stress–dilatancy relation is still tried.
const ONE_PRESSURE: &str = r#"leave_out=["mohr-coulomb", "critical-state"]"#;

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("summary.json")).expect("summary.json"))
        .expect("json")
}

/// `grainlaw run biaxial -q` with each of `sets` as a `--set`, into `out`: a short run's
/// verdict may be refused (exit 3, e.g. no stress–dilatancy relation from so few windows); any
/// other exit fails. Returns its `summary.json`.
fn run_biaxial(sets: &[&str], out: &Path) -> serde_json::Value {
    let mut args = vec!["run", "biaxial"];
    for set in sets {
        args.extend(["--set", set]);
    }
    args.push("-q");
    let o = grainlaw(&args, Some(out));
    assert!(
        matches!(o.status.code(), Some(0) | Some(3)),
        "{}",
        stderr(&o)
    );
    summary(out)
}

fn num(s: &serde_json::Value, key: &str) -> f64 {
    s[key]
        .as_f64()
        .unwrap_or_else(|| panic!("{key} missing: {s}"))
}

/// Each bad value: one `error:` line naming the key, exit code 2, nothing run.
#[test]
fn bad_inputs_are_refused_with_one_line() {
    for (set, key) in [
        ("confining_pressures=[]", "confining_pressures"),
        (
            "confining_pressures=[1000.0, -5.0]",
            "confining_pressures[1]",
        ),
        ("confining_pressures=[0.0]", "confining_pressures[0]"),
        ("preparation=\"medium\"", "preparation"),
        ("inertial_number=0.5", "inertial_number"),
        ("max_axial_strain=0.0", "max_axial_strain"),
        ("critical_strain=0.5", "critical_strain"),
        ("bin_strain=0.2", "bin_strain"),
        ("grains=10", "grains"),
        ("friction.grain_grain=-0.1", "friction.grain_grain"),
        ("compression_time=-1", "compression_time"),
        // checked before the run, not learnt after it: 2 pressures identify no Mohr–Coulomb
        // envelope (3 needed), 1 no critical state from replicas (2 needed)
        (
            "confining_pressures=[1000.0, 4000.0]",
            "confining_pressures",
        ),
        (
            r#"leave_out=["mohr-coulomb", "critical-state", "stress-dilatancy", "mohr-coulomb"]"#,
            "leave_out[3]",
        ),
        (r#"leave_out=["mu-i"]"#, "leave_out[0]"),
    ] {
        let o = grainlaw(&["run", "biaxial", "--set", set], None);
        assert_eq!(o.status.code(), Some(2), "{set}: {}", stderr(&o));
        let err = stderr(&o);
        let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
        assert_eq!(lines.len(), 1, "{set}: {err}");
        assert!(lines[0].contains(key), "{set}: {}", lines[0]);
    }
}

/// 400 frictionless disks (dense: frictionless throughout), p₀ = 1 kPa, axial strain 0.05:
/// the isotropic compression ends within the refusal tolerance of the control (25 %, measured
/// 0.06 %), the lateral stress of the axial compression averages −p₀ within 5 % (measured
/// 0.01 %), the test is quasi-static (I ≤ 10⁻³ with the mean pressure), and the plateau
/// (last 0.03) has the frictionless critical-state friction sin φ_c ≈ 0.1 (2D disks: Azéma &
/// Radjai, Phys. Rev. E 85, 2012; frictionless spheres: Peyneau & Roux, Phys. Rev. E 78, 2008,
/// μ ≈ 0.1) within [0.03, 0.17] for so short a plateau (measured 0.131 ± 0.006; seeds 2 and 3:
/// 0.084, 0.118), and the solid fraction of random close packing of these disks, 0.82–0.86
/// (measured 0.837). With 100 disks and a plateau of 0.01 the critical friction scattered from
/// 0.002 to 0.14 over seeds and solver tolerances (a finite-size fluctuation, not a law).
#[test]
fn stress_control_and_frictionless_critical_state() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f");
    let s = run_biaxial(
        &[
            "grains=400",
            "confining_pressures=[1000.0]",
            ONE_PRESSURE,
            "friction.grain_grain=0.0",
            "max_axial_strain=0.05",
            "critical_strain=0.03",
            "bin_strain=0.0025",
        ],
        &out,
    );
    let comp = num(&s, "p1_compression_stress_error");
    assert!(comp <= 0.25, "compression error {comp}");
    let lat = num(&s, "p1_lateral_stress_error");
    assert!(lat <= 0.05, "lateral error {lat}");
    let i = num(&s, "p1_I");
    assert!(i <= 1e-3, "I = {i}");
    let sc = num(&s, "p1_friction_critical_sin_phi");
    assert!((0.03..=0.17).contains(&sc), "sin φ_c = {sc}");
    let phi = num(&s, "p1_solid_fraction_critical");
    assert!((0.82..=0.86).contains(&phi), "φ_c = {phi}");
    // the history has its units in the header
    let h = std::fs::read_to_string(out.join("history_p1.csv")).unwrap();
    let header = h.lines().find(|l| !l.starts_with('#')).unwrap();
    for col in [
        "t_s",
        "axial_strain",
        "sigma_xx_Pa",
        "D_yy_1_s",
        "p_Pa",
        "sin_phi_mob",
    ] {
        assert!(header.split(',').any(|c| c == col), "{col} in {header}");
    }
}

/// The frictional biaxial test the implicit cell control makes possible (`dem::cell_coupling`;
/// with the explicit law 179 of 190 axial steps stopped at the sweep cap, worst error 10⁻²):
/// 100 disks, μ = 0.5, p₀ = 1 kPa, dense, compressed for 0.3 s (twice the default, so that the
/// jammed part over which the reached stress is averaged is long), then to ε_a = 0.03. The
/// isotropic compression ends at −p₀ within 1 % (measured 0.002 %; 14–29 % under the explicit
/// law), the lateral stress of the axial compression averages −p₀ within 1 %, at most 3 % of its
/// 570 steps end above the tolerance 10⁻⁴ and none above 10× it (measured 0–2 steps, worst
/// 2.0·10⁻⁴), and the mobilised friction has a peak above its value at the end, sin φ_peak in
/// [0.35, 0.6] (measured 0.49, 29.4°; dense disks with μ = 0.5 peak at 25–35°, e.g. Azéma &
/// Radjai, Phys. Rev. E 85, 2012). The explicit law on the same run: 125 unconverged steps,
/// 20 times slower.
#[test]
fn frictional_biaxial_steps_converge_under_the_implicit_control() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mu");
    let s = run_biaxial(
        &[
            "grains=100",
            "confining_pressures=[1000.0]",
            ONE_PRESSURE,
            "max_axial_strain=0.03",
            "critical_strain=0.01",
            "bin_strain=0.0025",
            "compression_time=0.3",
        ],
        &out,
    );
    assert_eq!(s["cell_control"], "implicit");
    let comp = num(&s, "p1_compression_stress_error");
    assert!(comp <= 0.01, "compression error {comp}");
    let lat = num(&s, "p1_lateral_stress_error");
    assert!(lat <= 0.01, "lateral error {lat}");
    let unconverged = num(&s, "solver_unconverged_steps");
    assert!(
        unconverged <= 0.03 * 570.0,
        "{unconverged} unconverged steps"
    );
    let worst = num(&s, "solver_worst_error");
    assert!(worst <= 1e-3, "worst solver error {worst}");
    let peak = num(&s, "p1_friction_peak_sin_phi");
    let end = num(&s, "p1_friction_critical_sin_phi");
    assert!((0.35..=0.6).contains(&peak), "sin φ_peak = {peak}");
    assert!(peak > end, "peak {peak} vs end {end}");
    // The solver sensitivity: 20 axial steps evenly spread (every ⌊steps/20⌋-th) solved again
    // to 1e-8 with the cell, none failing; sin φ and p move by less than the suspect limits
    // (0.005, 2.5 %), so the loaded contacts' proxy is judged against its refusal limit only.
    let steps = num(&s, "window_steps");
    let samples = num(&s, "window_resolved_samples");
    let every = (steps / 20.0).floor().max(1.0);
    assert_eq!(samples, (steps / every).floor(), "{steps} axial steps");
    assert!(samples >= 20.0, "{samples} samples");
    assert_eq!(num(&s, "window_unresolved_samples"), 0.0);
    let dmu = num(&s, "window_resolved_mu_change");
    let dp = num(&s, "window_resolved_pressure_change");
    assert!(dmu > 0.0 && dmu < 0.005, "sin φ moves by {dmu}");
    assert!(dp > 0.0 && dp < 0.025, "p moves by {dp}");
    let reasons = s["verdict_reasons"].to_string();
    assert!(
        !reasons.contains("solver.loaded_error_over_tolerance")
            && !reasons.contains("solver.sensitivity"),
        "{reasons}"
    );
}

/// A run stopped inside the axial compression and resumed writes the same files as an
/// uninterrupted run, `summary.json`'s `wall_seconds` aside: bit-identical results.
#[test]
fn resume_is_bit_identical() {
    let tiny: &[&str] = &[
        "run",
        "biaxial",
        "--set",
        "grains=50",
        "--set",
        "confining_pressures=[1000.0, 2000.0]",
        "--set",
        r#"leave_out=["mohr-coulomb"]"#,
        "--set",
        "compression_time=0.02",
        "--set",
        "max_axial_strain=0.004",
        "--set",
        "critical_strain=0.002",
        "--set",
        "bin_strain=0.001",
        "-q",
    ];
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    // 80 compression steps and 76 axial steps per pressure: stop inside the second pressure's
    // axial compression
    run_stopped_and_resumed(tiny, "260", &a, &b);
    assert!(a.join("history_p2.csv").is_file());
    assert_same_outputs(&a, &b);
}

/// 200 frictionless disks to ε_a = 0.3 (9 s under the implicit cell control; it took about
/// 15 min under the explicit one), the critical state taken over the last 0.2 of axial strain
/// (a frictionless packing reaches it within a few %; the volumetric strain of so small a cell
/// wanders by ± 0.005, which over a plateau of 0.1 alone makes |sin ψ| up to 0.05): sin φ_c =
/// 0.10 ± 0.04 (the frictionless value of 2D disks, Azéma & Radjai 2012; Peyneau & Roux 2008
/// for spheres; measured 0.104–0.110 over builds that differ in rounding) and no dilatancy,
/// |sin ψ_c| ≤ 0.03 (measured 0.008–0.019).
#[test]
fn frictionless_critical_state_long() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("long");
    let s = run_biaxial(
        &[
            "confining_pressures=[1000.0]",
            ONE_PRESSURE,
            "friction.grain_grain=0.0",
            "critical_strain=0.2",
        ],
        &out,
    );
    let sc = num(&s, "p1_friction_critical_sin_phi");
    assert!((sc - 0.10).abs() <= 0.04, "sin φ_c = {sc}");
    let psi = num(&s, "p1_dilatancy_critical_sin_psi");
    assert!(psi.abs() <= 0.03, "sin ψ_c = {psi}");
}

/// A seed nobody tuned for: 50 grains, one pressure, ε_a to 0.06. With the dilatancy taken from
/// differences of bin means, `d/(2 + d)` with `d = −Δε_v/Δε_a`, seed 27 reported a largest
/// sin ψ of 49.8 (a burst of contraction, `2 + d` near 0). From the mean strain-rate tensor over
/// windows of 4 bins, every sin ψ written (summary.json, biaxial.csv, dilatancy.csv) lies in
/// [−1, 1] or is absent, and the largest has a standard error (measured 0.355 ± 0.013).
#[test]
fn a_hidden_seed_never_reports_a_dilatancy_outside_its_range() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s27");
    let s = run_biaxial(
        &[
            "seed=27",
            "grains=50",
            "confining_pressures=[1000.0]",
            ONE_PRESSURE,
            "max_axial_strain=0.06",
            "critical_strain=0.02",
        ],
        &out,
    );
    let in_range = |v: f64| (-1.0..=1.0).contains(&v);
    for key in ["p1_dilatancy_max_sin_psi", "p1_dilatancy_critical_sin_psi"] {
        if let Some(v) = s[key].as_f64() {
            assert!(in_range(v), "{key} = {v}");
        }
    }
    let max = num(&s, "p1_dilatancy_max_sin_psi");
    assert!(max > 0.0, "a dense packing dilates: {max}");
    assert!(num(&s, "p1_dilatancy_max_sin_psi_std_error") > 0.0);
    for (file, cols) in [
        ("biaxial.csv", &["sin_psi_max", "sin_psi_critical"][..]),
        ("dilatancy.csv", &["sin_psi"][..]),
    ] {
        let text = std::fs::read_to_string(out.join(file)).unwrap();
        let mut lines = text.lines().filter(|l| !l.starts_with('#'));
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let mut seen = 0;
        for line in lines {
            let cells: Vec<&str> = line.split(',').collect();
            for c in cols {
                let j = header.iter().position(|h| h == c).unwrap();
                if !cells[j].is_empty() {
                    let v: f64 = cells[j].parse().unwrap();
                    assert!(in_range(v), "{file} {c} = {v}");
                    seen += 1;
                }
            }
        }
        assert!(seen > 0, "{file}: no sin ψ written");
    }
}

/// A plan with one pressure: refused at start (exit 2, one line naming `confining_pressures`,
/// saying what each law needs and how to leave it out), in well under a second, nothing
/// written; `scenarios --show biaxial` states every law's needs.
#[test]
fn too_few_pressures_are_refused_at_start() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("one");
    let t = std::time::Instant::now();
    let o = grainlaw(
        &["run", "biaxial", "--set", "confining_pressures=[1000.0]"],
        Some(&out),
    );
    assert!(t.elapsed().as_secs_f64() < 5.0);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(
        lines[0].contains("key `confining_pressures`")
            && lines[0].contains("mohr-coulomb")
            && lines[0].contains("at least 3")
            && lines[0].contains(r#"leave_out = ["mohr-coulomb"]"#),
        "{err}"
    );
    assert!(!out.exists(), "nothing run, nothing written");
    let o = grainlaw(&["scenarios", "--show", "biaxial"], None);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    for need in [
        "#   mohr-coulomb (",
        "at least 3 confining_pressures",
        "#   critical-state (",
        "at least 2 confining_pressures",
        "#   stress-dilatancy (",
    ] {
        assert!(text.contains(need), "{need}: {text}");
    }
    // what --show prints is a plan that loads (the needs are comments)
    let plan = dir.path().join("plan.toml");
    std::fs::write(&plan, text.as_bytes()).unwrap();
    let o = grainlaw(
        &["run", plan.to_str().unwrap(), "--set", "grains=10"],
        Some(&out),
    );
    assert!(stderr(&o).contains("key `grains`"), "{}", stderr(&o));
}
