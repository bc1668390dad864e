//! Lemke's complementary pivoting method on the 2D frictional-contact problem.
//!
//! **2D only, by algorithm.** It is exact because the plane cone is polyhedral (two faces); the
//! circular cone of a 3D contact (`crate::cone::FrictionCone`, the `dim3` skeleton) is not, and
//! a 3D problem has no such LCP without faceting the cone. It therefore takes the plane cone's
//! data directly, not the cone interface.
//!
//! In 2D the Coulomb cone `|r_t| ≤ μ r_n` is a polyhedron, and the contact problem of a step
//! (`u = W r + q`, Coulomb's law with De Saxcé's modified velocity, `docs/physics.md` §3) is
//! the linear complementarity problem of Stewart & Trinkle (1996). Per contact α, with
//! `r_t = β⁺ − β⁻` and the sliding speed `λ`:
//!
//! ```text
//! w_n = u_n                 ≥ 0   ⊥   r_n ≥ 0
//! w⁺  = λ + u_t             ≥ 0   ⊥   β⁺  ≥ 0
//! w⁻  = λ − u_t             ≥ 0   ⊥   β⁻  ≥ 0
//! w_λ = μ r_n − β⁺ − β⁻     ≥ 0   ⊥   λ   ≥ 0
//! ```
//!
//! that is `w = M z + q̄ ≥ 0`, `z ≥ 0`, `zᵀ w = 0` with `z = (r_n, β⁺, β⁻, λ)_α`. Its solutions
//! are exactly those of the Coulomb problem: a sticking contact has `λ = 0`, hence `u = 0`; a
//! sliding one `λ = |u_t|`, `r_t = −μ r_n sign u_t`, `u_n = 0`; an open one `r = 0`, `u_n ≥ 0`.
//!
//! Lemke's method (Lemke 1965; Cottle, Pang & Stone, *The Linear Complementarity Problem*, 1992,
//! §4.4) follows the almost-complementary path of `w − M z − d z₀ = q̄` from `z₀` large down to
//! `z₀ = 0`: at each pivot the complement of the variable that left the basis enters, the
//! minimum-ratio test picks the one that leaves, until `z₀` itself leaves. It needs no
//! regularisation and does not care that `W` is singular (hyperstatic packings, where the
//! reactions are not unique): its bases stay non-singular along the path. Anitescu & Potra
//! (1997, *Nonlinear Dynamics* 14, 231–247) show that it processes the contact LCP of rigid
//! bodies with friction; Siconos implements it on the same formulation (`fc2d_lexicolemke`).
//! Where Gauss–Seidel and Newton stall on the stick–slip degeneracies of dense packings
//! (`datasets/fc-problems/hard/README.md`), it ends on an exact solution.
//!
//! This implementation is the *revised* method: the basis matrix `B` (columns `e_k` for a basic
//! `w_k`, `−M_{:k}` for a basic `z_k`, `−d` for `z₀`) is factorised by faer's sparse LU, and
//! the pivots in between are applied in product form (eta vectors; Chvátal, *Linear
//! Programming*, 1983, ch. 24), refactorising every [`LemkeParams::refactor_every`] pivots.
//! Impulses are scaled by the mean diagonal of `W` so that every entry of `M` is of order one.
//!
//! Ties in the ratio test (a degenerate, hyperstatic problem has many) go to `z₀`, then to the
//! largest pivot. A warm start ([`solve`] with a [`Warm`]) takes a complementary basis: the final
//! basis of the previous step's solve, or else the one the statuses of approximate impulses
//! define (open, sliding, sticking), with the covering vector `d = B v`, `v_i = δ − x*_i` on the
//! basic variables that are infeasible at `x* = B⁻¹ q̄` and 0 elsewhere; when the basis is nearly
//! right the path ends after few pivots. When that basis is singular, or the warm path ends on a
//! ray, at its cap of `m/4` pivots or with an error above the tolerance asked for, the method
//! restarts from the cold basis (`B = I`, `d = e`).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};
use serde::Serialize;

