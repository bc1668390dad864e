//! What every fit returns: [`FitReport`] (parameters with standard errors and confidence
//! intervals, correlation matrix, residuals, R², AIC/BIC, validity range) and the pieces it is
//! made of. Plain data, serialisable; the algorithms that fill it live in [`crate::fit`].

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

use crate::stats;

/// One estimated quantity with its uncertainty.
///
/// `ci_low`/`ci_high` is the two-sided interval at the report's confidence level (95 % by
/// default): `value ∓ t_{(1+level)/2, n−p} · std_error` (Wald interval from the linearised
/// covariance; derived quantities use the delta method).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// Name (`K`, `mu_w`, `mu_s`, ...).
    pub name: String,
    /// SI unit (`"1"` for dimensionless, `"Pa"`, `"m"`, `"rad"`, ...).
    pub unit: String,
    /// Best estimate.
    pub value: f64,
    /// Standard error.
    pub std_error: f64,
    /// Lower end of the confidence interval.
    pub ci_low: f64,
    /// Upper end of the confidence interval.
    pub ci_high: f64,
    /// True when the estimate sits on a constraint that is allowed to be active (only the
    /// cohesion of Mohr–Coulomb, `c = 0`, can be; least-squares fits return
    /// [`crate::IdentifyError::ParameterAtBound`] instead).
    #[serde(default)]
    pub at_bound: bool,
}

impl Estimate {
    /// Builds an estimate with the interval `value ∓ t·std_error`.
    pub fn new(name: &str, unit: &str, value: f64, std_error: f64, t: f64) -> Self {
        Estimate {
            name: name.to_string(),
            unit: unit.to_string(),
            value,
            std_error,
            ci_low: value - t * std_error,
            ci_high: value + t * std_error,
            at_bound: false,
        }
    }

    /// True when `x` lies in `[ci_low, ci_high]`.
    pub fn covers(&self, x: f64) -> bool {
        self.ci_low <= x && x <= self.ci_high
    }
}

/// Range of one input variable over the data used by a fit: the law is valid (calibrated) there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ValidityRange {
    /// Variable (`z`, `I`, `V`, `p`, ...).
    pub variable: String,
    /// SI unit.
    pub unit: String,
    /// Smallest value in the data.
    pub min: f64,
    /// Largest value in the data.
    pub max: f64,
}

impl ValidityRange {
    /// Range of `values` (min, max).
    pub fn of(variable: &str, unit: &str, values: &[f64]) -> Self {
        let (min, max) = crate::stats::min_max(values);
        ValidityRange {
            variable: variable.to_string(),
            unit: unit.to_string(),
            min,
            max,
        }
    }

    /// True when `x` lies in `[min, max]`.
    pub fn contains(&self, x: f64) -> bool {
        self.min <= x && x <= self.max
    }
}

/// Result of a seeded case-resampling bootstrap.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BootstrapSummary {
    /// Seed of the `ChaCha8Rng` used.
    pub seed: u64,
    /// Resamples attempted.
    pub resamples: usize,
    /// Resamples whose refit failed (excluded).
    pub failed: usize,
    /// Per parameter, in report order: standard deviation of the bootstrap estimates.
    pub std_error: Vec<f64>,
    /// Per parameter: percentile interval `[q_{(1−level)/2}, q_{(1+level)/2}]`.
    pub ci: Vec<[f64; 2]>,
    /// The bootstrap estimates (one row per successful resample).
    pub samples: Vec<Vec<f64>>,
}

/// Residuals of one group of observations (e.g. `sigma_v`, `sigma_h`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupSummary {
    /// Group name.
    pub name: String,
    /// Observations in the group.
    pub n: usize,
    /// Residual sum of squares `Σ (y − f)²` in data units.
    pub rss: f64,
    /// Total sum of squares about the group mean.
    pub tss: f64,
    /// Weight `1/s_g` applied to the group's residuals in the fit.
    pub weight: f64,
}

