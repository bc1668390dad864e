//! Nonlinear Gauss–Seidel (NLGS) over contacts with body velocities kept up to date.
//!
//! The Delassus operator `W = H M⁻¹ Hᵀ` is never assembled. Body velocities
//! `v = v_free + M⁻¹ Hᵀ R` are kept current: for contact α,
//!
//! ```text
//! u_α  = H_α v + shift_α                (current local velocity, O(1))
//! q̃_α  = u_α − W_αα r_α                  (everything but contact α itself)
//! r_α' = solve_local(W_αα, q̃_α, μ_α)    (exact fixed point of the bipotential predictor–corrector)
//! v   += M⁻¹ H_αᵀ (r_α' − r_α)          (O(1): two bodies)
//! ```
//!
//! so one contact update costs O(1) whatever the number of contacts. Each update is the exact
//! minimisation of the local problem, which is what makes the sweep converge on disk contacts
//! (a single predictor–corrector step with ρ = 1/W_nn does not: W_tt = 3 W_nn).
//!
//! Convergence is judged on the error measure of `formats/frictional-contact.md` (Siconos'
//! natural-map error): `e = ‖r − proj_K(r − ū)‖ / max(‖q‖, ‖r‖, ‖u‖)`, `q` the local velocity at
//! zero impulse, `ū = u + μ|u_t| n`.

use serde::{Deserialize, Serialize};

use crate::contact::ContactRow;
use crate::local::{natural_map_residual, project_on_cone, solve_local, ContactStatus};

/// Parameters of the NLGS solver.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverParams {
    /// Tolerance on the error measure (dimensionless).
    pub tolerance: f64,
    /// Maximum number of sweeps per step.
    pub max_iterations: usize,
    /// Relaxation factor ω of the impulse update, `r ← proj_K(r + ω (r_local − r))`, in (0, 2).
    #[serde(default = "one")]
    pub relaxation: f64,
    /// Alternate forward and backward sweeps (symmetric Gauss–Seidel).
    #[serde(default)]
    pub symmetric: bool,
}

fn one() -> f64 {
    1.0
}

impl Default for SolverParams {
    fn default() -> Self {
        SolverParams {
            tolerance: 1e-6,
            max_iterations: 10_000,
            relaxation: 1.0,
            symmetric: false,
        }
    }
}

/// Outcome of one contact solve.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct SolveReport {
    /// Sweeps done.
    pub iterations: usize,
    /// Error measure at the returned impulses.
    pub error: f64,
    /// Whether `error ≤ tolerance`.
    pub converged: bool,
}

/// Sweeps without the error halving after which the sweep order is shuffled.
pub const STALL_SWEEPS: usize = 500;

/// Apply the impulses currently stored in `rows` to the velocities (warm start):
/// `v ← v + M⁻¹ Hᵀ R`.
pub fn apply_impulses(rows: &[ContactRow], vel: &mut [[f64; 3]], inv: &[[f64; 3]]) {
    for c in rows {
        if c.r != [0.0, 0.0] {
            let (a, b) = (c.a as usize, c.b as usize);
            let (mut va, mut vb) = (vel[a], vel[b]);
            c.apply(c.r, &mut va, &inv[a], &mut vb, &inv[b]);
            vel[a] = va;
            vel[b] = vb;
        }
    }
}

/// Error measure of the current state: `‖r − proj_K(r − ū)‖ / max(q_norm, ‖r‖, ‖u‖)`.
pub fn error_measure(rows: &[ContactRow], vel: &[[f64; 3]], q_norm: f64) -> f64 {
    let (mut e2, mut r2, mut u2) = (0.0, 0.0, 0.0);
    for c in rows {
        let u = c.velocity(&vel[c.a as usize], &vel[c.b as usize]);
        let e = natural_map_residual(c.r, u, c.mu);
        e2 += e[0] * e[0] + e[1] * e[1];
        r2 += c.r[0] * c.r[0] + c.r[1] * c.r[1];
        u2 += u[0] * u[0] + u[1] * u[1];
    }
    let den = q_norm.max(r2.sqrt()).max(u2.sqrt());
    if den > 0.0 {
        e2.sqrt() / den
    } else {
        0.0
    }
}

/// Norm of the free local velocities `‖q‖`, `q_α = H_α v_free + shift_α`, computed from the
/// velocities *before* the warm-start impulses are applied.
pub fn free_velocity_norm(rows: &[ContactRow], vel: &[[f64; 3]]) -> f64 {
    rows.iter()
        .map(|c| {
            let u = c.velocity(&vel[c.a as usize], &vel[c.b as usize]);
            u[0] * u[0] + u[1] * u[1]
        })
        .sum::<f64>()
        .sqrt()
}

