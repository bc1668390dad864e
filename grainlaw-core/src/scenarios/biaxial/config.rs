//! The `biaxial` scenario: a biperiodic deformable cell (no walls, no gravity), compressed
//! isotropically to each confining pressure p₀, then compressed along y at a constant strain
//! rate with the lateral stress σ_xx = −p₀ held: peak and critical-state friction, dilatancy.

use serde::{Deserialize, Serialize};

use datasets::error::{in_range, num, positive, DatasetError, Result};
use datasets::limits;

use crate::scenarios::common::config::{CellControlMode, GrainSpec, SolverSpec};
use crate::scenarios::common::laws::LawNeed;
use crate::scenarios::simple_shear::config::CellFriction;

/// How the sample is prepared: the grain–grain friction during the isotropic compression.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Preparation {
    /// Friction switched to 0 during the isotropic compression (the densest packing the
    /// grains reach under isotropic stress), restored for the axial compression.
    Dense,
    /// Friction kept during the isotropic compression (a looser packing).
    Loose,
}

impl Preparation {
    /// `dense` or `loose`.
    pub fn as_str(self) -> &'static str {
        match self {
            Preparation::Dense => "dense",
            Preparation::Loose => "loose",
        }
    }
}

/// Configuration of the `biaxial` scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BiaxialConfig {
    /// Always `"biaxial"`.
    pub scenario: String,
    /// Seed of the radii and the initial placement (the same packing for every pressure).
    pub seed: u64,
    /// Number of grains (≥ 50).
    pub grains: usize,
    /// Grain size and density.
    pub grain: GrainSpec,
    /// Friction coefficient between grains (during the axial compression; see `preparation`).
    pub friction: CellFriction,
    /// Confining pressures p₀ (Pa), one sample each: σ_xx = σ_yy = −p₀ in the isotropic
    /// compression, σ_xx = −p₀ in the axial compression.
    pub confining_pressures: Vec<f64>,
    /// `dense` (friction 0 during the isotropic compression) or `loose` (friction kept).
    pub preparation: Preparation,
    /// Inertial number of the axial compression `I = ε̇_a d / √(p₀/ρ)` (1): sets the axial
    /// strain rate of each pressure, in (0, 0.01].
    pub inertial_number: f64,
    /// Axial strain reached (1), in (0, 1].
    pub max_axial_strain: f64,
    /// The last `critical_strain` of axial strain is the critical-state plateau (1).
    pub critical_strain: f64,
    /// Width of the axial-strain bins of the peak, dilatancy and stress–dilatancy analysis (1).
    pub bin_strain: f64,
    /// Relative travel of neighbours a diameter apart per step over the mean radius (1), the
    /// step-length rule of the axial compression: `Δt = travel_per_step · R̄ / (ε̇_a d)` with
    /// `d = 2 R̄`, an axial strain of `travel_per_step / 2` per step at every pressure.
    /// In [10⁻⁵, 0.1].
    #[serde(default = "default_travel_per_step")]
    pub travel_per_step: f64,
    /// Largest time step (s), if given: caps the travel rule's step.
    #[serde(default)]
    pub dt_max: Option<f64>,
    /// θ of the Moreau–Jean position update `q⁺ = q⁻ + h((1 − θ) v⁻ + θ v⁺)`, in [½, 1].
    #[serde(default = "default_theta")]
    pub theta: f64,
    /// Cap of the cell's strain rate under stress control, as an inertial number
    /// `I_cell = ε̇_max d / √(p₀/ρ)` (1), in (0, 0.1].
    pub control_inertial_number: f64,
    /// `implicit` (default) or `explicit` control of the cell ([`CellControlMode`]).
    #[serde(default)]
    pub cell_control: CellControlMode,
    /// Duration of the isotropic compression (s).
    pub compression_time: f64,
    /// Steps of the isotropic compression (its time step `compression_time / compression_steps`,
    /// capped by `dt_max` if given: the compression only has to reach its target state).
    #[serde(default = "default_compression_steps")]
    pub compression_steps: u64,
    /// Solid fraction of the initial loose packing (1), in [0.2, 0.6].
    pub initial_solid_fraction: f64,
    /// Contact solver.
    pub solver: SolverSpec,
    /// Laws not to fit (`grainlaw fit` names), so that a plan short of their data runs
    /// ([`crate::scenarios::common::laws`]: checked at load, said at the start of the run).
    #[serde(default)]
    pub leave_out: Vec<String>,
}

/// The default [`BiaxialConfig::travel_per_step`]: an axial strain of 5·10⁻⁵ a step.
fn default_travel_per_step() -> f64 {
    1e-4
}

