//! Acceptance of a fit: the checks every calibrated law passes before a number is exported.
//!
//! Principle: a calibrated law feeds a design decision, so every number exported is either
//! right (these checks passed, its interval stated) or refused with its reason. Each check has
//! one implementation here, and every fit of the crate calls them through
//! [`Acceptance::check`], in this order (the first that fails is returned):
//!
//! 1. **scale in the data** ([`check_scale`]): a scale parameter (`I₀` of μ(I), `V*` of a wall
//!    law, `δ` of a boundary layer) must lie in `[x_min⁺, x_max]`, the range of its variable in
//!    the data (`x_min⁺` the smallest positive value). Outside, the data see only one side of
//!    the law's curvature: the scale and the asymptote beyond it are extrapolations
//!    → [`IdentifyError::ScaleNotResolved`].
//! 2. **standard error below the value** ([`check_identified`]): `se(θ) ≤ |θ|` for every
//!    parameter except the offsets a law declares may vanish (the boundary layer's slip
//!    velocity) → [`IdentifyError::ParameterNotIdentified`]. Checked before the ranges: a
//!    parameter the data do not determine at all is the more telling diagnosis.
//! 3. **intervals inside the physical range** ([`check_physical_ranges`]): the interval
//!    `θ̂ ∓ t_{0.975,n−p} se` must stay within the parameter's physical range (`I₀ ≥ 0`,
//!    `c ≥ 0`, `0 ≤ φ_min ≤ 1`, `μ_w ≤ μ_wall`, ...); an interval that reaches beyond does not
//!    exclude unphysical values → [`IdentifyError::IntervalCrossesBound`]. Parameters held on
//!    an admissible bound (`at_bound`, e.g. the Mohr–Coulomb cohesion at `c = 0` with its
//!    one-sided interval) are exempt from 2 and 3: they are not estimates and are printed as
//!    such.
//! 4. **R² above a threshold** ([`check_r_squared`]): `R² ≥` [`MIN_R_SQUARED`] (0.5 by default,
//!    [`crate::FitOptions::min_r_squared`]): a law that explains less than half of the variance
//!    of its data does not describe them → [`IdentifyError::RSquaredTooLow`].
//! 5. **better than the simpler nested form** ([`check_nested`]): the adjusted
//!    `R̄² = 1 − (1 − R²)(n − 1)/(n − p)` must not be below the nested form's (μ(I) against
//!    `μ_s + b I`, Janssen's `(K, μ_w)` against full mobilisation `μ_w = μ_wall`, `K μ_w`
//!    against the hydrostatic line, Mohr–Coulomb against `c = 0`); the adjustment makes an
//!    extra parameter pay for itself (`R̄²` is higher iff the extra parameters' F statistic
//!    exceeds 1) → [`IdentifyError::WorseThanNested`].
//!
//! A refusal offers the simpler form the data support, when the law has one
//! ([`IdentifyError::suggestion`]).

use crate::error::{BoundSide, IdentifyError, Result, ScaleSide, Suggestion};
use crate::report::{Estimate, FitReport};
use crate::stats::min_max;

/// Default threshold of [`check_r_squared`]: a law must explain at least half of the variance
/// of its data, `R² ≥ 0.5`.
pub const MIN_R_SQUARED: f64 = 0.5;

/// Adjusted coefficient of determination `R̄² = 1 − (1 − R²)(n − 1)/(n − p)` (Theil 1961) of a
/// fit with `p` free parameters to `n` observations (`p = 0` for a law with none).
pub fn adjusted_r_squared(r_squared: f64, n: usize, p: usize) -> f64 {
    if n <= p {
        return f64::NEG_INFINITY;
    }
    1.0 - (1.0 - r_squared) * (n as f64 - 1.0) / (n - p) as f64
}

/// `R² = 1 − RSS/TSS` of predictions `f` against observations `y` (about the mean of `y`).
pub fn r_squared_of(y: &[f64], f: &[f64]) -> f64 {
    let n = y.len().max(1) as f64;
    let mean = y.iter().sum::<f64>() / n;
    let rss: f64 = y.iter().zip(f).map(|(a, b)| (a - b).powi(2)).sum();
    let tss: f64 = y.iter().map(|a| (a - mean).powi(2)).sum();
    1.0 - rss / tss
}

/// Physical range `[lower, upper]` of one parameter (either end may be infinite).
#[derive(Debug, Clone, PartialEq)]
pub struct PhysicalRange {
    /// Parameter name, as in the report.
    pub name: String,
    /// Lower physical bound.
    pub lower: f64,
    /// Upper physical bound.
    pub upper: f64,
    /// What to offer when the interval crosses this range (overrides the law's suggestion).
    pub suggestion: Option<String>,
}

