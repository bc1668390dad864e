//! `grainlaw bench`: the performance figures of the project in one table.
//!
//! 1. Frictional-contact problems of `docs/formats.md` §1 solved to 10⁻⁶ against Siconos fc2d
//!    NSGS ([`crate::fc_bench`]), and the hard ones by Lemke's method against Siconos' NSGS and
//!    Lemke: Siconos measured in the same run when it is installed ([`crate::siconos_peer`]),
//!    else its quoted figures, labelled as quoted.
//! 2. Bare Gauss–Seidel sweep throughput (contact updates per second, one core).
//! 3. Engine time per step of a settled deposit about 25 grains deep in a box that widens with
//!    N ([`crate::benchmarks::scaling_deposit`]), on 1 and 2 threads (colour-ordered
//!    parallel solve, the same numbers on both), with the fitted exponent of `t ∝ Nᵃ`.
//! 4. Janssen columns settled to kinetic / potential energy < 10⁻⁸
//!    ([`crate::benchmarks::settle_column`]) against a soft-contact code, LAMMPS (Hookean
//!    with history, one core), run in the same bench on the same initial column
//!    ([`crate::lammps_peer`]) when `lmp` is found; otherwise against its quoted times,
//!    labelled as quoted.
//! 5. Biaxial RVEs (the `biaxial` scenario's cell, [`crate::scenarios::biaxial::bench_rve`]):
//!    time per step and per percent of axial strain, with the solver counts.
//! 6. The representative-volume race (`--rve N`, [`rve_rows`]): grainlaw's `simple-shear`
//!    scenario against LAMMPS on the same grains ([`crate::lammps_rve_peer`]), seconds per unit
//!    shear strain, μ and φ of both.
//! 7. Memory per grain and per contact ([`crate::engine_bench::MemoryFootprint`]).

use std::path::Path;

use crate::benchmarks::{
    scaling_deposit, scaling_exponent, settle_column, time_steps, ColumnRun, Preparation,
    ScalingRow,
};

use crate::error::{CliError, Result};
use crate::scenarios::{biaxial, registry};

/// What to run.
#[derive(Debug, Clone)]
pub struct BenchPlan {
    /// Directory of the frictional-contact problems.
    pub fc_dir: std::path::PathBuf,
    /// Grain counts of the engine scaling rows.
    pub engine_grains: Vec<usize>,
    /// Thread counts of the engine rows.
    pub threads: Vec<usize>,
    /// Grain counts of deposited columns.
    pub columns: Vec<usize>,
    /// Grain counts of poured columns.
    pub pour: Vec<usize>,
    /// Seeds `1..=seeds` of the deposited and poured columns.
    pub seeds: u64,
    /// Steps that relax each engine deposit before the timed steps.
    pub relax_steps: usize,
    /// Grain counts of the read-and-homogenise rows (synthetic LAMMPS dumps); none by default.
    pub homogenise_grains: Vec<usize>,
    /// Grain counts of the biaxial RVE rows.
    pub biaxial_grains: Vec<usize>,
    /// Isotropic-compression steps before the timed axial steps of a biaxial row.
    pub biaxial_compress_steps: usize,
    /// Timed axial steps of a biaxial row.
    pub biaxial_steps: usize,
    /// The representative-volume race.
    pub rve: RvePlan,
}

/// What the representative-volume race runs (`grainlaw bench --rve N`, [`rve_rows`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RvePlan {
    /// Grain counts (none: no race).
    pub grains: Vec<usize>,
    /// Shear strain of each run.
    pub strain: f64,
    /// The last `average` of the strain is averaged.
    pub average: f64,
    /// Inertial number of the shear.
    pub inertial: f64,
    /// Settings of grainlaw's run (`KEY=VALUE`, as `grainlaw run --set`), after the race's own.
    pub sets: Vec<String>,
    /// Normal restitution of the LAMMPS peer between two grains of the mean mass (its dashpot,
    /// [`crate::lammps_peer::ContactModel::with_stiffness`]), in [0, 1).
    pub restitution: f64,
    /// Stiffness number κ = k_n / (P · 1 m) of the LAMMPS peer.
    pub kappa: f64,
    /// Which codes run.
    pub side: RveSide,
}

/// Which codes a race runs (`grainlaw bench --rve-only`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum RveSide {
    /// grainlaw and LAMMPS (the race).
    #[default]
    Both,
    /// grainlaw only (a measurement of μ and φ, no ratio).
    Grainlaw,
    /// LAMMPS only (the peer, on the grains grainlaw would start from).
    Lammps,
}

impl RveSide {
    /// Whether grainlaw runs.
    pub fn grainlaw(self) -> bool {
        self != RveSide::Lammps
    }

    /// Whether LAMMPS runs (when it is found).
    pub fn lammps(self) -> bool {
        self != RveSide::Grainlaw
    }
}

/// The standard error of μ the race prices (issue 34's target: a μ point with SE ≤ 0.005).
pub const TARGET_MU_SE: f64 = 0.005;

/// Seconds to a μ point whose standard error is `target`, estimated from a run that took
/// `prep` s to prepare its packing and `shear` s to shear it by `strain`, of which the last
/// `average` was averaged with standard error `se`. The standard error of a time average over
/// a stationary signal falls as `1/√T` once `T` exceeds its correlation time (Allen &
/// Tildesley, *Computer Simulation of Liquids*, 2nd ed. 2017, §8.4), so the averaged strain
/// needed is `a' = a (se/target)²` and
///
/// ```text
/// t = prep + (shear / strain) · (strain − a + a')
/// ```
///
/// (the transient `strain − a` is kept whole). NaN when an input is not finite or
/// `strain ≤ 0`.
pub fn seconds_to_precision(
    prep: f64,
    shear: f64,
    strain: f64,
    average: f64,
    se: f64,
    target: f64,
) -> f64 {
    if !(strain > 0.0 && average > 0.0 && se.is_finite() && target > 0.0) {
        return f64::NAN;
    }
    let needed = average * (se / target).powi(2);
    prep + shear / strain * (strain - average + needed)
}

/// Quoted wall seconds (range) of a soft-contact DEM code for a settled column of `n` grains
/// (issue 6: LAMMPS, Hookean with history, one core): printed, labelled as quoted, only when
/// LAMMPS is not there to be measured.
fn lammps_reference(n: usize) -> Option<(f64, f64)> {
    match n {
        2000 => Some((15.0, 25.0)),
        10000 => Some((190.0, 340.0)),
        _ => None,
    }
}

