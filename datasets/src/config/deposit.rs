//! Settings of a gravity deposition phase (shared by the column scenarios).

use serde::{Deserialize, Serialize};

use super::common::SolverSpec;
use crate::error::{at_least, positive, Result};

/// A deposition by gravity: grains placed without overlap above the floor fall and settle.
///
/// The phase runs with the time step `dt / substeps` (sub-stepping keeps each grain's travel
/// per step below about a tenth of the smallest radius during the collapse, where the contact
/// solver then needs few sweeps) until the grains are at rest,
/// `E_kin < rest_energy · Σ m g d` (d the grain's diameter), or until `max_time`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepositSpec {
    /// Sub-steps per scenario time step during the deposition (≥ 1).
    pub substeps: usize,
    /// Longest deposition (s of simulated time).
    pub max_time: f64,
    /// Rest criterion: kinetic energy over `Σ m g d` (1).
    pub rest_energy: f64,
    /// Contact solver of the deposition (a loose tolerance, e.g. 1e-4, is enough).
    pub solver: SolverSpec,
}

impl DepositSpec {
    /// Checks every field; `prefix` is the table's key.
    pub fn validate(&self, prefix: &str) -> Result<()> {
        at_least(&format!("{prefix}.substeps"), self.substeps, 1)?;
        positive(&format!("{prefix}.max_time"), self.max_time)?;
        positive(&format!("{prefix}.rest_energy"), self.rest_energy)?;
        self.solver.validate(&format!("{prefix}.solver"))
    }
}

/// A relaxation at the scenario's time step with a tight solver tolerance, until rest or
/// `max_time`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RelaxSpec {
    /// Shortest relaxation (s).
    pub min_time: f64,
    /// Longest relaxation (s).
    pub max_time: f64,
    /// Rest criterion: kinetic energy over `Σ m g d` (1).
    pub rest_energy: f64,
    /// Contact solver of the relaxation (tight, e.g. 1e-6: the measured state).
    pub solver: SolverSpec,
}

impl RelaxSpec {
    /// Checks every field; `prefix` is the table's key.
    pub fn validate(&self, prefix: &str) -> Result<()> {
        crate::error::non_negative(&format!("{prefix}.min_time"), self.min_time)?;
        positive(&format!("{prefix}.max_time"), self.max_time)?;
        if self.min_time > self.max_time {
            return Err(crate::error::DatasetError::Invalid {
                key: format!("{prefix}.min_time"),
                reason: format!(
                    "must not exceed max_time ({} s), got {}",
                    self.max_time, self.min_time
                ),
            });
        }
        positive(&format!("{prefix}.rest_energy"), self.rest_energy)?;
        self.solver.validate(&format!("{prefix}.solver"))
    }
}
