//! Every kind of bad user input, one table row each, through the `grainlaw` binary: scenario
//! TOML (in a file and with `--set`), CSV data for `grainlaw fit`, frictional-contact problems
//! for `grainlaw solve-fc`.
//!
//! Each row checks: exit code 2; nothing on stdout; exactly one line on stderr, starting with
//! `error: ` and containing every expected piece (the file, line or key, and what is wrong); no
//! panic, backtrace or internal error; no `summary.json` left behind.
//! Errors about a data file (`grainlaw fit`, `grainlaw solve-fc`) start with the file's path.
//! A second table sets NaN, +∞ and −∞ in every float key of every built-in scenario.
//! Fits that succeed but hold a parameter at its bound print it as such, not as an estimate.
//! Fits refused on data that were read (exit code 3) are in `tests/fit_refusals.rs`.

mod common;

use std::io::Write as _;
use std::path::Path;
use std::process::{Command, Output};

use toml::{Table, Value};

fn grainlaw(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_grainlaw"))
        .args(args)
        .current_dir(cwd)
        .env_remove("RUST_BACKTRACE")
        .output()
        .expect("the grainlaw binary runs")
}

/// One row: a label, the arguments, and the pieces the error line must contain.
struct Row {
    label: &'static str,
    args: Vec<String>,
    needles: Vec<String>,
    /// Pieces the error line must not contain.
    absent: Vec<String>,
}

fn row(label: &'static str, args: &[&str], needles: &[&str]) -> Row {
    Row {
        label,
        args: args.iter().map(|s| s.to_string()).collect(),
        needles: needles.iter().map(|s| s.to_string()).collect(),
        absent: Vec::new(),
    }
}

impl Row {
    /// The same row, whose error line must not contain any of `pieces`.
    fn without(mut self, pieces: &[&str]) -> Row {
        self.absent = pieces.iter().map(|s| s.to_string()).collect();
        self
    }
}

/// Checks one row (module documentation); returns a description of what failed.
fn failure(r: &Row, cwd: &Path) -> Option<String> {
    let args: Vec<&str> = r.args.iter().map(String::as_str).collect();
    let out = grainlaw(&args, cwd);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    let mut why = Vec::new();
    if out.status.code() != Some(2) {
        why.push(format!("exit {:?}", out.status.code()));
    }
    if lines.len() != 1 {
        why.push(format!("{} lines on stderr", lines.len()));
    }
    if !stderr.starts_with("error: ") {
        why.push("stderr does not start with `error: `".into());
    }
    for bad in [
        "panicked",
        "RUST_BACKTRACE",
        "stack backtrace",
        "internal error",
    ] {
        if stderr.contains(bad) {
            why.push(format!("stderr contains `{bad}`"));
        }
    }
    for n in &r.needles {
        if !stderr.contains(n.as_str()) {
            why.push(format!("`{n}` missing"));
        }
    }
    for n in &r.absent {
        if stderr.contains(n.as_str()) {
            why.push(format!("contains `{n}`"));
        }
    }
    if !out.stdout.is_empty() {
        why.push(format!("stdout: {}", String::from_utf8_lossy(&out.stdout)));
    }
    if common::walk(cwd)
        .iter()
        .any(|p| p.ends_with("summary.json"))
    {
        why.push("left a summary.json".into());
    }
    if why.is_empty() {
        None
    } else {
        Some(format!(
            "[{}] grainlaw {}: {}\n    stderr: {}",
            r.label,
            r.args.join(" "),
            why.join("; "),
            stderr.trim_end()
        ))
    }
}

fn run_table(rows: &[Row], cwd: &Path) {
    let failures: Vec<String> = rows.iter().filter_map(|r| failure(r, cwd)).collect();
    common::assert_no_failures(&failures, rows.len());
}

fn builtin(name: &str) -> &'static str {
    grainlaw::scenarios::registry::get(name)
        .unwrap()
        .builtin_toml()
}

