//! Benchmark worlds: the settled Janssen column of the performance targets.
//!
//! `n` disks of radius uniform in [1, 2] mm (density 2500 kg/m³, seeded), μ = 0.5 between grains
//! and with the walls, e = 0, in a box 40 mean diameters wide (0.12 m), settled under gravity
//! until kinetic / potential energy < 10⁻⁸ (`KE = Σ ½ m |v|² + ½ I ω²`, `PE = Σ m g y` above the
//! floor). Two preparations:
//!
//! - [`Preparation::Pour`]: the grains start on loose rows ([`datasets::generators::rain()`]) and
//!   fall: the whole column compacts (the protocol of a soft-contact code's pour);
//! - [`Preparation::Deposit`]: sequential geometric deposition
//!   ([`datasets::generators::deposition`]), then the engine relaxes the packing under gravity.
//!
//! The engine settings of each are in [`ColumnRun`]; [`settle_column`] returns the timing and
//! the checks of the final state.
//!
//! For profiling and small test worlds: [`grid_world`], [`deposit_world`] (disks on a loose
//! seeded grid in a box).

use std::time::Instant;

use dem::math::Vector;
use dem::settle::{energy_ratio, settle, SettleReport};
use dem::step_control::StepControl;
use dem::{ContactLaws, SolverParams, World, WorldParams};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use datasets::error::Result;
use datasets::generators::{deposit, rain, spatial_order, uniform_radii, RainBox};

use crate::scenarios::common::build::{box_walls, GRAIN};
use crate::scenarios::common::config::{FrictionSpec, GrainSpec};

/// How the column is prepared before it settles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Preparation {
    /// Loose rows that fall and compact.
    Pour,
    /// Geometric sequential deposition, then relaxation.
    Deposit,
}

/// Engine settings of a settling run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ColumnRun {
    /// First time step (s), within `dt_range`.
    pub dt: f64,
    /// Time step range `[h_min, h_max]` (s) of the adaptive step ([`StepControl`]): halved after
    /// a capped step, doubled after a calm run. `[dt, dt]` keeps the step fixed.
    pub dt_range: [f64; 2],
    /// Solver tolerance (error measure of `docs/formats.md` §1.2).
    pub tolerance: f64,
    /// Sweep cap per step: a step that reaches it continues with its best iterate (counted).
    pub max_sweeps: usize,
    /// Colour-ordered parallel sweeps.
    pub parallel: bool,
    /// Start the first solve from the weight-carrying impulses
    /// ([`dem::World::prime_with_weight`]) rather than from zero.
    pub prime: bool,
    /// Longest simulated time (s).
    pub max_time: f64,
    /// Halvings of a fixed step whose solve does not converge
    /// ([`dem::SolverParams::max_halvings`]); unused with an adaptive step.
    #[serde(default)]
    pub max_halvings: u32,
    /// When the solves evaluate their error ([`dem::SolverParams::check_every`]; 0: the
    /// growing schedule of every scenario).
    #[serde(default)]
    pub check_every: usize,
}

