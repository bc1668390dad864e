//! The `grainlaw` command line (`docs/cli.md`).
//!
//! ```text
//! grainlaw [run [SCENARIO] [--out DIR] [--set KEY=VALUE ...] [--quiet] [--allow-suspect]]   (default: run janssen)
//!          [--checkpoint-every STEPS] [--checkpoint-seconds S]
//! grainlaw run --resume DIR [--checkpoint-every STEPS] [--checkpoint-seconds S] [--quiet]
//! grainlaw scenarios [--show NAME]
//! grainlaw fit LAW DATA.csv [MORE.csv ...] [--out law.json]
//! grainlaw solve-fc PROBLEM.json [--tol T] [--method nlgs|newton|auto|lemke] [--out SOLUTION.json]
//! grainlaw bench [--dir DIR] [--engine-grains N ...] [--rve N ...]
//! ```
//!
//! Every error is one line on stderr and exit code 2. A run that finishes with a `refused`
//! verdict, or `suspect` without `--allow-suspect` ([`crate::verdict`]), writes everything, its
//! laws as `NAME_law.rejected.json`, and exits with 3.
//!
//! `run` writes a checkpoint (`OUT/checkpoint/run.json.gz`, [`crate::checkpoint`]) every
//! `--checkpoint-seconds` (default 60 s of wall-clock time) and every `--checkpoint-every` steps
//! (default: not by steps; 0 turns either off). Ctrl-C stops the run after the current step with
//! a checkpoint there, no `summary.json`, one line saying how to resume, and exit code 130 (the
//! shells' code for SIGINT, so that scripts tell "stopped, resumable" from "failed"); a second
//! Ctrl-C quits at once. `run --resume DIR` continues the run in DIR with the checkpoint's
//! scenario and overrides (a SCENARIO or `--set` given as well must be the same) and gives the
//! same files as an uninterrupted run, `wall_seconds` aside.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use clap::{Parser, Subcommand};

use crate::checkpoint::{self, RunCheckpoint};
use crate::error::{CliError, Result};
use crate::output::OutputDir;
use crate::progress::Verbosity;
use crate::scenarios::phased::DEFAULT_CHECKPOINT_SECONDS;
use crate::scenarios::{self, registry, CheckpointPolicy, RunContext, RunControl};

