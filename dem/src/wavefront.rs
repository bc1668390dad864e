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
//! bit. Built by a counting sort, O(n + bodies), once a solve.
//!
//! Walls are bodies like any other here (their velocities are written back by the updates,
//! unchanged but for the sign of a zero), so the contacts on one wall keep their order.
//!
//! The idea is the level scheduling of sparse triangular solves (E. Anderson and Y. Saad,
//! *Solving sparse triangular linear systems on parallel computers*, Int. J. High Speed
//! Computing 1 (1989) 73–95), used here for instruction-level parallelism on one core.

use crate::contact::ContactRow;

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
        let mut depths = 0u32;
        for &i in given {
            let c = &rows[i as usize];
            let (a, b) = (c.a as usize, c.b as usize);
            let d = self.depth[a].max(self.depth[b]);
            self.depth[a] = d + 1;
            self.depth[b] = d + 1;
            depths = depths.max(d + 1);
            let status = if c.r[0] <= 0.0 {
                0
            } else if c.r[1].abs() < c.mu * c.r[0] {
                1
            } else {
                2
            };
            self.key[i as usize] = 3 * d + status;
        }
        self.start.clear();
        self.start.resize(3 * depths as usize + 1, 0);
        for &i in given {
            self.start[self.key[i as usize] as usize + 1] += 1;
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
    use crate::solver::sweep;

    /// A ring of disks `0–1–2–…–0` with contacts between neighbours, plus contacts of every
    /// fourth disk on a wall (body `n`).
    fn rows(n: usize) -> Vec<ContactRow> {
        let mut rows = Vec::new();
        let mut lcg = 12345u64;
        let mut next = || {
            lcg = lcg
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((lcg >> 11) as f64) / ((1u64 << 53) as f64)
        };
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

    fn inverse(n: usize) -> Vec<[f64; 3]> {
        let mut inv = vec![[1.0, 1.0, 3.0]; n];
        inv.push([0.0; 3]);
        inv
    }

    /// Contacts of one depth share no body; contacts sharing a body keep their given order.
    #[test]
    fn schedule_is_a_topological_order_with_independent_depths() {
        let n = 40;
        let r = rows(n);
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
        let inv = inverse(n);
        let mut va: Vec<[f64; 3]> = (0..=n)
            .map(|i| {
                if i == n {
                    [0.0; 3]
                } else {
                    let x = i as f64;
                    [
                        (0.7 * x).sin(),
                        (1.3 * x).cos() - 0.5,
                        0.1 * (2.1 * x).sin(),
                    ]
                }
            })
            .collect();
        // Warm impulses on half of the contacts, for a status mix at the build.
        for (k, c) in a.iter_mut().enumerate() {
            if k % 2 == 0 {
                c.r = [0.01 * (k % 7) as f64, 0.004 * ((k % 5) as f64 - 2.0)];
            }
        }
        let mut b = a.clone();
        let mut vb = va.clone();
        // A scrambled given order (a shuffle by the LCG of `rows`'s kind).
        let mut given: Vec<u32> = (0..a.len() as u32).collect();
        let mut state = 99u64;
        for i in (1..given.len()).rev() {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            given.swap(i, ((state >> 33) as usize) % (i + 1));
        }
        let mut w = Wavefront::default();
        w.build(&b, &given, n + 1);
        assert_ne!(w.order, given, "the schedule reorders");
        for _ in 0..10 {
            sweep(&mut a, &given, &mut va, &inv, 1.0);
            sweep(&mut b, &w.order, &mut vb, &inv, 1.0);
        }
        let bits = |rows: &[ContactRow], v: &[[f64; 3]]| -> Vec<u64> {
            rows.iter()
                .flat_map(|c| c.r)
                .chain(v.iter().flatten().copied())
                .map(f64::to_bits)
                .collect()
        };
        assert_eq!(bits(&a, &va), bits(&b, &vb));
        let moved = a.iter().filter(|c| c.r != [0.0, 0.0]).count();
        assert!(moved > a.len() / 4, "{moved} contacts carry an impulse");
    }
}
