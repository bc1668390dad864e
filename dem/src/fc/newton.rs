//! Semismooth Newton method on the Alart–Curnier function with a proximal regularisation, so
//! that it stays well posed when `W` is singular (hyperstatic packings), an Armijo line search,
//! and Gauss–Seidel sweeps when the line search fails.
//!
//! **2D only, by algorithm.** The linearisation below is written for the plane cone: per
//! contact a 2×2 generalised Jacobian of `Φ` over the interval `[−μ z_n⁺, μ z_n⁺]` (the plane
//! cone's tangential projection). A 3D contact's circular cone has a 3×3 Jacobian of the
//! second-order cone projection (Acary, Brémond & Huber 2018, §3.2), another module; this one
//! takes the plane cone's data (`μ`, the 2×2 blocks) directly, not through
//! [`crate::cone::FrictionCone`]. Its smoothing sweeps are the shared ones
//! ([`crate::fc::nsgs`], [`crate::sweep::solve_row`]).
//!
//! **Formulation** (Alart & Curnier 1991; the 2D form of Acary, Brémond & Huber 2018, §3.2).
//! With `u = W r + q` and per-contact weights `ρ_n = 1/W_nn`, `ρ_t = 1/W_tt`,
//!
//! ```text
//! z_n = r_n − ρ_n u_n,   z_t = r_t − ρ_t u_t
//! Φ_n(r) = r_n − max(0, z_n)
//! Φ_t(r) = r_t − proj_[−μ z_n⁺, μ z_n⁺](z_t)
//! ```
//!
//! `Φ(r) = 0` exactly when `(u, r)` satisfies Signorini and Coulomb's law, i.e. when `r ∈ K_μ`,
//! `ū = u + μ|u_t| n ∈ K_μ*`, `r · ū = 0` (the problem of [`super::problem::FcProblem`]). `Φ`
//! is piecewise affine in `r`; an element of its generalised Jacobian is
//! `J = D_r + D_u W` with, per contact (rows n, t; columns n, t):
//!
//! ```text
//! normal,     z_n > 0:          D_r = (0, 0),      D_u = (ρ_n, 0)
//! normal,     z_n ≤ 0:          D_r = (1, 0),      D_u = 0
//! tangential, z_n ≤ 0:          D_r = (0, 1),      D_u = 0
//!             |z_t| ≤ μ z_n:    D_r = (0, 0),      D_u = (0, ρ_t)             (sticking)
//!             otherwise, s = sign z_t:
//!                               D_r = (−μ s, 1),   D_u = (μ s ρ_n, 0)         (sliding)
//! ```
//!
//! **Proximal regularisation.** Where contacts stick, rows of `J` are rows of `ρ W`, and
//! `W = H M⁻¹ Hᵀ` is singular as soon as the packing is hyperstatic (more contact unknowns
//! than degrees of freedom): the plain Newton system has no solution and its solutions are not
//! isolated. Each iteration therefore takes one Newton step on the proximal problem centred at
//! the current iterate `r_k` (Rockafellar 1976; Siconos' `fc3d_proximal`; the proximal-point
//! variant of Acary, Brémond & Huber 2018, §5):
//!
//! ```text
//! u_η(r) = W r + q + η D (r − r_k),     D = diag(W_nn, W_tt) per contact
//! J_η = D_r + D_u (W + η D),           J_η d = −Φ(r_k),     r_{k+1} = r_k + t d
//! ```
//!
//! `W + η D` is positive definite, so `J_η` is invertible, and `d` is the exact Newton
//! direction of `ψ_η = ½‖Φ_η‖²` (at the centre `Φ_η = Φ`), hence a descent direction: the
//! Armijo rule `ψ_η(r_k + t d) ≤ (1 − 2σt) ψ(r_k)`, σ = 10⁻⁴, `t ∈ {1, ½, …, 2⁻¹⁰}`, always
//! has an answer in exact arithmetic. The weight adapts like a trust region: after a full step
//! `η ← η/4` (down to 10⁻¹⁰: the method becomes Newton's and converges superlinearly once the
//! contact statuses settle), after a shortened step `η ← 4η`, after a failed line search
//! `η ← 16η`, up to [`NewtonParams::eta_max`]. `J_η` is factorised by faer's sparse LU with
//! partial pivoting, supernodal, sequential (the symbolic analysis once per solve: the pattern
//! is that of `W`).
//!
//! **Fallback.** A failed line search at `η_max` (rounding, or an indefinite `W` read from a
//! file) is followed by [`NewtonParams::smoothing_sweeps`] sweeps of nonlinear Gauss–Seidel
//! ([`super::nsgs`]) from the current iterate, within the caller's sweep budget.
//!
//! **Active-set finish** ([`active_set_finish`]). When `auto` ends above its tolerance with an
//! iterate whose error is at most [`FINISH_MAX_ERROR`], the statuses are read from `r` alone
//! (open, sliding on the cone's edge, sticking) and the linear system they define is solved
//! once; the result is kept when its projection lowers the error. Where the statuses are those
//! of a solution this is exact (the slow-shear problem of `datasets/fc-problems/hard/`: from
//! 3.2·10⁻⁶ to 9·10⁻¹⁵); where the active set is nearly singular (the Janssen release) it is not
//! kept. `datasets/fc-problems/hard/README.md` has the measurements.
//!
//! **Stopping.** Every iterate is projected on the cones and its error measure
//! ([`super::measure`], `u = W r + q` recomputed from `r`) evaluated, together with an optional
//! acceptance test of the caller (the engine's approach speed); the solve stops at the first
//! projected iterate that passes, or returns the projected iterate of least error. The error
//! reported is always the true error of the impulses returned, which lie in their cones.
//!
//! **Behaviour.** From 100 Gauss–Seidel sweeps, every reference problem of `datasets/fc-problems`
//! reaches 10⁻⁸ (the 7002-contact granular flow in 35 iterations, where Gauss–Seidel stalls
//! near 10⁻⁹ after 10⁵ sweeps). Problems where many contacts sit on the stick–slip boundary
//! (a column sliding along frictional walls) converge only linearly, like the proximal-point
//! method they then are; the engine's `auto` mode hands them back to Gauss–Seidel after
//! [`NewtonParams::max_iterations`].