/// grainlaw: discrete-element simulations of granular media turned into calibrated continuum laws.
#[derive(Debug, Parser)]
#[command(name = "grainlaw", version, about, long_about = None, allow_negative_numbers = true)]
pub struct Cli {
    /// What to do (default: `run janssen`).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a scenario end to end (simulation, homogenisation, fits, figures, summary.json).
    Run(RunArgs),
    /// List the built-in scenarios, or print one's full TOML.
    Scenarios {
        /// Print the full TOML of this scenario.
        #[arg(long, value_name = "NAME")]
        show: Option<String>,
    },
    /// Fit a law to your own data: janssen, janssen-kmu, wall-law, mu-i, mu-i-linear, phi-i,
    /// mohr-coulomb. Exit code 2 for bad input, 3 when the fit is refused.
    Fit {
        /// Law name.
        law: String,
        /// CSV file (units in the headers, `# key = value` constants); several files of the
        /// same columns are merged as `campaign --collect` merges its runs' tables.
        #[arg(required = true, num_args = 1..)]
        data: Vec<PathBuf>,
        /// Write the calibrated law here (JSON); without it the JSON goes to stdout.
        #[arg(long, value_name = "LAW.json")]
        out: Option<PathBuf>,
    },
    /// Solve one frictional-contact problem (fc-problem-v1 JSON, plain or gzip).
    SolveFc {
        /// The problem file.
        problem: PathBuf,
        /// Tolerance on the error measure.
        #[arg(long, default_value_t = 1e-6, allow_negative_numbers = true)]
        tol: f64,
        /// Largest number of Gauss–Seidel sweeps.
        #[arg(long, default_value_t = 100_000)]
        max_iterations: usize,
        /// The solver: nlgs (Gauss–Seidel), newton (proximal semismooth Newton), auto
        /// (Gauss–Seidel, then Newton if it stalls, then Lemke's method if still unconverged)
        /// or lemke (Lemke's complementary pivoting method alone: exact).
        #[arg(long, default_value = "auto")]
        method: String,
        /// Write `{"r", "u", "iterations", "error", "seconds", "converged"}` here.
        #[arg(long, value_name = "SOLUTION.json")]
        out: Option<PathBuf>,
    },
    /// Run a sweep of scenario runs from a plan (TOML: `scenario`, `[set]`, `[sweep]`), in
    /// parallel, resumable, then merge their tables and fit the laws (docs/cli.md §9).
    Campaign {
        /// The plan file.
        plan: PathBuf,
        /// The campaign directory (default `grainlaw-out/campaign-PLANSTEM`).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Run only the K-th share (1-based) of `--of N` (a cluster job array's task).
        #[arg(long, value_name = "K")]
        task: Option<usize>,
        /// Number of shares the runs are split into.
        #[arg(long, value_name = "N")]
        of: Option<usize>,
        /// Only merge the finished runs and fit the laws.
        #[arg(long)]
        collect: bool,
        /// Runs at once (default: the cores available).
        #[arg(long, value_name = "J")]
        jobs: Option<usize>,
    },
    /// Run a calibrated μ(I) law in a continuum solver (Gerris) and compare with DEM:
    /// `column-collapse` or `inclined-plane` (docs/continuum.md). Exit code 2 for bad input, 3
    /// for a refused result or a missing or failing solver.
    #[command(subcommand)]
    Continuum(ContinuumCommand),
    /// Homogenise snapshots of another DEM code (LAMMPS/LIGGGHTS dumps, LMGC90 files, plain
    /// grainlaw-snapshot-v1 JSON): stresses, fabric, wall loads, profiles, figures, VTK.
    Homogenise(HomogeniseArgs),
    /// Solve the reference frictional-contact problems and compare with Siconos' times.
    Bench {
        /// Directory of the reference problems (default: the repository's
        /// `datasets/fc-problems`, or `GRAINLAW_FC_DIR`).
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
        /// Grain counts of the engine benchmark (settled deposits); none to skip it.
        #[arg(long, value_name = "N", num_args = 0.., default_values_t = [1000usize, 10000])]
        engine_grains: Vec<usize>,
        /// Thread counts of the engine rows (the first is the reference of the speed-up).
        #[arg(long, value_name = "T", num_args = 1.., default_values_t = [1usize, 2])]
        threads: Vec<usize>,
        /// Grain counts of the deposited Janssen columns settled to KE/PE < 1e-8; none to skip.
        #[arg(long, value_name = "N", num_args = 0.., default_values_t = [2000usize])]
        columns: Vec<usize>,
        /// Grain counts of the poured Janssen columns (slower); none by default.
        #[arg(long, value_name = "N", num_args = 0..)]
        pour: Vec<usize>,
        /// Seeds of the deposited and poured columns: 1 to K, each run by grainlaw and by the
        /// LAMMPS peer, with the totals (the time to settle follows the grains' chaotic
        /// trajectory: a single seed's ratio moves by tens of percent).
        #[arg(long, value_name = "K", default_value_t = 1)]
        seeds: u64,
        /// Steps relaxing each engine deposit before the timed steps.
        #[arg(long, value_name = "STEPS", default_value_t = 30)]
        relax_steps: usize,
        /// Grain counts of synthetic LAMMPS dumps read and homogenised (none by default).
        #[arg(long, value_name = "N", num_args = 0..)]
        homogenise_grains: Vec<usize>,
        /// Grain counts of the biaxial RVE rows (none by default: a 10⁴-grain row takes minutes).
        #[arg(long, value_name = "N", num_args = 0..)]
        biaxial_grains: Vec<usize>,
        /// Isotropic-compression steps of a biaxial row before its timed steps (default: the
        /// built-in scenario's compression_time / dt_max, 0.15 s / 2.5e-4 s).
        #[arg(long, value_name = "STEPS", default_value_t = 600)]
        biaxial_compress_steps: usize,
        /// Timed axial steps of a biaxial row.
        #[arg(long, value_name = "STEPS", default_value_t = 20)]
        biaxial_steps: usize,
        /// Grain counts of the representative-volume race (none by default): grainlaw's
        /// `simple-shear` scenario against LAMMPS on the same grains, both on one core.
        #[arg(long, value_name = "N", num_args = 0..)]
        rve: Vec<usize>,
        /// Shear strain of the representative-volume runs.
        #[arg(long, value_name = "S", default_value_t = 2.0)]
        rve_strain: f64,
        /// The last part of the strain averaged in the representative-volume runs.
        #[arg(long, value_name = "A", default_value_t = 1.0)]
        rve_average: f64,
        /// Inertial number of the representative-volume runs.
        #[arg(long, value_name = "I", default_value_t = 0.01)]
        rve_inertial: f64,
        /// A setting of grainlaw's `simple-shear` run in the race, as `grainlaw run --set`
        /// takes it (repeatable), e.g. `--rve-set solver.max_iterations=300`; the LAMMPS side
        /// follows the same grains, pressure and inertial number (`seed=N`: both codes start
        /// from the grains of seed N; `restitution=E`: grainlaw's Newton restitution).
        #[arg(long = "rve-set", value_name = "KEY=VALUE")]
        rve_set: Vec<String>,
        /// Normal restitution of the LAMMPS peer between two grains of the mean mass, in
        /// [0, 1): its dashpot γ_n from e = exp(−π ζ / √(1 − ζ²)). grainlaw's own is the
        /// `restitution` key of `simple-shear` (`--rve-set restitution=E`, default 0).
        #[arg(long, value_name = "E", default_value_t = crate::lammps_rve_peer::RESTITUTION, value_parser = parse_restitution)]
        rve_restitution: f64,
        /// Stiffness number κ = k_n / (P · 1 m) of the LAMMPS peer (≥ 100; 10⁴ is the rigid
        /// limit of da Cruz et al. 2005); its step stays t_c / 12.
        #[arg(long, value_name = "K", default_value_t = crate::lammps_rve_peer::KAPPA)]
        rve_kappa: f64,
        /// Run one code of the race only (`grainlaw` or `lammps`; default both).
        #[arg(long, value_enum, value_name = "CODE", default_value_t = crate::bench_cmd::RveSide::Both)]
        rve_only: crate::bench_cmd::RveSide,
    },
}

