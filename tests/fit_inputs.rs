//! What `grainlaw fit LAW FILE` reads (docs/formats.md §3.2), through the binary:
//!
//! - round trips: every CSV a scenario writes that the docs call a fit input (`janssen`'s
//!   `wall_profile.csv`, `shear-cell`'s `rheology.csv`) is fitted as written by each law it is
//!   an input of: exit 0 (the law is written) or the documented refusal 3, never bad input (2);
//! - the input grammar, one table row per case: comments that are not `# key = value` metadata
//!   are ignored, an unknown key is refused with the keys the law reads, unit-suffixed headers in
//!   kPa, MPa and mm are converted (the fitted values are those of the same data in SI) and
//!   other units refused with the expected header, semicolon- and tab-delimited files get a hint
//!   about the delimiter, three triaxial points suffice with `# cohesion = 0`, Windows line
//!   endings and a UTF-8 byte-order mark (spreadsheet exports) are read.

mod common;

use std::fmt::Write as _;
use std::path::Path;
use std::process::Output;

use common::stderr;

/// `grainlaw ARGS` run in `dir` ([`common::grainlaw_in`]).
fn grainlaw(dir: &Path, args: &[&str]) -> Output {
    common::grainlaw_in(args, dir)
}

/// Runs `grainlaw fit LAW FILE --out law.json` in `dir`: exit code, stdout + stderr, and the
/// fitted parameters by name when the law was written.
fn fit(dir: &Path, law: &str, file: &str) -> (i32, String, Vec<(String, f64)>) {
    let out = dir.join(format!("{law}.law.json"));
    let _ = std::fs::remove_file(&out);
    let o = grainlaw(dir, &["fit", law, file, "--out", out.to_str().unwrap()]);
    let code = o.status.code().unwrap_or(-1);
    let text = format!("{}{}", String::from_utf8_lossy(&o.stdout), stderr(&o));
    let params = if code == 0 {
        common::law_parameters(&out)
    } else {
        assert!(
            !out.exists(),
            "{law} {file}: exit {code} but a law was written"
        );
        Vec::new()
    };
    (code, text, params)
}

/// The CSVs of two short runs, each fitted by every law the docs name for it.
#[test]
fn every_fit_input_a_scenario_writes_is_fitted_as_written() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let runs: [(&str, &[&str], &str, &[&str]); 2] = [
        (
            "janssen",
            &["--set", "grains=100"],
            "wall_profile.csv",
            &["janssen", "janssen-kmu"],
        ),
        (
            "shear-cell",
            &[
                "--set",
                "grains=80",
                "--set",
                "cell_length_diameters=10",
                "--set",
                "inertial_numbers=[0.02, 0.04, 0.08, 0.15, 0.3]",
                "--set",
                "strain=1",
                "--set",
                "average_strain=0.5",
            ],
            "rheology.csv",
            &["mu-i", "mu-i-linear", "phi-i"],
        ),
    ];
    for (scenario, sets, file, laws) in runs {
        let out = d.join(scenario);
        let mut args = vec!["run", scenario, "-q", "--out", out.to_str().unwrap()];
        args.extend_from_slice(sets);
        let o = grainlaw(d, &args);
        // 3: the run's verdict refused a result (short runs often are); its CSVs are written
        assert!(
            matches!(o.status.code(), Some(0) | Some(3)),
            "{scenario}: {}",
            stderr(&o)
        );
        let text = std::fs::read_to_string(out.join(file)).unwrap();
        assert!(
            text.contains(&format!("grainlaw fit {} {file}", laws[0])),
            "{file} tells how to fit it"
        );
        for law in laws {
            let (code, msg, params) = fit(&out, law, file);
            assert!(
                code == 0 || code == 3,
                "{scenario}/{file} with {law}: exit {code}: {msg}"
            );
            if code == 3 {
                // the refusals of docs/cli.md: refused, not identifiable, a parameter at its
                // physical bound
                assert!(
                    msg.contains("refused")
                        || msg.contains("not identifiable")
                        || msg.contains("ended at its"),
                    "{msg}"
                );
            } else {
                assert!(!params.is_empty() && params.iter().all(|(_, v)| v.is_finite()));
            }
        }
    }
}

/// `z, σ_v, σ_h` of Janssen's law with `K`, `μ_w` (width 0.03 m, ρ_b g = 1600·9.81), at 12
/// depths, `z` divided by `z_unit` and the stresses by `p_unit` (so that a header in mm gets
/// `z_unit = 1e-3`).
fn janssen_rows(z_unit: f64, p_unit: f64, sep: &str, end: &str) -> String {
    let (k, mu_w, w, rg) = (0.6, 0.2, 0.03, 1600.0 * 9.81);
    let a = 2.0 * k * mu_w / w;
    let mut s = String::new();
    for i in 1..=12 {
        let z = 0.005 * i as f64;
        let sv = rg / a * (1.0 - (-a * z).exp());
        write!(
            s,
            "{}{sep}{}{sep}{}{end}",
            z / z_unit,
            sv / p_unit,
            k * sv / p_unit
        )
        .unwrap();
    }
    s
}

