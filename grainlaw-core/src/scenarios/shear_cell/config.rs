//! The `shear-cell` scenario (beyond the paper): steady plane shear of a periodic sample between
//! two rough walls, the top wall at imposed normal pressure and velocity, swept over several
//! inertial numbers; μ(I), φ(I) and the wall boundary-layer law are fitted.

use serde::{Deserialize, Serialize};

use datasets::error::{in_range, num, positive, DatasetError, Result};
use datasets::limits;

use crate::scenarios::common::config::{
    check_inertial_numbers, check_periodic_cell, check_strain_window, FrictionSpec, GrainSpec,
    SolverSpec,
};
use crate::scenarios::common::laws::LawNeed;

/// Configuration of the `shear-cell` scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShearCellConfig {
    /// Always `"shear-cell"`.
    pub scenario: String,
    /// Seed of the radii, placement and wall roughness.
    pub seed: u64,
    /// Number of grains.
    pub grains: usize,
    /// Length of the periodic cell, in mean grain diameters.
    pub cell_length_diameters: f64,
    /// Grain size and density.
    pub grain: GrainSpec,
    /// Friction coefficients (wall = the glued grains of the rough walls).
    pub friction: FrictionSpec,
    /// Normal pressure imposed on the top wall P (Pa).
    pub pressure: f64,
    /// Target inertial numbers `I = γ̇ d / √(P/ρ)`, one run each; the top wall velocity is
    /// `V = I √(P/ρ) H / d` with H the sample height after compression.
    pub inertial_numbers: Vec<f64>,
    /// Shear strain of each run.
    pub strain: f64,
    /// The last `average_strain` of each run is averaged.
    pub average_strain: f64,
    /// Corrections of the wall velocity in the lead of each run (the strain before the
    /// averaged part), so that the bulk reaches its target inertial number although the shear
    /// localises and slips at the walls: the correcting stages share the first half of the lead;
    /// after each, V is multiplied by `√(I_target / I_measured)` with the bulk I measured over
    /// the stage's second half (bounded to [1/2, 2]; none within a factor 1.5 of the target);
    /// the second half of the lead settles the flow at the final V. 0: V stays at its
    /// uniform-shear estimate. Absent from older files: 2.
    #[serde(default = "default_velocity_corrections")]
    pub velocity_corrections: usize,
    /// Decades by which the lead stages of the runs may tighten `solver.tolerance`: after each
    /// lead stage whose samples, solved again to 10⁻⁸, could move the bulk μ by more than 0.005
    /// or its pressure by more than 2.5 % (the verdict's suspect limits of the solver
    /// sensitivity, against the measured change plus two standard errors) and whose solves
    /// took at most a fifth of the sweep cap on average, the tolerance of the following stages
    /// is divided by 10, at most this many times in all (the tightening carries over to the
    /// next runs, whose I is higher). 0: the tolerance stays as given. Absent from older
    /// files: 2.
    #[serde(default = "default_solver_tightenings")]
    pub solver_tightenings: u32,
    /// Largest time step (s).
    pub dt_max: f64,
    /// Largest travel of the top wall per step, as a fraction of the mean radius (sets dt).
    pub travel_per_step: f64,
    /// Mass of the top wall over the grains' mass, in [10⁻³, 10³].
    pub wall_mass_ratio: f64,
    /// Duration of the initial compression at zero shear (s).
    pub compression_time: f64,
    /// Contact solver.
    pub solver: SolverSpec,
    /// Laws not to fit (`grainlaw fit` names), so that a plan short of their data runs
    /// ([`crate::scenarios::common::laws`]: checked at load, said at the start of the run).
    #[serde(default)]
    pub leave_out: Vec<String>,
}

/// Default of [`ShearCellConfig::velocity_corrections`].
pub const DEFAULT_VELOCITY_CORRECTIONS: usize = 2;

fn default_velocity_corrections() -> usize {
    DEFAULT_VELOCITY_CORRECTIONS
}

/// Largest number of wall-velocity corrections a run.
pub const MAX_VELOCITY_CORRECTIONS: usize = 4;

/// Default of [`ShearCellConfig::solver_tightenings`].
pub const DEFAULT_SOLVER_TIGHTENINGS: u32 = 2;

fn default_solver_tightenings() -> u32 {
    DEFAULT_SOLVER_TIGHTENINGS
}