/// The cases of `grainlaw continuum`.
#[derive(Debug, Subcommand)]
pub enum ContinuumCommand {
    /// The 2D collapse of a granular column (Lagrée, Staron & Popinet 2011): front x_f(t*) and
    /// height profiles h(x), compared with a DEM `column-collapse` run's.
    ColumnCollapse(ColumnArgs),
    /// Steady flow down a slope: Gerris' profile against the analytic Bagnold profile of the
    /// law and a DEM `inclined-flow` run's velocity profile.
    InclinedPlane(InclinedArgs),
}

/// The options of `grainlaw continuum column-collapse`.
#[derive(Debug, Clone, clap::Args)]
pub struct ColumnArgs {
    /// The calibrated μ(I) law (`mu_i_law.json`, schema 2: mu-i or mu-i-linear).
    #[arg(long, value_name = "LAW.json")]
    pub law: PathBuf,
    /// The continuum solver (only `gerris`).
    #[arg(long, default_value = "gerris")]
    pub solver: String,
    /// Output directory (default `grainlaw-out/continuum-column-collapse`).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// A DEM `column-collapse` output directory: compared with, and the set-up (a, R0, φ, g,
    /// the instants, the time of rest) taken from it.
    #[arg(long, value_name = "DEM_OUTPUT_DIR")]
    pub dem: Option<PathBuf>,
    /// Aspect ratio a = H0/R0 (default: the DEM's, else 6.26).
    #[arg(long, value_name = "A")]
    pub aspect_ratio: Option<f64>,
    /// Initial half-width R0 (m) (default: the DEM's, else d/0.04623 as in the Gerris example).
    #[arg(long, value_name = "METRES")]
    pub half_width: Option<f64>,
    /// Packing fraction φ of the continuum, its density φ ρ_s (default: the DEM's initial one;
    /// needed without --dem).
    #[arg(long, value_name = "PHI")]
    pub packing_fraction: Option<f64>,
    /// Gerris refinement level: cells of domain/2^L in and around the grains.
    #[arg(long, value_name = "L", default_value_t = crate::continuum::column::DEFAULT_LEVEL)]
    pub level: u32,
    /// Side of the square domain, in units of R0 (default: the power of two ≥ 2.5 a).
    #[arg(long, value_name = "R0S")]
    pub domain: Option<f64>,
    /// End of the run in t* = t √(g/H0) (default: the DEM's time of rest, else 4).
    #[arg(long, value_name = "T_STAR")]
    pub t_end: Option<f64>,
    /// Cap of the μ(I) viscosity in Gerris units ρ_b √(g R0³) (the zones at rest creep at
    /// about μ P / cap).
    #[arg(long, value_name = "ETA", default_value_t = crate::continuum::column::DEFAULT_VISCOSITY_CAP)]
    pub viscosity_cap: f64,
    /// Also run the band of the law's uncertainty (2p + 1 runs along the covariance's
    /// principal axes) and say whether the DEM lies inside it.
    #[arg(long)]
    pub band: bool,
    /// Gerris runs at once for the band (default: the cores available).
    #[arg(long, value_name = "J")]
    pub jobs: Option<usize>,
    /// The Gerris 2D command (default `gerris2D` on the PATH).
    #[arg(long, value_name = "PATH")]
    pub gerris: Option<PathBuf>,
    /// A suspect result (the law used far outside its calibrated range) exits 0.
    #[arg(long)]
    pub allow_suspect: bool,
    /// No report on stdout.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The options of `grainlaw continuum inclined-plane`.
#[derive(Debug, Clone, clap::Args)]
pub struct InclinedArgs {
    /// The calibrated μ(I) law (`mu_i_law.json`, schema 2: mu-i or mu-i-linear).
    #[arg(long, value_name = "LAW.json")]
    pub law: PathBuf,
    /// The continuum solver (only `gerris`).
    #[arg(long, default_value = "gerris")]
    pub solver: String,
    /// Output directory (default `grainlaw-out/continuum-inclined-plane`).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// A DEM `inclined-flow` output directory: compared with, slope, depth and φ taken from it.
    #[arg(long, value_name = "DEM_OUTPUT_DIR")]
    pub dem: Option<PathBuf>,
    /// Slope angle (degrees) (default: the DEM's).
    #[arg(long, value_name = "DEG")]
    pub slope_deg: Option<f64>,
    /// Layer thickness H (m) (default: the DEM's flow height, else 20 d).
    #[arg(long, value_name = "METRES")]
    pub depth: Option<f64>,
    /// Packing fraction φ of the layer (default: the DEM layer's mean; needed without --dem).
    #[arg(long, value_name = "PHI")]
    pub packing_fraction: Option<f64>,
    /// Gerris refinement level (2^L cells across the layer).
    #[arg(long, value_name = "L", default_value_t = crate::continuum::inclined::DEFAULT_LEVEL)]
    pub level: u32,
    /// Cap of the μ(I) viscosity in Gerris units ρ_b √(g H³).
    #[arg(long, value_name = "ETA", default_value_t = crate::continuum::inclined::DEFAULT_VISCOSITY_CAP)]
    pub viscosity_cap: f64,
    /// The Gerris 2D command (default `gerris2D` on the PATH).
    #[arg(long, value_name = "PATH")]
    pub gerris: Option<PathBuf>,
    /// A suspect result exits 0.
    #[arg(long)]
    pub allow_suspect: bool,
    /// No report on stdout.
    #[arg(long, short)]
    pub quiet: bool,
}

fn check_solver(solver: &str) -> Result<()> {
    if solver == "gerris" {
        Ok(())
    } else {
        Err(CliError::Usage(format!(
            "--solver {solver}: the only continuum solver is `gerris`"
        )))
    }
}

/// `grainlaw continuum …`: runs the case, prints its warnings (stderr) and report (stdout);
/// exit 3 when its verdict does not pass.
fn continuum_cmd(cmd: ContinuumCommand) -> Result<()> {
    let (lines, warnings, verdict, dir, quiet) = match cmd {
        ContinuumCommand::ColumnCollapse(a) => {
            check_solver(&a.solver)?;
            let out = a
                .out
                .unwrap_or_else(|| PathBuf::from("grainlaw-out").join("continuum-column-collapse"));
            let mut plan = crate::continuum::ColumnPlan::new(a.law, out);
            plan.inputs.dem = a.dem;
            plan.aspect_ratio = a.aspect_ratio;
            plan.half_width_m = a.half_width;
            plan.inputs.packing_fraction = a.packing_fraction;
            plan.inputs.level = a.level;
            plan.domain = a.domain;
            plan.end_t_star = a.t_end;
            plan.inputs.viscosity_cap = a.viscosity_cap;
            plan.band = a.band;
            plan.jobs = a
                .jobs
                .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
            plan.inputs.gerris = a.gerris;
            plan.inputs.allow_suspect = a.allow_suspect;
            let o = crate::continuum::column_collapse(&plan)?;
            (o.lines, o.warnings, o.verdict, o.dir, a.quiet)
        }
        ContinuumCommand::InclinedPlane(a) => {
            check_solver(&a.solver)?;
            let out = a
                .out
                .unwrap_or_else(|| PathBuf::from("grainlaw-out").join("continuum-inclined-plane"));
            let mut plan = crate::continuum::InclinedPlan::new(a.law, out.clone());
            plan.inputs.dem = a.dem;
            plan.slope_deg = a.slope_deg;
            plan.depth_m = a.depth;
            plan.inputs.packing_fraction = a.packing_fraction;
            plan.inputs.level = a.level;
            plan.inputs.viscosity_cap = a.viscosity_cap;
            plan.inputs.gerris = a.gerris;
            plan.inputs.allow_suspect = a.allow_suspect;
            let o = crate::continuum::inclined_plane(&plan)?;
            (o.lines, o.warnings, o.verdict, out, a.quiet)
        }
    };
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    if !quiet {
        for l in &lines {
            println!("{l}");
        }
    }
    if verdict.passes() {
        Ok(())
    } else {
        Err(CliError::Verdict {
            dir: dir.display().to_string(),
            reason: verdict.failure_line(),
        })
    }
}

/// A restitution coefficient of `--rve-restitution`: a number in [0, 1).
fn parse_restitution(s: &str) -> std::result::Result<f64, String> {
    let e: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("a restitution must be a number in [0, 1), got '{s}'"))?;
    if (0.0..1.0).contains(&e) {
        Ok(e)
    } else {
        Err(format!("a restitution must lie in [0, 1), got {e}"))
    }
}