use std::time::Instant;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuSymbolicParams, NumericLu, SymbolicLu};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};
use serde::{Deserialize, Serialize};

use super::error::FcError;
use super::measure::error_given_velocity;
use super::nsgs::{self, FcOptions, FcSolution};
use super::problem::FcProblem;
use super::problem::LowRank;
use crate::local::project_on_cone;

/// Parameters of the Newton solver.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NewtonParams {
    /// Largest number of Newton iterations (factorisations) per solve.
    #[serde(default = "default_max_newton")]
    pub max_iterations: usize,
    /// Starting and largest proximal weight `η` (dimensionless: relative to the diagonal of
    /// `W`).
    #[serde(default = "default_eta_max")]
    pub eta_max: f64,
    /// Gauss–Seidel sweeps done when the line search fails.
    #[serde(default = "default_smoothing")]
    pub smoothing_sweeps: usize,
}

fn default_max_newton() -> usize {
    50
}
fn default_eta_max() -> f64 {
    1e-2
}
fn default_smoothing() -> usize {
    10
}

impl Default for NewtonParams {
    fn default() -> Self {
        Self {
            max_iterations: default_max_newton(),
            eta_max: default_eta_max(),
            smoothing_sweeps: default_smoothing(),
        }
    }
}

impl NewtonParams {
    /// Checks the parameters; the error names the key.
    pub fn validate(&self) -> Result<(), FcError> {
        let bad = |name: &str, reason: String| {
            Err(FcError::Option {
                name: name.into(),
                reason,
            })
        };
        if self.max_iterations == 0 {
            return bad("newton.max_iterations", "must be at least 1".into());
        }
        if !(self.eta_max > 0.0 && self.eta_max.is_finite()) {
            return bad(
                "newton.eta_max",
                format!("{} is not a finite number > 0", self.eta_max),
            );
        }
        Ok(())
    }
}

/// Smallest proximal weight η (relative to the diagonal of W).
const ETA_MIN: f64 = 1e-10;
/// Shift keeping the Newton matrix invertible where a diagonal block of W vanishes.
const EPSILON: f64 = 1e-12;
/// Armijo constant.
const SIGMA: f64 = 1e-4;
/// Smallest step length tried.
const T_MIN: f64 = 1.0 / 1024.0;

/// What a Newton solve did, besides the solution.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct NewtonStats {
    /// Newton iterations (one factorisation each).
    pub iterations: usize,
    /// Line searches that failed (each followed by smoothing sweeps).
    pub line_search_failures: usize,
    /// Gauss–Seidel sweeps done as smoothing.
    pub smoothing_sweeps: usize,
    /// Factorisations that failed (a structurally singular matrix; smoothing was done instead).
    pub singular: usize,
}

/// Reusable buffers of [`solve_with`]: the matrix `J_ηᵀ` in compressed columns (that is, `J_η`
/// by rows, the block-CSR order of `W`) and the vectors.
#[derive(Debug, Clone, Default)]
pub struct NewtonWork {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    val: Vec<f64>,
    /// Position in `val` of the four entries of block `k` of `W` (row n, then row t).
    block_pos: Vec<[usize; 2]>,
    /// Position in `val` of the diagonal entries `(nn, tt)` of each contact.
    diag_pos: Vec<[usize; 2]>,
    u: Vec<f64>,
    phi: Vec<f64>,
    d: Vec<f64>,
    trial: Vec<f64>,
    best: Vec<f64>,
}

