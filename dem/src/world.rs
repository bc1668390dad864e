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

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

use crate::blocked::BlockLayout;
use crate::body::{external_loads, Body, Dof};
use crate::cell::{Cell, CellControl, Mat, Vect};
use crate::cell_coupling::CellCoupling;
use crate::checkpoint::WorldState;
use crate::collider::{rotate, Collider, Shape};
use crate::colouring::ContactColouring;
use crate::contact::ContactSet;
use crate::detection::{Detector, Periodic};
use crate::error::DemError;
use crate::fc::FcProblem;
use crate::material::ContactLaws;
use crate::snapshot::{BodyKind, BodyState, ContactState, Snapshot, WallGeometry, WallState};
use crate::solver::{self, SolveReport, SolverParams, SweepOrder};
use crate::stabilise::{CorrectionReport, Projection};

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
    pub gravity: Vector2<f64>,
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
            gravity: Vector2::new(0.0, -9.81),
            periodic_x: None,
            detection_gap: 1e-4,
            overlap_rate: default_overlap_rate(),
            position_correction: default_position_correction(),
            solver: SolverParams::default(),
        }
    }
}

/// Spatial blocks of the parallel sweep ([`ContactColouring::build_blocked`]); fixed, so the
/// numbers do not depend on the thread count.
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

/// A 2D granular world.
#[derive(Debug, Clone)]
pub struct World {
    /// Time stepping parameters.
    pub params: WorldParams,
    /// Bodies (grains and walls).
    pub bodies: Vec<Body>,
    /// Shapes attached to bodies.
    pub colliders: Vec<Collider>,
    /// Friction and restitution between materials.
    pub laws: ContactLaws,
    /// Current time (s).
    pub time: f64,
    /// Steps done.
    pub step_index: u64,
    contacts: ContactSet,
    previous: ContactSet,
    detector: Detector,
    vel: Vec<[f64; 3]>,
    inv: Vec<[f64; 3]>,
    body_force: Vec<[f64; 3]>,
    order: Vec<u32>,
    mobile: Vec<bool>,
    pos: Vec<[f64; 2]>,
    layout: BlockLayout,
    colouring: ContactColouring,
    v_free: Vec<[f64; 3]>,
    pub(crate) work: solver::SolverWork,
    displacement: Vec<[f64; 3]>,
    projection: Projection,
    /// Contacts detected again after a step whose disks outran their swept margins.
    fresh: ContactSet,
    last: StepReport,
    /// Keep the frictional-contact problem of each step ([`World::last_problem`]), to write it
    /// to a file (`grainlaw run --dump-problems`). Costs one assembly of `W` per step.
    pub record_problems: bool,
    last_problem: Option<FcProblem>,
    /// When problems are recorded: the problem and report of the first kept sub-step of the
    /// last subdivided step whose solve did not converge
    /// ([`crate::step_control::step_subdivided`]; a later sub-step may converge and be the
    /// last problem). Work space: a step clears it.
    pub(crate) unconverged_problem: Option<(FcProblem, StepReport)>,
    /// Biperiodic deformable cell ([`crate::cell`]); `None`: walls and `periodic_x` only.
    /// Set it with [`World::set_cell`].
    cell: Option<Cell>,
    /// Mixed stress/strain-rate control of the cell, applied after every step.
    pub cell_control: Option<CellControl>,
    /// Mean stress of the cell after the last step (Pa), [`World::cell_stress`].
    cell_sigma: Option<Mat>,
    /// Fluctuating displacements of the last step (cell only), for the outran check.
    fluct_displacement: Vec<[f64; 3]>,
    /// Kinetic energy changed by wraps during the position correction (J).
    last_wrap_energy: f64,
    /// Whether the last step's implicit cell changed `L` by more than the swept margins
    /// covered ([`crate::detection::Detector::image_rate`]): detect again after it.
    image_outran: bool,
    /// What a deformable cell's last step adds to its contact problem, when that step can be
    /// solved again ([`World::last_step_problem`]): state, like the free velocities.
    last_cell_step: Option<LastCellStep>,
}

/// The part of a deformable cell's step that depends on the contact impulses, kept after the
/// step for [`World::last_step_problem`] and [`World::snapshot_with_last_impulses`]: under an
/// implicit control the coupling of its stress-controlled components to the contacts
/// ([`crate::cell_coupling`]), whose change `δ` of `L` the grains then follow
/// (`v ← v + δ (x − c)`); without a control, or one that imposes no stress, nothing (the
/// cell's motion does not depend on the impulses). An explicit control, whose next `L`
/// depends on the step's stress through its own law, keeps none (not available).
#[derive(Debug, Clone, Default)]
struct LastCellStep {
    coupling: Option<CellCoupling>,
}

impl World {
    /// An empty world.
    pub fn new(params: WorldParams, laws: ContactLaws) -> Self {
        World {
            params,
            bodies: Vec::new(),
            colliders: Vec::new(),
            laws,
            time: 0.0,
            step_index: 0,
            contacts: ContactSet::default(),
            previous: ContactSet::default(),
            detector: Detector::default(),
            vel: Vec::new(),
            inv: Vec::new(),
            body_force: Vec::new(),
            order: Vec::new(),
            mobile: Vec::new(),
            pos: Vec::new(),
            layout: BlockLayout::default(),
            colouring: ContactColouring::default(),
            v_free: Vec::new(),
            work: solver::SolverWork::default(),
            displacement: Vec::new(),
            projection: Projection::default(),
            fresh: ContactSet::default(),
            last: StepReport::default(),
            record_problems: false,
            last_problem: None,
            unconverged_problem: None,
            cell: None,
            cell_control: None,
            cell_sigma: None,
            fluct_displacement: Vec::new(),
            last_wrap_energy: 0.0,
            image_outran: false,
            last_cell_step: None,
        }
    }

