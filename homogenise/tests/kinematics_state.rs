//! Strain rate by affine fit, wall-driven shear, near-wall profiles, solid fraction,
//! coordination with rattlers, fabric, and the border weighting of regions.

mod support;

use dem::math::Tensor;
use homogenise::kinematics::{
    shear_rate, velocity_gradient, wall_driven_velocity_gradient, VelocityWeight,
};
use homogenise::state::{coordination, fabric, rattlers, solid_fraction, ContactCounting};
use homogenise::stress::{grain_stresses, mean_stress};
use homogenise::walls::{near_wall_profile, NearWallSpec};
use homogenise::Region;
use support::{rel, v, Builder};

#[test]
fn affine_fit_recovers_an_exact_velocity_gradient() {
    let mut snap = support::random_dynamic(1, 9, 7, v(0.5, -0.2));
    let l = Tensor::new(0.7, -2.3, 1.1, -0.4);
    let v0 = v(0.05, -0.02);
    for b in snap.bodies.iter_mut().filter(|b| b.radius > 0.0) {
        b.velocity = v0 + l * b.position;
    }
    for weight in [VelocityWeight::Uniform, VelocityWeight::Mass] {
        for region in [
            Region::Whole,
            Region::Rectangle {
                min: v(0.503, -0.197),
                max: v(0.515, -0.188),
            },
        ] {
            let fit = velocity_gradient(&snap, &region, weight).unwrap();
            assert!(rel(&fit.gradient, &l) < 1e-10, "{}", fit.gradient);
            assert!(fit.rms_residual < 1e-12);
            let v_at_mean = v0 + l * fit.mean_position;
            assert!((fit.mean_velocity - v_at_mean).norm() < 1e-10);
            assert!(rel(&fit.strain_rate(), &((l + l.transpose()) * 0.5)) < 1e-10);
            assert!(rel(&(fit.strain_rate() + fit.spin()), &l) < 1e-10);
        }
    }
}

#[test]
fn shear_rate_definition() {
    // simple shear v_x = γ̇ y: D = [[0, γ̇/2], [γ̇/2, 0]] → γ̇; pure shear diag(ε, −ε) → 2ε;
    // isotropic expansion and rigid rotation → 0
    assert!((shear_rate(&Tensor::new(0.0, 3.0, 0.0, 0.0)) - 3.0).abs() < 1e-15);
    assert!((shear_rate(&Tensor::new(0.5, 0.0, 0.0, -0.5)) - 1.0).abs() < 1e-15);
    assert!(shear_rate(&Tensor::new(2.0, 0.0, 0.0, 2.0)).abs() < 1e-15);
    assert!(shear_rate(&Tensor::new(0.0, -1.0, 1.0, 0.0)).abs() < 1e-15);
}

/// Grains in `layers` rows on a bottom wall moving at `u_wall`, velocity
/// `u_wall + slip + γ̇ (y − r)` along x, periodic in x; each bottom grain pushed by the wall
/// with `(f_n, f_t)`.
fn sheared_layers(clump: bool, periodic: bool) -> (dem::snapshot::Snapshot, f64, f64, f64) {
    let (r, cols, layers) = (1e-3, 10usize, 6usize);
    let (u_wall, slip, rate) = (0.2, 0.03, 40.0);
    let mut b = Builder::new(v(0.0, -9.81));
    let cell = 2.0 * r * cols as f64;
    if periodic {
        b.snap.periodic_x = Some([0.0, cell]);
    }
    let wall = if clump {
        let centres: Vec<_> = (0..cols).map(|i| v((2 * i + 1) as f64 * r, -r)).collect();
        b.clump_wall("bottom", centres, vec![r; cols])
    } else {
        b.line_wall("bottom", v(0.0, 0.0), v(0.0, 1.0))
    };
    b.snap.bodies[wall as usize].velocity = v(u_wall, 0.0);
    for j in 0..layers {
        for i in 0..cols {
            let y = r + 2.0 * r * j as f64;
            // shift odd columns across the periodic boundary to test the unwrapping
            let x = ((2 * i + 1) as f64 * r + 0.5 * r * j as f64) % cell;
            let id = b.grain(v(x, y), r, 2500.0, 1.0);
            b.motion(id, v(u_wall + slip + rate * (y - r), 0.0), 0.0);
            if j == 0 {
                // f_t t with t = (−1, 0): the wall drags the grains along +x with f_t < 0
                b.contact(wall, id, v(x, 0.0), v(0.0, 1.0), 0.01, -0.004, 0.5);
            }
        }
    }
    (b.finish(), slip, rate, 0.4)
}