impl NewtonWork {
    /// Builds the pattern of `J_η` from the block pattern of `W` (diagonal blocks added).
    fn pattern(&mut self, p: &FcProblem) {
        let w = p.w();
        let n = p.contacts();
        self.col_ptr.clear();
        self.row_idx.clear();
        self.block_pos.clear();
        self.block_pos.resize(w.nnz_blocks(), [usize::MAX; 2]);
        self.diag_pos.clear();
        self.diag_pos.resize(n, [usize::MAX; 2]);
        self.col_ptr.push(0);
        let mut cols: Vec<(usize, Option<usize>)> = Vec::new();
        for a in 0..n {
            cols.clear();
            let start = w.row_ptr()[a];
            for (k, (j, _)) in w.row(a).enumerate() {
                cols.push((j, Some(start + k)));
            }
            if !cols.iter().any(|(j, _)| *j == a) {
                let at = cols.partition_point(|(j, _)| *j < a);
                cols.insert(at, (a, None));
            }
            for row in 0..2 {
                for &(j, k) in &cols {
                    let at = self.row_idx.len();
                    if let Some(k) = k {
                        self.block_pos[k][row] = at;
                    }
                    if j == a {
                        self.diag_pos[a][row] = at + row;
                    }
                    self.row_idx.push(2 * j);
                    self.row_idx.push(2 * j + 1);
                }
                self.col_ptr.push(self.row_idx.len());
            }
        }
        self.val.clear();
        self.val.resize(self.row_idx.len(), 0.0);
    }
}

/// The diagonal `D = (W_nn, W_tt)` of each contact (negative rounding clipped to 0) and the
/// Alart–Curnier weights `ρ = 1/D` (1 where a diagonal entry vanishes).
fn scales(problem: &FcProblem) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let diag: Vec<[f64; 2]> = (0..problem.contacts())
        .map(|a| {
            let d = problem.delassus(a);
            [d.nn.max(0.0), d.tt.max(0.0)]
        })
        .collect();
    let rho = diag
        .iter()
        .map(|d| {
            let inv = |x: f64| if x > 0.0 { 1.0 / x } else { 1.0 };
            [inv(d[0]), inv(d[1])]
        })
        .collect();
    (diag, rho)
}

impl NewtonWork {
    /// Zeroes the per-iteration vectors for `n` contacts.
    fn reset(&mut self, n: usize) {
        for v in [&mut self.u, &mut self.phi, &mut self.d, &mut self.trial] {
            v.clear();
            v.resize(2 * n, 0.0);
        }
    }
}

/// The sparse LU of the Newton matrices of one solve: the symbolic analysis once (the pattern
/// is that of `W`), a numeric factorisation per direction.
#[derive(Default)]
struct NewtonLu {
    symbolic: Option<SymbolicLu<usize>>,
    numeric: NumericLu<usize, f64>,
    scratch: Option<MemBuffer>,
}

