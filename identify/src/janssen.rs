//! Janssen fits for a 2D column between two vertical walls (law in [`crate::laws::janssen`]).
//!
//! - [`fit_janssen`]: joint fit of `K` and the mobilised wall friction `μ_w` to the vertical
//!   stress `σ_v(z)` and the wall normal stress `σ_h(z)` (and optionally the wall shear
//!   `τ_w(z)`), bounds `K > 0`, `0 < μ_w ≤ μ_wall`. Each quantity is a group with its own
//!   estimated noise level ([`crate::fit`]). `σ_v` alone fixes `K μ_w` only (the exponent);
//!   `σ_h = K σ_v` separates `K`.
//! - [`fit_janssen_k_mu`]: the one-parameter fit of `K μ_w` from `σ_v` alone.
//! - [`fit_janssen_full_mobilisation`]: `μ_w` fixed at `μ_wall` (Janssen's own assumption:
//!   every wall contact sliding), fitting `K` only. The documented fallback when the joint fit
//!   returns [`IdentifyError::ParameterAtBound`] for `mu_w` at its upper bound.
//!
//! Every fit passes the checks of [`crate::accept`] or is refused: intervals of `K`, `K μ_w`
//! non-negative and of `μ_w` inside `[0, μ_wall]` (crossing `μ_wall` offers full
//! mobilisation), standard errors below the values, `R²` above the threshold, and an adjusted
//! `R²` not below that of the nested form (full mobilisation for the joint fit, the hydrostatic
//! line `ρ_b g z` for `K μ_w`).
//!
//! Each result reports `K`, `μ_w`, `K μ_w`, the saturation length `λ = W/(2Kμ_w)` and the
//! mobilisation `μ_w/μ_wall` with 95 % intervals (delta method for derived quantities), the
//! residuals by depth with the hydrostatic line `ρ_b g z`, and the depth range used.
//! A depth window skips the top rebound zone (and any bottom layer affected by the floor).
//!
//! Inputs are compressive-positive magnitudes in Pa; depth `z` in m, down from the free surface.

use serde::{Deserialize, Serialize};

use crate::accept::{r_squared_of, Acceptance, NestedForm, PhysicalRange};
use crate::error::{
    check_finite, check_non_negative_pressure, check_same_len, check_setup_positive, check_spread,
    BoundSide, IdentifyError, Result,
};
use crate::fit::{
    fit_least_squares, log_grid, FitOptions, LeastSquaresModel, Observations, ParameterSpec,
};
use crate::laws::janssen::{janssen_shape, JanssenLaw, JanssenVerticalLaw, STANDARD_GRAVITY};
use crate::report::{Estimate, FitReport, ValidityRange};
use crate::stats::min_max;
use nalgebra::DMatrix;

/// What a refusal of the joint fit offers when `μ_w` reaches the wall friction.
const FULL_MOBILISATION: &str =
    "use full mobilisation, mu_w = mu_wall (janssen with '# full_mobilisation = 1')";

/// A measured stress profile down a column (data).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JanssenProfile {
    /// Depth below the free surface `z` (m), one per row.
    pub z_m: Vec<f64>,
    /// Vertical stress `σ_v` (Pa, compressive positive).
    pub sigma_v_pa: Vec<f64>,
    /// Wall normal stress `σ_h` (Pa, compressive positive), needed by [`fit_janssen`].
    pub sigma_h_pa: Option<Vec<f64>>,
    /// Wall shear stress magnitude `τ_w` (Pa), optional.
    pub tau_w_pa: Option<Vec<f64>>,
}

/// Constants of the column (data).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JanssenSetup {
    /// Column width `W` between the walls (m).
    pub width_m: f64,
    /// Bulk density `ρ_b = φ ρ_grain` (kg/m³), measured.
    pub bulk_density_kg_m3: f64,
    /// Gravity `g` (m/s²).
    pub gravity_m_s2: f64,
    /// Grain–wall friction coefficient `μ_wall` (1): upper bound of `μ_w`.
    pub wall_friction: f64,
}

