//! Mohr–Coulomb envelope (friction angle, cohesion) from stress states at yield, posed as a
//! second-order cone program solved by Clarabel (law in [`crate::laws::mohr_coulomb`]).
//!
//! Both input forms reduce to a straight line `y = a x + b` with sign constraints:
//! - Mohr circles at yield ([`YieldData::Circles`], from 2D tensors or principal stresses):
//!   `x = p = (σ₁ + σ₃)/2`, `y = q = (σ₁ − σ₃)/2`, tangency `q = p sin φ + c cos φ`, so
//!   `a = sin φ ∈ [0, 1]`, `b = c cos φ ≥ 0`;
//! - failure-plane tractions ([`YieldData::FailurePlane`], direct shear):
//!   `x = σ_n`, `y = |τ|`, `τ = c + σ_n tan φ`, so `a = tan φ ≥ 0`, `b = c ≥ 0`.
//!
//! Objective: least squares on `y`, `min ‖y − a x − b 1‖₂` subject to the constraints, written as
//! the conic program `min t` s.t. `(t, y − a x − b) ∈ SOC`, `b ≥ 0`, `a ≥ 0` (`a ≤ 1`).
//! Why this norm: with Gaussian scatter of the yield stress it is the maximum-likelihood
//! estimate; when no constraint is active it equals ordinary least squares, so the OLS
//! covariance `s² (XᵀX)⁻¹` gives honest intervals; and the cone form lets the solver enforce
//! `c ≥ 0` exactly (a plain regression returns negative cohesion on cohesionless data).
//! (An L1 objective would be an LP and more robust to outliers, but has no simple covariance.)
//! Scatter in `x` is neglected (regression of `y` on `x`).
//!
//! Cohesion at zero is an expected outcome for a cohesionless material, not a failure: the fit
//! then reports `c = 0` with `at_bound = true`, refits `a` through the origin for the
//! friction angle's interval, and gives for `c` the one-sided interval
//! `[0, max(b_ols, 0) + t·se(b_ols)]` from the unconstrained regression (Student's `t` at
//! `n − 2` degrees of freedom; `b` turned into `c = b / cos φ` for circles), with the standard
//! error `se(b_ols)` (likewise turned into `c`'s). The upper end never falls below `t·se`, the
//! end the data would give at `b_ols = 0`: a regression that dips below zero does not claim a
//! precision the data lack (the power-constrained limit of Cowan, Cranmer, Gross & Vitells,
//! arXiv:1105.3166, 2011). The friction coefficient ending at `a = 0` (or `sin φ = 1`) is
//! [`IdentifyError::ParameterAtBound`].
//!
//! With the cohesion fixed at zero ([`MohrCoulombOptions::cohesionless`], `# cohesion = 0` in a
//! CSV) only `a` is fitted, through the origin, and three states at yield suffice (`n ≥ p + 2`).
//! A cohesion the user fixed is a constant, not an estimate: interval `[0, 0]`, standard error 0.
//! A cohesion fixed at zero because the data do not support one
//! ([`MohrCoulombOptions::cohesion_held_by_data`], what [`fit_mohr_coulomb_supported`] falls back
//! to) is an estimate at its bound and gets the one-sided interval above.
//!
//! The fit then passes the checks of [`crate::accept`] or is refused: the interval of `φ`
//! inside `[0, π/2]` and of `c` above 0 (a cohesion whose interval crosses 0 offers to fix it
//! at zero), standard errors below the values, `R²` above the threshold, and an adjusted `R²`
//! not below that of the cohesionless envelope.
//!
//! The 2D Drucker–Prager equivalent is [`MohrCoulombLaw::drucker_prager_2d`]
//! (`α = sin φ`, `k = c cos φ`, exact in 2D).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::accept::{Acceptance, NestedForm, PhysicalRange};
use crate::error::{
    check_finite, check_non_negative_pressure, check_same_len, check_spread, BoundSide,
    IdentifyError, Result,
};
use crate::laws::mohr_coulomb::{p_q_from_tension_positive, MohrCoulombLaw};
use crate::report::{
    correlation_of, matrix_rows, Estimate, FitReport, GroupSummary, ValidityRange,
};
use crate::stats;
use crate::stats::min_max;

