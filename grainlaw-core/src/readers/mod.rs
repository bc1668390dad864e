//! Snapshots of other DEM codes read into the engine's [`Snapshot`] (`docs/formats.md` §
//! "Snapshots of other codes"), so that `grainlaw homogenise` treats them like its own.
//!
//! - [`read_lammps`]: LAMMPS (and LIGGGHTS) `dump custom` per-atom files with `dump local`
//!   pair-force files, 2D; walls from `fix wall/gran ... contacts` per-atom columns;
//! - [`read_lmgc90`]: LMGC90 2D `DOF.OUT`, `BODIES.DAT` and `Vloc_Rloc.OUT` (disks `DISKx`,
//!   contacts `DKDKx` and `DKJCx`);
//! - [`read_plain`]: the documented plain format `grainlaw-snapshot-v1` (one JSON per snapshot).
//!
//! Every reader fills a code-neutral [`Frame`] (grains by id, walls, contacts by force vector);
//! [`build_snapshots`] then makes the snapshots: contact normals, tangential and normal parts,
//! lever arms, and the accelerations that the inertia part of the stress needs
//! (`Σ_i = (I/(2V)) (−ω̇ j + ω² 𝟙)`, `docs/physics.md` §2.1). Accelerations come, in this order
//! of preference, from the file (forces and torques, `a = f/m`, `ω̇ = τ/I`), from a finite
//! difference of the velocities of consecutive snapshots (`a_k = (v_k − v_{k−1})/(t_k − t_{k−1})`,
//! the engine's own `(v⁺ − v⁻)/h`; the first snapshot takes the forward difference), or are set
//! to zero when there is a single snapshot and no force in the file; [`AccelerationSource`]
//! says which, per snapshot.

pub mod frame;
pub mod lammps;
pub mod lmgc90;
pub mod plain;

use std::path::Path;

pub use frame::{build_snapshots, ContactRecord, Frame, FrameCell, GrainRecord, Other, WallRecord};
pub use lammps::read_lammps;
pub use lmgc90::read_lmgc90;
pub use plain::read_plain;

use dem::snapshot::Snapshot;
use serde::Serialize;
use thiserror::Error;

/// What a reader cannot read. The message names the file, and the line when there is one.
#[derive(Debug, Error)]
pub enum ReadError {
    /// The file cannot be opened or decompressed.
    #[error("{file}: {reason}")]
    Io {
        /// The file.
        file: String,
        /// The operating system's message.
        reason: String,
    },
    /// A line of the file is not what the format says.
    #[error("{file}:{line}: {reason}")]
    Parse {
        /// The file.
        file: String,
        /// Line number (1-based).
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// The file (or a set of files) is readable but cannot make a snapshot: a missing column,
    /// a contact naming an unknown grain, snapshots that do not match.
    #[error("{file}: {reason}")]
    Content {
        /// The file (or files).
        file: String,
        /// What is wrong.
        reason: String,
    },
}

impl ReadError {
    pub(crate) fn parse(file: &Path, line: usize, reason: impl Into<String>) -> Self {
        ReadError::Parse {
            file: file.display().to_string(),
            line,
            reason: reason.into(),
        }
    }

    pub(crate) fn content(file: &Path, reason: impl Into<String>) -> Self {
        ReadError::Content {
            file: file.display().to_string(),
            reason: reason.into(),
        }
    }
}

/// Where the accelerations (and angular accelerations) of a snapshot come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AccelerationSource {
    /// From the file: forces and torques (`a = f/m`, `ω̇ = τ/I`) or accelerations.
    File,
    /// Backward difference of the velocities with the previous snapshot.
    BackwardDifference,
    /// Forward difference with the next snapshot (the first snapshot of a series).
    ForwardDifference,
    /// None available (a single snapshot without forces): set to zero, so the inertia part of
    /// the stress keeps only its centripetal term `(I/(2V)) ω² 𝟙`.
    Zero,
}

impl AccelerationSource {
    /// The name written in outputs (`file`, `backward_difference`, ...).
    pub fn name(self) -> &'static str {
        match self {
            AccelerationSource::File => "file",
            AccelerationSource::BackwardDifference => "backward_difference",
            AccelerationSource::ForwardDifference => "forward_difference",
            AccelerationSource::Zero => "zero",
        }
    }
}

/// Where the velocity gradient `L` of a biperiodic cell comes from (the affine field that the
/// kinetic stress and the shear rate of a representative volume refer to; `frame` module
/// documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GradientSource {
    /// The cell's own rate of deformation between consecutive snapshots, `L = ḣ h⁻¹` (for
    /// simple shear the tilt rate over the height, `γ̇ = ẋy / l_y`).
    CellDeformation,
    /// The mass-weighted affine fit of the grain velocities over the cell (a single snapshot,
    /// or snapshots without times).
    VelocityProfile,
    /// Neither (a single snapshot whose grains are too few or aligned for the fit): `L = 0`.
    Zero,
}