impl JanssenSetup {
    /// Set-up with `g` = [`STANDARD_GRAVITY`].
    pub fn new(width_m: f64, bulk_density_kg_m3: f64, wall_friction: f64) -> Self {
        JanssenSetup {
            width_m,
            bulk_density_kg_m3,
            gravity_m_s2: STANDARD_GRAVITY,
            wall_friction,
        }
    }

    fn validate(&self, need_wall_friction: bool) -> Result<()> {
        check_setup_positive("width_m", self.width_m)?;
        check_setup_positive("bulk_density_kg_m3", self.bulk_density_kg_m3)?;
        check_setup_positive("gravity_m_s2", self.gravity_m_s2)?;
        if need_wall_friction {
            check_setup_positive("wall_friction", self.wall_friction)?;
        }
        Ok(())
    }
}

/// Options of the Janssen fits.
#[derive(Debug, Clone, PartialEq)]
pub struct JanssenOptions {
    /// Only depths `z_min ≤ z ≤ z_max` are used (m); `None` uses all.
    pub depth_window: Option<(f64, f64)>,
    /// Include `τ_w` as a third group when the profile has it (default true).
    pub use_tau_w: bool,
    /// Generic fit options (confidence level, bootstrap, ...).
    pub fit: FitOptions,
}

impl Default for JanssenOptions {
    fn default() -> Self {
        JanssenOptions {
            depth_window: None,
            use_tau_w: true,
            fit: FitOptions::default(),
        }
    }
}

/// Residuals at one depth (Pa): data minus the fitted law.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DepthResidual {
    /// Depth (m).
    pub z_m: f64,
    /// `σ_v` residual.
    pub sigma_v_pa: f64,
    /// `σ_h` residual, when fitted.
    pub sigma_h_pa: Option<f64>,
    /// `τ_w` residual, when fitted.
    pub tau_w_pa: Option<f64>,
    /// Hydrostatic line `ρ_b g z` at this depth, for comparison.
    pub hydrostatic_pa: f64,
}

/// Result of [`fit_janssen`] or [`fit_janssen_full_mobilisation`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JanssenFit {
    /// The calibrated law.
    pub law: JanssenLaw,
    /// The fit (parameters `K`, `mu_w`; only `K` under full mobilisation).
    pub report: FitReport,
    /// Stress ratio `K` (1).
    pub k: Estimate,
    /// Mobilised wall friction `μ_w` (1). Under full mobilisation it is `μ_wall` with zero
    /// standard error and `at_bound = true`.
    pub mu_w: Estimate,
    /// `K μ_w` (1).
    pub k_mu_w: Estimate,
    /// Saturation length `λ = W/(2 K μ_w)` (m).
    pub saturation_length_m: Estimate,
    /// Mobilisation `μ_w / μ_wall` (1).
    pub mobilisation: Estimate,
    /// Grain–wall friction `μ_wall` the fit was bounded by (1).
    pub wall_friction: f64,
    /// Depth range used `[z_min, z_max]` (m).
    pub depth_range_m: [f64; 2],
    /// Depths used / depths given.
    pub points_used: usize,
    /// Depths given.
    pub points_total: usize,
    /// Residuals by depth.
    pub residuals_by_depth: Vec<DepthResidual>,
}

impl JanssenFit {
    /// Flat `(key, value)` pairs for a scenario's `summary.json`: `janssen_K`,
    /// `janssen_mu_w`, `janssen_K_mu_w`, `janssen_saturation_length_m`, `janssen_mobilisation`,
    /// each with `_ci_low`/`_ci_high`, then `janssen_r_squared`, `janssen_depth_min_m`,
    /// `janssen_depth_max_m`, `janssen_points`.
    pub fn summary_entries(&self) -> Vec<(String, f64)> {
        let mut out = Vec::new();
        for (key, e) in [
            ("janssen_K", &self.k),
            ("janssen_mu_w", &self.mu_w),
            ("janssen_K_mu_w", &self.k_mu_w),
            ("janssen_saturation_length_m", &self.saturation_length_m),
            ("janssen_mobilisation", &self.mobilisation),
        ] {
            out.push((key.to_string(), e.value));
            out.push((format!("{key}_ci_low"), e.ci_low));
            out.push((format!("{key}_ci_high"), e.ci_high));
        }
        out.push(("janssen_r_squared".into(), self.report.r_squared));
        out.push(("janssen_depth_min_m".into(), self.depth_range_m[0]));
        out.push(("janssen_depth_max_m".into(), self.depth_range_m[1]));
        out.push(("janssen_points".into(), self.points_used as f64));
        out
    }
}

