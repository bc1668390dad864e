//! Closing the loop: a law calibrated on DEM data, evaluated in its continuum setting and set
//! against the DEM data it came from.
//!
//! 1. Runs the `janssen` scenario (deposit, relax, release, homogenise, fit).
//! 2. Loads the calibrated law from its JSON file, as a continuum solver would, and integrates
//!    the Janssen equation `dσ_v/dz = ρ_b g − (2 K μ_w / W) σ_v`, `σ_v(0) = 0` (RK4).
//! 3. Compares the integrated profile with the closed form and with the DEM vertical stress
//!    (method of planes), prints the misfit, and draws `close_the_loop_janssen.png`.
//!
//! `cargo run --release --example close_the_loop -- [OUT_DIR]`

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use grainlaw::output::OutputDir;
use grainlaw::plot::xy::{draw_xy, Axis, Series, Style, XyPlot};
use grainlaw::progress::Verbosity;
use grainlaw::scenarios::{run, RunContext};
use identify::continuum::janssen_ode_rk4;
use identify::law::Law;
use identify::CalibratedLaw;
use plotters::style::RGBColor;

/// `(z, σ_v)` of the DEM from `wall_profile.csv` (comment lines start with `#`).
fn dem_profile(path: &Path) -> Result<Vec<(f64, f64)>, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(path)?;
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().ok_or("empty profile")?.split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or(format!("no column {name}"))
    };
    let (iz, iv) = (col("z_m")?, col("sigma_v_Pa")?);
    let mut out = Vec::new();
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        out.push((f[iz].parse::<f64>()?, f[iv].parse::<f64>()?));
    }
    Ok(out)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "grainlaw-out/close-the-loop".into()),
    );
    let dir = root.join("janssen");
    let mut ctx = RunContext {
        out: OutputDir::create(&dir)?,
        verbosity: Verbosity::Normal,
        loaded: datasets::load("janssen", &[])?,
        interrupted: Arc::new(AtomicBool::new(false)),
    };
    run(&mut ctx)?;

    // The calibrated law as a continuum solver reads it.
    let law = CalibratedLaw::load(&dir.join("janssen_law.json"))?;
    let Law::Janssen(janssen) = law.to_law()? else {
        return Err("janssen_law.json does not hold a Janssen law".into());
    };
    let dem = dem_profile(&dir.join("wall_profile.csv"))?;
    let depth = dem.iter().map(|p| p.0).fold(0.0, f64::max) * 1.05;
    let ode = janssen_ode_rk4(&janssen.vertical(), depth, 400)?;

    // RK4 against the closed form, and the law against the DEM.
    let ode_error = ode
        .z_m
        .iter()
        .zip(&ode.sigma_v_pa)
        .map(|(&z, &s)| (s - janssen.sigma_v(z)).abs() / janssen.sigma_v(depth))
        .fold(0.0, f64::max);
    let rms = (dem
        .iter()
        .map(|&(z, s)| (s - janssen.sigma_v(z)).powi(2))
        .sum::<f64>()
        / dem.len() as f64)
        .sqrt();
    let mean = dem.iter().map(|p| p.1).sum::<f64>() / dem.len() as f64;
    println!(
        "Janssen law from {}: K = {:.3}, μ_w = {:.3}, saturation length W/(2Kμ_w) = {:.3} m",
        dir.join("janssen_law.json").display(),
        janssen.k,
        janssen.mu_w,
        janssen.width_m / (2.0 * janssen.k * janssen.mu_w)
    );
    println!(
        "continuum (RK4, 400 steps) vs closed form: max difference {ode_error:.1e} of σ_v(depth)"
    );
    println!(
        "law vs DEM σ_v: RMS misfit {rms:.1} Pa ({:.1} % of the mean DEM stress)",
        100.0 * rms / mean
    );
    for &(z, s) in &dem {
        println!(
            "  z = {:.4} m: DEM {:8.1} Pa, Janssen {:8.1} Pa, hydrostatic {:8.1} Pa",
            z,
            s,
            janssen.sigma_v(z),
            janssen.hydrostatic(z)
        );
    }

    let mut plot = XyPlot::new(
        "Janssen column: calibrated continuum law vs DEM",
        Axis::new("vertical stress σ_v (Pa)"),
        Axis::new("depth below the free surface z (m)").reversed(),
    );
    let swap = |v: Vec<(f64, f64)>| v.into_iter().map(|(z, s)| (s, z)).collect::<Vec<_>>();
    plot.series.push(Series::new(
        "hydrostatic ρ_b g z",
        Style::Dashed,
        RGBColor(90, 90, 90),
        swap(
            ode.z_m
                .iter()
                .map(|&z| (z, janssen.hydrostatic(z)))
                .collect(),
        ),
    ));
    plot.series.push(Series::new(
        "Janssen ODE (RK4) with the calibrated K, μ_w",
        Style::Line,
        RGBColor(0, 114, 178),
        swap(
            ode.z_m
                .iter()
                .copied()
                .zip(ode.sigma_v_pa.iter().copied())
                .collect(),
        ),
    ));
    plot.series.push(Series::new(
        "DEM σ_v (method of planes)",
        Style::Points,
        RGBColor(213, 94, 0),
        swap(dem.clone()),
    ));
    plot.notes.push(format!(
        "K = {:.3}, μ_w = {:.3}; RMS misfit {:.0} Pa",
        janssen.k, janssen.mu_w, rms
    ));
    let mut out = OutputDir::create(&root)?;
    draw_xy(&mut out, "close_the_loop_janssen.png", &plot)?;
    println!(
        "figure: {}",
        root.join("close_the_loop_janssen.png").display()
    );
    Ok(())
}
