//! No overlap drift (issue 12): the position correction after each step ([`dem::stabilise`])
//! removes the overlaps a step leaves, down to the slop, without touching the velocities.

mod common;
use common::fingerprint;

use dem::energy::{load_energy_scale, EnergyProbe};
use dem::{BodyKind, ContactLaws, Dof, SolverParams, World, WorldParams};
use nalgebra::Vector2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const G: f64 = 9.81;
/// Smallest grain radius of the sheared strip (m).
const R_MIN: f64 = 1e-3;

/// The energy-growth tolerance of `grainlaw_core::scenarios::phases` (`ENERGY_GROWTH_TOLERANCE`): a
/// step whose residual δ exceeds this fraction of the load energy scale counts as an energy growth.
const ENERGY_GROWTH_TOLERANCE: f64 = 1e-5;

/// Largest geometric overlap over the smallest grain radius after the last step: every pair of
/// grains (nearest periodic image) and every grain against the disks of clumps and line walls,
/// computed from the positions alone.
fn max_overlap(w: &World) -> f64 {
    let per = w.periodic();
    let wrap_dx = |dx: f64| per.map_or(dx, |p| p.min_image(dx));
    let grains: Vec<(Vector2<f64>, f64)> = w
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .map(|b| (b.position, b.radius))
        .collect();
    let r_min = grains.iter().map(|g| g.1).fold(f64::INFINITY, f64::min);
    let mut walls: Vec<(Vector2<f64>, f64)> = Vec::new();
    let mut lines: Vec<(Vector2<f64>, Vector2<f64>)> = Vec::new();
    for c in &w.colliders {
        let b = &w.bodies[c.body as usize];
        if b.kind != BodyKind::Wall {
            continue;
        }
        match c.shape {
            dem::collider::Shape::Disk { radius, offset } => {
                walls.push((b.position + dem::collider::rotate(offset, b.angle), radius))
            }
            dem::collider::Shape::Line { point, normal } => lines.push((
                b.position + dem::collider::rotate(point, b.angle),
                dem::collider::rotate(normal, b.angle),
            )),
            dem::collider::Shape::Segment { .. } => {}
        }
    }
    let mut worst = 0.0f64;
    for (i, &(xi, ri)) in grains.iter().enumerate() {
        for &(xj, rj) in grains[i + 1..].iter().chain(&walls) {
            let d = Vector2::new(wrap_dx(xj.x - xi.x), xj.y - xi.y);
            worst = worst.max(ri + rj - d.norm());
        }
        for &(p, n) in &lines {
            worst = worst.max(ri - (xi - p).dot(&n));
        }
    }
    worst / r_min
}

/// A periodic strip between a fixed rough floor (glued disks of radius `R_MIN` on y = 0, body 0)
/// and a rough top wall (body 1), with `grains` disks of radius `R_MIN`–1.5 `R_MIN` (seeded),
/// `per_row` to a row, under gravity, μ = 0.5 everywhere, h = 0.5 ms. The grains start on a
/// loose lattice with the top wall fixed far above them; [`shear_run`] lets them settle, lowers
/// the wall onto them and loads it.
fn sheared_strip(grains: usize, per_row: usize, solver: SolverParams, correction: bool) -> World {
    let pitch = 2.0 * 1.5 * R_MIN * 1.02;
    let length = per_row as f64 * pitch;
    let params = WorldParams {
        dt: 5e-4,
        theta: 1.0,
        gravity: Vector2::new(0.0, -G),
        periodic_x: Some([0.0, length]),
        detection_gap: 0.1 * R_MIN,
        position_correction: correction,
        solver,
        ..Default::default()
    };
    let mut w = World::new(params, ContactLaws::new(&["grain"], 0.5));
    let row = |y: f64| -> (Vec<Vector2<f64>>, Vec<f64>) {
        let m = (length / (2.0 * R_MIN)).floor() as usize;
        let p = length / m as f64;
        (
            (0..m)
                .map(|k| Vector2::new((k as f64 + 0.5) * p, y))
                .collect(),
            vec![R_MIN; m],
        )
    };
    let (c, r) = row(0.0);
    w.add_clump("bottom", &c, &r, 0);
    let rows = grains.div_ceil(per_row);
    let (c, r) = row(R_MIN + (rows as f64 + 1.0) * pitch);
    w.add_clump("top", &c, &r, 0);
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for k in 0..grains {
        let (i, j) = (k % per_row, k / per_row);
        let x = (i as f64 + 0.5) * pitch + if j % 2 == 1 { 0.25 * pitch } else { 0.0 };
        let y = R_MIN + (j as f64 + 0.5) * pitch;
        let radius = R_MIN * rng.random_range(1.0..1.5);
        w.add_grain(Vector2::new(x, y), radius, 2500.0, 0);
    }
    w.validate(1e-12).unwrap();
    w
}

