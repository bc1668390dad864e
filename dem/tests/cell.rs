//! The biperiodic deformable cell (`dem::cell`): its kinematics against closed forms, the
//! minimum image against a brute-force search, contacts across the corner of the cell, the
//! basis change, the energy balance and the mixed stress control.

mod common;

use dem::cell::{Cell, CellControl, Imposed, Shift};
use dem::math::{Tensor, Vector};
use dem::{ContactLaws, SolverParams, World, WorldParams};
use nalgebra::Vector2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn params(dt: f64) -> WorldParams {
    WorldParams {
        dt,
        gravity: Vector2::zeros(),
        detection_gap: 1e-5,
        solver: SolverParams {
            tolerance: 1e-12,
            max_iterations: 20_000,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Constant `L = [[a, γ], [0, b]]`: `h(t) = exp(L t) h₀` with
/// `exp(L t) = [[e^{at}, γ (e^{at} − e^{bt})/(a − b)], [0, e^{bt}]]`; 1000 steps of
/// `h ← exp(L Δt) h` agree with it to 10⁻¹² (relative to the cell size).
#[test]
fn empty_cell_deforms_as_l_says() {
    let (a, g, b) = (0.3, 1.7, -0.2);
    let h0 = Tensor::new(0.02, 0.005, 0.0, 0.03);
    let mut cell = Cell::new(h0, Tensor::new(a, g, 0.0, b)).unwrap();
    let (dt, n) = (1e-3, 1000);
    for _ in 0..n {
        cell.advance(dt);
    }
    let t = dt * n as f64;
    let e = Tensor::new(
        (a * t).exp(),
        g * ((a * t).exp() - (b * t).exp()) / (a - b),
        0.0,
        (b * t).exp(),
    );
    let exact = e * h0;
    let err = (cell.h - exact).abs().max() / h0.abs().max();
    assert!(err < 1e-12, "relative error {err:e}");
    // Simple shear: L nilpotent, the tilt grows by exactly γ̇ t (Lees–Edwards offset).
    let mut le = Cell::new(
        Tensor::new(0.02, 0.0, 0.0, 0.03),
        Tensor::new(0.0, 2.0, 0.0, 0.0),
    )
    .unwrap();
    for _ in 0..100 {
        le.advance(1e-3);
    }
    assert!((le.h[(0, 1)] - 2.0 * 0.1 * 0.03).abs() < 1e-12 * 0.03);
    assert!((le.volume() - 0.02 * 0.03).abs() < 1e-12 * 0.02 * 0.03);
}

/// A random reduced cell: sides in [0.5, 2], tilt in [−½, ½], a small rotation.
fn random_cell(rng: &mut ChaCha8Rng) -> Cell {
    let (lx, ly) = (rng.random_range(0.5..2.0), rng.random_range(0.5..2.0));
    let tilt = rng.random_range(-0.5..0.5);
    let h = Tensor::new(lx, tilt * lx, 0.0, ly);
    Cell::new(h, Tensor::zeros()).unwrap()
}

/// The minimum image across both boundaries of a sheared cell is the shortest of the 9 images
/// `x_j − x_i + h k`, k ∈ {−1, 0, 1}², of points wrapped into the cell: same length to 10⁻¹²
/// (1000 random cells and pairs).
#[test]
fn minimum_image_matches_brute_force() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for _ in 0..1000 {
        let cell = random_cell(&mut rng);
        let p = |rng: &mut ChaCha8Rng| {
            let x = cell.h * Vector::new(rng.random_range(-1.5..2.5), rng.random_range(-1.5..2.5));
            cell.wrap(&x).0
        };
        let (xi, xj) = (p(&mut rng), p(&mut rng));
        for x in [xi, xj] {
            let s = cell.reduced(&x);
            assert!(
                (0.0..1.0).contains(&s.x) && (0.0..1.0).contains(&s.y),
                "{s:?}"
            );
        }
        let (d, k) = cell.min_image(&(xj - xi));
        assert!((d - (xj - xi + cell.shift_vector(&k))).norm() < 1e-15);
        let mut best = f64::INFINITY;
        for i in -1..=1 {
            for j in -1..=1 {
                best = best.min((xj - xi + cell.shift_vector(&Shift::new(i, j))).norm());
            }
        }
        assert!(
            (d.norm() - best).abs() < 1e-12,
            "min image {} vs brute force {best}",
            d.norm()
        );
    }
}

/// Two equal disks of a cell `cell`, `a` at `xa`, `b` at `xb`, with velocities `va`, `vb`.
fn pair(cell: Cell, xa: Vector, xb: Vector, va: Vector, vb: Vector) -> World {
    let mut w = World::new(params(1e-4), ContactLaws::new(&["g"], 0.4));
    let a = w.add_grain(xa, 1e-3, 2500.0, 0) as usize;
    let b = w.add_grain(xb, 1e-3, 2500.0, 0) as usize;
    w.bodies[a].velocity = va;
    w.bodies[b].velocity = vb;
    w.set_cell(Some(cell)).unwrap();
    w
}

/// Two grains colliding across the corner of a sheared cell (their contact crosses both
/// boundaries) get the same impulse and velocities after the step as the same pair inside the
/// cell, with the same velocities relative to the affine field: to 10⁻¹² relative.
#[test]
fn contact_across_the_corner_equals_inside() {
    let gd = 5.0;
    let cell = Cell::new(
        Tensor::new(0.02, 0.004, 0.0, 0.02),
        Tensor::new(0.0, gd, 0.0, 0.0),
    )
    .unwrap();
    // Branch from a to b: (1.4, 1.3) mm, overlapping gap −0.0... closed within the step.
    let branch = Vector::new(1.45e-3, 1.35e-3);
    let fluct_a = Vector::new(0.02, 0.01);
    let fluct_b = Vector::new(-0.03, -0.02);
    let run = |xa: Vector| {
        let xb = xa + branch;
        let va = fluct_a + cell.affine_velocity(&xa);
        // The image of b at xb moves with the affine velocity at xb.
        let vb = fluct_b + cell.affine_velocity(&xb);
        let (xbw, k) = cell.wrap(&xb);
        let mut w = pair(cell, xa, xbw, va, vb + cell.image_velocity(&k));
        w.step().unwrap();
        let c = w.contacts();
        assert_eq!(c.len(), 1);
        let r = c.rows[0].r;
        let dv = w.bodies[1].velocity - w.bodies[0].velocity;
        (r, k, dv, c.geometry[0].gap)
    };
    // Near the upper-right corner of the tilted cell: b's centre lies beyond both faces.
    let corner = cell.h * Vector::new(0.98, 0.97);
    let (r_corner, k, dv_c, gap_c) = run(corner);
    assert_eq!(k, Shift::new(-1, -1), "the pair must cross both boundaries");
    let middle = cell.h * Vector::new(0.4, 0.4);
    let (r_mid, k0, dv_m, gap_m) = run(middle);
    assert_eq!(k0, Shift::zeros());
    assert!(r_mid[0] > 0.0, "the pair must collide: {r_mid:?}");
    let scale = r_mid[0].abs().max(r_mid[1].abs());
    for d in 0..2 {
        assert!(
            (r_corner[d] - r_mid[d]).abs() < 1e-12 * scale,
            "impulse {r_corner:?} vs {r_mid:?}"
        );
    }
    assert!((gap_c - gap_m).abs() < 1e-15);
    // Relative velocity after the step, minus the affine one across the branch (the corner
    // pair's b velocity is that of the wrapped grain, L h k higher).
    let affine = cell.l * branch;
    let rel_c = dv_c - cell.image_velocity(&k) - affine;
    let rel_m = dv_m - affine;
    assert!(
        (rel_c - rel_m).norm() < 1e-12 * rel_m.norm().max(1e-3),
        "{rel_c} vs {rel_m}"
    );
}

/// A basis change of a cell tilted beyond half a period keeps every pair distance (shortest
/// image) to 10⁻¹² of the cell size, and every grain inside the new cell.
#[test]
fn remap_preserves_pair_distances() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut cell = Cell::new(
        Tensor::new(1.0, 0.0, 0.0, 1.2),
        Tensor::new(0.0, 1.0, 0.0, 0.0),
    )
    .unwrap();
    let pts: Vec<Vector> = (0..60)
        .map(|_| cell.h * Vector::new(rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)))
        .collect();
    // Shear to a tilt of 0.84 (beyond ½), moving the points affinely.
    let h0 = cell.h;
    cell.advance(0.7);
    let f = cell.h * h0.try_inverse().unwrap();
    let pts: Vec<Vector> = pts.iter().map(|x| f * x).collect();
    let brute = |c: &Cell, a: &Vector, b: &Vector| {
        let mut best = f64::INFINITY;
        for i in -3..=3 {
            for j in -3..=3 {
                best = best.min((b - a + c.shift_vector(&Shift::new(i, j))).norm());
            }
        }
        best
    };
    let before: Vec<f64> = pts
        .iter()
        .enumerate()
        .flat_map(|(i, a)| pts[i + 1..].iter().map(move |b| (a, b)))
        .map(|(a, b)| brute(&cell, a, b))
        .collect();
    assert!((cell.tilt() - 0.84).abs() < 1e-12);
    assert_eq!(cell.remap(), 1);
    assert!(cell.tilt().abs() <= 0.5);
    let wrapped: Vec<Vector> = pts.iter().map(|x| cell.wrap(x).0).collect();
    let after: Vec<f64> = wrapped
        .iter()
        .enumerate()
        .flat_map(|(i, a)| wrapped[i + 1..].iter().map(move |b| (a, b)))
        .map(|(a, b)| cell.min_image(&(b - a)).0.norm())
        .collect();
    for (x, y) in before.iter().zip(&after) {
        assert!((x - y).abs() < 1e-12, "{x} vs {y}");
    }
    for x in &wrapped {
        let s = cell.reduced(x);
        assert!((0.0..1.0).contains(&s.x) && (0.0..1.0).contains(&s.y));
    }
}

