//! Second-order tensors of the space ([`dem::math::Tensor`], `T[(i, j)] = T_ij`) and the few
//! operations the homogenisation needs. The types are those of the dimension layer
//! ([`dem::math`]); the functions here are the plane ones (a 3D build would give
//! [`rotation_generator`], [`deviator`] and [`slope_frame`] their 3D forms there).
//!
//! Convention for dyads: `(a ⊗ b)_ij = a_i b_j`, so the Love–Weber term `r ⊗ (x − c)` has the
//! force in the row index and the lever in the column index.

use dem::math::{SymTensor, Tensor, Vector};

/// Cross product of two vectors, `a × b = a_x b_y − a_y b_x` in the plane (from the dimension
/// layer).
pub use dem::math::cross;

/// The former name of [`dem::math::Tensor`] (the same type), kept for the callers in the CLI
/// package until they are converted; new code writes `dem::math::Tensor`.
pub use dem::math::Tensor as Tensor2;

/// The rotation generator `j = [[0, −1], [1, 0]]`: `j u = e_z × u` (a quarter turn counter-clockwise).
pub fn rotation_generator() -> Tensor {
    Tensor::new(0.0, -1.0, 1.0, 0.0)
}

/// Dyadic product `a ⊗ b`, `(a ⊗ b)_ij = a_i b_j`.
pub fn outer(a: &Vector, b: &Vector) -> Tensor {
    a * b.transpose()
}

/// Symmetric part `(T + Tᵀ)/2`.
pub fn symmetric_part(t: &Tensor) -> SymTensor {
    (t + t.transpose()) * 0.5
}

/// Skew part `(T − Tᵀ)/2`.
pub fn skew_part(t: &Tensor) -> Tensor {
    (t - t.transpose()) * 0.5
}

/// Frobenius norm `‖T‖_F = √(T : T)`.
pub fn frobenius(t: &Tensor) -> f64 {
    t.norm()
}

/// Relative asymmetry `‖skew T‖_F / ‖T‖_F` (0 for the zero tensor).
pub fn skew_ratio(t: &Tensor) -> f64 {
    let n = frobenius(t);
    if n > 0.0 {
        frobenius(&skew_part(t)) / n
    } else {
        0.0
    }
}

/// Deviatoric part in 2D, `T' = T − (tr T / 2) 𝟙`.
pub fn deviator(t: &Tensor) -> Tensor {
    t - Tensor::identity() * (t.trace() * 0.5)
}

/// Components in the orthonormal frame `(e1, e2)`: `T'_ab = e_a · T e_b`, i.e. `Qᵀ T Q` with
/// `Q = [e1 e2]` (columns). Used for the slope frame of the rolling disk (e1 down the slope,
/// e2 the outward normal).
pub fn in_frame(t: &Tensor, e1: &Vector, e2: &Vector) -> Tensor {
    let q = Tensor::from_columns(&[*e1, *e2]);
    q.transpose() * t * q
}

/// The slope frame of a plane inclined by `angle` (rad) going down towards +x under gravity
/// along −y: `e1 = (cos φ, −sin φ)` down the slope, `e2 = (sin φ, cos φ)` the outward normal
/// (right-handed). Use with [`in_frame`] for the rolling disk (`docs/physics.md` §2.3).
pub fn slope_frame(angle: f64) -> (Vector, Vector) {
    let (s, c) = angle.sin_cos();
    (Vector::new(c, -s), Vector::new(s, c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn j_is_the_quarter_turn() {
        let u = Vector::new(0.3, -1.7);
        let ju = rotation_generator() * u;
        // e_z × u = (−u_y, u_x)
        assert!((ju - Vector::new(1.7, 0.3)).norm() < 1e-15);
    }

    #[test]
    fn skew_of_dyad_is_the_torque() {
        // skew(r ⊗ l)_xy = (r_x l_y − r_y l_x)/2 = −(l × r)/2
        let r = Vector::new(2.0, 3.0);
        let l = Vector::new(-0.5, 0.25);
        let s = skew_part(&outer(&r, &l));
        assert!((s[(0, 1)] + 0.5 * cross(&l, &r)).abs() < 1e-15);
    }

    #[test]
    fn slope_frame_is_orthonormal_and_right_handed() {
        let (e1, e2) = slope_frame(0.4);
        assert!((e1.norm() - 1.0).abs() < 1e-15 && (e2.norm() - 1.0).abs() < 1e-15);
        assert!(e1.dot(&e2).abs() < 1e-15);
        assert!((cross(&e1, &e2) - 1.0).abs() < 1e-15);
        // gravity (0, −g) has component g sinφ down the slope
        assert!((Vector::new(0.0, -1.0).dot(&e1) - 0.4f64.sin()).abs() < 1e-15);
    }

    #[test]
    fn frame_change_preserves_invariants() {
        let t = Tensor::new(1.0, 2.0, 0.5, -3.0);
        let a: f64 = 0.7;
        let e1 = Vector::new(a.cos(), -a.sin());
        let e2 = Vector::new(a.sin(), a.cos());
        let tf = in_frame(&t, &e1, &e2);
        assert!((tf.trace() - t.trace()).abs() < 1e-14);
        assert!((tf.norm() - t.norm()).abs() < 1e-14);
        assert!((tf[(0, 1)] - e1.dot(&(t * e2))).abs() < 1e-14);
    }
}
