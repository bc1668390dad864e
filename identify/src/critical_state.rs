//! The critical state and the stress–dilatancy relation of a biaxial test (laws in
//! [`crate::laws::critical_state`]), from homogenised histories.
//!
//! **Critical state** ([`fit_critical_state`]): each confining pressure `k` gives a plateau
//! (the large-strain end of its test) with the means of `sin φ = q/p` and of the solid
//! fraction `φ` and their block-averaged standard errors `s_k` (Flyvbjerg & Petersen 1989).
//! For rigid grains the critical state does not depend on the pressure, so the estimate is the
//! mean over the pressures, `x̄ = (1/n) Σ x_k`, with the larger of two standard errors: the
//! propagated one `√(Σ s_k²)/n` and, with two pressures or more, the scatter between them
//! `sd(x_k)/√n` (a pressure dependence, or plateaus not reached, then shows as a wide
//! interval). The interval is `x̄ ∓ t s` with Student's `t` at `Σ (b_k − 1)` degrees of
//! freedom (`b_k` blocks per plateau) for the propagated error, `n − 1` for the scatter.
//!
//! Which kind each interval is ([`IntervalKind`]) is part of the fit: the block average of one
//! plateau measures the noise of that sample's time series only, and understates the scatter
//! between independent samples (the biaxial's critical solid fraction at 1 and 4 kPa, statistical
//! replicas for rigid grains, differed by 10 of its block standard errors), so an interval is
//! stated from the replicas whenever there are two or more. The fit also gives the standard
//! deviation between the replicas, `sd(x_k)`: the standard error of *one* sample's value, whose
//! interval `x_k ∓ t_{n−1} sd` ([`CriticalStateFit::sample_interval`]) is the one to put on a
//! single pressure's (or seed's) plateau value. The
//! angle is `φ_c = asin(sin φ_c)` with `s_φ = s / cos φ_c` (delta method). A constant explains
//! none of the variance of its data: the report's `R²` is 0 by definition and no `R²`
//! threshold applies; refusals: a standard error above its value, an interval of `φ_c` outside
//! `[0, π/2]` or of the solid fraction outside `[0, 1]`.
//!
//! **Stress–dilatancy** ([`fit_stress_dilatancy`]): `sin φ_mob = sin φ_cv + β sin ψ` by least
//! squares ([`crate::fit`]) over binned points of the hardening phase (with the samples of the
//! points given, intervals that cover the scatter between them: [`fit_stress_dilatancy`]), with
//! the checks of
//! [`crate::accept`]: `sin φ_cv` inside `[0, 1]`, `β ≥ 0`, standard errors below the values,
//! `R²` above the threshold.

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::accept::{Acceptance, PhysicalRange};
use crate::error::{check_finite, check_spread, IdentifyError, Result};
use crate::fit::{fit_least_squares, FitOptions, Observations};
use crate::laws::{CriticalStateLaw, StressDilatancyLaw};
use crate::mu_i::{ols_start, LinearModel};
use crate::report::{
    correlation_of, matrix_rows, Estimate, FitReport, GroupSummary, ValidityRange,
};
use crate::stats;

/// The critical-state plateau of one test.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PlateauMeasure {
    /// Mean pressure `p` on the plateau (Pa, compressive positive).
    pub pressure_pa: f64,
    /// Mean `sin φ = q/p` (1).
    pub sin_phi: f64,
    /// Its block-averaged standard error (1).
    pub sin_phi_std_error: f64,
    /// Mean solid fraction (1).
    pub solid_fraction: f64,
    /// Its block-averaged standard error (1).
    pub solid_fraction_std_error: f64,
    /// Blocks of the block average (≥ 2).
    pub blocks: usize,
}

/// What an interval of the critical state is made of (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IntervalKind {
    /// The scatter between independent samples (pressures or seeds as replicas), `sd/√n` at
    /// `n − 1` degrees of freedom: it was the larger error.
    Replicas,
    /// The plateaus' block averages propagated, `√(Σ s_k²)/n`: larger than the scatter between
    /// the replicas, which it therefore covers.
    BlockAverages,
    /// One sample's block average: nothing measures the scatter between samples, which it
    /// understates.
    OneSample,
}

