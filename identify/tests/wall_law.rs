//! Wall friction laws (model choice by AIC) and the boundary-layer thickness.

mod common;

use common::gaussian;
use identify::fit::FitOptions;
use identify::laws::{VelocityBoundaryLayer, WallFrictionLaw};
use identify::wall_law::{
    fit_boundary_layer, fit_wall_law, select_wall_law, VelocityProfile, WallLawForm, WallSlipSeries,
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

#[test]
fn exponential_data_select_the_exponential_law() {
    let truth = WallFrictionLaw::Exponential {
        mu_0: 0.15,
        mu_inf: 0.45,
        v_star: 0.5,
    };
    let sel = select_wall_law(&series(&truth, 1, 0.003), &FitOptions::default()).unwrap();
    assert_eq!(sel.best().form, WallLawForm::Exponential);
    assert_eq!(sel.comparison.best(), Some("wall-law-exponential"));
    assert_eq!(sel.comparison.ranking[0].delta_aic, 0.0);
    assert!(
        sel.comparison.ranking[1].delta_aic > 4.0,
        "{:?}",
        sel.comparison
    );
    let w: f64 = sel.comparison.ranking.iter().map(|c| c.akaike_weight).sum();
    assert!((w - 1.0).abs() < 1e-12);
    for (p, t) in sel.best().report.parameters.iter().zip([0.15, 0.45, 0.5]) {
        assert!((p.value - t).abs() < 3.0 * p.std_error, "{p:?}");
    }
    assert_eq!(sel.best().report.validity[0].variable, "V");
}

#[test]
fn hyperbolic_data_select_the_hyperbolic_law() {
    let truth = WallFrictionLaw::Hyperbolic {
        mu_0: 0.1,
        mu_inf: 0.5,
        v_star: 0.3,
    };
    let sel = select_wall_law(&series(&truth, 2, 0.003), &FitOptions::default()).unwrap();
    assert_eq!(
        sel.best().form,
        WallLawForm::Hyperbolic,
        "{:?}",
        sel.comparison
    );
    for (p, t) in sel.best().report.parameters.iter().zip([0.1, 0.5, 0.3]) {
        assert!((p.value - t).abs() < 3.0 * p.std_error, "{p:?}");
    }
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