impl PhysicalRange {
    /// `[lower, upper]`.
    pub fn new(name: &str, lower: f64, upper: f64) -> Self {
        PhysicalRange {
            name: name.to_string(),
            lower,
            upper,
            suggestion: None,
        }
    }

    /// `[0, ∞)`.
    pub fn non_negative(name: &str) -> Self {
        Self::new(name, 0.0, f64::INFINITY)
    }

    /// The same range, offering `text` when crossed.
    pub fn suggesting(mut self, text: &str) -> Self {
        self.suggestion = Some(text.to_string());
        self
    }
}

/// A scale parameter and the range of its variable in the data.
#[derive(Debug, Clone, PartialEq)]
pub struct ScaleCheck {
    /// Parameter name (`I_0`, `V_star`, `delta`).
    pub parameter: String,
    /// Its variable (`I`, `V`, `y`).
    pub variable: String,
    /// Smallest positive value of the variable in the data.
    pub data_min: f64,
    /// Largest value of the variable in the data.
    pub data_max: f64,
}

impl ScaleCheck {
    /// The scale `parameter` of `variable`, whose data are `x`.
    pub fn new(parameter: &str, variable: &str, x: &[f64]) -> Self {
        let (_, data_max) = min_max(x);
        let data_min = x
            .iter()
            .cloned()
            .filter(|v| *v > 0.0)
            .fold(f64::INFINITY, f64::min);
        ScaleCheck {
            parameter: parameter.to_string(),
            variable: variable.to_string(),
            data_min,
            data_max,
        }
    }
}

/// The simpler form nested in a law, fitted to the same data.
#[derive(Debug, Clone, PartialEq)]
pub struct NestedForm {
    /// Its name (`mu-i-linear`, ...).
    pub name: String,
    /// Its R² on the same observations.
    pub r_squared: f64,
    /// Its number of free parameters.
    pub parameters: usize,
}

/// What one law's fit must satisfy (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Acceptance {
    /// Law name, for messages.
    pub law: String,
    /// The simpler form offered by every refusal of this law, if any.
    pub suggestion: Option<String>,
    /// Scale parameters.
    pub scales: Vec<ScaleCheck>,
    /// Physical ranges of the parameters (report parameters and `extra`).
    pub ranges: Vec<PhysicalRange>,
    /// Parameters exempt from the standard-error check (offsets that may rightly vanish).
    pub may_vanish: Vec<String>,
    /// Estimates checked with the report's parameters (e.g. `μ₂ − μ_s`).
    pub extra: Vec<Estimate>,
    /// R² threshold.
    pub min_r_squared: f64,
    /// The simpler nested form, when fitted.
    pub nested: Option<NestedForm>,
}

impl Acceptance {
    /// Checks for `law` with R² threshold `min_r_squared` and nothing else yet.
    pub fn new(law: &str, min_r_squared: f64) -> Self {
        Acceptance {
            law: law.to_string(),
            suggestion: None,
            scales: Vec::new(),
            ranges: Vec::new(),
            may_vanish: Vec::new(),
            extra: Vec::new(),
            min_r_squared,
            nested: None,
        }
    }

    /// Offers `text` in every refusal.
    pub fn suggest(mut self, text: &str) -> Self {
        self.suggestion = Some(text.to_string());
        self
    }

    /// Adds a scale check.
    pub fn scale(mut self, check: ScaleCheck) -> Self {
        self.scales.push(check);
        self
    }

    /// Adds a physical range.
    pub fn range(mut self, range: PhysicalRange) -> Self {
        self.ranges.push(range);
        self
    }

    /// Adds `[0, ∞)` for each of `names`.
    pub fn non_negative(mut self, names: &[&str]) -> Self {
        self.ranges
            .extend(names.iter().map(|n| PhysicalRange::non_negative(n)));
        self
    }

    /// Exempts `names` from the standard-error check.
    pub fn may_vanish(mut self, names: &[&str]) -> Self {
        self.may_vanish.extend(names.iter().map(|n| n.to_string()));
        self
    }

    /// Adds an estimate checked with the report's parameters.
    pub fn extra(mut self, estimate: Estimate) -> Self {
        self.extra.push(estimate);
        self
    }

    /// Compares with a nested form (skipped when `nested` is `None`, e.g. its fit failed).
    pub fn nested(mut self, nested: Option<NestedForm>) -> Self {
        self.nested = nested;
        self
    }

