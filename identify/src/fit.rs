//! Generic nonlinear least squares with uncertainty: the machinery every law's fit calls.
//!
//! Given a model `f(θ)` (one prediction per observation, [`LeastSquaresModel`]) and observations
//! `y` split into groups (e.g. `σ_v` and `σ_h` of a Janssen profile), [`fit_least_squares`]
//! minimises `Σ_k w_{g(k)}² (y_k − f_k(θ))²` over the box of admissible parameters with
//! [`crate::lm::BoundedLevenbergMarquardt`] (driven by argmin), then reports:
//!
//! - covariance `C = s² (J_wᵀ J_w)⁻¹`, `J_w` the weighted Jacobian at the optimum,
//!   `s² = Σ (w r)² / (n − p)` the residual variance;
//! - standard errors `√C_ii` and intervals `θ̂ ∓ t_{0.975, n−p} √C_ii` (Student-t quantile);
//! - the correlation matrix, residuals, `R²`, AIC/BIC ([`crate::stats`]);
//! - optionally a seeded case-resampling bootstrap (resampling observations within each group,
//!   refitting from `θ̂`), with percentile intervals.
//!
//! Observations with known standard errors `σ_k` ([`Observations::std_errors`]) are weighted by
//! `w_k ∝ 1/σ_k` (weighted least squares; the covariance keeps the residual-variance scale `s²`,
//! so only the relative sizes of the `σ_k` matter).
//!
//! With several groups, group weights are estimated (two-stage feasible weighted least
//! squares): a first unweighted fit gives each group's residual variance `s_g² = RSS_g/n_g`,
//! the final fit uses `w_g = 1/s_g`. This makes a joint fit of quantities with different noise
//! levels (wall and vertical stresses) efficient and its covariance honest.
//!
//! A parameter that ends on its bound is an error, [`IdentifyError::ParameterAtBound`], carrying
//! the constrained fit for inspection; a rank-deficient Jacobian is
//! [`IdentifyError::NotIdentifiable`]. What a law's fit must pass on top of this (scales in the
//! data, intervals inside the physical ranges, standard errors below the values, R², the nested
//! form) is in [`crate::accept`].

use argmin::core::{Error as ArgminError, Jacobian, Operator};
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::error::{check_finite, BoundSide, IdentifyError, Result};
use crate::lm;
use crate::report::{
    correlation_of, matrix_rows, summarise_bootstrap, Estimate, FitReport, GroupSummary,
    ValidityRange,
};
use crate::stats;

/// Name, unit and admissible box of one parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterSpec {
    /// Name.
    pub name: String,
    /// SI unit.
    pub unit: String,
    /// Lower bound (may be `-∞`).
    pub lower: f64,
    /// Upper bound (may be `+∞`).
    pub upper: f64,
}

impl ParameterSpec {
    /// A parameter with bounds `[lower, upper]`.
    pub fn new(name: &str, unit: &str, lower: f64, upper: f64) -> Self {
        ParameterSpec {
            name: name.to_string(),
            unit: unit.to_string(),
            lower,
            upper,
        }
    }
}

/// A model `f(θ)`: one prediction per observation, in the order of the [`Observations`].
pub trait LeastSquaresModel {
    /// Model name, for reports and errors.
    fn name(&self) -> String;
    /// Parameters with units and bounds.
    fn parameters(&self) -> Vec<ParameterSpec>;
    /// Predictions `f_k(θ)` for every observation.
    fn predict(&self, theta: &[f64]) -> Vec<f64>;
    /// Jacobian `∂f_k/∂θ_j` (rows: observations). Default: central finite differences with
    /// step `h_j = 10⁻⁶ max(|θ_j|, 10⁻⁶)`; laws override it with the analytic form.
    fn jacobian(&self, theta: &[f64]) -> DMatrix<f64> {
        finite_difference_jacobian(|t| self.predict(t), theta)
    }
}

