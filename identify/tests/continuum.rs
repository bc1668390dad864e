//! Closing the loop: the Janssen ODE against its closed form, and the Bagnold profile of a
//! μ(I) law on a slope against a numerical integration of its shear rate.

use identify::continuum::{janssen_ode_rk4, BagnoldFlow, SolidFraction};
use identify::laws::{JanssenVerticalLaw, MuILaw, PhiILaw};
use identify::IdentifyError;

#[test]
fn janssen_ode_matches_closed_form_to_1e_8() {
    let law = JanssenVerticalLaw {
        k_mu_w: 0.12,
        width_m: 0.03,
        bulk_density_kg_m3: 1600.0,
        gravity_m_s2: 9.81,
    };
    // Column 5 saturation lengths deep, 2000 RK4 steps (h/λ = 2.5·10⁻³).
    let profile = janssen_ode_rk4(&law, 5.0 * law.saturation_length(), 2000).unwrap();
    let mut worst: f64 = 0.0;
    for (z, s) in profile.z_m.iter().zip(&profile.sigma_v_pa).skip(1) {
        let exact = law.sigma_v(*z);
        worst = worst.max(((s - exact) / exact).abs());
    }
    assert!(worst <= 1e-8, "max relative error {worst:e}");
    // Saturation: σ_v → ρ_b g λ.
    let last = *profile.sigma_v_pa.last().unwrap();
    assert!((last / law.saturation_stress() - (1.0 - (-5f64).exp())).abs() < 1e-8);
    assert!(janssen_ode_rk4(&law, -1.0, 10).is_err());
    assert!(janssen_ode_rk4(&law, 1.0, 0).is_err());
}

fn flow() -> BagnoldFlow {
    let mu_i = MuILaw {
        mu_s: 0.38,
        mu_2: 0.64,
        i0: 0.279,
    };
    BagnoldFlow::new(
        &mu_i,
        SolidFraction::Law(PhiILaw {
            phi_max: 0.82,
            slope: 0.27,
        }),
        26f64.to_radians(),
        0.03,
        0.003,
        9.81,
    )
    .unwrap()
}

#[test]
fn bagnold_profile_matches_integrated_shear_rate() {
    let f = flow();
    // μ(I) = tan θ at the flow's I, and φ = φ(I).
    let mu_i = MuILaw {
        mu_s: 0.38,
        mu_2: 0.64,
        i0: 0.279,
    };
    assert!((mu_i.mu(f.inertial_number) - 26f64.to_radians().tan()).abs() < 1e-14);
    assert!((f.solid_fraction - (0.82 - 0.27 * f.inertial_number)).abs() < 1e-14);
    // Integrate du/dz = γ̇(z) from the base with composite Simpson on 2·10⁵ intervals;
    // γ̇ ~ √(H − z) at the surface limits the order, the error stays below 1e-6 relative.
    let n = 200_000;
    let h = f.depth_m / n as f64;
    let mut u = 0.0;
    let mut worst: f64 = 0.0;
    for k in 0..n {
        let z0 = k as f64 * h;
        u += h / 6.0 * (f.shear_rate(z0) + 4.0 * f.shear_rate(z0 + 0.5 * h) + f.shear_rate(z0 + h));
        if (k + 1) % 1000 == 0 {
            let exact = f.velocity(z0 + h);
            worst = worst.max(((u - exact) / exact).abs());
        }
    }
    assert!(worst < 1e-6, "max relative error {worst:e}");
    // Depth average = 3/5 of the surface velocity (trapezoid on the analytic profile).
    let pts = f.profile(20_001);
    let mean: f64 = pts
        .windows(2)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum::<f64>()
        / f.depth_m;
    assert!((mean / f.mean_velocity() - 1.0).abs() < 1e-6);
    assert_eq!(f.velocity(0.0), 0.0);
    // Pressure vanishes at the free surface and is lithostatic at the base.
    assert!(
        (f.pressure(0.0, 2500.0)
            - f.solid_fraction * 2500.0 * 9.81 * 26f64.to_radians().cos() * 0.03)
            .abs()
            < 1e-9
    );
    assert_eq!(f.pressure(0.03, 2500.0), 0.0);
}

#[test]
fn no_steady_flow_outside_mu_s_mu_2() {
    let mu_i = MuILaw {
        mu_s: 0.38,
        mu_2: 0.64,
        i0: 0.279,
    };
    for deg in [15.0f64, 40.0] {
        let e = BagnoldFlow::new(
            &mu_i,
            SolidFraction::Constant(0.6),
            deg.to_radians(),
            0.03,
            0.003,
            9.81,
        )
        .unwrap_err();
        assert!(matches!(e, IdentifyError::NoSteadyFlow { .. }), "{e}");
    }
    let e = BagnoldFlow::new(
        &mu_i,
        SolidFraction::Constant(1.5),
        26f64.to_radians(),
        0.03,
        0.003,
        9.81,
    )
    .unwrap_err();
    assert!(matches!(e, IdentifyError::InvalidSetup { .. }));
}
