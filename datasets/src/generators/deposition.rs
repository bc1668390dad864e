//! Sequential geometric deposition ("drop and roll", Visscher & Bolsterli 1972): grains are
//! dropped one by one at a random abscissa into a box of width `W` with a floor at `y = 0`;
//! each falls vertically until it touches a grain, then rolls down over it (keeping contact)
//! until it touches a second support; it stops when its two supports straddle its centre
//! (or one is the floor, or a side wall opposite the first support), otherwise it keeps rolling
//! over the new support or falls again when it rolls off. The result is a dense, gravitationally
//! stable packing (φ ≈ 0.8 for polydisperse disks) in O(N) neighbour queries, which the engine
//! then only has to relax instead of pouring a loose lattice.
//!
//! Contact distances include a gap `gap` (m) so that no two grains overlap after rounding.

use dem::math::Vector;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::error::{DatasetError, Result};

/// Rolls allowed per grain before it is left where it is (a non-overlapping position).
const MAX_MOVES: usize = 10_000;

/// What a deposited grain rests on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Support {
    /// The floor `y = 0`.
    Floor,
    /// The wall `x = 0`.
    LeftWall,
    /// The wall `x = W`.
    RightWall,
    /// Another grain (its index; always an earlier one).
    Grain(usize),
}

/// A deposited packing: centres (m) and, for each grain, its one or two supports.
#[derive(Debug, Clone, PartialEq)]
pub struct Deposition {
    /// Centres (m), in the order of the radii.
    pub centres: Vec<Vector>,
    /// Supports of each grain: the floor alone, or the grain it rolled over and the one (or the
    /// wall) that stopped it. A grain left after `MAX_MOVES` rolls keeps its last pivot only.
    pub supports: Vec<[Option<Support>; 2]>,
}

/// Grid of placed grains (cells of side `cell`, rows growing upwards).
struct Grid {
    cell: f64,
    cols: usize,
    cells: Vec<Vec<u32>>,
}

impl Grid {
    fn col(&self, x: f64) -> usize {
        ((x / self.cell).floor().max(0.0) as usize).min(self.cols - 1)
    }
    fn row(&self, y: f64) -> usize {
        (y / self.cell).floor().max(0.0) as usize
    }
    fn insert(&mut self, i: usize, c: Vector) {
        let row = self.row(c.y);
        if (row + 1) * self.cols > self.cells.len() {
            self.cells.resize_with((row + 1) * self.cols, Vec::new);
        }
        let idx = row * self.cols + self.col(c.x);
        self.cells[idx].push(i as u32);
    }
    /// Grains whose centre lies in the cells overlapping `[x0, x1] × [y0, y1]`.
    fn query(&self, x0: f64, x1: f64, y0: f64, y1: f64, out: &mut Vec<u32>) {
        out.clear();
        let rows = self.cells.len() / self.cols;
        if rows == 0 {
            return;
        }
        let (c0, c1) = (self.col(x0), self.col(x1));
        let r0 = self.row(y0);
        let r1 = self.row(y1.max(0.0)).min(rows - 1);
        if r0 > r1 {
            return;
        }
        for r in r0..=r1 {
            for c in c0..=c1 {
                out.extend_from_slice(&self.cells[r * self.cols + c]);
            }
        }
    }
}

/// Centres (m) of grains of the given radii (in order) deposited into `[0, width]` above the
/// floor `y = 0` (see the module documentation). Fails when a grain is wider than the box.
pub fn deposit(rng: &mut ChaCha8Rng, radii: &[f64], width: f64, gap: f64) -> Result<Deposition> {
    let r_max = radii.iter().cloned().fold(0.0, f64::max);
    if width.is_nan() || width <= 2.0 * r_max + 2.0 * gap {
        return Err(DatasetError::Generator(format!(
            "deposition: box width {width} m cannot hold a grain of radius {r_max} m"
        )));
    }
    let mut grid = Grid {
        cell: 2.0 * r_max + gap,
        cols: ((width / (2.0 * r_max + gap)).ceil() as usize).max(1),
        cells: Vec::new(),
    };
    let mut centres: Vec<Vector> = Vec::with_capacity(radii.len());
    let mut supports = Vec::with_capacity(radii.len());
    let mut near = Vec::new();
    let mut top = 0.0f64; // highest grain top so far
    for (i, &r) in radii.iter().enumerate() {
        let (xl, xr) = (r + gap, width - r - gap);
        let mut c = Vector::new(rng.random_range(xl..=xr), top + 2.0 * r + 2.0 * gap);
        let mut moves = 0;
        let rests: [Option<Support>; 2];
        'grain: loop {
            // Fall vertically from c.
            let (y_land, support) = fall(&grid, &centres, radii, c, r, gap, &mut near);
            c.y = y_land;
            let Support::Grain(mut pivot) = support else {
                rests = [Some(Support::Floor), None];
                break 'grain; // on the floor
            };
            // Roll over the pivot (direction: away from it), until stable or rolled off.
            loop {
                moves += 1;
                if moves > MAX_MOVES {
                    rests = [Some(Support::Grain(pivot)), None];
                    break 'grain;
                }
                let p = centres[pivot];
                let d = r + radii[pivot] + gap;
                let right = if c.x != p.x {
                    c.x > p.x
                } else {
                    rng.random_bool(0.5)
                };
                let phi0 = (c.y - p.y).atan2(c.x - p.x);
                match roll(
                    &grid, &centres, radii, p, pivot, d, phi0, right, r, gap, xl, xr, &mut near,
                ) {
                    Some((phi, s)) => {
                        c = p + d * Vector::new(phi.cos(), phi.sin());
                        let stable = match s {
                            Support::Floor => true,
                            Support::LeftWall => !right,
                            Support::RightWall => right,
                            Support::Grain(k) => (centres[k].x > c.x) == right,
                        };
                        if stable {
                            rests = [Some(Support::Grain(pivot)), Some(s)];
                            break 'grain;
                        }
                        match s {
                            Support::Grain(k) => pivot = k,
                            // a wall on the pivot's side: cannot happen while rolling away
                            _ => {
                                rests = [Some(Support::Grain(pivot)), Some(s)];
                                break 'grain;
                            }
                        }
                    }
                    None => {
                        // rolled off: centre level with the pivot, falls again
                        let end = if right { 0.0 } else { std::f64::consts::PI };
                        c = p + d * Vector::new(end.cos(), end.sin());
                        c.x = c.x.clamp(xl, xr);
                        c.y -= 1e-12;
                        continue 'grain;
                    }
                }
            }
        }
        top = top.max(c.y + r);
        grid.insert(i, c);
        centres.push(c);
        supports.push(rests);
    }
    Ok(Deposition { centres, supports })
}

