//! The data of one 2D frictional-contact problem in local (reduced) form.

use super::block_csr::BlockCsr2;
use super::error::FcError;
use crate::local::{Coulomb2, Delassus2};

/// The friction cone of an fc-problem-v1 contact ([`FcProblem::cone`]): the plane Coulomb cone
/// (the format is 2D). The Gauss–Seidel sweep (`super::nsgs`) and the error measure
/// (`super::measure`) reach the law through [`crate::cone::FrictionCone`] on it; Lemke's and
/// Newton's methods are 2D by algorithm and read `μ` directly.
pub type ProblemCone = Coulomb2;

/// One 2D frictional-contact problem (fc-problem-v1), contact-local frames, normal first:
///
/// ```text
/// find r, u ∈ ℝ^{2 nc}:  u = W r + q,   r_α ∈ K_μα,   ū_α = u_α + μ_α |u_tα| n ∈ K_μα*,   r_α · ū_α = 0
/// ```
///
/// `r` are impulses (N·s), `u` relative velocities (m/s), `W` the Delassus matrix (1/kg),
/// `q` the free relative velocity (m/s), all stored interleaved `(n, t)` per contact.
///
/// Built only through [`FcProblem::new`] (or the reader), which validates sizes, finiteness,
/// `μ ≥ 0` and the positive definiteness of every diagonal block.
#[derive(Debug, Clone)]
pub struct FcProblem {
    mu: Vec<f64>,
    q: Vec<f64>,
    w: BlockCsr2,
    diag: Vec<Delassus2>,
    skew: Vec<f64>,
    low_rank: Option<LowRank>,
}

/// Largest number of contacts of a problem with a [`LowRank`] term that the global methods take
/// ([`FcProblem::check_global`]): Lemke's method and the problem files fold the term into `W`
/// ([`FcProblem::expanded`]: `(2 nc)²` entries, 1.3·10⁷ here, about 0.3 GB while it is built),
/// Newton's method and the active-set finish solve through it (Woodbury's identity,
/// [`super::newton`]); above it, only Gauss–Seidel solves such a problem (it keeps the term's
/// three sums current, [`super::nsgs`]).
pub const LOW_RANK_EXPAND_MAX_CONTACTS: usize = 1800;

/// The rank of a [`LowRank`] term: the three components of a biperiodic cell's velocity
/// gradient (xx, yy, xy) that a stress may control, eliminated from a step's problem
/// (`crate::cell_coupling`). Not the rigid-body `crate::math::SPATIAL_DIM`, which is also 3 in
/// the plane.
pub const LOW_RANK: usize = 3;

/// A rank-three term `Σ_κ m_κ b_κ b_κᵀ` of the Delassus operator: a biperiodic cell's
/// stress-controlled components eliminated from the step's problem (`crate::cell_coupling`:
/// `m_κ = g/(h V)`, `b_κ` stacked from each contact's `B_cκ`). Every contact the cell's change
/// reaches has a non-zero `b`, so the term is dense: it is kept apart from the sparse `W`.
#[derive(Debug, Clone, PartialEq)]
pub struct LowRank {
    /// `m_κ` of xx, yy, xy (1/(kg·m²)); 0 for a component whose rate is imposed.
    pub compliance: [f64; LOW_RANK],
    /// `B_cκ = (b_κ,2c, b_κ,2c+1)` per contact and component (m); zero for a contact the cell's
    /// change does not reach.
    pub coef: Vec<[[f64; 2]; LOW_RANK]>,
}

impl LowRank {
    /// `Σ_κ m_κ B_cκ B_c'κᵀ` as a 2×2 block `[nn, nt, tn, tt]` of contacts `c`, `c'`.
    pub fn block(&self, c: usize, d: usize) -> [f64; 4] {
        let (a, b) = (&self.coef[c], &self.coef[d]);
        let mut out = [0.0; 4];
        for k in 0..3 {
            let m = self.compliance[k];
            out[0] += m * a[k][0] * b[k][0];
            out[1] += m * a[k][0] * b[k][1];
            out[2] += m * a[k][1] * b[k][0];
            out[3] += m * a[k][1] * b[k][1];
        }
        out
    }

