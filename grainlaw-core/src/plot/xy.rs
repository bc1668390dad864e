//! Curves, points with error bars, and confidence bands on linear or logarithmic axes, with a
//! legend.

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::CoordTranslate;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::{font, padded_range, render, DrawResult};
use crate::error::Result;
use crate::output::OutputDir;

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Style {
    /// A solid line.
    Line,
    /// A dashed line.
    Dashed,
    /// Filled circles.
    Points,
    /// Hollow circles.
    Circles,
    /// A line with filled circles.
    LinePoints,
    /// A thin line (for long time series).
    Thin,
}

/// One series.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text (empty: not in the legend).
    pub label: String,
    /// How it is drawn.
    pub style: Style,
    /// Colour.
    pub color: RGBColor,
    /// Points `(x, y)`; non-finite points are skipped.
    pub xy: Vec<(f64, f64)>,
    /// Error bars: one `(x_error, y_error)` half-width per point of `xy` (a standard error,
    /// drawn as `x ± x_error`, `y ± y_error`; a non-finite or non-positive half-width draws no
    /// bar), or empty for a series without error bars.
    pub errors: Vec<(f64, f64)>,
}

impl Series {
    /// A series.
    pub fn new(label: &str, style: Style, color: RGBColor, xy: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.to_string(),
            style,
            color,
            xy: xy
                .into_iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect(),
            errors: Vec::new(),
        }
    }

    /// A series of points with error bars: `(x, y, x_error, y_error)`, the errors half-widths
    /// (e.g. standard errors; NaN where a point has none). Points with a non-finite `x` or `y`
    /// are skipped with their errors.
    pub fn with_errors(
        label: &str,
        style: Style,
        color: RGBColor,
        pts: Vec<(f64, f64, f64, f64)>,
    ) -> Self {
        let kept: Vec<_> = pts
            .into_iter()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        Self {
            label: label.to_string(),
            style,
            color,
            xy: kept.iter().map(|p| (p.0, p.1)).collect(),
            errors: kept.iter().map(|p| (p.2, p.3)).collect(),
        }
    }

    /// The error bars drawn: `(x, y, x_error, y_error)` for each point with at least one usable
    /// half-width (finite and positive; the other one is then 0).
    pub fn error_bars(&self) -> Vec<(f64, f64, f64, f64)> {
        let usable = |e: f64| if e.is_finite() && e > 0.0 { e } else { 0.0 };
        self.xy
            .iter()
            .zip(&self.errors)
            .map(|(&(x, y), &(ex, ey))| (x, y, usable(ex), usable(ey)))
            .filter(|b| b.2 > 0.0 || b.3 > 0.0)
            .collect()
    }
}

/// A shaded band between two curves (e.g. a 95 % confidence band), drawn under the series.
#[derive(Debug, Clone)]
pub struct Band {
    /// Legend text.
    pub label: String,
    /// Colour (drawn at 25 % opacity).
    pub color: RGBColor,
    /// The closed outline: lower curve forward then upper curve backward.
    pub outline: Vec<(f64, f64)>,
}

impl Band {
    /// A band from points `(x, lo, hi)`.
    pub fn between(label: &str, color: RGBColor, pts: &[(f64, f64, f64)]) -> Self {
        Self::outlined(label, color, pts, |a, b| (a, b))
    }

    /// A band from points `(y, x_lo, x_hi)` (for profiles drawn with x as the value).
    pub fn between_x(label: &str, color: RGBColor, pts: &[(f64, f64, f64)]) -> Self {
        Self::outlined(label, color, pts, |a, b| (b, a))
    }

    /// The band of points `(s, lo, hi)`, `place(s, v)` the drawn point of value `v` at `s`:
    /// the lower curve forward then the upper one backward, non-finite points left out.
    fn outlined(
        label: &str,
        color: RGBColor,
        pts: &[(f64, f64, f64)],
        place: impl Fn(f64, f64) -> (f64, f64),
    ) -> Self {
        let mut outline: Vec<(f64, f64)> = pts.iter().map(|&(s, lo, _)| place(s, lo)).collect();
        outline.extend(pts.iter().rev().map(|&(s, _, hi)| place(s, hi)));
        Self {
            label: label.to_string(),
            color,
            outline: outline
                .into_iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .collect(),
        }
    }
}

