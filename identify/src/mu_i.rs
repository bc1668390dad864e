//! μ(I) and φ(I) fits from steady shear (laws in [`crate::laws::mu_i`]).
//!
//! - [`fit_mu_i`]: `μ(I) = μ_s + (μ₂ − μ_s)/(1 + I₀/I)` (GDR MiDi 2004; Jop, Forterre &
//!   Pouliquen 2006), fitted in the parameters `(μ_s, Δμ = μ₂ − μ_s, I₀)` with box bounds
//!   `μ_s > 0`, `0 < Δμ ≤ 10`, `I₀ > 0` (so that `μ_s < μ₂` holds by construction) and reported
//!   as `(μ_s, μ₂, I₀)` (exact linear reparametrisation of the covariance). Started from a
//!   variable-projection grid over `I₀` (the law is linear in `μ_s, Δμ` for fixed `I₀`).
//! - [`fit_mu_i_linear`]: `μ = μ_s + b I`, the form nested in μ(I) as `I₀ → ∞` with
//!   `(μ₂ − μ_s)/I₀ = b` ([`compare_mu_i_forms`] ranks both by AIC).
//! - [`fit_mu_i_or_linear`]: μ(I), or the linear form with the reason μ(I) was refused.
//! - [`fit_phi_i`]: `φ(I) = φ_max − a I`, with `0 ≤ φ_max ≤ 1`, `a ≥ 0` (the former `phi-i`,
//!   `φ_max − (φ_max − φ_min) I`, and `phi-i-linear` were the same line under two names; merged,
//!   with the slope as parameter: it claims nothing at `I = 1`, far beyond the data).
//!
//! Every fit passes the checks of [`crate::accept`] or is refused. For μ(I): `I₀` inside the
//! range of `I` in the data (above `I_max` the data see only the initial slope
//! `(μ₂ − μ_s)/I₀`, below `I_min` only the plateau `μ₂`), the intervals of `μ_s`, `μ₂ − μ_s` and
//! `I₀` non-negative, every standard error below its value, `R²` above the threshold, and an
//! adjusted `R²` not below that of `μ_s + b I`. A refusal offers `use mu-i-linear` when the
//! linear form passes its own checks. Physical ranges: `μ_s ≥ 0`, `b ≥ 0` (friction grows with
//! `I`), `0 ≤ φ_max ≤ 1`, `a ≥ 0` (dilatancy).

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::accept::{Acceptance, NestedForm, PhysicalRange, ScaleCheck};
use crate::error::{
    check_finite, check_non_negative_pressure, check_same_len, check_spread, IdentifyError, Result,
};
use crate::fit::{
    fit_least_squares, log_grid, separable_start, FitOptions, LeastSquaresModel, Observations,
    ParameterSpec,
};
use crate::laws::mu_i::{LinearMuILaw, MuILaw, PhiILaw};
use crate::report::{FitReport, ModelComparison, ValidityRange};

/// Steady-shear measurements (data): one row per steady state.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct RheologySeries {
    /// Inertial number `I = γ̇ d/√(P/ρ_s)` (1), strictly positive.
    pub inertial_number: Vec<f64>,
    /// Friction coefficient `μ = τ/P` (1), when measured.
    pub mu: Option<Vec<f64>>,
    /// Solid fraction `φ` (1), when measured.
    pub phi: Option<Vec<f64>>,
    /// Pressure `P` (Pa, compressive positive), optional: checked and reported as validity.
    pub pressure_pa: Option<Vec<f64>>,
    /// Standard error of each `μ` (e.g. block-averaged over the steady state), optional: the
    /// μ(I) fits then weigh each point by `1/σ` ([`crate::fit::Observations::std_errors`]).
    #[serde(default)]
    pub mu_std_error: Option<Vec<f64>>,
    /// Standard error of each `φ`, optional: the φ(I) fits weigh by it.
    #[serde(default)]
    pub phi_std_error: Option<Vec<f64>>,
}

/// Result of [`fit_mu_i`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MuIFit {
    /// The calibrated law.
    pub law: MuILaw,
    /// Parameters `mu_s`, `mu_2`, `I_0`.
    pub report: FitReport,
}

