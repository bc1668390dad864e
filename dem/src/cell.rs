//! A biperiodic deformable cell (Parrinello & Rahman 1981; Lees & Edwards 1972 for simple
//! shear), and the mixed stress/strain-rate control of its deformation.
//!
//! The cell is the parallelogram spanned by the columns `a₁, a₂` of the matrix `h` (m), with its
//! origin at 0: a point `x` has the reduced (fractional) coordinates `s = h⁻¹ x`, and it lies in
//! the cell when `s ∈ [0, 1)²`. Space is tiled by the images `x + h k`, `k ∈ ℤ²`. The cell
//! deforms with the homogeneous velocity gradient `L` (1/s), the affine velocity field being
//! `v = L x`:
//!
//! ```text
//! ḣ = L h        integrated exactly for a step of constant L:  h ← exp(L Δt) h
//! ```
//!
//! so that for a constant `L` the cell after `n` steps is `exp(L n Δt) h₀` to rounding. Lees–Edwards
//! simple shear is `L = [[0, γ̇], [0, 0]]`: `a₂` tilts by `γ̇ Δt a₂·e_y` per step.
//!
//! **Images.** The image of grain `j` by `k` sits at `x_j + h k` and moves with
//! `v_j + L h k` (the affine velocity of the shift vector `h k`): the relative velocity of a
//! contact with an image includes the affine term `L h k`. Grain velocities are stored as total
//! velocities (fluctuation plus affine field); a grain that leaves the cell and is wrapped back
//! by `h k` gets `v ← v + L h k`, which keeps it identical to the image that entered.
//!
//! **Minimum image.** The shortest image of a separation `Δx` is found in reduced coordinates,
//! `Δs = h⁻¹ Δx − round(h⁻¹ Δx)`, then among the 9 neighbouring lattice shifts of that one
//! (which also covers a cell tilted up to half a period, where rounding alone can miss it).
//! The cell is kept reduced: when its tilt `a₁·a₂ / |a₁|²` exceeds ½, the lattice basis is
//! changed, `h ← h [[1, −m], [0, 1]]`, `m = round(a₁·a₂ / |a₁|²)`, as periodic-cell codes do
//! (the Lees–Edwards boundary's wrap; YADE's `Cell` flip; LAMMPS' triclinic box flip). The
//! lattice, so every pair distance, is unchanged by it.
//!
//! **Control** ([`CellControl`]): each of σ_xx, σ_yy, σ_xy is either imposed (the matching
//! component of `L` follows the stress error) or its strain rate is imposed; see
//! [`CellControl::update`] for the law and its stability limit. Methods of periodic cells in
//! contact dynamics: Radjai & Dubois (2011), "Discrete-element modeling of granular
//! materials", Wiley–ISTE, ch. on boundary conditions.
//!
//! Types are written with the names of the dimension layer (`crate::math`: [`DIM`],
//! [`Vector`], [`Tensor`]) so that a 3D cell has the same shape.

use nalgebra::SVector;
use serde::{Deserialize, Serialize};

use crate::error::DemError;
use crate::math::{Real, Tensor, Vector, DIM};

/// The components `(i, j)` of `L` a cell control can impose a stress on: xx, yy, xy.
pub const COMPONENTS: [(usize, usize); 3] = [(0, 0), (1, 1), (0, 1)];
/// One value per component of [`COMPONENTS`] (xx, yy, xy): a compliance, a free change `δ⁰`
/// or a change `δ` of `L` ([`CellControl::free_change`], [`crate::cell_coupling`]). Its length
/// is the number of components of `L` a stress may be imposed on (three in the plane), not the
/// rigid-body [`crate::math::SPATIAL_DIM`] that it happens to equal.
pub type ComponentValues = [Real; COMPONENTS.len()];
/// An integer lattice shift `k` (the image `x + h k`).
pub type Shift = SVector<i64, DIM>;

/// Largest tilt `a₁·a₂ / |a₁|²` of a reduced cell (half a period).
pub const MAX_TILT: f64 = 0.5;

