//! Nonlinear block Gauss–Seidel (NSGS) over contacts with the exact local solver, accelerated
//! by safeguarded Anderson mixing.
//!
//! **Sweep.** For contact α, with all other impulses fixed,
//!
//! ```text
//! q̃_α = q_α + Σ_{β≠α} W_αβ r_β + K_α r_α,      r_α ← cone_α.solve_local(S_α, q̃_α)
//! ```
//!
//! where `W_αα = S_α + K_α` (symmetric part `S_α`, a [`Delassus2`], and skew part `K_α`, zero
//! for a symmetric W and lagged by one sweep otherwise) and `cone_α` the contact's friction cone
//! ([`FcProblem::cone`], a [`ProblemCone`]). The plane cone's `solve_local` returns the fixed
//! point of the bipotential predictor–corrector for the 2×2 block, so each update solves its
//! contact exactly. With over-relaxation `ω ≠ 1`, `r_α ← proj_K((1 − ω) r_α^old + ω r_α^local)`,
//! which keeps `r_α` in the Coulomb cone. The update is the sweep's one,
//! [`crate::sweep::solve_row`] ([`crate::cone::relaxed_local_solve`] written against
//! [`crate::cone::FrictionCone`]), on the row's view of the problem (`ProblemRow`). The row of
//! W is recomputed at each update (block CSR in sweep order, diagonal blocks apart): cost
//! proportional to the row's block count, no allocation in the loop.
//!
//! **Acceleration.** Once the contact statuses stop changing, one sweep is an affine map and
//! Gauss–Seidel converges linearly and slowly (the weight of a pile has to diffuse through the
//! network). [`Acceleration::Anderson`] mixes the last `m` sweeps ([`crate::anderson`]), which on
//! an affine map is GMRES. It is safeguarded: the true error is evaluated every
//! `check_every` sweeps; if it has not dropped by a factor 0.7 over a window of 60 sweeps, the
//! history is cleared and plain sweeps are done for 32 sweeps (doubling at each new stagnation),
//! and if it ever becomes non-finite or 10³ times the best error, the best iterate is restored.
//! The worst case is therefore plain Gauss–Seidel plus bounded overhead. The iteration, the
//! mixing and the safeguard are the driver shared with the engine's solver,
//! [`crate::nlgs::drive`]; this module supplies the sweep over the permuted block-CSR copy of
//! `W` and the error evaluation ([`crate::nlgs::SweepProblem`]).
//!
//! **Stopping.** The error measure of [`super::measure`] is evaluated exactly (a full
//! `u = W r + q`): every `check_every` sweeps, and earlier when the sweep's relative impulse
//! change, scaled by the error / change ratio seen at the last evaluation, predicts convergence
//! ([`crate::nlgs::CheckSchedule::Every`]). The returned error is always the true error at the
//! returned `r`.

use std::time::Instant;

use super::error::FcError;
use super::ordering::{contact_order, ContactOrdering};
use super::problem::{FcProblem, ProblemCone, LOW_RANK};
use crate::cone::FrictionCone;
use crate::local::Delassus2;
use crate::nlgs::{drive, CheckSchedule, DriveParams, DriveWork, SweepProblem};
use crate::sweep::{solve_row, SweepRow};

/// Acceleration of the Gauss–Seidel sweeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Acceleration {
    /// Plain nonlinear Gauss–Seidel (Siconos' NSGS).
    None,
    /// Safeguarded Anderson mixing of the last `memory` sweeps (see the module docs).
    Anderson {
        /// Number of past sweeps mixed (4 by default).
        memory: usize,
    },
}

impl Default for Acceleration {
    fn default() -> Self {
        Acceleration::Anderson { memory: 4 }
    }
}

