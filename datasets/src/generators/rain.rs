//! Grains placed without overlap in horizontal rows above a floor, ready to fall ("rain").
//!
//! Row k occupies the band `[b_k, b_k + 2 R_max,k]`; its grains sit left to right with random
//! gaps that share out the row's slack, and at random heights inside the band. Successive bands
//! are separated by `gap`, so no two grains overlap and none crosses the side walls.

use dem::math::Vector;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::error::{DatasetError, Result};

/// Where grains go: an interval of x and a floor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RainBox {
    /// Left end (m).
    pub x_min: f64,
    /// Right end (m).
    pub x_max: f64,
    /// Bottom of the first row (m).
    pub y_min: f64,
    /// Smallest gap between neighbours and between rows (m).
    pub gap: f64,
    /// Whether x is periodic (then the last grain of a row keeps `gap` from the first one's image).
    pub periodic: bool,
}

/// Centres (m) for grains of the given radii (in order), placed as described in the module
/// documentation. Fails when a grain is wider than the box.
pub fn rain(rng: &mut ChaCha8Rng, radii: &[f64], b: &RainBox) -> Result<Vec<Vector>> {
    let width = b.x_max - b.x_min;
    if !(width.is_finite() && width > 0.0 && b.gap >= 0.0) {
        return Err(DatasetError::Generator(format!(
            "rain box needs x_min < x_max and gap ≥ 0, got [{}, {}], gap {}",
            b.x_min, b.x_max, b.gap
        )));
    }
    let mut out = Vec::with_capacity(radii.len());
    let mut i = 0;
    let mut y = b.y_min;
    while i < radii.len() {
        // Fill one row greedily.
        let mut used = b.gap;
        let start = i;
        while i < radii.len() && used + 2.0 * radii[i] + b.gap <= width + 1e-15 {
            used += 2.0 * radii[i] + b.gap;
            i += 1;
        }
        if i == start {
            return Err(DatasetError::Generator(format!(
                "grain of radius {} m does not fit in a box {} m wide",
                radii[i], width
            )));
        }
        let row = &radii[start..i];
        let rmax = row.iter().cloned().fold(0.0, f64::max);
        // Share the slack at random among the gaps.
        let slack = (width - used).max(0.0);
        let mut w: Vec<f64> = (0..=row.len())
            .map(|_| rng.random_range(0.0..1.0))
            .collect();
        let s: f64 = w.iter().sum::<f64>().max(1e-300);
        for x in &mut w {
            *x *= slack / s;
        }
        let mut x = b.x_min + b.gap + w[0];
        for (k, &r) in row.iter().enumerate() {
            let cx = x + r;
            let cy = y + rmax + rng.random_range(-1.0..=1.0) * (rmax - r);
            out.push(Vector::new(cx, cy));
            x = cx + r + b.gap + w[k + 1];
        }
        y += 2.0 * rmax + b.gap;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn no_overlap_and_inside_the_box() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let radii: Vec<f64> = (0..500).map(|_| rng.random_range(0.5e-3..2.5e-3)).collect();
        let b = RainBox {
            x_min: 0.0,
            x_max: 0.03,
            y_min: 0.0,
            gap: 1e-5,
            periodic: false,
        };
        let c = rain(&mut rng, &radii, &b).unwrap();
        for i in 0..c.len() {
            assert!(
                c[i].x - radii[i] >= b.gap * 0.999 && c[i].x + radii[i] <= b.x_max - b.gap * 0.999
            );
            assert!(c[i].y - radii[i] >= 0.0);
            for j in 0..i {
                let d = (c[i] - c[j]).norm() - radii[i] - radii[j];
                assert!(d >= b.gap * 0.999, "{i} {j} gap {d}");
            }
        }
    }
}
