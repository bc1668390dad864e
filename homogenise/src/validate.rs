//! Checks on a snapshot before it is homogenised: every later computation may then assume
//! finite numbers, valid indices and grains with positive radius, mass, inertia and thickness.

use dem::math::Vector;
use dem::snapshot::{BodyKind, Snapshot};

use crate::error::{HomogeniseError, Result};

fn finite_vec(v: &Vector) -> bool {
    v.x.is_finite() && v.y.is_finite()
}

/// The unit vector `n / |n|` of the parameter `normal`; an error when `n` is not a finite
/// non-zero vector.
pub(crate) fn unit_normal(n: Vector) -> Result<Vector> {
    let nn = n.norm();
    if !(nn.is_finite() && nn > 0.0) {
        return Err(HomogeniseError::InvalidParameter {
            name: "normal",
            reason: "must be a finite non-zero vector".into(),
        });
    }
    Ok(n / nn)
}

/// Checks the snapshot: finite time step and gravity; grains with finite kinematics and
/// positive finite radius, mass, moment of inertia and thickness; contacts with body indices in
/// range, a unit normal, finite forces, levers and friction coefficient.
pub fn check_snapshot(snapshot: &Snapshot) -> Result<()> {
    if !snapshot.dt.is_finite() || snapshot.dt <= 0.0 {
        return Err(HomogeniseError::InvalidParameter {
            name: "dt",
            reason: format!("time step must be finite and > 0, got {}", snapshot.dt),
        });
    }
    if !finite_vec(&snapshot.gravity) {
        return Err(HomogeniseError::InvalidParameter {
            name: "gravity",
            reason: "must be finite".into(),
        });
    }
    if let Some([a, b]) = snapshot.periodic_x {
        if !(a.is_finite() && b.is_finite() && b > a) {
            return Err(HomogeniseError::InvalidParameter {
                name: "periodic_x",
                reason: format!("needs finite x_min < x_max, got [{a}, {b})"),
            });
        }
    }
    for (index, b) in snapshot.bodies.iter().enumerate() {
        let bad = |reason: &str| HomogeniseError::InvalidBody {
            index,
            reason: reason.to_string(),
        };
        if !(finite_vec(&b.position) && finite_vec(&b.velocity) && b.omega.is_finite()) {
            return Err(bad("non-finite position or velocity"));
        }
        if b.kind == BodyKind::Grain {
            if !(finite_vec(&b.acceleration) && b.angular_acceleration.is_finite()) {
                return Err(bad("non-finite acceleration"));
            }
            for (what, v) in [
                ("radius", b.radius),
                ("mass", b.mass),
                ("inertia", b.inertia),
                ("thickness", b.thickness),
            ] {
                if !(v.is_finite() && v > 0.0) {
                    return Err(bad(&format!(
                        "grain {what} must be finite and > 0, got {v}"
                    )));
                }
            }
        }
    }
    let n = snapshot.bodies.len();
    for (index, c) in snapshot.contacts.iter().enumerate() {
        let bad = |reason: String| HomogeniseError::InvalidContact { index, reason };
        if c.body_a as usize >= n || c.body_b as usize >= n {
            return Err(bad(format!(
                "body index out of range ({}, {}) for {n} bodies",
                c.body_a, c.body_b
            )));
        }
        if c.body_a == c.body_b {
            return Err(bad("a body in contact with itself".into()));
        }
        if !(finite_vec(&c.point)
            && finite_vec(&c.normal)
            && finite_vec(&c.lever_a)
            && finite_vec(&c.lever_b)
            && c.force_n.is_finite()
            && c.force_t.is_finite()
            && c.mu.is_finite())
        {
            return Err(bad("non-finite value".into()));
        }
        if (c.normal.norm() - 1.0).abs() > 1e-6 {
            return Err(bad(format!(
                "normal is not unit (|n| = {})",
                c.normal.norm()
            )));
        }
    }
    for w in &snapshot.walls {
        if w.body as usize >= n {
            return Err(HomogeniseError::InvalidParameter {
                name: "walls",
                reason: format!("wall `{}` refers to body {} of {n}", w.name, w.body),
            });
        }
    }
    Ok(())
}