/// Largest [`ShearCellConfig::solver_tightenings`]: the tolerance of a run stays at or above
/// 10⁻⁴ of the one given.
pub const MAX_SOLVER_TIGHTENINGS: u32 = 4;

impl ShearCellConfig {
    /// The laws it fits and the data each needs ([`crate::scenarios::common::laws`]): μ(I), φ(I)
    /// and the wall law (from both walls of each run: 2 points per inertial number).
    pub fn law_needs(&self) -> Vec<LawNeed> {
        let n = self.inertial_numbers.len();
        let mut needs = crate::scenarios::common::laws::rheology(n);
        needs.push(LawNeed {
            law: "wall-law",
            formula: "μ_eff(V) at the walls, best of three forms by AIC",
            key: "inertial_numbers",
            needs: 3,
            have: Some(n),
            why: "3 parameters + 2 points, two per inertial number (both walls)",
            instead_of: None,
        });
        needs
    }

    /// Checks every value (key named in the error), and that no phase takes more than
    /// [`limits::MAX_STEPS`] steps. A run at inertial number `I` shears at `γ̇ = I √(P/ρ) / d`
    /// (d = 2 R̄) with the step `dt = min(dt_max, travel_per_step · R̄ / V)`, `V = γ̇ H`, so it takes
    /// `strain · H / (V dt) = max(strain / (γ̇ dt_max), strain · H / (travel_per_step · R̄))`
    /// steps; the sample height is estimated as `H ≈ N π ⟨R²⟩ / (φ₀ L)` with φ₀ =
    /// [`crate::scenarios::common::build::PACKING_GUESS`] (the settled sample is a little looser,
    /// so a little higher).
    pub fn validate(&self) -> Result<()> {
        limits::grains("grains", self.grains, 20)?;
        check_periodic_cell(
            "cell_length_diameters",
            self.cell_length_diameters,
            &self.grain,
        )?;
        self.friction.validate("friction")?;
        limits::pressure("pressure", self.pressure)?;
        check_inertial_numbers(&self.inertial_numbers, "shear-cell", |k, v| {
            in_range(k, v, 1e-6, 2.0)
        })?;
        check_strain_window(self.strain, self.average_strain)?;
        limits::at_most(
            "velocity_corrections",
            self.velocity_corrections,
            MAX_VELOCITY_CORRECTIONS,
        )?;
        limits::at_most(
            "solver_tightenings",
            self.solver_tightenings as usize,
            MAX_SOLVER_TIGHTENINGS as usize,
        )?;
        if self.velocity_corrections > 0 && self.average_strain >= self.strain {
            return Err(DatasetError::invalid(
                "velocity_corrections",
                format!(
                    "needs a lead before the averaged strain to correct the wall velocity in: \
                     average_strain ({}) must be below strain ({}), or set 0",
                    num(self.average_strain),
                    num(self.strain)
                ),
            ));
        }
        positive("dt_max", self.dt_max)?;
        in_range("travel_per_step", self.travel_per_step, 1e-4, 1.0)?;
        in_range("wall_mass_ratio", self.wall_mass_ratio, 1e-3, 1e3)?;
        positive("compression_time", self.compression_time)?;
        limits::steps(
            "compression_time",
            "compression_time / dt_max",
            self.compression_time,
            self.dt_max,
        )?;
        self.solver.validate("solver")?;
        let r = self.grain.radius_mean;
        let length = self.cell_length_diameters * 2.0 * r;
        let height = self.grains as f64 * std::f64::consts::PI * self.grain.mean_square_radius()
            / (crate::scenarios::common::build::PACKING_GUESS * length);
        let i_min = self
            .inertial_numbers
            .iter()
            .cloned()
            .fold(f64::MAX, f64::min);
        let gamma_dot = i_min * (self.pressure / self.grain.density).sqrt() / (2.0 * r);
        limits::steps(
            "inertial_numbers",
            &format!(
                "strain / (γ̇ dt_max) of the slowest run (I = {i_min:e}, γ̇ = {gamma_dot:.3e} 1/s)"
            ),
            self.strain / gamma_dot,
            self.dt_max,
        )?;
        limits::steps(
            "travel_per_step",
            "strain · H / (travel_per_step · radius_mean)",
            self.strain * height,
            self.travel_per_step * r,
        )?;
        Ok(())
    }
}