/// Highest landing height of a grain of radius `r` falling from `c`, and its support.
fn fall(
    grid: &Grid,
    centres: &[Vector],
    radii: &[f64],
    c: Vector,
    r: f64,
    gap: f64,
    near: &mut Vec<u32>,
) -> (f64, Support) {
    let reach = r + grid.cell;
    let (mut best, mut support) = (r + gap, Support::Floor);
    grid.query(c.x - reach, c.x + reach, 0.0, c.y, near);
    for &j in near.iter() {
        let j = j as usize;
        let d = r + radii[j] + gap;
        let dx = c.x - centres[j].x;
        if dx.abs() < d {
            let y = centres[j].y + (d * d - dx * dx).sqrt();
            if y <= c.y + 1e-12 && y > best {
                best = y;
                support = Support::Grain(j);
            }
        }
    }
    (best, support)
}

/// Rolls a grain of radius `r` over the grain at `p` (contact distance `d`) from angle `phi0`
/// towards angle 0 (`right`) or π; returns the angle of the first new contact and what it is,
/// or `None` when the grain reaches the horizontal through `p` without one.
#[allow(clippy::too_many_arguments)]
fn roll(
    grid: &Grid,
    centres: &[Vector],
    radii: &[f64],
    p: Vector,
    pivot: usize,
    d: f64,
    phi0: f64,
    right: bool,
    r: f64,
    gap: f64,
    xl: f64,
    xr: f64,
    near: &mut Vec<u32>,
) -> Option<(f64, Support)> {
    // Progress along the path: s = phi0 − phi (right) or phi − phi0 (left), s ∈ (0, s_end].
    let s_end = if right {
        phi0
    } else {
        std::f64::consts::PI - phi0
    };
    if s_end <= 0.0 {
        return None;
    }
    let to_s = |phi: f64| if right { phi0 - phi } else { phi - phi0 };
    let eps = 1e-10;
    let start = p + d * Vector::new(phi0.cos(), phi0.sin());
    let ahead = |s: Support| match s {
        Support::Grain(k) => (centres[k].x > start.x) == right,
        Support::LeftWall => !right,
        Support::RightWall => right,
        Support::Floor => false,
    };
    let mut best: Option<(f64, Support)> = None;
    let consider = |phi: f64, s: Support, best: &mut Option<(f64, Support)>| {
        let phi = if phi < -std::f64::consts::FRAC_PI_2 {
            phi + 2.0 * std::f64::consts::PI
        } else {
            phi
        };
        let sv = to_s(phi);
        // A support touched already at the start (s ≈ 0) counts when it lies on the rolling
        // side: the grain landed on the pivot and on it at once (equal disks in level rows),
        // and rolling on would take it through that support.
        let touching_ahead = sv > -eps && ahead(s);
        if (sv > eps || touching_ahead)
            && sv <= s_end + eps
            && best.is_none_or(|(b, _)| sv < to_s(b))
        {
            *best = Some((phi, s));
        }
    };
    // other grains
    let reach = d + r + grid.cell;
    grid.query(p.x - reach, p.x + reach, p.y - reach, p.y + reach, near);
    for &k in near.iter() {
        let k = k as usize;
        if k == pivot {
            continue;
        }
        let e = r + radii[k] + gap;
        let v = centres[k] - p;
        let l = v.norm();
        if l >= d + e || l <= (d - e).abs() || l == 0.0 {
            continue;
        }
        // intersection of |c − p| = d and |c − c_k| = e
        let a = (d * d - e * e + l * l) / (2.0 * l);
        let h = (d * d - a * a).max(0.0).sqrt();
        let base = v.y.atan2(v.x);
        let off = (h).atan2(a);
        for phi in [base + off, base - off] {
            let phi = wrap(phi);
            consider(phi, Support::Grain(k), &mut best);
        }
    }
    // walls and floor
    for (x, s) in [(xl, Support::LeftWall), (xr, Support::RightWall)] {
        let cx = (x - p.x) / d;
        if cx.abs() <= 1.0 {
            let a = cx.acos();
            consider(a, s, &mut best);
            consider(-a, s, &mut best);
        }
    }
    let sy = (r + gap - p.y) / d;
    if sy.abs() <= 1.0 {
        let a = sy.asin();
        consider(a, Support::Floor, &mut best);
        consider(std::f64::consts::PI - a, Support::Floor, &mut best);
    }
    best
}