/// Parses `args` and runs; returns the process exit code (0; 2 on any error; 3 for a refused
/// result; 130 for an interrupted run).
pub fn main_with_args<I, T>(args: I) -> i32
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            match e.kind() {
                ErrorKind::DisplayHelp
                | ErrorKind::DisplayVersion
                | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    let _ = e.print();
                    return 0;
                }
                _ => {
                    let text = e.to_string();
                    let first = text.lines().next().unwrap_or("error: bad arguments").trim();
                    let first = first.strip_prefix("error: ").unwrap_or(first);
                    eprintln!("error: {first} (see grainlaw --help)");
                    return 2;
                }
            }
        }
    };
    match dispatch(cli.command) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {}", e.one_line());
            e.exit_code()
        }
    }
}

/// The options of `grainlaw run`.
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// A built-in scenario name (see `grainlaw scenarios`) or a TOML file path (default
    /// `janssen`; with `--resume`, the checkpoint's).
    pub scenario: Option<String>,
    /// Output directory (default `grainlaw-out/SCENARIO`).
    #[arg(long, value_name = "DIR", conflicts_with = "resume")]
    pub out: Option<PathBuf>,
    /// Override a scenario key (dotted keys for tables), e.g. `--set grains=2000`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// No progress bars and no report on stdout (warnings and errors still go to stderr).
    #[arg(long, short)]
    pub quiet: bool,
    /// Continue the interrupted run whose output directory is DIR, from its checkpoint
    /// (scenario and overrides are the checkpoint's; output continues in DIR).
    #[arg(long, value_name = "DIR")]
    pub resume: Option<PathBuf>,
    /// Write a checkpoint every STEPS steps (all phases together; 0: not by steps).
    #[arg(long, value_name = "STEPS", default_value_t = 0)]
    pub checkpoint_every: u64,
    /// Write a checkpoint every S seconds of wall-clock time (0: not by time).
    #[arg(long, value_name = "S", default_value_t = DEFAULT_CHECKPOINT_SECONDS)]
    pub checkpoint_seconds: f64,
    /// Write the frictional-contact problems of chosen steps into DIR as fc-problem-v1 files
    /// (`PHASE_STEP.json.gz`), for `grainlaw solve-fc` or another solver; by default the steps
    /// whose solve did not converge.
    #[arg(long, value_name = "DIR")]
    pub dump_problems: Option<PathBuf>,
    /// With --dump-problems: write the steps FIRST..LAST (inclusive indices of the world's steps, a subdivided step counting its sub-steps, as in the names of the files written).
    #[arg(
        long,
        value_name = "FIRST..LAST",
        requires = "dump_problems",
        conflicts_with = "dump_capped"
    )]
    pub dump_steps: Option<String>,
    /// With --dump-problems: write the steps whose solve did not converge (the default).
    #[arg(long, requires = "dump_problems")]
    pub dump_capped: bool,
    /// Export suspect laws as calibrated laws (marked `"verdict": "suspect"`) and exit with 0;
    /// refused results are never exported as laws. Recorded in the checkpoint.
    #[arg(long)]
    pub allow_suspect: bool,
    /// Test hook: stop as Ctrl-C does after this many steps of this invocation.
    #[arg(long, value_name = "STEPS", hide = true)]
    pub stop_after_steps: Option<u64>,
}

