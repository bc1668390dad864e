//! μ(I) and φ(I) fits: recovery, coverage, model comparison, bootstrap, identifiability errors.

mod common;

use common::gaussian;
use identify::error::ScaleSide;
use identify::fit::{BootstrapOptions, FitOptions};
use identify::laws::MuILaw;
use identify::mu_i::{compare_mu_i_forms, fit_mu_i, fit_mu_i_linear, fit_phi_i, RheologySeries};
use identify::IdentifyError;

const TRUTH: MuILaw = MuILaw {
    mu_s: 0.38,
    mu_2: 0.64,
    i0: 0.279,
};

/// 25 inertial numbers log-spaced over [10⁻³, 1], μ with N(0, 0.005²) noise.
fn series(seed: u64, noise: f64) -> RheologySeries {
    let i: Vec<f64> = (0..25)
        .map(|k| 10f64.powf(-3.0 + 3.0 * k as f64 / 24.0))
        .collect();
    let e = gaussian(seed, i.len(), noise);
    RheologySeries {
        mu: Some(i.iter().zip(&e).map(|(i, e)| TRUTH.mu(*i) + e).collect()),
        phi: Some(
            i.iter()
                .zip(gaussian(seed + 77, i.len(), 0.002))
                .map(|(i, e)| 0.82 - (0.82 - 0.55) * i + e)
                .collect(),
        ),
        pressure_pa: Some(vec![1000.0; i.len()]),
        inertial_number: i,
        ..Default::default()
    }
}

#[test]
fn recovers_mu_s_mu_2_i0_within_intervals() {
    let fit = fit_mu_i(&series(1, 0.005), &FitOptions::default()).unwrap();
    let r = &fit.report;
    let names: Vec<&str> = r.parameters.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["mu_s", "mu_2", "I_0"]);
    // One draw: within 3 standard errors (the 95 % coverage is tested over 100 draws below).
    for (p, truth) in r.parameters.iter().zip([0.38, 0.64, 0.279]) {
        assert!((p.value - truth).abs() < 3.0 * p.std_error, "{p:?}");
        assert!(p.std_error < 0.1 * truth, "{p:?}");
    }
    assert!(fit.law.mu_s < fit.law.mu_2);
    // μ₂ = μ_s + Δμ: its variance is var μ_s + var Δμ + 2 cov, so μ_s and μ₂ correlate.
    assert!(r.correlation[0][1].abs() <= 1.0);
    assert_eq!(r.validity[0].variable, "I");
    assert!((r.validity[0].min - 1e-3).abs() < 1e-15 && (r.validity[0].max - 1.0).abs() < 1e-12);
    assert_eq!(r.validity[1].variable, "P");
    // Noise-free data are recovered to solver precision.
    let exact = fit_mu_i(&series(1, 0.0), &FitOptions::default()).unwrap();
    assert!((exact.law.mu_s - 0.38).abs() < 1e-8);
    assert!((exact.law.mu_2 - 0.64).abs() < 1e-8);
    assert!((exact.law.i0 - 0.279).abs() < 1e-7);
}

#[test]
fn ninety_five_percent_intervals_cover_the_truth_in_at_least_90_of_100_draws() {
    let mut covered = [0usize; 3];
    for seed in 0..100 {
        let fit = fit_mu_i(&series(100 + seed, 0.005), &FitOptions::default()).unwrap();
        for ((c, truth), p) in covered
            .iter_mut()
            .zip([0.38, 0.64, 0.279])
            .zip(&fit.report.parameters)
        {
            *c += p.covers(truth) as usize;
        }
    }
    eprintln!("coverage /100 of (mu_s, mu_2, I_0): {covered:?}");
    assert!(covered.iter().all(|&c| c >= 90), "{covered:?}");
}