/// A loose polydisperse packing of `n` disks (radius 1 mm ± 20 %) on a jittered square lattice
/// in a square cell, at rest.
fn packing(n_side: usize, seed: u64, mu: f64) -> World {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let spacing = 2.6e-3;
    let side = spacing * n_side as f64;
    let mut w = World::new(params(2e-4), ContactLaws::new(&["g"], mu));
    for i in 0..n_side {
        for j in 0..n_side {
            let r = 1e-3 * rng.random_range(0.8..1.2);
            let jit = Vector::new(rng.random_range(-0.1..0.1), rng.random_range(-0.1..0.1)) * 1e-3;
            let x = Vector::new(i as f64 + 0.5, j as f64 + 0.5) * spacing + jit;
            w.add_grain(x, r, 2500.0, 0);
        }
    }
    w.set_cell(Some(Cell::rectangle(side, side).unwrap()))
        .unwrap();
    w.validate(0.0).unwrap();
    w
}

/// Lees–Edwards shear under mixed control of 36 grains: a loose packing is first compressed at
/// an imposed strain rate to φ = 0.74, then sheared at γ̇ (I ≈ 0.05) to a strain of 1 with σ_yy = −P
/// imposed and L_xx = 0: the mean σ_yy over the last half of the shear is within 10 % of −P, and the
/// energy balance with the cell's work (`StepReport::cell_work`) has no step gaining more than
/// 10⁻⁶ of the kinetic energy.
#[test]
fn stress_control_reaches_its_target() {
    let p = 100.0;
    let mut w = packing(6, 3, 0.3);
    let (rho, d): (f64, f64) = (2500.0, 2e-3);
    let gd = 0.05 * (p / rho).sqrt() / d;
    let area: f64 = w
        .bodies
        .iter()
        .map(|b| std::f64::consts::PI * b.radius * b.radius)
        .sum();
    let mut worst = 0.0f64;
    let mut step = |w: &mut World| {
        let probe = dem::energy::EnergyProbe::before(w);
        w.step().unwrap();
        let e = w.kinetic_energy().max(probe.kinetic).max(1e-300);
        worst = worst.max(probe.residual(w) / e);
    };
    // Compression at an imposed rate, stopped at φ = 0.74.
    w.set_velocity_gradient(Tensor::new(-gd, 0.0, 0.0, -gd));
    while area / w.cell().unwrap().volume() < 0.74 {
        step(&mut w);
    }
    w.set_velocity_gradient(Tensor::new(0.0, gd, 0.0, 0.0));
    w.cell_control = Some(CellControl {
        xx: Imposed::Rate(0.0),
        yy: Imposed::Stress(-p),
        xy: Imposed::Rate(gd),
        gain: 0.3 * w.params.dt / (rho * d * d),
        max_rate: gd,
        relaxation: 0.0,
        tolerance: 0.5 * p,
        max_corrections: 12,
        implicit: false,
        affine: false,
    });
    w.validate(1e-4 * d).unwrap();
    let steps = (1.0 / (gd * w.params.dt)) as usize;
    let (mut syy, mut k) = (0.0, 0);
    for s in 0..steps {
        step(&mut w);
        if s >= steps / 2 {
            syy += w.cell_stress().unwrap()[(1, 1)];
            k += 1;
        }
    }
    let syy = syy / k as f64;
    assert!((syy + p).abs() < 0.1 * p, "σ_yy = {syy} Pa, target {}", -p);
    assert!(
        worst < 1e-6,
        "energy residual / kinetic energy up to {worst:e}"
    );
}

