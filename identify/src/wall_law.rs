//! Wall boundary-layer law: effective wall friction against slip velocity, with model choice by
//! AIC, and the boundary-layer thickness from a velocity profile (laws in
//! [`crate::laws::wall_friction`] and [`crate::laws::boundary_layer`]).
//!
//! Slip velocities `V_s` (m/s) are normalised as `V = V_s/√(g d)`. Candidates
//! ([`WallLawForm`]):
//! - exponential saturation `μ_∞ − (μ_∞ − μ_0) exp(−V/V*)`,
//! - hyperbolic saturation `μ_0 + (μ_∞ − μ_0) V/(V + V*)`,
//! - power law `μ_0 + k V^n`.
//!
//! [`select_wall_law`] fits all three, ranks them by AIC and reports `ΔAIC` and Akaike weights.
//! Bounds: `0 ≤ μ_0, μ_∞ ≤ 10`, `V* > 0`, `|k| ≤ 10`, `0 < n ≤ 5`. Each form passes the checks
//! of [`crate::accept`] or is refused: a velocity scale `V*` outside `[V_min⁺, V_max]` (`V_min⁺`
//! the smallest positive `V`) is [`IdentifyError::ScaleNotResolved`] (the data do not see the
//! law's curvature); intervals of `μ_0`, `μ_∞`, `V*`, `n` below 0 are
//! [`IdentifyError::IntervalCrossesBound`]; a parameter with a standard error above its value is
//! [`IdentifyError::ParameterNotIdentified`] ([`crate::accept::check_identified`]): e.g. μ_eff
//! falling like `a − b ln V` is fitted by the power law only as `n → 0`, `μ_0 → +∞`,
//! `k → −∞`, with intervals spanning zero by orders of magnitude; `R²` below the threshold is
//! [`IdentifyError::RSquaredTooLow`]. A refused form is left out of the AIC ranking (listed as
//! failed with the reason).
//!
//! [`fit_boundary_layer`] fits `u(y) = u_b − (u_b − u_s) exp(−y/δ)` to a velocity profile
//! (`y` distance from the wall, m) and reports `δ` in metres and in grain diameters.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::accept::{check_scale, Acceptance, ScaleCheck};
use crate::error::{
    check_finite, check_same_len, check_setup_positive, check_spread, IdentifyError, Result,
};
use crate::fit::{
    fit_least_squares, log_grid, separable_start, FitOptions, LeastSquaresModel, Observations,
    ParameterSpec,
};
use crate::laws::boundary_layer::VelocityBoundaryLayer;
use crate::laws::janssen::STANDARD_GRAVITY;
use crate::laws::wall_friction::WallFrictionLaw;
use crate::report::{Estimate, FitReport, ModelComparison, ValidityRange};
use crate::stats::min_max;

/// Wall friction against slip velocity (data).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WallSlipSeries {
    /// Slip velocity magnitude of the grains along the wall `V_s` (m/s), ≥ 0.
    pub slip_velocity_m_s: Vec<f64>,
    /// Effective wall friction `μ_eff = τ_w/σ_w` (1), ≥ 0.
    pub mu_eff: Vec<f64>,
    /// Mean grain diameter `d` (m).
    pub grain_diameter_m: f64,
    /// Gravity `g` (m/s²).
    pub gravity_m_s2: f64,
}

impl WallSlipSeries {
    /// Series with `g` = [`STANDARD_GRAVITY`].
    pub fn new(slip_velocity_m_s: Vec<f64>, mu_eff: Vec<f64>, grain_diameter_m: f64) -> Self {
        WallSlipSeries {
            slip_velocity_m_s,
            mu_eff,
            grain_diameter_m,
            gravity_m_s2: STANDARD_GRAVITY,
        }
    }

    /// Normalised slip velocities `V = V_s/√(g d)`.
    pub fn normalised_velocity(&self) -> Vec<f64> {
        let scale = (self.gravity_m_s2 * self.grain_diameter_m).sqrt();
        self.slip_velocity_m_s.iter().map(|v| v / scale).collect()
    }
}