/// Writes `text` to `dir/name`.
fn put(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

/// Writes the built-in `name` with the first line starting with `line_start` replaced by
/// `replacement` (empty to delete it) to `dir/file`.
fn put_edited(dir: &Path, file: &str, name: &str, line_start: &str, replacement: &str) {
    let text = builtin(name);
    let mut found = false;
    let mut out = String::new();
    for l in text.lines() {
        if !found && l.starts_with(line_start) {
            found = true;
            if !replacement.is_empty() {
                out.push_str(replacement);
                out.push('\n');
            }
        } else {
            out.push_str(l);
            out.push('\n');
        }
    }
    assert!(found, "{name} has no line starting with `{line_start}`");
    put(dir, file, &out);
}

#[test]
fn bad_scenarios_in_files_and_overrides() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Scenario files, each with one thing wrong.
    put(
        d,
        "unknown.toml",
        &format!("{}\nwobble = 3\n", builtin("rolling")),
    );
    put_edited(
        d,
        "unknown_nested.toml",
        "janssen",
        "radius_mean",
        "radius = 1.5e-3",
    );
    put_edited(
        d,
        "wrong_type.toml",
        "janssen",
        "grains =",
        "grains = \"many\"",
    );
    put_edited(
        d,
        "wrong_type_float.toml",
        "rolling",
        "radius =",
        "radius = \"big\"",
    );
    put_edited(
        d,
        "table_for_value.toml",
        "rolling",
        "radius =",
        "radius = { value = 1 }",
    );
    put_edited(
        d,
        "neg_radius.toml",
        "rolling",
        "radius =",
        "radius = -0.01",
    );
    put_edited(d, "zero_radius.toml", "rolling", "radius =", "radius = 0.0");
    put_edited(
        d,
        "neg_grain_radius.toml",
        "janssen",
        "radius_mean",
        "radius_mean = -1.5e-3",
    );
    put_edited(
        d,
        "neg_density.toml",
        "arrangements",
        "density =",
        "density = -2500.0",
    );
    put_edited(
        d,
        "zero_density.toml",
        "rolling",
        "density =",
        "density = 0",
    );
    put_edited(d, "neg_dt.toml", "rolling", "dt =", "dt = -1e-3");
    put_edited(d, "zero_dt.toml", "janssen", "dt =", "dt = 0.0");
    put_edited(
        d,
        "neg_duration.toml",
        "arrangements",
        "duration =",
        "duration = -0.5",
    );
    put_edited(
        d,
        "zero_duration.toml",
        "inclined-flow",
        "duration =",
        "duration = 0.0",
    );
    put_edited(
        d,
        "neg_friction.toml",
        "janssen",
        "grain_grain",
        "grain_grain = -0.25",
    );
    put_edited(d, "nan.toml", "janssen", "dt =", "dt = nan");
    put_edited(d, "inf.toml", "rolling", "duration =", "duration = inf");
    put_edited(
        d,
        "neg_inf.toml",
        "shear-cell",
        "pressure =",
        "pressure = -inf",
    );
    put_edited(
        d,
        "slope90.toml",
        "rolling",
        "slope_deg",
        "slope_deg = 90.0",
    );
    put_edited(
        d,
        "slope95.toml",
        "inclined-flow",
        "slope_deg",
        "slope_deg = 95.0",
    );
    // A box that cannot hold the grains: the column's width follows from the grains' area and
    // the aspect ratio; ten grains in a column 1000 widths high give a box narrower than a grain.
    put(
        d,
        "narrow_box.toml",
        &builtin("janssen")
            .replace("grains = 350", "grains = 10")
            .replace("column_aspect = 4.0", "column_aspect = 1000.0"),
    );
    // A container narrower than two mean diameters.
    put_edited(
        d,
        "narrow_container.toml",
        "stick-slip",
        "width_diameters",
        "width_diameters = 1.0",
    );
    // Rows of a stack that would start overlapping (negative gap).
    put_edited(d, "overlap_gap.toml", "arrangements", "gap =", "gap = -0.5");
    put_edited(
        d,
        "spread.toml",
        "janssen",
        "radius_spread",
        "radius_spread = 2e-3",
    );
    put_edited(d, "missing.toml", "rolling", "density =", "");
    put(
        d,
        "duplicate.toml",
        &format!("{}seed = 2\n", builtin("rolling")),
    );
    put(
        d,
        "syntax.toml",
        "scenario = \"rolling\"\nseed = 1\nslope_deg = = 3\n",
    );
    put(d, "no_kind.toml", "seed = 1\n");
    put(
        d,
        "bad_kind.toml",
        &builtin("rolling").replace("scenario = \"rolling\"", "scenario = \"flying\""),
    );
    put(
        d,
        "many_grains.toml",
        &builtin("janssen").replace("grains = 350", "grains = 1000000000000"),
    );
    put(
        d,
        "tiny_dt.toml",
        &builtin("rolling").replace("dt = 1e-3", "dt = 1e-300"),
    );
    std::fs::write(d.join("binary.toml"), [0xffu8, 0xfe, 0x00, 0x41]).unwrap();

    let rows = vec![
        row(
            "unknown key",
            &["run", "unknown.toml"],
            &["unknown.toml", "unknown key `wobble`"],
        ),
        row(
            "unknown nested key",
            &["run", "unknown_nested.toml"],
            &["unknown_nested.toml", "unknown key `grain.radius`"],
        ),
        row(
            "wrong type (string for integer)",
            &["run", "wrong_type.toml"],
            &["wrong_type.toml", "key `grains`", "expected usize"],
        ),
        row(
            "wrong type (string for float)",
            &["run", "wrong_type_float.toml"],
            &["wrong_type_float.toml", "key `radius`", "expected f64"],
        ),
        row(
            "wrong type (table for float)",
            &["run", "table_for_value.toml"],
            &["table_for_value.toml", "key `radius`"],
        ),
        row(
            "negative radius",
            &["run", "neg_radius.toml"],
            &["neg_radius.toml", "key `radius`", "> 0"],
        ),
        row(
            "zero radius",
            &["run", "zero_radius.toml"],
            &["zero_radius.toml", "key `radius`", "got 0"],
        ),
        row(
            "negative grain radius",
            &["run", "neg_grain_radius.toml"],
            &["key `grain.radius_mean`", "> 0"],
        ),
        row(
            "negative density",
            &["run", "neg_density.toml"],
            &["neg_density.toml", "key `density`"],
        ),
        row(
            "zero density",
            &["run", "zero_density.toml"],
            &["key `density`", "got 0"],
        ),
        row(
            "negative time step",
            &["run", "neg_dt.toml"],
            &["neg_dt.toml", "key `dt`", "> 0"],
        ),
        row(
            "zero time step",
            &["run", "zero_dt.toml"],
            &["key `dt`", "got 0"],
        ),
        row(
            "negative duration",
            &["run", "neg_duration.toml"],
            &["key `duration`", "> 0"],
        ),
        row(
            "zero duration",
            &["run", "zero_duration.toml"],
            &["key `duration`", "got 0"],
        ),
        row(
            "friction < 0",
            &["run", "neg_friction.toml"],
            &["key `friction.grain_grain`", "≥ 0"],
        ),
        row(
            "NaN in a file",
            &["run", "nan.toml"],
            &["nan.toml", "key `dt`", "NaN"],
        ),
        row(
            "inf in a file",
            &["run", "inf.toml"],
            &["key `duration`", "inf"],
        ),
        row(
            "-inf in a file",
            &["run", "neg_inf.toml"],
            &["key `pressure`", "-inf"],
        ),
        row(
            "slope = 90°",
            &["run", "slope90.toml"],
            &["key `slope_deg`", "90"],
        ),
        row(
            "slope > 90°",
            &["run", "slope95.toml"],
            &["key `slope_deg`", "95"],
        ),
        row(
            "box cannot hold the grains",
            &["run", "narrow_box.toml"],
            &[
                "narrow_box.toml",
                "key `column_aspect`",
                "narrower than the largest grain",
            ],
        ),
        row(
            "container narrower than a grain",
            &["run", "narrow_container.toml"],
            &["key `width_diameters`"],
        ),
        row(
            "stack rows overlapping at start",
            &["run", "overlap_gap.toml"],
            &["key `gap`", "-0.5"],
        ),
        row(
            "radius spread ≥ mean radius",
            &["run", "spread.toml"],
            &["key `grain.radius_spread`"],
        ),
        row(
            "missing key",
            &["run", "missing.toml"],
            &["missing.toml", "key `density`", "missing"],
        ),
        row(
            "duplicate key",
            &["run", "duplicate.toml"],
            &["duplicate.toml:", "duplicate key"],
        ),
        row(
            "TOML syntax",
            &["run", "syntax.toml"],
            &["syntax.toml:3:", "invalid TOML"],
        ),
        row(
            "no scenario kind",
            &["run", "no_kind.toml"],
            &["no_kind.toml", "key `scenario`", "missing"],
        ),
        row(
            "unknown scenario kind",
            &["run", "bad_kind.toml"],
            &["bad_kind.toml", "key `scenario`", "flying"],
        ),
        row(
            "too many grains",
            &["run", "many_grains.toml"],
            &["key `grains`", "at most"],
        ),
        row(
            "time step too small for the duration",
            &["run", "tiny_dt.toml"],
            &["key `dt`", "time steps"],
        ),
        row("not UTF-8", &["run", "binary.toml"], &["binary.toml"]),
        row("file absent", &["run", "absent.toml"], &["absent.toml"]),
        row(
            "unknown built-in",
            &["run", "no-such-scenario"],
            &["unknown scenario `no-such-scenario`"],
        ),
        // The same through --set on the built-ins.
        row(
            "--set unknown key",
            &["run", "--set", "wobble=3"],
            &["builtin:janssen", "unknown key `wobble`"],
        ),
        row(
            "--set wrong type",
            &["run", "--set", "grains=many"],
            &["key `grains`", "integer"],
        ),
        row(
            "--set negative radius",
            &["run", "rolling", "--set", "radius=-0.01"],
            &["builtin:rolling", "key `radius`"],
        ),
        row(
            "--set zero density",
            &["run", "--set", "grain.density=0"],
            &["key `grain.density`"],
        ),
        row(
            "--set negative time step",
            &["run", "stick-slip", "--set", "dt=-1e-3"],
            &["key `dt`"],
        ),
        row(
            "--set zero duration",
            &["run", "rolling", "--set", "duration=0"],
            &["key `duration`"],
        ),
        row(
            "--set friction < 0",
            &[
                "run",
                "stick-slip",
                "--set",
                "cases.walls_only.grain_wall=-0.8",
            ],
            &["key `cases.walls_only.grain_wall`"],
        ),
        row(
            "--set NaN",
            &["run", "--set", "friction.grain_wall=nan"],
            &["key `friction.grain_wall`", "NaN"],
        ),
        row(
            "--set inf",
            &["run", "shear-cell", "--set", "strain=inf"],
            &["key `strain`", "inf"],
        ),
        row(
            "--set slope 90°",
            &["run", "inclined-flow", "--set", "slope_deg=90"],
            &["key `slope_deg`"],
        ),
        row(
            "--set box cannot hold the grains",
            &["run", "--set", "grains=10", "--set", "column_aspect=1000"],
            &["key `column_aspect`"],
        ),
        row(
            "--set too many solver tightenings",
            &["run", "shear-cell", "--set", "solver_tightenings=5"],
            &["key `solver_tightenings`", "5"],
        ),
        row(
            "--set radius larger than the cell",
            &["run", "shear-cell", "--set", "cell_length_diameters=1"],
            &["key `cell_length_diameters`"],
        ),
        row(
            "--set huge radius (infinite mass)",
            &["run", "--set", "grain.radius_mean=1e300"],
            &["key `grain.radius_mean`", "1e300"],
        ),
        row(
            "--set huge density (infinite mass)",
            &["run", "arrangements", "--set", "density=1e308"],
            &["key `density`"],
        ),
        row(
            "--set too many bins",
            &[
                "run",
                "inclined-flow",
                "--set",
                "profile_bins=100000000000000",
            ],
            &["key `profile_bins`", "at most"],
        ),
        row(
            "--set too many sub-steps",
            &["run", "--set", "deposit.substeps=1000000000000"],
            &["key `deposit.substeps`"],
        ),
        row(
            "--set scenario kind",
            &["run", "--set", "scenario=rolling"],
            &["--set `scenario=rolling`", "cannot be changed"],
        ),
        row(
            "--set without =",
            &["run", "--set", "grains"],
            &["KEY=VALUE"],
        ),
        row(
            "--set on a table",
            &["run", "--set", "grain=1"],
            &["grain", "table"],
        ),
    ];
    run_table(&rows, d);
    // The checker itself refuses a successful command and a wrong expectation.
    assert!(failure(&row("valid", &["scenarios"], &[]), d).is_some());
    assert!(failure(
        &row("wrong needle", &["run", "--set", "dt=0"], &["grains"]),
        d
    )
    .is_some());
}

