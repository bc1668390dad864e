//! The `grainlaw` command line (DESIGN §5).
//!
//! ```text
//! grainlaw [run [SCENARIO] [--out DIR] [--set KEY=VALUE ...] [--quiet]]   (default: run janssen)
//! grainlaw scenarios [--show NAME]
//! grainlaw fit LAW DATA.csv [--out law.json]
//! grainlaw solve-fc PROBLEM.json [--tol T] [--out SOLUTION.json]
//! grainlaw bench [--dir DIR] [--tol T]
//! ```
//!
//! Every error is one line on stderr and exit code 2.

use std::ffi::OsString;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use clap::{Parser, Subcommand};

use crate::error::{CliError, Result};
use crate::output::OutputDir;
use crate::progress::Verbosity;
use crate::scenarios::{self, RunContext};

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
    Run {
        /// A built-in scenario name (see `grainlaw scenarios`) or a TOML file path.
        #[arg(default_value = "janssen")]
        scenario: String,
        /// Output directory (default `grainlaw-out/SCENARIO`).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Override a scenario key (dotted keys for tables), e.g. `--set grains=2000`.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// No progress bars and no report on stdout (warnings and errors still go to stderr).
        #[arg(long, short)]
        quiet: bool,
    },
    /// List the built-in scenarios, or print one's full TOML.
    Scenarios {
        /// Print the full TOML of this scenario.
        #[arg(long, value_name = "NAME")]
        show: Option<String>,
    },
    /// Fit a law to your own data: janssen, janssen-kmu, wall-law, mu-i, phi-i, mohr-coulomb.
    Fit {
        /// Law name.
        law: String,
        /// CSV file (units in the headers, `# key = value` constants).
        data: PathBuf,
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
        /// Write `{"r", "u", "iterations", "error", "seconds"}` here.
        #[arg(long, value_name = "SOLUTION.json")]
        out: Option<PathBuf>,
    },
    /// Solve the reference frictional-contact problems and compare with Siconos' times.
    Bench {
        /// Directory of the reference problems (default: the repository's
        /// `datasets/fc-problems`, or `GRAINLAW_FC_DIR`).
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
        /// Grain counts of the engine benchmark (settled deposits); none to skip it.
        #[arg(long, value_name = "N", num_args = 0.., default_values_t = [1000usize])]
        engine_grains: Vec<usize>,
    },
}

/// Parses `args` and runs; returns the process exit code (0, or 2 on any error).
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
            2
        }
    }
}

fn dispatch(cmd: Option<Command>) -> Result<()> {
    match cmd.unwrap_or(Command::Run {
        scenario: "janssen".into(),
        out: None,
        set: Vec::new(),
        quiet: false,
    }) {
        Command::Run {
            scenario,
            out,
            set,
            quiet,
        } => run(&scenario, out, &set, quiet),
        Command::Scenarios { show } => scenarios_cmd(show.as_deref()),
        Command::Fit { law, data, out } => crate::fit_cmd::fit(&law, &data, out.as_deref()),
        Command::SolveFc {
            problem,
            tol,
            max_iterations,
            out,
        } => crate::fc_cmd::solve_fc(&problem, tol, max_iterations, out.as_deref()),
        Command::Bench { dir, engine_grains } => {
            crate::fc_cmd::bench(dir.as_deref(), &engine_grains)
        }
    }
}

fn run(spec: &str, out: Option<PathBuf>, set: &[String], quiet: bool) -> Result<()> {
    let loaded = datasets::load(spec, set)?;
    let dir = out.unwrap_or_else(|| PathBuf::from("grainlaw-out").join(&loaded.name));
    let verbosity = if quiet {
        Verbosity::Quiet
    } else {
        Verbosity::Normal
    };
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        // A second handler cannot be installed (tests run several times in one process): ignore.
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    }
    let mut ctx = RunContext {
        out: OutputDir::create(&dir)?,
        verbosity,
        loaded,
        interrupted,
    };
    let outcome = scenarios::run(&mut ctx)?;
    if !quiet {
        for l in outcome.headline {
            println!("{l}");
        }
    }
    Ok(())
}

fn scenarios_cmd(show: Option<&str>) -> Result<()> {
    match show {
        Some(name) => {
            let b = datasets::builtin(name).ok_or_else(|| {
                CliError::Dataset(datasets::DatasetError::UnknownScenario {
                    name: name.to_string(),
                    known: datasets::builtin::builtin_names(),
                })
            })?;
            print!("{}", b.toml);
        }
        None => {
            for b in datasets::BUILTINS.iter() {
                println!("{:<14} {}", b.name, b.description);
            }
            println!("\nRun one with `grainlaw run NAME`, print its keys with `grainlaw scenarios --show NAME`.");
        }
    }
    Ok(())
}