/// Central finite-difference Jacobian of `f` at `theta`.
pub fn finite_difference_jacobian<F>(f: F, theta: &[f64]) -> DMatrix<f64>
where
    F: Fn(&[f64]) -> Vec<f64>,
{
    let f0 = f(theta);
    let mut jac = DMatrix::zeros(f0.len(), theta.len());
    let mut t = theta.to_vec();
    for j in 0..theta.len() {
        let h = 1e-6 * theta[j].abs().max(1e-6);
        t[j] = theta[j] + h;
        let fp = f(&t);
        t[j] = theta[j] - h;
        let fm = f(&t);
        t[j] = theta[j];
        for k in 0..f0.len() {
            jac[(k, j)] = (fp[k] - fm[k]) / (2.0 * h);
        }
    }
    jac
}

/// Observations `y`, each tagged with a group.
#[derive(Debug, Clone, PartialEq)]
pub struct Observations {
    /// Observed values, stacked group after group as the model predicts them.
    pub y: Vec<f64>,
    /// Group index of each observation.
    pub group_of: Vec<usize>,
    /// Group names (quantity names, e.g. `sigma_v`).
    pub group_names: Vec<String>,
    /// Standard error `σ_k` of each observation, when known (e.g. block-averaged over a steady
    /// state): the fit then weighs observation `k` by `1/σ_k` (relative weights; the covariance
    /// keeps its residual-variance scale).
    pub std_errors: Option<Vec<f64>>,
}

impl Observations {
    /// One group.
    pub fn single(name: &str, y: Vec<f64>) -> Self {
        let n = y.len();
        Observations {
            y,
            group_of: vec![0; n],
            group_names: vec![name.to_string()],
            std_errors: None,
        }
    }

    /// The same observations with the standard error of each (`None`: unweighted).
    pub fn with_std_errors(mut self, std_errors: Option<Vec<f64>>) -> Self {
        self.std_errors = std_errors;
        self
    }

    /// Several groups, stacked in the given order.
    pub fn grouped(groups: Vec<(String, Vec<f64>)>) -> Self {
        let mut y = Vec::new();
        let mut group_of = Vec::new();
        let mut group_names = Vec::new();
        for (g, (name, values)) in groups.into_iter().enumerate() {
            group_of.extend(std::iter::repeat_n(g, values.len()));
            y.extend(values);
            group_names.push(name);
        }
        Observations {
            y,
            group_of,
            group_names,
            std_errors: None,
        }
    }

    /// Number of observations.
    pub fn len(&self) -> usize {
        self.y.len()
    }

    /// True when there is no observation.
    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }
}

/// Bootstrap settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BootstrapOptions {
    /// Number of resamples.
    pub resamples: usize,
    /// Seed of the `ChaCha8Rng`.
    pub seed: u64,
}

/// The weight `w_k = σ̄/σ_k` of each observation from its standard error (`σ̄` their mean, so
/// that the weights are of order one), or 1 for all without standard errors. Errors: a length
/// that differs from the observations' ([`IdentifyError::LengthMismatch`]), a standard error
/// that is not a finite positive number ([`IdentifyError::OutOfDomain`]).
fn observation_weights(obs: &Observations) -> Result<Vec<f64>> {
    let Some(se) = &obs.std_errors else {
        return Ok(vec![1.0; obs.len()]);
    };
    if se.len() != obs.len() {
        return Err(IdentifyError::LengthMismatch {
            first: "observations".into(),
            first_len: obs.len(),
            second: "standard errors".into(),
            second_len: se.len(),
        });
    }
    if let Some(k) = se.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(IdentifyError::OutOfDomain {
            column: "std_error".into(),
            index: k,
            value: se[k],
            expected: "a finite standard error > 0".into(),
        });
    }
    let mean = se.iter().sum::<f64>() / se.len() as f64;
    Ok(se.iter().map(|s| mean / s).collect())
}

