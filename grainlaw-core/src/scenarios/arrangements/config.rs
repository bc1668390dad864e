//! The `arrangements` scenario (paper §4.1, Fig. 5): equal rigid cylinders stacked in a box of
//! two vertical and two horizontal fixed walls, in rectangular, triangular and "cannonball"
//! arrangements; load transfer to the walls.

use serde::{Deserialize, Serialize};

use datasets::error::{at_least, in_range, positive, Result};
use datasets::limits;

use crate::scenarios::common::config::{check_dt, FrictionSpec, SolverSpec};

/// Configuration of the `arrangements` scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArrangementsConfig {
    /// Always `"arrangements"`.
    pub scenario: String,
    /// Seed of the small random initial gaps (see `jitter`).
    pub seed: u64,
    /// Radius of every cylinder (m).
    pub radius: f64,
    /// Density (kg/m³).
    pub density: f64,
    /// Cylinders in the bottom row; the box is `2 R · columns` wide.
    pub columns: usize,
    /// Rows of the rectangular and triangular stacks (the cannonball pyramid has `columns` rows).
    pub rows: usize,
    /// Friction coefficients (walls rub when `grain_wall > 0`).
    pub friction: FrictionSpec,
    /// Initial vertical gap between rows, as a fraction of the radius, so that each stack settles
    /// under gravity into its contacts.
    pub gap: f64,
    /// Random extra gap, uniform in `[0, jitter · R]` per cylinder (seeded), 0 for perfect
    /// lattices.
    pub jitter: f64,
    /// Time step (s).
    pub dt: f64,
    /// Simulated time of the settling (s).
    pub duration: f64,
    /// Contact solver.
    pub solver: SolverSpec,
}

impl ArrangementsConfig {
    /// Checks every value (key named in the error).
    pub fn validate(&self) -> Result<()> {
        limits::radius("radius", self.radius)?;
        limits::density("density", self.density)?;
        at_least("columns", self.columns, 2)?;
        limits::at_most("columns", self.columns, 200)?;
        at_least("rows", self.rows, 1)?;
        limits::at_most("rows", self.rows, 200)?;
        self.friction.validate("friction")?;
        in_range("gap", self.gap, 0.0, 1.0)?;
        in_range("jitter", self.jitter, 0.0, 1.0)?;
        positive("duration", self.duration)?;
        check_dt("dt", self.dt, self.duration)?;
        limits::steps("dt", "duration / dt", self.duration, self.dt)?;
        self.solver.validate("solver")
    }
}