/// Stress states at yield (data). Compressive-positive magnitudes, Pa.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum YieldData {
    /// Mohr circles: centre `p = (σ₁ + σ₃)/2` and radius `q = (σ₁ − σ₃)/2`.
    Circles {
        /// Mean in-plane stress `p` (Pa).
        p_pa: Vec<f64>,
        /// Circle radius `q` (Pa).
        q_pa: Vec<f64>,
    },
    /// Normal and shear traction on the failure plane.
    FailurePlane {
        /// Normal stress `σ_n` (Pa).
        sigma_n_pa: Vec<f64>,
        /// Shear stress `τ` (Pa); its magnitude is used.
        tau_pa: Vec<f64>,
    },
}

impl YieldData {
    /// Number of stress states.
    pub fn len(&self) -> usize {
        match self {
            YieldData::Circles { p_pa, .. } => p_pa.len(),
            YieldData::FailurePlane { sigma_n_pa, .. } => sigma_n_pa.len(),
        }
    }

    /// Whether there is no stress state.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Mohr circles from 2D tension-positive stress tensors `(σ_xx, σ_yy, σ_xy)` (the project's
    /// convention, e.g. homogenised `Σ`): `p = −(σ_xx + σ_yy)/2`,
    /// `q = √(((σ_xx − σ_yy)/2)² + σ_xy²)`.
    pub fn from_tension_positive_tensors(tensors: &[[f64; 3]]) -> Self {
        let (p_pa, q_pa) = tensors
            .iter()
            .map(|t| p_q_from_tension_positive(t[0], t[1], t[2]))
            .unzip();
        YieldData::Circles { p_pa, q_pa }
    }

    /// Mohr circles from compressive-positive principal stresses `σ₁ ≥ σ₃`.
    pub fn from_principal(sigma_1_pa: &[f64], sigma_3_pa: &[f64]) -> Self {
        YieldData::Circles {
            p_pa: sigma_1_pa
                .iter()
                .zip(sigma_3_pa)
                .map(|(a, b)| 0.5 * (a + b))
                .collect(),
            q_pa: sigma_1_pa
                .iter()
                .zip(sigma_3_pa)
                .map(|(a, b)| 0.5 * (a - b).abs())
                .collect(),
        }
    }
}

/// Result of [`fit_mohr_coulomb`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MohrCoulombFit {
    /// The calibrated law.
    pub law: MohrCoulombLaw,
    /// Friction angle `φ` (rad).
    pub friction_angle: Estimate,
    /// Friction angle in degrees (same estimate, for reading).
    pub friction_angle_deg: Estimate,
    /// Cohesion `c` (Pa); `at_bound = true` when the constraint `c ≥ 0` is active.
    pub cohesion: Estimate,
    /// The fit, with parameters `friction_angle` (rad) and `cohesion` (Pa); residuals on `q`
    /// (circles) or `|τ|` (failure plane).
    pub report: FitReport,
}

/// What a refusal offers when the cohesion is not supported by the data.
const COHESIONLESS: &str =
    "fix the cohesion at zero ('# cohesion = 0', MohrCoulombOptions::cohesionless)";

/// Options of [`fit_mohr_coulomb_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MohrCoulombOptions {
    /// Confidence level of the intervals (default 0.95).
    pub confidence: f64,
    /// Fix the cohesion at `c = 0` instead of fitting it (default false).
    pub cohesion_fixed_zero: bool,
    /// With `cohesion_fixed_zero`: the cohesion is held at zero because the data do not support
    /// one (not asserted by the user), so it is reported as an estimate at its bound, with the
    /// one-sided interval of the unconstrained regression (module documentation), not `[0, 0]`
    /// (default false).
    pub cohesion_held_by_data: bool,
    /// R² threshold (default [`crate::accept::MIN_R_SQUARED`]).
    pub min_r_squared: f64,
}

