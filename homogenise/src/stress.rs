//! Mean stress of a grain with inertia (`docs/physics.md` §2.1, the seed paper's eq. 8–12) and
//! its region mean (eq. 9, `docs/physics.md` §2.2).
//!
//! For a grain `p` (volume `V_p`, centre `c_p`) under contact forces `r_α` at points `x_α` and
//! the body force `ρ (g − ẍ)`:
//!
//! `Σ_p = (1/V_p) [ Σ_α r_α ⊗ (x_α − c_p) + ∫_{V_p} ρ (g − ẍ) ⊗ (x − c_p) dV ]`.
//!
//! With the origin at the centre, gravity and the centre's acceleration drop out; for a rigid
//! disk (`ẍ = c̈ + ω̇ j (x − c) − ω² (x − c)`, `J = ∫ ρ (x−c)⊗(x−c) dV = (I/2) 𝟙`) the body-force
//! part is the **inertia term**
//!
//! `Σ_i = (I / (2 V_p)) (−ω̇ j + ω² 𝟙)`,  `j = [[0, −1], [1, 0]]`,
//!
//! and the **contact term** (Love–Weber tensor) is `Σ_c = (1/V_p) Σ_α r_α ⊗ (x_α − c_p)`.
//! Its skew part is `−(Σ_α (x_α − c_p) × r_α) / (2 V_p) · j`, which the inertia term cancels when
//! `I ω̇ = Σ_α (x_α − c_p) × r_α`: `Σ_p = Σ_c + Σ_i` is symmetric. Tension positive; Pa.
//!
//! The snapshot gives `ω̇ = (ω⁺ − ω⁻)/h`, consistent with the step's impulses; `ω` in the
//! centripetal term is the end-of-step `ω⁺` (it only changes the isotropic part).
//! Wall contacts count as contacts of the grain; levers come from the snapshot (`lever_a`,
//! `lever_b`), so a periodic x direction needs no image handling.

use dem::math::{Tensor, Vector};
use dem::snapshot::{BodyKind, Snapshot};
use serde::{Deserialize, Serialize};

use crate::error::{HomogeniseError, Result};
use crate::region::{Rect, Region};
use crate::tensor::{outer, rotation_generator};
use crate::validate::check_snapshot;

/// The mean stress of one grain and its two parts (Pa, tension positive).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GrainStress {
    /// Index of the grain in `Snapshot::bodies`.
    pub body: usize,
    /// Centre of the grain (m).
    pub position: Vector,
    /// Radius (m).
    pub radius: f64,
    /// Volume `V_p = π R² · thickness` (m³).
    pub volume: f64,
    /// Thickness along z (m).
    pub thickness: f64,
    /// Contact (Love–Weber) term `Σ_c = (1/V_p) Σ_α r_α ⊗ (x_α − c_p)` (Pa); not symmetric in
    /// dynamics.
    pub contact: Tensor,
    /// Inertia term `Σ_i = (I/(2V_p)) (−ω̇ j + ω² 𝟙)` (Pa).
    pub inertia: Tensor,
    /// Total `Σ_p = Σ_c + Σ_i` (Pa); symmetric when `ω̇` is consistent with the forces.
    pub total: Tensor,
}

impl GrainStress {
    /// Planar area of the grain `A_p = V_p / thickness = π R²` (m²).
    pub fn area(&self) -> f64 {
        self.volume / self.thickness
    }
}

/// Contact term `Σ_α r_α ⊗ (x_α − c_p)` (N·m) of every body, indexed like `Snapshot::bodies`
/// (walls get theirs too, unused). Body `b` of a contact receives `f_n n + f_t t` at lever
/// `lever_b`; body `a` receives the opposite at `lever_a`.
pub(crate) fn contact_moments(snapshot: &Snapshot) -> Vec<Tensor> {
    let mut m = vec![Tensor::zeros(); snapshot.bodies.len()];
    for c in &snapshot.contacts {
        let f = c.force_on_b();
        m[c.body_b as usize] += outer(&f, &c.lever_b);
        m[c.body_a as usize] -= outer(&f, &c.lever_a);
    }
    m
}

/// Inertia term `Σ_i = (I/(2V)) (−ω̇ j + ω² 𝟙)` (Pa) of a rigid disk of moment of inertia `I`
/// (kg·m²), volume `V` (m³), angular velocity `ω` (rad/s) and angular acceleration `ω̇` (rad/s²).
pub fn disk_inertia_stress(inertia: f64, volume: f64, omega: f64, omega_dot: f64) -> Tensor {
    let k = inertia / (2.0 * volume);
    (rotation_generator() * (-omega_dot) + Tensor::identity() * (omega * omega)) * k
}

/// Per-grain mean stresses `Σ_p` (contact, inertia, total) of every grain of the snapshot, in
/// body order. Implements `docs/physics.md` §2.1 (see the module documentation).
pub fn grain_stresses(snapshot: &Snapshot) -> Result<Vec<GrainStress>> {
    check_snapshot(snapshot)?;
    let moments = contact_moments(snapshot);
    Ok(snapshot
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| b.kind == BodyKind::Grain)
        .map(|(i, b)| {
            let v = b.volume();
            let contact = moments[i] / v;
            let inertia = disk_inertia_stress(b.inertia, v, b.omega, b.angular_acceleration);
            GrainStress {
                body: i,
                position: b.position,
                radius: b.radius,
                volume: v,
                thickness: b.thickness,
                contact,
                inertia,
                total: contact + inertia,
            }
        })
        .collect())
}

