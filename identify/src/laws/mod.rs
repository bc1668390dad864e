//! The closed-form laws, as plain parameter structs with their formulas (and the derivatives
//! the fits need). The fits that calibrate them live in the modules named after each law
//! ([`crate::janssen`], [`crate::mu_i`], [`crate::wall_law`], [`crate::mohr_coulomb`], [`crate::critical_state`]).

pub mod boundary_layer;
pub mod critical_state;
pub mod janssen;
pub mod mohr_coulomb;
pub mod mu_i;
pub mod wall_friction;

pub use boundary_layer::VelocityBoundaryLayer;
pub use critical_state::{CriticalStateLaw, StressDilatancyLaw};
pub use janssen::{JanssenLaw, JanssenVerticalLaw, STANDARD_GRAVITY};
pub use mohr_coulomb::{DruckerPrager, MohrCoulombLaw};
pub use mu_i::{LinearMuILaw, MuILaw, PhiILaw};
pub use wall_friction::WallFrictionLaw;
