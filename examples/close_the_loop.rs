//! Closing the loop: a law calibrated on DEM data, evaluated in its continuum setting and set
//! against the DEM data it came from.
//!
//! 1. Runs the `janssen` scenario (deposit, relax, release, homogenise, fit).
//! 2. Loads the calibrated law from its JSON file, as a continuum solver would, and integrates
//!    the Janssen equation `dσ_v/dz = ρ_b g − (2 K μ_w / W) σ_v`, `σ_v(0) = 0` (RK4).
//! 3. Compares the integrated profile with the closed form and with the DEM vertical stress
//!    (method of planes), prints the misfit, and draws `close_the_loop_janssen.png`.
//! 4. Runs the `shear-cell` scenario (plane shear at imposed pressure, several I) and loads its
//!    calibrated μ(I) and φ(I) laws (when the run's verdict refuses them, it prints why and
//!    stops there: the default cell's slow runs do not converge well enough); runs `inclined-flow` on a 20° slope (slower than the
//!    paper's 26°, so that the flow is steady within the run; a steady μ(I) flow needs
//!    μ_s < tan θ < μ₂, which `BagnoldFlow::new` checks), and sets the steady Bagnold profile `u(z) = (2/3)(I/d)√(φ g cos θ)(H^{3/2} − (H − z)^{3/2})`
//!    of the calibrated law against the DEM velocity profile: `close_the_loop_bagnold.png`.
//!
//! `cargo run --release --example close_the_loop -- [OUT_DIR]`

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use grainlaw::output::OutputDir;
use grainlaw::plot::xy::{draw_xy, Axis, Series, Style, XyPlot};
use grainlaw::progress::Verbosity;
use grainlaw::scenarios::{run, RunContext};
use identify::continuum::{janssen_ode_rk4, BagnoldFlow, SolidFraction};
use identify::law::Law;
use identify::CalibratedLaw;
use plotters::style::RGBColor;

/// Two columns `x`, `y` of a CSV written by a scenario (comment lines start with `#`; rows with
/// an empty cell are skipped).
fn csv_columns(
    path: &Path,
    x: &str,
    y: &str,
) -> Result<Vec<(f64, f64)>, Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(path)?;
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().ok_or("empty profile")?.split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or(format!("no column {name}"))
    };
    let (iz, iv) = (col(x)?, col(y)?);
    let mut out = Vec::new();
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        // An empty cell is an undefined value (e.g. an empty slice): skip the row.
        if f[iz].is_empty() || f[iv].is_empty() {
            continue;
        }
        out.push((f[iz].parse::<f64>()?, f[iv].parse::<f64>()?));
    }
    Ok(out)
}

/// Runs a built-in scenario into `dir` with `--set` overrides and prints its verdict.
fn run_scenario(name: &str, set: &[&str], dir: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    let mut ctx = RunContext {
        out: OutputDir::create(dir)?,
        verbosity: Verbosity::Normal,
        loaded: grainlaw::scenarios::registry::load(name, &set)?,
        interrupted: Arc::new(AtomicBool::new(false)),
        dump: None,
    };
    let outcome = run(&mut ctx)?;
    // as `grainlaw run` prints it: a suspect or refused run is said, not hidden
    for line in outcome.verdict.lines() {
        println!("{name}: {line}");
    }
    Ok(())
}

