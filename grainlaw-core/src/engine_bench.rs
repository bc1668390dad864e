//! Measurements of the engine behind `grainlaw bench` (`grainlaw::bench_cmd`; the benchmark
//! worlds are built in `crate::benchmarks`, settled by `dem::settle`): the bare sweep rate
//! of a world's contacts ([`sweep_rate`]) and the memory footprint of the engine's data layout
//! ([`MemoryFootprint`]).

use std::time::Instant;

use dem::World;
use serde::{Deserialize, Serialize};

/// Contact updates per second of bare Gauss–Seidel sweeps (natural order, one thread, no error
/// evaluation, no acceleration) over the contacts of the last step of `w`, from its impulses:
/// `contacts × sweeps / seconds`. Measures the O(1) contact update itself.
pub fn sweep_rate(w: &World, sweeps: usize) -> f64 {
    let mut rows = w.contacts().rows.clone();
    if rows.is_empty() || sweeps == 0 {
        return 0.0;
    }
    let inv: Vec<dem::math::Spatial> = w.bodies.iter().map(dem::Body::inverse_mass).collect();
    let mut vel: Vec<dem::math::Spatial> = w
        .bodies
        .iter()
        .map(|b| [b.velocity.x, b.velocity.y, b.omega])
        .collect();
    let order: Vec<u32> = (0..rows.len() as u32).collect();
    let t0 = Instant::now();
    for _ in 0..sweeps {
        dem::sweep::sweep(&mut rows, &order, &mut vel, &inv, 1.0);
    }
    let secs = t0.elapsed().as_secs_f64();
    std::hint::black_box(&rows);
    (rows.len() * sweeps) as f64 / secs.max(1e-12)
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
        let per_grain = size_of::<dem::Body>()
            + size_of::<dem::collider::Collider>()
            + 3 * size_of::<dem::math::Spatial>() // velocities, inverse masses, free velocities
            + 3 * size_of::<dem::math::Spatial>() // body forces
            + 4 + 16 + 8 + 8 + 4 + 4 + 4 // detector: collider, centre, radius, margin, cells
            + 4 + 8 + 16 + 8 + 4 // candidate list: collider, radius, centre, reach, start
            + 4; // wavefront schedule: depth
        let one_set = size_of::<dem::contact::ContactRow>()
            + size_of::<dem::contact::ContactGeometry>()
            + size_of::<dem::local::ContactStatus>();
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

    /// What the parallel mode ([`dem::SolverParams::parallel`]) adds: the block-contiguous copy
    /// of the problem ([`dem::blocked::BlockLayout`]: rows, body vectors, permutations) and
    /// the colouring with its body → contact adjacency.
    pub fn parallel_extra() -> Self {
        use std::mem::size_of;
        let per_grain = 3 * size_of::<dem::math::Spatial>() // velocities, free velocities, inverse masses
            + 2 * 16 // centres (world and copy)
            + 2 // mobility flags
            + 4 + 4 // permutation both ways
            + 8 + 4 + 4; // colouring: masks, slab, sort buffer
        let per_contact = size_of::<dem::contact::ContactRow>() // the copy
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
        assert!(m.per_contact >= 2 * std::mem::size_of::<dem::contact::ContactRow>());
        let n = m.largest_sample(24 << 30, 2.0);
        let used = n as f64 * (m.per_grain as f64 + 2.0 * m.per_contact as f64);
        assert!(used <= (24u64 << 30) as f64);
        assert!(used + m.per_grain as f64 + 2.0 * m.per_contact as f64 > (24u64 << 30) as f64);
    }
}
