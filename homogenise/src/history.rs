//! Sampling snapshots every `k` steps into a [`Table`] of homogenised quantities over a region.
//!
//! Columns of a row (units in brackets; a quantity undefined at a sample is missing, NaN):
//! `step [-]`, `time [s]`; the mean stress `sigma_xx … sigma_yy [Pa]` and its contact part
//! `contact_xx … contact_yy [Pa]`; `skew_ratio [-]` (‖skew Σ‖/‖Σ‖); `pressure [Pa]`,
//! `shear_stress [Pa]`, `stress_ratio [-]` ([`crate::invariants`]); the fitted strain rate
//! `d_xx, d_xy, d_yy [1/s]`, `shear_rate [1/s]`, `inertial_number [-]`
//! ([`crate::kinematics`]); `solid_fraction`, `coordination`, `coordination_nonrattler`,
//! `rattler_fraction`, `fabric_anisotropy [-]`, `fabric_angle [rad]` ([`crate::state`]);
//! `kinetic_energy [J]` of the grains (translation and rotation); `fluid_fraction [-]`
//! ([`crate::inertia_ratio`]); `bulk_sliding_fraction`, `wall_sliding_fraction [-]`
//! (share of contacts with `m ≥ 0.99`, [`crate::mobilisation`]); then for every wall `w`
//! `wall_w_fx`, `wall_w_fy [N]` (total force on the wall).

use dem::math::Twist;
use dem::snapshot::{BodyKind, Snapshot};
use serde::{Deserialize, Serialize};

use crate::error::{positive, HomogeniseError, Result};
use crate::inertia_ratio::{fluid_fraction, inertia_ratios};
use crate::invariants::{inertial_number, stress_invariants};
use crate::kinematics::{velocity_gradient, VelocityWeight};
use crate::mobilisation::{contact_mobilisations, ContactClass, COULOMB_LIMIT};
use crate::region::Region;
use crate::state::{coordination, fabric, solid_fraction, ContactCounting};
use crate::stress::{grain_stresses, mean_stress};
use crate::table::{Column, Table};
use crate::tensor::skew_ratio;

/// What and how often to sample.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SamplerConfig {
    /// Sample the snapshots whose step is a multiple of this (≥ 1).
    pub every: u64,
    /// Region of the averages.
    pub region: Region,
    /// Grain diameter `d` of the inertial number (m); default: the grains' mean diameter.
    pub diameter: Option<f64>,
    /// Grain density `ρ` of the inertial number (kg/m³); default: total mass / total volume.
    pub density: Option<f64>,
    /// Weight of the velocity fit.
    pub velocity_weight: VelocityWeight,
    /// Contact counting for coordination and fabric.
    pub counting: ContactCounting,
    /// Inertia-ratio threshold above which a grain is fluid-like (default 1).
    pub fluid_threshold: f64,
}

impl Default for SamplerConfig {
    fn default() -> Self {
        Self {
            every: 1,
            region: Region::Whole,
            diameter: None,
            density: None,
            velocity_weight: VelocityWeight::Mass,
            counting: ContactCounting::default(),
            fluid_threshold: 1.0,
        }
    }
}

fn wall_column_name(name: &str, index: usize) -> String {
    let clean: String = name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if clean.is_empty() {
        format!("wall{index}")
    } else {
        clean
    }
}

