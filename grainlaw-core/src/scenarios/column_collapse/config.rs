//! The `column-collapse` scenario: a 2D column of polydisperse disks, deposited behind a gate,
//! collapses onto a rough horizontal floor when the gate is removed (Lajeunesse,
//! Mangeney-Castelnau & Vilotte, Phys. Fluids 16, 2004; Lube et al., J. Fluid Mech. 508, 2004;
//! Staron & Hinch, J. Fluid Mech. 545, 2005; Lagrée, Staron & Popinet, J. Fluid Mech. 686,
//! 2011).
//!
//! Geometry (the contract of the continuum comparison): the symmetry wall is the plane x = 0,
//! the floor the plane y = 0 (the tops of the glued floor disks); the column occupies
//! `0 ≤ x ≤ R₀`, `0 ≤ y ≤ H₀`, with `R₀ = half_width_diameters · 2 R̄` and `H₀ = a R₀`.

use serde::{Deserialize, Serialize};

use datasets::error::{at_least, in_range, non_negative, num, DatasetError, Result};
use datasets::limits;

use crate::scenarios::common::config::{check_dt, check_dt_gravity, GrainSpec, MAX_FRICTION};
use crate::scenarios::common::deposit::{DepositSpec, RelaxSpec};

/// Solid fraction by which the number of poured grains is sized: above the densest packing the
/// drop-and-roll deposition and its relaxation reach with these disks (about 0.80–0.84), so
/// that the deposited column is always taller than `H₀` and is trimmed to it.
pub const POUR_PACKING: f64 = 0.9;

/// Gravity of the scenario (m/s²), along −y.
pub const GRAVITY: f64 = 9.81;

/// The reference instants of the contact-dynamics comparison (Lagrée, Staron & Popinet 2011,
/// the Gerris example `column`): `t* = t √(g/H₀)`.
pub const REFERENCE_T_STAR: [f64; 5] = [0.66, 0.95, 1.24, 1.52, 2.28];

/// Configuration of the `column-collapse` scenario (every key of
/// `scenarios/column-collapse.toml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnCollapseConfig {
    /// Always `"column-collapse"`.
    pub scenario: String,
    /// Seed of the radii and of the deposition.
    pub seed: u64,
    /// Aspect ratio `a = H₀ / R₀` of the initial column.
    pub aspect_ratio: f64,
    /// Initial half-width `R₀` in mean grain diameters `2 R̄`.
    pub half_width_diameters: f64,
    /// Length of the rough floor from the symmetry wall, in units of `R₀`.
    pub floor_length: f64,
    /// Grain size and density.
    pub grain: GrainSpec,
    /// Coulomb friction coefficients.
    pub friction: CollapseFriction,
    /// Normal restitution coefficient `e` of every contact of a grain (Newton's law on impacts),
    /// in [0, 1); 0 (the contact-dynamics choice of the references): impacts are perfectly
    /// inelastic.
    pub restitution: f64,
    /// Time step of the collapse (s).
    pub dt: f64,
    /// Preparation: the column poured (drop-and-roll deposition) behind the gate, then settled
    /// under gravity at `dt / deposit.substeps` until at rest.
    pub deposit: DepositSpec,
    /// The collapse after the gate is removed: at `dt` until the deposit is at rest
    /// (`collapse.rest_energy`, after `collapse.min_time`) or `collapse.max_time`.
    pub collapse: RelaxSpec,
    /// Measurement and output settings.
    pub analysis: CollapseAnalysis,
}

/// Friction coefficients of the collapse.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollapseFriction {
    /// Grain–grain μ_p.
    pub grain_grain: f64,
    /// Grain–floor μ (the glued disks of the rough floor, and the flat wall under them).
    pub floor: f64,
    /// Grain–wall μ of the symmetry wall x = 0 and of the gate (0: a symmetry plane carries no
    /// shear stress).
    pub wall: f64,
}

/// What to measure and write.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollapseAnalysis {
    /// Instants `t* = t √(g/H₀)` at which the height profile is written (strictly increasing,
    /// > 0); the contract's `[0.66, 0.95, 1.24, 1.52, 2.28]` ([`REFERENCE_T_STAR`]).
    pub reference_t_star: Vec<f64>,
    /// Interval of `t*` between two samples of the front position (`front.csv`).
    pub sample_t_star: f64,
    /// Largest number of VTK frames (one every 0.1 t* of the collapse; the final state always).
    pub vtk_frames: usize,
}

/// Largest number of front samples of a run (`collapse.max_time / (sample_t_star √(H₀/g))`).
pub const MAX_SAMPLES: f64 = 1e6;

/// Largest number of reference instants.
pub const MAX_INSTANTS: usize = 100;

impl ColumnCollapseConfig {
    /// Mean grain diameter `d = 2 R̄` (m).
    pub fn diameter(&self) -> f64 {
        2.0 * self.grain.radius_mean
    }

    /// Initial half-width `R₀` (m), the gate's abscissa.
    pub fn half_width(&self) -> f64 {
        self.half_width_diameters * self.diameter()
    }

    /// Initial height `H₀ = a R₀` (m).
    pub fn height(&self) -> f64 {
        self.aspect_ratio * self.half_width()
    }