/// Options of [`solve`].
#[derive(Debug, Clone)]
pub struct FcOptions {
    /// Stop when the error measure is at most this (default 1e-6).
    pub tolerance: f64,
    /// Maximum number of sweeps (default 100 000).
    pub max_iterations: usize,
    /// Initial impulses `r` (N·s, length 2 nc, interleaved `(n, t)`), e.g. the previous step's
    /// solution (warm start); `None` starts from `r = 0`.
    pub initial_guess: Option<Vec<f64>>,
    /// Contact order of the sweeps (default [`ContactOrdering::LoadFront`]).
    pub ordering: ContactOrdering,
    /// Over-relaxation factor ω ∈ (0, 2) (default 1: none). Values near 1.8 speed up plain
    /// Gauss–Seidel on static piles but make it stall on flows; with Anderson keep 1.
    pub omega: f64,
    /// Acceleration (default Anderson with memory 4).
    pub acceleration: Acceleration,
    /// Evaluate the true error at least every this many sweeps (default 10).
    pub check_every: usize,
}

impl Default for FcOptions {
    fn default() -> Self {
        Self {
            tolerance: 1e-6,
            max_iterations: 100_000,
            initial_guess: None,
            ordering: ContactOrdering::default(),
            omega: 1.0,
            acceleration: Acceleration::default(),
            check_every: 10,
        }
    }
}

/// Result of [`solve`]. `error` is the true error measure at the returned `r` (not an estimate).
#[derive(Debug, Clone, PartialEq)]
pub struct FcSolution {
    /// Impulses `r` (N·s), interleaved `(r_n, r_t)` per contact, in the input's contact order;
    /// every `r_α` lies in its Coulomb cone.
    pub r: Vec<f64>,
    /// Velocities `u = W r + q` (m/s), interleaved `(u_n, u_t)`.
    pub u: Vec<f64>,
    /// Gauss–Seidel sweeps done (one sweep updates every contact once).
    pub iterations: usize,
    /// Error measure `‖r − proj_K(r − ū)‖ / max(‖q‖, ‖r‖, ‖u‖)` at `r`.
    pub error: f64,
    /// Wall-clock seconds of the solve (ordering, copy into sweep order, sweeps, acceleration,
    /// error evaluations).
    pub seconds: f64,
    /// Whether `error ≤ tolerance` was reached within `max_iterations`. When it was not, `r` is
    /// the iterate with the smallest error seen.
    pub converged: bool,
}

/// A standalone problem as the NLGS driver ([`crate::nlgs::drive`]) sweeps it, the
/// counterpart of the engine's step (`crate::solver`): the problem copied into sweep order,
/// structure of arrays, off-diagonal blocks only.
struct FcSweeps {
    perm: Vec<u32>,
    row_ptr: Vec<u32>,
    col: Vec<u32>,
    val: Vec<[f64; 4]>,
    diag: Vec<Delassus2>,
    skew: Vec<f64>,
    cone: Vec<ProblemCone>,
    q: Vec<[f64; 2]>,
    r: Vec<[f64; 2]>,
    u: Vec<[f64; 2]>,
    /// Over-relaxation factor of [`SweepProblem::sweep`].
    omega: f64,
    /// The problem's low-rank term in sweep order (empty without one): `B_cκ` per contact,
    /// `m_κ`, and the current sums `s_κ = Σ_c B_cκ · r_c`, kept current by the sweep.
    lr_coef: Vec<[[f64; 2]; LOW_RANK]>,
    lr_m: [f64; LOW_RANK],
    lr_s: [f64; LOW_RANK],
}