/// Axis settings.
#[derive(Debug, Clone, Default)]
pub struct Axis {
    /// Quantity and unit, e.g. `depth z (m)`.
    pub label: String,
    /// Fixed range; `None` fits the data.
    pub range: Option<(f64, f64)>,
    /// Logarithmic axis.
    pub log: bool,
    /// Drawn from high to low (e.g. depth downwards).
    pub reversed: bool,
}

impl Axis {
    /// A linear axis fitted to the data.
    pub fn new(label: &str) -> Self {
        Self {
            label: label.to_string(),
            ..Default::default()
        }
    }

    /// Fixed range.
    pub fn range(mut self, lo: f64, hi: f64) -> Self {
        self.range = Some((lo, hi));
        self
    }

    /// Logarithmic.
    pub fn log(mut self) -> Self {
        self.log = true;
        self
    }

    /// Reversed.
    pub fn reversed(mut self) -> Self {
        self.reversed = true;
        self
    }
}

/// Margin of a chart around its title, labels and plotting area (px).
const MARGIN: u32 = 18;
/// Height of the x tick labels and axis description below the plotting area (px).
const X_LABEL_AREA: u32 = 55;
/// Width of the y tick labels and axis description left of the plotting area (px).
const Y_LABEL_AREA: u32 = 85;
/// Font size of a chart's title.
const TITLE_SIZE: f64 = 22.0;

/// Where the legend goes.
pub use plotters::chart::SeriesLabelPosition as LegendAt;

/// A figure of curves.
#[derive(Debug, Clone)]
pub struct XyPlot {
    /// Title above the axes (empty for none).
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// Series, drawn in order.
    pub series: Vec<Series>,
    /// Bands, drawn first.
    pub bands: Vec<Band>,
    /// Legend position.
    pub legend: LegendAt,
    /// Extra text lines in the upper left of the plotting area.
    pub notes: Vec<String>,
    /// One unit of x as long on the screen as one unit of y (circles drawn round): the
    /// shorter range is widened above its high end to the plotting area's aspect ratio.
    pub equal_aspect: bool,
}

impl XyPlot {
    /// An empty figure.
    pub fn new(title: &str, x: Axis, y: Axis) -> Self {
        Self {
            title: title.to_string(),
            x,
            y,
            series: Vec::new(),
            bands: Vec::new(),
            legend: LegendAt::UpperRight,
            notes: Vec::new(),
            equal_aspect: false,
        }
    }

    fn data_range(&self, xs: bool, axis: &Axis) -> (f64, f64) {
        if let Some(r) = axis.range {
            return r;
        }
        let bar_ends = self.series.iter().flat_map(|s| {
            s.error_bars()
                .into_iter()
                .flat_map(|(x, y, ex, ey)| [(x - ex, y - ey), (x + ex, y + ey)])
        });
        let vals = self
            .series
            .iter()
            .flat_map(|s| s.xy.iter().copied())
            .chain(self.bands.iter().flat_map(|b| b.outline.iter().copied()))
            .chain(bar_ends)
            .map(|(x, y)| if xs { x } else { y })
            .filter(|v| !axis.log || *v > 0.0);
        if axis.log {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for v in vals {
                lo = lo.min(v);
                hi = hi.max(v);
            }
            if !lo.is_finite() {
                return (1e-3, 1.0);
            }
            if hi <= lo * 1.0001 {
                return (lo / 2.0, hi * 2.0);
            }
            let f = (hi / lo).powf(0.05);
            (lo / f, hi * f)
        } else {
            padded_range(vals, 0.05)
        }
    }

    /// The plotting area's size in pixels when the figure is drawn into `area` (the chart's
    /// layout: its margins, the title, the label areas).
    pub fn plotting_pixels(&self, area: &DrawingArea<BitMapBackend, Shift>) -> (f64, f64) {
        let (w, h) = area.dim_in_pixel();
        let title_h = if self.title.is_empty() {
            0
        } else {
            // `DrawingArea::titled`: the text's height and a padding of min(h/2, 5) above and
            // below it
            let th = area
                .estimate_text_size(&self.title, &font(TITLE_SIZE))
                .map(|s| s.1)
                .unwrap_or(0);
            th + 2 * (th / 2).min(5)
        };
        (
            (w as f64 - 2.0 * MARGIN as f64 - Y_LABEL_AREA as f64).max(1.0),
            (h as f64 - 2.0 * MARGIN as f64 - title_h as f64 - X_LABEL_AREA as f64).max(1.0),
        )
    }

