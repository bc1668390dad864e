//! Snapshots of other DEM codes (LAMMPS/LIGGGHTS dumps, LMGC90 2D files, plain
//! grainlaw-snapshot-v1 JSON) read into [`Snapshot`]s, the input of the homogenisation
//! functions: the readers of `grainlaw homogenise --from` (`grainlaw_core::readers`,
//! docs/formats.md §7), and `homogenise`: the whole `grainlaw homogenise --from` (CSV tables,
//! figures, VTK, summary.json) from Python, the same Rust function
//! (`grainlaw_core::homogenise_cmd::homogenise`).

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::{cli_err, input, panic_err, OutputError};
use crate::world::Snapshot;

/// The reader options of `grainlaw homogenise`'s flags (`--mu`, `--wall-mu`, `--dt`,
/// `--gravity`, `--inertia-factor`, `--density`, `--column`).
#[allow(clippy::too_many_arguments)]
fn read_options(
    mu: Option<f64>,
    wall_mu: Option<f64>,
    dt: Option<f64>,
    gravity: (f64, f64),
    inertia_factor: f64,
    density: Option<f64>,
    columns: Option<std::collections::BTreeMap<String, String>>,
) -> grainlaw_core::readers::ReadOptions {
    grainlaw_core::readers::ReadOptions {
        gravity: [gravity.0, gravity.1],
        mu,
        wall_mu,
        dt,
        inertia_factor,
        density,
        columns: columns.unwrap_or_default().into_iter().collect(),
    }
}

/// read_snapshots(format, files, mu=None, dt=None, gravity=(0.0, -9.81), inertia_factor=0.5,
/// density=None, columns=None, wall_mu=None)
///
/// Reads the snapshots of another DEM code, as ``grainlaw homogenise --from FORMAT FILES``
/// does. ``format``: ``"lammps"`` (or ``"liggghts"``), ``"lmgc90"`` or ``"plain"``; ``files``:
/// paths (plain or gzip). ``mu``: friction coefficient given to every contact (for the
/// mobilisation); ``wall_mu``: that of the wall contacts when the walls have their own
/// (default ``mu``); ``dt`` (s): time step when the files do not give times; ``gravity`` (m/s²);
/// ``inertia_factor``: ``k`` in ``I = k m R²`` for codes that do not write ``I`` (1/2 disks,
/// 2/5 spheres); ``density`` (kg/m³): LMGC90's grain density; ``columns``: dict ``{key:
/// header}`` of LAMMPS local-dump column names.
///
/// LAMMPS cells are read from the dump headers (orthogonal or triclinic, periodic or not per
/// axis, docs/formats.md §7.1): pairs take the minimum image of the cell; a biperiodic cell is
/// the snapshot's ``cell`` (positions relative to its corner), over which the whole-sample
/// functions (``mean_stress``, ``solid_fraction`` without a region) average.
///
/// Returns a list, one dict per snapshot in time order: ``snapshot`` (a ``Snapshot``),
/// ``grain_ids`` (int64 array, the other code's ids, in the order of the snapshot's grains),
/// ``accelerations`` (``"file"``, ``"backward_difference"``, ``"forward_difference"`` or
/// ``"zero"``: where the inertia part of the stress takes ``ω̇`` from), ``velocity_gradient``
/// (``"cell_deformation"``, ``"velocity_profile"`` or None: where the velocity gradient of a
/// biperiodic cell comes from) and ``source`` (the file). Raises ``InputError`` naming the file
/// and line of what cannot be read.
#[pyfunction]
#[pyo3(signature = (format, files, mu=None, dt=None, gravity=(0.0, -9.81), inertia_factor=0.5, density=None, columns=None, wall_mu=None))]
#[allow(clippy::too_many_arguments)]
pub fn read_snapshots<'py>(
    py: Python<'py>,
    format: &str,
    files: Vec<PathBuf>,
    mu: Option<f64>,
    dt: Option<f64>,
    gravity: (f64, f64),
    inertia_factor: f64,
    density: Option<f64>,
    columns: Option<std::collections::BTreeMap<String, String>>,
    wall_mu: Option<f64>,
) -> PyResult<Bound<'py, PyList>> {
    let format: grainlaw_core::readers::Format = format.parse().map_err(input)?;
    let opts = read_options(mu, wall_mu, dt, gravity, inertia_factor, density, columns);
    let snaps = py
        .detach(|| grainlaw_core::readers::read(format, &files, &opts))
        .map_err(|e| input(e.to_string()))?;
    let list = PyList::empty(py);
    for s in snaps {
        let d = PyDict::new(py);
        d.set_item(
            "grain_ids",
            PyArray1::from_vec(py, s.grain_ids.iter().map(|&i| i as i64).collect()),
        )?;
        d.set_item("accelerations", s.accelerations.name())?;
        d.set_item("velocity_gradient", s.velocity_gradient.map(|g| g.name()))?;
        d.set_item("source", s.source)?;
        d.set_item("snapshot", Snapshot { inner: s.snapshot })?;
        list.append(d)?;
    }
    Ok(list)
}

