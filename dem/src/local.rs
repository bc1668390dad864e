//! The local contact law: Signorini + Coulomb written as one bipotential (De Saxcé), and its
//! solution for a single contact.
//!
//! For one contact with local Delassus block `W` (2×2, symmetric positive definite) and local
//! free velocity `q` (everything the other contacts and the external forces contribute), the
//! unknowns are the impulse `r = (r_n, r_t)` and the relative velocity `u = W r + q`. The
//! bipotential
//!
//! ```text
//! b(−u, r) = ψ_{ℝ⁻}(−u_n) + ψ_{K_μ}(r) + μ r_n |u_t|,     K_μ = {(r_n, r_t) : |r_t| − μ r_n ≤ 0}
//! ```
//!
//! has as extremal pairs (b(−u, r) = −u·r) exactly the Signorini–Coulomb law, equivalently the
//! cone complementarity `K_μ ∋ r ⊥ ū ∈ K_μ*` with the modified velocity `ū = u + μ|u_t| n`.
//!
//! The paper solves it with the Uzawa predictor–corrector
//!
//! ```text
//! predictor:  τ = r − ρ [u_t t + (u_n + μ|u_t|) n]
//! corrector:  r = proj(τ, K_μ)
//! ```
//!
//! ([`predictor_corrector`], [`project_on_cone`]). With a scalar ρ the step over-shoots on disk
//! contacts, whose tangential Delassus entry is three times the normal one, and Gauss–Seidel
//! built on a single step does not converge. [`solve_local`] therefore returns the *fixed point*
//! of the predictor–corrector for the whole 2×2 block, in closed form: it tries the three
//! outcomes of the corrector (no contact, sticking, sliding either way) with `W` itself as the
//! metric and keeps the one that satisfies the law. [`solve_local_uzawa`] iterates the scalar
//! predictor–corrector with `ρ = 1/λ_max(W)` to the same point; the tests check that both agree.

use serde::{Deserialize, Serialize};

pub use crate::cone::ContactStatus;
use crate::cone::{self, FrictionCone};
use crate::math::Real;

/// Symmetric 2×2 local Delassus block `W = H M⁻¹ Hᵀ` of one contact, normal first.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Delassus2 {
    /// `W_nn` (1/kg for impulses in N·s and velocities in m/s).
    pub nn: f64,
    /// `W_nt = W_tn`.
    pub nt: f64,
    /// `W_tt`.
    pub tt: f64,
}

impl Delassus2 {
    /// `W r` for `r = (r_n, r_t)`.
    #[inline(always)]
    pub fn mul(&self, r: [f64; 2]) -> [f64; 2] {
        [
            self.nn * r[0] + self.nt * r[1],
            self.nt * r[0] + self.tt * r[1],
        ]
    }

    /// Largest eigenvalue of the block.
    pub fn lambda_max(&self) -> f64 {
        let m = 0.5 * (self.nn + self.tt);
        let d = (0.25 * (self.nn - self.tt).powi(2) + self.nt * self.nt).sqrt();
        m + d
    }

    /// Determinant `W_nn W_tt − W_nt²`.
    #[inline(always)]
    pub fn det(&self) -> f64 {
        self.nn * self.tt - self.nt * self.nt
    }
}

/// Euclidean projection of `tau = (τ_n, τ_t)` on the Coulomb cone `K_μ` (the corrector).
///
/// ```text
/// |τ_t| ≤ μ τ_n, τ_n ≥ 0 → τ                         (inside: sticking)
/// μ|τ_t| ≤ −τ_n          → 0                         (polar cone: no contact)
/// otherwise              → r_n = (τ_n + μ|τ_t|)/(1+μ²), r_t = μ r_n sign τ_t   (sliding)
/// ```
#[inline(always)]
pub fn project_on_cone(tau: [f64; 2], mu: f64) -> ([f64; 2], ContactStatus) {
    let [tn, tt] = tau;
    let at = tt.abs();
    // τ_n ≥ 0 matters for μ = 0, where |τ_t| ≤ μ τ_n alone would accept (τ_n < 0, 0).
    if tn >= 0.0 && at <= mu * tn {
        (tau, ContactStatus::Stick)
    } else if mu * at <= -tn {
        ([0.0, 0.0], ContactStatus::Open)
    } else {
        let rn = (tn + mu * at) / (1.0 + mu * mu);
        ([rn, mu * rn * tt.signum()], ContactStatus::Slide)
    }
}

/// The modified (De Saxcé) velocity `ū = (u_n + μ|u_t|, u_t)`.
#[inline(always)]
pub fn modified_velocity(u: [f64; 2], mu: f64) -> [f64; 2] {
    [u[0] + mu * u[1].abs(), u[1]]
}