impl ColumnRun {
    /// The settings used for `preparation`.
    ///
    /// - Pouring: 0.5 ms steps, at most 100 sweeps per attempt, a step that does not converge
    ///   redone in up to 32 sub-steps ([`dem::step_control::step_subdivided`]): a stalled
    ///   attempt is given up after 100 sweeps rather than 1000, and the smaller sub-steps of the
    ///   collapse converge. Measured on 2000 grains (CPU seconds, 2026-12-02): 100 sweeps and up
    ///   to 32 sub-steps, 75 060 sweeps in 4614 sub-steps, none capped, 13.0 s; 1000 sweeps and
    ///   up to 8 sub-steps, 199 529 sweeps, 2 capped, 18.0 s; 100 sweeps and up to 16, 27
    ///   capped; 50 sweeps and up to 64, 60 309 sweeps but 8085 sub-steps, 17.4 s (each
    ///   sub-step costs its detection and assembly, about 22 sweeps, before the detection kept
    ///   its candidate pairs between sub-steps: 1.3 times faster since, the same run bit for
    ///   bit). With 100 sweeps and no
    ///   subdivision the column settled 4 times faster but 251 of its 654 steps ended at the
    ///   cap; `auto` (Newton on stalled steps) was slower. The error is evaluated when the
    ///   sweeps' change predicts convergence, at least every 16 sweeps
    ///   ([`dem::solver::MEASURED_CHECK_EVERY`]), rather than after each of a short solve's
    ///   sweeps: 15 % less time over seeds 1–6 (2026-12-02, with the Anderson copies made by
    ///   the sweep), the solves stopping where their true error meets the tolerance all the
    ///   same; and a sub-step at the largest subdivision may sweep 10 times the cap
    ///   ([`dem::step_control::LAST_LEVEL_SWEEPS`]), which left no step capped over those
    ///   seeds (0–3 a run before).
    /// - Deposit: the first solve starts from the weight-carrying impulses, then an adaptive
    ///   step between 0.125 ms and 1 ms starting at 0.25 ms, at most 100 sweeps per step.
    ///   With a fixed 1 ms step the few dozen capped steps of the transient left overlaps of
    ///   1.3 % (2000 grains) and 6.4 % (10⁴ grains) of the smallest radius; the adaptive step
    ///   keeps them below 0.1 %.
    pub fn for_preparation(preparation: Preparation) -> Self {
        match preparation {
            Preparation::Pour => ColumnRun {
                dt: 5e-4,
                dt_range: [5e-4, 5e-4],
                tolerance: 1e-4,
                max_sweeps: 100,
                parallel: true,
                prime: false,
                max_time: 5.0,
                max_halvings: 5,
                check_every: dem::solver::MEASURED_CHECK_EVERY,
            },
            Preparation::Deposit => ColumnRun {
                dt: 2.5e-4,
                dt_range: [1.25e-4, 1e-3],
                tolerance: 1e-4,
                max_sweeps: 100,
                parallel: true,
                prime: true,
                max_time: 5.0,
                max_halvings: 0,
                check_every: 0,
            },
        }
    }

    /// The settings for a column of `grains` grains: those of `preparation`, with the parallel
    /// sweeps from [`PARALLEL_FROM_GRAINS`] grains on. Below, the colour-ordered sweep and its
    /// block copy cost more per step than a second thread saves: a deposited 2000-grain column
    /// took 8.1 ms per step in parallel mode on two threads against 6.8 ms in natural order on
    /// one.
    pub fn for_column(preparation: Preparation, grains: usize) -> Self {
        ColumnRun {
            parallel: grains >= PARALLEL_FROM_GRAINS,
            ..Self::for_preparation(preparation)
        }
    }

    /// The step control of this run, `None` for a fixed step (`dt_range = [dt, dt]`).
    pub fn step_control(&self) -> Option<StepControl> {
        let [lo, hi] = self.dt_range;
        (lo < hi).then(|| StepControl::new(lo, hi))
    }

    /// Checks `0 < h_min ≤ dt ≤ h_max` (finite).
    pub fn check(&self) -> Result<()> {
        let [lo, hi] = self.dt_range;
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo <= self.dt && self.dt <= hi) {
            return Err(datasets::DatasetError::Generator(format!(
                "column run: need 0 < dt_range[0] ≤ dt ≤ dt_range[1] (s), got dt = {} in [{lo}, {hi}]",
                self.dt
            )));
        }
        Ok(())
    }
}

/// What settling a column measured.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ColumnReport {
    /// The preparation.
    pub preparation: Preparation,
    /// Engine settings.
    pub run: ColumnRun,
    /// Seconds spent preparing the grains' positions (generator).
    pub prepare_seconds: f64,
    /// The settling run (its `wall_seconds` excludes the preparation).
    pub settle: SettleReport,
    /// Largest overlap in the final state relative to the smallest radius.
    pub final_overlap_ratio: f64,
    /// Solid fraction of the settled column: area of the grains whose centre lies between
    /// 2 R_max above the floor and 4 R_max below the top, over that band's area.
    pub solid_fraction: f64,
}

impl ColumnReport {
    /// Total wall seconds: preparation + settling.
    pub fn total_seconds(&self) -> f64 {
        self.prepare_seconds + self.settle.wall_seconds
    }
}