/// Settings of [`fit_least_squares`].
#[derive(Debug, Clone, PartialEq)]
pub struct FitOptions {
    /// Confidence level of the intervals (default 0.95).
    pub confidence: f64,
    /// Iteration limit of the optimiser (default 500).
    pub max_iters: u64,
    /// Estimate one weight per group (default true; no effect with one group).
    pub reweight_groups: bool,
    /// Seeded bootstrap (default none).
    pub bootstrap: Option<BootstrapOptions>,
    /// A law whose `R²` is below this is refused (default [`crate::accept::MIN_R_SQUARED`],
    /// 0.5; see [`crate::accept::check_r_squared`]).
    pub min_r_squared: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            confidence: 0.95,
            max_iters: 500,
            reweight_groups: true,
            bootstrap: None,
            min_r_squared: crate::accept::MIN_R_SQUARED,
        }
    }
}

/// Weighted residuals `r_k = w_k (f_k(θ) − y_k)` on a subset (with repetitions) of observations:
/// the argmin problem.
struct WeightedResiduals<'a, M: LeastSquaresModel> {
    model: &'a M,
    y: &'a [f64],
    weight: &'a [f64],
    index: &'a [usize],
}

impl<M: LeastSquaresModel> Operator for WeightedResiduals<'_, M> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, theta: &DVector<f64>) -> std::result::Result<DVector<f64>, ArgminError> {
        let f = self.model.predict(theta.as_slice());
        Ok(DVector::from_iterator(
            self.index.len(),
            self.index
                .iter()
                .map(|&k| self.weight[k] * (f[k] - self.y[k])),
        ))
    }
}

impl<M: LeastSquaresModel> Jacobian for WeightedResiduals<'_, M> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, theta: &DVector<f64>) -> std::result::Result<DMatrix<f64>, ArgminError> {
        let full = self.model.jacobian(theta.as_slice());
        Ok(DMatrix::from_fn(self.index.len(), full.ncols(), |r, c| {
            let k = self.index[r];
            self.weight[k] * full[(k, c)]
        }))
    }
}

fn run<M: LeastSquaresModel>(
    model: &M,
    y: &[f64],
    weight: &[f64],
    index: &[usize],
    theta0: &[f64],
    specs: &[ParameterSpec],
    max_iters: u64,
) -> Result<lm::LmOutcome> {
    let lower = DVector::from_iterator(specs.len(), specs.iter().map(|s| s.lower));
    let upper = DVector::from_iterator(specs.len(), specs.iter().map(|s| s.upper));
    let problem = WeightedResiduals {
        model,
        y,
        weight,
        index,
    };
    lm::minimise(
        problem,
        DVector::from_column_slice(theta0),
        lower,
        upper,
        max_iters,
    )
    .map_err(|reason| IdentifyError::NoConvergence {
        solver: format!("Levenberg-Marquardt ({})", model.name()),
        reason,
    })
}

pub use crate::accept::check_identified;

/// Minimum number of observations for `p` parameters: `p + 2`.
pub fn min_points(p: usize) -> usize {
    p + 2
}

