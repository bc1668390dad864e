//! The `simple-shear` scenario: a biperiodic deformable cell (no walls, no gravity), compressed
//! isotropically to a pressure, then sheared Lees–Edwards style at imposed shear rate and normal
//! stress σ_yy = −P for each inertial number; μ(I) and φ(I) are fitted.

use serde::{Deserialize, Serialize};

use datasets::error::{in_range, non_negative, num, positive, DatasetError, Result};
use datasets::limits;

use crate::scenarios::common::config::{
    check_inertial_numbers, check_strain_window, CellControlMode, GrainSpec, SolverSpec,
};
use crate::scenarios::common::laws::LawNeed;

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
    /// Normal restitution coefficient `e` between grains (Newton's law on impacts,
    /// `u_n⁺ ≥ −e u_n⁻`), in [0, 0.99]; default 0, the contact-dynamics choice (impacts
    /// perfectly inelastic). Set it to compare with a soft-contact code run at the same `e`
    /// (`grainlaw bench --rve … --rve-restitution E --rve-set restitution=E`).
    #[serde(default)]
    pub restitution: f64,
    /// θ of the Moreau–Jean step, `q⁺ = q⁻ + h((1 − θ) v⁻ + θ v⁺)` with the gap-closing shift
    /// `g/(hθ)` (Jean 1999), in [0.5, 1]; default ½ (since 2026-12-07; 1 before). At ½ the
    /// positions are second-order in the step: on the 2000-grain cell at I = 0.01 φ comes out
    /// 0.809–0.810 at every travel a step from 0.005 to 0.02, where θ = 1 gives 0.800–0.805
    /// and a soft-contact code at the rigid limit 0.810; μ is the same at both θ. The default
    /// 200-grain run at ½: φ 0.004–0.006 higher at all five I, μ within its errors, no step
    /// gaining energy, verdicts ok over three seeds (`docs/solver.md`).
    #[serde(default = "default_theta")]
    pub theta: f64,
    /// Confining pressure P (Pa), > 0: σ_xx = σ_yy = −P in the compression, σ_yy = −P in shear.
    pub pressure: f64,
    /// Target inertial numbers `I = γ̇ d / √(P/ρ)`, one shear run each (lowest first).
    pub inertial_numbers: Vec<f64>,
    /// Shear strain of each run (1).
    pub strain: f64,
    /// The last `average_strain` of each run is averaged (1).
    pub average_strain: f64,
    /// An absolute cap of the time step (s), if any (default none): the steps follow the
    /// grains' own scales ([`SimpleShearConfig::shear_dt`], [`SimpleShearConfig::compression_dt`]),
    /// so that a consistent change of units gives the same run.
    #[serde(default)]
    pub dt_max: Option<f64>,
    /// Largest relative travel of neighbouring grains per step, `γ̇ d Δt / R̄` (1), sets Δt.
    pub travel_per_step: f64,
    /// Cap of the cell's strain rate under stress control, as an inertial number
    /// `I_cell = ε̇_max d / √(P/ρ)` (1), in (0, 0.1].
    pub control_inertial_number: f64,
    /// `implicit` (default) or `explicit` control of the cell ([`CellControlMode`]).
    #[serde(default)]
    pub cell_control: CellControlMode,
    /// Under the implicit control, the grains follow the cell's change within each step
    /// (`dem::CellControl::affine`: every contact sees the uniform deformation, no boundary wave
    /// for Gauss–Seidel to carry in) instead of at its end. Default `true` (since 2026-12-06;
    /// `false` before): at 2000 grains it stops the cell's ringing (σ_yy from ±66 % to ±0.1 % of
    /// its target from step to step) and cuts the overlaps 18-fold; at the end of the step, the
    /// default 200-grain cell ran away at I = 0.25 with a travel of 0.01 a step (one seed of
    /// three, another suspect for a step's energy growth; `docs/solver.md`). Above 1800
    /// contacts the global methods do not run on its dense cell term.
    #[serde(default = "default_cell_affine")]
    pub cell_affine: bool,
    /// Duration of the isotropic compression in units of the grains' time `t_g = d √(ρ/P)`
    /// (1; 32 t_g is 0.15 s for the default 3 mm grains at 1 kPa): the cell's strain-rate cap
    /// allows `control_inertial_number` of strain per `t_g`.
    pub compression_duration: f64,
    /// Solid fraction of the initial loose packing (1), in [0.2, 0.6].
    pub initial_solid_fraction: f64,
    /// Contact solver.
    pub solver: SolverSpec,
    /// Laws not to fit (`grainlaw fit` names), so that a plan short of their data runs
    /// ([`crate::scenarios::common::laws`]: checked at load, said at the start of the run).
    #[serde(default)]
    pub leave_out: Vec<String>,
    /// Largest number of time steps of the whole plan ([`SimpleShearConfig::planned_steps`]),
    /// default [`DEFAULT_MAX_PLAN_STEPS`]: a plan beyond it is refused at load with the numbers
    /// that make it so, unless this key raises the bound (asked for explicitly).
    #[serde(default = "default_max_plan_steps")]
    pub max_steps: f64,
    /// Window steps of each run solved again to measure the solver's effect on μ and σ_yy
    /// (evenly spread; default [`DEFAULT_SENSITIVITY_SAMPLES`]), in [1, 1000]. The mean effect is
    /// resolved to about `σ/√n` with σ the run's own per-step deviation (3.5–4.5·10⁻³ in μ on
    /// the 2000-grain cell at I = 0.01 with 300 sweeps a step, `docs/solver.md`): 60 or more
    /// give a clean verdict there where 20 leave it on its edge. With two threads the re-solves
    /// run beside the run.
    #[serde(default = "default_sensitivity_samples")]
    pub sensitivity_samples: u64,
}

