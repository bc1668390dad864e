//! Wall friction laws (model choice by AIC) and the boundary-layer thickness.

mod common;

use common::gaussian;
use identify::fit::FitOptions;
use identify::laws::{VelocityBoundaryLayer, WallFrictionLaw};
use identify::wall_law::{
    fit_boundary_layer, fit_wall_law, select_wall_law, VelocityProfile, WallLawForm,
    WallLawSelection, WallSlipSeries,
};
use identify::IdentifyError;

const D: f64 = 0.003; // grain diameter (m)

/// 40 slip velocities with V = V_s/√(g d) log-spaced over [0.01, 5], μ_eff from `law` plus noise.
fn series(law: &WallFrictionLaw, seed: u64, noise: f64) -> WallSlipSeries {
    let scale = (9.81 * D).sqrt();
    let v: Vec<f64> = (0..40)
        .map(|k| 10f64.powf(-2.0 + (5f64.log10() + 2.0) * k as f64 / 39.0))
        .collect();
    let e = gaussian(seed, v.len(), noise);
    WallSlipSeries::new(
        v.iter().map(|v| v * scale).collect(),
        v.iter().zip(&e).map(|(v, e)| law.mu_eff(*v) + e).collect(),
        D,
    )
}

/// Selects a law on `series(truth, seed, noise)` and asserts that `form` wins, with every
/// parameter within 3 standard errors of `expected`; returns the selection for further checks.
fn selects(
    truth: &WallFrictionLaw,
    seed: u64,
    noise: f64,
    form: WallLawForm,
    expected: &[f64],
) -> WallLawSelection {
    let sel = select_wall_law(&series(truth, seed, noise), &FitOptions::default()).unwrap();
    assert_eq!(sel.best().form, form, "{:?}", sel.comparison);
    let params = &sel.best().report.parameters;
    assert_eq!(params.len(), expected.len());
    for (p, t) in params.iter().zip(expected) {
        assert!((p.value - t).abs() < 3.0 * p.std_error, "{p:?}");
    }
    sel
}

#[test]
fn exponential_data_select_the_exponential_law() {
    let truth = WallFrictionLaw::Exponential {
        mu_0: 0.15,
        mu_inf: 0.45,
        v_star: 0.5,
    };
    let sel = selects(
        &truth,
        1,
        0.003,
        WallLawForm::Exponential,
        &[0.15, 0.45, 0.5],
    );
    assert_eq!(sel.comparison.best(), Some("wall-law-exponential"));
    assert_eq!(sel.comparison.ranking[0].delta_aic, 0.0);
    assert!(
        sel.comparison.ranking[1].delta_aic > 4.0,
        "{:?}",
        sel.comparison
    );
    let w: f64 = sel.comparison.ranking.iter().map(|c| c.akaike_weight).sum();
    assert!((w - 1.0).abs() < 1e-12);
    assert_eq!(sel.best().report.validity[0].variable, "V");
}

#[test]
fn hyperbolic_data_select_the_hyperbolic_law() {
    let truth = WallFrictionLaw::Hyperbolic {
        mu_0: 0.1,
        mu_inf: 0.5,
        v_star: 0.3,
    };
    selects(&truth, 2, 0.003, WallLawForm::Hyperbolic, &[0.1, 0.5, 0.3]);
}

#[test]
fn velocity_scale_outside_the_data_is_not_identifiable() {
    let truth = WallFrictionLaw::Exponential {
        mu_0: 0.1,
        mu_inf: 0.4,
        v_star: 200.0,
    };
    // V ∈ [0.01, 5] ≪ V* = 200: the data see only the initial slope.
    let err = fit_wall_law(
        &series(&truth, 3, 0.0),
        WallLawForm::Exponential,
        &FitOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(&err, IdentifyError::ScaleNotResolved { parameter, .. } if parameter == "V_star"),
        "{err}"
    );
}

#[test]
fn degenerate_wall_series() {
    let truth = WallFrictionLaw::Exponential {
        mu_0: 0.15,
        mu_inf: 0.45,
        v_star: 0.5,
    };
    let good = series(&truth, 4, 0.003);
    let o = FitOptions::default();
    let mut s = good.clone();
    s.slip_velocity_m_s[0] = -0.1;
    assert!(matches!(
        select_wall_law(&s, &o).unwrap_err(),
        IdentifyError::OutOfDomain { index: 0, .. }
    ));
    let mut s = good.clone();
    s.mu_eff = vec![0.3; 40];
    assert!(matches!(
        select_wall_law(&s, &o).unwrap_err(),
        IdentifyError::ZeroVariance { .. }
    ));
    let mut s = good.clone();
    s.grain_diameter_m = 0.0;
    assert!(matches!(
        select_wall_law(&s, &o).unwrap_err(),
        IdentifyError::InvalidSetup { .. }
    ));
    let mut s = good;
    s.slip_velocity_m_s.truncate(4);
    s.mu_eff.truncate(4);
    assert!(matches!(
        select_wall_law(&s, &o).unwrap_err(),
        IdentifyError::TooFewPoints {
            needed: 5,
            got: 4,
            ..
        }
    ));
}