/// A number of a scenario's `summary.json`.
fn summary_number(dir: &Path, key: &str) -> Result<f64, Box<dyn std::error::Error>> {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json"))?)?;
    v[key]
        .as_f64()
        .ok_or_else(|| format!("summary.json has no number `{key}`").into())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "grainlaw-out/close-the-loop".into()),
    );
    let dir = root.join("janssen");
    run_scenario("janssen", &[], &dir)?;

    // The calibrated law as a continuum solver reads it.
    let law = CalibratedLaw::load(&dir.join("janssen_law.json"))?;
    let Law::Janssen(janssen) = law.to_law()? else {
        return Err("janssen_law.json does not hold a Janssen law".into());
    };
    let dem = csv_columns(&dir.join("wall_profile.csv"), "z_m", "sigma_v_Pa")?;
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

    // μ(I) calibrated in plane shear, evaluated as a steady flow down a 20° slope.
    let shear = root.join("shear-cell");
    run_scenario("shear-cell", &[], &shear)?;
    // A law is used only if its run exported it as calibrated (verdict ok): otherwise the
    // reasons are printed and the comparison is not made with numbers that look right.
    for law in ["mu_i_law.json", "phi_i_law.json"] {
        if !shear.join(law).is_file() {
            let v: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(shear.join("summary.json"))?)?;
            println!(
                "the shear cell did not calibrate {law} (verdict {}): no Bagnold comparison. Reasons:",
                v["verdict"]
            );
            for r in v["verdict_reasons"].as_array().into_iter().flatten() {
                println!("  {}: {}", r["verdict"], r["message"]);
            }
            println!("(more seeds and a longer averaging window narrow the intervals: see `grainlaw campaign`, docs/cli.md §9)");
            return Ok(());
        }
    }
    let Law::MuI(mu_i) = CalibratedLaw::load(&shear.join("mu_i_law.json"))?.to_law()? else {
        return Err("mu_i_law.json does not hold a μ(I) law".into());
    };
    let Law::PhiI(phi_i) = CalibratedLaw::load(&shear.join("phi_i_law.json"))?.to_law()? else {
        return Err("phi_i_law.json does not hold a φ(I) law".into());
    };
    let slope_deg = 20.0f64;
    let flow_dir = root.join("inclined-flow-20deg");
    run_scenario("inclined-flow", &["slope_deg=20"], &flow_dir)?;
    let height = summary_number(&flow_dir, "flow_height_m")?;
    let diameter = summary_number(&flow_dir, "mean_diameter_m")?;
    let flow = BagnoldFlow::new(
        &mu_i,
        SolidFraction::Law(phi_i),
        slope_deg.to_radians(),
        height,
        diameter,
        9.81,
    )?;
    let dem_u = csv_columns(&flow_dir.join("profiles.csv"), "height_m", "velocity_m_s")?;
    let dem_mean = dem_u.iter().map(|p| p.1).sum::<f64>() / dem_u.len() as f64;
    println!(
        "μ(I) from the shear cell: μ_s = {:.3}, μ₂ = {:.3}, I₀ = {:.3}; on a {slope_deg}° slope: I = {:.3}, φ = {:.3}",
        mu_i.mu_s, mu_i.mu_2, mu_i.i0, flow.inertial_number, flow.solid_fraction
    );
    println!(
        "flow {:.1} mm deep: Bagnold surface velocity {:.3} m/s, mean {:.3} m/s; DEM surface {:.3} m/s, mean {:.3} m/s",
        height * 1e3,
        flow.surface_velocity(),
        flow.mean_velocity(),
        summary_number(&flow_dir, "surface_velocity_m_s")?,
        dem_mean
    );
    let mut plot = XyPlot::new(
        &format!("Flow down a {slope_deg}° slope: Bagnold profile of the calibrated μ(I) vs DEM"),
        Axis::new("velocity along the slope u (m/s)"),
        Axis::new("height above the rough base z (m)"),
    );
    plot.series.push(Series::new(
        &format!(
            "Bagnold, μ(I) from the shear cell (I = {:.3})",
            flow.inertial_number
        ),
        Style::Line,
        RGBColor(0, 114, 178),
        flow.profile(200).into_iter().map(|(z, u)| (u, z)).collect(),
    ));
    plot.series.push(Series::new(
        "DEM (time average, slices)",
        Style::Points,
        RGBColor(213, 94, 0),
        dem_u.iter().map(|&(z, u)| (u, z)).collect(),
    ));
    plot.notes.push(format!(
        "μ_s = {:.3}, μ₂ = {:.3}, I₀ = {:.3}; H = {:.1} mm, d = {:.2} mm",
        mu_i.mu_s,
        mu_i.mu_2,
        mu_i.i0,
        height * 1e3,
        diameter * 1e3
    ));
    draw_xy(&mut out, "close_the_loop_bagnold.png", &plot)?;
    println!(
        "figure: {}",
        root.join("close_the_loop_bagnold.png").display()
    );
    Ok(())
}
