//! A schedule of a Gauss–Seidel sweep that gives the same sweep, bit for bit, with independent
//! contact updates next to each other.
//!
//! The update of contact α reads and writes the velocities of its two bodies and its own
//! impulse, nothing else ([`crate::solver`]). Two sweeps over the same contacts therefore give
//! the same impulses and velocities, to the last bit, whenever every pair of contacts that
//! share a body is updated in the same relative order: the sweep is a directed acyclic graph of
//! updates, and any topological order of it does the same arithmetic on the same operands.
//!
//! In the given order (the contacts as the detection listed them, neighbours after
//! neighbours), consecutive updates nearly always share a body, so each one waits for the
//! previous one's velocities: a chain of dependent loads, products and a division, about 40
//! cycles an update, with the processor's other execution units idle. The wavefront schedule
//! gives each contact its depth in that graph,
//!
//! ```text
//! d_α = max(D_a, D_b),   then D_a = D_b = d_α + 1      (contacts taken in the given order,
//!                                                       D_x = 0 for every body at the start)
//! ```
//!
//! and sweeps the contacts by increasing depth: contacts of one depth share no body (a later
//! contact on a body of α gets at least `d_α + 1`), and of two contacts that share a body the
//! earlier one in the given order is the shallower. The processor overlaps the independent
//! updates of one depth. Within a depth, contacts are grouped by the status of their impulse at
//! the start of the solve (open, sticking, sliding), which makes the branches of the exact
//! local solve ([`crate::local::solve_local`]) predictable; the order within a depth changes no
//! bit. Built by a counting sort, O(n + bodies), once a solve, by [`crate::solver::solve`] for
//! its natural-order sweeps without a coupled cell (whose unknowns every update touches); a
//! stall shuffle returns to the given order.
//!
//! One number is not the same: the sums of a sweep's measured change (`‖Δr‖²`, `‖r‖²`, with
//! [`crate::SolverParams::check_every`] ≥ 1) are added in the schedule's order, so their last
//! bit may differ, and with it, rarely, the sweep after which the error is checked and so the
//! iterate a solve stops at. With `check_every = 0` (every scenario's default) a solve is the
//! same bit for bit.
//!
//! Walls are bodies like any other here (their velocities are written back by the updates,
//! unchanged but for the sign of a zero), so the contacts on one wall keep their order.
//!
//! The idea is the level scheduling of sparse triangular solves (E. Anderson and Y. Saad,
//! *Solving sparse triangular linear systems on parallel computers*, Int. J. High Speed
//! Computing 1 (1989) 73–95), used here for instruction-level parallelism on one core.

use crate::contact::ContactRow;
use crate::local::ContactStatus;
#[cfg(test)]
use crate::math::Spatial;

/// Buffers of [`Wavefront::build`], kept between solves.
#[derive(Debug, Clone, Default)]
pub struct Wavefront {
    /// The schedule: the indices of the contacts, by increasing key.
    pub order: Vec<u32>,
    /// Depth reached so far by each body.
    depth: Vec<u32>,
    /// Key of each contact: `3 d_α + status` (status 0 open, 1 sticking, 2 sliding).
    key: Vec<u32>,
    /// Counting-sort offsets by key.
    start: Vec<u32>,
}

