//! The `inclined-flow` scenario (paper §3, Fig. 4): a polydisperse layer flowing down a rough
//! slope, periodic along the slope; per-grain inertia ratio map and velocity profile.

use serde::{Deserialize, Serialize};

use datasets::error::{at_least, in_range, num, positive, DatasetError, Result};
use datasets::limits;

use crate::scenarios::common::config::{
    check_average, check_dt, check_dt_gravity, check_periodic_cell, FrictionSpec, GrainSpec,
    SolverSpec,
};

/// Configuration of the `inclined-flow` scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InclinedFlowConfig {
    /// Always `"inclined-flow"`.
    pub scenario: String,
    /// Seed of the radii, placement and bottom roughness.
    pub seed: u64,
    /// Number of grains.
    pub grains: usize,
    /// Slope angle θ (degrees), in (0, 90).
    pub slope_deg: f64,
    /// Length of the periodic cell along the slope, in mean grain diameters.
    pub cell_length_diameters: f64,
    /// Grain size and density.
    pub grain: GrainSpec,
    /// Friction coefficients (wall = the glued grains of the rough bottom).
    pub friction: FrictionSpec,
    /// Time step (s).
    pub dt: f64,
    /// Simulated time of the flow (s).
    pub duration: f64,
    /// The profiles and maps are averaged over the last `average` seconds.
    pub average: f64,
    /// Contact solver.
    pub solver: SolverSpec,
    /// Number of layers of the velocity profile.
    pub profile_bins: usize,
    /// Inertia ratio above which a grain counts as fluid-like (1).
    pub fluid_threshold: f64,
    /// VTK frames written during the flow.
    pub vtk_frames: usize,
}

impl InclinedFlowConfig {
    /// Checks every value (key named in the error).
    pub fn validate(&self) -> Result<()> {
        limits::grains("grains", self.grains, 10)?;
        in_range("slope_deg", self.slope_deg, 0.0, 89.999)?;
        if self.slope_deg <= 0.0 {
            return Err(DatasetError::invalid(
                "slope_deg",
                format!("must be in (0, 90)°, got {}", num(self.slope_deg)),
            ));
        }
        check_periodic_cell(
            "cell_length_diameters",
            self.cell_length_diameters,
            &self.grain,
        )?;
        self.friction.validate("friction")?;
        positive("duration", self.duration)?;
        check_dt("dt", self.dt, self.duration)?;
        check_dt_gravity("dt", self.dt, self.grain.radius_min())?;
        limits::steps("dt", "duration / dt", self.duration, self.dt)?;
        check_average("average", self.average, "duration", self.duration, " s")?;
        self.solver.validate("solver")?;
        at_least("profile_bins", self.profile_bins, 2)?;
        limits::at_most("profile_bins", self.profile_bins, limits::MAX_BINS)?;
        limits::at_most("vtk_frames", self.vtk_frames, limits::MAX_FRAMES)?;
        positive("fluid_threshold", self.fluid_threshold)?;
        Ok(())
    }
}
