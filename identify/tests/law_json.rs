//! Calibrated-law JSON (schema 2): every law of the registry fitted, written, read back and
//! evaluated from its JSON (typed evaluation and the formula text) against the fitted function
//! to 1e-12; schema 1 still read; schema and content errors.

mod common;

use common::{gaussian, janssen_profile, janssen_truth};
use identify::fit::FitOptions;
use identify::janssen::{
    fit_janssen, fit_janssen_full_mobilisation, fit_janssen_k_mu, JanssenOptions,
};
use identify::law::{
    check_variable_names, CalibratedLaw, GrainScale, Law, Provenance, DIMENSION, REGISTRY,
    SCHEMA_VERSION,
};
use identify::laws::{MohrCoulombLaw, MuILaw, VelocityBoundaryLayer, WallFrictionLaw};
use identify::mohr_coulomb::{
    fit_mohr_coulomb, fit_mohr_coulomb_with, MohrCoulombOptions, YieldData,
};
use identify::mu_i::{fit_mu_i, fit_mu_i_linear, fit_phi_i, RheologySeries};
use identify::wall_law::{
    fit_boundary_layer, fit_wall_law, VelocityProfile, WallLawForm, WallSlipSeries,
};
use identify::IdentifyError;

const GRAIN: GrainScale = GrainScale {
    diameter_m: 0.002,
    density_kg_m3: 2500.0,
};

fn prov() -> Provenance {
    Provenance::new("test", Some(7))
}

/// 25 inertial numbers over [10⁻³, 1] with μ(I) and φ(I) plus noise.
fn rheology(seed: u64) -> RheologySeries {
    let truth = MuILaw {
        mu_s: 0.38,
        mu_2: 0.64,
        i0: 0.279,
    };
    let i: Vec<f64> = (0..25)
        .map(|k| 10f64.powf(-3.0 + 3.0 * k as f64 / 24.0))
        .collect();
    RheologySeries {
        mu: Some(
            i.iter()
                .zip(gaussian(seed, 25, 0.004))
                .map(|(i, e)| truth.mu(*i) + e)
                .collect(),
        ),
        phi: Some(
            i.iter()
                .zip(gaussian(seed + 1, 25, 0.002))
                .map(|(i, e)| 0.82 - 0.27 * i + e)
                .collect(),
        ),
        pressure_pa: None,
        inertial_number: i,
        ..Default::default()
    }
}

/// Linear μ(I) and φ(I) data over I ∈ [0.01, 0.1].
fn linear_rheology(seed: u64) -> RheologySeries {
    let i: Vec<f64> = (0..20).map(|k| 0.01 + 0.09 * k as f64 / 19.0).collect();
    RheologySeries {
        mu: Some(
            i.iter()
                .zip(gaussian(seed, 20, 0.003))
                .map(|(i, e)| 0.3 + 1.2 * i + e)
                .collect(),
        ),
        phi: Some(
            i.iter()
                .zip(gaussian(seed + 1, 20, 0.002))
                .map(|(i, e)| 0.8 - 0.5 * i + e)
                .collect(),
        ),
        pressure_pa: None,
        inertial_number: i,
        ..Default::default()
    }
}

fn wall_series(law: &WallFrictionLaw, seed: u64) -> WallSlipSeries {
    let d: f64 = 0.003;
    let scale = (9.81 * d).sqrt();
    let v: Vec<f64> = (0..40)
        .map(|k| 10f64.powf(-2.0 + (5f64.log10() + 2.0) * k as f64 / 39.0))
        .collect();
    WallSlipSeries::new(
        v.iter().map(|v| v * scale).collect(),
        v.iter()
            .zip(gaussian(seed, 40, 0.002))
            .map(|(v, e)| law.mu_eff(*v) + e)
            .collect(),
        d,
    )
}

/// A calibrated law, the fitted function and inputs to evaluate it at.
type Case = (CalibratedLaw, Box<dyn Fn(f64) -> f64>, Vec<f64>);