/// Result of [`fit_janssen_k_mu`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JanssenKMuFit {
    /// The calibrated `σ_v` law.
    pub law: JanssenVerticalLaw,
    /// The fit (parameter `K_mu_w`).
    pub report: FitReport,
    /// `K μ_w` (1).
    pub k_mu_w: Estimate,
    /// Saturation length `λ = W/(2 K μ_w)` (m).
    pub saturation_length_m: Estimate,
    /// Depth range used (m).
    pub depth_range_m: [f64; 2],
    /// Depths used.
    pub points_used: usize,
    /// Depths given.
    pub points_total: usize,
    /// Residuals by depth (only `σ_v`).
    pub residuals_by_depth: Vec<DepthResidual>,
}

/// The profile restricted to the depth window, validated.
struct Selected {
    z: Vec<f64>,
    sv: Vec<f64>,
    sh: Option<Vec<f64>>,
    tw: Option<Vec<f64>>,
    total: usize,
}

fn select(profile: &JanssenProfile, options: &JanssenOptions, need_h: bool) -> Result<Selected> {
    let z = &profile.z_m;
    check_finite("z_m", z)?;
    check_finite("sigma_v_Pa", &profile.sigma_v_pa)?;
    check_same_len("z_m", z, "sigma_v_Pa", &profile.sigma_v_pa)?;
    if let Some(i) = z.iter().position(|v| *v < 0.0) {
        return Err(IdentifyError::OutOfDomain {
            column: "z_m".into(),
            index: i,
            value: z[i],
            expected: "a depth below the free surface, z ≥ 0".into(),
        });
    }
    check_non_negative_pressure("sigma_v_Pa", &profile.sigma_v_pa)?;
    let sh = if need_h {
        let sh = profile
            .sigma_h_pa
            .as_ref()
            .ok_or_else(|| IdentifyError::NotIdentifiable {
                reason: "K and μ_w need the wall normal stress σ_h(z); with σ_v alone only K μ_w is identified (use the one-parameter K·μ_w fit)".into(),
            })?;
        check_finite("sigma_h_Pa", sh)?;
        check_same_len("z_m", z, "sigma_h_Pa", sh)?;
        check_non_negative_pressure("sigma_h_Pa", sh)?;
        Some(sh)
    } else {
        None
    };
    let tw = match (&profile.tau_w_pa, need_h && options.use_tau_w) {
        (Some(tw), true) => {
            check_finite("tau_w_Pa", tw)?;
            check_same_len("z_m", z, "tau_w_Pa", tw)?;
            if let Some(i) = tw.iter().position(|v| *v < 0.0) {
                return Err(IdentifyError::OutOfDomain {
                    column: "tau_w_Pa".into(),
                    index: i,
                    value: tw[i],
                    expected: "a wall shear magnitude ≥ 0".into(),
                });
            }
            Some(tw)
        }
        _ => None,
    };
    let (lo, hi) = options
        .depth_window
        .unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
    let keep: Vec<usize> = (0..z.len()).filter(|&i| z[i] >= lo && z[i] <= hi).collect();
    let pick = |v: &Vec<f64>| keep.iter().map(|&i| v[i]).collect::<Vec<f64>>();
    let sel = Selected {
        z: pick(z),
        sv: pick(&profile.sigma_v_pa),
        sh: sh.map(pick),
        tw: tw.map(pick),
        total: z.len(),
    };
    if sel.z.len() < 3 && options.depth_window.is_some() {
        return Err(IdentifyError::EmptyDepthWindow {
            z_min: lo,
            z_max: hi,
            kept: sel.z.len(),
            total: z.len(),
        });
    }
    // At least (parameters + 2) depths: 4 for (K, μ_w), 3 for K μ_w.
    let needed = if need_h { 4 } else { 3 };
    if sel.z.len() < needed {
        return Err(IdentifyError::TooFewPoints {
            law: if need_h { "janssen" } else { "janssen-kmu" }.into(),
            needed,
            got: sel.z.len(),
        });
    }
    check_spread("z_m", &sel.z)?;
    Ok(sel)
}

