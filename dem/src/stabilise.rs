//! Post-stabilisation of positions: a frictionless projection that removes the overlaps a step
//! leaves, without changing any velocity (split impulses).
//!
//! The Moreau–Jean step works on velocities: a closed contact only gets `u_n⁺ ≥ 0`, so an overlap
//! left by an inexact solve, a fast impact or an imposed wall is never undone by the step itself,
//! and pushing it apart with a velocity would inject kinetic energy. Instead, after the θ-method
//! update `q⁺ = q⁻ + h[(1 − θ) v⁻ + θ v⁺]`, the positions are projected back to within a slop
//! `s_α` of the admissible set, at position level only.
//!
//! For every contact α of the step, with the step's geometry (gap `g⁻_α` at `q⁻`, normal and
//! lever arms of its [`ContactRow`]), the gap after the step is predicted to first order,
//!
//! ```text
//! g⁺_α = g⁻_α + H_n,α Δq,     Δq = h[(1 − θ) v⁻ + θ v⁺]      (Δq: the θ-method displacement)
//! ```
//!
//! and normal pseudo-impulses `P ≥ 0` (kg·m; frictionless: tangential rows are left out) solve the
//! linear complementarity problem
//!
//! ```text
//! c = g⁺ + W_nn P ≥ −s,   P ≥ 0,   Pᵀ(c + s) = 0,        W_nn = H_n M⁻¹ H_nᵀ
//! q  ←  q + M⁻¹ H_nᵀ P                                    (translations and rotations)
//! ```
//!
//! by projected Gauss–Seidel on the normal rows, with the displacement kept current as the solver
//! keeps the velocities current ([`ContactRow::apply`] with `(ΔP, 0)`):
//! `P_α ← max(0, P_α − (c_α + s_α)/W_αα)`. Velocities are not touched, so kinetic energy is not
//! changed; imposed degrees of freedom (inverse mass 0) do not move. The slop `s_α` is [`SLOP`]
//! times the smaller radius of the pair, the gap below which a contact already counts as closed
//! ([`crate::contact::CLOSED_GAP`], stored per contact as `ContactGeometry::closed_gap`): an
//! overlap up to it is tolerated, so a resting contact is not pushed apart and pulled back every
//! step. A projection runs only when some predicted overlap exceeds its slop by more than
//! [`TOLERANCE`] of it (`g⁺_α < −(1 + TOLERANCE) s_α`): a contact left at the slop by an earlier
//! correction does not trigger one every step on rounding-level excursions. The sweeps stop when
//! no pseudo-impulse moves its gap by more than [`TOLERANCE`] of its slop, or after
//! [`MAX_SWEEPS`]; what is left is corrected by the next step. The contacts are
//! swept in their stored order (sorted by collider pair) on one thread, so the result does not
//! depend on the thread count.
//!
//! Energy: the projection does no kinetic work, but it moves bodies under gravity and applied loads
//! `f`; their work over the projection, `W_corr = Σ f·Δq_corr` over free degrees of freedom
//! ([`CorrectionReport::load_work`]), is the opposite of the potential-energy change it causes. It
//! is reported separately; the energy balance of the step ([`crate::world`],
//! `grainlaw_core::scenarios::phases`) counts the work of the loads along the velocities and is
//! left unchanged.
//!
//! References: M. B. Cline, D. K. Pai, *Post-stabilization for rigid body simulation with contact
//! and constraints*, IEEE ICRA 2003 (the projection `Δq = M⁻¹ Hᵀ P` after the velocity step);
//! V. Acary, *Projected event-capturing time-stepping schemes for nonsmooth mechanical systems
//! with unilateral contact and Coulomb's friction*, CMAME 256 (2013) (the position projection of
//! the combined-projection Moreau–Jean scheme, Siconos' `MoreauJeanCombinedProjectionOSI`);
//! E. Catto, Box2D (split impulses / position correction with a linear slop).

use serde::{Deserialize, Serialize};

