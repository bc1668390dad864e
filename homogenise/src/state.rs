//! State of the packing in a region: solid fraction, coordination number (with and without
//! rattlers) and fabric tensor.
//!
//! - Solid fraction `φ = Σ_p w_p π R_p² / A_R`, `w_p` the grain's area fraction in the region.
//! - A contact is **force-carrying** when `f_n > force_threshold` (N).
//! - **Rattlers** are found iteratively: a grain with fewer than `min_contacts` force-carrying
//!   contacts with walls or non-rattler grains is a rattler; removing it may make its
//!   neighbours rattlers, until nothing changes. Wall contacts always count for this test.
//! - Coordination `Z = Σ_p w_p c_p / Σ_p w_p` with `c_p` the number of force-carrying contacts
//!   of grain `p` (wall contacts included when `count_wall_contacts`); `Z*` the same over
//!   non-rattlers, counting only contacts with walls and non-rattlers.
//! - Fabric `F = (1/N_c) Σ_α n_α ⊗ n_α` over force-carrying contacts whose point lies in the
//!   region (tr F = 1); anisotropy `a = 2 (λ₁ − λ₂)` (λ the eigenvalues, so `F = (𝟙 + a (e⊗e −
//!   e⊥⊗e⊥)/2)/2` along the major direction `e`) and the major direction's angle.

use dem::snapshot::{BodyKind, Snapshot};
use serde::{Deserialize, Serialize};

use crate::error::{HomogeniseError, Result};
use crate::region::Region;
use crate::tensor::outer;
use crate::validate::check_snapshot;
use dem::math::{SymTensor, Tensor};

/// Which contacts count, for coordination and fabric.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ContactCounting {
    /// A contact carries force when `f_n` exceeds this (N); default 0.
    pub force_threshold: f64,
    /// Count wall contacts in `Z` and in the fabric; default true.
    pub count_wall_contacts: bool,
    /// A grain with fewer force-carrying contacts than this is a rattler; default 2.
    pub min_contacts: usize,
}

impl Default for ContactCounting {
    fn default() -> Self {
        Self {
            force_threshold: 0.0,
            count_wall_contacts: true,
            min_contacts: 2,
        }
    }
}

/// Coordination numbers over a region.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Coordination {
    /// Weighted number of grains in the region `Σ w_p`.
    pub grains: f64,
    /// Mean number of force-carrying contacts per grain `Z`.
    pub z: f64,
    /// The same over non-rattlers, counting contacts with non-rattlers and walls, `Z*`.
    pub z_without_rattlers: f64,
    /// Weighted share of rattlers among the region's grains.
    pub rattler_fraction: f64,
}

/// Fabric tensor over a region.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Fabric {
    /// `F = (1/N_c) Σ n ⊗ n` (dimensionless, trace 1); zero when no contact.
    pub tensor: SymTensor,
    /// Number of contacts used `N_c`.
    pub contacts: usize,
    /// Anisotropy `a = 2 (λ₁ − λ₂)` ∈ [0, 2].
    pub anisotropy: f64,
    /// Angle of the major principal direction from x (rad, in `[0, π)`).
    pub major_angle: f64,
}

fn check_counting(c: &ContactCounting) -> Result<()> {
    if !(c.force_threshold.is_finite() && c.force_threshold >= 0.0) {
        return Err(HomogeniseError::InvalidParameter {
            name: "force_threshold",
            reason: format!("must be finite and ≥ 0, got {}", c.force_threshold),
        });
    }
    Ok(())
}

/// Solid fraction `φ = Σ_p w_p π R_p² / A_R` of the region (dimensionless).
pub fn solid_fraction(snapshot: &Snapshot, region: &Region) -> Result<f64> {
    check_snapshot(snapshot)?;
    let rect = region.resolve(snapshot)?;
    let a: f64 = snapshot
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .map(|b| {
            rect.disk_fraction(&b.position, b.radius) * std::f64::consts::PI * b.radius * b.radius
        })
        .sum();
    Ok(a / rect.area())
}