/// Lowers the top wall (body 1) onto the highest grain (a gap of 10⁻³ `R_MIN` left), frees its
/// y under the pressure `pressure` (Pa, per metre of thickness), mass `mass_ratio` times the
/// grains'.
fn load_top_wall(w: &mut World, pressure: f64, mass_ratio: f64) {
    let length = w.params.periodic_x.map_or(0.0, |[a, b]| b - a);
    let top = w
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .map(|b| b.position.y + b.radius)
        .fold(0.0, f64::max);
    let mass: f64 = w
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .map(|b| b.mass)
        .sum();
    let b = &mut w.bodies[1];
    b.position.y = top + R_MIN * (1.0 + 1e-3);
    b.dofs = [Dof::Imposed, Dof::Free, Dof::Imposed];
    b.mass = mass_ratio * mass;
    b.gravity = false;
    b.applied_force = Vector2::new(0.0, -pressure * length);
}

/// The worst of a run, step by step.
#[derive(Debug, Default, Clone, Copy)]
struct Worst {
    /// Largest geometric overlap after a step over `R_MIN` ([`max_overlap`]).
    overlap: f64,
    /// Largest overlap at the start of a step over `R_MIN` (`StepReport::max_penetration`).
    start_overlap: f64,
    /// Largest energy residual δ / E_load of a step.
    growth: f64,
    /// Steps where the projection moved something.
    corrected_steps: usize,
    /// Steps whose projection stopped at `MAX_SWEEPS`.
    capped_corrections: usize,
    /// Mean projection sweeps over the corrected steps.
    sweeps: usize,
    /// Σ of the loads' work over the corrections (J).
    load_work: f64,
    /// Steps.
    steps: usize,
}

/// Runs `steps` steps of `w`, recording the geometric overlap and the energy residual of every
/// step.
fn run(w: &mut World, steps: usize, worst: &mut Worst) {
    let e_load = load_energy_scale(w);
    for _ in 0..steps {
        let probe = EnergyProbe::before(w);
        let rep = w.step().unwrap();
        worst.steps += 1;
        worst.growth = worst.growth.max(probe.residual(w) / e_load);
        worst.overlap = worst.overlap.max(max_overlap(w));
        worst.start_overlap = worst.start_overlap.max(rep.max_penetration / R_MIN);
        let c = rep.position_correction;
        if c.corrected_contacts > 0 {
            worst.corrected_steps += 1;
            worst.sweeps += c.sweeps;
        }
        if c.capped {
            worst.capped_corrections += 1;
        }
        worst.load_work += c.load_work;
    }
}