/// Joint model: groups `σ_v`, `σ_h` (and `τ_w`) at the same depths; parameters `(K, μ_w)`, or
/// `(K)` with `μ_w` fixed.
struct JointModel<'a> {
    z: &'a [f64],
    setup: JanssenSetup,
    with_tau: bool,
    mu_fixed: Option<f64>,
}

impl JointModel<'_> {
    fn k_mu(&self, t: &[f64]) -> (f64, f64) {
        (t[0], self.mu_fixed.unwrap_or_else(|| t[1]))
    }
}

impl LeastSquaresModel for JointModel<'_> {
    fn name(&self) -> String {
        if self.mu_fixed.is_some() {
            "janssen (full mobilisation)".into()
        } else {
            "janssen".into()
        }
    }
    fn parameters(&self) -> Vec<ParameterSpec> {
        let mut p = vec![ParameterSpec::new("K", "1", 0.0, f64::INFINITY)];
        if self.mu_fixed.is_none() {
            p.push(ParameterSpec::new(
                "mu_w",
                "1",
                0.0,
                self.setup.wall_friction,
            ));
        }
        p
    }
    fn predict(&self, t: &[f64]) -> Vec<f64> {
        let (k, mu) = self.k_mu(t);
        let rg = self.setup.bulk_density_kg_m3 * self.setup.gravity_m_s2;
        let a = 2.0 * k * mu / self.setup.width_m;
        let sv: Vec<f64> = self.z.iter().map(|&z| rg * janssen_shape(a, z).0).collect();
        let mut out = sv.clone();
        out.extend(sv.iter().map(|s| k * s));
        if self.with_tau {
            out.extend(sv.iter().map(|s| mu * k * s));
        }
        out
    }
    fn jacobian(&self, t: &[f64]) -> DMatrix<f64> {
        let (k, mu) = self.k_mu(t);
        let rg = self.setup.bulk_density_kg_m3 * self.setup.gravity_m_s2;
        let w = self.setup.width_m;
        let a = 2.0 * k * mu / w;
        let n = self.z.len();
        let groups = if self.with_tau { 3 } else { 2 };
        let np = if self.mu_fixed.is_some() { 1 } else { 2 };
        let mut jac = DMatrix::zeros(groups * n, np);
        for (i, &z) in self.z.iter().enumerate() {
            let (f, df) = janssen_shape(a, z);
            let sv = rg * f;
            let dsv_dk = rg * df * 2.0 * mu / w;
            let dsv_dmu = rg * df * 2.0 * k / w;
            jac[(i, 0)] = dsv_dk;
            jac[(n + i, 0)] = sv + k * dsv_dk;
            if self.with_tau {
                jac[(2 * n + i, 0)] = mu * sv + mu * k * dsv_dk;
            }
            if np == 2 {
                jac[(i, 1)] = dsv_dmu;
                jac[(n + i, 1)] = k * dsv_dmu;
                if self.with_tau {
                    jac[(2 * n + i, 1)] = k * sv + mu * k * dsv_dmu;
                }
            }
        }
        jac
    }
}

/// One-parameter model `σ_v(z; K μ_w)`.
struct VerticalModel<'a> {
    z: &'a [f64],
    setup: JanssenSetup,
}

