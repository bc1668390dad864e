//! Janssen fits on synthetic columns: recovery, interval coverage, depth window, bounds and
//! degenerate inputs.

mod common;

use common::{gaussian, janssen_profile, janssen_truth};
use identify::error::BoundSide;
use identify::janssen::{
    fit_janssen, fit_janssen_full_mobilisation, fit_janssen_k_mu, JanssenOptions, JanssenProfile,
};
use identify::IdentifyError;

#[test]
fn joint_fit_recovers_k_and_mu_w_within_intervals() {
    let (law, setup) = janssen_truth();
    let fit = fit_janssen(
        &janssen_profile(&law, 7, false),
        &setup,
        &JanssenOptions::default(),
    )
    .unwrap();
    assert!(fit.k.covers(0.6), "K {:?}", fit.k);
    assert!(fit.mu_w.covers(0.2), "mu_w {:?}", fit.mu_w);
    assert!(fit.k_mu_w.covers(0.12));
    // Precision of this design: K to ~2 %, μ_w to ~3 % (standard errors).
    assert!(fit.k.std_error < 0.02 * 0.6 && fit.mu_w.std_error < 0.03 * 0.2);
    assert!(
        (fit.saturation_length_m.value - 0.125).abs() < 3.0 * fit.saturation_length_m.std_error
    );
    assert!((fit.mobilisation.value - fit.mu_w.value / 0.25).abs() < 1e-14);
    assert!(fit.report.r_squared > 0.99);
    assert_eq!(fit.depth_range_m, [0.01, 0.3]);
    assert_eq!(fit.points_used, 30);
    // Residuals by depth, with the hydrostatic line ρ_b g z.
    let row = &fit.residuals_by_depth[9];
    assert!((row.z_m - 0.1).abs() < 1e-15);
    assert!((row.hydrostatic_pa - 1600.0 * 9.81 * 0.1).abs() < 1e-9);
    assert!(row.sigma_h_pa.is_some() && row.tau_w_pa.is_none());
    // Noise levels are estimated per group: weights ≈ ratio of noise σ (30 Pa / 15 Pa).
    let ratio = fit.report.groups[1].weight / fit.report.groups[0].weight;
    assert!(ratio > 1.3 && ratio < 3.0, "weight ratio {ratio}");
}

#[test]
fn joint_fit_with_wall_shear_group() {
    let (law, setup) = janssen_truth();
    let fit = fit_janssen(
        &janssen_profile(&law, 11, true),
        &setup,
        &JanssenOptions::default(),
    )
    .unwrap();
    assert_eq!(fit.report.groups.len(), 3);
    assert!(fit.k.covers(0.6) && fit.mu_w.covers(0.2));
    assert!(fit.residuals_by_depth[0].tau_w_pa.is_some());
}

#[test]
fn ninety_five_percent_intervals_cover_the_truth_in_at_least_90_of_100_draws() {
    let (law, setup) = janssen_truth();
    let (mut k, mut mu, mut kmu, mut kmu1) = (0, 0, 0, 0);
    for seed in 0..100 {
        let profile = janssen_profile(&law, 1000 + seed, false);
        let fit = fit_janssen(&profile, &setup, &JanssenOptions::default()).unwrap();
        k += fit.k.covers(0.6) as usize;
        mu += fit.mu_w.covers(0.2) as usize;
        kmu += fit.k_mu_w.covers(0.12) as usize;
        let one = fit_janssen_k_mu(&profile, &setup, &JanssenOptions::default()).unwrap();
        kmu1 += one.k_mu_w.covers(0.12) as usize;
    }
    eprintln!(
        "coverage /100: K {k}, mu_w {mu}, K mu_w (joint) {kmu}, K mu_w (sigma_v only) {kmu1}"
    );
    assert!(
        k >= 90 && mu >= 90 && kmu >= 90 && kmu1 >= 90,
        "{k} {mu} {kmu} {kmu1}"
    );
}

#[test]
fn one_parameter_fit_from_sigma_v_alone() {
    let (law, setup) = janssen_truth();
    let mut profile = janssen_profile(&law, 3, false);
    profile.sigma_h_pa = None;
    let fit = fit_janssen_k_mu(&profile, &setup, &JanssenOptions::default()).unwrap();
    assert!(fit.k_mu_w.covers(0.12));
    assert!(fit.k_mu_w.std_error < 0.05 * 0.12);
    assert!((fit.law.saturation_length() - fit.saturation_length_m.value).abs() < 1e-12);
    // Without σ_h the joint fit refuses: only K μ_w is identified.
    let err = fit_janssen(&profile, &setup, &JanssenOptions::default()).unwrap_err();
    assert!(
        matches!(err, IdentifyError::NotIdentifiable { .. }),
        "{err}"
    );
}

#[test]
fn depth_window_skips_the_top_rebound_zone() {
    let (law, setup) = janssen_truth();
    let mut profile = janssen_profile(&law, 5, false);
    // A rebound zone: the top 5 cm carry 40 % more vertical and wall stress than Janssen.
    for i in 0..5 {
        profile.sigma_v_pa[i] *= 1.4;
        if let Some(h) = profile.sigma_h_pa.as_mut() {
            h[i] *= 1.4;
        }
    }
    let options = JanssenOptions {
        depth_window: Some((0.055, 1.0)),
        ..Default::default()
    };
    let fit = fit_janssen(&profile, &setup, &options).unwrap();
    assert_eq!(fit.points_used, 25);
    assert_eq!(fit.points_total, 30);
    assert!((fit.depth_range_m[0] - 0.06).abs() < 1e-12);
    assert!(fit.k.covers(0.6) && fit.mu_w.covers(0.2));
    // An empty window is an error.
    let options = JanssenOptions {
        depth_window: Some((0.5, 1.0)),
        ..Default::default()
    };
    assert!(matches!(
        fit_janssen(&profile, &setup, &options).unwrap_err(),
        IdentifyError::EmptyDepthWindow { kept: 0, .. }
    ));
}

