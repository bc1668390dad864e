//! Figures of `column-collapse`: the grains at each labelled instant with the height profile,
//! the front against `t*` with the contact-dynamics reference and the runout scalings, the
//! profiles, the kinetic energy.

use dem::snapshot::WallGeometry;
use plotters::style::RGBColor;

use super::config::ColumnCollapseConfig;
use super::{scaling, FrontSample, HistoryRow, LabelledProfile};
use crate::error::Result;
use crate::plot::particles::{draw_particles, GrainFill, ParticleView};
use crate::plot::xy::{draw_xy, Axis, LegendAt, Series, Style, XyPlot};
use crate::plot::PALETTE;
use crate::scenarios::RunContext;

/// What the figures show.
pub struct Inputs<'a> {
    pub c: &'a ColumnCollapseConfig,
    pub profiles: &'a [LabelledProfile],
    pub frames: &'a [(String, dem::Snapshot)],
    pub front: &'a [FrontSample],
    pub history: &'a [HistoryRow],
    /// The contact-dynamics front `(t*, x_f/R₀)` of the reference case, if this is it.
    pub reference: Option<&'a [(f64, f64)]>,
    /// Runout at rest (m).
    pub runout: f64,
    /// Mean diameter (m).
    pub d: f64,
}

/// The snapshot cropped for a figure: the floor disks beyond the grains (and a margin of
/// `margin` m) left out.
fn cropped(snap: &dem::Snapshot, margin: f64) -> dem::Snapshot {
    let reach = snap
        .bodies
        .iter()
        .filter(|b| b.kind == dem::BodyKind::Grain)
        .map(|b| b.position.x + b.radius)
        .fold(0.0, f64::max)
        + margin;
    let mut s = snap.clone();
    for w in &mut s.walls {
        if let WallGeometry::Clump { centres, radii } = &mut w.geometry {
            let keep: Vec<bool> = centres.iter().map(|c| c.x <= reach).collect();
            let mut k = keep.iter();
            centres.retain(|_| *k.next().unwrap_or(&false));
            let mut k = keep.iter();
            radii.retain(|_| *k.next().unwrap_or(&false));
        }
    }
    s
}

/// Draws every figure.
pub fn draw(ctx: &mut RunContext, i: &Inputs) -> Result<()> {
    let c = i.c;
    let (r0, h0, ts) = (c.half_width(), c.height(), c.time_scale());
    let red = RGBColor(200, 30, 30);
    for (label, snap) in i.frames {
        let Some(p) = i.profiles.iter().find(|p| &p.label == label) else {
            continue;
        };
        let x_f = p.profile.front(i.d);
        let mut overlays = vec![(red, p.profile.points())];
        let top = p.profile.h.iter().cloned().fold(0.0, f64::max);
        overlays.push((PALETTE[0], vec![(x_f, 0.0), (x_f, top.max(i.d))]));
        draw_particles(
            &mut ctx.out,
            &format!("snapshot_{label}.png"),
            &ParticleView {
                snap: &cropped(snap, 4.0 * i.d),
                title: format!(
                    "a = {}, t* = {:.2}: height profile h(x) (red), front x_f = {:.2} R0 (blue)",
                    c.aspect_ratio,
                    p.t / ts,
                    x_f / r0
                ),
                fill: GrainFill::Plain,
                forces: false,
                axis_labels: ("x (m)".into(), "y (m)".into()),
                width_px: 1400,
                overlays,
            },
        )?;
    }

    // Front against t*.
    let mut pf = XyPlot::new(
        &format!("Front of the collapsing column, a = {}", c.aspect_ratio),
        Axis::new("t* = t √(g/H₀)"),
        Axis::new("x_f / R₀"),
    );
    pf.series.push(Series::new(
        "DEM (grainlaw)",
        Style::Line,
        PALETTE[0],
        i.front.iter().map(|f| (f.t / ts, f.x_f / r0)).collect(),
    ));
    if let Some(reference) = i.reference {
        pf.series.push(Series::new(
            "contact dynamics (Staron & Hinch 2005, Gerris example column)",
            Style::Points,
            PALETTE[1],
            reference.to_vec(),
        ));
    }
    let t_end = i.front.last().map_or(1.0, |f| f.t / ts);
    let law = 1.0 + scaling::normalised_runout(c.aspect_ratio);
    pf.series.push(Series::new(
        &format!(
            "runout of the 2D experiments (Lube et al. 2005): 1 + {}",
            if c.aspect_ratio < scaling::POWER_MIN_A {
                format!("{} a", scaling::LINEAR)
            } else {
                format!("{} a^(2/3)", scaling::POWER)
            }
        ),
        Style::Dashed,
        PALETTE[2],
        vec![(0.0, law), (t_end, law)],
    ));
    pf.series.push(Series::new(
        "DEM runout at rest",
        Style::Dashed,
        PALETTE[0],
        vec![(0.0, i.runout / r0), (t_end, i.runout / r0)],
    ));
    pf.legend = LegendAt::LowerRight;
    draw_xy(&mut ctx.out, "front.png", &pf)?;

    // Profiles.
    let mut pp = XyPlot::new(
        &format!("Height profiles, a = {}", c.aspect_ratio),
        Axis::new("x / R₀"),
        Axis::new("h / R₀"),
    );
    for (k, p) in i.profiles.iter().enumerate() {
        pp.series.push(Series::new(
            &format!("{} (t* = {:.2})", p.label, p.t / ts),
            Style::Line,
            PALETTE[k % PALETTE.len()],
            p.profile
                .points()
                .into_iter()
                .map(|(x, h)| (x / r0, h / r0))
                .collect(),
        ));
    }
    pp.equal_aspect = true;
    pp.legend = LegendAt::UpperRight;
    pp.notes.push(format!(
        "H₀ = {h0:.3} m, R₀ = {r0:.3} m, bins of one mean diameter"
    ));
    draw_xy(&mut ctx.out, "profiles.png", &pp)?;

    // Kinetic energy.
    let mut pk = XyPlot::new(
        "Kinetic energy of the grains",
        Axis::new("t* = t √(g/H₀)"),
        Axis::new("kinetic energy (J per m)"),
    );
    pk.series.push(Series::new(
        "",
        Style::Thin,
        PALETTE[0],
        i.history
            .iter()
            .map(|r| (r.t / ts, r.kinetic_energy))
            .collect(),
    ));
    draw_xy(&mut ctx.out, "kinetic_energy.png", &pk)?;
    Ok(())
}

