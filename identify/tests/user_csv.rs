//! Fitting laws by name from a user's CSV files.

mod common;

use std::fmt::Write as _;
use std::path::PathBuf;

use common::{gaussian, janssen_profile, janssen_truth};
use identify::law::CalibratedLaw;
use identify::laws::{MohrCoulombLaw, MuILaw, WallFrictionLaw};
use identify::user_fit::{fit_csv_file, CsvFitOptions, LAW_NAMES};
use identify::IdentifyError;

fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn janssen_csv() -> String {
    let (law, _) = janssen_truth();
    let p = janssen_profile(&law, 31, true);
    let mut s = String::from(
        "# Janssen column, synthetic\n# width_m = 0.03\n# bulk_density_kg_m3 = 1600\n# wall_friction = 0.25\nz_m,sigma_v_Pa,sigma_h_Pa,tau_w_Pa\n",
    );
    for i in 0..p.z_m.len() {
        writeln!(
            s,
            "{},{},{},{}",
            p.z_m[i],
            p.sigma_v_pa[i],
            p.sigma_h_pa.as_ref().unwrap()[i],
            p.tau_w_pa.as_ref().unwrap()[i]
        )
        .unwrap();
    }
    s
}

#[test]
fn janssen_from_csv_exports_a_law_that_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(&dir, "column.csv", &janssen_csv());
    let law = fit_csv_file("janssen", &path, &CsvFitOptions::default()).unwrap();
    assert_eq!(law.law, "janssen");
    assert_eq!(law.provenance.scenario, "user-csv");
    assert_eq!(
        law.provenance.source.as_deref(),
        Some(path.to_str().unwrap())
    );
    let k = law.parameters.iter().find(|p| p.name == "K").unwrap();
    assert!((k.value - 0.6).abs() < 3.0 * k.std_error, "{k:?}");
    let out = dir.path().join("law.json");
    law.save(&out).unwrap();
    assert_eq!(CalibratedLaw::load(&out).unwrap(), law);
    // janssen-kmu uses σ_v only.
    let one = fit_csv_file("janssen-kmu", &path, &CsvFitOptions::default()).unwrap();
    let kmu = &one.parameters[0];
    assert_eq!(kmu.name, "K_mu_w");
    assert!((kmu.value - 0.12).abs() < 3.0 * kmu.std_error);
}

#[test]
fn mu_i_wall_law_and_mohr_coulomb_from_csv() {
    let dir = tempfile::tempdir().unwrap();
    let truth = MuILaw {
        mu_s: 0.38,
        mu_2: 0.64,
        i0: 0.279,
    };
    let mut s =
        String::from("# grain_diameter_m = 0.002\n# grain_density_kg_m3 = 2500\nI,mu,P_Pa\n");
    let e = gaussian(8, 25, 0.004);
    for (k, ek) in e.iter().enumerate() {
        let i = 10f64.powf(-3.0 + 3.0 * k as f64 / 24.0);
        writeln!(s, "{i},{},{}", truth.mu(i) + ek, 500.0 + 10.0 * k as f64).unwrap();
    }
    let law = fit_csv_file(
        "mu-i",
        &write(&dir, "mu.csv", &s),
        &CsvFitOptions::default(),
    )
    .unwrap();
    assert_eq!(law.law, "mu-i");
    assert!(law
        .validity
        .iter()
        .any(|v| v.variable == "P" && v.min == 500.0));

    let wall = WallFrictionLaw::Exponential {
        mu_0: 0.15,
        mu_inf: 0.45,
        v_star: 0.5,
    };
    let d: f64 = 0.002;
    let mut s = format!("# grain_diameter_m = {d}\nslip_velocity_m_s,tau_w_Pa,sigma_w_Pa\n");
    let e = gaussian(9, 40, 0.003);
    for (k, ek) in e.iter().enumerate() {
        let v = 10f64.powf(-2.0 + 2.7 * k as f64 / 39.0);
        let sigma = 1000.0;
        writeln!(
            s,
            "{},{},{sigma}",
            v * (9.81 * d).sqrt(),
            (wall.mu_eff(v) + ek) * sigma
        )
        .unwrap();
    }
    let law = fit_csv_file(
        "wall-law",
        &write(&dir, "wall.csv", &s),
        &CsvFitOptions::default(),
    )
    .unwrap();
    assert_eq!(law.law, "wall-law-exponential");
    let sel = law.model_selection.as_ref().unwrap();
    assert_eq!(sel.ranking.len() + sel.failed.len(), 3);

    let mc = MohrCoulombLaw {
        friction_angle_rad: 30f64.to_radians(),
        cohesion_pa: 0.0,
    };
    let mut s = String::from("sigma_xx_Pa,sigma_yy_Pa,sigma_xy_Pa\n");
    for k in 0..10 {
        let p = 1000.0 * (k + 1) as f64;
        let q = mc.yield_q(p);
        // Principal axes along x and y, σ_yy the major compression (tension positive).
        writeln!(s, "{},{},0", -(p - q), -(p + q)).unwrap();
    }
    let law = fit_csv_file(
        "mohr-coulomb",
        &write(&dir, "mc.csv", &s),
        &CsvFitOptions::default(),
    )
    .unwrap();
    let phi = law
        .parameters
        .iter()
        .find(|p| p.name == "friction_angle")
        .unwrap();
    assert!((phi.value - 30f64.to_radians()).abs() < 1e-6);
    assert!(law
        .parameters
        .iter()
        .any(|p| p.name == "cohesion" && p.at_bound));
}

#[test]
fn csv_errors_name_the_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let bad = janssen_csv().replacen("0.05,", "0.05x,", 1);
    let path = write(&dir, "bad.csv", &bad);
    let err = fit_csv_file("janssen", &path, &CsvFitOptions::default()).unwrap_err();
    match &err {
        IdentifyError::NonNumericCell {
            line,
            column,
            value,
            ..
        } => {
            assert_eq!(*line, 10); // 4 metadata/comment lines + header + 5th data row
            assert_eq!(column, "z_m");
            assert_eq!(value, "0.05x");
        }
        other => panic!("{other}"),
    }
    assert!(err.to_string().contains("bad.csv:10"));

    let no_h = janssen_csv().replace("sigma_h_Pa", "sigma_x_Pa");
    let err = fit_csv_file(
        "janssen",
        &write(&dir, "noh.csv", &no_h),
        &CsvFitOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(&err, IdentifyError::MissingColumn { column, .. } if column == "sigma_h_Pa"),
        "{err}"
    );

    let no_meta = janssen_csv().replace("# width_m = 0.03\n", "");
    let err = fit_csv_file(
        "janssen",
        &write(&dir, "nom.csv", &no_meta),
        &CsvFitOptions::default(),
    )
    .unwrap_err();
    assert!(err.to_string().contains("width_m"), "{err}");
    // …which the options can supply.
    let mut o = CsvFitOptions::default();
    o.metadata.insert("width_m".into(), 0.03);
    assert!(fit_csv_file("janssen", &write(&dir, "nom2.csv", &no_meta), &o).is_ok());

    let err = fit_csv_file("hooke", &path, &CsvFitOptions::default()).unwrap_err();
    assert!(matches!(err, IdentifyError::UnknownLaw { .. }));
    assert!(err.to_string().contains(&LAW_NAMES.join(", ")));

    let err = fit_csv_file(
        "mu-i",
        &dir.path().join("missing.csv"),
        &CsvFitOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(err, IdentifyError::Io { .. }));
}
