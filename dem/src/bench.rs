//! Measurements behind `grainlaw bench` (the benchmark worlds themselves are built in
//! `datasets::benchmarks`): bare sweep rate ([`sweep_rate`]), settling to rest with an optional
//! adaptive step ([`settle`], [`energy_ratio`]) and the memory footprint of the data layout
//! ([`MemoryFootprint`]); plus a loose-grid deposit ([`deposit_world`]) for profiling.

use std::time::Instant;

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

use crate::step_control::{step_subdivided, StepControl, Subdivision};
use crate::{ContactLaws, SolverParams, World, WorldParams};

/// A box `width` wide holding `n` disks of radius in [1, 2] mm on a loose seeded grid, μ = 0.3,
/// density 2500 kg/m³, time step 2·10⁻⁴ s.
pub fn deposit_world(n: usize, width: f64, seed: u64) -> World {
    grid_world(n, width, 0.3, seed)
}

/// [`deposit_world`] with friction coefficient `mu`.
pub fn grid_world(n: usize, width: f64, mu: f64, seed: u64) -> World {
    let (r_min, r_max) = (1e-3, 2e-3);
    let params = WorldParams {
        dt: 2e-4,
        theta: 1.0,
        gravity: Vector2::new(0.0, -9.81),
        periodic_x: None,
        detection_gap: 0.1 * r_min,
        overlap_rate: 1e-4,
        position_correction: true,
        solver: SolverParams {
            tolerance: 1e-4,
            max_iterations: 1000,
            ..Default::default()
        },
    };
    let mut w = World::new(params, ContactLaws::new(&["grain"], mu));
    w.add_line_wall("bottom", Vector2::new(0.0, 0.0), Vector2::new(0.0, 1.0), 0);
    w.add_line_wall("left", Vector2::new(0.0, 0.0), Vector2::new(1.0, 0.0), 0);
    w.add_line_wall(
        "right",
        Vector2::new(width, 0.0),
        Vector2::new(-1.0, 0.0),
        0,
    );
    let pitch = 2.0 * r_max * 1.02;
    let per_row = ((width / pitch).floor() as usize).max(1);
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut uniform = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    for i in 0..n {
        let (ix, iy) = (i % per_row, i / per_row);
        let r = r_min + (r_max - r_min) * uniform();
        let x = pitch * (ix as f64 + 0.5) + (uniform() - 0.5) * 0.02 * r_max;
        let y = pitch * (iy as f64 + 0.5);
        w.add_grain(Vector2::new(x, y), r, 2500.0, 0);
    }
    w
}

/// Contact updates per second of bare Gauss–Seidel sweeps (natural order, one thread, no error
/// evaluation, no acceleration) over the contacts of the last step of `w`, from its impulses:
/// `contacts × sweeps / seconds`. Measures the O(1) contact update itself.
pub fn sweep_rate(w: &World, sweeps: usize) -> f64 {
    let mut rows = w.contacts().rows.clone();
    if rows.is_empty() || sweeps == 0 {
        return 0.0;
    }
    let inv: Vec<[f64; 3]> = w.bodies.iter().map(crate::Body::inverse_mass).collect();
    let mut vel: Vec<[f64; 3]> = w
        .bodies
        .iter()
        .map(|b| [b.velocity.x, b.velocity.y, b.omega])
        .collect();
    let order: Vec<u32> = (0..rows.len() as u32).collect();
    let t0 = Instant::now();
    for _ in 0..sweeps {
        crate::solver::sweep(&mut rows, &order, &mut vel, &inv, 1.0);
    }
    let secs = t0.elapsed().as_secs_f64();
    std::hint::black_box(&rows);
    (rows.len() * sweeps) as f64 / secs.max(1e-12)
}

