//! `grainlaw.run`: a scenario end to end, as `grainlaw run` does it.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::time::Duration;

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use crate::arrays::out1;
use crate::errors::{cli_err, identify_err, input, panic_err, verdict_err, OutputError};
use crate::fit::Law;

/// One override value as TOML text: bool, int, float (its `repr`, which reads back to the same
/// number), str (as is: a bare word is read as a string, quotes are optional), or a list/tuple
/// of those.
fn toml_value(v: &Bound<'_, PyAny>, key: &str) -> PyResult<String> {
    if v.is_instance_of::<PyBool>() {
        Ok(if v.extract::<bool>()? {
            "true"
        } else {
            "false"
        }
        .into())
    } else if v.is_instance_of::<PyInt>() {
        Ok(v.str()?.to_string())
    } else if v.is_instance_of::<PyFloat>() {
        Ok(v.repr()?.to_string())
    } else if v.is_instance_of::<PyString>() {
        Ok(v.extract::<String>()?)
    } else if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v
            .try_iter()?
            .map(|x| toml_value(&x?, key))
            .collect::<PyResult<Vec<_>>>()?;
        Ok(format!("[{}]", items.join(", ")))
    } else {
        Err(input(format!(
            "override `{key}`: a bool, int, float, str or list is expected, got {}",
            v.get_type().name()?
        )))
    }
}

/// `{"grains": 200, "grain.radius_mean": 1e-3}` (or a list of `"KEY=VALUE"` strings) as the
/// command line's `--set KEY=VALUE` arguments.
fn override_args(overrides: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<String>> {
    let Some(o) = overrides else {
        return Ok(Vec::new());
    };
    if let Ok(d) = o.cast::<PyDict>() {
        d.iter()
            .map(|(k, v)| {
                let key: String = k
                    .extract()
                    .map_err(|_| input("overrides: every key must be a str"))?;
                Ok(format!("{key}={}", toml_value(&v, &key)?))
            })
            .collect()
    } else if o.is_none() {
        Ok(Vec::new())
    } else {
        o.try_iter()
            .map_err(|_| input("overrides: a dict {key: value} or a list of \"KEY=VALUE\""))?
            .map(|x| {
                x?.extract::<String>()
                    .map_err(|_| input("overrides: a list must hold \"KEY=VALUE\" strings"))
            })
            .collect()
    }
}

/// Runs the scenario on a worker thread with the GIL released; the calling thread checks for
/// Python signals every 0.1 s and turns a Ctrl-C into a clean stop (checkpoint written), then
/// re-raises it.
fn run_released(
    py: Python<'_>,
    spec: &str,
    sets: &[String],
    dir: &Path,
    quiet: bool,
    allow_suspect: bool,
) -> PyResult<grainlaw_core::scenarios::RunOutcome> {
    let flag = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel();
    let (result, interrupt) = std::thread::scope(|s| {
        let worker_flag = flag.clone();
        s.spawn(move || {
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                grainlaw_core::api::run_scenario(spec, sets, dir, quiet, allow_suspect, worker_flag)
            }));
            let _ = tx.send(r);
        });
        let mut interrupt: Option<PyErr> = None;
        // The receiver is moved into each detached wait and back (it is Send, not Sync).
        let mut rx = rx;
        loop {
            let (got, back) = py.detach(move || (rx.recv_timeout(Duration::from_millis(100)), rx));
            rx = back;
            match got {
                Ok(r) => break (Some(r), interrupt),
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if interrupt.is_none() {
                        if let Err(e) = py.check_signals() {
                            flag.store(true, Ordering::SeqCst);
                            interrupt = Some(e);
                        }
                    }
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => break (None, interrupt),
            }
        }
    });
    match result {
        None => Err(crate::errors::GrainlawError::new_err(
            "internal error: the run's thread ended without a result",
        )),
        Some(Err(payload)) => Err(panic_err(payload)),
        // An interrupted run gives CliError::Interrupted (KeyboardInterrupt naming the
        // checkpoint); any other error is raised as it is.
        Some(Ok(Err(e))) => Err(cli_err(py, e)),
        Some(Ok(Ok(outcome))) => match interrupt {
            // The signal came after the last step: the run is complete, raise it now.
            Some(ki) => Err(ki),
            None => Ok(outcome),
        },
    }
}