impl IntervalKind {
    /// `replicas`, `block-averages` or `one-sample`.
    pub fn as_str(self) -> &'static str {
        match self {
            IntervalKind::Replicas => "replicas",
            IntervalKind::BlockAverages => "block-averages",
            IntervalKind::OneSample => "one-sample",
        }
    }

    /// One phrase for a report, with `n` the replicas.
    pub fn describe(self, n: usize) -> String {
        match self {
            IntervalKind::Replicas => format!("the scatter between the {n} replicas"),
            IntervalKind::BlockAverages => format!(
                "the block averages of the plateaus, wider than the scatter between the {n} replicas"
            ),
            IntervalKind::OneSample => {
                "the block average of one sample, which understates the scatter between samples"
                    .into()
            }
        }
    }
}

/// Result of [`fit_critical_state`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CriticalStateFit {
    /// The law.
    pub law: CriticalStateLaw,
    /// `φ_c` (rad), parameter `friction_angle_c`.
    pub friction_angle: Estimate,
    /// The same in degrees (`friction_angle_c_deg`).
    pub friction_angle_deg: Estimate,
    /// `sin φ_c` (`sin_phi_c`).
    pub sin_phi: Estimate,
    /// Critical solid fraction (`solid_fraction_c`).
    pub solid_fraction: Estimate,
    /// Parameters `friction_angle_c`, `solid_fraction_c` (observations: the `sin φ` of each
    /// plateau).
    pub report: FitReport,
    /// Plateaus (independent samples: pressures or seeds).
    pub replicas: usize,
    /// What the intervals of `sin φ_c` (and `φ_c`) are made of.
    pub sin_phi_interval: IntervalKind,
    /// What the interval of the solid fraction is made of.
    pub solid_fraction_interval: IntervalKind,
    /// Standard deviation of the plateaus' `sin φ` between the replicas (NaN with one): the
    /// standard error of one sample's value.
    pub sin_phi_replica_sd: f64,
    /// The same for the solid fraction.
    pub solid_fraction_replica_sd: f64,
    /// Student's `t` at `n − 1` degrees of freedom and the fit's confidence (NaN with one
    /// replica), for [`CriticalStateFit::sample_interval`].
    pub replica_t: f64,
}

impl CriticalStateFit {
    /// The interval of one sample's plateau value `x` whose standard deviation between the
    /// replicas is `sd` (`sin_phi_replica_sd` or `solid_fraction_replica_sd`): `x ∓ t_{n−1} sd`,
    /// the interval that covers the scatter between samples (NaN bounds with one replica).
    pub fn sample_interval(&self, x: f64, sd: f64) -> (f64, f64) {
        (x - self.replica_t * sd, x + self.replica_t * sd)
    }
}

/// Standard deviation of `x` (NaN with fewer than two values).
fn replica_sd(x: &[f64]) -> f64 {
    if x.len() < 2 {
        return f64::NAN;
    }
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// Mean, standard error, degrees of freedom and the kind of the interval (module
/// documentation).
fn pooled(x: &[f64], se: &[f64], blocks: &[usize]) -> (f64, f64, usize, IntervalKind) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let prop = se.iter().map(|s| s * s).sum::<f64>().sqrt() / n;
    let dof_prop: usize = blocks.iter().map(|b| b.saturating_sub(1).max(1)).sum();
    if x.len() >= 2 {
        let scatter = replica_sd(x) / n.sqrt();
        if scatter > prop {
            return (mean, scatter, x.len() - 1, IntervalKind::Replicas);
        }
        return (mean, prop, dof_prop, IntervalKind::BlockAverages);
    }
    (mean, prop, dof_prop, IntervalKind::OneSample)
}

