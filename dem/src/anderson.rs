//! Anderson acceleration (type II) of a fixed-point iteration `x ← G(x)`.
//!
//! With residuals `f_k = G(x_k) − x_k` and the last `m` differences `ΔF_j = f_{j+1} − f_j`,
//! `ΔG_j = G(x_{j+1}) − G(x_j)`, the next iterate is
//!
//! ```text
//! γ = argmin_γ ‖f_k − ΔF γ‖₂,      x_{k+1} = G(x_k) − ΔG γ
//! ```
//!
//! On an affine map this is equivalent to GMRES; Gauss–Seidel over contacts is affine once the
//! contact statuses (open / stick / slide) stop changing, which is where its slow linear tail is.
//! The least-squares problem is solved through its regularised normal equations
//! (`(ΔFᵀΔF + λ I) γ = ΔFᵀ f`, `λ = 1e-12 · max diag`), the Gram matrix being updated by one
//! column per step: O(m · len) per step in two passes over the vectors, no allocation after
//! construction. Both passes run over fixed chunks on the rayon pool (same bits on any thread
//! count).

use rayon::prelude::*;

use crate::parallel::{runs_inline, MIN_CHUNKS_PER_TASK};

/// Anderson acceleration state for vectors of a fixed length.
#[derive(Debug, Clone)]
pub struct Anderson {
    m: usize,
    len: usize,
    df: Vec<Vec<f64>>,
    dg: Vec<Vec<f64>>,
    f_prev: Vec<f64>,
    g_prev: Vec<f64>,
    gram: Vec<f64>,
    count: usize,
    next: usize,
    has_prev: bool,
    // small dense workspace
    a: Vec<f64>,
    b: Vec<f64>,
    old: Vec<usize>,
    gram_j: Vec<f64>,
    rhs: Vec<f64>,
    partials: Vec<f64>,
    slots: Vec<usize>,
}

/// Entries per chunk of the parallel passes; the partial sums of the chunks are added in chunk
/// order, so the result does not depend on the number of threads.
const CHUNK: usize = 2 * crate::parallel::CHUNK;

impl Anderson {
    /// Acceleration with memory `m ≥ 1` for vectors of length `len`.
    pub fn new(m: usize, len: usize) -> Self {
        let m = m.max(1);
        Self {
            m,
            len,
            df: vec![vec![0.0; len]; m],
            dg: vec![vec![0.0; len]; m],
            f_prev: vec![0.0; len],
            g_prev: vec![0.0; len],
            gram: vec![0.0; m * m],
            count: 0,
            next: 0,
            has_prev: false,
            a: vec![0.0; m * m],
            b: vec![0.0; m],
            old: Vec::with_capacity(m),
            gram_j: vec![0.0; m],
            rhs: vec![0.0; m],
            partials: Vec::new(),
            slots: Vec::with_capacity(m),
        }
    }

    /// Forgets the history and takes vectors of length `len` from now on, keeping the
    /// buffers: the same as [`Anderson::new`] with the same memory (nothing of the old history
    /// is read again: every entry is written before it is read), without allocating once the
    /// buffers have grown to the largest length met (the contact count of a step changes from
    /// step to step).
    pub fn reset_to_length(&mut self, len: usize) {
        if len != self.len {
            for v in self.df.iter_mut().chain(self.dg.iter_mut()) {
                v.resize(len, 0.0);
            }
            self.f_prev.resize(len, 0.0);
            self.g_prev.resize(len, 0.0);
            self.len = len;
        }
        self.reset();
    }

    /// Forgets the history (after a change of regime, or when the step was rejected).
    pub fn reset(&mut self) {
        self.count = 0;
        self.next = 0;
        self.has_prev = false;
    }