fn engine_rows(plan: &BenchPlan) -> Result<Vec<ScalingRow>> {
    if plan.engine_grains.is_empty() {
        return Ok(Vec::new());
    }
    println!(
        "\nengine, deposit ~25 grains deep after {} relaxation steps (radius 1–2 mm, μ = 0.5, h = 1 ms, tolerance 1e-4, at most 200 sweeps, parallel mode):",
        plan.relax_steps
    );
    println!(
        "{:>9} {:>7} {:>9} {:>7} {:>11} {:>11} {:>8} {:>11}",
        "grains", "threads", "contacts", "sweeps", "s/step", "updates/s", "speed-up", "sweep upd/s"
    );
    let mut one_thread = Vec::new();
    for &n in &plan.engine_grains {
        let w0 = scaling_deposit(n, plan.relax_steps, true, 1)?;
        let rate = crate::engine_bench::sweep_rate(&w0, 20);
        let steps = if n >= 500_000 {
            3
        } else if n >= 50_000 {
            10
        } else {
            20
        };
        let mut base = None;
        for &t in &plan.threads {
            let mut w = w0.clone();
            let r = time_steps(&mut w, steps, t)?;
            let speedup = base.map_or(1.0, |b: f64| b / r.seconds_per_step);
            if base.is_none() {
                base = Some(r.seconds_per_step);
            }
            println!(
                "{:>9} {:>7} {:>9.0} {:>7.1} {:>11.3e} {:>11.3e} {:>8.2} {:>11.3e}",
                r.grains,
                r.threads,
                r.contacts,
                r.sweeps,
                r.seconds_per_step,
                r.updates_per_second,
                speedup,
                rate
            );
            if t == plan.threads[0] {
                one_thread.push(r);
            }
        }
    }
    if let Some(a) = scaling_exponent(&one_thread) {
        let per_sweep: Vec<ScalingRow> = one_thread
            .iter()
            .map(|r| ScalingRow {
                seconds_per_step: r.seconds_per_step / r.sweeps.max(1.0),
                ..*r
            })
            .collect();
        let b = scaling_exponent(&per_sweep).unwrap_or(f64::NAN);
        println!(
            "on {} thread(s), least squares in log–log: time per step ∝ N^{a:.2}, time per sweep ∝ N^{b:.2}",
            plan.threads[0]
        );
    }
    Ok(one_thread)
}

/// The soft-contact peer's figure in the column table: its wall seconds and the ratio
/// grainlaw / LAMMPS when it settled, a label otherwise (never a number that looks right).
fn peer_cells(
    peer: Option<&crate::lammps_peer::PeerOutcome>,
    n: usize,
    total: f64,
) -> (String, String) {
    use crate::lammps_peer::PeerOutcome;
    match peer {
        Some(PeerOutcome::Ran(p)) if p.settled => (
            format!("{:.1}", p.wall_seconds),
            format!("{:.3}", total / p.wall_seconds),
        ),
        Some(PeerOutcome::Ran(_)) => ("NOT settled".into(), "–".into()),
        Some(PeerOutcome::Failed { .. }) => ("FAILED".into(), "–".into()),
        None => match lammps_reference(n) {
            Some((lo, hi)) => (
                format!("quoted {lo:.0}–{hi:.0}"),
                format!("{:.2}–{:.2}", total / hi, total / lo),
            ),
            None => ("–".into(), "–".into()),
        },
    }
}

/// The line under a column row that says what the peer did.
fn peer_line(peer: &crate::lammps_peer::PeerOutcome, column: &crate::lammps_peer::PeerColumn) {
    use crate::lammps_peer::PeerOutcome;
    match peer {
        PeerOutcome::Ran(p) => println!(
            "{:>7} LAMMPS: {:.1} s wall ({} in its loop), {} steps of {:.3} µs ({:.3} s simulated), KE/PE {:.2e}: {}; overlap/r {:.4}",
            "",
            p.wall_seconds,
            p.log
                .loop_seconds
                .map_or_else(|| "?".to_string(), |t| format!("{t:.1} s")),
            p.log.steps,
            column.model.dt * 1e6,
            p.log.simulated_seconds,
            p.log.energy_ratio,
            if p.settled {
                "settled".to_string()
            } else {
                format!(
                    "NOT settled (limits {:.1} s simulated, {:.0} s wall)",
                    column.max_time, column.wall_limit
                )
            },
            p.overlap_ratio
        ),
        PeerOutcome::Failed { reason, dir } => println!(
            "{:>7} LAMMPS FAILED: {reason} (files kept in {})",
            "",
            dir.display()
        ),
    }
}

/// The column table's name of a preparation.
fn preparation_name(prep: Preparation) -> &'static str {
    match prep {
        Preparation::Pour => "pour",
        Preparation::Deposit => "deposit",
    }
}

/// The Janssen-column race: per column size and preparation, grainlaw's settling over the
/// seeds and LAMMPS' on the same initial columns when it is found (stages: the header →
/// [`column_seeds`] per column → [`print_seed_totals`] → the footnote).
fn columns(plan: &BenchPlan) -> Result<()> {
    let jobs: Vec<(usize, Preparation)> = plan
        .columns
        .iter()
        .map(|&n| (n, Preparation::Deposit))
        .chain(plan.pour.iter().map(|&n| (n, Preparation::Pour)))
        .collect();
    if jobs.is_empty() {
        return Ok(());
    }
    let lammps = crate::lammps_peer::find_lammps();
    let wall_limit = crate::lammps_peer::wall_limit()?;
    print_columns_header(lammps.as_deref(), wall_limit);
    for (n, prep) in jobs {
        let totals = column_seeds(plan, n, prep, lammps.as_deref(), wall_limit)?;
        if plan.seeds > 1 {
            print_seed_totals(plan, n, prep, &totals, lammps.is_some());
        }
    }
    println!(
        "(capped: steps that stopped at the cap of {} sweeps (deposit) or {} sweeps in up to {} sub-steps (pour) with their best iterate;\n overlap/r: largest overlap over the smallest radius; h: the step range used, sub-steps included; a deposit starts from the\n weight-carrying impulses and adapts its step, halved after a capped step)",
        ColumnRun::for_preparation(Preparation::Deposit).max_sweeps,
        ColumnRun::for_preparation(Preparation::Pour).max_sweeps,
        1u32 << ColumnRun::for_preparation(Preparation::Pour).max_halvings
    );
    Ok(())
}

/// The column table's title, what LAMMPS is (measured or quoted), and the column heads.
fn print_columns_header(lammps: Option<&Path>, wall_limit: f64) {
    println!(
        "\nJanssen column settled to KE/PE < 1e-8 (radius 1–2 mm, μ = 0.5, box 40 mean diameters; one thread below {} grains, else all):",
        crate::benchmarks::PARALLEL_FROM_GRAINS
    );
    match lammps {
        Some(lmp) => println!(
            "LAMMPS peer measured in this run ({}, one core, serial): the same initial column, gran/hooke/history, k_n = 2e5 m g/d, k_t = 2/7 k_n,\n restitution 0.2 between mean grains, h = t_c/{}, KE/PE checked every {} steps, at most {:.0} s wall (GRAINLAW_LAMMPS_TIMEOUT); ratio = grainlaw/LAMMPS",
            lmp.display(),
            crate::lammps_peer::STEPS_PER_COLLISION,
            crate::lammps_peer::CHECK_EVERY,
            wall_limit
        ),
        None => println!(
            "LAMMPS not found (PATH, GRAINLAW_LAMMPS; or disabled by GRAINLAW_LAMMPS=off): its times are QUOTED, not measured (Hookean with history, one core); ratio = grainlaw/quoted"
        ),
    }
    println!(
        "{:>7} {:>8} {:>4} {:>6} {:>7} {:>7} {:>9} {:>10} {:>11} {:>9} {:>14} {:>9}",
        "grains",
        "prepare",
        "seed",
        "steps",
        "sweeps",
        "capped",
        "overlap/r",
        "φ",
        "h (ms)",
        "wall (s)",
        "LAMMPS (s)",
        "ratio"
    );
}