#[test]
fn near_wall_profile_slip_and_effective_friction() {
    for clump in [false, true] {
        let (snap, slip, rate, friction) = sheared_layers(clump, true);
        let spec = NearWallSpec {
            wall: "bottom".into(),
            flow_direction: v(1.0, 0.0),
            normal: None,
            bin_width: 2e-3,
            bins: 6,
            first_layer: 2e-3,
        };
        let p = near_wall_profile(&snap, &spec).unwrap();
        assert!((p.normal - v(0.0, 1.0)).norm() < 1e-15);
        assert!(p.surface.abs() < 1e-15);
        assert_eq!(p.first_layer_grains, 10);
        assert!((p.slip_velocity.unwrap() - slip).abs() < 1e-12);
        for (j, u) in p.velocity.iter().enumerate() {
            let expected = slip + rate * (2e-3 * j as f64);
            assert!((u.unwrap() - expected).abs() < 1e-12, "bin {j}");
            assert_eq!(p.grains[j], 10);
        }
        assert!((p.effective_friction.unwrap() - friction).abs() < 1e-12);
        assert!(p.normal_force > 0.0 && p.tangential_force < 0.0);
        // the affine fit and the walls give the shear rate of the bulk
        let fit = velocity_gradient(&snap, &Region::Whole, VelocityWeight::Mass).unwrap();
        assert!(
            (fit.shear_rate() - rate).abs() < 1e-9 * rate,
            "{}",
            fit.shear_rate()
        );
        assert!((fit.gradient[(0, 1)] - rate).abs() < 1e-9 * rate);
    }
    let (snap, ..) = sheared_layers(false, true);
    let bad = NearWallSpec {
        wall: "bottom".into(),
        flow_direction: v(0.0, 1.0),
        normal: None,
        bin_width: 1e-3,
        bins: 3,
        first_layer: 1e-3,
    };
    assert!(near_wall_profile(&snap, &bad).is_err());
}

#[test]
fn wall_driven_strain_rate() {
    let mut b = Builder::new(v(0.0, -9.81));
    b.line_wall("bottom", v(0.0, 0.0), v(0.0, 1.0));
    let top = b.line_wall("top", v(0.3, 0.02), v(0.0, -1.0));
    b.snap.bodies[top as usize].velocity = v(0.1, 0.0);
    b.grain(v(0.01, 0.01), 1e-3, 2500.0, 1.0);
    let snap = b.finish();
    let l = wall_driven_velocity_gradient(&snap, "bottom", "top", None).unwrap();
    assert!(rel(&l, &Tensor::new(0.0, 5.0, 0.0, 0.0)) < 1e-14);
    assert!((shear_rate(&l) - 5.0).abs() < 1e-13);
    assert!(wall_driven_velocity_gradient(&snap, "bottom", "lid", None).is_err());
    // clumps need their normal
    let mut b = Builder::new(v(0.0, -9.81));
    b.clump_wall("bottom", vec![v(0.0, 0.0)], vec![1e-3]);
    let top = b.clump_wall("top", vec![v(0.0, 0.01)], vec![1e-3]);
    b.snap.bodies[top as usize].velocity = v(-0.02, 0.0);
    let snap = b.finish();
    assert!(wall_driven_velocity_gradient(&snap, "bottom", "top", None).is_err());
    let l = wall_driven_velocity_gradient(&snap, "bottom", "top", Some(v(0.0, 2.0))).unwrap();
    assert!((l[(0, 1)] + 2.0).abs() < 1e-12);
}

#[test]
fn too_few_or_aligned_grains_are_reported() {
    let (snap, ..) = sheared_layers(false, false);
    // one layer only: all grains at the same height, the y gradient is undetermined
    let one_row = Region::Slice {
        y_min: 0.0,
        y_max: 1e-3,
    };
    let e = velocity_gradient(&snap, &one_row, VelocityWeight::Uniform);
    assert!(
        matches!(e, Err(homogenise::HomogeniseError::NotEnoughData(_))),
        "{e:?}"
    );
}