/// A square lattice of 5 × 4 equal frictionless touching disks (radius R) filling a periodic cell at rest,
/// with σ_xx = −p_x and σ_yy = −p_y imposed by the implicit control (L_xy = 0): a rigid
/// lattice cannot deform, so the cell stays at rest (|L| ≤ 10⁻⁹ of the rate cap) and the
/// contacts carry the imposed stress exactly: the image contacts across x sum to
/// `p_x L_y h`, those across y to `p_y L_x h` (statics of the cell, 10⁻¹⁰ relative), every
/// chain carries one force along its length (equilibrium of each grain), and no grain moves
/// (≤ 10⁻¹² m/s) — over 20 steps. With `L` fixed during the step (the explicit law) this
/// problem has no bounded solution once the target moves the cell inward.
#[test]
fn implicit_control_holds_a_rigid_lattice_at_its_stress() {
    let (r, nx, ny) = (1e-3, 5usize, 4usize);
    let (lx, ly) = (2.0 * r * nx as f64, 2.0 * r * ny as f64);
    let (px, py) = (100.0, 300.0);
    // Frictionless: with friction, the tangential impulses of one direction's contacts could
    // carry a self-stress between the chains of the other (hyperstatic), so the chain forces
    // would not be unique.
    let mut w = World::new(params(1e-4), ContactLaws::new(&["g"], 0.0));
    for i in 0..nx {
        for j in 0..ny {
            w.add_grain(
                Vector::new((2 * i + 1) as f64 * r, (2 * j + 1) as f64 * r),
                r,
                2500.0,
                0,
            );
        }
    }
    w.set_cell(Some(Cell::rectangle(lx, ly).unwrap())).unwrap();
    let max_rate = 1.0;
    w.cell_control = Some(CellControl::implicit_law(
        Imposed::Stress(-px),
        Imposed::Stress(-py),
        Imposed::Rate(0.0),
        10.0 * max_rate / py,
        max_rate,
    ));
    w.validate(1e-12).unwrap();
    let thickness = w.bodies[0].thickness;
    let h = w.params.dt;
    for _ in 0..20 {
        let rep = w.step().unwrap();
        assert!(rep.solver.converged, "{:?}", rep.solver);
        let l = w.cell().unwrap().l;
        assert!(l.abs().max() < 1e-9 * max_rate, "L = {l}");
        let c = w.contacts();
        let (mut sx, mut sy) = (0.0, 0.0);
        for (row, geo) in c.rows.iter().zip(&c.geometry) {
            let fx = row.r[0] * row.n[0] - row.r[1] * row.n[1];
            let fy = row.r[0] * row.n[1] + row.r[1] * row.n[0];
            sx += fx * geo.image[0];
            sy += fy * geo.image[1];
        }
        let (ex, ey) = (px * ly * thickness * h * lx, py * lx * thickness * h * ly);
        assert!((sx - ex).abs() < 1e-10 * ex, "x: {sx:e} vs {ex:e}");
        assert!((sy - ey).abs() < 1e-10 * ey, "y: {sy:e} vs {ey:e}");
        // One normal impulse along each chain.
        for row in &c.rows {
            let horizontal = row.n[0].abs() > 0.5;
            let twin = c
                .rows
                .iter()
                .find(|o| {
                    (o.n[0].abs() > 0.5) == horizontal
                        && (o.b == row.a || o.a == row.b || o.a == row.a || o.b == row.b)
                        && !std::ptr::eq(*o, row)
                })
                .unwrap();
            assert!(
                (row.r[0] - twin.r[0]).abs() < 1e-10 * row.r[0].abs().max(twin.r[0].abs()),
                "chain impulses {} vs {}",
                row.r[0],
                twin.r[0]
            );
        }
        for b in &w.bodies {
            assert!(b.velocity.norm() < 1e-12 && b.omega.abs() < 1e-9, "{b:?}");
        }
    }
}