/// A column's results over the seeds.
struct SeedTotals {
    /// grainlaw's seconds.
    ours: f64,
    /// Whether every grainlaw run settled.
    all_settled: bool,
    /// grainlaw's capped steps.
    capped: u64,
    /// `(grainlaw s, LAMMPS s)` of each seed while every peer run settled.
    pairs: Vec<(f64, f64)>,
    /// Whether every peer run settled (LAMMPS' total is then the sum of the pairs').
    peer_settled: bool,
}

/// Settles the column of `n` grains prepared by `prep` for each seed, with LAMMPS on the same
/// initial column when it is found; prints a row per seed and returns the totals.
fn column_seeds(
    plan: &BenchPlan,
    n: usize,
    prep: Preparation,
    lammps: Option<&Path>,
    wall_limit: f64,
) -> Result<SeedTotals> {
    let run = ColumnRun::for_column(prep, n);
    let mut t = SeedTotals {
        ours: 0.0,
        all_settled: true,
        capped: 0,
        pairs: Vec::new(),
        peer_settled: true,
    };
    for seed in 1..=plan.seeds.max(1) {
        let r = settle_column(n, prep, &run, seed)?;
        let total = r.total_seconds();
        let peer = match lammps {
            Some(lmp) => {
                let w = crate::benchmarks::janssen_column(n, prep, &run, seed)?;
                let column =
                    crate::lammps_peer::PeerColumn::from_world(&w, 1e-8, run.max_time, wall_limit)?;
                let dir = std::env::temp_dir().join(format!(
                    "grainlaw-lammps-{}-{n}-{prep:?}-{seed}",
                    std::process::id()
                ));
                Some((crate::lammps_peer::run(lmp, &column, &dir)?, column))
            }
            None => None,
        };
        t.ours += total;
        t.all_settled &= r.settle.settled;
        t.capped += r.settle.unconverged_steps;
        match peer.as_ref().map(|p| &p.0) {
            Some(crate::lammps_peer::PeerOutcome::Ran(p)) if p.settled && t.peer_settled => {
                t.pairs.push((total, p.wall_seconds))
            }
            _ => t.peer_settled = false,
        }
        let (reference, ratio) = peer_cells(peer.as_ref().map(|p| &p.0), n, total);
        println!(
            "{:>7} {:>8} {:>4} {:>6} {:>7.1} {:>7} {:>9.4} {:>10.3} {:>11} {:>9.2} {:>14} {:>9}{}",
            n,
            preparation_name(prep),
            seed,
            r.settle.steps,
            r.settle.mean_sweeps,
            r.settle.unconverged_steps,
            r.final_overlap_ratio,
            r.solid_fraction,
            {
                let [lo, hi] = r.settle.dt_range;
                if lo < hi {
                    format!("{:.3}–{:.2}", lo * 1e3, hi * 1e3)
                } else {
                    format!("{:.2}", lo * 1e3)
                }
            },
            total,
            reference,
            ratio,
            if r.settle.settled {
                ""
            } else {
                "  NOT settled"
            }
        );
        if let Some((p, column)) = &peer {
            peer_line(p, column);
        }
    }
    Ok(t)
}

/// The row of a column's totals over the seeds, and the ratio of the totals with its interval
/// when every peer run settled.
fn print_seed_totals(
    plan: &BenchPlan,
    n: usize,
    prep: Preparation,
    t: &SeedTotals,
    measured: bool,
) {
    let theirs = t.pairs.iter().map(|p| p.1).sum::<f64>();
    let (reference, ratio) = if t.peer_settled && measured {
        (format!("{theirs:.1}"), format!("{:.3}", t.ours / theirs))
    } else {
        ("–".into(), "–".into())
    };
    println!(
        "{:>7} {:>8} {:>4} {:>6} {:>7} {:>7} {:>9} {:>10} {:>11} {:>9.2} {:>14} {:>9}{}",
        n,
        preparation_name(prep),
        format!("1–{}", plan.seeds),
        "",
        "",
        t.capped,
        "",
        "",
        "total",
        t.ours,
        reference,
        ratio,
        if t.all_settled {
            ""
        } else {
            "  NOT all settled"
        }
    );
    if let Some(e) = RatioOfTotals::estimate(&t.pairs).filter(|_| t.peer_settled) {
        println!(
            "        ratio of the totals {:.3}: standard error {:.3} over the {} seeds, 95 % interval {:.3}–{:.3} \
             (ratio estimator, t with {} degrees of freedom; {:.1}× to {} faster than LAMMPS)",
            e.ratio,
            e.standard_error,
            t.pairs.len(),
            e.interval[0],
            e.interval[1],
            t.pairs.len() - 1,
            1.0 / e.interval[1],
            if e.interval[0] > 0.0 {
                format!("{:.1}×", 1.0 / e.interval[0])
            } else {
                "any factor".to_string()
            },
        );
    }
}

/// The ratio of two totals over paired samples, `R = Σ x_i / Σ y_i` (here grainlaw's and LAMMPS'
/// seconds over the seeds of a column), with its standard error by the ratio estimator's
/// linearisation (W. G. Cochran, *Sampling Techniques*, 3rd ed., Wiley 1977, §6.3):
///
/// ```text
/// se(R) = √( Σ (x_i − R y_i)² / (n (n − 1)) ) / ȳ,      ȳ = Σ y_i / n,
/// ```
///
/// and the interval `R ∓ t_{0.975, n−1} se(R)`. The seeds' times scatter because each column
/// settles along its own chaotic trajectory; the interval says how far the ratio of another set
/// of seeds may fall, which a single ratio of totals does not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RatioOfTotals {
    /// `Σ x / Σ y`.
    pub ratio: f64,
    /// Its standard error.
    pub standard_error: f64,
    /// The 95 % interval.
    pub interval: [f64; 2],
}

impl RatioOfTotals {
    /// The estimate from `(x_i, y_i)` pairs; `None` with fewer than two pairs or a total of `y`
    /// that is not positive.
    pub fn estimate(pairs: &[(f64, f64)]) -> Option<Self> {
        let n = pairs.len();
        let (sx, sy) = pairs
            .iter()
            .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x, b + y));
        if n < 2 || sy.is_nan() || sy <= 0.0 || !sx.is_finite() {
            return None;
        }
        let ratio = sx / sy;
        let ss: f64 = pairs.iter().map(|&(x, y)| (x - ratio * y).powi(2)).sum();
        let standard_error = (ss / (n * (n - 1)) as f64).sqrt() / (sy / n as f64);
        let t = identify::stats::student_t_quantile(0.975, (n - 1) as f64);
        Some(Self {
            ratio,
            standard_error,
            interval: [ratio - t * standard_error, ratio + t * standard_error],
        })
    }
}

