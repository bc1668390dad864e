//! Run arguments and helpers shared by the command-line tests.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `grainlaw run shear-cell -q` on a small cell: 60 grains, 10 diameters long, short runs
/// (strain 0.6, the last 0.3 averaged) after a 0.05 s compression, about a second; the target
/// inertial numbers follow as `--set inertial_numbers=[…]`.
pub const SMALL_SHEAR_CELL: &[&str] = &[
    "run",
    "shear-cell",
    "-q",
    "--set",
    "grains=60",
    "--set",
    "cell_length_diameters=10",
    "--set",
    "strain=0.6",
    "--set",
    "average_strain=0.3",
    "--set",
    "compression_time=0.05",
    "--set",
];

/// The laws a rheology of three inertial numbers cannot identify (μ(I) needs 5, its linear
/// form and φ(I) 4: `grainlaw::scenarios::common::laws`), left out so that such a plan runs.
pub const LEAVE_OUT_RHEOLOGY: &str = r#"leave_out=["mu-i", "mu-i-linear", "phi-i"]"#;

/// [`SMALL_SHEAR_CELL`] at the three inertial numbers `list` (a TOML array) with the laws they
/// cannot identify left out ([`LEAVE_OUT_RHEOLOGY`]: the wall law is still fitted), then
/// `extra`.
pub fn small_shear_cell<'a>(list: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    SMALL_SHEAR_CELL
        .iter()
        .copied()
        .chain([list, "--set", LEAVE_OUT_RHEOLOGY])
        .chain(extra.iter().copied())
        .collect()
}

/// `grainlaw ARGS [--out DIR]` at a fixed date (`SOURCE_DATE_EPOCH`): the provenance of the
/// laws written by a run and by its resumed twin agree.
pub fn grainlaw(args: &[&str], dir: Option<&Path>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_grainlaw"));
    cmd.env("SOURCE_DATE_EPOCH", "1767225600").args(args);
    if let Some(d) = dir {
        cmd.arg("--out").arg(d);
    }
    cmd.output().expect("grainlaw runs")
}

/// `grainlaw ARGS` run in `cwd`.
pub fn grainlaw_in(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_grainlaw"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("the grainlaw binary runs")
}

/// `grainlaw ARGS` run in the test's directory.
pub fn grainlaw_here(args: &[&str]) -> Output {
    grainlaw_in(args, Path::new("."))
}

/// The standard error of a finished command, as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// Every file under `dir`, in its subdirectories too (directories that cannot be read are
/// skipped).
pub fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Ok(rd) = std::fs::read_dir(dir) {
        for e in rd.flatten() {
            let p = e.path();
            if p.is_dir() {
                out.extend(walk(&p));
            } else {
                out.push(p);
            }
        }
    }
    out
}

/// Every file under `dir` (relative path → bytes).
pub fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    walk(dir)
        .into_iter()
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap();
            (p.strip_prefix(dir).unwrap().to_path_buf(), bytes)
        })
        .collect()
}

/// `a` and `b` hold the same files with the same bytes; `summary.json` the same keys and
/// values in the same order, `wall_seconds` aside.
pub fn assert_same_outputs(a: &Path, b: &Path) {
    let (fa, fb) = (files(a), files(b));
    let names = |f: &BTreeMap<PathBuf, Vec<u8>>| f.keys().cloned().collect::<Vec<_>>();
    assert_eq!(names(&fa), names(&fb), "different files");
    for (name, bytes) in &fa {
        if name == Path::new("summary.json") {
            continue;
        }
        assert!(bytes == &fb[name], "{} differs", name.display());
    }
    let summary = |f: &BTreeMap<PathBuf, Vec<u8>>| -> Vec<(String, serde_json::Value)> {
        let v: serde_json::Map<String, serde_json::Value> =
            serde_json::from_slice(&f[Path::new("summary.json")]).unwrap();
        v.into_iter().filter(|(k, _)| k != "wall_seconds").collect()
    };
    let (sa, sb) = (summary(&fa), summary(&fb));
    assert_eq!(sa.len(), sb.len());
    for ((ka, va), (kb, vb)) in sa.iter().zip(&sb) {
        assert_eq!(ka, kb, "keys in another order");
        assert_eq!(va, vb, "summary key {ka} differs");
    }
}

