//! The energy balance of one step, from the world before and after it.
//!
//! With θ-method positions `q⁺ = q⁻ + h[(1 − θ) v⁻ + θ v⁺]`, the free degrees of freedom of a
//! step satisfy `ΔK = W_ext + W_drive + uᵀR − ½‖v⁺ − v⁻‖²_M + (1 − θ) h f·(v⁺ − v⁻)`, with
//! `K = Σ ½ m |v|² + ½ I ω²`, `W_ext = h Σ f·[(1 − θ) v⁻ + θ v⁺]` the work of gravity and the
//! applied loads `f` (it replaces `−ΔE_pot` and stays right across a periodic boundary), and
//! `W_drive = −h Σ F_c·v` the work the drives of imposed degrees of freedom put in against the
//! contact force `F_c` they receive. For θ = 1 and an exact solve `uᵀR ≤ 0`, so the residual
//! `δ = ΔK − W_ext − W_drive ≤ 0` (Moreau 1988; Acary & Brogliato 2008, §7.2): [`EnergyProbe`]
//! measures it. The position correction ([`crate::stabilise`]) moves no velocity and is not in δ.

use crate::body::{external_loads, Body, BodyKind, Dof};
use crate::cell::Imposed;
use crate::math::Spatial;
use crate::world::World;

/// [`external_loads`] on the free degrees of freedom of `b`, zero on imposed ones.
pub fn free_loads(world: &World, b: &Body) -> Spatial {
    let f = external_loads(b, world.params.gravity);
    let mut out = [0.0; 3];
    for d in 0..3 {
        if b.dofs[d] == Dof::Free {
            out[d] = f[d];
        }
    }
    out
}

/// The power of the external loads on the free degrees of freedom, `Σ f·v` (W).
pub fn load_power(world: &World) -> f64 {
    world
        .bodies
        .iter()
        .map(|b| {
            let f = free_loads(world, b);
            f[0] * b.velocity.x + f[1] * b.velocity.y + f[2] * b.omega
        })
        .sum()
}

/// What the energy balance of one step needs from the state before it: the kinetic energy of
/// the free degrees of freedom and the power of the external loads, with the step's `h` and θ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyProbe {
    /// Kinetic energy `K⁻` of the free degrees of freedom (J).
    pub kinetic: f64,
    /// Power of the external loads `Σ f·v⁻` (W).
    pub load_power: f64,
    /// Time step h (s).
    pub dt: f64,
    /// θ of the step.
    pub theta: f64,
}

impl EnergyProbe {
    /// Measures `world` before a step.
    pub fn before(world: &World) -> Self {
        EnergyProbe {
            kinetic: world.kinetic_energy(),
            load_power: load_power(world),
            dt: world.params.dt,
            theta: world.params.theta,
        }
    }

    /// The residual `δ = ΔK − W_ext − W_drive − W_cell` (J) of the step that took the world from
    /// the probed state to `after` (module documentation): `W_ext = h[(1 − θ) Σ f·v⁻ + θ Σ f·v⁺]`,
    /// `W_drive = −h Σ F_c·v` over imposed degrees of freedom, `F_c` the contact force received
    /// during the step, `W_cell` the work of a deformable periodic cell
    /// (`StepReport::cell_work`). At most round-off for θ = 1 and an exact solve. The position correction
    /// of the step moves no velocity and is not in δ; its work is in
    /// `StepReport::position_correction.load_work`.
    pub fn residual(&self, after: &World) -> f64 {
        let h = self.dt;
        let th = self.theta;
        let w_ext = h * ((1.0 - th) * self.load_power + th * load_power(after));
        let mut w_drive = 0.0;
        for (i, b) in after.bodies.iter().enumerate() {
            if b.dofs.iter().all(|d| *d == Dof::Free) {
                continue;
            }
            let (f, t) = after.contact_force(i);
            let fc = [f.x, f.y, t];
            let v = [b.velocity.x, b.velocity.y, b.omega];
            for d in 0..3 {
                if b.dofs[d] == Dof::Imposed && v[d] != 0.0 {
                    w_drive -= h * fc[d] * v[d];
                }
            }
        }
        // The work of a deformable periodic cell (0 without one).
        let w_cell = after.last_report().cell_work;
        after.kinetic_energy() - self.kinetic - w_ext - w_drive - w_cell
    }
}

