//! Mohr–Coulomb envelope by conic programming (Clarabel) on synthetic states at yield.

mod common;

use common::gaussian;
use identify::laws::MohrCoulombLaw;
use identify::mohr_coulomb::{fit_mohr_coulomb, fit_mohr_coulomb_supported, YieldData};
use identify::IdentifyError;

/// 40 Mohr circles at yield with p ∈ [1, 20] kPa, q = p sin φ + c cos φ + noise, each turned
/// into a tension-positive 2D tensor at a different orientation.
fn tensors(phi_deg: f64, c: f64, seed: u64, noise: f64) -> Vec<[f64; 3]> {
    let law = MohrCoulombLaw {
        friction_angle_rad: phi_deg.to_radians(),
        cohesion_pa: c,
    };
    let e = gaussian(seed, 40, noise);
    (0..40)
        .map(|k| {
            let p = 1000.0 + 19000.0 * k as f64 / 39.0;
            let q = law.yield_q(p) + e[k];
            let a = 0.37 * k as f64; // principal direction
            let (s1, s3) = (-(p + q), -(p - q)); // tension positive: compression negative
            [
                s1 * a.cos().powi(2) + s3 * a.sin().powi(2),
                s1 * a.sin().powi(2) + s3 * a.cos().powi(2),
                (s1 - s3) * a.sin() * a.cos(),
            ]
        })
        .collect()
}

#[test]
fn noise_free_states_give_phi_and_c_exactly() {
    let fit = fit_mohr_coulomb(
        &YieldData::from_tension_positive_tensors(&tensors(30.0, 500.0, 0, 0.0)),
        0.95,
    )
    .unwrap();
    assert!(
        (fit.friction_angle_deg.value - 30.0).abs() < 1e-6,
        "{:?}",
        fit.friction_angle_deg
    );
    assert!(
        (fit.cohesion.value - 500.0).abs() < 1e-3,
        "{:?}",
        fit.cohesion
    );
    assert!(!fit.cohesion.at_bound);
}

#[test]
fn noisy_cohesive_states_recover_phi_and_c() {
    // Tolerances: φ within 0.5°, c within 150 Pa (noise 50 Pa on q), and within 3 standard errors.
    let fit = fit_mohr_coulomb(
        &YieldData::from_tension_positive_tensors(&tensors(30.0, 500.0, 1, 50.0)),
        0.95,
    )
    .unwrap();
    let phi = &fit.friction_angle_deg;
    assert!((phi.value - 30.0).abs() < 0.5 && (phi.value - 30.0).abs() < 3.0 * phi.std_error);
    let c = &fit.cohesion;
    assert!((c.value - 500.0).abs() < 150.0 && (c.value - 500.0).abs() < 3.0 * c.std_error);
    assert_eq!(fit.report.parameters[0].unit, "rad");
    assert_eq!(fit.report.validity[0].variable, "p");
    // The 2D Drucker–Prager equivalent gives the same yield radius.
    let dp = fit.law.drucker_prager_2d();
    assert!((dp.alpha * 5000.0 + dp.k_pa - fit.law.yield_q(5000.0)).abs() < 1e-9);
}

#[test]
fn cohesionless_states_give_c_zero_on_its_bound() {
    for seed in 0..5 {
        let fit = fit_mohr_coulomb(
            &YieldData::from_tension_positive_tensors(&tensors(25.0, 0.0, 10 + seed, 50.0)),
            0.95,
        )
        .unwrap();
        // Either the constraint is active (c = 0 exactly) or c is small, and φ is recovered.
        assert!(fit.cohesion.value >= 0.0);
        if fit.cohesion.at_bound {
            assert_eq!(fit.cohesion.value, 0.0);
            assert_eq!(fit.cohesion.ci_low, 0.0);
            assert!(fit.cohesion.ci_high >= 0.0);
        } else {
            assert!(fit.cohesion.value < 150.0);
        }
        assert!((fit.friction_angle_deg.value - 25.0).abs() < 0.5);
    }
    // A draw whose unconstrained intercept is negative: cohesion sits at 0 with the flag.
    let states = tensors(25.0, 0.0, 0, 0.0);
    // Shift every circle's radius down by 100 Pa (q = p sin φ − 100): OLS would give c < 0.
    let data = YieldData::from_tension_positive_tensors(&states);
    let YieldData::Circles { p_pa, q_pa } = data else {
        unreachable!()
    };
    let shifted = YieldData::Circles {
        p_pa: p_pa.clone(),
        q_pa: q_pa.iter().map(|q| q - 100.0).collect(),
    };
    let fit = fit_mohr_coulomb(&shifted, 0.95).unwrap();
    assert!(fit.cohesion.at_bound && fit.cohesion.value == 0.0);
    assert!((fit.friction_angle_deg.value - 25.0).abs() < 1.0);
}

