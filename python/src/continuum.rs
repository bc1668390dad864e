//! `grainlaw.continuum`: a calibrated μ(I) law run in Gerris, as `grainlaw continuum` does it
//! (the library crate, `grainlaw_core::continuum`).

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use pyo3::types::PyDict;

use grainlaw_core::continuum::dem_column::{group_profiles, read_rows, FrontRow, ProfileRow};
use grainlaw_core::continuum::{
    column_collapse, inclined_plane, CaseInputs, ColumnPlan, InclinedPlan,
};
use grainlaw_core::verdict::{RunVerdict, Verdict};

use crate::arrays::out1;
use crate::errors::{cli_err, input, panic_err, verdict_err, OutputError};

fn read_text(path: &Path) -> PyResult<String> {
    std::fs::read_to_string(path)
        .map_err(|e| OutputError::new_err(format!("{}: {e}", path.display())))
}

/// Runs `f` with the GIL released: its error as the Python error of [`cli_err`], a panic as
/// that of [`panic_err`].
fn detached<T: Send>(
    py: Python<'_>,
    f: impl FnOnce() -> grainlaw_core::error::Result<T> + Send,
) -> PyResult<T> {
    match py.detach(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f))) {
        Err(p) => Err(panic_err(p)),
        Ok(Err(e)) => Err(cli_err(py, e)),
        Ok(Ok(o)) => Ok(o),
    }
}

/// The columns of a numeric CSV the run wrote, as arrays (absent file: None).
fn table<'py>(py: Python<'py>, path: &Path) -> PyResult<Option<Bound<'py, PyDict>>> {
    if !path.is_file() {
        return Ok(None);
    }
    let t = grainlaw_core::api::read_csv_table(path).map_err(|e| cli_err(py, e))?;
    let cols = PyDict::new(py);
    for (h, c) in t.headers.into_iter().zip(t.columns) {
        cols.set_item(h, out1(py, c))?;
    }
    Ok(Some(cols))
}

/// The result dict of a finished run in `dir`.
fn collect<'py>(
    py: Python<'py>,
    dir: &Path,
    lines: Vec<String>,
    warnings: Vec<String>,
    verdict: &RunVerdict,
) -> PyResult<Bound<'py, PyDict>> {
    let result = PyDict::new(py);
    let json = py.import("json")?;
    let summary = json.call_method1("loads", (read_text(&dir.join("summary.json"))?,))?;
    result.set_item("summary", &summary)?;
    let front = dir.join("front.csv");
    if front.is_file() {
        let rows: Vec<FrontRow> = read_rows(&front).map_err(|e| cli_err(py, e))?;
        let d = PyDict::new(py);
        d.set_item("t_s", out1(py, rows.iter().map(|r| r.t_s).collect()))?;
        d.set_item("t_star", out1(py, rows.iter().map(|r| r.t_star).collect()))?;
        d.set_item("x_f_m", out1(py, rows.iter().map(|r| r.x_f_m).collect()))?;
        result.set_item("front", d)?;
    }
    let profiles = dir.join("profiles.csv");
    if profiles.is_file() {
        let rows: Vec<ProfileRow> = read_rows(&profiles).map_err(|e| cli_err(py, e))?;
        let d = PyDict::new(py);
        for (label, p) in group_profiles(rows) {
            let one = PyDict::new(py);
            one.set_item("t_star", p.t_star)?;
            one.set_item("x_m", out1(py, p.points.iter().map(|q| q.0).collect()))?;
            one.set_item("h_m", out1(py, p.points.iter().map(|q| q.1).collect()))?;
            d.set_item(label, one)?;
        }
        result.set_item("profiles", d)?;
    }
    let cmp = dir.join("comparison.json");
    if cmp.is_file() {
        result.set_item(
            "comparison",
            json.call_method1("loads", (read_text(&cmp)?,))?,
        )?;
    }
    result.set_item("band", table(py, &dir.join("band.csv"))?)?;
    result.set_item("profile", table(py, &dir.join("profile.csv"))?)?;
    result.set_item("verdict", verdict.verdict().as_str())?;
    result.set_item("verdict_reasons", summary.get_item("verdict_reasons")?)?;
    result.set_item("verdict_lines", verdict.lines())?;
    result.set_item("lines", lines)?;
    result.set_item("warnings", warnings)?;
    result.set_item("out", dir.to_path_buf())?;
    Ok(result)
}