/// Default of [`SimpleShearConfig::sensitivity_samples`].
pub const DEFAULT_SENSITIVITY_SAMPLES: u64 = 20;

fn default_sensitivity_samples() -> u64 {
    DEFAULT_SENSITIVITY_SAMPLES
}

/// The steps that cover a phase of `ratio` time steps: `⌈ratio⌉`, a ratio within 10⁻⁹ of an
/// integer taken as that integer (rounding in `t / Δt` must not add a step: a consistent change
/// of units gives the same count).
pub fn whole_steps(ratio: f64) -> u64 {
    let r = ratio.round();
    if (ratio - r).abs() <= 1e-9 * r.max(1.0) {
        r as u64
    } else {
        ratio.ceil() as u64
    }
}

/// Default of [`SimpleShearConfig::max_steps`]: 10⁶ steps (about an hour at a few ms a step).
pub const DEFAULT_MAX_PLAN_STEPS: f64 = 1e6;

fn default_theta() -> f64 {
    0.5
}

fn default_cell_affine() -> bool {
    true
}

fn default_max_plan_steps() -> f64 {
    DEFAULT_MAX_PLAN_STEPS
}

impl SimpleShearConfig {
    /// The grains' time `t_g = d̄ √(ρ/P)` (s), `d̄ = 2 R̄`: the time a grain takes to move by its
    /// diameter under the confining pressure; `I = γ̇ t_g`.
    pub fn grain_time(&self) -> f64 {
        2.0 * self.grain.radius_mean * (self.grain.density / self.pressure).sqrt()
    }

    /// Shear rate `γ̇ = I / t_g` (1/s) of target inertial number `i` ([`Self::grain_time`];
    /// the run's own `d` is the packing's mean diameter, within the spread of `2 R̄`).
    pub fn shear_rate(&self, i: f64) -> f64 {
        i / self.grain_time()
    }

    /// Time step of the shear run at shear rate `gamma_dot` (1/s) with mean diameter `d` (m):
    /// neighbours a diameter apart travel `travel_per_step · R̄` relative to each other per
    /// step, `Δt = travel_per_step · R̄ / (γ̇ d)`, capped by `dt_max` if given. A strain of
    /// `travel_per_step R̄ / d` per step: 0.005 at the default 0.01.
    pub fn shear_dt(&self, gamma_dot: f64, d: f64) -> f64 {
        let dt = self.travel_per_step * self.grain.radius_mean / (gamma_dot * d);
        self.dt_max.map_or(dt, |m| dt.min(m))
    }

    /// Time step of the isotropic compression with mean diameter `d` (m): the travel rule at
    /// the cell's strain-rate cap `ε̇_max = control_inertial_number · √(P/ρ) / d`
    /// ([`Self::shear_dt`] with `γ̇ = ε̇_max`), capped by `dt_max` if given.
    pub fn compression_dt(&self, d: f64) -> f64 {
        let rate = self.control_inertial_number * (self.pressure / self.grain.density).sqrt() / d;
        self.shear_dt(rate, d)
    }

