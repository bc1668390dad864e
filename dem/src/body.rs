//! Rigid bodies: grains (disks) and walls, with per-degree-of-freedom control.

use crate::math::{Spatial, Vector};
use serde::{Deserialize, Serialize};

pub use crate::snapshot::BodyKind;
use crate::snapshot::BodyState;

/// How one degree of freedom (x, y or rotation) of a body moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Dof {
    /// Moves under gravity, applied loads and contact impulses: `m v⁺ = m v⁻ + h f + Hᵀ R`.
    Free,
    /// The velocity component is imposed (kept at the body's current value): infinite mass for
    /// contacts. A fixed wall has all three imposed at zero.
    Imposed,
}

/// A rigid body: its state (what a snapshot shows of it, [`BodyState`]: kind, name, position,
/// angle, velocities, accelerations, mass, inertia, radius, density, thickness), whose fields
/// it shows as its own (`body.position`, through `Deref`), and its control (degrees of
/// freedom, applied loads, gravity). Geometry lives in the colliders attached to it
/// (`collider.rs`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Body {
    /// The body's state (serialised with the body's own fields, flat).
    #[serde(flatten)]
    pub state: BodyState,
    /// Control of x, y, rotation.
    pub dofs: [Dof; 3],
    /// Constant applied force (N) on free degrees of freedom, besides gravity (e.g. a
    /// pressure-controlled platen).
    pub applied_force: Vector,
    /// Constant applied torque (N·m).
    pub applied_torque: f64,
    /// Whether gravity acts on the free degrees of freedom of this body.
    pub gravity: bool,
}

impl std::ops::Deref for Body {
    type Target = BodyState;

    #[inline]
    fn deref(&self) -> &BodyState {
        &self.state
    }
}

impl std::ops::DerefMut for Body {
    #[inline]
    fn deref_mut(&mut self) -> &mut BodyState {
        &mut self.state
    }
}

impl Body {
    /// A free disk grain at rest: `m = ρ π R² t`, `I = m R² / 2`.
    pub fn disk(position: Vector, radius: f64, density: f64, thickness: f64) -> Self {
        Body {
            state: BodyState::disk(position, radius, density, thickness),
            dofs: [Dof::Free; 3],
            applied_force: Vector::zeros(),
            applied_torque: 0.0,
            gravity: true,
        }
    }

    /// A wall body whose motion is fully imposed (velocity `velocity`, no rotation).
    pub fn wall(name: &str, position: Vector, velocity: Vector) -> Self {
        Body {
            state: BodyState::wall(name, position, velocity),
            dofs: [Dof::Imposed; 3],
            applied_force: Vector::zeros(),
            applied_torque: 0.0,
            gravity: false,
        }
    }

    /// Inverse mass per degree of freedom `(1/m, 1/m, 1/I)`, zero where the motion is imposed.
    #[inline]
    pub fn inverse_mass(&self) -> Spatial {
        let inv = |d: Dof, m: f64| {
            if d == Dof::Free && m > 0.0 {
                1.0 / m
            } else {
                0.0
            }
        };
        [
            inv(self.dofs[0], self.mass),
            inv(self.dofs[1], self.mass),
            inv(self.dofs[2], self.inertia),
        ]
    }

    /// True when no degree of freedom is free (contacts between two such bodies are skipped).
    #[inline]
    pub fn is_kinematic(&self) -> bool {
        self.dofs.iter().all(|d| *d == Dof::Imposed)
    }

    /// Kinetic energy `½ m |v|² + ½ I ω²` over the free degrees of freedom (J).
    pub fn kinetic_energy(&self) -> f64 {
        let mut e = 0.0;
        if self.dofs[0] == Dof::Free {
            e += 0.5 * self.mass * self.velocity.x * self.velocity.x;
        }
        if self.dofs[1] == Dof::Free {
            e += 0.5 * self.mass * self.velocity.y * self.velocity.y;
        }
        if self.dofs[2] == Dof::Free {
            e += 0.5 * self.inertia * self.omega * self.omega;
        }
        e
    }
}

impl From<&Body> for BodyState {
    /// The body as a snapshot shows it: its state after a step, without its control (degrees
    /// of freedom, applied loads, gravity switch).
    fn from(b: &Body) -> Self {
        b.state.clone()
    }
}

/// Gravity `g` (if it acts on the body) plus the applied force and torque, `(f_x, f_y, torque)`.
pub fn external_loads(b: &Body, g: Vector) -> Spatial {
    let grav = if b.gravity {
        g * b.mass
    } else {
        Vector::zeros()
    };
    [
        grav.x + b.applied_force.x,
        grav.y + b.applied_force.y,
        b.applied_torque,
    ]
}