/// Dotted keys of the float leaves of `t` (`inertial_numbers[0]` for an array of floats).
fn float_keys(t: &Table) -> Vec<String> {
    common::toml_leaves(t)
        .into_iter()
        .filter_map(|(key, v)| match v {
            Value::Float(_) => Some(key),
            Value::Array(a) if a.iter().all(Value::is_float) && !a.is_empty() => {
                Some(format!("{key}[0]"))
            }
            _ => None,
        })
        .collect()
}

/// `t` with the float at `key` (dotted, `name[0]` for an array's first element) set to `v`.
fn set_float(t: &mut Table, key: &str, v: f64) {
    let mut parts: Vec<&str> = key.split('.').collect();
    let last = parts.pop().unwrap();
    let mut cur = t;
    for p in parts {
        cur = cur.get_mut(p).unwrap().as_table_mut().unwrap();
    }
    if let Some(name) = last.strip_suffix("[0]") {
        cur.get_mut(name).unwrap().as_array_mut().unwrap()[0] = Value::Float(v);
    } else {
        cur.insert(last.to_string(), Value::Float(v));
    }
}

/// NaN, +∞ and −∞ in every float key of every built-in, through `--set` and in a TOML file: each
/// is refused in one line naming the key (and the file).
#[test]
fn non_finite_values_in_every_float_key() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut rows = Vec::new();
    let mut count = 0;
    for b in grainlaw::scenarios::registry::SCENARIOS.iter() {
        let table: Table = b.builtin_toml().parse().unwrap();
        let keys = float_keys(&table);
        assert!(keys.len() >= 5, "{}: {keys:?}", b.name());
        for key in &keys {
            for (word, v) in [
                ("nan", f64::NAN),
                ("inf", f64::INFINITY),
                ("-inf", f64::NEG_INFINITY),
            ] {
                let set_arg = if let Some(name) = key.strip_suffix("[0]") {
                    // a dotted name reaches an array inside a table (`analysis.reference_t_star`)
                    let mut a = name
                        .split('.')
                        .fold(&Value::Table(table.clone()), |v, p| &v[p])
                        .as_array()
                        .unwrap()
                        .clone();
                    a[0] = Value::Float(v);
                    format!("{name}={}", Value::Array(a))
                } else {
                    format!("{key}={word}")
                };
                rows.push(Row {
                    label: "non-finite --set",
                    args: vec!["run".into(), b.name().into(), "--set".into(), set_arg],
                    needles: vec![format!("builtin:{}", b.name()), format!("key `{key}`")],
                    absent: Vec::new(),
                });
                let mut t = table.clone();
                set_float(&mut t, key, v);
                count += 1;
                let file = format!("nonfinite_{count}.toml");
                let text = toml::to_string(&t).unwrap();
                assert!(text.contains(word), "{text}");
                std::fs::File::create(d.join(&file))
                    .unwrap()
                    .write_all(text.as_bytes())
                    .unwrap();
                rows.push(Row {
                    label: "non-finite in a file",
                    args: vec!["run".into(), file.clone()],
                    needles: vec![file, format!("key `{key}`")],
                    absent: Vec::new(),
                });
            }
        }
    }
    assert!(rows.len() > 300, "{} rows", rows.len());
    run_table(&rows, d);
}