use crate::contact::{ContactGeometry, ContactRow};
use crate::math::Spatial;

/// Slop of the projection, as a fraction of the smaller radius of the pair (1): overlaps up to
/// `SLOP · min(R_a, R_b)` are left alone. Equal to [`crate::contact::CLOSED_GAP`] (the contact's
/// `closed_gap` is the slop), so a gap the step treats as closed is never pushed open.
pub const SLOP: f64 = crate::contact::CLOSED_GAP;

/// Largest number of projected Gauss–Seidel sweeps of one step's projection.
pub const MAX_SWEEPS: usize = 100;

/// Tolerance of the projection, as a fraction of each contact's slop (1): a projection runs when
/// a predicted overlap exceeds `(1 + TOLERANCE) s`, and its sweeps stop when no pseudo-impulse
/// changes its gap by more than `TOLERANCE · s` in a sweep, `W_αα |ΔP_α| ≤ TOLERANCE · s_α`.
pub const TOLERANCE: f64 = 0.1;

/// What the position projection of one step did.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct CorrectionReport {
    /// Contacts whose predicted overlap after the step exceeded their slop by more than
    /// [`TOLERANCE`] of it (before projecting); the projection runs when there is one.
    pub violated_contacts: usize,
    /// Contacts with a positive pseudo-impulse at the end.
    pub corrected_contacts: usize,
    /// Projected Gauss–Seidel sweeps done (0 when nothing exceeded the slop).
    pub sweeps: usize,
    /// Whether the sweeps stopped at [`MAX_SWEEPS`] before meeting [`TOLERANCE`] (the overlaps
    /// left are in `overlap_after`, and the next step corrects them further).
    pub capped: bool,
    /// Largest predicted overlap `max(−g⁺, 0)` before the projection (m).
    pub overlap_before: f64,
    /// Largest predicted overlap `max(−c, 0)` after the projection (m).
    pub overlap_after: f64,
    /// Largest displacement of a body centre by the projection (m).
    pub max_displacement: f64,
    /// Work of gravity and the applied loads over the projection's displacements,
    /// `Σ f·Δq_corr` over free degrees of freedom (J); the potential energy changes by its
    /// opposite. Filled in by the world.
    pub load_work: f64,
}

/// Work buffers of the projection (no state: every step starts from `P = 0`).
#[derive(Debug, Clone, Default)]
pub struct Projection {
    gap: Vec<f64>,
    p: Vec<f64>,
    dq: Vec<Spatial>,
}

/// Normal part of `H Δq` for one contact: `n·(Δx_b − Δx_a) + (ρ_b×n) Δθ_b − (ρ_a×n) Δθ_a`.
#[inline(always)]
fn normal_motion(row: &ContactRow, da: &Spatial, db: &Spatial) -> f64 {
    let [nx, ny] = row.n;
    nx * (db[0] - da[0]) + ny * (db[1] - da[1]) + row.k[2] * db[2] - row.k[0] * da[2]
}

impl Projection {
    /// The position correction `Δq_corr = M⁻¹ H_nᵀ P` of each body (`[Δx, Δy, Δθ]`) found by the
    /// last [`Projection::project`].
    pub fn correction(&self) -> &[Spatial] {
        &self.dq
    }