    /// The ranges drawn into `area`: each axis's fixed range or the data's, widened to equal
    /// scales when [`XyPlot::equal_aspect`] (linear axes only).
    pub fn ranges(&self, area: &DrawingArea<BitMapBackend, Shift>) -> ((f64, f64), (f64, f64)) {
        let (mut x0, mut x1) = self.data_range(true, &self.x);
        let (mut y0, mut y1) = self.data_range(false, &self.y);
        if self.equal_aspect && !self.x.log && !self.y.log {
            let (pw, ph) = self.plotting_pixels(area);
            // metres (or pascals) per pixel along each axis; the larger one wins
            let per_px = ((x1 - x0) / pw).max((y1 - y0) / ph);
            // the shorter range grows upwards from its low end (e.g. a τ axis from 0)
            let widen = |lo: f64, _hi: f64, px: f64| (lo, lo + per_px * px);
            (x0, x1) = widen(x0, x1, pw);
            (y0, y1) = widen(y0, y1, ph);
        }
        ((x0, x1), (y0, y1))
    }

    /// Draws the figure into `area`.
    pub fn draw_on(&self, area: &DrawingArea<BitMapBackend, Shift>) -> DrawResult {
        let ranges = self.ranges(area);
        let ((x0, x1), (y0, y1)) = ranges;
        let xr = if self.x.reversed { (x1, x0) } else { (x0, x1) };
        let yr = if self.y.reversed { (y1, y0) } else { (y0, y1) };
        match (self.x.log, self.y.log) {
            (false, false) => self.draw_generic(area, ranges, xr.0..xr.1, yr.0..yr.1),
            (true, false) => self.draw_generic(area, ranges, (xr.0..xr.1).log_scale(), yr.0..yr.1),
            (false, true) => self.draw_generic(area, ranges, xr.0..xr.1, (yr.0..yr.1).log_scale()),
            (true, true) => self.draw_generic(
                area,
                ranges,
                (xr.0..xr.1).log_scale(),
                (yr.0..yr.1).log_scale(),
            ),
        }
    }

