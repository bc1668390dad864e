//! Walls and boundaries: a driven wall, segments, glued-disk (rough) walls, the periodic
//! boundary, restitution, and validation of a world before it runs.

use dem::{ContactLaws, DemError, SolverParams, World, WorldParams};
use nalgebra::Vector2;

const G: f64 = 9.81;

fn params(dt: f64) -> WorldParams {
    WorldParams {
        dt,
        theta: 1.0,
        gravity: Vector2::new(0.0, -G),
        periodic_x: None,
        detection_gap: 1e-4,
        overlap_rate: 1e-4,
        position_correction: true,
        solver: SolverParams {
            tolerance: 1e-12,
            max_iterations: 10_000,
            ..Default::default()
        },
    }
}

/// A floor pushed up at 5e-3 m/s (the stick-slip drive) lifts a resting disk with it: the first
/// step is an inelastic impact of impulse `m (v_w + g h)`; afterwards the disk moves at the
/// wall's speed and the wall records the disk's weight every step (1e-9 relative).
#[test]
fn driven_floor_lifts_a_disk_and_records_its_weight() {
    let h = 1e-3;
    let mut w = World::new(params(h), ContactLaws::new(&["m"], 0.5));
    let floor = w.add_line_wall("floor", Vector2::zeros(), Vector2::new(0.0, 1.0), 0) as usize;
    w.bodies[floor].velocity = Vector2::new(0.0, 5e-3);
    let r = 0.01;
    let b = w.add_grain(Vector2::new(0.0, r), r, 2500.0, 0) as usize;
    let mg = w.bodies[b].mass * G;
    for step in 0..1000 {
        assert!(w.step().unwrap().solver.converged);
        let (f, _) = w.contact_force(floor);
        let expected = if step == 0 {
            mg + w.bodies[b].mass * 5e-3 / h
        } else {
            mg
        };
        assert!(
            (f.y + expected).abs() <= 1e-9 * expected,
            "step {step}: floor force {}",
            f.y
        );
        assert!((w.bodies[b].velocity.y - 5e-3).abs() < 1e-12);
    }
    // After 1 s both moved 5 mm; the disk still rests on the floor.
    assert!((w.bodies[floor].position.y - 5e-3).abs() < 1e-12);
    assert!(
        (w.bodies[b].position.y - (r + 5e-3)).abs() < 1e-12,
        "{}",
        w.bodies[b].position.y
    );
}

/// A disk on a horizontal segment rests on it; past the segment's end it falls freely.
#[test]
fn segment_supports_a_disk_only_along_its_length() {
    let h = 1e-3;
    let mut w = World::new(params(h), ContactLaws::new(&["m"], 0.5));
    w.add_segment_wall("ledge", Vector2::new(-0.1, 0.0), Vector2::new(0.1, 0.0), 0);
    let r = 0.01;
    let on = w.add_grain(Vector2::new(0.05, r), r, 2500.0, 0) as usize;
    let off = w.add_grain(Vector2::new(0.2, r), r, 2500.0, 0) as usize;
    for _ in 0..200 {
        w.step().unwrap();
    }
    assert!((w.bodies[on].position.y - r).abs() < 1e-12);
    // Free fall with θ = 1: v = g t exactly.
    assert!((w.bodies[off].velocity.y + G * 0.2).abs() < 1e-12);
}

