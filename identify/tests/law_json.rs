//! Calibrated-law JSON: round trip, evaluation after loading, schema checks.

mod common;

use common::{janssen_profile, janssen_truth};
use identify::fit::FitOptions;
use identify::janssen::{fit_janssen, JanssenOptions};
use identify::law::{CalibratedLaw, Law, Provenance, SCHEMA_VERSION};
use identify::mohr_coulomb::{fit_mohr_coulomb, YieldData};
use identify::mu_i::{fit_mu_i, RheologySeries};
use identify::IdentifyError;

fn janssen_law() -> (CalibratedLaw, identify::janssen::JanssenFit) {
    let (truth, setup) = janssen_truth();
    let fit = fit_janssen(
        &janssen_profile(&truth, 21, false),
        &setup,
        &JanssenOptions::default(),
    )
    .unwrap();
    (
        CalibratedLaw::from_janssen(&fit, Provenance::new("janssen", Some(7))),
        fit,
    )
}

#[test]
fn janssen_law_round_trips_through_json_and_evaluates() {
    let (law, fit) = janssen_law();
    assert_eq!(law.schema_version, SCHEMA_VERSION);
    assert_eq!(law.law, "janssen");
    assert!(law.formula.contains("exp(-2*K*mu_w*z/W)"));
    assert_eq!(law.provenance.seed, Some(7));
    assert_eq!(law.provenance.grainlaw_version, env!("CARGO_PKG_VERSION"));
    let text = law.to_json_string().unwrap();
    let back = CalibratedLaw::from_json_str(&text).unwrap();
    assert_eq!(back, law);
    for z in [0.0, 0.05, 0.2, 1.0] {
        let v = back.evaluate(z).unwrap();
        assert!((v - fit.law.sigma_v(z)).abs() <= 1e-12 * fit.law.sigma_v(z).max(1.0));
    }
    assert!(back.in_validity_range(0.1) && !back.in_validity_range(0.5));
    let k = back.parameters.iter().find(|p| p.name == "K").unwrap();
    assert_eq!(k.ci_low, fit.k.ci_low);
    match back.to_law().unwrap() {
        Law::Janssen(j) => assert_eq!(j.width_m, 0.03),
        other => panic!("{other:?}"),
    }
}

#[test]
fn save_and_load_through_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("law.json");
    let i: Vec<f64> = (0..20)
        .map(|k| 10f64.powf(-3.0 + 3.0 * k as f64 / 19.0))
        .collect();
    let truth = identify::laws::MuILaw {
        mu_s: 0.38,
        mu_2: 0.64,
        i0: 0.279,
    };
    let series = RheologySeries {
        mu: Some(
            i.iter()
                .zip(common::gaussian(3, 20, 0.004))
                .map(|(i, e)| truth.mu(*i) + e)
                .collect(),
        ),
        inertial_number: i,
        ..Default::default()
    };
    let fit = fit_mu_i(&series, &FitOptions::default()).unwrap();
    let law = CalibratedLaw::from_mu_i(&fit, Provenance::new("shear-cell", Some(1)));
    law.save(&path).unwrap();
    let back = CalibratedLaw::load(&path).unwrap();
    assert_eq!(back, law);
    assert!((back.evaluate(0.1).unwrap() - fit.law.mu(0.1)).abs() < 1e-15);

    let mc = fit_mohr_coulomb(
        &YieldData::Circles {
            p_pa: vec![1000.0, 2000.0, 3000.0, 4000.0, 5000.0],
            q_pa: vec![600.0, 1100.0, 1600.0, 2100.0, 2600.0],
        },
        0.95,
    )
    .unwrap();
    let law = CalibratedLaw::from_mohr_coulomb(&mc, Provenance::new("biaxial", None));
    let back = CalibratedLaw::from_json_str(&law.to_json_string().unwrap()).unwrap();
    // sin φ = 0.5 → τ(σ) = c + σ tan 30°, c = 100/cos 30°.
    let c = 100.0 / 30f64.to_radians().cos();
    assert!(
        (back.evaluate(1000.0).unwrap() - (c + 1000.0 * 30f64.to_radians().tan())).abs() < 1e-4
    );
}

#[test]
fn schema_and_content_errors() {
    let (law, _) = janssen_law();
    let mut v: serde_json::Value = serde_json::from_str(&law.to_json_string().unwrap()).unwrap();
    v["schema_version"] = serde_json::json!(SCHEMA_VERSION + 1);
    assert!(matches!(
        CalibratedLaw::from_json_str(&v.to_string()).unwrap_err(),
        IdentifyError::UnsupportedSchema { .. }
    ));
    let mut v: serde_json::Value = serde_json::from_str(&law.to_json_string().unwrap()).unwrap();
    v["parameters"]
        .as_array_mut()
        .unwrap()
        .retain(|p| p["name"] != "mu_w");
    let err = CalibratedLaw::from_json_str(&v.to_string()).unwrap_err();
    assert!(err.to_string().contains("mu_w"), "{err}");
    let mut v: serde_json::Value = serde_json::from_str(&law.to_json_string().unwrap()).unwrap();
    v["law"] = serde_json::json!("no-such-law");
    assert!(matches!(
        CalibratedLaw::from_json_str(&v.to_string()).unwrap_err(),
        IdentifyError::LawFormat { .. }
    ));
    assert!(matches!(
        CalibratedLaw::from_json_str("{not json").unwrap_err(),
        IdentifyError::LawFormat { .. }
    ));
    assert!(matches!(
        CalibratedLaw::load(std::path::Path::new("/nonexistent/law.json")).unwrap_err(),
        IdentifyError::Io { .. }
    ));
}