use super::error::FcError;
use super::measure::fc_error;
use super::problem::FcProblem;

/// Parameters of [`solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LemkeParams {
    /// Largest number of pivots of the cold path, per LCP variable (`4 × contacts`); a problem
    /// of the hard set takes 0.5–7 (2–26 per contact). A warm path stops at `m/4` pivots.
    pub max_pivots_per_variable: usize,
    /// Pivots applied in product form between two sparse LU factorisations of the basis.
    pub refactor_every: usize,
}

impl Default for LemkeParams {
    fn default() -> Self {
        LemkeParams {
            max_pivots_per_variable: 10,
            refactor_every: 64,
        }
    }
}

/// How a Lemke path ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LemkeOutcome {
    /// `z₀` left the basis: a complementary solution.
    Solved,
    /// The entering column has no positive entry: the path ends on a ray (no solution found).
    Ray,
    /// The pivot cap was reached.
    PivotCap,
    /// A basis could not be factorised, or its solution is not finite.
    Singular,
}

/// What [`solve`] did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LemkeReport {
    /// Pivots in all (warm path and cold path).
    pub pivots: usize,
    /// Sparse LU factorisations of the basis.
    pub factorisations: usize,
    /// Whether the warm start's path gave the answer.
    pub warm_solved: bool,
    /// How the warm start's path ended (`None` without a warm start).
    pub warm_outcome: Option<LemkeOutcome>,
    /// Pivots of the warm paths (from the previous basis, then from the statuses), together.
    pub warm_pivots: usize,
    /// How the last path ended.
    pub outcome: LemkeOutcome,
    /// Error measure of the returned impulses (`NaN` if none).
    pub error: f64,
}

/// Feasibility tolerance of the ratio test, relative to `‖q̄‖∞` (Harris 1973).
const HARRIS_DELTA: f64 = 1e-11;

/// Size of the perturbation of `q̄` that the path follows, relative to `‖q̄‖∞` (each entry
/// gets `δ_i ∈ [1, 2) × 10⁻¹⁰ ‖q̄‖∞`, from a fixed pseudo-random sequence). A hyperstatic problem
/// is degenerate (many basic variables at zero) and the plain path can cycle; the perturbation
/// makes ties unlikely, as the lexicographic rule would in exact arithmetic (Charnes 1952). The
/// final basis is then evaluated with the true `q̄`.
const PERTURBATION: f64 = 1e-10;

/// `z₀` counts as vanished when `z₀ ‖v‖∞ ≤` this `× ‖q̄‖∞`, with `v = B₀⁻¹ d` the direction of
/// the path's start (`e` cold): its part in the basic values is then below rounding and the
/// almost-complementary point is taken as a solution (its error is measured by the caller).
const Z0_ZERO: f64 = 1e-12;

/// Variable codes: `k < m` is `w_k`, `m ≤ k < 2m` is `z_{k−m}`, `2m` is `z₀`.
struct Lcp {
    m: usize,
    /// `M` by columns (CSC).
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    val: Vec<f64>,
    /// `q̄`, scaled.
    q: Vec<f64>,
    /// `q̄ + δ` with the small positive perturbation δ that the path follows (see [`PERTURBATION`]).
    q_path: Vec<f64>,
    /// Impulse scale: `r = z / scale` for the impulse variables.
    scale: f64,
    /// Friction coefficients.
    mu: Vec<f64>,
}