/// Fits `model` to `obs` from the start `theta0` and reports the estimate with its uncertainty
/// (see the module documentation). `validity` is copied into the report.
///
/// In stages: the observations are checked, the weighted minimisation runs (observation
/// weights, then group weights), the report is built with the covariance, a parameter on its
/// bound or a rank-deficient Jacobian is refused, and the bootstrap runs when asked for.
///
/// Errors: [`IdentifyError::TooFewPoints`] (`n < p + 2`), [`IdentifyError::NonFinite`],
/// [`IdentifyError::ZeroVariance`] (a group with constant observations),
/// [`IdentifyError::NoConvergence`], [`IdentifyError::ParameterAtBound`],
/// [`IdentifyError::NotIdentifiable`] (Jacobian rank deficient at the optimum).
pub fn fit_least_squares<M: LeastSquaresModel>(
    model: &M,
    obs: &Observations,
    theta0: &[f64],
    options: &FitOptions,
    validity: Vec<ValidityRange>,
) -> Result<FitReport> {
    let specs = model.parameters();
    check_observations(model, obs, specs.len())?;
    let theta0: Vec<f64> = theta0
        .iter()
        .zip(&specs)
        .map(|(t, s)| t.clamp(s.lower, s.upper))
        .collect();
    let (outcome, weight) = minimise_weighted(model, obs, &theta0, &specs, options)?;
    let theta = outcome.x.as_slice().to_vec();
    let (mut report, rank_problem) = least_squares_report(
        model,
        obs,
        &outcome,
        &weight,
        &specs,
        options.confidence,
        validity,
    );

    // A parameter on its bound is not an estimate.
    if let Some((j, side, bound)) = parameter_on_bound(&specs, &theta0, &theta) {
        return Err(IdentifyError::ParameterAtBound {
            name: specs[j].name.clone(),
            value: theta[j],
            bound,
            side,
            report: Box::new(report),
            suggestion: crate::error::Suggestion::none(),
        });
    }
    if let Some(reason) = rank_problem {
        return Err(IdentifyError::NotIdentifiable { reason });
    }

    if let Some(bs) = options.bootstrap {
        report.bootstrap = Some(bootstrap(model, obs, &weight, &theta, &specs, options, bs));
    }
    Ok(report)
}

/// Stage 1, the observations: at least `p + 2` of them for `p` parameters, and in every group
/// finite values that are not all the same (`max − min ≤ 10⁻¹⁴ max(|min|, |max|)` is constant).
/// Errors: [`IdentifyError::TooFewPoints`], [`IdentifyError::NonFinite`],
/// [`IdentifyError::ZeroVariance`].
fn check_observations<M: LeastSquaresModel>(model: &M, obs: &Observations, p: usize) -> Result<()> {
    let n = obs.len();
    if n < min_points(p) {
        return Err(IdentifyError::TooFewPoints {
            law: model.name(),
            needed: min_points(p),
            got: n,
        });
    }
    for (g, name) in obs.group_names.iter().enumerate() {
        let values: Vec<f64> = group_values(obs, g);
        check_finite(name, &values)?;
        let (lo, hi) = crate::stats::min_max(&values);
        if values.len() > 1 && hi - lo <= 1e-14 * lo.abs().max(hi.abs()) {
            return Err(IdentifyError::ZeroVariance {
                column: name.clone(),
                value: lo,
            });
        }
    }
    Ok(())
}

/// Stage 2, the minimisation of `Σ_k w_k² (y_k − f_k(θ))²` from `theta0`: first with the
/// observations' own weights (`1/σ_k`, or 1; [`observation_weights`]), then, with several
/// groups and `options.reweight_groups`, again from that optimum with one weight per group on
/// top of them ([`group_weights`]). Returns the last outcome and the weights it used.
/// Errors: those of [`observation_weights`], [`IdentifyError::NoConvergence`].
fn minimise_weighted<M: LeastSquaresModel>(
    model: &M,
    obs: &Observations,
    theta0: &[f64],
    specs: &[ParameterSpec],
    options: &FitOptions,
) -> Result<(lm::LmOutcome, Vec<f64>)> {
    let all: Vec<usize> = (0..obs.len()).collect();
    let base = observation_weights(obs)?;
    let mut weight = base.clone();
    let mut outcome = run(
        model,
        &obs.y,
        &weight,
        &all,
        theta0,
        specs,
        options.max_iters,
    )?;
    if obs.group_names.len() > 1 && options.reweight_groups {
        let f = model.predict(outcome.x.as_slice());
        if let Some(grouped) = group_weights(obs, &base, &f) {
            weight = grouped;
            let start = outcome.x.as_slice().to_vec();
            outcome = run(
                model,
                &obs.y,
                &weight,
                &all,
                &start,
                specs,
                options.max_iters,
            )?;
        }
    }
    Ok((outcome, weight))
}