/// Result of [`fit_mu_i_linear`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinearMuIFit {
    /// The calibrated law.
    pub law: LinearMuILaw,
    /// Parameters `mu_s`, `b`.
    pub report: FitReport,
}

/// Result of [`fit_mu_i_or_linear`]: the full μ(I) when it is accepted, else the linear form
/// with the reason the full form was refused.
#[derive(Debug, Clone, PartialEq)]
pub enum MuIChoice {
    /// μ(I) passed its checks.
    Full(MuIFit),
    /// μ(I) was refused; `μ_s + b I` passed its checks.
    Linear {
        /// The linear fit.
        fit: LinearMuIFit,
        /// Why the full form was refused (one line, e.g. `I_0` above the data).
        full_refusal: String,
    },
}

/// Result of [`fit_phi_i`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhiIFit {
    /// The calibrated law.
    pub law: PhiILaw,
    /// Parameters `phi_max`, `a`.
    pub report: FitReport,
}

fn checked_i(series: &RheologySeries) -> Result<&[f64]> {
    let i = &series.inertial_number;
    check_finite("I", i)?;
    if let Some(k) = i.iter().position(|v| *v <= 0.0) {
        return Err(IdentifyError::OutOfDomain {
            column: "I".into(),
            index: k,
            value: i[k],
            expected: "an inertial number I > 0".into(),
        });
    }
    if let Some(p) = &series.pressure_pa {
        check_finite("P_Pa", p)?;
        check_same_len("I", i, "P_Pa", p)?;
        check_non_negative_pressure("P_Pa", p)?;
    }
    Ok(i)
}

fn checked_column<'a>(
    series: &'a RheologySeries,
    name: &str,
    column: &'a Option<Vec<f64>>,
) -> Result<&'a [f64]> {
    let y = column
        .as_ref()
        .ok_or_else(|| IdentifyError::NotIdentifiable {
            reason: format!("the series has no {name} column"),
        })?;
    check_finite(name, y)?;
    check_same_len("I", &series.inertial_number, name, y)?;
    if let Some(k) = y.iter().position(|v| *v < 0.0) {
        return Err(IdentifyError::OutOfDomain {
            column: name.into(),
            index: k,
            value: y[k],
            expected: "a non-negative value".into(),
        });
    }
    Ok(y)
}

fn validity(series: &RheologySeries) -> Vec<ValidityRange> {
    let mut v = vec![ValidityRange::of("I", "1", &series.inertial_number)];
    if let Some(p) = &series.pressure_pa {
        v.push(ValidityRange::of("P", "Pa", p));
    }
    v
}

struct MuIModel<'a> {
    i: &'a [f64],
    i_max: f64,
}

impl LeastSquaresModel for MuIModel<'_> {
    fn name(&self) -> String {
        "mu-i".into()
    }
    fn parameters(&self) -> Vec<ParameterSpec> {
        vec![
            ParameterSpec::new("mu_s", "1", 0.0, f64::INFINITY),
            ParameterSpec::new("delta_mu", "1", 0.0, 10.0),
            ParameterSpec::new("I_0", "1", 0.0, 1e4 * self.i_max),
        ]
    }
    fn predict(&self, t: &[f64]) -> Vec<f64> {
        let law = MuILaw {
            mu_s: t[0],
            mu_2: t[0] + t[1],
            i0: t[2],
        };
        self.i.iter().map(|&i| law.mu(i)).collect()
    }
    fn jacobian(&self, t: &[f64]) -> DMatrix<f64> {
        let law = MuILaw {
            mu_s: t[0],
            mu_2: t[0] + t[1],
            i0: t[2],
        };
        let mut j = DMatrix::zeros(self.i.len(), 3);
        for (k, &i) in self.i.iter().enumerate() {
            let g = law.gradient_delta_form(i);
            for c in 0..3 {
                j[(k, c)] = g[c];
            }
        }
        j
    }
}

