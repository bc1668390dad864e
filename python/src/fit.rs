//! The fits of `identify` from numpy columns, and `Law`: a calibrated law (schema 2 JSON,
//! schema 1 read and upgraded) with its estimates, intervals, covariance and vectorised
//! evaluation.
//!
//! The columns and metadata are those of `grainlaw fit LAW DATA.csv` (identify/README.md):
//! the arrays are written as the CSV table that command reads (numbers printed in Rust's
//! shortest round-trip form, so each value is read back exactly) and fitted by
//! `identify::user_fit::fit_table`, so that a fit from Python and from the command line are
//! the same computation with the same acceptance checks.

use std::collections::BTreeMap;
use std::path::PathBuf;

use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use identify::user_fit::{fit_table, CsvFitOptions, LAW_NAMES};
use identify::CalibratedLaw;

use crate::arrays::{finite1, out1, vec1};
use crate::errors::{identify_err, input};

/// fit(law, columns, metadata=None, confidence=0.95, min_r_squared=0.5)
/// --
///
/// Fits `law` ("janssen", "janssen-kmu", "wall-law", "mu-i", "mu-i-linear", "phi-i",
/// "mohr-coulomb"; "_" may stand for "-") to `columns`, a dict
/// ``{header: 1-D array}`` with the headers and units of ``grainlaw fit`` (``z_m``,
/// ``sigma_v_Pa``, ``I``, ``mu``, ...; identify/README.md), and `metadata`, the ``# key =
/// value`` constants of that file (``width_m``, ``grain_diameter_m``, ...). Stresses are
/// compressive-positive magnitudes, except the Mohr–Coulomb tensor columns (tension positive).
/// The per-law functions (``fit_mu_i`` and so on) call this one.
///
/// Returns a Law. Raises FitRefused (with ``reason`` and ``suggestion``) when the data are
/// valid but do not support the law, InputError for bad input.
#[pyfunction]
#[pyo3(signature = (law, columns, metadata=None, confidence=0.95, min_r_squared=0.5))]
pub fn fit(
    py: Python<'_>,
    law: &str,
    columns: &Bound<'_, PyDict>,
    metadata: Option<&Bound<'_, PyDict>>,
    confidence: f64,
    min_r_squared: f64,
) -> PyResult<Law> {
    let law = law.replace('_', "-");
    if !LAW_NAMES.contains(&law.as_str()) {
        return Err(input(format!(
            "unknown law `{law}`: one of {}",
            LAW_NAMES.join(", ")
        )));
    }
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(input(format!(
            "`confidence` must be in (0, 1), got {confidence}"
        )));
    }
    if !min_r_squared.is_finite() {
        return Err(input("`min_r_squared` must be finite"));
    }
    let mut headers = Vec::new();
    let mut data: Vec<Vec<f64>> = Vec::new();
    for (k, v) in columns.iter() {
        let name: String = k
            .extract()
            .map_err(|_| input("`columns`: every key must be a str"))?;
        if name.is_empty() || name.contains([',', '\n', '\r', '"', '#']) {
            return Err(input(format!("`columns`: bad column name {name:?}")));
        }
        let col = finite1(&v, &name)?;
        if let Some(first) = data.first() {
            if col.len() != first.len() {
                return Err(input(format!(
                    "column `{name}` has {} values, `{}` has {}",
                    col.len(),
                    headers[0],
                    first.len()
                )));
            }
        }
        headers.push(name);
        data.push(col);
    }
    if headers.is_empty() || data[0].is_empty() {
        return Err(input("`columns`: no data"));
    }
    let mut meta = BTreeMap::new();
    if let Some(m) = metadata {
        for (k, v) in m.iter() {
            if v.is_none() {
                continue;
            }
            let key: String = k
                .extract()
                .map_err(|_| input("`metadata`: every key must be a str"))?;
            let value: f64 = v
                .extract()
                .map_err(|_| input(format!("metadata `{key}`: a number is expected")))?;
            if !value.is_finite() {
                return Err(input(format!("metadata `{key}` is not finite ({value})")));
            }
            meta.insert(key, value);
        }
    }
    let mut text = String::new();
    for (k, v) in &meta {
        text.push_str(&format!("# {k} = {v:e}\n"));
    }
    text.push_str(&headers.join(","));
    text.push('\n');
    for i in 0..data[0].len() {
        let row: Vec<String> = data.iter().map(|c| format!("{:e}", c[i])).collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    let options = CsvFitOptions {
        fit: identify::FitOptions {
            confidence,
            min_r_squared,
            ..identify::FitOptions::default()
        },
        scenario: "python".into(),
        ..CsvFitOptions::default()
    };
    let result = py.detach(|| {
        let table = identify::data::Table::parse_csv(&text, "arrays")?;
        fit_table(&law, &table, &options)
    });
    result
        .map(|inner| Law { inner })
        .map_err(|e| identify_err(py, e))
}

