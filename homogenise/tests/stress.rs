//! Mean stress with inertia: the rolling disk exact solution (`docs/physics.md` §2.3), symmetry,
//! translation invariance, and the boundary (virial) identity.

mod support;

use dem::math::Tensor;
use homogenise::inertia_ratio::inertia_ratios;
use homogenise::stress::{boundary_moment, grain_stresses, mean_stress};
use homogenise::tensor::{frobenius, in_frame, skew_ratio};
use homogenise::Region;
use support::{rel, rolling_disk, v};

#[test]
fn rolling_disk_is_exact_at_several_times_angles_and_radii() {
    // Σ_p = ρ g a [[0, s/6], [s/6, −c]] + (ρ g L s / 3) 𝟙 in the slope frame, to 1e-6 relative
    let mut cases = 0;
    for phi_deg in [5.0f64, 15.0, 26.0, 40.0] {
        for a in [1e-3, 2e-2, 0.3] {
            for t in [0.0, 0.01, 0.2, 1.5] {
                for mirrored in [false, true] {
                    let phi = phi_deg.to_radians();
                    let r = rolling_disk(phi, a, 2500.0, t, mirrored, v(0.1, -0.2));
                    // the hand-built snapshot is the analytic motion: a = (2/3) g sinφ e1 and
                    // |ω̇| = a/R, both as the engine would report them from the impulses
                    let b = &r.snap.bodies[1];
                    let acc = r.e1 * (2.0 / 3.0 * 9.81 * phi.sin());
                    assert!((b.acceleration - acc).norm() <= 1e-12 * acc.norm());
                    assert!(
                        (b.angular_acceleration - r.omega_dot).abs() <= 1e-12 * r.omega_dot.abs()
                    );
                    assert!((r.omega_dot.abs() - acc.norm() / a).abs() <= 1e-12 * acc.norm() / a);

                    if !mirrored {
                        let (e1, e2) = homogenise::tensor::slope_frame(phi);
                        assert!((e1 - r.e1).norm() < 1e-15 && (e2 - r.e2).norm() < 1e-15);
                    }
                    let g = grain_stresses(&r.snap).unwrap();
                    assert_eq!(g.len(), 1);
                    let total = in_frame(&g[0].total, &r.e1, &r.e2);
                    let contact = in_frame(&g[0].contact, &r.e1, &r.e2);
                    assert!(
                        rel(&total, &r.sigma) < 1e-6,
                        "φ={phi_deg} a={a} t={t} mirrored={mirrored}: {total} vs {}",
                        r.sigma
                    );
                    assert!(rel(&contact, &r.contact) < 1e-6);
                    // the ω² term is the isotropic (ρ g L sinφ/3) 𝟙
                    let iso = 2500.0 * 9.81 * r.travelled * phi.sin() / 3.0;
                    let inertia = in_frame(&g[0].inertia, &r.e1, &r.e2);
                    assert!((0.5 * inertia.trace() - iso).abs() <= 1e-9 * (iso + 1.0));
                    // symmetric in total, visibly not in the contact part alone:
                    // ‖skew Σ_c‖/‖Σ_c‖ = (√2 s/6) / √(s²/9 + c²)
                    assert!(skew_ratio(&g[0].total) <= 1e-8);
                    let (s, c) = (phi.sin(), phi.cos());
                    let expected_skew = 2f64.sqrt() * s / 6.0 / (s * s / 9.0 + c * c).sqrt();
                    assert!((skew_ratio(&g[0].contact) - expected_skew).abs() < 1e-9);
                    assert!(skew_ratio(&g[0].contact) > 0.01);
                    cases += 1;
                }
            }
        }
    }
    assert_eq!(cases, 96);
}