/// Two disks of radius R started overlapping by 5 % of R, at rest, without gravity: after one
/// step the overlap is the slop `s = 10⁻⁴ R` (to 10⁻⁹ of it: rounding), each disk moved back by
/// half of `0.05 R − s` along the line of centres, and both velocities are exactly zero (the
/// kinetic energy is exactly 0). Ten more steps change nothing beyond rounding. Without the
/// correction the overlap stays at 5 %.
#[test]
fn overlapping_disks_at_rest_are_separated_without_velocity() {
    let r = 1e-3;
    let slop = dem::stabilise::SLOP * r;
    let make = |correction: bool| {
        let params = WorldParams {
            gravity: Vector2::zeros(),
            position_correction: correction,
            ..Default::default()
        };
        let mut w = World::new(params, ContactLaws::new(&["m"], 0.5));
        w.add_grain(Vector2::new(0.0, 0.0), r, 2500.0, 0);
        w.add_grain(Vector2::new(2.0 * r - 0.05 * r, 0.0), r, 2500.0, 0);
        w
    };
    let overlap = |w: &World| 2.0 * r - (w.bodies[1].position - w.bodies[0].position).norm();
    let mut w = make(true);
    let rep = w.step().unwrap();
    let c = rep.position_correction;
    assert_eq!((c.violated_contacts, c.corrected_contacts), (1, 1), "{c:?}");
    assert!(!c.capped, "{c:?}");
    assert_eq!(c.load_work, 0.0);
    assert!(
        (overlap(&w) - slop).abs() <= 1e-9 * slop,
        "overlap {:e}",
        overlap(&w)
    );
    let half = 0.5 * (0.05 * r - slop);
    assert!((w.bodies[0].position.x + half).abs() <= 1e-9 * slop);
    assert!((w.bodies[1].position.x - (2.0 * r - 0.05 * r + half)).abs() <= 1e-9 * slop);
    for b in &w.bodies {
        assert_eq!(b.position.y, 0.0);
        assert_eq!((b.velocity.x, b.velocity.y, b.omega), (0.0, 0.0, 0.0));
        assert_eq!(b.angle, 0.0);
    }
    assert_eq!(w.kinetic_energy(), 0.0);
    for _ in 0..10 {
        w.step().unwrap();
        assert!(overlap(&w) <= slop * (1.0 + 1e-9), "{:e}", overlap(&w));
        assert_eq!(w.kinetic_energy(), 0.0);
    }
    let mut off = make(false);
    off.step().unwrap();
    assert!((overlap(&off) - 0.05 * r).abs() <= 1e-12 * r);
}

/// A disk pushed 5 % of its radius into a fixed floor, at rest under gravity: the floor (all its
/// degrees of freedom imposed) does not move, the disk is lifted to the slop, and the step
/// reports the work of gravity over the lift, `−m g (0.05 R − s)` (10⁻⁹ relative), which is
/// the opposite of the potential energy the correction added. The kinetic energy stays that of
/// the plain step, below 10⁻¹² of `m g R` (the contact solve leaves v⁺ at rounding level).
#[test]
fn a_disk_inside_a_fixed_floor_is_lifted_and_the_work_reported() {
    let r = 1e-3;
    let mut w = World::new(WorldParams::default(), ContactLaws::new(&["m"], 0.5));
    let floor = w.add_line_wall("floor", Vector2::zeros(), Vector2::new(0.0, 1.0), 0) as usize;
    let b = w.add_grain(Vector2::new(0.0, 0.95 * r), r, 2500.0, 0) as usize;
    let m = w.bodies[b].mass;
    let e_pot = w.potential_energy();
    let rep = w.step().unwrap();
    let lift = 0.05 * r - dem::stabilise::SLOP * r;
    let y = w.bodies[b].position.y;
    // θ = 1: the step itself moves the disk by h v⁺ ≈ 0.
    assert!((y - (0.95 * r + lift)).abs() <= 1e-9 * lift, "y = {y:e}");
    assert_eq!(w.bodies[floor].position, Vector2::zeros());
    let work = rep.position_correction.load_work;
    assert!(
        (work + m * G * lift).abs() <= 1e-9 * m * G * lift,
        "load work {work:e}, expected {:e}",
        -m * G * lift
    );
    let de_pot = w.potential_energy() - e_pot;
    assert!(
        (de_pot + work).abs() <= 1e-6 * m * G * lift,
        "ΔE_pot {de_pot:e}"
    );
    assert!(w.kinetic_energy() <= 1e-12 * m * G * r);
}

