//! The `stick-slip` scenario (paper §4.2, Fig. 6): grains deposited by gravity in an open
//! container, then the bottom wall pushed up at constant speed; the force on the moving wall
//! against time for three friction cases.

use serde::{Deserialize, Serialize};

use datasets::error::{in_range, positive, Result};
use datasets::limits;

use crate::scenarios::common::config::{
    check_dt, check_dt_gravity, FrictionSpec, GrainSpec, SolverSpec,
};
use crate::scenarios::common::deposit::DepositSpec;

/// Configuration of the `stick-slip` scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StickSlipConfig {
    /// Always `"stick-slip"`.
    pub scenario: String,
    /// Seed of the radii and the initial placement (the same for the three cases).
    pub seed: u64,
    /// Number of grains.
    pub grains: usize,
    /// Container width in mean grain diameters.
    pub width_diameters: f64,
    /// Grain size and density.
    pub grain: GrainSpec,
    /// Upward speed of the bottom wall (m/s).
    pub push_velocity: f64,
    /// Time step of the push (s).
    pub dt: f64,
    /// Duration of the push (s).
    pub push_duration: f64,
    /// Deposition before the push (with the case's friction).
    pub deposit: DepositSpec,
    /// Contact solver during the push.
    pub solver: SolverSpec,
    /// The three friction cases.
    pub cases: StickSlipCases,
}

/// The paper's three friction cases.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StickSlipCases {
    /// μ = 0 everywhere.
    pub frictionless: FrictionSpec,
    /// Friction at the walls only.
    pub walls_only: FrictionSpec,
    /// Friction at the walls and between grains.
    pub walls_and_grains: FrictionSpec,
}

impl StickSlipCases {
    /// `(name, friction)` of each case, in the paper's order.
    pub fn list(&self) -> [(&'static str, FrictionSpec); 3] {
        [
            ("frictionless", self.frictionless),
            ("walls_only", self.walls_only),
            ("walls_and_grains", self.walls_and_grains),
        ]
    }
}

impl StickSlipConfig {
    /// Checks every value (key named in the error); the deposition and the push take at most
    /// [`limits::MAX_STEPS`] steps each.
    pub fn validate(&self) -> Result<()> {
        limits::grains("grains", self.grains, 3)?;
        in_range("width_diameters", self.width_diameters, 2.0, 1e4)?;
        self.grain.validate("grain")?;
        positive("push_velocity", self.push_velocity)?;
        positive("push_duration", self.push_duration)?;
        check_dt("dt", self.dt, self.push_duration)?;
        check_dt_gravity("dt", self.dt, self.grain.radius_min())?;
        limits::steps("dt", "push_duration / dt", self.push_duration, self.dt)?;
        self.deposit.validate("deposit", self.dt)?;
        self.solver.validate("solver")?;
        self.cases.frictionless.validate("cases.frictionless")?;
        self.cases.walls_only.validate("cases.walls_only")?;
        self.cases
            .walls_and_grains
            .validate("cases.walls_and_grains")
    }
}