    /// Appends the term's non-zero entries `Σ_κ m_κ B_cκ B_c'κᵀ` of every pair of contacts it
    /// reaches to the triplets `(row, col, value)` of an assembled operator (scalar indices
    /// `2c + i`), the pairs in contact order: how `W` and the term are folded into one matrix.
    pub fn push_triplets(&self, ri: &mut Vec<usize>, ci: &mut Vec<usize>, v: &mut Vec<f64>) {
        let reached: Vec<usize> = (0..self.coef.len())
            .filter(|&c| self.coef[c] != [[0.0; 2]; 3])
            .collect();
        for &i in &reached {
            for &j in &reached {
                for (k, x) in self.block(i, j).into_iter().enumerate() {
                    if x != 0.0 {
                        ri.push(2 * i + k / 2);
                        ci.push(2 * j + k % 2);
                        v.push(x);
                    }
                }
            }
        }
    }

    /// `s_κ = b_κᵀ r` for impulses `r` (interleaved, length 2 nc).
    pub fn sums(&self, r: &[f64]) -> [f64; LOW_RANK] {
        let mut s = [0.0; 3];
        for (c, x) in self.coef.iter().zip(r.chunks_exact(2)) {
            for k in 0..3 {
                s[k] += c[k][0] * x[0] + c[k][1] * x[1];
            }
        }
        s
    }
}

impl FcProblem {
    /// Validates and assembles a problem from friction coefficients `mu` (length nc), free
    /// velocity `q` (length 2 nc) and Delassus matrix `w` (nc × nc blocks).
    ///
    /// Each diagonal block `W_αα` is split into its symmetric part (a [`Delassus2`], which must be
    /// positive definite: `W_nn > 0`, `W_nn W_tt − W_nt² > 0`) and its skew part
    /// `(W_nt − W_tn)/2` (non-zero only in problems whose W was printed with few digits).
    pub fn new(mu: Vec<f64>, q: Vec<f64>, w: BlockCsr2) -> Result<Self, FcError> {
        let nc = mu.len();
        if q.len() != 2 * nc {
            return Err(FcError::SizeMismatch {
                key: "q".into(),
                expected: 2 * nc,
                found: q.len(),
            });
        }
        if w.n() != nc {
            return Err(FcError::SizeMismatch {
                key: "W.shape".into(),
                expected: 2 * nc,
                found: 2 * w.n(),
            });
        }
        for (i, &m) in mu.iter().enumerate() {
            if !m.is_finite() {
                return Err(FcError::NonFinite {
                    key: format!("mu[{i}]"),
                });
            }
            if m < 0.0 {
                return Err(FcError::NegativeFriction {
                    contact: i,
                    value: m,
                });
            }
        }
        if let Some(i) = q.iter().position(|x| !x.is_finite()) {
            return Err(FcError::NonFinite {
                key: format!("q[{i}]"),
            });
        }
        let mut diag = Vec::with_capacity(nc);
        let mut skew = Vec::with_capacity(nc);
        for a in 0..nc {
            let b = w.diagonal(a);
            let d = Delassus2 {
                nn: b[0],
                nt: 0.5 * (b[1] + b[2]),
                tt: b[3],
            };
            // Positive definite with a relative margin: det > 1e-14 · W_nn W_tt.
            if !(d.nn > 0.0 && d.tt > 0.0 && d.det() > 1e-14 * d.nn * d.tt) {
                return Err(FcError::NotPositiveDefinite {
                    contact: a,
                    nn: d.nn,
                    nt: d.nt,
                    tt: d.tt,
                });
            }
            diag.push(d);
            skew.push(0.5 * (b[1] - b[2]));
        }
        Ok(Self {
            mu,
            q,
            w,
            diag,
            skew,
            low_rank: None,
        })
    }

    /// A problem assembled by the engine ([`crate::assemble`]): sizes and finiteness hold by
    /// construction, and a diagonal block may be singular (a contact between two bodies whose
    /// degrees of freedom are all imposed cannot react; the solvers leave it at zero).
    pub(crate) fn from_engine(mu: Vec<f64>, q: Vec<f64>, w: BlockCsr2) -> Self {
        Self::from_engine_with(mu, q, w, None)
    }

