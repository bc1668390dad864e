//! The 3D skeleton (cargo feature `dim3`): a sphere, its contact frame and the 3D Coulomb cone,
//! as new code implementing the interfaces the 2D engine is written against. It shows where 3D
//! goes; no engine steps it yet (`docs/architecture.md` §"Where 3D goes").
//!
//! - [`math`]: the 3D aliases under the names of `crate::math` (`Real`, `DIM`, `Vector`,
//!   `AngVector`, `Rotation`, `Tensor`), as rapier's `math` module has them for `rapier3d`.
//! - [`Sphere`]: mass and inertia of a homogeneous sphere.
//! - [`ContactFrame`]: the orthonormal frame `(n, t₁, t₂)` of a contact from its normal, in
//!   which impulses and velocities are `(r_n, r_t1, r_t2)`.
//! - [`Delassus3`] and [`Coulomb3`]: the circular cone `‖r_t‖ ≤ μ r_n` as a
//!   [`crate::cone::FrictionCone`]: its projection in closed form, its local solve by the
//!   generic predictor–corrector ([`crate::cone::solve_local_iterated`]). A 3D row plugs into
//!   the sweep the 2D solvers use ([`crate::sweep::SweepRow`], [`crate::sweep::solve_row`]; the
//!   test `the_3d_cone_plugs_into_the_gauss_seidel_sweep`).

use nalgebra::{Matrix3, SVector, UnitQuaternion};

use crate::cone::{ContactStatus, FrictionCone};

/// The 3D dimension layer: the names of `crate::math` bound to their 3D types.
pub mod math {
    use super::*;

    /// The floating-point scalar.
    pub type Real = f64;
    /// Space dimension.
    pub const DIM: usize = 3;
    /// Rotational degrees of freedom of a body.
    pub const ANG_DIM: usize = 3;
    /// A vector of the space (SI units of what it holds).
    pub type Vector = SVector<Real, DIM>;
    /// An angular velocity (rad/s) or a torque (N·m): a 3-vector in space.
    pub type AngVector = SVector<Real, ANG_DIM>;
    /// A rotation of the space: a unit quaternion.
    pub type Rotation = UnitQuaternion<Real>;
    /// A second-order tensor (stress in Pa, tension positive; velocity gradient; inertia).
    pub type Tensor = Matrix3<Real>;
}

use math::{Real, Tensor, Vector};

/// A homogeneous sphere of radius `radius` (m) and density `density` (kg/m³).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Radius (m).
    pub radius: Real,
    /// Density (kg/m³).
    pub density: Real,
}

impl Sphere {
    /// Mass `m = 4/3 π R³ ρ` (kg).
    pub fn mass(&self) -> Real {
        4.0 / 3.0 * std::f64::consts::PI * self.radius.powi(3) * self.density
    }

    /// Inertia tensor about the centre, `I = 2/5 m R² 𝟙` (kg·m²).
    pub fn inertia(&self) -> Tensor {
        Tensor::identity() * (0.4 * self.mass() * self.radius * self.radius)
    }
}

/// The local frame of a contact: its normal `n` (from the first body to the second) and two
/// tangents completing a right-handed orthonormal basis, `t₁ × t₂ = n`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactFrame {
    /// Unit normal.
    pub n: Vector,
    /// First unit tangent.
    pub t1: Vector,
    /// Second unit tangent.
    pub t2: Vector,
}

impl ContactFrame {
    /// The frame of a unit normal `n`, by the branch-free construction of Duff et al.
    /// (*Building an orthonormal basis, revisited*, J. Comput. Graph. Tech. 6 (2017) 1–8),
    /// continuous except where `n_z` changes sign.
    pub fn from_normal(n: Vector) -> Self {
        let sign = 1.0f64.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let t1 = Vector::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t2 = Vector::new(b, sign + n.y * n.y * a, -n.y);
        ContactFrame { n, t1, t2 }
    }

    /// A vector's local components `(v·n, v·t₁, v·t₂)`.
    pub fn to_local(&self, v: Vector) -> [Real; 3] {
        [v.dot(&self.n), v.dot(&self.t1), v.dot(&self.t2)]
    }

    /// The vector of local components `l`: `l₀ n + l₁ t₁ + l₂ t₂`.
    pub fn to_global(&self, l: [Real; 3]) -> Vector {
        self.n * l[0] + self.t1 * l[1] + self.t2 * l[2]
    }
}

/// The Delassus block of a 3D contact (1/kg), symmetric 3×3 in the contact frame.
pub type Delassus3 = Matrix3<Real>;

/// The circular Coulomb cone `‖r_t‖ ≤ μ r_n` of a 3D contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coulomb3 {
    /// The friction coefficient μ ≥ 0.
    pub mu: Real,
}

impl FrictionCone for Coulomb3 {
    type Local = [Real; 3];
    type Block = Delassus3;

