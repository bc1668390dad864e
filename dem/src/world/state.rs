//! The world's two halves: its state ([`WorldState`]: what a checkpoint saves and an undo
//! restores) and its work space ([`WorkSpace`]: buffers, scratch and caches that a step fills
//! before it reads them). A [`World`](super::World) is one of each; the step
//! ([`super::step`]) reads the state, works in the work space and leaves its results in the
//! state.

use serde::{Deserialize, Serialize};

use crate::blocked::BlockLayout;
use crate::body::Body;
use crate::cell::{Cell, CellControl};
use crate::cell_coupling::CellCoupling;
use crate::collider::Collider;
use crate::colouring::ContactColouring;
use crate::contact::ContactSet;
use crate::detection::Detector;
use crate::fc::FcProblem;
use crate::material::ContactLaws;
use crate::math::{Spatial, Tensor};
use crate::solver::{NewtonBackoff, SolverWork};
use crate::stabilise::Projection;

use super::{StepReport, WorldParams};

/// The state of a [`World`](super::World): everything a step reads before writing it, so that
/// stepping a copy of it gives the same bits as stepping the world. Its serialised fields are
/// the checkpoint ([`crate::checkpoint`], format `grainlaw-checkpoint-v1`: same keys, same
/// order); the others ([`WorldState::record_problems`] and the record of the last step, which
/// a resumed run rebuilds or does without) are copied by an undo point
/// ([`World::undo_point`](super::World::undo_point)) but not written.
///
/// The world's public fields (`params`, `bodies`, `colliders`, `laws`, `time`, `step_index`,
/// `cell_control`, `record_problems`) are reached through the world (`world.bodies`), which
/// dereferences to its state.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct WorldState {
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
    /// Contacts of the last step (their impulses warm-start the next one).
    pub(crate) contacts: ContactSet,
    /// Report of the last step.
    pub(crate) last: StepReport,
    /// Back-off of the `auto` solver's Newton stage (a resumed run takes the same decisions).
    #[serde(default)]
    pub(crate) newton_backoff: NewtonBackoff,
    /// Biperiodic deformable cell ([`crate::cell`]); `None`: walls and `periodic_x` only.
    /// Set it with [`World::set_cell`](super::World::set_cell).
    #[serde(default)]
    pub(crate) cell: Option<Cell>,
    /// Mixed stress/strain-rate control of the cell, applied after every step.
    #[serde(default)]
    pub cell_control: Option<CellControl>,
    /// Mean stress of the cell after the last step (Pa),
    /// [`World::cell_stress`](super::World::cell_stress).
    #[serde(default)]
    pub(crate) cell_stress: Option<Tensor>,
    /// Keep the frictional-contact problem of each step
    /// ([`World::last_problem`](super::World::last_problem)), to write it to a file
    /// (`grainlaw run --dump-problems`). Costs one assembly of `W` per step. Not checkpointed.
    #[serde(skip)]
    pub record_problems: bool,
    /// What the last step leaves to be read after it. Not checkpointed.
    #[serde(skip)]
    pub(crate) last_step: LastStep,
}

impl WorldState {
    /// The state of an empty world.
    pub(crate) fn new(params: WorldParams, laws: ContactLaws) -> Self {
        WorldState {
            params,
            bodies: Vec::new(),
            colliders: Vec::new(),
            laws,
            time: 0.0,
            step_index: 0,
            contacts: ContactSet::default(),
            last: StepReport::default(),
            newton_backoff: NewtonBackoff::default(),
            cell: None,
            cell_control: None,
            cell_stress: None,
            record_problems: false,
            last_step: LastStep::default(),
        }
    }
}

/// What a step leaves behind besides the bodies and contacts, read after it (contact forces on
/// bodies, [`World::last_step_problem`](super::World::last_step_problem)): part of the state,
/// copied by an undo point, not checkpointed (a resumed world refreshes the inverse masses and
/// body forces, and has no last problem).
#[derive(Debug, Clone, Default)]
pub(crate) struct LastStep {
    /// Inverse mass per degree of freedom of every body, `(1/m, 1/m, 1/I)`, zero where imposed.
    pub(crate) inv: Vec<Spatial>,
    /// Contact force and torque received by each body (N, N·m).
    pub(crate) body_force: Vec<Spatial>,
    /// The free velocities of the step (empty when its problem is not available).
    pub(crate) v_free: Vec<Spatial>,
    /// The step's problem, when [`WorldState::record_problems`] is set.
    pub(crate) problem: Option<FcProblem>,
    /// What a deformable cell's step adds to its contact problem.
    pub(crate) cell_step: Option<LastCellStep>,
}

