//! Bad user CSV files for `fit_csv_file`, one table row each: the typed error expected, and a
//! piece of its one-line message (file, line, column or parameter). Fits that end on a bound or
//! are not identifiable return an error that says so, never numbers; computed values in the
//! messages are short (six significant digits).

use std::fmt::Write as _;

use identify::user_fit::{fit_csv_file, CsvFitOptions};
use identify::IdentifyError;

/// Janssen set-up lines (width, bulk density, wall friction).
const JANSSEN_META: &str =
    "# width_m = 0.03\n# bulk_density_kg_m3 = 1600\n# wall_friction = 0.25\n";

/// Rows `I, mu` of a μ(I) law with μ_s = 0.38, μ₂ = 0.64, I₀ = 0.279 at I from 10⁻³ to 1.
fn mu_i_rows() -> String {
    let mut s = String::new();
    for k in 0..12 {
        let i = 10f64.powf(-3.0 + 3.0 * k as f64 / 11.0);
        let mu = 0.38 + 0.26 / (0.279 / i + 1.0);
        writeln!(s, "{i},{mu}").unwrap();
    }
    s
}

/// A column `sigma_v = ρ g z` (no wall friction at all) with `sigma_h = σ_v / 2`.
fn hydrostatic() -> String {
    let mut s = format!("{JANSSEN_META}z_m,sigma_v_Pa,sigma_h_Pa\n");
    for k in 1..=12 {
        let z = 0.005 * k as f64;
        let sv = 1600.0 * 9.81 * z;
        writeln!(s, "{z},{sv},{}", 0.5 * sv).unwrap();
    }
    s
}

type Check = fn(&IdentifyError) -> bool;

struct Row {
    label: &'static str,
    law: &'static str,
    text: String,
    is_expected: Check,
    needle: &'static str,
}

