//! Pieces shared by several scenario configurations.

use serde::{Deserialize, Serialize};

use datasets::error::{at_least, in_range, non_negative, num, positive, DatasetError, Result};
use datasets::limits;

/// Polydisperse disk grains: radii uniform in `[radius_mean − radius_spread, radius_mean + radius_spread]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GrainSpec {
    /// Material density ρ (kg/m³); a disk of radius R has mass ρ π R² per metre of thickness.
    pub density: f64,
    /// Mean radius (m).
    pub radius_mean: f64,
    /// Half-width of the uniform radius distribution (m), `0 ≤ spread < mean`.
    pub radius_spread: f64,
}

impl GrainSpec {
    /// Checks `density` within [`limits::DENSITY_RANGE`], `radius_mean` within
    /// [`limits::RADIUS_RANGE`], `0 ≤ radius_spread < radius_mean` and the smallest radius
    /// `radius_mean − radius_spread` at least the range's lower end; `prefix` is the table's key
    /// (`grain`).
    pub fn validate(&self, prefix: &str) -> Result<()> {
        limits::density(&format!("{prefix}.density"), self.density)?;
        limits::radius(&format!("{prefix}.radius_mean"), self.radius_mean)?;
        non_negative(&format!("{prefix}.radius_spread"), self.radius_spread)?;
        if self.radius_spread >= self.radius_mean {
            return Err(DatasetError::invalid(
                format!("{prefix}.radius_spread"),
                format!(
                    "must be below radius_mean ({} m) so that every radius is positive, got {}",
                    num(self.radius_mean),
                    num(self.radius_spread)
                ),
            ));
        }
        if self.radius_min() < limits::RADIUS_RANGE.0 || self.radius_max() > limits::RADIUS_RANGE.1
        {
            return Err(DatasetError::invalid(
                format!("{prefix}.radius_spread"),
                format!(
                    "gives radii in [{:e}, {:e}] m, outside [{:e}, {:e}] m",
                    self.radius_min(),
                    self.radius_max(),
                    limits::RADIUS_RANGE.0,
                    limits::RADIUS_RANGE.1
                ),
            ));
        }
        Ok(())
    }

    /// Smallest radius (m).
    pub fn radius_min(&self) -> f64 {
        self.radius_mean - self.radius_spread
    }

    /// Largest radius (m).
    pub fn radius_max(&self) -> f64 {
        self.radius_mean + self.radius_spread
    }

    /// Mean of R² for the uniform distribution, `R̄² + s²/3` (m²).
    pub fn mean_square_radius(&self) -> f64 {
        self.radius_mean * self.radius_mean + self.radius_spread * self.radius_spread / 3.0
    }
}

/// Largest Coulomb friction coefficient of the scenarios that use [`FrictionSpec`] (`janssen`,
/// `inclined-flow`, `shear-cell`, `stick-slip`, `arrangements`) (1). Measured grain–grain and
/// grain–wall coefficients of dry granular materials lie between about 0.1 and 0.9; above 1 the
/// Janssen fit degenerates (`friction.grain_wall = 1.5` gave K = 4.6·10⁶).
pub const MAX_FRICTION: f64 = 1.0;

/// Coulomb friction coefficients between grains and between grains and walls.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionSpec {
    /// Grain–grain μ (1).
    pub grain_grain: f64,
    /// Grain–wall μ (1).
    pub grain_wall: f64,
}