#[test]
fn rolling_disk_region_mean_and_inertia_ratio() {
    let (phi, a, rho, t) = (26f64.to_radians(), 0.05, 2000.0, 0.4);
    let r = rolling_disk(phi, a, rho, t, false, v(0.0, 0.0));
    let g = grain_stresses(&r.snap).unwrap();
    // a rectangle holding the whole disk: Σ = (π a² / A) Σ_p (eq. 9 with one grain)
    let c = g[0].position;
    let region = Region::Rectangle {
        min: c - v(0.2, 0.1),
        max: c + v(0.3, 0.15),
    };
    let m = mean_stress(&r.snap, &g, &region).unwrap();
    let area = 0.5 * 0.25;
    let expected = g[0].total * (std::f64::consts::PI * a * a / area);
    assert!(rel(&m.total, &expected) < 1e-12);
    assert!((m.grains - 1.0).abs() < 1e-12);
    // the inertia ratio ‖Σ_i‖/‖Σ_c‖ from the analytic parts:
    // Σ_i = (ρ a²/4)(−ω̇ j + ω² 𝟙): ‖Σ_i‖ = (ρ a²/4) √(2 ω̇² + 2 ω⁴); ‖Σ_c‖ = ρ g a √(s²/9 + c²)
    let k = rho * a * a / 4.0;
    let ni = k * (2.0 * r.omega_dot.powi(2) + 2.0 * r.omega.powi(4)).sqrt();
    let nc = rho * 9.81 * a * ((phi.sin() / 3.0).powi(2) + phi.cos().powi(2)).sqrt();
    let ratio = inertia_ratios(&g)[0].ratio.unwrap();
    assert!((ratio - ni / nc).abs() < 1e-12 * ni / nc);
    assert!((frobenius(&g[0].inertia) - ni).abs() < 1e-9 * ni);
}

#[test]
fn consistent_dynamic_states_give_symmetric_stress() {
    for seed in 0..5u64 {
        let snap = support::random_dynamic(seed, 8, 6, v(0.0, 0.0));
        let g = grain_stresses(&snap).unwrap();
        assert_eq!(g.len(), 48);
        let mut worst_contact: f64 = 0.0;
        for p in &g {
            assert!(
                skew_ratio(&p.total) <= 1e-8,
                "seed {seed} grain {}: {}",
                p.body,
                skew_ratio(&p.total)
            );
            worst_contact = worst_contact.max(skew_ratio(&p.contact));
        }
        // the contact part alone is visibly skew in these dynamic states
        assert!(worst_contact > 0.05, "seed {seed}: {worst_contact}");
        for region in [
            Region::Whole,
            Region::Slice {
                y_min: 2e-3,
                y_max: 9e-3,
            },
            Region::Rectangle {
                min: v(1e-3, 1e-3),
                max: v(1.1e-2, 1.3e-2),
            },
        ] {
            let m = mean_stress(&snap, &g, &region).unwrap();
            assert!(skew_ratio(&m.total) <= 1e-8);
            assert!(rel(&(m.contact + m.inertia), &m.total) < 1e-14);
        }
    }
}

#[test]
fn translation_by_a_kilometre_leaves_the_stress_unchanged() {
    let shift = v(1e3, 1e3);
    for seed in [3u64, 11] {
        let a = support::random_dynamic(seed, 7, 5, v(0.0, 0.0));
        let b = support::random_dynamic(seed, 7, 5, shift);
        let (ga, gb) = (grain_stresses(&a).unwrap(), grain_stresses(&b).unwrap());
        for (p, q) in ga.iter().zip(&gb) {
            assert!(
                rel(&q.total, &p.total) < 1e-9,
                "{}",
                rel(&q.total, &p.total)
            );
            assert!(rel(&q.contact, &p.contact) < 1e-9);
        }
        // region means, with regions that cut grains (border weights computed at 1e3 m)
        let (min, max) = (v(2.1e-3, 1.7e-3), v(1.05e-2, 8.2e-3));
        for (ra, rb) in [
            (Region::Whole, Region::Whole),
            (
                Region::Rectangle { min, max },
                Region::Rectangle {
                    min: min + shift,
                    max: max + shift,
                },
            ),
            (
                Region::Slice {
                    y_min: 3.3e-3,
                    y_max: 7.9e-3,
                },
                Region::Slice {
                    y_min: 3.3e-3 + shift.y,
                    y_max: 7.9e-3 + shift.y,
                },
            ),
        ] {
            let ma = mean_stress(&a, &ga, &ra).unwrap();
            let mb = mean_stress(&b, &gb, &rb).unwrap();
            assert!(
                rel(&mb.total, &ma.total) < 1e-9,
                "{}",
                rel(&mb.total, &ma.total)
            );
            assert!((mb.grains - ma.grains).abs() < 1e-9 * ma.grains);
        }
    }
}

