//! Pictures of the grains: walls, grains as disks (outlined, or filled by a per-grain value with a
//! colour bar) and contact forces as force chains, segments between the centres of the bodies in
//! contact with a line width proportional to the normal force.

use dem::snapshot::{BodyKind, BodyState, Snapshot, WallGeometry};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::colormap::{colorbar, Scale};
use super::{font, render, DrawResult};
use crate::error::Result;
use crate::output::vtk::{branch, clip_line, grain_extent};
use crate::output::OutputDir;

/// How the grains are filled.
#[derive(Debug, Clone)]
pub enum GrainFill {
    /// Light grey disks with a thin outline.
    Plain,
    /// One value per grain (in body order of the grains), coloured through `scale`, with a
    /// colour bar labelled `label`; NaN values are drawn white.
    Values {
        /// Per-grain values.
        values: Vec<f64>,
        /// Colour scale.
        scale: Scale,
        /// Quantity and unit of the colour bar.
        label: String,
    },
}

/// A picture of a snapshot.
#[derive(Debug, Clone)]
pub struct ParticleView<'a> {
    /// The state drawn.
    pub snap: &'a Snapshot,
    /// Title.
    pub title: String,
    /// Grain fill.
    pub fill: GrainFill,
    /// Draw the force chains.
    pub forces: bool,
    /// Horizontal and vertical axis labels.
    pub axis_labels: (String, String),
    /// Width of the plotting area in pixels (the height follows the data's aspect).
    pub width_px: u32,
    /// Polylines drawn over the grains (m), each in its colour (e.g. a height profile); empty
    /// for none.
    pub overlays: Vec<(RGBColor, Vec<(f64, f64)>)>,
}

/// The chart a [`ParticleView`] draws on (metres on both axes).
type GrainChart<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Draws the view as `name`: its extent and size → the axes → the walls → the grains → the
/// force chains → the overlays → the colour bar.
pub fn draw_particles(out: &mut OutputDir, name: &str, view: &ParticleView) -> Result<()> {
    let snap = view.snap;
    let (x0, x1, y0, y1) = view_extent(snap);
    let (dx, dy) = (x1 - x0, y1 - y0);
    let plot_w = view.width_px.max(200);
    let plot_h = ((plot_w as f64) * dy / dx).clamp(150.0, 4000.0) as u32;
    let bar = matches!(view.fill, GrainFill::Values { .. });
    let (left, bottom, top, right) = (90u32, 70u32, 50u32, if bar { 215u32 } else { 30u32 });
    let size = (plot_w + left + right, plot_h + bottom + top);
    render(out, name, size, |root| {
        let (main, bar_area) = root.split_horizontally(size.0 - right);
        let mut chart = ChartBuilder::on(&main)
            .caption(
                &view.title,
                font((1.7 * size.0 as f64 / view.title.chars().count().max(1) as f64).min(22.0)),
            )
            .margin_left(10)
            .margin_top(10)
            .x_label_area_size(bottom - 10)
            .y_label_area_size(left - 10)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(view.axis_labels.0.as_str())
            .y_desc(view.axis_labels.1.as_str())
            .label_style(font(15.0))
            .axis_desc_style(font(17.0))
            .x_label_formatter(&|v| super::xy::fmt_tick(*v))
            .y_label_formatter(&|v| super::xy::fmt_tick(*v))
            .draw()?;
        let px_per_m = {
            let a = chart.backend_coord(&(x0, y0));
            let b = chart.backend_coord(&(x1, y0));
            (b.0 - a.0) as f64 / dx
        };
        draw_walls(&mut chart, snap, (x0, x1, y0, y1), px_per_m)?;
        let grains: Vec<_> = snap
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
            .collect();
        draw_grains(&mut chart, &grains, &view.fill, px_per_m)?;
        if view.forces {
            draw_force_chains(&mut chart, &main, snap, &grains, px_per_m)?;
        }
        for (colour, line) in &view.overlays {
            chart.draw_series(std::iter::once(PathElement::new(
                line.clone(),
                colour.stroke_width(3),
            )))?;
        }
        if let GrainFill::Values { scale, label, .. } = &view.fill {
            colorbar(&bar_area, scale, label)?;
        }
        Ok(())
    })
}

/// The drawn extent `(x0, x1, y0, y1)` (m): the grains' (the periodic cell's along x), and the
/// clump walls' vertically.
fn view_extent(snap: &Snapshot) -> (f64, f64, f64, f64) {
    let (mut x0, mut x1, mut y0, mut y1) = grain_extent(snap);
    if let Some([a, b]) = snap.periodic_x {
        x0 = a;
        x1 = b;
    }
    for w in &snap.walls {
        if let WallGeometry::Clump { centres, radii } = &w.geometry {
            for (c, r) in centres.iter().zip(radii) {
                y0 = y0.min(c.y - r);
                y1 = y1.max(c.y + r);
            }
        }
    }
    (x0, x1, y0, y1)
}