impl NewtonLu {
    /// Solves `J d = −Φ` into `work.d`, with `Φ` in `work.phi`, the velocities `work.u` at the
    /// current impulses and `J = D_r + D_u (W + η D) + ε I` (by rows, its transpose by
    /// columns), the per-contact `(D_r, D_u)` given by `lin(α, u)`. `Ok(false)` when the
    /// factorisation fails (a structurally singular matrix) or the direction is not finite.
    fn newton_direction(
        &mut self,
        problem: &FcProblem,
        work: &mut NewtonWork,
        diag: &[[f64; 2]],
        eta: f64,
        lin: impl Fn(usize, &[f64]) -> ([f64; 4], [f64; 4]),
    ) -> Result<bool, FcError> {
        let n = problem.contacts();
        if self.symbolic.is_none() {
            work.pattern(problem);
        }
        work.val.iter_mut().for_each(|v| *v = 0.0);
        let w = problem.w();
        for (a, &[dn, dt]) in diag.iter().enumerate().take(n) {
            let (dr, du) = lin(a, &work.u);
            let start = w.row_ptr()[a];
            for (k, (_, b)) in w.row(a).enumerate() {
                let pos = work.block_pos[start + k];
                work.val[pos[0]] += du[0] * b[0] + du[1] * b[2];
                work.val[pos[0] + 1] += du[0] * b[1] + du[1] * b[3];
                work.val[pos[1]] += du[2] * b[0] + du[3] * b[2];
                work.val[pos[1] + 1] += du[2] * b[1] + du[3] * b[3];
            }
            let [pn, pt] = work.diag_pos[a];
            work.val[pn] += dr[0] + du[0] * eta * dn + EPSILON;
            work.val[pn + 1] += dr[1] + du[1] * eta * dt;
            work.val[pt - 1] += dr[2] + du[2] * eta * dn;
            work.val[pt] += dr[3] + du[3] * eta * dt + EPSILON;
        }
        let sym =
            SymbolicSparseColMatRef::new_checked(2 * n, 2 * n, &work.col_ptr, None, &work.row_idx);
        if self.symbolic.is_none() {
            let params = LuSymbolicParams {
                // Supernodal: 2.3× faster than the simplicial one on 700-contact columns.
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            };
            let s = factorize_symbolic_lu(sym, params).map_err(|e| FcError::Option {
                name: "newton".into(),
                reason: format!("symbolic factorisation failed: {e:?}"),
            })?;
            let req = s
                .factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default())
                .or(s.solve_transpose_in_place_scratch::<f64>(1, Par::Seq));
            self.scratch = Some(MemBuffer::new(req));
            self.symbolic = Some(s);
        }
        let (Some(symbolic), Some(scratch)) = (self.symbolic.as_ref(), self.scratch.as_mut())
        else {
            return Ok(false);
        };
        let jt = SparseColMatRef::new(sym, &work.val);
        let Ok(lu) = symbolic.factorize_numeric_lu(
            &mut self.numeric,
            jt,
            Par::Seq,
            MemStack::new(scratch),
            Default::default(),
        ) else {
            return Ok(false);
        };
        for (d, f) in work.d.iter_mut().zip(&work.phi) {
            *d = -f;
        }
        let solve = |x: &mut [f64], scratch: &mut MemBuffer| {
            lu.solve_transpose_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(x, 2 * n, 1),
                Par::Seq,
                MemStack::new(scratch),
            )
        };
        solve(&mut work.d, scratch);
        if let Some(l) = problem.low_rank() {
            woodbury(l, &mut work.d, |a| lin(a, &work.u).1, |x| solve(x, scratch));
        }
        Ok(work.d.iter().all(|x| x.is_finite()))
    }
}

/// The Newton direction with a [`LowRank`] term `W_L = Σ_κ m_κ b_κ b_κᵀ` in `W`, by the
/// Sherman–Morrison–Woodbury identity: `J = A + P M Bᵀ` with `A` the matrix of the sparse part
/// (factorised), `P = D_u B` (`B = [b_κ]`, `M = diag m_κ`, over the components with `m_κ > 0`),
///
/// ```text
/// J⁻¹ y = A⁻¹y − A⁻¹P (M⁻¹ + Bᵀ A⁻¹ P)⁻¹ Bᵀ A⁻¹ y
/// ```
///
/// (Golub & Van Loan, *Matrix Computations*, 4th ed., §2.1.4): one solve with `A` per
/// component and a 3×3 system, instead of factorising the dense `2n × 2n` matrix the folded
/// term would make. `d` holds `A⁻¹y` on entry and `J⁻¹y` on return; `du(α)` is contact `α`'s
/// `D_u` (row-major 2×2) and `solve` applies `A⁻¹` in place.
fn woodbury(
    l: &LowRank,
    d: &mut [f64],
    du: impl Fn(usize) -> [f64; 4],
    mut solve: impl FnMut(&mut [f64]),
) {
    let comps: Vec<usize> = (0..3).filter(|&k| l.compliance[k] > 0.0).collect();
    let k = comps.len();
    if k == 0 {
        return;
    }
    let n2 = d.len();
    // Z = A⁻¹ P, column by column.
    let mut z = vec![vec![0.0; n2]; k];
    for (zc, &kappa) in z.iter_mut().zip(&comps) {
        for (a, (c, x)) in l.coef.iter().zip(zc.chunks_exact_mut(2)).enumerate() {
            let b = c[kappa];
            let m = du(a);
            x[0] = m[0] * b[0] + m[1] * b[1];
            x[1] = m[2] * b[0] + m[3] * b[1];
        }
        solve(zc);
    }
    // S = M⁻¹ + Bᵀ Z and the right-hand side Bᵀ A⁻¹ y.
    let bt = |kappa: usize, x: &[f64]| -> f64 {
        l.coef
            .iter()
            .zip(x.chunks_exact(2))
            .map(|(c, x)| c[kappa][0] * x[0] + c[kappa][1] * x[1])
            .sum()
    };
    let mut s = nalgebra::DMatrix::<f64>::zeros(k, k);
    let mut rhs = nalgebra::DVector::<f64>::zeros(k);
    for (i, &ki) in comps.iter().enumerate() {
        for (j, zc) in z.iter().enumerate() {
            s[(i, j)] = bt(ki, zc);
        }
        s[(i, i)] += 1.0 / l.compliance[ki];
        rhs[i] = bt(ki, d);
    }
    let Some(c) = s.lu().solve(&rhs) else {
        // A singular capacitance matrix: the direction is left non-finite for the caller.
        d.iter_mut().for_each(|x| *x = f64::NAN);
        return;
    };
    for (j, zc) in z.iter().enumerate() {
        for (x, zv) in d.iter_mut().zip(zc) {
            *x -= c[j] * zv;
        }
    }
}

