//! The contact set of a step: hot rows read by the solver (body indices, frame, lever arms,
//! Delassus block, impulse) and cold geometry kept for output, both in the same order, sorted by
//! collider pair so that warm starting is a merge with the previous step.

use serde::{Deserialize, Serialize};

use crate::local::{ContactStatus, Coulomb2, Delassus2};
use crate::math::Spatial;

/// The friction cone of the engine's contact rows ([`ContactRow::cone`]): the plane Coulomb
/// cone. The one name a 3D engine changes (to `crate::dim3::Coulomb3`, with the rows' frame,
/// Delassus block and impulse in three components); the sweeps are written against
/// [`crate::cone::FrictionCone`] through [`crate::sweep::SweepRow`].
pub type RowCone = Coulomb2;

/// What the solver reads and writes for one contact (hot data, 17 words).
///
/// Kinematics with `t = (−n_y, n_x)` and lever arms `ρ_a = x − c_a`, `ρ_b = x − c_b`:
/// ```text
/// u_n = n·(v_b − v_a) + (ρ_b×n) ω_b − (ρ_a×n) ω_a + shift + affine_n
/// u_t = t·(v_b − v_a) + (ρ_b×t) ω_b − (ρ_a×t) ω_a + affine_t
/// ```
/// which is `u = H v + shift + affine`; `affine` is the velocity `L h k` of the image of `b`
/// that `a` touches across a deformable periodic cell ([`crate::cell`]), 0 otherwise; the impulse `R = r_n n + r_t t` acts on `b` and `−R` on `a`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[repr(C)]
pub struct ContactRow {
    /// Body `a` (the wall, or the disk of lower collider index).
    pub a: u32,
    /// Body `b`.
    pub b: u32,
    /// Unit normal from `a` to `b`.
    pub n: [f64; 2],
    /// Lever cross products `[ρ_a×n, ρ_a×t, ρ_b×n, ρ_b×t]` (m).
    pub k: [f64; 4],
    /// Local Delassus block `W_αα = H_α M⁻¹ H_αᵀ` (1/kg).
    pub w: Delassus2,
    /// Constant shift of the normal velocity (m/s): `max(g,0)/(hθ)` lets an open gap close
    /// within the step; `e u_n⁻` adds Newton restitution on impacts.
    pub shift: f64,
    /// Affine velocity of the periodic image of `b` in the contact frame, `(n·L h k, t·L h k)`
    /// (m/s), with `h k` the image's shift vector ([`crate::cell`]); zero inside the cell.
    #[serde(default)]
    pub affine: [f64; 2],
    /// Friction coefficient μ.
    pub mu: f64,
    /// Impulse `(r_n, r_t)` (N·s).
    pub r: [f64; 2],
    /// The contact's part of the final basis of the last Lemke solve that ended a step's solve
    /// ([`crate::fc::lemke::Warm::basis`]: bit `j` set where `z_j` of `(r_n, β⁺, β⁻, λ)` is
    /// basic), carried from step to step with the impulse as the next Lemke path's warm start;
    /// 0 for a new contact.
    #[serde(default)]
    pub basis: u8,
}

impl ContactRow {
    /// The contact's friction cone, `|r_t| ≤ μ r_n` with its coefficient [`ContactRow::mu`].
    #[inline(always)]
    pub fn cone(&self) -> RowCone {
        Coulomb2 { mu: self.mu }
    }

    /// Local relative velocity `u = H v + (shift, 0) + affine` from body velocities
    /// `[v_x, v_y, ω]`.
    #[inline(always)]
    pub fn velocity(&self, va: &Spatial, vb: &Spatial) -> [f64; 2] {
        let [nx, ny] = self.n;
        let dx = vb[0] - va[0];
        let dy = vb[1] - va[1];
        [
            nx * dx + ny * dy + self.k[2] * vb[2] - self.k[0] * va[2] + self.shift + self.affine[0],
            -ny * dx + nx * dy + self.k[3] * vb[2] - self.k[1] * va[2] + self.affine[1],
        ]
    }

    /// Apply an impulse increment `d = (Δr_n, Δr_t)` to the body velocities:
    /// `v_b += M_b⁻¹ H_bᵀ d`, `v_a −= M_a⁻¹ H_aᵀ d`.
    #[inline(always)]
    pub fn apply(
        &self,
        d: [f64; 2],
        va: &mut Spatial,
        ia: &Spatial,
        vb: &mut Spatial,
        ib: &Spatial,
    ) {
        let [nx, ny] = self.n;
        let fx = d[0] * nx - d[1] * ny;
        let fy = d[0] * ny + d[1] * nx;
        vb[0] += ib[0] * fx;
        vb[1] += ib[1] * fy;
        vb[2] += ib[2] * (self.k[2] * d[0] + self.k[3] * d[1]);
        va[0] -= ia[0] * fx;
        va[1] -= ia[1] * fy;
        va[2] -= ia[2] * (self.k[0] * d[0] + self.k[1] * d[1]);
    }