    /// Time scale `√(H₀/g)` of `t*` (s).
    pub fn time_scale(&self) -> f64 {
        (self.height() / GRAVITY).sqrt()
    }

    /// Number of grains poured behind the gate: `⌈φ_p R₀ H₀ / (π ⟨R²⟩)⌉` with
    /// φ_p = [`POUR_PACKING`] (more than the column holds: the deposit is trimmed to `H₀`).
    pub fn poured_grains(&self) -> usize {
        let n = POUR_PACKING * self.half_width() * self.height()
            / (std::f64::consts::PI * self.grain.mean_square_radius());
        if n.is_finite() {
            n.ceil().max(0.0).min(usize::MAX as f64) as usize
        } else {
            usize::MAX
        }
    }

    /// Floor length (m).
    pub fn floor_extent(&self) -> f64 {
        self.floor_length * self.half_width()
    }

    /// Checks every value (key named in the error), including the derived ones: the column
    /// must hold the largest grain across and two mean diameters high, the poured grains and
    /// the floor disks stay within [`limits::MAX_GRAINS`], the profile bins within
    /// [`limits::MAX_BINS`], and no phase takes more than [`limits::MAX_STEPS`] steps.
    pub fn validate(&self) -> Result<()> {
        self.grain.validate("grain")?;
        in_range("aspect_ratio", self.aspect_ratio, 0.1, 50.0)?;
        in_range(
            "half_width_diameters",
            self.half_width_diameters,
            3.0,
            1000.0,
        )?;
        in_range("floor_length", self.floor_length, 2.0, 1000.0)?;
        let needed = 2.0 * self.grain.radius_max() + 4.0 * 0.02 * self.grain.radius_min();
        if self.half_width() <= needed {
            return Err(DatasetError::invalid(
                "half_width_diameters",
                format!(
                    "{} gives a column {:.3e} m wide, not wider than the largest grain with its \
                     gaps ({needed:.3e} m): raise it or lower grain.radius_spread",
                    num(self.half_width_diameters),
                    self.half_width()
                ),
            ));
        }
        if self.height() < 2.0 * self.diameter() {
            return Err(DatasetError::invalid(
                "aspect_ratio",
                format!(
                    "{} gives a column {:.3e} m high, lower than two mean diameters ({:.3e} m): \
                     raise it or half_width_diameters",
                    num(self.aspect_ratio),
                    self.height(),
                    2.0 * self.diameter()
                ),
            ));
        }
        limits::grains("aspect_ratio", self.poured_grains(), 10)?;
        let floor_disks = self.floor_length * self.half_width_diameters;
        if floor_disks > limits::MAX_BINS as f64 {
            return Err(DatasetError::invalid(
                "floor_length",
                format!(
                    "{} R₀ is {floor_disks:.0} mean diameters of floor (and of height profile), \
                     more than {}: shorten it",
                    num(self.floor_length),
                    limits::MAX_BINS
                ),
            ));
        }
        for (key, mu) in [
            ("friction.grain_grain", self.friction.grain_grain),
            ("friction.floor", self.friction.floor),
            ("friction.wall", self.friction.wall),
        ] {
            non_negative(key, mu)?;
            if mu > MAX_FRICTION {
                return Err(DatasetError::invalid(
                    key,
                    format!(
                        "friction coefficient {} is above {MAX_FRICTION}, the range of this \
                         scenario (dry granular materials and walls have μ ≈ 0.1–0.9)",
                        num(mu)
                    ),
                ));
            }
        }
        in_range("restitution", self.restitution, 0.0, 0.99)?;
        check_dt("dt", self.dt, 1.0)?;
        check_dt_gravity("dt", self.dt, self.grain.radius_min())?;
        self.deposit.validate("deposit", self.dt)?;
        self.collapse.validate("collapse", self.dt)?;
        let a = &self.analysis;
        at_least("analysis.reference_t_star", a.reference_t_star.len(), 1)?;
        limits::at_most(
            "analysis.reference_t_star",
            a.reference_t_star.len(),
            MAX_INSTANTS,
        )?;
        let mut before = 0.0;
        for (i, &t) in a.reference_t_star.iter().enumerate() {
            let key = format!("analysis.reference_t_star[{i}]");
            in_range(&key, t, 1e-6, 1e6)?;
            if t <= before {
                return Err(DatasetError::invalid(
                    key,
                    format!(
                        "must increase strictly, got {} after {}",
                        num(t),
                        num(before)
                    ),
                ));
            }
            before = t;
        }
        in_range("analysis.sample_t_star", a.sample_t_star, 1e-6, 1.0)?;
        let samples = self.collapse.max_time / (a.sample_t_star * self.time_scale());
        if samples.is_nan() || samples > MAX_SAMPLES {
            return Err(DatasetError::invalid(
                "analysis.sample_t_star",
                format!(
                    "gives {samples:.3e} front samples over collapse.max_time, more than \
                     {MAX_SAMPLES:e}: raise it"
                ),
            ));
        }
        limits::at_most("analysis.vtk_frames", a.vtk_frames, limits::MAX_FRAMES)?;
        Ok(())
    }
}
