//! The DEM `column-collapse` run's output, as the continuum comparison reads it: `summary.json`
//! (its `column` object), `front.csv` (`t_s,t_star,x_f_m`) and `profiles.csv`
//! (`label,t_star,x_m,h_m`). SI units; the symmetry plane is `x = 0`, the floor `y = 0`, the
//! initial column `0 ≤ x ≤ R₀`, `0 ≤ y ≤ H₀`; `t* = t √(g/H₀)`. The continuum run writes its own
//! `front.csv` and `profiles.csv` in the same format ([`write_front`], [`write_profiles`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{CliError, Result};
use crate::output::OutputDir;

/// The `column` object of the DEM run's `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ColumnSummary {
    /// Initial half-width `R₀` (m).
    pub initial_half_width_m: f64,
    /// Initial height `H₀` (m).
    pub initial_height_m: f64,
    /// `a = H₀/R₀`.
    pub aspect_ratio: f64,
    /// Mean grain diameter `d` (m).
    pub mean_diameter_m: f64,
    /// Gravity (m/s²).
    pub gravity_m_s2: f64,
    /// Grain density `ρ_s` (kg/m³).
    pub grain_density_kg_m3: f64,
    /// Initial packing fraction `φ₀`.
    pub initial_packing_fraction: f64,
    /// Grain–grain friction.
    #[serde(default)]
    pub grain_friction: Option<f64>,
    /// Grain–floor friction.
    #[serde(default)]
    pub floor_friction: Option<f64>,
    /// Runout `r_∞` at rest, from `x = 0` (m).
    #[serde(default)]
    pub runout_m: Option<f64>,
    /// Height at `x = 0` at rest (m).
    #[serde(default)]
    pub final_height_m: Option<f64>,
    /// Time of rest (s).
    #[serde(default)]
    pub rest_time_s: Option<f64>,
    /// The reference instants `t*` of the profiles.
    #[serde(default)]
    pub reference_instants_t_star: Vec<f64>,
}

impl ColumnSummary {
    /// `t*` of rest, when the run came to rest.
    pub fn rest_t_star(&self) -> Option<f64> {
        self.rest_time_s
            .map(|t| t * (self.gravity_m_s2 / self.initial_height_m).sqrt())
    }
}

/// One row of `front.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FrontRow {
    /// Time (s).
    pub t_s: f64,
    /// `t* = t √(g/H₀)`.
    pub t_star: f64,
    /// Front position (m).
    pub x_f_m: f64,
}

/// One row of `profiles.csv`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProfileRow {
    /// `t0.66`, …, `rest` (the continuum writes `end` for its last instant).
    pub label: String,
    /// `t*` of the profile.
    pub t_star: f64,
    /// Position (m).
    pub x_m: f64,
    /// Height of the surface above the floor (m).
    pub h_m: f64,
}

/// A height profile at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// Its `t*`.
    pub t_star: f64,
    /// `(x, h)` (m), sorted by `x`.
    pub points: Vec<(f64, f64)>,
}

/// A DEM column-collapse output directory, read.
#[derive(Debug, Clone, PartialEq)]
pub struct DemColumn {
    /// The directory.
    pub dir: PathBuf,
    /// Its `column` object.
    pub summary: ColumnSummary,
    /// `front.csv`, in time order.
    pub front: Vec<FrontRow>,
    /// `profiles.csv` by label.
    pub profiles: BTreeMap<String, Profile>,
}

