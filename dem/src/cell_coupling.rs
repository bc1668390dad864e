//! The stress-controlled components of a biperiodic cell as unknowns of the step's contact
//! problem: the *implicit* cell control ([`CellControl::implicit`]).
//!
//! With the velocity gradient `L` of the cell fixed during a step, a jammed packing of rigid
//! grains asked to deform in a way its contact network cannot follow has no bounded contact
//! impulses: the step's problem is infeasible (Lemke's method ends on a ray) and every solver
//! stops at its cap. A periodic cell whose stress is imposed is properly a degree of freedom of
//! the dynamics (Parrinello & Rahman 1981, J. Appl. Phys. 52, 7182; in contact dynamics,
//! Radjai & Dubois 2011, "Discrete-element modeling of granular materials", ch. 7); here its
//! stress-controlled components `L_κ`, `κ ∈ {xx, yy, xy}`, are solved for together with the
//! impulses, by the implicit law
//!
//! ```text
//! L⁺_κ = L^ref_κ + g (σ*_κ − σ⁺_κ),     L^ref_κ = clamp(L⁻_κ, −ε̇_max, ε̇_max),
//! σ⁺_ij = σ^kin_ij − (1/(h V)) Σ_{image contacts c} R_c,i (h k_c)_j
//! ```
//!
//! (`g` the gain, 1/(Pa·s); `ε̇_max` the rate cap; `R_c` the impulse of contact `c` on the image
//! of `b` at `x_b + h k_c`, in N·s; `h` the time step; `V` the cell's volume, area × thickness;
//! `σ^kin = −(1/V) Σ_p m_p ṽ_p ⊗ ṽ_p` the kinetic stress of the velocity fluctuations at the
//! start of the step, tension positive). `σ⁺` is the mean stress carried across the cell's
//! boundary (the virial of the periodic images, equal to the Love–Weber stress of
//! [`crate::World::cell_stress`] at equilibrium): its contact part is linear in the impulses, so
//! `δ = L⁺ − L⁻` is
//!
//! ```text
//! δ_κ = δ⁰_κ + m Σ_c B_cκ · r_c,    δ⁰_κ = L^ref_κ − L⁻_κ + g (σ*_κ − σ^kin_κ),   m = g/(h V),
//! B_cκ = (n_i (h k_c)_j, t_i (h k_c)_j)   for κ = (i, j)
//! ```
//!
//! and the local velocity of an image contact gains `Σ_κ B_cκ δ_κ` (the image moves with
//! `L⁺ h k`). Eliminating `δ`, the step's problem is the frictional-contact problem
//!
//! ```text
//! u = (W + m Σ_κ B_κ B_κᵀ) r + q + Σ_κ B_κ δ⁰_κ
//! ```
//!
//! whose operator is still symmetric positive semidefinite: the cell adds a rank-one term per
//! controlled component, coupling the contacts across the boundary. A jammed packing now finds
//! the cell rate it can follow, with the stress error `(L⁺ − L^ref)/g`: the change of that rate
//! over one step divided by the gain. In the limit `g → ∞` the cell is massless and its stress
//! is exactly `σ*`; the law is a Parrinello–Rahman cell of mass `h V/g` integrated by implicit
//! Euler, whose reference rate saturates at `ε̇_max`, so that a packing without contacts closes at
//! most at `ε̇_max + g |σ*|`. It has no stability limit on `g` (implicit).
//!
//! Gauss–Seidel keeps `δ` current: the update of a coupled contact uses the augmented diagonal
//! block `W_cc + m Σ_κ B_cκ B_cκᵀ` and the velocity with the current `δ`, then adds
//! `m B_cκ · Δr_c` to `δ_κ` (an exact Gauss–Seidel step on the eliminated problem). The global
//! methods take the cell's term as a rank-three term beside the sparse operator
//! ([`CellCoupling::low_rank`], [`crate::fc::LowRank`]).
//!
//! *Parallel sweeps* ([`CellCoupling::sweep_coupled`], `solver.parallel`). Two contacts
//! conflict when they share a mobile body or are both coupled to the cell (`δ` is read and
//! written by every coupled update). The colour-ordered sweep of [`crate::parallel`] (Renouf,
//! Dubois & Alart 2004, "A parallel version of the non smooth contact dynamics algorithm
//! applied to the simulation of granular media", J. Comput. Appl. Math. 168, 375–382: the
//! contacts of a colour class, sharing no body, are updated concurrently) therefore visits
//! the contacts *not* coupled, whose updates do not depend on `δ`
//! (`u_c = H_c v + q_c` without a `B_cκ` term), then the coupled ones on one thread with `δ`
//! current:
//!
//! ```text
//! for block, class in colouring:    (blocks concurrently, then classes; coupled c skipped)
//!     r_c ← solve_local(W_cc, u_c − W_cc r_c)
//! for c in coupled (slot order):    (one thread)
//!     u_c includes Σ_κ B_cκ δ_κ;  r_c ← solve_local(W_cc + m Σ_κ B_cκ B_cκᵀ, …);
//!     δ_κ += m B_cκ · Δr_c
//! ```
//!
//! Every contact is visited once per sweep in an order fixed by the positions (the colouring)
//! and the contact order (the slots): one Gauss–Seidel sweep, exact on the eliminated problem,
//! in another order than the natural one, with the same bits on any number of threads. The
//! contacts through the boundary are a few percent of a large cell's (about 2 % at 10⁴
//! grains). When the grains follow the cell within the step every contact is coupled and that
//! one-thread pass would be the whole sweep: each block and each class is then swept in fixed
//! units, each with its own copy of `δ`, the units' increments added in unit order after the
//! phase ([`CellCoupling::sweep_coupled`]; deterministic, a Jacobi step on the cell's rank-3
//! term between the units, Gauss–Seidel within them).