/// The default [`BiaxialConfig::compression_steps`]: 600 (steps of 0.25 ms at the default
/// `compression_time`).
fn default_compression_steps() -> u64 {
    600
}

/// The default [`BiaxialConfig::theta`]: 1, the Moreau–Jean step that only dissipates.
fn default_theta() -> f64 {
    1.0
}

impl BiaxialConfig {
    /// The laws it fits and the data each needs ([`crate::scenarios::common::laws`]).
    pub fn law_needs(&self) -> Vec<LawNeed> {
        let n = self.confining_pressures.len();
        vec![
            LawNeed {
                law: "mohr-coulomb",
                formula: "q = p sin φ + c cos φ over the peaks",
                key: "confining_pressures",
                needs: 3,
                have: Some(n),
                why: "the envelope through the origin, 1 parameter + 2; a free cohesion from 4",
                instead_of: None,
            },
            LawNeed {
                law: "critical-state",
                formula: "sin φ_c and φ_c, plateau means over the pressures",
                key: "confining_pressures",
                needs: 2,
                have: Some(n),
                why:
                    "its intervals come from the scatter between samples, the pressures as replicas",
                instead_of: None,
            },
            LawNeed {
                law: "stress-dilatancy",
                formula: "sin φ = sin φ_cv + β sin ψ over the hardening phases",
                key: "",
                needs: 4,
                have: None,
                why: "dilatancy windows before the peaks",
                instead_of: None,
            },
        ]
    }

    /// Checks every value (key named in the error) and that no phase exceeds
    /// [`limits::MAX_STEPS`] steps.
    pub fn validate(&self) -> Result<()> {
        limits::grains("grains", self.grains, 50)?;
        self.grain.validate("grain")?;
        in_range("friction.grain_grain", self.friction.grain_grain, 0.0, 1.0)?;
        if self.confining_pressures.is_empty() {
            return Err(DatasetError::invalid(
                "confining_pressures",
                "is empty: give at least one confining pressure in Pa (3 or more to fit Mohr–Coulomb)",
            ));
        }
        limits::at_most("confining_pressures", self.confining_pressures.len(), 20)?;
        for (i, &p) in self.confining_pressures.iter().enumerate() {
            let key = format!("confining_pressures[{i}]");
            if !(p.is_finite() && p > 0.0) {
                return Err(DatasetError::invalid(
                    key,
                    format!(
                        "must be a positive pressure in Pa (compression), got {}",
                        num(p)
                    ),
                ));
            }
            limits::pressure(&key, p)?;
        }
        in_range("inertial_number", self.inertial_number, 1e-6, 1e-2)?;
        in_range("max_axial_strain", self.max_axial_strain, 1e-3, 1.0)?;
        positive("critical_strain", self.critical_strain)?;
        if self.critical_strain >= self.max_axial_strain {
            return Err(DatasetError::invalid(
                "critical_strain",
                format!(
                    "must be below max_axial_strain ({}), got {}",
                    num(self.max_axial_strain),
                    num(self.critical_strain)
                ),
            ));
        }
        positive("bin_strain", self.bin_strain)?;
        if self.bin_strain * 4.0 > self.max_axial_strain {
            return Err(DatasetError::invalid(
                "bin_strain",
                format!(
                    "must be at most a quarter of max_axial_strain ({}), got {}",
                    num(self.max_axial_strain),
                    num(self.bin_strain)
                ),
            ));
        }
        in_range("travel_per_step", self.travel_per_step, 1e-5, 0.1)?;
        if let Some(dt) = self.dt_max {
            positive("dt_max", dt)?;
        }
        in_range("theta", self.theta, 0.5, 1.0)?;
        if self.compression_steps == 0 {
            return Err(DatasetError::invalid(
                "compression_steps",
                "must be at least 1",
            ));
        }
        // the isotropic compression: the cap of the cell's strain rate under stress control,
        // its duration in at most limits-many steps, the loose packing, the solver table
        in_range(
            "control_inertial_number",
            self.control_inertial_number,
            1e-6,
            0.1,
        )?;
        positive("compression_time", self.compression_time)?;
        in_range(
            "initial_solid_fraction",
            self.initial_solid_fraction,
            0.2,
            0.6,
        )?;
        self.solver.validate("solver")?;
        limits::steps(
            "compression_time",
            "compression_time / Δt (the step of the isotropic compression)",
            self.compression_time,
            self.compression_dt(),
        )?;
        let d = 2.0 * self.grain.radius_mean;
        let p_min = self
            .confining_pressures
            .iter()
            .cloned()
            .fold(f64::MAX, f64::min);
        let rate = self.inertial_number * (p_min / self.grain.density).sqrt() / d;
        limits::steps(
            "inertial_number",
            &format!("max_axial_strain / (ε̇_a Δt) at the lowest pressure ({p_min:e} Pa)"),
            self.max_axial_strain / rate,
            self.axial_dt(p_min),
        )?;
        Ok(())
    }

