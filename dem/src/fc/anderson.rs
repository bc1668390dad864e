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
//! column per step: O(m · len) per step, no allocation after construction.

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
}

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
        }
    }

    /// Forgets the history (after a change of regime, or when the step was rejected).
    pub fn reset(&mut self) {
        self.count = 0;
        self.next = 0;
        self.has_prev = false;
    }

    /// Given the previous iterate `x` and `g = G(x)` (in place), replaces `g` by the accelerated
    /// iterate `x_{k+1}`.
    pub fn step(&mut self, x: &[f64], g: &mut [f64]) {
        debug_assert_eq!(x.len(), self.len);
        debug_assert_eq!(g.len(), self.len);
        if self.has_prev {
            let j = self.next;
            {
                let (dfj, dgj) = (&mut self.df[j], &mut self.dg[j]);
                for ((((dfi, dgi), (&gi, &xi)), fp), gp) in dfj
                    .iter_mut()
                    .zip(dgj.iter_mut())
                    .zip(g.iter().zip(x))
                    .zip(self.f_prev.iter_mut())
                    .zip(self.g_prev.iter_mut())
                {
                    let f = gi - xi;
                    *dfi = f - *fp;
                    *dgi = gi - *gp;
                    *fp = f;
                    *gp = gi;
                }
            }
            self.count = (self.count + 1).min(self.m);
            self.next = (self.next + 1) % self.m;
            // Update row/column j of the Gram matrix.
            for k in 0..self.count {
                let kk = self.slot(k);
                let d = dot(&self.df[j], &self.df[kk]);
                self.gram[j * self.m + kk] = d;
                self.gram[kk * self.m + j] = d;
            }
        } else {
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
        }
        self.has_prev = true;
        let c = self.count;
        if c == 0 {
            return;
        }
        // Normal equations on the c stored columns (slots in insertion order).
        let mut maxd = 0.0f64;
        for p in 0..c {
            let sp = self.slot(p);
            self.b[p] = dot(&self.df[sp], &self.f_prev);
            for q in 0..c {
                let sq = self.slot(q);
                self.a[p * c + q] = self.gram[sp * self.m + sq];
            }
            maxd = maxd.max(self.a[p * c + p]);
        }
        if !(maxd > 0.0) {
            return;
        }
        for p in 0..c {
            self.a[p * c + p] += 1e-12 * maxd;
        }
        if !solve_dense(&mut self.a[..c * c], &mut self.b[..c], c) {
            self.reset();
            return;
        }
        // g −= ΔG γ, two columns per pass.
        let mut p = 0;
        while p + 1 < c {
            let (s0, s1) = (self.slot(p), self.slot(p + 1));
            let (g0, g1) = (self.b[p], self.b[p + 1]);
            for ((gi, &a), &b) in g.iter_mut().zip(&self.dg[s0]).zip(&self.dg[s1]) {
                *gi -= g0 * a + g1 * b;
            }
            p += 2;
        }
        if p < c {
            let s0 = self.slot(p);
            let g0 = self.b[p];
            for (gi, &a) in g.iter_mut().zip(&self.dg[s0]) {
                *gi -= g0 * a;
            }
        }
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
        if !(best > 0.0) {
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