/// The mean stress over a region and what it is made of.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RegionStress {
    /// The resolved region.
    pub region: Rect,
    /// Area of the region `A_R` (m²), voids included.
    pub area: f64,
    /// Grain area inside the region `Σ_p w_p A_p` (m²).
    pub grain_area: f64,
    /// Weighted number of grains `Σ_p w_p`.
    pub grains: f64,
    /// Mean stress `Σ = (1/A_R) Σ_p w_p A_p Σ_p` (Pa), eq. 9.
    pub total: Tensor,
    /// Mean of the contact terms alone (Pa).
    pub contact: Tensor,
    /// Mean of the inertia terms alone (Pa).
    pub inertia: Tensor,
}

/// Region mean `Σ = (1/A_R) Σ_p w_p A_p Σ_p` (Pa) of per-grain stresses, `w_p` the fraction of
/// grain `p`'s disk inside the region (see [`crate::region`]). With a common thickness `t` this
/// is the paper's `Σ = (1/V) Σ_p V_p Σ_p`, `V = A_R t` (eq. 9). An empty region (no grain)
/// gives zero stress, not an error; a region with no area is an error.
pub fn mean_stress(
    snapshot: &Snapshot,
    grains: &[GrainStress],
    region: &Region,
) -> Result<RegionStress> {
    let rect = region.resolve(snapshot)?;
    Ok(mean_stress_in(&rect, grains))
}

/// [`mean_stress`] over an already resolved rectangle.
pub fn mean_stress_in(rect: &Rect, grains: &[GrainStress]) -> RegionStress {
    let area = rect.area();
    let (mut total, mut contact, mut inertia) = (Tensor::zeros(), Tensor::zeros(), Tensor::zeros());
    let (mut grain_area, mut count) = (0.0, 0.0);
    for g in grains {
        let w = rect.disk_fraction(&g.position, g.radius);
        if w == 0.0 {
            continue;
        }
        let wa = w * g.area();
        grain_area += wa;
        count += w;
        total += g.total * wa;
        contact += g.contact * wa;
        inertia += g.inertia * wa;
    }
    RegionStress {
        region: *rect,
        area,
        grain_area,
        grains: count,
        total: total / area,
        contact: contact / area,
        inertia: inertia / area,
    }
}

/// Mean stresses of consecutive horizontal slices `[y_k, y_{k+1}]` (edges in m, increasing),
/// across the sample's width (see [`Region::Slice`]). For vertical stress profiles σ_yy(y).
pub fn slice_stress_profile(
    snapshot: &Snapshot,
    grains: &[GrainStress],
    y_edges: &[f64],
) -> Result<Vec<RegionStress>> {
    if y_edges.len() < 2 {
        return Err(HomogeniseError::InvalidParameter {
            name: "y_edges",
            reason: "needs at least two edges".into(),
        });
    }
    y_edges
        .windows(2)
        .map(|w| {
            mean_stress(
                snapshot,
                grains,
                &Region::Slice {
                    y_min: w[0],
                    y_max: w[1],
                },
            )
        })
        .collect()
}

/// The boundary form of the total stress moment of all grains (N·m), the exact identity that
/// follows from each grain's dynamic equilibrium:
///
/// `Σ_p V_p Σ_p = Σ_{α ∈ wall contacts} r_α ⊗ x_α + Σ_p [ m_p (g − c̈_p) ⊗ c_p + (I_p/2)(−ω̇_p j + ω_p² 𝟙) ]`,
///
/// where the internal grain–grain forces cancel by action–reaction. Positions are taken
/// relative to `origin` (the identity holds for any origin; a nearby one limits rounding).
/// Used to check [`grain_stresses`] against the forces the walls carry; also the "virial"
/// route to the whole-sample stress.
pub fn boundary_moment(snapshot: &Snapshot, origin: &Vector) -> Result<Tensor> {
    check_snapshot(snapshot)?;
    let is_grain = |i: u32| snapshot.bodies[i as usize].kind == BodyKind::Grain;
    let mut m = Tensor::zeros();
    for c in &snapshot.contacts {
        let f = c.force_on_b();
        let (ga, gb) = (is_grain(c.body_a), is_grain(c.body_b));
        if gb && !ga {
            let x = snapshot.bodies[c.body_b as usize].position + c.lever_b - origin;
            m += outer(&f, &x);
        } else if ga && !gb {
            let x = snapshot.bodies[c.body_a as usize].position + c.lever_a - origin;
            m -= outer(&f, &x);
        } else if ga && gb {
            // b sees r at its contact point, a sees −r at its own: r ⊗ (x_b − x_a), zero unless
            // the contact crosses the periodic boundary (then x_b − x_a is the cell shift).
            let pb = snapshot.bodies[c.body_b as usize].position + c.lever_b;
            let pa = snapshot.bodies[c.body_a as usize].position + c.lever_a;
            m += outer(&f, &(pb - pa));
        }
    }
    for b in snapshot.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
        let c = b.position - origin;
        m += outer(&((snapshot.gravity - b.acceleration) * b.mass), &c);
        m += disk_inertia_stress(b.inertia, 1.0, b.omega, b.angular_acceleration);
    }
    Ok(m)
}
