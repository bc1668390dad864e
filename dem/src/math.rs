//! The dimension layer: the names under which the code writes a scalar, a vector, a point, an
//! angular quantity, a rotation, a second-order tensor and a rigid-body velocity (a twist).
//!
//! Code outside this module writes [`Vector`], [`Tensor`], [`Twist`], … and never
//! `Vector2<f64>`, `Matrix2<f64>` or a bare `[f64; 3]` meaning `(v_x, v_y, ω)`; the dimension
//! then lives here only. This is the layout of rapier and parry (their `math` module), where one
//! source builds `rapier2d` and `rapier3d`.
//!
//! **Today: 2D only.** Every alias below is the plane one.
//!
//! **How a 3D build would swap them** (none of it exists yet). A `dim3` cargo feature would
//! select a second set of definitions, `#[cfg(feature = "dim3")]`, beside these
//! (`#[cfg(not(feature = "dim3"))]` in front of the present ones):
//!
//! | name | 2D (now) | 3D |
//! |---|---|---|
//! | [`DIM`] | 2 | 3 |
//! | [`ANG_DIM`] | 1 (ω about e_z) | 3 |
//! | [`Vector`] | `SVector<Real, 2>` | `SVector<Real, 3>` |
//! | [`Point`] | `Point2<Real>` | `Point3<Real>` |
//! | [`AngVector`] | `Real` (ω_z) | `SVector<Real, 3>` |
//! | [`Rotation`] | `UnitComplex<Real>` | `UnitQuaternion<Real>` |
//! | [`Tensor`], [`SymTensor`] | `Matrix2<Real>` | `Matrix3<Real>` |
//! | [`Twist`] | `{ linear: Vector, angular: AngVector }` (3 numbers) | the same struct (6 numbers) |
//!
//! and the few functions whose algebra differs ([`cross`], [`ang_cross`], [`Twist::velocity_at`]
//! through them, [`Twist::kinetic_energy`] with a scalar or a tensor inertia) get a 3D body
//! under the same `cfg`. Code written against these names compiles unchanged in both;
//! code that is 2D by algorithm (the closed-form 2D friction law, Lemke on the polyhedral 2D
//! cone, the plane Mohr circle) says so and stays behind `cfg(not(feature = "dim3"))`.
//! The choice of a feature over generics on a dimension type is argued in
//! `docs/architecture.md` §"Dimension layer".
//!
//! The engine (`dem/src`) is written against these names too: its vectors are [`Vector`]s, the
//! cell's matrices [`Tensor`]s, and the per-body triples of the solver's hot loops (velocities,
//! inverse masses, impulses, displacements) [`Spatial`] arrays.

use nalgebra::{Matrix2, Point2, SVector, UnitComplex};
use serde::{Deserialize, Serialize};

/// The floating-point scalar of every computation (`f64`; rapier lets it be `f32` too).
pub type Real = f64;

/// Space dimension: 2 (plane motion of disks, extruded along z by a thickness).
pub const DIM: usize = 2;

/// Number of rotational degrees of freedom of a body: 1 in the plane (the rotation about e_z),
/// 3 in space.
pub const ANG_DIM: usize = 1;

/// Degrees of freedom of a rigid body, `DIM + ANG_DIM` (the length of a twist, a wrench or an
/// inverse-mass triple: 3 in 2D, 6 in 3D).
pub const SPATIAL_DIM: usize = DIM + ANG_DIM;

/// A rigid body's packed triple of generalised components, `[Real; SPATIAL_DIM]`: `(v_x, v_y, ω)`
/// of a velocity, `(1/m, 1/m, 1/I)` of an inverse mass, `(F_x, F_y, torque)·h` of an impulse, a
/// displacement `(Δx, Δy, Δθ)`. The layout of the solver's hot loops, which keep one per body
/// in flat arrays ([`Twist`] is the named form; [`Twist::from_array`], [`Twist::to_array`]).
/// In 3D the same name is six numbers (`SPATIAL_DIM` = 6).
pub type Spatial = [Real; SPATIAL_DIM];

