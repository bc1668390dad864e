//! Mean strain rate over a region: least-squares affine fit of grain velocities, and the
//! strain rate imposed by two walls.
//!
//! The fit minimises `Σ_p w_p |v_p − v̄ − L (x_p − x̄)|²` over the mean velocity `v̄` and the
//! velocity gradient `L_ij = ∂v_i/∂x_j`, with `x̄, v̄` the weighted means; its solution is
//! `L = (Σ w δv δxᵀ)(Σ w δx δxᵀ)⁻¹`. The strain rate is `D = (L + Lᵀ)/2`, the spin
//! `W = (L − Lᵀ)/2`, and the **shear rate** `γ̇ = √(2 D' : D')`, `D' = D − (tr D / 2) 𝟙`; for a
//! simple shear `v_x = γ̇ y` it is `γ̇ = |∂v_x/∂y| = 2 |D_xy|`.

use dem::math::{SymTensor, Tensor, Vector};
use dem::snapshot::{BodyKind, Snapshot, WallGeometry};
use serde::{Deserialize, Serialize};

use crate::error::{HomogeniseError, Result};
use crate::region::Region;
use crate::tensor::{deviator, outer, skew_part, symmetric_part};
use crate::validate::{check_snapshot, unit_normal};

/// Weight of each grain in the velocity fit, multiplied by its area fraction inside the region.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum VelocityWeight {
    /// Every grain counts the same.
    Uniform,
    /// Grains weighted by their mass (the fit then conserves the region's momentum).
    #[default]
    Mass,
}

/// Result of the affine fit of grain velocities over a region.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AffineFit {
    /// Weighted mean position `x̄` (m); x relative to the region's centre when periodic.
    pub mean_position: Vector,
    /// Weighted mean velocity `v̄` (m/s).
    pub mean_velocity: Vector,
    /// Velocity gradient `L_ij = ∂v_i/∂x_j` (1/s).
    pub gradient: Tensor,
    /// Number of grains with a non-zero weight (at least partly inside the region).
    pub grains: usize,
    /// Root-mean-square (weighted) velocity residual of the fit (m/s): the velocity fluctuation.
    pub rms_residual: f64,
}

impl AffineFit {
    /// Strain-rate tensor `D = (L + Lᵀ)/2` (1/s).
    pub fn strain_rate(&self) -> SymTensor {
        symmetric_part(&self.gradient)
    }

    /// Spin tensor `W = (L − Lᵀ)/2` (1/s).
    pub fn spin(&self) -> Tensor {
        skew_part(&self.gradient)
    }

    /// Shear rate `γ̇ = √(2 D' : D')` (1/s).
    pub fn shear_rate(&self) -> f64 {
        shear_rate(&self.strain_rate())
    }
}

/// Shear rate `γ̇ = √(2 D' : D')` (1/s) of a strain-rate tensor `D` (its symmetric part is used).
pub fn shear_rate(d: &Tensor) -> f64 {
    let dd = deviator(&symmetric_part(d));
    (2.0 * dd.component_mul(&dd).sum()).sqrt()
}

/// Least-squares affine fit of the velocities of the grains in `region` (see the module
/// documentation). Grains are weighted by their area fraction inside the region times
/// `weight`. With a periodic x direction, x positions are taken as the image nearest the
/// region's centre. Fails when fewer than 3 grains or when the grains are (nearly) aligned, so
/// that the gradient is not determined.
pub fn velocity_gradient(
    snapshot: &Snapshot,
    region: &Region,
    weight: VelocityWeight,
) -> Result<AffineFit> {
    check_snapshot(snapshot)?;
    let rect = region.resolve(snapshot)?;
    let yc = 0.5 * (rect.min.y + rect.max.y);
    let mut pts: Vec<(f64, Vector, Vector)> = Vec::new();
    for b in snapshot.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
        let w = rect.disk_fraction(&b.position, b.radius);
        if w > 0.0 {
            let w = match weight {
                VelocityWeight::Uniform => w,
                VelocityWeight::Mass => w * b.mass,
            };
            let x = Vector::new(rect.dx_from_centre(b.position.x), b.position.y - yc);
            pts.push((w, x, b.velocity));
        }
    }
    if pts.len() < 3 {
        return Err(HomogeniseError::NotEnoughData(format!(
            "velocity fit needs ≥ 3 grains in the region, found {}",
            pts.len()
        )));
    }
    let wsum: f64 = pts.iter().map(|p| p.0).sum();
    let xm = pts.iter().map(|p| p.1 * p.0).sum::<Vector>() / wsum;
    let vm = pts.iter().map(|p| p.2 * p.0).sum::<Vector>() / wsum;
    let (mut a, mut b) = (Tensor::zeros(), Tensor::zeros());
    for (w, x, v) in &pts {
        let dx = x - xm;
        a += outer(&dx, &dx) * *w;
        b += outer(&(v - vm), &dx) * *w;
    }
    let scale = a.trace();
    if scale.is_nan() || scale <= 0.0 || a.determinant() <= 1e-10 * scale * scale {
        return Err(HomogeniseError::NotEnoughData(
            "grains are aligned: the velocity gradient is not determined".into(),
        ));
    }
    let inv = a
        .try_inverse()
        .ok_or_else(|| HomogeniseError::NotEnoughData("singular position moment matrix".into()))?;
    let l = b * inv;
    let res2: f64 = pts
        .iter()
        .map(|(w, x, v)| w * (v - vm - l * (x - xm)).norm_squared())
        .sum();
    Ok(AffineFit {
        mean_position: xm + Vector::new(0.5 * (rect.min.x + rect.max.x), yc),
        mean_velocity: vm,
        gradient: l,
        grains: pts.len(),
        rms_residual: (res2 / wsum).sqrt(),
    })
}

/// Velocity gradient imposed by two parallel walls `a` and `b` (1/s):
/// `L = (v_b − v_a) ⊗ n / ((x_b − x_a) · n)`, with `x, v` the walls' body positions and
/// velocities and `n` the walls' common normal: given, or that of wall `a` when it is a line.
/// For a plane shear cell with the top wall moving at `V` over a gap `H`: `L_xy = V/H`, `γ̇ = V/H`.
pub fn wall_driven_velocity_gradient(
    snapshot: &Snapshot,
    wall_a: &str,
    wall_b: &str,
    normal: Option<Vector>,
) -> Result<Tensor> {
    check_snapshot(snapshot)?;
    let find = |name: &str| {
        snapshot
            .walls
            .iter()
            .find(|w| w.name == name)
            .ok_or_else(|| HomogeniseError::UnknownWall(name.to_string()))
    };
    let (wa, wb) = (find(wall_a)?, find(wall_b)?);
    let n = match (normal, &wa.geometry) {
        (Some(n), _) => n,
        (None, WallGeometry::Line { normal, .. }) => *normal,
        (None, _) => {
            return Err(HomogeniseError::InvalidParameter {
                name: "normal",
                reason: format!("wall `{wall_a}` is not a line: give the walls' normal"),
            })
        }
    };
    let n = unit_normal(n)?;
    let (ba, bb) = (
        &snapshot.bodies[wa.body as usize],
        &snapshot.bodies[wb.body as usize],
    );
    let gap = (bb.position - ba.position).dot(&n);
    if gap.abs() <= f64::EPSILON * (bb.position.norm() + ba.position.norm() + 1.0) {
        return Err(HomogeniseError::InvalidParameter {
            name: "walls",
            reason: format!("walls `{wall_a}` and `{wall_b}` have no gap along the normal"),
        });
    }
    Ok(outer(&(bb.velocity - ba.velocity), &n) / gap)
}