#[test]
fn solid_fraction_coordination_and_fabric_of_a_column() {
    let n = 12;
    let r = 1e-3;
    let snap = support::column(n, r, 2500.0, 1.0, 0.3, 0.01, &vec![0.001; n]);
    let whole = solid_fraction(&snap, &Region::Whole).unwrap();
    assert!((whole - std::f64::consts::PI / 4.0).abs() < 1e-14);
    // a window cutting disks through their centres keeps π/4 (square lattice, exact weights)
    let cut = Region::Rectangle {
        min: v(0.0, 3.0 * r),
        max: v(2.0 * r, 9.0 * r),
    };
    assert!((solid_fraction(&snap, &cut).unwrap() - std::f64::consts::PI / 4.0).abs() < 1e-14);

    let counting = ContactCounting::default();
    let c = coordination(&snap, &Region::Whole, &counting).unwrap();
    // every disk: two side walls, below, above; the top one has no disk above
    let z = (4.0 * (n - 1) as f64 + 3.0) / n as f64;
    assert!((c.z - z).abs() < 1e-14 && (c.z_without_rattlers - z).abs() < 1e-14);
    assert_eq!(c.rattler_fraction, 0.0);
    let no_walls = ContactCounting {
        count_wall_contacts: false,
        ..counting
    };
    let c = coordination(&snap, &Region::Whole, &no_walls).unwrap();
    assert!((c.z - (2.0 * (n - 1) as f64) / n as f64).abs() < 1e-14);

    // fabric: 2n horizontal wall contacts and n vertical ones: F = diag(2/3, 1/3)
    let f = fabric(&snap, &Region::Whole, &counting).unwrap();
    assert_eq!(f.contacts, 3 * n);
    assert!(rel(&f.tensor, &Tensor::new(2.0 / 3.0, 0.0, 0.0, 1.0 / 3.0)) < 1e-14);
    assert!((f.anisotropy - 2.0 / 3.0).abs() < 1e-14 && f.major_angle.abs() < 1e-14);
    let f = fabric(&snap, &Region::Whole, &no_walls).unwrap();
    assert!((f.anisotropy - 2.0).abs() < 1e-14);
    assert!((f.major_angle - std::f64::consts::FRAC_PI_2).abs() < 1e-14);
}

#[test]
fn rattlers_are_removed_iteratively() {
    // G1 on the bottom wall against the left wall and touching G2; G2 touches G1 and G3;
    // G3 touches only G2. G3 is a rattler, then G2 (one contact left); G1 keeps two walls.
    let mut b = Builder::new(v(0.0, -9.81));
    let left = b.line_wall("left", v(0.0, 0.0), v(1.0, 0.0));
    let bottom = b.line_wall("bottom", v(0.0, 0.0), v(0.0, 1.0));
    let r = 1e-3;
    let g1 = b.grain(v(r, r), r, 2500.0, 1.0);
    let g2 = b.grain(v(3.0 * r, r), r, 2500.0, 1.0);
    let g3 = b.grain(v(5.0 * r, r), r, 2500.0, 1.0);
    let g4 = b.grain(v(9.0 * r, r), r, 2500.0, 1.0); // no contact at all
    b.contact(bottom, g1, v(r, 0.0), v(0.0, 1.0), 0.1, 0.0, 0.5);
    b.contact(left, g1, v(0.0, r), v(1.0, 0.0), 0.1, 0.0, 0.5);
    b.contact(g1, g2, v(2.0 * r, r), v(1.0, 0.0), 0.1, 0.0, 0.5);
    b.contact(g2, g3, v(4.0 * r, r), v(1.0, 0.0), 0.1, 0.0, 0.5);
    b.contact(g3, g4, v(7.0 * r, r), v(1.0, 0.0), 0.0, 0.0, 0.5); // open: carries nothing
    let snap = b.finish();
    let counting = ContactCounting::default();
    let rat = rattlers(&snap, &counting).unwrap();
    assert_eq!(
        [
            rat[g1 as usize],
            rat[g2 as usize],
            rat[g3 as usize],
            rat[g4 as usize]
        ],
        [false, true, true, true]
    );
    assert!(!rat[left as usize] && !rat[bottom as usize]);
    let c = coordination(&snap, &Region::Whole, &counting).unwrap();
    assert!((c.z - (3.0 + 2.0 + 1.0 + 0.0) / 4.0).abs() < 1e-14);
    assert!((c.z_without_rattlers - 2.0).abs() < 1e-14);
    assert!((c.rattler_fraction - 0.75).abs() < 1e-14);
    // a force threshold above 0.1 N leaves every grain a rattler
    let high = ContactCounting {
        force_threshold: 0.2,
        ..counting
    };
    assert!(
        (coordination(&snap, &Region::Whole, &high)
            .unwrap()
            .rattler_fraction
            - 1.0)
            .abs()
            < 1e-15
    );
    let bad = ContactCounting {
        force_threshold: f64::NAN,
        ..counting
    };
    assert!(rattlers(&snap, &bad).is_err());
}

