//! The figures of the `janssen` scenario: the stress profile with its fit, the wall-friction
//! mobilisation, the force chains of the last state, and the history of the run.

use dem::snapshot::Snapshot;
use homogenise::mobilisation::COULOMB_LIMIT;
use identify::IdentifyError;

use super::fit::{fit_band, JanssenOutcome};
use super::measure::ColumnProfile;
use super::RunContext;
use crate::error::Result;
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
    pub history: &'a [super::ColumnStep],
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
            // the last state: the last measured step after the release
            title: format!(
                "Column after the release, {} grains: normal forces",
                f.grains
            ),
            fill: GrainFill::Plain,
            forces: true,
            axis_labels: ("x (m)".into(), "y (m)".into()),
            width_px: if f.grains > 3000 { 900 } else { 520 },
            overlays: Vec::new(),
        },
    )?;
    let t: Vec<(f64, f64)> = f.history.iter().map(|r| (r.t, r.kinetic_energy)).collect();
    let l: Vec<(f64, f64)> = f.history.iter().map(|r| (r.t, r.bottom_load)).collect();
    let mut ke = XyPlot::new(
        "Kinetic energy",
        Axis::new("time t (s)"),
        Axis::new("kinetic energy (J/m)").log(),
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
    // Phase boundaries: (the new phase's code, the time of the step before it).
    let starts: Vec<(f64, f64)> = f
        .history
        .windows(2)
        .filter(|w| w[1].phase != w[0].phase)
        .map(|w| (w[1].phase, w[0].t))
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
    let plot = profile_plot(p, fitted.as_ref().ok(), rho_b, g, window, mu_wall);
    draw_xy(&mut ctx.out, "wall_stress_profile.png", &plot)
}

/// Number of intervals of the drawn law.
const PROFILE_INTERVALS: usize = 120;

/// The stress profile: the measured σ_v, σ_h and τ_w per depth bin, the hydrostatic line, and
/// the fitted law with the 95 % bands of σ_v and of σ_h, each under its own legend, drawn over
/// the fit's depth window only (the law is not extrapolated to the surface or the floor).
/// When τ_w was left out of the fit, its curve is the law's prediction `μ_w σ_h` and says so.
pub(super) fn profile_plot(
    p: &ColumnProfile,
    fitted: Option<&JanssenOutcome>,
    rho_b: f64,
    g: f64,
    window: (f64, f64),
    mu_wall: f64,
) -> XyPlot {
    let mut plot = XyPlot::new(
        "Stresses in the column vs depth, after the release",
        Axis::new("stress (Pa)"),
        Axis::new("depth below the free surface z (m)").reversed(),
    );
    let zmax = p.surface;
    let (z0, z1) = (window.0.max(0.0), window.1.min(zmax));
    let zs: Vec<f64> = (0..=PROFILE_INTERVALS)
        .map(|k| z0 + (z1 - z0) * k as f64 / PROFILE_INTERVALS as f64)
        .collect();
    if let Some(o) = fitted {
        let band = fit_band(&o.fit, &zs);
        plot.bands.push(Band::between_x(
            "95 % band of σ_v",
            PALETTE[0],
            &band
                .iter()
                .map(|b| (b.z, b.sigma_v_lo, b.sigma_v_hi))
                .collect::<Vec<_>>(),
        ));
        plot.bands.push(Band::between_x(
            "95 % band of σ_h",
            PALETTE[1],
            &band
                .iter()
                .map(|b| (b.z, b.sigma_h_lo, b.sigma_h_hi))
                .collect::<Vec<_>>(),
        ));
    }
    plot.series.push(Series::new(
        "hydrostatic ρ_b g z",
        Style::Dashed,
        PALETTE[6],
        vec![(0.0, 0.0), (rho_b * g * zmax, zmax)],
    ));
    if let Some(o) = fitted {
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
            if o.uses_tau_w {
                "Janssen τ_w = μ_w σ_h"
            } else {
                "Janssen τ_w = μ_w σ_h (τ_w not fitted)"
            },
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
        plot.notes
            .push(format!("fitted over z ∈ [{z0:.3}, {z1:.3}] m"));
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
    plot
}

#[cfg(test)]
mod tests {
    use super::*;
    use identify::janssen::JanssenSetup;
    use identify::laws::janssen::JanssenLaw;

    /// A column drawn from Janssen's law (K = 0.8, μ_w = 0.2, eight bins of a 12 cm column),
    /// fitted over z ∈ [0.02, 0.1] m: both bands are in the legend, each of its own curve; the
    /// law's curves and bands lie within the fit's window (not extrapolated to the surface
    /// or the floor); the measured points are all drawn.
    #[test]
    fn the_profile_shows_both_bands_and_the_law_over_its_window_only() {
        let law = JanssenLaw {
            k: 0.8,
            mu_w: 0.2,
            width_m: 0.03,
            bulk_density_kg_m3: 2000.0,
            gravity_m_s2: 9.81,
        };
        let z: Vec<f64> = (0..8).map(|i| 0.12 * (i as f64 + 0.5) / 8.0).collect();
        let wobble = |k: usize| 1.0 + 0.03 * [0.6, -1.0, 0.3, 0.9, -0.7, -0.2, 1.0, -0.8][k % 8];
        let p = ColumnProfile {
            sigma_v: z
                .iter()
                .enumerate()
                .map(|(k, &z)| law.sigma_v(z) * wobble(k))
                .collect(),
            sigma_h: z
                .iter()
                .enumerate()
                .map(|(k, &z)| law.sigma_h(z) * wobble(k + 3))
                .collect(),
            tau_w: z
                .iter()
                .enumerate()
                .map(|(k, &z)| law.tau_w(z) * wobble(k + 5))
                .collect(),
            z,
            surface: 0.12,
        };
        let setup = JanssenSetup {
            width_m: 0.03,
            bulk_density_kg_m3: 2000.0,
            gravity_m_s2: 9.81,
            wall_friction: 0.25,
        };
        let window = (0.02, 0.1);
        let o = super::super::fit_profile(&p, &setup, window).unwrap();
        let plot = profile_plot(&p, Some(&o), 2000.0, 9.81, window, 0.25);
        let labels: Vec<&str> = plot.bands.iter().map(|b| b.label.as_str()).collect();
        assert_eq!(labels, ["95 % band of σ_v", "95 % band of σ_h"]);
        let inside = |z: f64| (window.0 - 1e-15..=window.1 + 1e-15).contains(&z);
        for b in &plot.bands {
            assert!(b.outline.iter().all(|q| inside(q.1)), "{}", b.label);
        }
        for s in plot
            .series
            .iter()
            .filter(|s| s.label.starts_with("Janssen"))
        {
            let zs: Vec<f64> = s.xy.iter().map(|q| q.1).collect();
            assert!(zs.iter().all(|&z| inside(z)), "{}", s.label);
            assert_eq!(zs.first(), Some(&window.0), "{}", s.label);
            assert!((zs.last().unwrap() - window.1).abs() < 1e-15, "{}", s.label);
        }
        let dem = plot.series.iter().filter(|s| s.label.starts_with("DEM"));
        assert!(dem.clone().all(|s| s.xy.len() == 8));
        assert_eq!(dem.count(), 3);
    }
}