/// The candidate forms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WallLawForm {
    /// `μ_∞ − (μ_∞ − μ_0) exp(−V/V*)`.
    Exponential,
    /// `μ_0 + (μ_∞ − μ_0) V/(V + V*)`.
    Hyperbolic,
    /// `μ_0 + k V^n`.
    PowerLaw,
}

impl WallLawForm {
    /// All candidates.
    pub const ALL: [WallLawForm; 3] = [
        WallLawForm::Exponential,
        WallLawForm::Hyperbolic,
        WallLawForm::PowerLaw,
    ];

    /// Law name used in reports and JSON: `wall-law-exponential`, `wall-law-hyperbolic`,
    /// `wall-law-power`.
    pub fn law_name(&self) -> &'static str {
        match self {
            WallLawForm::Exponential => "wall-law-exponential",
            WallLawForm::Hyperbolic => "wall-law-hyperbolic",
            WallLawForm::PowerLaw => "wall-law-power",
        }
    }

    /// The parameters the velocity dependence rests on: `V_star` for the saturating forms, `k`
    /// and `n` for the power law (with `k → 0` or `n → 0` the law is a constant).
    pub fn shape_parameters(&self) -> &'static [&'static str] {
        match self {
            WallLawForm::Exponential | WallLawForm::Hyperbolic => &["V_star"],
            WallLawForm::PowerLaw => &["k", "n"],
        }
    }

    fn build(&self, t: &[f64]) -> WallFrictionLaw {
        match self {
            WallLawForm::Exponential => WallFrictionLaw::Exponential {
                mu_0: t[0],
                mu_inf: t[1],
                v_star: t[2],
            },
            WallLawForm::Hyperbolic => WallFrictionLaw::Hyperbolic {
                mu_0: t[0],
                mu_inf: t[1],
                v_star: t[2],
            },
            WallLawForm::PowerLaw => WallFrictionLaw::PowerLaw {
                mu_0: t[0],
                k: t[1],
                n: t[2],
            },
        }
    }
}

/// One fitted wall law.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WallLawFit {
    /// Its form.
    pub form: WallLawForm,
    /// The calibrated law.
    pub law: WallFrictionLaw,
    /// The fit (`mu_0, mu_inf, V_star` or `mu_0, k, n`).
    pub report: FitReport,
}

/// Result of [`select_wall_law`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WallLawSelection {
    /// Fitted candidates, best AIC first.
    pub fits: Vec<WallLawFit>,
    /// AIC ranking (ΔAIC, Akaike weights) and failed candidates.
    pub comparison: ModelComparison,
}

impl WallLawSelection {
    /// The lowest-AIC fit.
    pub fn best(&self) -> &WallLawFit {
        &self.fits[0]
    }
}

struct WallModel<'a> {
    v: &'a [f64],
    form: WallLawForm,
    v_max: f64,
}

impl LeastSquaresModel for WallModel<'_> {
    fn name(&self) -> String {
        self.form.law_name().into()
    }
    fn parameters(&self) -> Vec<ParameterSpec> {
        match self.form {
            WallLawForm::Exponential | WallLawForm::Hyperbolic => vec![
                ParameterSpec::new("mu_0", "1", 0.0, 10.0),
                ParameterSpec::new("mu_inf", "1", 0.0, 10.0),
                ParameterSpec::new("V_star", "1", 0.0, 1e3 * self.v_max),
            ],
            WallLawForm::PowerLaw => vec![
                ParameterSpec::new("mu_0", "1", 0.0, 10.0),
                ParameterSpec::new("k", "1", -10.0, 10.0),
                ParameterSpec::new("n", "1", 0.0, 5.0),
            ],
        }
    }
    fn predict(&self, t: &[f64]) -> Vec<f64> {
        let law = self.form.build(t);
        self.v.iter().map(|&v| law.mu_eff(v)).collect()
    }
    fn jacobian(&self, t: &[f64]) -> DMatrix<f64> {
        let law = self.form.build(t);
        let mut j = DMatrix::zeros(self.v.len(), 3);
        for (k, &v) in self.v.iter().enumerate() {
            let g = law.gradient(v);
            for c in 0..3 {
                j[(k, c)] = g[c];
            }
        }
        j
    }
}