impl FrictionSpec {
    /// Checks both coefficients are finite, ≥ 0 and at most [`MAX_FRICTION`].
    pub fn validate(&self, prefix: &str) -> Result<()> {
        for (key, mu) in [
            (format!("{prefix}.grain_grain"), self.grain_grain),
            (format!("{prefix}.grain_wall"), self.grain_wall),
        ] {
            non_negative(&key, mu)?;
            if mu > MAX_FRICTION {
                return Err(DatasetError::invalid(
                    &key,
                    format!(
                        "friction coefficient {} is above {MAX_FRICTION}, the range of this \
                         scenario (dry granular materials and walls have μ ≈ 0.1–0.9; beyond 1 a \
                         contact sticks at almost any load and the fitted laws lose their meaning)",
                        num(mu)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Contact laws with materials `grain` (0) and `wall` (1).
    pub fn laws(&self) -> dem::ContactLaws {
        let mut laws = dem::ContactLaws::new(&["grain", "wall"], self.grain_grain);
        laws.set_friction(0, 1, self.grain_wall);
        laws.set_friction(1, 1, self.grain_wall);
        laws
    }
}

/// Contact solver settings of one phase.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// Tolerance on the natural-map error measure (1), > 0.
    pub tolerance: f64,
    /// Largest number of Gauss–Seidel sweeps per step, ≥ 1.
    pub max_iterations: usize,
    /// Solve on all threads ([`dem::SolverParams::parallel`]); the numbers do not depend on the
    /// thread count. Default false.
    #[serde(default)]
    pub parallel: bool,
    /// The algorithm: `"nlgs"`, `"newton"`, `"auto"` (default) or `"lemke"`
    /// ([`dem::fc::SolverMethod`]).
    #[serde(default)]
    pub method: dem::fc::SolverMethod,
    /// Largest step (contacts) that `auto` ends with Lemke's method when the other stages did
    /// not converge ([`dem::SolverParams::lemke_max_contacts`], default 0: off).
    #[serde(default = "dem::solver::lemke_max_contacts")]
    pub lemke_max_contacts: usize,
    /// Largest number of halvings of a step whose solve does not converge (the step is undone
    /// and done again in up to `2^max_halvings` sub-steps, [`dem::SolverParams::max_halvings`]),
    /// in 0..=10. Default [`DEFAULT_MAX_HALVINGS`].
    #[serde(default = "default_max_halvings")]
    pub max_halvings: u32,
    /// When the error is evaluated ([`dem::SolverParams::check_every`]): 0 (default) after each
    /// of a solve's first twenty sweeps, then sparser; `N` in 1..=1000, where the sweeps'
    /// measured change predicts convergence and at least every `N` sweeps (natural order).
    #[serde(default)]
    pub check_every: usize,
    /// With `method = "nlgs"`, the sweep cap at the largest subdivision in multiples of
    /// `max_iterations` ([`dem::SolverParams::last_level_sweeps`]), in 1..=1000. Default 1.
    #[serde(default = "one")]
    pub last_level_sweeps: usize,
    /// The scale the tolerance applies to: `"problem"` (default) or `"loaded"`, the loaded
    /// contacts' scale too ([`dem::solver::ErrorScale`]).
    #[serde(default)]
    pub error_scale: dem::solver::ErrorScale,
    /// Largest overlap growth per step of a converged solve, as a fraction of the smallest
    /// radius ([`dem::WorldParams::overlap_rate`]: no closed or loaded contact may approach
    /// faster than `overlap_rate · R_min / h`), ≥ 0 (0: no such condition). Default 10⁻⁴.
    #[serde(default = "default_overlap_rate")]
    pub overlap_rate: f64,
    /// Relaxation factor ω of the Gauss–Seidel update, `r ← proj_K(r + ω (r_local − r))`
    /// ([`dem::SolverParams::relaxation`]), in (0, 2). Default 1 (plain Gauss–Seidel).
    #[serde(default = "unit_relaxation")]
    pub relaxation: f64,
    /// Memory of the Anderson acceleration of the sweeps ([`dem::SolverParams::anderson_memory`];
    /// Walker & Ni, SIAM J. Numer. Anal. 49 (2011) 1715–1735), in 0..=50 (0: plain sweeps).
    /// Default: the engine's.
    #[serde(default = "default_anderson_memory")]
    pub anderson_memory: usize,
}

fn one() -> usize {
    1
}

fn unit_relaxation() -> f64 {
    1.0
}

fn default_anderson_memory() -> usize {
    dem::SolverParams::default().anderson_memory
}

/// Default of [`SolverSpec::overlap_rate`]: the engine's.
pub fn default_overlap_rate() -> f64 {
    dem::WorldParams::default().overlap_rate
}

/// Default of [`SolverSpec::max_halvings`]: up to 8 sub-steps.
pub const DEFAULT_MAX_HALVINGS: u32 = 3;

fn default_max_halvings() -> u32 {
    DEFAULT_MAX_HALVINGS
}

impl SolverSpec {
    /// Checks `0 < tolerance < 1`, `max_iterations ≥ 1`, `max_halvings ≤ 10`,
    /// `check_every ≤ 1000`, `1 ≤ last_level_sweeps ≤ 1000`, `0 < relaxation < 2` and
    /// `anderson_memory ≤ 50`.
    pub fn validate(&self, prefix: &str) -> Result<()> {
        in_range(
            &format!("{prefix}.tolerance"),
            self.tolerance,
            f64::MIN_POSITIVE,
            1.0,
        )?;
        at_least(&format!("{prefix}.max_iterations"), self.max_iterations, 1)?;
        limits::at_most(
            &format!("{prefix}.max_halvings"),
            self.max_halvings as usize,
            10,
        )?;
        limits::at_most(&format!("{prefix}.check_every"), self.check_every, 1000)?;
        at_least(
            &format!("{prefix}.last_level_sweeps"),
            self.last_level_sweeps,
            1,
        )?;
        limits::at_most(
            &format!("{prefix}.last_level_sweeps"),
            self.last_level_sweeps,
            1000,
        )?;
        in_range(
            &format!("{prefix}.overlap_rate"),
            self.overlap_rate,
            0.0,
            1.0,
        )?;
        if !(self.relaxation > 0.0 && self.relaxation < 2.0) {
            return Err(datasets::DatasetError::invalid(
                format!("{prefix}.relaxation"),
                format!("{} is outside (0, 2)", self.relaxation),
            ));
        }
        limits::at_most(
            &format!("{prefix}.anderson_memory"),
            self.anderson_memory,
            50,
        )?;
        Ok(())
    }

    /// Sets the engine's solver parameters ([`SolverSpec::params`]) and overlap rate in `p`.
    pub fn apply(&self, p: &mut dem::WorldParams) {
        p.solver = self.params();
        p.overlap_rate = self.overlap_rate;
    }

    /// Engine parameters with this tolerance and sweep cap.
    pub fn params(&self) -> dem::SolverParams {
        dem::SolverParams {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            parallel: self.parallel,
            method: self.method,
            lemke_max_contacts: self.lemke_max_contacts,
            max_halvings: self.max_halvings,
            check_every: self.check_every,
            last_level_sweeps: self.last_level_sweeps,
            error_scale: self.error_scale,
            relaxation: self.relaxation,
            anderson_memory: self.anderson_memory,
            ..Default::default()
        }
    }
}

/// A periodic cell `cell_length_diameters · 2 R̄` long must hold three cells of the engine's
/// contact-detection grid, `L ≥ 3 (1.5 d_max + g)`: a grid cell is the largest diameter
/// `d_max = 2 R_max` plus the detection gap `g = R_min / 10` plus twice the swept margin (the
/// distance a grain moves in one step), here allowed up to a quarter of `d_max`. Also checks
/// `grain` and that the length lies in [4, 10⁴] mean diameters. `key` names the length in the
/// error.
pub fn check_periodic_cell(key: &str, cell_length_diameters: f64, grain: &GrainSpec) -> Result<()> {
    in_range(key, cell_length_diameters, 4.0, 1e4)?;
    grain.validate("grain")?;
    let length = cell_length_diameters * 2.0 * grain.radius_mean;
    let needed = 3.0 * (1.5 * 2.0 * grain.radius_max() + 0.1 * grain.radius_min());
    if length < needed {
        return Err(DatasetError::invalid(
            key,
            format!(
                "{} gives a periodic cell {length:.3e} m long, shorter than the {needed:.3e} m \
                 (3 contact-detection cells of 1.5 largest diameters and a detection gap) the \
                 engine needs",
                num(cell_length_diameters)
            ),
        ));
    }
    Ok(())
}

/// Largest fall under gravity in one step from rest, `g h²`, as a fraction of the smallest
/// radius (see [`check_dt_gravity`]).
pub const MAX_FALL_PER_STEP: f64 = 0.25;

/// A time step under gravity must let a grain at rest fall by at most [`MAX_FALL_PER_STEP`] of
/// the smallest radius in one step, `g h² ≤ 0.25 R_min` (`g` = 9.81 m/s²): beyond it contacts
/// are crossed rather than resolved, detection margins grow with the step and the deposit
/// overlaps (`janssen` with `dt = 0.1` reached 42 % of R_min). `key` names the step in the
/// error.
pub fn check_dt_gravity(key: &str, dt: f64, r_min: f64) -> Result<()> {
    let g = 9.81;
    let fall = g * dt * dt;
    if fall > MAX_FALL_PER_STEP * r_min {
        return Err(DatasetError::invalid(
            key,
            format!(
                "time step {} s lets a grain fall {fall:.3e} m in one step under gravity, more \
                 than a quarter of the smallest radius ({r_min:.3e} m); use at most {:.3e} s",
                num(dt),
                (MAX_FALL_PER_STEP * r_min / g).sqrt()
            ),
        ));
    }
    Ok(())
}

/// `dt` must be positive and finite and at most `max` (s).
pub fn check_dt(key: &str, dt: f64, max: f64) -> Result<f64> {
    positive(key, dt)?;
    if dt > max {
        return Err(DatasetError::invalid(
            key,
            format!("time step {} s is larger than {} s", num(dt), num(max)),
        ));
    }
    Ok(dt)
}

/// An averaging window `key` over the end of a run: positive and finite, and at most the
/// run's length `total` (named `total_key` in the error, with its `unit`, e.g. `" s"` or
/// `""`).
pub fn check_average(
    key: &str,
    window: f64,
    total_key: &str,
    total: f64,
    unit: &str,
) -> Result<()> {
    positive(key, window)?;
    if window > total {
        return Err(DatasetError::invalid(
            key,
            format!(
                "must not exceed {total_key} ({}{unit}), got {}",
                num(total),
                num(window)
            ),
        ));
    }
    Ok(())
}

/// The shear strain of a shear run, `strain` > 0, and its averaged end `average_strain` > 0 and
/// at most `strain` ([`check_average`]).
pub fn check_strain_window(strain: f64, average_strain: f64) -> Result<()> {
    positive("strain", strain)?;
    check_average("average_strain", average_strain, "strain", strain, "")
}

/// The target inertial numbers `inertial_numbers` of a shear scenario named `scenario`: at
/// least one (the error points at `grainlaw scenarios --show SCENARIO`), at most 100, and each
/// accepted by `each` (given its key `inertial_numbers[i]` and value).
pub fn check_inertial_numbers(
    inertial_numbers: &[f64],
    scenario: &str,
    each: impl Fn(&str, f64) -> Result<f64>,
) -> Result<()> {
    if inertial_numbers.is_empty() {
        return Err(DatasetError::invalid(
            "inertial_numbers",
            format!("is empty: give at least one inertial number (what each law needs: `grainlaw scenarios --show {scenario}`)"),
        ));
    }
    limits::at_most("inertial_numbers", inertial_numbers.len(), 100)?;
    for (i, &v) in inertial_numbers.iter().enumerate() {
        each(&format!("inertial_numbers[{i}]"), v)?;
    }
    Ok(())
}

/// How the cell's stress-controlled components follow their targets (`dem::cell::CellControl`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CellControlMode {
    /// Unknowns of each step's contact problem (`dem::cell_coupling`): a jammed frictional
    /// packing finds the deformation it can follow within the step.
    #[default]
    Implicit,
    /// The explicit proportional law between steps, with re-solves of a step whose stress
    /// misses the target (the law before the implicit one; its frictional steps are mostly
    /// infeasible, `docs/physics.md` §8).
    Explicit,
}

impl CellControlMode {
    /// `implicit` or `explicit`.
    pub fn as_str(self) -> &'static str {
        match self {
            CellControlMode::Implicit => "implicit",
            CellControlMode::Explicit => "explicit",
        }
    }
}