/// A disk resting on a rough wall of glued disks (a clump) in the hollow between two of them:
/// the two contacts share the weight equally, by symmetry, and the clump stays fixed.
#[test]
fn disk_rests_in_the_hollow_of_a_rough_wall() {
    let h = 1e-3;
    let mut w = World::new(params(h), ContactLaws::new(&["m"], 0.0));
    let r = 0.01;
    let centres: Vec<Vector2<f64>> = (0..5)
        .map(|i| Vector2::new(2.0 * r * i as f64, 0.0))
        .collect();
    let clump = w.add_clump("rough", &centres, &[r; 5], 0) as usize;
    // On top of disks 1 and 2: centre at x = 3r, height √3 r.
    let b = w.add_grain(Vector2::new(3.0 * r, 3f64.sqrt() * r), r, 2500.0, 0) as usize;
    let mg = w.bodies[b].mass * G;
    for _ in 0..100 {
        assert!(w.step().unwrap().solver.converged);
    }
    let snap = w.snapshot();
    let loads: Vec<f64> = snap
        .contacts
        .iter()
        .filter(|c| c.force_n > 0.0)
        .map(|c| c.force_n)
        .collect();
    assert_eq!(loads.len(), 2);
    // Each of the two normals is 30° from vertical: f_n = m g / (2 cos 30°).
    let expected = mg / (2.0 * (30f64).to_radians().cos());
    for f in loads {
        assert!((f - expected).abs() <= 1e-9 * mg, "{f} vs {expected}");
    }
    assert_eq!(w.bodies[clump].position, Vector2::new(4.0 * r, 0.0));
    let (f, _) = w.contact_force(clump);
    assert!((f.y + mg).abs() <= 1e-9 * mg);
}

/// Across the periodic boundary: a disk moving right through x_max meets a resting disk just
/// inside x_min; the perfectly inelastic frictionless impact shares the momentum (each ends at
/// v/2, total momentum conserved to 1e-12) and positions stay inside the cell.
#[test]
fn periodic_boundary_carries_contacts_across() {
    let h = 1e-4;
    let mut p = params(h);
    p.gravity = Vector2::zeros();
    p.periodic_x = Some([0.0, 0.1]);
    let mut w = World::new(p, ContactLaws::new(&["m"], 0.0));
    let r = 0.005;
    let a = w.add_grain(Vector2::new(0.1 - r - 1e-3, 0.05), r, 2500.0, 0) as usize;
    let b = w.add_grain(Vector2::new(r, 0.05), r, 2500.0, 0) as usize;
    w.bodies[a].velocity = Vector2::new(1.0, 0.0);
    for _ in 0..100 {
        w.step().unwrap();
        for body in &w.bodies {
            assert!((0.0..0.1).contains(&body.position.x));
        }
    }
    assert!(
        (w.bodies[a].velocity.x - 0.5).abs() < 1e-12,
        "{}",
        w.bodies[a].velocity.x
    );
    assert!((w.bodies[b].velocity.x - 0.5).abs() < 1e-12);
}

/// Newton restitution e: a disk dropped on a floor bounces back with −e times its impact
/// velocity (frictionless), to 1e-9 relative.
#[test]
fn restitution_reverses_the_normal_velocity() {
    let h = 1e-4;
    let mut laws = ContactLaws::new(&["m"], 0.0);
    laws.set_restitution(0, 0, 0.5);
    let mut w = World::new(params(h), laws);
    w.add_line_wall("floor", Vector2::zeros(), Vector2::new(0.0, 1.0), 0);
    let r = 0.01;
    let b = w.add_grain(Vector2::new(0.0, r), r, 2500.0, 0) as usize;
    w.bodies[b].velocity = Vector2::new(0.0, -1.0);
    w.params.gravity = Vector2::zeros();
    w.step().unwrap();
    assert!(
        (w.bodies[b].velocity.y - 0.5).abs() < 1e-9,
        "{}",
        w.bodies[b].velocity.y
    );
}

