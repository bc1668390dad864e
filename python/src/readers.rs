//! Snapshots of other DEM codes (LAMMPS/LIGGGHTS dumps, LMGC90 2D files, plain
//! grainlaw-snapshot-v1 JSON) read into [`Snapshot`]s, the input of the homogenisation
//! functions: the readers of `grainlaw homogenise --from` (`grainlaw::readers`,
//! docs/formats.md §7).

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::input;
use crate::world::Snapshot;

/// read_snapshots(format, files, mu=None, dt=None, gravity=(0.0, -9.81), inertia_factor=0.5,
/// density=None, columns=None)
///
/// Reads the snapshots of another DEM code, as ``grainlaw homogenise --from FORMAT FILES``
/// does. ``format``: ``"lammps"`` (or ``"liggghts"``), ``"lmgc90"`` or ``"plain"``; ``files``:
/// paths (plain or gzip). ``mu``: friction coefficient given to every contact (for the
/// mobilisation); ``dt`` (s): time step when the files do not give times; ``gravity`` (m/s²);
/// ``inertia_factor``: ``k`` in ``I = k m R²`` for codes that do not write ``I`` (1/2 disks,
/// 2/5 spheres); ``density`` (kg/m³): LMGC90's grain density; ``columns``: dict ``{key:
/// header}`` of LAMMPS local-dump column names.
///
/// Returns a list, one dict per snapshot in time order: ``snapshot`` (a ``Snapshot``),
/// ``grain_ids`` (int64 array, the other code's ids, in the order of the snapshot's grains),
/// ``accelerations`` (``"file"``, ``"backward_difference"``, ``"forward_difference"`` or
/// ``"zero"``: where the inertia part of the stress takes ``ω̇`` from) and ``source`` (the
/// file). Raises ``InputError`` naming the file and line of what cannot be read.
#[pyfunction]
#[pyo3(signature = (format, files, mu=None, dt=None, gravity=(0.0, -9.81), inertia_factor=0.5, density=None, columns=None))]
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
) -> PyResult<Bound<'py, PyList>> {
    let format: grainlaw::readers::Format = format.parse().map_err(input)?;
    let opts = grainlaw::readers::ReadOptions {
        gravity: [gravity.0, gravity.1],
        mu,
        dt,
        inertia_factor,
        density,
        columns: columns.unwrap_or_default().into_iter().collect(),
    };
    let snaps = py
        .detach(|| grainlaw::readers::read(format, &files, &opts))
        .map_err(|e| input(e.to_string()))?;
    let list = PyList::empty(py);
    for s in snaps {
        let d = PyDict::new(py);
        d.set_item(
            "grain_ids",
            PyArray1::from_vec(py, s.grain_ids.iter().map(|&i| i as i64).collect()),
        )?;
        d.set_item("accelerations", s.accelerations.name())?;
        d.set_item("source", s.source)?;
        d.set_item("snapshot", Snapshot { inner: s.snapshot })?;
        list.append(d)?;
    }
    Ok(list)
}