/// homogenise(format, files, out, mu=None, dt=None, gravity=(0.0, -9.81), inertia_factor=0.5,
/// density=None, columns=None, wall_mu=None)
/// --
///
/// Homogenises the snapshots of another DEM code and writes every output of
/// ``grainlaw homogenise --from FORMAT FILES... --out OUT`` (the same Rust function): per
/// snapshot ``grains_STEP.csv``, a row of ``snapshots.csv``, a row per wall of ``walls.csv``
/// and a VTK frame (``vtk/*.vtp``, ``grains.pvd``, ``contacts.pvd``, ``walls.pvd``); for the
/// last snapshot ``stress_profile.csv`` and ``.png``, ``wall_profile_WALL.csv``,
/// ``mobilisation.csv`` (with ``mu``), ``coarse.csv``, ``grains.png``; ``janssen.csv`` for a
/// column between two vertical walls; ``rheology.csv`` (the point of μ(I), φ(I)) for a series
/// of a sheared biperiodic cell; ``summary.json`` last (files and keys in docs/outputs.md §4).
/// Stresses in Pa, tension positive.
///
/// ``format``, ``files`` and the options as in ``read_snapshots``; ``out``: the output
/// directory (str or os.PathLike; created if needed).
///
/// Returns a dict: ``summary`` (summary.json as a dict, read back by Python's ``json``: the
/// file's numbers bit for bit), ``files`` (``{name relative to out: full path}`` of every file
/// written, in the order written), ``headline`` (the report lines the CLI prints), ``out``.
/// The GIL is released while it runs.
///
/// Raises ``InputError`` (a file that cannot be read, naming file and line; an option out of
/// its domain; ``out`` a file), ``OutputError`` (a file that cannot be written), or the
/// ``GrainlawError`` (a refused result) when the simple-shear point is refused, every
/// file written.
#[pyfunction]
#[pyo3(signature = (format, files, out, mu=None, dt=None, gravity=(0.0, -9.81), inertia_factor=0.5, density=None, columns=None, wall_mu=None))]
#[allow(clippy::too_many_arguments)]
pub fn homogenise<'py>(
    py: Python<'py>,
    format: &str,
    files: Vec<PathBuf>,
    out: PathBuf,
    mu: Option<f64>,
    dt: Option<f64>,
    gravity: (f64, f64),
    inertia_factor: f64,
    density: Option<f64>,
    columns: Option<std::collections::BTreeMap<String, String>>,
    wall_mu: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let format: grainlaw_core::readers::Format = format.parse().map_err(input)?;
    let plan = grainlaw_core::homogenise_cmd::HomogenisePlan {
        format,
        files,
        out: out.clone(),
        options: read_options(mu, wall_mu, dt, gravity, inertia_factor, density, columns),
        quiet: true,
    };
    let outcome = py
        .detach(|| {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                grainlaw_core::homogenise_cmd::homogenise(&plan)
            }))
        })
        .map_err(panic_err)?
        .map_err(|e| cli_err(py, e))?;
    let summary_path = out.join("summary.json");
    let text = std::fs::read_to_string(&summary_path)
        .map_err(|e| OutputError::new_err(format!("{}: {e}", summary_path.display())))?;
    let result = PyDict::new(py);
    result.set_item(
        "summary",
        py.import("json")?.call_method1("loads", (text,))?,
    )?;
    let written = PyDict::new(py);
    for f in &outcome.files {
        written.set_item(f, out.join(f).display().to_string())?;
    }
    result.set_item("files", written)?;
    result.set_item("headline", outcome.lines)?;
    result.set_item("out", out.display().to_string())?;
    Ok(result)
}

/// _synthetic_lammps_dump(n)
/// --
///
/// The synthetic LAMMPS dump of `grainlaw bench --homogenise-grains N`
/// (`grainlaw_core::homogenise_cmd::synthetic_lammps_dump`): ``(atoms, pairs)``, the texts of the
/// per-atom and local dumps of ``n`` disks of radius 0.5 mm on a square lattice of spacing
/// 0.999 mm, each touching its right and upper neighbours (about ``2 n`` contacts). For the
/// benchmarks (python/bench/overhead.py), not part of the public API.
#[pyfunction]
#[pyo3(name = "_synthetic_lammps_dump")]
pub fn synthetic_lammps_dump(n: usize) -> (String, String) {
    grainlaw_core::homogenise_cmd::synthetic_lammps_dump(n)
}
