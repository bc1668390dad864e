//! The `rolling` scenario (paper §3, `docs/physics.md` §2.3): one homogeneous disk released
//! from rest on a slope, the exact check of the mean stress with inertia.

use serde::{Deserialize, Serialize};

use datasets::error::{in_range, non_negative, num, positive, DatasetError, Result};
use datasets::limits;

use crate::scenarios::common::config::check_dt;

/// Configuration of the `rolling` scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RollingConfig {
    /// Always `"rolling"`.
    pub scenario: String,
    /// Seed (the scenario is deterministic; recorded for provenance).
    pub seed: u64,
    /// Slope angle φ (degrees), in [0, 90).
    pub slope_deg: f64,
    /// Disk radius a (m).
    pub radius: f64,
    /// Disk density ρ (kg/m³).
    pub density: f64,
    /// Disk–slope friction μ (rolls without slipping when μ ≥ tan φ / 3).
    pub friction: f64,
    /// Simulated time (s).
    pub duration: f64,
    /// Time step (s).
    pub dt: f64,
}

impl RollingConfig {
    /// Checks every value (key named in the error).
    pub fn validate(&self) -> Result<()> {
        in_range("slope_deg", self.slope_deg, 0.0, 90.0)?;
        if self.slope_deg >= 90.0 {
            return Err(DatasetError::invalid(
                "slope_deg",
                format!("must be below 90°, got {}", num(self.slope_deg)),
            ));
        }
        limits::radius("radius", self.radius)?;
        limits::density("density", self.density)?;
        non_negative("friction", self.friction)?;
        positive("duration", self.duration)?;
        check_dt("dt", self.dt, self.duration)?;
        limits::steps("dt", "duration / dt", self.duration, self.dt)?;
        Ok(())
    }
}