impl Default for MohrCoulombOptions {
    fn default() -> Self {
        MohrCoulombOptions {
            confidence: 0.95,
            cohesion_fixed_zero: false,
            cohesion_held_by_data: false,
            min_r_squared: crate::accept::MIN_R_SQUARED,
        }
    }
}

impl MohrCoulombOptions {
    /// Defaults with the cohesion fixed at zero.
    pub fn cohesionless() -> Self {
        MohrCoulombOptions {
            cohesion_fixed_zero: true,
            ..Default::default()
        }
    }
}

/// Solves `min ‖y − a x − b‖₂` s.t. `a ≥ 0`, `b ≥ 0`, `a ≤ a_max` (if finite) with Clarabel.
/// Inputs are scaled by `max |y|` for conditioning. Returns `(a, b)`.
fn solve_conic(x: &[f64], y: &[f64], a_max: f64) -> Result<(f64, f64)> {
    let n = x.len();
    let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    let xs: Vec<f64> = x.iter().map(|v| v / scale).collect();
    let ys: Vec<f64> = y.iter().map(|v| v / scale).collect();
    // Variables (a, b, t). Rows: nonnegative cone [a ≥ 0, b ≥ 0, (a ≤ a_max)], then SOC of
    // dimension n + 1: (t, y − a x − b).
    let n_nonneg = if a_max.is_finite() { 3 } else { 2 };
    let m = n_nonneg + 1 + n;
    let mut rows_a = Vec::new();
    let mut vals_a = Vec::new();
    let mut rows_b = Vec::new();
    let mut vals_b = Vec::new();
    let mut rhs = vec![0.0; m];
    // a ≥ 0: s = a → −a + s = 0.
    rows_a.push(0);
    vals_a.push(-1.0);
    // b ≥ 0.
    rows_b.push(1);
    vals_b.push(-1.0);
    if a_max.is_finite() {
        rows_a.push(2);
        vals_a.push(1.0);
        rhs[2] = a_max;
    }
    // SOC head: s₀ = t.
    let head = n_nonneg;
    for k in 0..n {
        let r = head + 1 + k;
        rows_a.push(r);
        vals_a.push(xs[k]);
        rows_b.push(r);
        vals_b.push(1.0);
        rhs[r] = ys[k];
    }
    let mut colptr = vec![0];
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    for (rows, vals) in [(rows_a, vals_a), (rows_b, vals_b), (vec![head], vec![-1.0])] {
        rowval.extend(rows);
        nzval.extend(vals);
        colptr.push(rowval.len());
    }
    let a_mat = CscMatrix::new(m, 3, colptr, rowval, nzval);
    let p_mat = CscMatrix::new(3, 3, vec![0, 0, 0, 0], vec![], vec![]);
    let q = [0.0, 0.0, 1.0];
    let cones = [
        SupportedConeT::NonnegativeConeT(n_nonneg),
        SupportedConeT::SecondOrderConeT(n + 1),
    ];
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .tol_gap_abs(1e-12)
        .tol_gap_rel(1e-12)
        .tol_feas(1e-12)
        .build()
        .map_err(|e| IdentifyError::ConicSolver {
            status: format!("settings: {e}"),
        })?;
    let mut solver =
        DefaultSolver::new(&p_mat, &q, &a_mat, &rhs, &cones, settings).map_err(|e| {
            IdentifyError::ConicSolver {
                status: format!("{e:?}"),
            }
        })?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {}
        status => {
            return Err(IdentifyError::ConicSolver {
                status: format!("{status:?}"),
            })
        }
    }
    let sol = &solver.solution.x;
    Ok((sol[0], sol[1] * scale))
}