fn rows() -> Vec<Row> {
    let good = mu_i_rows();
    let with_cell = |line: usize, cell: &str| {
        // `line` is the 1-based file line (header = 1) whose `mu` cell is replaced.
        let mut lines: Vec<String> = format!("I,mu\n{good}").lines().map(String::from).collect();
        let (i, _) = lines[line - 1].split_once(',').unwrap();
        lines[line - 1] = format!("{i},{cell}");
        lines.join("\n") + "\n"
    };
    let text_cell = with_cell(4, "abc");
    let nan_cell = with_cell(5, "NaN");
    let inf_cell = with_cell(6, "-inf");
    vec![
        Row {
            label: "missing column",
            law: "mu-i",
            text: format!("I,friction\n{good}"),
            is_expected: |e| matches!(e, IdentifyError::MissingColumn { column, .. } if column == "mu"),
            needle: "missing column 'mu'",
        },
        Row {
            label: "non-numeric cell",
            law: "mu-i",
            text: text_cell,
            is_expected: |e| matches!(e, IdentifyError::NonNumericCell { line: 4, .. }),
            needle: ":4: column 'mu': 'abc' is not a number",
        },
        Row {
            label: "NaN cell",
            law: "mu-i",
            text: nan_cell,
            is_expected: |e| matches!(e, IdentifyError::NonFiniteCell { line: 5, .. }),
            needle: ":5: column 'mu'",
        },
        Row {
            label: "-inf cell",
            law: "mu-i",
            text: inf_cell,
            is_expected: |e| matches!(e, IdentifyError::NonFiniteCell { line: 6, .. }),
            needle: "-inf is not finite",
        },
        Row {
            label: "too few rows",
            law: "mu-i",
            text: format!("I,mu\n{}", good.lines().take(2).collect::<Vec<_>>().join("\n")),
            is_expected: |e| matches!(e, IdentifyError::TooFewPoints { got: 2, .. }),
            needle: "too few points: 2 given",
        },
        Row {
            label: "header only",
            law: "phi-i",
            text: "I,phi\n".into(),
            is_expected: |e| matches!(e, IdentifyError::Csv { line: 1, .. }),
            needle: ":1: no data rows after the header",
        },
        Row {
            label: "empty file",
            law: "mu-i",
            text: String::new(),
            is_expected: |e| matches!(e, IdentifyError::Csv { .. }),
            needle: "no header line",
        },
        Row {
            label: "ragged row",
            law: "mu-i",
            text: format!("I,mu\n0.1\n{good}"),
            is_expected: |e| matches!(e, IdentifyError::Csv { line: 2, .. }),
            needle: ":2: 1 fields, but the header has 2",
        },
        Row {
            label: "column named twice (after comments)",
            law: "mu-i",
            text: format!("# a comment\n\nI,mu,i\n{}", good.replace('\n', ",1\n")),
            is_expected: |e| matches!(e, IdentifyError::Csv { line: 3, .. }),
            needle: ":3: column 'i' appears twice (fields 1 and 3)",
        },
        Row {
            label: "value outside its domain",
            law: "mu-i",
            text: format!("I,mu\n-0.5,0.3\n{good}"),
            is_expected: |e| matches!(e, IdentifyError::OutOfDomain { index: 0, .. }),
            needle: "I[0] = -0.5 is out of its domain",
        },
        Row {
            label: "missing metadata",
            law: "janssen",
            text: hydrostatic().replace("# width_m = 0.03\n", ""),
            is_expected: |e| matches!(e, IdentifyError::Metadata { .. }),
            needle: "missing metadata line '# width_m = <value>'",
        },
        Row {
            label: "non-numeric metadata",
            law: "janssen",
            text: hydrostatic().replace("# width_m = 0.03", "# width_m = wide"),
            is_expected: |e| matches!(e, IdentifyError::Metadata { .. }),
            needle: "line 1: metadata 'width_m' = 'wide' is not a number",
        },
        Row {
            label: "negative set-up constant",
            law: "janssen",
            text: hydrostatic().replace("# width_m = 0.03", "# width_m = -0.03"),
            is_expected: |e| matches!(e, IdentifyError::InvalidSetup { .. }),
            needle: "width_m = -0.03",
        },
        // Fits that cannot give numbers.
        Row {
            label: "μ(I) decreasing: μ₂ − μ_s at its bound 0",
            law: "mu-i",
            text: "I,mu\n0.01,0.5\n0.02,0.45\n0.05,0.4\n0.1,0.35\n0.2,0.3\n0.3,0.28\n".into(),
            is_expected: |e| matches!(e, IdentifyError::ParameterAtBound { .. }),
            needle: "ended at its lower bound",
        },
        Row {
            label: "μ(I) far below I₀: not identifiable",
            law: "mu-i",
            text: "I,mu\n1e-6,0.3\n2e-6,0.3001\n3e-6,0.3002\n4e-6,0.3003\n5e-6,0.3004\n6e-6,0.3005\n"
                .into(),
            is_expected: |e| matches!(e, IdentifyError::ScaleNotResolved { .. }),
            needle: "I_0 and the law's asymptote are not separately identifiable",
        },
        Row {
            label: "no spread in I",
            law: "mu-i",
            text: "I,mu\n0.1,0.3\n0.1,0.31\n0.1,0.32\n0.1,0.33\n0.1,0.34\n0.1,0.35\n".into(),
            is_expected: |e| matches!(e, IdentifyError::ZeroVariance { .. }),
            needle: "cannot be identified",
        },
        Row {
            label: "φ(I) increasing: a slope below 0",
            law: "phi-i",
            text: "I,phi\n0.01,0.78\n0.02,0.79\n0.05,0.8\n0.1,0.81\n0.2,0.82\n0.3,0.83\n".into(),
            is_expected: |e| matches!(e, IdentifyError::IntervalCrossesBound { .. }),
            needle: "the 95 % interval of a [",
        },
        Row {
            label: "hydrostatic column: Janssen μ_w at its bound 0",
            law: "janssen",
            text: hydrostatic(),
            is_expected: |e| matches!(e, IdentifyError::ParameterAtBound { .. }),
            needle: "parameter mu_w ended at its lower bound 0",
        },
        Row {
            label: "hydrostatic column: K μ_w at its bound 0",
            law: "janssen-kmu",
            text: hydrostatic(),
            is_expected: |e| matches!(e, IdentifyError::ParameterAtBound { .. }),
            needle: "parameter K_mu_w ended at its lower bound 0",
        },
        Row {
            label: "no horizontal stress: K not identifiable",
            law: "janssen",
            text: hydrostatic()
                .lines()
                .map(|l| match l.rsplit_once(',') {
                    Some((a, _)) if !l.starts_with(['#', 'z']) => format!("{a},0\n"),
                    _ => format!("{l}\n"),
                })
                .collect(),
            is_expected: |e| matches!(e, IdentifyError::ZeroVariance { .. }),
            needle: "sigma_h has zero variance",
        },
        Row {
            label: "shear stress falling with normal stress: friction angle at its bound",
            law: "mohr-coulomb",
            text: "sigma_n_Pa,tau_Pa\n100,950\n200,900\n300,850\n400,800\n500,750\n600,700\n"
                .into(),
            is_expected: |e| matches!(e, IdentifyError::ParameterAtBound { .. }),
            needle: "parameter friction_angle ended at its lower bound 0",
        },
        Row {
            label: "wall friction scattered with no resolved velocity dependence",
            law: "wall-law",
            text: "# grain_diameter_m = 0.002\nslip_velocity_m_s,mu_eff\n0.01,0.47\n0.02,0.44\n0.05,0.45\n0.1,0.43\n0.2,0.44\n0.5,0.42\n1.0,0.43\n"
                .into(),
            is_expected: |e| {
                matches!(e, IdentifyError::ScaleNotResolved { parameter, .. } if parameter == "V_star")
            },
            needle: "wall-law-exponential: refused: V_star = 0.0414559 lies below the smallest V in the data",
        },
        Row {
            label: "constant wall friction: not identifiable",
            law: "wall-law",
            text: "# grain_diameter_m = 0.002\nslip_velocity_m_s,mu_eff\n0.01,0.3\n0.02,0.3\n0.05,0.3\n0.1,0.3\n0.2,0.3\n0.5,0.3\n"
                .into(),
            is_expected: |e| matches!(e, IdentifyError::ZeroVariance { .. }),
            needle: "mu_eff has zero variance",
        },
    ]
}