/// The common result of every fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitReport {
    /// Model name.
    pub model: String,
    /// Confidence level of the intervals (0.95).
    pub confidence: f64,
    /// Critical value `t_{(1+level)/2, dof}` used for the intervals.
    pub t_critical: f64,
    /// Fitted parameters.
    pub parameters: Vec<Estimate>,
    /// Covariance matrix `s² (J_wᵀ J_w)⁻¹` (row-major, parameters in report order).
    pub covariance: Vec<Vec<f64>>,
    /// Correlation matrix `C_ij / √(C_ii C_jj)`.
    pub correlation: Vec<Vec<f64>>,
    /// Observations.
    pub observed: Vec<f64>,
    /// Model predictions at the optimum.
    pub fitted: Vec<f64>,
    /// Residuals `y − f` in data units.
    pub residuals: Vec<f64>,
    /// Group index of each observation (into `groups`).
    pub group_of: Vec<usize>,
    /// Per-group residual summary.
    pub groups: Vec<GroupSummary>,
    /// Number of observations.
    pub n: usize,
    /// Degrees of freedom `n − p`.
    pub dof: usize,
    /// Residual variance of the weighted fit `s² = Σ (w r)² / (n − p)`.
    pub residual_variance: f64,
    /// `R² = 1 − Σ_g RSS_g / Σ_g TSS_g` (data units, about each group's mean).
    pub r_squared: f64,
    /// Gaussian AIC (see [`stats::aic`]).
    pub aic: f64,
    /// Gaussian BIC (see [`stats::bic`]).
    pub bic: f64,
    /// Optimiser iterations.
    pub iterations: u64,
    /// Range of the inputs the fit saw.
    pub validity: Vec<ValidityRange>,
    /// Bootstrap, when asked for.
    pub bootstrap: Option<BootstrapSummary>,
}

impl FitReport {
    /// Parameter by name.
    pub fn parameter(&self, name: &str) -> Option<&Estimate> {
        self.parameters.iter().find(|p| p.name == name)
    }

    /// Parameter values in report order.
    pub fn values(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.value).collect()
    }

    /// Covariance as a matrix.
    pub fn covariance_matrix(&self) -> DMatrix<f64> {
        let p = self.parameters.len();
        DMatrix::from_fn(p, p, |i, j| self.covariance[i][j])
    }

    /// A derived quantity `g(θ)` by the delta method: value `g(θ̂)`, variance `∇gᵀ C ∇g`,
    /// interval `g ∓ t·se`. `g` returns the value and its gradient with respect to the
    /// parameters in report order.
    pub fn derived<G>(&self, name: &str, unit: &str, g: G) -> Estimate
    where
        G: Fn(&[f64]) -> (f64, Vec<f64>),
    {
        let (value, grad) = g(&self.values());
        let grad = DVector::from_vec(grad);
        let var = (grad.transpose() * self.covariance_matrix() * &grad)[(0, 0)];
        Estimate::new(name, unit, value, var.max(0.0).sqrt(), self.t_critical)
    }

    /// The same fit expressed in other parameters `φ = g(θ)` (e.g. `(μ_s, Δμ, I₀)` →
    /// `(μ_s, μ₂, I₀)`): covariance `G C Gᵀ` with `G = ∂g/∂θ`, intervals rebuilt, bootstrap
    /// samples mapped through `g`. `g` returns the new values and the Jacobian `G`
    /// (rows: new parameters).
    pub fn reparametrised<G>(&self, names: &[(&str, &str)], g: G) -> FitReport
    where
        G: Fn(&[f64]) -> (Vec<f64>, DMatrix<f64>),
    {
        let (values, jac) = g(&self.values());
        let cov = &jac * self.covariance_matrix() * jac.transpose();
        let mut out = self.clone();
        out.parameters = names
            .iter()
            .zip(values.iter())
            .enumerate()
            .map(|(i, ((name, unit), v))| {
                Estimate::new(name, unit, *v, cov[(i, i)].max(0.0).sqrt(), self.t_critical)
            })
            .collect();
        out.covariance = matrix_rows(&cov);
        out.correlation = matrix_rows(&correlation_of(&cov));
        if let Some(bs) = &self.bootstrap {
            let samples: Vec<Vec<f64>> = bs.samples.iter().map(|s| g(s).0).collect();
            out.bootstrap = Some(summarise_bootstrap(
                bs.seed,
                bs.resamples,
                bs.failed,
                samples,
                self.confidence,
            ));
        }
        out
    }

    /// Residuals of one group, in observation order.
    pub fn group_residuals(&self, group: usize) -> Vec<f64> {
        self.residuals
            .iter()
            .zip(&self.group_of)
            .filter(|(_, g)| **g == group)
            .map(|(r, _)| *r)
            .collect()
    }
}