/// One predictor–corrector step of the paper: `τ = r − ρ ū(u)`, `r ← proj(τ, K_μ)` (the
/// generic step, [`cone::predictor_corrector`], on the plane cone).
#[inline(always)]
pub fn predictor_corrector(
    r: [f64; 2],
    u: [f64; 2],
    rho: f64,
    mu: f64,
) -> ([f64; 2], ContactStatus) {
    cone::predictor_corrector(&Coulomb2 { mu }, r, u, rho)
}

/// Natural-map residual of one contact, `r − proj_K(r − ū)` with ρ = 1: the per-contact term of
/// the error measure of `docs/formats.md` §1.2 (Siconos' fc2d error).
///
/// The projection is computed without a branch (its outcomes computed, the valid one selected
/// on the bits): the outcome changes from contact to contact at random. The same values as
/// [`project_on_cone`] but for the sign of a zero (an open outcome may come out as `−0`), so
/// the squared residual is the same bit for bit; a NaN in `r` or `u` gives a NaN.
#[inline(always)]
pub fn natural_map_residual(r: [f64; 2], u: [f64; 2], mu: f64) -> [f64; 2] {
    let ub = modified_velocity(u, mu);
    let [tn, tt] = [r[0] - ub[0], r[1] - ub[1]];
    let at = tt.abs();
    let stick = tn >= 0.0 && at <= mu * tn;
    // Sliding, or open where this is ≤ 0 (`μ|τ_t| ≤ −τ_n` exactly when `τ_n + μ|τ_t| ≤ 0` in
    // floating point too); a NaN stays NaN.
    let rn = (tn + mu * at) / (1.0 + mu * mu);
    let rn = select(rn < 0.0, 0.0, rn);
    let pn = select(stick, tn, rn);
    let pt = select(stick, tt, mu * rn * tt.signum());
    [r[0] - pn, r[1] - pt]
}

/// `if c { a } else { b }` on the bits, so that it compiles to a select rather than a branch
/// (for passes over contacts whose outcome changes at random from one to the next).
#[inline(always)]
pub fn select(c: bool, a: f64, b: f64) -> f64 {
    let mask = u64::from(c).wrapping_neg();
    f64::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// Exact solution of the one-contact problem `u = W r + q`, `(u, r)` an extremal pair of the
/// bipotential, i.e. the fixed point of the predictor–corrector for the 2×2 block.
///
/// The three outcomes of the corrector are tried in order:
/// 1. no contact, `r = 0`, valid when `q_n ≥ 0`;
/// 2. sticking, `u = 0`, `r = −W⁻¹ q`, valid when `r ∈ K_μ`;
/// 3. sliding with `s = sign u_t`: `r_t = −s μ r_n`, `u_n = 0` gives
///    `r_n = −q_n / (W_nn − s μ W_nt)`, valid when `s u_t ≥ 0`.
///
/// If rounding leaves no candidate valid (only possible for nearly singular blocks with large
/// `W_nt`), the iterated predictor–corrector [`solve_local_uzawa`] is used. Cost: O(1).
#[inline(always)]
pub fn solve_local(w: &Delassus2, q: [f64; 2], mu: f64) -> ([f64; 2], ContactStatus) {
    let [qn, qt] = q;
    if qn >= 0.0 {
        return ([0.0, 0.0], ContactStatus::Open);
    }
    let det = w.det();
    if det > 0.0 {
        let rn = (-w.tt * qn + w.nt * qt) / det;
        let rt = (w.nt * qn - w.nn * qt) / det;
        if rn >= 0.0 && rt.abs() <= mu * rn {
            return ([rn, rt], ContactStatus::Stick);
        }
        // Sliding: the direction is the one the sticking impulse points away from first.
        let s_first = if rt > 0.0 { -1.0 } else { 1.0 };
        for s in [s_first, -s_first] {
            let den = w.nn - s * mu * w.nt;
            if den <= 0.0 {
                continue;
            }
            let rn = -qn / den;
            let rt = -s * mu * rn;
            let ut = w.nt * rn + w.tt * rt + qt;
            if s * ut >= -1e-14 * (qt.abs() + w.tt * rt.abs()) {
                return ([rn, rt], ContactStatus::Slide);
            }
        }
    }
    solve_local_uzawa(w, q, mu, [0.0, 0.0], 1e-15, 10_000)
}

/// The paper's predictor–corrector iterated on one contact with the scalar step
/// `ρ = 1/λ_max(W)` until the change of `r` is below `tol·‖r‖`, starting from `r0`.
///
/// Converges to the same point as [`solve_local`]; kept as the literal algorithm of the paper
/// and as a fallback for degenerate blocks.
pub fn solve_local_uzawa(
    w: &Delassus2,
    q: [f64; 2],
    mu: f64,
    r0: [f64; 2],
    tol: f64,
    max_iter: usize,
) -> ([f64; 2], ContactStatus) {
    cone::solve_local_iterated(&Coulomb2 { mu }, w, q, r0, tol, max_iter)
}

/// The plane Coulomb cone `|r_t| ≤ μ r_n` of a 2D contact: the law of every solver of the crate
/// today ([`crate::cone::FrictionCone`]). Its operations are this module's (the same bits):
/// the projection [`project_on_cone`], the branch-free residual [`natural_map_residual`], the
/// closed-form local solve [`solve_local`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coulomb2 {
    /// The friction coefficient μ ≥ 0.
    pub mu: Real,
}

