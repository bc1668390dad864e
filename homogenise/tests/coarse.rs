//! Gaussian coarse-grained fields: mass conservation, uniform velocity, stress total.

mod support;

use dem::math::Tensor;
use homogenise::coarse::{coarse_grain, Grid};
use homogenise::stress::grain_stresses;
use support::v;

#[test]
fn density_integrates_to_the_mass_and_stress_to_its_total() {
    // kernel width w = 1 mm, cutoff 5w, grid spacing w/2 with a margin of 5w:
    // Σ ρ Δ² equals Σ m/t to 1e-6 relative (the sampling error of the kernel's kink at r_c)
    let mut snap = support::random_dynamic(2, 8, 6, v(0.0, 0.0));
    let u = v(0.12, -0.03);
    for b in snap.bodies.iter_mut().filter(|b| b.radius > 0.0) {
        b.velocity = u;
    }
    let g = grain_stresses(&snap).unwrap();
    let w = 1e-3;
    let grid = Grid::covering(&snap, 0.5 * w, 5.0 * w).unwrap();
    let f = coarse_grain(&snap, &g, &grid, w, 5.0).unwrap();
    let mass: f64 = snap
        .bodies
        .iter()
        .filter(|b| b.radius > 0.0)
        .map(|b| b.mass / b.thickness)
        .sum();
    let rel_mass = (f.mass_per_thickness() - mass).abs() / mass;
    assert!(rel_mass < 1e-6, "{rel_mass}");
    // uniform grain velocity: the field is that velocity wherever there is mass, and the
    // kinetic stress vanishes
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            if f.density[[j, i]] > 0.0 {
                assert!((f.velocity_x[[j, i]] - u.x).abs() < 1e-12);
                assert!((f.velocity_y[[j, i]] - u.y).abs() < 1e-12);
                assert!(f.kinetic_stress.at(i, j).norm() < 1e-12 * f.density[[j, i]]);
            }
        }
    }
    // ∫ σ dA = Σ_p A_p Σ_p
    let total: Tensor = g.iter().map(|p| p.total * p.area()).sum();
    let mut sum = Tensor::zeros();
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            sum += f.stress.at(i, j) * (grid.spacing * grid.spacing);
        }
    }
    assert!(
        support::rel(&sum, &total) < 1e-6,
        "{}",
        support::rel(&sum, &total)
    );
}

#[test]
fn periodic_coarse_graining_conserves_mass_and_sees_shear() {
    // a periodic sheared bed: density integral exact to 1e-6, velocity profile linear in the bulk
    let mut b = support::Builder::new(v(0.0, -9.81));
    let (r, cols, layers) = (1e-3, 6usize, 20usize);
    let cell = 2.0 * r * cols as f64;
    b.snap.periodic_x = Some([0.0, cell]);
    let rate = 10.0;
    for j in 0..layers {
        for i in 0..cols {
            let y = r + 2.0 * r * j as f64;
            let id = b.grain(v((2 * i) as f64 * r, y), r, 2500.0, 1.0);
            b.motion(id, v(rate * y, 0.0), 0.0);
        }
    }
    let snap = b.finish();
    let g = grain_stresses(&snap).unwrap();
    let w = 2e-3;
    let grid = Grid::covering(&snap, 0.5e-3, 5.0 * w).unwrap();
    assert!((grid.spacing * grid.nx as f64 - cell).abs() < 1e-15);
    let f = coarse_grain(&snap, &g, &grid, w, 5.0).unwrap();
    let mass: f64 = snap.bodies.iter().map(|b| b.mass).sum();
    assert!((f.mass_per_thickness() - mass).abs() < 1e-6 * mass);
    // more than r_c = 10 mm inside the bed, the kernel (w = layer spacing, 5 w wider than the
    // 12 mm cell: several images) gives the linear velocity profile to 1e-6 relative
    let mut checked = 0;
    for j in 0..grid.ny {
        let y = grid.node(0, j).y;
        if y > 11e-3 && y < 29e-3 {
            for i in 0..grid.nx {
                let u = f.velocity_x[[j, i]];
                assert!((u - rate * y).abs() < 1e-6 * rate * y, "y = {y}: {u}");
                checked += 1;
            }
        }
    }
    assert!(checked > 100);
    assert!(coarse_grain(&snap, &g, &grid, w, 1.0).is_err());
    assert!(coarse_grain(&snap, &g, &grid, -1.0, 4.0).is_err());
}