/// Outcome of settling a column to rest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SettleReport {
    /// Grains.
    pub grains: usize,
    /// Box width (m); NaN when unknown ([`settle`] of a given world).
    pub width: f64,
    /// Steps until rest.
    pub steps: u64,
    /// Simulated time (s).
    pub simulated_seconds: f64,
    /// Smallest and largest time step the steps used (s).
    pub dt_range: [f64; 2],
    /// Wall-clock seconds (building excluded).
    pub wall_seconds: f64,
    /// Mean sweeps per step.
    pub mean_sweeps: f64,
    /// Steps that stopped at the sweep cap.
    pub unconverged_steps: u64,
    /// Final kinetic / potential energy (potential `Σ m g y`, y above the floor).
    pub energy_ratio: f64,
    /// Whether the ratio went below the target, on a step whose solve converged, before the
    /// time limit.
    pub settled: bool,
    /// Height of the highest grain top (m).
    pub height: f64,
}

/// Kinetic energy `Σ ½ m |v|² + ½ I ω²` over potential energy `Σ m g y` of the grains (floor at
/// y = 0).
pub fn energy_ratio(w: &World) -> f64 {
    let g = w.params.gravity.norm();
    let (mut ke, mut pe) = (0.0, 0.0);
    for b in w.bodies.iter().filter(|b| b.kind == crate::BodyKind::Grain) {
        ke += 0.5 * b.mass * b.velocity.norm_squared() + 0.5 * b.inertia * b.omega * b.omega;
        pe += b.mass * g * b.position.y;
    }
    if pe > 0.0 {
        ke / pe
    } else {
        f64::INFINITY
    }
}

/// Steps `w` until [`energy_ratio`] < `target` after a step whose solve converged (or
/// `max_time` simulated seconds), timed; with
/// `control`, the time step follows [`StepControl`] (starting from `w.params.dt`); without it,
/// steps whose solve does not converge are subdivided as `w.params.solver.max_halvings` allows
/// ([`step_subdivided`]; `unconverged_steps` counts those left unconverged at the largest
/// subdivision, `dt_range` the sub-steps).
pub fn settle(
    w: &mut World,
    target: f64,
    max_time: f64,
    mut control: Option<StepControl>,
) -> SettleReport {
    let t0 = Instant::now();
    let (mut steps, mut sweeps, mut unconverged) = (0u64, 0u64, 0u64);
    let (mut simulated, mut dt_min, mut dt_max) = (0.0f64, f64::INFINITY, 0.0f64);
    let mut ratio = energy_ratio(w);
    // Rest is declared on a step whose solve converged: a capped step carries its best
    // iterate, and a packing held still by impulses that do not solve the step is not at rest
    // (a primed deposit could otherwise be declared settled after one capped step, its time
    // reported as 0).
    let mut last_converged = false;
    let mut subdivision = Subdivision::default();
    // half a step of slack: the sum of the steps must not add a step to a fixed-step run
    while simulated < max_time - 0.5 * w.params.dt {
        let h = w.params.dt;
        let (rep, sub_h) = if control.is_some() {
            let Ok(rep) = w.step() else { break };
            (rep, h)
        } else {
            let Ok(s) = step_subdivided(w, &mut subdivision) else {
                break;
            };
            (s.report, h / f64::from(1u32 << s.halvings))
        };
        steps += 1;
        simulated += h;
        dt_min = dt_min.min(sub_h);
        dt_max = dt_max.max(sub_h);
        sweeps += rep.solver.iterations as u64;
        unconverged += u64::from(!rep.solver.converged);
        ratio = energy_ratio(w);
        last_converged = rep.solver.converged;
        if ratio < target && last_converged {
            break;
        }
        if let Some(c) = control.as_mut() {
            c.after(w, &rep);
        }
    }
    let height = w
        .bodies
        .iter()
        .filter(|b| b.kind == crate::BodyKind::Grain)
        .map(|b| b.position.y + b.radius)
        .fold(0.0, f64::max);
    let grains = w
        .bodies
        .iter()
        .filter(|b| b.kind == crate::BodyKind::Grain)
        .count();
    SettleReport {
        grains,
        width: f64::NAN,
        steps,
        simulated_seconds: simulated,
        dt_range: if steps > 0 {
            [dt_min, dt_max]
        } else {
            [w.params.dt; 2]
        },
        wall_seconds: t0.elapsed().as_secs_f64(),
        mean_sweeps: sweeps as f64 / steps.max(1) as f64,
        unconverged_steps: unconverged,
        energy_ratio: ratio,
        settled: ratio < target && last_converged,
        height,
    }
}

