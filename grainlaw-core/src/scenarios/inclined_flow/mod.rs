//! The `inclined-flow` scenario (paper §3, Fig. 4): a polydisperse layer flowing down a rough
//! slope, periodic along the slope, computed in the slope frame (x down the slope, y its
//! normal, gravity `g (sin θ, −cos θ)`).
//!
//! Measured: per grain the ratio `‖Σ_i‖_F / ‖Σ_c‖_F` of the inertia to the contact part of its
//! mean stress (large in fluid-like, collisional zones; small in solid-like, enduring-contact
//! zones), mapped on the grains at the end; the time-averaged profiles of velocity along the
//! slope, solid fraction and inertia ratio across the layer; the mean flow velocity history.

pub mod build;
pub mod config;

use dem::snapshot::Snapshot;
use dem::BodyKind;
use homogenise::inertia_ratio::{fluid_fraction, inertia_ratios};

use serde::{Deserialize, Serialize};

use super::common::{mean_diameter, solver_keys, Stop, VtkFrames};
use super::loader::{common_methods, ScenarioConfig};
use super::phased::{drive, Enter, Leave, PhasedRun, RunControl, Step};
use super::phases::PhaseStats;
use super::rows::{self, serde_csv_table, table_row};
use super::{RunContext, RunOutcome};
use crate::checkpoint::PhasePlan;
use crate::error::Result;
use crate::output::{CsvTable, OutputDir, Summary};
use crate::plot::colormap::Scale;
use crate::plot::particles::{draw_particles, GrainFill, ParticleView};
use crate::plot::xy::{draw_row, draw_xy, Axis, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use crate::verdict::{max_solid_fraction, Checks, WindowStats};
use build::inclined_flow;
use config::InclinedFlowConfig;

/// Relative difference of the window halves of the mean velocity that matters for a steady
/// flow (1; [`crate::verdict::halves_drift`]).
pub const STEADY_VELOCITY_TOLERANCE: f64 = 0.02;

/// Accumulated profiles across the layer (bins of height y above the base).
#[derive(Serialize, Deserialize)]
struct Profiles {
    dy: f64,
    #[serde(with = "crate::floats::vec")]
    mv: Vec<f64>,
    #[serde(with = "crate::floats::vec")]
    m: Vec<f64>,
    #[serde(with = "crate::floats::vec")]
    area: Vec<f64>,
    #[serde(with = "crate::floats::vec")]
    log_ratio: Vec<f64>,
    #[serde(with = "crate::floats::vec")]
    n_ratio: Vec<f64>,
    samples: usize,
}

impl Profiles {
    fn new(bins: usize, dy: f64) -> Self {
        Self {
            dy,
            mv: vec![0.0; bins],
            m: vec![0.0; bins],
            area: vec![0.0; bins],
            log_ratio: vec![0.0; bins],
            n_ratio: vec![0.0; bins],
            samples: 0,
        }
    }

    fn add(&mut self, snap: &Snapshot, base: f64) -> Result<()> {
        let ratios = inertia_ratios(&homogenise::grain_stresses(snap)?);
        let grains = snap.bodies.iter().filter(|b| b.kind == BodyKind::Grain);
        for (b, r) in grains.zip(&ratios) {
            let k = ((b.position.y - base) / self.dy).floor();
            if k < 0.0 || k as usize >= self.m.len() {
                continue;
            }
            let k = k as usize;
            self.mv[k] += b.mass * b.velocity.x;
            self.m[k] += b.mass;
            // The solid fraction counts the part of each disk inside each layer (exact
            // circular-segment areas), so that it stays below 1 whatever the layer thickness.
            let (yc, rad) = (b.position.y - base, b.radius);
            let first = ((yc - rad) / self.dy).floor().max(0.0) as usize;
            let last = (((yc + rad) / self.dy).floor().max(0.0) as usize).min(self.area.len() - 1);
            for j in first..=last {
                let (y0, y1) = (j as f64 * self.dy, (j + 1) as f64 * self.dy);
                self.area[j] += disk_area_below(y1 - yc, rad) - disk_area_below(y0 - yc, rad);
            }
            if let Some(x) = r.ratio.filter(|x| *x > 0.0) {
                self.log_ratio[k] += x.log10();
                self.n_ratio[k] += 1.0;
            }
        }
        self.samples += 1;
        Ok(())
    }
}

/// The single phase: the layer flows for `duration`; profiles are averaged over the last
/// `average` seconds.
struct Flow<'a> {
    c: &'a InclinedFlowConfig,
}