    /// Steps of the isotropic compression (`compression_duration · t_g / Δt`) with mean
    /// diameter `d` (m).
    pub fn compression_steps(&self, d: f64) -> u64 {
        whole_steps(self.compression_duration * self.grain_time() / self.compression_dt(d))
    }

    /// Steps of the shear run at target inertial number `i` with mean diameter `d` (m):
    /// `strain / (γ̇ Δt)`.
    pub fn shear_steps(&self, i: f64, d: f64) -> u64 {
        let g = i * (self.pressure / self.grain.density).sqrt() / d;
        whole_steps(self.strain / (g * self.shear_dt(g, d)))
    }

    /// Steps of the whole plan, the compression and every shear run, at the nominal mean
    /// diameter `2 R̄`: `(compression, [run per inertial number])`.
    pub fn planned_steps(&self) -> (u64, Vec<u64>) {
        let d = 2.0 * self.grain.radius_mean;
        (
            self.compression_steps(d),
            self.inertial_numbers
                .iter()
                .map(|&i| self.shear_steps(i, d))
                .collect(),
        )
    }

    /// The laws it fits and the data each needs ([`crate::scenarios::common::laws`]).
    pub fn law_needs(&self) -> Vec<LawNeed> {
        crate::scenarios::common::laws::rheology(self.inertial_numbers.len())
    }