/// Validation names what is wrong before anything runs.
#[test]
fn validation_rejects_bad_worlds() {
    let base = || {
        let mut w = World::new(params(1e-3), ContactLaws::new(&["m"], 0.3));
        w.add_line_wall("floor", Vector2::zeros(), Vector2::new(0.0, 1.0), 0);
        w
    };
    // Overlapping grains.
    let mut w = base();
    w.add_grain(Vector2::new(0.0, 0.02), 0.01, 2500.0, 0);
    w.add_grain(Vector2::new(0.015, 0.02), 0.01, 2500.0, 0);
    assert!(matches!(w.validate(1e-9), Err(DemError::Overlap { .. })));
    // A grain below the floor.
    let mut w = base();
    w.add_grain(Vector2::new(0.0, 0.005), 0.01, 2500.0, 0);
    assert!(matches!(w.validate(1e-9), Err(DemError::Outside { ref wall, .. }) if wall == "floor"));
    // Negative radius, NaN velocity, zero time step, negative friction.
    let mut w = base();
    let g = w.add_grain(Vector2::new(0.0, 0.02), 0.01, 2500.0, 0) as usize;
    w.bodies[g].radius = -0.01;
    assert!(matches!(w.validate(1e-9), Err(DemError::Body { ref field, .. }) if field == "radius"));
    let mut w = base();
    let g = w.add_grain(Vector2::new(0.0, 0.02), 0.01, 2500.0, 0) as usize;
    w.bodies[g].velocity.x = f64::NAN;
    assert!(matches!(w.validate(1e-9), Err(DemError::Body { .. })));
    let mut w = base();
    w.params.dt = 0.0;
    assert!(matches!(w.validate(1e-9), Err(DemError::Parameter { ref name, .. }) if name == "dt"));
    let mut w = base();
    w.laws.set_friction(0, 0, -0.1);
    assert!(
        matches!(w.validate(1e-9), Err(DemError::Parameter { ref name, .. }) if name == "friction")
    );
    // A last-level sweep budget of 0 or beyond 1000 times the cap.
    for bad in [0, 1001] {
        let mut w = base();
        w.params.solver.last_level_sweeps = bad;
        assert!(
            matches!(w.validate(1e-9), Err(DemError::Parameter { ref name, .. }) if name == "solver.last_level_sweeps")
        );
    }
    // A valid world passes.
    let mut w = base();
    w.add_grain(Vector2::new(0.0, 0.02), 0.01, 2500.0, 0);
    assert!(w.validate(1e-9).is_ok());
}

/// Restitution also holds for an impact that happens inside a step (the swept detection finds
/// the contact while the gap is still open): the disk leaves with −e times its approach velocity.
#[test]
fn restitution_holds_when_the_impact_happens_inside_a_step() {
    for gap in [0.0, 5e-5, 1.5e-4] {
        let h = 1e-4;
        let mut laws = ContactLaws::new(&["m"], 0.0);
        laws.set_restitution(0, 0, 0.5);
        let mut p = params(h);
        p.gravity = Vector2::zeros();
        let mut w = World::new(p, laws);
        w.add_line_wall("floor", Vector2::zeros(), Vector2::new(0.0, 1.0), 0);
        let r = 0.01;
        let b = w.add_grain(Vector2::new(0.0, r + gap), r, 2500.0, 0) as usize;
        w.bodies[b].velocity = Vector2::new(0.0, -1.0);
        for _ in 0..5 {
            w.step().unwrap();
        }
        assert!(
            (w.bodies[b].velocity.y - 0.5).abs() < 1e-9,
            "gap {gap}: {}",
            w.bodies[b].velocity.y
        );
    }
}

/// One fast grain does not coarsen the grid nor break a periodic run; contacts are still found.
#[test]
fn a_fast_grain_in_a_periodic_cell_is_handled() {
    let h = 1e-3;
    let mut p = params(h);
    p.gravity = Vector2::zeros();
    p.periodic_x = Some([0.0, 0.1]);
    let mut w = World::new(p, ContactLaws::new(&["m"], 0.0));
    let r = 0.005;
    let fast = w.add_grain(Vector2::new(0.02, 0.05), r, 2500.0, 0) as usize;
    w.add_grain(Vector2::new(0.08, 0.05), r, 2500.0, 0);
    w.bodies[fast].velocity = Vector2::new(20.0, 0.0);
    w.validate(1e-12).unwrap();
    let mut met = false;
    for _ in 0..10 {
        w.step().unwrap();
        met |= w.contacts().rows.iter().any(|c| c.r[0] > 0.0);
    }
    assert!(met, "the fast grain never met the other one");
    // Inelastic frictionless impact: momentum shared equally.
    assert!((w.bodies[fast].velocity.x - 10.0).abs() < 1e-9);
}

