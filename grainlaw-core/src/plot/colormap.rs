//! The viridis colour map (perceptually uniform, readable in grey) and colour bars.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{font, DrawResult};

/// Viridis anchor colours at t = 0, 0.125, …, 1.
const VIRIDIS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 44, 122),
    (59, 81, 139),
    (44, 113, 142),
    (33, 144, 141),
    (39, 173, 129),
    (92, 200, 99),
    (170, 220, 50),
    (253, 231, 37),
];

/// Viridis colour at `t ∈ [0, 1]` (clamped), linearly interpolated between anchors.
pub fn viridis(t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let lerp = |p: u8, q: u8| (p as f64 + f * (q as f64 - p as f64)).round() as u8;
    RGBColor(lerp(a.0, b.0), lerp(a.1, b.1), lerp(a.2, b.2))
}

/// A mapping from values to `[0, 1]`, linear or logarithmic.
#[derive(Debug, Clone, Copy)]
pub struct Scale {
    /// Lowest value (mapped to 0).
    pub min: f64,
    /// Highest value (mapped to 1).
    pub max: f64,
    /// Logarithmic (values and bounds must be > 0).
    pub log: bool,
}

impl Scale {
    /// Position of `v` in `[0, 1]` (clamped).
    pub fn t(&self, v: f64) -> f64 {
        let (a, b, x) = if self.log {
            (
                self.min.max(1e-300).log10(),
                self.max.max(1e-300).log10(),
                v.max(1e-300).log10(),
            )
        } else {
            (self.min, self.max, v)
        };
        if b > a {
            ((x - a) / (b - a)).clamp(0.0, 1.0)
        } else {
            0.5
        }
    }

    /// Colour of `v`.
    pub fn color(&self, v: f64) -> RGBColor {
        viridis(self.t(v))
    }
}

/// Draws a vertical colour bar for `scale` in `area` with the quantity `label`.
pub fn colorbar(
    area: &DrawingArea<BitMapBackend, Shift>,
    scale: &Scale,
    label: &str,
) -> DrawResult {
    let (lo, hi) = (scale.min, scale.max);
    let n = 200;
    if scale.log {
        let mut chart = ChartBuilder::on(area)
            .margin_top(40)
            .margin_bottom(60)
            .margin_left(25)
            .margin_right(20)
            .set_label_area_size(LabelAreaPosition::Right, 110)
            .build_cartesian_2d(0.0..1.0, (lo..hi).log_scale())?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .disable_y_mesh()
            .disable_x_axis()
            .y_desc(label)
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .label_style(font(15.0))
            .axis_desc_style(font(17.0))
            .draw()?;
        let (a, b) = (lo.log10(), hi.log10());
        chart.draw_series((0..n).map(|k| {
            let v0 = 10f64.powf(a + (b - a) * k as f64 / n as f64);
            let v1 = 10f64.powf(a + (b - a) * (k + 1) as f64 / n as f64);
            Rectangle::new(
                [(0.0, v0), (1.0, v1)],
                scale.color(0.5 * (v0 + v1)).filled(),
            )
        }))?;
    } else {
        let mut chart = ChartBuilder::on(area)
            .margin_top(40)
            .margin_bottom(60)
            .margin_left(25)
            .margin_right(20)
            .set_label_area_size(LabelAreaPosition::Right, 110)
            .build_cartesian_2d(0.0..1.0, lo..hi)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .disable_y_mesh()
            .disable_x_axis()
            .y_desc(label)
            .label_style(font(15.0))
            .axis_desc_style(font(17.0))
            .draw()?;
        chart.draw_series((0..n).map(|k| {
            let v0 = lo + (hi - lo) * k as f64 / n as f64;
            let v1 = lo + (hi - lo) * (k + 1) as f64 / n as f64;
            Rectangle::new(
                [(0.0, v0), (1.0, v1)],
                scale.color(0.5 * (v0 + v1)).filled(),
            )
        }))?;
    }
    Ok(())
}
