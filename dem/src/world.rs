//! The world: bodies, colliders, contact laws, and the Moreau–Jean time step.
//!
//! One step of length h (θ-method, impulses `R = h r`):
//!
//! ```text
//! 1. detect contacts at q⁻ (gap ≤ detection gap), warm-start impulses by collider pair
//! 2. v_free = v⁻ + h M⁻¹ f_ext                    (imposed degrees of freedom keep their velocity)
//! 3. solve  u = H v⁺ + shift,  v⁺ = v_free + M⁻¹ Hᵀ R,  (u, R) extremal pairs of the bipotential
//!    with shift = g⁻/(hθ) for an open gap (g⁻ above 10⁻⁴ of the smaller radius) + e·min(u_n⁻, 0)
//! 4. q⁺ = q⁻ + h [(1 − θ) v⁻ + θ v⁺]
//! ```
//!
//! The shift lets a contact that is still open at the start of the step close during it (it
//! stops exactly at contact for θ = 1); a gap below 10⁻⁴ of the smaller radius counts as closed
//! ([`crate::contact::CLOSED_GAP`]) and adds Newton restitution `u_n⁺ ≥ −e u_n⁻` on impacts;
//! with `e = 0` (the default) an impact is perfectly inelastic. The velocities never push an
//! overlap apart, so the scheme injects no kinetic energy: with θ = 1 the energy change of a
//! step is `R·u⁺ − ½ ‖v⁺ − v⁻‖²_M ≤ 0`.
//!
//! ```text
//! 5. position correction (WorldParams::position_correction, on by default): when a contact's
//!    predicted gap g⁺ = g⁻ + H_n (q⁺ − q⁻) is below −s (s = 10⁻⁴ of the smaller radius; by more
//!    than s/10), q⁺ ← q⁺ + M⁻¹ H_nᵀ P with P ≥ 0,  g⁺ + W_nn P ≥ −s,  Pᵀ(g⁺ + W_nn P + s) = 0
//! ```
//!
//! Overlaps left by a step (an inexact solve, a fast impact, an imposed wall) are thus removed at
//! position level, down to the slop, by a frictionless projection that changes no velocity
//! ([`crate::stabilise`]; Cline & Pai's post-stabilisation, the position projection of Acary's
//! combined-projection Moreau–Jean scheme): the kinetic energy is untouched, and the work of
//! gravity and the applied loads over the correction, the opposite of the potential energy it
//! adds, is reported in [`StepReport::position_correction`] (`load_work`).

use serde::{Deserialize, Serialize};

use crate::body::{Body, Dof};
use crate::cell::{Cell, ComponentValues};
use crate::cell_coupling::CellCoupling;
use crate::collider::{rotate, Collider, Shape};
use crate::contact::ContactSet;
use crate::detection::Periodic;
use crate::error::DemError;
use crate::fc::FcProblem;
use crate::material::ContactLaws;
use crate::math::{Spatial, Tensor, Vector};
use crate::snapshot::{BodyKind, BodyState, ContactState, Snapshot, WallGeometry, WallState};
use crate::solver::{self, SolveReport, SolverParams};
use crate::stabilise::CorrectionReport;

/// Parameters of the time stepping.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WorldParams {
    /// Time step h (s).
    pub dt: f64,
    /// θ of the θ-method, in [1/2, 1]. The default θ = 1 makes every step dissipative
    /// (`ΔE = R·u⁺ − ½‖v⁺ − v⁻‖²_M ≤ 0`); θ = 1/2 integrates free flight exactly but a step with
    /// several contacts can gain a little energy.
    pub theta: f64,
    /// Gravity (m/s²).
    pub gravity: Vector,
    /// Periodic cell along x, `[x_min, x_max)` (m).
    pub periodic_x: Option<[f64; 2]>,
    /// Detection gap (m): pairs closer than this become contacts.
    pub detection_gap: f64,
    /// Largest overlap growth per step allowed at a converged contact solve, as a fraction of
    /// the smallest grain radius `R_min`: the solve continues until no closed or loaded contact
    /// approaches faster than `overlap_rate · R_min / h` (besides the error tolerance). Overlaps
    /// are never pushed apart (that would inject energy), so this bounds how fast solver
    /// residuals can let them build up. 0 disables the check.
    #[serde(default = "default_overlap_rate")]
    pub overlap_rate: f64,
    /// Post-stabilisation of positions after each step ([`crate::stabilise`]): overlaps deeper
    /// than the slop ([`crate::stabilise::SLOP`] of the smaller radius of the pair) are removed by
    /// a frictionless projection `q ← q + M⁻¹ H_nᵀ P` that changes no velocity (Cline & Pai
    /// 2003). On by default (also when absent from a file); `false` gives the plain Moreau–Jean
    /// step, where overlaps are never pushed apart.
    #[serde(default = "default_position_correction")]
    pub position_correction: bool,
    /// Contact solver.
    pub solver: SolverParams,
}

impl Default for WorldParams {
    fn default() -> Self {
        WorldParams {
            dt: 1e-3,
            theta: 1.0,
            gravity: Vector::new(0.0, -9.81),
            periodic_x: None,
            detection_gap: 1e-4,
            overlap_rate: default_overlap_rate(),
            position_correction: default_position_correction(),
            solver: SolverParams::default(),
        }
    }
}

/// Spatial blocks of the parallel sweep
/// ([`crate::colouring::ContactColouring::build_blocked`]); fixed, so the numbers do not depend
/// on the thread count.
pub const SWEEP_BLOCKS: usize = 16;
/// Below this many contacts the parallel mode sweeps one block (sequentially, same order on any
/// thread count).
pub const BLOCKED_MIN_CONTACTS: usize = 4096;

fn default_overlap_rate() -> f64 {
    1e-4
}

fn default_position_correction() -> bool {
    true
}