/// An applied force counts in the swept margin: a disk pushed hard onto a floor does not overlap.
#[test]
fn applied_force_is_in_the_swept_margin() {
    let h = 1e-3;
    let mut w = World::new(params(h), ContactLaws::new(&["m"], 0.3));
    w.add_line_wall("floor", Vector2::zeros(), Vector2::new(0.0, 1.0), 0);
    let r = 0.01;
    let b = w.add_grain(Vector2::new(0.0, r + 2e-4), r, 2500.0, 0) as usize;
    let m = w.bodies[b].mass;
    w.bodies[b].applied_force = Vector2::new(0.0, -50.0 * m * G);
    for _ in 0..20 {
        let rep = w.step().unwrap();
        assert!(
            rep.max_penetration <= 1e-12,
            "overlap {}",
            rep.max_penetration
        );
    }
    assert!(w.bodies[b].position.y >= r - 1e-12);
}

/// A segment longer than half the periodic cell supports disks along its whole length.
#[test]
fn long_segment_in_a_periodic_cell_supports_everywhere() {
    let mut p = params(1e-3);
    p.periodic_x = Some([0.0, 0.1]);
    let mut w = World::new(p, ContactLaws::new(&["m"], 0.3));
    w.add_segment_wall("floor", Vector2::new(0.0, 0.0), Vector2::new(0.1, 0.0), 0);
    let r = 0.005;
    let ids: Vec<usize> = [0.03, 0.07, 0.095]
        .iter()
        .map(|&x| w.add_grain(Vector2::new(x, r), r, 2500.0, 0) as usize)
        .collect();
    for _ in 0..100 {
        w.step().unwrap();
    }
    for i in ids {
        assert!(
            (w.bodies[i].position.y - r).abs() < 1e-12,
            "{}",
            w.bodies[i].position.y
        );
    }
}

/// Far-away and coincident grains give errors, not panics or silent passes.
#[test]
fn degenerate_positions_are_reported() {
    let mut w = World::new(params(1e-3), ContactLaws::new(&["m"], 0.3));
    w.add_grain(Vector2::new(0.0, 1e20), 0.01, 2500.0, 0);
    w.add_grain(Vector2::new(0.0, 0.0), 0.01, 2500.0, 0);
    assert!(w.validate(1e-9).is_ok());
    w.step().unwrap();
    let mut w = World::new(params(1e-3), ContactLaws::new(&["m"], 0.3));
    w.add_grain(Vector2::new(0.0, 0.0), 0.01, 2500.0, 0);
    w.add_grain(Vector2::new(0.0, 0.0), 0.01, 2500.0, 0);
    assert!(matches!(w.validate(1e-9), Err(DemError::Overlap { .. })));
}

/// Snapshot forces are the step's impulses over that step's time step, even if the time step is
/// changed before the snapshot is taken; bad solver parameters are rejected.
#[test]
fn snapshot_forces_use_the_step_time_step_and_solver_parameters_are_checked() {
    let mut w = World::new(params(1e-3), ContactLaws::new(&["m"], 0.3));
    w.add_line_wall("floor", Vector2::zeros(), Vector2::new(0.0, 1.0), 0);
    let b = w.add_grain(Vector2::new(0.0, 0.01), 0.01, 2500.0, 0) as usize;
    w.step().unwrap();
    w.params.dt = 1e-4;
    let mg = w.bodies[b].mass * G;
    let f = w.snapshot().contacts[0].force_n;
    assert!((f - mg).abs() <= 1e-9 * mg, "{f} vs {mg}");
    for bad in [0.0, 2.0, f64::NAN] {
        w.params.solver.relaxation = bad;
        assert!(
            matches!(w.validate(1e-9), Err(DemError::Parameter { ref name, .. }) if name == "solver.relaxation")
        );
    }
}