impl FcSweeps {
    fn new(p: &FcProblem, ordering: ContactOrdering) -> Self {
        let n = p.contacts();
        let perm = contact_order(ordering, p.w(), p.q());
        // The sweep reads r through `inv` without bounds checks: perm must be a permutation.
        assert_eq!(perm.len(), n, "contact ordering is not a permutation");
        let mut inv = vec![u32::MAX; n];
        for (new, &old) in perm.iter().enumerate() {
            assert_eq!(
                inv[old as usize],
                u32::MAX,
                "contact ordering is not a permutation"
            );
            inv[old as usize] = new as u32;
        }
        let w = p.w();
        let mut row_ptr = Vec::with_capacity(n + 1);
        let mut col = Vec::with_capacity(w.nnz_blocks());
        let mut val = Vec::with_capacity(w.nnz_blocks());
        let mut diag = Vec::with_capacity(n);
        let mut skew = Vec::with_capacity(n);
        let mut cone = Vec::with_capacity(n);
        let mut q = Vec::with_capacity(n);
        let mut row: Vec<(u32, [f64; 4])> = Vec::new();
        row_ptr.push(0u32);
        for &old in &perm {
            let old = old as usize;
            row.clear();
            row.extend(
                w.row(old)
                    .filter(|(j, _)| *j != old)
                    .map(|(j, b)| (inv[j], *b)),
            );
            row.sort_unstable_by_key(|(j, _)| *j);
            for (j, b) in &row {
                col.push(*j);
                val.push(*b);
            }
            row_ptr.push(col.len() as u32);
            diag.push(p.delassus(old));
            skew.push(p.diagonal_skew(old));
            cone.push(p.cone(old));
            q.push([p.q()[2 * old], p.q()[2 * old + 1]]);
        }
        let (lr_coef, lr_m) = match p.low_rank() {
            Some(l) => (
                perm.iter().map(|&old| l.coef[old as usize]).collect(),
                l.compliance,
            ),
            None => (Vec::new(), [0.0; 3]),
        };
        Self {
            perm,
            row_ptr,
            col,
            val,
            diag,
            skew,
            cone,
            q,
            r: vec![[0.0; 2]; n],
            u: vec![[0.0; 2]; n],
            omega: 1.0,
            lr_coef,
            lr_m,
            lr_s: [0.0; 3],
        }
    }

    /// Sets the low-rank sums `s_κ` from the current impulses.
    fn refresh_low_rank(&mut self) {
        let mut s = [0.0; 3];
        for (c, r) in self.lr_coef.iter().zip(&self.r) {
            for (s, b) in s.iter_mut().zip(c) {
                *s += b[0] * r[0] + b[1] * r[1];
            }
        }
        self.lr_s = s;
    }

    /// The low-rank term's part of `u_α` from the other contacts,
    /// `Σ_κ m_κ B_ακ (s_κ − B_ακ · r_α)`, and `s` moved by `Δr_α` after an update.
    #[inline(always)]
    fn low_rank_q(&self, a: usize) -> [f64; 2] {
        let r = self.r[a];
        let mut x = [0.0; 2];
        for ((b, m), s) in self.lr_coef[a].iter().zip(self.lr_m).zip(self.lr_s) {
            let f = m * (s - (b[0] * r[0] + b[1] * r[1]));
            x[0] += b[0] * f;
            x[1] += b[1] * f;
        }
        x
    }

    /// `q_α + Σ_{β≠α} W_αβ r_β + K_α r_α`.
    #[inline(always)]
    fn local_q(&self, a: usize) -> [f64; 2] {
        let s = self.row_ptr[a] as usize;
        let e = self.row_ptr[a + 1] as usize;
        let ra = self.r[a];
        let k = self.skew[a];
        let q = self.q[a];
        // Two partial sums per component halve the dependency chain.
        let (mut x0, mut x1, mut y0, mut y1) = (q[0] + k * ra[1], q[1] - k * ra[0], 0.0, 0.0);
        let cols = &self.col[s..e];
        let vals = &self.val[s..e];
        let mut it = cols.chunks_exact(2).zip(vals.chunks_exact(2));
        for (c, w) in &mut it {
            // SAFETY: every column index is `inv[j] < n` (inverse of a permutation of 0..n, see
            // `FcSweeps::new`), and `self.r.len() == n`.
            let (rb, rc) = unsafe {
                (
                    *self.r.get_unchecked(c[0] as usize),
                    *self.r.get_unchecked(c[1] as usize),
                )
            };
            x0 += w[0][0] * rb[0] + w[0][1] * rb[1];
            x1 += w[0][2] * rb[0] + w[0][3] * rb[1];
            y0 += w[1][0] * rc[0] + w[1][1] * rc[1];
            y1 += w[1][2] * rc[0] + w[1][3] * rc[1];
        }
        if let (Some(&c), Some(w)) = (cols.last(), vals.last()) {
            if cols.len() % 2 == 1 {
                let rb = self.r[c as usize];
                x0 += w[0] * rb[0] + w[1] * rb[1];
                x1 += w[2] * rb[0] + w[3] * rb[1];
            }
        }
        [x0 + y0, x1 + y1]
    }