/// `runout.png` of a campaign: `(r_∞ − R₀)/R₀` against `a` (log axes), the runs whose verdict
/// is `ok` filled, the others hollow, with the two regimes of [`scaling`] over their ranges.
pub fn runout_figure(
    out: &mut crate::output::OutputDir,
    ok: &[(f64, f64)],
    other: &[(f64, f64)],
) -> Result<()> {
    let mut p = XyPlot::new(
        "Runout of collapsed columns against the aspect ratio",
        Axis::new("a = H₀ / R₀").log(),
        Axis::new("(r_∞ − R₀) / R₀").log(),
    );
    let all: Vec<f64> = ok
        .iter()
        .chain(other)
        .map(|q| q.0)
        .filter(|a| *a > 0.0)
        .collect();
    let lo = all.iter().cloned().fold(f64::INFINITY, f64::min).min(0.5);
    let hi = all.iter().cloned().fold(0.0, f64::max).max(10.0);
    let curve = |a0: f64, a1: f64, f: fn(f64) -> f64| -> Vec<(f64, f64)> {
        (0..=40)
            .map(|k| {
                let a = a0 * (a1 / a0).powf(k as f64 / 40.0);
                (a, f(a))
            })
            .collect()
    };
    p.series.push(Series::new(
        &format!(
            "{} a (Lube et al. 2005, 2D, a ≲ {})",
            scaling::LINEAR,
            scaling::LINEAR_MAX_A
        ),
        Style::Dashed,
        PALETTE[2],
        curve(lo, scaling::LINEAR_MAX_A, scaling::linear),
    ));
    p.series.push(Series::new(
        &format!(
            "{} a^(2/3) (Lube et al. 2005, 2D, a ≳ {})",
            scaling::POWER,
            scaling::POWER_MIN_A
        ),
        Style::Line,
        PALETTE[2],
        curve(scaling::POWER_MIN_A, hi, scaling::power),
    ));
    p.series.push(Series::new(
        "DEM (grainlaw), verdict ok",
        Style::Points,
        PALETTE[0],
        ok.to_vec(),
    ));
    p.series.push(Series::new(
        "DEM, verdict suspect or refused",
        Style::Circles,
        PALETTE[1],
        other.to_vec(),
    ));
    p.legend = LegendAt::UpperLeft;
    draw_xy(out, "runout.png", &p)
}
