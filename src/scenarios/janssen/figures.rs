//! The figures of the `janssen` scenario: the stress profile with its fit, the wall-friction
//! mobilisation, the force chains of the last state, and the history of the run.

use dem::snapshot::Snapshot;
use homogenise::mobilisation::COULOMB_LIMIT;
use identify::IdentifyError;

use super::fit::{fit_band, JanssenOutcome};
use super::measure::ColumnProfile;
use super::RunContext;
use crate::error::Result;
use crate::output::CsvTable;
use crate::plot::histogram::{draw_histogram, HistogramPlot};
use crate::plot::particles::{draw_particles, GrainFill, ParticleView};
use crate::plot::xy::{draw_row, draw_xy, Axis, Band, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;

/// What the figures show.
pub(super) struct Inputs<'a> {
    /// Time-averaged profile.
    pub profile: &'a ColumnProfile,
    /// The fit, or why it failed.
    pub fitted: &'a std::result::Result<JanssenOutcome, IdentifyError>,
    /// Bulk density (kg/m³) and gravity (m/s²).
    pub rho_b: f64,
    pub g: f64,
    /// Depth window of the fit (m).
    pub window: (f64, f64),
    /// Wall friction coefficient.
    pub mu_wall: f64,
    /// Mobilisations of the side-wall contacts over the measurement window.
    pub mobilisations: &'a [f64],
    /// States in the measurement window.
    pub samples: u64,
    /// Share at the Coulomb limit and mean mobilisation.
    pub sliding: f64,
    pub mean_mob: f64,
    /// Last state.
    pub snap: &'a Snapshot,
    /// Number of grains.
    pub grains: usize,
    /// `history.csv`.
    pub history: &'a CsvTable,
    /// Simulated time at the end (s).
    pub end_time: f64,
}

/// Draws `wall_stress_profile.png`, `wall_mobilisation.png`, `force_chains.png` and
/// `history.png`.
pub(super) fn draw(ctx: &mut RunContext, f: &Inputs) -> Result<()> {
    figure_profile(ctx, f.profile, f.fitted, f.rho_b, f.g, f.window, f.mu_wall)?;
    let hist = homogenise::mobilisation::Histogram::new(f.mobilisations, 0.0, 1.0, 20)?;
    draw_histogram(
        &mut ctx.out,
        "wall_mobilisation.png",
        &HistogramPlot {
            title: "Friction mobilisation of the side-wall contacts".into(),
            x_label: "mobilisation |f_t| / (μ f_n)".into(),
            y_label: "fraction of wall contacts".into(),
            edges: hist.edges.clone(),
            values: hist.fractions(),
            color: PALETTE[0],
            markers: vec![(1.0, "Coulomb limit ".into())],
            notes: vec![
                format!(
                    "{} wall contacts in {} states, μ_wall = {}",
                    f.mobilisations.len(),
                    f.samples,
                    f.mu_wall
                ),
                format!(
                    "at the Coulomb limit (≥ {COULOMB_LIMIT}): {:.0} %",
                    100.0 * f.sliding
                ),
                format!("mean mobilisation: {:.2}", f.mean_mob),
            ],
        },
    )?;
    draw_particles(
        &mut ctx.out,
        "force_chains.png",
        &ParticleView {
            snap: f.snap,
            title: format!("Relaxed column, {} grains: normal contact forces", f.grains),
            fill: GrainFill::Plain,
            forces: true,
            axis_labels: ("x (m)".into(), "y (m)".into()),
            width_px: if f.grains > 3000 { 900 } else { 520 },
        },
    )?;
    let t: Vec<(f64, f64)> = f.history.rows.iter().map(|r| (r[0], r[2])).collect();
    let l: Vec<(f64, f64)> = f.history.rows.iter().map(|r| (r[0], r[6])).collect();
    let mut ke = XyPlot::new(
        "Kinetic energy",
        Axis::new("time t (s)"),
        Axis::new("kinetic energy (J)").log(),
    );
    ke.series.push(Series::new(
        "",
        Style::Thin,
        PALETTE[0],
        t.into_iter().filter(|p| p.1 > 0.0).collect(),
    ));
    let mut bl = XyPlot::new(
        "Load on the floor",
        Axis::new("time t (s)"),
        Axis::new("bottom load / weight").range(0.0, 1.5),
    );
    bl.series.push(Series::new("", Style::Thin, PALETTE[1], l));
    bl.series.push(Series::new(
        "weight",
        Style::Dashed,
        PALETTE[6],
        vec![(0.0, 1.0), (f.end_time, 1.0)],
    ));
    // Phase boundaries (history column 1 holds the phase code).
    let starts: Vec<(f64, f64)> = f
        .history
        .rows
        .windows(2)
        .filter(|w| w[1][1] != w[0][1])
        .map(|w| (w[1][1], w[0][0]))
        .collect();
    let names = ["deposit", "relax", "release", "measure"];
    let mut note = String::from("phases: deposit from 0 s");
    for (code, t) in &starts {
        if let Some(n) = names.get(*code as usize) {
            note.push_str(&format!(", {n} from {t:.3} s"));
        }
    }
    bl.notes.push(note);
    bl.legend = LegendAt::LowerRight;
    for (_, t) in &starts {
        bl.series.push(Series::new(
            "",
            Style::Dashed,
            PALETTE[4],
            vec![(*t, 0.0), (*t, 1.5)],
        ));
    }
    draw_row(&mut ctx.out, "history.png", &[ke, bl], (1600, 600))?;

    Ok(())
}