/// Runs the benchmark plan and prints the tables.
pub fn bench(plan: &BenchPlan) -> Result<()> {
    if plan.threads.is_empty() || plan.threads.contains(&0) {
        return Err(CliError::Usage("--threads must list counts ≥ 1".into()));
    }
    let peer = crate::siconos_peer::detect();
    run_fc(&plan.fc_dir, &peer)?;
    hard_rows(&plan.fc_dir.join("hard"), &peer)?;
    engine_rows(plan)?;
    columns(plan)?;
    homogenise_rows(plan)?;
    biaxial_rows(plan)?;
    rve_rows(&plan.rve)?;
    let mem = crate::engine_bench::MemoryFootprint::current(4);
    println!(
        "\nmemory: {} B per grain, {} B per contact; at 2 contacts per grain, 24 GiB hold about {:.1e} grains",
        mem.per_grain,
        mem.per_contact,
        mem.largest_sample(24 << 30, 2.0) as f64
    );
    let extra = crate::engine_bench::MemoryFootprint::parallel_extra();
    let both = crate::engine_bench::MemoryFootprint {
        per_grain: mem.per_grain + extra.per_grain,
        per_contact: mem.per_contact + extra.per_contact,
    };
    println!(
        "parallel mode adds {} B per grain, {} B per contact: about {:.1e} grains in 24 GiB",
        extra.per_grain,
        extra.per_contact,
        both.largest_sample(24 << 30, 2.0) as f64
    );
    Ok(())
}

/// The hard problems (`DIR/hard`, where Gauss–Seidel and Newton stall): Lemke's method from a
/// cold start to 10⁻⁸, pivots, error recomputed from `r`, seconds (one thread), beside Siconos
/// 4.4 fc2d on the same files. With the peer (`peer = Ok(python)`, [`crate::siconos_peer`]),
/// Siconos is run in this run: NSGS at tolerance 10⁻⁸ with at most 20 000 iterations and a
/// 60 s wall-clock cap, and Lemke (`fc2d_lexicolemke`, dense) at 10⁻⁸ with a 60 s cap; its
/// seconds are those of the solver call timed inside the script. Without it, the figures quoted
/// from `datasets/fc-problems/hard/README.md` ([`crate::siconos_peer::QUOTED_HARD`]).
/// `ratio` = Siconos Lemke seconds / ours, when both converged.
fn hard_rows(dir: &Path, peer: &std::result::Result<std::path::PathBuf, String>) -> Result<()> {
    use crate::siconos_peer::{self as sp, SiconosCell};
    if !dir.is_dir() {
        return Ok(());
    }
    let files = crate::fc_bench::problem_files(dir)?;
    println!(
        "
hard problems ({}), Lemke's method from a cold start to 1e-8, one thread; {}:",
        dir.display(),
        match peer {
            Ok(_) => "Siconos 4.4 fc2d MEASURED in this run (NSGS: 1e-8, at most 20000 iterations, 60 s cap; Lemke: 1e-8, 60 s cap; seconds of the solver call, one core)".to_string(),
            Err(why) => format!("Siconos 4.4 fc2d QUOTED from datasets/fc-problems/hard/README.md (NSGS 1e-8, at most 20000 iterations; Lemke \"-\": not finished in 120 s or not measured), not measured: {why}"),
        }
    );
    println!(
        "{:<30} {:>8} {:>7} {:>9} {:>8} | {:<8} {:>11} {:>6} {:>9} {:>4} | {:>11} {:>6} {:>9} {:>4} | {:>7}",
        "problem", "contacts", "pivots", "error", "seconds", "siconos", "NSGS s", "its", "error", "conv", "Lemke s", "pivots", "error", "conv", "ratio"
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| CliError::Usage(format!("cannot start a thread pool: {e}")))?;
    let mut failures = Vec::new();
    for f in files {
        let problem = dem::fc::read_problem(&f)?;
        let t0 = std::time::Instant::now();
        let (sol, report) = pool.install(|| {
            dem::fc::lemke::solve(
                &problem,
                dem::fc::lemke::Warm::default(),
                1e-8,
                &dem::fc::lemke::LemkeParams::default(),
            )
        })?;
        let seconds = t0.elapsed().as_secs_f64();
        let error = sol.map_or(f64::NAN, |s| dem::fc::fc_error(&problem, &s.r));
        let name = crate::fc_bench::problem_name(dir, &f);
        let (nsgs, lemke) = match peer {
            Ok(python) => {
                let req = |solver, max_iter| sp::PeerRequest {
                    solver,
                    tol: 1e-8,
                    max_iter,
                    repeat: 1,
                    repeat_budget: 0.0,
                    cap: std::time::Duration::from_secs(60),
                };
                (
                    SiconosCell::Measured(sp::solve(python, &f, &req("NSGS", 20_000))),
                    SiconosCell::Measured(sp::solve(python, &f, &req("LEMKE", 1_000_000))),
                )
            }
            Err(_) => {
                let q = sp::QUOTED_HARD.iter().find(|(n, _, _)| *n == name);
                (
                    SiconosCell::Quoted(q.map(|(_, (it, s, c), _)| (*it, *s, Some(*c)))),
                    SiconosCell::Quoted(q.and_then(|(_, _, l)| l.map(|(p, s)| (p, s, Some(true))))),
                )
            }
        };
        for cell in [&nsgs, &lemke] {
            if let Some(why) = cell.failure() {
                failures.push(format!("{name} {}: {why}", cell.source()));
            }
        }
        let [ns, ni, ne, nc] = nsgs.columns();
        let [ls, li, le, lc] = lemke.columns();
        let ours_ok = error <= 1e-8;
        println!(
            "{:<30} {:>8} {:>7} {:>9.2e} {:>8.3} | {:<8} {:>11} {:>6} {:>9} {:>4} | {:>11} {:>6} {:>9} {:>4} | {:>7}{}",
            name,
            problem.contacts(),
            report.pivots,
            error,
            seconds,
            nsgs.source(),
            ns, ni, ne, nc, ls, li, le, lc,
            lemke
                .ratio(seconds)
                .filter(|_| ours_ok)
                .map(|v| format!("{v:.1}x"))
                .unwrap_or_else(|| "-".into()),
            if ours_ok { "" } else { "  OURS NOT CONVERGED" }
        );
    }
    for f in failures {
        println!("  siconos failed: {f}");
    }
    Ok(())
}