/// The frictional packing of 36 disks (μ = 0.5) compressed isotropically to `p` under the
/// implicit control for 1500 exact steps (Lemke's method where the sweeps stall), with the
/// control's axial rate `ε̇`, rate cap and gain: `(world, ε̇, ε̇_max, g)`.
fn compressed_frictional_cell(p: f64) -> (World, f64, f64, f64) {
    let mut w = packing(6, 5, 0.5);
    let (rho, d): (f64, f64) = (2500.0, 2e-3);
    let rate = 1e-3 * (p / rho).sqrt() / d;
    let max_rate = 20.0 * rate;
    let gain = 10.0 * max_rate / p;
    // Isotropic compression to P, implicit on both normal components.
    w.cell_control = Some(CellControl::implicit_law(
        Imposed::Stress(-p),
        Imposed::Stress(-p),
        Imposed::Rate(0.0),
        gain,
        max_rate,
    ));
    w.params.solver.tolerance = 1e-9;
    w.params.solver.lemke_max_contacts = 1000;
    for _ in 0..1500 {
        w.step().unwrap();
    }
    (w, rate, max_rate, gain)
}

/// The kinetic stress `σ^kin_xx` of the grains' velocity fluctuations (Pa), as the implicit
/// law takes it at the start of a step (module documentation of `dem::cell_coupling`).
fn kinetic_xx(w: &World) -> f64 {
    let cell = *w.cell().unwrap();
    let thickness = w.bodies[0].thickness;
    let grains: Vec<_> = w.bodies.iter().filter(|b| b.mass > 0.0).collect();
    let c0 = cell.centre();
    let mass: f64 = grains.iter().map(|b| b.mass).sum();
    let mom = grains.iter().fold(Vector::zeros(), |m, b| {
        m + (b.velocity - cell.l * (b.position - c0)) * b.mass
    });
    let mean_v = mom / mass;
    -grains
        .iter()
        .map(|b| {
            let v = b.velocity - cell.l * (b.position - c0) - mean_v;
            b.mass * v.x * v.x
        })
        .sum::<f64>()
        / (cell.volume() * thickness)
}