impl Default for RunArgs {
    /// `grainlaw run` with no option: janssen, checkpoints every
    /// [`DEFAULT_CHECKPOINT_SECONDS`].
    fn default() -> Self {
        RunArgs {
            scenario: None,
            out: None,
            set: Vec::new(),
            quiet: false,
            resume: None,
            checkpoint_every: 0,
            checkpoint_seconds: DEFAULT_CHECKPOINT_SECONDS,
            dump_problems: None,
            dump_steps: None,
            dump_capped: false,
            allow_suspect: false,
            stop_after_steps: None,
        }
    }
}

/// The options of `grainlaw homogenise` (`docs/cli.md`).
#[derive(Debug, Clone, clap::Args)]
pub struct HomogeniseArgs {
    /// Input format: lammps (also liggghts), lmgc90 or plain.
    #[arg(long, value_name = "FORMAT")]
    pub from: String,
    /// The files (per-atom and local dumps; BODIES.DAT, DOF.OUT, Vloc_Rloc.OUT; JSON), plain or .gz.
    #[arg(required = true, value_name = "FILES")]
    pub files: Vec<PathBuf>,
    /// Output directory (default `grainlaw-out/homogenise`).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Friction coefficient of the contacts, for the mobilisation |f_t|/(μ f_n).
    #[arg(long)]
    pub mu: Option<f64>,
    /// Friction coefficient of the wall contacts when the walls have their own (default:
    /// --mu); written as the wall friction of the Janssen table.
    #[arg(long)]
    pub wall_mu: Option<f64>,
    /// Time step (s): times of LAMMPS dumps without ITEM: TIME are step × dt.
    #[arg(long)]
    pub dt: Option<f64>,
    /// Gravity `GX,GY` (m/s²).
    #[arg(
        long,
        value_name = "GX,GY",
        default_value = "0,-9.81",
        allow_hyphen_values = true
    )]
    pub gravity: String,
    /// Moment of inertia I = K m R² for LAMMPS (0.5 disks, 0.4 spheres).
    #[arg(long, value_name = "K", default_value_t = 0.5)]
    pub inertia_factor: f64,
    /// Grain density (kg/m³) for LMGC90 (Umas of BULK_BEHAV.DAT).
    #[arg(long)]
    pub density: Option<f64>,
    /// LAMMPS local-dump column of a key: `id1=c_ids[1]`, `fx=c_pf[2]`, ... (repeatable).
    #[arg(long = "column", value_name = "KEY=HEADER")]
    pub columns: Vec<String>,
    /// No report on stdout.
    #[arg(long, short)]
    pub quiet: bool,
}