fn read_text(path: &Path) -> PyResult<String> {
    std::fs::read_to_string(path)
        .map_err(|e| OutputError::new_err(format!("{}: {e}", path.display())))
}

/// Everything a run wrote that Python wants back: `summary.json` as a dict (parsed by Python's
/// `json`, so its numbers are the file's, bit for bit), every CSV table as a dict of arrays
/// with its `# key = value` constants, every calibrated law (`laws`) and every law written as
/// `NAME_law.rejected.json` (`rejected_laws`), the verdict and its reasons.
fn collect<'py>(
    py: Python<'py>,
    dir: &Path,
    outcome: &grainlaw_core::scenarios::RunOutcome,
) -> PyResult<Bound<'py, PyDict>> {
    let result = PyDict::new(py);
    let json = py.import("json")?;
    let summary = json.call_method1("loads", (read_text(&dir.join("summary.json"))?,))?;
    result.set_item("summary", &summary)?;
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| OutputError::new_err(format!("{}: {e}", dir.display())))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    let tables = PyDict::new(py);
    let constants = PyDict::new(py);
    let laws = PyDict::new(py);
    let rejected = PyDict::new(py);
    for path in entries {
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default()
            .to_string();
        let name = path
            .file_name()
            .and_then(|s| s.to_str())
            .unwrap_or_default();
        if name.ends_with(".csv") {
            let t = grainlaw_core::api::read_csv_table(&path).map_err(|e| cli_err(py, e))?;
            let cols = PyDict::new(py);
            for (h, c) in t.headers.into_iter().zip(t.columns) {
                cols.set_item(h, out1(py, c))?;
            }
            tables.set_item(&stem, cols)?;
            let k = PyDict::new(py);
            for (key, v) in t.constants {
                k.set_item(key, v)?;
            }
            constants.set_item(&stem, k)?;
        } else if name.ends_with("_law.json") {
            let law = identify::CalibratedLaw::load(&path).map_err(|e| identify_err(py, e))?;
            laws.set_item(&stem, Law { inner: law })?;
        } else if let Some(base) = name.strip_suffix("_law.rejected.json") {
            let law = identify::CalibratedLaw::load(&path).map_err(|e| identify_err(py, e))?;
            rejected.set_item(format!("{base}_law"), Law { inner: law })?;
        }
    }
    result.set_item("tables", tables)?;
    result.set_item("constants", constants)?;
    result.set_item("laws", laws)?;
    result.set_item("rejected_laws", rejected)?;
    result.set_item("headline", outcome.headline.clone())?;
    result.set_item("verdict", outcome.verdict.verdict().as_str())?;
    result.set_item("verdict_reasons", summary.get_item("verdict_reasons")?)?;
    result.set_item("verdict_lines", outcome.verdict.lines())?;
    Ok(result)
}