/// The weights of the second stage (two-stage feasible weighted least squares): each group's
/// residual scale `s_g = √(Σ_{k∈g} (w_k (y_k − f_k))² / n_g)` from the first stage's
/// predictions `f` and weights `w = base`, and `w'_k = w_k s_max / max(s_{g(k)}, 10⁻⁹ s_max)`.
/// `None` when every residual is zero (`s_max = 0`).
fn group_weights(obs: &Observations, base: &[f64], f: &[f64]) -> Option<Vec<f64>> {
    let n = obs.len();
    let s: Vec<f64> = (0..obs.group_names.len())
        .map(|g| {
            let (rss, ng) = (0..n)
                .filter(|&k| obs.group_of[k] == g)
                .fold((0.0, 0usize), |(a, c), k| {
                    (a + (base[k] * (obs.y[k] - f[k])).powi(2), c + 1)
                });
            (rss / ng.max(1) as f64).sqrt()
        })
        .collect();
    let s_max = s.iter().cloned().fold(0.0, f64::max);
    if s_max > 0.0 {
        let floor = 1e-9 * s_max;
        Some(
            (0..n)
                .map(|k| base[k] * s_max / s[obs.group_of[k]].max(floor))
                .collect(),
        )
    } else {
        None
    }
}

/// Stage 3, the report at the optimum `θ̂` of `outcome` with the final weights: residuals
/// `r_k = y_k − f_k(θ̂)`, covariance `C = s² (J_wᵀ J_w)⁻¹` with `s² = Σ (w r)² / (n − p)`
/// ([`covariance`]), standard errors `√C_jj` and intervals `θ̂_j ∓ t √C_jj` (Student's `t` at
/// `n − p` degrees of freedom), the groups' summaries, `R² = 1 − Σ RSS_g / Σ TSS_g`, AIC and
/// BIC, with the optimiser's iterations and `validity`. Returns the report and the reason the
/// Jacobian is rank deficient, if it is.
fn least_squares_report<M: LeastSquaresModel>(
    model: &M,
    obs: &Observations,
    outcome: &lm::LmOutcome,
    weight: &[f64],
    specs: &[ParameterSpec],
    confidence: f64,
    validity: Vec<ValidityRange>,
) -> (FitReport, Option<String>) {
    let (n, p) = (obs.len(), specs.len());
    let theta = outcome.x.as_slice();
    let fitted = model.predict(theta);
    let residuals: Vec<f64> = obs.y.iter().zip(&fitted).map(|(y, f)| y - f).collect();

    // Covariance from the weighted Jacobian, column-scaled for conditioning.
    let jac = model.jacobian(theta);
    let jw = DMatrix::from_fn(n, p, |k, j| weight[k] * jac[(k, j)]);
    let wrss: f64 = residuals
        .iter()
        .zip(weight)
        .map(|(r, w)| (w * r).powi(2))
        .sum();
    let dof = n - p;
    let s2 = wrss / dof as f64;
    let (cov, rank_problem) = covariance(&jw, s2, specs);
    let t = stats::t_critical(confidence, dof);

    let parameters: Vec<Estimate> = specs
        .iter()
        .enumerate()
        .map(|(j, s)| Estimate::new(&s.name, &s.unit, theta[j], cov[(j, j)].max(0.0).sqrt(), t))
        .collect();
    let groups = group_summaries(obs, &residuals, weight);
    let rss_total: f64 = groups.iter().map(|g| g.rss).sum();
    let tss_total: f64 = groups.iter().map(|g| g.tss).sum();
    let by_group: Vec<(usize, f64)> = groups.iter().map(|g| (g.n, g.rss)).collect();
    let report = FitReport {
        model: model.name(),
        confidence,
        t_critical: t,
        parameters,
        covariance: matrix_rows(&cov),
        correlation: matrix_rows(&correlation_of(&cov)),
        observed: obs.y.clone(),
        fitted,
        residuals,
        group_of: obs.group_of.clone(),
        groups,
        n,
        dof,
        residual_variance: s2,
        r_squared: 1.0 - rss_total / tss_total,
        aic: stats::aic(&by_group, p),
        bic: stats::bic(&by_group, p),
        iterations: outcome.iterations,
        validity,
        bootstrap: None,
    };
    (report, rank_problem)
}