/// Ordinary least squares `y = a x + b`: `(a, b, cov, rss)`.
fn ols(x: &[f64], y: &[f64]) -> (f64, f64, DMatrix<f64>, f64) {
    let n = x.len();
    let xm = DMatrix::from_fn(n, 2, |k, j| if j == 0 { x[k] } else { 1.0 });
    let yv = DVector::from_column_slice(y);
    let xtx = xm.tr_mul(&xm);
    let inv = xtx
        .try_inverse()
        .unwrap_or_else(|| DMatrix::from_element(2, 2, f64::NAN));
    let beta = &inv * xm.tr_mul(&yv);
    let rss = (&xm * &beta - &yv).norm_squared();
    let s2 = rss / (n - 2) as f64;
    (beta[0], beta[1], inv * s2, rss)
}

/// Fits the Mohr–Coulomb envelope with the default options (see the module documentation and
/// [`fit_mohr_coulomb_with`]).
pub fn fit_mohr_coulomb(data: &YieldData, confidence: f64) -> Result<MohrCoulombFit> {
    fit_mohr_coulomb_with(
        data,
        &MohrCoulombOptions {
            confidence,
            ..Default::default()
        },
    )
}

/// Fits the envelope in the form the data support: with a free cohesion (at least 4 states)
/// and, when that fit is refused (typically a cohesion whose interval crosses zero: rigid
/// cohesionless grains have none), the cohesionless envelope `q = p sin φ` through the origin.
/// Returns the fit, whether its cohesion is fixed at zero, and the refusal of the free form when
/// it fell back to the cohesionless one. Errors: those of [`fit_mohr_coulomb_with`], the free
/// form's when neither form is accepted.
pub fn fit_mohr_coulomb_supported(
    data: &YieldData,
    confidence: f64,
) -> Result<(MohrCoulombFit, bool, Option<IdentifyError>)> {
    let free = MohrCoulombOptions {
        confidence,
        ..Default::default()
    };
    let refusal = if data.len() >= 4 {
        match fit_mohr_coulomb_with(data, &free) {
            Ok(f) => return Ok((f, false, None)),
            Err(e) => Some(e),
        }
    } else {
        None
    };
    let fixed = MohrCoulombOptions {
        confidence,
        cohesion_fixed_zero: true,
        cohesion_held_by_data: true,
        ..Default::default()
    };
    match (fit_mohr_coulomb_with(data, &fixed), refusal) {
        (Ok(f), refusal) => Ok((f, true, refusal)),
        // Neither form: the free form's reason is the data's first refusal.
        (Err(_), Some(free)) => Err(free),
        (Err(e), None) => Err(e),
    }
}

