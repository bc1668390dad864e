//! Columns at rest: the vertical stress at the bottom is the weight per width minus what the
//! walls carry; wall stress profiles and friction mobilisation by depth.

mod support;

use homogenise::depth::{DepthAxis, DepthBins};
use homogenise::mobilisation::{
    contact_mobilisations, fraction_at_limit_by_depth, mobilisation_stats, ContactClass,
    COULOMB_LIMIT,
};
use homogenise::stress::{grain_stresses, slice_stress_profile};
use homogenise::walls::{plane_stress_profile, wall_stress_profile};
use support::v;

const G: f64 = 9.81;

fn weight(snap: &dem::snapshot::Snapshot) -> f64 {
    snap.bodies
        .iter()
        .map(|b| if b.radius > 0.0 { b.mass * G } else { 0.0 })
        .sum()
}

/// Vertical force the side walls carry (N): minus the y force the grains put on them.
fn side_wall_load(snap: &dem::snapshot::Snapshot) -> f64 {
    snap.walls
        .iter()
        .filter(|w| w.name == "left" || w.name == "right")
        .map(|w| -w.force.y)
        .sum()
}

#[test]
fn bottom_vertical_stress_is_weight_minus_wall_load_per_width() {
    // 20 disks of r = 1.5 mm, thickness 1 cm, side friction T = 0.4 μ H on each wall contact
    let (n, r, t) = (20, 1.5e-3, 0.01);
    let (mu, h) = (0.25, 0.005);
    let tk = vec![0.4 * mu * h; n];
    let snap = support::column(n, r, 2500.0, t, mu, h, &tk);
    // the hand-built column is in equilibrium (what the engine would report at rest)
    for b in snap.bodies.iter().filter(|b| b.radius > 0.0) {
        assert!(b.acceleration.norm() < 1e-12 && b.angular_acceleration.abs() < 1e-9);
    }
    let width = 2.0 * r;
    let (w, walls) = (weight(&snap), side_wall_load(&snap));
    assert!(walls > 0.1 * w, "the walls must carry a visible share");
    let bottom_expected = -(w - walls) / (width * t);
    // bottom wall force agrees too
    let bottom = snap.walls.iter().find(|w| w.name == "bottom").unwrap();
    assert!((-bottom.force.y - (w - walls)).abs() < 1e-12 * w);

    // 1. method of planes at the bottom wall's surface and just above it
    let planes = plane_stress_profile(&snap, &[0.0, 0.5 * r], None).unwrap();
    for pl in &planes {
        assert!((pl.width - width).abs() < 1e-15);
        assert!((pl.sigma_yy - bottom_expected).abs() < 1e-12 * bottom_expected.abs());
        assert!(pl.sigma_xy.abs() < 1e-12 * bottom_expected.abs());
    }

    // 2. mean stress Σ over the layers: σ̄_k = −(P_k + P_{k+1}) / (2 W t) exactly, and its
    // linear extrapolation to the bottom is the same weight-minus-walls stress
    let g = grain_stresses(&snap).unwrap();
    let edges: Vec<f64> = (0..=n).map(|k| 2.0 * r * k as f64).collect();
    let slices = slice_stress_profile(&snap, &g, &edges).unwrap();
    let levels: Vec<f64> = edges.clone();
    let p = plane_stress_profile(&snap, &levels[..n], None).unwrap();
    for k in 0..n {
        let top = if k + 1 < n { p[k + 1].sigma_yy } else { 0.0 };
        let expected = 0.5 * (p[k].sigma_yy + top);
        let got = slices[k].total[(1, 1)];
        assert!(
            (got - expected).abs() < 1e-12 * bottom_expected.abs(),
            "layer {k}: {got} vs {expected}"
        );
        assert!(slices[k].total[(0, 1)].abs() < 1e-9 * bottom_expected.abs()); // T balanced left/right
    }
    let extrapolated =
        slices[0].total[(1, 1)] - 0.5 * (slices[1].total[(1, 1)] - slices[0].total[(1, 1)]);
    assert!(
        (extrapolated - bottom_expected).abs() < 1e-12 * bottom_expected.abs(),
        "{extrapolated} vs {bottom_expected}"
    );
}