table_row! {
    /// One step of the flow: a row of `history.csv`.
    struct FlowStep {
        /// Time (s).
        t: "time_s",
        /// Mass-weighted mean velocity of the grains along the slope (m/s).
        mean_velocity: "mean_velocity_m_s",
        /// Kinetic energy (J).
        kinetic_energy: "kinetic_energy_J",
        /// Sweeps of the step's solve.
        sweeps: "sweeps",
        /// The solve's error.
        solver_error: "solver_error",
    }
}

/// What the flow phase collects.
#[derive(Serialize, Deserialize)]
struct FlowState {
    /// Top of the rough base (m).
    base: f64,
    prof: Profiles,
    /// One row per step: `history.csv`.
    #[serde(with = "serde_csv_table")]
    hist: Vec<FlowStep>,
    vtk: VtkFrames,
    /// Steps done.
    k: u64,
    stats: PhaseStats,
    /// Numerics of the averaging window.
    #[serde(default)]
    window: WindowStats,
}

impl Flow<'_> {
    fn steps(&self) -> u64 {
        (self.c.duration / self.c.dt).round() as u64
    }
}

impl PhasedRun for Flow<'_> {
    type State = FlowState;

    fn enter(&self, _st: &mut FlowState, _at: Enter<'_>) -> Result<Option<PhasePlan>> {
        Ok(Some(PhasePlan::new("flow", Stop::Steps(self.steps()))))
    }

    fn step(&self, st: &mut FlowState, at: Step<'_>) -> Result<()> {
        let (out, w, r, p) = (at.out, at.world, at.report, at.progress);
        let c = self.c;
        let avg_from = ((c.duration - c.average) / c.dt).round() as u64;
        let sample_every = ((0.002 / c.dt).round() as u64).max(1);
        st.k += 1;
        st.window.step(st.k > avg_from, w, r, &p.stats);
        let (mut mv, mut m) = (0.0, 0.0);
        for b in w.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
            mv += b.mass * b.velocity.x;
            m += b.mass;
        }
        st.hist.push(FlowStep {
            t: w.time,
            mean_velocity: mv / m,
            kinetic_energy: w.kinetic_energy(),
            sweeps: r.solver.iterations as f64,
            solver_error: r.solver.error,
        });
        if st.k > avg_from && st.k.is_multiple_of(sample_every) {
            st.prof.add(&w.snapshot(), st.base)?;
        }
        st.vtk.maybe(out, w)
    }

    fn leave(&self, st: &mut FlowState, at: Leave<'_>) -> Result<()> {
        let stats = at.stats;
        st.stats = *stats;
        Ok(())
    }
}

/// Area of a disk of radius `r` below the line at height `z` above its centre:
/// `r² (t √(1 − t²) + asin t + π/2)`, `t = z/r` clamped to [−1, 1].
fn disk_area_below(z: f64, r: f64) -> f64 {
    let t = (z / r).clamp(-1.0, 1.0);
    r * r * (t * (1.0 - t * t).sqrt() + t.asin() + std::f64::consts::FRAC_PI_2)
}

/// Stages "build" and "run": the layer on its rough base, flowing for `duration` (or resumed
/// from a checkpoint); with the number of profile layers.
fn simulate(
    c: &InclinedFlowConfig,
    ctx: &mut RunContext,
    ctl: &mut RunControl,
    length: f64,
) -> Result<(dem::World, FlowState, usize)> {
    // Layers are never thinner than a mean grain diameter: a thinner layer holds a fraction of
    // a grain and its averages are noise. Their number follows from the sample.
    let layer_height = |world: &dem::World| {
        // Layer height estimate from the grains' area at φ ≈ 0.75, with room for dilation.
        1.6 * crate::scenarios::common::build::grain_area(world) / (0.75 * length)
    };
    let bins = {
        let world = build::inclined_flow(c)?;
        let fit = (layer_height(&world) / (2.0 * c.grain.radius_mean)).floor() as usize;
        c.profile_bins.min(fit.max(1))
    };
    let fresh = || -> Result<(dem::World, FlowState)> {
        let world = build::inclined_flow(c)?;
        let h_est = layer_height(&world) / 1.6;
        let state = FlowState {
            base: c.grain.radius_mean, // top of the rough base (disks centred on y = 0)
            prof: Profiles::new(bins, 1.6 * h_est / bins as f64),
            hist: Vec::new(),
            vtk: VtkFrames::new(c.duration / c.vtk_frames.max(1) as f64, c.vtk_frames.max(1)),
            k: 0,
            stats: PhaseStats::default(),
            window: WindowStats::default(),
        };
        Ok((world, state))
    };
    let (world, state) = drive(ctx, ctl, &Flow { c }, fresh)?;
    Ok((world, state, bins))
}

/// A profile across the layer: `(value, height above the base)` per layer.
type Profile = Vec<(f64, f64)>;