    /// [`FcProblem::from_engine`] with a [`LowRank`] term besides the sparse `W` (its diagonal
    /// blocks included in [`FcProblem::delassus`]).
    pub(crate) fn from_engine_with(
        mu: Vec<f64>,
        q: Vec<f64>,
        w: BlockCsr2,
        low_rank: Option<LowRank>,
    ) -> Self {
        let (diag, skew) = (0..mu.len())
            .map(|a| {
                let mut b = w.diagonal(a);
                if let Some(l) = &low_rank {
                    let d = l.block(a, a);
                    (0..4).for_each(|k| b[k] += d[k]);
                }
                (
                    Delassus2 {
                        nn: b[0],
                        nt: 0.5 * (b[1] + b[2]),
                        tt: b[3],
                    },
                    0.5 * (b[1] - b[2]),
                )
            })
            .unzip();
        Self {
            mu,
            q,
            w,
            diag,
            skew,
            low_rank,
        }
    }

    /// Whether a global method (Newton, the active-set finish, Lemke) takes this problem:
    /// [`FcError::LowRankTooLarge`] for a problem with a [`LowRank`] term and more than
    /// [`LOW_RANK_EXPAND_MAX_CONTACTS`] contacts. (Newton solves through the term without
    /// folding it, but on the 2000-grain cell whose grains follow it, about 5800 contacts, its
    /// iterations made the sensitivity re-solves 2.5 times slower and ended no more of them:
    /// 14 of 20 unresolved against 15, run 127.5 s against 49.9 s.)
    pub fn check_global(&self) -> Result<(), FcError> {
        let n = self.contacts();
        if self.low_rank.is_some() && n > LOW_RANK_EXPAND_MAX_CONTACTS {
            return Err(FcError::LowRankTooLarge {
                contacts: n,
                limit: LOW_RANK_EXPAND_MAX_CONTACTS,
            });
        }
        Ok(())
    }

    /// The rank-three term of the operator besides [`FcProblem::w`], if any.
    pub fn low_rank(&self) -> Option<&LowRank> {
        self.low_rank.as_ref()
    }

    /// The same problem with its [`LowRank`] term folded into `W` (dense among the contacts it
    /// reaches), for the methods that factor `W` (Newton, the active-set finish, Lemke) and for
    /// writing it; a clone without one.
    ///
    /// # Errors
    /// [`FcError::LowRankTooLarge`] above [`LOW_RANK_EXPAND_MAX_CONTACTS`] contacts.
    pub fn expanded(&self) -> Result<FcProblem, FcError> {
        self.check_global()?;
        let Some(l) = &self.low_rank else {
            return Ok(self.clone());
        };
        let n = self.contacts();
        let (mut ri, mut ci, mut v) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..n {
            for (j, b) in self.w.row(i) {
                for (k, &x) in b.iter().enumerate() {
                    ri.push(2 * i + k / 2);
                    ci.push(2 * j + k % 2);
                    v.push(x);
                }
            }
        }
        l.push_triplets(&mut ri, &mut ci, &mut v);
        let w = BlockCsr2::from_triplets(n, &ri, &ci, &v)?;
        Ok(Self::from_engine(self.mu.clone(), self.q.clone(), w))
    }

    /// Number of contacts `nc`.
    pub fn contacts(&self) -> usize {
        self.mu.len()
    }

    /// Friction coefficients μ_α (dimensionless), length nc.
    pub fn mu(&self) -> &[f64] {
        &self.mu
    }

    /// Free relative velocity `q` (m/s), interleaved `(q_n, q_t)` per contact, length 2 nc.
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// Delassus matrix `W` (1/kg) in block CSR: its sparse part, without the [`LowRank`] term
    /// if the problem has one ([`FcProblem::low_rank`], [`FcProblem::expanded`]).
    pub fn w(&self) -> &BlockCsr2 {
        &self.w
    }

    /// The friction cone of contact `α`, `|r_t| ≤ μ_α r_n`.
    pub fn cone(&self, alpha: usize) -> ProblemCone {
        Coulomb2 { mu: self.mu[alpha] }
    }

    /// Symmetric part of the diagonal block of contact `α`, as used by the local solver (the
    /// block of its [`ProblemCone`]).
    pub fn delassus(&self, alpha: usize) -> Delassus2 {
        self.diag[alpha]
    }

    /// Skew part `k_α = (W_nt − W_tn)/2` of the diagonal block of contact `α`
    /// (`W_αα = sym + [[0, k], [−k, 0]]`).
    pub fn diagonal_skew(&self, alpha: usize) -> f64 {
        self.skew[alpha]
    }

    /// `u = W r + q` for impulses `r` (length 2 nc).
    ///
    /// # Panics
    /// If `r.len() != 2 nc` (programming error).
    pub fn velocity(&self, r: &[f64]) -> Vec<f64> {
        assert_eq!(r.len(), self.q.len(), "r has the wrong length");
        let mut u = vec![0.0; r.len()];
        self.mul_add(r, &self.q, &mut u);
        u
    }