fn homogenise_cmd(a: HomogeniseArgs) -> Result<()> {
    let format = a.from.parse().map_err(CliError::Usage)?;
    let g: Vec<f64> = a
        .gravity
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .ok()
        .filter(|v: &Vec<f64>| v.len() == 2 && v.iter().all(|x| x.is_finite()))
        .ok_or_else(|| CliError::Usage(format!("--gravity `{}`: expected GX,GY", a.gravity)))?;
    let plan = crate::homogenise_cmd::HomogenisePlan {
        format,
        files: a.files,
        out: a
            .out
            .unwrap_or_else(|| PathBuf::from("grainlaw-out").join("homogenise")),
        options: crate::readers::ReadOptions {
            gravity: [g[0], g[1]],
            mu: a.mu,
            wall_mu: a.wall_mu,
            dt: a.dt,
            inertia_factor: a.inertia_factor,
            density: a.density,
            columns: crate::homogenise_cmd::parse_columns(&a.columns)?,
        },
        quiet: a.quiet,
    };
    let outcome = crate::homogenise_cmd::homogenise(&plan)?;
    if !plan.quiet {
        for l in outcome.lines {
            println!("{l}");
        }
    }
    Ok(())
}

fn dispatch(cmd: Option<Command>) -> Result<()> {
    match cmd.unwrap_or(Command::Run(RunArgs::default())) {
        Command::Run(args) => run(args),
        Command::Homogenise(args) => homogenise_cmd(args),
        Command::Continuum(cmd) => continuum_cmd(cmd),
        Command::Scenarios { show } => scenarios_cmd(show.as_deref()),
        Command::Fit { law, data, out } => crate::fit_cmd::fit_files(&law, &data, out.as_deref()),
        Command::Campaign {
            plan,
            out,
            task,
            of,
            collect,
            jobs,
        } => crate::campaign::campaign(crate::campaign::CampaignArgs {
            plan,
            out,
            task,
            of,
            collect,
            jobs,
        }),
        Command::SolveFc {
            problem,
            tol,
            max_iterations,
            method,
            out,
        } => crate::fc_cmd::solve_fc(&problem, tol, max_iterations, &method, out.as_deref()),
        Command::Bench {
            dir,
            engine_grains,
            threads,
            columns,
            pour,
            seeds,
            relax_steps,
            homogenise_grains,
            biaxial_grains,
            biaxial_compress_steps,
            biaxial_steps,
            rve,
            rve_strain,
            rve_average,
            rve_inertial,
            rve_set,
            rve_restitution,
            rve_kappa,
            rve_only,
        } => crate::bench_cmd::bench(&crate::bench_cmd::BenchPlan {
            fc_dir: dir.unwrap_or_else(crate::fc_cmd::default_dir),
            engine_grains,
            threads,
            columns,
            pour,
            seeds,
            relax_steps,
            homogenise_grains,
            biaxial_grains,
            biaxial_compress_steps,
            biaxial_steps,
            rve: crate::bench_cmd::RvePlan {
                grains: rve,
                strain: rve_strain,
                average: rve_average,
                inertial: rve_inertial,
                sets: rve_set,
                restitution: rve_restitution,
                kappa: rve_kappa,
                side: rve_only,
            },
        }),
    }
}