/// Angle in (−π, π].
fn wrap(phi: f64) -> f64 {
    let tau = 2.0 * std::f64::consts::PI;
    let mut p = phi % tau;
    if p <= -std::f64::consts::PI {
        p += tau;
    } else if p > std::f64::consts::PI {
        p -= tau;
    }
    p
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn check(centres: &[Vector], radii: &[f64], width: f64, gap: f64) -> f64 {
        let mut area = 0.0;
        let mut height = 0.0f64;
        for (i, (c, r)) in centres.iter().zip(radii).enumerate() {
            assert!(
                c.x - r >= -1e-12 && c.x + r <= width + 1e-12,
                "grain {i} outside"
            );
            assert!(c.y - r >= -1e-12, "grain {i} below the floor");
            for (j, (cj, rj)) in centres.iter().zip(radii).enumerate().take(i) {
                let dist = (c - cj).norm();
                assert!(
                    dist >= r + rj + 0.5 * gap,
                    "grains {j} and {i} overlap: {dist} < {}",
                    r + rj
                );
            }
            area += std::f64::consts::PI * r * r;
            height = height.max(c.y + r);
        }
        area / (width * height)
    }

    #[test]
    fn equal_disks_in_a_box_width_of_one_disk_stack_vertically() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let radii = vec![1e-3; 5];
        let c = deposit(&mut rng, &radii, 2.5e-3, 1e-9).unwrap().centres;
        for (k, ck) in c.iter().enumerate() {
            // box too narrow for two side by side: a vertical stack touching each other
            if k > 0 {
                let dist = (ck - c[k - 1]).norm();
                assert!((dist - 2e-3).abs() < 1e-8, "{dist}");
            }
        }
        assert!((c[0].y - 1e-3).abs() < 1e-8);
    }

    #[test]
    fn polydisperse_deposit_is_dense_without_overlap_and_supported() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let radii: Vec<f64> = (0..800).map(|_| rng.random_range(1e-3..2e-3)).collect();
        let (width, gap) = (0.06, 1e-8);
        let dep = deposit(&mut rng, &radii, width, gap).unwrap();
        let c = dep.centres.clone();
        let phi = check(&c, &radii, width, gap);
        // dense random deposit (the top row's roughness counts as void): 0.7–0.85
        assert!(phi > 0.7 && phi < 0.86, "solid fraction {phi}");
        // every grain rests on the floor, or touches grains placed before it (or a wall) on
        // both sides of its centre, one of them below it: gravitationally supported
        for (i, (ci, ri)) in c.iter().zip(&radii).enumerate() {
            if ci.y - ri < 1e-6 {
                continue;
            }
            let touching: Vec<Vector> = c[..i]
                .iter()
                .zip(&radii)
                .filter(|(cj, rj)| ((*ci - **cj).norm() - (ri + **rj)).abs() < 1e-6)
                .map(|(cj, _)| cj - ci)
                .collect();
            let left = touching.iter().any(|v| v.x <= 0.0) || ci.x - ri < 1e-6;
            let right = touching.iter().any(|v| v.x >= 0.0) || ci.x + ri > width - 1e-6;
            let below = touching.iter().any(|v| v.y < 0.0);
            assert!(
                left && right && below,
                "grain {i} unsupported: {touching:?}"
            );
        }
        // the recorded supports touch their grain (contact distance r_i + r_j + gap)
        for (i, sup) in dep.supports.iter().enumerate() {
            assert!(sup[0].is_some(), "grain {i} without support");
            for s in sup.iter().flatten() {
                let d = match *s {
                    Support::Grain(j) => (c[i] - c[j]).norm() - radii[i] - radii[j],
                    Support::Floor => c[i].y - radii[i],
                    Support::LeftWall => c[i].x - radii[i],
                    Support::RightWall => width - c[i].x - radii[i],
                };
                assert!((d - gap).abs() < 1e-9, "grain {i} support {s:?} at {d}");
            }
        }
    }
}