impl GradientSource {
    /// The name written in outputs: `cell_deformation`, `velocity_profile` or `zero`.
    pub fn name(self) -> &'static str {
        match self {
            GradientSource::CellDeformation => "cell_deformation",
            GradientSource::VelocityProfile => "velocity_profile",
            GradientSource::Zero => "zero",
        }
    }
}

/// A snapshot read from another code, with what the reader had to supply.
#[derive(Debug, Clone)]
pub struct ExternalSnapshot {
    /// The snapshot, ready for the homogenisation.
    pub snapshot: Snapshot,
    /// The ids the other code gave the grains, in the order of the snapshot's grain bodies.
    pub grain_ids: Vec<u64>,
    /// Where the accelerations come from.
    pub accelerations: AccelerationSource,
    /// Where the velocity gradient of the snapshot's biperiodic cell comes from (`None`
    /// without such a cell).
    pub velocity_gradient: Option<GradientSource>,
    /// The file(s) it was read from.
    pub source: String,
}

/// What the files do not say and the reader must be told.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    /// Gravity (m/s²), written into the snapshots (default `(0, −9.81)`).
    pub gravity: [f64; 2],
    /// Friction coefficient given to every contact, for the mobilisation `|f_t|/(μ f_n)`
    /// (default none: contacts count as frictionless, no mobilisation).
    pub mu: Option<f64>,
    /// Friction coefficient of the wall contacts, when the walls have their own (default:
    /// [`ReadOptions::mu`]).
    pub wall_mu: Option<f64>,
    /// Time step (s) of the simulation: times of LAMMPS dumps without `ITEM: TIME` are
    /// `step · dt`. Default: from the files when they tell it.
    pub dt: Option<f64>,
    /// Moment of inertia factor `k`, `I = k m R²`, for codes that do not write `I`
    /// (LAMMPS): 1/2 for disks (`fix nve/sphere disc`, the default), 2/5 for spheres.
    pub inertia_factor: f64,
    /// Grain density (kg/m³) for LMGC90 (the `Umas` of `BULK_BEHAV.DAT`); mass `ρ π avrd²`
    /// per metre of thickness.
    pub density: Option<f64>,
    /// Column names of LAMMPS local dumps: `(key, header)` pairs that override the default
    /// names (`docs/formats.md`).
    pub columns: Vec<(String, String)>,
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self {
            gravity: [0.0, -9.81],
            mu: None,
            wall_mu: None,
            dt: None,
            inertia_factor: 0.5,
            density: None,
            columns: Vec::new(),
        }
    }
}

/// The formats `grainlaw homogenise --from` reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// LAMMPS or LIGGGHTS text dumps.
    Lammps,
    /// LMGC90 2D output files.
    Lmgc90,
    /// grainlaw-snapshot-v1 JSON.
    Plain,
}

impl std::str::FromStr for Format {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "lammps" | "liggghts" => Ok(Format::Lammps),
            "lmgc90" => Ok(Format::Lmgc90),
            "plain" | "grainlaw" | "json" => Ok(Format::Plain),
            _ => Err(format!(
                "unknown format `{s}`: expected lammps, liggghts, lmgc90 or plain"
            )),
        }
    }
}

/// Reads `files` in the given format.
pub fn read(
    format: Format,
    files: &[std::path::PathBuf],
    opts: &ReadOptions,
) -> Result<Vec<ExternalSnapshot>, ReadError> {
    match format {
        Format::Lammps => read_lammps(files, opts),
        Format::Lmgc90 => read_lmgc90(files, opts),
        Format::Plain => read_plain(files, opts),
    }
}

/// The text of a file, gunzipped when its name ends in `.gz`.
pub fn read_text(path: &Path) -> Result<String, ReadError> {
    use std::io::Read;
    let io = |e: std::io::Error| ReadError::Io {
        file: path.display().to_string(),
        reason: e.to_string(),
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let mut text = String::new();
    if path.extension().is_some_and(|e| e == "gz") {
        flate2::read::MultiGzDecoder::new(std::io::BufReader::new(file))
            .read_to_string(&mut text)
            .map_err(io)?;
    } else {
        std::io::BufReader::new(file)
            .read_to_string(&mut text)
            .map_err(io)?;
    }
    Ok(text)
}

/// Parses a number of a text file, naming the file, line and what it is on failure.
pub(crate) fn number(file: &Path, line: usize, what: &str, text: &str) -> Result<f64, ReadError> {
    // Fortran writes exponents with D (0.1D+01).
    let t = text.trim();
    let v = if t.contains(['D', 'd']) {
        t.replace(['D', 'd'], "E").parse::<f64>()
    } else {
        t.parse::<f64>()
    };
    match v {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(ReadError::parse(
            file,
            line,
            format!("{what} is not finite: `{t}`"),
        )),
        Err(_) => Err(ReadError::parse(
            file,
            line,
            format!("{what}: `{t}` is not a number"),
        )),
    }
}