/// Fits `μ(I) = μ_s + (μ₂ − μ_s)/(1 + I₀/I)` (see the module documentation).
///
/// Errors: too few points (< 5), non-finite values, `I ≤ 0`, negative pressure, zero variance
/// of `I` or `μ`; refusals ([`IdentifyError::is_refusal`]): [`IdentifyError::ScaleNotResolved`]
/// (`I₀` outside the `I` of the data), [`IdentifyError::ParameterAtBound`],
/// [`IdentifyError::IntervalCrossesBound`], [`IdentifyError::ParameterNotIdentified`],
/// [`IdentifyError::RSquaredTooLow`], [`IdentifyError::WorseThanNested`] (against
/// `μ_s + b I`), each offering `use mu-i-linear` when the linear form passes.
pub fn fit_mu_i(series: &RheologySeries, options: &FitOptions) -> Result<MuIFit> {
    let i = checked_i(series)?;
    let mu = checked_column(series, "mu", &series.mu)?;
    if i.len() < crate::fit::min_points(3) {
        return Err(IdentifyError::TooFewPoints {
            law: "mu-i".into(),
            needed: crate::fit::min_points(3),
            got: i.len(),
        });
    }
    check_spread("I", i)?;
    check_spread("mu", mu)?;
    let linear = linear_mu_report(series, options);
    let simpler = linear
        .as_ref()
        .ok()
        .filter(|r| accept_linear_mu(r, options).is_ok())
        .map(|_| "use mu-i-linear");
    let refuse = |e: IdentifyError| match simpler {
        Some(s) => e.suggesting(s),
        None => e,
    };
    let (i_min, i_max) = crate::stats::min_max(i);
    let grid = log_grid(1e-2 * i_min, 1e2 * i_max, 121);
    let (i0, c) = separable_start(&grid, mu, |i0| {
        DMatrix::from_fn(
            i.len(),
            2,
            |k, j| if j == 0 { 1.0 } else { i[k] / (i[k] + i0) },
        )
    })
    .ok_or_else(|| IdentifyError::NotIdentifiable {
        reason: "no start value for μ(I)".into(),
    })?;
    let model = MuIModel { i, i_max };
    let theta0 = [c[0].max(1e-3), c[1].clamp(1e-3, 9.0), i0];
    let scale = ScaleCheck::new("I_0", "I", i);
    let result = fit_least_squares(
        &model,
        &Observations::single("mu", mu.to_vec()).with_std_errors(series.mu_std_error.clone()),
        &theta0,
        options,
        validity(series),
    );
    let report = match result {
        Ok(r) => r,
        Err(e @ IdentifyError::ParameterAtBound { .. }) => {
            // A runaway I₀ is the more telling diagnosis.
            if let IdentifyError::ParameterAtBound { report, name, .. } = &e {
                if name == "I_0" {
                    crate::accept::check_scale("mu-i", &scale, report.parameters[2].value)
                        .map_err(refuse)?;
                }
            }
            return Err(refuse(e));
        }
        Err(e) => return Err(refuse(e)),
    };
    Acceptance::new("mu-i", options.min_r_squared)
        .scale(scale)
        .non_negative(&["mu_s", "delta_mu", "I_0"])
        .nested(linear.ok().map(|r| NestedForm {
            name: "mu-i-linear".into(),
            r_squared: r.r_squared,
            parameters: 2,
        }))
        .check(&report)
        .map_err(refuse)?;
    let report = report.reparametrised(&[("mu_s", "1"), ("mu_2", "1"), ("I_0", "1")], |p| {
        (
            vec![p[0], p[0] + p[1], p[2]],
            DMatrix::from_row_slice(3, 3, &[1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0]),
        )
    });
    let law = MuILaw {
        mu_s: report.parameters[0].value,
        mu_2: report.parameters[1].value,
        i0: report.parameters[2].value,
    };
    Ok(MuIFit { law, report })
}

/// Fits μ(I) ([`fit_mu_i`]) and, when it is refused, the linear form `μ_s + b I`
/// ([`fit_mu_i_linear`]), returned with the reason of the refusal. Errors: bad input (the error
/// of [`fit_mu_i`] that is not a refusal), or, when both forms are refused, the full form's
/// refusal.
pub fn fit_mu_i_or_linear(series: &RheologySeries, options: &FitOptions) -> Result<MuIChoice> {
    match fit_mu_i(series, options) {
        Ok(f) => Ok(MuIChoice::Full(f)),
        Err(e) if e.is_refusal() => match fit_mu_i_linear(series, options) {
            Ok(fit) => Ok(MuIChoice::Linear {
                fit,
                full_refusal: e.to_string(),
            }),
            Err(_) => Err(e),
        },
        Err(e) => Err(e),
    }
}