    /// Axial strain rate `ε̇_a = I √(p₀/ρ) / d` (1/s) at confining pressure `p0` (Pa), with the
    /// mean diameter `d = 2 R̄`.
    pub fn axial_rate(&self, p0: f64) -> f64 {
        self.inertial_number * (p0 / self.grain.density).sqrt() / (2.0 * self.grain.radius_mean)
    }

    /// `dt` capped by `dt_max` if given.
    fn capped(&self, dt: f64) -> f64 {
        self.dt_max.map_or(dt, |m| dt.min(m))
    }

    /// Time step of the axial compression at confining pressure `p0` (Pa): the travel rule
    /// `Δt = travel_per_step · R̄ / (ε̇_a d)` with `d = 2 R̄`, i.e. `travel_per_step / (2 ε̇_a)`
    /// at the axial rate [`Self::axial_rate`]: an axial strain of `travel_per_step / 2` a
    /// step (less if `dt_max` caps it).
    pub fn axial_dt(&self, p0: f64) -> f64 {
        self.capped(self.travel_per_step / (2.0 * self.axial_rate(p0)))
    }

    /// Time step of the isotropic compression: `compression_time / compression_steps`, capped
    /// by `dt_max` if given.
    pub fn compression_dt(&self) -> f64 {
        self.capped(self.compression_time / self.compression_steps as f64)
    }

    /// Steps of the isotropic compression: `compression_steps`, more if `dt_max` shortens
    /// the step.
    pub fn compression_step_count(&self) -> u64 {
        (self.compression_time / self.compression_dt()).ceil() as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use datasets::overrides::{apply_override, parse_override};

    use crate::scenarios::loader::{parse_table, typed, ScenarioConfig};

    /// The built-in TOML with `sets` applied, typed and validated (what the loader does).
    fn load(sets: &[&str]) -> Result<BiaxialConfig> {
        let source = "builtin:biaxial";
        let mut table = parse_table(
            include_str!("../../../../datasets/scenarios/biaxial.toml"),
            source,
        )?;
        for s in sets {
            apply_override(&mut table, &parse_override(s)?, source)?;
        }
        let c: BiaxialConfig = typed(table, source)?;
        c.check()?;
        Ok(c)
    }

    /// The travel rule of the axial compression: an axial strain `ε̇_a Δt = travel_per_step / 2`
    /// a step at every confining pressure (analytic), so the axial phase takes
    /// `2 max_axial_strain / travel_per_step` steps whatever the pressure; grains 1000 times
    /// larger (the axial rate 1000 times slower) take 1000 times longer steps and as many.
    #[test]
    fn the_axial_step_is_a_fixed_strain_at_every_pressure_and_scale() {
        let mm = load(&[]).unwrap();
        let m = load(&["grain.radius_mean=1.5", "grain.radius_spread=0.3"]).unwrap();
        for &p0 in &mm.confining_pressures {
            let strain = mm.axial_rate(p0) * mm.axial_dt(p0);
            assert!(
                (strain - mm.travel_per_step / 2.0).abs() < 1e-15,
                "{p0}: {strain}"
            );
            let ratio = m.axial_dt(p0) / mm.axial_dt(p0);
            assert!((ratio - 1000.0).abs() < 1e-9, "{p0}: {ratio}");
        }
        // the compression: compression_time in compression_steps steps
        assert!((mm.compression_dt() - 0.15 / 600.0).abs() < 1e-18);
        assert_eq!(mm.compression_step_count(), 600);
    }

    /// `dt_max` (not in the built-in file: a user's TOML may give it) caps both phases' steps.
    #[test]
    fn dt_max_caps_both_phases() {
        let mut c = load(&[]).unwrap();
        c.dt_max = Some(1e-4);
        assert_eq!(c.axial_dt(1000.0), 1e-4);
        assert_eq!(c.compression_dt(), 1e-4);
        assert_eq!(c.compression_step_count(), 1500);
        c.dt_max = Some(-1.0);
        let e = c.check().unwrap_err().to_string();
        assert!(e.contains("dt_max"), "{e}");
    }

    /// Out-of-range step keys are refused, naming the key.
    #[test]
    fn step_keys_out_of_range_are_refused() {
        for (set, key) in [
            ("travel_per_step=0", "travel_per_step"),
            ("travel_per_step=0.2", "travel_per_step"),
            ("compression_steps=0", "compression_steps"),
            ("theta=0.4", "theta"),
        ] {
            let e = load(&[set]).unwrap_err().to_string();
            assert!(e.contains(key), "{set}: {e}");
        }
    }
}
