//! `solver.error_scale`: the tolerance on the loaded contacts' scale (docs/physics.md §1.6).
//!
//! A stack of thirty disks rests on a floor (Gauss–Seidel needs tens of sweeps for it), and
//! beside it one more disk hangs a quarter of the detection gap above the floor, at rest: its pair with the floor is in the step's problem with
//! a gap-closing shift `g / (θ h)` of about 0.4 m/s, against the stack's velocities of order
//! `g h ≈ 10⁻³ m/s`. That shift enters the error's scale `max(‖q‖, ‖r‖, ‖u‖)` and nothing else,
//! so on the problem's scale a solve meets its tolerance with the stack's contacts solved
//! hundreds of times less accurately; with `error_scale = "loaded"` the same tolerance holds on
//! the loaded contacts' scale `max(‖q − s⁺‖, ‖r‖, ‖u − s⁺‖)`.

mod common;

use common::{column, nlgs};
use dem::solver::ErrorScale;
use dem::{SolverParams, World};
use nalgebra::Vector2;

const TOLERANCE: f64 = 1e-6;
/// Disks in the stack.
const STACK: usize = 30;

fn scene(scale: ErrorScale) -> World {
    let mut w = column(
        STACK,
        SolverParams {
            error_scale: scale,
            ..nlgs(TOLERANCE, 100_000)
        },
    );
    // The detection gap is a tenth of the smallest radius (1e-4 m): this pair is detected,
    // open by 2.5e-5 m.
    w.add_grain(Vector2::new(5e-3, 1e-3 + 2.5e-5), 1e-3, 2500.0, 0);
    w
}

/// On the problem's scale the first step converges with the stack's contacts far above the
/// tolerance on their own scale (measured: 79 sweeps, error 4.9e-7, 8.7e-5 without the open
/// pair's shift); on the loaded scale it goes on until both meet the tolerance (94 sweeps,
/// 5.0e-7). The factor of 10 is the assertion's margin.
#[test]
fn the_loaded_scale_holds_the_tolerance_where_the_problem_scale_is_diluted() {
    let mut w = scene(ErrorScale::Problem);
    let diluted = w.step().unwrap().solver;
    assert!(diluted.converged, "{diluted:?}");
    assert!(diluted.error <= TOLERANCE, "{diluted:?}");
    assert!(
        diluted.error_without_gap_shifts > 10.0 * TOLERANCE,
        "the open pair must dilute the scale: {diluted:?}"
    );

    let mut w = scene(ErrorScale::Loaded);
    let loaded = w.step().unwrap().solver;
    assert!(loaded.converged, "{loaded:?}");
    assert!(loaded.error_without_gap_shifts <= TOLERANCE, "{loaded:?}");
    assert!(loaded.error <= TOLERANCE, "{loaded:?}");
    assert!(
        loaded.iterations > diluted.iterations,
        "{loaded:?} {diluted:?}"
    );
}

/// Unknown values of `error_scale` are refused by the parser, naming the variants.
#[test]
fn an_unknown_error_scale_is_refused() {
    let e = serde_json::from_str::<SolverParams>(
        r#"{"tolerance": 1e-6, "max_iterations": 10, "error_scale": "contacts"}"#,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("unknown variant `contacts`"), "{e}");
    assert!(e.contains("problem") && e.contains("loaded"), "{e}");
}

/// The governing error: the problem's measure, or the larger of both; a NaN in either fails
/// the `loaded` test (`f64::max` alone would hide it).
#[test]
fn the_governing_error_of_each_scale() {
    assert_eq!(ErrorScale::Problem.governing([1e-6, 3e-5]), 1e-6);
    assert_eq!(ErrorScale::Loaded.governing([1e-6, 3e-5]), 3e-5);
    assert_eq!(ErrorScale::Loaded.governing([2e-6, 1e-6]), 2e-6);
    assert!(ErrorScale::Loaded.governing([f64::NAN, 1e-6]).is_nan());
    assert!(ErrorScale::Loaded.governing([1e-6, f64::NAN]).is_nan());
    assert_eq!(ErrorScale::Loaded.name(), "loaded");
}