#[test]
fn whole_sample_stress_equals_the_boundary_moment() {
    // Σ_p V_p Σ_p = Σ_wall r ⊗ x + Σ_p [m (g − a) ⊗ c + (I/2)(−ω̇ j + ω² 𝟙)] for any origin
    let snaps = [
        support::random_dynamic(7, 6, 6, v(0.0, 0.0)),
        support::column(12, 1e-3, 2600.0, 1.0, 0.3, 0.02, &[0.001; 12]),
        support::cannonball(0.01, 1000.0),
    ];
    for snap in &snaps {
        let g = grain_stresses(snap).unwrap();
        let sum: Tensor = g.iter().map(|p| p.total * p.volume).sum();
        let m0 = boundary_moment(snap, &v(0.0, 0.0)).unwrap();
        let m1 = boundary_moment(snap, &v(0.013, -0.021)).unwrap();
        assert!(rel(&m0, &sum) < 1e-10, "{}", rel(&m0, &sum));
        assert!(rel(&m1, &sum) < 1e-9, "{}", rel(&m1, &sum));
        // and the whole-sample mean is that moment over the sample's area (thickness 1)
        let whole = mean_stress(snap, &g, &Region::Whole).unwrap();
        assert!(rel(&(whole.total * whole.area), &sum) < 1e-12);
    }
}

#[test]
fn region_means_are_additive_over_a_partition() {
    // area-weighted slice means add up to the mean over their union, grains cut or not
    let snap = support::random_dynamic(5, 8, 8, v(0.0, 0.0));
    let g = grain_stresses(&snap).unwrap();
    let whole = mean_stress(&snap, &g, &Region::Whole).unwrap();
    let (y0, y1) = (whole.region.min.y, whole.region.max.y);
    let edges: Vec<f64> = (0..=7)
        .map(|k| y0 + (y1 - y0) * (k as f64 / 7.0).powf(1.3))
        .collect();
    let slices = homogenise::stress::slice_stress_profile(&snap, &g, &edges).unwrap();
    let sum: Tensor = slices.iter().map(|s| s.total * s.area).sum();
    assert!(rel(&sum, &(whole.total * whole.area)) < 1e-12);
    let count: f64 = slices.iter().map(|s| s.grains).sum();
    assert!((count - 64.0).abs() < 1e-12);
}

#[test]
fn bad_snapshots_are_errors_not_panics() {
    let mut snap = support::cannonball(0.01, 1000.0);
    snap.bodies[3].radius = f64::NAN;
    assert!(grain_stresses(&snap).is_err());
    let mut snap = support::cannonball(0.01, 1000.0);
    snap.contacts[0].body_b = 99;
    assert!(grain_stresses(&snap).is_err());
    let mut snap = support::cannonball(0.01, 1000.0);
    snap.contacts[1].force_t = f64::INFINITY;
    assert!(grain_stresses(&snap).is_err());
    let snap = support::cannonball(0.01, 1000.0);
    let g = grain_stresses(&snap).unwrap();
    let flat = Region::Rectangle {
        min: v(0.0, 0.0),
        max: v(1.0, 0.0),
    };
    assert!(mean_stress(&snap, &g, &flat).is_err());
}