fn checked_series(series: &WallSlipSeries) -> Result<Vec<f64>> {
    check_setup_positive("grain_diameter_m", series.grain_diameter_m)?;
    check_setup_positive("gravity_m_s2", series.gravity_m_s2)?;
    let vs = &series.slip_velocity_m_s;
    check_finite("slip_velocity_m_s", vs)?;
    check_finite("mu_eff", &series.mu_eff)?;
    check_same_len("slip_velocity_m_s", vs, "mu_eff", &series.mu_eff)?;
    for (name, col) in [("slip_velocity_m_s", vs), ("mu_eff", &series.mu_eff)] {
        if let Some(k) = col.iter().position(|v| *v < 0.0) {
            return Err(IdentifyError::OutOfDomain {
                column: name.into(),
                index: k,
                value: col[k],
                expected: "a non-negative magnitude".into(),
            });
        }
    }
    if vs.len() < crate::fit::min_points(3) {
        return Err(IdentifyError::TooFewPoints {
            law: "wall-law".into(),
            needed: crate::fit::min_points(3),
            got: vs.len(),
        });
    }
    check_spread("slip_velocity_m_s", vs)?;
    check_spread("mu_eff", &series.mu_eff)?;
    Ok(series.normalised_velocity())
}

/// Fits one wall-law form. Errors: data checks (≥ 5 points, finite, non-negative, spread);
/// refusals (module documentation): [`IdentifyError::ScaleNotResolved`] for `V*`,
/// [`IdentifyError::ParameterAtBound`], [`IdentifyError::IntervalCrossesBound`],
/// [`IdentifyError::ParameterNotIdentified`], [`IdentifyError::RSquaredTooLow`].
pub fn fit_wall_law(
    series: &WallSlipSeries,
    form: WallLawForm,
    options: &FitOptions,
) -> Result<WallLawFit> {
    let v = checked_series(series)?;
    let mu = &series.mu_eff;
    let (v_min, v_max) = min_max(&v);
    let scale = ScaleCheck::new("V_star", "V", &v);
    let v_min_pos = scale.data_min.min(v_max);
    let start = match form {
        WallLawForm::Exponential => {
            separable_start(&log_grid(1e-2 * v_min_pos, 1e2 * v_max, 121), mu, |s| {
                DMatrix::from_fn(v.len(), 2, |k, j| {
                    let e = (-v[k] / s).exp();
                    if j == 0 {
                        e
                    } else {
                        1.0 - e
                    }
                })
            })
        }
        WallLawForm::Hyperbolic => {
            separable_start(&log_grid(1e-2 * v_min_pos, 1e2 * v_max, 121), mu, |s| {
                DMatrix::from_fn(v.len(), 2, |k, j| {
                    let r = v[k] / (v[k] + s);
                    if j == 0 {
                        1.0 - r
                    } else {
                        r
                    }
                })
            })
        }
        WallLawForm::PowerLaw => separable_start(&log_grid(0.05, 4.0, 80), mu, |n| {
            DMatrix::from_fn(v.len(), 2, |k, j| if j == 0 { 1.0 } else { v[k].powf(n) })
        }),
    };
    let (s, c) = start.ok_or_else(|| IdentifyError::NotIdentifiable {
        reason: "no start value for the wall law".into(),
    })?;
    let theta0 = match form {
        WallLawForm::PowerLaw => [c[0].clamp(1e-3, 9.0), c[1].clamp(-9.0, 9.0), s],
        _ => [c[0].clamp(1e-3, 9.0), c[1].clamp(1e-3, 9.0), s],
    };
    let model = WallModel { v: &v, form, v_max };
    let validity = vec![
        ValidityRange {
            variable: "V".into(),
            unit: "1".into(),
            min: v_min,
            max: v_max,
        },
        ValidityRange::of("slip_velocity", "m/s", &series.slip_velocity_m_s),
    ];
    let result = fit_least_squares(
        &model,
        &Observations::single("mu_eff", mu.clone()),
        &theta0,
        options,
        validity,
    );
    let report = match result {
        Ok(r) => r,
        Err(e @ IdentifyError::ParameterAtBound { .. }) => {
            // A runaway velocity scale is the more telling diagnosis.
            if let IdentifyError::ParameterAtBound { report, name, .. } = &e {
                if name == "V_star" {
                    check_scale(form.law_name(), &scale, report.parameters[2].value)?;
                }
            }
            return Err(e);
        }
        Err(e) => return Err(e),
    };
    let acceptance = Acceptance::new(form.law_name(), options.min_r_squared);
    match form {
        WallLawForm::PowerLaw => acceptance.non_negative(&["mu_0", "n"]),
        _ => acceptance
            .scale(scale)
            .non_negative(&["mu_0", "mu_inf", "V_star"]),
    }
    .check(&report)?;
    Ok(WallLawFit {
        form,
        law: form.build(&report.values()),
        report,
    })
}