/// `grainlaw run`: a new run, or with `resume` the continuation of an interrupted one.
pub fn run(args: RunArgs) -> Result<()> {
    if !(args.checkpoint_seconds >= 0.0 && args.checkpoint_seconds.is_finite()) {
        return Err(CliError::Usage(format!(
            "--checkpoint-seconds must be a finite number ≥ 0, got {}",
            args.checkpoint_seconds
        )));
    }
    let policy = CheckpointPolicy {
        every_steps: (args.checkpoint_every > 0).then_some(args.checkpoint_every),
        every_seconds: (args.checkpoint_seconds > 0.0).then_some(args.checkpoint_seconds),
    };
    let mut allow_suspect = args.allow_suspect;
    let (loaded, dir, sets) = match &args.resume {
        Some(dir) => {
            let loaded = resumed_scenario(dir, args.scenario.as_deref(), &args.set)?;
            allow_suspect |= loaded.2;
            (loaded.0, dir.clone(), loaded.1)
        }
        None => {
            let spec = args.scenario.as_deref().unwrap_or(registry::DEFAULT);
            let loaded = registry::load(spec, &args.set)?;
            let dir = args
                .out
                .clone()
                .unwrap_or_else(|| PathBuf::from("grainlaw-out").join(&loaded.name));
            crate::output::dir::check_out_dir(&dir, loaded.config.kind())?;
            (loaded, dir, args.set.clone())
        }
    };
    let verbosity = if args.quiet {
        Verbosity::Quiet
    } else {
        Verbosity::Normal
    };
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        let out_dir = dir.clone();
        // The first Ctrl-C, SIGTERM (what batch schedulers send before they kill a job) or
        // SIGHUP asks for a checkpoint and a clean stop after the current step, and says so at
        // once; a second one stops at once (files are written atomically: nothing half-written
        // is left that looks complete). A second handler cannot be installed (library callers
        // may run several times in one process): ignore.
        let _ = ctrlc::set_handler(move || {
            if flag.swap(true, Ordering::SeqCst) {
                eprintln!("error: interrupted twice: stopped at once (the last checkpoint, if any, is kept)");
                checkpoint::remove_temporaries(&out_dir);
                std::process::exit(130);
            }
            eprintln!(
                "warning: stop requested: writing a checkpoint after the current step (a second signal stops at once)"
            );
        });
    }
    let dump = match &args.dump_problems {
        Some(d) => Some(Arc::new(scenarios::dump::ProblemDump {
            dir: d.clone(),
            steps: match &args.dump_steps {
                Some(t) => scenarios::dump::ProblemDump::parse_range(t)?,
                None => scenarios::dump::DumpSteps::Capped,
            },
            scenario: loaded.name.clone(),
        })),
        None => None,
    };
    let mut ctx = RunContext {
        out: OutputDir::create(&dir)?,
        verbosity,
        loaded,
        interrupted,
        dump,
    };
    let mut ctl = RunControl::new(sets, policy);
    ctl.resume = args.resume.is_some();
    ctl.stop_after_steps = args.stop_after_steps;
    ctl.allow_suspect = allow_suspect;
    let outcome = scenarios::run_controlled(&mut ctx, &mut ctl)?;
    if !args.quiet {
        for l in outcome.headline.iter().chain(&outcome.verdict.lines()) {
            println!("{l}");
        }
    }
    if outcome.verdict.passes() {
        Ok(())
    } else {
        Err(CliError::Verdict {
            dir: dir.display().to_string(),
            reason: outcome.verdict.failure_line(),
        })
    }
}