/// Issue 12's sheared dense packing: 300 disks (radius 1–1.5 mm, μ = 0.5) in a periodic strip under
/// gravity, settled for 200 steps, loaded by a rough top wall at 1 kPa (free along y, 0.2 times the
/// grains' mass) for 150 steps, then sheared by it at 0.1 m/s for 500 steps (h = 0.5 ms, about 0.05
/// R_min per step; Gauss–Seidel to 10⁻⁵ with at most 300 sweeps, so many steps end at the cap and
/// leave approaching contacts behind). At every step: the largest overlap after the step, computed
/// from the positions, stays ≤ 0.1 % of R_min, and the energy residual `δ = ΔK − W_ext − W_drive`
/// (the check of `grainlaw_core::scenarios::phases`) stays ≤ 10⁻⁵ E_load. The same loading and
/// shear without the correction, from the same settled state, goes beyond 0.1 %.
#[test]
fn a_sheared_dense_packing_keeps_its_overlaps_below_a_thousandth_of_the_radius() {
    let solver = SolverParams {
        tolerance: 1e-5,
        max_iterations: 300,
        method: dem::fc::SolverMethod::Nlgs,
        ..Default::default()
    };
    let mut w = sheared_strip(300, 30, solver, true);
    let mut with = Worst::default();
    run(&mut w, 200, &mut with);
    let mut off = w.clone();
    let shear = |w: &mut World, worst: &mut Worst| {
        load_top_wall(w, 1000.0, 0.2);
        run(w, 150, worst);
        w.bodies[1].velocity.x = 0.1;
        run(w, 500, worst);
    };
    shear(&mut w, &mut with);
    off.params.position_correction = false;
    let mut without = Worst::default();
    shear(&mut off, &mut without);
    eprintln!("with the correction:    {with:?}");
    eprintln!("without the correction: {without:?}");
    assert!(with.overlap <= 1e-3, "{with:?}");
    assert!(with.start_overlap <= 1e-3, "{with:?}");
    assert!(with.growth <= ENERGY_GROWTH_TOLERANCE, "{with:?}");
    assert!(
        with.corrected_steps > with.steps / 2,
        "the correction must be exercised: {with:?}"
    );
    assert!(with.load_work.is_finite());
    assert!(
        without.overlap > 1e-3,
        "without the correction the test shows nothing: {without:?}"
    );
}

/// A hexagonal crystal of `nx × ny` disks of radius `R_MIN` whose neighbours overlap by
/// 0.2 % of the radius (20 slops), in a box whose floor and side walls it also overlaps, under
/// gravity, μ = 0.3, parallel solve: every contact needs the correction.
fn compressed_crystal(nx: usize, ny: usize) -> World {
    let params = WorldParams {
        dt: 1e-3,
        solver: SolverParams {
            tolerance: 1e-5,
            max_iterations: 100,
            parallel: true,
            method: dem::fc::SolverMethod::Nlgs,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut w = World::new(params, ContactLaws::new(&["grain"], 0.3));
    let d = 2.0 * R_MIN * (1.0 - 1e-3);
    let width = d * nx as f64 + 0.5 * d;
    let inset = R_MIN * 2e-3;
    w.add_line_wall(
        "bottom",
        Vector2::new(0.0, inset),
        Vector2::new(0.0, 1.0),
        0,
    );
    w.add_line_wall("left", Vector2::new(inset, 0.0), Vector2::new(1.0, 0.0), 0);
    w.add_line_wall(
        "right",
        Vector2::new(width + 2.0 * R_MIN - d - inset, 0.0),
        Vector2::new(-1.0, 0.0),
        0,
    );
    for j in 0..ny {
        for i in 0..nx {
            let shift = if j % 2 == 1 { 0.5 * d } else { 0.0 };
            let p = Vector2::new(
                R_MIN + d * i as f64 + shift,
                R_MIN + j as f64 * 0.5 * 3f64.sqrt() * d,
            );
            w.add_grain(p, R_MIN, 2500.0, 0);
        }
    }
    w
}

/// The correction keeps the step deterministic: a compressed 3600-disk crystal (about 10⁴
/// contacts, so that the parallel solve is split into blocks) gives the same bits on one and
/// two threads over 6 steps, and a run stopped after 3 steps, written to a checkpoint and
/// resumed, the same bits as one never stopped — with the correction acting in every step.
#[test]
fn corrected_steps_are_bit_identical_on_any_thread_count_and_on_resume() {
    let steps = 6;
    let run_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut w = compressed_crystal(60, 60);
            let mut corrected = usize::MAX;
            let mut contacts = 0;
            for _ in 0..steps {
                let rep = w.step().unwrap();
                corrected = corrected.min(rep.position_correction.corrected_contacts);
                contacts = contacts.max(rep.contacts);
            }
            (fingerprint(&w), corrected, contacts)
        })
    };
    let (one, corrected, contacts) = run_on(1);
    assert!(corrected > 0, "the correction must act in every step");
    assert!(
        contacts >= 4096,
        "{contacts} contacts: the solve is not split"
    );
    let (two, _, _) = run_on(2);
    assert!(one == two, "two threads differ from one");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("crystal.ckpt.json.gz");
    let mut w = compressed_crystal(60, 60);
    for _ in 0..3 {
        w.step().unwrap();
    }
    dem::checkpoint::write_checkpoint(&w, &path).unwrap();
    drop(w);
    let mut w = dem::checkpoint::read_checkpoint(&path).unwrap();
    for _ in 3..steps {
        w.step().unwrap();
    }
    assert!(fingerprint(&w) == one, "the resumed run differs");
}