impl Lcp {
    /// Builds `M` and `q̄` of the Stewart–Trinkle LCP, impulses scaled by the mean `W_nn`.
    fn new(p: &FcProblem) -> Lcp {
        let nc = p.contacts();
        let m = 4 * nc;
        let w = p.w();
        let scale = {
            let s: f64 = (0..nc).map(|a| w.diagonal(a)[0].abs()).sum::<f64>() / nc.max(1) as f64;
            if s > 0.0 && s.is_finite() {
                s
            } else {
                1.0
            }
        };
        // Columns of W: for block column b, the blocks (a, W_ab).
        let mut by_col: Vec<Vec<(usize, [f64; 4])>> = vec![Vec::new(); nc];
        for a in 0..nc {
            for (b, blk) in w.row(a) {
                by_col[b].push((a, *blk));
            }
        }
        let mut col_ptr = Vec::with_capacity(m + 1);
        let mut row_idx = Vec::new();
        let mut val = Vec::new();
        col_ptr.push(0);
        for (b, blocks) in by_col.iter().enumerate() {
            // r_n, β⁺, β⁻: the W part (u rows), then the μ row of contact b.
            for (j, (wcol, own)) in [(0usize, p.mu()[b]), (1, -1.0), (1, -1.0)]
                .into_iter()
                .enumerate()
            {
                let sign = if j == 2 { -1.0 } else { 1.0 };
                let mut own_done = false;
                for &(a, blk) in blocks {
                    if a > b && !own_done {
                        row_idx.push(4 * b + 3);
                        val.push(own);
                        own_done = true;
                    }
                    let wn = sign * blk[wcol] / scale; // W_nn or W_nt
                    let wt = sign * blk[2 + wcol] / scale; // W_tn or W_tt
                    row_idx.extend([4 * a, 4 * a + 1, 4 * a + 2]);
                    val.extend([wn, wt, -wt]);
                    if a == b {
                        row_idx.push(4 * b + 3);
                        val.push(own);
                        own_done = true;
                    }
                }
                if !own_done {
                    row_idx.push(4 * b + 3);
                    val.push(own);
                }
                col_ptr.push(row_idx.len());
            }
            // λ: rows w⁺ and w⁻ of contact b.
            row_idx.extend([4 * b + 1, 4 * b + 2]);
            val.extend([1.0, 1.0]);
            col_ptr.push(row_idx.len());
        }
        let qp = p.q();
        let q: Vec<f64> = (0..nc)
            .flat_map(|a| [qp[2 * a], qp[2 * a + 1], -qp[2 * a + 1], 0.0])
            .collect();
        let qn = q.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        let mut state = 0x243F_6A88_85A3_08D3u64;
        let q_path = q
            .iter()
            .map(|v| {
                // splitmix64: a fixed sequence, so that solves are reproducible.
                state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
                let mut z = state;
                z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
                z ^= z >> 31;
                let unit = (z >> 11) as f64 / (1u64 << 53) as f64;
                v + PERTURBATION * qn * (1.0 + unit)
            })
            .collect();
        Lcp {
            q_path,
            m,
            col_ptr,
            row_idx,
            val,
            q,
            scale,
            mu: p.mu().to_vec(),
        }
    }

    /// Adds the column of variable `v` (times `factor`) to the sparse list `out`.
    fn column(&self, v: usize, d: &[f64], out: &mut Vec<(usize, f64)>) {
        let m = self.m;
        if v < m {
            out.push((v, 1.0));
        } else if v < 2 * m {
            let k = v - m;
            for i in self.col_ptr[k]..self.col_ptr[k + 1] {
                out.push((self.row_idx[i], -self.val[i]));
            }
        } else {
            out.extend(
                d.iter()
                    .enumerate()
                    .filter(|(_, x)| **x != 0.0)
                    .map(|(i, x)| (i, -x)),
            );
        }
    }

    fn complement(&self, v: usize) -> usize {
        if v < self.m {
            v + self.m
        } else {
            v - self.m
        }
    }
}

/// One eta vector of the product form: the basis column at `row` was replaced by a column whose
/// representation in the previous basis is `y` (`pivot = y[row]`, `rest` its other non-zeros).
struct Eta {
    row: usize,
    pivot: f64,
    rest: Vec<(usize, f64)>,
}