    /// `out = (W + Σ_κ m_κ b_κ b_κᵀ) x + y`: the whole operator, its [`LowRank`] term included
    /// (the sparse part alone, bit for bit as [`BlockCsr2::mul_add`], when there is none).
    pub fn mul_add(&self, x: &[f64], y: &[f64], out: &mut [f64]) {
        self.w.mul_add(x, y, out);
        if let Some(l) = &self.low_rank {
            let s = l.sums(x);
            for (c, o) in l.coef.iter().zip(out.chunks_exact_mut(2)) {
                for k in 0..3 {
                    let m = l.compliance[k] * s[k];
                    o[0] += c[k][0] * m;
                    o[1] += c[k][1] * m;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fc::{nsgs, FcOptions};

    /// Three contacts with a diagonal sparse `W` and a cell's rank-three term reaching two of
    /// them: `u = W r + q` with the term kept apart equals the folded operator's to rounding, and
    /// Gauss–Seidel solves both to the same impulses (to 10⁻⁹ of their scale at 10⁻¹²); the
    /// term's diagonal blocks are in the local solver's blocks. Above
    /// [`LOW_RANK_EXPAND_MAX_CONTACTS`] contacts the fold is refused.
    #[test]
    fn a_low_rank_term_kept_apart_is_the_folded_operator() {
        let n = 3;
        let (mut ri, mut ci, mut v) = (Vec::new(), Vec::new(), Vec::new());
        for a in 0..n {
            for (k, x) in [2.0 + a as f64, 0.1, 0.1, 3.0].into_iter().enumerate() {
                ri.push(2 * a + k / 2);
                ci.push(2 * a + k % 2);
                v.push(x);
            }
        }
        let w = BlockCsr2::from_triplets(n, &ri, &ci, &v).unwrap();
        let low = LowRank {
            compliance: [0.0, 0.8, 0.3],
            coef: vec![
                [[0.0; 2]; 3],
                [[0.0, 0.0], [0.5, -0.2], [0.1, 0.4]],
                [[0.0, 0.0], [-0.7, 0.3], [0.2, 0.1]],
            ],
        };
        // Approaching contacts: the cell's term carries load between contacts 1 and 2.
        let q = vec![-1.0, 0.2, -0.5, 0.3, -0.8, -0.1];
        let mu = vec![0.5, 0.3, 0.4];
        let kept = FcProblem::from_engine_with(mu, q, w, Some(low));
        let folded = kept.expanded().unwrap();
        assert!(folded.low_rank().is_none());
        let r = [0.3, 0.1, 0.2, -0.05, 0.4, 0.02];
        for (a, b) in kept.velocity(&r).iter().zip(folded.velocity(&r)) {
            assert!((a - b).abs() < 1e-14, "{a} vs {b}");
        }
        for a in 0..n {
            assert_eq!(kept.delassus(a), folded.delassus(a));
        }
        let options = FcOptions {
            tolerance: 1e-12,
            max_iterations: 10_000,
            ..FcOptions::default()
        };
        let (s1, s2) = (
            nsgs::solve(&kept, &options).unwrap(),
            nsgs::solve(&folded, &options).unwrap(),
        );
        assert!(s1.converged && s2.converged);
        let scale = s2.r.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        assert!(scale > 0.1, "loaded: {:?}", s2.r);
        for (a, b) in s1.r.iter().zip(&s2.r) {
            assert!((a - b).abs() < 1e-9 * scale, "{a} vs {b}");
        }
        let big = FcProblem::from_engine_with(
            vec![0.5; LOW_RANK_EXPAND_MAX_CONTACTS + 1],
            vec![0.0; 2 * (LOW_RANK_EXPAND_MAX_CONTACTS + 1)],
            BlockCsr2::from_triplets(LOW_RANK_EXPAND_MAX_CONTACTS + 1, &[], &[], &[]).unwrap(),
            Some(LowRank {
                compliance: [1.0, 0.0, 0.0],
                coef: vec![[[1.0, 0.0], [0.0; 2], [0.0; 2]]; LOW_RANK_EXPAND_MAX_CONTACTS + 1],
            }),
        );
        assert!(matches!(
            big.expanded(),
            Err(FcError::LowRankTooLarge { .. })
        ));
    }
}