    /// The generalised impulse `H_bᵀ r` (side 1) or `−H_aᵀ r` (side 0) on one body of the
    /// contact, before the inverse mass: `(F_x, F_y, torque)`·h.
    #[inline(always)]
    pub fn impulse_on(&self, side: u32, r: [f64; 2]) -> Spatial {
        let [nx, ny] = self.n;
        let fx = r[0] * nx - r[1] * ny;
        let fy = r[0] * ny + r[1] * nx;
        if side == 1 {
            [fx, fy, self.k[2] * r[0] + self.k[3] * r[1]]
        } else {
            [-fx, -fy, -(self.k[0] * r[0] + self.k[1] * r[1])]
        }
    }

    /// The local Delassus block from the inverse masses of both bodies.
    #[inline]
    pub fn delassus(n: [f64; 2], k: [f64; 4], ia: &Spatial, ib: &Spatial) -> Delassus2 {
        let [nx, ny] = n;
        let (tx, ty) = (-ny, nx);
        let lin = |i: &Spatial| {
            (
                i[0] * nx * nx + i[1] * ny * ny,
                i[0] * nx * tx + i[1] * ny * ty,
                i[0] * tx * tx + i[1] * ty * ty,
            )
        };
        let (an, at_, att) = lin(ia);
        let (bn, bt, btt) = lin(ib);
        Delassus2 {
            nn: an + bn + ia[2] * k[0] * k[0] + ib[2] * k[2] * k[2],
            nt: at_ + bt + ia[2] * k[0] * k[1] + ib[2] * k[2] * k[3],
            tt: att + btt + ia[2] * k[1] * k[1] + ib[2] * k[3] * k[3],
        }
    }
}

/// Geometry of one contact kept for output (cold data).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ContactGeometry {
    /// Collider pair key `(collider_a << 32) | collider_b`; identity across steps.
    pub key: u64,
    /// Contact point (m), on the surface of `b`.
    pub point: [f64; 2],
    /// Gap at the start of the step (m).
    pub gap: f64,
    /// Lever arm `x − c_a` (m).
    pub lever_a: [f64; 2],
    /// Lever arm `x − c_b` (m).
    pub lever_b: [f64; 2],
    /// Normal restitution coefficient of the pair.
    pub restitution: f64,
    /// Gap below which the contact counts as closed (m): [`CLOSED_GAP`] times the smaller
    /// radius of the pair.
    #[serde(default)]
    pub closed_gap: f64,
    /// Shift vector `h k` (m) of the periodic image of `b` that `a` touches across a
    /// deformable cell ([`crate::cell`]); zero inside the cell or without one.
    #[serde(default)]
    pub image: [f64; 2],
}

/// A gap below this fraction of the smaller radius counts as closed: no gap-closing velocity is
/// asked of it (a modelling tolerance of 10⁻⁴ R on contact). Such gaps are rounding-level
/// leftovers of settled packings. Asking a statically indeterminate cluster to close them all
/// within one step makes Gauss–Seidel stall: on a settled 350-grain column the error stayed at
/// 1.2·10⁻⁵ after 6·10⁴ sweeps with the shifts, and reached 10⁻⁶ in about 100 sweeps without.
pub const CLOSED_GAP: f64 = 1e-4;

/// All contacts of a step, sorted by `geometry.key`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct ContactSet {
    /// Solver rows.
    pub rows: Vec<ContactRow>,
    /// Output geometry, same order.
    pub geometry: Vec<ContactGeometry>,
    /// Local-law outcome after the solve, same order.
    pub status: Vec<ContactStatus>,
    /// Time step (s) of the step these impulses belong to (0 before any step).
    #[serde(default)]
    pub dt: f64,
}

impl ContactSet {
    /// Each contact's solver row with its geometry, in order.
    pub fn rows_with_geometry(&self) -> impl Iterator<Item = (&ContactRow, &ContactGeometry)> {
        self.rows.iter().zip(&self.geometry)
    }

    /// Each contact's solver row (to change) with its geometry, in order.
    pub fn rows_with_geometry_mut(
        &mut self,
    ) -> impl Iterator<Item = (&mut ContactRow, &ContactGeometry)> {
        self.rows.iter_mut().zip(&self.geometry)
    }

    /// Number of contacts.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// True when there is no contact.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Remove every contact, keeping the allocations.
    pub fn clear(&mut self) {
        self.rows.clear();
        self.geometry.clear();
        self.status.clear();
    }

    /// Warm start: copy the impulses of `previous` onto the contacts with the same key (both sets
    /// sorted by key; a linear merge), scaled by `scale` (ratio of time steps).
    pub fn warm_start_from(&mut self, previous: &ContactSet, scale: f64) {
        let mut j = 0;
        let pk = &previous.geometry;
        for (i, g) in self.geometry.iter().enumerate() {
            while j < pk.len() && pk[j].key < g.key {
                j += 1;
            }
            if j < pk.len() && pk[j].key == g.key {
                let r = previous.rows[j].r;
                self.rows[i].r = [r[0] * scale, r[1] * scale];
                self.rows[i].basis = previous.rows[j].basis;
            } else {
                self.rows[i].r = [0.0, 0.0];
                self.rows[i].basis = 0;
            }
        }
    }
}