#[test]
fn failure_plane_and_principal_forms() {
    let law = MohrCoulombLaw {
        friction_angle_rad: 35f64.to_radians(),
        cohesion_pa: 200.0,
    };
    let sigma: Vec<f64> = (1..=10).map(|k| 1000.0 * k as f64).collect();
    let tau: Vec<f64> = sigma.iter().map(|s| -law.shear_strength(*s)).collect(); // sign ignored
    let fit = fit_mohr_coulomb(
        &YieldData::FailurePlane {
            sigma_n_pa: sigma.clone(),
            tau_pa: tau,
        },
        0.95,
    )
    .unwrap();
    assert!((fit.friction_angle_deg.value - 35.0).abs() < 1e-6);
    assert!((fit.cohesion.value - 200.0).abs() < 1e-3);
    // Principal stresses σ₁ = p + q, σ₃ = p − q.
    let (s1, s3): (Vec<f64>, Vec<f64>) = sigma
        .iter()
        .map(|p| (p + law.yield_q(*p), p - law.yield_q(*p)))
        .unzip();
    let fit = fit_mohr_coulomb(&YieldData::from_principal(&s1, &s3), 0.95).unwrap();
    assert!((fit.friction_angle_deg.value - 35.0).abs() < 1e-6);
    assert!((fit.cohesion.value - 200.0).abs() < 1e-3);
}

#[test]
fn degenerate_yield_data() {
    let bad = YieldData::Circles {
        p_pa: vec![1000.0, -5.0, 3000.0, 4000.0],
        q_pa: vec![500.0, 1000.0, 1500.0, 2000.0],
    };
    assert!(matches!(
        fit_mohr_coulomb(&bad, 0.95).unwrap_err(),
        IdentifyError::NegativePressure { index: 1, .. }
    ));
    let few = YieldData::Circles {
        p_pa: vec![1000.0, 2000.0, 3000.0],
        q_pa: vec![500.0, 1000.0, 1500.0],
    };
    assert!(matches!(
        fit_mohr_coulomb(&few, 0.95).unwrap_err(),
        IdentifyError::TooFewPoints {
            needed: 4,
            got: 3,
            ..
        }
    ));
    let same = YieldData::Circles {
        p_pa: vec![1000.0; 6],
        q_pa: vec![500.0, 510.0, 490.0, 505.0, 495.0, 500.0],
    };
    assert!(matches!(
        fit_mohr_coulomb(&same, 0.95).unwrap_err(),
        IdentifyError::ZeroVariance { .. }
    ));
    // q decreasing with p: the friction coefficient ends at its bound 0.
    let weird = YieldData::Circles {
        p_pa: vec![1000.0, 2000.0, 3000.0, 4000.0, 5000.0],
        q_pa: vec![900.0, 800.0, 700.0, 600.0, 500.0],
    };
    assert!(matches!(
        fit_mohr_coulomb(&weird, 0.95).unwrap_err(),
        IdentifyError::ParameterAtBound { .. }
    ));
    let nan = YieldData::Circles {
        p_pa: vec![1000.0, 2000.0, f64::NAN, 4000.0],
        q_pa: vec![500.0, 1000.0, 1500.0, 2000.0],
    };
    assert!(matches!(
        fit_mohr_coulomb(&nan, 0.95).unwrap_err(),
        IdentifyError::NonFinite { index: 2, .. }
    ));
}

