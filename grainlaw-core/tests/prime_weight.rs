//! Starting a deposited column's first solve from the weight-carrying impulses
//! (`World::prime_with_weight`).

use dem::BodyKind;
use grainlaw_core::benchmarks::{janssen_column, ColumnRun, Preparation};

fn column(n: usize, seed: u64) -> dem::World {
    let run = ColumnRun {
        dt: 2.5e-4,
        dt_range: [2.5e-4, 2.5e-4],
        tolerance: 1e-4,
        max_sweeps: 100,
        parallel: false,
        prime: false,
        max_time: 1.0,
        max_halvings: 0,
        check_every: 0,
    };
    janssen_column(n, Preparation::Deposit, &run, seed).unwrap()
}

/// The primed impulses carry the grains' weight to the walls: each grain's load is split over
/// its supports so that the vertical components add up to it, except where a support is capped
/// (a grain leaning on one steep contact) or a grain rests on a side wall and one grain; the
/// walls therefore give between 95 % and 100 % of `Σ m g h` upwards (measured: 98.1 %), never
/// more.
#[test]
fn primed_impulses_carry_the_weight_to_the_walls() {
    let mut w = column(600, 5);
    w.prime_with_weight().unwrap();
    let (h, g) = (w.params.dt, w.params.gravity.norm());
    let weight: f64 = w
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .map(|b| b.mass * g * h)
        .sum();
    let mut from_walls = 0.0;
    for c in &w.contacts().rows {
        if w.bodies[c.a as usize].kind == BodyKind::Wall {
            // impulse r_n n on b, t = (−n_y, n_x)
            from_walls += c.r[0] * c.n[1] + c.r[1] * c.n[0];
        }
    }
    let ratio = from_walls / weight;
    assert!(
        (0.95..=1.0 + 1e-12).contains(&ratio),
        "walls carry {from_walls:.4e} N·s of {weight:.4e}"
    );
}

/// Error and approach speed after three capped steps (100 sweeps) of a column, from zero or
/// from the primed impulses.
fn after_three_steps(n: usize, seed: u64, prime: bool) -> (f64, f64) {
    let mut w = column(n, seed);
    if prime {
        w.prime_with_weight().unwrap();
    }
    let mut last = None;
    for _ in 0..3 {
        last = Some(w.step().unwrap());
    }
    let r = last.unwrap().solver;
    (r.error, r.approach_speed)
}

/// On a 2000-grain column (50 grains deep) 100 sweeps per step cannot carry the weight down
/// from zero impulses: after three steps the primed start has less than 0.6 times the error and
/// half the approach speed of the cold start (measured: 0.23–0.37 and 0.12–0.26 over these
/// seeds), so the transient leaves less overlap behind.
#[test]
fn priming_a_deep_column_leaves_less_to_solve() {
    for seed in 1..=3 {
        let (e0, a0) = after_three_steps(2000, seed, false);
        let (e1, a1) = after_three_steps(2000, seed, true);
        assert!(
            e1 < 0.6 * e0,
            "seed {seed}: error {e1:.2e} primed, {e0:.2e} cold"
        );
        assert!(
            a1 < 0.5 * a0,
            "seed {seed}: approach {a1:.2e} primed, {a0:.2e} cold"
        );
    }
}