/// Fits the Mohr–Coulomb envelope (see the module documentation), in stages: the data as the
/// points of a line, the constrained line, its covariance and degrees of freedom, the map
/// `(a, b) → (φ, c)`, the estimates and the report, and the checks.
///
/// Errors: [`IdentifyError::TooFewPoints`] (< 4, < 3 with the cohesion fixed at zero),
/// [`IdentifyError::NonFinite`],
/// [`IdentifyError::NegativePressure`] (`p` or `σ_n` < 0: tensile states are not handled),
/// [`IdentifyError::OutOfDomain`] (`q < 0`), [`IdentifyError::ZeroVariance`] (all states at the
/// same pressure), [`IdentifyError::ParameterAtBound`] (`φ = 0` or `φ = 90°`),
/// [`IdentifyError::ConicSolver`], and the refusals of the module documentation.
pub fn fit_mohr_coulomb_with(
    data: &YieldData,
    options: &MohrCoulombOptions,
) -> Result<MohrCoulombFit> {
    let line = yield_line(data, options.cohesion_fixed_zero)?;
    let envelope = solve_envelope(&line, options.cohesion_fixed_zero)?;
    let line_fit = line_covariance(&line, &envelope, options);
    let t = stats::t_critical(options.confidence, line_fit.dof);
    let (phi, c, cov) =
        friction_and_cohesion(line_fit.a, line_fit.b, &line_fit.cov_ab, line.circles);
    let (friction_angle, cohesion) =
        envelope_estimates(phi, c, &cov, t, line_fit.b_upper, line.circles);
    let report = envelope_report(
        &line,
        &line_fit,
        envelope.cohesionless,
        &cov,
        t,
        vec![friction_angle.clone(), cohesion.clone()],
        options.confidence,
    );
    if let Some((bound, side)) = friction_angle_at_bound(line_fit.a, line.circles) {
        return Err(IdentifyError::ParameterAtBound {
            name: "friction_angle".into(),
            value: phi,
            bound,
            side,
            report: Box::new(report),
            suggestion: crate::error::Suggestion::none(),
        });
    }
    accept_envelope(&line, &envelope, &report, options)?;
    let deg = 180.0 / std::f64::consts::PI;
    let friction_angle_deg = Estimate {
        name: "friction_angle_deg".into(),
        unit: "deg".into(),
        value: phi * deg,
        std_error: friction_angle.std_error * deg,
        ci_low: friction_angle.ci_low * deg,
        ci_high: friction_angle.ci_high * deg,
        at_bound: false,
    };
    Ok(MohrCoulombFit {
        law: MohrCoulombLaw {
            friction_angle_rad: phi,
            cohesion_pa: c,
        },
        friction_angle,
        friction_angle_deg,
        cohesion,
        report,
    })
}

/// The stress states at yield as the points `(x_k, y_k)` of the line `y = a x + b` (module
/// documentation): `(p, q)` for Mohr circles, `(σ_n, |τ|)` on a failure plane.
struct YieldLine {
    /// Abscissae `x_k` (`p` or `σ_n`, Pa).
    x: Vec<f64>,
    /// Ordinates `y_k` (`q` or `|τ|`, Pa).
    y: Vec<f64>,
    /// Mohr circles (`a = sin φ ≤ 1`) rather than a failure plane (`a = tan φ`).
    circles: bool,
}

/// Stage 1, the data: the points of the line, checked finite, of equal lengths, at
/// non-negative pressure `x ≥ 0` and radius `y ≥ 0`, at least 4 of them (3 with the cohesion
/// fixed at zero), not all at the same pressure. Errors: those of [`fit_mohr_coulomb_with`] on
/// the data.
fn yield_line(data: &YieldData, fixed: bool) -> Result<YieldLine> {
    let (x, y, circles, xname, yname) = match data {
        YieldData::Circles { p_pa, q_pa } => (p_pa.clone(), q_pa.clone(), true, "p_Pa", "q_Pa"),
        YieldData::FailurePlane { sigma_n_pa, tau_pa } => (
            sigma_n_pa.clone(),
            tau_pa.iter().map(|t| t.abs()).collect(),
            false,
            "sigma_n_Pa",
            "tau_Pa",
        ),
    };
    check_finite(xname, &x)?;
    check_finite(yname, &y)?;
    check_same_len(xname, &x, yname, &y)?;
    check_non_negative_pressure(xname, &x)?;
    if let Some(k) = y.iter().position(|v| *v < 0.0) {
        return Err(IdentifyError::OutOfDomain {
            column: yname.into(),
            index: k,
            value: y[k],
            expected: "a Mohr-circle radius q ≥ 0".into(),
        });
    }
    let n = x.len();
    let needed = if fixed { 3 } else { 4 };
    if n < needed {
        return Err(IdentifyError::TooFewPoints {
            law: if fixed {
                "mohr-coulomb (cohesion fixed at 0)".into()
            } else {
                "mohr-coulomb (with cohesion free; 3 suffice with '# cohesion = 0')".into()
            },
            needed,
            got: n,
        });
    }
    check_spread(xname, &x)?;
    Ok(YieldLine { x, y, circles })
}

