//! A first guess of the contact impulses of a packing at rest: each grain's weight, plus what
//! the grains above pass on to it, carried down to its supports.
//!
//! Gauss–Seidel moves a load change through a network about one contact per sweep, so a deep
//! packing started from zero impulses (a freshly generated deposit) needs of the order of `H²`
//! sweeps per step, `H` its depth in grains, before its weight reaches the floor; meanwhile the
//! unbalanced grains creep into each other. Starting the solve from this estimate leaves it only
//! local corrections.
//!
//! Grains are visited from the top down (along gravity `ĝ`). Grain `i` carries the vertical
//! impulse `P_i = m_i |g| h + Σ` (what its upper neighbours pass on). Its supports are the
//! contacts `k` whose unit normal `d_k`, pointing from the neighbour towards `i`, rises:
//! `c_k = −d_k·ĝ ≥ C_MIN`. They get the normal impulses of the least-norm split of the vertical
//! balance alone,
//!
//! ```text
//! r_n,k = min(P_i c_k / Σ_j c_j², P_MAX · P_i),      Σ_k r_n,k c_k = P_i (unless capped),
//! ```
//!
//! and a supporting grain receives `r_n,k c_k`. Tangential impulses stay zero and horizontal
//! balance is left to the solver: it is local. Grains without a support keep their load (the
//! solver finds where it goes); walls absorb what reaches them.
//!
//! Carrying the full load *vector* instead (each grain's load split exactly on the pair of
//! support normals whose cone holds it, horizontal parts passed on too) was tried and fails:
//! grains wedged between two near-horizontal contacts get large opposing impulses, their
//! neighbours receive them unbalanced, and a 10⁴-grain column overlapped by several radii in its
//! first step. On the benchmark columns ([`C_MIN`], [`P_MAX`] chosen by trying 0.2–0.85 and
//! 1–2) the primed start halves to quarters the error and approach speed of the first steps.

use crate::math::{Spatial, Vector};

use crate::body::Body;
use crate::contact::ContactRow;

/// Smallest rise `c = −d·ĝ` of a support normal (a contact within about 78° of vertical).
pub const C_MIN: f64 = 0.2;
/// Largest normal impulse given to one support, in units of the load of the grain it supports.
pub const P_MAX: f64 = 2.0;