/// The implicit law holds at every step of a frictional biaxial compression of 36 disks
/// (σ_xx = −P, L_yy = −ε̇ imposed, μ = 0.5), recomputed from the public state alone: after each
/// converged step, `L⁺_xx = clamp(L⁻_xx, ±ε̇_max) + g (σ* − σ⁺)` with
/// `σ⁺ = σ^kin − (1/(hV)) Σ R_x (h k)_x` over the step's image contacts and `σ^kin` the kinetic
/// stress at its start, to 10⁻⁸ of `ε̇_max`; every step converges, and the measured lateral
/// stress (`World::cell_stress`) averages −P within 10 % over the compression.
fn implicit_law_holds_in_a_frictional_compression(affine: bool) {
    let p = 100.0;
    let (mut w, rate, max_rate, gain) = compressed_frictional_cell(p);
    let s = w.cell_stress().unwrap();
    assert!(
        (s[(0, 0)] + p).abs() < 0.2 * p && (s[(1, 1)] + p).abs() < 0.2 * p,
        "isotropic stress {s}"
    );
    let ctl = CellControl::implicit_law(
        Imposed::Stress(-p),
        Imposed::Rate(-rate),
        Imposed::Rate(0.0),
        gain,
        max_rate,
    )
    .with_affine(affine);
    w.cell_control = Some(ctl);
    let thickness = w.bodies[0].thickness;
    let (mut mean, mut n) = (0.0, 0);
    for _ in 0..400 {
        let cell0 = *w.cell().unwrap();
        let kin_xx = kinetic_xx(&w);
        let rep = w.step().unwrap();
        assert!(rep.solver.converged, "{:?}", rep.solver);
        let h = w.params.dt;
        let c = w.contacts();
        let boundary: f64 = c
            .rows
            .iter()
            .zip(&c.geometry)
            .map(|(row, geo)| {
                // The arm the cell's change acts on: the image shift, or the whole branch
                // vector when the grains follow the cell within the step.
                let arm = if affine {
                    geo.lever_a[0] - geo.lever_b[0]
                } else {
                    geo.image[0]
                };
                (row.r[0] * row.n[0] - row.r[1] * row.n[1]) * arm
            })
            .sum();
        let sigma = kin_xx - boundary / (h * cell0.volume() * thickness);
        let want = cell0.l[(0, 0)].clamp(-max_rate, max_rate) + gain * (-p - sigma);
        let got = w.cell().unwrap().l[(0, 0)];
        assert!(
            (got - want).abs() < 1e-8 * max_rate,
            "L_xx {got:e} vs the law's {want:e}"
        );
        assert_eq!(w.cell().unwrap().l[(1, 1)], -rate);
        mean += w.cell_stress().unwrap()[(0, 0)];
        n += 1;
    }
    let mean = mean / n as f64;
    assert!((mean + p).abs() < 0.1 * p, "mean σ_xx = {mean} Pa");
}

