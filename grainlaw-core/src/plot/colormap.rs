//! The viridis colour map (perceptually uniform, readable in grey) and colour bars.

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
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
        let (a, b) = (lo.log10(), hi.log10());
        let exponent = |v: &f64| format!("{v:.0e}");
        bar(
            area,
            (lo..hi).log_scale(),
            scale,
            label,
            Some(&exponent),
            |k| 10f64.powf(a + (b - a) * k as f64 / n as f64),
            n,
        )
    } else {
        bar(
            area,
            lo..hi,
            scale,
            label,
            None,
            |k| lo + (hi - lo) * k as f64 / n as f64,
            n,
        )
    }
}

/// The colour bar of [`colorbar`] on the value axis `y` (linear or logarithmic), its ticks
/// written by `ticks` (the axis' own without), in `n` bands whose edges are `edge(k)`,
/// `k = 0..=n`, each filled with the colour of its middle value.
fn bar<Y>(
    area: &DrawingArea<BitMapBackend, Shift>,
    y: Y,
    scale: &Scale,
    label: &str,
    ticks: Option<&dyn Fn(&f64) -> String>,
    edge: impl Fn(usize) -> f64,
    n: usize,
) -> DrawResult
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut chart = ChartBuilder::on(area)
        .margin_top(40)
        .margin_bottom(60)
        .margin_left(25)
        .margin_right(20)
        .set_label_area_size(LabelAreaPosition::Right, 110)
        .build_cartesian_2d(0.0..1.0, y)?;
    let mut mesh = chart.configure_mesh();
    mesh.disable_x_mesh()
        .disable_y_mesh()
        .disable_x_axis()
        .y_desc(label)
        .label_style(font(15.0))
        .axis_desc_style(font(17.0));
    if let Some(f) = ticks {
        mesh.y_label_formatter(f);
    }
    mesh.draw()?;
    chart.draw_series((0..n).map(|k| {
        let (v0, v1) = (edge(k), edge(k + 1));
        Rectangle::new(
            [(0.0, v0), (1.0, v1)],
            scale.color(0.5 * (v0 + v1)).filled(),
        )
    }))?;
    Ok(())
}