use crate::cell::{Cell, CellControl, ComponentValues, Imposed, COMPONENTS};
use crate::colouring::ContactColouring;
use crate::contact::{ContactGeometry, ContactRow};
use crate::local::Delassus2;
use crate::math::Spatial;
use crate::math::Tensor;
use crate::parallel::{
    coloured_sweep_where, coloured_units, shared_sweep_inputs, update_shared, TASK,
};
use crate::sweep::update;
use rayon::prelude::*;

/// No coupling slot.
const NONE: u32 = u32::MAX;

/// The cell's stress-controlled components as unknowns of one step's contact problem (module
/// documentation): the contacts through the cell's boundary, their coupling coefficients, and
/// the current change `δ` of `L`.
#[derive(Debug, Clone, Default)]
pub struct CellCoupling {
    /// `m_κ = g/(h V)` per component, 0 where the rate is imposed (1/(kg·m²)).
    compliance: ComponentValues,
    /// `δ⁰_κ` (1/s).
    delta0: ComponentValues,
    /// Current `δ_κ` (1/s); every coupled row's `affine` is `base + Σ_κ B_κ δ_κ` outside a sweep.
    delta: ComponentValues,
    /// Coupled rows (indices into the step's rows).
    rows: Vec<u32>,
    /// Each coupled row's affine velocity with `L⁻` (m/s, contact frame).
    base: Vec<[f64; 2]>,
    /// `B_cκ` of each coupled row (m).
    coef: Vec<[[f64; 2]; 3]>,
    /// Each coupled row's own Delassus block, without the cell's term.
    own: Vec<Delassus2>,
    /// Row → slot in the lists above, or [`NONE`].
    slot: Vec<u32>,
    /// Whether the rows' blocks are augmented now.
    attached: bool,
    /// Whether some grains follow the cell's change within the step (their contacts are all
    /// coupled, by their whole branch vectors).
    within_step: bool,
}