/// The factorised basis: sparse LU of `B₀` and the etas applied since.
struct Basis {
    symbolic: Option<SymbolicLu<usize>>,
    numeric: NumericLu<usize, f64>,
    scratch: MemBuffer,
    etas: Vec<Eta>,
    factorisations: usize,
}

impl Basis {
    fn new() -> Basis {
        Basis {
            symbolic: None,
            numeric: NumericLu::new(),
            scratch: MemBuffer::new(faer::dyn_stack::StackReq::empty()),
            etas: Vec::new(),
            factorisations: 0,
        }
    }

    /// Factorises the basis whose columns are those of `vars`. `false` if it fails.
    fn factorise(&mut self, lcp: &Lcp, vars: &[usize], d: &[f64]) -> bool {
        let m = lcp.m;
        let mut col_ptr = Vec::with_capacity(m + 1);
        let mut row_idx = Vec::new();
        let mut val = Vec::new();
        let mut col = Vec::new();
        col_ptr.push(0);
        for &v in vars {
            col.clear();
            lcp.column(v, d, &mut col);
            col.sort_unstable_by_key(|e| e.0);
            for &(i, x) in col.iter() {
                row_idx.push(i);
                val.push(x);
            }
            col_ptr.push(row_idx.len());
        }
        self.etas.clear();
        self.factorisations += 1;
        let sym = SymbolicSparseColMatRef::new_checked(m, m, &col_ptr, None, &row_idx);
        let Ok(symbolic) = factorize_symbolic_lu(sym, LuSymbolicParams::default()) else {
            self.symbolic = None;
            return false;
        };
        let req = symbolic
            .factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        self.scratch = MemBuffer::new(req);
        let mat = SparseColMatRef::new(sym, &val);
        let ok = symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                mat,
                Par::Seq,
                MemStack::new(&mut self.scratch),
                Default::default(),
            )
            .is_ok();
        self.symbolic = Some(symbolic);
        ok
    }

    /// `x ← B⁻¹ x` (the LU, then the etas in order).
    fn solve(&mut self, x: &mut [f64]) {
        let Some(symbolic) = self.symbolic.as_ref() else {
            x.iter_mut().for_each(|v| *v = f64::NAN);
            return;
        };
        let n = x.len();
        LuRef::new_unchecked(symbolic, &self.numeric).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, n, 1),
            Par::Seq,
            MemStack::new(&mut self.scratch),
        );
        for e in &self.etas {
            let t = x[e.row] / e.pivot;
            x[e.row] = t;
            if t != 0.0 {
                for &(i, y) in &e.rest {
                    x[i] -= y * t;
                }
            }
        }
    }
}

/// The covering vector of a path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Cover {
    /// `d = e` from the basis `B = I` (Lemke's original start, which his theory covers).
    Unit,
    /// From a complementary basis with values `x* = B⁻¹ q̄`: `d = B v` with `v_i = δ − x*_i` on
    /// the infeasible basics (`x*_i < 0`) and 0 elsewhere, so that the path starts from
    /// `x*` moved onto the feasible side along the infeasible basics only (`δ = 10⁻⁶ ‖q̄‖∞`).
    Infeasible,
}

/// The covering vector `d = B v` of a path (added into `d`, which holds zeros) and `v`:
/// `v = e` for [`Cover::Unit`] (`B = I`), `v_i = δ − x*_i` on the basics infeasible at `x*`
/// (and 0 elsewhere) for [`Cover::Infeasible`], `δ = 10⁻⁶ ‖q̄‖∞`.
fn covering(
    lcp: &Lcp,
    vars: &[usize],
    cover: Cover,
    x: &[f64],
    qn: f64,
    d: &mut [f64],
) -> Vec<f64> {
    // v = B⁻¹ d.
    let v: Vec<f64> = match cover {
        Cover::Unit => vec![1.0; lcp.m],
        Cover::Infeasible => x
            .iter()
            .map(|&xi| if xi < 0.0 { 1e-6 * qn - xi } else { 0.0 })
            .collect(),
    };
    let mut col = Vec::new();
    for (&var, &vi) in vars.iter().zip(&v) {
        if vi != 0.0 {
            col.clear();
            lcp.column(var, &[], &mut col);
            for &(i, c) in &col {
                d[i] += vi * c;
            }
        }
    }
    v
}

