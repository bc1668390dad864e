//! `grainlaw._grainlaw`: the compiled part of the Python package `grainlaw` (PyO3 + numpy).
//!
//! The package (`python/grainlaw/__init__.py`) re-exports everything here and adds the
//! per-law fit functions. The pieces:
//!
//! - [`run`]: `run(scenario, overrides, out, progress, allow_suspect)`: a scenario end to end,
//!   as `grainlaw run` (`grainlaw_core::api::run_scenario`), the GIL released; a run
//!   whose verdict the command line would exit 3 for raises `ResultRefused` / `ResultSuspect`;
//! - [`world`]: `World` and `Snapshot` over `dem::World` and `dem::Snapshot`;
//! - [`homog`]: per-grain and region mean stress (contact + inertia parts), solid fraction,
//!   coordination and fabric (`homogenise`);
//! - [`readers`]: `read_snapshots` (other codes' files as `Snapshot`s) and `homogenise`
//!   (`grainlaw homogenise --from`: every output written, the GIL released);
//! - [`fit`]: the fits of `identify` from numpy columns and `Law`, the calibrated-law JSON
//!   (schemas 1 and 2) with vectorised evaluation;
//! - [`continuum`]: `continuum(case, law, ...)`: a μ(I) law run in Gerris (`grainlaw continuum`,
//!   library crate `grainlaw_core::continuum`), the GIL released;
//! - [`errors`]: the exception hierarchy (`GrainlawError` and its subclasses).
//!
//! Units SI, 2D quantities per metre of thickness, stresses tension positive (the fits take
//! compressive-positive magnitudes, as `grainlaw fit` does).

use pyo3::prelude::*;

mod arrays;
mod continuum;
mod errors;
mod fit;
mod homog;
mod readers;
mod run;
mod world;

/// The extension module.
#[pymodule]
fn _grainlaw(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("GrainlawError", py.get_type::<errors::GrainlawError>())?;
    m.add("InputError", py.get_type::<errors::InputError>())?;
    m.add("FitRefused", py.get_type::<errors::FitRefused>())?;
    m.add("SolverError", py.get_type::<errors::SolverError>())?;
    m.add("OutputError", py.get_type::<errors::OutputError>())?;
    m.add("ResultRefused", py.get_type::<errors::ResultRefused>())?;
    m.add("ResultSuspect", py.get_type::<errors::ResultSuspect>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(run::scenarios, m)?)?;
    m.add_class::<world::World>()?;
    m.add_class::<world::Snapshot>()?;
    m.add_function(wrap_pyfunction!(homog::grain_stresses, m)?)?;
    m.add_function(wrap_pyfunction!(homog::mean_stress, m)?)?;
    m.add_function(wrap_pyfunction!(homog::solid_fraction, m)?)?;
    m.add_function(wrap_pyfunction!(homog::coordination, m)?)?;
    m.add_function(wrap_pyfunction!(homog::fabric, m)?)?;
    m.add_function(wrap_pyfunction!(readers::read_snapshots, m)?)?;
    m.add_function(wrap_pyfunction!(readers::homogenise, m)?)?;
    m.add_function(wrap_pyfunction!(readers::synthetic_lammps_dump, m)?)?;
    m.add_class::<fit::Law>()?;
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    m.add_function(wrap_pyfunction!(fit::load_law, m)?)?;
    m.add_function(wrap_pyfunction!(fit::law_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(continuum::continuum, m)?)?;
    Ok(())
}