#[test]
fn aic_prefers_mu_i_over_the_linear_form_on_curved_data() {
    let s = series(3, 0.005);
    let cmp = compare_mu_i_forms(&s, &FitOptions::default());
    assert_eq!(cmp.best(), Some("mu-i"));
    assert!(cmp.ranking[1].delta_aic > 10.0);
    let w: f64 = cmp.ranking.iter().map(|c| c.akaike_weight).sum();
    assert!((w - 1.0).abs() < 1e-12);
    let lin = fit_mu_i_linear(&s, &FitOptions::default()).unwrap();
    assert!(lin.report.r_squared < 0.99);
}

#[test]
fn phi_i_recovered() {
    let fit = fit_phi_i(&series(4, 0.005), &FitOptions::default()).unwrap();
    // generated as φ_max − (φ_max − φ(1)) I: φ_max = 0.82, a = 0.82 − 0.55
    for (p, truth) in fit.report.parameters.iter().zip([0.82, 0.82 - 0.55]) {
        assert!((p.value - truth).abs() < 3.0 * p.std_error, "{p:?}");
    }
    assert!((fit.law.phi(0.5) - (0.82 + 0.55) / 2.0).abs() < 0.01);
}

#[test]
fn seeded_bootstrap_is_reproducible_and_agrees_with_the_covariance() {
    let s = series(5, 0.005);
    let options = FitOptions {
        bootstrap: Some(BootstrapOptions {
            resamples: 200,
            seed: 42,
        }),
        ..Default::default()
    };
    let a = fit_mu_i(&s, &options).unwrap();
    let b = fit_mu_i(&s, &options).unwrap();
    let (ba, bb) = (a.report.bootstrap.unwrap(), b.report.bootstrap.unwrap());
    assert_eq!(ba, bb, "same seed, same numbers");
    assert!(ba.failed <= 10);
    // Bootstrap and linearised standard errors agree within a factor 2 for μ_s and μ₂.
    for j in 0..2 {
        let ratio = ba.std_error[j] / a.report.parameters[j].std_error;
        assert!(ratio > 0.5 && ratio < 2.0, "param {j}: ratio {ratio}");
    }
    // Percentile intervals bracket the estimate.
    for j in 0..3 {
        let v = a.report.parameters[j].value;
        assert!(ba.ci[j][0] < v && v < ba.ci[j][1]);
    }
}

/// The error of fitting μ(I) to exact points of [`TRUTH`] at `I = step, 2 step, …, 20 step`:
/// a scale the data do not resolve, on `side`.
fn unresolved_scale(step: f64, side: ScaleSide) -> (RheologySeries, IdentifyError) {
    let i: Vec<f64> = (1..=20).map(|k| step * k as f64).collect();
    let s = RheologySeries {
        mu: Some(i.iter().map(|i| TRUTH.mu(*i)).collect()),
        inertial_number: i,
        ..Default::default()
    };
    let err = fit_mu_i(&s, &FitOptions::default()).unwrap_err();
    assert!(
        matches!(&err, IdentifyError::ScaleNotResolved { side: sd, .. } if *sd == side),
        "{err}"
    );
    (s, err)
}

#[test]
fn i_range_far_below_i0_is_not_identifiable() {
    // I ≤ 10⁻²: μ ≈ μ_s + (μ₂ − μ_s) I/I₀, only the slope is seen.
    let (s, err) = unresolved_scale(5e-4, ScaleSide::AboveData);
    // The linear form is what these data support, and the refusal offers it.
    assert!(fit_mu_i_linear(&s, &FitOptions::default()).is_ok());
    assert_eq!(err.suggestion(), Some("use mu-i-linear"));
    assert!(err.to_string().ends_with("; use mu-i-linear"), "{err}");
}

#[test]
fn i_range_far_above_i0_is_not_identifiable() {
    unresolved_scale(5.0, ScaleSide::BelowData);
}