/// Fits every form of [`WallLawForm::ALL`] and ranks them by AIC. Errors only when no form can
/// be fitted (the first form's error is returned).
pub fn select_wall_law(series: &WallSlipSeries, options: &FitOptions) -> Result<WallLawSelection> {
    let mut fits = Vec::new();
    let mut failed = Vec::new();
    let mut first_error = None;
    for form in WallLawForm::ALL {
        match fit_wall_law(series, form, options) {
            Ok(f) => fits.push(f),
            Err(e) => {
                failed.push((form.law_name().to_string(), e.to_string()));
                first_error.get_or_insert(e);
            }
        }
    }
    if fits.is_empty() {
        return Err(first_error.unwrap_or(IdentifyError::NotIdentifiable {
            reason: "no wall law could be fitted".into(),
        }));
    }
    let aics: Vec<(String, f64)> = fits
        .iter()
        .map(|f| (f.form.law_name().to_string(), f.report.aic))
        .collect();
    let comparison = ModelComparison::from_aics(&aics, failed);
    fits.sort_by(|a, b| a.report.aic.total_cmp(&b.report.aic));
    Ok(WallLawSelection { fits, comparison })
}

/// A velocity profile across the boundary layer (data).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VelocityProfile {
    /// Distance from the wall `y` (m), ≥ 0.
    pub distance_m: Vec<f64>,
    /// Velocity parallel to the wall `u` (m/s).
    pub velocity_m_s: Vec<f64>,
    /// Mean grain diameter `d` (m).
    pub grain_diameter_m: f64,
}

/// Result of [`fit_boundary_layer`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BoundaryLayerFit {
    /// The calibrated profile.
    pub law: VelocityBoundaryLayer,
    /// The fit (`u_bulk`, `u_slip`, `delta`).
    pub report: FitReport,
    /// Thickness `δ` (m).
    pub thickness_m: Estimate,
    /// Thickness in grain diameters `δ/d` (1).
    pub thickness_diameters: Estimate,
}

struct LayerModel<'a> {
    y: &'a [f64],
    y_max: f64,
}

impl LeastSquaresModel for LayerModel<'_> {
    fn name(&self) -> String {
        "boundary-layer".into()
    }
    fn parameters(&self) -> Vec<ParameterSpec> {
        vec![
            ParameterSpec::new("u_bulk", "m/s", f64::NEG_INFINITY, f64::INFINITY),
            ParameterSpec::new("u_slip", "m/s", f64::NEG_INFINITY, f64::INFINITY),
            ParameterSpec::new("delta", "m", 0.0, 1e3 * self.y_max),
        ]
    }
    fn predict(&self, t: &[f64]) -> Vec<f64> {
        let law = VelocityBoundaryLayer {
            u_bulk: t[0],
            u_slip: t[1],
            delta_m: t[2],
        };
        self.y.iter().map(|&y| law.velocity(y)).collect()
    }
    fn jacobian(&self, t: &[f64]) -> DMatrix<f64> {
        let law = VelocityBoundaryLayer {
            u_bulk: t[0],
            u_slip: t[1],
            delta_m: t[2],
        };
        let mut j = DMatrix::zeros(self.y.len(), 3);
        for (k, &y) in self.y.iter().enumerate() {
            let g = law.gradient(y);
            for c in 0..3 {
                j[(k, c)] = g[c];
            }
        }
        j
    }
}