/// One row of homogenised quantities of a snapshot (see the module documentation).
pub fn sample_row(snapshot: &Snapshot, config: &SamplerConfig) -> Result<Vec<(Column, f64)>> {
    let grains = grain_stresses(snapshot)?;
    let ms = mean_stress(snapshot, &grains, &config.region)?;
    let inv = stress_invariants(&ms.total);
    let nan = f64::NAN;
    let mut row: Vec<(Column, f64)> = Vec::with_capacity(40);
    let mut push = |name: &str, unit: &str, v: f64| row.push((Column::new(name, unit), v));
    push("step", "-", snapshot.step as f64);
    push("time", "s", snapshot.time);
    for (p, t) in [("sigma", &ms.total), ("contact", &ms.contact)] {
        push(&format!("{p}_xx"), "Pa", t[(0, 0)]);
        push(&format!("{p}_xy"), "Pa", t[(0, 1)]);
        push(&format!("{p}_yx"), "Pa", t[(1, 0)]);
        push(&format!("{p}_yy"), "Pa", t[(1, 1)]);
    }
    push("skew_ratio", "-", skew_ratio(&ms.total));
    push("pressure", "Pa", inv.pressure);
    push("shear_stress", "Pa", inv.shear_stress);
    push("stress_ratio", "-", inv.friction.unwrap_or(nan));
    // grains' mean diameter and density
    let gs: Vec<_> = snapshot
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .collect();
    let d = match config.diameter {
        Some(d) => positive("diameter", d)?,
        None => 2.0 * gs.iter().map(|b| b.radius).sum::<f64>() / gs.len().max(1) as f64,
    };
    let rho = match config.density {
        Some(r) => positive("density", r)?,
        None => gs.iter().map(|b| b.mass).sum::<f64>() / gs.iter().map(|b| b.volume()).sum::<f64>(),
    };
    match velocity_gradient(snapshot, &config.region, config.velocity_weight) {
        Ok(fit) => {
            let dd = fit.strain_rate();
            let gd = fit.shear_rate();
            push("d_xx", "1/s", dd[(0, 0)]);
            push("d_xy", "1/s", dd[(0, 1)]);
            push("d_yy", "1/s", dd[(1, 1)]);
            push("shear_rate", "1/s", gd);
            push(
                "inertial_number",
                "-",
                inertial_number(gd, d, inv.pressure, rho).unwrap_or(nan),
            );
        }
        Err(HomogeniseError::NotEnoughData(_)) => {
            for (n, u) in [
                ("d_xx", "1/s"),
                ("d_xy", "1/s"),
                ("d_yy", "1/s"),
                ("shear_rate", "1/s"),
            ] {
                push(n, u, nan);
            }
            push("inertial_number", "-", nan);
        }
        Err(e) => return Err(e),
    }
    push(
        "solid_fraction",
        "-",
        solid_fraction(snapshot, &config.region)?,
    );
    match coordination(snapshot, &config.region, &config.counting) {
        Ok(c) => {
            push("coordination", "-", c.z);
            push("coordination_nonrattler", "-", c.z_without_rattlers);
            push("rattler_fraction", "-", c.rattler_fraction);
        }
        Err(HomogeniseError::EmptyRegion(_)) => {
            push("coordination", "-", nan);
            push("coordination_nonrattler", "-", nan);
            push("rattler_fraction", "-", nan);
        }
        Err(e) => return Err(e),
    }
    let f = fabric(snapshot, &config.region, &config.counting)?;
    let has = f.contacts > 0;
    push(
        "fabric_anisotropy",
        "-",
        if has { f.anisotropy } else { nan },
    );
    push("fabric_angle", "rad", if has { f.major_angle } else { nan });
    let ke: f64 = gs
        .iter()
        .map(|b| Twist::new(b.velocity, b.omega).kinetic_energy(b.mass, b.inertia))
        .sum();
    push("kinetic_energy", "J", ke);
    push(
        "fluid_fraction",
        "-",
        fluid_fraction(&inertia_ratios(&grains), config.fluid_threshold)?,
    );
    for (name, class) in [
        ("bulk_sliding_fraction", ContactClass::Bulk),
        ("wall_sliding_fraction", ContactClass::Wall),
    ] {
        let m = contact_mobilisations(snapshot, &class)?;
        let v = if m.is_empty() {
            nan
        } else {
            m.iter().filter(|(_, m)| *m >= COULOMB_LIMIT).count() as f64 / m.len() as f64
        };
        push(name, "-", v);
    }
    for (i, w) in snapshot.walls.iter().enumerate() {
        let n = wall_column_name(&w.name, i);
        push(&format!("wall_{n}_fx"), "N", w.force.x);
        push(&format!("wall_{n}_fy"), "N", w.force.y);
    }
    Ok(row)
}

/// Collects [`sample_row`] every `every` steps into a [`Table`]; the columns are fixed by the
/// first sampled snapshot (a later snapshot with other walls is an error).
#[derive(Debug, Clone)]
pub struct Sampler {
    config: SamplerConfig,
    table: Option<Table>,
}

impl Sampler {
    /// A sampler with this configuration (`every ≥ 1`, `fluid_threshold ≥ 0`).
    pub fn new(config: SamplerConfig) -> Result<Self> {
        if config.every == 0 {
            return Err(HomogeniseError::InvalidParameter {
                name: "every",
                reason: "must be ≥ 1".into(),
            });
        }
        if !(config.fluid_threshold.is_finite() && config.fluid_threshold >= 0.0) {
            return Err(HomogeniseError::InvalidParameter {
                name: "fluid_threshold",
                reason: "must be finite and ≥ 0".into(),
            });
        }
        Ok(Self {
            config,
            table: None,
        })
    }

    /// Samples the snapshot if its step is a multiple of `every`; returns whether it did.
    pub fn observe(&mut self, snapshot: &Snapshot) -> Result<bool> {
        if !snapshot.step.is_multiple_of(self.config.every) {
            return Ok(false);
        }
        let row = sample_row(snapshot, &self.config)?;
        let table = match &mut self.table {
            Some(t) => t,
            None => self
                .table
                .insert(Table::new(row.iter().map(|(c, _)| c.clone()).collect())?),
        };
        if table.columns().len() != row.len()
            || table.columns().iter().zip(&row).any(|(a, (b, _))| a != b)
        {
            return Err(HomogeniseError::Table(format!(
                "step {}: the sampled columns changed (walls added or removed?)",
                snapshot.step
            )));
        }
        let values: Vec<f64> = row.iter().map(|(_, v)| *v).collect();
        table.push_row(&values)?;
        Ok(true)
    }

    /// The table so far (`None` before the first sample).
    pub fn table(&self) -> Option<&Table> {
        self.table.as_ref()
    }

    /// The table, consuming the sampler.
    pub fn into_table(self) -> Option<Table> {
        self.table
    }
}