    fn mu(&self) -> Real {
        self.mu
    }

    fn block_mul(w: &Delassus3, r: [Real; 3]) -> [Real; 3] {
        let v = w * Vector::from(r);
        [v.x, v.y, v.z]
    }

    fn block_lambda_max(w: &Delassus3) -> Real {
        w.symmetric_eigenvalues().max()
    }

    /// Projection on the second-order cone (closed form, e.g. Acary, Brémond & Huber 2018):
    ///
    /// ```text
    /// ‖τ_t‖ ≤ μ τ_n        → τ                                   (stick)
    /// μ ‖τ_t‖ ≤ −τ_n       → 0                                   (open)
    /// otherwise            → r_n = (τ_n + μ‖τ_t‖)/(1 + μ²),  r_t = μ r_n τ_t/‖τ_t‖   (slide)
    /// ```
    fn project(&self, tau: [Real; 3]) -> ([Real; 3], ContactStatus) {
        let [tn, a, b] = tau;
        let nt = (a * a + b * b).sqrt();
        let mu = self.mu;
        if tn >= 0.0 && nt <= mu * tn {
            (tau, ContactStatus::Stick)
        } else if mu * nt <= -tn {
            ([0.0; 3], ContactStatus::Open)
        } else {
            let rn = (tn + mu * nt) / (1.0 + mu * mu);
            let s = mu * rn / nt;
            ([rn, s * a, s * b], ContactStatus::Slide)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::local::{Coulomb2, Delassus2};
    use crate::test_support::lcg;

    /// The frame is orthonormal and right-handed for normals all over the sphere (10⁻¹⁴), and
    /// local components go and come back.
    #[test]
    fn the_contact_frame_is_orthonormal_and_right_handed() {
        let mut s = 3u64;
        for _ in 0..1000 {
            let n =
                Vector::new(lcg(&mut s) - 0.5, lcg(&mut s) - 0.5, lcg(&mut s) - 0.5).normalize();
            let f = ContactFrame::from_normal(n);
            for (u, v) in [(f.n, f.t1), (f.n, f.t2), (f.t1, f.t2)] {
                assert!(u.dot(&v).abs() < 1e-14);
            }
            for u in [f.t1, f.t2] {
                assert!((u.norm() - 1.0).abs() < 1e-14);
            }
            assert!((f.t1.cross(&f.t2) - f.n).norm() < 1e-14);
            let v = Vector::new(0.3, -1.2, 2.0);
            assert!((f.to_global(f.to_local(v)) - v).norm() < 1e-14);
        }
    }

    /// The cone's projection is a projection (idempotent, into the cone) and Moreau's
    /// decomposition holds: `τ − proj_K τ` is orthogonal to `proj_K τ`.
    #[test]
    fn the_circular_cone_projection_is_moreau_s() {
        let mut s = 5u64;
        for _ in 0..1000 {
            let cone = Coulomb3 {
                mu: 0.05 + lcg(&mut s),
            };
            let tau = [
                2.0 * lcg(&mut s) - 1.0,
                2.0 * lcg(&mut s) - 1.0,
                2.0 * lcg(&mut s) - 1.0,
            ];
            let (p, _) = cone.project(tau);
            let (pp, _) = cone.project(p);
            let d: Real = p.iter().zip(&pp).map(|(a, b)| (a - b).abs()).sum();
            assert!(d < 1e-14);
            assert!((p[1] * p[1] + p[2] * p[2]).sqrt() <= cone.mu * p[0] + 1e-14);
            let dot: Real = (0..3).map(|k| (tau[k] - p[k]) * p[k]).sum();
            assert!(dot.abs() < 1e-14, "{dot}");
        }
    }

    /// A 3D contact whose block does not couple the second tangent and whose free velocity has
    /// none is the plane problem: the 3D cone's local solve (the generic predictor–corrector)
    /// gives the 2D closed form's impulse (to 10⁻⁹ of its size) and outcome, with `r_t2 = 0`.
    #[test]
    fn a_3d_contact_without_its_second_tangent_is_the_plane_law() {
        let mut s = 11u64;
        for _ in 0..500 {
            let (a, b) = (0.5 + 2.0 * lcg(&mut s), 0.5 + 2.0 * lcg(&mut s));
            let nt = (lcg(&mut s) - 0.5) * (a * b).sqrt();
            let w2 = Delassus2 { nn: a, nt, tt: b };
            let w3 = Delassus3::new(a, nt, 0.0, nt, b, 0.0, 0.0, 0.0, b);
            let q = [2.0 * lcg(&mut s) - 1.4, 2.0 * lcg(&mut s) - 1.0];
            let mu = 0.05 + lcg(&mut s);
            let (r2, st2) = Coulomb2 { mu }.solve_local(&w2, q);
            let (r3, st3) = Coulomb3 { mu }.solve_local(&w3, [q[0], q[1], 0.0]);
            let scale = (r2[0].abs() + r2[1].abs()).max(1e-12);
            assert!(
                (r2[0] - r3[0]).abs() + (r2[1] - r3[1]).abs() + r3[2].abs() <= 1e-9 * scale,
                "{r2:?} vs {r3:?}"
            );
            assert_eq!(st2, st3);
        }
    }

    /// The 3D cone plugs into the sweep the 2D solvers use: a row of a 3D problem implements
    /// [`crate::sweep::SweepRow`] (cone [`Coulomb3`], block [`Delassus3`], its free velocity
    /// read from the problem) and Gauss–Seidel sweeps of [`crate::sweep::solve_row`] (with and
    /// without over-relaxation) solve a coupled problem of four contacts to the natural-map
    /// error 10⁻¹⁰ ([`crate::cone::natural_map_error`], generic too).
    #[test]
    fn the_3d_cone_plugs_into_the_gauss_seidel_sweep() {
        use crate::cone::natural_map_error;
        use crate::sweep::{solve_row, SweepRow};
        use nalgebra::DMatrix;

        /// Row `a` of a dense 3D problem `u = W r + q` as a sweep sees it.
        struct Row3<'a> {
            w: &'a DMatrix<Real>,
            blocks: &'a [Delassus3],
            cones: &'a [Coulomb3],
            q: &'a [Real],
            r: &'a [Real],
            a: usize,
        }
        impl SweepRow for Row3<'_> {
            type Cone = Coulomb3;
            type Context = ();
            fn cone(&self) -> Coulomb3 {
                self.cones[self.a]
            }
            fn block(&self) -> &Delassus3 {
                &self.blocks[self.a]
            }
            fn impulse(&self) -> [Real; 3] {
                let i = 3 * self.a;
                [self.r[i], self.r[i + 1], self.r[i + 2]]
            }
            fn free_velocity(&self, (): ()) -> [Real; 3] {
                let mut q = [0.0; 3];
                for (k, q) in q.iter_mut().enumerate() {
                    let i = 3 * self.a + k;
                    *q = self.q[i];
                    for j in 0..self.r.len() {
                        if j / 3 != self.a {
                            *q += self.w[(i, j)] * self.r[j];
                        }
                    }
                }
                q
            }
        }

        let n = 4;
        let mut s = 13u64;
        // W = J M⁻¹ Jᵀ-like: a random SPD matrix with a dominant block diagonal.
        let a = DMatrix::from_fn(3 * n, 3 * n, |_, _| lcg(&mut s) - 0.5);
        let mut w = &a * a.transpose() * 0.1;
        for i in 0..3 * n {
            w[(i, i)] += 1.0 + lcg(&mut s);
        }
        let blocks: Vec<Delassus3> = (0..n)
            .map(|c| w.fixed_view::<3, 3>(3 * c, 3 * c).into_owned())
            .collect();
        let cones: Vec<Coulomb3> = (0..n)
            .map(|_| Coulomb3 {
                mu: 0.2 + 0.5 * lcg(&mut s),
            })
            .collect();
        let q: Vec<Real> = (0..3 * n)
            .map(|i| {
                if i % 3 == 0 {
                    -1.0 - lcg(&mut s)
                } else {
                    2.0 * lcg(&mut s) - 1.0
                }
            })
            .collect();
        for omega in [1.0, 0.8] {
            let mut r = vec![0.0; 3 * n];
            for _ in 0..200 {
                for c in 0..n {
                    let row = Row3 {
                        w: &w,
                        blocks: &blocks,
                        cones: &cones,
                        q: &q,
                        r: &r,
                        a: c,
                    };
                    let new = solve_row(&row, (), omega);
                    r[3 * c..3 * c + 3].copy_from_slice(&new);
                }
            }
            let u: Vec<Real> = (&w * nalgebra::DVector::from_column_slice(&r))
                .iter()
                .zip(&q)
                .map(|(wr, q)| wr + q)
                .collect();
            let e = natural_map_error(n, |c| cones[c], &q, &r, &u);
            assert!(e < 1e-10, "ω = {omega}: error {e}");
            // Every contact is loaded: the cone was exercised, not only its apex.
            assert!((0..n).all(|c| r[3 * c] > 0.0));
        }
    }

    /// A sphere's mass and inertia (a 1 mm glass bead).
    #[test]
    fn a_sphere_has_the_mass_and_inertia_of_a_ball() {
        let s = Sphere {
            radius: 1e-3,
            density: 2500.0,
        };
        let m = 4.0 / 3.0 * std::f64::consts::PI * 1e-9 * 2500.0;
        assert!((s.mass() - m).abs() < 1e-18);
        assert!((s.inertia()[(1, 1)] - 0.4 * m * 1e-6).abs() < 1e-24);
        assert_eq!(s.inertia()[(0, 1)], 0.0);
    }
}
