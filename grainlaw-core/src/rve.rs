//! Another code's representative volume in simple shear (`grainlaw homogenise` on a series of
//! snapshots of a biperiodic cell, e.g. LAMMPS dumps of a `fix deform xy erate ... remap v`
//! run): the point of μ(I), φ(I) that grainlaw's own `simple-shear` scenario makes for one
//! inertial number, with the same samples, averages, checks and table
//! (`crate::scenarios::simple_shear::RheologyPoint`, `crate::scenarios::shear_cell::judge_points`,
//! `crate::scenarios::shear_cell::write_rheology_table`).
//!
//! Per snapshot, the whole-cell state ([`homogenise::cell::cell_state`]: mean stress over the
//! cell of area `det h`, kinetic stress of the velocity fluctuations about the cell's affine
//! field included); over the series, the means and block-averaged standard errors of
//! μ = |Σ_xy|/(−Σ_yy), φ, `P = −Σ_yy`, and `I = |γ̇| d/√(P/ρ)` with `d` the mean diameter and
//! `ρ` the grains' mass over their area. The shear rate `γ̇` is the cell's own: its tilt rate
//! over the series, `γ̇ = Σ_k L_xy,k Δt_k / (t_N − t_0)` with `L = ḣ h⁻¹` of each interval
//! (`readers::frame`), when the snapshots have times; otherwise the mean of the affine fits of
//! the grain velocities. Both are reported ([`RvePoint::shear_rate_velocity_profile`]).
//! The series is the averaging window: its snapshots must be taken in the steady state, the
//! steady-state checks (window halves of μ and φ) say whether they were.

use homogenise::cell::cell_state;
use homogenise::kinematics::{velocity_gradient, VelocityWeight};
use homogenise::Region;
use identify::law::GrainScale;

use crate::error::Result;
use crate::output::{OutputDir, Summary};
use crate::readers::{ExternalSnapshot, GradientSource};
use crate::scenarios::rows::TableRow;
use crate::scenarios::shear_cell::{judge_points, write_rheology_table, RunCheckData};
use crate::scenarios::simple_shear::{CellSamples, RheologyPoint, RheologyRow};
use crate::verdict::{max_solid_fraction, Checks, Verdict, WindowStats};

/// The point of a series of snapshots of a sheared biperiodic cell (module documentation).
#[derive(Debug, Clone)]
pub struct RvePoint {
    /// The row of `rheology.csv` (the columns of the `simple-shear` scenario's, `I_target` and
    /// `cell_corrections_per_step` NaN), without its verdict.
    pub row: RheologyRow,
    /// The point's verdict.
    pub verdict: Verdict,
    /// The failed checks.
    pub checks: Checks,
    /// Shear rate `γ̇` (1/s) of the point.
    pub shear_rate: f64,
    /// Where it comes from.
    pub source: GradientSource,
    /// The mean over the snapshots of `L_xy` of the mass-weighted affine fit of the grain
    /// velocities (1/s): the check of `γ̇` against the flow.
    pub shear_rate_velocity_profile: f64,
    /// Mean diameter `d` (m) and density `ρ` (kg/m³) of the grains.
    pub grain: GrainScale,
    /// Snapshots averaged.
    pub samples: usize,
}

/// The point of `snaps` when every snapshot has a biperiodic cell and the cell is sheared
/// (`γ̇ ≠ 0`); `None` otherwise.
pub fn rve_point(snaps: &[ExternalSnapshot]) -> Result<Option<RvePoint>> {
    if snaps.is_empty() || snaps.iter().any(|e| e.snapshot.cell.is_none()) {
        return Ok(None);
    }
    let l_xy = |e: &ExternalSnapshot| e.snapshot.cell.map_or(0.0, |c| c.l[(0, 1)]);
    let by_cell = snaps.len() >= 2
        && snaps
            .iter()
            .all(|e| e.velocity_gradient == Some(GradientSource::CellDeformation));
    let (shear_rate, source) = if by_cell {
        let t0 = snaps[0].snapshot.time;
        let t1 = snaps[snaps.len() - 1].snapshot.time;
        let sum: f64 = snaps
            .windows(2)
            .map(|w| l_xy(&w[1]) * (w[1].snapshot.time - w[0].snapshot.time))
            .sum();
        (sum / (t1 - t0), GradientSource::CellDeformation)
    } else {
        (
            snaps.iter().map(l_xy).sum::<f64>() / snaps.len() as f64,
            GradientSource::VelocityProfile,
        )
    };
    if !(shear_rate.is_finite() && shear_rate != 0.0) {
        return Ok(None);
    }
    // the grain velocities' affine fit (NaN where the grains are too few or aligned for it)
    let mut fitted = 0.0;
    let mut samples = CellSamples::default();
    for e in snaps {
        samples.push(&cell_state(&e.snapshot)?);
        fitted += velocity_gradient(&e.snapshot, &Region::Whole, VelocityWeight::Mass)
            .map_or(f64::NAN, |f| f.gradient[(0, 1)]);
    }
    let first = &snaps[0].snapshot;
    let grains: Vec<_> = first
        .bodies
        .iter()
        .filter(|b| b.kind == dem::snapshot::BodyKind::Grain)
        .collect();
    let n = grains.len().max(1) as f64;
    let d = grains.iter().map(|b| 2.0 * b.radius).sum::<f64>() / n;
    let rho =
        grains.iter().map(|b| b.mass).sum::<f64>() / grains.iter().map(|b| b.volume()).sum::<f64>();
    let (r_min, r_max) = grains.iter().fold((f64::INFINITY, 0.0f64), |(a, b), g| {
        (a.min(g.radius), b.max(g.radius))
    });
    let point = RheologyPoint::of(&samples, shear_rate, d, rho)?;
    // the time step, from the steps and times of the first two snapshots
    let dt = match snaps {
        [a, b, ..] if b.snapshot.step > a.snapshot.step => {
            (b.snapshot.time - a.snapshot.time) / (b.snapshot.step - a.snapshot.step) as f64
        }
        _ => f64::NAN,
    };
    let judged = judge_points(
        "simple_shear",
        &[RunCheckData {
            i_target: f64::NAN,
            i_measured: point.i,
            window: WindowStats::default(),
            mu: samples.mu.clone(),
            phi: samples.phi.clone(),
        }],
        max_solid_fraction(0.5 * (r_max - r_min)),
    );
    let mut checks = judged.common;
    checks.extend(&judged.mu);
    checks.extend(&judged.phi);
    Ok(Some(RvePoint {
        row: point.row(f64::NAN, shear_rate, dt, snaps.len(), f64::NAN),
        verdict: judged.points.first().copied().unwrap_or(Verdict::Refused),
        checks,
        shear_rate,
        source,
        shear_rate_velocity_profile: fitted / snaps.len() as f64,
        grain: GrainScale {
            diameter_m: d,
            density_kg_m3: rho,
        },
        samples: snaps.len(),
    }))
}