/// Every law of the registry, fitted.
fn every_law() -> Vec<Case> {
    let o = FitOptions::default();
    let mut out: Vec<Case> = Vec::new();
    let zs = vec![0.0, 0.01, 0.05, 0.2, 0.3];
    let (truth, setup) = janssen_truth();
    let profile = janssen_profile(&truth, 21, true);
    let jo = JanssenOptions::default();
    let j = fit_janssen(&profile, &setup, &jo).unwrap();
    let l = j.law;
    out.push((
        CalibratedLaw::from_janssen(&j, prov()),
        Box::new(move |z| l.sigma_v(z)),
        zs.clone(),
    ));
    let jf = fit_janssen_full_mobilisation(&profile, &setup, &jo).unwrap();
    let l = jf.law;
    out.push((
        CalibratedLaw::from_janssen(&jf, prov()),
        Box::new(move |z| l.sigma_v(z)),
        zs.clone(),
    ));
    let jk = fit_janssen_k_mu(&profile, &setup, &jo).unwrap();
    let l = jk.law;
    out.push((
        CalibratedLaw::from_janssen_k_mu(&jk, prov()),
        Box::new(move |z| l.sigma_v(z)),
        zs,
    ));
    let vs = vec![0.0, 0.01, 0.3, 1.0, 5.0];
    for (form, truth) in [
        (
            WallLawForm::Exponential,
            WallFrictionLaw::Exponential {
                mu_0: 0.15,
                mu_inf: 0.45,
                v_star: 0.5,
            },
        ),
        (
            WallLawForm::Hyperbolic,
            WallFrictionLaw::Hyperbolic {
                mu_0: 0.1,
                mu_inf: 0.5,
                v_star: 0.3,
            },
        ),
        (
            WallLawForm::PowerLaw,
            WallFrictionLaw::PowerLaw {
                mu_0: 0.2,
                k: 0.1,
                n: 0.5,
            },
        ),
    ] {
        let w = fit_wall_law(&wall_series(&truth, 3), form, &o).unwrap();
        let l = w.law;
        out.push((
            CalibratedLaw::from_wall_law(&w, 0.003, 9.81, None, prov()),
            Box::new(move |v| l.mu_eff(v)),
            vs.clone(),
        ));
    }
    let bl = VelocityBoundaryLayer {
        u_bulk: 0.2,
        u_slip: 0.05,
        delta_m: 0.009,
    };
    let y: Vec<f64> = (0..30).map(|k| 0.0015 * k as f64).collect();
    let profile = VelocityProfile {
        velocity_m_s: y
            .iter()
            .zip(gaussian(9, 30, 0.002))
            .map(|(y, e)| bl.velocity(*y) + e)
            .collect(),
        distance_m: y.clone(),
        grain_diameter_m: 0.003,
    };
    let b = fit_boundary_layer(&profile, &o).unwrap();
    let l = b.law;
    out.push((
        CalibratedLaw::from_boundary_layer(&b, 0.003, prov()),
        Box::new(move |y| l.velocity(y)),
        y,
    ));
    let is = vec![0.001, 0.01, 0.1, 0.5, 1.0];
    let m = fit_mu_i(&rheology(1), &o).unwrap();
    let l = m.law;
    out.push((
        CalibratedLaw::from_mu_i(&m, GRAIN, prov()),
        Box::new(move |i| l.mu(i)),
        is.clone(),
    ));
    let p = fit_phi_i(&rheology(1), &o).unwrap();
    let l = p.law;
    out.push((
        CalibratedLaw::from_phi_i(&p, GRAIN, prov()),
        Box::new(move |i| l.phi(i)),
        is.clone(),
    ));
    let ml = fit_mu_i_linear(&linear_rheology(2), &o).unwrap();
    let l = ml.law;
    out.push((
        CalibratedLaw::from_mu_i_linear(&ml, GRAIN, prov()),
        Box::new(move |i| l.mu(i)),
        is.clone(),
    ));
    let pl = fit_phi_i(&linear_rheology(2), &o).unwrap();
    let l = pl.law;
    out.push((
        CalibratedLaw::from_phi_i(&pl, GRAIN, prov()),
        Box::new(move |i| l.phi(i)),
        is,
    ));
    let mc_law = MohrCoulombLaw {
        friction_angle_rad: 30f64.to_radians(),
        cohesion_pa: 400.0,
    };
    let p: Vec<f64> = (1..=10).map(|k| 1000.0 * k as f64).collect();
    let data = YieldData::Circles {
        q_pa: p
            .iter()
            .zip(gaussian(4, 10, 20.0))
            .map(|(p, e)| mc_law.yield_q(*p) + e)
            .collect(),
        p_pa: p.clone(),
    };
    let sn = vec![0.0, 1000.0, 5000.0, 20000.0];
    let mc = fit_mohr_coulomb(&data, 0.95).unwrap();
    let l = mc.law;
    out.push((
        CalibratedLaw::from_mohr_coulomb(&mc, prov()),
        Box::new(move |s| l.shear_strength(s)),
        sn.clone(),
    ));
    let mc0 = fit_mohr_coulomb_with(&data, &MohrCoulombOptions::cohesionless()).unwrap();
    let l = mc0.law;
    out.push((
        CalibratedLaw::from_mohr_coulomb(&mc0, prov()),
        Box::new(move |s| l.shear_strength(s)),
        sn,
    ));
    let plateaus: Vec<identify::critical_state::PlateauMeasure> = [0.27, 0.28, 0.26]
        .iter()
        .map(|&s| identify::critical_state::PlateauMeasure {
            pressure_pa: 1000.0,
            sin_phi: s,
            sin_phi_std_error: 0.005,
            solid_fraction: 0.81,
            solid_fraction_std_error: 0.002,
            blocks: 8,
        })
        .collect();
    let cs = identify::critical_state::fit_critical_state(&plateaus, 0.95).unwrap();
    let l = cs.law;
    out.push((
        CalibratedLaw::from_critical_state(&cs, prov()),
        Box::new(move |p| l.q(p)),
        vec![100.0, 1000.0, 1e4],
    ));
    let psi: Vec<f64> = (0..10).map(|k| 0.02 * k as f64).collect();
    let sd = identify::critical_state::fit_stress_dilatancy(
        &identify::critical_state::StressDilatancyData {
            sin_phi: psi
                .iter()
                .zip(gaussian(5, 10, 0.005))
                .map(|(x, e)| 0.27 + 0.9 * x + e)
                .collect(),
            sin_psi: psi.clone(),
            sample: None,
        },
        &o,
    )
    .unwrap();
    let l = sd.law;
    out.push((
        CalibratedLaw::from_stress_dilatancy(&sd, prov()),
        Box::new(move |x| l.sin_phi(x)),
        psi,
    ));
    out
}

