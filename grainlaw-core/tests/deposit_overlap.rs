//! The approach-speed criterion of the contact solve on the janssen deposit.

use grainlaw_core::scenarios::common::build::{column, column_width};
use grainlaw_core::scenarios::common::config::{FrictionSpec, GrainSpec};

/// The engine's default `overlap_rate`.
const RATE: f64 = 1e-4;

/// Steps of the janssen deposit (350 grains, radius 0.5–2.5 mm, μ = 0.25, h = 0.25 ms,
/// tolerance 1e-4) declared converged while a closed or loaded contact approached faster than
/// [`RATE`] of the smallest radius per step, with the engine's `overlap_rate` set as given; and the
/// largest overlap over the smallest radius.
fn fast_approaches(overlap_rate: f64, steps: usize) -> (usize, f64) {
    let grain = GrainSpec {
        density: 2500.0,
        radius_mean: 1.5e-3,
        radius_spread: 1.0e-3,
    };
    let friction = FrictionSpec {
        grain_grain: 0.25,
        grain_wall: 0.25,
    };
    let width = column_width(&grain, 350, 4.0);
    let mut w = column(&grain, 350, width, &friction, 1, 2.5e-4)
        .unwrap()
        .world;
    w.params.solver.tolerance = 1e-4;
    w.params.solver.max_iterations = 1000;
    // The criterion in isolation: Gauss–Seidel alone (Newton converges far below the tolerance
    // and hides it) and no position correction (which removes the overlaps it would leave).
    w.params.solver.method = dem::fc::SolverMethod::Nlgs;
    w.params.position_correction = false;
    w.params.overlap_rate = overlap_rate;
    let r_min = w
        .bodies
        .iter()
        .filter(|b| b.radius > 0.0)
        .map(|b| b.radius)
        .fold(f64::INFINITY, f64::min);
    let limit = RATE * r_min / w.params.dt;
    let (mut fast, mut overlap) = (0, 0.0f64);
    for _ in 0..steps {
        let r = w.step().unwrap();
        overlap = overlap.max(r.max_penetration / r_min);
        if r.solver.converged && r.solver.approach_speed > limit {
            fast += 1;
        }
    }
    (fast, overlap)
}

/// The relative error measure is normalised by the step's largest velocities: while grains
/// still fall it accepts iterates where resting contacts approach at up to 1e-4 of those, and
/// since overlaps are never pushed apart they add up (here 8 % of the smallest radius after 450
/// steps). With `overlap_rate` ([`RATE`] of the smallest radius per step, the default) no step
/// counts as converged while a contact approaches faster, and the overlaps stay below 1 %.
#[test]
fn converged_steps_respect_the_approach_speed_limit() {
    let steps = 450;
    let (with, overlap_with) = fast_approaches(RATE, steps);
    let (without, overlap_without) = fast_approaches(0.0, steps);
    eprintln!(
        "with: {with} fast, overlap {overlap_with:.4}; without: {without}, {overlap_without:.4}"
    );
    assert_eq!(
        with, 0,
        "{with} of {steps} converged steps approach too fast"
    );
    assert!(overlap_with < 0.01, "overlap {overlap_with} of R_min");
    assert!(
        without > 0 && overlap_without > 0.02,
        "the relative error alone: {without} fast steps, overlap {overlap_without}: the test shows nothing"
    );
}

/// Equal disks poured by drop and roll into a column an exact number of diameters wide (the
/// `column-collapse` built-in with `grain.radius_spread = 0`: R₀ = 20 d): rows fill level
/// with the walls, and a grain rolling towards a wall it already touches must stop there.
/// Before the fix it rolled off past the wall, was clamped back onto a grain of its row and
/// fell through it (two grains at the same centre, "overlap by 5.000e-3 m").
#[test]
fn equal_disks_in_an_exact_width_column_do_not_overlap() {
    let source = "builtin:column-collapse";
    let mut table = grainlaw_core::scenarios::loader::parse_table(
        include_str!("../../datasets/scenarios/column-collapse.toml"),
        source,
    )
    .unwrap();
    let spread = datasets::overrides::parse_override("grain.radius_spread=0").unwrap();
    datasets::overrides::apply_override(&mut table, &spread, source).unwrap();
    let c: grainlaw_core::scenarios::column_collapse::config::ColumnCollapseConfig =
        grainlaw_core::scenarios::loader::typed(table, source).unwrap();
    grainlaw_core::scenarios::column_collapse::build::column_collapse_deposit(&c).unwrap();
}