/// Fits `u(y) = u_b − (u_b − u_s) exp(−y/δ)`. Errors: data checks (≥ 5 points, `y ≥ 0`,
/// spread); refusals ([`crate::accept`]): [`IdentifyError::ScaleNotResolved`] for `δ` outside
/// `[y_min⁺, y_max]`, [`IdentifyError::ParameterAtBound`], an interval of `δ` below 0, a standard
/// error above its value (`u_slip` exempt: a no-slip wall has `u_s ≈ 0`), `R²` below the
/// threshold.
pub fn fit_boundary_layer(
    profile: &VelocityProfile,
    options: &FitOptions,
) -> Result<BoundaryLayerFit> {
    check_setup_positive("grain_diameter_m", profile.grain_diameter_m)?;
    let y = &profile.distance_m;
    let u = &profile.velocity_m_s;
    check_finite("y_m", y)?;
    check_finite("u_m_s", u)?;
    check_same_len("y_m", y, "u_m_s", u)?;
    if let Some(k) = y.iter().position(|v| *v < 0.0) {
        return Err(IdentifyError::OutOfDomain {
            column: "y_m".into(),
            index: k,
            value: y[k],
            expected: "a distance from the wall ≥ 0".into(),
        });
    }
    if y.len() < crate::fit::min_points(3) {
        return Err(IdentifyError::TooFewPoints {
            law: "boundary-layer".into(),
            needed: crate::fit::min_points(3),
            got: y.len(),
        });
    }
    check_spread("y_m", y)?;
    check_spread("u_m_s", u)?;
    let scale = ScaleCheck::new("delta", "y", y);
    let (y_min_pos, y_max) = (scale.data_min, scale.data_max);
    let (s, c) = separable_start(&log_grid(1e-2 * y_min_pos, 1e2 * y_max, 121), u, |d| {
        DMatrix::from_fn(y.len(), 2, |k, j| {
            let e = (-y[k] / d).exp();
            if j == 0 {
                1.0 - e
            } else {
                e
            }
        })
    })
    .ok_or_else(|| IdentifyError::NotIdentifiable {
        reason: "no start value for the boundary layer".into(),
    })?;
    let model = LayerModel { y, y_max };
    let report = match fit_least_squares(
        &model,
        &Observations::single("u", u.clone()),
        &[c[0], c[1], s],
        options,
        vec![ValidityRange::of("y", "m", y)],
    ) {
        Ok(r) => r,
        Err(e @ IdentifyError::ParameterAtBound { .. }) => {
            if let IdentifyError::ParameterAtBound { report, name, .. } = &e {
                if name == "delta" {
                    check_scale("boundary-layer", &scale, report.parameters[2].value)?;
                }
            }
            return Err(e);
        }
        Err(e) => return Err(e),
    };
    Acceptance::new("boundary-layer", options.min_r_squared)
        .scale(scale)
        .non_negative(&["delta"])
        .may_vanish(&["u_slip"])
        .check(&report)?;
    let d = profile.grain_diameter_m;
    let thickness_m = report.parameters[2].clone();
    let thickness_diameters =
        report.derived("delta_over_d", "1", |p| (p[2] / d, vec![0.0, 0.0, 1.0 / d]));
    let t = report.values();
    Ok(BoundaryLayerFit {
        law: VelocityBoundaryLayer {
            u_bulk: t[0],
            u_slip: t[1],
            delta_m: t[2],
        },
        report,
        thickness_m,
        thickness_diameters,
    })
}