/// Runs `args` (a `grainlaw run` without `--out`) into `a` uninterrupted, then into `b`
/// stopped after `stop_after` steps (exit 130) and resumed: the resumed run ends with the
/// uninterrupted one's exit code, 0 or 3 (a refused or suspect verdict).
pub fn run_stopped_and_resumed(args: &[&str], stop_after: &str, a: &Path, b: &Path) {
    let o = grainlaw(args, Some(a));
    let code = o.status.code();
    assert!(matches!(code, Some(0) | Some(3)), "{}", stderr(&o));
    let o = grainlaw(
        &[args, &["--stop-after-steps", stop_after]].concat(),
        Some(b),
    );
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    let o = grainlaw(&["run", "--resume", b.to_str().unwrap(), "-q"], None);
    assert_eq!(o.status.code(), code, "{}", stderr(&o));
}

/// The parameters of the law file `path` (a `grainlaw fit --out` or scenario law JSON) by name,
/// in the file's order.
pub fn law_parameters(path: &Path) -> Vec<(String, f64)> {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    v["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            (
                p["name"].as_str().unwrap().to_string(),
                p["value"].as_f64().unwrap(),
            )
        })
        .collect()
}

/// Σ_i of LAMMPS' per-atom `compute stress/atom NULL pair` columns (xx, yy, xy) of a dump.
pub fn lammps_stress_sum(path: &Path) -> [f64; 3] {
    let text = grainlaw::readers::read_text(path).unwrap();
    let mut lines = text.lines().skip_while(|l| !l.starts_with("ITEM: ATOMS"));
    let header: Vec<&str> = lines.next().unwrap().split_whitespace().skip(2).collect();
    let col = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (xx, yy, xy) = (col("c_s[1]"), col("c_s[2]"), col("c_s[4]"));
    let mut s = [0.0; 3];
    for l in lines {
        let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
        s[0] += v[xx];
        s[1] += v[yy];
        s[2] += v[xy];
    }
    s
}

/// The standard output then the standard error of a finished command, as text.
pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// A temporary directory holding the campaign plan `plan` as `plan.toml`.
pub fn plan_dir(plan: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("plan.toml"), plan).unwrap();
    dir
}

/// `grainlaw campaign ARGS` run in `cwd`.
pub fn campaign(cwd: &Path, args: &[&str]) -> Output {
    grainlaw_in(&[&["campaign"], args].concat(), cwd)
}

/// A CSV table read whole: its header and its rows.
pub struct Table {
    /// The header row.
    pub head: csv::StringRecord,
    /// The rows below it.
    pub rows: Vec<csv::StringRecord>,
}

impl Table {
    /// The table in `text`, its `#` comment lines skipped (panics on a malformed one).
    pub fn parse(text: &str) -> Table {
        let mut r = csv::ReaderBuilder::new()
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let head = r.headers().unwrap().clone();
        let rows = r.records().map(|r| r.unwrap()).collect();
        Table { head, rows }
    }

    /// The table in the file at `path` ([`Table::parse`]).
    pub fn read(path: &Path) -> Table {
        Table::parse(&std::fs::read_to_string(path).unwrap())
    }

    /// The index of the column `name` (panics without it).
    pub fn col(&self, name: &str) -> usize {
        self.head
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name} in {:?}", self.head))
    }

    /// The rows as numbers (a cell that is not one reads as NaN).
    pub fn numbers(&self) -> Vec<Vec<f64>> {
        self.rows
            .iter()
            .map(|r| r.iter().map(|c| c.parse().unwrap_or(f64::NAN)).collect())
            .collect()
    }
}

/// Every leaf of the TOML table `t` that is not a table, under its dotted key (`a.b.c`),
/// depth first in the table's order (inline tables included).
pub fn toml_leaves(t: &toml::Table) -> Vec<(String, &toml::Value)> {
    fn walk<'a>(t: &'a toml::Table, prefix: &str, out: &mut Vec<(String, &'a toml::Value)>) {
        for (k, v) in t {
            let key = if prefix.is_empty() {
                k.clone()
            } else {
                format!("{prefix}.{k}")
            };
            match v {
                toml::Value::Table(sub) => walk(sub, &key, out),
                _ => out.push((key, v)),
            }
        }
    }
    let mut out = Vec::new();
    walk(t, "", &mut out);
    out
}

/// Asserts that a table test's `failures` (one message per failed row, of `rows` rows) is
/// empty, listing them all when not.
pub fn assert_no_failures(failures: &[String], rows: usize) {
    assert!(
        failures.is_empty(),
        "{} of {} rows failed:\n{}",
        failures.len(),
        rows,
        failures.join("\n")
    );
}

/// `grainlaw homogenise` of LAMMPS dumps at μ = 0.5, quietly; the output directory and the
/// files follow.
pub const HOMOGENISE_LAMMPS: &[&str] = &[
    "homogenise",
    "--from",
    "lammps",
    "--mu",
    "0.5",
    "-q",
    "--out",
];
