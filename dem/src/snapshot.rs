//! The state of a simulation after one step, as plain data: what the later stages
//! (homogenisation, output) read. Produced by `World::snapshot`; serialisable.
//!
//! Units: SI. Positions in m, velocities in m/s, angles in rad, forces in N (for the body's
//! thickness along z), masses in kg, areas in m², volumes in m³.
//! A contact force is the step's impulse divided by the time step, `f = R / h`.

use crate::math::Vector;
use serde::{Deserialize, Serialize};

use crate::local::ContactStatus;

/// What a body is, for the stages that treat grains and boundaries differently.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum BodyKind {
    /// A free rigid disk (a grain).
    Grain,
    /// A boundary: a line or segment wall, or a rigid clump of glued disks (rough wall), fixed,
    /// driven at an imposed velocity, or controlled per degree of freedom.
    Wall,
}

/// One body after a step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodyState {
    /// What the body is.
    pub kind: BodyKind,
    /// Name given in the scenario (walls: `left`, `right`, `bottom`, ...); empty for grains.
    pub name: String,
    /// Centre of mass (m). Inside the periodic cell when the x direction is periodic.
    pub position: Vector,
    /// Rotation angle (rad, counter-clockwise).
    pub angle: f64,
    /// Velocity of the centre after the step, `v⁺` (m/s).
    pub velocity: Vector,
    /// Angular velocity after the step, `ω⁺` (rad/s).
    pub omega: f64,
    /// Mean acceleration over the step, `(v⁺ − v⁻)/h` (m/s²), consistent with the impulses.
    pub acceleration: Vector,
    /// Mean angular acceleration over the step, `(ω⁺ − ω⁻)/h` (rad/s²).
    pub angular_acceleration: f64,
    /// Mass (kg); `m = ρ π R² · thickness` for a disk; `f64::INFINITY` for a wall whose motion is
    /// imposed.
    #[serde(with = "crate::serde_float")]
    pub mass: f64,
    /// Moment of inertia about the centre (kg·m²); `I = m R²/2` for a disk.
    #[serde(with = "crate::serde_float")]
    pub inertia: f64,
    /// Disk radius (m) for grains; 0 for walls.
    pub radius: f64,
    /// Material density (kg/m³); 0 for walls.
    pub density: f64,
    /// Thickness along z (m), 1 by default: a disk stands for a cylinder.
    pub thickness: f64,
}

impl BodyState {
    /// A disk grain at rest: `m = ρ π R² t`, `I = m R² / 2`.
    pub fn disk(position: Vector, radius: f64, density: f64, thickness: f64) -> Self {
        let mass = density * std::f64::consts::PI * radius * radius * thickness;
        BodyState {
            kind: BodyKind::Grain,
            name: String::new(),
            position,
            angle: 0.0,
            velocity: Vector::zeros(),
            omega: 0.0,
            acceleration: Vector::zeros(),
            angular_acceleration: 0.0,
            mass,
            inertia: 0.5 * mass * radius * radius,
            radius,
            density,
            thickness,
        }
    }

    /// A wall whose motion is imposed (infinite mass and inertia), moving at `velocity`
    /// without rotation, thickness 1.
    pub fn wall(name: &str, position: Vector, velocity: Vector) -> Self {
        BodyState {
            kind: BodyKind::Wall,
            name: name.to_string(),
            position,
            angle: 0.0,
            velocity,
            omega: 0.0,
            acceleration: Vector::zeros(),
            angular_acceleration: 0.0,
            mass: f64::INFINITY,
            inertia: f64::INFINITY,
            radius: 0.0,
            density: 0.0,
            thickness: 1.0,
        }
    }

    /// Volume of a grain, `V_p = π R² · thickness` (m³); 0 for walls.
    pub fn volume(&self) -> f64 {
        std::f64::consts::PI * self.radius * self.radius * self.thickness
    }
}