#[test]
fn every_bad_csv_gives_its_typed_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    let rows = rows();
    for (k, r) in rows.iter().enumerate() {
        let path = dir.path().join(format!("case{k}.csv"));
        std::fs::write(&path, &r.text).unwrap();
        match fit_csv_file(r.law, &path, &CsvFitOptions::default()) {
            Ok(l) => failures.push(format!(
                "[{}] fitted: {:?}",
                r.label,
                l.parameters
                    .iter()
                    .map(|p| (&p.name, p.value))
                    .collect::<Vec<_>>()
            )),
            Err(e) => {
                let m = e.to_string();
                // Computed numbers are shown short (`4.93824e-17`, not `0.0000000000000000493…`).
                if !(r.is_expected)(&e)
                    || !m.contains(r.needle)
                    || m.contains('\n')
                    || m.contains("0.000000")
                {
                    failures.push(format!("[{}] {e:?}\n    message: {m}", r.label));
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} rows failed:\n{}",
        failures.len(),
        rows.len(),
        failures.join("\n")
    );
}

/// The good μ(I) rows of the table fit (the rows above fail because of their one defect).
#[test]
fn the_reference_rows_fit() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("good.csv");
    std::fs::write(
        &path,
        format!(
            "# grain_diameter_m = 0.002\n# grain_density_kg_m3 = 2500\nI,mu\n{}",
            mu_i_rows()
        ),
    )
    .unwrap();
    let law = fit_csv_file("mu-i", &path, &CsvFitOptions::default()).unwrap();
    let mu_s = law.parameters.iter().find(|p| p.name == "mu_s").unwrap();
    assert!((mu_s.value - 0.38).abs() < 1e-6, "{mu_s:?}");
}