/// The part of a deformable cell's step that depends on the contact impulses, kept after the
/// step for [`World::last_step_problem`](super::World::last_step_problem) and
/// [`World::snapshot_with_last_impulses`](super::World::snapshot_with_last_impulses): under an
/// implicit control the coupling of its stress-controlled components to the contacts
/// ([`crate::cell_coupling`]), whose change `δ` of `L` the grains then follow
/// (`v ← v + δ (x − c)`); without a control, or one that imposes no stress, nothing (the
/// cell's motion does not depend on the impulses). An explicit control, whose next `L`
/// depends on the step's stress through its own law, keeps none (not available).
#[derive(Debug, Clone, Default)]
pub(crate) struct LastCellStep {
    pub(crate) coupling: Option<CellCoupling>,
}

/// The work space of a [`World`](super::World): what a step fills before reading it. An undo
/// point leaves it empty (but for what the solver carries over, [`SolverWork::carried`]);
/// returning to one keeps it, with its allocations.
#[derive(Debug, Clone, Default)]
pub(crate) struct WorkSpace {
    /// The previous step's contacts, warm-start source of the detection.
    pub(crate) previous: ContactSet,
    /// Broad phase, with the candidate list it keeps between detections (the contacts are the
    /// same with or without it).
    pub(crate) detector: Detector,
    /// Velocities during the solve, `(v_x, v_y, ω)` per body.
    pub(crate) vel: Vec<Spatial>,
    /// Sweep order in natural mode.
    pub(crate) order: Vec<u32>,
    /// Whether each body has a free degree of freedom (parallel sweep).
    pub(crate) mobile: Vec<bool>,
    /// Body centres (parallel sweep).
    pub(crate) pos: Vec<[f64; 2]>,
    /// Block-contiguous copy of the problem (parallel sweep).
    pub(crate) layout: BlockLayout,
    /// Colouring of the parallel sweep.
    pub(crate) colouring: ContactColouring,
    /// The contact solver's buffers (and the back-off of `auto`, copied from and to
    /// [`WorldState::newton_backoff`] around each solve).
    pub(crate) solver: SolverWork,
    /// Displacement of each body over the step.
    pub(crate) displacement: Vec<Spatial>,
    /// Fluctuating displacements of the step (cell only), for the outran check.
    pub(crate) fluct_displacement: Vec<Spatial>,
    /// The position correction's projection.
    pub(crate) projection: Projection,
    /// Contacts detected again after a step whose disks outran their swept margins.
    pub(crate) fresh: ContactSet,
    /// Kinetic energy changed by wraps during the position correction (J).
    pub(crate) wrap_energy: f64,
    /// Whether the step's implicit cell changed `L` by more than the swept margins covered
    /// ([`crate::detection::Detector::image_rate`]): detect again after it.
    pub(crate) image_outran: bool,
    /// When problems are recorded: the problem and report of the first kept sub-step of the
    /// last subdivided step whose solve did not converge
    /// ([`crate::step_control::step_subdivided`]). A step clears it.
    pub(crate) unconverged_problem: Option<(FcProblem, StepReport)>,
}

impl WorkSpace {
    /// The work space of an undo point: empty, but for what the solver carries from one solve
    /// to the next ([`SolverWork::carried`]).
    pub(crate) fn carried(&self) -> WorkSpace {
        WorkSpace {
            solver: self.solver.carried(),
            ..WorkSpace::default()
        }
    }

    /// Takes what the solver carries from `src` ([`WorkSpace::carried`]), keeping the rest.
    pub(crate) fn restore_carried(&mut self, src: &WorkSpace) {
        self.solver.restore_carried(&src.solver);
    }
}