    /// A copy of the world to come back to after steps that are undone ([`World::undo_to`];
    /// [`crate::step_control::step_subdivided`]): everything a step reads from the world, but
    /// not the work space that a step fills before reading it (the previous step's contact set,
    /// detection, solver and projection buffers), which is left empty; and the free velocities
    /// of the last step, with which its problem stays available ([`World::last_step_problem`]).
    /// Stepping the copy gives the same bits as stepping the world; it is cheaper to make than a
    /// clone.
    pub fn undo_point(&self) -> World {
        // Listed field by field (no `..`): a new field must be sorted into state or work space.
        let World {
            params,
            bodies,
            colliders,
            laws,
            time,
            step_index,
            contacts,
            previous: _,
            detector: _,
            vel: _,
            inv,
            body_force,
            order: _,
            mobile: _,
            pos: _,
            layout,
            colouring,
            v_free,
            work,
            displacement: _,
            projection: _,
            fresh: _,
            last,
            record_problems,
            last_problem,
            unconverged_problem: _,
            cell,
            cell_control,
            cell_sigma,
            fluct_displacement: _,
            last_wrap_energy: _,
            image_outran: _,
            last_cell_step,
        } = self;
        World {
            bodies: bodies.clone(),
            colliders: colliders.clone(),
            time: *time,
            step_index: *step_index,
            contacts: contacts.clone(),
            inv: inv.clone(),
            body_force: body_force.clone(),
            layout: layout.clone(),
            colouring: colouring.clone(),
            v_free: v_free.clone(),
            work: work.carried(),
            last: *last,
            record_problems: *record_problems,
            last_problem: last_problem.clone(),
            cell: *cell,
            cell_control: *cell_control,
            cell_sigma: *cell_sigma,
            last_cell_step: last_cell_step.clone(),
            ..World::new(*params, laws.clone())
        }
    }

    /// Returns the world to `point` ([`World::undo_point`]): its state is then that of the
    /// world when the point was made, bit for bit; the work space is kept (no step reads it
    /// before filling it), with its allocations.
    pub fn undo_to(&mut self, point: &World) {
        let World {
            params,
            bodies,
            colliders,
            laws,
            time,
            step_index,
            contacts,
            previous: _,
            detector: _,
            vel: _,
            inv,
            body_force,
            order: _,
            mobile: _,
            pos: _,
            layout,
            colouring,
            v_free,
            work,
            displacement: _,
            projection: _,
            fresh: _,
            last,
            record_problems,
            last_problem,
            unconverged_problem: _,
            cell,
            cell_control,
            cell_sigma,
            fluct_displacement: _,
            last_wrap_energy: _,
            image_outran: _,
            last_cell_step,
        } = point;
        self.params = *params;
        self.bodies.clone_from(bodies);
        self.colliders.clone_from(colliders);
        self.laws.clone_from(laws);
        self.time = *time;
        self.step_index = *step_index;
        self.contacts.clone_from(contacts);
        self.inv.clone_from(inv);
        self.body_force.clone_from(body_force);
        self.layout.clone_from(layout);
        self.colouring.clone_from(colouring);
        self.v_free.clone_from(v_free);
        self.work.restore_carried(work);
        self.last = *last;
        self.record_problems = *record_problems;
        self.last_problem.clone_from(last_problem);
        self.cell = *cell;
        self.cell_control = *cell_control;
        self.cell_sigma = *cell_sigma;
        self.last_cell_step.clone_from(last_cell_step);
    }

    /// The biperiodic deformable cell, if any.
    pub fn cell(&self) -> Option<&Cell> {
        self.cell.as_ref()
    }

    /// Makes the world a biperiodic deformable cell ([`crate::cell`]; grains only, no walls,
    /// `periodic_x` must be `None`) and wraps the grains into it; `None` removes it. The grains'
    /// velocities are left as they are (total velocities): see [`World::set_velocity_gradient`]
    /// to give them the affine field.
    pub fn set_cell(&mut self, cell: Option<Cell>) -> Result<(), DemError> {
        if let Some(c) = &cell {
            c.check()?;
        }
        self.cell = cell;
        self.cell_sigma = None;
        self.forget_last_step_problem();
        self.wrap_grains();
        Ok(())
    }