/// Each group's summary: its size `n_g`, `RSS_g = Σ_{k∈g} r_k²` (unweighted), `TSS_g` about its
/// mean, and the weight of its first observation.
fn group_summaries(obs: &Observations, residuals: &[f64], weight: &[f64]) -> Vec<GroupSummary> {
    let n = obs.len();
    (0..obs.group_names.len())
        .map(|g| {
            let idx: Vec<usize> = (0..n).filter(|&k| obs.group_of[k] == g).collect();
            let mean = idx.iter().map(|&k| obs.y[k]).sum::<f64>() / idx.len().max(1) as f64;
            GroupSummary {
                name: obs.group_names[g].clone(),
                n: idx.len(),
                rss: idx.iter().map(|&k| residuals[k].powi(2)).sum(),
                tss: idx.iter().map(|&k| (obs.y[k] - mean).powi(2)).sum(),
                weight: idx.first().map_or(1.0, |&k| weight[k]),
            }
        })
        .collect()
}

/// Stage 4, the first parameter that ended on its bound: `(j, side, bound)` when
/// `|θ_j − bound| ≤ 10⁻⁹ max(|θ0_j|, |θ_j|, |bound|)` for a finite bound (the lower one first).
fn parameter_on_bound(
    specs: &[ParameterSpec],
    theta0: &[f64],
    theta: &[f64],
) -> Option<(usize, BoundSide, f64)> {
    specs.iter().enumerate().find_map(|(j, s)| {
        let scale = theta0[j].abs().max(theta[j].abs()).max(1e-300);
        if s.lower.is_finite() && (theta[j] - s.lower).abs() <= 1e-9 * scale.max(s.lower.abs()) {
            Some((j, BoundSide::Lower, s.lower))
        } else if s.upper.is_finite()
            && (theta[j] - s.upper).abs() <= 1e-9 * scale.max(s.upper.abs())
        {
            Some((j, BoundSide::Upper, s.upper))
        } else {
            None
        }
    })
}

/// `s² (J_wᵀJ_w)⁻¹` with column scaling; reports rank deficiency (condition number of the
/// scaled Jacobian above 10¹⁰) as a reason string and returns NaN there.
fn covariance(
    jw: &DMatrix<f64>,
    s2: f64,
    specs: &[ParameterSpec],
) -> (DMatrix<f64>, Option<String>) {
    let p = jw.ncols();
    let norms: Vec<f64> = (0..p).map(|j| jw.column(j).norm()).collect();
    if let Some(j) = norms.iter().position(|v| *v <= 0.0 || !v.is_finite()) {
        return (
            DMatrix::from_element(p, p, f64::NAN),
            Some(format!(
                "the predictions do not depend on parameter {} over these data",
                specs[j].name
            )),
        );
    }
    let scaled = DMatrix::from_fn(jw.nrows(), p, |k, j| jw[(k, j)] / norms[j]);
    let svd = scaled.clone().svd(false, false);
    let smax = svd.singular_values.max();
    let smin = svd.singular_values.min();
    if smin <= 1e-10 * smax {
        return (
            DMatrix::from_element(p, p, f64::NAN),
            Some(format!(
                "the Jacobian is rank deficient (condition number {:.1e}): the parameters are not separately identifiable",
                smax / smin.max(f64::MIN_POSITIVE)
            )),
        );
    }
    let ata = scaled.tr_mul(&scaled);
    let inv = match ata.cholesky() {
        Some(ch) => ch.inverse(),
        None => {
            return (
                DMatrix::from_element(p, p, f64::NAN),
                Some("JᵀJ is not positive definite".to_string()),
            )
        }
    };
    let cov = DMatrix::from_fn(p, p, |i, j| s2 * inv[(i, j)] / (norms[i] * norms[j]));
    (cov, None)
}