    /// Draws the figure into `area` on the coordinates `xr`, `yr` (linear or logarithmic)
    /// spanning `ranges`: the mesh → the bands → each series with its error bars → the legend
    /// → the notes.
    fn draw_generic<XR, YR>(
        &self,
        area: &DrawingArea<BitMapBackend, Shift>,
        ranges: ((f64, f64), (f64, f64)),
        xr: XR,
        yr: YR,
    ) -> DrawResult
    where
        XR: AsRangedCoord<Value = f64>,
        YR: AsRangedCoord<Value = f64>,
        XR::CoordDescType: ValueFormatter<f64>,
        YR::CoordDescType: ValueFormatter<f64>,
    {
        let mut builder = ChartBuilder::on(area);
        builder
            .margin(MARGIN)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA);
        if !self.title.is_empty() {
            builder.caption(&self.title, font(TITLE_SIZE));
        }
        let mut chart = builder.build_cartesian_2d(xr, yr)?;
        self.draw_mesh(&mut chart, ranges)?;
        let mut labelled = self.draw_bands(&mut chart)?;
        for s in &self.series {
            self.draw_error_bars(&mut chart, s, ranges)?;
            labelled |= draw_series(&mut chart, s)?;
        }
        if labelled {
            self.draw_legend(&mut chart)?;
        }
        self.draw_notes(area, &chart)
    }

    /// The axes, their labels and the grid; a logarithmic axis spanning less than a decade
    /// labels every tick.
    fn draw_mesh<'a, 'b: 'a, X, Y>(
        &self,
        chart: &mut XyChart<'a, 'b, X, Y>,
        ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
    ) -> DrawResult
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let (xlog, ylog) = (self.x.log, self.y.log);
        let within_decade = |a: f64, b: f64| a.max(b) < 10.0 * a.min(b);
        let (xall, yall) = (within_decade(x0, x1), within_decade(y0, y1));
        let xf = move |v: &f64| match (xlog, xall) {
            (true, false) => fmt_log_tick(*v),
            _ => fmt_tick(*v),
        };
        let yf = move |v: &f64| match (ylog, yall) {
            (true, false) => fmt_log_tick(*v),
            _ => fmt_tick(*v),
        };
        chart
            .configure_mesh()
            .max_light_lines(if xlog || ylog { 0 } else { 5 })
            .x_desc(self.x.label.as_str())
            .y_desc(self.y.label.as_str())
            .label_style(font(16.0))
            .axis_desc_style(font(18.0))
            .light_line_style(RGBColor(235, 235, 235))
            .bold_line_style(RGBColor(210, 210, 210))
            .x_label_formatter(&xf)
            .y_label_formatter(&yf)
            .draw()?;
        Ok(())
    }

    /// The bands, shaded; whether one is in the legend.
    fn draw_bands<'a, 'b: 'a, X, Y>(&self, chart: &mut XyChart<'a, 'b, X, Y>) -> DrawResult<bool>
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let mut labelled = false;
        for b in &self.bands {
            let c = b.color;
            let poly = chart.draw_series(std::iter::once(Polygon::new(
                b.outline.clone(),
                c.mix(0.22).filled(),
            )))?;
            if !b.label.is_empty() {
                labelled = true;
                poly.label(b.label.as_str()).legend(move |(x, y)| {
                    Rectangle::new([(x, y - 6), (x + 22, y + 6)], c.mix(0.3).filled())
                });
            }
        }
        Ok(labelled)
    }

    /// The error bars of series `s` on the chart spanning `ranges`; on a logarithmic axis a
    /// bar reaching zero or below is cut at the axis.
    fn draw_error_bars<'a, 'b: 'a, X, Y>(
        &self,
        chart: &mut XyChart<'a, 'b, X, Y>,
        s: &Series,
        ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
    ) -> DrawResult
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let (xlog, ylog) = (self.x.log, self.y.log);
        let c = s.color;
        let (xlo, ylo) = (x0.min(x1), y0.min(y1));
        let low = |v: f64, e: f64, log: bool, floor: f64| {
            if log && v - e <= 0.0 {
                floor
            } else {
                v - e
            }
        };
        for (x, y, ex, ey) in s.error_bars() {
            if ey > 0.0 {
                chart.draw_series(std::iter::once(ErrorBar::new_vertical(
                    x,
                    low(y, ey, ylog, ylo),
                    y,
                    y + ey,
                    c.stroke_width(2),
                    10,
                )))?;
            }
            if ex > 0.0 {
                chart.draw_series(std::iter::once(ErrorBar::new_horizontal(
                    y,
                    low(x, ex, xlog, xlo),
                    x,
                    x + ex,
                    c.stroke_width(2),
                    10,
                )))?;
            }
        }
        Ok(())
    }

    /// The legend (one in the upper left goes below the notes drawn there).
    fn draw_legend<'a, 'b: 'a, X, Y>(&self, chart: &mut XyChart<'a, 'b, X, Y>) -> DrawResult
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let position = match (&self.legend, self.notes.len()) {
            (LegendAt::UpperLeft, n) if n > 0 => LegendAt::Coordinate(5, 10 + 22 * n as i32),
            (l, _) => l.clone(),
        };
        chart
            .configure_series_labels()
            .position(position)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(150, 150, 150))
            .label_font(font(16.0))
            .draw()?;
        Ok(())
    }

    /// The notes, in the upper left of the plotting area.
    fn draw_notes<'a, 'b: 'a, X, Y>(
        &self,
        area: &DrawingArea<BitMapBackend, Shift>,
        chart: &XyChart<'a, 'b, X, Y>,
    ) -> DrawResult
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        if self.notes.is_empty() {
            return Ok(());
        }
        // Pixel ranges are absolute; `area.draw` takes coordinates relative to the area.
        let (px, py) = chart.plotting_area().get_pixel_range();
        let (ax, ay) = area.get_base_pixel();
        for (k, n) in self.notes.iter().enumerate() {
            area.draw(&Text::new(
                n.clone(),
                (px.start - ax + 12, py.start - ay + 10 + 22 * k as i32),
                font(16.0),
            ))?;
        }
        Ok(())
    }
}