impl CellCoupling {
    /// The coupling of a step of `cell` under `ctl` (implicit), with the contacts `rows` and
    /// their `geometry` (image shift vectors), the impulse time `dt` (s), the grains'
    /// `thickness` (m) and the impulse-free change `delta0` ([`CellControl::free_change`] at the
    /// start of the step). `δ` is set from the rows' (warm-start) impulses and the coupled rows'
    /// affine velocities with it ([`CellCoupling::refresh`]). `None` when `ctl` is not implicit
    /// or imposes no stress.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctl: &CellControl,
        cell: &Cell,
        rows: &mut [ContactRow],
        geometry: &[ContactGeometry],
        follows: &[bool],
        dt: f64,
        thickness: f64,
        delta0: ComponentValues,
    ) -> Option<Self> {
        if !ctl.implicit {
            return None;
        }
        let volume = cell.volume() * thickness;
        let m = ctl.gain / (dt * volume);
        let mut compliance = [0.0; 3];
        let mut any = false;
        for (k, imposed) in ctl.components().into_iter().enumerate() {
            if let Imposed::Stress(_) = imposed {
                compliance[k] = m;
                any = true;
            }
        }
        if !(any && m.is_finite() && m > 0.0) {
            return None;
        }
        let mut c = CellCoupling {
            compliance,
            delta0,
            slot: vec![NONE; rows.len()],
            within_step: follows.iter().any(|&f| f),
            ..CellCoupling::default()
        };
        for (i, (row, geo)) in rows.iter().zip(geometry).enumerate() {
            // The branch vector the cell's change acts on: between the centres when both
            // bodies follow it within the step, else the image shift alone.
            let follow = |b: u32| follows.get(b as usize).copied().unwrap_or(false);
            let both = follow(row.a) && follow(row.b);
            let arm = if both {
                [
                    geo.lever_a[0] - geo.lever_b[0],
                    geo.lever_a[1] - geo.lever_b[1],
                ]
            } else {
                geo.image
            };
            if arm == [0.0, 0.0] {
                continue;
            }
            let [nx, ny] = row.n;
            let (n, t) = ([nx, ny], [-ny, nx]);
            let mut coef = [[0.0; 2]; 3];
            let mut coupled = false;
            for (k, &(a, b)) in COMPONENTS.iter().enumerate() {
                if compliance[k] > 0.0 {
                    coef[k] = [n[a] * arm[b], t[a] * arm[b]];
                    coupled |= coef[k] != [0.0, 0.0];
                }
            }
            if coupled {
                c.slot[i] = c.rows.len() as u32;
                c.rows.push(i as u32);
                c.base.push(row.affine);
                c.coef.push(coef);
                c.own.push(row.w);
            }
        }
        c.refresh(rows);
        Some(c)
    }

    /// Number of contacts of the step the coupling was made for (coupled or not).
    pub fn row_count(&self) -> usize {
        self.slot.len()
    }

    /// Whether grains follow the cell's change within the step ([`crate::CellControl::affine`]):
    /// then every contact between two of them is coupled.
    pub fn within_step(&self) -> bool {
        self.within_step
    }

    /// Number of contacts coupled to the cell.
    pub fn coupled_contacts(&self) -> usize {
        self.rows.len()
    }

    /// The current change `δ = L⁺ − L⁻` of the velocity gradient (1/s): zero on the components
    /// whose rate is imposed.
    pub fn delta(&self) -> Tensor {
        let mut d = Tensor::zeros();
        for (k, &ij) in COMPONENTS.iter().enumerate() {
            d[ij] = self.delta[k];
        }
        d
    }

    /// The change of `δ` (1/s, as a matrix: zero on the components whose rate is imposed) that
    /// impulses `r` (N·s, interleaved `(r_n, r_t)` per row of `rows`) give instead of the rows'
    /// own: `Δδ_κ = m_κ Σ_c B_cκ · (r_c − r_c^rows)` over the coupled rows.
    pub fn delta_change(&self, rows: &[ContactRow], r: &[f64]) -> Tensor {
        let mut dd = [0.0; 3];
        for (s, &i) in self.rows.iter().enumerate() {
            let i = i as usize;
            let own = rows[i].r;
            let d = [r[2 * i] - own[0], r[2 * i + 1] - own[1]];
            for (k, x) in dd.iter_mut().enumerate() {
                let b = self.coef[s][k];
                *x += self.compliance[k] * (b[0] * d[0] + b[1] * d[1]);
            }
        }
        let mut m = Tensor::zeros();
        for (k, &ij) in COMPONENTS.iter().enumerate() {
            m[ij] = dd[k];
        }
        m
    }

    /// `Σ_κ B_cκ δ_κ` of slot `s` for the change `delta`.
    #[inline]
    fn affine_of(&self, s: usize, delta: &ComponentValues) -> [f64; 2] {
        let (b, c) = (&self.base[s], &self.coef[s]);
        let mut a = *b;
        for k in 0..3 {
            a[0] += c[k][0] * delta[k];
            a[1] += c[k][1] * delta[k];
        }
        a
    }

    /// Sets `δ` from the impulses in `rows` and every coupled row's affine velocity from it.
    pub fn refresh(&mut self, rows: &mut [ContactRow]) {
        let mut delta = self.delta0;
        for (s, &i) in self.rows.iter().enumerate() {
            self.add_impulse(s, rows[i as usize].r, &mut delta);
        }
        self.delta = delta;
        self.sync(rows);
    }

    /// `δ_κ += m_κ B_sκ · x` for an impulse (or an impulse's change) `x` of the contact of slot
    /// `s`: the one form of the cell's change by its contacts' impulses (`refresh`, and every
    /// coupled update of a sweep).
    #[inline(always)]
    fn add_impulse(&self, s: usize, x: [f64; 2], delta: &mut ComponentValues) {
        for (k, d) in delta.iter_mut().enumerate() {
            let b = self.coef[s][k];
            *d += self.compliance[k] * (b[0] * x[0] + b[1] * x[1]);
        }
    }

    /// Every coupled row's affine velocity from the current `δ`.
    fn sync(&self, rows: &mut [ContactRow]) {
        for (s, &i) in self.rows.iter().enumerate() {
            rows[i as usize].affine = self.affine_of(s, &self.delta);
        }
    }

    /// Augments the coupled rows' Delassus blocks by `m Σ_κ B_cκ B_cκᵀ` and sets `δ` from their
    /// impulses (before a solve).
    pub fn attach(&mut self, rows: &mut [ContactRow]) {
        if !self.attached {
            for (s, &i) in self.rows.iter().enumerate() {
                let mut w = self.own[s];
                for k in 0..3 {
                    let (b, m) = (self.coef[s][k], self.compliance[k]);
                    w.nn += m * b[0] * b[0];
                    w.nt += m * b[0] * b[1];
                    w.tt += m * b[1] * b[1];
                }
                rows[i as usize].w = w;
            }
            self.attached = true;
        }
        self.refresh(rows);
    }

    /// Restores the coupled rows' own Delassus blocks (after a solve); their affine velocities
    /// keep the final `δ`.
    pub fn detach(&mut self, rows: &mut [ContactRow]) {
        if self.attached {
            for (s, &i) in self.rows.iter().enumerate() {
                rows[i as usize].w = self.own[s];
            }
            self.attached = false;
        }
        self.sync(rows);
    }

    /// One Gauss–Seidel sweep over `rows` in `order` with the cell's components kept current
    /// (module documentation); the blocks must be [`CellCoupling::attach`]ed.
    pub fn sweep(
        &mut self,
        rows: &mut [ContactRow],
        order: &[u32],
        vel: &mut [Spatial],
        inv: &[Spatial],
        omega: f64,
    ) {
        for &i in order {
            let c = &mut rows[i as usize];
            let s = self.slot[i as usize];
            if s == NONE {
                update(c, vel, inv, omega);
            } else {
                self.update_coupled(c, s as usize, vel, inv, omega);
            }
        }
        self.sync(rows);
    }

    /// The Gauss–Seidel update of the contact of slot `s` with `δ` current, then `δ` moved by
    /// its impulse's change.
    #[inline(always)]
    fn update_coupled(
        &mut self,
        c: &mut ContactRow,
        s: usize,
        vel: &mut [Spatial],
        inv: &[Spatial],
        omega: f64,
    ) {
        c.affine = self.affine_of(s, &self.delta);
        let before = c.r;
        if update(c, vel, inv, omega) {
            let mut delta = self.delta;
            self.add_impulse(s, [c.r[0] - before[0], c.r[1] - before[1]], &mut delta);
            self.delta = delta;
        }
    }

    /// One Gauss–Seidel sweep in colour order on all rayon threads with the cell's components
    /// kept current (module documentation, *Parallel sweeps*): the contacts not coupled to the
    /// cell by `crate::parallel::coloured_sweep_where` (blocks' interiors concurrently, then
    /// the colour classes), then the coupled ones on the calling thread in slot order, each
    /// with the current `δ`. The blocks must be [`CellCoupling::attach`]ed and `colouring`
    /// built from `rows` and `mobile`. Every contact is visited once in an order fixed by the colouring
    /// and the slots, so the impulses, velocities and `δ` have the same bits on any number of
    /// threads.
    #[allow(clippy::too_many_arguments)]
    pub fn sweep_coupled(
        &mut self,
        rows: &mut [ContactRow],
        colouring: &ContactColouring,
        vel: &mut [Spatial],
        inv: &[Spatial],
        mobile: &[bool],
        omega: f64,
    ) {
        assert_eq!(self.slot.len(), rows.len(), "coupling of other rows");
        if self.within_step {
            self.sweep_units(rows, colouring, vel, inv, mobile, omega);
            return;
        }
        let slot = &self.slot;
        coloured_sweep_where(rows, colouring, vel, inv, mobile, omega, |i| {
            slot[i] == NONE
        });
        for s in 0..self.rows.len() {
            let i = self.rows[s] as usize;
            self.update_coupled(&mut rows[i], s, vel, inv, omega);
        }
        self.sync(rows);
    }

    /// [`CellCoupling::sweep_coupled`] when the grains follow the cell within the step, so that
    /// every contact between two grains is coupled and the one-thread pass over the coupled
    /// contacts would be the whole sweep: the colour-ordered sweep in fixed units
    /// ([`crate::parallel::coloured_units`]: each block's interior, then each class in chunks),
    /// each unit a Gauss–Seidel pass with its own copy of `δ` kept current by its own updates,
    /// the units' changes of `δ` added in unit order after each phase:
    ///
    /// ```text
    /// for phase in (blocks, class 1, class 2, …):
    ///     for unit in phase (concurrently):   δ_u ← δ;  for c in unit: update c with δ_u;  δ_u += m B_c · Δr_c
    ///     δ ← δ + Σ_u (δ_u − δ)               (unit order)
    /// ```
    ///
    /// Within a unit it is the exact Gauss–Seidel step of the eliminated problem; between the
    /// units of a phase it is a Jacobi step on the cell's rank-three term (Renouf, Dubois &
    /// Alart 2004 for the colour-ordered sweep). The units are fixed by the colouring, so the
    /// bits are the same on any number of threads.
    fn sweep_units(
        &mut self,
        rows: &mut [ContactRow],
        colouring: &ContactColouring,
        vel: &mut [Spatial],
        inv: &[Spatial],
        mobile: &[bool],
        omega: f64,
    ) {
        let (n_rows, pr, pv) = shared_sweep_inputs(rows, colouring, vel, inv, mobile);
        let this = &*self;
        let mut delta = self.delta;
        coloured_units(
            colouring,
            &mut delta,
            |start: &ComponentValues, ids: &[u32]| {
                let mut local = *start;
                for &i in ids {
                    let i = i as usize;
                    assert!(i < n_rows);
                    let s = this.slot[i];
                    // SAFETY: within a phase no two units share a row or a mobile body
                    // (`ContactColouring::build_blocked`: blocks' interiors are disjoint, a
                    // class's contacts share no mobile body); `i` checked, body indices checked
                    // in `update_shared`.
                    if s == NONE {
                        unsafe { update_shared(pr, i, pv, inv, mobile, omega) };
                        continue;
                    }
                    let s = s as usize;
                    let row = unsafe { pr.ptr().add(i) };
                    let before = unsafe {
                        (*row).affine = this.affine_of(s, &local);
                        (*row).r
                    };
                    if unsafe { update_shared(pr, i, pv, inv, mobile, omega) } {
                        let after = unsafe { (*row).r };
                        this.add_impulse(
                            s,
                            [after[0] - before[0], after[1] - before[1]],
                            &mut local,
                        );
                    }
                }
                std::array::from_fn(|k| local[k] - start[k])
            },
            |delta: &mut ComponentValues, change: ComponentValues| {
                for (x, c) in delta.iter_mut().zip(change) {
                    *x += c;
                }
            },
        );
        self.delta = delta;
        // Every row's affine velocity from the final δ: a function of the row alone, so the
        // rows are set concurrently with the same bits on any thread count.
        let this = &*self;
        rows.par_iter_mut()
            .with_min_len(TASK)
            .enumerate()
            .for_each(|(i, row)| {
                if this.slot[i] != NONE {
                    row.affine = this.affine_of(this.slot[i] as usize, &delta);
                }
            });
    }

    /// The same coupling for the rows renumbered so that new row `j` is old row
    /// `row_old[j]` (a permutation: the block-contiguous copy of the parallel solve,
    /// [`crate::blocked::BlockLayout`]). The slots keep their order.
    pub fn renumbered(&self, row_old: &[u32]) -> CellCoupling {
        assert_eq!(row_old.len(), self.slot.len(), "a permutation of the rows");
        let mut c = self.clone();
        c.slot.clear();
        c.slot
            .extend(row_old.iter().map(|&k| self.slot[k as usize]));
        for (new, &s) in c.slot.iter().enumerate() {
            if s != NONE {
                c.rows[s as usize] = new as u32;
            }
        }
        c
    }

    /// Takes `δ` from `solved` (this coupling [`CellCoupling::renumbered`], after its solve)
    /// and sets this coupling's rows' affine velocities from it.
    pub fn adopt(&mut self, solved: &CellCoupling, rows: &mut [ContactRow]) {
        self.delta = solved.delta;
        self.sync(rows);
    }

    /// The correction of the free local velocity `q` of row `i` from what its affine velocity
    /// holds now (`Σ_κ B_cκ δ_κ`) to the impulse-free part `Σ_κ B_cκ δ⁰_κ`; zero for a row
    /// not coupled.
    pub fn free_correction(&self, i: usize) -> [f64; 2] {
        match self.slot.get(i) {
            Some(&s) if s != NONE => {
                let s = s as usize;
                let mut q = [0.0; 2];
                for k in 0..3 {
                    let (b, d) = (self.coef[s][k], self.delta0[k] - self.delta[k]);
                    q[0] += b[0] * d;
                    q[1] += b[1] * d;
                }
                q
            }
            _ => [0.0; 2],
        }
    }

    /// The cell's term `m Σ_κ B_cκ B_c'κᵀ` of the eliminated problem as a rank-three term
    /// beside the sparse Delassus operator ([`crate::fc::LowRank`]; dense among the coupled
    /// contacts, which are all of them when the grains follow the cell within the step).
    pub fn low_rank(&self) -> crate::fc::LowRank {
        let mut coef = vec![[[0.0; 2]; 3]; self.slot.len()];
        for (s, &i) in self.rows.iter().enumerate() {
            coef[i as usize] = self.coef[s];
        }
        crate::fc::LowRank {
            compliance: self.compliance,
            coef,
        }
    }
}
