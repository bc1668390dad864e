//! Column profiles for the Janssen fit and flow profiles for μ(I).

mod support;

use homogenise::column::{column_profile, ColumnSpec};
use homogenise::flow::{flow_profile, GrainScale};
use homogenise::invariants::stress_invariants;
use homogenise::stress::grain_stresses;
use support::v;

#[test]
fn column_profile_of_a_janssen_like_column() {
    let (n, r, t) = (16, 1e-3, 0.02);
    let (mu, h) = (0.3, 0.002);
    let tk: Vec<f64> = (0..n)
        .map(|k| mu * h * if k < 6 { 1.0 } else { 0.25 })
        .collect();
    let snap = support::column(n, r, 2500.0, t, mu, h, &tk);
    let w = snap.bodies.iter().find(|b| b.radius > 0.0).unwrap().mass * 9.81;
    let spec = ColumnSpec {
        left: "left".into(),
        right: "right".into(),
        bin_width: 2.0 * r,
    };
    let p = column_profile(&snap, &spec).unwrap();
    assert!((p.width - 2.0 * r).abs() < 1e-15);
    assert!((p.surface_y - 2.0 * r * n as f64).abs() < 1e-15);
    assert_eq!(p.depth.len(), n);
    let area = 2.0 * r * t; // wall length of a bin × thickness, and width × thickness
    for k in 0..n {
        let layer = n - 1 - k; // the bin's middle is that layer's centre
        assert!((p.depth[k] - (2 * k + 1) as f64 * r).abs() < 1e-15);
        // planes above the layer's centre carry the load of the layers above, planes below it
        // that load plus the layer's weight minus its wall friction: half of each
        let above: f64 = (layer + 1..n).map(|j| w - 2.0 * tk[j]).sum();
        let below: f64 = above + w - 2.0 * tk[layer];
        let mid = 0.5 * (above + below) / area;
        assert!(
            (p.sigma_v[k] - mid).abs() < 1e-12 * w * n as f64 / area,
            "bin {k}"
        );
        assert!(
            (p.sigma_v_mean[k] - 0.5 * (above + below) / area).abs() < 1e-12 * w * n as f64 / area
        );
        assert!((p.sigma_h[k] - h / area).abs() < 1e-12 * h / area);
        assert!((p.tau_w[k] - tk[layer] / area).abs() < 1e-12 * h / area);
        let lim = if layer < 6 { 1.0 } else { 0.0 };
        assert_eq!(p.wall_fraction_at_limit[k], Some(lim));
        assert!(p.bulk_fraction_at_limit[k].is_none_or(|f| f == 0.0));
        assert!((p.solid_fraction[k] - std::f64::consts::PI / 4.0).abs() < 1e-13);
    }
    let total = w * n as f64;
    let side: f64 = tk.iter().map(|t| 2.0 * t).sum();
    assert!((p.weight - total).abs() < 1e-12 * total);
    assert!((p.side_wall_load_over_weight - side / total).abs() < 1e-12);
    assert!((p.bottom_load_over_weight - (total - side) / total).abs() < 1e-12);
    assert!((p.bottom_load_over_weight + p.side_wall_load_over_weight - 1.0).abs() < 1e-12);
    assert!((p.bulk_density - 2500.0 * std::f64::consts::PI / 4.0).abs() < 1e-9);
    // wrong names and tilted gravity are errors
    let bad = ColumnSpec {
        left: "west".into(),
        ..spec.clone()
    };
    assert!(column_profile(&snap, &bad).is_err());
    let mut tilted = snap.clone();
    tilted.gravity = v(1.0, -9.81);
    assert!(column_profile(&tilted, &spec).is_err());
}

#[test]
fn flow_profile_of_a_sheared_packing() {
    // a random dynamic packing with the velocity field v_x = γ̇ y: every slice sees γ̇ exactly
    let mut snap = support::random_dynamic(4, 10, 10, v(0.0, 0.0));
    let rate = 25.0;
    for b in snap.bodies.iter_mut().filter(|b| b.radius > 0.0) {
        b.velocity = v(rate * b.position.y, 0.0);
    }
    let g = grain_stresses(&snap).unwrap();
    let edges: Vec<f64> = (0..=10).map(|k| 3e-3 * k as f64).collect();
    let scale = GrainScale {
        diameter: 2.5e-3,
        density: 2500.0,
    };
    let prof = flow_profile(&snap, &g, &edges, &scale, 1.0).unwrap();
    assert_eq!(prof.len(), 10);
    for s in &prof {
        assert!(s.grains > 0.5);
        assert!((s.velocity_gradient.unwrap() - rate).abs() < 1e-9 * rate);
        assert!((s.velocity.x - rate * s.mean_y).abs() < 1e-12);
        let inv = stress_invariants(&s.stress);
        assert_eq!(s.pressure, inv.pressure);
        if s.pressure > 0.0 {
            let i = rate * scale.diameter / (s.pressure / scale.density).sqrt();
            assert!((s.inertial_number.unwrap() - i).abs() < 1e-12 * i);
            assert!(
                (s.stress_ratio_xy.unwrap() - s.stress[(0, 1)].abs() / s.pressure).abs() < 1e-15
            );
        }
        let f = s.fluid_fraction.unwrap();
        assert!((0.0..=1.0).contains(&f));
    }
    assert!(flow_profile(&snap, &g, &[0.0, 0.0], &scale, 1.0).is_err());
    let bad = GrainScale {
        diameter: -1.0,
        density: 2500.0,
    };
    assert!(flow_profile(&snap, &g, &edges, &bad, 1.0).is_err());
}
