//! The `simple-shear` scenario: a biperiodic deformable cell (no walls, no gravity), compressed
//! isotropically to a pressure, then sheared Lees–Edwards style at imposed shear rate and normal
//! stress σ_yy = −P for each inertial number; μ(I) and φ(I) are fitted.

use serde::{Deserialize, Serialize};

use super::common::{check_cell_compression, CellControlMode, GrainSpec, SolverSpec};
use crate::error::{in_range, non_negative, num, positive, DatasetError, Result};
use crate::limits;

/// Grain–grain friction (there are no walls in the cell).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellFriction {
    /// Grain–grain μ (1), ≥ 0.
    pub grain_grain: f64,
}

/// Configuration of the `simple-shear` scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimpleShearConfig {
    /// Always `"simple-shear"`.
    pub scenario: String,
    /// Seed of the radii and the initial placement.
    pub seed: u64,
    /// Number of grains (≥ 50: the cell must be at least 3 diameters wide plus margins).
    pub grains: usize,
    /// Grain size and density.
    pub grain: GrainSpec,
    /// Friction coefficient between grains.
    pub friction: CellFriction,
    /// Confining pressure P (Pa), > 0: σ_xx = σ_yy = −P in the compression, σ_yy = −P in shear.
    pub pressure: f64,
    /// Target inertial numbers `I = γ̇ d / √(P/ρ)`, one shear run each (lowest first).
    pub inertial_numbers: Vec<f64>,
    /// Shear strain of each run (1).
    pub strain: f64,
    /// The last `average_strain` of each run is averaged (1).
    pub average_strain: f64,
    /// Largest time step (s).
    pub dt_max: f64,
    /// Largest relative travel of neighbouring grains per step, `γ̇ d Δt / R̄` (1), sets Δt.
    pub travel_per_step: f64,
    /// Cap of the cell's strain rate under stress control, as an inertial number
    /// `I_cell = ε̇_max d / √(P/ρ)` (1), in (0, 0.1].
    pub control_inertial_number: f64,
    /// `implicit` (default) or `explicit` control of the cell ([`CellControlMode`]).
    #[serde(default)]
    pub cell_control: CellControlMode,
    /// Duration of the isotropic compression (s).
    pub compression_time: f64,
    /// Solid fraction of the initial loose packing (1), in [0.2, 0.6].
    pub initial_solid_fraction: f64,
    /// Contact solver.
    pub solver: SolverSpec,
    /// Laws not to fit (`grainlaw fit` names), so that a plan short of their data runs
    /// ([`super::laws`]: checked at load, said at the start of the run).
    #[serde(default)]
    pub leave_out: Vec<String>,
}

impl SimpleShearConfig {
    /// The laws it fits and the data each needs ([`super::laws`]).
    pub fn law_needs(&self) -> Vec<super::laws::LawNeed> {
        super::laws::rheology(self.inertial_numbers.len())
    }

    /// Checks every value (key named in the error) and that no phase exceeds
    /// [`limits::MAX_STEPS`] steps.
    pub fn validate(&self) -> Result<()> {
        limits::grains("grains", self.grains, 50)?;
        self.grain.validate("grain")?;
        non_negative("friction.grain_grain", self.friction.grain_grain)?;
        if !(self.pressure.is_finite() && self.pressure > 0.0) {
            return Err(DatasetError::invalid(
                "pressure",
                format!(
                    "must be a positive pressure in Pa, got {}",
                    num(self.pressure)
                ),
            ));
        }
        limits::pressure("pressure", self.pressure)?;
        if self.inertial_numbers.is_empty() {
            return Err(DatasetError::invalid(
                "inertial_numbers",
                "is empty: give at least one inertial number (what each law needs: `grainlaw scenarios --show simple-shear`)",
            ));
        }
        limits::at_most("inertial_numbers", self.inertial_numbers.len(), 100)?;
        for (i, &v) in self.inertial_numbers.iter().enumerate() {
            if !(v.is_finite() && v > 0.0) {
                return Err(DatasetError::invalid(
                    format!("inertial_numbers[{i}]"),
                    format!("must be > 0, got {}", num(v)),
                ));
            }
            in_range(&format!("inertial_numbers[{i}]"), v, 1e-5, 1.0)?;
        }
        positive("strain", self.strain)?;
        positive("average_strain", self.average_strain)?;
        if self.average_strain > self.strain {
            return Err(DatasetError::invalid(
                "average_strain",
                format!(
                    "must not exceed strain ({}), got {}",
                    num(self.strain),
                    num(self.average_strain)
                ),
            ));
        }
        in_range("travel_per_step", self.travel_per_step, 1e-4, 0.5)?;
        check_cell_compression(
            self.dt_max,
            self.control_inertial_number,
            self.compression_time,
            self.initial_solid_fraction,
            &self.solver,
        )?;
        let d = 2.0 * self.grain.radius_mean;
        let i_min = self
            .inertial_numbers
            .iter()
            .cloned()
            .fold(f64::MAX, f64::min);
        let gamma_dot = i_min * (self.pressure / self.grain.density).sqrt() / d;
        limits::steps(
            "inertial_numbers",
            &format!("strain / (γ̇ dt_max) of the slowest run (I = {i_min:e})"),
            self.strain / gamma_dot,
            self.dt_max,
        )?;
        limits::steps(
            "travel_per_step",
            "strain · d / (travel_per_step · radius_mean)",
            self.strain * d,
            self.travel_per_step * self.grain.radius_mean,
        )?;
        Ok(())
    }
}