#[test]
fn implicit_law_holds_at_every_step_of_a_frictional_compression() {
    implicit_law_holds_in_a_frictional_compression(false);
}

/// The same with the grains following the cell's change within the step
/// (`CellControl::affine`): the law's stress is then the Love–Weber sum over every contact,
/// `σ⁺ = σ^kin − (1/(hV)) Σ_c R_c,x l_c,x` with `l_c` the branch vector between the centres (the
/// image's for a contact across the boundary), which equals the boundary sum above only at
/// equilibrium.
#[test]
fn affine_implicit_law_holds_at_every_step_of_a_frictional_compression() {
    implicit_law_holds_in_a_frictional_compression(true);
}

/// A world under an implicit cell control is never subdivided
/// (`dem::step_control::step_subdivided`): its law is written per step, and applied over
/// sub-steps it ran away on a dilute sheared cell. Even a solve that cannot converge (one sweep
/// to 10⁻³⁰⁰) with `max_halvings = 3` is kept whole, as one step of `h` giving what
/// `World::step` gives; without the cell control the same packing is subdivided 3 times.
#[test]
fn implicit_cell_steps_are_not_subdivided() {
    use dem::step_control::{step_subdivided, Subdivision};
    let p = 100.0;
    let mut w = packing(5, 3, 0.5);
    w.params.solver.max_iterations = 1;
    w.params.solver.tolerance = 1e-300;
    w.params.solver.max_halvings = 3;
    // Compress the lattice into contact first (imposed gradient, no control).
    w.set_velocity_gradient(Tensor::new(-20.0, 0.0, 0.0, -20.0));
    for _ in 0..40 {
        w.step().unwrap();
    }
    assert!(!w.contacts().rows.is_empty());
    let mut plain = w.clone();
    let s = step_subdivided(&mut plain, &mut Subdivision::default()).unwrap();
    assert_eq!(s.halvings, 3, "without the control the step is subdivided");

    w.cell_control = Some(CellControl::implicit_law(
        Imposed::Stress(-p),
        Imposed::Stress(-p),
        Imposed::Rate(0.0),
        1.0,
        1.0,
    ));
    let mut whole = w.clone();
    let h = w.params.dt;
    let t0 = w.time;
    let s = step_subdivided(&mut w, &mut Subdivision::default()).unwrap();
    assert_eq!((s.halvings, s.retries, s.substeps.len()), (0, 0, 1));
    assert!(!s.report.solver.converged);
    let r = whole.step().unwrap();
    assert_eq!(s.report, r);
    assert!((w.time - t0 - h).abs() <= 1e-15);
    for (a, b) in w.bodies.iter().zip(&whole.bodies) {
        assert_eq!(a.position, b.position);
        assert_eq!(a.velocity, b.velocity);
    }
}