impl LeastSquaresModel for VerticalModel<'_> {
    fn name(&self) -> String {
        "janssen-kmu".into()
    }
    fn parameters(&self) -> Vec<ParameterSpec> {
        vec![ParameterSpec::new("K_mu_w", "1", 0.0, f64::INFINITY)]
    }
    fn predict(&self, t: &[f64]) -> Vec<f64> {
        let rg = self.setup.bulk_density_kg_m3 * self.setup.gravity_m_s2;
        let a = 2.0 * t[0] / self.setup.width_m;
        self.z.iter().map(|&z| rg * janssen_shape(a, z).0).collect()
    }
    fn jacobian(&self, t: &[f64]) -> DMatrix<f64> {
        let rg = self.setup.bulk_density_kg_m3 * self.setup.gravity_m_s2;
        let w = self.setup.width_m;
        let a = 2.0 * t[0] / w;
        DMatrix::from_fn(self.z.len(), 1, |i, _| {
            rg * janssen_shape(a, self.z[i]).1 * 2.0 / w
        })
    }
}

/// Start for `K μ_w`: the best of a log grid of saturation lengths `λ ∈ [10⁻² z_max, 10³ z_max]`.
fn k_mu_start(z: &[f64], sv: &[f64], setup: &JanssenSetup) -> f64 {
    let (_, zmax) = min_max(z);
    let rg = setup.bulk_density_kg_m3 * setup.gravity_m_s2;
    let mut best = (f64::INFINITY, 1.0);
    for lambda in log_grid(1e-2 * zmax, 1e3 * zmax, 101) {
        let a = 1.0 / lambda;
        let rss: f64 = z
            .iter()
            .zip(sv)
            .map(|(&z, &s)| (s - rg * janssen_shape(a, z).0).powi(2))
            .sum();
        if rss < best.0 {
            best = (rss, setup.width_m / (2.0 * lambda));
        }
    }
    best.1
}

fn validity(sel: &Selected) -> Vec<ValidityRange> {
    let mut v = vec![
        ValidityRange::of("z", "m", &sel.z),
        ValidityRange::of("sigma_v", "Pa", &sel.sv),
    ];
    if let Some(sh) = &sel.sh {
        v.push(ValidityRange::of("sigma_h", "Pa", sh));
    }
    v
}

fn residual_rows(sel: &Selected, report: &FitReport, setup: &JanssenSetup) -> Vec<DepthResidual> {
    let n = sel.z.len();
    let r = &report.residuals;
    (0..n)
        .map(|i| DepthResidual {
            z_m: sel.z[i],
            sigma_v_pa: r[i],
            sigma_h_pa: sel.sh.as_ref().map(|_| r[n + i]),
            tau_w_pa: sel.tw.as_ref().map(|_| r[2 * n + i]),
            hydrostatic_pa: setup.bulk_density_kg_m3 * setup.gravity_m_s2 * sel.z[i],
        })
        .collect()
}

/// Joint fit of `K` and `μ_w` (see the module documentation).
///
/// Errors: the data checks of [`crate::fit::fit_least_squares`]; [`IdentifyError::NotIdentifiable`]
/// without `σ_h`; [`IdentifyError::NegativePressure`]; [`IdentifyError::EmptyDepthWindow`];
/// [`IdentifyError::ParameterAtBound`] when `K → 0`, `μ_w → 0` or `μ_w → μ_wall` (for the last,
/// see [`fit_janssen_full_mobilisation`]); the refusals of the module documentation.
pub fn fit_janssen(
    profile: &JanssenProfile,
    setup: &JanssenSetup,
    options: &JanssenOptions,
) -> Result<JanssenFit> {
    fit_joint(profile, setup, options, None)
}

/// Fit of `K` with `μ_w = μ_wall` fixed (full mobilisation, Janssen's assumption). `mu_w` is
/// reported with zero standard error and `at_bound = true`; the mobilisation is exactly 1.
pub fn fit_janssen_full_mobilisation(
    profile: &JanssenProfile,
    setup: &JanssenSetup,
    options: &JanssenOptions,
) -> Result<JanssenFit> {
    fit_joint(profile, setup, options, Some(setup.wall_friction))
}

