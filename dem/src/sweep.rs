//! One Gauss–Seidel sweep over the engine's contact rows, with the body velocities kept
//! current: the O(1) update of one contact ([`update`]), a sweep in a given order ([`sweep`]),
//! and the status of a contact read from its impulse ([`status`], [`classify`]). The step's
//! solver ([`crate::solver`]) drives these sweeps, the coupled cell ([`crate::cell_coupling`])
//! and the wavefront schedule ([`crate::wavefront`]) use them; the colour-ordered sweep on
//! several threads is [`crate::parallel`]'s.

use crate::contact::ContactRow;
use crate::local::ContactStatus;
use crate::parallel::local_update;

/// Update of one contact: exact local solve, optional relaxation projected back on the cone,
/// velocities of its two bodies updated. O(1).
/// Returns whether the impulse changed.
#[inline(always)]
pub fn update(c: &mut ContactRow, vel: &mut [[f64; 3]], inv: &[[f64; 3]], omega: f64) -> bool {
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
    vel: &mut [[f64; 3]],
    inv: &[[f64; 3]],
    omega: f64,
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
