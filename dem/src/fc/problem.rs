//! The data of one 2D frictional-contact problem in local (reduced) form.

use super::block_csr::BlockCsr2;
use super::error::FcError;
use crate::local::Delassus2;

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
        })
    }

    /// A problem assembled by the engine ([`crate::assemble`]): sizes and finiteness hold by
    /// construction, and a diagonal block may be singular (a contact between two bodies whose
    /// degrees of freedom are all imposed cannot react; the solvers leave it at zero).
    pub(crate) fn from_engine(mu: Vec<f64>, q: Vec<f64>, w: BlockCsr2) -> Self {
        let (diag, skew) = (0..mu.len())
            .map(|a| {
                let b = w.diagonal(a);
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
        }
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

    /// Delassus matrix `W` (1/kg) in block CSR.
    pub fn w(&self) -> &BlockCsr2 {
        &self.w
    }

    /// Symmetric part of the diagonal block of contact `α`, as used by the local solver.
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
        self.w.mul_add(r, &self.q, &mut u);
        u
    }
}
