//! `grainlaw scenarios`, `fit` and `solve-fc` on small inputs with known answers.

mod common;

use common::grainlaw_here as grainlaw;

use serde_json::Value;

#[test]
fn scenarios_lists_and_shows_every_builtin() {
    let o = grainlaw(&["scenarios"]);
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    for b in grainlaw::scenarios::registry::SCENARIOS.iter() {
        assert!(text.contains(b.name()), "{} not listed", b.name());
        let o = grainlaw(&["scenarios", "--show", b.name()]);
        assert!(o.status.success());
        let shown = String::from_utf8(o.stdout).unwrap();
        // the built-in TOML, then (for a scenario that fits laws) the data each law needs, as
        // comments
        let rest = shown
            .strip_prefix(b.builtin_toml())
            .expect("the built-in TOML first");
        assert!(
            rest.lines().all(|l| l.is_empty() || l.starts_with('#')),
            "{rest}"
        );
        let fits = grainlaw::scenarios::registry::load(b.name(), &[])
            .unwrap()
            .config
            .law_needs();
        for need in &fits {
            assert!(
                rest.contains(&format!("#   {} (", need.law)),
                "{}: {rest}",
                b.name()
            );
        }
        assert_eq!(rest.is_empty(), fits.is_empty(), "{}: {rest}", b.name());
        // The TOML shown is a complete scenario: it loads as a file.
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.toml");
        std::fs::write(&p, &shown).unwrap();
        grainlaw::scenarios::registry::load(p.to_str().unwrap(), &[]).unwrap();
        assert!(shown.contains("seed"), "{} has no seed", b.name());
    }
}

/// A one-contact problem with a known solution: W = diag(1, 3), q = (−1, 0.5), μ = 0.3.
/// Sticking would need r_t = −0.5/3 with |r_t| ≤ 0.3 r_n = 0.3: it sticks, r = (1, −1/6), u = 0.
#[test]
fn solve_fc_one_contact() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("p.json");
    std::fs::write(
        &p,
        r#"{"format":"fc-problem-v1","dimension":2,"nc":1,"mu":[0.3],"q":[-1.0,0.5],"W":{"storage":"dense","data":[[1.0,0.0],[0.0,3.0]]}}"#,
    )
    .unwrap();
    let sol = dir.path().join("s.json");
    let o = grainlaw(&[
        "solve-fc",
        p.to_str().unwrap(),
        "--tol",
        "1e-10",
        "--out",
        sol.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8(o.stdout).unwrap();
    assert!(out.contains("iterations") && out.contains("error"), "{out}");
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&sol).unwrap()).unwrap();
    let r: Vec<f64> = serde_json::from_value(v["r"].clone()).unwrap();
    assert!(
        (r[0] - 1.0).abs() < 1e-9 && (r[1] + 1.0 / 6.0).abs() < 1e-9,
        "r = {r:?}"
    );
    for k in ["u", "iterations", "error", "seconds"] {
        assert!(v.get(k).is_some(), "solution JSON lacks `{k}`");
    }
    assert!(v["error"].as_f64().unwrap() <= 1e-10);
}

/// `grainlaw fit janssen` recovers K and μ_w from an exact Janssen profile (within 1e-3), and
/// the law it writes has a verdict (`ok`) like the laws of a run.
#[test]
fn fit_janssen_from_csv() {
    let (k, mu, w, rho_b, g) = (0.8, 0.2, 0.03, 1600.0, 9.81);
    let a = 2.0 * k * mu / w;
    let mut csv = format!(
        "# width_m = {w}\n# bulk_density_kg_m3 = {rho_b}\n# wall_friction = 0.3\nz_m,sigma_v_Pa,sigma_h_Pa\n"
    );
    for i in 1..=15 {
        let z = 0.008 * i as f64;
        let sv = rho_b * g / a * (1.0 - (-a * z).exp());
        // ±0.2 % deterministic "noise" so that the residual variance is not zero.
        let e = 1.0 + 0.002 * if i % 2 == 0 { 1.0 } else { -1.0 };
        csv.push_str(&format!("{z},{},{}\n", sv * e, k * sv / e));
    }
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("j.csv");
    std::fs::write(&data, csv).unwrap();
    let law = dir.path().join("law.json");
    let o = grainlaw(&[
        "fit",
        "janssen",
        data.to_str().unwrap(),
        "--out",
        law.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&law).unwrap()).unwrap();
    let p = |name: &str| {
        v["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name)
            .unwrap()["value"]
            .as_f64()
            .unwrap()
    };
    assert!((p("K") - k).abs() < 1e-3 * k * 10.0, "K = {}", p("K"));
    assert!(
        (p("mu_w") - mu).abs() < 1e-3 * mu * 10.0,
        "mu_w = {}",
        p("mu_w")
    );
    // A fitted law carries its verdict as a run's laws do: it passed every check, `ok`.
    assert_eq!(v["verdict"], "ok", "{v}");
    // Without --out the law JSON goes to stdout.
    let o = grainlaw(&["fit", "janssen", data.to_str().unwrap()]);
    assert!(o.status.success());
    let v = serde_json::from_slice::<Value>(&o.stdout).expect("law JSON on stdout");
    assert_eq!(v["verdict"], "ok");
}