/// The chart an [`XyPlot`] draws on.
type XyChart<'a, 'b, X, Y> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<X, Y>>;

/// Draws series `s` in its style; whether it is in the legend.
fn draw_series<'a, 'b: 'a, X, Y>(chart: &mut XyChart<'a, 'b, X, Y>, s: &Series) -> DrawResult<bool>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let c = s.color;
    let anno = match s.style {
        Style::Line | Style::Thin | Style::LinePoints => {
            let w = if s.style == Style::Thin { 1 } else { 3 };
            if s.style == Style::LinePoints {
                chart.draw_series(s.xy.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
            }
            let a = chart.draw_series(LineSeries::new(s.xy.clone(), c.stroke_width(w)))?;
            Some((a, s.style))
        }
        Style::Dashed => {
            let pts = dash(&s.xy, |p| chart.as_coord_spec().translate(p));
            let mut a = None;
            for seg in pts {
                a = Some(chart.draw_series(LineSeries::new(seg, c.stroke_width(2)))?);
            }
            a.map(|a| (a, s.style))
        }
        Style::Points => Some((
            chart.draw_series(s.xy.iter().map(|&p| Circle::new(p, 4, c.filled())))?,
            s.style,
        )),
        Style::Circles => Some((
            chart.draw_series(s.xy.iter().map(|&p| Circle::new(p, 5, c.stroke_width(2))))?,
            s.style,
        )),
    };
    let Some((a, style)) = anno.filter(|_| !s.label.is_empty()) else {
        return Ok(false);
    };
    a.label(s.label.as_str()).legend(
        move |(x, y)| -> DynElement<'static, BitMapBackend, (i32, i32)> {
            match style {
                Style::Points => Circle::new((x + 11, y), 4, c.filled()).into_dyn(),
                Style::Circles => Circle::new((x + 11, y), 5, c.stroke_width(2)).into_dyn(),
                Style::Dashed => {
                    PathElement::new(vec![(x, y), (x + 8, y)], c.stroke_width(2)).into_dyn()
                }
                _ => PathElement::new(vec![(x, y), (x + 22, y)], c.stroke_width(3)).into_dyn(),
            }
        },
    );
    Ok(true)
}

/// Splits a polyline into dashes of about 10 px drawn, 6 px skipped.
fn dash(xy: &[(f64, f64)], to_px: impl Fn(&(f64, f64)) -> (i32, i32)) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    let (on, off) = (10.0, 6.0);
    let mut acc = 0.0;
    let mut drawing = true;
    for w in xy.windows(2) {
        let (p, q) = (w[0], w[1]);
        let (a, b) = (to_px(&p), to_px(&q));
        let len = (((b.0 - a.0) as f64).powi(2) + ((b.1 - a.1) as f64).powi(2)).sqrt();
        let steps = (len / 2.0).ceil().max(1.0) as usize;
        for k in 0..steps {
            let t0 = k as f64 / steps as f64;
            let pt = (p.0 + (q.0 - p.0) * t0, p.1 + (q.1 - p.1) * t0);
            if drawing {
                cur.push(pt);
            }
            acc += len / steps as f64;
            let limit = if drawing { on } else { off };
            if acc >= limit {
                acc = 0.0;
                if drawing {
                    cur.push(pt);
                    out.push(std::mem::take(&mut cur));
                }
                drawing = !drawing;
            }
        }
    }
    if drawing {
        if let Some(&l) = xy.last() {
            cur.push(l);
        }
        if cur.len() >= 2 {
            out.push(cur);
        }
    }
    out
}

/// Tick label: plain decimals for moderate magnitudes, scientific otherwise.
pub fn fmt_tick(v: f64) -> String {
    let a = v.abs();
    if a < 1e-13 {
        "0".into()
    } else if (1e-3..1e5).contains(&a) {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.').to_string();
        if s == "-0" {
            "0".into()
        } else {
            s
        }
    } else {
        let s = format!("{v:.1e}");
        s.replace(".0e", "e")
    }
}