/// Harris' two-pass ratio test of a pivot with basic values `x` and entering column
/// `y = B⁻¹ a`: the largest step that no basic variable overshoots by more than
/// `δ = HARRIS_DELTA ‖q̄‖∞` (`qn = ‖q̄‖∞`), then, among the rows blocking within it, the row of
/// `z₀` (variable code `z0`) or else the largest pivot. `None` when no row blocks (a ray).
fn ratio_test(x: &[f64], y: &[f64], vars: &[usize], z0: usize, qn: f64) -> Option<usize> {
    let m = x.len();
    let ymax = y.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    let tol = 1e-11 * ymax;
    let delta = HARRIS_DELTA * qn;
    let mut bound = f64::INFINITY;
    for i in 0..m {
        if y[i] > tol {
            bound = bound.min((x[i].max(0.0) + delta) / y[i]);
        }
    }
    if !bound.is_finite() {
        return None;
    }
    let mut row = usize::MAX;
    let mut row_y = 0.0;
    for i in 0..m {
        if y[i] > tol && x[i].max(0.0) / y[i] <= bound {
            if vars[i] == z0 {
                row = i;
                break;
            }
            if y[i] > row_y {
                row = i;
                row_y = y[i];
            }
        }
    }
    Some(row)
}

/// The values of the complementary basis `vars` at the end of a path, from a fresh
/// factorisation (`x_B = B⁻¹ q̄`); the path's own values `x` when that factorisation fails or
/// gives a value that is not finite.
fn complementary_values(
    lcp: &Lcp,
    vars: &[usize],
    d: &[f64],
    basis: &mut Basis,
    x: Vec<f64>,
) -> Vec<f64> {
    if !basis.factorise(lcp, vars, d) {
        return x;
    }
    let mut fresh = lcp.q.clone();
    basis.solve(&mut fresh);
    if !fresh.iter().all(|v| v.is_finite()) {
        return x;
    }
    fresh
}