/// One contact after a step. The normal `n` points from body `a` to body `b`, the tangent is
/// `t = (−n_y, n_x)`. The force on `b` is `f_n n + f_t t`; `a` receives the opposite.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactState {
    /// Index of body `a` in [`Snapshot::bodies`].
    pub body_a: u32,
    /// Index of body `b` in [`Snapshot::bodies`] (always a grain or clump disk).
    pub body_b: u32,
    /// Contact point (m): on the surface of `b`, `x = c_b − R_b n` for a disk `b`.
    /// With a periodic x direction, the point is given near body `b`.
    pub point: Vector,
    /// Unit normal from `a` to `b`.
    pub normal: Vector,
    /// Normal force (N), `r_n / h ≥ 0`.
    pub force_n: f64,
    /// Tangential force (N), `r_t / h`, `|f_t| ≤ μ f_n`.
    pub force_t: f64,
    /// Gap at the start of the step (m); negative when the bodies overlap.
    pub gap: f64,
    /// Friction coefficient of the contact.
    pub mu: f64,
    /// Outcome of the local law.
    pub status: ContactStatus,
    /// Lever arm of the contact point from the centre of `a`, `x − c_a` (m). Walls that are
    /// lines have their reference point as centre.
    pub lever_a: Vector,
    /// Lever arm of the contact point from the centre of `b`, `x − c_b` (m).
    pub lever_b: Vector,
}

impl ContactState {
    /// Unit tangent `t = (−n_y, n_x)`.
    pub fn tangent(&self) -> Vector {
        Vector::new(-self.normal.y, self.normal.x)
    }

    /// Force vector on body `b` (N): `f_n n + f_t t`.
    pub fn force_on_b(&self) -> Vector {
        self.normal * self.force_n + self.tangent() * self.force_t
    }

    /// Mobilisation of friction `m = |f_t| / (μ f_n)` ∈ [0, 1]; `None` when the contact carries
    /// no normal force or is frictionless.
    pub fn mobilisation(&self) -> Option<f64> {
        if self.force_n > 0.0 && self.mu > 0.0 {
            Some((self.force_t.abs() / (self.mu * self.force_n)).min(1.0))
        } else {
            None
        }
    }
}

/// Geometry of a wall, for wall profiles (stress by depth along the wall).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum WallGeometry {
    /// Infinite line through `point` with unit `normal` pointing into the sample.
    Line {
        /// A point of the line (m).
        point: Vector,
        /// Unit normal pointing to the side where grains are.
        normal: Vector,
    },
    /// Segment from `a` to `b`; grains may touch either side or the ends.
    Segment {
        /// First end (m).
        a: Vector,
        /// Second end (m).
        b: Vector,
    },
    /// A rigid clump of glued disks (rough wall): centres (m) and radii (m).
    Clump {
        /// Disk centres in world coordinates (m).
        centres: Vec<Vector>,
        /// Disk radii (m).
        radii: Vec<f64>,
    },
}

/// A wall after a step: which body it is, its geometry and the total force it received.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WallState {
    /// Index of the wall's body in [`Snapshot::bodies`].
    pub body: u32,
    /// Name given in the scenario.
    pub name: String,
    /// Geometry in world coordinates.
    pub geometry: WallGeometry,
    /// Total contact force received during the step (N), sum of `R/h` over its contacts.
    pub force: Vector,
    /// Total contact torque about the body's centre (N·m).
    pub torque: f64,
}

/// Everything the later stages need from one step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Step index (0 before the first step).
    pub step: u64,
    /// Time at the end of the step (s).
    pub time: f64,
    /// Time step h (s).
    pub dt: f64,
    /// Gravity vector (m/s²).
    pub gravity: Vector,
    /// Periodic cell along x, `[x_min, x_max)` (m), if any.
    pub periodic_x: Option<[f64; 2]>,
    /// Biperiodic deformable cell (matrix `h`, velocity gradient `L`), if any
    /// ([`crate::cell`]): grain positions are then inside it, velocities are total velocities
    /// (affine field `L (x − c)` included), and contact points are given near body `b`.
    #[serde(default)]
    pub cell: Option<crate::cell::Cell>,
    /// All bodies, grains and walls, in the world's order.
    pub bodies: Vec<BodyState>,
    /// Contacts of the step (including open ones, with zero force).
    pub contacts: Vec<ContactState>,
    /// The walls.
    pub walls: Vec<WallState>,
}