/// Parameters written before the correction existed (no `position_correction` key) load with it
/// on.
#[test]
fn old_parameter_files_load_with_the_correction_on() {
    let mut v = serde_json::to_value(WorldParams {
        position_correction: false,
        ..Default::default()
    })
    .unwrap();
    assert!(v
        .as_object_mut()
        .unwrap()
        .remove("position_correction")
        .is_some());
    let p: WorldParams = serde_json::from_value(v).unwrap();
    assert!(p.position_correction);
    assert!(WorldParams::default().position_correction);
}

/// A disk knocked by an impact travels farther in the step than its swept margin allowed at
/// detection, into a disk no contact of the step knew: the correction detects again at the
/// new positions and removes that overlap too (≤ the slop, relative 1e-9 besides), with the
/// velocities bit for bit those of the uncorrected step.
#[test]
fn a_disk_knocked_beyond_its_detection_margin_is_kept_out_of_its_neighbour() {
    let r = 1e-3;
    let h = 1e-3;
    let step = |correction: bool| {
        let params = WorldParams {
            dt: h,
            gravity: Vector2::zeros(),
            position_correction: correction,
            ..WorldParams::default()
        };
        let mut w = World::new(params, ContactLaws::new(&["glass"], 0.0));
        // A (fast) touches B (at rest); C sits 0.15 r beyond B, outside B's detection reach (the
        // detection gap is 10⁻⁴ m = 0.1 r, B's swept margin 0).
        // The impact is perfectly inelastic: A and B leave at v/2 and B travels 0.2 r.
        let v = 0.4 * r / h;
        let a = w.add_grain(Vector2::new(0.0, 0.0), r, 2500.0, 0) as usize;
        w.add_grain(Vector2::new(2.0 * r, 0.0), r, 2500.0, 0);
        w.add_grain(Vector2::new(4.15 * r, 0.0), r, 2500.0, 0);
        w.bodies[a].velocity = Vector2::new(v, 0.0);
        w.step().unwrap();
        w
    };
    let off = step(false);
    let on = step(true);
    let gap_bc = |w: &World| (w.bodies[2].position - w.bodies[1].position).norm() - 2.0 * r;
    // Without the correction B ends inside C by 0.05 r.
    assert!(
        (gap_bc(&off) + 0.05 * r).abs() <= 1e-9 * r,
        "gap {}",
        gap_bc(&off)
    );
    // With it, at most the slop (1e-4 r) and the projection's tolerance.
    assert!(gap_bc(&on) >= -1e-4 * r * 1.1, "gap {}", gap_bc(&on));
    for (x, y) in off.bodies.iter().zip(&on.bodies) {
        assert_eq!(x.velocity, y.velocity);
        assert_eq!(x.omega, y.omega);
    }
    assert!(on.last_report().position_correction.corrected_contacts > 0);
}