/// Biaxial RVEs: compression, then timed steps of the axial compression.
fn biaxial_rows(plan: &BenchPlan) -> Result<()> {
    if plan.biaxial_grains.is_empty() {
        return Ok(());
    }
    println!(
        "\nbiaxial RVE (built-in `biaxial`, p0 = 1 kPa, dense: {} frictionless compression steps, then {} timed axial steps at I = 1e-3, μ = 0.5, tolerance 1e-4, the sweeps on {} thread(s), solver.parallel = true):",
        plan.biaxial_compress_steps,
        plan.biaxial_steps,
        rayon::current_num_threads()
    );
    println!(
        "{:>7} {:>10} {:>9} {:>8} {:>8} {:>8} {:>8} {:>11} {:>10}",
        "grains",
        "compress s",
        "contacts",
        "sweeps",
        "re-solve",
        "capped",
        "s/step",
        "strain/step",
        "s/percent"
    );
    for &n in &plan.biaxial_grains {
        let loaded = registry::load("biaxial", &biaxial::bench_sets(n))?;
        let c: crate::scenarios::biaxial::config::BiaxialConfig = registry::config_of(&loaded)?;
        let r = biaxial::bench_rve(&c, plan.biaxial_compress_steps, plan.biaxial_steps)?;
        println!(
            "{:>7} {:>10.1} {:>9.0} {:>8.1} {:>8.2} {:>8} {:>8.3} {:>11.2e} {:>10.0}",
            r.grains,
            r.compress_seconds,
            r.contacts,
            r.sweeps,
            r.corrections,
            r.unconverged,
            r.seconds_per_step,
            r.strain_per_step,
            r.seconds_per_percent
        );
    }
    println!("(sweeps: of the last solve of a step; re-solve: solves of a step repeated by the cell control; capped: steps stopped at the sweep cap)");
    Ok(())
}

/// Reading and homogenising synthetic LAMMPS dumps ([`crate::homogenise_cmd::bench_homogenise`]).
fn homogenise_rows(plan: &BenchPlan) -> Result<()> {
    if plan.homogenise_grains.is_empty() {
        return Ok(());
    }
    println!("\nread + homogenise a LAMMPS dump (synthetic, one snapshot, one thread):");
    println!(
        "{:>9} {:>9} {:>9} {:>12} {:>9}",
        "grains", "contacts", "read s", "homogenise s", "total s"
    );
    let dir = std::env::temp_dir();
    for &n in &plan.homogenise_grains {
        let (c, r, h) = crate::homogenise_cmd::bench_homogenise(n, &dir)?;
        println!("{n:>9} {c:>9} {r:>9.3} {h:>12.3} {:>9.3}", r + h);
    }
    Ok(())
}

/// The reference problems (`DIR`, tolerance 10⁻⁶ from `r = 0`, one thread) with
/// [`crate::fc_bench::run_reference_benchmarks`], beside Siconos 4.4 fc2d NSGS (sparse block
/// storage, 10⁻⁶, `r = 0`, one core): measured in this run when the peer is available
/// (`peer = Ok(python)`, [`crate::siconos_peer`]: seconds of the solver call timed inside the
/// script, best of up to 3 solves within 1 s, 300 s wall-clock cap per problem), else quoted
/// from [`crate::fc_bench::SICONOS_REFERENCE`] and labelled so.
fn run_fc(dir: &Path, peer: &std::result::Result<std::path::PathBuf, String>) -> Result<()> {
    use crate::siconos_peer::{self as sp, SiconosCell};
    // one thread: the comparison with Siconos is per core
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| CliError::Usage(format!("cannot start a thread pool: {e}")))?;
    let rows = pool.install(|| crate::fc_bench::run_reference_benchmarks(dir))?;
    if rows.is_empty() {
        return Err(CliError::io(dir, "no .json or .json.gz problems found"));
    }
    let files = crate::fc_bench::problem_files(dir)?;
    println!(
        "frictional-contact problems ({}), one thread; {}:",
        dir.display(),
        match peer {
            Ok(p) => format!("Siconos 4.4 fc2d NSGS MEASURED in this run ({} scripts/siconos_solve_fc.py, 1e-6 from r = 0, one core, seconds of the solver call, best of up to 3 solves within 1 s)", p.display()),
            Err(why) => format!("Siconos 4.4 fc2d NSGS QUOTED from an earlier measurement (datasets/fc-problems/README.md), not measured: {why}"),
        }
    );
    println!(
        "{:<48} {:>8} {:>6} {:>9} {:>9} {:>10} | {:<8} {:>10} {:>7} {:>9} {:>4} | {:>8}",
        "problem",
        "contacts",
        "iters",
        "error",
        "seconds",
        "Mupdates/s",
        "siconos",
        "seconds",
        "iters",
        "error",
        "conv",
        "ratio"
    );
    let mut failures = Vec::new();
    for r in &rows {
        let cell = match peer {
            Ok(python) => {
                let file = files
                    .iter()
                    .find(|f| crate::fc_bench::problem_name(dir, f) == r.problem);
                SiconosCell::Measured(match file {
                    Some(f) => sp::solve(
                        python,
                        f,
                        &sp::PeerRequest {
                            solver: "NSGS",
                            tol: 1e-6,
                            max_iter: 100_000,
                            repeat: 3,
                            repeat_budget: 1.0,
                            cap: std::time::Duration::from_secs(300),
                        },
                    ),
                    None => sp::PeerOutcome::Failed("problem file not found".into()),
                })
            }
            Err(_) => SiconosCell::Quoted(
                r.siconos_iterations
                    .zip(r.siconos_seconds)
                    .map(|(i, s)| (i, s, Some(true))),
            ),
        };
        if let Some(why) = cell.failure() {
            failures.push(format!("{}: {why}", r.problem));
        }
        let [s, i, e, c] = cell.columns();
        println!(
            "{:<48} {:>8} {:>6} {:>9.2e} {:>9.5} {:>10.1} | {:<8} {:>10} {:>7} {:>9} {:>4} | {:>8}{}",
            r.problem,
            r.contacts,
            r.iterations,
            r.error,
            r.seconds,
            r.updates_per_second / 1e6,
            cell.source(),
            s,
            i,
            e,
            c,
            cell.ratio(r.seconds)
                .filter(|_| r.converged)
                .map(|v| format!("{v:.1}x"))
                .unwrap_or_else(|| "-".into()),
            if r.converged { "" } else { "  NOT CONVERGED" }
        );
    }
    for f in failures {
        println!("  siconos failed: {f}");
    }
    println!(
        "(ratio: Siconos seconds / ours, when both converged and Siconos' time is at least 1e-4 s)"
    );
    Ok(())
}

/// The laws that a run at one inertial number cannot fit, left out of the race's runs.
const RVE_LEAVE_OUT: &str = r#"leave_out=["mu-i","mu-i-linear","phi-i"]"#;