/// Update of one contact: exact local solve, optional relaxation projected back on the cone,
/// velocities of its two bodies updated. O(1).
#[inline(always)]
fn update(c: &mut ContactRow, vel: &mut [[f64; 3]], inv: &[[f64; 3]], omega: f64) {
    let (a, b) = (c.a as usize, c.b as usize);
    let (mut va, mut vb) = (vel[a], vel[b]);
    let u = c.velocity(&va, &vb);
    let wr = c.w.mul(c.r);
    let q = [u[0] - wr[0], u[1] - wr[1]];
    let (mut r, _) = solve_local(&c.w, q, c.mu);
    if omega != 1.0 {
        let t = [c.r[0] + omega * (r[0] - c.r[0]), c.r[1] + omega * (r[1] - c.r[1])];
        r = project_on_cone(t, c.mu).0;
    }
    let d = [r[0] - c.r[0], r[1] - c.r[1]];
    if d != [0.0, 0.0] {
        c.apply(d, &mut va, &inv[a], &mut vb, &inv[b]);
        vel[a] = va;
        vel[b] = vb;
        c.r = r;
    }
}

/// One Gauss–Seidel sweep over `rows` in the order given by `order` (forward or backward),
/// with relaxation `omega`.
#[inline]
pub fn sweep(
    rows: &mut [ContactRow],
    order: &[u32],
    vel: &mut [[f64; 3]],
    inv: &[[f64; 3]],
    omega: f64,
    backward: bool,
) {
    if backward {
        for &i in order.iter().rev() {
            update(&mut rows[i as usize], vel, inv, omega);
        }
    } else {
        for &i in order {
            update(&mut rows[i as usize], vel, inv, omega);
        }
    }
}

/// Solve the contact problem of a step by NLGS, starting from the impulses stored in `rows`
/// (already applied to `vel`, see [`apply_impulses`]). `q_norm` is [`free_velocity_norm`].
///
/// The error is evaluated after every sweep during the first ten, then every
/// `max(1, iterations/10)` sweeps (at most 16): the reported error is always the true error at
/// the returned impulses.
///
/// Gauss–Seidel in a fixed order can cycle on statically indeterminate clusters of sticking
/// contacts (closed loops of grains) instead of converging. When the error has not halved over
/// [`STALL_SWEEPS`] sweeps, the sweeps continue in a fresh pseudo-random order each time (seeded,
/// so runs stay reproducible), which breaks the cycle.
pub fn solve(
    rows: &mut [ContactRow],
    order: &mut [u32],
    vel: &mut [[f64; 3]],
    inv: &[[f64; 3]],
    q_norm: f64,
    params: &SolverParams,
) -> SolveReport {
    if rows.is_empty() {
        return SolveReport {
            iterations: 0,
            error: 0.0,
            converged: true,
        };
    }
    let mut error = error_measure(rows, vel, q_norm);
    if error <= params.tolerance {
        return SolveReport {
            iterations: 0,
            error,
            converged: true,
        };
    }
    let mut it = 0;
    let mut next_check = 1;
    let (mut best, mut best_it) = (error, 0usize);
    let mut shuffling = false;
    let mut seed = 0x9E37_79B9_7F4A_7C15u64;
    while it < params.max_iterations {
        if shuffling {
            for i in (1..order.len()).rev() {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                order.swap(i, ((seed >> 33) as usize) % (i + 1));
            }
        }
        sweep(rows, order, vel, inv, params.relaxation, params.symmetric && it % 2 == 1);
        it += 1;
        if it >= next_check || it == params.max_iterations {
            error = error_measure(rows, vel, q_norm);
            if error <= params.tolerance {
                break;
            }
            if error < 0.5 * best {
                (best, best_it) = (error, it);
            } else if !shuffling && it - best_it >= STALL_SWEEPS {
                shuffling = true;
            }
            next_check = it + if it < 10 { 1 } else { (it / 10).clamp(1, 16) };
        }
    }
    SolveReport {
        iterations: it,
        error,
        converged: error <= params.tolerance,
    }
}

/// Status of each contact from its impulse: open when `r = 0`, sliding when on the cone's
/// boundary (`|r_t| ≥ μ r_n (1 − 10⁻⁹)`), sticking otherwise.
pub fn classify(rows: &[ContactRow], status: &mut [ContactStatus]) {
    for (c, s) in rows.iter().zip(status.iter_mut()) {
        *s = if c.r[0] <= 0.0 {
            ContactStatus::Open
        } else if c.r[1].abs() >= c.mu * c.r[0] * (1.0 - 1e-9) {
            ContactStatus::Slide
        } else {
            ContactStatus::Stick
        };
    }
}