/// Per-contact linearisation: `Φ_α` and the 2×2 matrices `D_r`, `D_u` (row-major).
#[inline]
fn linearise(r: [f64; 2], u: [f64; 2], mu: f64, rho: [f64; 2]) -> ([f64; 2], [f64; 4], [f64; 4]) {
    let zn = r[0] - rho[0] * u[0];
    let zt = r[1] - rho[1] * u[1];
    if zn <= 0.0 {
        return (r, [1.0, 0.0, 0.0, 1.0], [0.0; 4]);
    }
    let phi_n = rho[0] * u[0];
    let bound = mu * zn;
    if zt.abs() <= bound {
        ([phi_n, rho[1] * u[1]], [0.0; 4], [rho[0], 0.0, 0.0, rho[1]])
    } else {
        let s = zt.signum();
        (
            [phi_n, r[1] - s * bound],
            [0.0, 0.0, -mu * s, 1.0],
            [rho[0], 0.0, mu * s * rho[0], 0.0],
        )
    }
}

/// Solves `problem` by the proximal semismooth Newton method (module docs), from
/// `options.initial_guess` (or `r = 0`), to `options.tolerance` on the error measure.
/// `options.max_iterations` bounds the Gauss–Seidel smoothing sweeps in all.
pub fn solve(
    problem: &FcProblem,
    options: &FcOptions,
    params: &NewtonParams,
) -> Result<(FcSolution, NewtonStats), FcError> {
    let mut work = NewtonWork::default();
    solve_with(problem, options, params, &mut work, |_, _| true)
}