/// The constrained line and the cohesionless envelope nested in it.
struct Envelope {
    /// Slope `a` of the conic fit (0 with the cohesion fixed at zero).
    a: f64,
    /// Intercept `b ≥ 0` of the conic fit (0 with the cohesion fixed at zero).
    b: f64,
    /// The cohesion is fixed at zero, or the conic fit put it there (`b ≤ 10⁻⁸ max y`).
    cohesionless: bool,
    /// `S_xx = Σ x_k²`.
    sxx: f64,
    /// Slope of the line through the origin, `a₀ = Σ x_k y_k / S_xx` clamped to `[0, a_max]`.
    a_origin: f64,
    /// Its predictions `a₀ x_k` (the nested form of the acceptance checks).
    origin_fit: Vec<f64>,
}

/// Stage 2, the envelope: `(a, b)` minimising `‖y − a x − b‖₂` subject to `a ≥ 0`, `b ≥ 0`
/// and, for circles, `a ≤ 1` ([`solve_conic`]; not solved with the cohesion fixed at zero), and
/// the least-squares line through the origin `a₀ = Σ x y / Σ x²`.
/// Errors: [`IdentifyError::ConicSolver`].
fn solve_envelope(line: &YieldLine, fixed: bool) -> Result<Envelope> {
    let (x, y) = (&line.x, &line.y);
    let a_max = if line.circles { 1.0 } else { f64::INFINITY };
    let (a, b) = if fixed {
        (0.0, 0.0)
    } else {
        solve_conic(x, y, a_max)?
    };
    let (_, y_max) = min_max(y);
    let cohesionless = fixed || b <= 1e-8 * y_max;
    // The cohesionless envelope through the origin: the nested form.
    let sxx: f64 = x.iter().map(|v| v * v).sum();
    let a_origin = (x.iter().zip(y).map(|(u, v)| u * v).sum::<f64>() / sxx).clamp(0.0, a_max);
    let origin_fit: Vec<f64> = x.iter().map(|u| a_origin * u).collect();
    Ok(Envelope {
        a,
        b,
        cohesionless,
        sxx,
        a_origin,
        origin_fit,
    })
}

/// The fitted line with its covariance.
struct LineFit {
    /// Slope `a` (the line through the origin's when cohesionless).
    a: f64,
    /// Intercept `b` (0 when cohesionless).
    b: f64,
    /// Covariance of `(a, b)`.
    cov_ab: DMatrix<f64>,
    /// Degrees of freedom, `n − 2` (`n − 1` when cohesionless).
    dof: usize,
    /// When cohesionless: the upper end of the intercept's one-sided interval and its standard
    /// error, `(max(b_ols, 0) + t se(b_ols), se(b_ols))`, or `(0, 0)` for a cohesion the user
    /// fixed.
    b_upper: Option<(f64, f64)>,
}

/// Stage 3, covariance and degrees of freedom. With a free cohesion: the OLS covariance
/// `s² (XᵀX)⁻¹`, `s² = RSS/(n − 2)`, `n − 2` degrees of freedom. Cohesionless: the line through
/// the origin, `Var a₀ = RSS₀/(n − 1) / Σ x²`, `n − 1` degrees of freedom, and the one-sided
/// interval of `b` from the unconstrained regression (module documentation), `[0, 0]` for a
/// cohesion the user fixed.
fn line_covariance(line: &YieldLine, envelope: &Envelope, options: &MohrCoulombOptions) -> LineFit {
    let (x, y) = (&line.x, &line.y);
    let n = x.len();
    if envelope.cohesionless {
        let a0 = envelope.a_origin;
        let rss: f64 = x.iter().zip(y).map(|(u, v)| (v - a0 * u).powi(2)).sum();
        let dof = n - 1;
        let var_a = rss / dof as f64 / envelope.sxx;
        // Fixed by the user: the interval of c is [0, 0]; held at 0 by the data: one-sided,
        // `[0, max(b_ols, 0) + t se(b_ols)]` with the standard error se(b_ols).
        let bound = if options.cohesion_fixed_zero && !options.cohesion_held_by_data {
            (0.0, 0.0)
        } else {
            let (_, b_ols, cov_ols, _) = ols(x, y);
            let t2 = stats::t_critical(options.confidence, n - 2);
            let se = cov_ols[(1, 1)].max(0.0).sqrt();
            (b_ols.max(0.0) + t2 * se, se)
        };
        let cov = DMatrix::from_row_slice(2, 2, &[var_a, 0.0, 0.0, 0.0]);
        LineFit {
            a: a0,
            b: 0.0,
            cov_ab: cov,
            dof,
            b_upper: Some(bound),
        }
    } else {
        let (_, _, cov, _) = ols(x, y);
        LineFit {
            a: envelope.a,
            b: envelope.b,
            cov_ab: cov,
            dof: n - 2,
            b_upper: None,
        }
    }
}