#[test]
fn boundary_layer_thickness_in_grain_diameters() {
    let truth = VelocityBoundaryLayer {
        u_bulk: 0.2,
        u_slip: 0.05,
        delta_m: 3.0 * D,
    };
    let y: Vec<f64> = (0..30).map(|k| 0.5 * D * k as f64).collect();
    let e = gaussian(9, y.len(), 0.002);
    let profile = VelocityProfile {
        velocity_m_s: y
            .iter()
            .zip(&e)
            .map(|(y, e)| truth.velocity(*y) + e)
            .collect(),
        distance_m: y,
        grain_diameter_m: D,
    };
    let fit = fit_boundary_layer(&profile, &FitOptions::default()).unwrap();
    let t = &fit.thickness_diameters;
    assert!((t.value - 3.0).abs() < 3.0 * t.std_error, "{t:?}");
    assert!(t.std_error < 0.3);
    assert!((fit.thickness_m.value / D - t.value).abs() < 1e-12);
    assert!((fit.law.u_slip - 0.05).abs() < 0.01);
}

/// μ_eff falling like `0.45 − 0.005 ln V` over V ∈ [0.01, 10] (12 points, ±0.001 alternating):
/// the power law reaches it only as `n → 0`, `μ_0 → 10`, `k → −10`, with standard errors of
/// hundreds and intervals spanning zero. Without the identifiability check it was returned
/// (and won the AIC ranking) with every interval spanning zero.
fn log_falling() -> WallSlipSeries {
    let scale = (9.81 * D).sqrt();
    let v: Vec<f64> = (0..12)
        .map(|k| 10f64.powf(-2.0 + 3.0 * k as f64 / 11.0))
        .collect();
    let wiggle = |k: usize| if k.is_multiple_of(2) { 0.001 } else { -0.001 };
    WallSlipSeries::new(
        v.iter().map(|v| v * scale).collect(),
        v.iter()
            .enumerate()
            .map(|(k, v)| 0.45 - 0.005 * v.ln() + wiggle(k))
            .collect(),
        D,
    )
}

#[test]
fn a_power_law_with_unresolved_exponent_is_not_identifiable() {
    let o = FitOptions::default();
    let err = fit_wall_law(&log_falling(), WallLawForm::PowerLaw, &o).unwrap_err();
    let IdentifyError::ParameterNotIdentified {
        law,
        name,
        value,
        std_error,
        ci_low,
        ci_high,
        ..
    } = &err
    else {
        panic!("expected ParameterNotIdentified, got {err:?}");
    };
    assert_eq!(law, "wall-law-power");
    assert!(["mu_0", "k", "n"].contains(&name.as_str()), "{name}");
    // The criterion: standard error above the magnitude, interval across zero.
    assert!(
        *std_error > value.abs() && *ci_low < 0.0 && *ci_high > 0.0,
        "{err}"
    );
    let m = err.to_string();
    assert!(m.contains("not identifiable") && !m.contains('\n'), "{m}");
    // The selection keeps the identified saturating forms and lists the power law as failed.
    let sel = select_wall_law(&log_falling(), &o).unwrap();
    assert_ne!(sel.best().form, WallLawForm::PowerLaw);
    assert!(
        sel.comparison
            .failed
            .iter()
            .any(|(f, why)| f == "wall-law-power" && why.contains("not identifiable")),
        "{:?}",
        sel.comparison
    );
    for f in &sel.fits {
        let v_star = f.report.parameter("V_star").unwrap();
        assert!(v_star.std_error < v_star.value, "{v_star:?}");
    }
}

#[test]
fn a_true_power_law_is_identified() {
    let truth = WallFrictionLaw::PowerLaw {
        mu_0: 0.2,
        k: 0.1,
        n: 0.5,
    };
    let sel = selects(&truth, 5, 0.002, WallLawForm::PowerLaw, &[0.2, 0.1, 0.5]);
    for p in &sel.best().report.parameters {
        assert!(p.std_error < 0.1 * p.value, "{p:?}");
    }
}

/// μ_eff scattered around 0.44 with a slight fall: the exponential's `V*` lies below the data
/// (so do the others' scales, or their parameters are not determined): no form is identified,
/// the selection is an error, a refusal with its reason.
#[test]
fn scattered_friction_without_velocity_dependence_is_not_identifiable() {
    let scale = (9.81 * 0.002f64).sqrt();
    let v = [0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0];
    let series = WallSlipSeries::new(
        v.to_vec(),
        vec![0.47, 0.44, 0.45, 0.43, 0.44, 0.42, 0.43],
        0.002,
    );
    assert!((series.normalised_velocity()[0] - 0.01 / scale).abs() < 1e-15);
    let err = select_wall_law(&series, &FitOptions::default()).unwrap_err();
    assert!(
        matches!(&err, IdentifyError::ScaleNotResolved { parameter, .. } if parameter == "V_star"),
        "{err}"
    );
    assert!(err.is_refusal());
}