#[test]
fn janssen_like_column_planes_give_the_load_at_every_depth() {
    // friction growing with depth (as in Janssen), some wall contacts at the Coulomb limit
    let (n, r, t) = (30, 1e-3, 1.0);
    let (mu, h) = (0.3, 0.01);
    let tk: Vec<f64> = (0..n)
        .map(|k| mu * h * if k < 10 { 1.0 } else { 0.5 })
        .collect();
    let snap = support::column(n, r, 2600.0, t, mu, h, &tk);
    let m = snap.bodies.iter().find(|b| b.radius > 0.0).unwrap().mass;
    let width = 2.0 * r;
    let levels: Vec<f64> = (0..n).map(|k| 2.0 * r * k as f64 + 0.3 * r).collect();
    let planes = plane_stress_profile(&snap, &levels, Some(width)).unwrap();
    for (k, pl) in planes.iter().enumerate() {
        // load on layer k from below: the weight of layers ≥ k minus their wall friction
        let load: f64 = (k..n).map(|j| m * G - 2.0 * tk[j]).sum();
        assert!((pl.sigma_yy + load / width).abs() < 1e-12 * (m * G * n as f64 / width));
    }

    // wall stress profile on the left wall: depth from the free surface, bins of one layer
    let axis = DepthAxis::from_gravity(&snap).unwrap();
    assert!((axis.surface.y - 2.0 * r * n as f64).abs() < 1e-15);
    let bins = DepthBins::new(axis, 2.0 * r, n).unwrap();
    let prof = wall_stress_profile(&snap, "left", &bins).unwrap();
    for (k, b) in prof.iter().enumerate() {
        let layer = n - 1 - k;
        assert!((b.normal_stress + h / (2.0 * r * t)).abs() < 1e-12 * h / r);
        assert!((b.shear_stress - tk[layer] / (2.0 * r * t)).abs() < 1e-12 * h / r);
        assert!((b.friction().unwrap() - tk[layer] / h).abs() < 1e-12);
        assert_eq!(b.contacts, 1);
        let at_limit = if layer < 10 { 1.0 } else { 0.0 };
        assert_eq!(b.fraction_at_limit, Some(at_limit));
        assert!((b.mean_mobilisation.unwrap() - tk[layer] / (mu * h)).abs() < 1e-12);
    }
    // the right wall carries the same
    let right = wall_stress_profile(&snap, "right", &bins).unwrap();
    for (a, b) in prof.iter().zip(&right) {
        assert!(
            (a.shear_stress - b.shear_stress).abs() < 1e-9
                && (a.normal_stress - b.normal_stress).abs() < 1e-9
        );
    }

    // mobilisation: 60 side-wall contacts, 20 at the limit; bulk contacts carry no friction
    let wall_m: Vec<f64> = ["left", "right"]
        .iter()
        .flat_map(|w| {
            contact_mobilisations(&snap, &ContactClass::WallNamed(w.to_string())).unwrap()
        })
        .map(|(_, m)| m)
        .collect();
    // all walls: the bottom contact has no friction force (m = 0)
    assert_eq!(
        contact_mobilisations(&snap, &ContactClass::Wall)
            .unwrap()
            .len(),
        61
    );
    let stats = mobilisation_stats(&wall_m, 10, COULOMB_LIMIT).unwrap();
    assert_eq!(stats.contacts, 60);
    assert_eq!(stats.at_limit, 20);
    assert!((stats.fraction_at_limit.unwrap() - 1.0 / 3.0).abs() < 1e-15);
    assert_eq!(stats.histogram.counts[9], 20); // m = 1 is in the last, closed bin
    assert_eq!(stats.histogram.counts[5], 40); // m = 0.5
    let bulk = contact_mobilisations(&snap, &ContactClass::Bulk).unwrap();
    assert_eq!(bulk.len(), n - 1);
    assert!(bulk.iter().all(|(_, m)| *m == 0.0));
    let by_depth = fraction_at_limit_by_depth(
        &snap,
        &ContactClass::WallNamed("left".into()),
        &bins,
        COULOMB_LIMIT,
    )
    .unwrap();
    for (k, f) in by_depth.iter().enumerate() {
        assert_eq!(*f, Some(if n - 1 - k < 10 { 1.0 } else { 0.0 }));
    }
    assert!(contact_mobilisations(&snap, &ContactClass::WallNamed("nope".into())).is_err());
}

#[test]
fn cannonball_stack_loads_the_bottom_with_its_whole_weight() {
    // frictionless walls carry nothing vertical: bottom stress = 3 m g / (4 r)
    let r = 0.01;
    let snap = support::cannonball(r, 1000.0);
    for b in snap.bodies.iter().filter(|b| b.radius > 0.0) {
        assert!(b.acceleration.norm() < 1e-12, "{}", b.acceleration);
    }
    let w = weight(&snap);
    let p = plane_stress_profile(&snap, &[0.5 * r, 1.5 * r], None).unwrap();
    assert!((p[0].width - 4.0 * r).abs() < 1e-15);
    assert!((p[0].sigma_yy + w / (4.0 * r)).abs() < 1e-12 * w / r);
    // above the bottom disks' centres only the top disk's weight crosses
    assert!((p[1].sigma_yy + w / 3.0 / (4.0 * r)).abs() < 1e-12 * w / r);
    let axis = DepthAxis::new(v(0.0, -1.0), v(0.0, 4.0 * r)).unwrap();
    let bins = DepthBins::new(axis, 4.0 * r, 1).unwrap();
    let left = wall_stress_profile(&snap, "left", &bins).unwrap();
    assert!(left[0].shear_stress.abs() < 1e-15);
    assert!(left[0].friction().unwrap().abs() < 1e-15);
    assert!(wall_stress_profile(&snap, "middle", &bins).is_err());
    // a depth axis across the bottom wall is refused
    assert!(wall_stress_profile(&snap, "bottom", &bins).is_err());
}