impl DemColumn {
    /// Reads `dir`. Errors: [`CliError::Input`] naming the file (missing, no `column` object,
    /// a row that does not parse, with its line; a non-finite or non-positive scale).
    pub fn read(dir: &Path) -> Result<DemColumn> {
        let sp = dir.join("summary.json");
        let text = std::fs::read_to_string(&sp).map_err(|e| input(&sp, e))?;
        let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| input(&sp, e))?;
        let col = v.get("column").ok_or_else(|| {
            input(
                &sp,
                "no `column` object: not the output of a DEM column-collapse run",
            )
        })?;
        let summary: ColumnSummary =
            serde_json::from_value(col.clone()).map_err(|e| input(&sp, format!("column: {e}")))?;
        for (name, val) in [
            ("initial_half_width_m", summary.initial_half_width_m),
            ("initial_height_m", summary.initial_height_m),
            ("aspect_ratio", summary.aspect_ratio),
            ("mean_diameter_m", summary.mean_diameter_m),
            ("gravity_m_s2", summary.gravity_m_s2),
            ("grain_density_kg_m3", summary.grain_density_kg_m3),
            ("initial_packing_fraction", summary.initial_packing_fraction),
        ] {
            if !(val.is_finite() && val > 0.0) {
                return Err(input(
                    &sp,
                    format!("column.{name} = {val} must be finite and > 0"),
                ));
            }
        }
        if summary.initial_packing_fraction > 1.0 {
            return Err(input(
                &sp,
                format!(
                    "column.initial_packing_fraction = {} is above 1",
                    summary.initial_packing_fraction
                ),
            ));
        }
        let mut front: Vec<FrontRow> = read_rows(&dir.join("front.csv"))?;
        front.sort_by(|a, b| a.t_star.total_cmp(&b.t_star));
        let rows: Vec<ProfileRow> = read_rows(&dir.join("profiles.csv"))?;
        Ok(DemColumn {
            dir: dir.to_path_buf(),
            summary,
            front,
            profiles: group_profiles(rows),
        })
    }
}

/// Profiles by label, each sorted by `x`.
pub fn group_profiles(rows: Vec<ProfileRow>) -> BTreeMap<String, Profile> {
    let mut out: BTreeMap<String, Profile> = BTreeMap::new();
    for r in rows {
        out.entry(r.label.clone())
            .or_insert_with(|| Profile {
                t_star: r.t_star,
                points: Vec::new(),
            })
            .points
            .push((r.x_m, r.h_m));
    }
    for p in out.values_mut() {
        p.points.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    out
}

/// Reads a CSV of typed rows (`#` lines are comments). Errors: [`CliError::Input`] naming the
/// file and the line of a row that does not parse, or a file without rows.
pub fn read_rows<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<Vec<T>> {
    let text = std::fs::read_to_string(path).map_err(|e| input(path, e))?;
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let mut out = Vec::new();
    for r in reader.deserialize::<T>() {
        out.push(r.map_err(|e| {
            let line = e.position().map(|p| p.line()).unwrap_or(0);
            input(path, format!("line {line}: {e}"))
        })?);
    }
    if out.is_empty() {
        return Err(input(path, "no rows"));
    }
    Ok(out)
}

/// Writes `front.csv` (`t_s,t_star,x_f_m`) into `out`.
pub fn write_front(out: &mut OutputDir, rows: &[FrontRow], comment: &str) -> Result<()> {
    write_rows(out, "front.csv", rows, comment)
}

/// Writes `profiles.csv` (`label,t_star,x_m,h_m`) into `out`.
pub fn write_profiles(out: &mut OutputDir, rows: &[ProfileRow], comment: &str) -> Result<()> {
    write_rows(out, "profiles.csv", rows, comment)
}

/// Writes typed rows as CSV (header from the field names) after a `# comment` line.
pub fn write_rows<T: Serialize>(
    out: &mut OutputDir,
    name: &str,
    rows: &[T],
    comment: &str,
) -> Result<()> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r)
            .map_err(|e| CliError::io(out.file(name), e))?;
    }
    let body = w
        .into_inner()
        .map_err(|e| CliError::io(out.file(name), e.to_string()))?;
    let mut text = format!("# {comment}\n").into_bytes();
    text.extend(body);
    out.write(name, &text).map(|_| ())
}

fn input(path: &Path, e: impl std::fmt::Display) -> CliError {
    CliError::Input {
        path: path.display().to_string(),
        reason: e.to_string(),
    }
}