    /// Given the previous iterate `x` and `g = G(x)` (in place), replaces `g` by the accelerated
    /// iterate `x_{k+1}`.
    ///
    /// Two passes over the vectors: one computes the new differences, the new Gram row and the
    /// right-hand side `ΔFᵀ f` chunk by chunk (each stored vector read once), one applies the
    /// combination.
    pub fn step(&mut self, x: &[f64], g: &mut [f64]) {
        debug_assert_eq!(x.len(), self.len);
        debug_assert_eq!(g.len(), self.len);
        if !self.has_prev {
            for (((fp, gp), &gi), &xi) in self
                .f_prev
                .iter_mut()
                .zip(self.g_prev.iter_mut())
                .zip(g.iter())
                .zip(x)
            {
                *fp = gi - xi;
                *gp = gi;
            }
            self.has_prev = true;
            return;
        }
        let m = self.m;
        let j = self.next;
        // Stored columns that survive (the slot j is overwritten when the memory is full).
        let mut old = std::mem::take(&mut self.old);
        old.clear();
        for p in 0..self.count {
            let s = self.slot(p);
            if s != j {
                old.push(s);
            }
        }
        let mut dfj = std::mem::take(&mut self.df[j]);
        let mut dgj = std::mem::take(&mut self.dg[j]);
        let mut gram_j = std::mem::take(&mut self.gram_j);
        let mut rhs = std::mem::take(&mut self.rhs);
        let mut partials = std::mem::take(&mut self.partials);
        partials.clear();
        partials.resize(self.len.div_ceil(CHUNK) * 2 * m, 0.0);
        {
            let (df, old) = (&self.df, &old);
            type Item<'v> = (
                usize,
                (
                    (
                        ((&'v mut [f64], &'v mut [f64]), &'v mut [f64]),
                        &'v mut [f64],
                    ),
                    &'v mut [f64],
                ),
            );
            let pass = |(ci, ((((dfc, dgc), fpc), gpc), part)): Item| {
                let r = ci * CHUNK..ci * CHUNK + dfc.len();
                for ((((dfi, dgi), (&gi, &xi)), fp), gp) in dfc
                    .iter_mut()
                    .zip(dgc.iter_mut())
                    .zip(g[r.clone()].iter().zip(&x[r.clone()]))
                    .zip(fpc.iter_mut())
                    .zip(gpc.iter_mut())
                {
                    let f = gi - xi;
                    *dfi = f - *fp;
                    *dgi = gi - *gp;
                    *fp = f;
                    *gp = gi;
                }
                part[j] = dot(dfc, dfc);
                part[m + j] = dot(dfc, fpc);
                for &k in old {
                    let dk = &df[k][r.clone()];
                    part[k] = dot(dfc, dk);
                    part[m + k] = dot(dk, fpc);
                }
            };
            if runs_inline(self.len.div_ceil(CHUNK)) {
                dfj.chunks_mut(CHUNK)
                    .zip(dgj.chunks_mut(CHUNK))
                    .zip(self.f_prev.chunks_mut(CHUNK))
                    .zip(self.g_prev.chunks_mut(CHUNK))
                    .zip(partials.chunks_mut(2 * m))
                    .enumerate()
                    .for_each(pass);
            } else {
                dfj.par_chunks_mut(CHUNK)
                    .zip(dgj.par_chunks_mut(CHUNK))
                    .zip(self.f_prev.par_chunks_mut(CHUNK))
                    .zip(self.g_prev.par_chunks_mut(CHUNK))
                    .zip(partials.par_chunks_mut(2 * m))
                    .with_min_len(MIN_CHUNKS_PER_TASK)
                    .enumerate()
                    .for_each(pass);
            }
        }
        // Partial sums added in chunk order: the same bits on any number of threads.
        gram_j.iter_mut().for_each(|v| *v = 0.0);
        rhs.iter_mut().for_each(|v| *v = 0.0);
        for part in partials.chunks_exact(2 * m) {
            for &k in old.iter().chain(std::iter::once(&j)) {
                gram_j[k] += part[k];
                rhs[k] += part[m + k];
            }
        }
        self.partials = partials;
        self.df[j] = dfj;
        self.dg[j] = dgj;
        for &k in old.iter().chain(std::iter::once(&j)) {
            self.gram[j * m + k] = gram_j[k];
            self.gram[k * m + j] = gram_j[k];
        }
        self.old = old;
        self.gram_j = gram_j;
        self.rhs = rhs;
        self.count = (self.count + 1).min(m);
        self.next = (self.next + 1) % m;
        self.mix(g);
    }

