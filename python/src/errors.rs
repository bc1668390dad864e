//! The exception hierarchy of the package and the mapping of the crates' typed errors onto it.
//!
//! ```text
//! Exception
//! └── GrainlawError            every error raised by grainlaw
//!     ├── InputError           bad input: scenario, override, TOML, array, metadata, law JSON
//!     ├── FitRefused           valid data, but the fit was refused (reason, suggestion)
//!     ├── SolverError          the engine failed during a step (non-finite state, ...)
//!     ├── OutputError          a file could not be written or read
//!     ├── ResultRefused        a run finished with the verdict `refused` (exit status 3)
//!     └── ResultSuspect        a run finished `suspect` without `allow_suspect=True` (exit 3)
//! ```
//!
//! `ResultRefused` and `ResultSuspect` carry `verdict` (str), `reasons` (the failed checks,
//! `summary.json`'s `verdict_reasons`: dicts `check`, `verdict`, `value`, `threshold`,
//! `message`) and `result` (what `run` would have returned: every file was written).
//!
//! A run stopped by Ctrl-C raises `KeyboardInterrupt` (a checkpoint is left in the output
//! directory). A panic inside Rust (a bug) never crashes the interpreter: in `run` and
//! `World.step`, the long computations, it is caught and raised as a `GrainlawError` naming it;
//! elsewhere pyo3 raises it as `pyo3_runtime.PanicException`.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyKeyboardInterrupt};
use pyo3::prelude::*;

use grainlaw_core::CliError;

create_exception!(
    grainlaw,
    GrainlawError,
    PyException,
    "Base class of every error raised by grainlaw."
);
create_exception!(
    grainlaw,
    InputError,
    GrainlawError,
    "Bad input: unknown scenario or key, an override or TOML value out of its domain, arrays of \
     the wrong shape or with non-finite values, a missing metadata value, a malformed law JSON."
);
create_exception!(
    grainlaw,
    FitRefused,
    GrainlawError,
    "The data were valid but the fit was refused (not identifiable, a parameter at its bound, \
     an interval crossing a physical bound, R² too low, ...). Attributes: `reason` (str) and \
     `suggestion` (the simpler form to fit, or None)."
);
create_exception!(
    grainlaw,
    SolverError,
    GrainlawError,
    "The engine failed during a step (a non-finite state, a checkpoint that cannot be used), or \
     an external solver (Gerris) is missing or failed."
);
create_exception!(
    grainlaw,
    OutputError,
    GrainlawError,
    "A file could not be written or read (output directory, figure, CSV, law file)."
);

create_exception!(
    grainlaw,
    ResultRefused,
    GrainlawError,
    "A run finished with the verdict `refused` (a check failed by far, or a law could not be \
     fitted): as `grainlaw run` exits with status 3. Attributes: `verdict` ('refused'), \
     `reasons` (list of dicts: check, verdict, value, threshold, message) and `result` (the dict \
     `run` returns: every file was written, its laws under `rejected_laws`)."
);
create_exception!(
    grainlaw,
    ResultSuspect,
    GrainlawError,
    "A run finished with the verdict `suspect` and `allow_suspect` was not set: as `grainlaw run` \
     exits with status 3 without `--allow-suspect`. Attributes as `ResultRefused` (`verdict` \
     'suspect')."
);

/// The error of a run whose `verdict` (`refused`, or `suspect` when not allowed) is `raise`d:
/// [`ResultRefused`] or [`ResultSuspect`] with the message `line` and the attributes `verdict`,
/// `reasons`, `result`.
pub fn verdict_err<'py>(
    py: Python<'py>,
    verdict: &str,
    line: String,
    reasons: Bound<'py, PyAny>,
    result: Bound<'py, PyAny>,
) -> PyErr {
    let err = if verdict == "refused" {
        ResultRefused::new_err(line)
    } else {
        ResultSuspect::new_err(line)
    };
    let value = err.value(py);
    // As in `refused`: setting attributes on a fresh instance cannot fail short of memory.
    let _ = value.setattr("verdict", verdict);
    let _ = value.setattr("reasons", reasons);
    let _ = value.setattr("result", result);
    err
}

/// An [`InputError`] with `msg`.
pub fn input(msg: impl Into<String>) -> PyErr {
    InputError::new_err(msg.into())
}

/// A [`FitRefused`] with `reason` and `suggestion` set as attributes.
fn refused(py: Python<'_>, reason: String, suggestion: Option<&str>) -> PyErr {
    let err = FitRefused::new_err(reason.clone());
    let value = err.value(py);
    // Setting attributes on a fresh exception instance cannot fail short of memory exhaustion;
    // the message carries the same text anyway.
    let _ = value.setattr("reason", reason);
    let _ = value.setattr("suggestion", suggestion);
    err
}

/// Maps an identification error: a refusal ([`identify::IdentifyError::is_refusal`]) to
/// [`FitRefused`], an unreadable law file to [`OutputError`], anything else to [`InputError`].
pub fn identify_err(py: Python<'_>, e: identify::IdentifyError) -> PyErr {
    let msg = one_line(&e.to_string());
    if e.is_refusal() {
        refused(py, msg, e.suggestion())
    } else if matches!(e, identify::IdentifyError::Io { .. }) {
        OutputError::new_err(msg)
    } else {
        InputError::new_err(msg)
    }
}

/// Maps an engine error: a world that cannot be built or stepped as given (parameters, bodies,
/// overlaps at the start) is an [`InputError`]; a failure during a step is a [`SolverError`].
pub fn dem_err(e: dem::DemError) -> PyErr {
    let msg = one_line(&e.to_string());
    match e {
        dem::DemError::Parameter { .. }
        | dem::DemError::Body { .. }
        | dem::DemError::Overlap { .. }
        | dem::DemError::Outside { .. } => InputError::new_err(msg),
        _ => SolverError::new_err(msg),
    }
}

/// Maps a homogenisation error (always about its input: a region, a snapshot, a parameter).
pub fn homogenise_err(e: homogenise::HomogeniseError) -> PyErr {
    InputError::new_err(one_line(&e.to_string()))
}

/// Maps an error of a scenario run.
pub fn cli_err(py: Python<'_>, e: CliError) -> PyErr {
    let msg = e.one_line();
    match e {
        CliError::Dataset(_) | CliError::Usage(_) | CliError::Input { .. } => {
            InputError::new_err(msg)
        }
        CliError::Dem(d) => dem_err(d),
        CliError::Homogenise(h) => homogenise_err(h),
        CliError::Identify(i) => identify_err(py, i),
        CliError::FitRefused { reason, .. } => refused(py, reason, None),
        CliError::Interrupted { .. } => PyKeyboardInterrupt::new_err(msg),
        CliError::Fc(_)
        | CliError::NotConverged { .. }
        | CliError::Checkpoint { .. }
        | CliError::ExternalSolver { .. } => SolverError::new_err(msg),
        CliError::Io { .. } | CliError::Plot { .. } => OutputError::new_err(msg),
        // `run` raises a run's verdict itself, with its result (`verdict_err`); the library
        // returns it in the outcome, never as this error.
        CliError::Verdict { .. } => GrainlawError::new_err(msg),
        CliError::CampaignStopped { .. } => PyKeyboardInterrupt::new_err(msg),
    }
}

/// A panic payload caught at the boundary, as a [`GrainlawError`].
pub fn panic_err(payload: Box<dyn std::any::Any + Send>) -> PyErr {
    let msg = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into());
    GrainlawError::new_err(format!(
        "internal error (a bug in grainlaw): {}",
        one_line(&msg)
    ))
}

/// Runs of whitespace folded to one space.
pub fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}