#[test]
fn degenerate_series_give_typed_errors() {
    let good = series(6, 0.005);
    let o = FitOptions::default();

    let mut s = good.clone();
    s.inertial_number[3] = 0.0;
    assert!(matches!(
        fit_mu_i(&s, &o).unwrap_err(),
        IdentifyError::OutOfDomain { index: 3, .. }
    ));

    let mut s = good.clone();
    s.pressure_pa.as_mut().unwrap()[1] = -5.0;
    assert!(matches!(
        fit_mu_i(&s, &o).unwrap_err(),
        IdentifyError::NegativePressure { index: 1, .. }
    ));

    let mut s = good.clone();
    s.mu = Some(vec![0.5; 25]);
    assert!(matches!(
        fit_mu_i(&s, &o).unwrap_err(),
        IdentifyError::ZeroVariance { .. }
    ));

    let mut s = good.clone();
    s.mu.as_mut().unwrap()[7] = f64::INFINITY;
    assert!(matches!(
        fit_mu_i(&s, &o).unwrap_err(),
        IdentifyError::NonFinite { index: 7, .. }
    ));

    let s = RheologySeries {
        inertial_number: vec![0.01, 0.1, 0.3, 1.0],
        mu: Some(vec![0.4, 0.45, 0.5, 0.55]),
        ..Default::default()
    };
    assert!(matches!(
        fit_mu_i(&s, &o).unwrap_err(),
        IdentifyError::TooFewPoints {
            needed: 5,
            got: 4,
            ..
        }
    ));

    // φ that grows with I: its slope a below 0, refused by its interval.
    let mut s = good.clone();
    s.phi = Some(s.inertial_number.iter().map(|i| 0.6 + 0.1 * i).collect());
    assert!(matches!(
        fit_phi_i(&s, &o).unwrap_err(),
        IdentifyError::IntervalCrossesBound { .. }
    ));
}

/// Standard errors weigh the points: on the exact line μ = 0.3 + 0.9 I at eight points, one
/// point moved up by 0.2 with a standard error 10⁶ times the others' leaves the weighted fit
/// on the line (parameters to 10⁻⁹), while the unweighted fit is pulled off it by more than
/// 10⁻²; a standard error that is zero is refused with the point it names.
#[test]
fn standard_errors_weigh_the_points() {
    let i: Vec<f64> = (0..8).map(|k| 0.01 + 0.04 * k as f64).collect();
    let mut mu: Vec<f64> = i.iter().map(|i| 0.3 + 0.9 * i).collect();
    // A little exact-zero-mean scatter, so that the residual variance is not zero.
    for (k, m) in mu.iter_mut().enumerate() {
        *m += if k % 2 == 0 { 1e-12 } else { -1e-12 };
    }
    mu[5] += 0.2;
    let mut se = vec![1e-3; i.len()];
    se[5] = 1e3;
    let base = RheologySeries {
        inertial_number: i,
        mu: Some(mu),
        ..Default::default()
    };
    let weighted = RheologySeries {
        mu_std_error: Some(se.clone()),
        ..base.clone()
    };
    let opts = FitOptions::default();
    let w = fit_mu_i_linear(&weighted, &opts).unwrap();
    let (mu_s, b) = (w.law.mu_s, w.law.slope);
    assert!(
        (mu_s - 0.3).abs() < 1e-9 && (b - 0.9).abs() < 1e-9,
        "{mu_s} {b}"
    );
    match fit_mu_i_linear(&base, &opts) {
        Ok(u) => assert!(
            (u.law.mu_s - 0.3).abs() > 1e-2 || (u.law.slope - 0.9).abs() > 1e-2,
            "the unweighted fit should feel the moved point: {} {}",
            u.law.mu_s,
            u.law.slope
        ),
        Err(e) => assert!(e.is_refusal(), "{e}"),
    }
    se[2] = 0.0;
    let bad = RheologySeries {
        mu_std_error: Some(se),
        ..base
    };
    match fit_mu_i_linear(&bad, &opts) {
        Err(IdentifyError::OutOfDomain { index, .. }) => assert_eq!(index, 2),
        other => panic!("expected the zero standard error refused, got {other:?}"),
    }
}
