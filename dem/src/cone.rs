//! The friction-cone interface: what a contact solver needs of a contact's friction law,
//! whatever the dimension.
//!
//! A frictional contact has an impulse `r = (r_n, r_t)` and a relative velocity `u = W r + q`
//! in its local frame (normal first; `r_t` has one component in 2D, two in 3D). Signorini's
//! condition and Coulomb's law together are the cone complementarity (De Saxcé's bipotential,
//! `crate::local`)
//!
//! ```text
//! K_μ ∋ r ⊥ ū ∈ K_μ*,     K_μ = {r : ‖r_t‖ ≤ μ r_n},     ū = (u_n + μ ‖u_t‖, u_t)
//! ```
//!
//! and every solver in the crate is built from four operations on it, which
//! [`FrictionCone`] names: the Euclidean projection on `K_μ` (the corrector), the modified
//! velocity `ū`, the natural-map residual `r − proj_K(r − ū)` (the per-contact error of
//! `docs/formats.md` §1.2), and the exact solution of one contact's problem given its Delassus
//! block ([`FrictionCone::Block`]) and the others' contribution `q` (the Gauss–Seidel update).
//! The generic predictor–corrector ([`predictor_corrector`], [`solve_local_iterated`]) is
//! written once against the interface, and so is the relaxed local update of every
//! Gauss–Seidel sweep of the crate ([`relaxed_local_solve`], called through
//! `crate::sweep::solve_row` on any row implementing `crate::sweep::SweepRow`: the engine's
//! rows, the standalone problem's, a 3D row).
//!
//! Implementations: `crate::local::Coulomb2`, the plane cone, whose local solve is the closed
//! form over its three outcomes (`crate::local::solve_local`); the 3D circular cone of the compile-only
//! skeleton (`crate::dim3::Coulomb3`, feature `dim3`). Methods that are 2D by algorithm say
//! so and take the plane cone's data directly: Lemke's method (`crate::fc::lemke`, exact because
//! the plane cone is polyhedral), and the semismooth Newton linearisation (`crate::fc::newton`,
//! per-contact 2×2 Jacobians).
//!
//! References: P. Alart, A. Curnier, *A mixed formulation for frictional contact problems prone
//! to Newton like solution methods*, CMAME 92 (1991) 353–375; G. De Saxcé, Z.-Q. Feng, *The
//! bipotential method*, Math. Comput. Model. 28 (1998) 225–245; V. Acary, M. Brémond,
//! O. Huber, *On solving contact problems with Coulomb friction: formulations and numerical
//! comparisons*, in *Advanced Topics in Nonsmooth Dynamics*, Springer (2018) 375–457.

use serde::{Deserialize, Serialize};

use crate::math::Real;

/// Status of a contact after the local solve (the three outcomes of the corrector).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum ContactStatus {
    /// No reaction: the prediction lies in the polar cone (`r = 0`, `u_n ≥ 0`).
    #[default]
    Open,
    /// Reaction strictly inside the Coulomb cone, no relative velocity (`u = 0`).
    Stick,
    /// Reaction on the boundary of the cone, sliding opposite to the tangential impulse.
    Slide,
}

impl ContactStatus {
    /// A short lowercase name (`open`, `stick`, `slide`) for tables and files.
    pub fn name(self) -> &'static str {
        match self {
            ContactStatus::Open => "open",
            ContactStatus::Stick => "stick",
            ContactStatus::Slide => "slide",
        }
    }
}

/// The friction law of one contact as the solvers see it (module documentation).
pub trait FrictionCone: Copy {
    /// A local impulse or velocity, normal component first: `[Real; 2]` in 2D, `[Real; 3]` in
    /// 3D (N·s or m/s).
    type Local: Copy + Default + AsRef<[Real]> + AsMut<[Real]>;
    /// The contact's own Delassus block `W_αα` (1/kg), symmetric positive semi-definite.
    type Block: Copy;

    /// The friction coefficient μ (1).
    fn mu(&self) -> Real;

    /// `W r` for the block `w`.
    fn block_mul(w: &Self::Block, r: Self::Local) -> Self::Local;

    /// Largest eigenvalue of the block (1/kg): the step `ρ = 1/λ_max` of the iterated
    /// predictor–corrector.
    fn block_lambda_max(w: &Self::Block) -> Real;

    /// Euclidean projection of `tau` on `K_μ`, with the outcome (open: the polar cone; stick:
    /// inside; slide: on the boundary).
    fn project(&self, tau: Self::Local) -> (Self::Local, ContactStatus);

    /// De Saxcé's modified velocity `ū = (u_n + μ ‖u_t‖, u_t)`.
    fn modified_velocity(&self, u: Self::Local) -> Self::Local {
        let mut ub = u;
        let t = &u.as_ref()[1..];
        let norm_t = t.iter().map(|x| x * x).sum::<Real>().sqrt();
        ub.as_mut()[0] += self.mu() * norm_t;
        ub
    }

    /// The natural-map residual `r − proj_K(r − ū)` (zero exactly when `(r, u)` obeys the law).
    fn natural_map_residual(&self, r: Self::Local, u: Self::Local) -> Self::Local {
        let ub = self.modified_velocity(u);
        let mut tau = r;
        for (t, x) in tau.as_mut().iter_mut().zip(ub.as_ref()) {
            *t -= x;
        }
        let (p, _) = self.project(tau);
        let mut e = r;
        for (e, x) in e.as_mut().iter_mut().zip(p.as_ref()) {
            *e -= x;
        }
        e
    }