/// The scenario of the checkpoint in `dir`, with its overrides and `--allow-suspect`; refuses a missing or unreadable
/// checkpoint, and a SCENARIO or `--set` given on the command line that differs from it.
fn resumed_scenario(
    dir: &Path,
    scenario: Option<&str>,
    set: &[String],
) -> Result<(crate::scenarios::loader::LoadedScenario, Vec<String>, bool)> {
    let cp: RunCheckpoint<serde::de::IgnoredAny> = checkpoint::read(dir)?;
    let rec = cp.scenario;
    let refuse = |given: String| CliError::Checkpoint {
        path: checkpoint::file_of(dir).display().to_string(),
        reason: format!(
            "the run there is `{}`, not `{given}`: resume it with `grainlaw run --resume {}` alone",
            rec.describe(),
            dir.display()
        ),
    };
    match scenario {
        Some(spec) => {
            let given = registry::load(spec, set)?;
            if given.effective_toml != rec.effective_toml {
                let mut g = given.source.clone();
                for o in set {
                    g.push_str(" --set ");
                    g.push_str(o);
                }
                return Err(refuse(g));
            }
        }
        None if !set.is_empty() && set != rec.sets.as_slice() => {
            let g = set
                .iter()
                .map(|o| format!("--set {o}"))
                .collect::<Vec<_>>()
                .join(" ");
            return Err(refuse(format!("{} {g}", rec.source)));
        }
        None => {}
    }
    let loaded =
        registry::from_text(&rec.name, &rec.source, &rec.effective_toml, &[]).map_err(|e| {
            CliError::Checkpoint {
                path: checkpoint::file_of(dir).display().to_string(),
                reason: format!("its scenario does not load any more ({e})"),
            }
        })?;
    Ok((loaded, rec.sets, rec.allow_suspect))
}

fn scenarios_cmd(show: Option<&str>) -> Result<()> {
    match show {
        Some(name) => {
            let s = registry::get(name)?;
            print!("{}", s.builtin_toml());
            // the laws it fits and the data each needs, from the same table the load checks
            let loaded = registry::load(name, &[])?;
            let needs = crate::scenarios::common::laws::describe(&loaded.config.law_needs());
            if !needs.is_empty() {
                println!("\n{}", needs.join("\n"));
            }
        }
        None => {
            for s in registry::SCENARIOS.iter() {
                println!("{:<15} {}", s.name(), s.description());
            }
            println!("\nRun one with `grainlaw run NAME`, print its keys with `grainlaw scenarios --show NAME`.");
        }
    }
    Ok(())
}

#[cfg(test)]
mod rve_option_tests {
    use super::{Cli, Command};
    use crate::bench_cmd::RveSide;
    use clap::Parser;

    fn bench(args: &[&str]) -> Option<(f64, RveSide, Vec<String>)> {
        let all = ["grainlaw", "bench"].iter().chain(args).copied();
        match Cli::try_parse_from(all).ok()?.command? {
            Command::Bench {
                rve_restitution,
                rve_only,
                rve_set,
                ..
            } => Some((rve_restitution, rve_only, rve_set)),
            _ => None,
        }
    }

    /// The race's peer restitution and side: defaults (e = the peer's constant, both codes),
    /// set values, and values outside [0, 1) or unknown sides refused by the parser.
    #[test]
    fn the_race_options_parse() {
        let (e, side, sets) = bench(&["--rve", "2000"]).unwrap();
        assert_eq!(e, crate::lammps_rve_peer::RESTITUTION);
        assert_eq!(side, RveSide::Both);
        assert!(sets.is_empty());
        let (e, side, sets) = bench(&[
            "--rve",
            "2000",
            "--rve-restitution",
            "0.05",
            "--rve-only",
            "lammps",
            "--rve-set",
            "seed=3",
        ])
        .unwrap();
        assert_eq!((e, side), (0.05, RveSide::Lammps));
        assert_eq!(sets, vec!["seed=3".to_string()]);
        assert!(side.lammps() && !side.grainlaw());
        let (_, side, _) = bench(&["--rve-only", "grainlaw"]).unwrap();
        assert!(side.grainlaw() && !side.lammps());
        assert_eq!(bench(&["--rve-restitution", "0"]).unwrap().0, 0.0);
        for bad in ["1", "1.5", "-0.1", "NaN", "x"] {
            assert!(bench(&["--rve-restitution", bad]).is_none(), "{bad}");
        }
        assert!(bench(&["--rve-only", "siconos"]).is_none());
        match Cli::try_parse_from(["grainlaw", "bench", "--rve-kappa", "1e5"])
            .unwrap()
            .command
        {
            Some(Command::Bench { rve_kappa, .. }) => assert_eq!(rve_kappa, 1e5),
            _ => panic!("not bench"),
        }
    }
}