/// The critical state from the plateaus of one or more tests (module documentation).
///
/// Errors: [`IdentifyError::TooFewPoints`] (none), [`IdentifyError::NonFinite`], and the
/// refusals of the module documentation.
pub fn fit_critical_state(
    plateaus: &[PlateauMeasure],
    confidence: f64,
) -> Result<CriticalStateFit> {
    if plateaus.is_empty() {
        return Err(IdentifyError::TooFewPoints {
            law: "critical-state".into(),
            needed: 1,
            got: 0,
        });
    }
    let col = |f: fn(&PlateauMeasure) -> f64| -> Vec<f64> { plateaus.iter().map(f).collect() };
    let (s, s_se, f, f_se, p) = (
        col(|m| m.sin_phi),
        col(|m| m.sin_phi_std_error),
        col(|m| m.solid_fraction),
        col(|m| m.solid_fraction_std_error),
        col(|m| m.pressure_pa),
    );
    for (name, v) in [
        ("sin_phi", &s),
        ("sin_phi_std_error", &s_se),
        ("solid_fraction", &f),
        ("solid_fraction_std_error", &f_se),
        ("p", &p),
    ] {
        check_finite(name, v)?;
    }
    let blocks: Vec<usize> = plateaus.iter().map(|m| m.blocks).collect();
    let (sm, sse, sdof, s_kind) = pooled(&s, &s_se, &blocks);
    let (fm, fse, fdof, f_kind) = pooled(&f, &f_se, &blocks);
    let ts = stats::t_critical(confidence, sdof);
    let tf = stats::t_critical(confidence, fdof);
    let sin_phi = Estimate::new("sin_phi_c", "1", sm, sse, ts);
    let angle = sm.clamp(-1.0, 1.0).asin();
    let angle_se = sse / angle.cos().max(1e-12);
    let friction_angle = Estimate::new("friction_angle_c", "rad", angle, angle_se, ts);
    let k = 180.0 / std::f64::consts::PI;
    let friction_angle_deg =
        Estimate::new("friction_angle_c_deg", "deg", angle * k, angle_se * k, ts);
    let solid_fraction = Estimate::new("solid_fraction_c", "1", fm, fse, tf);
    let cov = DMatrix::from_row_slice(2, 2, &[angle_se * angle_se, 0.0, 0.0, fse * fse]);
    let n = s.len();
    let residuals: Vec<f64> = s.iter().map(|v| v - sm).collect();
    let rss: f64 = residuals.iter().map(|r| r * r).sum();
    let dof = sdof.min(fdof);
    let report = FitReport {
        model: "critical-state".into(),
        confidence,
        t_critical: ts,
        parameters: vec![friction_angle.clone(), solid_fraction.clone()],
        covariance: matrix_rows(&cov),
        correlation: matrix_rows(&correlation_of(&cov)),
        observed: s.clone(),
        fitted: vec![sm; n],
        residuals,
        group_of: vec![0; n],
        groups: vec![GroupSummary {
            name: "sin_phi".into(),
            n,
            rss,
            tss: rss,
            weight: 1.0,
        }],
        n,
        dof,
        residual_variance: if n > 1 {
            rss / (n - 1) as f64
        } else {
            sse * sse
        },
        // a constant explains none of the variance about the mean (module documentation)
        r_squared: 0.0,
        aic: stats::aic(&[(n, rss.max(f64::MIN_POSITIVE))], 1),
        bic: stats::bic(&[(n, rss.max(f64::MIN_POSITIVE))], 1),
        iterations: 0,
        validity: vec![ValidityRange::of("p", "Pa", &p)],
        bootstrap: None,
    };
    Acceptance::new("critical-state", f64::NEG_INFINITY)
        .range(PhysicalRange::new(
            "friction_angle_c",
            0.0,
            std::f64::consts::FRAC_PI_2,
        ))
        .range(PhysicalRange::new("solid_fraction_c", 0.0, 1.0))
        .check(&report)?;
    Ok(CriticalStateFit {
        law: CriticalStateLaw {
            friction_angle_rad: angle,
            solid_fraction: fm,
        },
        friction_angle,
        friction_angle_deg,
        sin_phi,
        solid_fraction,
        report,
        replicas: n,
        sin_phi_interval: s_kind,
        solid_fraction_interval: f_kind,
        sin_phi_replica_sd: replica_sd(&s),
        solid_fraction_replica_sd: replica_sd(&f),
        replica_t: if n >= 2 {
            stats::t_critical(confidence, n - 1)
        } else {
            f64::NAN
        },
    })
}

/// Points of a stress–dilatancy relation: `sin ψ` and `sin φ_mob` (1), same length.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StressDilatancyData {
    /// `sin ψ = −ε̇_v/ε̇_γ` (1).
    pub sin_psi: Vec<f64>,
    /// `sin φ_mob = q/p` (1).
    pub sin_phi: Vec<f64>,
    /// The independent sample (a pressure's test, a seed) each point comes from, when known:
    /// points of one sample are correlated, and the intervals then cover the scatter between
    /// the samples ([`fit_stress_dilatancy`]).
    #[serde(default)]
    pub sample: Option<Vec<usize>>,
}