#[test]
fn bad_csv_for_fits() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good_rows = "0.01,0.30\n0.02,0.31\n0.05,0.35\n0.1,0.40\n0.2,0.45\n0.3,0.47\n";
    put(d, "nocol.csv", "x,y\n1,2\n3,4\n");
    put(
        d,
        "janssen_nocol.csv",
        "# width_m = 0.03\n# bulk_density_kg_m3 = 1600\n# wall_friction = 0.25\nz_m,sigma_v_Pa\n0.01,10\n",
    );
    put(
        d,
        "text.csv",
        "I,mu\n0.01,0.3\n0.02,abc\n0.05,0.35\n0.1,0.4\n0.2,0.45\n",
    );
    put(
        d,
        "nan.csv",
        "I,mu\n0.01,0.3\n0.02,0.31\n0.05,NaN\n0.1,0.4\n0.2,0.45\n",
    );
    put(
        d,
        "inf.csv",
        "I,mu\n0.01,0.3\ninf,0.31\n0.05,0.35\n0.1,0.4\n0.2,0.45\n",
    );
    put(d, "short.csv", "I,mu\n0.01,0.3\n");
    put(d, "header_only.csv", "I,mu\n");
    put(d, "empty.csv", "");
    put(
        d,
        "ragged.csv",
        "I,mu\n0.01,0.3\n0.02\n0.05,0.35\n0.1,0.4\n0.2,0.45\n",
    );
    put(
        d,
        "dup.csv",
        &format!("I,mu,I\n{}", "0.01,0.3,0.02\n".repeat(6)),
    );
    put(
        d,
        "neg_i.csv",
        &format!("I,mu\n-0.01,0.3\n{}", &good_rows[10..]),
    );
    put(
        d,
        "meta_missing.csv",
        "z_m,sigma_v_Pa,sigma_h_Pa\n0.01,10,5\n0.02,20,10\n",
    );
    put(
        d,
        "meta_text.csv",
        "# width_m = wide\nz_m,sigma_v_Pa,sigma_h_Pa\n0.01,10,5\n",
    );
    std::fs::write(d.join("binary.csv"), [0xffu8, 0xfe, b',', b'\n']).unwrap();
    let rows = vec![
        row(
            "missing column",
            &["fit", "mu-i", "nocol.csv"],
            &["nocol.csv", "missing column 'I'"],
        ),
        row(
            "missing column (janssen)",
            &["fit", "janssen", "janssen_nocol.csv"],
            &["janssen_nocol.csv", "missing column 'sigma_h_Pa'"],
        ),
        row(
            "non-numeric cell",
            &["fit", "mu-i", "text.csv"],
            &["text.csv:3", "column 'mu'", "'abc' is not a number"],
        ),
        row(
            "NaN cell",
            &["fit", "mu-i", "nan.csv"],
            &["nan.csv:4", "column 'mu'", "not finite"],
        ),
        row(
            "inf cell",
            &["fit", "mu-i", "inf.csv"],
            &["inf.csv:3", "column 'I'", "not finite"],
        ),
        row(
            "too few rows",
            &["fit", "mu-i", "short.csv"],
            &["error: short.csv: ", "too few points: 1 given"],
        ),
        row(
            "header only",
            &["fit", "mu-i", "header_only.csv"],
            &["header_only.csv:1", "no data rows"],
        ),
        row(
            "empty file",
            &["fit", "mu-i", "empty.csv"],
            &["empty.csv", "no header line"],
        ),
        row(
            "ragged row",
            &["fit", "mu-i", "ragged.csv"],
            &["ragged.csv:3", "1 fields"],
        ),
        row(
            "duplicate column",
            &["fit", "mu-i", "dup.csv"],
            &["dup.csv:1", "column 'I' appears twice"],
        ),
        row(
            "value outside its domain",
            &["fit", "mu-i", "neg_i.csv"],
            &["error: neg_i.csv: ", "I[0] = -0.01", "out of its domain"],
        )
        .without(&["0.000000"]),
        row(
            "missing metadata",
            &["fit", "janssen", "meta_missing.csv"],
            &["meta_missing.csv", "# width_m"],
        ),
        row(
            "non-numeric metadata",
            &["fit", "janssen", "meta_text.csv"],
            &["meta_text.csv", "line 1", "'wide' is not a number"],
        ),
        row("not UTF-8", &["fit", "mu-i", "binary.csv"], &["binary.csv"]),
        row(
            "file absent",
            &["fit", "mu-i", "absent.csv"],
            &["absent.csv"],
        ),
        row(
            "unknown law",
            &["fit", "no-such-law", "text.csv"],
            &["no-such-law", "mu-i"],
        ),
    ];
    run_table(&rows, d);
}