    /// One forward sweep with over-relaxation `omega`; returns `Σ_α |Δr_α|²`.
    fn relaxed_sweep(&mut self, omega: f64) -> f64 {
        let mut d = 0.0;
        let low_rank = !self.lr_coef.is_empty();
        for a in 0..self.r.len() {
            let rn = solve_row(&ProblemRow { sweeps: self, a }, (), omega);
            let old = self.r[a];
            self.r[a] = rn;
            let d0 = rn[0] - old[0];
            let d1 = rn[1] - old[1];
            if low_rank {
                for (s, b) in self.lr_s.iter_mut().zip(&self.lr_coef[a]) {
                    *s += b[0] * d0 + b[1] * d1;
                }
            }
            d += d0 * d0 + d1 * d1;
        }
        d
    }

    /// Recomputes `u = W r + q` and returns the error measure.
    fn evaluate(&mut self) -> f64 {
        let mut res2 = 0.0;
        let (mut q2, mut r2, mut u2) = (0.0, 0.0, 0.0);
        if !self.lr_coef.is_empty() {
            // Fresh sums: the sweeps' running ones drift by rounding.
            self.refresh_low_rank();
        }
        for a in 0..self.r.len() {
            let mut u = self.local_q(a);
            if !self.lr_coef.is_empty() {
                let x = self.low_rank_q(a);
                u[0] += x[0];
                u[1] += x[1];
            }
            let ra = self.r[a];
            // local_q has q_α, the off-diagonal blocks and the skew part K_α r_α; add S_α r_α.
            let s = self.diag[a].mul(ra);
            u[0] += s[0];
            u[1] += s[1];
            self.u[a] = u;
            let e = self.cone[a].natural_map_residual(ra, u);
            res2 += e[0] * e[0] + e[1] * e[1];
            let q = self.q[a];
            q2 += q[0] * q[0] + q[1] * q[1];
            r2 += ra[0] * ra[0] + ra[1] * ra[1];
            u2 += u[0] * u[0] + u[1] * u[1];
        }
        let scale = q2.max(r2).max(u2).sqrt();
        let res = res2.sqrt();
        if scale > f64::EPSILON {
            res / scale
        } else {
            res
        }
    }

    fn r_norm(&self) -> f64 {
        self.r
            .iter()
            .map(|r| r[0] * r[0] + r[1] * r[1])
            .sum::<f64>()
            .sqrt()
    }
}

/// Row `a` of a problem in sweep order as a Gauss–Seidel sweep sees it ([`SweepRow`]): its
/// cone and the symmetric part `S_α` of its diagonal block; its free velocity is
/// `q̃_α = q_α + Σ_{β≠α} W_αβ r_β + K_α r_α` (with the low-rank term's part from the other
/// contacts), read from the problem's current impulses.
struct ProblemRow<'a> {
    sweeps: &'a FcSweeps,
    a: usize,
}

impl SweepRow for ProblemRow<'_> {
    type Cone = ProblemCone;
    type Context = ();

    #[inline(always)]
    fn cone(&self) -> ProblemCone {
        self.sweeps.cone[self.a]
    }

    #[inline(always)]
    fn block(&self) -> &Delassus2 {
        &self.sweeps.diag[self.a]
    }

    #[inline(always)]
    fn impulse(&self) -> [f64; 2] {
        self.sweeps.r[self.a]
    }

    #[inline(always)]
    fn free_velocity(&self, (): ()) -> [f64; 2] {
        let mut q = self.sweeps.local_q(self.a);
        if !self.sweeps.lr_coef.is_empty() {
            let x = self.sweeps.low_rank_q(self.a);
            q[0] += x[0];
            q[1] += x[1];
        }
        q
    }
}

/// The problem in sweep order as [`drive`] sees it: the impulses are `r`; `u` is recomputed by
/// each error evaluation.
impl SweepProblem for FcSweeps {
    fn dim(&self) -> usize {
        2 * self.r.len()
    }

    /// One sweep; returns its relative impulse change `‖Δr‖ / ‖r‖`.
    fn sweep(&mut self) -> Option<f64> {
        let d2 = self.relaxed_sweep(self.omega);
        Some(d2.sqrt() / self.r_norm().max(f64::MIN_POSITIVE))
    }

    fn error(&mut self) -> f64 {
        self.evaluate()
    }

    fn save(&self, x: &mut [f64]) {
        x.copy_from_slice(self.r.as_flattened());
    }