    /// Runs the checks in the order of the module documentation on `report`.
    pub fn check(&self, report: &FitReport) -> Result<()> {
        self.run(report).map_err(|e| match &self.suggestion {
            Some(s) => e.suggesting(s),
            None => e,
        })
    }

    fn run(&self, report: &FitReport) -> Result<()> {
        for s in &self.scales {
            if let Some(p) = report.parameter(&s.parameter) {
                check_scale(&self.law, s, p.value)?;
            }
        }
        let estimates: Vec<&Estimate> = report.parameters.iter().chain(&self.extra).collect();
        let names: Vec<&str> = estimates
            .iter()
            .map(|e| e.name.as_str())
            .filter(|n| !self.may_vanish.iter().any(|m| m == n))
            .collect();
        check_estimates_identified(&self.law, report, &estimates, &names)?;
        check_physical_ranges(&self.law, report, &estimates, &self.ranges)?;
        check_r_squared(&self.law, report, self.min_r_squared)?;
        if let Some(nested) = &self.nested {
            check_nested(&self.law, report, nested)?;
        }
        Ok(())
    }
}

/// Refuses a scale `value` outside `[data_min, data_max]` of its variable
/// ([`IdentifyError::ScaleNotResolved`]).
pub fn check_scale(law: &str, scale: &ScaleCheck, value: f64) -> Result<()> {
    let side = if value > scale.data_max || !value.is_finite() {
        Some(ScaleSide::AboveData)
    } else if value < scale.data_min {
        Some(ScaleSide::BelowData)
    } else {
        None
    };
    match side {
        Some(side) => Err(IdentifyError::ScaleNotResolved {
            law: law.to_string(),
            parameter: scale.parameter.clone(),
            value,
            variable: scale.variable.clone(),
            side,
            data_min: scale.data_min,
            data_max: scale.data_max,
            suggestion: Suggestion::none(),
        }),
        None => Ok(()),
    }
}

/// Refuses the first estimate whose interval `[ci_low, ci_high]` reaches beyond its physical
/// range ([`IdentifyError::IntervalCrossesBound`]); estimates held on a bound (`at_bound`) and
/// estimates without a range are skipped.
pub fn check_physical_ranges(
    law: &str,
    report: &FitReport,
    estimates: &[&Estimate],
    ranges: &[PhysicalRange],
) -> Result<()> {
    for r in ranges {
        let Some(e) = estimates.iter().find(|e| e.name == r.name) else {
            continue;
        };
        if e.at_bound {
            continue;
        }
        let crossed = if e.ci_low < r.lower || e.ci_low.is_nan() {
            Some((r.lower, BoundSide::Lower))
        } else if e.ci_high > r.upper || e.ci_high.is_nan() {
            Some((r.upper, BoundSide::Upper))
        } else {
            None
        };
        if let Some((bound, side)) = crossed {
            return Err(IdentifyError::IntervalCrossesBound {
                law: law.to_string(),
                name: e.name.clone(),
                value: e.value,
                ci_low: e.ci_low,
                ci_high: e.ci_high,
                bound,
                side,
                confidence: report.confidence,
                report: Box::new(report.clone()),
                suggestion: r
                    .suggestion
                    .as_deref()
                    .map_or_else(Suggestion::none, Suggestion::of),
            });
        }
    }
    Ok(())
}

/// Checks that each parameter of `names` is determined by the data, else returns
/// [`IdentifyError::ParameterNotIdentified`] for the first that is not.
///
/// Criterion: a parameter `θ` with standard error `se` is not identified when `se > |θ|`
/// (or `se` is not finite). Its interval `θ ∓ t·se` then spans zero and reaches beyond it by
/// more than `(t − 1)|θ|` (`t ≈ 2.0–2.8` at 95 %, so the interval is several times wider than
/// the value): the data fix neither the sign nor the order of magnitude of `θ`. Parameters held
/// on a bound (`at_bound`: not estimates, a one-sided interval at most) are skipped.
pub fn check_identified(report: &FitReport, names: &[&str]) -> Result<()> {
    let estimates: Vec<&Estimate> = report.parameters.iter().collect();
    check_estimates_identified(&report.model, report, &estimates, names)
}

fn check_estimates_identified(
    law: &str,
    report: &FitReport,
    estimates: &[&Estimate],
    names: &[&str],
) -> Result<()> {
    for name in names {
        let Some(p) = estimates.iter().find(|e| e.name == *name) else {
            continue;
        };
        if p.at_bound {
            continue;
        }
        let identified = p.std_error.is_finite() && p.std_error <= p.value.abs();
        if !identified {
            return Err(IdentifyError::ParameterNotIdentified {
                law: law.to_string(),
                name: p.name.clone(),
                value: p.value,
                std_error: p.std_error,
                ci_low: p.ci_low,
                ci_high: p.ci_high,
                confidence: report.confidence,
                report: Box::new(report.clone()),
                suggestion: Suggestion::none(),
            });
        }
    }
    Ok(())
}