/// Stage 4, `(a, b) → (φ, c)` and the covariance of `(φ, c)`, `J C_ab Jᵀ` with `J` the
/// Jacobian `∂(φ, c)/∂(a, b)`. Circles: `φ = asin a`, `c = b / cos φ = b / √(1 − a²)`,
/// `J = [[1/√(1 − a²), 0], [a b/(1 − a²)^{3/2}, 1/√(1 − a²)]]`. Failure plane: `φ = atan a`,
/// `c = b`, `J = [[1/(1 + a²), 0], [0, 1]]`. Returns `(φ, c, C_φc)`.
fn friction_and_cohesion(
    a: f64,
    b: f64,
    cov_ab: &DMatrix<f64>,
    circles: bool,
) -> (f64, f64, DMatrix<f64>) {
    let (phi, c, jac) = if circles {
        let ca = (1.0 - a * a).max(0.0).sqrt();
        let phi = a.clamp(-1.0, 1.0).asin();
        let c = if ca > 0.0 { b / ca } else { f64::INFINITY };
        let jac = DMatrix::from_row_slice(2, 2, &[1.0 / ca, 0.0, b * a / (ca * ca * ca), 1.0 / ca]);
        (phi, c, jac)
    } else {
        let jac = DMatrix::from_row_slice(2, 2, &[1.0 / (1.0 + a * a), 0.0, 0.0, 1.0]);
        (a.atan(), b, jac)
    };
    let cov = &jac * cov_ab * jac.transpose();
    (phi, c, cov)
}

/// Stage 5a, the estimates of `φ` (rad) and `c` (Pa): standard errors `√C_ii`, intervals
/// `θ̂ ∓ t √C_ii`; a cohesion at zero (`b_upper`) is at its bound with the one-sided interval
/// `[0, upper / cos φ]` and standard error `se / cos φ` for circles (`c = b / cos φ`), `[0, upper]`
/// and `se` on a failure plane.
fn envelope_estimates(
    phi: f64,
    c: f64,
    cov: &DMatrix<f64>,
    t: f64,
    b_upper: Option<(f64, f64)>,
    circles: bool,
) -> (Estimate, Estimate) {
    let friction_angle = Estimate::new("friction_angle", "rad", phi, cov[(0, 0)].sqrt(), t);
    let mut cohesion = Estimate::new("cohesion", "Pa", c, cov[(1, 1)].max(0.0).sqrt(), t);
    if let Some((upper, se)) = b_upper {
        // c = b / cos φ for circles (b = c cos φ), c = b on a failure plane
        let to_c = if circles { 1.0 / phi.cos() } else { 1.0 };
        cohesion.at_bound = true;
        cohesion.std_error = se * to_c;
        cohesion.ci_low = 0.0;
        cohesion.ci_high = upper * to_c;
    }
    (friction_angle, cohesion)
}