impl FrictionCone for Coulomb2 {
    type Local = [Real; 2];
    type Block = Delassus2;

    #[inline(always)]
    fn mu(&self) -> Real {
        self.mu
    }

    #[inline(always)]
    fn block_mul(w: &Delassus2, r: [Real; 2]) -> [Real; 2] {
        w.mul(r)
    }

    fn block_lambda_max(w: &Delassus2) -> Real {
        w.lambda_max()
    }

    #[inline(always)]
    fn project(&self, tau: [Real; 2]) -> ([Real; 2], ContactStatus) {
        project_on_cone(tau, self.mu)
    }

    #[inline(always)]
    fn modified_velocity(&self, u: [Real; 2]) -> [Real; 2] {
        modified_velocity(u, self.mu)
    }

    #[inline(always)]
    fn natural_map_residual(&self, r: [Real; 2], u: [Real; 2]) -> [Real; 2] {
        natural_map_residual(r, u, self.mu)
    }

    #[inline(always)]
    fn solve_local(&self, w: &Delassus2, q: [Real; 2]) -> ([Real; 2], ContactStatus) {
        solve_local(w, q, self.mu)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::lcg;

    fn law_error(w: &Delassus2, q: [f64; 2], mu: f64, r: [f64; 2]) -> f64 {
        let wr = w.mul(r);
        let u = [wr[0] + q[0], wr[1] + q[1]];
        let e = natural_map_residual(r, u, mu);
        (e[0] * e[0] + e[1] * e[1]).sqrt()
    }

    #[test]
    fn projection_outcomes() {
        let mu = 0.5;
        assert_eq!(project_on_cone([1.0, 0.2], mu).1, ContactStatus::Stick);
        assert_eq!(project_on_cone([-1.0, 0.2], mu).1, ContactStatus::Open);
        let (r, s) = project_on_cone([1.0, 2.0], mu);
        assert_eq!(s, ContactStatus::Slide);
        assert!((r[1].abs() - mu * r[0]).abs() < 1e-15);
        // The projection is idempotent and orthogonal: (τ − p)·p = 0.
        let tau = [1.0, 2.0];
        assert!(((tau[0] - r[0]) * r[0] + (tau[1] - r[1]) * r[1]).abs() < 1e-14);
    }

    #[test]
    fn frictionless_projection_is_onto_the_normal_half_line() {
        // K_0 = {r_t = 0, r_n ≥ 0}.
        assert_eq!(
            project_on_cone([-0.357, 0.0], 0.0),
            ([0.0, 0.0], ContactStatus::Open)
        );
        assert_eq!(project_on_cone([-1.0, 0.5], 0.0).0, [0.0, 0.0]);
        assert_eq!(project_on_cone([2.0, 0.5], 0.0).0, [2.0, 0.0]);
        // An open frictionless contact separating at 0.357 m/s satisfies the law exactly.
        assert_eq!(
            natural_map_residual([0.0, 0.0], [0.357, 0.0], 0.0),
            [0.0, 0.0]
        );
        // The same for μ > 0 and for a sticking contact.
        assert_eq!(
            natural_map_residual([0.0, 0.0], [0.357, 0.1], 0.3),
            [0.0, 0.0]
        );
        assert_eq!(
            natural_map_residual([1.0, 0.1], [0.0, 0.0], 0.3),
            [0.0, 0.0]
        );
    }

    #[test]
    fn exact_local_solution_satisfies_the_law_and_matches_uzawa() {
        // Random SPD blocks of the disk type (W_tt ≈ 3 W_nn) and general ones.
        let mut s = 7u64;
        for k in 0..20_000 {
            let nn = 0.1 + lcg(&mut s);
            let (nt, tt) = if k % 2 == 0 {
                (0.0, 3.0 * nn)
            } else {
                let tt = 0.1 + 3.0 * lcg(&mut s);
                (0.9 * (lcg(&mut s) - 0.5) * 2.0 * (nn * tt).sqrt(), tt)
            };
            let w = Delassus2 { nn, nt, tt };
            let q = [2.0 * lcg(&mut s) - 1.5, 2.0 * lcg(&mut s) - 1.0];
            let mu = 1.2 * lcg(&mut s);
            let (r, _) = solve_local(&w, q, mu);
            let scale = q[0].abs().max(q[1].abs()).max(1e-300);
            assert!(
                law_error(&w, q, mu, r) <= 1e-12 * scale,
                "case {k}: {w:?} q={q:?} mu={mu} r={r:?}"
            );
            if k % 2 == 0 {
                let (ru, _) = solve_local_uzawa(&w, q, mu, [0.0, 0.0], 1e-14, 100_000);
                let d = ((ru[0] - r[0]).powi(2) + (ru[1] - r[1]).powi(2)).sqrt();
                let n = (r[0] * r[0] + r[1] * r[1]).sqrt().max(1e-12);
                assert!(d <= 1e-8 * n, "case {k}: exact {r:?} vs uzawa {ru:?}");
            }
        }
    }

    #[test]
    fn single_scalar_step_with_normal_rho_overshoots_on_disks() {
        // The failure mode the design notes warn about: ρ = 1/W_nn on a disk block
        // (W_tt = 3 W_nn) makes the tangential update of the predictor–corrector diverge.
        let w = Delassus2 {
            nn: 1.0,
            nt: 0.0,
            tt: 3.0,
        };
        let q = [-1.0, 0.3];
        let mu = 2.0; // sticking solution r = (1, -0.1)
        let mut r = [0.0, 0.0];
        for _ in 0..50 {
            let wr = w.mul(r);
            r = predictor_corrector(r, [wr[0] + q[0], wr[1] + q[1]], 1.0 / w.nn, mu).0;
        }
        assert!(
            law_error(&w, q, mu, r) > 1e-3,
            "expected no convergence, r = {r:?}"
        );
        let (rx, st) = solve_local(&w, q, mu);
        assert_eq!(st, ContactStatus::Stick);
        assert!((rx[0] - 1.0).abs() < 1e-15 && (rx[1] + 0.1).abs() < 1e-15);
    }
    /// The generic operations written against the interface give, on the plane cone, what its
    /// own closed forms give: the iterated predictor–corrector reaches the closed-form local
    /// solution (to 10⁻⁹ of its size, same outcome), and the generic residual (its default
    /// method, through the projection) equals the branch-free one to rounding, on 2000 random
    /// blocks, free velocities and friction coefficients.
    #[test]
    fn the_generic_local_solve_and_residual_agree_with_the_plane_closed_forms() {
        /// The trait's default methods on the same cone (no override).
        #[derive(Clone, Copy)]
        struct Plain(Coulomb2);
        impl FrictionCone for Plain {
            type Local = [Real; 2];
            type Block = Delassus2;
            fn mu(&self) -> Real {
                self.0.mu
            }
            fn block_mul(w: &Delassus2, r: [Real; 2]) -> [Real; 2] {
                w.mul(r)
            }
            fn block_lambda_max(w: &Delassus2) -> Real {
                w.lambda_max()
            }
            fn project(&self, tau: [Real; 2]) -> ([Real; 2], ContactStatus) {
                self.0.project(tau)
            }
        }
        let mut s = 7u64;
        let mut statuses = [0usize; 3];
        for _ in 0..2000 {
            let (a, b) = (0.5 + 2.0 * lcg(&mut s), 0.5 + 2.0 * lcg(&mut s));
            let nt = (lcg(&mut s) - 0.5) * (a * b).sqrt();
            let w = Delassus2 { nn: a, nt, tt: b };
            let q = [2.0 * lcg(&mut s) - 1.4, 2.0 * lcg(&mut s) - 1.0];
            let cone = Coulomb2 {
                mu: 0.05 + lcg(&mut s),
            };
            let (exact, st) = cone.solve_local(&w, q);
            let (iter, st2) = Plain(cone).solve_local(&w, q);
            let scale = (exact[0].abs() + exact[1].abs()).max(1e-12);
            assert!(
                (exact[0] - iter[0]).abs() + (exact[1] - iter[1]).abs() <= 1e-9 * scale,
                "{exact:?} vs {iter:?} for {w:?}, {q:?}, μ = {}",
                cone.mu
            );
            assert_eq!(st, st2);
            statuses[st as usize] += 1;
            let r = [lcg(&mut s), lcg(&mut s) - 0.5];
            let u = [lcg(&mut s) - 0.5, lcg(&mut s) - 0.5];
            let (e1, e2) = (
                cone.natural_map_residual(r, u),
                Plain(cone).natural_map_residual(r, u),
            );
            assert!((e1[0] - e2[0]).abs() + (e1[1] - e2[1]).abs() < 1e-15);
        }
        // Every outcome was exercised.
        assert!(statuses.iter().all(|&n| n > 100), "{statuses:?}");
    }
}