/// load_law(path)
/// --
///
/// Reads a calibrated-law JSON file (schema 2, or schema 1 upgraded), checked against the law
/// registry. Raises InputError for a malformed or unknown law, OutputError when unreadable.
#[pyfunction]
pub fn load_law(py: Python<'_>, path: PathBuf) -> PyResult<Law> {
    CalibratedLaw::load(&path)
        .map(|inner| Law { inner })
        .map_err(|e| identify_err(py, e))
}

/// law_from_json(text)
/// --
///
/// A Law from JSON text (schema 1 or 2); see ``load_law``.
#[pyfunction]
pub fn law_from_json(py: Python<'_>, text: &str) -> PyResult<Law> {
    CalibratedLaw::from_json_str(text)
        .map(|inner| Law { inner })
        .map_err(|e| identify_err(py, e))
}

/// A calibrated law: the fitted parameters with standard errors, confidence intervals and
/// covariance, derived quantities, set-up constants, the fit's R², AIC and BIC, the validity
/// range and the law's formula (schema 2 of docs/formats.md). ``law["K"]`` is a parameter's
/// (or a derived quantity's, or a constant's) value; ``law.evaluate(x)`` evaluates it on an
/// array of its input variable (``law.input``, in its unit).
#[pyclass(module = "grainlaw", frozen)]
pub struct Law {
    pub inner: CalibratedLaw,
}

fn estimate_dict<'py>(py: Python<'py>, e: &identify::Estimate) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("value", e.value)?;
    d.set_item("unit", &e.unit)?;
    d.set_item("std_error", e.std_error)?;
    d.set_item("ci", (e.ci_low, e.ci_high))?;
    d.set_item("at_bound", e.at_bound)?;
    Ok(d)
}

