//! The measurement of the column: wall and vertical stresses by depth, loads and wall-friction
//! mobilisation, averaged over a window of steps at the end of the release.
//!
//! One state of a narrow column is a poor sample of its stresses: a depth bin five diameters
//! deep holds a few wall contacts, and while the floor sinks the column advances by slip events,
//! so a single step can catch the column accelerating (floor and wall loads then miss the
//! weight by a few per cent) or one wall grain slipping back (a bin's mean τ_w turns negative).
//! The measurement is therefore the time average over the `analysis.measure_steps` steps of the
//! `measure` phase, each solved to the tight tolerance, with the depth bins fixed at the first
//! step's free surface (the floor sinks by `release.speed · dt` a step, a small fraction of a
//! bin). Time averaging over a quasi-static window is the usual DEM practice for stresses
//! (e.g. Radjaï & Dubois 2011, *Discrete-element modeling of granular materials*, ch. 8);
//! averaged over the window, the loads balance the weight up to the change of the grains'
//! momentum over the window divided by its duration.
//!
//! Per sample: σ_h = −σ_nn and τ_w on both side walls (mean of the two,
//! `homogenise::walls::wall_stress_profile`), σ_v = −σ_yy across horizontal planes at the bins'
//! middles (method of planes, `homogenise::walls::plane_stress_profile`), the floor and wall
//! vertical loads, and the mobilisation `|f_t|/(μ f_n)` of every side-wall contact.
//! Compressive stresses are positive in this file.

use dem::math::Vector;
use dem::snapshot::Snapshot;
use dem::BodyKind;
use homogenise::depth::{DepthAxis, DepthBins};
use homogenise::mobilisation::{contact_mobilisations, ContactClass, COULOMB_LIMIT};
use homogenise::walls::{plane_stress_profile, wall_stress_profile};
use serde::{Deserialize, Serialize};

use crate::error::Result;

/// The measured profile of the column (a time average over the measurement window).
#[derive(Debug, Clone)]
pub struct ColumnProfile {
    /// Bin-middle depths (m).
    pub z: Vec<f64>,
    /// σ_v (Pa, compressive positive), method of planes.
    pub sigma_v: Vec<f64>,
    /// σ_h (Pa), mean of both side walls.
    pub sigma_h: Vec<f64>,
    /// τ_w (Pa), mean of both side walls.
    pub tau_w: Vec<f64>,
    /// Height of the free surface above the floor (m).
    pub surface: f64,
}

impl ColumnProfile {
    /// The bins whose middle lies in the depth window `[z_min, z_max]` and whose wall shear
    /// stress is negative (the wall holds the grains down there): `(z, τ_w)`.
    pub fn negative_tau_w(&self, window: (f64, f64)) -> Vec<(f64, f64)> {
        self.z
            .iter()
            .zip(&self.tau_w)
            .filter(|(z, t)| **z >= window.0 && **z <= window.1 && **t < 0.0)
            .map(|(z, t)| (*z, *t))
            .collect()
    }
}

/// Height of the free surface: the mean over one-diameter-wide columns of the highest grain
/// top (m).
pub fn surface_height(snap: &Snapshot, width: f64, d: f64) -> f64 {
    let n = ((width / d).floor() as usize).max(1);
    let mut top = vec![f64::NAN; n];
    for b in snap.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
        let k = ((b.position.x / width * n as f64).floor().max(0.0) as usize).min(n - 1);
        let t = b.position.y + b.radius;
        if top[k].is_nan() || top[k] < t {
            top[k] = t;
        }
    }
    let v: Vec<f64> = top.into_iter().filter(|t| t.is_finite()).collect();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Mean diameter of the grains of a snapshot (m).
fn mean_grain_diameter(snap: &Snapshot) -> f64 {
    let g: Vec<f64> = snap
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .map(|b| 2.0 * b.radius)
        .collect();
    g.iter().sum::<f64>() / g.len().max(1) as f64
}

/// `bins` depth bins of equal thickness from a free surface at height `surface` down to the
/// floor (y = 0).
fn depth_bins(surface: f64, bins: usize) -> Result<DepthBins> {
    let axis = DepthAxis::new(Vector::new(0.0, -1.0), Vector::new(0.0, surface))?;
    Ok(DepthBins::new(axis, surface / bins as f64, bins)?)
}

/// The stress profile of one state in fixed depth bins.
fn profile_in(snap: &Snapshot, width: f64, db: &DepthBins, surface: f64) -> Result<ColumnProfile> {
    let left = wall_stress_profile(snap, "left", db)?;
    let right = wall_stress_profile(snap, "right", db)?;
    let z: Vec<f64> = left.iter().map(|b| b.depth()).collect();
    let levels: Vec<f64> = z.iter().map(|z| surface - z).collect();
    let planes = plane_stress_profile(snap, &levels, Some(width))?;
    Ok(ColumnProfile {
        sigma_v: planes.iter().map(|p| -p.sigma_yy).collect(),
        sigma_h: left
            .iter()
            .zip(&right)
            .map(|(l, r)| -0.5 * (l.normal_stress + r.normal_stress))
            .collect(),
        tau_w: left
            .iter()
            .zip(&right)
            .map(|(l, r)| 0.5 * (l.shear_stress + r.shear_stress))
            .collect(),
        z,
        surface,
    })
}