/// A vector of the space (a position, a velocity, a force, a lever arm, a normal…), in SI
/// units of what it holds. `SVector<Real, DIM>`, the same type as `nalgebra::Vector2<f64>`.
pub type Vector = SVector<Real, DIM>;

/// A point of the space (m), for code that keeps points and vectors apart (parry's `Point`).
/// The project mostly stores positions as [`Vector`]s; `Point::from(v)` and `p.coords` convert
/// without cost.
pub type Point = Point2<Real>;

/// An angular quantity (an angular velocity in rad/s, a torque in N·m, an angle increment):
/// in the plane the single component along e_z, a [`Real`]; a 3-vector in 3D.
pub type AngVector = Real;

/// A rotation of the space: a unit complex number `cos θ + i sin θ` in 2D (a unit quaternion
/// in 3D). `Rotation::new(θ)` turns counter-clockwise by θ (rad); `Rotation::angle()` gives θ
/// back in (−π, π].
pub type Rotation = UnitComplex<Real>;

/// A second-order tensor of the space, `T[(i, j)] = T_ij` (a stress in Pa, tension positive; a
/// velocity gradient in 1/s; a cell matrix in m; a fabric tensor).
pub type Tensor = Matrix2<Real>;

/// A second-order tensor that is symmetric by construction or by the physics (a Cauchy
/// stress, a strain rate, a fabric tensor). The same type as [`Tensor`]: the name states the
/// intent, nothing is enforced (take [`Tensor`]'s symmetric part where it matters).
pub type SymTensor = Tensor;

/// Cross product of two vectors: in the plane the z component `a × b = a_x b_y − a_y b_x`
/// (an [`AngVector`]; a vector in 3D). A torque is `cross(lever, force)`.
#[inline]
pub fn cross(a: &Vector, b: &Vector) -> AngVector {
    a.x * b.y - a.y * b.x
}

/// Cross product of an angular vector with a vector, `ω × r`: in the plane `ω e_z × r =
/// ω (−r_y, r_x)`, the velocity a rotation at rate ω gives to the lever arm `r`.
#[inline]
pub fn ang_cross(w: AngVector, r: &Vector) -> Vector {
    Vector::new(-r.y, r.x) * w
}

/// The velocity of a rigid body, a twist `(v, ω)`: the velocity `v` of its centre of mass (m/s)
/// and its angular velocity `ω` (rad/s, counter-clockwise about e_z in the plane).
///
/// It is the named form of a [`Spatial`] velocity `(v_x, v_y, ω)`, which the engine's hot loops
/// keep packed, one per body, for speed ([`Twist::from_array`] and [`Twist::to_array`] convert
/// exactly). The velocity field of the body is
/// `u(x) = v + ω × (x − c)` ([`Twist::velocity_at`]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Twist {
    /// Velocity of the centre of mass (m/s).
    pub linear: Vector,
    /// Angular velocity (rad/s).
    pub angular: AngVector,
}

impl Twist {
    /// The twist `(linear, angular)`.
    pub fn new(linear: Vector, angular: AngVector) -> Self {
        Self { linear, angular }
    }

    /// The body at rest.
    pub fn zero() -> Self {
        Self::default()
    }

    /// From the engine's packed layout `[v_x, v_y, ω]` (the order of the solver's arrays).
    pub fn from_array(a: [Real; SPATIAL_DIM]) -> Self {
        Self::new(Vector::new(a[0], a[1]), a[2])
    }

    /// To the engine's packed layout `[v_x, v_y, ω]`.
    pub fn to_array(&self) -> [Real; SPATIAL_DIM] {
        [self.linear.x, self.linear.y, self.angular]
    }