/// Fewest grains for which a benchmark column sweeps in parallel ([`ColumnRun::for_column`]).
pub const PARALLEL_FROM_GRAINS: usize = 5000;

const R_MIN: f64 = 1e-3;
const R_MAX: f64 = 2e-3;
/// Box width: 40 mean diameters (m).
pub const COLUMN_WIDTH: f64 = 40.0 * (R_MIN + R_MAX);

/// The benchmark column of `n` grains prepared as asked, with the engine settings of `run`.
pub fn janssen_column(
    n: usize,
    preparation: Preparation,
    run: &ColumnRun,
    seed: u64,
) -> Result<World> {
    let (grain, mut rng, radii) = benchmark_grains(n, seed);
    let centres = match preparation {
        Preparation::Pour => rain(
            &mut rng,
            &radii,
            &RainBox {
                x_min: 0.0,
                x_max: COLUMN_WIDTH,
                y_min: 0.0,
                gap: 0.02 * R_MIN,
                periodic: false,
            },
        )?,
        Preparation::Deposit => deposit(&mut rng, &radii, COLUMN_WIDTH, 1e-6 * R_MIN)?.centres,
    };
    let mut w = box_world(COLUMN_WIDTH, run, &centres, &radii, grain.density);
    w.validate(crate::scenarios::common::build::BUILD_TOLERANCE)?;
    Ok(w)
}

/// The benchmark grains: `n` seeded radii uniform in [R_MIN, R_MAX], density 2500 kg/m³; the
/// generator continues to place them.
fn benchmark_grains(n: usize, seed: u64) -> (GrainSpec, ChaCha8Rng, Vec<f64>) {
    let grain = GrainSpec {
        density: 2500.0,
        radius_mean: 0.5 * (R_MIN + R_MAX),
        radius_spread: 0.5 * (R_MAX - R_MIN),
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let radii = uniform_radii(&mut rng, n, grain.radius_mean, grain.radius_spread);
    (grain, rng, radii)
}

/// A box `width` wide (floor `y = 0`, walls `x = 0` and `x = width`), μ = 0.5 between grains
/// and with the walls, holding grains of the given centres and radii, with the engine settings
/// of `run`.
fn box_world(
    width: f64,
    run: &ColumnRun,
    centres: &[Vector],
    radii: &[f64],
    density: f64,
) -> World {
    let friction = FrictionSpec {
        grain_grain: 0.5,
        grain_wall: 0.5,
    };
    let params = dem::WorldParams {
        dt: run.dt,
        detection_gap: 0.1 * R_MIN,
        solver: dem::SolverParams {
            tolerance: run.tolerance,
            max_iterations: run.max_sweeps,
            parallel: run.parallel,
            // The benchmark measures Gauss–Seidel at a fixed sweep cap (the published tables);
            // one Newton iteration on 10⁴ grains costs as much as hundreds of sweeps.
            method: dem::fc::SolverMethod::Nlgs,
            max_halvings: run.max_halvings,
            check_every: run.check_every,
            last_level_sweeps: match run.max_halvings {
                0 => 1,
                _ => dem::step_control::LAST_LEVEL_SWEEPS,
            },
            ..Default::default()
        },
        ..Default::default()
    };
    let mut w = World::new(params, friction.laws());
    box_walls(&mut w, width);
    // Numbered along a Z-order curve: the deposition places grains all over the width, and in
    // placement order a bare sweep over 10⁶ grains ran at 1.4·10⁷ updates/s against 3.2·10⁷.
    for i in spatial_order(centres, 2.0 * R_MAX) {
        w.add_grain(centres[i], radii[i], density, GRAIN);
    }
    w
}

/// Prepares and settles the benchmark column (KE/PE < 10⁻⁸), timed.
pub fn settle_column(
    n: usize,
    preparation: Preparation,
    run: &ColumnRun,
    seed: u64,
) -> Result<ColumnReport> {
    run.check()?;
    let t0 = Instant::now();
    let mut w = janssen_column(n, preparation, run, seed)?;
    if run.prime {
        w.prime_with_weight()?;
    }
    let prepare_seconds = t0.elapsed().as_secs_f64();
    let mut settle = settle(&mut w, 1e-8, run.max_time, run.step_control());
    settle.width = COLUMN_WIDTH;
    debug_assert!(energy_ratio(&w) == settle.energy_ratio);
    let overlap = w
        .contacts()
        .geometry
        .iter()
        .map(|g| -g.gap)
        .fold(0.0, f64::max);
    // grains whose centre lies in the band [2 R_max, H − 4 R_max] (away from the floor layer
    // and the rough top) over the band's area: unbiased on average for a uniform packing
    let (y0, y1) = (2.0 * R_MAX, settle.height - 4.0 * R_MAX);
    let area: f64 = w
        .bodies
        .iter()
        .filter(|b| b.kind == dem::BodyKind::Grain && b.position.y >= y0 && b.position.y < y1)
        .map(|b| std::f64::consts::PI * b.radius * b.radius)
        .sum();
    Ok(ColumnReport {
        preparation,
        run: *run,
        prepare_seconds,
        settle,
        final_overlap_ratio: overlap / R_MIN,
        solid_fraction: area / (COLUMN_WIDTH * (y1 - y0).max(f64::MIN_POSITIVE)),
    })
}

/// One row of the engine scaling benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ScalingRow {
    /// Grains.
    pub grains: usize,
    /// Threads of the rayon pool the steps ran on.
    pub threads: usize,
    /// Mean contacts per timed step.
    pub contacts: f64,
    /// Mean sweeps per timed step.
    pub sweeps: f64,
    /// Wall seconds per timed step (detection + solve + update).
    pub seconds_per_step: f64,
    /// Contact updates per second over the whole step (contacts × sweeps / step time).
    pub updates_per_second: f64,
    /// Timed steps that reached the sweep cap.
    pub unconverged_steps: usize,
}