/// Stage "measure": the time-averaged profiles of velocity, solid fraction and inertia ratio
/// over `bins` layers of a cell of `length` (m), written to `profiles.csv`.
fn layer_profiles(
    out: &mut OutputDir,
    c: &InclinedFlowConfig,
    prof: &Profiles,
    bins: usize,
    length: f64,
) -> Result<(Profile, Profile, Profile)> {
    let dy = prof.dy;
    // Profiles.
    let mut table = CsvTable::new(&[
        "height_m",
        "velocity_m_s",
        "solid_fraction",
        "mean_log10_inertia_ratio",
    ]);
    let mut vel = Vec::new();
    let mut phi = Vec::new();
    let mut lr = Vec::new();
    for i in 0..bins {
        let y = (i as f64 + 0.5) * dy;
        let v = if prof.m[i] > 0.0 {
            prof.mv[i] / prof.m[i]
        } else {
            f64::NAN
        };
        let f = prof.area[i] / (prof.samples.max(1) as f64 * length * dy);
        let l = if prof.n_ratio[i] > 0.0 {
            prof.log_ratio[i] / prof.n_ratio[i]
        } else {
            f64::NAN
        };
        table.push(vec![y, v, f, l]);
        if v.is_finite() {
            vel.push((v, y));
        }
        phi.push((f, y));
        if l.is_finite() {
            lr.push((l, y));
        }
    }
    table.comments.push(format!(
        "time averages over the last {} s ({} samples); height above the rough base (m)",
        c.average, prof.samples
    ));
    table.write(out, "profiles.csv")?;
    Ok((vel, phi, lr))
}

/// Stage "report": `inertia_ratio_map.png` (per grain, over the last state `snap` at
/// `time`), `profiles.png` and `velocity_history.png`.
fn figures(
    out: &mut OutputDir,
    c: &InclinedFlowConfig,
    (snap, time): (&Snapshot, f64),
    values: &[f64],
    (vel, phi, lr): (&Profile, &Profile, Profile),
    hist: &[FlowStep],
) -> Result<()> {
    // Colour range: the 2 % and 98 % quantiles, widened to whole decades.
    let mut finite: Vec<f64> = values
        .iter()
        .copied()
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    finite.sort_by(f64::total_cmp);
    let (lo, hi) = if finite.len() >= 2 {
        let q = |p: f64| finite[((finite.len() - 1) as f64 * p).round() as usize];
        (q(0.02), q(0.98))
    } else {
        (1e-3, 1.0)
    };
    let lo = 10f64.powf(lo.log10().floor());
    let hi = 10f64.powf(hi.log10().ceil()).max(lo * 10.0);
    draw_particles(
        out,
        "inertia_ratio_map.png",
        &ParticleView {
            snap,
            title: format!(
                "‖Σ_inertia‖/‖Σ_contact‖ per grain, slope {}°, t = {:.2} s (white: no contact)",
                c.slope_deg, time
            ),
            fill: GrainFill::Values {
                values: values.to_vec(),
                scale: Scale {
                    min: lo,
                    max: hi,
                    log: true,
                },
                label: "‖Σ_i‖_F / ‖Σ_c‖_F".into(),
            },
            forces: false,
            axis_labels: (
                "x along the slope (m)".into(),
                "y normal to the slope (m)".into(),
            ),
            width_px: 1300,
            overlays: Vec::new(),
        },
    )?;
    let mut pv = XyPlot::new(
        &format!("Velocity profile (mean over the last {} s)", c.average),
        Axis::new("velocity along the slope (m/s)"),
        Axis::new("height above the base y (m)"),
    );
    pv.series.push(Series::new(
        "DEM",
        Style::LinePoints,
        PALETTE[0],
        vel.clone(),
    ));
    pv.legend = LegendAt::UpperLeft;
    let mut pf = XyPlot::new(
        "Solid fraction",
        Axis::new("solid fraction φ"),
        Axis::new("height above the base y (m)"),
    );
    pf.series
        .push(Series::new("", Style::LinePoints, PALETTE[2], phi.clone()));
    let mut pr = XyPlot::new(
        "Inertia ratio across the layer",
        Axis::new("mean log₁₀ ‖Σ_i‖/‖Σ_c‖"),
        Axis::new("height above the base y (m)"),
    );
    pr.series
        .push(Series::new("", Style::LinePoints, PALETTE[1], lr));
    draw_row(out, "profiles.png", &[pv, pf, pr], (1800, 650))?;
    let mut ph = XyPlot::new(
        "Mean velocity of the layer",
        Axis::new("time t (s)"),
        Axis::new("mean velocity along the slope (m/s)"),
    );
    ph.series.push(Series::new(
        "",
        Style::Thin,
        PALETTE[0],
        hist.iter().map(|r| (r.t, r.mean_velocity)).collect(),
    ));
    draw_xy(out, "velocity_history.png", &ph)?;
    Ok(())
}