#[test]
fn bad_frictional_contact_problems() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let valid = r#"{"format":"fc-problem-v1","dimension":2,"nc":2,"mu":[0.3,0.5],"q":[-1,0,-0.5,0.1],"W":{"storage":"coo","shape":[4,4],"row":[0,1,2,3],"col":[0,1,2,3],"val":[1,3,1,3]}}"#;
    let edit = |from: &str, to: &str| {
        assert!(valid.contains(from), "{from}");
        valid.replacen(from, to, 1)
    };
    put(d, "trunc.json", &valid[..valid.len() / 2]);
    put(d, "not_json.json", "this is not JSON\n");
    put(d, "negmu.json", &edit("[0.3,0.5]", "[0.3,-0.5]"));
    put(d, "nanmu.json", &edit("[0.3,0.5]", "[0.3,NaN]"));
    put(d, "mu_len.json", &edit("[0.3,0.5]", "[0.3]"));
    put(d, "q_len.json", &edit("[-1,0,-0.5,0.1]", "[-1,0]"));
    put(d, "shape.json", &edit("[4,4]", "[4,6]"));
    put(d, "shape_size.json", &edit("[4,4]", "[2,2]"));
    put(
        d,
        "index.json",
        &edit("\"row\":[0,1,2,3]", "\"row\":[0,1,2,9]"),
    );
    put(
        d,
        "dense_ragged.json",
        r#"{"format":"fc-problem-v1","dimension":2,"nc":1,"mu":[0.3],"q":[-1,0],"W":{"storage":"dense","data":[[1,0],[0]]}}"#,
    );
    put(
        d,
        "dense_size.json",
        r#"{"format":"fc-problem-v1","dimension":2,"nc":2,"mu":[0.3,0.3],"q":[-1,0,-1,0],"W":{"storage":"dense","data":[[1,0],[0,3]]}}"#,
    );
    put(d, "dim3.json", &edit("\"dimension\":2", "\"dimension\":3"));
    {
        let mut s = valid[..valid.find(",\"W\"").unwrap()].to_string();
        s.push('}');
        put(d, "no_w.json", &s);
    }
    put(d, "mu_type.json", &edit("[0.3,0.5]", "\"high\""));
    put(
        d,
        "not_pd.json",
        &edit("\"val\":[1,3,1,3]", "\"val\":[1,3,-1,3]"),
    );
    // A gzip file cut in the middle.
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(valid.as_bytes()).unwrap();
    let gz = gz.finish().unwrap();
    std::fs::write(d.join("cut.json.gz"), &gz[..gz.len() / 2]).unwrap();
    put(d, "ok.json", valid);
    let rows = vec![
        row(
            "file absent",
            &["solve-fc", "absent.json"],
            &["error: absent.json: "],
        ),
        row(
            "truncated JSON",
            &["solve-fc", "trunc.json"],
            &["error: trunc.json: ", "invalid JSON", "line 1"],
        ),
        row(
            "not JSON",
            &["solve-fc", "not_json.json"],
            &["error: not_json.json: ", "invalid JSON", "line 1"],
        ),
        row(
            "μ < 0",
            &["solve-fc", "negmu.json"],
            &["error: negmu.json: ", "key `mu[1]`", "-0.5 < 0"],
        ),
        row(
            "μ = NaN",
            &["solve-fc", "nanmu.json"],
            &["error: nanmu.json: ", "key `mu`", "non-finite"],
        ),
        row(
            "mu length ≠ nc",
            &["solve-fc", "mu_len.json"],
            &["error: mu_len.json: ", "key `mu`", "length 1, expected 2"],
        ),
        row(
            "q length ≠ 2 nc",
            &["solve-fc", "q_len.json"],
            &["error: q_len.json: ", "key `q`", "length 2, expected 4"],
        ),
        row(
            "W not square (shape)",
            &["solve-fc", "shape.json"],
            &["error: shape.json: ", "key `W.shape`", "not square"],
        ),
        row(
            "W size ≠ 2 nc",
            &["solve-fc", "shape_size.json"],
            &["error: shape_size.json: ", "key `W.shape`", "expected 4"],
        ),
        row(
            "W index out of range",
            &["solve-fc", "index.json"],
            &["error: index.json: ", "key `W.row[3]`", "out of range"],
        ),
        row(
            "W not square (dense rows)",
            &["solve-fc", "dense_ragged.json"],
            &[
                "error: dense_ragged.json: ",
                "key `W.data[1]`",
                "not square",
            ],
        ),
        row(
            "W dense size ≠ 2 nc",
            &["solve-fc", "dense_size.json"],
            &["error: dense_size.json: ", "key `W.data`", "expected 4"],
        ),
        row(
            "3D problem",
            &["solve-fc", "dim3.json"],
            &["error: dim3.json: ", "key `dimension`", "3D"],
        ),
        row(
            "missing W",
            &["solve-fc", "no_w.json"],
            &["error: no_w.json: ", "missing key `W`"],
        ),
        row(
            "wrong type",
            &["solve-fc", "mu_type.json"],
            &["error: mu_type.json: ", "key `mu`", "array of numbers"],
        ),
        row(
            "W block not positive definite",
            &["solve-fc", "not_pd.json"],
            &[
                "error: not_pd.json: ",
                "key `W`",
                "contact 1",
                "not positive definite",
            ],
        ),
        row(
            "gzip cut in the middle",
            &["solve-fc", "cut.json.gz"],
            &["error: cut.json.gz: "],
        ),
        row(
            "--tol < 0",
            &["solve-fc", "ok.json", "--tol", "-1"],
            &["--tol"],
        ),
        row(
            "--tol NaN",
            &["solve-fc", "ok.json", "--tol", "nan"],
            &["--tol"],
        ),
        row(
            "--max-iterations 0",
            &["solve-fc", "ok.json", "--max-iterations", "0"],
            &["--max-iterations"],
        ),
    ];
    run_table(&rows, d);
}