    /// Sets the cell's velocity gradient to `l` (1/s) and adds the change of the affine field to
    /// every grain, `v ← v + (l − L)(x − c)` (a homogeneous deformation rate: YADE's
    /// `homoDeform`), so that the grains follow the cell at once instead of by waves from its
    /// boundaries. Returns the kinetic energy this added (J). No-op without a cell.
    pub fn set_velocity_gradient(&mut self, l: Mat) -> f64 {
        let Some(cell) = self.cell.as_mut() else {
            return 0.0;
        };
        let dl = l - cell.l;
        cell.l = l;
        let c = cell.centre();
        let mut de = 0.0;
        for b in self.bodies.iter_mut() {
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
    pub fn cell_stress(&self) -> Option<Mat> {
        self.cell_sigma
    }

    fn measure_cell_stress(&self, cell: &Cell) -> Mat {
        let h = self.impulse_dt();
        let mut m = Mat::zeros();
        for (row, geo) in self.contacts.rows.iter().zip(&self.contacts.geometry) {
            if row.r == [0.0, 0.0] {
                continue;
            }
            let [nx, ny] = row.n;
            let f = Vect::new(row.r[0] * nx - row.r[1] * ny, row.r[0] * ny + row.r[1] * nx) / h;
            let l = Vect::new(
                geo.lever_b[0] - geo.lever_a[0],
                geo.lever_b[1] - geo.lever_a[1],
            );
            m += f * l.transpose();
        }
        let thickness = self.grain_thickness();
        let j = Mat::new(0.0, -1.0, 1.0, 0.0);
        for b in self.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
            m += (j * (-b.angular_acceleration) + Mat::identity() * (b.omega * b.omega))
                * (0.5 * b.inertia);
        }
        let s = m / (cell.volume() * thickness);
        (s + s.transpose()) * 0.5 + self.kinetic_stress(cell)
    }

    /// The thickness of the grains (m; 1 without grains).
    fn grain_thickness(&self) -> f64 {
        self.bodies
            .iter()
            .rfind(|b| b.kind == BodyKind::Grain)
            .map_or(1.0, |b| b.thickness)
    }

    /// Kinetic (Reynolds) stress of the grains' velocity fluctuations in `cell` (Pa, tension
    /// positive): `−(1/V) Σ_p m_p ṽ_p ⊗ ṽ_p`, `ṽ_p = v_p − L (x_p − c)` minus its mass mean.
    fn kinetic_stress(&self, cell: &Cell) -> Mat {
        let c = cell.centre();
        let (mut mass, mut mom) = (0.0, Vect::zeros());
        for b in self.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
            mass += b.mass;
            mom += (b.velocity - cell.l * (b.position - c)) * b.mass;
        }
        let mean = if mass > 0.0 {
            mom / mass
        } else {
            Vect::zeros()
        };
        let mut m = Mat::zeros();
        for b in self.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
            let v = b.velocity - cell.l * (b.position - c) - mean;
            m -= v * v.transpose() * b.mass;
        }
        m / (cell.volume() * self.grain_thickness())
    }

    /// Whether each body follows a change of the cell's velocity gradient within a step (a grain
    /// with both translations free: [`World::set_velocity_gradient`] drags it); empty without
    /// an implicit cell control whose grains follow it within the step
    /// ([`CellControl::affine`]). The cell's change then acts on the contacts between two such
    /// bodies through their whole branch vector ([`crate::cell_coupling`]).
    fn follows_cell(&self) -> Vec<bool> {
        match (self.cell, self.cell_control) {
            (Some(_), Some(ctl)) if ctl.implicit && ctl.affine => self
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
        let Some(cell) = self.cell else {
            if let Some(p) = self.periodic() {
                for b in self.bodies.iter_mut() {
                    if b.kind == BodyKind::Grain {
                        b.position.x = p.wrap(b.position.x);
                    }
                }
            }
            return 0.0;
        };
        let mut de = 0.0;
        for b in self.bodies.iter_mut() {
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
    /// impulses in N·s), when [`World::record_problems`] was set for it.
    pub fn last_problem(&self) -> Option<&FcProblem> {
        self.last_problem.as_ref()
    }

    /// The problem that stands for the last step, with the report of its own solve: after a
    /// step of [`crate::step_control::step_subdivided`] some kept sub-step of which did not
    /// converge, the first such sub-step's (the step's failure, where the last sub-step may
    /// have converged); otherwise the last (sub-)step's ([`World::last_problem`],
    /// [`World::last_report`]). `None` unless [`World::record_problems`] was set.
    pub fn problem_of_last_step(&self) -> Option<(&FcProblem, StepReport)> {
        match &self.unconverged_problem {
            Some((p, r)) => Some((p, *r)),
            None => self.last_problem.as_ref().map(|p| (p, self.last)),
        }
    }

    /// The frictional-contact problem of the last step, assembled on demand from its contacts
    /// and free velocities (`u = W r + q`, [`crate::assemble::contact_problem`]; the contacts in
    /// the order of [`World::snapshot`]), with the impulses its solve returned (N·s, interleaved
    /// `(r_n, r_t)`): what [`World::snapshot_with_last_impulses`] takes other impulses for.
    /// Needs no [`World::record_problems`]; after [`World::undo_to`], the problem of the step
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
        let rows = &self.contacts.rows;
        let coupling = self.last_coupling();
        let problem =
            crate::assemble::contact_problem_with(rows, &self.v_free, &self.inv, coupling);
        Some((problem, rows.iter().flat_map(|c| c.r).collect()))
    }

    /// Drops what [`World::last_step_problem`] is assembled from (the free velocities and the
    /// cell's coupling): done where the contacts or the cell change outside a step's solve.
    fn forget_last_step_problem(&mut self) {
        self.v_free.clear();
        self.last_cell_step = None;
    }

    /// The coupling of the last step's cell to its contacts, if any.
    fn last_coupling(&self) -> Option<&CellCoupling> {
        self.last_cell_step.as_ref()?.coupling.as_ref()
    }

    /// Whether [`World::last_step_problem`] can be assembled: the free velocities of a step
    /// are there, and no deformable cell or one whose step was recorded.
    fn has_last_step_problem(&self) -> bool {
        let cell_consistent = match (&self.cell, &self.last_cell_step) {
            (None, None) => true,
            (Some(_), Some(step)) => step
                .coupling
                .as_ref()
                .is_none_or(|c| c.row_count() == self.contacts.rows.len()),
            _ => false,
        };
        cell_consistent
            && self.v_free.len() == self.bodies.len()
            && self.inv.len() == self.bodies.len()
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
        let rows = &self.contacts.rows;
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
        let mut dj = vec![[0.0; 3]; self.bodies.len()];
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
        let dv: Vec<[f64; 3]> = dj
            .iter()
            .zip(&self.inv)
            .map(|(j, i)| [i[0] * j[0], i[1] * j[1], i[2] * j[2]])
            .collect();
        let theta = self.params.theta;
        let periodic = self.periodic();
        let mut snap = self.snapshot();
        // The cell's change with the impulses, and the grains following it.
        if let (Some(coupling), Some(cell)) = (self.last_coupling(), snap.cell.as_mut()) {
            let dl = coupling.delta_change(rows, r);
            if dl != Mat::zeros() {
                cell.l += dl;
                let c = cell.centre();
                for (b, body) in snap.bodies.iter_mut().zip(&self.bodies) {
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
            b.velocity += Vector2::new(d[0], d[1]);
            b.omega += d[2];
            b.acceleration += Vector2::new(d[0], d[1]) / h;
            b.angular_acceleration += d[2] / h;
            b.position += Vector2::new(d[0], d[1]) * (theta * h);
            b.angle += theta * h * d[2];
            if let (Some(p), BodyKind::Grain) = (periodic, b.kind) {
                b.position.x = p.wrap(b.position.x);
            }
        }
        for wall in &mut snap.walls {
            let j = dj[wall.body as usize];
            if j != [0.0, 0.0, 0.0] {
                wall.force += Vector2::new(j[0], j[1]) / h;
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
    pub fn add_grain(
        &mut self,
        position: Vector2<f64>,
        radius: f64,
        density: f64,
        material: u16,
    ) -> u32 {
        self.add_grain_with_thickness(position, radius, density, 1.0, material)
    }

    /// Add a free disk grain of given thickness (m); returns its body index.
    pub fn add_grain_with_thickness(
        &mut self,
        position: Vector2<f64>,
        radius: f64,
        density: f64,
        thickness: f64,
        material: u16,
    ) -> u32 {
        let b = self.bodies.len() as u32;
        self.bodies
            .push(Body::disk(position, radius, density, thickness));
        self.colliders.push(Collider {
            body: b,
            shape: Shape::Disk {
                radius,
                offset: Vector2::zeros(),
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
        point: Vector2<f64>,
        normal: Vector2<f64>,
        material: u16,
    ) -> u32 {
        let b = self.bodies.len() as u32;
        self.bodies.push(Body::wall(name, point, Vector2::zeros()));
        self.colliders.push(Collider {
            body: b,
            shape: Shape::Line {
                point: Vector2::zeros(),
                normal: normal.normalize(),
            },
            material,
        });
        b
    }

    /// Add a fixed segment wall from `a` to `b`; returns its body index (centre at the middle).
    pub fn add_segment_wall(
        &mut self,
        name: &str,
        a: Vector2<f64>,
        b: Vector2<f64>,
        material: u16,
    ) -> u32 {
        let id = self.bodies.len() as u32;
        let c = (a + b) * 0.5;
        self.bodies.push(Body::wall(name, c, Vector2::zeros()));
        self.colliders.push(Collider {
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
        centres: &[Vector2<f64>],
        radii: &[f64],
        material: u16,
    ) -> u32 {
        let id = self.bodies.len() as u32;
        let n = centres.len().max(1) as f64;
        let c = centres.iter().fold(Vector2::zeros(), |s, x| s + x) / n;
        self.bodies.push(Body::wall(name, c, Vector2::zeros()));
        for (x, &r) in centres.iter().zip(radii) {
            self.colliders.push(Collider {
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
        self.params.periodic_x.map(|[a, b]| Periodic {
            x_min: a,
            length: b - a,
        })
    }

    /// Take the disk pairs of every detection from the cell grid (`true`) instead of from the
    /// candidate list kept between detections (`false`, the default;
    /// [`crate::detection::Detector::detect`]). The contacts, hence the whole run, are the same
    /// bit for bit either way; only the time differs.
    pub fn set_full_detection(&mut self, full: bool) {
        self.detector.set_full_detection(full);
    }

    /// Detections and builds of their candidate list since this world was made (or restored
    /// from a state): the list was reused by the detections that did not build it.
    pub fn candidate_counts(&self) -> crate::detection::CandidateCounts {
        self.detector.candidate_counts()
    }

    /// Every number of the dynamic state, bit for bit, in a fixed order: position, angle,
    /// velocity and spin of every body, then the key and the two impulse components of every
    /// contact. Two runs that agree on it took the same trajectory (reproducibility and
    /// bit-identity checks).
    pub fn state_bits(&self) -> Vec<u64> {
        let mut f = Vec::with_capacity(6 * self.bodies.len() + 3 * self.contacts.len());
        for b in &self.bodies {
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
        for (row, g) in self.contacts.rows.iter().zip(&self.contacts.geometry) {
            f.extend([g.key, row.r[0].to_bits(), row.r[1].to_bits()]);
        }
        f
    }

    /// Contacts of the last step.
    pub fn contacts(&self) -> &ContactSet {
        &self.contacts
    }

    /// Report of the last step.
    pub fn last_report(&self) -> StepReport {
        self.last
    }

    /// Total contact force (N) and torque (N·m) received by body `b` during the last step.
    pub fn contact_force(&self, b: usize) -> (Vector2<f64>, f64) {
        let f = self.body_force.get(b).copied().unwrap_or([0.0; 3]);
        (Vector2::new(f[0], f[1]), f[2])
    }

    /// Kinetic energy of all free degrees of freedom (J).
    pub fn kinetic_energy(&self) -> f64 {
        self.bodies.iter().map(Body::kinetic_energy).sum()
    }

    /// Gravitational potential energy `−Σ m g·x` over free degrees of freedom (J), relative to
    /// the origin.
    pub fn potential_energy(&self) -> f64 {
        let g = self.params.gravity;
        self.bodies
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
        let p = &self.params;
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
        if let Some(cell) = &self.cell {
            cell.check()?;
            if p.periodic_x.is_some() {
                return Err(perr(
                    "periodic_x",
                    "must be unset with a biperiodic cell (the cell is periodic in x and y)".into(),
                ));
            }
        }
        if let Some(c) = &self.cell_control {
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
        for &mu in self.laws.friction_table() {
            if !(mu.is_finite() && mu >= 0.0) {
                return Err(perr("friction", format!("must be ≥ 0, got {mu}")));
            }
        }
        for &e in self.laws.restitution_table() {
            if !(0.0..=1.0).contains(&e) {
                return Err(perr("restitution", format!("must lie in [0, 1], got {e}")));
            }
        }
        for (i, b) in self.bodies.iter().enumerate() {
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
        for c in &self.colliders {
            if c.body as usize >= self.bodies.len() {
                return Err(perr(
                    "collider",
                    format!("refers to body {} that does not exist", c.body),
                ));
            }
            if c.material as usize >= self.laws.len() {
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
                let b = &self.bodies[c.body as usize];
                return Err(DemError::Body {
                    index: c.body as usize,
                    label: format!(" ({})", b.name),
                    field: "shape".into(),
                    reason: "has a non-finite or non-positive size".into(),
                });
            }
        }
        // Overlaps and grains behind walls, with the detector at zero gap.
        self.refresh_inverse_mass();
        let mut set = ContactSet::default();
        self.detect_into(0.0, 0.0, 0.0, 0.0, &mut set)?;
        for (row, g) in set.rows.iter().zip(&set.geometry) {
            if g.gap < -tolerance {
                let (a, b) = (row.a as usize, row.b as usize);
                if self.bodies[a].kind == BodyKind::Wall {
                    return Err(DemError::Outside {
                        grain: b,
                        wall: self.bodies[a].name.clone(),
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
        let (h, g) = (self.params.dt, self.params.gravity);
        crate::hydrostatic::weight_impulses(&mut self.contacts.rows, &self.bodies, &self.inv, g, h);
        self.contacts.dt = h;
        Ok(())
    }

    /// Detection into `self.contacts` with the step's gap, time step and gravity (the inverse
    /// masses must be current).
    ///
    /// `free_change`: the impulse-free change `δ⁰` of an implicit cell control over the step
    /// ([`World::implicit_free_change`]); the reach of the pairs through the cell's boundary
    /// covers the images' drift under it, as the sum of its components' magnitudes (the pairs
    /// inside the cell do not drift with the cell). Normal impulses across the boundary mostly
    /// open the cell further, but frictional or shear ones can close it more: a change beyond
    /// the margins detects again after the step (`image_outran`).
    fn detect_step_contacts(&mut self, free_change: Option<[f64; 3]>) -> Result<(), DemError> {
        let mut set = std::mem::take(&mut self.contacts);
        let (gap, h, g) = (
            self.params.detection_gap,
            self.params.dt,
            self.params.gravity.norm(),
        );
        let rate_bound = free_change.map_or(0.0, |d| d.iter().map(|x| x.abs()).sum());
        let found = self.detect_into(gap, h, g, rate_bound, &mut set);
        self.contacts = set;
        found
    }

    /// The impulse-free change `δ⁰` of the stress-controlled components of an implicit cell
    /// control over the next step ([`CellControl::free_change`], with the kinetic stress now);
    /// `None` without one.
    fn implicit_free_change(&self) -> Option<[f64; 3]> {
        match (self.cell_control, self.cell) {
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
        if let Some(cell) = self.cell {
            return self.detector.detect_cell(
                &self.bodies,
                &self.inv,
                &self.colliders,
                &self.laws,
                &cell,
                gap,
                h,
                rate_bound,
                set,
            );
        }
        let periodic = self.periodic();
        self.detector.detect(
            &self.bodies,
            &self.inv,
            &self.colliders,
            &self.laws,
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
        self.body_force.clear();
        self.body_force.resize(self.bodies.len(), [0.0; 3]);
        let mut active = 0;
        for row in &self.contacts.rows {
            if row.r[0] > 0.0 {
                active += 1;
            }
            for (side, body) in [(1, row.b), (0, row.a)] {
                let j = row.impulse_on(side, row.r);
                let f = &mut self.body_force[body as usize];
                (0..3).for_each(|k| f[k] += j[k] / h);
            }
        }
        active
    }

    fn refresh_inverse_mass(&mut self) {
        self.inv.clear();
        self.inv.extend(self.bodies.iter().map(Body::inverse_mass));
    }

    /// Advance one time step (see the module documentation). Non-convergence of the contact
    /// solver is reported in the returned [`StepReport`], never hidden; a non-finite state is an
    /// error.
    ///
    /// Called from outside the rayon pool, a step that will fork runs on one of its workers
    /// (one hand-over per step), so that the many short parallel kernels of the solve fork and
    /// join between workers instead of each waking the pool from the outside and blocking on
    /// it. A step that will not fork (the sweeps in natural order and every chunked pass one
    /// task's worth, [`crate::parallel::runs_inline`]) stays on the calling thread: handed over,
    /// it kept a second worker spinning beside it for nothing (the poured 2000-grain column,
    /// 4614 sub-steps: about 15 % slower on two cores, same bits).
    pub fn step(&mut self) -> Result<StepReport, DemError> {
        self.unconverged_problem = None;
        let forks = self.params.solver.parallel
            || !crate::parallel::runs_inline(self.contacts.len().div_ceil(crate::parallel::CHUNK));
        if forks && rayon::current_thread_index().is_none() {
            rayon::scope(|_| self.step_in_pool())
        } else {
            self.step_in_pool()
        }
    }

    /// A step, with the implicit correction of a stress-controlled cell
    /// ([`CellControl::tolerance`]): when the step ends with a mean stress error beyond the
    /// tolerance (more compressive: typically a rigid packing asked to deform faster than it
    /// can, whose impulses then grow without bound; or more tensile), the step is done again
    /// from its start with the stress-controlled components of `L` changed by a common `δ`,
    /// found by bracketing and bisection on the mean signed error `Σ (σ_ij − σ*_ij)/n` (which
    /// grows with `δ`), until that error is within the tolerance or
    /// [`CellControl::max_corrections`] re-solves are spent. On the tensile side `δ ≥ −ε̇_max`
    /// (a loose packing cannot be brought to its stress within one step).
    fn step_in_pool(&mut self) -> Result<StepReport, DemError> {
        let (Some(ctl), Some(_)) = (self.cell_control, self.cell) else {
            return self.step_plain();
        };
        if ctl.implicit || ctl.tolerance <= 0.0 || ctl.max_corrections == 0 {
            return self.step_plain();
        }
        // State only: every re-solve starts from it ([`World::undo_point`]).
        let backup = self.undo_point();
        let first = self.step_plain()?;
        let f0 = ctl.signed_error(&self.cell_sigma.unwrap_or_else(Mat::zeros));
        if f0.abs() <= ctl.tolerance {
            return Ok(first);
        }
        let l0 = backup.cell.map_or_else(Mat::zeros, |c| c.l);
        let mut tries = 0u32;
        let attempt = |w: &mut World, delta: f64, tries: &mut u32| -> Result<f64, DemError> {
            w.undo_to(&backup);
            let e = w.set_velocity_gradient(l0 + ctl.direction() * delta);
            let mut r = w.step_plain()?;
            r.cell_work += e;
            *tries += 1;
            r.cell_corrections = *tries;
            w.last = r;
            Ok(ctl.signed_error(&w.cell_sigma.unwrap_or_else(Mat::zeros)))
        };
        // Bracket the root of f(δ) (f grows with δ): [lo, hi] with f(lo) < 0 < f(hi).
        let (mut lo, mut hi);
        if f0 < 0.0 {
            // Too compressive: open faster, doubling the step (a rigid packing can need it).
            lo = 0.0;
            hi = ctl.max_rate;
            let mut f = attempt(self, hi, &mut tries)?;
            while f < -ctl.tolerance && (tries as usize) < ctl.max_corrections / 2 {
                lo = hi;
                hi *= 2.0;
                f = attempt(self, hi, &mut tries)?;
            }
            if f.abs() <= ctl.tolerance || f < 0.0 {
                return Ok(self.last);
            }
        } else {
            // Too tensile: close, but no component faster than ε̇_max (a loose packing cannot
            // be brought to its stress within one step; no rigidity to overcome this way).
            let dir = ctl.direction();
            let l_min = (0..2)
                .flat_map(|i| (0..2).map(move |j| (i, j)))
                .filter(|&ij| dir[ij] != 0.0)
                .map(|ij| l0[ij])
                .fold(f64::INFINITY, f64::min);
            hi = 0.0;
            lo = -(ctl.max_rate + l_min);
            if lo.is_nan() || lo >= 0.0 {
                return Ok(first);
            }
            let f = attempt(self, lo, &mut tries)?;
            if f >= -ctl.tolerance {
                return Ok(self.last);
            }
        }
        let mut last_ok = true;
        while (tries as usize) < ctl.max_corrections {
            let mid = 0.5 * (lo + hi);
            let f = attempt(self, mid, &mut tries)?;
            if f.abs() <= ctl.tolerance {
                return Ok(self.last);
            }
            if f < 0.0 {
                lo = mid;
                last_ok = false;
            } else {
                hi = mid;
                last_ok = true;
            }
        }
        // Out of re-solves: end on the bracket's side that is not too compressive.
        if !last_ok {
            attempt(self, hi, &mut tries)?;
        }
        Ok(self.last)
    }

    fn step_plain(&mut self) -> Result<StepReport, DemError> {
        let h = self.params.dt;
        let theta = self.params.theta;
        let g = self.params.gravity;
        let periodic = self.periodic();
        self.refresh_inverse_mass();
        // The contacts are about to change: a step that fails before its solve leaves no
        // problem behind.
        self.forget_last_step_problem();

        // 1. Detection at q⁻, warm start from the previous step.
        std::mem::swap(&mut self.contacts, &mut self.previous);
        // The impulse-free change of an implicit cell over the step (its images' drift widens
        // the swept margins; the contact problem below starts from it).
        let free_change = self.implicit_free_change();
        self.detect_step_contacts(free_change)?;
        // Impulses scale with the time step (R = h r): rescale if it changed.
        let scale = if self.previous.dt > 0.0 {
            h / self.previous.dt
        } else {
            1.0
        };
        self.contacts.warm_start_from(&self.previous, scale);
        self.contacts.dt = h;

        // 2. Free velocities.
        self.vel.clear();
        for b in &self.bodies {
            self.vel.push([b.velocity.x, b.velocity.y, b.omega]);
        }
        let mut max_pen = 0.0f64;
        for (row, geo) in self.contacts.rows.iter_mut().zip(&self.contacts.geometry) {
            let open_gap = if geo.gap > geo.closed_gap {
                geo.gap
            } else {
                0.0
            };
            let mut shift = open_gap / (h * theta);
            max_pen = max_pen.max(-geo.gap);
            if geo.restitution > 0.0 {
                // Detection leaves the shift at zero, so this is u_n⁻.
                let un = row.velocity(&self.vel[row.a as usize], &self.vel[row.b as usize])[0];
                // An impact during this step (closed gap, or one that closes within the step
                // at the approach velocity): Newton's law u_n⁺ ≥ −e u_n⁻ from now on.
                if un < 0.0 && open_gap + h * un <= 0.0 {
                    shift = geo.restitution * un;
                }
            }
            row.shift = shift;
        }
        for (i, b) in self.bodies.iter().enumerate() {
            let inv = &self.inv[i];
            let f = external_loads(b, g);
            for d in 0..3 {
                if b.dofs[d] == Dof::Free {
                    self.vel[i][d] += h * inv[d] * f[d];
                }
            }
        }

        // 3. Contact solve (with the cell's stress-controlled components as unknowns under an
        //    implicit control, `crate::cell_coupling`).
        let q_norms = solver::free_velocity_norms(&self.contacts.rows, &self.vel);
        let thickness = self.grain_thickness();
        let follows = self.follows_cell();
        let mut coupling = match (self.cell_control, self.cell, free_change) {
            (Some(ctl), Some(cell), Some(delta0)) => CellCoupling::new(
                &ctl,
                &cell,
                &mut self.contacts.rows,
                &self.contacts.geometry,
                &follows,
                h,
                thickness,
                delta0,
            ),
            _ => None,
        };
        let approach_limit = self.approach_limit();
        // Emptied at the start of the step (`forget_last_step_problem`).
        self.v_free.extend_from_slice(&self.vel);
        self.last_problem = self.record_problems.then(|| {
            crate::assemble::contact_problem_with(
                &self.contacts.rows,
                &self.v_free,
                &self.inv,
                coupling.as_ref(),
            )
        });
        // Without a contact across the boundary the cell's change is δ⁰ whatever the impulses.
        // In parallel the coupled contacts are swept after the others, on one thread
        // (`CellCoupling::sweep_coupled`).
        let coupled = coupling.as_mut().filter(|c| c.coupled_contacts() > 0);
        let report = if self.params.solver.parallel {
            self.mobile.clear();
            self.mobile
                .extend(self.inv.iter().map(|i| i.iter().any(|&x| x != 0.0)));
            self.pos.clear();
            self.pos
                .extend(self.bodies.iter().map(|b| [b.position.x, b.position.y]));
            let blocks = if self.contacts.len() >= BLOCKED_MIN_CONTACTS {
                SWEEP_BLOCKS
            } else {
                1
            };
            // Solve in a block-contiguous copy (no two threads on one cache line).
            self.layout.gather(
                &self.contacts.rows,
                &self.vel,
                &self.v_free,
                &self.inv,
                &self.mobile,
                &self.pos,
                blocks,
            );
            let l = &mut self.layout;
            self.colouring
                .build_blocked(&l.rows, &l.mobile, &l.pos, blocks);
            let order = SweepOrder::Coloured {
                colouring: &mut self.colouring,
                mobile: &l.mobile,
            };
            solver::rebuild_velocities(&l.rows, &mut l.vel, &l.v_free, &l.inv, &order);
            // The coupling in the copy's numbering; its δ comes back with the impulses.
            let mut renumbered = coupled.as_deref().map(|c| c.renumbered(l.row_old()));
            let report = solver::solve(
                &mut l.rows,
                order,
                &mut l.vel,
                &l.v_free,
                &l.inv,
                q_norms,
                approach_limit,
                &self.params.solver,
                &mut self.work,
                renumbered.as_mut(),
            );
            l.scatter(&mut self.contacts.rows, &mut self.vel);
            if let (Some(c), Some(solved)) = (coupled, &renumbered) {
                c.adopt(solved, &mut self.contacts.rows);
            }
            report
        } else {
            self.order.clear();
            self.order.extend(0..self.contacts.len() as u32);
            let order = SweepOrder::Natural(&mut self.order);
            solver::rebuild_velocities(
                &self.contacts.rows,
                &mut self.vel,
                &self.v_free,
                &self.inv,
                &order,
            );
            solver::solve(
                &mut self.contacts.rows,
                order,
                &mut self.vel,
                &self.v_free,
                &self.inv,
                q_norms,
                approach_limit,
                &self.params.solver,
                &mut self.work,
                coupled,
            )
        };
        solver::classify(&self.contacts.rows, &mut self.contacts.status);
        // The images moved with L⁺ h k = (L⁻ + δ) h k during the solve: the cell deforms with
        // L⁺ (4b), the grains follow δ at the end of the step (6.).
        let delta = coupling.as_ref().map_or_else(Mat::zeros, |c| c.delta());
        self.image_outran = delta.abs().sum() > self.detector.image_rate();
        self.last_cell_step = match (self.cell, self.cell_control) {
            (Some(_), Some(ctl)) if !ctl.implicit => None,
            (Some(_), _) => Some(LastCellStep {
                coupling: coupling.take(),
            }),
            (None, _) => None,
        };

        // 4. Positions, accelerations. The grains that follow the cell's change move with it
        //    over the step (their velocities take it at 6.).
        let affine = !follows.is_empty();
        let drag_centre = self.cell.filter(|_| affine).map(|c| c.centre());
        self.displacement.clear();
        for (i, b) in self.bodies.iter_mut().enumerate() {
            let v = self.vel[i];
            for (d, x) in v.iter().enumerate() {
                if !x.is_finite() {
                    return Err(DemError::NonFinite {
                        step: self.step_index + 1,
                        body: i,
                        what: ["x velocity", "y velocity", "angular velocity"][d].into(),
                    });
                }
            }
            let vm = [b.velocity.x, b.velocity.y, b.omega];
            b.acceleration = Vector2::new((v[0] - vm[0]) / h, (v[1] - vm[1]) / h);
            b.angular_acceleration = (v[2] - vm[2]) / h;
            let mut d = [
                h * ((1.0 - theta) * vm[0] + theta * v[0]),
                h * ((1.0 - theta) * vm[1] + theta * v[1]),
                h * ((1.0 - theta) * vm[2] + theta * v[2]),
            ];
            if let (Some(c), true) = (drag_centre, follows.get(i) == Some(&true)) {
                let a = delta * (b.position - c);
                d[0] += h * theta * a.x;
                d[1] += h * theta * a.y;
            }
            self.displacement.push(d);
            b.position.x += d[0];
            b.position.y += d[1];
            b.angle += d[2];
            b.velocity = Vector2::new(v[0], v[1]);
            b.omega = v[2];
            if let Some(p) = periodic {
                if b.kind == BodyKind::Grain {
                    b.position.x = p.wrap(b.position.x);
                }
            }
        }

        // 4b. The deformable cell: h ← exp(L h) h, a basis change when it tilts beyond half a
        //     period, grains wrapped back with v ← v + L h k.
        let mut cell_work = 0.0;
        let mut cell_gap_shift = Vec::new();
        if let Some(mut cell) = self.cell {
            // The grains moved with L⁻ (the images with L⁺ = L⁻ + δ under an implicit cell).
            let (h_old, l) = (cell.h, cell.l);
            // Affine part of the step's displacements, for the outran check.
            let c = cell.centre();
            self.fluct_displacement.clear();
            for (b, d) in self.bodies.iter().zip(&self.displacement) {
                let x_old = b.position - Vect::new(d[0], d[1]);
                let a = if affine {
                    (l + delta) * (x_old - c) * h
                } else {
                    l * (x_old - c) * h
                };
                self.fluct_displacement.push([d[0] - a.x, d[1] - a.y, d[2]]);
            }
            cell.advance_with(&(l + delta), h);
            // Gap change of each image contact from the cell's deformation, n·(Δh k).
            let dh = (cell.h - h_old) * cell_inverse(&h_old);
            for (row, geo) in self.contacts.rows.iter().zip(&self.contacts.geometry) {
                if geo.image != [0.0, 0.0] {
                    let u = dh * Vect::new(geo.image[0], geo.image[1]);
                    cell_gap_shift.push(row.n[0] * u.x + row.n[1] * u.y);
                } else {
                    cell_gap_shift.push(0.0);
                }
            }
            cell.remap();
            // Until the grains follow δ (6.), the affine field of their velocities stays L⁻: the
            // wraps and the kinetic stress use it.
            self.cell = Some(cell);
            cell_work += self.wrap_grains();
            // Work of the impulses against the images' affine velocities.
            for row in &self.contacts.rows {
                cell_work -= row.r[0] * row.affine[0] + row.r[1] * row.affine[1];
            }
        }

        // 5. Position correction (velocities untouched but for the wraps of 4b).
        self.last_wrap_energy = 0.0;
        let correction = if self.params.position_correction {
            if cell_gap_shift.is_empty() {
                self.correct_positions()
            } else {
                // The projection predicts g⁺ = g⁻ + H_n Δq: add the images' affine part.
                let saved: Vec<f64> = self.contacts.geometry.iter().map(|g| g.gap).collect();
                for (g, s) in self.contacts.geometry.iter_mut().zip(&cell_gap_shift) {
                    g.gap += s;
                }
                let r = self.correct_positions();
                for (g, s) in self.contacts.geometry.iter_mut().zip(saved) {
                    g.gap = s;
                }
                r
            }
        } else {
            CorrectionReport::default()
        };

        cell_work += self.last_wrap_energy;
        let active = self.refresh_body_forces();

        // 6. Cell control: the mean stress of the step, then the new velocity gradient with
        //    the homogeneous change of the grains' velocities.
        if let Some(cell) = self.cell {
            let sigma = self.measure_cell_stress(&cell);
            self.cell_sigma = Some(sigma);
            if let Some(ctl) = self.cell_control {
                let l = if ctl.implicit {
                    // The grains take the step's change δ too (from L⁻ to the next L).
                    ctl.implicit_next(&(cell.l + delta))
                } else {
                    ctl.update(&cell.l, &sigma, h)
                };
                if l != cell.l {
                    cell_work += self.set_velocity_gradient(l);
                }
            }
        }

        // A cell whose control ran away (its rate ringing up against the packing, test
        // `a_cell_control_that_runs_away_fails_its_run_at_the_step`) makes the grains'
        // velocities non-finite only here, through the grains following it: the step fails,
        // not the measurement after it.
        if let Some(cell) = &self.cell {
            if !cell.l.iter().chain(cell.h.iter()).all(|x| x.is_finite()) {
                return Err(DemError::NonFiniteCell {
                    step: self.step_index + 1,
                });
            }
            if let Some(i) = self.bodies.iter().position(|b| {
                !(b.position
                    .iter()
                    .chain(b.velocity.iter())
                    .all(|x| x.is_finite())
                    && b.omega.is_finite())
            }) {
                return Err(DemError::NonFinite {
                    step: self.step_index + 1,
                    body: i,
                    what: "position or velocity after the cell's change".into(),
                });
            }
        }

        self.step_index += 1;
        self.time += h;
        self.last = StepReport {
            step: self.step_index,
            time: self.time,
            contacts: self.contacts.len(),
            active_contacts: active,
            solver: report,
            max_penetration: max_pen,
            position_correction: correction,
            cell_work,
            cell_corrections: 0,
        };
        Ok(self.last)
    }

    /// Step 5 (module documentation, [`crate::stabilise`]): projects the positions after the
    /// update so that no contact of the step overlaps by more than its slop, moving free degrees
    /// of freedom only and no velocity, and wraps moved grains into the periodic cell. Returns
    /// the projection's report with the work of gravity and the applied loads over it.
    fn correct_positions(&mut self) -> CorrectionReport {
        let mut report = self.projection.project(
            &self.contacts.rows,
            &self.contacts.geometry,
            &self.displacement,
            &self.inv,
        );
        if report.corrected_contacts > 0 {
            report.load_work = self.apply_correction();
        }
        // A disk that travelled beyond its swept margin plus half the detection gap, with the
        // correction, may overlap one that no contact of the step knew (`Detector::outran`):
        // detect again at the corrected positions (nothing moves now, so no swept
        // margin; pairs up to a quarter of the smallest radius apart, which the projection can
        // push into contact) and project the actual gaps.
        let moved = if self.cell.is_some() {
            &self.fluct_displacement
        } else {
            &self.displacement
        };
        // The correction that was applied (none when no contact kept a projection impulse).
        let correction = if report.corrected_contacts > 0 {
            self.projection.correction()
        } else {
            &[]
        };
        if self.image_outran || self.detector.outran(&self.colliders, moved, correction) {
            let mut fresh = std::mem::take(&mut self.fresh);
            let reach = 0.25 * self.smallest_radius().unwrap_or(0.0);
            // The second projection moves nothing unless a contact is violated: look for one
            // first (the same pairs and gaps, without making the contacts), and detect the
            // contacts only then. Without one, its report is the empty one it would return.
            let deep = self.cell.is_some()
                || self
                    .detector
                    .finds_deep_overlap(
                        &self.bodies,
                        &self.inv,
                        &self.colliders,
                        &self.laws,
                        self.periodic(),
                        reach,
                        0.0,
                        0.0,
                    )
                    .unwrap_or(true);
            let detected = if deep {
                self.detect_into(reach, 0.0, 0.0, 0.0, &mut fresh)
            } else {
                Ok(())
            };
            if detected.is_ok() {
                let second = if deep {
                    let still = vec![[0.0; 3]; self.bodies.len()];
                    self.projection
                        .project(&fresh.rows, &fresh.geometry, &still, &self.inv)
                } else {
                    CorrectionReport::default()
                };
                if second.corrected_contacts > 0 {
                    report.load_work += self.apply_correction();
                }
                report.violated_contacts += second.violated_contacts;
                report.corrected_contacts += second.corrected_contacts;
                report.sweeps += second.sweeps;
                report.capped |= second.capped;
                report.overlap_before = report.overlap_before.max(second.overlap_before);
                report.overlap_after = second.overlap_after;
                report.max_displacement = report.max_displacement.max(second.max_displacement);
            }
            self.fresh = fresh;
        }
        report
    }

    /// Moves the bodies by the last projection's correction (free degrees of freedom only,
    /// periodic wrap) and returns the work of gravity and the applied loads over it.
    fn apply_correction(&mut self) -> f64 {
        let g = self.params.gravity;
        let periodic = self.periodic();
        let mut work = 0.0;
        for ((b, dq), inv) in self
            .bodies
            .iter_mut()
            .zip(self.projection.correction())
            .zip(&self.inv)
        {
            if *dq == [0.0; 3] {
                continue;
            }
            b.position.x += dq[0];
            b.position.y += dq[1];
            b.angle += dq[2];
            let f = external_loads(b, g);
            for d in 0..3 {
                if inv[d] != 0.0 {
                    work += f[d] * dq[d];
                }
            }
            if let Some(p) = periodic {
                if b.kind == BodyKind::Grain {
                    b.position.x = p.wrap(b.position.x);
                }
            }
        }
        if self.cell.is_some() {
            // A correction is a few 10⁻⁴ R: a grain it moves across a face keeps the velocity
            // of its image, as in the step.
            self.last_wrap_energy += self.wrap_grains();
        }
        work
    }

    /// Largest approach speed of a converged solve (m/s): `overlap_rate · R_min / h`, infinite
    /// when the rate is 0 or there is no grain.
    fn approach_limit(&self) -> f64 {
        match self.smallest_radius() {
            Some(r_min) if self.params.overlap_rate > 0.0 => {
                self.params.overlap_rate * r_min / self.params.dt
            }
            _ => f64::INFINITY,
        }
    }

    /// The smallest grain radius (m), if there is a grain.
    fn smallest_radius(&self) -> Option<f64> {
        let r_min = self
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain && b.radius > 0.0)
            .map(|b| b.radius)
            .fold(f64::INFINITY, f64::min);
        r_min.is_finite().then_some(r_min)
    }

    /// Time step (s) of the impulses held in the contact set: forces are impulses divided by it.
    fn impulse_dt(&self) -> f64 {
        if self.contacts.dt > 0.0 {
            self.contacts.dt
        } else {
            self.params.dt
        }
    }

    /// The complete state needed to continue the run exactly (see [`crate::checkpoint`]).
    pub fn state(&self) -> WorldState {
        WorldState {
            params: self.params,
            bodies: self.bodies.clone(),
            colliders: self.colliders.clone(),
            laws: self.laws.clone(),
            time: self.time,
            step_index: self.step_index,
            contacts: self.contacts.clone(),
            last: self.last,
            newton_backoff: self.work.backoff,
            cell: self.cell,
            cell_control: self.cell_control,
            cell_stress: self.cell_sigma,
        }
    }

    /// Rebuild a world from [`World::state`]: stepping it gives bit-identical results to
    /// stepping the original.
    pub fn from_state(s: WorldState) -> Self {
        let mut w = World::new(s.params, s.laws);
        w.bodies = s.bodies;
        w.colliders = s.colliders;
        w.time = s.time;
        w.step_index = s.step_index;
        w.contacts = s.contacts;
        w.last = s.last;
        w.work.backoff = s.newton_backoff;
        w.cell = s.cell;
        w.cell_control = s.cell_control;
        w.refresh_inverse_mass();
        w.refresh_body_forces();
        w.cell_sigma = s.cell_stress;
        w
    }

    /// The state after the last step as plain data (see [`crate::snapshot`]).
    pub fn snapshot(&self) -> Snapshot {
        let h = self.impulse_dt();
        let bodies = self
            .bodies
            .iter()
            .map(|b| BodyState {
                kind: b.kind,
                name: b.name.clone(),
                position: b.position,
                angle: b.angle,
                velocity: b.velocity,
                omega: b.omega,
                acceleration: b.acceleration,
                angular_acceleration: b.angular_acceleration,
                mass: b.mass,
                inertia: b.inertia,
                radius: b.radius,
                density: b.density,
                thickness: b.thickness,
            })
            .collect();
        let contacts = self
            .contacts
            .rows
            .iter()
            .zip(&self.contacts.geometry)
            .zip(&self.contacts.status)
            .map(|((row, geo), st)| ContactState {
                body_a: row.a,
                body_b: row.b,
                point: Vector2::new(geo.point[0], geo.point[1]),
                normal: Vector2::new(row.n[0], row.n[1]),
                force_n: row.r[0] / h,
                force_t: row.r[1] / h,
                gap: geo.gap,
                mu: row.mu,
                status: *st,
                lever_a: Vector2::new(geo.lever_a[0], geo.lever_a[1]),
                lever_b: Vector2::new(geo.lever_b[0], geo.lever_b[1]),
            })
            .collect();
        let mut walls = Vec::new();
        for (i, b) in self.bodies.iter().enumerate() {
            if b.kind != BodyKind::Wall {
                continue;
            }
            let mine: Vec<&Collider> = self
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
            step: self.step_index,
            time: self.time,
            dt: h,
            gravity: self.params.gravity,
            periodic_x: self.params.periodic_x,
            cell: self.cell,
            bodies,
            contacts,
            walls,
        }
    }
}

/// `h⁻¹` of a cell matrix (`det h > 0` for a cell).
fn cell_inverse(h: &Mat) -> Mat {
    h.try_inverse().unwrap_or_else(Mat::zeros)
}