    fn load(&mut self, x: &[f64]) {
        self.r.as_flattened_mut().copy_from_slice(x);
        if !self.lr_coef.is_empty() {
            self.refresh_low_rank();
        }
    }
}

/// Checks the options against the problem size.
fn validate(n: usize, options: &FcOptions) -> Result<(), FcError> {
    let bad = |name: &str, reason: String| {
        Err(FcError::Option {
            name: name.into(),
            reason,
        })
    };
    if options.tolerance.is_nan() || options.tolerance <= 0.0 {
        return bad("tolerance", format!("{} is not > 0", options.tolerance));
    }
    if !(options.omega > 0.0 && options.omega < 2.0) {
        return bad("omega", format!("{} is not in (0, 2)", options.omega));
    }
    if options.check_every == 0 {
        return bad("check_every", "must be at least 1".into());
    }
    if let Acceleration::Anderson { memory: 0 } = options.acceleration {
        return bad("acceleration", "Anderson memory must be at least 1".into());
    }
    if let Some(g) = &options.initial_guess {
        if g.len() != 2 * n {
            return bad(
                "initial_guess",
                format!("length {}, expected {}", g.len(), 2 * n),
            );
        }
        if let Some(i) = g.iter().position(|x| !x.is_finite()) {
            return bad("initial_guess", format!("entry {i} is not finite"));
        }
    }
    Ok(())
}

/// Solves `problem` by nonlinear block Gauss–Seidel with the exact local solver (see the module
/// documentation for the sweep, the acceleration and the stopping rule).
///
/// Never fails to return on a valid problem: non-convergence within `max_iterations` is reported
/// by `converged = false` (with the best iterate). Errors only on invalid options (initial guess
/// of the wrong length or not finite, tolerance not positive, ω outside (0, 2), zero
/// `check_every` or Anderson memory).
pub fn solve(problem: &FcProblem, options: &FcOptions) -> Result<FcSolution, FcError> {
    let n = problem.contacts();
    validate(n, options)?;
    let t0 = Instant::now();
    let mut ws = FcSweeps::new(problem, options.ordering);
    if let Some(g) = &options.initial_guess {
        for (new, &old) in ws.perm.iter().enumerate() {
            let old = old as usize;
            ws.r[new] = [g[2 * old], g[2 * old + 1]];
        }
    }
    ws.refresh_low_rank();
    ws.omega = options.omega;
    let memory = match options.acceleration {
        Acceleration::Anderson { memory } => memory,
        Acceleration::None => 0,
    };
    let report = drive(
        &mut ws,
        &DriveParams {
            tolerance: options.tolerance,
            max_sweeps: options.max_iterations,
            anderson_memory: memory,
            plain_sweeps: 0,
            schedule: CheckSchedule::Every(options.check_every),
            sweep_first: false,
        },
        &mut DriveWork::default(),
    );
    let mut r = vec![0.0; 2 * n];
    let mut u = vec![0.0; 2 * n];
    for (new, &old) in ws.perm.iter().enumerate() {
        let old = old as usize;
        r[2 * old..2 * old + 2].copy_from_slice(&ws.r[new]);
        u[2 * old..2 * old + 2].copy_from_slice(&ws.u[new]);
    }
    if !r.iter().chain(&u).all(|x| x.is_finite()) {
        return Err(FcError::Overflow);
    }
    Ok(FcSolution {
        r,
        u,
        iterations: report.iterations,
        error: report.error,
        seconds: t0.elapsed().as_secs_f64(),
        converged: report.converged,
    })
}

/// Contact updates per second of `sweeps` plain Gauss–Seidel sweeps (no acceleration, no error
/// evaluation) from `r = 0` on one core: the raw cost of one update, `nc · sweeps / seconds`.
pub fn sweep_rate(problem: &FcProblem, sweeps: usize) -> f64 {
    let mut ws = FcSweeps::new(problem, ContactOrdering::default());
    let t = Instant::now();
    let mut d = 0.0;
    for _ in 0..sweeps {
        d += ws.relaxed_sweep(1.0);
    }
    let s = t.elapsed().as_secs_f64();
    std::hint::black_box(d);
    (problem.contacts() * sweeps) as f64 / s.max(1e-12)
}