/// What one step did.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct StepReport {
    /// Step index after the step.
    pub step: u64,
    /// Time after the step (s).
    pub time: f64,
    /// Contacts detected.
    pub contacts: usize,
    /// Contacts with a non-zero normal impulse.
    pub active_contacts: usize,
    /// The contact solve.
    pub solver: SolveReport,
    /// Largest overlap (−gap) at the start of the step (m), 0 if none.
    pub max_penetration: f64,
    /// The position correction after the update ([`crate::stabilise`]); all zeros when it is
    /// off or found nothing to correct.
    #[serde(default)]
    pub position_correction: CorrectionReport,
    /// Work done on the grains by a deformable periodic cell during the step (J): the impulses
    /// against the affine velocities of the images, `−Σ_α R_α·(L h k)_α`, plus the kinetic
    /// energy changed by wrapping grains back into the cell (`v ← v + L h k`) and by the
    /// control's homogeneous velocity change (`v ← v + ΔL (x − c)`). 0 without a cell.
    #[serde(default)]
    pub cell_work: f64,
    /// Re-solves of the step by the implicit correction of a stress-controlled cell
    /// ([`crate::cell::CellControl::tolerance`]); 0 when the explicit law sufficed.
    #[serde(default)]
    pub cell_corrections: u32,
}

mod state;
mod step;

pub use state::WorldState;
use state::{LastCellStep, WorkSpace};

/// A 2D granular world: its state ([`WorldState`]: bodies, colliders, laws, time, the last
/// step's contacts and what it leaves behind; what a checkpoint saves and an undo restores) and
/// its work space (buffers, scratch and caches that a step fills before reading them). The
/// world dereferences to its state: `world.bodies`, `world.params`, `world.time`.
#[derive(Debug, Clone)]
pub struct World {
    state: WorldState,
    pub(crate) work: WorkSpace,
}

impl std::ops::Deref for World {
    type Target = WorldState;

    fn deref(&self) -> &WorldState {
        &self.state
    }
}

impl std::ops::DerefMut for World {
    fn deref_mut(&mut self) -> &mut WorldState {
        &mut self.state
    }
}

impl World {
    /// An empty world.
    pub fn new(params: WorldParams, laws: ContactLaws) -> Self {
        World {
            state: WorldState::new(params, laws),
            work: WorkSpace::default(),
        }
    }

    /// A copy of the world to come back to after steps that are undone ([`World::undo_to`];
    /// [`crate::step_control::step_subdivided`]): its state ([`WorldState`]), with the work
    /// space left empty but for what the solver carries over. Stepping the copy gives the same
    /// bits as stepping the world; it is cheaper to make than a clone.
    pub fn undo_point(&self) -> World {
        World {
            state: self.state.clone(),
            work: self.work.carried(),
        }
    }

    /// Returns the world to `point` ([`World::undo_point`]): its state is then that of the
    /// world when the point was made, bit for bit; the work space is kept (no step reads it
    /// before filling it), with its allocations.
    pub fn undo_to(&mut self, point: &World) {
        self.state.clone_from(&point.state);
        self.work.restore_carried(&point.work);
    }

    /// The biperiodic deformable cell, if any.
    pub fn cell(&self) -> Option<&Cell> {
        self.state.cell.as_ref()
    }

    /// Makes the world a biperiodic deformable cell ([`crate::cell`]; grains only, no walls,
    /// `periodic_x` must be `None`) and wraps the grains into it; `None` removes it. The grains'
    /// velocities are left as they are (total velocities): see [`World::set_velocity_gradient`]
    /// to give them the affine field.
    pub fn set_cell(&mut self, cell: Option<Cell>) -> Result<(), DemError> {
        if let Some(c) = &cell {
            c.check()?;
        }
        self.state.cell = cell;
        self.state.cell_stress = None;
        self.forget_last_step_problem();
        self.wrap_grains();
        Ok(())
    }

    /// Sets the cell's velocity gradient to `l` (1/s) and adds the change of the affine field to
    /// every grain, `v ← v + (l − L)(x − c)` (a homogeneous deformation rate: YADE's
    /// `homoDeform`), so that the grains follow the cell at once instead of by waves from its
    /// boundaries. Returns the kinetic energy this added (J). No-op without a cell.
    pub fn set_velocity_gradient(&mut self, l: Tensor) -> f64 {
        let Some(cell) = self.state.cell.as_mut() else {
            return 0.0;
        };
        let dl = l - cell.l;
        cell.l = l;
        let c = cell.centre();
        let mut de = 0.0;
        for b in self.state.bodies.iter_mut() {
            if b.kind != BodyKind::Grain {
                continue;
            }
            let dv = dl * (b.position - c);
            let before = b.velocity;
            for d in 0..2 {
                if b.dofs[d] == Dof::Free {
                    b.velocity[d] += dv[d];
                }
            }
            de += 0.5 * b.mass * (b.velocity.norm_squared() - before.norm_squared());
        }
        de
    }

    /// Mean stress of the cell after the last step (Pa, tension positive, symmetric part):
    ///
    /// `Σ = (1/V) [ Σ_α f_α ⊗ (ρ_b − ρ_a)_α + Σ_p (I_p/2)(−ω̇_p j + ω_p² 𝟙) − Σ_p m_p ṽ_p ⊗ ṽ_p ]`,
    ///
    /// `V = det h` × thickness, `f_α` the force on `b`, `ρ` the lever arms (`ρ_b − ρ_a` is
    /// minus the branch vector to the image of `b`), `ṽ_p = v_p − L (x_p − c)` minus its mass
    /// mean. The first two terms are `Σ_p V_p Σ_p` of the seed paper's grain stress with
    /// inertia (`homogenise::stress`, `docs/physics.md` §2.1), computed here because the
    /// engine's cell control needs it every step; the last is the kinetic (Reynolds) stress of
    /// the velocity fluctuations. `None` without a cell or before the first step.
    pub fn cell_stress(&self) -> Option<Tensor> {
        self.state.cell_stress
    }