    /// Solves the projection of one step (module documentation): `rows` and `geometry` are the
    /// step's contacts (geometry at `q⁻`), `displacement` the θ-method displacement of each body
    /// during the step, `inv` the inverse masses. The correction is left in
    /// [`Projection::correction`] (all zeros when no predicted overlap exceeds its slop).
    pub fn project(
        &mut self,
        rows: &[ContactRow],
        geometry: &[ContactGeometry],
        displacement: &[Spatial],
        inv: &[Spatial],
    ) -> CorrectionReport {
        let mut report = CorrectionReport::default();
        self.dq.clear();
        self.dq.resize(inv.len(), [0.0; 3]);
        self.gap.clear();
        self.gap.extend(rows.iter().zip(geometry).map(|(row, geo)| {
            geo.gap
                + normal_motion(
                    row,
                    &displacement[row.a as usize],
                    &displacement[row.b as usize],
                )
        }));
        for ((row, geo), &g) in rows.iter().zip(geometry).zip(&self.gap) {
            if g < -(1.0 + TOLERANCE) * geo.closed_gap && row.w.nn > 0.0 {
                report.violated_contacts += 1;
                report.overlap_before = report.overlap_before.max(-g);
            }
        }
        if report.violated_contacts == 0 {
            return report;
        }
        self.p.clear();
        self.p.resize(rows.len(), 0.0);
        report.capped = true;
        while report.sweeps < MAX_SWEEPS {
            report.sweeps += 1;
            let mut settled = true;
            for (alpha, (row, geo)) in rows.iter().zip(geometry).enumerate() {
                let w = row.w.nn;
                if w <= 0.0 {
                    continue;
                }
                let (a, b) = (row.a as usize, row.b as usize);
                let s = geo.closed_gap;
                let c = self.gap[alpha] + normal_motion(row, &self.dq[a], &self.dq[b]);
                let p = self.p[alpha];
                let p_new = (p - (c + s) / w).max(0.0);
                let dp = p_new - p;
                if dp == 0.0 {
                    continue;
                }
                self.p[alpha] = p_new;
                let (mut qa, mut qb) = (self.dq[a], self.dq[b]);
                row.apply([dp, 0.0], &mut qa, &inv[a], &mut qb, &inv[b]);
                self.dq[a] = qa;
                self.dq[b] = qb;
                if (w * dp).abs() > TOLERANCE * s {
                    settled = false;
                }
            }
            if settled {
                report.capped = false;
                break;
            }
        }
        for (alpha, row) in rows.iter().enumerate() {
            if self.p[alpha] > 0.0 {
                report.corrected_contacts += 1;
            }
            if row.w.nn > 0.0 {
                let (a, b) = (row.a as usize, row.b as usize);
                let c = self.gap[alpha] + normal_motion(row, &self.dq[a], &self.dq[b]);
                report.overlap_after = report.overlap_after.max(-c);
            }
        }
        // The largest squared norm, then one root (`hypot` per body was a library call).
        report.max_displacement = self
            .dq
            .iter()
            .map(|d| d[0] * d[0] + d[1] * d[1])
            .fold(0.0, f64::max)
            .sqrt();
        report
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::ContactRow;

    /// Two unit-mass points on the x axis, overlapping by 1e-2 with slop 1e-4: one sweep moves
    /// each by half the excess, the second sees nothing left to do.
    #[test]
    fn one_pair_is_projected_to_its_slop() {
        let inv = [[1.0, 1.0, 0.0]; 2];
        let n = [1.0, 0.0];
        let k = [0.0; 4];
        let row = ContactRow {
            a: 0,
            b: 1,
            n,
            k,
            w: ContactRow::delassus(n, k, &inv[0], &inv[1]),
            ..Default::default()
        };
        let geo = ContactGeometry {
            gap: -1e-2,
            closed_gap: 1e-4,
            ..Default::default()
        };
        let mut proj = Projection::default();
        let rep = proj.project(&[row], &[geo], &[[0.0; 3]; 2], &inv);
        assert!(!rep.capped && rep.sweeps == 2, "{rep:?}");
        assert_eq!(rep.violated_contacts, 1);
        assert_eq!(rep.corrected_contacts, 1);
        let dq = proj.correction();
        let excess = 1e-2 - 1e-4;
        assert!((dq[1][0] - excess / 2.0).abs() < 1e-15, "{dq:?}");
        assert!((dq[0][0] + excess / 2.0).abs() < 1e-15, "{dq:?}");
        assert!((rep.overlap_after - 1e-4).abs() < 1e-15, "{rep:?}");
    }
}