/// A biperiodic deformable cell (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cell {
    /// Cell matrix, columns = cell vectors `a₁, a₂` (m); `det h > 0`.
    pub h: Tensor,
    /// Homogeneous velocity gradient `L = ∂v/∂x` (1/s), `L_ij = ∂v_i/∂x_j`.
    pub l: Tensor,
}

impl Cell {
    /// A cell with matrix `h` (columns the cell vectors, m) and velocity gradient `l` (1/s);
    /// refuses a non-finite or degenerate (`det h ≤ 0`) matrix or a non-finite gradient.
    pub fn new(h: Tensor, l: Tensor) -> Result<Self, DemError> {
        let c = Cell { h, l };
        c.check()?;
        Ok(c)
    }

    /// The rectangle `[0, lx) × [0, ly)` (m) at rest.
    pub fn rectangle(lx: f64, ly: f64) -> Result<Self, DemError> {
        Cell::new(Tensor::new(lx, 0.0, 0.0, ly), Tensor::zeros())
    }

    /// Checks the cell: finite, `det h > 0`, finite `L`.
    pub fn check(&self) -> Result<(), DemError> {
        let det = self.h.determinant();
        if !(self.h.iter().all(|x| x.is_finite()) && det.is_finite() && det > 0.0) {
            return Err(DemError::Parameter {
                name: "cell.h".into(),
                reason: format!(
                    "must be finite with a positive determinant (area), got det = {det}"
                ),
            });
        }
        if !self.l.iter().all(|x| x.is_finite()) {
            return Err(DemError::Parameter {
                name: "cell.l".into(),
                reason: "the velocity gradient must be finite".into(),
            });
        }
        Ok(())
    }

    /// Volume (area per metre of thickness) `det h` (m²).
    pub fn volume(&self) -> f64 {
        self.h.determinant()
    }

    /// `h⁻¹` (1/m).
    pub fn inverse(&self) -> Tensor {
        // det h > 0 is an invariant of the type (checked at construction, kept by `advance`).
        self.h.try_inverse().unwrap_or_else(Tensor::zeros)
    }

    /// Reduced coordinates `s = h⁻¹ x`.
    pub fn reduced(&self, x: &Vector) -> Vector {
        self.inverse() * x
    }

    /// The point of the cell equivalent to `x`: `(x + h k, k)` with `h⁻¹(x + h k) ∈ [0, 1)²`.
    pub fn wrap(&self, x: &Vector) -> (Vector, Shift) {
        let s = self.reduced(x);
        let mut k = Shift::zeros();
        let mut sw = s;
        for d in 0..DIM {
            let f = s[d].floor();
            let mut w = s[d] - f;
            let mut kd = -f;
            if w >= 1.0 {
                // s just below an integer: the fraction rounded up to 1.
                w = 0.0;
                kd -= 1.0;
            }
            sw[d] = w;
            k[d] = kd as i64;
        }
        if sw == s {
            return (*x, Shift::zeros());
        }
        (self.h * sw, k)
    }

    /// Shift vector `h k` (m) of the lattice shift `k`.
    pub fn shift_vector(&self, k: &Shift) -> Vector {
        self.h * k.map(|v| v as f64)
    }

    /// The shortest image of the separation `dx` (m): `(dx + h k, k)` minimising `|dx + h k|`
    /// (module documentation; exact for a reduced cell).
    pub fn min_image(&self, dx: &Vector) -> (Vector, Shift) {
        let s = self.reduced(dx);
        let k0: Shift = s.map(|v| -(v.round() as i64));
        let mut best = (self.shift_vector(&k0) + dx, k0);
        let mut best_n = best.0.norm_squared();
        for i in -1i64..=1 {
            for j in -1i64..=1 {
                if i == 0 && j == 0 {
                    continue;
                }
                let k = k0 + Shift::new(i, j);
                let y = dx + self.shift_vector(&k);
                let n = y.norm_squared();
                if n < best_n {
                    best = (y, k);
                    best_n = n;
                }
            }
        }
        best
    }