    fn measure_cell_stress(&self, cell: &Cell) -> Tensor {
        let h = self.impulse_dt();
        let mut m = Tensor::zeros();
        for (row, geo) in self.state.contacts.rows_with_geometry() {
            if row.r == [0.0, 0.0] {
                continue;
            }
            let [nx, ny] = row.n;
            let f = Vector::new(row.r[0] * nx - row.r[1] * ny, row.r[0] * ny + row.r[1] * nx) / h;
            let l = Vector::new(
                geo.lever_b[0] - geo.lever_a[0],
                geo.lever_b[1] - geo.lever_a[1],
            );
            m += f * l.transpose();
        }
        let thickness = self.grain_thickness();
        let j = Tensor::new(0.0, -1.0, 1.0, 0.0);
        for b in self
            .state
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
        {
            m += (j * (-b.angular_acceleration) + Tensor::identity() * (b.omega * b.omega))
                * (0.5 * b.inertia);
        }
        let s = m / (cell.volume() * thickness);
        (s + s.transpose()) * 0.5 + self.kinetic_stress(cell)
    }

    /// The thickness of the grains (m; 1 without grains).
    fn grain_thickness(&self) -> f64 {
        self.state
            .bodies
            .iter()
            .rfind(|b| b.kind == BodyKind::Grain)
            .map_or(1.0, |b| b.thickness)
    }

    /// Kinetic (Reynolds) stress of the grains' velocity fluctuations in `cell` (Pa, tension
    /// positive): `−(1/V) Σ_p m_p ṽ_p ⊗ ṽ_p`, `ṽ_p = v_p − L (x_p − c)` minus its mass mean.
    fn kinetic_stress(&self, cell: &Cell) -> Tensor {
        let c = cell.centre();
        let (mut mass, mut mom) = (0.0, Vector::zeros());
        for b in self
            .state
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
        {
            mass += b.mass;
            mom += (b.velocity - cell.l * (b.position - c)) * b.mass;
        }
        let mean = if mass > 0.0 {
            mom / mass
        } else {
            Vector::zeros()
        };
        let mut m = Tensor::zeros();
        for b in self
            .state
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
        {
            let v = b.velocity - cell.l * (b.position - c) - mean;
            m -= v * v.transpose() * b.mass;
        }
        m / (cell.volume() * self.grain_thickness())
    }

    /// Whether each body follows a change of the cell's velocity gradient within a step (a grain
    /// with both translations free: [`World::set_velocity_gradient`] drags it); empty without
    /// an implicit cell control whose grains follow it within the step
    /// ([`CellControl::affine`](crate::cell::CellControl::affine)). The cell's change then acts on the contacts between two such
    /// bodies through their whole branch vector ([`crate::cell_coupling`]).
    fn follows_cell(&self) -> Vec<bool> {
        match (self.state.cell, self.state.cell_control) {
            (Some(_), Some(ctl)) if ctl.implicit && ctl.affine => self
                .state
                .bodies
                .iter()
                .map(|b| {
                    b.kind == BodyKind::Grain && b.dofs[0] == Dof::Free && b.dofs[1] == Dof::Free
                })
                .collect(),
            _ => Vec::new(),
        }
    }

    /// Wraps every grain into the cell (`x ← x + h k`) with `v ← v + L h k`; returns the kinetic
    /// energy change (J). Without a cell, wraps x into `periodic_x`.
    fn wrap_grains(&mut self) -> f64 {
        let Some(cell) = self.state.cell else {
            if let Some(p) = self.periodic() {
                for b in self.state.bodies.iter_mut() {
                    if b.kind == BodyKind::Grain {
                        b.position.x = p.wrap(b.position.x);
                    }
                }
            }
            return 0.0;
        };
        let mut de = 0.0;
        for b in self.state.bodies.iter_mut() {
            if b.kind != BodyKind::Grain {
                continue;
            }
            let (x, k) = cell.wrap(&b.position);
            if k == crate::cell::Shift::zeros() {
                continue;
            }
            b.position = x;
            let before = b.velocity;
            b.velocity += cell.image_velocity(&k);
            de += 0.5 * b.mass * (b.velocity.norm_squared() - before.norm_squared());
        }
        de
    }

    /// The frictional-contact problem of the last step (`u = W r + q` in the contacts' order,
    /// impulses in N·s), when [`WorldState::record_problems`] was set for it.
    pub fn last_problem(&self) -> Option<&FcProblem> {
        self.state.last_step.problem.as_ref()
    }

    /// The problem that stands for the last step, with the report of its own solve: after a
    /// step of [`crate::step_control::step_subdivided`] some kept sub-step of which did not
    /// converge, the first such sub-step's (the step's failure, where the last sub-step may
    /// have converged); otherwise the last (sub-)step's ([`World::last_problem`],
    /// [`World::last_report`]). `None` unless [`WorldState::record_problems`] was set.
    pub fn problem_of_last_step(&self) -> Option<(&FcProblem, StepReport)> {
        match &self.work.unconverged_problem {
            Some((p, r)) => Some((p, *r)),
            None => self
                .state
                .last_step
                .problem
                .as_ref()
                .map(|p| (p, self.state.last)),
        }
    }

    /// The frictional-contact problem of the last step, assembled on demand from its contacts
    /// and free velocities (`u = W r + q`, [`crate::assemble::contact_problem`]; the contacts in
    /// the order of [`World::snapshot`]), with the impulses its solve returned (N·s, interleaved
    /// `(r_n, r_t)`): what [`World::snapshot_with_last_impulses`] takes other impulses for.
    /// Needs no [`WorldState::record_problems`]; after [`World::undo_to`], the problem of the step
    /// that led to the point returned to. With a deformable cell under an implicit control, the
    /// problem with the cell's stress-controlled components eliminated
    /// ([`crate::assemble::contact_problem_with`], [`crate::cell_coupling`]), as the step solved
    /// it. `None` before a step, after a resume (the free velocities are not checkpointed), and
    /// with a cell under an explicit control (its next `L` follows the step's stress by its own
    /// law, outside the problem).
    pub fn last_step_problem(&self) -> Option<(FcProblem, Vec<f64>)> {
        if !self.has_last_step_problem() {
            return None;
        }
        let rows = &self.state.contacts.rows;
        let coupling = self.last_coupling();
        let problem = crate::assemble::contact_problem_with(
            rows,
            &self.state.last_step.v_free,
            &self.state.last_step.inv,
            coupling,
        );
        Some((problem, rows.iter().flat_map(|c| c.r).collect()))
    }