/// Rows of a matrix as nested vectors (for serialisation).
pub(crate) fn matrix_rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)]).collect())
        .collect()
}

/// Correlation matrix of a covariance matrix (zero where a variance vanishes).
pub(crate) fn correlation_of(cov: &DMatrix<f64>) -> DMatrix<f64> {
    let p = cov.nrows();
    DMatrix::from_fn(p, p, |i, j| {
        let d = (cov[(i, i)] * cov[(j, j)]).sqrt();
        if i == j {
            1.0
        } else if d > 0.0 {
            cov[(i, j)] / d
        } else {
            0.0
        }
    })
}

/// Bootstrap standard errors and percentile intervals from the samples.
pub(crate) fn summarise_bootstrap(
    seed: u64,
    resamples: usize,
    failed: usize,
    samples: Vec<Vec<f64>>,
    level: f64,
) -> BootstrapSummary {
    let p = samples.first().map_or(0, |s| s.len());
    let mut std_error = Vec::with_capacity(p);
    let mut ci = Vec::with_capacity(p);
    for j in 0..p {
        let mut col: Vec<f64> = samples.iter().map(|s| s[j]).collect();
        col.sort_by(f64::total_cmp);
        let m = col.len() as f64;
        let mean = col.iter().sum::<f64>() / m;
        let var = col.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (m - 1.0).max(1.0);
        std_error.push(var.sqrt());
        ci.push([
            stats::quantile_sorted(&col, 0.5 - 0.5 * level),
            stats::quantile_sorted(&col, 0.5 + 0.5 * level),
        ]);
    }
    BootstrapSummary {
        seed,
        resamples,
        failed,
        std_error,
        ci,
        samples,
    }
}

/// One candidate of a model comparison.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateScore {
    /// Model name.
    pub model: String,
    /// Its AIC.
    pub aic: f64,
    /// `AIC − min AIC`.
    pub delta_aic: f64,
    /// Akaike weight `exp(−Δ/2)/Σ exp(−Δ_j/2)`.
    pub akaike_weight: f64,
}

/// Model choice by AIC among candidates fitted to the same data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelComparison {
    /// Candidates that could be fitted, best (lowest AIC) first.
    pub ranking: Vec<CandidateScore>,
    /// Candidates that failed, with the error message.
    pub failed: Vec<(String, String)>,
}

impl ModelComparison {
    /// Builds the ranking from `(model, AIC)` pairs.
    pub fn from_aics(aics: &[(String, f64)], failed: Vec<(String, String)>) -> Self {
        let values: Vec<f64> = aics.iter().map(|(_, a)| *a).collect();
        let weights = stats::akaike_weights(&values);
        let min = values.iter().cloned().fold(f64::INFINITY, f64::min);
        let mut ranking: Vec<CandidateScore> = aics
            .iter()
            .zip(weights)
            .map(|((model, aic), w)| CandidateScore {
                model: model.clone(),
                aic: *aic,
                delta_aic: aic - min,
                akaike_weight: w,
            })
            .collect();
        ranking.sort_by(|a, b| a.aic.total_cmp(&b.aic));
        ModelComparison { ranking, failed }
    }

    /// Name of the best model, if any could be fitted.
    pub fn best(&self) -> Option<&str> {
        self.ranking.first().map(|c| c.model.as_str())
    }
}