const JANSSEN_META: &str =
    "# width_m = 0.03\n# bulk_density_kg_m3 = 1600\n# wall_friction = 0.25\n";
const GRAIN: &str = "# grain_diameter_m = 0.002\n# grain_density_kg_m3 = 2500\n";

/// `I, mu` rows of the GDR MiDi μ(I) at 20 log-spaced `I` in [10⁻³, 1].
fn mu_rows() -> String {
    (0..20)
        .map(|k| {
            let i = 1e-3 * 1000f64.powf(k as f64 / 19.0);
            format!("{i},{}\n", 0.38 + 0.26 * i / (i + 0.279))
        })
        .collect()
}

struct Case {
    what: &'static str,
    law: &'static str,
    text: String,
    code: i32,
    fragments: &'static [&'static str],
    /// Parameters the law must hold, `(name, value, absolute tolerance)`.
    truth: &'static [(&'static str, f64, f64)],
}

fn cases() -> Vec<Case> {
    let janssen_truth: &[(&str, f64, f64)] = &[("K", 0.6, 1e-6), ("mu_w", 0.2, 1e-6)];
    vec![
        Case {
            what: "comments that are not metadata, some holding '=', are ignored",
            law: "mu-i",
            text: format!(
                "# steady shear (I, mu = |sigma_xy|/P)\n# note: mu_s = 0.38 here\n# K = 0.6 at the bottom\n{GRAIN}#\nI,mu\n{}",
                mu_rows()
            ),
            code: 0,
            fragments: &["mu-i fitted to "],
            truth: &[("mu_s", 0.38, 1e-6), ("I_0", 0.279, 1e-5)],
        },
        Case {
            what: "a point_verdict column: only its rows with 0 are fitted, the others counted",
            law: "mu-i",
            text: format!(
                "{GRAIN}I,mu,point_verdict\n{}0.01,5.0,1\n0.1,-2.0,2\n0.5,9.0,1\n",
                mu_rows().replace('\n', ",0\n")
            ),
            code: 0,
            fragments: &["3 rows left out: their point_verdict is not 0"],
            truth: &[("mu_s", 0.38, 1e-6), ("I_0", 0.279, 1e-5)],
        },
        Case {
            what: "a point_verdict column where every row failed: nothing is fitted",
            law: "mu-i",
            text: format!("{GRAIN}I,mu,point_verdict\n{}", mu_rows().replace('\n', ",2\n")),
            code: 3,
            fragments: &["all 20 rows of ", " have point_verdict ≠ 0 (each failed its run's checks)"],
            truth: &[],
        },
        Case {
            what: "an unknown metadata key, refused with the keys the law reads",
            law: "mu-i",
            text: format!("{GRAIN}# colour = 3\nI,mu\n{}", mu_rows()),
            code: 2,
            fragments: &[
                ":3: unknown metadata key 'colour' for mu-i (known keys: grain_diameter_m, grain_density_kg_m3)",
            ],
            truth: &[],
        },
        Case {
            what: "a metadata key the law reads, with a value that is not a number",
            law: "janssen",
            text: format!(
                "# width_m = wide\n# bulk_density_kg_m3 = 1600\n# wall_friction = 0.25\nz_m,sigma_v_Pa,sigma_h_Pa\n{}",
                janssen_rows(1.0, 1.0, ",", "\n")
            ),
            code: 2,
            fragments: &["line 1: metadata 'width_m' = 'wide' is not a number"],
            truth: &[],
        },
        Case {
            what: "depth in mm, stresses in kPa, converted",
            law: "janssen",
            text: format!(
                "{JANSSEN_META}z_mm,sigma_v_kPa,sigma_h_kPa\n{}",
                janssen_rows(1e-3, 1e3, ",", "\n")
            ),
            code: 0,
            fragments: &["janssen fitted to "],
            truth: janssen_truth,
        },
        Case {
            what: "stresses in MPa, mixed with a column in Pa",
            law: "janssen",
            text: format!(
                "{JANSSEN_META}z_m,sigma_v_MPa,sigma_h_Pa\n{}",
                janssen_rows(1.0, 1.0, ",", "\n")
                    .lines()
                    .map(|l| {
                        let c: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
                        format!("{},{},{}\n", c[0], c[1] / 1e6, c[2])
                    })
                    .collect::<String>()
            ),
            code: 0,
            fragments: &["janssen fitted to "],
            truth: janssen_truth,
        },
        Case {
            what: "a depth in a unit that is not read, refused with the expected header",
            law: "janssen",
            text: format!(
                "{JANSSEN_META}z_cm,sigma_v_Pa,sigma_h_Pa\n{}",
                janssen_rows(1e-2, 1.0, ",", "\n")
            ),
            code: 2,
            fragments: &["missing column 'z_m'", "name it 'z_m' (or z_mm, converted)"],
            truth: &[],
        },
        Case {
            what: "a stress in psi, refused with the expected headers",
            law: "janssen",
            text: format!(
                "{JANSSEN_META}z_m,sigma_v_psi,sigma_h_Pa\n{}",
                janssen_rows(1.0, 6894.76, ",", "\n")
            ),
            code: 2,
            fragments: &["column 'sigma_v_psi' is in a unit grainlaw does not read: name it 'sigma_v_Pa' (or sigma_v_kPa, sigma_v_MPa, converted)"],
            truth: &[],
        },
        Case {
            what: "a depth column under another name, refused naming the column expected",
            law: "janssen",
            text: format!(
                "{JANSSEN_META}depth_mm,sigma_v_Pa,sigma_h_Pa\n{}",
                janssen_rows(1e-3, 1.0, ",", "\n")
            ),
            code: 2,
            fragments: &["missing column 'z_m'", "depth_mm"],
            truth: &[],
        },
        Case {
            what: "a semicolon-delimited file with decimal commas",
            law: "janssen",
            text: format!(
                "{JANSSEN_META}z_m;sigma_v_Pa;sigma_h_Pa\n{}",
                janssen_rows(1.0, 1.0, ";", "\n").replace('.', ",")
            ),
            code: 2,
            fragments: &[":4: the header is one field", "semicolon-delimited", "decimal commas by points"],
            truth: &[],
        },
        Case {
            what: "a tab-delimited file",
            law: "janssen",
            text: format!(
                "{JANSSEN_META}z_m\tsigma_v_Pa\tsigma_h_Pa\n{}",
                janssen_rows(1.0, 1.0, "\t", "\n")
            ),
            code: 2,
            fragments: &["tab-delimited", "replace tabs by ','"],
            truth: &[],
        },
        Case {
            what: "three triaxial points with the cohesion fixed at zero",
            law: "mohr-coulomb",
            text: "# cohesion = 0\np_Pa,q_Pa\n1000,500\n2000,1000\n3000,1500\n".into(),
            code: 0,
            fragments: &["cohesion   = at its bound (0 Pa), not an estimate"],
            truth: &[("friction_angle", std::f64::consts::FRAC_PI_6, 1e-9)],
        },
        Case {
            what: "three triaxial points with the cohesion free: too few",
            law: "mohr-coulomb",
            text: "p_Pa,q_Pa\n1000,500\n2000,1000\n3000,1500\n".into(),
            code: 2,
            fragments: &["3 suffice with '# cohesion = 0'"],
            truth: &[],
        },
        Case {
            what: "Windows line endings and a UTF-8 byte-order mark (a spreadsheet export)",
            law: "janssen",
            text: format!(
                "\u{feff}{}z_mm,sigma_v_kPa,sigma_h_kPa\r\n{}",
                JANSSEN_META.replace('\n', "\r\n"),
                janssen_rows(1e-3, 1e3, ",", "\r\n")
            ),
            code: 0,
            fragments: &["janssen fitted to "],
            truth: janssen_truth,
        },
    ]
}

#[test]
fn each_input_case_gives_its_exit_status_and_message() {
    let tmp = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for (k, c) in cases().iter().enumerate() {
        let file = format!("case{k}.csv");
        std::fs::write(tmp.path().join(&file), &c.text).unwrap();
        let (code, msg, params) = fit(tmp.path(), c.law, &file);
        let mut why = Vec::new();
        if code != c.code {
            why.push(format!("exit {code}, expected {}", c.code));
        }
        for f in c.fragments {
            if !msg.contains(f) {
                why.push(format!("no '{f}'"));
            }
        }
        if c.code == 2 {
            let lines: Vec<&str> = msg.lines().collect();
            if lines.len() != 1 || !lines[0].starts_with(&format!("error: {file}")) {
                why.push("not one line 'error: FILE…'".into());
            }
        }
        for (name, value, tol) in c.truth {
            match params.iter().find(|(n, _)| n == name) {
                Some((_, v)) if (v - value).abs() <= *tol => {}
                other => why.push(format!("{name} = {other:?}, expected {value} ± {tol}")),
            }
        }
        if !why.is_empty() {
            failures.push(format!("{}: {}\n  output: {msg}", c.what, why.join("; ")));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