impl Wavefront {
    /// Sets [`Wavefront::order`] to the wavefront schedule of the sweep over `rows` in the
    /// order `given` (a permutation of `0..rows.len()`) on `bodies` bodies (module
    /// documentation). Returns the number of depths.
    pub fn build(&mut self, rows: &[ContactRow], given: &[u32], bodies: usize) -> usize {
        debug_assert_eq!(given.len(), rows.len());
        self.depth.clear();
        self.depth.resize(bodies, 0);
        self.key.clear();
        self.key.resize(rows.len(), 0);
        // `start[k + 1]` counts the contacts of key `k` (grown as deeper keys appear).
        self.start.clear();
        let mut depths = 0u32;
        for &i in given {
            let c = &rows[i as usize];
            let (a, b) = (c.a as usize, c.b as usize);
            let d = self.depth[a].max(self.depth[b]);
            self.depth[a] = d + 1;
            self.depth[b] = d + 1;
            depths = depths.max(d + 1);
            let status = match crate::sweep::status(c) {
                ContactStatus::Open => 0,
                ContactStatus::Stick => 1,
                ContactStatus::Slide => 2,
            };
            let key = 3 * d + status;
            self.key[i as usize] = key;
            if self.start.len() < key as usize + 2 {
                self.start.resize(key as usize + 2, 0);
            }
            self.start[key as usize + 1] += 1;
        }
        for k in 1..self.start.len() {
            self.start[k] += self.start[k - 1];
        }
        self.order.clear();
        self.order.resize(given.len(), 0);
        for &i in given {
            let slot = &mut self.start[self.key[i as usize] as usize];
            self.order[*slot as usize] = i;
            *slot += 1;
        }
        depths as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::sweep;

    /// A ring of disks `0–1–2–…–0` with contacts between neighbours, plus contacts of every
    /// fourth disk on a wall (body `n`).
    fn rows(n: usize) -> Vec<ContactRow> {
        let mut rows = Vec::new();
        let mut state = 12345u64;
        let mut next = || crate::test_support::lcg(&mut state);
        for i in 0..n {
            let pairs = [(i, (i + 1) % n), (i, n)];
            for (a, b) in pairs {
                if b == n && i % 4 != 0 {
                    continue;
                }
                let ang: f64 = std::f64::consts::TAU * next();
                let n_ = [ang.cos(), ang.sin()];
                let k = [0.4 * next(), 0.3 * next(), -0.2 * next(), 0.5 * next()];
                let ia = [1.0, 1.0, 3.0];
                let ib = if b == n { [0.0; 3] } else { [1.0, 1.0, 3.0] };
                rows.push(ContactRow {
                    a: a as u32,
                    b: b as u32,
                    n: n_,
                    k,
                    w: ContactRow::delassus(n_, k, &ia, &ib),
                    shift: 0.0,
                    affine: [0.0, 0.0],
                    mu: 0.3,
                    r: [0.0, 0.0],
                    basis: 0,
                });
            }
        }
        rows
    }

    fn inverse(n: usize) -> Vec<Spatial> {
        let mut inv = vec![[1.0, 1.0, 3.0]; n];
        inv.push([0.0; 3]);
        inv
    }

    /// Velocities of the `n` disks (the wall, body `n`, at rest).
    fn velocities(n: usize) -> Vec<Spatial> {
        (0..=n)
            .map(|i| {
                let x = i as f64;
                if i == n {
                    [0.0; 3]
                } else {
                    [
                        (0.7 * x).sin(),
                        (1.3 * x).cos() - 0.5,
                        0.1 * (2.1 * x).sin(),
                    ]
                }
            })
            .collect()
    }

    /// Warm impulses on every other contact, for a mix of statuses when the schedule is built.
    fn warm(rows: &mut [ContactRow]) {
        for (k, c) in rows.iter_mut().enumerate().filter(|(k, _)| k % 2 == 0) {
            c.r = [0.01 * (k % 7) as f64, 0.004 * ((k % 5) as f64 - 2.0)];
        }
    }

    /// The bits of the impulses and velocities.
    fn bits(rows: &[ContactRow], v: &[Spatial]) -> Vec<u64> {
        rows.iter()
            .flat_map(|c| c.r)
            .chain(v.iter().flatten().copied())
            .map(f64::to_bits)
            .collect()
    }

    /// Contacts of one depth share no body; contacts sharing a body keep their given order;
    /// within a depth the statuses come open, sticking, sliding.
    #[test]
    fn schedule_is_a_topological_order_with_independent_depths() {
        let n = 40;
        let mut r = rows(n);
        for (k, c) in r.iter_mut().enumerate() {
            // Open, sticking (|r_t| < μ r_n) and sliding (|r_t| = μ r_n) in turn.
            c.r = match k % 3 {
                0 => [0.0, 0.0],
                1 => [0.1, 0.01],
                _ => [0.1, -0.03],
            };
        }
        let given: Vec<u32> = (0..r.len() as u32).rev().collect();
        let mut w = Wavefront::default();
        let depths = w.build(&r, &given, n + 1);
        // The wall is shared by the n/4 contacts on it: at least n/4 depths.
        assert!(depths >= n / 4, "{depths} depths");
        assert!(depths < r.len(), "{depths} depths for {} contacts", r.len());
        let mut pos = vec![0usize; r.len()];
        for (p, &i) in w.order.iter().enumerate() {
            pos[i as usize] = p;
        }
        // Keys never decrease along the schedule; one depth holds each body at most once.
        let keys: Vec<u32> = w.order.iter().map(|&i| w.key[i as usize]).collect();
        assert!(keys.windows(2).all(|k| k[0] <= k[1]));
        for d in 0..depths as u32 {
            let mut seen = vec![false; n + 1];
            for &i in w.order.iter().filter(|&&i| w.key[i as usize] / 3 == d) {
                for b in [r[i as usize].a, r[i as usize].b] {
                    assert!(!seen[b as usize], "body {b} twice at depth {d}");
                    seen[b as usize] = true;
                }
            }
        }
        assert!(keys.iter().any(|k| k % 3 == 2), "sliding contacts present");
        let mut sorted = w.order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..r.len() as u32).collect::<Vec<_>>());
        for (x, &i) in given.iter().enumerate() {
            for &j in &given[x + 1..] {
                let (ci, cj) = (&r[i as usize], &r[j as usize]);
                let share = [ci.a, ci.b].iter().any(|b| *b == cj.a || *b == cj.b);
                if share {
                    assert!(pos[i as usize] < pos[j as usize], "{i} before {j}");
                }
            }
        }
    }

    /// Ten sweeps in the wavefront schedule give the impulses and velocities of ten sweeps in
    /// the given order, bit for bit (statuses mixed: some contacts open, some sliding).
    #[test]
    fn wavefront_sweeps_equal_the_given_order_bit_for_bit() {
        let n = 60;
        let mut a = rows(n);
        warm(&mut a);
        let inv = inverse(n);
        let mut va = velocities(n);
        let (mut b, mut vb) = (a.clone(), va.clone());
        // A scrambled given order: k ↦ 7919 k mod m, a permutation (7919 is a prime not
        // dividing m).
        let m = a.len() as u32;
        assert_ne!(m % 7919, 0);
        let given: Vec<u32> = (0..m).map(|k| (7919 * k) % m).collect();
        let mut w = Wavefront::default();
        w.build(&b, &given, n + 1);
        assert_ne!(w.order, given, "the schedule reorders");
        for _ in 0..10 {
            sweep(&mut a, &given, &mut va, &inv, 1.0);
            sweep(&mut b, &w.order, &mut vb, &inv, 1.0);
        }
        assert_eq!(bits(&a, &va), bits(&b, &vb));
        let moved = a.iter().filter(|c| c.r != [0.0, 0.0]).count();
        assert!(moved > a.len() / 4, "{moved} contacts carry an impulse");
    }

    /// `solver::solve` in natural order returns the impulses and velocities of plain sweeps in
    /// the given order, bit for bit: eight sweeps, no acceleration, the error evaluated after
    /// each and the best iterate returned (the drive's rule for a solve that does not converge).
    #[test]
    fn solve_in_natural_order_equals_sweeps_in_the_given_order() {
        use crate::fc::SolverMethod;
        use crate::solver::{
            apply_impulses, error_measure, free_velocity_norms, solve, SolverParams, SolverWork,
            SweepOrder,
        };
        let n = 60;
        let mut rows0 = rows(n);
        warm(&mut rows0);
        let inv = inverse(n);
        let v_free = velocities(n);
        let q_norms = free_velocity_norms(&rows0, &v_free);
        let q_norm = q_norms[0];
        let mut given: Vec<u32> = (0..rows0.len() as u32).collect();
        given.reverse();
        let sweeps = 8;
        // Reference: plain sweeps in the given order, the best iterate kept.
        let mut a = rows0.clone();
        let mut va = v_free.clone();
        apply_impulses(&a, &mut va, &inv);
        let mut best = (error_measure(&a, &va, q_norm), a.clone());
        let mut last = best.0;
        for _ in 0..sweeps {
            sweep(&mut a, &given, &mut va, &inv, 1.0);
            last = error_measure(&a, &va, q_norm);
            if last < best.0 {
                best = (last, a.clone());
            }
        }
        if best.0 < last {
            a = best.1;
            va.copy_from_slice(&v_free);
            apply_impulses(&a, &mut va, &inv);
        }
        // The engine's solve, scheduled.
        let mut b = rows0.clone();
        let mut vb = v_free.clone();
        apply_impulses(&b, &mut vb, &inv);
        let params = SolverParams {
            tolerance: 1e-300,
            max_iterations: sweeps,
            anderson_memory: 0,
            method: SolverMethod::Nlgs,
            ..SolverParams::default()
        };
        let mut order = given.clone();
        let report = solve(
            &mut b,
            SweepOrder::Natural(&mut order),
            &mut vb,
            &v_free,
            &inv,
            q_norms,
            f64::INFINITY,
            &params,
            &mut SolverWork::default(),
            None,
        );
        assert_eq!(report.iterations, sweeps);
        assert!(!report.converged);
        assert_eq!(bits(&a, &va), bits(&b, &vb));
        assert_eq!(
            report.error.to_bits(),
            error_measure(&a, &va, q_norm).to_bits()
        );
    }
}
