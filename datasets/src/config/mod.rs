//! Typed scenario configurations (one struct per scenario, `deny_unknown_fields`), each with a
//! `validate` that names the key of any out-of-range value.

pub mod arrangements;
pub mod biaxial;
pub mod column_collapse;
pub mod common;
pub mod deposit;
pub mod inclined_flow;
pub mod janssen;
pub mod laws;
pub mod rolling;
pub mod shear_cell;
pub mod simple_shear;
pub mod stick_slip;

pub use arrangements::ArrangementsConfig;
pub use biaxial::{BiaxialConfig, Preparation};
pub use column_collapse::{CollapseAnalysis, CollapseFriction, ColumnCollapseConfig};
pub use common::{CellControlMode, FrictionSpec, GrainSpec, SolverSpec};
pub use deposit::{DepositSpec, RelaxSpec};
pub use inclined_flow::InclinedFlowConfig;
pub use janssen::{JanssenAnalysis, JanssenConfig, ReleaseSpec};
pub use rolling::RollingConfig;
pub use shear_cell::ShearCellConfig;
pub use simple_shear::{CellFriction, SimpleShearConfig};
pub use stick_slip::{StickSlipCases, StickSlipConfig};