/// Overwrite the normal impulses of `rows` (N·s) with the weight-carrying estimate (tangential
/// impulses set to zero) for time step `h` (s) and gravity `gravity` (m/s²). `inv` holds the
/// bodies' inverse masses: a body carries and passes on load if gravity acts on it, its mass is
/// finite and it is free to translate along x or y (grains and clumps; walls only receive).
///
/// Bodies are visited by the height of their centre along `−ĝ`, which orders supports below the
/// grains they carry for disks. For clumps, or for a support across a periodic boundary, a
/// support can come first; its load is then not passed on (lost, never counted twice), which
/// only weakens the estimate.
pub fn weight_impulses(
    rows: &mut [ContactRow],
    bodies: &[Body],
    inv: &[Spatial],
    gravity: Vector,
    h: f64,
) {
    for c in rows.iter_mut() {
        c.r = [0.0, 0.0];
    }
    let g = gravity.norm();
    if g == 0.0 || rows.is_empty() {
        return;
    }
    let down = gravity / g;
    let n = bodies.len();
    // Body → contacts adjacency (CSR).
    let mut offsets = vec![0u32; n + 1];
    for c in rows.iter() {
        offsets[c.a as usize + 1] += 1;
        offsets[c.b as usize + 1] += 1;
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut adj = vec![0u32; 2 * rows.len()];
    for (k, c) in rows.iter().enumerate() {
        for body in [c.a as usize, c.b as usize] {
            adj[fill[body] as usize] = k as u32;
            fill[body] += 1;
        }
    }
    let carries = |i: usize| {
        let b = &bodies[i];
        b.gravity && (inv[i][0] != 0.0 || inv[i][1] != 0.0) && b.mass.is_finite()
    };
    let mut order: Vec<u32> = (0..n as u32).filter(|&i| carries(i as usize)).collect();
    let height = |i: u32| -bodies[i as usize].position.dot(&down);
    order.sort_by(|&x, &y| height(y).total_cmp(&height(x)).then(x.cmp(&y)));
    let mut load: Vec<f64> = bodies
        .iter()
        .map(|b| {
            if b.mass.is_finite() {
                b.mass * g * h
            } else {
                0.0
            }
        })
        .collect();
    for &i in &order {
        let i = i as usize;
        let p = load[i];
        let contacts = &adj[offsets[i] as usize..offsets[i + 1] as usize];
        // Rise of each contact's normal as seen from grain i.
        let rise = |c: &ContactRow| {
            let d = Vector::new(c.n[0], c.n[1]) * if c.b as usize == i { 1.0 } else { -1.0 };
            -d.dot(&down)
        };
        let sum: f64 = contacts
            .iter()
            .map(|&k| rise(&rows[k as usize]))
            .filter(|&c| c >= C_MIN)
            .map(|c| c * c)
            .sum();
        if sum == 0.0 {
            continue;
        }
        for &k in contacts {
            let c = rise(&rows[k as usize]);
            if c < C_MIN {
                continue;
            }
            let rn = (p * c / sum).min(P_MAX * p);
            let row = &mut rows[k as usize];
            row.r[0] = rn;
            let other = if row.b as usize == i { row.a } else { row.b } as usize;
            if carries(other) {
                load[other] += rn * c;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::Body;
    use crate::contact::ContactRow;

    fn grain(x: f64, y: f64, m: f64) -> Body {
        let mut b = Body::disk(Vector::new(x, y), 1.0, 1.0, 1.0);
        b.mass = m;
        b
    }

    /// A grain resting on two grains at ±30° from the vertical and touching a side wall: the
    /// side contact (horizontal normal, rise 0 < C_MIN) gets nothing, the two supports
    /// `P / (2 cos 30°)` each, which balances the grain exactly (statics of a symmetric wedge).
    #[test]
    fn a_grain_on_two_slanted_supports_is_balanced() {
        let wall = Body::wall("side", Vector::zeros(), Vector::zeros());
        let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
        let mut bodies = vec![
            wall,
            grain(-s, -c, 1.0),
            grain(s, -c, 1.0),
            grain(0.0, 0.0, 2.0),
        ];
        // the two supports are held by the wall of the test (immobile)
        for b in &mut bodies[1..3] {
            b.dofs = [crate::Dof::Imposed; 3];
        }
        let inv: Vec<Spatial> = bodies.iter().map(Body::inverse_mass).collect();
        let mk = |a: u32, b: u32, n: [f64; 2]| ContactRow {
            a,
            b,
            n,
            mu: 0.5,
            ..Default::default()
        };
        // normals from a (support) to b (the top grain)
        let mut rows = vec![mk(1, 3, [s, c]), mk(2, 3, [-s, c]), mk(0, 3, [1.0, 0.0])];
        let (g, h) = (9.81, 1e-3);
        weight_impulses(&mut rows, &bodies, &inv, Vector::new(0.0, -g), h);
        let p = 2.0 * g * h;
        for row in &rows[..2] {
            assert!((row.r[0] - p / (2.0 * c)).abs() <= 1e-12 * p, "{:?}", row.r);
        }
        assert_eq!(rows[2].r, [0.0, 0.0]);
        let fx: f64 = rows.iter().map(|r| r.r[0] * r.n[0]).sum();
        let fy: f64 = rows.iter().map(|r| r.r[0] * r.n[1]).sum();
        assert!(fx.abs() <= 1e-12 * p && (fy - p).abs() <= 1e-12 * p);
    }

    /// A vertical stack of three grains on a fixed floor: the floor contact carries the weight
    /// of all three, the middle one two, the top one one (exact for a column of single grains).
    #[test]
    fn a_stack_passes_its_whole_weight_to_the_floor() {
        let floor = Body::wall("floor", Vector::zeros(), Vector::zeros());
        let bodies = vec![
            floor,
            grain(0.0, 1.0, 1.0),
            grain(0.0, 3.0, 2.0),
            grain(0.0, 5.0, 3.0),
        ];
        let inv: Vec<Spatial> = bodies.iter().map(Body::inverse_mass).collect();
        let row = |a: u32, b: u32| ContactRow {
            a,
            b,
            n: [0.0, 1.0],
            mu: 0.5,
            ..Default::default()
        };
        let mut rows = vec![row(0, 1), row(1, 2), row(2, 3)];
        let (g, h) = (9.81, 1e-3);
        weight_impulses(&mut rows, &bodies, &inv, Vector::new(0.0, -g), h);
        let expect = [6.0 * g * h, 5.0 * g * h, 3.0 * g * h];
        for (c, e) in rows.iter().zip(expect) {
            assert!((c.r[0] - e).abs() <= 1e-12 * e, "{} vs {e}", c.r[0]);
            assert_eq!(c.r[1], 0.0);
        }
    }
}