/// run(scenario="janssen", overrides=None, out=None, progress=False, allow_suspect=False)
/// --
///
/// Runs a scenario end to end, exactly as `grainlaw run SCENARIO --out OUT --set KEY=VALUE ...`
/// (same seed, same files, same `summary.json` except `wall_seconds`), and is as loud about its
/// verdict as the command line's exit status: a run judged ``refused`` raises ResultRefused, a
/// run judged ``suspect`` raises ResultSuspect unless ``allow_suspect=True`` (then its suspect
/// laws are exported as laws, marked suspect, as with ``--allow-suspect``). The exception
/// carries ``verdict``, ``reasons`` and ``result``, the dict below (every file is written).
///
/// Parameters
/// ----------
/// scenario : str
///     A built-in scenario (`grainlaw.scenarios()`) or the path of a scenario TOML file.
/// overrides : dict or list of str, optional
///     Scenario keys to override, e.g. ``{"grains": 200, "grain.radius_mean": 1e-3}`` (dotted
///     keys for tables, SI units as in the TOML) or ``["grains=200"]``.
/// out : str or os.PathLike, optional
///     Output directory (CSV, figures, VTK, laws, summary.json). None: a temporary directory,
///     read back and removed.
/// progress : bool
///     Print the phase lines on stderr (warnings are printed in any case).
/// allow_suspect : bool
///     Return a ``suspect`` run instead of raising (``--allow-suspect``); ``refused`` always
///     raises.
///
/// Returns
/// -------
/// dict
///     ``summary``: summary.json as a dict (keys and units in docs/outputs.md);
///     ``tables``: ``{file stem: {column header: numpy array}}`` for every CSV written
///     (histories, profiles; the unit is in each header, e.g. ``sigma_v_Pa``);
///     ``constants``: ``{file stem: {key: value}}`` from the tables' ``# key = value`` lines;
///     ``laws``: ``{file stem: Law}`` for every calibrated law written (``NAME_law.json``);
///     ``rejected_laws``: the same for the laws written as ``NAME_law.rejected.json`` (not
///     calibrated: their ``verdict`` says why);
///     ``verdict``: ``ok``, ``suspect`` (with ``allow_suspect=True``) or, on the exceptions'
///     ``result``, ``refused``; ``verdict_reasons``: the failed checks (dicts ``check``,
///     ``verdict``, ``value``, ``threshold``, ``message``); ``verdict_lines``: the verdict block
///     the CLI prints; ``headline``: the report lines the CLI prints; ``out``: the directory,
///     or None.
///
/// The GIL is released during the run. Ctrl-C stops it after the current step (a checkpoint is
/// left in ``out``) and raises KeyboardInterrupt.
///
/// Raises
/// ------
/// ResultRefused, ResultSuspect (the verdict), InputError, SolverError, OutputError
#[pyfunction]
#[pyo3(signature = (scenario="janssen", overrides=None, out=None, progress=false, allow_suspect=false))]
pub fn run<'py>(
    py: Python<'py>,
    scenario: &str,
    overrides: Option<&Bound<'py, PyAny>>,
    out: Option<PathBuf>,
    progress: bool,
    allow_suspect: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let sets = override_args(overrides)?;
    // Without `out`, a temporary directory removed when `_temp` is dropped.
    let (dir, _temp) = match &out {
        Some(d) => (d.clone(), None),
        None => {
            let t = tempfile::Builder::new()
                .prefix("grainlaw-run-")
                .tempdir()
                .map_err(|e| OutputError::new_err(format!("temporary directory: {e}")))?;
            (t.path().to_path_buf(), Some(t))
        }
    };
    let outcome = run_released(py, scenario, &sets, &dir, !progress, allow_suspect)?;
    let result = collect(py, &dir, &outcome)?;
    let out_name = out.map(|d| d.display().to_string());
    result.set_item("out", out_name.clone())?;
    // As loud as the command line's exit status (`RunVerdict::passes`).
    if !outcome.verdict.passes() {
        let verdict = outcome.verdict.verdict().as_str();
        let line = format!(
            "{}: {}{}",
            out_name.unwrap_or_else(|| scenario.to_string()),
            outcome.verdict.failure_line(),
            if verdict == "suspect" {
                " (allow_suspect=True returns it)"
            } else {
                ""
            }
        );
        let reasons = result
            .get_item("verdict_reasons")?
            .unwrap_or_else(|| PyList::empty(py).into_any());
        return Err(verdict_err(py, verdict, line, reasons, result.into_any()));
    }
    Ok(result)
}

/// scenarios()
/// --
///
/// The built-in scenarios: ``{name: description}``. Their full TOML (every key, with units) is
/// printed by ``grainlaw scenarios --show NAME``.
#[pyfunction]
pub fn scenarios(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    for s in grainlaw_core::scenarios::registry::SCENARIOS.iter() {
        d.set_item(s.name(), s.description())?;
    }
    Ok(d)
}