    /// Velocity of the image shift `k` relative to the original: `L h k` (m/s).
    pub fn image_velocity(&self, k: &Shift) -> Vector {
        self.l * self.shift_vector(k)
    }

    /// Affine velocity `L (x − c)` at `x` (m/s), relative to the centre `c = h (½, ½)` of the
    /// cell (the affine field is defined up to a uniform velocity; the centre keeps a
    /// homogeneous kick [`crate::World::set_velocity_gradient`] free of net momentum for a
    /// uniform packing).
    pub fn affine_velocity(&self, x: &Vector) -> Vector {
        self.l * (x - self.centre())
    }

    /// Centre of the cell `h (½, ½)` (m).
    pub fn centre(&self) -> Vector {
        self.h * Vector::repeat(0.5)
    }

    /// Advances the cell by `dt` (s) at constant `L`: `h ← exp(L dt) h`.
    pub fn advance(&mut self, dt: f64) {
        self.advance_with(&self.l.clone(), dt);
    }

    /// Advances the cell by `dt` (s) at the constant gradient `l` (1/s), `h ← exp(l dt) h`,
    /// leaving its own `L` unchanged (an implicit control's step deforms the cell with the
    /// `L⁺` its solve found before the grains take it, [`crate::cell_coupling`]).
    pub fn advance_with(&mut self, l: &Tensor, dt: f64) {
        let f = (l * dt).exp();
        self.h = f * self.h;
    }

    /// The tilt `a₁·a₂ / |a₁|²` of `a₂` along `a₁` (the Lees–Edwards shear offset over the
    /// period, γ for an initially rectangular cell in simple shear).
    pub fn tilt(&self) -> f64 {
        let a1 = self.h.column(0);
        let a2 = self.h.column(1);
        a1.dot(&a2) / a1.norm_squared()
    }

    /// Keeps the cell reduced: when [`Cell::tilt`] exceeds ½ in magnitude, `a₂ ← a₂ − m a₁`
    /// with `m = round(tilt)`. Returns `m` (0 when nothing changed). The lattice (hence every
    /// pair distance and image) is unchanged; grains must be wrapped into the new cell.
    pub fn remap(&mut self) -> i64 {
        let t = self.tilt();
        if t.abs() <= MAX_TILT {
            return 0;
        }
        let m = t.round();
        let a1 = self.h.column(0).into_owned();
        let mut a2 = self.h.column_mut(1);
        a2 -= a1 * m;
        m as i64
    }

    /// Widths of the cell across each pair of opposite faces (m): `det h / |a₂|` across the
    /// faces parallel to `a₂`, `det h / |a₁|` across those parallel to `a₁` (`1/|row_d(h⁻¹)|`).
    pub fn widths(&self) -> Vector {
        let inv = self.inverse();
        Vector::from_fn(|d, _| 1.0 / inv.row(d).norm())
    }

    /// Strain rate `D = (L + Lᵀ)/2` (1/s).
    pub fn strain_rate(&self) -> Tensor {
        (self.l + self.l.transpose()) * 0.5
    }
}

/// What is imposed on one component of the cell's deformation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Imposed {
    /// The velocity gradient component `L_ij` (1/s): a strain rate (a shear rate for xy).
    Rate(f64),
    /// The mean stress component `σ_ij` (Pa, tension positive): the cell deforms to reach it.
    Stress(f64),
}