/// Tick label of a logarithmic axis: only 1, 2 and 5 × 10^k are labelled.
pub fn fmt_log_tick(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return String::new();
    }
    let e = v.log10().floor();
    let m = v / 10f64.powf(e);
    if [1.0, 2.0, 5.0].iter().any(|t| (m - t).abs() < 1e-6 * t) || (m - 10.0).abs() < 1e-5 {
        if (1e-3..1e5).contains(&v) {
            fmt_tick(v)
        } else {
            format!("{v:.0e}")
        }
    } else {
        String::new()
    }
}

/// Draws `plot` alone as `name` (1000 × 700 px).
pub fn draw_xy(out: &mut OutputDir, name: &str, plot: &XyPlot) -> Result<()> {
    render(out, name, (1000, 700), |root| plot.draw_on(root))
}

/// Draws several plots side by side (one row) as `name`.
pub fn draw_row(out: &mut OutputDir, name: &str, plots: &[XyPlot], size: (u32, u32)) -> Result<()> {
    render(out, name, size, |root| {
        let areas = root.split_evenly((1, plots.len().max(1)));
        for (p, a) in plots.iter().zip(areas.iter()) {
            p.draw_on(a)?;
        }
        Ok(())
    })
}

/// Draws several plots stacked in one column as `name`.
pub fn draw_column(
    out: &mut OutputDir,
    name: &str,
    plots: &[XyPlot],
    size: (u32, u32),
) -> Result<()> {
    render(out, name, size, |root| {
        let areas = root.split_evenly((plots.len().max(1), 1));
        for (p, a) in plots.iter().zip(areas.iter()) {
            p.draw_on(a)?;
        }
        Ok(())
    })
}

#[allow(dead_code)]
type Lin = RangedCoordf64;

#[cfg(test)]
mod tests {
    use super::*;

    /// With equal scales, the plotting area's size computed from the layout is the one the
    /// chart gets (to a pixel), and one unit of x spans as many pixels as one unit of y (to
    /// 1 %), the shorter range grown from its low end; the data stay inside the ranges.
    #[test]
    fn equal_aspect_draws_equal_scales() {
        crate::plot::init_font();
        let (w, h) = (650u32, 650u32);
        let mut buf = vec![0u8; (w * h * 3) as usize];
        let area = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let mut plot = XyPlot::new("Mohr", Axis::new("σ (Pa)"), Axis::new("τ (Pa)"));
        plot.series.push(Series::new(
            "",
            Style::Line,
            RGBColor(0, 0, 0),
            vec![(0.0, 0.0), (10_000.0, 0.0), (6000.0, 3000.0)],
        ));
        plot.equal_aspect = true;
        let (pw, ph) = plot.plotting_pixels(&area);
        let ((x0, x1), (y0, y1)) = plot.ranges(&area);
        let chart = ChartBuilder::on(&area)
            .margin(MARGIN)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .caption("Mohr", font(TITLE_SIZE))
            .build_cartesian_2d(x0..x1, y0..y1)
            .unwrap();
        let (aw, ah) = chart.plotting_area().dim_in_pixel();
        assert!((aw as f64 - pw).abs() <= 1.0 && (ah as f64 - ph).abs() <= 1.0);
        let (sx, sy) = ((x1 - x0) / aw as f64, (y1 - y0) / ah as f64);
        assert!((sx / sy - 1.0).abs() < 0.01, "{sx} {sy}");
        // x is the longer range (padded 5 %); y grew upwards from its padded low end
        assert!(x0 < 0.0 && x1 > 10_000.0 && (y0 - (-150.0)).abs() < 1e-9 && y1 > 3000.0);
    }

    /// Error bars: a point with a finite positive standard error has a bar, one with NaN or
    /// zero has none, and points dropped for a non-finite coordinate drop their errors.
    #[test]
    fn error_bars_follow_their_points() {
        let s = Series::with_errors(
            "",
            Style::Points,
            RGBColor(0, 0, 0),
            vec![
                (1.0, 2.0, f64::NAN, 0.1),
                (f64::NAN, 3.0, 0.5, 0.5),
                (2.0, 4.0, 0.0, f64::NAN),
                (3.0, 5.0, 0.2, 0.0),
            ],
        );
        assert_eq!(s.xy, vec![(1.0, 2.0), (2.0, 4.0), (3.0, 5.0)]);
        assert_eq!(
            s.error_bars(),
            vec![(1.0, 2.0, 0.0, 0.1), (3.0, 5.0, 0.2, 0.0)]
        );
    }
}
