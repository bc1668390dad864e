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

/// A rigid body. Geometry lives in the colliders attached to it (`collider.rs`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Body {
    /// Grain or wall.
    pub kind: BodyKind,
    /// Name (walls); empty for grains.
    pub name: String,
    /// Centre of mass (m).
    pub position: Vector,
    /// Rotation angle (rad, counter-clockwise).
    pub angle: f64,
    /// Velocity (m/s).
    pub velocity: Vector,
    /// Angular velocity (rad/s).
    pub omega: f64,
    /// Mass (kg); `m = ρ π R² · thickness` for a disk; infinite for a fixed wall.
    #[serde(with = "crate::serde_float")]
    pub mass: f64,
    /// Moment of inertia about the centre (kg·m²); `I = m R² / 2` for a disk.
    #[serde(with = "crate::serde_float")]
    pub inertia: f64,
    /// Disk radius (m) for grains, 0 otherwise.
    pub radius: f64,
    /// Density (kg/m³) for grains, 0 otherwise.
    pub density: f64,
    /// Thickness along z (m).
    pub thickness: f64,
    /// Control of x, y, rotation.
    pub dofs: [Dof; 3],
    /// Constant applied force (N) on free degrees of freedom, besides gravity (e.g. a
    /// pressure-controlled platen).
    pub applied_force: Vector,
    /// Constant applied torque (N·m).
    pub applied_torque: f64,
    /// Whether gravity acts on the free degrees of freedom of this body.
    pub gravity: bool,
    /// Mean acceleration over the last step (m/s²), `(v⁺ − v⁻)/h`.
    pub acceleration: Vector,
    /// Mean angular acceleration over the last step (rad/s²).
    pub angular_acceleration: f64,
}

impl Body {
    /// A free disk grain at rest: `m = ρ π R² t`, `I = m R² / 2`.
    pub fn disk(position: Vector, radius: f64, density: f64, thickness: f64) -> Self {
        let mass = density * std::f64::consts::PI * radius * radius * thickness;
        Body {
            kind: BodyKind::Grain,
            name: String::new(),
            position,
            angle: 0.0,
            velocity: Vector::zeros(),
            omega: 0.0,
            mass,
            inertia: 0.5 * mass * radius * radius,
            radius,
            density,
            thickness,
            dofs: [Dof::Free; 3],
            applied_force: Vector::zeros(),
            applied_torque: 0.0,
            gravity: true,
            acceleration: Vector::zeros(),
            angular_acceleration: 0.0,
        }
    }

    /// A wall body whose motion is fully imposed (velocity `velocity`, no rotation).
    pub fn wall(name: &str, position: Vector, velocity: Vector) -> Self {
        Body {
            kind: BodyKind::Wall,
            name: name.to_string(),
            position,
            angle: 0.0,
            velocity,
            omega: 0.0,
            mass: f64::INFINITY,
            inertia: f64::INFINITY,
            radius: 0.0,
            density: 0.0,
            thickness: 1.0,
            dofs: [Dof::Imposed; 3],
            applied_force: Vector::zeros(),
            applied_torque: 0.0,
            gravity: false,
            acceleration: Vector::zeros(),
            angular_acceleration: 0.0,
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
        BodyState {
            kind: b.kind,
            name: b.name.clone(),
            position: b.position,
            angle: b.angle,
            velocity: b.velocity,
            omega: b.omega,
            acceleration: b.acceleration,
            angular_acceleration: b.angular_acceleration,
            mass: b.mass,
            inertia: b.inertia,
            radius: b.radius,
            density: b.density,
            thickness: b.thickness,
        }
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
