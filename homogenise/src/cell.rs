//! The state of a biperiodic deformable cell (`dem::cell`): mean stress over the whole cell,
//! with velocity fluctuations measured against the affine field, and the cell's kinematic and
//! structural measures.
//!
//! The cell holds every grain once (images are the same grains), so the mean stress over the
//! cell of volume `V = det h · t` (thickness t) is the paper's volume average of the grain
//! stresses (`docs/physics.md` §2.1–2.2, [`crate::stress`]) plus the kinetic stress of the
//! velocity fluctuations:
//!
//! `Σ = (1/V) [ Σ_p V_p Σ_p − Σ_p m_p ṽ_p ⊗ ṽ_p ]`,  `ṽ_p = v_p − L (x_p − c) − ⟨v − L (x − c)⟩`,
//!
//! `Σ_p` the contact (Love–Weber) and rotational-inertia terms of each grain (its levers are
//! taken across the periodic boundary, so contacts with images need no special treatment),
//! `L` the cell's velocity gradient, `c` its centre, and the mean subtracted mass-weighted.
//! Snapshot velocities are total velocities (affine field included, `dem::cell`); the
//! fluctuations relative to the affine field are what carries momentum flux. Tension positive.

use dem::math::{SymTensor, Tensor, Vector};
use dem::snapshot::{BodyKind, Snapshot};
use serde::{Deserialize, Serialize};

use crate::error::{HomogeniseError, Result};
use crate::stress::grain_stresses;
use crate::tensor::outer;

/// Whole-cell measures of one snapshot (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CellState {
    /// Cell volume `det h · t` (m³; m² per metre of thickness).
    pub volume: f64,
    /// Mean stress `Σ` (Pa), symmetric part, kinetic stress included.
    pub stress: SymTensor,
    /// Contact part `(1/V) Σ_p V_p Σ_c,p` (Pa).
    pub contact: Tensor,
    /// Rotational inertia part `(1/V) Σ_p V_p Σ_i,p` (Pa).
    pub inertia: Tensor,
    /// Kinetic part `−(1/V) Σ_p m_p ṽ_p ⊗ ṽ_p` (Pa).
    pub kinetic: Tensor,
    /// Strain rate of the cell `D = (L + Lᵀ)/2` (1/s).
    pub strain_rate: SymTensor,
    /// Velocity gradient of the cell `L` (1/s).
    pub velocity_gradient: Tensor,
    /// Pressure `p = −tr Σ / 2` (Pa).
    pub pressure: f64,
    /// Deviatoric stress `q = √(((Σ_xx − Σ_yy)/2)² + Σ_xy²)` (Pa).
    pub deviator: f64,
    /// Solid fraction `Σ_p A_p / det h` (1).
    pub solid_fraction: f64,
    /// Coordination number `Z = 2 N_c / N` over contacts carrying a normal force (1).
    pub coordination: f64,
    /// Fabric tensor `(1/N_c) Σ_c n ⊗ n` over contacts carrying a normal force (1).
    pub fabric: SymTensor,
    /// Grains.
    pub grains: usize,
}

/// The whole-cell measures of a snapshot taken in a biperiodic cell; an error when the
/// snapshot has no cell.
pub fn cell_state(snapshot: &Snapshot) -> Result<CellState> {
    let cell = snapshot
        .cell
        .ok_or_else(|| HomogeniseError::InvalidParameter {
            name: "snapshot",
            reason: "has no biperiodic cell".into(),
        })?;
    let gs = grain_stresses(snapshot)?;
    let thickness = gs.first().map_or(1.0, |g| g.thickness);
    let volume = cell.volume() * thickness;
    let (mut contact, mut inertia) = (Tensor::zeros(), Tensor::zeros());
    let mut area = 0.0;
    for g in &gs {
        contact += g.contact * g.volume;
        inertia += g.inertia * g.volume;
        area += g.area();
    }
    let c = cell.centre();
    let l = cell.l;
    let grains: Vec<_> = snapshot
        .bodies
        .iter()
        .filter(|b| b.kind == BodyKind::Grain)
        .collect();
    let (mut mass, mut mom) = (0.0, Vector::zeros());
    for b in &grains {
        mass += b.mass;
        mom += (b.velocity - l * (b.position - c)) * b.mass;
    }
    let mean = if mass > 0.0 {
        mom / mass
    } else {
        Vector::zeros()
    };
    let mut kinetic = Tensor::zeros();
    for b in &grains {
        let v = b.velocity - l * (b.position - c) - mean;
        kinetic -= outer(&v, &v) * b.mass;
    }
    let (contact, inertia, kinetic) = (contact / volume, inertia / volume, kinetic / volume);
    let total = contact + inertia + kinetic;
    let stress = (total + total.transpose()) * 0.5;
    let mut fabric = Tensor::zeros();
    let mut nc = 0usize;
    for ct in snapshot.contacts.iter().filter(|c| c.force_n > 0.0) {
        fabric += outer(&ct.normal, &ct.normal);
        nc += 1;
    }
    if nc > 0 {
        fabric /= nc as f64;
    }
    let n = grains.len();
    Ok(CellState {
        volume,
        stress,
        contact,
        inertia,
        kinetic,
        strain_rate: cell.strain_rate(),
        velocity_gradient: l,
        pressure: -0.5 * stress.trace(),
        deviator: (0.25 * (stress[(0, 0)] - stress[(1, 1)]).powi(2) + stress[(0, 1)].powi(2))
            .sqrt(),
        solid_fraction: area / cell.volume(),
        coordination: if n > 0 {
            2.0 * nc as f64 / n as f64
        } else {
            0.0
        },
        fabric,
        grains: n,
    })
}