#[test]
fn every_law_evaluates_from_its_json_as_fitted() {
    let laws = every_law();
    let mut seen: Vec<&str> = laws.iter().map(|(l, _, _)| l.law.as_str()).collect();
    seen.sort();
    seen.dedup();
    let mut registry: Vec<&str> = REGISTRY.iter().map(|s| s.name).collect();
    registry.sort();
    assert_eq!(seen, registry, "every registry law is covered");
    for (law, f, xs) in &laws {
        assert_eq!(law.schema_version, SCHEMA_VERSION);
        assert_eq!(law.dimension, DIMENSION);
        let text = law.to_json_string().unwrap();
        let back = CalibratedLaw::from_json_str(&text).unwrap();
        assert_eq!(&back, law, "{}", law.law);
        let typed = back.evaluate(xs).unwrap();
        let formula = back.evaluate_formula(xs).unwrap();
        for ((x, a), b) in xs.iter().zip(&typed).zip(&formula) {
            let want = f(*x);
            let tol = 1e-12 * want.abs().max(1e-300);
            assert!((a - want).abs() <= tol, "{} at {x}: {a} vs {want}", law.law);
            assert!(
                (b - want).abs() <= tol.max(1e-15),
                "{} formula at {x}: {b} vs {want}",
                law.law
            );
        }
        // The covariance covers every parameter, in the registry's order.
        let cov = back.covariance.as_ref().unwrap();
        let names: Vec<&str> = back.parameters.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(cov.order, names, "{}", law.law);
        assert_eq!(cov.matrix.len(), names.len());
        for d in &back.derived {
            assert!(d.derived, "{}", d.name);
        }
        // Formula variables are exactly the input, parameter and constant names.
        let spec = identify::law::law_spec(&law.law).unwrap();
        check_variable_names(spec).unwrap();
        let consts: Vec<&str> = back.constants.iter().map(|c| c.name.as_str()).collect();
        let want: Vec<&str> = spec.constants.iter().map(|c| c.0).collect();
        assert_eq!(consts, want, "{}", law.law);
    }
}