/// Result of [`fit_stress_dilatancy`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StressDilatancyFit {
    /// The law.
    pub law: StressDilatancyLaw,
    /// Parameters `sin_phi_c`, `beta`.
    pub report: FitReport,
    /// Independent samples the points come from (0 when not given).
    pub samples: usize,
    /// Whether the intervals are the cluster-robust ones over the samples (they were wider
    /// than the least-squares ones, which take every point as independent).
    pub clustered: bool,
}

/// Cluster-robust covariance of the least-squares line `y = a + b x` over the samples
/// `sample` (Liang & Zeger, Biometrika 73, 1986; the small-sample factor
/// `G/(G − 1) · (n − 1)/(n − 2)` of Cameron & Miller, J. Human Resources 50, 2015):
/// `(XᵀX)⁻¹ Σ_g (X_gᵀ e_g)(X_gᵀ e_g)ᵀ (XᵀX)⁻¹`, `e` the residuals; with `G` samples.
fn cluster_covariance(x: &[f64], residuals: &[f64], sample: &[usize]) -> (DMatrix<f64>, usize) {
    let n = x.len();
    let xm = DMatrix::from_fn(n, 2, |k, j| if j == 0 { 1.0 } else { x[k] });
    let bread = (xm.transpose() * &xm)
        .try_inverse()
        .unwrap_or_else(|| DMatrix::from_element(2, 2, f64::NAN));
    let mut groups: Vec<usize> = sample.to_vec();
    groups.sort_unstable();
    groups.dedup();
    let mut meat = DMatrix::<f64>::zeros(2, 2);
    for g in &groups {
        let mut s = nalgebra::Vector2::zeros();
        for k in (0..n).filter(|&k| sample[k] == *g) {
            s += nalgebra::Vector2::new(residuals[k], residuals[k] * x[k]);
        }
        meat += s * s.transpose();
    }
    let gn = groups.len() as f64;
    let factor = gn / (gn - 1.0).max(1.0) * (n as f64 - 1.0) / (n as f64 - 2.0).max(1.0);
    (&bread * meat * &bread * factor, groups.len())
}