#[pymethods]
impl Law {
    /// Law name ("janssen", "mu-i", ...).
    #[getter]
    fn name(&self) -> &str {
        &self.inner.law
    }
    /// Schema version of the JSON it was read from (2, or 1 for an upgraded schema-1 file; a fit
    /// gives 2).
    #[getter]
    fn schema_version(&self) -> u32 {
        self.inner.schema_version
    }
    /// The formula, ``output = formula`` in the input, parameters and constants.
    #[getter]
    fn formula(&self) -> &str {
        &self.inner.expression.formula
    }
    /// (name, unit) of the input variable of ``evaluate``.
    #[getter]
    fn input(&self) -> (String, String) {
        let v = &self.inner.expression.input;
        (v.name.clone(), v.unit.clone())
    }
    /// (name, unit) of the output of ``evaluate``.
    #[getter]
    fn output(&self) -> (String, String) {
        let v = &self.inner.expression.output;
        (v.name.clone(), v.unit.clone())
    }
    /// Parameter values ``{name: value}`` in the registry's order (SI units, ``units``).
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in &self.inner.parameters {
            d.set_item(&p.name, p.value)?;
        }
        Ok(d)
    }
    /// Confidence intervals ``{name: (low, high)}`` at ``confidence``.
    #[getter]
    fn intervals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in &self.inner.parameters {
            d.set_item(&p.name, (p.ci_low, p.ci_high))?;
        }
        Ok(d)
    }
    /// Standard errors ``{name: value}``.
    #[getter]
    fn std_errors<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in &self.inner.parameters {
            d.set_item(&p.name, p.std_error)?;
        }
        Ok(d)
    }
    /// SI units ``{name: unit}`` of the parameters ("1": dimensionless).
    #[getter]
    fn units<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in &self.inner.parameters {
            d.set_item(&p.name, &p.unit)?;
        }
        Ok(d)
    }
    /// Every parameter: ``{name: {"value", "unit", "std_error", "ci", "at_bound"}}``.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in &self.inner.parameters {
            d.set_item(&p.name, estimate_dict(py, &p.estimate)?)?;
        }
        Ok(d)
    }
    /// Derived quantities (delta-method intervals): ``{name: {"value", "unit", "std_error",
    /// "ci", "at_bound", "formula"}}``.
    #[getter]
    fn derived<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for q in &self.inner.derived {
            let e = estimate_dict(py, &q.estimate)?;
            e.set_item("formula", &q.formula)?;
            d.set_item(&q.name, e)?;
        }
        Ok(d)
    }
    /// Set-up constants ``{name: value}`` (SI).
    #[getter]
    fn constants<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for c in &self.inner.constants {
            d.set_item(&c.name, c.value)?;
        }
        Ok(d)
    }
    /// Covariance of the parameters, (p, p) array in the order of ``covariance_order``; None
    /// for a law read from schema 1.
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match &self.inner.covariance {
            None => Ok(None),
            Some(c) => {
                let n = c.order.len();
                let flat: Vec<f64> = c.matrix.iter().flatten().copied().collect();
                Ok(Some(
                    PyArray1::from_vec(py, flat).reshape([n, n])?.into_any(),
                ))
            }
        }
    }
    /// Parameter names in the rows (and columns) of ``covariance``.
    #[getter]
    fn covariance_order(&self) -> Vec<String> {
        self.inner
            .covariance
            .as_ref()
            .map(|c| c.order.clone())
            .unwrap_or_default()
    }
    /// Verdict of the law: ``ok`` for a fit (it passed every check; a refused fit raises
    /// FitRefused), the run's verdict of it for a law a run wrote (``ok``, ``suspect``, or
    /// ``refused`` in a ``NAME_law.rejected.json``); None for a file written before verdicts.
    #[getter]
    fn verdict(&self) -> Option<&str> {
        self.inner.verdict.as_deref()
    }
    /// The failed checks behind a verdict other than ``ok``: dicts ``check``, ``verdict``,
    /// ``value``, ``threshold``, ``message`` (empty for ``ok``).
    #[getter]
    fn verdict_reasons<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = serde_json::to_string(&self.inner.verdict_reasons)
            .map_err(|e| input(format!("verdict reasons: {e}")))?;
        py.import("json")?.call_method1("loads", (text,))
    }
    /// R² of the fit.
    #[getter]
    fn r_squared(&self) -> f64 {
        self.inner.fit.r_squared
    }
    /// Number of observations.
    #[getter]
    fn n(&self) -> usize {
        self.inner.fit.n
    }
    /// Degrees of freedom of the residuals.
    #[getter]
    fn dof(&self) -> usize {
        self.inner.fit.dof
    }
    /// Akaike information criterion.
    #[getter]
    fn aic(&self) -> f64 {
        self.inner.fit.aic
    }
    /// Bayesian information criterion.
    #[getter]
    fn bic(&self) -> f64 {
        self.inner.fit.bic
    }
    /// Confidence level of the intervals.
    #[getter]
    fn confidence(&self) -> f64 {
        self.inner.fit.confidence
    }
    /// Data ranges the law was calibrated on: ``{variable: (min, max)}`` (SI).
    #[getter]
    fn validity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for v in &self.inner.validity {
            d.set_item(&v.variable, (v.min, v.max))?;
        }
        Ok(d)
    }

    /// evaluate(x): the law at each value of its input variable (``input``, in its unit), as a
    /// float64 array of the output (``output``, in its unit). Outside ``validity`` the law is
    /// extrapolated (see ``in_validity_range``).
    fn evaluate<'py>(&self, py: Python<'py>, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let np = py.import("numpy")?;
        let arr = np.getattr("asarray")?.call1((x, np.getattr("float64")?))?;
        let shape = arr.getattr("shape")?;
        let flat = vec1(&arr.call_method1("reshape", (-1i64,))?, "x")?;
        let y = self
            .inner
            .evaluate(&flat)
            .map_err(|e| identify_err(py, e))?;
        out1(py, y).call_method1("reshape", (shape,))
    }

    /// evaluate_formula(x): the JSON's formula text evaluated at each x with the parameters and
    /// constants (what a solver reading only the expression computes); equal to ``evaluate``.
    fn evaluate_formula<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let x = vec1(x, "x")?;
        let y = self
            .inner
            .evaluate_formula(&x)
            .map_err(|e| identify_err(py, e))?;
        Ok(out1(py, y))
    }

    /// in_validity_range(x): True where x lies in the calibrated range of the input variable.
    fn in_validity_range<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let x = vec1(x, "x")?;
        Ok(PyArray1::from_vec(
            py,
            x.iter().map(|&v| self.inner.in_validity_range(v)).collect(),
        ))
    }

    /// The law as pretty JSON text (schema 2).
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        self.inner.to_json_string().map_err(|e| identify_err(py, e))
    }

    /// save(path): writes the JSON (schema 2) to `path`, atomically.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let text = self
            .inner
            .to_json_string()
            .map_err(|e| identify_err(py, e))?
            + "\n";
        grainlaw_core::output::dir::write_atomic(&path, text.as_bytes())
            .map_err(|e| crate::errors::cli_err(py, e))
    }

    /// The whole law as a dict (the JSON's structure).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = self.to_json(py)?;
        py.import("json")?.call_method1("loads", (text,))
    }

    /// law[name]: the value of a parameter, derived quantity or constant.
    fn __getitem__(&self, name: &str) -> PyResult<f64> {
        self.inner
            .parameters
            .iter()
            .map(|p| (&p.name, p.value))
            .chain(self.inner.derived.iter().map(|d| (&d.name, d.value)))
            .chain(self.inner.constants.iter().map(|c| (&c.name, c.value)))
            .find(|(n, _)| *n == name)
            .map(|(_, v)| v)
            .ok_or_else(|| pyo3::exceptions::PyKeyError::new_err(name.to_string()))
    }

    fn __repr__(&self) -> String {
        let mut s = format!("Law({}", self.inner.law);
        for p in &self.inner.parameters {
            s.push_str(&format!(
                ", {} = {} [{}, {}]",
                p.name,
                identify::error::short(p.value),
                identify::error::short(p.ci_low),
                identify::error::short(p.ci_high)
            ));
        }
        s.push_str(&format!(", R² = {:.4}", self.inner.fit.r_squared));
        if let Some(v) = &self.inner.verdict {
            s.push_str(&format!(", verdict {v}"));
        }
        s.push(')');
        s
    }
}