impl RvePoint {
    /// Column `name` of [`RvePoint::row`].
    pub fn value(&self, name: &str) -> f64 {
        RheologyRow::HEADERS
            .iter()
            .position(|h| *h == name)
            .and_then(|k| self.row.to_values().get(k).copied())
            .unwrap_or(f64::NAN)
    }

    /// Writes `rheology.csv` (one row, the table of the `simple-shear` scenario; fit it, or
    /// several such tables merged, with `grainlaw fit mu-i`, `grainlaw fit phi-i`).
    pub fn write(&self, out: &mut OutputDir) -> Result<()> {
        write_rheology_table(
            out,
            std::slice::from_ref(&self.row),
            &[self.verdict],
            &format!(
                "another code's simple shear of a biperiodic cell (grainlaw homogenise): means over the {} snapshots with block-averaged standard errors; P is -sigma_yy, I is gamma_dot d / sqrt(P/rho), mu is |sigma_xy|/P; shear rate from the {}; I_target and cell_corrections_per_step empty (the run has no target); merge several runs with grainlaw fit mu-i A/rheology.csv B/rheology.csv ...",
                self.samples,
                match self.source {
                    GradientSource::CellDeformation => "cell's tilt rate",
                    _ => "grain velocities (affine fit)",
                }
            ),
            self.grain,
        )
    }

    /// Summary keys `rve_*` (`docs/outputs.md` §4).
    pub fn keys(&self, s: &mut Summary) {
        for (key, col) in [
            ("rve_I", "I"),
            ("rve_I_std_error", "I_std_error"),
            ("rve_mu", "mu"),
            ("rve_mu_std_error", "mu_std_error"),
            ("rve_phi", "phi"),
            ("rve_phi_std_error", "phi_std_error"),
            ("rve_P_Pa", "P_Pa"),
            ("rve_P_std_error_Pa", "P_std_error_Pa"),
            ("rve_p_mean_Pa", "p_mean_Pa"),
            ("rve_Z", "Z"),
        ] {
            s.num(key, self.value(col));
        }
        s.num("rve_shear_rate_1_s", self.shear_rate)
            .text("rve_shear_rate_source", self.source.name())
            .num(
                "rve_shear_rate_velocity_profile_1_s",
                self.shear_rate_velocity_profile,
            )
            .num("rve_grain_diameter_m", self.grain.diameter_m)
            .num("rve_grain_density_kg_m3", self.grain.density_kg_m3)
            .int("rve_samples", self.samples as u64)
            .text("rve_point_verdict", self.verdict.as_str())
            .set(
                "rve_point_reasons",
                serde_json::Value::Array(
                    self.checks
                        .reasons
                        .iter()
                        .map(crate::verdict::Reason::to_json)
                        .collect(),
                ),
            );
    }

    /// The report lines.
    pub fn lines(&self) -> Vec<String> {
        let mut l = vec![format!(
            "simple-shear point ({} snapshots, γ̇ = {:.4e} 1/s from the {}; grain velocities: {:.4e}): I = {:.4e} ± {:.1e}, μ = {:.4} ± {:.4}, φ = {:.4} ± {:.4}, P = {:.4e} Pa: {}",
            self.samples,
            self.shear_rate,
            match self.source {
                GradientSource::CellDeformation => "cell's tilt rate",
                _ => "grain velocities",
            },
            self.shear_rate_velocity_profile,
            self.value("I"),
            self.value("I_std_error"),
            self.value("mu"),
            self.value("mu_std_error"),
            self.value("phi"),
            self.value("phi_std_error"),
            self.value("P_Pa"),
            self.verdict.as_str()
        )];
        l.extend(
            self.checks
                .reasons
                .iter()
                .map(|r| format!("  {}", r.message)),
        );
        l
    }
}