/// [`solve`] with caller-owned buffers and an extra acceptance test `accept(r, u)` that must
/// hold, besides the tolerance, for the solve to count as converged (the engine asks that no
/// closed contact still approaches).
pub fn solve_with(
    problem: &FcProblem,
    options: &FcOptions,
    params: &NewtonParams,
    work: &mut NewtonWork,
    accept: impl Fn(&[f64], &[f64]) -> bool,
) -> Result<(FcSolution, NewtonStats), FcError> {
    params.validate()?;
    problem.check_global()?;
    let n = problem.contacts();
    let t0 = Instant::now();
    let tol = options.tolerance;
    if tol.is_nan() || tol <= 0.0 {
        return Err(FcError::Option {
            name: "tolerance".into(),
            reason: format!("{tol} is not > 0"),
        });
    }
    let mut r = match &options.initial_guess {
        Some(g) if g.len() == 2 * n && g.iter().all(|x| x.is_finite()) => g.clone(),
        Some(g) => {
            return Err(FcError::Option {
                name: "initial_guess".into(),
                reason: format!(
                    "length {} (expected {}) or a value that is not finite",
                    g.len(),
                    2 * n
                ),
            })
        }
        None => vec![0.0; 2 * n],
    };
    let mut stats = NewtonStats::default();
    let (diag, rho) = scales(problem);
    work.reset(n);
    work.best.clear();
    work.best.extend_from_slice(&r);
    let mut u_step = vec![0.0; 2 * n];
    let mut best_error = f64::INFINITY;
    let mut eta = params.eta_max;
    let mut lu = NewtonLu::default();
    let mut sweeps_left = options.max_iterations;
    let smooth = |r: &mut Vec<f64>, sweeps: usize| -> Result<(), FcError> {
        let o = FcOptions {
            tolerance: tol,
            max_iterations: sweeps,
            initial_guess: Some(r.clone()),
            ..options.clone()
        };
        *r = nsgs::solve(problem, &o)?.r;
        Ok(())
    };

    loop {
        // Stop on the projection of the iterate on the cones (what is returned).
        let (pe, ok) = projected(problem, &r, &mut work.trial, &mut work.d, tol, &accept);
        if pe < best_error || ok {
            best_error = pe;
            work.best.copy_from_slice(&work.trial);
        }
        if ok || stats.iterations >= params.max_iterations {
            break;
        }
        stats.iterations += 1;
        // Φ at r (the proximal centre: u_η = u there).
        problem.mul_add(&r, problem.q(), &mut work.u);
        let psi = phi_of(problem, &rho, &r, &work.u, &mut work.phi);
        let solved = lu.newton_direction(problem, work, &diag, eta, |a, u| {
            let (_, dr, du) = linearise(
                [r[2 * a], r[2 * a + 1]],
                [u[2 * a], u[2 * a + 1]],
                problem.mu()[a],
                rho[a],
            );
            (dr, du)
        })?;
        if !solved {
            stats.singular += 1;
        }
        // Armijo on ψ_η(r + t d) = ½‖Φ_η‖², u_η = u + t (W + η D) d: d is its Newton direction.
        let mut t = 1.0;
        let mut accepted = false;
        if solved {
            work.trial.iter_mut().for_each(|x| *x = 0.0);
            problem.mul_add(&work.d, &work.trial, &mut u_step);
            for a in 0..n {
                u_step[2 * a] += eta * diag[a][0] * work.d[2 * a];
                u_step[2 * a + 1] += eta * diag[a][1] * work.d[2 * a + 1];
            }
            while t >= T_MIN {
                for ((x, r0), d) in work.trial.iter_mut().zip(&r).zip(&work.d) {
                    *x = r0 + t * d;
                }
                let mut s2 = 0.0;
                for (a, &mu) in problem.mu().iter().enumerate() {
                    let ua = [
                        work.u[2 * a] + t * u_step[2 * a],
                        work.u[2 * a + 1] + t * u_step[2 * a + 1],
                    ];
                    let (f, _, _) =
                        linearise([work.trial[2 * a], work.trial[2 * a + 1]], ua, mu, rho[a]);
                    s2 += f[0] * f[0] + f[1] * f[1];
                }
                if 0.5 * s2 <= (1.0 - 2.0 * SIGMA * t) * psi {
                    accepted = true;
                    break;
                }
                t *= 0.5;
            }
        }
        if accepted {
            std::mem::swap(&mut r, &mut work.trial);
            eta = if t == 1.0 {
                (eta * 0.25).max(ETA_MIN)
            } else {
                (eta * 4.0).min(params.eta_max)
            };
        } else {
            stats.line_search_failures += 1;
            if eta < params.eta_max {
                eta = (eta * 16.0).min(params.eta_max);
            } else {
                let sweeps = params.smoothing_sweeps.min(sweeps_left);
                if sweeps == 0 {
                    break;
                }
                smooth(&mut r, sweeps)?;
                sweeps_left -= sweeps;
                stats.smoothing_sweeps += sweeps;
            }
        }
    }
    // The best projected iterate (the last one when it converged), its velocity and error.
    r.copy_from_slice(&work.best);
    problem.mul_add(&r, problem.q(), &mut work.u);
    let error = error_given_velocity(problem.mu(), problem.q(), &r, &work.u);
    let converged = error <= tol && accept(&r, &work.u);
    let u = work.u.clone();
    Ok((
        FcSolution {
            r,
            u,
            iterations: stats.iterations,
            error,
            seconds: t0.elapsed().as_secs_f64(),
            converged,
        },
        stats,
    ))
}

/// Largest error measure from which [`active_set_finish`] is tried: above it the statuses read
/// from an iterate were not those of a solution on any problem of `datasets/fc-problems/hard/`
/// (from Gauss–Seidel iterates at 4.9·10⁻⁵ and 9.8·10⁻⁶ of the slow shear the solve left the
/// cones), and an engine step would pay a factorisation for nothing.
pub const FINISH_MAX_ERROR: f64 = 1e-5;

/// Whether [`active_set_finish`] is tried from an iterate of error `error_now`: a finite error
/// of at most [`FINISH_MAX_ERROR`] (the one gate, also for callers deciding whether the finish
/// can do anything).
pub fn active_set_applies(error_now: f64) -> bool {
    !error_now.is_nan() && error_now <= FINISH_MAX_ERROR
}

/// Relative margin under which `|r_t| ≥ (1 − margin) μ r_n` reads as sliding in
/// [`active_set_finish`].
const SLIDING_MARGIN: f64 = 1e-9;