/// Refuses `R² < min_r_squared` (or a non-finite R²) ([`IdentifyError::RSquaredTooLow`]).
pub fn check_r_squared(law: &str, report: &FitReport, min_r_squared: f64) -> Result<()> {
    if report.r_squared < min_r_squared || report.r_squared.is_nan() {
        return Err(IdentifyError::RSquaredTooLow {
            law: law.to_string(),
            r_squared: report.r_squared,
            threshold: min_r_squared,
            report: Box::new(report.clone()),
            suggestion: Suggestion::none(),
        });
    }
    Ok(())
}

/// Refuses a fit whose adjusted R² is below its nested form's on the same `n` observations
/// ([`IdentifyError::WorseThanNested`], suggesting the nested form).
pub fn check_nested(law: &str, report: &FitReport, nested: &NestedForm) -> Result<()> {
    let p = report.parameters.iter().filter(|e| !e.at_bound).count();
    let full = adjusted_r_squared(report.r_squared, report.n, p);
    let simple = adjusted_r_squared(nested.r_squared, report.n, nested.parameters);
    if full < simple {
        return Err(IdentifyError::WorseThanNested {
            law: law.to_string(),
            adjusted_r_squared: full,
            nested: nested.name.clone(),
            nested_adjusted_r_squared: simple,
            report: Box::new(report.clone()),
            suggestion: Suggestion::of(&format!("use {}", nested.name)),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(params: Vec<Estimate>, r2: f64) -> FitReport {
        FitReport {
            model: "m".into(),
            confidence: 0.95,
            t_critical: 2.0,
            covariance: vec![vec![0.0; params.len()]; params.len()],
            correlation: vec![vec![0.0; params.len()]; params.len()],
            parameters: params,
            observed: vec![],
            fitted: vec![],
            residuals: vec![],
            group_of: vec![],
            groups: vec![],
            n: 10,
            dof: 8,
            residual_variance: 1.0,
            r_squared: r2,
            aic: 0.0,
            bic: 0.0,
            iterations: 0,
            validity: vec![],
            bootstrap: None,
        }
    }

    #[test]
    fn each_check_refuses_with_its_reason_and_the_suggestion() {
        let a = Acceptance::new("law", MIN_R_SQUARED)
            .suggest("use simpler")
            .non_negative(&["x"]);
        let ok = report(vec![Estimate::new("x", "1", 1.0, 0.1, 2.0)], 0.9);
        assert!(a.check(&ok).is_ok());
        let crossing = report(vec![Estimate::new("x", "1", 1.0, 0.6, 2.0)], 0.9);
        let e = a.check(&crossing).unwrap_err();
        assert!(
            matches!(e, IdentifyError::IntervalCrossesBound { .. }),
            "{e}"
        );
        assert!(e.to_string().ends_with("; use simpler"), "{e}");
        let vague = report(vec![Estimate::new("y", "1", 1.0, 1.5, 2.0)], 0.9);
        assert!(matches!(
            a.check(&vague).unwrap_err(),
            IdentifyError::ParameterNotIdentified { .. }
        ));
        let poor = report(vec![Estimate::new("x", "1", 1.0, 0.1, 2.0)], 0.3);
        assert!(matches!(
            a.check(&poor).unwrap_err(),
            IdentifyError::RSquaredTooLow { .. }
        ));
        let nested = a.clone().nested(Some(NestedForm {
            name: "simpler".into(),
            r_squared: 0.95,
            parameters: 0,
        }));
        let e = nested.check(&ok).unwrap_err();
        assert!(matches!(e, IdentifyError::WorseThanNested { .. }), "{e}");
        let scaled = Acceptance::new("law", 0.5).scale(ScaleCheck::new("x", "v", &[0.1, 0.5]));
        let e = scaled.check(&ok).unwrap_err();
        assert!(
            matches!(
                e,
                IdentifyError::ScaleNotResolved {
                    side: ScaleSide::AboveData,
                    ..
                }
            ),
            "{e}"
        );
    }

    #[test]
    fn adjusted_r_squared_penalises_parameters() {
        assert_eq!(adjusted_r_squared(1.0, 10, 3), 1.0);
        assert!((adjusted_r_squared(0.9, 11, 1) - 0.9).abs() < 1e-15);
        assert!(adjusted_r_squared(0.9, 11, 3) < 0.9);
    }
}