/// Runs the scenario: build and run (`simulate`), measure (`layer_profiles`, the inertia
/// ratios), verdict, report (`figures`).
pub fn run(
    c: &InclinedFlowConfig,
    ctx: &mut RunContext,
    ctl: &mut RunControl,
) -> Result<RunOutcome> {
    let length = c.cell_length_diameters * 2.0 * c.grain.radius_mean;
    let (
        world,
        FlowState {
            prof,
            hist,
            vtk,
            stats,
            window,
            ..
        },
        bins,
    ) = simulate(c, ctx, ctl, length)?;
    let d = mean_diameter(&world);
    let dy = prof.dy;
    vtk.finish(&mut ctx.out, &world)?;
    let snap = world.snapshot();
    let gs = homogenise::grain_stresses(&snap)?;
    let ratios = inertia_ratios(&gs);
    let fluid = fluid_fraction(&ratios, c.fluid_threshold)?;
    let values: Vec<f64> = ratios.iter().map(|r| r.ratio.unwrap_or(f64::NAN)).collect();

    let (vel, phi, lr) = layer_profiles(&mut ctx.out, c, &prof, bins, length)?;
    rows::table(&hist).write(&mut ctx.out, "history.csv")?;
    // Flow height: where the time-averaged solid fraction falls below half its bulk value.
    let bulk = phi.iter().map(|p| p.0).fold(0.0, f64::max);
    let height = phi
        .iter()
        .filter(|p| p.0 > 0.5 * bulk)
        .map(|p| p.1 + 0.5 * dy)
        .fold(0.0, f64::max);
    let mean_v = hist.last().map(|r| r.mean_velocity).unwrap_or(f64::NAN);
    let surface_v = vel
        .iter()
        .filter(|p| p.1 <= height)
        .map(|p| p.0)
        .fold(f64::NAN, f64::max);
    let n_contactless = ratios.iter().filter(|r| r.ratio.is_none()).count();

    let mut s = Summary::new();
    s.int("grains", c.grains as u64)
        .num("slope_deg", c.slope_deg)
        .num("friction", c.friction.grain_grain)
        .num("cell_length_m", length)
        .num("mean_diameter_m", d)
        .num("mean_velocity_m_s", mean_v)
        .num("surface_velocity_m_s", surface_v)
        .num("flow_height_m", height)
        .num("flow_height_diameters", height / d)
        .num(
            "froude_number",
            mean_v / (9.81 * c.slope_deg.to_radians().cos() * height).sqrt(),
        )
        .num("fluid_fraction", fluid)
        .num("fluid_threshold", c.fluid_threshold)
        .int("grains_without_contact", n_contactless as u64)
        .num("max_solid_fraction", bulk);
    solver_keys(&mut s, &stats);
    window.keys(&mut s, "window");

    // Checks (crate::verdict): the numerics of the averaging window, the steady state of the
    // mean velocity over it, the layer solid fractions.
    let mut checks = Checks::new();
    checks.window("averaging window", &window);
    let avg_steps = window.steps as usize;
    let v_window: Vec<f64> = hist[hist.len().saturating_sub(avg_steps)..]
        .iter()
        .map(|r| r.mean_velocity)
        .collect();
    let v_mean = v_window.iter().sum::<f64>() / v_window.len().max(1) as f64;
    checks.steady(
        "inclined_flow.steady_velocity",
        "the mean velocity (m/s)",
        &v_window,
        STEADY_VELOCITY_TOLERANCE * v_mean.abs(),
    );
    checks.solid_fraction(
        "inclined_flow.solid_fraction",
        "the densest layer",
        bulk,
        max_solid_fraction(c.grain.radius_spread),
    );

    figures(
        &mut ctx.out,
        c,
        (&snap, world.time),
        &values,
        (&vel, &phi, lr),
        &hist,
    )?;

    let headline = vec![
        format!("report: {}/", ctx.out.path().display()),
        format!(
            "mean velocity {mean_v:.3} m/s, flow height {:.1} diameters, fluid-like grains (ratio > {}): {:.0} %",
            height / d,
            c.fluid_threshold,
            100.0 * fluid
        ),
    ];
    Ok(RunOutcome::without_laws(s, headline, checks))
}

/// What the loader and the registry ask of every kind ([`ScenarioConfig`]).
impl ScenarioConfig for InclinedFlowConfig {
    common_methods!();

    fn kind(&self) -> &'static str {
        "inclined-flow"
    }

    fn grains(&self) -> usize {
        self.grains
    }

    fn build_first(&self) -> datasets::Result<()> {
        inclined_flow(self).map(drop)
    }
}