/// The walls: lines clipped to `extent`, segments, clumps as grey disks.
fn draw_walls<'a, 'b: 'a>(
    chart: &mut GrainChart<'a, 'b>,
    snap: &Snapshot,
    extent: (f64, f64, f64, f64),
    px_per_m: f64,
) -> DrawResult {
    let grey = RGBColor(90, 90, 90);
    for w in &snap.walls {
        match &w.geometry {
            WallGeometry::Line { point, normal } => {
                if let Some((a, b)) = clip_line(*point, *normal, extent) {
                    chart.draw_series(std::iter::once(PathElement::new(
                        vec![(a.x, a.y), (b.x, b.y)],
                        grey.stroke_width(4),
                    )))?;
                }
            }
            WallGeometry::Segment { a, b } => {
                chart.draw_series(std::iter::once(PathElement::new(
                    vec![(a.x, a.y), (b.x, b.y)],
                    grey.stroke_width(4),
                )))?;
            }
            WallGeometry::Clump { centres, radii } => {
                chart.draw_series(centres.iter().zip(radii).map(|(c, r)| {
                    Circle::new(
                        (c.x, c.y),
                        ((r * px_per_m).round() as i32).max(1),
                        RGBColor(120, 120, 120).filled(),
                    )
                }))?;
            }
        }
    }
    Ok(())
}

/// The disk of grain `b` drawn in `style` (its radius at least one pixel).
fn disk(b: &BodyState, px_per_m: f64, style: ShapeStyle) -> Circle<(f64, f64), i32> {
    Circle::new(
        (b.position.x, b.position.y),
        ((b.radius * px_per_m).round() as i32).max(1),
        style,
    )
}

/// The grains: filled (light grey, or by their value; NaN white), then outlined.
fn draw_grains<'a, 'b: 'a>(
    chart: &mut GrainChart<'a, 'b>,
    grains: &[&BodyState],
    fill: &GrainFill,
    px_per_m: f64,
) -> DrawResult {
    let outline = match fill {
        GrainFill::Plain => {
            chart.draw_series(
                grains
                    .iter()
                    .map(|b| disk(b, px_per_m, RGBColor(228, 228, 228).filled())),
            )?;
            RGBColor(170, 170, 170)
        }
        GrainFill::Values { values, scale, .. } => {
            chart.draw_series(grains.iter().zip(values).map(|(b, v)| {
                let c = if v.is_finite() {
                    scale.color(*v)
                } else {
                    WHITE
                };
                disk(b, px_per_m, c.filled())
            }))?;
            RGBColor(60, 60, 60)
        }
    };
    chart.draw_series(
        grains
            .iter()
            .map(|b| disk(b, px_per_m, outline.stroke_width(1))),
    )?;
    Ok(())
}

/// The force chains: a segment between the bodies of each contact, its width proportional to
/// the normal force (faint below a pixel), the strongest on top, and the scale's note.
fn draw_force_chains<'a, 'b: 'a>(
    chart: &mut GrainChart<'a, 'b>,
    main: &DrawingArea<BitMapBackend, Shift>,
    snap: &Snapshot,
    grains: &[&BodyState],
    px_per_m: f64,
) -> DrawResult {
    let fmax = snap.contacts.iter().map(|c| c.force_n).fold(0.0, f64::max);
    if fmax <= 0.0 {
        return Ok(());
    }
    let rmean = grains.iter().map(|b| b.radius).sum::<f64>() / grains.len().max(1) as f64;
    let wmax = (1.2 * rmean * px_per_m).clamp(3.0, 16.0);
    let red = RGBColor(170, 20, 20);
    let mut cs: Vec<_> = snap
        .contacts
        .iter()
        .filter(|c| c.force_n > 1e-6 * fmax)
        .collect();
    cs.sort_by(|a, b| a.force_n.total_cmp(&b.force_n));
    chart.draw_series(cs.iter().map(|c| {
        let (a, b) = branch(snap, c);
        let w = wmax * c.force_n / fmax;
        let style = if w >= 1.0 {
            red.stroke_width(w.round() as u32)
        } else {
            red.mix(w.max(0.15)).stroke_width(1)
        };
        PathElement::new(vec![(a.x, a.y), (b.x, b.y)], style)
    }))?;
    let (_, py) = chart.plotting_area().get_pixel_range();
    let px0 = chart.plotting_area().get_base_pixel().0;
    main.draw(&Text::new(
        format!("line width ∝ normal force, max {:.3e} N/m", fmax),
        (px0 + 5, py.end + 2 - 22),
        font(14.0),
    ))?;
    Ok(())
}