/// The line `y = a ± b x` as a least-squares model (shared with [`crate::critical_state`]).
pub(crate) struct LinearModel<'a> {
    pub(crate) x: &'a [f64],
    pub(crate) name: &'static str,
    pub(crate) names: [&'static str; 2],
    pub(crate) bounds: [(f64, f64); 2],
    /// `y = a + b x` (false) or `y = a − b x` (true).
    pub(crate) decreasing: bool,
}

impl LeastSquaresModel for LinearModel<'_> {
    fn name(&self) -> String {
        self.name.into()
    }
    fn parameters(&self) -> Vec<ParameterSpec> {
        vec![
            ParameterSpec::new(self.names[0], "1", self.bounds[0].0, self.bounds[0].1),
            ParameterSpec::new(self.names[1], "1", self.bounds[1].0, self.bounds[1].1),
        ]
    }
    fn predict(&self, t: &[f64]) -> Vec<f64> {
        let s = if self.decreasing { -1.0 } else { 1.0 };
        self.x.iter().map(|x| t[0] + s * t[1] * x).collect()
    }
    fn jacobian(&self, _t: &[f64]) -> DMatrix<f64> {
        let s = if self.decreasing { -1.0 } else { 1.0 };
        DMatrix::from_fn(
            self.x.len(),
            2,
            |k, j| if j == 0 { 1.0 } else { s * self.x[k] },
        )
    }
}

/// Ordinary least-squares start `(a, b)` of the line `y = a + b x`.
pub(crate) fn ols_start(x: &[f64], y: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let b = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    (my - b * mx, b)
}

