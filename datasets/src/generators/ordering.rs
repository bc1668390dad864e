//! Numbering grains along a space-filling curve.
//!
//! The solver visits contacts in the order of their bodies' indices and reads both bodies'
//! velocities at each update. Generators such as the sequential deposition produce grains in
//! placement order, scattered over the whole width, so that two touching grains can be
//! millions of indices apart: every update then misses the cache once the velocity arrays
//! outgrow it. Numbered along a Z-order (Morton) curve of cells about one grain diameter wide,
//! touching grains get nearby indices.

use dem::math::Vector;

/// Bits per coordinate of the Morton key (cells per side up to 2³²).
const BITS: u32 = 32;

/// The permutation `p` that sorts `centres` along a Z-order curve of square cells of side
/// `cell` (m): `centres[p[0]], centres[p[1]], …` are in curve order. Ties (same cell) keep the
/// input order, so the result is deterministic.
pub fn spatial_order(centres: &[Vector], cell: f64) -> Vec<usize> {
    if centres.is_empty() {
        return Vec::new();
    }
    let (mut x0, mut y0) = (f64::INFINITY, f64::INFINITY);
    for c in centres {
        x0 = x0.min(c.x);
        y0 = y0.min(c.y);
    }
    let cell = if cell.is_finite() && cell > 0.0 {
        cell
    } else {
        1.0
    };
    let max = ((1u64 << BITS) - 1) as f64;
    let key = |c: &Vector| {
        let ix = ((c.x - x0) / cell).floor().clamp(0.0, max) as u64;
        let iy = ((c.y - y0) / cell).floor().clamp(0.0, max) as u64;
        interleave(ix) | (interleave(iy) << 1)
    };
    let keys: Vec<u64> = centres.iter().map(key).collect();
    let mut order: Vec<usize> = (0..centres.len()).collect();
    order.sort_by_key(|&i| (keys[i], i));
    order
}

/// Spread the low 32 bits of `v` to the even bits of a `u64`.
fn interleave(mut v: u64) -> u64 {
    v &= 0xFFFF_FFFF;
    v = (v | (v << 16)) & 0x0000_FFFF_0000_FFFF;
    v = (v | (v << 8)) & 0x00FF_00FF_00FF_00FF;
    v = (v | (v << 4)) & 0x0F0F_0F0F_0F0F_0F0F;
    v = (v | (v << 2)) & 0x3333_3333_3333_3333;
    v = (v | (v << 1)) & 0x5555_5555_5555_5555;
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interleave_spreads_bits() {
        assert_eq!(interleave(0b1011), 0b1000101);
        assert_eq!(interleave(u32::MAX as u64), 0x5555_5555_5555_5555);
    }

    /// A 4 × 4 grid of unit cells given in reverse order comes back in Z order: the first four
    /// are the lower-left 2 × 2 block, in the order (0,0), (1,0), (0,1), (1,1).
    #[test]
    fn a_grid_comes_back_in_z_order() {
        let mut pts = Vec::new();
        for y in 0..4 {
            for x in 0..4 {
                pts.push(Vector::new(x as f64 + 0.5, y as f64 + 0.5));
            }
        }
        pts.reverse();
        let order = spatial_order(&pts, 1.0);
        let first: Vec<(f64, f64)> = order[..4]
            .iter()
            .map(|&i| (pts[i].x - 0.5, pts[i].y - 0.5))
            .collect();
        assert_eq!(first, vec![(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]);
        let mut sorted = order.clone();
        sorted.sort();
        assert_eq!(sorted, (0..16).collect::<Vec<_>>());
    }
}