    /// The second pass of [`Anderson::step`]: solves the normal equations on the stored
    /// columns (regularised by `10⁻¹²` of their largest diagonal; a singular system resets the
    /// memory) and replaces `g` by `g − ΔG γ`.
    fn mix(&mut self, g: &mut [f64]) {
        let m = self.m;
        let c = self.count;
        // Normal equations on the c stored columns (slots in insertion order).
        let mut maxd = 0.0f64;
        for p in 0..c {
            let sp = self.slot(p);
            self.b[p] = self.rhs[sp];
            for q in 0..c {
                let sq = self.slot(q);
                self.a[p * c + q] = self.gram[sp * m + sq];
            }
            maxd = maxd.max(self.a[p * c + p]);
        }
        if maxd.is_nan() || maxd <= 0.0 {
            return;
        }
        for p in 0..c {
            self.a[p * c + p] += 1e-12 * maxd;
        }
        if !solve_dense(&mut self.a[..c * c], &mut self.b[..c], c) {
            self.reset();
            return;
        }
        // g −= ΔG γ, chunk by chunk over all columns.
        let mut slots = std::mem::take(&mut self.slots);
        slots.clear();
        slots.extend((0..c).map(|p| self.slot(p)));
        let (dg, gamma) = (&self.dg, &self.b[..c]);
        let combine = |(ci, gc): (usize, &mut [f64])| {
            let start = ci * CHUNK;
            for (p, &gam) in gamma.iter().enumerate() {
                let dgp = &dg[slots[p]][start..start + gc.len()];
                for (gi, &a) in gc.iter_mut().zip(dgp) {
                    *gi -= gam * a;
                }
            }
        };
        if runs_inline(self.len.div_ceil(CHUNK)) {
            g.chunks_mut(CHUNK).enumerate().for_each(combine);
        } else {
            g.par_chunks_mut(CHUNK)
                .with_min_len(MIN_CHUNKS_PER_TASK)
                .enumerate()
                .for_each(combine);
        }
        self.slots = slots;
    }

    /// Slot of the p-th stored column (oldest first).
    fn slot(&self, p: usize) -> usize {
        (self.next + self.m - self.count + p) % self.m
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut s = [0.0f64; 4];
    let mut ia = a.chunks_exact(4);
    let mut ib = b.chunks_exact(4);
    for (x, y) in (&mut ia).zip(&mut ib) {
        s[0] += x[0] * y[0];
        s[1] += x[1] * y[1];
        s[2] += x[2] * y[2];
        s[3] += x[3] * y[3];
    }
    let mut t = (s[0] + s[1]) + (s[2] + s[3]);
    for (x, y) in ia.remainder().iter().zip(ib.remainder()) {
        t += x * y;
    }
    t
}

/// Gaussian elimination with partial pivoting on the `n × n` row-major `a`; solution in `b`.
/// Returns false if the matrix is numerically singular.
fn solve_dense(a: &mut [f64], b: &mut [f64], n: usize) -> bool {
    for k in 0..n {
        let (mut piv, mut best) = (k, a[k * n + k].abs());
        for i in k + 1..n {
            if a[i * n + k].abs() > best {
                best = a[i * n + k].abs();
                piv = i;
            }
        }
        if best.is_nan() || best <= 0.0 {
            return false;
        }
        if piv != k {
            for j in 0..n {
                a.swap(k * n + j, piv * n + j);
            }
            b.swap(k, piv);
        }
        for i in k + 1..n {
            let f = a[i * n + k] / a[k * n + k];
            for j in k..n {
                a[i * n + j] -= f * a[k * n + j];
            }
            b[i] -= f * b[k];
        }
    }
    for k in (0..n).rev() {
        let mut s = b[k];
        for j in k + 1..n {
            s -= a[k * n + j] * b[j];
        }
        b[k] = s / a[k * n + k];
    }
    b.iter().all(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mixes 12 iterates of the affine map `x ← A x + b` (a fixed 3-term recurrence) of
    /// length `len`, from `x = 0`, and returns the mixed iterates' bits.
    fn mix(acc: &mut Anderson, len: usize) -> Vec<u64> {
        let mut x = vec![0.0; len];
        let mut out = Vec::new();
        for _ in 0..12 {
            let mut g: Vec<f64> = (0..len)
                .map(|i| {
                    let l = if i > 0 { x[i - 1] } else { 0.0 };
                    let r = if i + 1 < len { x[i + 1] } else { 0.0 };
                    0.45 * (l + r) + 1.0 + 0.1 * (i % 7) as f64
                })
                .collect();
            acc.step(&x, &mut g);
            out.extend(g.iter().map(|v| v.to_bits()));
            x = g;
        }
        out
    }

    /// A history reset to another length gives the same iterates as a new one, bit for bit,
    /// shorter or longer than the vectors it held (stale entries are never read).
    #[test]
    fn a_history_reset_to_a_length_mixes_as_a_new_one() {
        for (first, then) in [(5000, 3000), (3000, 5000), (4096, 4096)] {
            let mut reused = Anderson::new(4, first);
            mix(&mut reused, first);
            reused.reset_to_length(then);
            assert_eq!(
                mix(&mut reused, then),
                mix(&mut Anderson::new(4, then), then)
            );
        }
    }
}
