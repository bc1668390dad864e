//! # homogenise — from contact-dynamics snapshots to continuum fields
//!
//! Reads `dem::snapshot::Snapshot`s (bodies, contacts, walls after a step; forces are the step's
//! impulses divided by the time step) and computes (`docs/physics.md` §2):
//!
//! - per-grain mean stress with inertia, `Σ_p = Σ_c + Σ_i`, symmetric, and its region mean
//!   `Σ = (1/V) Σ_p V_p Σ_p` ([`stress`], regions in [`region`], exact disk–rectangle areas in
//!   [`overlap`]); invariants `P`, `τ`, `μ = τ/P` and the inertial number ([`invariants`]);
//! - mean velocity gradient by an affine fit, shear rate, wall-driven strain rate ([`kinematics`]);
//! - solid fraction, coordination with and without rattlers, fabric ([`state`]);
//! - per-grain inertia ratio `‖Σ_i‖/‖Σ_c‖` ([`inertia_ratio`]);
//! - wall stress profiles by depth, vertical stress across planes, near-wall flow profiles
//!   ([`walls`], depth bins in [`depth`]) and friction mobilisation ([`mobilisation`]);
//! - histories: sampling into tables and CSV ([`history`], [`table`]), time averages with
//!   block-averaging standard errors ([`averaging`]);
//! - Gaussian coarse-grained fields ([`coarse`]).
//!
//! Units SI; stresses in Pa with tension positive; vectors and tensors are those of the
//! dimension layer, [`dem::math::Vector`] and [`dem::math::Tensor`], with
//! `(a ⊗ b)_ij = a_i b_j` ([`tensor`]).

pub mod averaging;
pub mod cell;
pub mod coarse;
pub mod column;
pub mod depth;
pub mod error;
pub mod flow;
pub mod history;
pub mod inertia_ratio;
pub mod invariants;
pub mod kinematics;
pub mod mobilisation;
pub mod overlap;
pub mod region;
pub mod state;
pub mod stress;
pub mod table;
pub mod tensor;
pub mod validate;
pub mod walls;

pub use error::{HomogeniseError, Result};
pub use region::{Rect, Region};
pub use stress::{grain_stresses, mean_stress, GrainStress, RegionStress};
pub use tensor::Tensor2;