    /// Drops what [`World::last_step_problem`] is assembled from (the free velocities and the
    /// cell's coupling): done where the contacts or the cell change outside a step's solve.
    fn forget_last_step_problem(&mut self) {
        self.state.last_step.v_free.clear();
        self.state.last_step.cell_step = None;
    }

    /// The coupling of the last step's cell to its contacts, if any.
    fn last_coupling(&self) -> Option<&CellCoupling> {
        self.state.last_step.cell_step.as_ref()?.coupling.as_ref()
    }

    /// Whether [`World::last_step_problem`] can be assembled: the free velocities of a step
    /// are there, and no deformable cell or one whose step was recorded.
    fn has_last_step_problem(&self) -> bool {
        let cell_consistent = match (&self.state.cell, &self.state.last_step.cell_step) {
            (None, None) => true,
            (Some(_), Some(step)) => step
                .coupling
                .as_ref()
                .is_none_or(|c| c.row_count() == self.state.contacts.rows.len()),
            _ => false,
        };
        cell_consistent
            && self.state.last_step.v_free.len() == self.state.bodies.len()
            && self.state.last_step.inv.len() == self.state.bodies.len()
    }

    /// The world's [`World::snapshot`] as if the last step's contact solve had returned the
    /// impulses `r` (N·s, interleaved `(r_n, r_t)` in the contacts' order) instead of its own:
    /// with `Δv = M⁻¹ Hᵀ (r − r_solved)` per body (Moreau–Jean, `v⁺ = v_free + M⁻¹ Hᵀ r`),
    ///
    /// ```text
    /// v⁺' = v⁺ + Δv,   a' = a + Δv / h,   q⁺' = q⁺ + θ h Δv,   f' = r / h,
    /// ```
    ///
    /// the contacts' statuses read from `r`, and the walls' resultant contact forces and torques
    /// in [`Snapshot::walls`] summed from `r`. The step's position correction is kept as it was
    /// made (it depends on the positions only through overlaps, a change of order `θ h Δv`), and
    /// so is the walls' geometry (a wall free to move shifts by `θ h Δv`). For a step done in
    /// sub-steps ([`crate::step_control`]) this is its last sub-step's solve.
    /// This is how a measurement tells what the solver's residual does to it: the same step,
    /// solved tighter (`grainlaw`'s solver-sensitivity check).
    ///
    /// With a deformable cell under an implicit control, the cell's stress-controlled
    /// components change with the impulses too ([`crate::cell_coupling`]):
    /// `Δδ_κ = m_κ Σ_c B_cκ · Δr_c`, so `L' = L + Δδ` and every grain, which followed `δ` at the
    /// end of the step, gains `Δδ (x − c)` on its free velocity components (no acceleration: the
    /// step's `a` is that of the solve, before the grains follow the cell). The cell's geometry,
    /// advanced over the step with `L⁻ + δ`, is kept (a change of order `h Δδ`), as are the
    /// positions' affine part and the wraps.
    ///
    /// # Errors
    /// [`DemError::Parameter`] when the last step's problem is not available
    /// ([`World::last_step_problem`]) or `r` does not have two entries per contact.
    pub fn snapshot_with_last_impulses(&self, r: &[f64]) -> Result<Snapshot, DemError> {
        let bad = |reason: String| DemError::Parameter {
            name: "impulses".into(),
            reason,
        };
        if !self.has_last_step_problem() {
            return Err(bad(
                "the last step's problem is not available (no step, a resume, or a cell under \
                 an explicit control)"
                    .into(),
            ));
        }
        let rows = &self.state.contacts.rows;
        if r.len() != 2 * rows.len() {
            return Err(bad(format!(
                "{} values for {} contacts (two per contact)",
                r.len(),
                rows.len()
            )));
        }
        let h = self.impulse_dt();
        // Per body, the change of its generalised impulse `Hᵀ Δr` (N·s, N·m·s): of its
        // velocity through `M⁻¹`, of its contact force and torque over `h`.
        let mut dj = vec![[0.0; 3]; self.state.bodies.len()];
        for (c, x) in rows.iter().zip(r.chunks_exact(2)) {
            let d = [x[0] - c.r[0], x[1] - c.r[1]];
            if d != [0.0, 0.0] {
                for (side, body) in [(0, c.a), (1, c.b)] {
                    let j = c.impulse_on(side, d);
                    let acc = &mut dj[body as usize];
                    (0..3).for_each(|k| acc[k] += j[k]);
                }
            }
        }
        let dv: Vec<Spatial> = dj
            .iter()
            .zip(&self.state.last_step.inv)
            .map(|(j, i)| [i[0] * j[0], i[1] * j[1], i[2] * j[2]])
            .collect();
        let theta = self.state.params.theta;
        let periodic = self.periodic();
        let mut snap = self.snapshot();
        // The cell's change with the impulses, and the grains following it.
        if let (Some(coupling), Some(cell)) = (self.last_coupling(), snap.cell.as_mut()) {
            let dl = coupling.delta_change(rows, r);
            if dl != Tensor::zeros() {
                cell.l += dl;
                let c = cell.centre();
                for (b, body) in snap.bodies.iter_mut().zip(&self.state.bodies) {
                    if body.kind != BodyKind::Grain {
                        continue;
                    }
                    let dv = dl * (b.position - c);
                    for d in 0..2 {
                        if body.dofs[d] == Dof::Free {
                            b.velocity[d] += dv[d];
                        }
                    }
                }
            }
        }
        for (b, d) in snap.bodies.iter_mut().zip(&dv) {
            if *d == [0.0, 0.0, 0.0] {
                continue;
            }
            b.velocity += Vector::new(d[0], d[1]);
            b.omega += d[2];
            b.acceleration += Vector::new(d[0], d[1]) / h;
            b.angular_acceleration += d[2] / h;
            b.position += Vector::new(d[0], d[1]) * (theta * h);
            b.angle += theta * h * d[2];
            if let (Some(p), BodyKind::Grain) = (periodic, b.kind) {
                b.position.x = p.wrap(b.position.x);
            }
        }
        for wall in &mut snap.walls {
            let j = dj[wall.body as usize];
            if j != [0.0, 0.0, 0.0] {
                wall.force += Vector::new(j[0], j[1]) / h;
                wall.torque += j[2] / h;
            }
        }
        for ((c, row), x) in snap.contacts.iter_mut().zip(rows).zip(r.chunks_exact(2)) {
            c.force_n = x[0] / h;
            c.force_t = x[1] / h;
            c.status = solver::status(&crate::contact::ContactRow {
                r: [x[0], x[1]],
                ..*row
            });
        }
        Ok(snap)
    }