/// Stage 5b, the report: predictions `a x_k + b`, residuals on `y`, `R² = 1 − RSS/TSS`, the
/// residual variance `RSS/dof`, AIC and BIC with 1 parameter (cohesionless) or 2, and the
/// ranges of `x` and `y` as the validity.
fn envelope_report(
    line: &YieldLine,
    line_fit: &LineFit,
    cohesionless: bool,
    cov: &DMatrix<f64>,
    t: f64,
    parameters: Vec<Estimate>,
    confidence: f64,
) -> FitReport {
    let (x, y, circles) = (&line.x, &line.y, line.circles);
    let (a, b, dof) = (line_fit.a, line_fit.b, line_fit.dof);
    let n = x.len();
    let fitted: Vec<f64> = x.iter().map(|v| a * v + b).collect();
    let residuals: Vec<f64> = y.iter().zip(&fitted).map(|(o, f)| o - f).collect();
    let rss: f64 = residuals.iter().map(|r| r * r).sum();
    let ymean = y.iter().sum::<f64>() / n as f64;
    let tss: f64 = y.iter().map(|v| (v - ymean).powi(2)).sum();
    let n_params = if cohesionless { 1 } else { 2 };
    FitReport {
        model: "mohr-coulomb".into(),
        confidence,
        t_critical: t,
        parameters,
        covariance: matrix_rows(cov),
        correlation: matrix_rows(&correlation_of(cov)),
        observed: y.clone(),
        fitted,
        residuals,
        group_of: vec![0; n],
        groups: vec![GroupSummary {
            name: if circles { "q" } else { "tau" }.into(),
            n,
            rss,
            tss,
            weight: 1.0,
        }],
        n,
        dof,
        residual_variance: rss / dof as f64,
        r_squared: 1.0 - rss / tss,
        aic: stats::aic(&[(n, rss)], n_params),
        bic: stats::bic(&[(n, rss)], n_params),
        iterations: 0,
        validity: vec![
            ValidityRange::of(if circles { "p" } else { "sigma_n" }, "Pa", x),
            ValidityRange::of(if circles { "q" } else { "tau" }, "Pa", y),
        ],
        bootstrap: None,
    }
}

/// Stage 6a, the friction angle at a bound: `(bound, side)` when the slope ends at `a ≤ 10⁻⁹`
/// (`φ = 0`) or, for circles, at `a ≥ 1 − 10⁻⁹` (`φ = π/2`); `None` inside.
fn friction_angle_at_bound(a: f64, circles: bool) -> Option<(f64, BoundSide)> {
    let a_tol = 1e-9;
    if a <= a_tol || (circles && a >= 1.0 - a_tol) {
        Some(if a <= a_tol {
            (0.0, BoundSide::Lower)
        } else {
            (std::f64::consts::FRAC_PI_2, BoundSide::Upper)
        })
    } else {
        None
    }
}

/// Stage 6b, acceptance ([`crate::accept`]): `φ` inside `[0, π/2]`, `c ≥ 0` (offering
/// [`COHESIONLESS`]), `R²` above `options.min_r_squared`, and, with a free cohesion, an adjusted
/// `R²` not below the cohesionless envelope's. Errors: the refusals of [`Acceptance::check`].
fn accept_envelope(
    line: &YieldLine,
    envelope: &Envelope,
    report: &FitReport,
    options: &MohrCoulombOptions,
) -> Result<()> {
    let nested = (!envelope.cohesionless).then(|| NestedForm {
        name: "the cohesionless envelope (# cohesion = 0)".into(),
        r_squared: crate::accept::r_squared_of(&line.y, &envelope.origin_fit),
        parameters: 1,
    });
    Acceptance::new("mohr-coulomb", options.min_r_squared)
        .range(PhysicalRange::new(
            "friction_angle",
            0.0,
            std::f64::consts::FRAC_PI_2,
        ))
        .range(PhysicalRange::non_negative("cohesion").suggesting(COHESIONLESS))
        .nested(nested)
        .check(report)
}