/// The unchecked least-squares fit of the line `y = a ± b I` (no bounds; `decreasing` for
/// `a − b I`), parameters `names`, to the column `y` of `series` (`(name, values, standard
/// errors)`).
fn linear_report(
    series: &RheologySeries,
    options: &FitOptions,
    law: &'static str,
    column: (&str, &[f64], &Option<Vec<f64>>),
    names: [&'static str; 2],
    decreasing: bool,
) -> Result<FitReport> {
    let i = &series.inertial_number;
    let model = LinearModel {
        x: i,
        name: law,
        names,
        bounds: [(f64::NEG_INFINITY, f64::INFINITY); 2],
        decreasing,
    };
    let (a, b) = ols_start(i, column.1);
    fit_least_squares(
        &model,
        &Observations::single(column.0, column.1.to_vec()).with_std_errors(column.2.clone()),
        &[a, if decreasing { -b } else { b }],
        options,
        validity(series),
    )
}

/// The unchecked fit of `μ = μ_s + b I`.
fn linear_mu_report(series: &RheologySeries, options: &FitOptions) -> Result<FitReport> {
    let i = checked_i(series)?;
    let mu = checked_column(series, "mu", &series.mu)?;
    check_spread("I", i)?;
    linear_report(
        series,
        options,
        "mu-i-linear",
        ("mu", mu, &series.mu_std_error),
        ["mu_s", "b"],
        false,
    )
}

/// The checks of `mu-i-linear`: `μ_s ≥ 0`, `b ≥ 0`, standard errors, R².
fn accept_linear_mu(report: &FitReport, options: &FitOptions) -> Result<()> {
    Acceptance::new("mu-i-linear", options.min_r_squared)
        .non_negative(&["mu_s", "b"])
        .check(report)
}

/// Fits the linear form `μ = μ_s + b I` (the limit `I₀ → ∞` of μ(I) with `(μ₂ − μ_s)/I₀ = b`;
/// unbounded least squares, exact). Errors: data checks as [`fit_mu_i`] (at least 4 points);
/// refusals: an interval of `μ_s` or `b` below 0 ([`IdentifyError::IntervalCrossesBound`]), a
/// standard error above its value, `R²` below the threshold.
pub fn fit_mu_i_linear(series: &RheologySeries, options: &FitOptions) -> Result<LinearMuIFit> {
    let report = linear_mu_report(series, options)?;
    accept_linear_mu(&report, options)?;
    let law = LinearMuILaw {
        mu_s: report.parameters[0].value,
        slope: report.parameters[1].value,
    };
    Ok(LinearMuIFit { law, report })
}

/// Fits both μ(I) forms and ranks them by AIC (ΔAIC, Akaike weights). A form that cannot be
/// fitted is listed in `failed` with its error.
pub fn compare_mu_i_forms(series: &RheologySeries, options: &FitOptions) -> ModelComparison {
    let mut aics = Vec::new();
    let mut failed = Vec::new();
    match fit_mu_i(series, options) {
        Ok(f) => aics.push(("mu-i".to_string(), f.report.aic)),
        Err(e) => failed.push(("mu-i".to_string(), e.to_string())),
    }
    match fit_mu_i_linear(series, options) {
        Ok(f) => aics.push(("mu-i-linear".to_string(), f.report.aic)),
        Err(e) => failed.push(("mu-i-linear".to_string(), e.to_string())),
    }
    ModelComparison::from_aics(&aics, failed)
}

fn checked_phi(series: &RheologySeries) -> Result<(&[f64], &[f64])> {
    let i = checked_i(series)?;
    let phi = checked_column(series, "phi", &series.phi)?;
    if let Some(k) = phi.iter().position(|v| *v > 1.0) {
        return Err(IdentifyError::OutOfDomain {
            column: "phi".into(),
            index: k,
            value: phi[k],
            expected: "a solid fraction 0 ≤ φ ≤ 1".into(),
        });
    }
    check_spread("I", i)?;
    Ok((i, phi))
}

/// The unchecked fit of `φ = φ_max − a I`.
fn linear_phi_report(series: &RheologySeries, options: &FitOptions) -> Result<FitReport> {
    let (_, phi) = checked_phi(series)?;
    linear_report(
        series,
        options,
        "phi-i",
        ("phi", phi, &series.phi_std_error),
        ["phi_max", "a"],
        true,
    )
}

/// The checks of `phi-i`: `0 ≤ φ_max ≤ 1`, `a ≥ 0`, standard errors, R².
fn accept_linear_phi(report: &FitReport, options: &FitOptions) -> Result<()> {
    Acceptance::new("phi-i", options.min_r_squared)
        .range(PhysicalRange::new("phi_max", 0.0, 1.0))
        .non_negative(&["a"])
        .check(report)
}

/// Fits `φ(I) = φ_max − a I` ([`PhiILaw`]; unbounded least squares, exact), valid over the
/// `I` of the data. Refusals: the interval of `φ_max` outside `[0, 1]` or of `a` below 0 (a
/// solid fraction that does not decrease with `I`), a standard error above its value, `R²`
/// below the threshold. One law under one name: it was also fitted as `φ_max − (φ_max − φ_min) I`
/// (the former `phi-i`, refused when the extrapolation `φ_min = φ(1)` left `[0, 1]`, offering
/// the same line as `phi-i-linear`); the two are merged into this one, `phi-i`.
pub fn fit_phi_i(series: &RheologySeries, options: &FitOptions) -> Result<PhiIFit> {
    let report = linear_phi_report(series, options)?;
    accept_linear_phi(&report, options)?;
    let law = PhiILaw {
        phi_max: report.parameters[0].value,
        slope: report.parameters[1].value,
    };
    Ok(PhiIFit { law, report })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::finite_difference_jacobian;

    #[test]
    fn mu_i_jacobian_matches_finite_differences() {
        let i: Vec<f64> = (1..20).map(|k| 0.01 * k as f64).collect();
        let m = MuIModel { i: &i, i_max: 0.19 };
        let t = [0.38, 0.26, 0.279];
        let a = m.jacobian(&t);
        let f = finite_difference_jacobian(|p| m.predict(p), &t);
        assert!((a - f).amax() < 1e-8);
    }
}
