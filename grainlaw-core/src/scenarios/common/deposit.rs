//! Settings of a gravity deposition phase (shared by the column scenarios).

use serde::{Deserialize, Serialize};

use super::config::SolverSpec;
use datasets::error::{at_least, num, positive, Result};
use datasets::limits;

use crate::scenarios::phases::RunUntilRest;

/// A deposition by gravity: grains placed without overlap above the floor fall and settle.
///
/// The phase runs with the time step `dt / substeps` (sub-stepping keeps each grain's travel
/// per step below about a tenth of the smallest radius during the collapse, where the contact
/// solver then needs few sweeps) until the grains are at rest,
/// `E_kin < rest_energy · Σ m g d` (d the grain's diameter) after 20 consecutive steps whose
/// solves converged ([`crate::scenarios::phases::RunUntilRest`]), or until `max_time`.
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
    /// The deposit's run until rest: from the start (no shortest time) to at most `max_time`,
    /// at rest below `rest_energy`.
    pub fn until_rest(&self) -> RunUntilRest {
        RunUntilRest {
            min_time: 0.0,
            max_time: self.max_time,
            rest_energy: self.rest_energy,
        }
    }

    /// Checks every field; `prefix` is the table's key and `dt` (s) the scenario's time step,
    /// which the deposition divides by `substeps` (at most [`limits::MAX_SUBSTEPS`], and at most
    /// [`limits::MAX_STEPS`] steps up to `max_time`).
    pub fn validate(&self, prefix: &str, dt: f64) -> Result<()> {
        at_least(&format!("{prefix}.substeps"), self.substeps, 1)?;
        limits::at_most(
            &format!("{prefix}.substeps"),
            self.substeps,
            limits::MAX_SUBSTEPS,
        )?;
        positive(&format!("{prefix}.max_time"), self.max_time)?;
        limits::steps(
            &format!("{prefix}.max_time"),
            &format!("{prefix}.max_time / (dt / {prefix}.substeps)"),
            self.max_time,
            dt / self.substeps as f64,
        )?;
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
    /// Rest criterion: kinetic energy over `Σ m g d` (1), after 20 consecutive converged steps
    /// ([`crate::scenarios::phases::RunUntilRest`]).
    pub rest_energy: f64,
    /// Contact solver of the relaxation (tight, e.g. 1e-6: the measured state).
    pub solver: SolverSpec,
}

impl RelaxSpec {
    /// The relaxation's run until rest: `min_time` to `max_time`, at rest below
    /// `rest_energy`.
    pub fn until_rest(&self) -> RunUntilRest {
        RunUntilRest {
            min_time: self.min_time,
            max_time: self.max_time,
            rest_energy: self.rest_energy,
        }
    }

    /// Checks every field; `prefix` is the table's key and `dt` (s) the time step of the
    /// relaxation (at most [`limits::MAX_STEPS`] steps up to `max_time`).
    pub fn validate(&self, prefix: &str, dt: f64) -> Result<()> {
        datasets::error::non_negative(&format!("{prefix}.min_time"), self.min_time)?;
        positive(&format!("{prefix}.max_time"), self.max_time)?;
        limits::steps(
            &format!("{prefix}.max_time"),
            &format!("{prefix}.max_time / dt"),
            self.max_time,
            dt,
        )?;
        if self.min_time > self.max_time {
            return Err(datasets::error::DatasetError::invalid(
                format!("{prefix}.min_time"),
                format!(
                    "must not exceed max_time ({} s), got {}",
                    num(self.max_time),
                    num(self.min_time)
                ),
            ));
        }
        positive(&format!("{prefix}.rest_energy"), self.rest_energy)?;
        self.solver.validate(&format!("{prefix}.solver"))
    }
}
