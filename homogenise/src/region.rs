//! Regions over which grain quantities are averaged: a rectangle, a horizontal slice, or the
//! whole sample.
//!
//! **Grains cut by the border** are counted with the weight `w_p = |D_p ∩ R| / |D_p|`, the exact
//! fraction of the grain's disk area inside the region ([`crate::overlap`]); a grain whole inside
//! has `w_p = 1`. The region mean of a per-grain quantity `Q_p` is `Σ_p w_p A_p Q_p / A_R`, which
//! is the paper's `(1/V) Σ_p V_p Σ_p` when no grain is cut (eq. 9), and is additive: the
//! area-weighted means over a partition of a region give the mean over the whole region.
//! With a periodic x direction the disk's images at `x ± L` are counted too, and a region
//! spanning the whole cell width covers every x.
//!
//! **Biperiodic cells** (`dem::cell`): the whole sample is the cell, of area `det h`; every
//! grain lies in it once (its images are the same grain) and counts whole, `w_p = 1`. A
//! rectangle or slice of a cell whose first edge lies along x (`a₁ = (l_x, 0)`, as in LAMMPS'
//! boxes and the engine's cells) is periodic along x with the period `l_x`.

use dem::math::Vector;
use dem::snapshot::{BodyKind, Snapshot};
use serde::{Deserialize, Serialize};

use crate::error::{finite, HomogeniseError, Result};
use crate::overlap::disk_rectangle_area;

/// A region of the plane, as the user describes it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Region {
    /// The rectangle `[min.x, max.x] × [min.y, max.y]` (m).
    Rectangle {
        /// Lower-left corner (m).
        min: Vector,
        /// Upper-right corner (m).
        max: Vector,
    },
    /// The horizontal slice `y_min ≤ y ≤ y_max` (m) across the sample's width: the periodic
    /// cell when x is periodic, else the grains' extent `[min(x_p − R_p), max(x_p + R_p)]`.
    Slice {
        /// Lower edge (m).
        y_min: f64,
        /// Upper edge (m).
        y_max: f64,
    },
    /// The whole sample: the bounding box of the grains' disks (x: the periodic cell when x is
    /// periodic). In a box whose walls all touch grains this is the box itself. In a
    /// biperiodic cell, the cell (module documentation).
    Whole,
}

/// A region resolved against a snapshot: an axis-aligned rectangle, possibly in a periodic cell.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rect {
    /// Lower-left corner (m).
    pub min: Vector,
    /// Upper-right corner (m).
    pub max: Vector,
    /// Periodic cell along x, `[x_min, x_max)` (m), if any.
    pub periodic_x: Option<[f64; 2]>,
    /// The whole biperiodic cell: its area `det h` (m²). Every grain counts whole in it;
    /// `min`, `max` are then the cell's bounding box.
    pub cell_area: Option<f64>,
}

/// Extent `[min, max]` of the grains' disks along x and y: `(x_lo, x_hi, y_lo, y_hi)`.
pub(crate) fn grain_extent(snapshot: &Snapshot) -> Option<(f64, f64, f64, f64)> {
    let mut ext: Option<(f64, f64, f64, f64)> = None;
    for b in snapshot.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
        let (x0, x1) = (b.position.x - b.radius, b.position.x + b.radius);
        let (y0, y1) = (b.position.y - b.radius, b.position.y + b.radius);
        ext = Some(match ext {
            None => (x0, x1, y0, y1),
            Some((a, bb, c, d)) => (a.min(x0), bb.max(x1), c.min(y0), d.max(y1)),
        });
    }
    ext
}