/// Mixed control of the cell (YADE's `PeriTriaxController`, MercuryDPM's
/// `StressStrainControlBoundary`): each of σ_xx, σ_yy, σ_xy is either imposed or its strain
/// rate is. `L_yx = 0` always (`a₁` stays along x: no rigid rotation of the cell).
///
/// The law ([`CellControl::update`]), after each step, on every stress-controlled component:
///
/// ```text
/// L*_ij = clamp(g (σ*_ij − σ_ij), −ε̇_max, ε̇_max)
/// L_ij ← L_ij + α (L*_ij − L_ij),   α = min(Δt/τ, 1)
/// ```
///
/// a proportional law of gain `g` (1/(Pa·s)) saturated at the strain rate `ε̇_max`, with an
/// optional first-order filter of time `τ` (`τ ≤ Δt`: none). The sign is that of a stable
/// material: a stress more compressive than the target (σ < σ*) opens the cell (`L > 0`), a
/// shear stress below its target shears faster. With `L` applied to every grain at once
/// ([`crate::World::set_velocity_gradient`]), a jammed packing of rigid grains answers a strain
/// rate within the step, by the impulses that stop its contacts from approaching:
/// `σ ≈ K L` with `K ≈ ρ d²/Δt` (a contact of branch ≈ d closing at `L d` needs the impulse
/// `≈ m L d`, `N_c ≈ 2N` contacts in the volume `≈ N d²`). The loop is then the iteration
/// `L ← L + α (g (σ* − K L) − L)`, whose factor `1 − α (1 + g K)` gives the **stability
/// limit** `α (1 + g K) < 2`, and no overshoot for `α (1 + g K) ≤ 1`: without filter (α = 1),
/// `g < Δt / (ρ d²)`. The scenarios take `g = ½ Δt/(ρ d²)`, no filter. It is quasi-static
/// when `ε̇_max` keeps the inertial number of the cell's deformation
/// `I_cell = ε̇_max d / √(p/ρ)` small (the scenarios take 10⁻², and a loose packing reaches
/// `|σ| ≈ K ε̇_max ≈ I_cell (d √(ρ/p) / Δt) p` on jamming, below `p` for their time steps).
/// In a steady state `L_ij` averages 0 on a stress-controlled component, so the mean stress
/// error does too.
///
/// **Limit of an explicit law with rigid grains.** Within a step `L` is imposed; when the
/// packing's contact network cannot follow it (a jammed packing compressed, or sheared faster
/// than it can dilate) the step has no bounded solution and its impulses grow to the sweep cap
/// (stress spikes of many orders of magnitude). The cell of a contact-dynamics code is then
/// properly an unknown of the contact problem (a massive cell, as in Parrinello–Rahman). Here,
/// without touching the contact solver, the step is solved again with a larger `L` until its
/// stress lies within [`CellControl::tolerance`] of the targets on the compressive side (an
/// implicit, massless cell for those steps; [`crate::World::step`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CellControl {
    /// σ_xx or L_xx.
    pub xx: Imposed,
    /// σ_yy or L_yy.
    pub yy: Imposed,
    /// σ_xy or L_xy (the shear rate γ̇ of `v_x = γ̇ y`).
    pub xy: Imposed,
    /// Gain `g` (1/(Pa·s)).
    pub gain: f64,
    /// Largest strain rate `ε̇_max` of a stress-controlled component (1/s).
    pub max_rate: f64,
    /// Filter time `τ` (s); at most the time step: no filter.
    pub relaxation: f64,
    /// Tolerance of the implicit correction (Pa): a step whose mean signed stress error
    /// [`CellControl::signed_error`] is more compressive than `−tolerance` is solved again with
    /// a larger `L` ([`crate::World::step`]); 0 disables it.
    #[serde(default)]
    pub tolerance: f64,
    /// Largest number of re-solves of one step by the implicit correction.
    #[serde(default)]
    pub max_corrections: usize,
    /// The stress-controlled components as unknowns of each step's contact problem
    /// ([`crate::cell_coupling`]): `L⁺ = clamp(L⁻, ±ε̇_max) + g (σ* − σ⁺)` with the stress `σ⁺`
    /// of the step's own impulses, instead of the explicit law above (then `relaxation`,
    /// `tolerance` and `max_corrections` are not used, no step is solved twice, and `g` has no
    /// stability limit). The rates of the other components are imposed at the end of each step.
    #[serde(default)]
    pub implicit: bool,
    /// Under the implicit law, the grains follow the cell's change `δ` within the step
    /// (Parrinello–Rahman's scaled coordinates: every contact between two grains sees `δ` on
    /// its whole branch vector, and the grains move with it) instead of at its end (only the
    /// contacts across the boundary see `δ`, through their image shift; [`crate::cell_coupling`]).
    /// Within the step, the uniform deformation of the packing is a local mode of each contact
    /// instead of a wave that Gauss–Seidel carries in from the boundary: at 2000 grains, I = 0.01
    /// and 100 sweeps a step, `σ_yy` swung by ±66 % of its target from step to step (a period of
    /// 9–10 steps) at the end of the step and by 0.1 % within it, and the largest overlap fell
    /// from 0.46 % to 0.026 % of the smallest radius; 2.5 mm grains sheared at I = 1, whose cell
    /// runs away at step 109 otherwise, run through. Gauss–Seidel converges more slowly on it
    /// (200 grains, I = 0.04, to 10⁻⁴: 28 s against 3.9 s). The cell's term is then dense
    /// among all contacts: the global methods fold it into `W` only up to
    /// [`crate::fc::LOW_RANK_EXPAND_MAX_CONTACTS`] contacts (Gauss–Seidel above).
    #[serde(default)]
    pub affine: bool,
}