/// The last step of a cell under the implicit control solved again
/// (`World::last_step_problem`, `World::snapshot_with_last_impulses`): a frictional biaxial
/// compression of 36 disks whose last step is swept 5 times (far from converged) is solved
/// again to 10⁻¹⁰ with the cell's stress-controlled component eliminated; the state those
/// impulses give keeps the implicit law, recomputed from the public state as in
/// `implicit_law_holds_at_every_step_of_a_frictional_compression`, with the new impulses (to
/// 10⁻⁸ of `ε̇_max`), while the cell's `L_xx` moved by more than 10⁻⁴ of it; the imposed `L_yy`
/// is unchanged; the re-solved snapshot is the state of the same step taken again with a
/// tight solve (L to 10⁻⁸ of the rate cap, velocities to 10⁻³ of the change); the run's own
/// impulses give its own snapshot bit for bit. Under an explicit control the problem is not
/// available.
#[test]
fn a_cell_step_solved_again_keeps_the_implicit_law() {
    use dem::fc::SolverMethod;
    let p = 100.0;
    let (mut w, rate, max_rate, gain) = compressed_frictional_cell(p);
    w.cell_control = Some(CellControl::implicit_law(
        Imposed::Stress(-p),
        Imposed::Rate(-rate),
        Imposed::Rate(0.0),
        gain,
        max_rate,
    ));
    for _ in 0..50 {
        w.step().unwrap();
    }
    // The last step swept 5 times.
    w.params.solver.method = SolverMethod::Nlgs;
    w.params.solver.max_iterations = 5;
    let thickness = w.bodies[0].thickness;
    let cell0 = *w.cell().unwrap();
    let kin_xx = kinetic_xx(&w);
    let point = w.undo_point();
    let rep = w.step().unwrap();
    assert!(!rep.solver.converged, "{:?}", rep.solver);

    let (problem, r) = w.last_step_problem().expect("an implicit cell's step");
    assert_eq!(
        w.snapshot_with_last_impulses(&r).unwrap(),
        w.snapshot(),
        "bit for bit"
    );
    let sol = common::solve_tightly(&problem, &r, 1e-10);
    let snap = w.snapshot_with_last_impulses(&sol.r).unwrap();

    // The implicit law with the new impulses.
    let h = w.params.dt;
    let c = w.contacts();
    let boundary: f64 = c
        .rows
        .iter()
        .zip(&c.geometry)
        .zip(sol.r.chunks_exact(2))
        .map(|((row, geo), x)| (x[0] * row.n[0] - x[1] * row.n[1]) * geo.image[0])
        .sum();
    let sigma = kin_xx - boundary / (h * cell0.volume() * thickness);
    let want = cell0.l[(0, 0)].clamp(-max_rate, max_rate) + gain * (-p - sigma);
    let (run_l, new_l) = (w.cell().unwrap().l, snap.cell.unwrap().l);
    assert!(
        (new_l[(0, 0)] - want).abs() < 1e-8 * max_rate,
        "L_xx {:e} vs the law's {want:e}",
        new_l[(0, 0)]
    );
    assert!(
        (new_l[(0, 0)] - run_l[(0, 0)]).abs() > 1e-4 * max_rate,
        "the re-solve moved L_xx by {:e} only",
        new_l[(0, 0)] - run_l[(0, 0)]
    );
    assert_eq!(new_l[(1, 1)], -rate);
    assert_eq!(new_l[(0, 1)], run_l[(0, 1)]);

    // The same step taken again from the same state with a tight solve: the re-solved snapshot
    // is that step's state, its cell's L to 10⁻⁸ of the rate cap and every grain's velocity
    // to 10⁻³ of the change the re-solve made (what is left is the cell's geometry, advanced
    // with the run's L, of order h ΔL); leaving out the grains' ΔL (x − c), or flipping it,
    // misses by a quarter of that change or more.
    let mut tight = point;
    tight.params.solver.method = SolverMethod::Auto;
    tight.params.solver.tolerance = 1e-12;
    tight.params.solver.max_iterations = 100_000;
    let rep = tight.step().unwrap();
    assert!(rep.solver.converged, "{:?}", rep.solver);
    let stepped = tight.snapshot();
    let tight_l = stepped.cell.unwrap().l;
    assert!(
        (tight_l - new_l).abs().max() < 1e-8 * max_rate,
        "L {tight_l} vs {new_l}"
    );
    let before = w.snapshot();
    let (mut change, mut miss) = (0.0f64, 0.0f64);
    for ((a, b), c) in before.bodies.iter().zip(&snap.bodies).zip(&stepped.bodies) {
        change = change.max((b.velocity - a.velocity).norm());
        miss = miss.max((b.velocity - c.velocity).norm());
    }
    assert!(
        change > 0.0 && miss < 1e-3 * change,
        "{miss:e} of {change:e} m/s"
    );

    // Priming the contacts again, or removing the cell, drops the coupled step's problem (a
    // primed coupled world used to assemble it with the new rows and panic).
    let mut primed = w.undo_point();
    primed.prime_with_weight().unwrap();
    assert!(primed.last_step_problem().is_none());
    assert!(primed.snapshot_with_last_impulses(&r).is_err());
    let mut cellless = w.undo_point();
    cellless.set_cell(None).unwrap();
    assert!(cellless.last_step_problem().is_none());

    // An explicit control: no problem to solve again.
    w.cell_control = Some(CellControl {
        implicit: false,
        affine: false,
        ..w.cell_control.unwrap()
    });
    w.step().unwrap();
    assert!(w.last_step_problem().is_none());
    assert!(w.snapshot_with_last_impulses(&r).is_err());
}