/// Rows of grains in the scaling deposit (the box widens with `n`, so the depth, hence the
/// sweeps a warm-started step needs, stays the same).
pub const SCALING_ROWS: f64 = 25.0;

/// A dense deposit of `n` grains (radius 1–2 mm, μ = 0.5, 2500 kg/m³) about [`SCALING_ROWS`]
/// grains deep in a box as wide as needed, made by geometric deposition and relaxed for
/// `relax_steps` steps of 1 ms (tolerance 10⁻⁴, at most 200 sweeps per step).
pub fn scaling_deposit(n: usize, relax_steps: usize, parallel: bool, seed: u64) -> Result<World> {
    let mean_area = std::f64::consts::PI * (R_MIN * R_MIN + R_MIN * R_MAX + R_MAX * R_MAX) / 3.0;
    let height = SCALING_ROWS * (R_MIN + R_MAX);
    let width = (n as f64 * mean_area / (0.8 * height)).max(4.0 * R_MAX);
    let (grain, mut rng, radii) = benchmark_grains(n, seed);
    let centres = deposit(&mut rng, &radii, width, 1e-6 * R_MIN)?.centres;
    let run = ColumnRun {
        dt: 1e-3,
        dt_range: [1e-3, 1e-3],
        tolerance: 1e-4,
        max_sweeps: 200,
        parallel,
        prime: false,
        max_time: f64::INFINITY,
        max_halvings: 0,
        check_every: 0,
    };
    let mut w = box_world(width, &run, &centres, &radii, grain.density);
    for _ in 0..relax_steps {
        w.step()?;
    }
    Ok(w)
}

/// Times `steps` steps of `w` on a rayon pool of `threads` threads.
pub fn time_steps(w: &mut World, steps: usize, threads: usize) -> Result<ScalingRow> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| datasets::DatasetError::Generator(format!("thread pool: {e}")))?;
    pool.install(|| {
        let (mut contacts, mut sweeps, mut unconverged, mut updates) =
            (0usize, 0usize, 0usize, 0f64);
        let t0 = Instant::now();
        for _ in 0..steps {
            let r = w.step()?;
            contacts += r.contacts;
            sweeps += r.solver.iterations;
            updates += (r.contacts * r.solver.iterations.max(1)) as f64;
            unconverged += usize::from(!r.solver.converged);
        }
        let secs = t0.elapsed().as_secs_f64();
        let k = steps.max(1) as f64;
        let grains = w
            .bodies
            .iter()
            .filter(|b| b.kind == dem::BodyKind::Grain)
            .count();
        Ok(ScalingRow {
            grains,
            threads,
            contacts: contacts as f64 / k,
            sweeps: sweeps as f64 / k,
            seconds_per_step: secs / k,
            updates_per_second: updates / secs.max(1e-12),
            unconverged_steps: unconverged,
        })
    })
}