/// One exact solve with the contact statuses read from `r` (the active-set finish).
///
/// From impulses `r` in their cones whose error is `error_now`, each contact is read as
/// *open* (`r_n ≤ 0`), *sliding* (`|r_t| ≥ (1 − 10⁻⁹) μ r_n`, direction `s = sign r_t`) or
/// *sticking*, and the linear system these statuses define is solved with one sparse LU:
///
/// ```text
/// open:      r_α = 0
/// sticking:  u_α = (W r + q)_α = 0
/// sliding:   u_nα = 0,   r_tα = s μ r_nα
/// ```
///
/// (a Newton step of the primal–dual active-set method of Hintermüller, Ito & Kunisch 2002 with
/// the statuses of the current iterate; rows scaled by `ρ = 1/W_αα` as in the Newton method).
/// When the statuses are those of a solution the result is that solution to rounding: on the
/// slow-shear problem of `datasets/fc-problems/hard/` it takes the 10⁵-sweep iterate from
/// 3.2·10⁻⁶ to 2·10⁻¹³. When they are not, the result leaves the cones or is worse; it is
/// returned only when its projection on the cones has an error below `error_now` (`None`
/// otherwise, when the factorisation fails, and when `error_now` exceeds [`FINISH_MAX_ERROR`]).
pub fn active_set_finish(
    problem: &FcProblem,
    r: &[f64],
    error_now: f64,
    work: &mut NewtonWork,
) -> Result<Option<(Vec<f64>, f64)>, FcError> {
    let n = problem.contacts();
    if n == 0 || r.len() != 2 * n || !active_set_applies(error_now) {
        return Ok(None);
    }
    problem.check_global()?;
    let (diag, rho) = scales(problem);
    work.reset(n);
    problem.mul_add(r, problem.q(), &mut work.u);
    // Statuses: 0 open, 1 sticking, ±2 sliding with sign s.
    let status: Vec<i8> = (0..n)
        .map(|a| {
            let (rn, rt, mu) = (r[2 * a], r[2 * a + 1], problem.mu()[a]);
            if rn <= 0.0 {
                0
            } else if rt.abs() >= (1.0 - SLIDING_MARGIN) * mu * rn {
                if rt > 0.0 {
                    2
                } else {
                    -2
                }
            } else {
                1
            }
        })
        .collect();
    let lin = |a: usize, u: &[f64]| -> ([f64; 2], [f64; 4], [f64; 4]) {
        let (rn, rt, mu) = (r[2 * a], r[2 * a + 1], problem.mu()[a]);
        let [pn, pt] = rho[a];
        match status[a] {
            0 => ([rn, rt], [1.0, 0.0, 0.0, 1.0], [0.0; 4]),
            1 => (
                [pn * u[2 * a], pt * u[2 * a + 1]],
                [0.0; 4],
                [pn, 0.0, 0.0, pt],
            ),
            st => {
                let s = f64::from(st.signum());
                (
                    [pn * u[2 * a], rt - s * mu * rn],
                    [0.0, 0.0, -s * mu, 1.0],
                    [pn, 0.0, 0.0, 0.0],
                )
            }
        }
    };
    for a in 0..n {
        let (f, _, _) = lin(a, &work.u);
        work.phi[2 * a] = f[0];
        work.phi[2 * a + 1] = f[1];
    }
    let mut lu = NewtonLu::default();
    if !lu.newton_direction(problem, work, &diag, 0.0, |a, u| {
        let (_, dr, du) = lin(a, u);
        (dr, du)
    })? {
        return Ok(None);
    }
    let x: Vec<f64> = r.iter().zip(&work.d).map(|(r, d)| r + d).collect();
    let mut rp = vec![0.0; 2 * n];
    let (error, _) = projected(problem, &x, &mut rp, &mut work.trial, 0.0, &|_, _| false);
    Ok((error < error_now).then_some((rp, error)))
}

/// `Φ(r)` into `phi` given `u`; returns `ψ = ½‖Φ‖²`.
fn phi_of(p: &FcProblem, rho: &[[f64; 2]], r: &[f64], u: &[f64], phi: &mut [f64]) -> f64 {
    let mut s = 0.0;
    for (a, &mu) in p.mu().iter().enumerate() {
        let (f, _, _) = linearise(
            [r[2 * a], r[2 * a + 1]],
            [u[2 * a], u[2 * a + 1]],
            mu,
            rho[a],
        );
        phi[2 * a] = f[0];
        phi[2 * a + 1] = f[1];
        s += f[0] * f[0] + f[1] * f[1];
    }
    0.5 * s
}

