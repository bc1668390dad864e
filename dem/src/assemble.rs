//! The frictional-contact problem of one engine step in local (reduced) form, assembled
//! explicitly: `W = H M⁻¹ Hᵀ` block by block and `q = H v_free + shift`.
//!
//! Gauss–Seidel never needs `W` (it keeps body velocities current), but the global solver
//! ([`crate::fc::newton`]) factorises it and the problems are written to files for other
//! solvers (`grainlaw run --dump-problems`). Block `(α, β)` is the sum over the bodies `b` that
//! contacts α and β share of `H_α^b M_b⁻¹ H_β^bᵀ`, with the 2×3 rows of contact α on body `b`
//! (see [`ContactRow`]):
//!
//! ```text
//! side b:   n-row ( n_x,  n_y, ρ_b×n),   t-row (−n_y, n_x, ρ_b×t)
//! side a:   the same with ρ_a and the opposite sign
//! ```
//!
//! Degrees of freedom with imposed velocity have a zero inverse mass and contribute nothing, so
//! walls and driven bodies do not couple the contacts they carry.

use crate::cell_coupling::CellCoupling;
use crate::contact::ContactRow;
use crate::fc::block_csr::BlockCsr2;
use crate::fc::problem::{FcProblem, LowRank};
use crate::math::Spatial;

/// Row of contact `c` on the body of `side` (0: `a`, 1: `b`): `[n-row, t-row]`, each
/// `(x, y, θ)`.
#[inline]
fn body_rows(c: &ContactRow, side: usize) -> [Spatial; 2] {
    let [nx, ny] = c.n;
    if side == 1 {
        [[nx, ny, c.k[2]], [-ny, nx, c.k[3]]]
    } else {
        [[-nx, -ny, -c.k[0]], [ny, -nx, -c.k[1]]]
    }
}

/// `W = H M⁻¹ Hᵀ` of the contacts `rows` with inverse masses `inv` (per body `[1/m, 1/m, 1/I]`,
/// zero for imposed degrees of freedom).
pub fn delassus_matrix(rows: &[ContactRow], inv: &[Spatial]) -> BlockCsr2 {
    delassus_with(rows, inv, None)
}

/// [`delassus_matrix`] plus the term `m Σ_κ B_κ B_κᵀ` of a cell whose stress-controlled
/// components are unknowns of the step ([`crate::cell_coupling`], [`CellCoupling::low_rank`]).
pub fn delassus_with(rows: &[ContactRow], inv: &[Spatial], cell: Option<&LowRank>) -> BlockCsr2 {
    // Body → (contact, side) adjacency in compressed form.
    let nb = inv.len();
    let mut count = vec![0usize; nb + 1];
    for c in rows {
        count[c.a as usize + 1] += 1;
        count[c.b as usize + 1] += 1;
    }
    for i in 0..nb {
        count[i + 1] += count[i];
    }
    let mut fill = count.clone();
    let mut adj = vec![(0u32, 0u8); 2 * rows.len()];
    for (k, c) in rows.iter().enumerate() {
        for (side, body) in [(0u8, c.a), (1u8, c.b)] {
            let at = &mut fill[body as usize];
            adj[*at] = (k as u32, side);
            *at += 1;
        }
    }
    let (mut ri, mut ci, mut v) = (Vec::new(), Vec::new(), Vec::new());
    for (b, m) in inv.iter().enumerate() {
        if m.iter().all(|&x| x == 0.0) {
            continue;
        }
        let list = &adj[count[b]..count[b + 1]];
        for &(ka, sa) in list {
            let ha = body_rows(&rows[ka as usize], sa as usize);
            for &(kb, sb) in list {
                let hb = body_rows(&rows[kb as usize], sb as usize);
                for (i, hai) in ha.iter().enumerate() {
                    for (j, hbj) in hb.iter().enumerate() {
                        let x = hai[0] * m[0] * hbj[0]
                            + hai[1] * m[1] * hbj[1]
                            + hai[2] * m[2] * hbj[2];
                        ri.push(2 * ka as usize + i);
                        ci.push(2 * kb as usize + j);
                        v.push(x);
                    }
                }
            }
        }
    }
    if let Some(cell) = cell {
        cell.push_triplets(&mut ri, &mut ci, &mut v);
    }
    // Indices are in range and the values finite by construction.
    BlockCsr2::from_triplets(rows.len(), &ri, &ci, &v)
        .unwrap_or_else(|e| panic!("engine Delassus assembly: {e}"))
}

/// The step's problem: `W` from [`delassus_matrix`], `q_α = H_α v_free + shift_α` from the free
/// velocities, μ from the rows.
pub fn contact_problem(rows: &[ContactRow], v_free: &[Spatial], inv: &[Spatial]) -> FcProblem {
    contact_problem_with(rows, v_free, inv, None)
}

/// [`contact_problem`] of a step whose cell's stress-controlled components are unknowns
/// ([`crate::cell_coupling`]): `W + m Σ_κ B_κ B_κᵀ`, and `q` with the impulse-free part
/// `Σ_κ B_κ δ⁰_κ` of the cell's change on the coupled contacts.
pub fn contact_problem_with(
    rows: &[ContactRow],
    v_free: &[Spatial],
    inv: &[Spatial],
    cell: Option<&CellCoupling>,
) -> FcProblem {
    // A term among the contacts across the boundary is folded into W as it is assembled (the
    // operator every method then sees: a dense block among some 10–25 % of the contacts) up to
    // the folding limit. Above it, or when the grains follow the cell within the step (every
    // contact coupled: folding made Newton factorise a dense 2n × 2n matrix, most of a
    // 200-grain run's time), the term is kept apart; Newton's method solves through it by
    // Woodbury's identity (`fc::newton`).
    let low_rank = cell.map(CellCoupling::low_rank);
    let fold = rows.len() <= crate::fc::LOW_RANK_EXPAND_MAX_CONTACTS
        && !cell.is_some_and(CellCoupling::within_step);
    let w = delassus_with(rows, inv, low_rank.as_ref().filter(|_| fold));
    let mut q = Vec::with_capacity(2 * rows.len());
    for (i, c) in rows.iter().enumerate() {
        let mut u = c.velocity(&v_free[c.a as usize], &v_free[c.b as usize]);
        if let Some(cell) = cell {
            let d = cell.free_correction(i);
            u[0] += d[0];
            u[1] += d[1];
        }
        q.extend_from_slice(&u);
    }
    FcProblem::from_engine_with(
        rows.iter().map(|c| c.mu).collect(),
        q,
        w,
        low_rank.filter(|_| !fold),
    )
}