/// One Lemke path from the complementary basis `vars` with the covering vector of `cover`;
/// `d` receives that vector. Returns the outcome and the final basis values.
fn path(
    lcp: &Lcp,
    vars: &mut [usize],
    cover: Cover,
    d: &mut Vec<f64>,
    basis: &mut Basis,
    params: &LemkeParams,
    pivots: &mut usize,
) -> (LemkeOutcome, Vec<f64>) {
    let m = lcp.m;
    let z0 = 2 * m;
    d.clear();
    d.resize(m, 0.0);
    // z₀ is not basic yet: the covering vector plays no part in this factorisation.
    if !basis.factorise(lcp, vars, d) {
        return (LemkeOutcome::Singular, Vec::new());
    }
    let mut x = lcp.q.clone();
    basis.solve(&mut x);
    if !x.iter().all(|v| v.is_finite()) {
        return (LemkeOutcome::Singular, Vec::new());
    }
    let qn = lcp.q.iter().fold(0.0f64, |s, v| s.max(v.abs())).max(1e-300);
    if x.iter().fold(f64::INFINITY, |s, v| s.min(*v)) >= -1e-13 * qn {
        return (LemkeOutcome::Solved, x);
    }
    x.clone_from(&lcp.q_path);
    basis.solve(&mut x);
    if x.iter().all(|&xi| xi >= 0.0) {
        // Feasible once perturbed (so within 2·10⁻¹⁰ ‖q̄‖∞ of feasible): this complementary
        // basis is the answer, evaluated with the true q̄.
        x.clone_from(&lcp.q);
        basis.solve(&mut x);
        return (LemkeOutcome::Solved, x);
    }
    let v = covering(lcp, vars, cover, &x, qn, d);
    let mut col = Vec::new();
    // z₀ enters at the row that needs the largest t for x + t v ≥ 0, t = max(−x_i / v_i).
    // Some x_i < 0 (else returned above), and v_i > 0 there: t > 0.
    let Some((imin, t)) = x
        .iter()
        .zip(&v)
        .enumerate()
        .filter(|(_, (_, &vi))| vi > 0.0)
        .map(|(i, (&xi, &vi))| (i, -xi / vi))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .filter(|&(_, t)| t > 0.0 && t.is_finite())
    else {
        return (LemkeOutcome::Singular, x);
    };
    for (xi, vi) in x.iter_mut().zip(&v) {
        *xi += t * vi;
    }
    x[imin] = t;
    basis.etas.push(Eta {
        row: imin,
        pivot: -v[imin],
        rest: v
            .iter()
            .enumerate()
            .filter(|&(i, vi)| i != imin && *vi != 0.0)
            .map(|(i, vi)| (i, -vi))
            .collect(),
    });
    let mut leaving = std::mem::replace(&mut vars[imin], z0);
    let mut z0_row = imin;
    let vmax = v.iter().fold(0.0f64, |s, x| s.max(x.abs()));
    let cap = match cover {
        // A warm path longer than this is not worth its start: the cold one takes 2–4 m.
        Cover::Infeasible => m / 4,
        Cover::Unit => params.max_pivots_per_variable.max(1) * m,
    };
    let mut y = vec![0.0; m];
    let mut since = 1;
    for _ in 0..cap {
        *pivots += 1;
        let entering = lcp.complement(leaving);
        col.clear();
        lcp.column(entering, d, &mut col);
        y.iter_mut().for_each(|v| *v = 0.0);
        for &(i, v) in &col {
            y[i] += v;
        }
        basis.solve(&mut y);
        if !y.iter().all(|v| v.is_finite()) {
            return (LemkeOutcome::Singular, x);
        }
        let Some(row) = ratio_test(&x, &y, vars, z0, qn) else {
            return (LemkeOutcome::Ray, x);
        };
        let theta = x[row].max(0.0) / y[row];
        for i in 0..m {
            x[i] -= theta * y[i];
        }
        x[row] = theta;
        leaving = std::mem::replace(&mut vars[row], entering);
        basis.etas.push(Eta {
            row,
            pivot: y[row],
            rest: y
                .iter()
                .enumerate()
                .filter(|&(i, v)| i != row && *v != 0.0)
                .map(|(i, v)| (i, *v))
                .collect(),
        });
        since += 1;
        if row == z0_row {
            z0_row = usize::MAX;
        }
        let z0_vanished = z0_row != usize::MAX && x[z0_row] * vmax <= Z0_ZERO * qn;
        if z0_vanished {
            // z₀ ≈ 0 while still basic: the point is already a solution (the missing pair has
            // both members at zero); complete the basis with the next entering variable.
            vars[z0_row] = lcp.complement(leaving);
            x[z0_row] = 0.0;
        }
        if leaving == z0 || z0_vanished {
            return (
                LemkeOutcome::Solved,
                complementary_values(lcp, vars, d, basis, x),
            );
        }
        if since >= params.refactor_every {
            since = 0;
            // x_B = B⁻¹ (q̄ + δ) with z₀ basic: the fresh values of every basic variable.
            if !basis.factorise(lcp, vars, d) {
                return (LemkeOutcome::Singular, x);
            }
            x.clone_from(&lcp.q_path);
            basis.solve(&mut x);
            if !x.iter().all(|v| v.is_finite()) {
                return (LemkeOutcome::Singular, x);
            }
        }
    }
    (LemkeOutcome::PivotCap, x)
}