/// Marks the rattlers (see the module documentation); `true` at the index of every grain that
/// is a rattler, `false` for non-rattlers and walls.
pub fn rattlers(snapshot: &Snapshot, counting: &ContactCounting) -> Result<Vec<bool>> {
    check_snapshot(snapshot)?;
    check_counting(counting)?;
    let n = snapshot.bodies.len();
    let is_grain: Vec<bool> = snapshot
        .bodies
        .iter()
        .map(|b| b.kind == BodyKind::Grain)
        .collect();
    let carrying: Vec<(usize, usize)> = snapshot
        .contacts
        .iter()
        .filter(|c| c.force_n > counting.force_threshold)
        .map(|c| (c.body_a as usize, c.body_b as usize))
        .collect();
    let mut rattler = vec![false; n];
    loop {
        let mut count = vec![0usize; n];
        for &(a, b) in &carrying {
            if !rattler[a] && !rattler[b] {
                count[a] += 1;
                count[b] += 1;
            }
        }
        let mut changed = false;
        for i in 0..n {
            if is_grain[i] && !rattler[i] && count[i] < counting.min_contacts {
                rattler[i] = true;
                changed = true;
            }
        }
        if !changed {
            return Ok(rattler);
        }
    }
}

/// Coordination numbers `Z`, `Z*` and rattler share over the region (see module docs).
/// Fails when no grain lies in the region.
pub fn coordination(
    snapshot: &Snapshot,
    region: &Region,
    counting: &ContactCounting,
) -> Result<Coordination> {
    let rattler = rattlers(snapshot, counting)?;
    let rect = region.resolve(snapshot)?;
    let n = snapshot.bodies.len();
    let is_grain = |i: usize| snapshot.bodies[i].kind == BodyKind::Grain;
    let (mut all, mut kept) = (vec![0usize; n], vec![0usize; n]);
    for c in snapshot
        .contacts
        .iter()
        .filter(|c| c.force_n > counting.force_threshold)
    {
        let (a, b) = (c.body_a as usize, c.body_b as usize);
        let bulk = is_grain(a) && is_grain(b);
        if !bulk && !counting.count_wall_contacts {
            continue;
        }
        for (p, q) in [(a, b), (b, a)] {
            all[p] += 1;
            if !rattler[q] {
                kept[p] += 1;
            }
        }
    }
    let (mut w_all, mut z_all, mut w_nr, mut z_nr) = (0.0, 0.0, 0.0, 0.0);
    for (i, b) in snapshot
        .bodies
        .iter()
        .enumerate()
        .filter(|(i, _)| is_grain(*i))
    {
        let w = rect.disk_fraction(&b.position, b.radius);
        if w == 0.0 {
            continue;
        }
        w_all += w;
        z_all += w * all[i] as f64;
        if !rattler[i] {
            w_nr += w;
            z_nr += w * kept[i] as f64;
        }
    }
    if w_all == 0.0 {
        return Err(HomogeniseError::EmptyRegion("contains no grain".into()));
    }
    Ok(Coordination {
        grains: w_all,
        z: z_all / w_all,
        z_without_rattlers: if w_nr > 0.0 { z_nr / w_nr } else { 0.0 },
        rattler_fraction: (w_all - w_nr) / w_all,
    })
}

/// Fabric tensor of the force-carrying contacts whose point lies in the region.
pub fn fabric(snapshot: &Snapshot, region: &Region, counting: &ContactCounting) -> Result<Fabric> {
    check_snapshot(snapshot)?;
    check_counting(counting)?;
    let rect = region.resolve(snapshot)?;
    let is_grain = |i: u32| snapshot.bodies[i as usize].kind == BodyKind::Grain;
    let mut f = Tensor::zeros();
    let mut nc = 0usize;
    for c in &snapshot.contacts {
        if c.force_n <= counting.force_threshold || !rect.contains(&c.point) {
            continue;
        }
        let bulk = is_grain(c.body_a) && is_grain(c.body_b);
        if !bulk && !counting.count_wall_contacts {
            continue;
        }
        f += outer(&c.normal, &c.normal);
        nc += 1;
    }
    if nc == 0 {
        return Ok(Fabric {
            tensor: f,
            contacts: 0,
            anisotropy: 0.0,
            major_angle: 0.0,
        });
    }
    let f = f / nc as f64;
    let diff = f[(0, 0)] - f[(1, 1)];
    let off = 0.5 * (f[(0, 1)] + f[(1, 0)]);
    let anisotropy = (diff * diff + 4.0 * off * off).sqrt() * 2.0 / f.trace();
    let major_angle = (0.5 * (2.0 * off).atan2(diff)).rem_euclid(std::f64::consts::PI);
    Ok(Fabric {
        tensor: f,
        contacts: nc,
        anisotropy,
        major_angle,
    })
}
