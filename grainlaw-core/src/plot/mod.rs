//! Figures (PNG, plotters with the `ab_glyph` text backend and the DejaVu Sans font shipped in
//! `assets/fonts/`, so they render on a machine without any system font).
//!
//! - [`xy`]: curves and points with legends, confidence bands, linear or log axes;
//! - [`particles`]: grains, walls and contact forces (force chains with line width ∝ f_n),
//!   per-grain colour maps;
//! - [`colormap`]: the viridis colour map and colour bars;
//! - [`histogram`]: bar histograms.
//!
//! Every figure is drawn to a temporary file and renamed into place ([`crate::output::OutputDir`]).

pub mod colormap;
pub mod histogram;
pub mod particles;
pub mod xy;

use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::error::{CliError, Result};
use crate::output::OutputDir;

/// The font file shipped with the repository (DejaVu Sans, Bitstream Vera licence, see
/// `assets/fonts/DejaVuSans-LICENSE.txt`).
static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// Font family name used by every figure.
pub const FONT_FAMILY: &str = "sans-serif";

static INIT: Once = Once::new();

/// Registers the shipped font under [`FONT_FAMILY`] (once per process).
pub fn init_font() {
    INIT.call_once(|| {
        let _ = plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, FONT);
        let _ = plotters::style::register_font(FONT_FAMILY, FontStyle::Bold, FONT);
        let _ = plotters::style::register_font(FONT_FAMILY, FontStyle::Italic, FONT);
        let _ = plotters::style::register_font(FONT_FAMILY, FontStyle::Oblique, FONT);
    });
}

/// Series colours (colour-blind safe, Okabe–Ito).
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(230, 159, 0),
    RGBColor(80, 80, 80),
];

/// Boxed error of a drawing closure (and what it returns, nothing by default).
pub type DrawResult<T = ()> = std::result::Result<T, Box<dyn std::error::Error>>;

/// Draws a `size` PNG named `name` in `out` with `draw`, atomically.
pub fn render<F>(out: &mut OutputDir, name: &str, size: (u32, u32), draw: F) -> Result<()>
where
    F: FnOnce(&DrawingArea<BitMapBackend, Shift>) -> DrawResult,
{
    init_font();
    let tmp = out.temp_path(name);
    let res = (|| -> DrawResult {
        let root = BitMapBackend::new(&tmp, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
        Ok(())
    })();
    if let Err(e) = res {
        let _ = std::fs::remove_file(&tmp);
        return Err(CliError::Plot {
            file: name.to_string(),
            reason: e.to_string(),
        });
    }
    out.commit(&tmp, name)?;
    Ok(())
}

/// Text style of the given size.
pub fn font(size: f64) -> TextStyle<'static> {
    (FONT_FAMILY, size).into_font().into()
}

/// A "nice" upper bound: the smallest of 1, 2, 2.5, 5 × 10^k at or above `v`.
pub fn nice_ceil(v: f64) -> f64 {
    if !(v.is_finite() && v > 0.0) {
        return 1.0;
    }
    let p = 10f64.powf(v.log10().floor());
    for m in [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0] {
        if m * p >= v * (1.0 - 1e-12) {
            return m * p;
        }
    }
    10.0 * p
}

/// Range `[lo, hi]` of finite values with a relative margin; a degenerate range is widened.
pub fn padded_range(values: impl Iterator<Item = f64>, margin: f64) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
        let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        return (lo - d, hi + d);
    }
    let d = (hi - lo) * margin;
    (lo - d, hi + d)
}