impl CellControl {
    /// Checks the parameters (gain, rate cap positive and finite, `τ ≥ 0`) and the imposed
    /// values (finite).
    pub fn check(&self) -> Result<(), DemError> {
        for (n, v) in [("gain", self.gain), ("max_rate", self.max_rate)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(DemError::Parameter {
                    name: format!("cell_control.{n}"),
                    reason: format!("must be finite and > 0, got {v}"),
                });
            }
        }
        if !(self.tolerance.is_finite() && self.tolerance >= 0.0) {
            return Err(DemError::Parameter {
                name: "cell_control.tolerance".into(),
                reason: format!("must be finite and ≥ 0 Pa, got {}", self.tolerance),
            });
        }
        if !(self.relaxation.is_finite() && self.relaxation >= 0.0) {
            return Err(DemError::Parameter {
                name: "cell_control.relaxation".into(),
                reason: format!("must be finite and ≥ 0 s, got {}", self.relaxation),
            });
        }
        for (n, c) in [("xx", self.xx), ("yy", self.yy), ("xy", self.xy)] {
            let v = match c {
                Imposed::Rate(v) | Imposed::Stress(v) => v,
            };
            if !v.is_finite() {
                return Err(DemError::Parameter {
                    name: format!("cell_control.{n}"),
                    reason: format!("must be finite, got {v}"),
                });
            }
        }
        Ok(())
    }

    /// The implicit control ([`CellControl::implicit`]) of xx, yy, xy with the gain `gain`
    /// (1/(Pa·s)) and the reference-rate cap `max_rate` (1/s); the explicit law's fields
    /// (`relaxation`, `tolerance`, `max_corrections`) are zero, unused.
    pub fn implicit_law(xx: Imposed, yy: Imposed, xy: Imposed, gain: f64, max_rate: f64) -> Self {
        CellControl {
            xx,
            yy,
            xy,
            gain,
            max_rate,
            relaxation: 0.0,
            tolerance: 0.0,
            max_corrections: 0,
            implicit: true,
            affine: false,
        }
    }

    /// What is imposed on xx, yy and xy, in that order ([`COMPONENTS`]).
    pub fn components(&self) -> [Imposed; 3] {
        [self.xx, self.yy, self.xy]
    }

    /// The same control with the grains following the cell's change within the step or not
    /// ([`CellControl::affine`]).
    pub fn with_affine(self, affine: bool) -> Self {
        CellControl { affine, ..self }
    }

    /// The change `δ⁰_κ = clamp(L_κ, ±ε̇_max) − L_κ + g (σ*_κ − σ^kin_κ)` of each
    /// stress-controlled component `κ` (xx, yy, xy; 0 where the rate is imposed) over a step of
    /// the implicit law ([`CellControl::implicit`], [`crate::cell_coupling`]) that carries no
    /// contact impulse, from the gradient `l` and the kinetic stress `kinetic` (Pa) at the start
    /// of the step (1/s).
    pub fn free_change(&self, l: &Tensor, kinetic: &Tensor) -> ComponentValues {
        let mut d = [0.0; 3];
        for (k, (c, ij)) in self.components().into_iter().zip(COMPONENTS).enumerate() {
            if let Imposed::Stress(target) = c {
                d[k] = l[ij].clamp(-self.max_rate, self.max_rate) - l[ij]
                    + self.gain * (target - kinetic[ij]);
            }
        }
        d
    }

    /// The velocity gradient for the next step of the implicit law ([`CellControl::implicit`]):
    /// `l` with the imposed rates set and `L_yx = 0`; the stress-controlled components are
    /// those the step's solve found.
    pub fn implicit_next(&self, l: &Tensor) -> Tensor {
        let mut out = *l;
        out[(1, 0)] = 0.0;
        for (c, ij) in self.components().into_iter().zip(COMPONENTS) {
            if let Imposed::Rate(v) = c {
                out[ij] = v;
            }
        }
        out
    }

    /// The velocity gradient after a step of `dt` (s) that ended with the mean stress `sigma`
    /// (Pa, symmetric), from the current `l` (law in the type's documentation).
    pub fn update(&self, l: &Tensor, sigma: &Tensor, dt: f64) -> Tensor {
        let alpha = if self.relaxation > dt {
            dt / self.relaxation
        } else {
            1.0
        };
        let mut out = *l;
        out[(1, 0)] = 0.0;
        for (c, (i, j)) in [(self.xx, (0, 0)), (self.yy, (1, 1)), (self.xy, (0, 1))] {
            out[(i, j)] = match c {
                Imposed::Rate(v) => v,
                Imposed::Stress(target) => {
                    let want =
                        (self.gain * (target - sigma[(i, j)])).clamp(-self.max_rate, self.max_rate);
                    l[(i, j)] + alpha * (want - l[(i, j)])
                }
            };
        }
        out
    }

    /// Mean signed stress error `(1/n) Σ (σ_ij − σ*_ij)` over the `n` stress-controlled
    /// components (Pa): negative when the stress is more compressive than the targets; 0 when
    /// none is controlled. It grows with the rates of those components.
    pub fn signed_error(&self, sigma: &Tensor) -> f64 {
        let mut s = 0.0;
        let mut n = 0;
        for (c, ij) in [(self.xx, (0, 0)), (self.yy, (1, 1)), (self.xy, (0, 1))] {
            if let Imposed::Stress(t) = c {
                s += sigma[ij] - t;
                n += 1;
            }
        }
        if n > 0 {
            s / n as f64
        } else {
            0.0
        }
    }

    /// The unit change of `L` of the implicit correction: 1 on every stress-controlled
    /// component, 0 elsewhere.
    pub fn direction(&self) -> Tensor {
        let mut m = Tensor::zeros();
        for (c, ij) in [(self.xx, (0, 0)), (self.yy, (1, 1)), (self.xy, (0, 1))] {
            if let Imposed::Stress(_) = c {
                m[ij] = 1.0;
            }
        }
        m
    }

    /// Largest stress error `|σ*_ij − σ_ij|` over the stress-controlled components (Pa); 0 when
    /// none is.
    pub fn stress_error(&self, sigma: &Tensor) -> f64 {
        [(self.xx, (0, 0)), (self.yy, (1, 1)), (self.xy, (0, 1))]
            .iter()
            .filter_map(|&(c, ij)| match c {
                Imposed::Stress(t) => Some((t - sigma[ij]).abs()),
                Imposed::Rate(_) => None,
            })
            .fold(0.0, f64::max)
    }
}