fn fit_joint(
    profile: &JanssenProfile,
    setup: &JanssenSetup,
    options: &JanssenOptions,
    mu_fixed: Option<f64>,
) -> Result<JanssenFit> {
    setup.validate(true)?;
    let sel = select(profile, options, true)?;
    let sh = sel.sh.clone().unwrap_or_default();
    let with_tau = sel.tw.is_some();
    let mut groups = vec![
        ("sigma_v".to_string(), sel.sv.clone()),
        ("sigma_h".to_string(), sh.clone()),
    ];
    if let Some(tw) = &sel.tw {
        groups.push(("tau_w".to_string(), tw.clone()));
    }
    let obs = Observations::grouped(groups);
    let model = JointModel {
        z: &sel.z,
        setup: *setup,
        with_tau,
        mu_fixed,
    };
    // Start: K from the median of σ_h/σ_v over the stressed part, K μ_w from σ_v.
    let (_, sv_max) = min_max(&sel.sv);
    let mut ratios: Vec<f64> = sel
        .sv
        .iter()
        .zip(&sh)
        .filter(|(v, _)| **v > 0.05 * sv_max)
        .map(|(v, h)| h / v)
        .collect();
    ratios.sort_by(f64::total_cmp);
    let k0 = ratios
        .get(ratios.len() / 2)
        .copied()
        .unwrap_or(0.5)
        .max(1e-3);
    let theta0 = match mu_fixed {
        Some(_) => vec![k0],
        None => {
            let kmu = if sel.sv.len() >= 2 {
                k_mu_start(&sel.z, &sel.sv, setup)
            } else {
                0.1
            };
            let mu0 = (kmu / k0).clamp(1e-3 * setup.wall_friction, 0.9 * setup.wall_friction);
            vec![k0, mu0]
        }
    };
    let report = fit_least_squares(&model, &obs, &theta0, &options.fit, validity(&sel)).map_err(
        |e| match &e {
            IdentifyError::ParameterAtBound {
                name,
                side: BoundSide::Upper,
                ..
            } if name == "mu_w" => e.suggesting(FULL_MOBILISATION),
            _ => e,
        },
    )?;
    let acceptance = Acceptance::new(&model.name(), options.fit.min_r_squared).non_negative(&["K"]);
    match mu_fixed {
        Some(_) => acceptance,
        None => {
            let nested = fit_joint(profile, setup, options, Some(setup.wall_friction))
                .ok()
                .map(|f| NestedForm {
                    name: "janssen with full mobilisation (# full_mobilisation = 1)".into(),
                    r_squared: f.report.r_squared,
                    parameters: 1,
                });
            acceptance
                .range(
                    PhysicalRange::new("mu_w", 0.0, setup.wall_friction)
                        .suggesting(FULL_MOBILISATION),
                )
                .nested(nested)
        }
    }
    .check(&report)?;
    let t = report.t_critical;
    let k = report.parameters[0].clone();
    let mu_w = match mu_fixed {
        Some(mu) => Estimate {
            at_bound: true,
            ..Estimate::new("mu_w", "1", mu, 0.0, t)
        },
        None => report.parameters[1].clone(),
    };
    let w = setup.width_m;
    let mu_wall = setup.wall_friction;
    let (k_mu_w, lambda, mobilisation) = match mu_fixed {
        Some(mu) => (
            report.derived("K_mu_w", "1", |p| (p[0] * mu, vec![mu])),
            report.derived("saturation_length", "m", |p| {
                let l = w / (2.0 * p[0] * mu);
                (l, vec![-l / p[0]])
            }),
            Estimate {
                at_bound: true,
                ..Estimate::new("mobilisation", "1", 1.0, 0.0, t)
            },
        ),
        None => (
            report.derived("K_mu_w", "1", |p| (p[0] * p[1], vec![p[1], p[0]])),
            report.derived("saturation_length", "m", |p| {
                let l = w / (2.0 * p[0] * p[1]);
                (l, vec![-l / p[0], -l / p[1]])
            }),
            report.derived("mobilisation", "1", |p| {
                (p[1] / mu_wall, vec![0.0, 1.0 / mu_wall])
            }),
        ),
    };
    let law = JanssenLaw {
        k: k.value,
        mu_w: mu_w.value,
        width_m: w,
        bulk_density_kg_m3: setup.bulk_density_kg_m3,
        gravity_m_s2: setup.gravity_m_s2,
    };
    let (zmin, zmax) = min_max(&sel.z);
    Ok(JanssenFit {
        law,
        residuals_by_depth: residual_rows(&sel, &report, setup),
        k,
        mu_w,
        k_mu_w,
        saturation_length_m: lambda,
        mobilisation,
        wall_friction: mu_wall,
        depth_range_m: [zmin, zmax],
        points_used: sel.z.len(),
        points_total: sel.total,
        report,
    })
}