fn figure_profile(
    ctx: &mut RunContext,
    p: &ColumnProfile,
    fitted: &std::result::Result<JanssenOutcome, IdentifyError>,
    rho_b: f64,
    g: f64,
    window: (f64, f64),
    mu_wall: f64,
) -> Result<()> {
    let mut plot = XyPlot::new(
        "Stresses in the column vs depth",
        Axis::new("stress (Pa)"),
        Axis::new("depth below the free surface z (m)").reversed(),
    );
    let zmax = p.surface;
    let zs: Vec<f64> = (0..=120).map(|k| zmax * k as f64 / 120.0).collect();
    if let Ok(o) = fitted {
        let band = fit_band(&o.fit, &zs);
        plot.bands.push(Band::between_x(
            "",
            PALETTE[0],
            &band.iter().map(|r| (r[0], r[2], r[3])).collect::<Vec<_>>(),
        ));
        plot.bands.push(Band::between_x(
            "95 % confidence band",
            PALETTE[1],
            &band.iter().map(|r| (r[0], r[5], r[6])).collect::<Vec<_>>(),
        ));
    }
    plot.series.push(Series::new(
        "hydrostatic ρ_b g z",
        Style::Dashed,
        PALETTE[6],
        vec![(0.0, 0.0), (rho_b * g * zmax, zmax)],
    ));
    if let Ok(o) = fitted {
        let f = &o.fit;
        plot.series.push(Series::new(
            "Janssen σ_v",
            Style::Line,
            PALETTE[0],
            zs.iter().map(|&z| (f.law.sigma_v(z), z)).collect(),
        ));
        plot.series.push(Series::new(
            "Janssen σ_h = K σ_v",
            Style::Line,
            PALETTE[1],
            zs.iter().map(|&z| (f.law.sigma_h(z), z)).collect(),
        ));
        plot.series.push(Series::new(
            "Janssen τ_w = μ_w σ_h",
            Style::Line,
            PALETTE[2],
            zs.iter().map(|&z| (f.law.tau_w(z), z)).collect(),
        ));
        let kmu = if o.mode == "joint" {
            format!(
                "K = {:.2} ± {:.2}, μ_w = {:.3} ± {:.3} (μ_wall = {mu_wall})",
                f.k.value,
                f.k.ci_high - f.k.value,
                f.mu_w.value,
                f.mu_w.ci_high - f.mu_w.value
            )
        } else {
            format!(
                "K = {:.2} ± {:.2}, μ_w = μ_wall = {mu_wall} (full mobilisation)",
                f.k.value,
                f.k.ci_high - f.k.value
            )
        };
        plot.notes.push(kmu);
        plot.notes.push(format!(
            "fitted over z ∈ [{:.3}, {:.3}] m",
            window.0, window.1
        ));
    }
    plot.series.push(Series::new(
        "DEM σ_v (planes)",
        Style::Points,
        PALETTE[0],
        p.z.iter().zip(&p.sigma_v).map(|(z, s)| (*s, *z)).collect(),
    ));
    plot.series.push(Series::new(
        "DEM σ_h (walls)",
        Style::Points,
        PALETTE[1],
        p.z.iter().zip(&p.sigma_h).map(|(z, s)| (*s, *z)).collect(),
    ));
    plot.series.push(Series::new(
        "DEM τ_w (walls)",
        Style::Circles,
        PALETTE[2],
        p.z.iter().zip(&p.tau_w).map(|(z, s)| (*s, *z)).collect(),
    ));
    plot.legend = LegendAt::UpperRight;
    let _ = &plot;
    draw_xy(&mut ctx.out, "wall_stress_profile.png", &plot)
}