/// Energy scale of the energy-balance check,
/// `E_load = Σ_grains m |g| d + Σ_bodies |f_a| d̄ + Σ_ij |σ*_ij| √V d̄` (J per metre): the work
/// of every external load over one diameter (`d = 2R` of the grain, `d̄` the mean grain
/// diameter for a load `f_a` applied on another body, e.g. a pressure-controlled platen; for
/// each stress `σ*_ij` imposed on a periodic cell of area `V`, its work over a boundary
/// displacement of `d̄`). Without loads it falls back to `Σ m d̄²/s²` (1 J for a world without
/// grains).
pub fn load_energy_scale(world: &World) -> f64 {
    let g = world.params.gravity.norm();
    let (mut n, mut dsum, mut mass, mut s) = (0usize, 0.0, 0.0, 0.0);
    for b in world.bodies.iter().filter(|b| b.kind == BodyKind::Grain) {
        n += 1;
        dsum += 2.0 * b.radius;
        mass += b.mass;
        if b.gravity {
            s += b.mass * g * 2.0 * b.radius;
        }
    }
    let dmean = if n > 0 { dsum / n as f64 } else { 0.0 };
    for b in &world.bodies {
        if b.dofs.contains(&Dof::Free) {
            s += (b.applied_force.norm() + b.applied_torque.abs() / dmean.max(1e-300)) * dmean;
        }
    }
    // A stress-controlled periodic cell: the work of each imposed stress over a boundary
    // displacement of one mean diameter, |σ*_ij| V (d̄ / √V).
    if let (Some(cell), Some(ctl)) = (world.cell(), world.cell_control.as_ref()) {
        let side = cell.volume().abs().sqrt();
        for imposed in [ctl.xx, ctl.yy, ctl.xy] {
            if let Imposed::Stress(sigma) = imposed {
                s += sigma.abs() * side * dmean;
            }
        }
    }
    if s > 0.0 && s.is_finite() {
        s
    } else if mass > 0.0 && dmean > 0.0 {
        mass * dmean * dmean
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::{Cell, CellControl};
    use crate::math::Vector;
    use crate::{ContactLaws, WorldParams};

    /// Without gravity, the scale of a cell under imposed σ_xx = σ_yy = −100 Pa (rate-controlled
    /// shear) is the work of both stresses over one mean diameter, 2 · 100 Pa · √V · d̄, exactly;
    /// without the control it falls back to Σ m d̄².
    #[test]
    fn scale_of_a_stress_controlled_cell_is_the_work_of_its_stresses() {
        let params = WorldParams {
            gravity: Vector::zeros(),
            ..Default::default()
        };
        let mut w = World::new(params, ContactLaws::new(&["g"], 0.3));
        for k in 0..4 {
            w.add_grain(
                Vector::new(2.5e-3 * (k as f64 + 0.5), 5e-3),
                1e-3,
                2500.0,
                0,
            );
        }
        w.set_cell(Some(Cell::rectangle(1e-2, 1e-2).unwrap()))
            .unwrap();
        let mass: f64 = w.bodies.iter().map(|b| b.mass).sum();
        let fallback = load_energy_scale(&w);
        assert!((fallback - mass * 4e-6).abs() <= 1e-12 * fallback);
        w.cell_control = Some(CellControl {
            xx: Imposed::Stress(-100.0),
            yy: Imposed::Stress(-100.0),
            xy: Imposed::Rate(0.0),
            gain: 1e-3,
            max_rate: 1.0,
            relaxation: 0.0,
            tolerance: 0.0,
            max_corrections: 0,
            implicit: false,
            affine: false,
        });
        let expected = 2.0 * 100.0 * 1e-2 * 2e-3;
        let s = load_energy_scale(&w);
        assert!(
            (s - expected).abs() <= 1e-12 * expected,
            "{s} vs {expected}"
        );
    }
}