impl Region {
    /// Resolves the region against a snapshot into a rectangle (m). Fails on non-finite or
    /// inverted bounds, or when `Whole`/`Slice` need grains and there are none.
    pub fn resolve(&self, snapshot: &Snapshot) -> Result<Rect> {
        if let (Region::Whole, Some(cell)) = (self, &snapshot.cell) {
            let h = cell.h;
            let xs = [0.0, h[(0, 0)], h[(0, 1)], h[(0, 0)] + h[(0, 1)]];
            let ys = [0.0, h[(1, 0)], h[(1, 1)], h[(1, 0)] + h[(1, 1)]];
            let lo = |v: &[f64; 4]| v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = |v: &[f64; 4]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            return Ok(Rect {
                min: Vector::new(lo(&xs), lo(&ys)),
                max: Vector::new(hi(&xs), hi(&ys)),
                periodic_x: None,
                cell_area: Some(cell.volume()),
            });
        }
        // a cell whose first edge lies along x is periodic along x with its length
        let periodic_x = snapshot.periodic_x.or_else(|| {
            snapshot
                .cell
                .filter(|c| c.h[(1, 0)] == 0.0)
                .map(|c| [0.0, c.h[(0, 0)]])
        });
        let x_range = || -> Result<(f64, f64)> {
            if let Some([a, b]) = periodic_x {
                return Ok((a, b));
            }
            grain_extent(snapshot)
                .map(|(a, b, _, _)| (a, b))
                .ok_or_else(|| {
                    HomogeniseError::EmptyRegion("needs grains: none in the snapshot".into())
                })
        };
        let (min, max) = match *self {
            Region::Rectangle { min, max } => (min, max),
            Region::Slice { y_min, y_max } => {
                finite("y_min", y_min)?;
                finite("y_max", y_max)?;
                let (a, b) = x_range()?;
                (Vector::new(a, y_min), Vector::new(b, y_max))
            }
            Region::Whole => {
                let (_, _, y0, y1) = grain_extent(snapshot).ok_or_else(|| {
                    HomogeniseError::EmptyRegion("whole sample: no grains".into())
                })?;
                let (a, b) = x_range()?;
                (Vector::new(a, y0), Vector::new(b, y1))
            }
        };
        for (name, v) in [
            ("min.x", min.x),
            ("min.y", min.y),
            ("max.x", max.x),
            ("max.y", max.y),
        ] {
            finite(name, v)?;
        }
        if max.x <= min.x || max.y <= min.y {
            return Err(HomogeniseError::EmptyRegion(format!(
                "[{}, {}] × [{}, {}] has no area",
                min.x, max.x, min.y, max.y
            )));
        }
        Ok(Rect {
            min,
            max,
            periodic_x,
            cell_area: None,
        })
    }
}

impl Rect {
    /// Area of the region (m²), voids included.
    pub fn area(&self) -> f64 {
        self.cell_area
            .unwrap_or((self.max.x - self.min.x) * (self.max.y - self.min.y))
    }

    /// Whether the rectangle covers the whole periodic cell width (then every x is inside).
    fn spans_cell(&self) -> bool {
        matches!(self.periodic_x, Some([a, b]) if self.max.x - self.min.x >= b - a)
    }

    /// `x` mapped by the periodicity into `[min.x, min.x + L)` (unchanged without periodicity).
    fn wrap_x(&self, x: f64) -> f64 {
        match self.periodic_x {
            Some([a, b]) => {
                let l = b - a;
                self.min.x + (x - self.min.x).rem_euclid(l)
            }
            None => x,
        }
    }

    /// Whether the point lies in the region (closed rectangle; periodic in x when the cell is).
    pub fn contains(&self, p: &Vector) -> bool {
        if self.cell_area.is_some() {
            return true;
        }
        if p.y < self.min.y || p.y > self.max.y {
            return false;
        }
        if self.spans_cell() {
            return true;
        }
        let x = self.wrap_x(p.x);
        x >= self.min.x && x <= self.max.x
    }

    /// The x offset of `x` from the region's centre, taking the shortest periodic image:
    /// `x − x_c` mapped into `[−L/2, L/2)` when x is periodic.
    pub fn dx_from_centre(&self, x: f64) -> f64 {
        let xc = 0.5 * (self.min.x + self.max.x);
        match self.periodic_x {
            Some([a, b]) => {
                let l = b - a;
                (x - xc + 0.5 * l).rem_euclid(l) - 0.5 * l
            }
            None => x - xc,
        }
    }

    /// Fraction `w ∈ [0, 1]` of the disk of the given centre and radius inside the region:
    /// `|D ∩ R| / (π R²)`, exact, summed over periodic images.
    pub fn disk_fraction(&self, centre: &Vector, radius: f64) -> f64 {
        if self.cell_area.is_some() {
            return 1.0;
        }
        if radius <= 0.0 {
            return if self.contains(centre) { 1.0 } else { 0.0 };
        }
        let full = std::f64::consts::PI * radius * radius;
        let area = if self.spans_cell() {
            let min = Vector::new(centre.x - 2.0 * radius, self.min.y);
            let max = Vector::new(centre.x + 2.0 * radius, self.max.y);
            disk_rectangle_area(centre, radius, &min, &max)
        } else if let Some([a, b]) = self.periodic_x {
            let l = b - a;
            // the image nearest the region, and its neighbours
            let x0 = self.wrap_x(centre.x);
            (-1..=1)
                .map(|k| {
                    let c = Vector::new(x0 + k as f64 * l, centre.y);
                    disk_rectangle_area(&c, radius, &self.min, &self.max)
                })
                .sum()
        } else {
            disk_rectangle_area(centre, radius, &self.min, &self.max)
        };
        (area / full).clamp(0.0, 1.0)
    }
}