/// Projects `r` on the cones into `rp`, computes `up = W rp + q` and returns the error of
/// `rp` and whether it passes (`error ≤ tol` and `accept`).
fn projected(
    problem: &FcProblem,
    r: &[f64],
    rp: &mut [f64],
    up: &mut [f64],
    tol: f64,
    accept: &impl Fn(&[f64], &[f64]) -> bool,
) -> (f64, bool) {
    for (a, &mu) in problem.mu().iter().enumerate() {
        let (p, _) = project_on_cone([r[2 * a], r[2 * a + 1]], mu);
        rp[2 * a] = p[0];
        rp[2 * a + 1] = p[1];
    }
    problem.mul_add(rp, problem.q(), up);
    let e = error_given_velocity(problem.mu(), problem.q(), rp, up);
    (e, e <= tol && accept(rp, up))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fc::block_csr::BlockCsr2;
    use crate::fc::{FcProblem, LOW_RANK_EXPAND_MAX_CONTACTS};

    /// A chain of `n` contacts: diagonal blocks `[[2 + s, 0.1], [0.1, 3]]`, neighbours coupled
    /// by `[[-0.5, 0], [0, -0.5]]` (diagonally dominant, so `W` is positive definite), every
    /// contact approaching, and a rank-two cell term (yy, xy) reaching them all, as when the
    /// grains follow the cell within the step.
    fn chain_with_cell(n: usize) -> FcProblem {
        let mut seed = 12345u64;
        let mut next = || crate::test_support::lcg(&mut seed);
        let (mut ri, mut ci, mut v) = (Vec::new(), Vec::new(), Vec::new());
        let mut push = |i: usize, j: usize, b: [f64; 4]| {
            for (k, x) in b.into_iter().enumerate() {
                ri.push(2 * i + k / 2);
                ci.push(2 * j + k % 2);
                v.push(x);
            }
        };
        for a in 0..n {
            push(a, a, [2.0 + (a % 7) as f64 * 0.1, 0.1, 0.1, 3.0]);
            if a + 1 < n {
                push(a, a + 1, [-0.5, 0.0, 0.0, -0.5]);
                push(a + 1, a, [-0.5, 0.0, 0.0, -0.5]);
            }
        }
        let w = BlockCsr2::from_triplets(n, &ri, &ci, &v).unwrap();
        let coef = (0..n)
            .map(|_| {
                [
                    [0.0; 2],
                    [next() - 0.3, 0.4 * (next() - 0.5)],
                    [0.3 * (next() - 0.5), next() - 0.5],
                ]
            })
            .collect();
        let low = LowRank {
            compliance: [0.0, 4.0 / n as f64, 1.0 / n as f64],
            coef,
        };
        let q = (0..n).flat_map(|_| [-0.5 - next(), next() - 0.5]).collect();
        let mu = (0..n).map(|a| 0.2 + 0.1 * (a % 4) as f64).collect();
        FcProblem::from_engine_with(mu, q, w, Some(low))
    }

    /// Newton's direction with the cell's term kept apart (Woodbury) is the direction of the
    /// folded operator: the same solve, to 10⁻¹² of the impulses' scale, in the same number
    /// of iterations; at the folding limit (1800 contacts, a folded operator of 1.3·10⁷
    /// entries) it converges to 10⁻¹⁰ within 30 iterations; above it, it refuses.
    #[test]
    fn newton_with_the_cell_term_kept_apart_solves_as_with_it_folded() {
        let kept = chain_with_cell(60);
        let folded = kept.expanded().unwrap();
        let options = FcOptions {
            tolerance: 1e-12,
            max_iterations: 0,
            ..FcOptions::default()
        };
        let params = NewtonParams::default();
        let (s1, st1) = solve(&kept, &options, &params).unwrap();
        let (s2, st2) = solve(&folded, &options, &params).unwrap();
        assert!(s1.converged && s2.converged, "{} {}", s1.error, s2.error);
        assert_eq!(st1.iterations, st2.iterations);
        let scale = s2.r.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        assert!(scale > 0.1, "loaded: {scale}");
        for (a, b) in s1.r.iter().zip(&s2.r) {
            assert!((a - b).abs() < 1e-12 * scale, "{a} vs {b}");
        }
        // Some contacts slide, some stick: the statuses that make the direction non-trivial.
        let sliding = (0..60)
            .filter(|&a| s1.r[2 * a + 1].abs() > (1.0 - 1e-9) * kept.mu()[a] * s1.r[2 * a])
            .count();
        assert!(sliding > 0 && sliding < 60, "sliding {sliding}");

        // Near the limit, where the folded operator would have 1.3·10⁷ entries, Newton
        // converges in a few iterations; above it the global methods refuse.
        let near = chain_with_cell(LOW_RANK_EXPAND_MAX_CONTACTS);
        let (s, st) = solve(
            &near,
            &FcOptions {
                tolerance: 1e-10,
                ..options.clone()
            },
            &params,
        )
        .unwrap();
        assert!(s.converged, "error {}", s.error);
        assert!(st.iterations <= 30, "{} iterations", st.iterations);
        let above = chain_with_cell(LOW_RANK_EXPAND_MAX_CONTACTS + 1);
        assert!(matches!(
            solve(&above, &options, &params),
            Err(FcError::LowRankTooLarge { .. })
        ));
    }
}
