//! The janssen scenario driven from Rust instead of the command line: load the built-in with
//! overrides, run it into a directory, read the fitted K and μ_w from the summary.
//!
//! `cargo run --release --example janssen_library -- [OUT_DIR]`

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use grainlaw::output::OutputDir;
use grainlaw::progress::Verbosity;
use grainlaw::scenarios::{run, RunContext};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "grainlaw-out/janssen-example".into());
    // A stiffer wall friction than the paper's, with the same seed.
    let loaded =
        grainlaw::scenarios::registry::load("janssen", &["friction.grain_wall=0.4".into()])?;
    let mut ctx = RunContext {
        out: OutputDir::create(std::path::Path::new(&dir))?,
        verbosity: Verbosity::Normal,
        loaded,
        interrupted: Arc::new(AtomicBool::new(false)),
        dump: None,
    };
    let outcome = run(&mut ctx)?;
    let s = &outcome.summary;
    println!(
        "K = {:?}, mu_w = {:?} (wall friction 0.4), bottom load / weight = {:?}",
        s.get_f64("janssen_K"),
        s.get_f64("janssen_mu_w"),
        s.get_f64("bottom_load_over_weight")
    );
    Ok(())
}