/// The impulses `r` and the basis bits of the basic values `x` of the basis `vars`.
fn solution(lcp: &Lcp, vars: &[usize], x: &[f64]) -> LemkeSolution {
    let m = lcp.m;
    let mut z = vec![0.0; m];
    let mut basis = vec![0u8; m / 4];
    for (&v, &xv) in vars.iter().zip(x) {
        if (m..2 * m).contains(&v) {
            z[v - m] = xv.max(0.0);
            basis[(v - m) / 4] |= 1 << ((v - m) % 4);
        }
    }
    let r = z
        .chunks_exact(4)
        .zip(&lcp.mu)
        .flat_map(|(c, &mu)| {
            // w_λ ≥ 0 holds to rounding: clip r_t into the cone.
            let (rn, rt) = (c[0] / lcp.scale, (c[1] - c[2]) / lcp.scale);
            [rn, rt.clamp(-mu * rn, mu * rn)]
        })
        .collect();
    LemkeSolution { r, basis }
}

/// The complementary basis defined by the statuses of `r` (with `u = W r + q`).
fn warm_basis(p: &FcProblem, r: &[f64]) -> Vec<usize> {
    let nc = p.contacts();
    let m = 4 * nc;
    let u = p.velocity(r);
    let (w, z) = (|k: usize| k, |k: usize| k + m);
    let rn_max = (0..nc).fold(0.0f64, |s, a| s.max(r[2 * a]));
    let mut vars = Vec::with_capacity(m);
    for a in 0..nc {
        let (rn, rt, ut, mu) = (r[2 * a], r[2 * a + 1], u[2 * a + 1], p.mu()[a]);
        let k = 4 * a;
        let set = if rn <= 1e-12 * rn_max {
            // open: λ = |u_t| basic; the w± of the other direction degenerate.
            if ut >= 0.0 {
                [w(k), w(k + 1), z(k + 2), z(k + 3)]
            } else {
                [w(k), z(k + 1), w(k + 2), z(k + 3)]
            }
        } else if rt.abs() >= (1.0 - 1e-9) * mu * rn {
            // sliding against u_t: r_t = −μ r_n sign u_t, λ = |u_t|.
            if rt < 0.0 {
                [z(k), w(k + 1), z(k + 2), z(k + 3)]
            } else {
                [z(k), z(k + 1), w(k + 2), z(k + 3)]
            }
        } else if rt >= 0.0 {
            [z(k), z(k + 1), w(k + 2), w(k + 3)]
        } else {
            [z(k), w(k + 1), z(k + 2), w(k + 3)]
        };
        vars.extend(set);
    }
    vars
}

/// A warm start of [`solve`]: the final basis of a previous solve and/or approximate impulses.
#[derive(Debug, Clone, Copy, Default)]
pub struct Warm<'a> {
    /// Per contact, the bits `j = 0..4` set where `z_{4α+j}` (`r_n, β⁺, β⁻, λ`) is basic and
    /// clear where its complement `w` is: [`LemkeSolution::basis`] of the previous step mapped
    /// onto this step's contacts (0, all `w` basic, for a new contact). The best start in a
    /// time-stepping sequence: a basis Lemke's path reached is well conditioned.
    pub basis: Option<&'a [u8]>,
    /// Approximate impulses: the basis their statuses define (open, sliding, sticking); often
    /// ill conditioned in a hyperstatic packing, since the statuses of an interior point are
    /// not those of a vertex.
    pub impulses: Option<&'a [f64]>,
}

/// An exact solution found by [`solve`].
#[derive(Debug, Clone, PartialEq)]
pub struct LemkeSolution {
    /// The impulses (in their cones).
    pub r: Vec<f64>,
    /// The final complementary basis, per contact (see [`Warm::basis`]).
    pub basis: Vec<u8>,
}