/// The detection of a biperiodic cell under a change `δ` of `L` within the step
/// (`Detector::detect_cell`'s `rate_bound`): the drift of the images is allowed for on the
/// pairs through the boundary only, and no pair that can touch is missed. 6 × 6 disks of
/// radius 1 mm ± 10 % on a square lattice of pitch 2.3 mm (gaps 0.1–0.5 mm) with random
/// velocities up to 0.01 m/s and the cell sheared at 1/s; `rate_bound` set so that an image
/// drifts by up to 0.25 mm over the step (under the cap of a quarter of the largest radius). For 200 random changes `δ` (xx, yy, xy) with `Σ|δ| = rate_bound` (its largest:
/// each on one component, both signs, and random mixes), the grains move with their
/// velocities, the cell with `L + δ`: every pair that touches after the step (gap ≤ 0
/// through any image) was detected, and some pairs do touch. Without the drift on the
/// boundary pairs' reach, the compression closes pairs that are not found (checked when the
/// test was written).
#[test]
fn cell_detection_finds_every_pair_an_image_drift_closes() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (n, pitch) = (6, 2.3e-3);
    let mut w = World::new(params(1e-3), ContactLaws::new(&["g"], 0.3));
    for i in 0..n {
        for j in 0..n {
            let x = Vector::new(i as f64 + 0.5, j as f64 + 0.5) * pitch;
            let b = w.add_grain(x, 1e-3 * rng.random_range(0.9..1.1), 2500.0, 0);
            w.bodies[b as usize].velocity =
                Vector::new(rng.random_range(-0.01..0.01), rng.random_range(-0.01..0.01));
        }
    }
    let side = pitch * n as f64;
    w.set_cell(Some(Cell::rectangle(side, side).unwrap()))
        .unwrap();
    w.set_velocity_gradient(Tensor::new(0.0, 1.0, 0.0, 0.0));
    let cell = *w.cell().unwrap();
    let dt = 1e-3;
    let lattice = 0.5 * dt * (cell.h.column(0).norm() + cell.h.column(1).norm());
    let rate_bound = 0.25e-3 / lattice;
    let inv: Vec<[f64; 3]> = w.bodies.iter().map(|b| b.inverse_mass()).collect();
    let mut det = dem::detection::Detector::default();
    let mut set = dem::contact::ContactSet::default();
    det.detect_cell(
        &w.bodies,
        &inv,
        &w.colliders,
        &w.laws,
        &cell,
        1e-6,
        dt,
        rate_bound,
        &mut set,
    )
    .unwrap();
    let found: std::collections::HashSet<(u32, u32)> = set
        .rows
        .iter()
        .map(|c| (c.a.min(c.b), c.a.max(c.b)))
        .collect();
    let mut closed = 0;
    for trial in 0..200 {
        let mut delta = [0.0f64; 3];
        if trial < 6 {
            delta[trial % 3] = if trial < 3 { -rate_bound } else { rate_bound };
        } else {
            let x: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
            let s: f64 = x.iter().map(|v| v.abs()).sum();
            delta = x.map(|v| v * rate_bound / s);
        }
        let l = cell.l + Tensor::new(delta[0], delta[2], 0.0, delta[1]);
        let h = cell.h + dt * l * cell.h;
        let x: Vec<Vector> = w
            .bodies
            .iter()
            .map(|b| b.position + dt * b.velocity)
            .collect();
        for a in 0..x.len() {
            for b in a + 1..x.len() {
                let touch = (-1..=1).any(|i| {
                    (-1..=1).any(|j| {
                        let k = Vector::new(i as f64, j as f64);
                        let gap =
                            (x[b] + h * k - x[a]).norm() - w.bodies[a].radius - w.bodies[b].radius;
                        gap <= 0.0
                    })
                });
                if touch {
                    closed += 1;
                    assert!(
                        found.contains(&(a as u32, b as u32)),
                        "trial {trial}: pair {a}–{b} touches after the step, not detected"
                    );
                }
            }
        }
    }
    assert!(closed > 0, "no pair closed: the test tests nothing");
}
