//! # dem — 2D non-smooth contact dynamics
//!
//! Rigid disks and walls, Moreau–Jean time stepping, Coulomb friction as one bipotential solved
//! by nonlinear Gauss–Seidel with the bipotential predictor–corrector per contact.
//!
//! Data: [`body::Body`] (rigid bodies with per-degree-of-freedom control), [`collider::Collider`]
//! (disks, lines, segments attached to bodies), [`material::ContactLaws`] (μ, e per material
//! pair), [`contact::ContactSet`] (the contacts of a step), [`snapshot::Snapshot`] (the state
//! after a step, for the later stages).
//!
//! Algorithms, in the order of one step ([`world::World::step`]):
//! [`detection`] (cell grid, O(N)) → free velocities → [`solver`] (NLGS, O(1) per contact
//! update, local law in [`local`]; optionally on several threads by spatial slabs and a
//! coloured separator, [`colouring`], [`blocked`] and [`parallel`], with the same numbers on any
//! thread count) → θ-method position update → [`stabilise`] (a frictionless projection of the
//! positions that removes the overlaps deeper than a slop, without touching the velocities).
//!
//! Steps the solver cannot finish: [`step_control::step_subdivided`] undoes such a step and
//! does it again in up to `2^max_halvings` sub-steps (every scenario phase steps through it).
//!
//! Helpers for runs that only want a state: [`hydrostatic`] (a weight-carrying first guess of
//! the impulses of a packing generated at rest, [`world::World::prime_with_weight`]) and
//! [`step_control::StepControl`] (a time step adapted to the solver's convergence).
//!
//! Boundaries: walls, a periodic x direction ([`detection::Periodic`]), or a biperiodic
//! deformable cell with mixed stress/strain-rate control ([`cell`], [`world::World::cell`]).
//!
//! The same local law solves standalone frictional-contact problems given by `W`, `q`, `μ`
//! ([`fc`]).

pub mod anderson;
pub mod assemble;
pub mod atomic;
pub mod blocked;
pub mod body;
pub mod cell;
pub mod cell_coupling;
pub mod checkpoint;
pub mod collider;
pub mod colouring;
pub mod cone;
pub mod contact;
pub mod detection;
#[cfg(feature = "dim3")]
pub mod dim3;
pub mod energy;
pub mod error;
pub mod fc;
pub mod hydrostatic;
pub mod local;
pub mod material;
pub mod math;
pub mod nlgs;
pub mod parallel;
pub mod serde_float;
pub mod settle;
pub mod snapshot;
pub mod solver;
pub mod stabilise;
pub mod step_control;
pub mod sweep;
#[cfg(test)]
mod test_support;
pub mod wavefront;
pub mod world;

pub use body::{Body, BodyKind, Dof};
pub use cell::{Cell, CellControl, Imposed};
pub use error::DemError;
pub use local::ContactStatus;
pub use material::ContactLaws;
pub use snapshot::Snapshot;
pub use solver::{SolveReport, SolverParams};
pub use world::{StepReport, World, WorldParams};