    /// Add a free disk grain (thickness 1 m); returns its body index.
    pub fn add_grain(&mut self, position: Vector, radius: f64, density: f64, material: u16) -> u32 {
        self.add_grain_with_thickness(position, radius, density, 1.0, material)
    }

    /// Add a free disk grain of given thickness (m); returns its body index.
    pub fn add_grain_with_thickness(
        &mut self,
        position: Vector,
        radius: f64,
        density: f64,
        thickness: f64,
        material: u16,
    ) -> u32 {
        let b = self.state.bodies.len() as u32;
        self.state
            .bodies
            .push(Body::disk(position, radius, density, thickness));
        self.state.colliders.push(Collider {
            body: b,
            shape: Shape::Disk {
                radius,
                offset: Vector::zeros(),
            },
            material,
        });
        b
    }

    /// Add a fixed (or, by setting its velocity, driven) infinite line wall through `point` with
    /// unit `normal` pointing to the grains; returns its body index.
    pub fn add_line_wall(
        &mut self,
        name: &str,
        point: Vector,
        normal: Vector,
        material: u16,
    ) -> u32 {
        let b = self.state.bodies.len() as u32;
        self.state
            .bodies
            .push(Body::wall(name, point, Vector::zeros()));
        self.state.colliders.push(Collider {
            body: b,
            shape: Shape::Line {
                point: Vector::zeros(),
                normal: normal.normalize(),
            },
            material,
        });
        b
    }

    /// Add the fixed line walls of an open box of `material`, in this order: `bottom` (y = 0),
    /// `left` (x = 0) and `right` (x = `width`, m), each facing the inside; returns their body
    /// indices.
    pub fn add_box_walls(&mut self, width: f64, material: u16) -> [u32; 3] {
        [
            self.add_line_wall("bottom", Vector::zeros(), Vector::new(0.0, 1.0), material),
            self.add_line_wall("left", Vector::zeros(), Vector::new(1.0, 0.0), material),
            self.add_line_wall(
                "right",
                Vector::new(width, 0.0),
                Vector::new(-1.0, 0.0),
                material,
            ),
        ]
    }

    /// Add a fixed segment wall from `a` to `b`; returns its body index (centre at the middle).
    pub fn add_segment_wall(&mut self, name: &str, a: Vector, b: Vector, material: u16) -> u32 {
        let id = self.state.bodies.len() as u32;
        let c = (a + b) * 0.5;
        self.state.bodies.push(Body::wall(name, c, Vector::zeros()));
        self.state.colliders.push(Collider {
            body: id,
            shape: Shape::Segment { a: a - c, b: b - c },
            material,
        });
        id
    }

    /// Add a rigid clump of glued disks (a rough wall), fixed by default; returns its body index.
    /// Its centre is the mean of the disk centres. Give it free degrees of freedom, a mass and
    /// an applied force to control it (e.g. a platen at imposed pressure).
    pub fn add_clump(
        &mut self,
        name: &str,
        centres: &[Vector],
        radii: &[f64],
        material: u16,
    ) -> u32 {
        let id = self.state.bodies.len() as u32;
        let n = centres.len().max(1) as f64;
        let c = centres.iter().fold(Vector::zeros(), |s, x| s + x) / n;
        self.state.bodies.push(Body::wall(name, c, Vector::zeros()));
        for (x, &r) in centres.iter().zip(radii) {
            self.state.colliders.push(Collider {
                body: id,
                shape: Shape::Disk {
                    radius: r,
                    offset: x - c,
                },
                material,
            });
        }
        id
    }

    /// The periodic x direction, if any (see [`World::cell`] for a biperiodic cell).
    pub fn periodic(&self) -> Option<Periodic> {
        self.state.params.periodic_x.map(|[a, b]| Periodic {
            x_min: a,
            length: b - a,
        })
    }

    /// Take the disk pairs of every detection from the cell grid (`true`) instead of from the
    /// candidate list kept between detections (`false`, the default;
    /// [`crate::detection::Detector::detect`]). The contacts, hence the whole run, are the same
    /// bit for bit either way; only the time differs.
    pub fn set_full_detection(&mut self, full: bool) {
        self.work.detector.set_full_detection(full);
    }

    /// Detections and builds of their candidate list since this world was made (or restored
    /// from a state): the list was reused by the detections that did not build it.
    pub fn candidate_counts(&self) -> crate::detection::CandidateCounts {
        self.work.detector.candidate_counts()
    }

    /// Every number of the dynamic state, bit for bit, in a fixed order: position, angle,
    /// velocity and spin of every body, then the key and the two impulse components of every
    /// contact. Two runs that agree on it took the same trajectory (reproducibility and
    /// bit-identity checks).
    pub fn state_bits(&self) -> Vec<u64> {
        let mut f = Vec::with_capacity(6 * self.state.bodies.len() + 3 * self.state.contacts.len());
        for b in &self.state.bodies {
            f.extend(
                [
                    b.position.x,
                    b.position.y,
                    b.angle,
                    b.velocity.x,
                    b.velocity.y,
                    b.omega,
                ]
                .map(f64::to_bits),
            );
        }
        for (row, g) in self.state.contacts.rows_with_geometry() {
            f.extend([g.key, row.r[0].to_bits(), row.r[1].to_bits()]);
        }
        f
    }

