//! Shapes attached to bodies: disks (grains, glued disks of rough walls), lines and segments.

use crate::math::Vector;
use serde::{Deserialize, Serialize};

/// A shape in its body's frame (rotated by the body's angle, translated by its position).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// A disk of radius `radius` (m) centred at `offset` from the body's centre.
    Disk {
        /// Radius (m).
        radius: f64,
        /// Centre relative to the body's centre, body frame (m).
        offset: Vector,
    },
    /// An infinite line through `point` with unit `normal` pointing to the grains' side: a
    /// one-sided wall, gap `g = (c − p)·n − R` for a disk of centre c.
    Line {
        /// A point of the line, body frame (m).
        point: Vector,
        /// Unit normal towards the grains, body frame.
        normal: Vector,
    },
    /// A segment from `a` to `b` (two-sided, rounded ends of radius 0), body frame (m).
    Segment {
        /// First end (m).
        a: Vector,
        /// Second end (m).
        b: Vector,
    },
}

/// A shape attached to a body, with a material index into the contact-law table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Collider {
    /// Index of the body.
    pub body: u32,
    /// Geometry in the body frame.
    pub shape: Shape,
    /// Material index (see [`crate::material::ContactLaws`]).
    pub material: u16,
}

/// Rotation of `v` by `angle` (rad).
#[inline]
pub fn rotate(v: Vector, angle: f64) -> Vector {
    // A disk centred on its body (the common case) has a zero offset: no sin/cos per pair.
    if angle == 0.0 || (v.x == 0.0 && v.y == 0.0) {
        return v;
    }
    let (s, c) = angle.sin_cos();
    Vector::new(c * v.x - s * v.y, s * v.x + c * v.y)
}
