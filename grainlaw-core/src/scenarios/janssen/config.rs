//! The `janssen` scenario (paper §4.3, Fig. 7): a polydisperse column deposited by gravity
//! between two vertical walls, relaxed, then its wall stresses compared with Janssen's law.

use serde::{Deserialize, Serialize};

use datasets::error::{at_least, in_range, non_negative, num, positive, DatasetError, Result};
use datasets::limits;

use crate::scenarios::common::build::column_width;
use crate::scenarios::common::config::{check_dt, check_dt_gravity, FrictionSpec, GrainSpec};
use crate::scenarios::common::deposit::{DepositSpec, RelaxSpec};

/// Configuration of the `janssen` scenario (every key of `scenarios/janssen.toml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JanssenConfig {
    /// Always `"janssen"`.
    pub scenario: String,
    /// Seed of the radii and the initial placement.
    pub seed: u64,
    /// Number of grains.
    pub grains: usize,
    /// Height / width of the settled column; the box width follows from the grains' area,
    /// `W = √(Σ π R² / (φ₀ · aspect))` with φ₀ = 0.8 (≈ 10 mean diameters for 350 grains).
    pub column_aspect: f64,
    /// Grain size and density.
    pub grain: GrainSpec,
    /// Friction coefficients.
    pub friction: FrictionSpec,
    /// Time step of the scenario (s), used in the relaxation.
    pub dt: f64,
    /// Deposition by gravity.
    pub deposit: DepositSpec,
    /// Release of the deposited column: the floor is lowered a little, slowly, so that the
    /// grains slide along the walls and the wall friction is mobilised ("relâcher le système
    /// afin de se mettre dans les conditions de Coulomb", paper §4.3).
    pub release: ReleaseSpec,
    /// Relaxation after the release.
    pub relax: RelaxSpec,
    /// Measurement and output settings.
    pub analysis: JanssenAnalysis,
}

/// Lowering of the floor after the deposition.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReleaseSpec {
    /// Distance the floor is lowered (m); 0 for none.
    pub floor_drop: f64,
    /// Speed of the floor while it is lowered (m/s).
    pub speed: f64,
    /// Contact solver during the release (the measured last step uses the relaxation's
    /// tolerance with `analysis.final_max_iterations` sweeps).
    pub solver: crate::scenarios::common::config::SolverSpec,
}

/// What to measure on the relaxed column.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JanssenAnalysis {
    /// Number of depth bins of the wall-stress profile.
    pub depth_bins: usize,
    /// Depths above this many mean diameters are left out of the fit (loose top layer).
    pub skip_top_diameters: f64,
    /// Depths within this many mean diameters of the floor are left out of the fit.
    pub skip_bottom_diameters: f64,
    /// Largest number of VTK frames (one every 0.02 s of simulated time; the final state always).
    pub vtk_frames: usize,
    /// Sweep cap of each measured step (solved to `relax.solver.tolerance`).
    pub final_max_iterations: usize,
    /// Steps of the measurement window that ends the release (the floor still sinking), each
    /// solved to `relax.solver.tolerance`; the stresses, loads and mobilisations are averaged
    /// over them. The built-in scenario sets 4; absent from scenario files written before the
    /// key existed: [`DEFAULT_MEASURE_STEPS`], the one step they were run with.
    #[serde(default = "default_measure_steps")]
    pub measure_steps: usize,
}

/// Length of the measurement window (steps) of a scenario file without the key: the single
/// measured step of the runs written before it existed, so that they run again the same.
pub const DEFAULT_MEASURE_STEPS: usize = 1;

fn default_measure_steps() -> usize {
    DEFAULT_MEASURE_STEPS
}

impl JanssenConfig {
    /// Checks every value (key named in the error), including the derived ones: the box width
    /// `W` ([`column_width`]) must hold the largest grain with the generator's gaps,
    /// and no phase may take more than [`limits::MAX_STEPS`] steps.
    pub fn validate(&self) -> Result<()> {
        limits::grains("grains", self.grains, 10)?;
        in_range("column_aspect", self.column_aspect, 0.2, 1000.0)?;
        self.grain.validate("grain")?;
        self.friction.validate("friction")?;
        check_dt("dt", self.dt, 1.0)?;
        check_dt_gravity("dt", self.dt, self.grain.radius_min())?;
        self.deposit.validate("deposit", self.dt)?;
        non_negative("release.floor_drop", self.release.floor_drop)?;
        positive("release.speed", self.release.speed)?;
        self.release.solver.validate("release.solver")?;
        at_least(
            "analysis.final_max_iterations",
            self.analysis.final_max_iterations,
            1,
        )?;
        at_least("analysis.measure_steps", self.analysis.measure_steps, 1)?;
        limits::at_most(
            "analysis.measure_steps",
            self.analysis.measure_steps,
            limits::MAX_STEPS as usize,
        )?;
        if self.release.floor_drop > 10.0 * self.grain.radius_mean {
            return Err(DatasetError::invalid(
                "release.floor_drop",
                format!(
                    "must be at most 10 mean radii ({} m), got {}",
                    num(10.0 * self.grain.radius_mean),
                    num(self.release.floor_drop)
                ),
            ));
        }
        limits::steps(
            "release.speed",
            "release.floor_drop / (release.speed · dt)",
            self.release.floor_drop / self.release.speed,
            self.dt,
        )?;
        self.relax.validate("relax", self.dt)?;
        at_least("analysis.depth_bins", self.analysis.depth_bins, 4)?;
        limits::at_most(
            "analysis.depth_bins",
            self.analysis.depth_bins,
            limits::MAX_BINS,
        )?;
        limits::at_most(
            "analysis.vtk_frames",
            self.analysis.vtk_frames,
            limits::MAX_FRAMES,
        )?;
        non_negative(
            "analysis.skip_top_diameters",
            self.analysis.skip_top_diameters,
        )?;
        non_negative(
            "analysis.skip_bottom_diameters",
            self.analysis.skip_bottom_diameters,
        )?;
        // The rain generator puts a gap of 2 % of the smallest radius on each side of a grain.
        let width = column_width(&self.grain, self.grains, self.column_aspect);
        let needed = 2.0 * self.grain.radius_max() + 2.0 * 0.02 * self.grain.radius_min();
        if width < needed {
            return Err(DatasetError::invalid(
                "column_aspect",
                format!(
                    "{} gives a box {width:.3e} m wide for {} grains, narrower than the largest \
                     grain with its gaps ({needed:.3e} m): lower column_aspect or add grains",
                    num(self.column_aspect),
                    self.grains
                ),
            ));
        }
        // Depth bins never thinner than a mean diameter: the column settles about
        // `column_aspect · W` high (W is chosen for that height at the packing guess).
        let height = self.column_aspect * width;
        let d = 2.0 * self.grain.radius_mean;
        if (height / self.analysis.depth_bins as f64) < d {
            return Err(DatasetError::invalid(
                "analysis.depth_bins",
                format!(
                    "{} bins over a column about {height:.3e} m high ({} grains) are thinner than \
                     a mean diameter ({d:.3e} m): use at most {} bins, or more grains",
                    self.analysis.depth_bins,
                    self.grains,
                    ((height / d).floor() as usize).max(1)
                ),
            ));
        }
        Ok(())
    }
}