/// Vertical loads of one state (N per metre of thickness, upward on the grains positive).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColumnLoads {
    /// Load the grains put on the floor.
    pub floor: f64,
    /// Vertical load the grains put on both side walls (friction).
    pub walls: f64,
}

/// Running sums of the measurement window (serialised in checkpoints, so a resumed run
/// averages the same samples).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MeasureWindow {
    /// States observed.
    pub samples: u64,
    /// Free-surface height at the first sample (m): the depth bins of every sample.
    #[serde(with = "dem::serde_float")]
    surface: f64,
    /// Σ σ_v, Σ σ_h, Σ τ_w by bin (Pa).
    sigma_v: Vec<f64>,
    sigma_h: Vec<f64>,
    tau_w: Vec<f64>,
    /// Σ floor load, Σ wall load (N/m).
    #[serde(with = "dem::serde_float")]
    floor: f64,
    #[serde(with = "dem::serde_float")]
    walls: f64,
    /// Mobilisation of every side-wall contact of every sample.
    mobilisations: Vec<f64>,
}

impl MeasureWindow {
    /// Adds one state: its stress profile in `bins` bins below the first sample's free surface,
    /// its loads, and its side-wall mobilisations.
    pub fn observe(
        &mut self,
        snap: &Snapshot,
        width: f64,
        bins: usize,
        loads: ColumnLoads,
    ) -> Result<()> {
        if self.samples == 0 {
            let surface = if self.surface > 0.0 {
                // Set by [`MeasureWindow::empty_like`].
                self.surface
            } else {
                surface_height(snap, width, mean_grain_diameter(snap))
            };
            *self = MeasureWindow {
                surface,
                sigma_v: vec![0.0; bins],
                sigma_h: vec![0.0; bins],
                tau_w: vec![0.0; bins],
                ..Default::default()
            };
        }
        let p = profile_in(snap, width, &depth_bins(self.surface, bins)?, self.surface)?;
        for (sum, v) in [
            (&mut self.sigma_v, &p.sigma_v),
            (&mut self.sigma_h, &p.sigma_h),
            (&mut self.tau_w, &p.tau_w),
        ] {
            sum.iter_mut().zip(v).for_each(|(s, x)| *s += x);
        }
        self.floor += loads.floor;
        self.walls += loads.walls;
        for wall in ["left", "right"] {
            self.mobilisations.extend(
                contact_mobilisations(snap, &ContactClass::WallNamed(wall.into()))?
                    .into_iter()
                    .map(|(_, m)| m),
            );
        }
        self.samples += 1;
        Ok(())
    }

    /// An empty window whose first sample will be binned below this window's free surface
    /// instead of its own (two measures of the same states in the same bins).
    pub fn empty_like(&self) -> MeasureWindow {
        MeasureWindow {
            surface: self.surface,
            ..Default::default()
        }
    }

    fn mean(&self, sum: f64) -> f64 {
        sum / self.samples as f64
    }

    /// The time-averaged profile (NaN stresses before the first sample).
    pub fn profile(&self, bins: usize) -> Result<ColumnProfile> {
        let surface = if self.samples > 0 {
            self.surface
        } else {
            f64::NAN
        };
        let db = depth_bins(if surface > 0.0 { surface } else { 1.0 }, bins)?;
        let mean = |v: &[f64]| -> Vec<f64> {
            (0..bins)
                .map(|b| v.get(b).map_or(f64::NAN, |s| self.mean(*s)))
                .collect()
        };
        Ok(ColumnProfile {
            z: (0..bins)
                .map(|b| {
                    let (d0, d1) = db.bounds(b);
                    0.5 * (d0 + d1)
                })
                .collect(),
            sigma_v: mean(&self.sigma_v),
            sigma_h: mean(&self.sigma_h),
            tau_w: mean(&self.tau_w),
            surface,
        })
    }

    /// Mean loads over the window.
    pub fn loads(&self) -> ColumnLoads {
        ColumnLoads {
            floor: self.mean(self.floor),
            walls: self.mean(self.walls),
        }
    }

    /// Mobilisations of the side-wall contacts of every sample.
    pub fn mobilisations(&self) -> &[f64] {
        &self.mobilisations
    }

    /// Share of the side-wall contacts (over all samples) at the Coulomb limit, and their mean
    /// mobilisation (NaN without wall contacts).
    pub fn sliding(&self) -> (f64, f64) {
        let m = &self.mobilisations;
        if m.is_empty() {
            return (f64::NAN, f64::NAN);
        }
        let n = m.len() as f64;
        (
            m.iter().filter(|&&x| x >= COULOMB_LIMIT).count() as f64 / n,
            m.iter().sum::<f64>() / n,
        )
    }

    /// Mean number of side-wall contacts per sample.
    pub fn wall_contacts(&self) -> f64 {
        self.mobilisations.len() as f64 / (self.samples as f64).max(1.0)
    }
}