/// Peak circles of a cohesionless material (sin φ = 0.45) with scatter of ±1–8 % at four
/// pressures, as the biaxial scenario measures them: the free-cohesion fit is refused (its
/// cohesion interval crosses zero), and [`fit_mohr_coulomb_supported`] fits the form the data
/// support, `q = p sin φ`, whose angle is then the least-squares slope through the origin,
/// `sin φ = Σ p q / Σ p²` (to 10⁻⁶), with the free form's refusal returned.
#[test]
fn unsupported_cohesion_falls_back_to_the_cohesionless_envelope() {
    let p = vec![1000.0, 2000.0, 4000.0, 8000.0];
    let q: Vec<f64> = p
        .iter()
        .zip([60.0, -80.0, 70.0, -40.0])
        .map(|(p, e)| 0.45 * p + e)
        .collect();
    let data = YieldData::Circles {
        p_pa: p.clone(),
        q_pa: q.clone(),
    };
    assert!(
        fit_mohr_coulomb(&data, 0.95).is_err(),
        "the free fit must be refused"
    );
    let (fit, fixed, refusal) = fit_mohr_coulomb_supported(&data, 0.95).unwrap();
    assert!(fixed && refusal.is_some());
    assert_eq!(fit.cohesion.value, 0.0);
    let slope: f64 =
        p.iter().zip(&q).map(|(p, q)| p * q).sum::<f64>() / p.iter().map(|p| p * p).sum::<f64>();
    assert!(
        (fit.friction_angle.value.sin() - slope).abs() < 1e-6,
        "sin φ = {} vs {slope}",
        fit.friction_angle.value.sin()
    );
    // The cohesion held at zero by the data is an estimate at its bound: one-sided interval
    // [0, max(b, 0) + t₀.₉₇₅,₂ se(b)] / cos φ from the unconstrained regression q = a p + b,
    // with its standard error se(b) / cos φ; never [0, 0].
    let (b, se) = ols_intercept(&p, &q);
    let cos = fit.friction_angle.value.cos();
    let high = (b.max(0.0) + identify::stats::t_critical(0.95, 2) * se) / cos;
    let c = &fit.cohesion;
    assert!(c.at_bound && c.ci_low == 0.0, "{c:?}");
    assert!(c.ci_high > 0.0 && c.std_error > 0.0, "{c:?}");
    assert!(
        (c.ci_high - high).abs() < 1e-6 * high,
        "{} vs {high}",
        c.ci_high
    );
    assert!((c.std_error - se / cos).abs() < 1e-6 * se, "{c:?}");
    // Three pressures (the free form is not tried): the same one-sided interval, at 1 degree of
    // freedom.
    let three = YieldData::Circles {
        p_pa: p[..3].to_vec(),
        q_pa: q[..3].to_vec(),
    };
    let (fit3, fixed3, refusal3) = fit_mohr_coulomb_supported(&three, 0.95).unwrap();
    assert!(fixed3 && refusal3.is_none());
    let (b3, se3) = ols_intercept(&p[..3], &q[..3]);
    let high3 = (b3.max(0.0) + identify::stats::t_critical(0.95, 1) * se3)
        / fit3.friction_angle.value.cos();
    let c3 = &fit3.cohesion;
    assert!(
        c3.at_bound && c3.ci_low == 0.0 && c3.std_error > 0.0,
        "{c3:?}"
    );
    assert!(
        (c3.ci_high - high3).abs() < 1e-6 * high3,
        "{} vs {high3}",
        c3.ci_high
    );
    // Fixed by the user (`# cohesion = 0`), it is a constant: [0, 0].
    let user = identify::mohr_coulomb::fit_mohr_coulomb_with(
        &three,
        &identify::mohr_coulomb::MohrCoulombOptions::cohesionless(),
    )
    .unwrap();
    assert_eq!(
        (
            user.cohesion.ci_low,
            user.cohesion.ci_high,
            user.cohesion.std_error
        ),
        (0.0, 0.0, 0.0)
    );
    // Exact cohesive data keep their free fit.
    let cohesive = YieldData::Circles {
        p_pa: p.clone(),
        q_pa: p.iter().map(|p| 0.45 * p + 300.0).collect(),
    };
    let (fit, fixed, refusal) = fit_mohr_coulomb_supported(&cohesive, 0.95).unwrap();
    assert!(!fixed && refusal.is_none() && fit.cohesion.value > 0.0);
}

/// Intercept `b` of the ordinary least-squares line `y = a x + b` and its standard error
/// `s √((XᵀX)⁻¹₂₂)`, `s² = RSS/(n − 2)`.
fn ols_intercept(x: &[f64], y: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let a = x
        .iter()
        .zip(y)
        .map(|(u, v)| (u - mx) * (v - my))
        .sum::<f64>()
        / sxx;
    let b = my - a * mx;
    let rss: f64 = x.iter().zip(y).map(|(u, v)| (v - a * u - b).powi(2)).sum();
    let s2 = rss / (n - 2.0);
    (b, (s2 * (1.0 / n + mx * mx / sxx)).sqrt())
}