/// Fits `sin φ_mob = sin φ_cv + β sin ψ` (module documentation). With the samples of the points
/// given (`data.sample`, two or more) and a cluster-robust variance over the samples
/// (`cluster_covariance`) larger than the least-squares one for either parameter, each
/// standard error is the larger of the two, with the cluster-robust correlation and Student's
/// `t` at `G − 1` degrees of freedom: the points of one sample are correlated (consecutive windows of
/// one test), and least squares alone takes them as independent.
///
/// Errors: [`IdentifyError::TooFewPoints`] (< 4), [`IdentifyError::NonFinite`],
/// [`IdentifyError::ZeroVariance`] (no spread of `sin ψ`), and the refusals of
/// [`crate::accept`].
pub fn fit_stress_dilatancy(
    data: &StressDilatancyData,
    options: &FitOptions,
) -> Result<StressDilatancyFit> {
    let (x, y) = (&data.sin_psi, &data.sin_phi);
    check_finite("sin_psi", x)?;
    check_finite("sin_phi", y)?;
    crate::error::check_same_len("sin_psi", x, "sin_phi", y)?;
    if x.len() < 4 {
        return Err(IdentifyError::TooFewPoints {
            law: "stress-dilatancy".into(),
            needed: 4,
            got: x.len(),
        });
    }
    check_spread("sin_psi", x)?;
    let model = LinearModel {
        x,
        name: "stress-dilatancy",
        names: ["sin_phi_c", "beta"],
        bounds: [(f64::NEG_INFINITY, f64::INFINITY); 2],
        decreasing: false,
    };
    let (a, b) = ols_start(x, y);
    let mut report = fit_least_squares(
        &model,
        &Observations::single("sin_phi", y.clone()),
        &[a, b],
        options,
        vec![
            ValidityRange::of("sin_psi", "1", x),
            ValidityRange::of("sin_phi", "1", y),
        ],
    )?;
    let mut samples = 0;
    let mut clustered = false;
    if let Some(sample) = &data.sample {
        if sample.len() != x.len() {
            return Err(IdentifyError::LengthMismatch {
                first: "sin_psi".into(),
                first_len: x.len(),
                second: "sample".into(),
                second_len: sample.len(),
            });
        }
        let (cov, g) = cluster_covariance(x, &report.residuals, sample);
        samples = g;
        let wider = (0..2).any(|j| cov[(j, j)] > report.parameters[j].std_error.powi(2));
        if g >= 2 && wider && cov.iter().all(|v| v.is_finite()) {
            clustered = true;
            let t = stats::t_critical(report.confidence, g - 1);
            // each standard error the larger of the two, with the cluster-robust correlation
            let corr = correlation_of(&cov);
            let se: Vec<f64> = (0..2)
                .map(|j| {
                    cov[(j, j)]
                        .max(0.0)
                        .sqrt()
                        .max(report.parameters[j].std_error)
                })
                .collect();
            let cov = DMatrix::from_fn(2, 2, |i, j| corr[(i, j)] * se[i] * se[j]);
            for (j, p) in report.parameters.iter_mut().enumerate() {
                *p = Estimate::new(&p.name, &p.unit, p.value, se[j], t);
            }
            report.t_critical = t;
            report.covariance = matrix_rows(&cov);
            report.correlation = matrix_rows(&corr);
        }
    }
    Acceptance::new("stress-dilatancy", options.min_r_squared)
        .range(PhysicalRange::new("sin_phi_c", 0.0, 1.0))
        .non_negative(&["beta"])
        .check(&report)?;
    Ok(StressDilatancyFit {
        law: StressDilatancyLaw {
            sin_phi_c: report.parameters[0].value,
            beta: report.parameters[1].value,
        },
        report,
        samples,
        clustered,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plateau(s: f64, se: f64, f: f64) -> PlateauMeasure {
        PlateauMeasure {
            pressure_pa: 1000.0,
            sin_phi: s,
            sin_phi_std_error: se,
            solid_fraction: f,
            solid_fraction_std_error: 0.001,
            blocks: 4,
        }
    }

    #[test]
    fn critical_state_is_the_mean_with_the_larger_error() {
        // three plateaus 0.30, 0.32, 0.34 with tiny block errors: the scatter dominates,
        // s = sd/√3 = 0.02/√3, t at 2 degrees of freedom (4.303)
        let f = fit_critical_state(
            &[
                plateau(0.30, 1e-4, 0.82),
                plateau(0.32, 1e-4, 0.82),
                plateau(0.34, 1e-4, 0.82),
            ],
            0.95,
        )
        .unwrap();
        assert!((f.sin_phi.value - 0.32).abs() < 1e-12);
        let se = 0.02 / 3f64.sqrt();
        assert!((f.sin_phi.std_error - se).abs() < 1e-12);
        assert!((f.sin_phi.ci_high - 0.32 - 4.303 * se).abs() < 1e-3 * se * 4.3);
        assert!((f.friction_angle.value - 0.32f64.asin()).abs() < 1e-12);
        // one plateau: its own block error, 3 degrees of freedom
        let g = fit_critical_state(&[plateau(0.30, 0.01, 0.82)], 0.95).unwrap();
        assert!((g.sin_phi.std_error - 0.01).abs() < 1e-15);
        assert!((g.report.t_critical - 3.182).abs() < 1e-3);
        // an error above its value is refused
        assert!(fit_critical_state(&[plateau(0.01, 0.05, 0.82)], 0.95).is_err());
    }

    /// Two pressures, statistical replicas for rigid grains, whose critical solid fractions
    /// differ by 10 of their block standard errors (the biaxial at 1 and 4 kPa): the block
    /// interval of one sample misses the other sample's value, the replica intervals cover
    /// both, and the fit says which kind each interval is.
    #[test]
    fn replica_intervals_cover_the_scatter_between_samples() {
        let se = 2e-4;
        let (a, b) = (0.8200, 0.8200 + 10.0 * se);
        let mut p1 = plateau(0.28, 1e-3, a);
        let mut p2 = plateau(0.28, 1e-3, b);
        p1.solid_fraction_std_error = se;
        p2.solid_fraction_std_error = se;
        p2.pressure_pa = 4000.0;
        let f = fit_critical_state(&[p1, p2], 0.95).unwrap();
        // the block interval of one sample (t at its 3 degrees of freedom) misses the other
        let t_block = stats::t_critical(0.95, 3);
        assert!(a + t_block * se < b);
        // the law's interval is the replicas': mean ∓ t₁ sd/√2 (sd = 10 se/√2), both inside
        assert_eq!(f.solid_fraction_interval, IntervalKind::Replicas);
        assert_eq!(f.replicas, 2);
        let sd = 10.0 * se / 2f64.sqrt();
        assert!((f.solid_fraction_replica_sd - sd).abs() < 1e-12);
        assert!((f.solid_fraction.std_error - sd / 2f64.sqrt()).abs() < 1e-12);
        assert!(
            f.solid_fraction.covers(a) && f.solid_fraction.covers(b),
            "{:?}",
            f.solid_fraction
        );
        // each sample's replica interval x_k ∓ t₁ sd covers the other sample
        for (x, other) in [(a, b), (b, a)] {
            let (lo, hi) = f.sample_interval(x, f.solid_fraction_replica_sd);
            assert!(lo <= other && other <= hi, "[{lo}, {hi}] misses {other}");
        }
        // equal sin φ: their scatter (0) is below the block errors, which are then the interval
        assert_eq!(f.sin_phi_interval, IntervalKind::BlockAverages);
        // one sample: said so, no replica interval
        let g = fit_critical_state(&[p1], 0.95).unwrap();
        assert_eq!(g.solid_fraction_interval, IntervalKind::OneSample);
        assert!(g.solid_fraction_replica_sd.is_nan() && g.replica_t.is_nan());
    }

    /// Three samples (pressures) of four windows each on the line 0.25 + 1.0 sin ψ, each
    /// sample shifted as a whole by −0.02, +0.02, 0 (a sample's plateau, not window noise) and
    /// by ±0.001 within: least squares takes the 12 points as independent; the cluster-robust
    /// interval over the 3 samples is wider and covers the line.
    #[test]
    fn stress_dilatancy_intervals_cover_the_scatter_between_samples() {
        let mut x = Vec::new();
        let mut y = Vec::new();
        let mut sample = Vec::new();
        for (g, shift) in [-0.02, 0.02, 0.0].iter().enumerate() {
            for k in 0..4 {
                let psi = 0.05 * k as f64;
                x.push(psi);
                y.push(0.25 + psi + shift + if k % 2 == 0 { 0.001 } else { -0.001 });
                sample.push(g);
            }
        }
        let plain = StressDilatancyData {
            sin_psi: x,
            sin_phi: y,
            sample: None,
        };
        let ls = fit_stress_dilatancy(&plain, &FitOptions::default()).unwrap();
        assert!(!ls.clustered && ls.samples == 0);
        let by_sample = StressDilatancyData {
            sample: Some(sample),
            ..plain
        };
        let cr = fit_stress_dilatancy(&by_sample, &FitOptions::default()).unwrap();
        assert!(cr.clustered && cr.samples == 3, "{cr:?}");
        assert!((cr.report.t_critical - stats::t_critical(0.95, 2)).abs() < 1e-12);
        for j in 0..2 {
            assert_eq!(cr.report.parameters[j].value, ls.report.parameters[j].value);
            assert!(cr.report.parameters[j].std_error >= ls.report.parameters[j].std_error);
        }
        // the intercept carries the samples' shifts: its interval (t at 2 degrees of freedom,
        // not 10) more than twice as wide (measured 2.7)
        let half = |e: &Estimate| e.ci_high - e.value;
        let ratio = half(&cr.report.parameters[0]) / half(&ls.report.parameters[0]);
        assert!(ratio > 2.0, "{ratio}");
        assert!(cr.report.parameters[0].covers(0.25) && cr.report.parameters[1].covers(1.0));
    }

    #[test]
    fn taylor_line_is_recovered() {
        // sin φ = 0.25 + 1.0 sin ψ with a ±0.002 alternating scatter
        let x: Vec<f64> = (0..12).map(|k| 0.01 * k as f64).collect();
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(k, v)| 0.25 + v + if k % 2 == 0 { 0.002 } else { -0.002 })
            .collect();
        let f = fit_stress_dilatancy(
            &StressDilatancyData {
                sin_psi: x,
                sin_phi: y,
                sample: None,
            },
            &FitOptions::default(),
        )
        .unwrap();
        assert!((f.law.sin_phi_c - 0.25).abs() < 0.003, "{:?}", f.law);
        assert!((f.law.beta - 1.0).abs() < 0.05, "{:?}", f.law);
        assert!(f.report.parameters[1].covers(1.0));
    }
}