    /// Contacts of the last step.
    pub fn contacts(&self) -> &ContactSet {
        &self.state.contacts
    }

    /// Report of the last step.
    pub fn last_report(&self) -> StepReport {
        self.state.last
    }

    /// Total contact force (N) and torque (N·m) received by body `b` during the last step.
    pub fn contact_force(&self, b: usize) -> (Vector, f64) {
        let f = self
            .state
            .last_step
            .body_force
            .get(b)
            .copied()
            .unwrap_or([0.0; 3]);
        (Vector::new(f[0], f[1]), f[2])
    }

    /// Kinetic energy of all free degrees of freedom (J).
    pub fn kinetic_energy(&self) -> f64 {
        self.state.bodies.iter().map(Body::kinetic_energy).sum()
    }

    /// Gravitational potential energy `−Σ m g·x` over free degrees of freedom (J), relative to
    /// the origin.
    pub fn potential_energy(&self) -> f64 {
        let g = self.state.params.gravity;
        self.state
            .bodies
            .iter()
            .filter(|b| b.gravity)
            .map(|b| {
                let mut e = 0.0;
                if b.dofs[0] == Dof::Free {
                    e -= b.mass * g.x * b.position.x;
                }
                if b.dofs[1] == Dof::Free {
                    e -= b.mass * g.y * b.position.y;
                }
                e
            })
            .sum()
    }

    /// Check every parameter, body, collider and contact law, and that no two grains overlap
    /// and no grain lies behind a line wall by more than `tolerance` (m).
    pub fn validate(&mut self, tolerance: f64) -> Result<(), DemError> {
        // The inverse masses are refreshed from the bodies (which may have been changed): the
        // last step's problem, assembled with them, is no longer the step's.
        self.forget_last_step_problem();
        self.check_parameters()?;
        self.check_bodies()?;
        // Overlaps and grains behind walls, with the detector at zero gap.
        self.refresh_inverse_mass();
        let mut set = ContactSet::default();
        self.detect_into(0.0, 0.0, 0.0, 0.0, &mut set)?;
        for (row, g) in set.rows_with_geometry() {
            if g.gap < -tolerance {
                let (a, b) = (row.a as usize, row.b as usize);
                if self.state.bodies[a].kind == BodyKind::Wall {
                    return Err(DemError::Outside {
                        grain: b,
                        wall: self.state.bodies[a].name.clone(),
                        depth: -g.gap,
                    });
                }
                return Err(DemError::Overlap {
                    a,
                    b,
                    overlap: -g.gap,
                });
            }
        }
        Ok(())
    }

    /// [`World::validate`]'s check of the parameters, the cell and its control, the solver's
    /// settings and the contact laws.
    fn check_parameters(&self) -> Result<(), DemError> {
        let p = &self.state.params;
        let perr = |name: &str, reason: String| DemError::Parameter {
            name: name.into(),
            reason,
        };
        if !(p.dt.is_finite() && p.dt > 0.0) {
            return Err(perr(
                "dt",
                format!("must be a positive time step in s, got {}", p.dt),
            ));
        }
        if !(0.5..=1.0).contains(&p.theta) {
            return Err(perr(
                "theta",
                format!("must lie in [0.5, 1], got {}", p.theta),
            ));
        }
        if !(p.gravity.x.is_finite() && p.gravity.y.is_finite()) {
            return Err(perr("gravity", "must be finite".into()));
        }
        if !(p.detection_gap.is_finite() && p.detection_gap >= 0.0) {
            return Err(perr(
                "detection_gap",
                format!("must be ≥ 0 m, got {}", p.detection_gap),
            ));
        }
        if !(p.overlap_rate.is_finite() && p.overlap_rate >= 0.0) {
            return Err(perr(
                "overlap_rate",
                format!(
                    "must be ≥ 0 (fraction of the smallest radius per step), got {}",
                    p.overlap_rate
                ),
            ));
        }
        if let Some([a, b]) = p.periodic_x {
            if !(a.is_finite() && b.is_finite() && b > a) {
                return Err(perr(
                    "periodic_x",
                    format!("needs x_min < x_max, got [{a}, {b}]"),
                ));
            }
        }
        if let Some(cell) = &self.state.cell {
            cell.check()?;
            if p.periodic_x.is_some() {
                return Err(perr(
                    "periodic_x",
                    "must be unset with a biperiodic cell (the cell is periodic in x and y)".into(),
                ));
            }
        }
        if let Some(c) = &self.state.cell_control {
            c.check()?;
        }
        if !(p.solver.tolerance.is_finite() && p.solver.tolerance > 0.0) {
            return Err(perr(
                "solver.tolerance",
                format!("must be > 0, got {}", p.solver.tolerance),
            ));
        }
        if p.solver.max_iterations == 0 {
            return Err(perr("solver.max_iterations", "must be ≥ 1".into()));
        }
        if !(p.solver.relaxation > 0.0 && p.solver.relaxation < 2.0) {
            return Err(perr(
                "solver.relaxation",
                format!("must lie in (0, 2), got {}", p.solver.relaxation),
            ));
        }
        if p.solver.anderson_memory > 64 {
            return Err(perr(
                "solver.anderson_memory",
                format!("must be at most 64, got {}", p.solver.anderson_memory),
            ));
        }
        if !(1..=1000).contains(&p.solver.last_level_sweeps) {
            return Err(perr(
                "solver.last_level_sweeps",
                format!(
                    "must lie in 1..=1000 (multiples of max_iterations), got {}",
                    p.solver.last_level_sweeps
                ),
            ));
        }
        for &mu in self.state.laws.friction_table() {
            if !(mu.is_finite() && mu >= 0.0) {
                return Err(perr("friction", format!("must be ≥ 0, got {mu}")));
            }
        }
        for &e in self.state.laws.restitution_table() {
            if !(0.0..=1.0).contains(&e) {
                return Err(perr("restitution", format!("must lie in [0, 1], got {e}")));
            }
        }
        Ok(())
    }