/// The hand measurement of LAMMPS on the reference case (2000 grains, I = 0.01, strain 2, the
/// last 1 averaged; 2026-12-05, this machine, LAMMPS 29 Sep 2021, k_n = 10⁷ N/m, dt = 7.6 µs ≈
/// t_c/12, y held by a barostat): printed, labelled as quoted, when LAMMPS is not there.
struct QuotedRve {
    seconds_per_strain: f64,
    seconds: f64,
    steps: u64,
    mu: f64,
    mu_se: f64,
    phi: f64,
}

const QUOTED_RVE: QuotedRve = QuotedRve {
    seconds_per_strain: 17.0,
    seconds: 33.5,
    steps: 125_228,
    mu: 0.281,
    mu_se: 0.005,
    phi: 0.809,
};

/// grainlaw's side of one race.
struct OurRve {
    loaded: crate::scenarios::loader::LoadedScenario,
    total_seconds: f64,
    prep_seconds: f64,
    shear_seconds: f64,
    shear_steps: u64,
    total_steps: u64,
    mu: f64,
    mu_se: f64,
    phi: f64,
    phi_se: f64,
    /// The measured inertial number `γ̇ d / √(⟨−σ_yy⟩/ρ)` and normal stress `⟨−σ_yy⟩` (Pa).
    inertial: f64,
    pn: f64,
    overlap_ratio: f64,
    verdict: String,
    failure: Option<String>,
}

/// The settings of grainlaw's `simple-shear` run of `n` grains in the race: the plan's inertial
/// number, strain and averaged strain, the laws left out, then the plan's own `--rve-set`s.
fn rve_sets(n: usize, plan: &RvePlan) -> Vec<String> {
    let sets = vec![
        format!("grains={n}"),
        format!("inertial_numbers=[{:e}]", plan.inertial),
        format!("strain={:e}", plan.strain),
        format!("average_strain={:e}", plan.average),
        RVE_LEAVE_OUT.to_string(),
    ];
    sets.into_iter().chain(plan.sets.iter().cloned()).collect()
}

/// Runs the `simple-shear` scenario as `grainlaw run` does ([`crate::scenarios::run_controlled`]:
/// the same loading, phases, measurement and verdict), for `n` grains at `plan`'s inertial
/// number, strain and averaged strain, the laws left out, the scenario's default solver
/// settings, on one thread, no checkpoints, into a temporary directory removed afterwards.
fn grainlaw_rve(n: usize, plan: &RvePlan) -> Result<OurRve> {
    use std::sync::atomic::AtomicBool;
    use std::sync::Arc;
    let sets = rve_sets(n, plan);
    let loaded = crate::scenarios::registry::load("simple-shear", &sets)?;
    let dir = std::env::temp_dir().join(format!("grainlaw-bench-rve-{}-{n}", std::process::id()));
    let mut ctx = crate::scenarios::RunContext {
        out: crate::output::OutputDir::create(&dir)?,
        verbosity: crate::progress::Verbosity::Quiet,
        loaded: loaded.clone(),
        interrupted: Arc::new(AtomicBool::new(false)),
        dump: None,
    };
    let mut ctl = crate::scenarios::RunControl::new(
        sets,
        crate::scenarios::CheckpointPolicy {
            every_steps: None,
            every_seconds: None,
        },
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| CliError::Usage(format!("cannot start a thread pool: {e}")))?;
    let t0 = std::time::Instant::now();
    let outcome = pool.install(|| crate::scenarios::run_controlled(&mut ctx, &mut ctl));
    let total_seconds = t0.elapsed().as_secs_f64();
    let outcome = match outcome {
        Ok(o) => o,
        Err(e) => {
            return Err(CliError::Usage(format!(
                "bench --rve {n}: grainlaw's run failed: {} (files kept in {})",
                e.one_line(),
                dir.display()
            )))
        }
    };
    let _ = std::fs::remove_dir_all(&dir);
    let shear: Vec<&crate::scenarios::PhaseTime> = ctl
        .phase_times
        .iter()
        .filter(|p| p.name != "compress")
        .collect();
    let get = |k: &str| outcome.summary.get_f64(k).unwrap_or(f64::NAN);
    Ok(OurRve {
        loaded,
        total_seconds,
        prep_seconds: ctl
            .phase_times
            .iter()
            .filter(|p| p.name == "compress")
            .map(|p| p.wall_seconds)
            .sum(),
        shear_seconds: shear.iter().map(|p| p.wall_seconds).sum(),
        shear_steps: shear.iter().map(|p| p.steps).sum(),
        total_steps: ctl.phase_times.iter().map(|p| p.steps).sum(),
        mu: get("run1_mu"),
        mu_se: get("run1_mu_std_error"),
        phi: get("run1_phi"),
        phi_se: get("run1_phi_std_error"),
        inertial: get("run1_I"),
        pn: get("run1_P_Pa"),
        overlap_ratio: get("max_penetration_over_radius"),
        verdict: outcome
            .summary
            .get("verdict")
            .and_then(|v| v.as_str())
            .unwrap_or("?")
            .to_string(),
        failure: (!outcome.verdict.passes()).then(|| outcome.verdict.failure_line()),
    })
}

/// `m ± se` with the digits of the standard error.
fn pm(m: f64, se: f64) -> String {
    if se.is_finite() {
        format!("{m:.4} ± {se:.4}")
    } else {
        format!("{m:.4} ± –")
    }
}

/// The z-score of the difference of two means with standard errors, `(a − b) / √(se_a² + se_b²)`
/// (NaN when an error is not known).
pub fn z_score(a: f64, se_a: f64, b: f64, se_b: f64) -> f64 {
    (a - b) / (se_a * se_a + se_b * se_b).sqrt()
}

/// The representative-volume race (`grainlaw bench --rve N ...`): per grain count, grainlaw's
/// `simple-shear` scenario (`grainlaw_rve`) and LAMMPS on the same initial grains
/// ([`crate::lammps_rve_peer`]) when it is found (else the quoted hand measurement of the
/// reference case, labelled so), both on one core; one table of wall seconds (shear, total),
/// seconds per unit shear strain, steps, μ ± SE, φ ± SE and the largest overlap, then the
/// ratio LAMMPS / grainlaw of the seconds per unit strain with LAMMPS' settings beside it and
/// the z-score of the two μ (`rve_race` per grain count).
pub fn rve_rows(plan: &RvePlan) -> Result<()> {
    if plan.grains.is_empty() {
        return Ok(());
    }
    let lammps = crate::lammps_peer::find_lammps();
    let wall_limit = crate::lammps_peer::wall_limit()?;
    println!(
        "\nrepresentative volume (`simple-shear`: biperiodic Lees–Edwards cell, radii 1.5 mm ± 20 %, ρ = 2500 kg/m³, μ_p = 0.5, P = σ_yy = −1 kPa held,\n I = {}, shear strain {}, the last {} averaged; one core each; {}):",
        plan.inertial,
        plan.strain,
        plan.average,
        match &lammps {
            Some(l) => format!("LAMMPS measured in this run ({})", l.display()),
            None => "LAMMPS not found (PATH, GRAINLAW_LAMMPS; or disabled by GRAINLAW_LAMMPS=off): its figures are QUOTED, not measured".to_string(),
        }
    );
    for &n in &plan.grains {
        rve_race(n, plan, lammps.as_deref(), wall_limit)?;
    }
    println!("(overlap/R_min: largest overlap over the smallest radius, grainlaw at the start of every step, LAMMPS on its snapshots; LAMMPS' shear s is its loop time of the shear run)");
    Ok(())
}

