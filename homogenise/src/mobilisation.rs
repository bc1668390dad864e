//! Mobilisation of friction at contacts, `m = |f_t| / (μ f_n)` ∈ [0, 1] (force polarisation):
//! per contact, histograms, and the share of contacts at the Coulomb limit `m ≥ 0.99`, overall
//! and by depth, for wall contacts and bulk (grain–grain) contacts.
//! Contacts without normal force or friction (`f_n = 0` or `μ = 0`) have no mobilisation and
//! are left out.

use dem::snapshot::{BodyKind, ContactState, Snapshot};
use serde::{Deserialize, Serialize};

use crate::depth::DepthBins;
use crate::error::{HomogeniseError, Result};
use crate::validate::check_snapshot;

/// Threshold of the Coulomb limit used by default: `m ≥ 0.99` counts as sliding.
pub const COULOMB_LIMIT: f64 = 0.99;

/// Which contacts a statistic runs over.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum ContactClass {
    /// Contacts between a grain and any wall.
    Wall,
    /// Contacts between a grain and the wall of that name.
    WallNamed(String),
    /// Contacts between a grain and any of the walls of these names.
    WallsNamed(Vec<String>),
    /// Contacts between two grains.
    Bulk,
    /// All contacts.
    All,
}

/// A histogram on `[lo, hi]`: equal bins, the last one closed on the right.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Histogram {
    /// Bin edges (`bins + 1` values).
    pub edges: Vec<f64>,
    /// Counts per bin.
    pub counts: Vec<u64>,
}

impl Histogram {
    /// Histogram of `values` on `[lo, hi]` with `bins` equal bins; values outside are ignored.
    pub fn new(values: &[f64], lo: f64, hi: f64, bins: usize) -> Result<Self> {
        if bins == 0 || !(lo.is_finite() && hi.is_finite() && hi > lo) {
            return Err(HomogeniseError::InvalidParameter {
                name: "bins",
                reason: format!("needs bins ≥ 1 and finite lo < hi, got {bins} on [{lo}, {hi}]"),
            });
        }
        let edges = (0..=bins)
            .map(|k| lo + (hi - lo) * k as f64 / bins as f64)
            .collect();
        let mut counts = vec![0u64; bins];
        for &v in values {
            if v >= lo && v <= hi {
                let k = (((v - lo) / (hi - lo)) * bins as f64).floor() as usize;
                counts[k.min(bins - 1)] += 1;
            }
        }
        Ok(Self { edges, counts })
    }

    /// Share of the counted values in each bin (sums to 1 when any value was counted).
    pub fn fractions(&self) -> Vec<f64> {
        let total: u64 = self.counts.iter().sum();
        self.counts
            .iter()
            .map(|&c| {
                if total > 0 {
                    c as f64 / total as f64
                } else {
                    0.0
                }
            })
            .collect()
    }
}

/// Statistics of mobilisations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MobilisationStats {
    /// Number of contacts with a mobilisation.
    pub contacts: usize,
    /// Mean mobilisation; `None` without contacts.
    pub mean: Option<f64>,
    /// Threshold used for the Coulomb limit.
    pub limit: f64,
    /// Number of contacts with `m ≥ limit`.
    pub at_limit: usize,
    /// Share of contacts with `m ≥ limit`; `None` without contacts.
    pub fraction_at_limit: Option<f64>,
    /// Histogram of `m` on `[0, 1]`.
    pub histogram: Histogram,
}

/// Statistics of the mobilisations `values` (each in [0, 1]) with `bins` histogram bins and
/// the Coulomb limit `limit` (usually [`COULOMB_LIMIT`]).
pub fn mobilisation_stats(values: &[f64], bins: usize, limit: f64) -> Result<MobilisationStats> {
    if !(limit.is_finite() && limit > 0.0 && limit <= 1.0) {
        return Err(HomogeniseError::InvalidParameter {
            name: "limit",
            reason: format!("must be in (0, 1], got {limit}"),
        });
    }
    let histogram = Histogram::new(values, 0.0, 1.0, bins)?;
    let n = values.len();
    let at_limit = values.iter().filter(|&&m| m >= limit).count();
    Ok(MobilisationStats {
        contacts: n,
        mean: (n > 0).then(|| values.iter().sum::<f64>() / n as f64),
        limit,
        at_limit,
        fraction_at_limit: (n > 0).then(|| at_limit as f64 / n as f64),
        histogram,
    })
}

/// Whether a contact belongs to the class.
pub(crate) fn in_class(snapshot: &Snapshot, c: &ContactState, class: &ContactClass) -> bool {
    let grain = |i: u32| snapshot.bodies[i as usize].kind == BodyKind::Grain;
    match class {
        ContactClass::All => true,
        ContactClass::Bulk => grain(c.body_a) && grain(c.body_b),
        ContactClass::Wall => grain(c.body_a) != grain(c.body_b),
        ContactClass::WallNamed(name) => snapshot
            .walls
            .iter()
            .filter(|w| &w.name == name)
            .any(|w| w.body == c.body_a || w.body == c.body_b),
        ContactClass::WallsNamed(names) => snapshot
            .walls
            .iter()
            .filter(|w| names.contains(&w.name))
            .any(|w| w.body == c.body_a || w.body == c.body_b),
    }
}

/// Mobilisation `m = |f_t|/(μ f_n)` of every contact of the class that has one, with the
/// contact's index: `(index, m)`. Fails on an unknown wall name.
pub fn contact_mobilisations(
    snapshot: &Snapshot,
    class: &ContactClass,
) -> Result<Vec<(usize, f64)>> {
    check_snapshot(snapshot)?;
    let names: &[String] = match class {
        ContactClass::WallNamed(name) => std::slice::from_ref(name),
        ContactClass::WallsNamed(names) => names,
        _ => &[],
    };
    for name in names {
        if !snapshot.walls.iter().any(|w| &w.name == name) {
            return Err(HomogeniseError::UnknownWall(name.clone()));
        }
    }
    Ok(snapshot
        .contacts
        .iter()
        .enumerate()
        .filter(|(_, c)| in_class(snapshot, c, class))
        .filter_map(|(i, c)| c.mobilisation().map(|m| (i, m)))
        .collect())
}

/// Share of contacts at the Coulomb limit (`m ≥ limit`) by depth bin of the contact point,
/// for the contacts of the class: `None` for a bin without contact.
pub fn fraction_at_limit_by_depth(
    snapshot: &Snapshot,
    class: &ContactClass,
    bins: &DepthBins,
    limit: f64,
) -> Result<Vec<Option<f64>>> {
    let ms = contact_mobilisations(snapshot, class)?;
    let (mut n, mut k) = (vec![0usize; bins.count], vec![0usize; bins.count]);
    for (i, m) in ms {
        if let Some(b) = bins.bin_of(&snapshot.contacts[i].point) {
            n[b] += 1;
            if m >= limit {
                k[b] += 1;
            }
        }
    }
    Ok(n.iter()
        .zip(&k)
        .map(|(&n, &k)| (n > 0).then(|| k as f64 / n as f64))
        .collect())
}