/// Least-squares exponent `a` of `t = c · nᵃ` through the rows (log–log fit).
pub fn scaling_exponent(rows: &[ScalingRow]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.grains > 0 && r.seconds_per_step > 0.0)
        .map(|r| ((r.grains as f64).ln(), r.seconds_per_step.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let k = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / k,
        pts.iter().map(|p| p.1).sum::<f64>() / k,
    );
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// A box `width` wide holding `n` disks of radius in [1, 2] mm on a loose seeded grid, μ = 0.3,
/// density 2500 kg/m³, time step 2·10⁻⁴ s.
pub fn deposit_world(n: usize, width: f64, seed: u64) -> World {
    grid_world(n, width, 0.3, seed)
}

/// [`deposit_world`] with friction coefficient `mu`.
pub fn grid_world(n: usize, width: f64, mu: f64, seed: u64) -> World {
    let (r_min, r_max) = (1e-3, 2e-3);
    let params = WorldParams {
        dt: 2e-4,
        theta: 1.0,
        gravity: Vector::new(0.0, -9.81),
        periodic_x: None,
        detection_gap: 0.1 * r_min,
        overlap_rate: 1e-4,
        position_correction: true,
        solver: SolverParams {
            tolerance: 1e-4,
            max_iterations: 1000,
            ..Default::default()
        },
    };
    let mut w = World::new(params, ContactLaws::new(&["grain"], mu));
    w.add_box_walls(width, 0);
    let pitch = 2.0 * r_max * 1.02;
    let per_row = ((width / pitch).floor() as usize).max(1);
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut uniform = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    for i in 0..n {
        let (ix, iy) = (i % per_row, i / per_row);
        let r = r_min + (r_max - r_min) * uniform();
        let x = pitch * (ix as f64 + 0.5) + (uniform() - 0.5) * 0.02 * r_max;
        let y = pitch * (iy as f64 + 0.5);
        w.add_grain(Vector::new(x, y), r, 2500.0, 0);
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deposited column settles with the benchmark protocol: at rest (KE/PE < 1e-8),
    /// overlaps below 0.1 % of the smallest radius, dense (0.75 < φ < 0.9), and the step did
    /// adapt (it left its first value).
    #[test]
    fn a_deposited_column_of_300_grains_settles() {
        let run = ColumnRun::for_preparation(Preparation::Deposit);
        let r = settle_column(300, Preparation::Deposit, &run, 3).unwrap();
        assert!(r.settle.settled, "{r:?}");
        assert!(r.final_overlap_ratio < 1e-3, "{r:?}");
        assert!(r.solid_fraction > 0.75 && r.solid_fraction < 0.9, "{r:?}");
        let [lo, hi] = r.settle.dt_range;
        assert!(lo < hi, "{r:?}");
    }

    #[test]
    fn exponent_of_exact_power_laws() {
        let row = |n: usize, t: f64| ScalingRow {
            grains: n,
            threads: 1,
            contacts: 0.0,
            sweeps: 0.0,
            seconds_per_step: t,
            updates_per_second: 0.0,
            unconverged_steps: 0,
        };
        let lin: Vec<_> = [1e3, 1e4, 1e5]
            .iter()
            .map(|&n| row(n as usize, 2e-6 * n))
            .collect();
        assert!((scaling_exponent(&lin).unwrap() - 1.0).abs() < 1e-12);
        let quad: Vec<_> = [1e3, 1e4]
            .iter()
            .map(|&n| row(n as usize, 1e-9 * n * n))
            .collect();
        assert!((scaling_exponent(&quad).unwrap() - 2.0).abs() < 1e-12);
        assert!(scaling_exponent(&lin[..1]).is_none());
    }
}