#[test]
fn mu_w_beyond_wall_friction_is_a_bound_error_and_full_mobilisation_is_the_fallback() {
    let (mut law, setup) = janssen_truth();
    law.mu_w = 0.3; // more than μ_wall = 0.25: the data push μ_w onto its bound.
    let profile = janssen_profile(&law, 9, false);
    match fit_janssen(&profile, &setup, &JanssenOptions::default()).unwrap_err() {
        IdentifyError::ParameterAtBound {
            name, side, bound, ..
        } => {
            assert_eq!(name, "mu_w");
            assert_eq!(side, BoundSide::Upper);
            assert_eq!(bound, 0.25);
        }
        other => panic!("expected ParameterAtBound, got {other}"),
    }
    // The fallback, on a column whose walls are fully mobilised (μ_w = μ_wall = 0.25).
    law.mu_w = 0.25;
    let profile = janssen_profile(&law, 9, false);
    let fit = fit_janssen_full_mobilisation(&profile, &setup, &JanssenOptions::default()).unwrap();
    assert!(fit.mu_w.at_bound && fit.mu_w.value == 0.25 && fit.mobilisation.value == 1.0);
    assert_eq!(fit.report.parameters.len(), 1);
    assert!(
        (fit.k.value - 0.6).abs() < 4.0 * fit.k.std_error,
        "{:?}",
        fit.k
    );
    assert!(fit.k.std_error < 0.01 * 0.6);
    // Its interval covers the truth in ≥ 90 of 100 seeded draws.
    let covered = (0..100)
        .filter(|seed| {
            let p = janssen_profile(&law, 5000 + seed, false);
            fit_janssen_full_mobilisation(&p, &setup, &JanssenOptions::default())
                .unwrap()
                .k
                .covers(0.6)
        })
        .count();
    eprintln!("coverage /100 of K under full mobilisation: {covered}");
    assert!(covered >= 90, "{covered}");
}

#[test]
fn super_hydrostatic_profile_puts_k_mu_at_its_bound() {
    let (_, setup) = janssen_truth();
    let z: Vec<f64> = (1..=20).map(|i| 0.01 * i as f64).collect();
    let noise = gaussian(4, z.len(), 5.0);
    let profile = JanssenProfile {
        sigma_v_pa: z
            .iter()
            .zip(&noise)
            .map(|(z, e)| 1.2 * 1600.0 * 9.81 * z + e)
            .collect(),
        z_m: z,
        sigma_h_pa: None,
        tau_w_pa: None,
    };
    let err = fit_janssen_k_mu(&profile, &setup, &JanssenOptions::default()).unwrap_err();
    assert!(
        matches!(&err, IdentifyError::ParameterAtBound { name, side: BoundSide::Lower, .. } if name == "K_mu_w"),
        "{err}"
    );
}

#[test]
fn degenerate_profiles_give_typed_errors() {
    let (law, setup) = janssen_truth();
    let good = janssen_profile(&law, 1, false);
    let opts = JanssenOptions::default();

    let mut p = good.clone();
    p.z_m.truncate(3);
    p.sigma_v_pa.truncate(3);
    p.sigma_h_pa.as_mut().unwrap().truncate(3);
    assert!(matches!(
        fit_janssen(&p, &setup, &opts).unwrap_err(),
        IdentifyError::TooFewPoints {
            needed: 4,
            got: 3,
            ..
        }
    ));

    let mut p = good.clone();
    p.sigma_v_pa[4] = f64::NAN;
    assert!(matches!(
        fit_janssen(&p, &setup, &opts).unwrap_err(),
        IdentifyError::NonFinite { index: 4, .. }
    ));

    let mut p = good.clone();
    p.sigma_h_pa.as_mut().unwrap()[2] = -10.0;
    assert!(matches!(
        fit_janssen(&p, &setup, &opts).unwrap_err(),
        IdentifyError::NegativePressure { index: 2, .. }
    ));

    let mut p = good.clone();
    p.z_m = vec![0.1; 30];
    assert!(matches!(
        fit_janssen(&p, &setup, &opts).unwrap_err(),
        IdentifyError::ZeroVariance { .. }
    ));

    let mut p = good.clone();
    p.sigma_v_pa.pop();
    assert!(matches!(
        fit_janssen(&p, &setup, &opts).unwrap_err(),
        IdentifyError::LengthMismatch { .. }
    ));

    let mut bad_setup = setup;
    bad_setup.width_m = -0.03;
    assert!(matches!(
        fit_janssen(&good, &bad_setup, &opts).unwrap_err(),
        IdentifyError::InvalidSetup { .. }
    ));
}

#[test]
fn summary_entries_carry_the_cli_keys() {
    let (law, setup) = janssen_truth();
    let fit = fit_janssen(
        &janssen_profile(&law, 2, false),
        &setup,
        &JanssenOptions::default(),
    )
    .unwrap();
    let entries = fit.summary_entries();
    let get = |k: &str| entries.iter().find(|(key, _)| key == k).map(|(_, v)| *v);
    for key in ["janssen_K", "janssen_mu_w", "janssen_K_mu_w"] {
        let v = get(key).unwrap();
        let lo = get(&format!("{key}_ci_low")).unwrap();
        let hi = get(&format!("{key}_ci_high")).unwrap();
        assert!(lo < v && v < hi, "{key}");
    }
    assert_eq!(get("janssen_K"), Some(fit.k.value));
}