/// Bytes held by the engine per grain and per contact, from the sizes of its data structures
/// (bodies, colliders, solver and detection buffers; contact rows, geometry, status, the previous
/// step's copy kept for warm starting, sweep order and its wavefront schedule, Anderson history
/// with memory `m`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MemoryFootprint {
    /// Bytes per grain (B).
    pub per_grain: usize,
    /// Bytes per contact (B).
    pub per_contact: usize,
}

impl MemoryFootprint {
    /// The footprint of the current layout with Anderson memory `m`.
    pub fn current(anderson_memory: usize) -> Self {
        use std::mem::size_of;
        let per_grain = size_of::<crate::Body>()
            + size_of::<crate::collider::Collider>()
            + 3 * size_of::<[f64; 3]>() // velocities, inverse masses, free velocities
            + 3 * size_of::<[f64; 3]>() // body forces
            + 4 + 16 + 8 + 8 + 4 + 4 + 4 // detector: collider, centre, radius, margin, cells
            + 4 + 8 + 16 + 8 + 4 // candidate list: collider, radius, centre, reach, start
            + 4; // wavefront schedule: depth
        let one_set = size_of::<crate::contact::ContactRow>()
            + size_of::<crate::contact::ContactGeometry>()
            + size_of::<crate::local::ContactStatus>();
        let per_contact = 2 * one_set // current and previous step
            + 4 // sweep order
            + 4 + 4 + 12 // wavefront schedule: order, key, offsets (3 a depth: at most)
            + 8 // detection neighbour list
            + 10 // candidate pairs: 8 B each, 1.2 per contact in the settled poured column
            + 2 * 8 * (2 * anderson_memory + 2) // Anderson differences and iterates
            + 16; // best iterate
        MemoryFootprint {
            per_grain,
            per_contact,
        }
    }

    /// What the parallel mode ([`crate::SolverParams::parallel`]) adds: the block-contiguous copy
    /// of the problem ([`crate::blocked::BlockLayout`]: rows, body vectors, permutations) and
    /// the colouring with its body → contact adjacency.
    pub fn parallel_extra() -> Self {
        use std::mem::size_of;
        let per_grain = 3 * size_of::<[f64; 3]>() // velocities, free velocities, inverse masses
            + 2 * 16 // centres (world and copy)
            + 2 // mobility flags
            + 4 + 4 // permutation both ways
            + 8 + 4 + 4; // colouring: masks, slab, sort buffer
        let per_contact = size_of::<crate::contact::ContactRow>() // the copy
            + 8 + 4 // sort keys, permutation
            + 1 + 4 + 4; // colour, slab, class or slab order
        MemoryFootprint {
            per_grain,
            per_contact,
        }
    }

    /// The largest number of grains that fits in `bytes` with `contacts_per_grain` contacts each
    /// (about 2 in a dense 2D packing).
    pub fn largest_sample(&self, bytes: usize, contacts_per_grain: f64) -> usize {
        (bytes as f64 / (self.per_grain as f64 + contacts_per_grain * self.per_contact as f64))
            as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn largest_sample_fits_in_the_budget() {
        let m = MemoryFootprint::current(4);
        assert!(m.per_contact >= 2 * std::mem::size_of::<crate::contact::ContactRow>());
        let n = m.largest_sample(24 << 30, 2.0);
        let used = n as f64 * (m.per_grain as f64 + 2.0 * m.per_contact as f64);
        assert!(used <= (24u64 << 30) as f64);
        assert!(used + m.per_grain as f64 + 2.0 * m.per_contact as f64 > (24u64 << 30) as f64);
    }
}