/// LAMMPS' side of a race: its seconds per unit shear strain, μ, SE(μ), and `measured` or
/// `QUOTED`.
type TheirRve = (f64, f64, f64, &'static str);

/// One grain count of the race: grainlaw's run (unless `--rve-only lammps`) → LAMMPS' on the
/// same initial grains (unless `--rve-only grainlaw`; else the quoted figures) → the seconds to
/// a μ point of the target precision → the ratio and the z-scores → grainlaw's settings.
fn rve_race(n: usize, plan: &RvePlan, lammps: Option<&Path>, wall_limit: f64) -> Result<()> {
    use crate::lammps_rve_peer::{self as lr, PeerRve, RveOutcome};
    let ours = if plan.side.grainlaw() {
        Some(grainlaw_rve(n, plan)?)
    } else {
        None
    };
    let loaded = match &ours {
        Some(o) => o.loaded.clone(),
        None => crate::scenarios::registry::load("simple-shear", &rve_sets(n, plan))?,
    };
    let c: crate::scenarios::simple_shear::config::SimpleShearConfig =
        crate::scenarios::registry::config_of(&loaded)?;
    let contact = lr::PeerContact {
        kappa: plan.kappa,
        restitution: plan.restitution,
    };
    let peer = PeerRve::from_config(&c, plan.inertial, wall_limit, contact)?;
    let outcome = match lammps.filter(|_| plan.side.lammps()) {
        Some(lmp) => {
            let dir = std::env::temp_dir()
                .join(format!("grainlaw-lammps-rve-{}-{n}", std::process::id()));
            Some(lr::run(lmp, &peer, &dir)?)
        }
        None => None,
    };
    println!(
        "{:<18} {:>9} {:>9} {:>9} {:>15} {:>17} {:>17} {:>13}  verdict",
        format!("{n} grains"),
        "shear s",
        "total s",
        "s/strain",
        "steps shear/all",
        "μ ± SE",
        "φ ± SE",
        "overlap/R_min"
    );
    if let Some(ours) = &ours {
        println!(
            "{:<18} {:>9.1} {:>9.1} {:>9.2} {:>15} {:>17} {:>17} {:>12.3}%  {}",
            "grainlaw",
            ours.shear_seconds,
            ours.total_seconds,
            ours.shear_seconds / plan.strain,
            format!("{}/{}", ours.shear_steps, ours.total_steps),
            pm(ours.mu, ours.mu_se),
            pm(ours.phi, ours.phi_se),
            100.0 * ours.overlap_ratio,
            ours.verdict
        );
        println!(
            "{:<18} grainlaw: ⟨−σ_yy⟩ = {:.1} Pa, I = {:.4}",
            "", ours.pn, ours.inertial
        );
    }
    let theirs = match &outcome {
        Some(RveOutcome::Ran(r)) => lammps_rve_row(r, plan),
        Some(RveOutcome::Failed { reason, dir }) => {
            println!(
                "{:<18} FAILED: {reason} (files kept in {})",
                "LAMMPS",
                dir.display()
            );
            None
        }
        None if !plan.side.lammps() => {
            println!("{:<18} not run (--rve-only grainlaw)", "LAMMPS");
            None
        }
        None => quoted_rve_row(n, plan),
    };
    let m = &peer.model;
    let settings = format!(
        "κ = k_n/(P·1 m) = {:.0e} (k_n = {:.3e} N/m per m), dt = t_c/{} = {:.3} µs (t_c = {:.2} µs, two smallest grains), k_t/k_n = 2/7, e = {} (mean pair; grainlaw's e = {})",
        peer.kappa,
        m.kn,
        lr::STEPS_PER_COLLISION,
        m.dt * 1e6,
        m.collision_time * 1e6,
        peer.restitution,
        c.restitution
    );
    if let Some(ours) = &ours {
        let theirs_to_se = match &outcome {
            Some(RveOutcome::Ran(r)) if r.finished => seconds_to_precision(
                r.log.compression_seconds,
                r.log.shear_seconds,
                plan.strain,
                plan.average,
                r.measure.mu_se,
                TARGET_MU_SE,
            ),
            _ => f64::NAN,
        };
        print_precision(ours, plan, theirs_to_se);
        if let Some(t) = theirs {
            print_rve_ratio(t, ours, ours.shear_seconds / plan.strain, &settings);
        }
        if let Some(RveOutcome::Ran(r)) = &outcome {
            println!(
                " φ: z = {:.2} (LAMMPS − grainlaw, {:+.4})",
                z_score(r.measure.phi, r.measure.phi_se, ours.phi, ours.phi_se),
                r.measure.phi - ours.phi
            );
        }
    } else if theirs.is_some() {
        println!(" LAMMPS gran/hooke/history at {settings}, σ_yy servo on the height");
    }
    println!(
        " grainlaw: `simple-shear` {} (travel_per_step {}, solver {} to tolerance {:e}, at most {} sweeps, cell control {}, restitution {}), one thread, h = {:.3} ms in the shear; shear s is its shear phase, total s the whole run with its measurement",
        if plan.sets.is_empty() {
            "defaults".to_string()
        } else {
            format!("with {}", plan.sets.join(" "))
        },
        c.travel_per_step,
        c.solver.method.name(),
        c.solver.tolerance,
        c.solver.max_iterations,
        c.cell_control.as_str(),
        c.restitution,
        1e3 * c.shear_dt(peer.gamma_dot, peer.mean_diameter),
    );
    if let Some(f) = ours.as_ref().and_then(|o| o.failure.as_ref()) {
        println!(" grainlaw's verdict: {f}");
    }
    Ok(())
}

/// The rows of a LAMMPS run of the race; its side when it finished.
fn lammps_rve_row(r: &crate::lammps_rve_peer::RveRun, plan: &RvePlan) -> Option<TheirRve> {
    let per_strain = r.log.shear_seconds / plan.strain;
    println!(
        "{:<18} {:>9.1} {:>9.1} {:>9.2} {:>15} {:>17} {:>17} {:>12.3}%  {}",
        "LAMMPS",
        r.log.shear_seconds,
        r.wall_seconds,
        per_strain,
        format!("{}/{}", r.log.shear_steps, r.log.end_step),
        pm(r.measure.mu, r.measure.mu_se),
        pm(r.measure.phi, r.measure.phi_se),
        100.0 * r.overlap_ratio,
        if r.finished {
            "finished"
        } else {
            "NOT finished (wall-clock limit, GRAINLAW_LAMMPS_TIMEOUT)"
        }
    );
    println!(
        "{:<18} LAMMPS: compression {:.1} s, ⟨p_yy⟩ = {:.1} ± {:.1} Pa, I = {:.4}, Z = {:.2}, {} samples; overlap over {} snapshots",
        "",
        r.log.compression_seconds,
        r.measure.pn,
        r.measure.pn_se,
        r.measure.inertial_number,
        r.measure.z,
        r.measure.samples,
        crate::lammps_rve_peer::OVERLAP_SNAPSHOTS
    );
    r.finished
        .then_some((per_strain, r.measure.mu, r.measure.mu_se, "measured"))
}

/// Without LAMMPS: the quoted hand measurement's row for the reference case (2000 grains,
/// I = 0.01, strain 2, the last 1 averaged), else a line saying there is none.
fn quoted_rve_row(n: usize, plan: &RvePlan) -> Option<TheirRve> {
    let reference = n == 2000 && plan.inertial == 0.01 && plan.strain == 2.0 && plan.average == 1.0;
    if !reference {
        println!(
            "{:<18} no quoted figures for this case (only 2000 grains, I = 0.01, strain 2, the last 1 averaged)",
            "LAMMPS"
        );
        return None;
    }
    let q = &QUOTED_RVE;
    println!(
        "{:<18} {:>9.1} {:>9} {:>9.2} {:>15} {:>17} {:>17} {:>13}  quoted (hand measurement, 2026-12-05)",
        "LAMMPS (quoted)",
        q.seconds,
        "–",
        q.seconds_per_strain,
        format!("{}/–", q.steps),
        pm(q.mu, q.mu_se),
        format!("{:.3}", q.phi),
        "≤ 0.1 % d̄",
    );
    Some((q.seconds_per_strain, q.mu, q.mu_se, "QUOTED"))
}

/// The estimated seconds to a μ point with SE [`TARGET_MU_SE`], grainlaw's and LAMMPS'
/// (`theirs_to_se`, NaN when not measured).
fn print_precision(ours: &OurRve, plan: &RvePlan, theirs_to_se: f64) {
    let ours_to_se = seconds_to_precision(
        ours.prep_seconds,
        ours.shear_seconds,
        plan.strain,
        plan.average,
        ours.mu_se,
        TARGET_MU_SE,
    );
    println!(
        "seconds to a μ point with SE {TARGET_MU_SE} (estimated: preparation + transient + the averaged strain that SE needs, SE ∝ 1/√strain): grainlaw {ours_to_se:.1} (verdict {}), {}",
        ours.verdict,
        if theirs_to_se.is_finite() {
            format!(
                "LAMMPS {theirs_to_se:.1}, ratio LAMMPS/grainlaw {:.3}",
                theirs_to_se / ours_to_se
            )
        } else {
            "LAMMPS not measured in this run".to_string()
        }
    );
}

/// The ratio LAMMPS/grainlaw of the seconds per unit shear strain, LAMMPS' `settings`, and
/// the z-score of the two μ.
fn print_rve_ratio(theirs: TheirRve, ours: &OurRve, ours_per_strain: f64, settings: &str) {
    let (per_strain, mu, mu_se, how) = theirs;
    let z = z_score(mu, mu_se, ours.mu, ours.mu_se);
    println!(
        "ratio LAMMPS/grainlaw of the seconds per unit shear strain: {:.3} ({how}; LAMMPS gran/hooke/history at {settings}{});\n μ: z = {:.2} ({})",
        per_strain / ours_per_strain,
        if how == "QUOTED" {
            ", quoted: k_n = 1e7 N/m, dt = 7.6 µs ≈ t_c/12"
        } else {
            ", σ_yy servo on the height"
        },
        z,
        if !z.is_finite() {
            "a standard error is not known"
        } else if z.abs() <= 2.0 {
            "the two μ agree within two combined standard errors"
        } else {
            "the two μ DIFFER by more than two combined standard errors"
        }
    );
}

#[cfg(test)]
mod ratio_tests {
    use super::RatioOfTotals;

    /// Times proportional to the peer's: the ratio exactly, no spread.
    #[test]
    fn proportional_times_have_no_spread() {
        let pairs = [(2.0, 10.0), (6.0, 30.0), (4.4, 22.0)];
        let e = RatioOfTotals::estimate(&pairs).unwrap();
        assert!((e.ratio - 0.2).abs() < 1e-15);
        assert!(e.standard_error < 1e-15);
    }

    /// Two seeds worked by hand: R = 4/20 = 0.2, residuals −1 and 1, se = √(2/2)/10 = 0.1, and
    /// t_{0.975,1} = 12.7062 (tables), so the interval is 0.2 ∓ 1.27062.
    #[test]
    fn two_seeds_by_hand() {
        let e = RatioOfTotals::estimate(&[(1.0, 10.0), (3.0, 10.0)]).unwrap();
        assert!((e.ratio - 0.2).abs() < 1e-15);
        assert!((e.standard_error - 0.1).abs() < 1e-12);
        assert!((e.interval[1] - (0.2 + 1.270_62)).abs() < 1e-4);
        assert!((e.interval[0] - (0.2 - 1.270_62)).abs() < 1e-4);
    }

    /// Fewer than two seeds, or no peer time: no estimate.
    #[test]
    fn too_few_seeds_give_none() {
        assert!(RatioOfTotals::estimate(&[(1.0, 5.0)]).is_none());
        assert!(RatioOfTotals::estimate(&[(1.0, 0.0), (1.0, 0.0)]).is_none());
    }

    /// Prepared in 20 s, sheared by 5 in 100 s with the last 4 averaged to SE 0.01: a SE of
    /// 0.005 needs 4 × (0.01/0.005)² = 16 averaged, so 20 + 20 × (1 + 16) = 360 s.
    #[test]
    fn seconds_to_precision_by_hand() {
        let t = super::seconds_to_precision(20.0, 100.0, 5.0, 4.0, 0.01, 0.005);
        assert!((t - 360.0).abs() < 1e-9, "{t}");
        // Already precise enough: fewer averaged strain than run (0.25 × 4 = 1), 20 + 20 × 2.
        let t = super::seconds_to_precision(20.0, 100.0, 5.0, 4.0, 0.0025, 0.005);
        assert!((t - 60.0).abs() < 1e-9, "{t}");
        assert!(super::seconds_to_precision(1.0, 1.0, 1.0, 1.0, f64::NAN, 0.005).is_nan());
    }

    /// μ of 0.30 ± 0.03 against 0.26 ± 0.04: z = 0.04 / √(0.03² + 0.04²) = 0.8 (a 3-4-5
    /// triangle); an unknown error gives NaN.
    #[test]
    fn z_score_by_hand() {
        assert!((super::z_score(0.30, 0.03, 0.26, 0.04) - 0.8).abs() < 1e-12);
        assert!((super::z_score(0.26, 0.04, 0.30, 0.03) + 0.8).abs() < 1e-12);
        assert!(super::z_score(0.3, f64::NAN, 0.2, 0.01).is_nan());
    }
}