    /// [`World::validate`]'s check of every body and collider.
    fn check_bodies(&self) -> Result<(), DemError> {
        let perr = |name: &str, reason: String| DemError::Parameter {
            name: name.into(),
            reason,
        };
        for (i, b) in self.state.bodies.iter().enumerate() {
            let berr = |field: &str, reason: String| DemError::Body {
                index: i,
                label: if b.name.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", b.name)
                },
                field: field.into(),
                reason,
            };
            let finite = b
                .position
                .iter()
                .chain(b.velocity.iter())
                .all(|x| x.is_finite())
                && b.angle.is_finite()
                && b.omega.is_finite();
            if !finite {
                return Err(berr("position/velocity", "must be finite".into()));
            }
            if b.kind == BodyKind::Grain {
                if !(b.radius.is_finite() && b.radius > 0.0) {
                    return Err(berr("radius", format!("must be > 0 m, got {}", b.radius)));
                }
                if !(b.density.is_finite() && b.density > 0.0) {
                    return Err(berr(
                        "density",
                        format!("must be > 0 kg/m³, got {}", b.density),
                    ));
                }
                if !(b.thickness.is_finite() && b.thickness > 0.0) {
                    return Err(berr(
                        "thickness",
                        format!("must be > 0 m, got {}", b.thickness),
                    ));
                }
            }
            for (d, &dof) in b.dofs.iter().enumerate() {
                let m = if d < 2 { b.mass } else { b.inertia };
                if dof == Dof::Free && !(m.is_finite() && m > 0.0) {
                    return Err(berr(
                        "mass",
                        format!("a free degree of freedom needs a finite positive mass, got {m}"),
                    ));
                }
            }
        }
        for c in &self.state.colliders {
            if c.body as usize >= self.state.bodies.len() {
                return Err(perr(
                    "collider",
                    format!("refers to body {} that does not exist", c.body),
                ));
            }
            if c.material as usize >= self.state.laws.len() {
                return Err(perr(
                    "collider",
                    format!("material {} is not defined", c.material),
                ));
            }
            let bad = match &c.shape {
                Shape::Disk { radius, offset } => {
                    !(radius.is_finite()
                        && *radius > 0.0
                        && offset.x.is_finite()
                        && offset.y.is_finite())
                }
                Shape::Line { point, normal } => {
                    !(point.x.is_finite() && point.y.is_finite() && normal.norm() > 0.0)
                }
                Shape::Segment { a, b } => {
                    !(a.x.is_finite() && a.y.is_finite() && b.x.is_finite() && b.y.is_finite())
                }
            };
            if bad {
                let b = &self.state.bodies[c.body as usize];
                return Err(DemError::Body {
                    index: c.body as usize,
                    label: format!(" ({})", b.name),
                    field: "shape".into(),
                    reason: "has a non-finite or non-positive size".into(),
                });
            }
        }
        Ok(())
    }

    /// Detect the current contacts and give them the impulses that carry each grain's weight
    /// down to its supports ([`crate::hydrostatic`]); the next step starts its solve from them
    /// instead of from zero. Meant for a packing generated at rest (a geometric deposit): its
    /// first steps otherwise spend of the order of `H²` sweeps (`H` its depth in grains) letting
    /// the weight reach the floor.
    ///
    /// The primed impulses replace the contact set that [`World::contacts`], snapshots and
    /// checkpoints show until the next step (contact forces on bodies are not refreshed). Called
    /// in the middle of a run it discards the warm start of the previous step.
    pub fn prime_with_weight(&mut self) -> Result<(), DemError> {
        // The last step's contacts are replaced: its problem goes with them.
        self.forget_last_step_problem();
        self.refresh_inverse_mass();
        self.detect_step_contacts(self.implicit_free_change())?;
        let (h, g) = (self.state.params.dt, self.state.params.gravity);
        crate::hydrostatic::weight_impulses(
            &mut self.state.contacts.rows,
            &self.state.bodies,
            &self.state.last_step.inv,
            g,
            h,
        );
        self.state.contacts.dt = h;
        Ok(())
    }

    /// Detection into `self.state.contacts` with the step's gap, time step and gravity (the inverse
    /// masses must be current).
    ///
    /// `free_change`: the impulse-free change `δ⁰` of an implicit cell control over the step
    /// ([`World::implicit_free_change`]); the reach of the pairs through the cell's boundary
    /// covers the images' drift under it, as the sum of its components' magnitudes (the pairs
    /// inside the cell do not drift with the cell). Normal impulses across the boundary mostly
    /// open the cell further, but frictional or shear ones can close it more: a change beyond
    /// the margins detects again after the step (`image_outran`).
    fn detect_step_contacts(
        &mut self,
        free_change: Option<ComponentValues>,
    ) -> Result<(), DemError> {
        let mut set = std::mem::take(&mut self.state.contacts);
        let (gap, h, g) = (
            self.state.params.detection_gap,
            self.state.params.dt,
            self.state.params.gravity.norm(),
        );
        let rate_bound = free_change.map_or(0.0, |d| d.iter().map(|x| x.abs()).sum());
        let found = self.detect_into(gap, h, g, rate_bound, &mut set);
        self.state.contacts = set;
        found
    }

    /// The impulse-free change `δ⁰` of the stress-controlled components of an implicit cell
    /// control over the next step ([`CellControl::free_change`](crate::cell::CellControl::free_change), with the kinetic stress now);
    /// `None` without one.
    fn implicit_free_change(&self) -> Option<ComponentValues> {
        match (self.state.cell_control, self.state.cell) {
            (Some(ctl), Some(cell)) if ctl.implicit => {
                Some(ctl.free_change(&cell.l, &self.kinetic_stress(&cell)))
            }
            _ => None,
        }
    }

    /// Detection into `set`: pairs closer than `gap` (m) plus what they can travel in a step of
    /// `h` (s) under gravity `g` (m/s²), and, in a biperiodic cell, the images' drift under a
    /// change of `L` by up to `rate_bound` (1/s, sum of the components' magnitudes) within it.
    fn detect_into(
        &mut self,
        gap: f64,
        h: f64,
        g: f64,
        rate_bound: f64,
        set: &mut ContactSet,
    ) -> Result<(), DemError> {
        if let Some(cell) = self.state.cell {
            return self.work.detector.detect_cell(
                &self.state.bodies,
                &self.state.last_step.inv,
                &self.state.colliders,
                &self.state.laws,
                &cell,
                gap,
                h,
                rate_bound,
                set,
            );
        }
        let periodic = self.periodic();
        self.work.detector.detect(
            &self.state.bodies,
            &self.state.last_step.inv,
            &self.state.colliders,
            &self.state.laws,
            periodic,
            gap,
            h,
            g,
            set,
        )
    }

    /// Contact forces received by each body during the last step (walls' loads), N and N·m;
    /// returns the number of contacts with a positive normal impulse.
    fn refresh_body_forces(&mut self) -> usize {
        let h = self.impulse_dt();
        self.state.last_step.body_force.clear();
        self.state
            .last_step
            .body_force
            .resize(self.state.bodies.len(), [0.0; 3]);
        let mut active = 0;
        for row in &self.state.contacts.rows {
            if row.r[0] > 0.0 {
                active += 1;
            }
            for (side, body) in [(1, row.b), (0, row.a)] {
                let j = row.impulse_on(side, row.r);
                let f = &mut self.state.last_step.body_force[body as usize];
                (0..3).for_each(|k| f[k] += j[k] / h);
            }
        }
        active
    }

    fn refresh_inverse_mass(&mut self) {
        self.state.last_step.inv.clear();
        self.state
            .last_step
            .inv
            .extend(self.state.bodies.iter().map(Body::inverse_mass));
    }

    /// Largest approach speed of a converged solve (m/s): `overlap_rate · R_min / h`, infinite
    /// when the rate is 0 or there is no grain.
    fn approach_limit(&self) -> f64 {
        match self.smallest_radius() {
            Some(r_min) if self.state.params.overlap_rate > 0.0 => {
                self.state.params.overlap_rate * r_min / self.state.params.dt
            }
            _ => f64::INFINITY,
        }
    }

    /// The smallest grain radius (m), if there is a grain.
    fn smallest_radius(&self) -> Option<f64> {
        let r_min = self
            .state
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain && b.radius > 0.0)
            .map(|b| b.radius)
            .fold(f64::INFINITY, f64::min);
        r_min.is_finite().then_some(r_min)
    }

    /// Time step (s) of the impulses held in the contact set: forces are impulses divided by it.
    fn impulse_dt(&self) -> f64 {
        if self.state.contacts.dt > 0.0 {
            self.state.contacts.dt
        } else {
            self.state.params.dt
        }
    }

    /// The complete state needed to continue the run exactly (see [`crate::checkpoint`]).
    pub fn state(&self) -> WorldState {
        self.state.clone()
    }

    /// Rebuild a world from [`World::state`]: stepping it gives bit-identical results to
    /// stepping the original. What the last step left behind but a checkpoint does not hold is
    /// rebuilt (inverse masses, contact forces on bodies) or dropped (its problem).
    pub fn from_state(s: WorldState) -> Self {
        let mut w = World {
            state: s,
            work: WorkSpace::default(),
        };
        w.state.record_problems = false;
        w.state.last_step = Default::default();
        w.refresh_inverse_mass();
        w.refresh_body_forces();
        w
    }

    /// The state after the last step as plain data (see [`crate::snapshot`]).
    pub fn snapshot(&self) -> Snapshot {
        let h = self.impulse_dt();
        let bodies = self.state.bodies.iter().map(BodyState::from).collect();
        let contacts = self
            .state
            .contacts
            .rows_with_geometry()
            .zip(&self.state.contacts.status)
            .map(|((row, geo), st)| ContactState {
                body_a: row.a,
                body_b: row.b,
                point: Vector::new(geo.point[0], geo.point[1]),
                normal: Vector::new(row.n[0], row.n[1]),
                force_n: row.r[0] / h,
                force_t: row.r[1] / h,
                gap: geo.gap,
                mu: row.mu,
                status: *st,
                lever_a: Vector::new(geo.lever_a[0], geo.lever_a[1]),
                lever_b: Vector::new(geo.lever_b[0], geo.lever_b[1]),
            })
            .collect();
        let mut walls = Vec::new();
        for (i, b) in self.state.bodies.iter().enumerate() {
            if b.kind != BodyKind::Wall {
                continue;
            }
            let mine: Vec<&Collider> = self
                .state
                .colliders
                .iter()
                .filter(|c| c.body as usize == i)
                .collect();
            let geometry = match mine.first().map(|c| &c.shape) {
                Some(Shape::Line { point, normal }) => WallGeometry::Line {
                    point: b.position + rotate(*point, b.angle),
                    normal: rotate(*normal, b.angle),
                },
                Some(Shape::Segment { a, b: e }) => WallGeometry::Segment {
                    a: b.position + rotate(*a, b.angle),
                    b: b.position + rotate(*e, b.angle),
                },
                _ => {
                    let mut centres = Vec::new();
                    let mut radii = Vec::new();
                    for c in &mine {
                        if let Shape::Disk { radius, offset } = c.shape {
                            let mut x = b.position + rotate(offset, b.angle);
                            if let Some(p) = self.periodic() {
                                x.x = p.wrap(x.x);
                            }
                            centres.push(x);
                            radii.push(radius);
                        }
                    }
                    WallGeometry::Clump { centres, radii }
                }
            };
            let (force, torque) = self.contact_force(i);
            walls.push(WallState {
                body: i as u32,
                name: b.name.clone(),
                geometry,
                force,
                torque,
            });
        }
        Snapshot {
            step: self.state.step_index,
            time: self.state.time,
            dt: h,
            gravity: self.state.params.gravity,
            periodic_x: self.state.params.periodic_x,
            cell: self.state.cell,
            bodies,
            contacts,
            walls,
        }
    }
}

/// `h⁻¹` of a cell matrix (`det h > 0` for a cell).
fn cell_inverse(h: &Tensor) -> Tensor {
    h.try_inverse().unwrap_or_else(Tensor::zeros)
}