/// continuum(case, law, out=None, *, dem=None, solver="gerris", packing_fraction=None, level=None, aspect_ratio=None, half_width=None, domain=None, t_end=None, viscosity_cap=None, band=False, jobs=None, slope_deg=None, depth=None, gerris=None, allow_suspect=False)
/// --
///
/// Runs a calibrated μ(I) law in the continuum solver Gerris, exactly as ``grainlaw continuum
/// CASE --law LAW --out OUT ...`` (docs/continuum.md), and is as loud about its verdict as the
/// command line's exit status: ``refused`` raises ResultRefused, ``suspect`` (the law used far
/// outside its calibrated range of I) raises ResultSuspect unless ``allow_suspect=True``.
/// Warnings (the run leaving the law's range, grains unlike the DEM's) are issued with
/// ``warnings.warn`` and listed in the result.
///
/// Parameters
/// ----------
/// case : str
///     ``"column-collapse"`` or ``"inclined-plane"``.
/// law : str or os.PathLike
///     The μ(I) law JSON (schema 2, ``mu-i`` or ``mu-i-linear``: a run's ``mu_i_law.json``).
/// out : str or os.PathLike, optional
///     Output directory (default ``grainlaw-out/continuum-CASE``); the Gerris case is in
///     ``out/gerris``.
/// dem : str or os.PathLike, optional
///     A DEM ``column-collapse`` (or ``inclined-flow``) output directory to compare with and
///     take the set-up from.
/// solver : str
///     Only ``"gerris"``.
/// packing_fraction : float, optional
///     φ of the continuum (its density φ ρ_s); needed without ``dem``.
/// level : int, optional
///     Gerris refinement level (default 8 for the column, 6 for the plane).
/// aspect_ratio, half_width, domain, t_end, band, jobs : column options (a, R0 in metres, the
///     domain's side in R0, the end in t*, the uncertainty band and its parallel runs).
/// slope_deg, depth : inclined-plane options (degrees, metres).
/// viscosity_cap : float, optional
///     Cap of the μ(I) viscosity in Gerris units (default 10 for the column, 1000 for the plane).
/// gerris : str or os.PathLike, optional
///     The Gerris 2D command (default ``gerris2D``).
/// allow_suspect : bool
///     Return a ``suspect`` run instead of raising.
///
/// Returns
/// -------
/// dict
///     ``summary`` (summary.json), ``front`` (arrays ``t_s``, ``t_star``, ``x_f_m``),
///     ``profiles`` (``{label: {"t_star", "x_m", "h_m"}}``, labels ``t0.66`` … and ``end``),
///     ``comparison`` (comparison.json, with ``dem``), ``band`` (band.csv's arrays, with
///     ``band=True``), ``profile`` (the plane's velocity profile arrays), ``verdict``,
///     ``verdict_reasons``, ``verdict_lines``, ``lines`` (the report), ``warnings``, ``out``.
///
/// The GIL is released while Gerris runs.
///
/// Raises
/// ------
/// InputError (bad input: a law that is not μ(I) or lacks d and rho_s, a missing packing
/// fraction, no steady flow on the slope, ...), SolverError (Gerris missing or failing; the
/// case is left in ``out/gerris``), OutputError, ResultRefused, ResultSuspect
#[pyfunction]
#[pyo3(signature = (case, law, out=None, *, dem=None, solver="gerris", packing_fraction=None, level=None, aspect_ratio=None, half_width=None, domain=None, t_end=None, viscosity_cap=None, band=false, jobs=None, slope_deg=None, depth=None, gerris=None, allow_suspect=false))]
#[allow(clippy::too_many_arguments)]
pub fn continuum<'py>(
    py: Python<'py>,
    case: &str,
    law: PathBuf,
    out: Option<PathBuf>,
    dem: Option<PathBuf>,
    solver: &str,
    packing_fraction: Option<f64>,
    level: Option<u32>,
    aspect_ratio: Option<f64>,
    half_width: Option<f64>,
    domain: Option<f64>,
    t_end: Option<f64>,
    viscosity_cap: Option<f64>,
    band: bool,
    jobs: Option<usize>,
    slope_deg: Option<f64>,
    depth: Option<f64>,
    gerris: Option<PathBuf>,
    allow_suspect: bool,
) -> PyResult<Bound<'py, PyDict>> {
    if solver != "gerris" {
        return Err(input(format!(
            "solver `{solver}`: the only continuum solver is `gerris`"
        )));
    }
    let dir =
        out.unwrap_or_else(|| PathBuf::from("grainlaw-out").join(format!("continuum-{case}")));
    // What both cases take, over the case's defaults of level and viscosity cap.
    let shared = move |defaults: CaseInputs| CaseInputs {
        dem,
        packing_fraction,
        level: level.unwrap_or(defaults.level),
        viscosity_cap: viscosity_cap.unwrap_or(defaults.viscosity_cap),
        gerris,
        allow_suspect,
        ..defaults
    };
    let outcome = match case {
        "column-collapse" => {
            let mut plan = ColumnPlan::new(law, dir.clone());
            plan.inputs = shared(plan.inputs);
            plan.aspect_ratio = aspect_ratio;
            plan.half_width_m = half_width;
            plan.domain = domain;
            plan.end_t_star = t_end;
            plan.band = band;
            plan.jobs =
                jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
            if slope_deg.is_some() || depth.is_some() {
                return Err(input(
                    "slope_deg and depth are options of the inclined-plane case",
                ));
            }
            let o = detached(py, || column_collapse(&plan))?;
            (o.lines, o.warnings, o.verdict, dir)
        }
        "inclined-plane" => {
            let mut plan = InclinedPlan::new(law, dir.clone());
            plan.inputs = shared(plan.inputs);
            plan.slope_deg = slope_deg;
            plan.depth_m = depth;
            if aspect_ratio.is_some()
                || half_width.is_some()
                || domain.is_some()
                || t_end.is_some()
                || band
            {
                return Err(input(
                    "aspect_ratio, half_width, domain, t_end and band are options of the column-collapse case",
                ));
            }
            let o = detached(py, || inclined_plane(&plan))?;
            (o.lines, o.warnings, o.verdict, dir)
        }
        other => {
            return Err(input(format!(
                "case `{other}`: column-collapse or inclined-plane"
            )))
        }
    };
    let (lines, warnings, verdict, dir) = outcome;
    let w = py.import("warnings")?;
    for m in &warnings {
        w.call_method1("warn", (m.as_str(),))?;
    }
    let result = collect(py, &dir, lines, warnings, &verdict)?;
    let v = verdict.verdict();
    if v == Verdict::Refused || (v == Verdict::Suspect && !allow_suspect) {
        let reasons = result
            .get_item("verdict_reasons")?
            .ok_or_else(|| OutputError::new_err("summary.json has no verdict_reasons"))?;
        return Err(verdict_err(
            py,
            v.as_str(),
            format!("{}: {}", dir.display(), verdict.failure_line()),
            reasons,
            result.into_any(),
        ));
    }
    Ok(result)
}