/// Solves `problem` by Lemke's method: from the warm basis of `warm` (the previous basis if one
/// is given and not all zero, else the statuses of the impulses), kept when its path ends with
/// an error within `tolerance`, then from the cold basis (`B = I`, `d = e`). Returns the
/// solution with the smallest finite error among the paths that ended on a complementary
/// basis (if any), with the report.
pub fn solve(
    problem: &FcProblem,
    warm: Warm<'_>,
    tolerance: f64,
    params: &LemkeParams,
) -> Result<(Option<LemkeSolution>, LemkeReport), FcError> {
    if problem.low_rank().is_some() {
        return solve(&problem.expanded()?, warm, tolerance, params);
    }
    let nc = problem.contacts();
    if params.refactor_every == 0 {
        return Err(FcError::Option {
            name: "lemke.refactor_every".into(),
            reason: "must be at least 1".into(),
        });
    }
    let mut report = LemkeReport {
        pivots: 0,
        factorisations: 0,
        warm_solved: false,
        warm_outcome: None,
        warm_pivots: 0,
        outcome: LemkeOutcome::Solved,
        error: f64::NAN,
    };
    if nc == 0 {
        report.error = 0.0;
        let empty = LemkeSolution {
            r: Vec::new(),
            basis: Vec::new(),
        };
        return Ok((Some(empty), report));
    }
    let lcp = Lcp::new(problem);
    let m = lcp.m;
    let mut basis = Basis::new();
    let mut pivots = 0;
    let mut d = Vec::new();
    let mut starts: Vec<Vec<usize>> = Vec::new();
    if let Some(b) = warm.basis.filter(|b| b.len() == nc) {
        starts.push(
            b.iter()
                .enumerate()
                .flat_map(|(a, bits)| {
                    (0..4).map(move |j| {
                        let k = 4 * a + j;
                        if bits & (1 << j) != 0 {
                            k + m
                        } else {
                            k
                        }
                    })
                })
                .collect(),
        );
    }
    let no_basis = starts.is_empty() || warm.basis.is_some_and(|b| b.iter().all(|&x| x == 0));
    if let Some(r0) = warm
        .impulses
        .filter(|r| no_basis && r.len() == 2 * nc && r.iter().all(|x| x.is_finite()))
    {
        starts.push(warm_basis(problem, r0));
    }
    let mut found = None;
    for mut vars in starts {
        let (outcome, x) = path(
            &lcp,
            &mut vars,
            Cover::Infeasible,
            &mut d,
            &mut basis,
            params,
            &mut pivots,
        );
        report.warm_outcome = Some(outcome);
        report.warm_pivots = pivots;
        if outcome == LemkeOutcome::Solved {
            let sol = solution(&lcp, &vars, &x);
            let error = fc_error(problem, &sol.r);
            if error <= tolerance {
                report = LemkeReport {
                    pivots,
                    factorisations: basis.factorisations,
                    warm_solved: true,
                    outcome,
                    error,
                    ..report
                };
                return Ok((Some(sol), report));
            }
            if error.is_finite() {
                found = Some((sol, error));
            }
        }
    }
    let mut vars: Vec<usize> = (0..m).collect();
    let (outcome, x) = path(
        &lcp,
        &mut vars,
        Cover::Unit,
        &mut d,
        &mut basis,
        params,
        &mut pivots,
    );
    report.pivots = pivots;
    report.factorisations = basis.factorisations;
    report.outcome = outcome;
    if outcome == LemkeOutcome::Solved {
        let sol = solution(&lcp, &vars, &x);
        let error = fc_error(problem, &sol.r);
        if error.is_finite() && found.as_ref().is_none_or(|(_, e)| error <= *e) {
            found = Some((sol, error));
        }
    }
    Ok(match found {
        Some((sol, error)) => {
            report.error = error;
            (Some(sol), report)
        }
        None => (None, report),
    })
}
