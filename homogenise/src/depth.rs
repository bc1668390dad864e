//! Depth below a free surface, and bins of depth, for profiles along walls and columns.
//!
//! `depth(x) = (x − s) · e_down`, with `e_down` a unit vector (down the column: along gravity)
//! and `s` a point at depth 0 (the free surface). Bin `k` holds depths in `[k Δ, (k+1) Δ)`.

use dem::math::Vector;
use dem::snapshot::{BodyKind, Snapshot};
use serde::{Deserialize, Serialize};

use crate::error::{positive, HomogeniseError, Result};

/// The depth coordinate `depth(x) = (x − surface) · down` (m).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DepthAxis {
    /// Unit vector pointing to increasing depth.
    pub down: Vector,
    /// A point at depth 0 (m).
    pub surface: Vector,
}

impl DepthAxis {
    /// An axis along `down` (normalised) with depth 0 at `surface`.
    pub fn new(down: Vector, surface: Vector) -> Result<Self> {
        let n = down.norm();
        if !(n.is_finite() && n > 0.0 && surface.x.is_finite() && surface.y.is_finite()) {
            return Err(HomogeniseError::InvalidParameter {
                name: "down",
                reason: "needs a finite non-zero direction and a finite surface point".into(),
            });
        }
        Ok(Self {
            down: down / n,
            surface,
        })
    }

    /// Depth along gravity below the highest grain top: `down = g/|g|`, depth 0 at
    /// `max_p (−c_p · down + R_p)` (the free surface of a column at rest). Fails without
    /// gravity or grains.
    pub fn from_gravity(snapshot: &Snapshot) -> Result<Self> {
        let g = snapshot.gravity;
        let n = g.norm();
        if !(n.is_finite() && n > 0.0) {
            return Err(HomogeniseError::InvalidParameter {
                name: "gravity",
                reason: "depth along gravity needs a non-zero gravity".into(),
            });
        }
        let down = g / n;
        let top = snapshot
            .bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Grain)
            .map(|b| b.position.dot(&down) - b.radius)
            .fold(f64::INFINITY, f64::min);
        if !top.is_finite() {
            return Err(HomogeniseError::EmptyRegion(
                "no grains: no free surface".into(),
            ));
        }
        Ok(Self {
            down,
            surface: down * top,
        })
    }

    /// Depth of a point (m).
    pub fn depth(&self, x: &Vector) -> f64 {
        (x - self.surface).dot(&self.down)
    }

    /// The point on the axis through `surface` at the given depth (m).
    pub fn point_at(&self, depth: f64) -> Vector {
        self.surface + self.down * depth
    }
}

/// Equal bins of depth: bin `k` is `[k width, (k+1) width)`, `k < count`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DepthBins {
    /// The depth coordinate.
    pub axis: DepthAxis,
    /// Bin width Δ (m).
    pub width: f64,
    /// Number of bins.
    pub count: usize,
}

impl DepthBins {
    /// Checks the width and count.
    pub fn new(axis: DepthAxis, width: f64, count: usize) -> Result<Self> {
        positive("width", width)?;
        if count == 0 {
            return Err(HomogeniseError::InvalidParameter {
                name: "count",
                reason: "needs at least one bin".into(),
            });
        }
        Ok(Self { axis, width, count })
    }

    /// Bin index of a point, `None` outside `[0, count · width)`.
    pub fn bin_of(&self, x: &Vector) -> Option<usize> {
        let d = self.axis.depth(x) / self.width;
        (d >= 0.0 && d < self.count as f64).then(|| (d.floor() as usize).min(self.count - 1))
    }

    /// Bounds `[depth_min, depth_max)` of bin `k` (m).
    pub fn bounds(&self, k: usize) -> (f64, f64) {
        (k as f64 * self.width, (k + 1) as f64 * self.width)
    }
}