fn group_values(obs: &Observations, g: usize) -> Vec<f64> {
    obs.y
        .iter()
        .zip(&obs.group_of)
        .filter(|(_, gg)| **gg == g)
        .map(|(y, _)| *y)
        .collect()
}

/// Case-resampling bootstrap within groups, seeded.
fn bootstrap<M: LeastSquaresModel>(
    model: &M,
    obs: &Observations,
    weight: &[f64],
    theta: &[f64],
    specs: &[ParameterSpec],
    options: &FitOptions,
    bs: BootstrapOptions,
) -> crate::report::BootstrapSummary {
    let mut rng = ChaCha8Rng::seed_from_u64(bs.seed);
    let members: Vec<Vec<usize>> = (0..obs.group_names.len())
        .map(|g| (0..obs.len()).filter(|&k| obs.group_of[k] == g).collect())
        .collect();
    let mut samples = Vec::with_capacity(bs.resamples);
    let mut failed = 0;
    for _ in 0..bs.resamples {
        let index: Vec<usize> = members
            .iter()
            .flat_map(|m| {
                (0..m.len())
                    .map(|_| m[rng.random_range(0..m.len())])
                    .collect::<Vec<_>>()
            })
            .collect();
        match run(
            model,
            &obs.y,
            weight,
            &index,
            theta,
            specs,
            options.max_iters,
        ) {
            Ok(out) if out.x.iter().all(|v| v.is_finite()) => {
                samples.push(out.x.as_slice().to_vec())
            }
            _ => failed += 1,
        }
    }
    summarise_bootstrap(bs.seed, bs.resamples, failed, samples, options.confidence)
}

/// Best start of a model linear in some coefficients for a fixed nonlinear parameter: for each
/// `s` of `grid`, solves the linear least squares `y ≈ Σ_j c_j b_j(s)` (columns `b_j` from
/// `basis(s)`) and keeps the `s` with the smallest residual. Returns `(s, c)`.
pub(crate) fn separable_start<B>(grid: &[f64], y: &[f64], basis: B) -> Option<(f64, Vec<f64>)>
where
    B: Fn(f64) -> DMatrix<f64>,
{
    let yv = DVector::from_column_slice(y);
    let mut best: Option<(f64, f64, Vec<f64>)> = None;
    for &s in grid {
        let a = basis(s);
        if a.iter().any(|v| !v.is_finite()) {
            continue;
        }
        let svd = a.clone().svd(true, true);
        let Ok(c) = svd.solve(&yv, 1e-12) else {
            continue;
        };
        let rss = (&a * &c - &yv).norm_squared();
        if rss.is_finite() && best.as_ref().is_none_or(|b| rss < b.0) {
            best = Some((rss, s, c.as_slice().to_vec()));
        }
    }
    best.map(|(_, s, c)| (s, c))
}