/// Runs `grainlaw fit LAW FILE --out law.json` in `d`; returns stdout and the law JSON.
fn fit_ok(d: &Path, law: &str, file: &str) -> (String, serde_json::Value) {
    let out = grainlaw(&["fit", law, file, "--out", "law.json"], d);
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert_eq!(
        out.status.code(),
        Some(0),
        "fit {law} {file}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json = std::fs::read_to_string(d.join("law.json")).unwrap();
    (stdout, serde_json::from_str(&json).unwrap())
}

/// Fits that give a law, but not every parameter as an estimate: a Mohr–Coulomb cohesion held at
/// its bound `c = 0` is printed as at its bound (it printed `cohesion = 0 (95 % CI 0 … 0)`) with
/// the upper end the data allow, and flagged `at_bound` in the JSON with its one-sided interval; a wall law falling like `a − b ln V`, which the power law
/// reaches only with every interval spanning zero, is not given as a power law (it was the
/// AIC winner), the power law is listed as failed, not identifiable.
#[test]
fn fits_do_not_print_numbers_that_are_not_estimates() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // τ = 0.49 σ_n − 40 Pa up to ±10 Pa: the unconstrained intercept is negative, c sits at 0.
    put(
        d,
        "cohesionless.csv",
        "sigma_n_Pa,tau_Pa\n1000,450\n2000,950\n3000,1440\n4000,1960\n5000,2450\n6000,2940\n",
    );
    let (stdout, law) = fit_ok(d, "mohr-coulomb", "cohesionless.csv");
    assert!(
        stdout.contains("cohesion   = at its bound (0 Pa), not an estimate"),
        "{stdout}"
    );
    assert!(!stdout.contains("cohesion   = 0"), "{stdout}");
    let c = law["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "cohesion")
        .unwrap();
    assert_eq!(c["at_bound"], true, "{c}");
    assert_eq!(c["value"], 0.0, "{c}");
    // one-sided: [0, t se(b)] with the unconstrained intercept's standard error, never [0, 0]
    // (b < 0 here: the upper end does not fall below t se, what the data resolve)
    assert_eq!(c["ci_low"], 0.0, "{c}");
    let (se, high) = (
        c["std_error"].as_f64().unwrap(),
        c["ci_high"].as_f64().unwrap(),
    );
    assert!(se > 0.0 && high > se, "{c}");
    assert!(stdout.contains("(the data allow up to "), "{stdout}");

    // μ_eff = 0.45 − 0.005 ln V ± 0.001, V = V_s/√(g d) from 0.01 to 10.
    let scale = (9.81f64 * 0.002).sqrt();
    let mut s = String::from("# grain_diameter_m = 0.002\nslip_velocity_m_s,mu_eff\n");
    for k in 0..12 {
        let v = 10f64.powf(-2.0 + 3.0 * k as f64 / 11.0);
        let wiggle = if k % 2 == 0 { 0.001 } else { -0.001 };
        s.push_str(&format!(
            "{},{}\n",
            v * scale,
            0.45 - 0.005 * v.ln() + wiggle
        ));
    }
    put(d, "wall_log.csv", &s);
    let (stdout, law) = fit_ok(d, "wall-law", "wall_log.csv");
    assert_ne!(law["law"], "wall-law-power", "{stdout}");
    let failed = law["model_selection"]["failed"].as_array().unwrap();
    assert!(
        failed.iter().any(
            |f| f[0] == "wall-law-power" && f[1].as_str().unwrap().contains("not identifiable")
        ),
        "{failed:?}"
    );
}