    /// Velocity of the material point at lever arm `r = x − c` from the centre of mass:
    /// `u = v + ω × r` (rigid-body kinematics).
    pub fn velocity_at(&self, r: &Vector) -> Vector {
        self.linear + ang_cross(self.angular, r)
    }

    /// Kinetic energy `½ m |v|² + ½ I ω²` (J per the body's thickness along z in 2D) of a body
    /// of mass `m` (kg) and moment of inertia `I` about its centre of mass (kg·m²).
    pub fn kinetic_energy(&self, mass: Real, inertia: Real) -> Real {
        0.5 * mass * self.linear.norm_squared() + 0.5 * inertia * self.angular * self.angular
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aliases_are_the_plane_types() {
        // The dimension layer is the plane nalgebra types.
        let v: nalgebra::Vector2<f64> = Vector::new(1.0, 2.0);
        let t: nalgebra::Matrix2<f64> = Tensor::identity();
        assert_eq!(v.len(), DIM);
        assert_eq!(t.nrows(), DIM);
        assert_eq!(SPATIAL_DIM, 3);
    }

    #[test]
    fn rotation_turns_counter_clockwise() {
        let q = Rotation::new(std::f64::consts::FRAC_PI_2);
        let e = q * Vector::x();
        assert!((e - Vector::y()).norm() < 1e-15, "{e}");
        assert!((Rotation::new(0.3).angle() - 0.3).abs() < 1e-15);
    }

    #[test]
    fn cross_products_are_the_plane_ones() {
        let a = Vector::new(0.3, -1.7);
        let b = Vector::new(2.0, 0.5);
        // a × b = |a| |b| sin(angle from a to b), antisymmetric.
        let sin = a.normalize().perp(&b.normalize());
        assert!((cross(&a, &b) - a.norm() * b.norm() * sin).abs() < 1e-14);
        assert_eq!(cross(&a, &b), -cross(&b, &a));
        // ω × r is r turned a quarter counter-clockwise, scaled by ω.
        let w = 2.5;
        let u = ang_cross(w, &a);
        assert_eq!(u.dot(&a), 0.0);
        assert!((u - Rotation::new(std::f64::consts::FRAC_PI_2) * a * w).norm() < 1e-14);
        // and (r × (ω × r)) = ω |r|²: the angular momentum of a point on a rotating lever.
        assert!((cross(&a, &u) - w * a.norm_squared()).abs() < 1e-14);
    }

    #[test]
    fn twist_gives_the_rigid_velocity_field() {
        let t = Twist::new(Vector::new(1.0, -0.5), 3.0);
        // Rigid motion: the distance between two material points does not change,
        // (u(r₁) − u(r₂)) · (r₁ − r₂) = 0.
        let (r1, r2) = (Vector::new(0.2, 0.7), Vector::new(-1.1, 0.4));
        let du = t.velocity_at(&r1) - t.velocity_at(&r2);
        assert!(du.dot(&(r1 - r2)).abs() < 1e-14);
        assert_eq!(t.velocity_at(&Vector::zeros()), t.linear);
        assert_eq!(Twist::from_array(t.to_array()), t);
        assert_eq!(t.to_array(), [1.0, -0.5, 3.0]);
        assert_eq!(Twist::zero().kinetic_energy(2.0, 3.0), 0.0);
    }

    #[test]
    fn kinetic_energy_of_a_rolling_disk() {
        // A disk rolling without slipping, v = ω R, I = m R²/2: E = ¾ m v².
        let (m, r, v) = (2.0, 0.1, 0.3);
        let t = Twist::new(Vector::new(v, 0.0), -v / r);
        let e = t.kinetic_energy(m, 0.5 * m * r * r);
        assert!((e - 0.75 * m * v * v).abs() < 1e-15 * e);
        // The contact point is at rest.
        assert!(t.velocity_at(&Vector::new(0.0, -r)).norm() < 1e-15);
    }
}