#[test]
fn json_carries_constants_derived_angles_and_provenance() {
    let laws = every_law();
    let janssen = &laws[0].0;
    let v: serde_json::Value = serde_json::from_str(&janssen.to_json_string().unwrap()).unwrap();
    assert_eq!(v["schema_version"], 2);
    assert_eq!(
        v["expression"]["formula"],
        "rho_b*g*W/(2*K*mu_w)*(1 - exp(-2*K*mu_w*z/W))"
    );
    assert_eq!(v["expression"]["convention"], "grainlaw-expr-1");
    assert_eq!(v["dimension"], "2D, per unit thickness");
    let derived = v["derived"].as_array().unwrap();
    for name in ["K_mu_w", "saturation_length", "mobilisation"] {
        let d = derived.iter().find(|d| d["name"] == name).unwrap();
        assert_eq!(d["derived"], true);
    }
    assert!(v["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .all(|p| p["name"] != "K_mu_w"));
    assert_eq!(v["provenance"]["seed"], 7);
    assert!(v["provenance"]["overrides"].as_array().unwrap().is_empty());
    let mu_i = laws.iter().find(|(l, _, _)| l.law == "mu-i").unwrap();
    let v: serde_json::Value = serde_json::from_str(&mu_i.0.to_json_string().unwrap()).unwrap();
    let consts = v["constants"].as_array().unwrap();
    assert_eq!(consts[0]["name"], "d");
    assert_eq!(consts[0]["unit"], "m");
    assert_eq!(consts[1]["name"], "rho_s");
    assert_eq!(
        v["expression"]["where"][0]["formula"],
        "gamma_dot*d/sqrt(P/rho_s)"
    );
    let mc = laws
        .iter()
        .find(|(l, _, _)| l.law == "mohr-coulomb")
        .unwrap();
    let phi =
        mc.0.parameters
            .iter()
            .find(|p| p.name == "friction_angle")
            .unwrap();
    let deg = phi.deg.unwrap();
    assert!((deg.value - phi.value.to_degrees()).abs() < 1e-12);
    assert!((deg.ci_high - phi.ci_high.to_degrees()).abs() < 1e-12);
    assert!((deg.value - 30.0).abs() < 1.0);
    // The full covariance of (φ, c), with the correlation the intercept and slope share.
    let cov = mc.0.covariance.as_ref().unwrap();
    assert!(cov.matrix[0][1] != 0.0 && cov.matrix[0][1] == cov.matrix[1][0]);
    let p = Provenance::new("user-csv", None)
        .with_date_now()
        .with_input("data.csv", b"abc")
        .with_overrides(vec!["width_m=0.03".into()]);
    assert_eq!(p.date.as_ref().unwrap().len(), 20);
    assert_eq!(
        p.inputs[0].sha256,
        "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    );
}

/// A schema-1 file (as written before schema 2) is read, upgraded and evaluated.
#[test]
fn schema_1_is_still_read() {
    let v1 = r#"{
      "schema_version": 1,
      "law": "janssen",
      "formula": "sigma_v(z) = rho_b*g*W/(2*K*mu_w)*(1 - exp(-2*K*mu_w*z/W)); sigma_h = K*sigma_v; tau_w = mu_w*sigma_h",
      "input": {"name": "z", "unit": "m"},
      "output": {"name": "sigma_v", "unit": "Pa"},
      "parameters": [
        {"name": "K", "unit": "1", "value": 0.6, "std_error": 0.01, "ci_low": 0.58, "ci_high": 0.62, "at_bound": false},
        {"name": "mu_w", "unit": "1", "value": 0.2, "std_error": 0.01, "ci_low": 0.18, "ci_high": 0.22, "at_bound": false},
        {"name": "K_mu_w", "unit": "1", "value": 0.12, "std_error": 0.003, "ci_low": 0.114, "ci_high": 0.126, "at_bound": false}
      ],
      "constants": [{"name": "width", "unit": "m", "value": 0.03}, {"name": "bulk_density", "unit": "kg/m^3", "value": 1600.0},
                    {"name": "gravity", "unit": "m/s^2", "value": 9.81}, {"name": "wall_friction", "unit": "1", "value": 0.25}],
      "validity": [{"variable": "z", "unit": "m", "min": 0.01, "max": 0.3}],
      "fit": {"n": 60, "dof": 58, "r_squared": 0.998, "aic": 0.0, "bic": 0.0, "confidence": 0.95},
      "model_selection": null,
      "provenance": {"scenario": "janssen", "seed": 1, "grainlaw_version": "0.1.0", "source": null}
    }"#;
    let law = CalibratedLaw::from_json_str(v1).unwrap();
    assert_eq!(law.schema_version, 1);
    assert!(law.covariance.is_none());
    assert_eq!(law.derived[0].name, "K_mu_w");
    assert_eq!(law.constant("W").unwrap(), 0.03);
    let Law::Janssen(j) = law.to_law().unwrap() else {
        panic!("not Janssen")
    };
    let y = law.evaluate(&[0.1, 0.2]).unwrap();
    assert_eq!(y, vec![j.sigma_v(0.1), j.sigma_v(0.2)]);
    assert!(law.in_validity_range(0.1) && !law.in_validity_range(0.5));
}

#[test]
fn schema_and_content_errors() {
    let law = every_law().swap_remove(0).0;
    let json =
        || -> serde_json::Value { serde_json::from_str(&law.to_json_string().unwrap()).unwrap() };
    let mut v = json();
    v["schema_version"] = serde_json::json!(SCHEMA_VERSION + 1);
    assert!(matches!(
        CalibratedLaw::from_json_str(&v.to_string()).unwrap_err(),
        IdentifyError::UnsupportedSchema { .. }
    ));
    let mut v = json();
    v["parameters"]
        .as_array_mut()
        .unwrap()
        .retain(|p| p["name"] != "mu_w");
    let err = CalibratedLaw::from_json_str(&v.to_string()).unwrap_err();
    assert!(err.to_string().contains("mu_w"), "{err}");
    let mut v = json();
    v["constants"].as_array_mut().unwrap().pop();
    let err = CalibratedLaw::from_json_str(&v.to_string()).unwrap_err();
    assert!(err.to_string().contains("constants"), "{err}");
    let mut v = json();
    v["expression"]["formula"] = serde_json::json!("K*z");
    let err = CalibratedLaw::from_json_str(&v.to_string()).unwrap_err();
    assert!(err.to_string().contains("registry"), "{err}");
    let mut v = json();
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
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("law.json");
    law.save(&path).unwrap();
    assert_eq!(CalibratedLaw::load(&path).unwrap(), law);
}

/// `phi-i` and `phi-i-linear` were two names of one line: merged into `phi-i`, `φ_max − a I`.
/// A `phi-i-linear` file reads as `phi-i` (same parameters, same values); a `phi-i` file of the
/// former form (`phi_min`) is refused with what to do; `phi-i-linear` is no name to fit.
#[test]
fn phi_i_linear_is_merged_into_phi_i() {
    let f = fit_phi_i(&linear_rheology(2), &FitOptions::default()).unwrap();
    let law = CalibratedLaw::from_phi_i(&f, GRAIN, prov());
    assert_eq!(law.law, "phi-i");
    let names: Vec<&str> = law.parameters.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["phi_max", "a"]);
    // generated as 0.8 − 0.5 I
    assert!((law.parameter("a").unwrap() - 0.5).abs() < 0.05);
    let text = law.to_json_string().unwrap();
    let old = text.replacen("\"law\": \"phi-i\"", "\"law\": \"phi-i-linear\"", 1);
    assert_ne!(old, text);
    let read = CalibratedLaw::from_json_str(&old).unwrap();
    assert_eq!(read.law, "phi-i");
    assert_eq!(
        read.evaluate(&[0.1]).unwrap(),
        law.evaluate(&[0.1]).unwrap()
    );
    let former = text.replace("\"a\"", "\"phi_min\"");
    let e = CalibratedLaw::from_json_str(&former)
        .unwrap_err()
        .to_string();
    assert!(e.contains("phi_min") && e.contains("fit it again"), "{e}");
    let e = identify::user_fit::fit_csv_file(
        "phi-i-linear",
        std::path::Path::new("nowhere.csv"),
        &Default::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("merged into phi-i"), "{e}");
}