#[test]
fn grains_cut_by_the_border_count_by_their_area_fraction() {
    let r = rolling_like();
    let g = grain_stresses(&r).unwrap();
    let c = g[0].position;
    let a = g[0].radius;
    // the right half of the disk lies in the rectangle
    let half = Region::Rectangle {
        min: v(c.x, c.y - 1.0),
        max: v(c.x + 2.0, c.y + 1.0),
    };
    let m = mean_stress(&r, &g, &half).unwrap();
    assert!((m.grains - 0.5).abs() < 1e-14);
    let expected: Tensor = g[0].total * (0.5 * std::f64::consts::PI * a * a / 4.0);
    assert!(rel(&m.total, &expected) < 1e-13);
    // a quarter
    let quarter = Region::Rectangle {
        min: c,
        max: c + v(2.0, 2.0),
    };
    assert!((mean_stress(&r, &g, &quarter).unwrap().grains - 0.25).abs() < 1e-14);
}

fn rolling_like() -> dem::snapshot::Snapshot {
    support::rolling_disk(0.4, 0.05, 2000.0, 0.3, false, v(0.0, 0.0)).snap
}

#[test]
fn periodic_images_are_counted() {
    let mut b = Builder::new(v(0.0, -9.81));
    b.snap.periodic_x = Some([0.0, 0.1]);
    let r = 0.01;
    b.grain(v(0.0, 0.5), r, 1000.0, 1.0); // centre on the cell's edge
    b.grain(v(0.05, 0.5), r, 1000.0, 1.0);
    let snap = b.finish();
    let rect = Region::Rectangle {
        min: v(0.08, 0.0),
        max: v(0.1, 1.0),
    }
    .resolve(&snap)
    .unwrap();
    assert!((rect.disk_fraction(&v(0.0, 0.5), r) - 0.5).abs() < 1e-14);
    assert!((rect.disk_fraction(&v(0.1, 0.5), r) - 0.5).abs() < 1e-14);
    assert!((rect.disk_fraction(&v(-0.1, 0.5), r) - 0.5).abs() < 1e-14);
    // a slice spans the cell: both disks count whole; φ = 2 π r² / (0.1 × 0.04)
    let slice = Region::Slice {
        y_min: 0.48,
        y_max: 0.52,
    };
    let phi = solid_fraction(&snap, &slice).unwrap();
    assert!((phi - 2.0 * std::f64::consts::PI * r * r / (0.1 * 0.04)).abs() < 1e-13);
    // a rectangle across the boundary, expressed either side of it
    let a = Region::Rectangle {
        min: v(-0.02, 0.0),
        max: v(0.02, 1.0),
    };
    let b2 = Region::Rectangle {
        min: v(0.08, 0.0),
        max: v(0.12, 1.0),
    };
    let (fa, fb) = (
        solid_fraction(&snap, &a).unwrap(),
        solid_fraction(&snap, &b2).unwrap(),
    );
    assert!((fa - fb).abs() < 1e-14 && (fa - std::f64::consts::PI * r * r / 0.04).abs() < 1e-13);
}

#[test]
fn the_whole_of_a_biperiodic_cell_is_the_cell() {
    // A tilted cell h = [[10, 4], [0, 8]] (area 80) holding three disks of radius 1, one of
    // them across its top edge and one past its bounding box's left side: the whole sample is
    // the cell, each disk counted whole once (φ = 3π/80), not the disks' bounding box; a
    // slice across the cell is periodic along x with the period 10.
    let mut b = Builder::new(v(0.0, 0.0));
    for p in [v(5.0, 4.0), v(7.0, 7.6), v(0.9, 0.5)] {
        b.grain(p, 1.0, 1.0, 1.0);
    }
    let mut snap = b.finish();
    let h = Tensor::new(10.0, 4.0, 0.0, 8.0);
    snap.cell = Some(dem::cell::Cell::new(h, Tensor::zeros()).unwrap());
    let phi = solid_fraction(&snap, &Region::Whole).unwrap();
    assert!(
        (phi - 3.0 * std::f64::consts::PI / 80.0).abs() < 1e-15,
        "{phi}"
    );
    let rect = Region::Whole.resolve(&snap).unwrap();
    assert_eq!(rect.area(), 80.0);
    // the slice 0 ≤ y ≤ 2 across the cell: the disk at (0.9, 0.5) wholly inside but for its
    // part below y = 0 (x wrapped by the period, so its left part at x < 0 counts too)
    let slice = Region::Slice {
        y_min: 0.0,
        y_max: 2.0,
    }
    .resolve(&snap)
    .unwrap();
    assert_eq!(slice.periodic_x, Some([0.0, 10.0]));
    let w = slice.disk_fraction(&v(0.9, 0.5), 1.0);
    // the circular segment below y = 0 at distance 0.5 from the centre: r² acos(d) − d√(1−d²)
    let seg = 0.5f64.acos() - 0.5 * (1.0f64 - 0.25).sqrt();
    assert!(
        (w - (1.0 - seg / std::f64::consts::PI)).abs() < 1e-12,
        "{w}"
    );
}