/// `count` values log-spaced from `lo` to `hi` (both > 0).
pub(crate) fn log_grid(lo: f64, hi: f64, count: usize) -> Vec<f64> {
    let (a, b) = (lo.ln(), hi.ln());
    (0..count)
        .map(|i| (a + (b - a) * i as f64 / (count - 1).max(1) as f64).exp())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = a + b x, linear: the LM fit must reproduce OLS and its textbook covariance.
    struct Line {
        x: Vec<f64>,
    }
    impl LeastSquaresModel for Line {
        fn name(&self) -> String {
            "line".into()
        }
        fn parameters(&self) -> Vec<ParameterSpec> {
            vec![
                ParameterSpec::new("a", "1", f64::NEG_INFINITY, f64::INFINITY),
                ParameterSpec::new("b", "1", f64::NEG_INFINITY, f64::INFINITY),
            ]
        }
        fn predict(&self, t: &[f64]) -> Vec<f64> {
            self.x.iter().map(|x| t[0] + t[1] * x).collect()
        }
    }

    #[test]
    fn linear_fit_matches_ordinary_least_squares() {
        let x: Vec<f64> = (0..10).map(|i| i as f64).collect();
        let noise = [0.1, -0.2, 0.05, 0.3, -0.1, 0.0, -0.25, 0.15, 0.2, -0.05];
        let y: Vec<f64> = x
            .iter()
            .zip(noise)
            .map(|(x, e)| 1.0 + 2.0 * x + e)
            .collect();
        let model = Line { x: x.clone() };
        let rep = fit_least_squares(
            &model,
            &Observations::single("y", y.clone()),
            &[0.0, 0.0],
            &FitOptions::default(),
            vec![],
        )
        .unwrap();
        // Closed-form OLS.
        let n = x.len() as f64;
        let mx = x.iter().sum::<f64>() / n;
        let my = y.iter().sum::<f64>() / n;
        let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
        let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
        let b = sxy / sxx;
        let a = my - b * mx;
        let rss: f64 = x.iter().zip(&y).map(|(u, v)| (v - a - b * u).powi(2)).sum();
        let s2 = rss / (n - 2.0);
        let se_b = (s2 / sxx).sqrt();
        let se_a = (s2 * (1.0 / n + mx * mx / sxx)).sqrt();
        assert!((rep.parameters[0].value - a).abs() < 1e-10);
        assert!((rep.parameters[1].value - b).abs() < 1e-10);
        assert!((rep.parameters[0].std_error - se_a).abs() < 1e-9 * se_a);
        assert!((rep.parameters[1].std_error - se_b).abs() < 1e-9 * se_b);
        // Correlation of intercept and slope: −x̄ / √(x̄² + Sxx/n).
        let rho = -mx / (mx * mx + sxx / n).sqrt();
        assert!((rep.correlation[0][1] - rho).abs() < 1e-9);
        assert!((rep.t_critical - 2.306_004_135).abs() < 1e-8);
        assert!(rep.r_squared > 0.99 && rep.r_squared < 1.0);
    }

    #[test]
    fn analytic_free_model_uses_finite_differences() {
        let jac = finite_difference_jacobian(|t| vec![t[0] * t[0], t[0] * t[1]], &[3.0, 2.0]);
        assert!((jac[(0, 0)] - 6.0).abs() < 1e-8);
        assert!((jac[(1, 0)] - 2.0).abs() < 1e-8);
        assert!((jac[(1, 1)] - 3.0).abs() < 1e-8);
    }

    #[test]
    fn bound_ending_parameter_is_an_error() {
        let x: Vec<f64> = (0..8).map(|i| i as f64).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|x| 1.0 - 0.5 * x + 0.01 * (x * 7.0).sin())
            .collect();
        struct PosLine(Line);
        impl LeastSquaresModel for PosLine {
            fn name(&self) -> String {
                "positive-slope line".into()
            }
            fn parameters(&self) -> Vec<ParameterSpec> {
                vec![
                    ParameterSpec::new("a", "1", f64::NEG_INFINITY, f64::INFINITY),
                    ParameterSpec::new("b", "1", 0.0, f64::INFINITY),
                ]
            }
            fn predict(&self, t: &[f64]) -> Vec<f64> {
                self.0.predict(t)
            }
        }
        let err = fit_least_squares(
            &PosLine(Line { x }),
            &Observations::single("y", y),
            &[0.0, 1.0],
            &FitOptions::default(),
            vec![],
        )
        .unwrap_err();
        match err {
            IdentifyError::ParameterAtBound { name, side, .. } => {
                assert_eq!(name, "b");
                assert_eq!(side, BoundSide::Lower);
            }
            other => panic!("expected ParameterAtBound, got {other}"),
        }
    }
}