/// One-parameter fit of `K μ_w` to `σ_v(z)` alone (`σ_h`, `τ_w` ignored; `wall_friction` not
/// needed). Errors as [`fit_janssen`]; `K μ_w → 0` (a hydrostatic profile) is
/// [`IdentifyError::ParameterAtBound`].
pub fn fit_janssen_k_mu(
    profile: &JanssenProfile,
    setup: &JanssenSetup,
    options: &JanssenOptions,
) -> Result<JanssenKMuFit> {
    setup.validate(false)?;
    let sel = select(profile, options, false)?;
    let obs = Observations::single("sigma_v", sel.sv.clone());
    let model = VerticalModel {
        z: &sel.z,
        setup: *setup,
    };
    let theta0 = if sel.sv.len() >= 2 {
        vec![k_mu_start(&sel.z, &sel.sv, setup)]
    } else {
        vec![0.1]
    };
    let report = fit_least_squares(&model, &obs, &theta0, &options.fit, validity(&sel))?;
    let rg = setup.bulk_density_kg_m3 * setup.gravity_m_s2;
    let hydrostatic: Vec<f64> = sel.z.iter().map(|z| rg * z).collect();
    Acceptance::new("janssen-kmu", options.fit.min_r_squared)
        .non_negative(&["K_mu_w"])
        .nested(Some(NestedForm {
            name: "the hydrostatic line rho_b*g*z".into(),
            r_squared: r_squared_of(&sel.sv, &hydrostatic),
            parameters: 0,
        }))
        .check(&report)?;
    let w = setup.width_m;
    let k_mu_w = report.parameters[0].clone();
    let lambda = report.derived("saturation_length", "m", |p| {
        let l = w / (2.0 * p[0]);
        (l, vec![-l / p[0]])
    });
    let law = JanssenVerticalLaw {
        k_mu_w: k_mu_w.value,
        width_m: w,
        bulk_density_kg_m3: setup.bulk_density_kg_m3,
        gravity_m_s2: setup.gravity_m_s2,
    };
    let (zmin, zmax) = min_max(&sel.z);
    Ok(JanssenKMuFit {
        law,
        residuals_by_depth: residual_rows(&sel, &report, setup),
        k_mu_w,
        saturation_length_m: lambda,
        depth_range_m: [zmin, zmax],
        points_used: sel.z.len(),
        points_total: sel.total,
        report,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::finite_difference_jacobian;

    #[test]
    fn analytic_jacobians_match_finite_differences() {
        let z: Vec<f64> = (0..12).map(|i| 0.01 * i as f64).collect();
        let setup = JanssenSetup::new(0.03, 1500.0, 0.4);
        for with_tau in [false, true] {
            let m = JointModel {
                z: &z,
                setup,
                with_tau,
                mu_fixed: None,
            };
            let t = [0.7, 0.25];
            let a = m.jacobian(&t);
            let f = finite_difference_jacobian(|p| m.predict(p), &t);
            assert!((a - f).amax() < 1e-5 * 1500.0 * 9.81 * 0.1);
        }
        let m = VerticalModel { z: &z, setup };
        let a = m.jacobian(&[0.2]);
        let f = finite_difference_jacobian(|p| m.predict(p), &[0.2]);
        assert!((a - f).amax() < 1e-5 * 1500.0 * 9.81 * 0.1);
    }
}