    /// Checks every value (key named in the error) and that no phase exceeds
    /// [`limits::MAX_STEPS`] steps.
    pub fn validate(&self) -> Result<()> {
        limits::grains("grains", self.grains, 50)?;
        self.grain.validate("grain")?;
        non_negative("friction.grain_grain", self.friction.grain_grain)?;
        in_range("restitution", self.restitution, 0.0, 0.99)?;
        in_range("theta", self.theta, 0.5, 1.0)?;
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
        check_inertial_numbers(&self.inertial_numbers, "simple-shear", |k, v| {
            if !(v.is_finite() && v > 0.0) {
                return Err(DatasetError::invalid(
                    k,
                    format!("must be > 0, got {}", num(v)),
                ));
            }
            in_range(k, v, 1e-5, 1.0)
        })?;
        check_strain_window(self.strain, self.average_strain)?;
        in_range("travel_per_step", self.travel_per_step, 1e-4, 0.5)?;
        if !(1..=1000).contains(&self.sensitivity_samples) {
            return Err(DatasetError::invalid(
                "sensitivity_samples",
                format!("must be in [1, 1000], got {}", self.sensitivity_samples),
            ));
        }
        if let Some(dt) = self.dt_max {
            positive("dt_max", dt)?;
        }
        in_range(
            "control_inertial_number",
            self.control_inertial_number,
            1e-6,
            0.1,
        )?;
        positive("compression_duration", self.compression_duration)?;
        in_range(
            "initial_solid_fraction",
            self.initial_solid_fraction,
            0.2,
            0.6,
        )?;
        self.solver.validate("solver")?;
        in_range("max_steps", self.max_steps, 1.0, limits::MAX_STEPS * 100.0)?;
        let (compression, runs) = self.planned_steps();
        let total = compression as f64 + runs.iter().map(|&n| n as f64).sum::<f64>();
        // total is finite: max_steps is in range and the counts are integers
        if total > self.max_steps {
            let slowest = runs
                .iter()
                .zip(&self.inertial_numbers)
                .max_by_key(|(n, _)| **n)
                .map(|(n, i)| format!("{n} at I = {i:e}"))
                .unwrap_or_default();
            return Err(DatasetError::invalid(
                "max_steps",
                format!(
                    "the plan takes {total:.3e} time steps (compression {compression}, the slowest run {slowest}: strain {} at a time step of {:.3e} s{}), more than {}: shorten the plan, raise travel_per_step, or set max_steps to ask for it",
                    num(self.strain),
                    self.shear_dt(
                        self.shear_rate(
                            self.inertial_numbers
                                .iter()
                                .cloned()
                                .fold(f64::MAX, f64::min)
                        ),
                        2.0 * self.grain.radius_mean
                    ),
                    if self.dt_max.is_some() { ", capped by dt_max" } else { "" },
                    num(self.max_steps)
                ),
            ));
        }
        for (n, &i) in runs.iter().zip(&self.inertial_numbers) {
            limits::steps(
                "inertial_numbers",
                &format!("the run at I = {i:e}"),
                *n as f64,
                1.0,
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::SimpleShearConfig;
    use datasets::overrides::{apply_override, parse_override};
    use datasets::Result;

    use crate::scenarios::loader::{parse_table, typed, ScenarioConfig};

    /// The built-in TOML with `sets` applied, typed and validated (what the loader does).
    fn load(sets: &[String]) -> Result<SimpleShearConfig> {
        let source = "builtin:simple-shear";
        let mut table = parse_table(
            include_str!("../../../../datasets/scenarios/simple-shear.toml"),
            source,
        )?;
        for s in sets {
            apply_override(&mut table, &parse_override(s)?, source)?;
        }
        let c: SimpleShearConfig = typed(table, source)?;
        c.check()?;
        Ok(c)
    }

    fn config(sets: &[&str]) -> SimpleShearConfig {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        load(&sets).expect("loads")
    }

    /// Grains given in metres where millimetres were meant (radius 1.5 m): the grains' time
    /// `d √(ρ/P)` grows 1000-fold and so do the time steps, so the plan takes exactly as many
    /// steps as the default 3 mm grains' (it took 713 771 steps and 3 min 50 s when the time
    /// step was an absolute `dt_max`). Analytic: `t_g = 2 R̄ √(ρ/P)` = 4.743 ms at the defaults.
    #[test]
    fn a_consistent_change_of_units_gives_the_same_plan() {
        let mm = config(&[]);
        let m = config(&["grain.radius_mean=1.5", "grain.radius_spread=0.3"]);
        let tg = 3e-3 * (2500.0f64 / 1000.0).sqrt();
        assert!((mm.grain_time() - tg).abs() < 1e-12 * tg);
        assert!((m.grain_time() / mm.grain_time() - 1000.0).abs() < 1e-9);
        assert_eq!(mm.planned_steps(), m.planned_steps());
        // travel rule: a strain of travel_per_step · R̄ / d = 0.005 per step, 600 steps for 3
        let (compression, runs) = mm.planned_steps();
        assert!(runs.iter().all(|&n| n == 600), "{runs:?}");
        // compression: 32 t_g at Δt = travel · R̄ / (I_c √(P/ρ)) = t_g / 4
        assert_eq!(compression, 128);
    }

    /// A plan beyond `max_steps` (10⁶ by default) is refused at load, naming the key and the
    /// numbers; raising `max_steps` asks for it explicitly.
    #[test]
    fn a_plan_beyond_its_step_bound_is_refused_unless_asked_for() {
        let sets: Vec<String> = ["travel_per_step=1e-4", "strain=20", "average_strain=1"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let e = load(&sets).unwrap_err().to_string();
        assert!(e.contains("max_steps") && e.contains("time steps"), "{e}");
        let mut more = sets.clone();
        more.push("max_steps=1e8".into());
        assert!(load(&more).is_ok());
    }

    /// `restitution`: 0 by default (no engine pair gets one), a set value reaches the world's
    /// grain–grain law, and values outside [0, 0.99] are refused with the key named.
    #[test]
    fn the_restitution_key_reaches_the_world() {
        let c = config(&["grains=50"]);
        assert_eq!(c.restitution, 0.0);
        let w = crate::scenarios::simple_shear::build::simple_shear(&c).unwrap();
        assert_eq!(w.laws.restitution(0, 0), 0.0);
        let c = config(&["grains=50", "restitution=0.2"]);
        let w = crate::scenarios::simple_shear::build::simple_shear(&c).unwrap();
        assert_eq!(w.laws.restitution(0, 0), 0.2);
        for bad in ["restitution=-0.1", "restitution=1.0"] {
            let e = load(&[bad.to_string()]).unwrap_err().to_string();
            assert!(e.contains("restitution"), "{e}");
        }
    }

    /// `theta`: ½ by default, a set value reaches the world's Moreau–Jean step, and values
    /// outside [0.5, 1] are refused with the key named.
    #[test]
    fn the_theta_key_reaches_the_world() {
        let c = config(&["grains=50"]);
        assert_eq!(c.theta, 0.5);
        let theta = |c: &SimpleShearConfig| {
            crate::scenarios::simple_shear::build::simple_shear(c)
                .unwrap()
                .params
                .theta
        };
        assert_eq!(theta(&c), 0.5);
        assert_eq!(theta(&config(&["grains=50", "theta=1"])), 1.0);
        for bad in ["theta=0.45", "theta=1.01"] {
            let e = load(&[bad.to_string()]).unwrap_err().to_string();
            assert!(e.contains("theta"), "{e}");
        }
    }
}
