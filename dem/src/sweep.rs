//! One Gauss–Seidel sweep over the engine's contact rows, with the body velocities kept
//! current: the O(1) update of one contact ([`update`]), a sweep in a given order ([`sweep`]),
//! and the status of a contact read from its impulse ([`status`], [`classify`]). The step's
//! solver ([`crate::solver`]) drives these sweeps, the coupled cell ([`crate::cell_coupling`])
//! and the wavefront schedule ([`crate::wavefront`]) use them; the colour-ordered sweep on
//! several threads is [`crate::parallel`]'s.
//!
//! **The row a sweep sees.** A sweep asks of each contact row what [`SweepRow`] names: its
//! friction cone ([`crate::cone::FrictionCone`]), its Delassus block `W_αα`, its impulse
//! `r_α` and its free velocity `q̃_α = u_α − W_αα r_α` (the local velocity with the other
//! contacts' impulses as they are and its own taken out), and updates it by
//! [`solve_row`], the relaxed local solve written once against the cone
//! ([`crate::cone::relaxed_local_solve`]). The engine's [`ContactRow`] and the standalone
//! problem's rows (`crate::fc::nsgs`) implement it with the plane cone; a 3D row (the
//! `dim3` skeleton's `Coulomb3`, `Delassus3`) implements the same trait and is swept by the
//! same [`solve_row`] (`crate::dim3`'s tests).

use crate::cone::{relaxed_local_solve, FrictionCone};
use crate::contact::{ContactRow, RowCone};
use crate::local::ContactStatus;
use crate::math::{Real, Spatial};

/// What a Gauss–Seidel sweep needs of a contact row (module documentation), whatever the
/// dimension and whatever holds the problem.
pub trait SweepRow {
    /// The row's friction law.
    type Cone: FrictionCone;
    /// What the free velocity is read from besides the row: the current velocities of its two
    /// bodies for the engine's rows, nothing (`()`) for a row that reads its problem itself.
    type Context;

    /// The row's friction cone.
    fn cone(&self) -> Self::Cone;

    /// The row's Delassus block `W_αα` (1/kg).
    fn block(&self) -> &<Self::Cone as FrictionCone>::Block;

    /// The row's current impulse `r_α` (N·s), normal first.
    fn impulse(&self) -> LocalOf<Self>;

    /// The row's free velocity `q̃_α = u_α − W_αα r_α` (m/s): everything but its own impulse.
    fn free_velocity(&self, context: Self::Context) -> LocalOf<Self>;
}

/// The local impulse or velocity type of a row's cone.
pub type LocalOf<R> = <<R as SweepRow>::Cone as FrictionCone>::Local;

/// The Gauss–Seidel update of one row: its new impulse, the relaxed local solve
/// ([`relaxed_local_solve`]) of its cone on its block, free velocity and impulse. O(1).
#[inline(always)]
pub fn solve_row<R: SweepRow + ?Sized>(row: &R, context: R::Context, omega: Real) -> LocalOf<R> {
    relaxed_local_solve(
        &row.cone(),
        row.block(),
        row.free_velocity(context),
        row.impulse(),
        omega,
    )
}

/// The engine's row on the plane cone ([`RowCone`]); its free velocity is read from the
/// current velocities `(v_a, v_b)` of its two bodies.
impl SweepRow for ContactRow {
    type Cone = RowCone;
    type Context = (Spatial, Spatial);

    #[inline(always)]
    fn cone(&self) -> RowCone {
        ContactRow::cone(self)
    }

    #[inline(always)]
    fn block(&self) -> &<RowCone as FrictionCone>::Block {
        &self.w
    }

    #[inline(always)]
    fn impulse(&self) -> [Real; 2] {
        self.r
    }

    /// `q̃ = H v + shift + affine − W r`.
    #[inline(always)]
    fn free_velocity(&self, (va, vb): (Spatial, Spatial)) -> [Real; 2] {
        let u = self.velocity(&va, &vb);
        let wr = self.w.mul(self.r);
        [u[0] - wr[0], u[1] - wr[1]]
    }
}

/// The exact local update of one contact on given body velocities ([`solve_row`]: the local
/// solve of `q̃ = u − W r`, optionally relaxed and projected back on the cone); returns whether
/// the impulse changed (then `va`, `vb` hold the updated velocities).
#[inline(always)]
pub(crate) fn local_update(
    c: &mut ContactRow,
    va: &mut Spatial,
    ia: &Spatial,
    vb: &mut Spatial,
    ib: &Spatial,
    omega: Real,
) -> bool {
    let r = solve_row(c, (*va, *vb), omega);
    let d = [r[0] - c.r[0], r[1] - c.r[1]];
    if d != [0.0, 0.0] {
        c.apply(d, va, ia, vb, ib);
        c.r = r;
        true
    } else {
        false
    }
}

/// Update of one contact: exact local solve, optional relaxation projected back on the cone,
/// velocities of its two bodies updated. O(1).
/// Returns whether the impulse changed.
#[inline(always)]
pub fn update(c: &mut ContactRow, vel: &mut [Spatial], inv: &[Spatial], omega: Real) -> bool {
    let (a, b) = (c.a as usize, c.b as usize);
    let (mut va, mut vb) = (vel[a], vel[b]);
    let changed = local_update(c, &mut va, &inv[a], &mut vb, &inv[b], omega);
    if changed {
        vel[a] = va;
        vel[b] = vb;
    }
    changed
}

/// One Gauss–Seidel sweep over `rows` in the order given by `order`, with relaxation `omega`.
/// (Alternating forward and backward sweeps was tried and converged worse; see `fc`.)
#[inline]
pub fn sweep(
    rows: &mut [ContactRow],
    order: &[u32],
    vel: &mut [Spatial],
    inv: &[Spatial],
    omega: Real,
) {
    for &i in order {
        update(&mut rows[i as usize], vel, inv, omega);
    }
}

/// Status of each contact from its impulse ([`status`]).
pub fn classify(rows: &[ContactRow], status: &mut [ContactStatus]) {
    for (c, s) in rows.iter().zip(status.iter_mut()) {
        *s = self::status(c);
    }
}

/// Status of a contact from its impulse: open when `r_n ≤ 0`, sliding when on the cone's
/// boundary (`|r_t| ≥ μ r_n (1 − 10⁻⁹)`), sticking otherwise.
#[inline]
pub fn status(c: &ContactRow) -> ContactStatus {
    if c.r[0] <= 0.0 {
        ContactStatus::Open
    } else if c.r[1].abs() >= c.mu * c.r[0] * (1.0 - 1e-9) {
        ContactStatus::Slide
    } else {
        ContactStatus::Stick
    }
}
