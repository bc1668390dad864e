//! # dem — 2D non-smooth contact dynamics
//!
//! Rigid disks and walls, Moreau–Jean time stepping, Coulomb friction as one bipotential solved
//! by nonlinear Gauss–Seidel with the bipotential predictor–corrector per contact.
//!
//! Pipeline of one step (see [`world::World::step`]):
//! detection ([`detection`]) → free velocities → NLGS contact solve ([`solver`], local law in
//! [`local`]) → θ-method position update.
//!
//! The same local law solves standalone frictional-contact problems given by `W`, `q`, `μ`
//! ([`fc`]).

pub mod fc;
pub mod local;
pub mod snapshot;
