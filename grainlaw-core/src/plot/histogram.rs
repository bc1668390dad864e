//! Bar histograms.

use plotters::prelude::*;

use super::{font, render, xy::fmt_tick};
use crate::error::Result;
use crate::output::OutputDir;

/// A histogram figure: bars over `edges` with heights `values`.
#[derive(Debug, Clone)]
pub struct HistogramPlot {
    /// Title.
    pub title: String,
    /// Horizontal quantity and unit.
    pub x_label: String,
    /// Vertical quantity.
    pub y_label: String,
    /// Bin edges (`values.len() + 1`).
    pub edges: Vec<f64>,
    /// Bar heights.
    pub values: Vec<f64>,
    /// Bar colour.
    pub color: RGBColor,
    /// Vertical marker lines `(x, label)`.
    pub markers: Vec<(f64, String)>,
    /// Text lines in the upper left.
    pub notes: Vec<String>,
}

/// Draws the histogram as `name` (1000 × 650 px).
pub fn draw_histogram(out: &mut OutputDir, name: &str, h: &HistogramPlot) -> Result<()> {
    render(out, name, (1000, 650), |root| {
        let x0 = h.edges.first().copied().unwrap_or(0.0);
        let x1 = h.edges.last().copied().unwrap_or(1.0);
        let ymax = h.values.iter().cloned().fold(0.0, f64::max).max(1e-12) * 1.15;
        let mut chart = ChartBuilder::on(root)
            .caption(&h.title, font(22.0))
            .margin(18)
            .x_label_area_size(55)
            .y_label_area_size(85)
            .build_cartesian_2d(x0..x1, 0.0..ymax)?;
        chart
            .configure_mesh()
            .x_desc(h.x_label.as_str())
            .y_desc(h.y_label.as_str())
            .label_style(font(16.0))
            .axis_desc_style(font(18.0))
            .light_line_style(RGBColor(235, 235, 235))
            .bold_line_style(RGBColor(210, 210, 210))
            .x_label_formatter(&|v| fmt_tick(*v))
            .y_label_formatter(&|v| fmt_tick(*v))
            .draw()?;
        chart.draw_series(h.values.iter().enumerate().map(|(k, &v)| {
            let (a, b) = (h.edges[k], h.edges[k + 1]);
            let pad = 0.04 * (b - a);
            Rectangle::new([(a + pad, 0.0), (b - pad, v)], h.color.filled())
        }))?;
        for (x, label) in &h.markers {
            chart.draw_series(LineSeries::new(
                vec![(*x, 0.0), (*x, ymax)],
                BLACK.stroke_width(2),
            ))?;
            chart.draw_series(std::iter::once(Text::new(
                label.clone(),
                (*x, ymax * 0.97),
                font(15.0).pos(plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Right,
                    plotters::style::text_anchor::VPos::Top,
                )),
            )))?;
        }
        let (_, py) = chart.plotting_area().get_pixel_range();
        let px0 = chart.plotting_area().get_base_pixel().0;
        for (k, n) in h.notes.iter().enumerate() {
            root.draw(&Text::new(
                n.clone(),
                (px0 + 12, py.start + 10 + 22 * k as i32),
                font(16.0),
            ))?;
        }
        Ok(())
    })
}