    /// The exact solution of one contact's problem `u = W r + q`, `(r, u)` obeying the law.
    /// By default the iterated predictor–corrector ([`solve_local_iterated`]) to 10⁻¹⁵;
    /// a cone with a closed form overrides it.
    fn solve_local(&self, w: &Self::Block, q: Self::Local) -> (Self::Local, ContactStatus) {
        solve_local_iterated(self, w, q, Self::Local::default(), 1e-15, 10_000)
    }
}

/// The relative error of a whole problem's impulses, for any cone (fc-problem-v1's measure,
/// Siconos' `fc2d_compute_error` in 2D; the same form in 3D):
///
/// ```text
/// e = ‖(r_α − proj_K(r_α − ū_α))_α‖₂ / max(‖q‖₂, ‖r‖₂, ‖u‖₂)
/// ```
///
/// with `n` contacts, contact `α`'s cone `cone(α)`, and `q`, `r`, `u = W r + q` stacked by
/// contact (`Local`'s length each); the absolute residual when the scale is not above machine
/// epsilon.
pub fn natural_map_error<C: FrictionCone>(
    n: usize,
    cone: impl Fn(usize) -> C,
    q: &[Real],
    r: &[Real],
    u: &[Real],
) -> Real {
    let d = C::Local::default().as_ref().len();
    let mut res2 = 0.0;
    for a in 0..n {
        let (mut ra, mut ua) = (C::Local::default(), C::Local::default());
        ra.as_mut().copy_from_slice(&r[d * a..d * (a + 1)]);
        ua.as_mut().copy_from_slice(&u[d * a..d * (a + 1)]);
        let e = cone(a).natural_map_residual(ra, ua);
        let mut e2 = 0.0;
        for x in e.as_ref() {
            e2 += x * x;
        }
        res2 += e2;
    }
    let norm = |x: &[Real]| x.iter().map(|v| v * v).sum::<Real>().sqrt();
    let scale = norm(q).max(norm(r)).max(norm(u));
    let res = res2.sqrt();
    if scale > Real::EPSILON {
        res / scale
    } else {
        res
    }
}

/// One step of the paper's predictor–corrector on any cone: `τ = r − ρ ū(u)`, `r ← proj(τ)`.
pub fn predictor_corrector<C: FrictionCone>(
    cone: &C,
    r: C::Local,
    u: C::Local,
    rho: Real,
) -> (C::Local, ContactStatus) {
    let ub = cone.modified_velocity(u);
    let mut tau = r;
    for (t, x) in tau.as_mut().iter_mut().zip(ub.as_ref()) {
        *t -= rho * x;
    }
    cone.project(tau)
}

/// The predictor–corrector iterated on one contact, `ρ = 1/λ_max(W)`, from `r0` until the
/// change of `r` is at most `tol ‖r‖` (or `max_iter` steps): the fixed point is the solution
/// of the contact's problem (De Saxcé & Feng 1998). Written once for every cone.
pub fn solve_local_iterated<C: FrictionCone>(
    cone: &C,
    w: &C::Block,
    q: C::Local,
    r0: C::Local,
    tol: Real,
    max_iter: usize,
) -> (C::Local, ContactStatus) {
    let rho = 1.0 / C::block_lambda_max(w).max(Real::MIN_POSITIVE);
    let mut r = r0;
    let mut status = ContactStatus::Open;
    for _ in 0..max_iter {
        let mut u = C::block_mul(w, r);
        for (u, q) in u.as_mut().iter_mut().zip(q.as_ref()) {
            *u += q;
        }
        let (next, st) = predictor_corrector(cone, r, u, rho);
        let (mut d2, mut s2) = (0.0, 0.0);
        for (a, b) in next.as_ref().iter().zip(r.as_ref()) {
            d2 += (a - b) * (a - b);
            s2 += a * a;
        }
        r = next;
        status = st;
        if d2.sqrt() <= tol * s2.sqrt().max(Real::MIN_POSITIVE) {
            break;
        }
    }
    (r, status)
}

/// The relaxed local update of nonlinear Gauss–Seidel, written once for every cone: the exact
/// solution `r* = solve_local(W, q)` of the contact's problem ([`FrictionCone::solve_local`]),
/// and with a relaxation factor `ω ≠ 1` the relaxed impulse projected back on the cone,
///
/// ```text
/// r ← r*                                    (ω = 1)
/// r ← proj_K(r_old + ω (r* − r_old))         (ω ≠ 1)
/// ```
///
/// so that `r` stays in `K_μ` (the over-relaxed NLGS of M. Jean, *The non-smooth contact
/// dynamics method*, CMAME 177 (1999) 235–257). Every sweep of the crate calls it, through
/// [`crate::sweep::solve_row`].
#[inline(always)]
pub fn relaxed_local_solve<C: FrictionCone>(
    cone: &C,
    w: &C::Block,
    q: C::Local,
    old: C::Local,
    omega: Real,
) -> C::Local {
    let (mut r, _) = cone.solve_local(w, q);
    if omega != 1.0 {
        let mut t = old;
        for ((t, o), x) in t.as_mut().iter_mut().zip(old.as_ref()).zip(r.as_ref()) {
            *t = o + omega * (x - o);
        }
        r = cone.project(t).0;
    }
    r
}
