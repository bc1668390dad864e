//! Memory layout of the parallel solve: bodies and contacts renumbered block by block.
//!
//! The parallel sweep ([`crate::colouring::ContactColouring::build_blocked`]) gives each thread
//! the contacts of a spatial slab. In the world's own numbering the bodies and contacts of
//! different slabs are interleaved in memory (bodies are numbered in creation order, contacts
//! by collider pair), so two threads keep writing to the same cache lines and the sweep hardly
//! scales. [`BlockLayout`] copies the problem into a numbering where the bodies of a slab, and
//! the contacts interior to it, are contiguous: mobile bodies sorted along the longer side of
//! their bounding box (then by index), immobile bodies after them; contacts sorted by slab
//! (separator last), then by their index. The solve runs on the copy; impulses and velocities
//! are copied back. O(N log N + contacts) per step, a few percent of a solve.

use crate::colouring::slab_order;
use crate::contact::ContactRow;
use crate::math::Spatial;

/// A block-contiguous copy of a contact problem (see the module documentation).
#[derive(Debug, Clone, Default)]
pub struct BlockLayout {
    /// Old index of each new body.
    body_old: Vec<u32>,
    /// New index of each old body.
    body_new: Vec<u32>,
    /// Old index of each new contact.
    row_old: Vec<u32>,
    keys: Vec<(u32, u32)>,
    /// Contact rows, renumbered.
    pub rows: Vec<ContactRow>,
    /// Velocities, renumbered.
    pub vel: Vec<Spatial>,
    /// Free velocities, renumbered.
    pub v_free: Vec<Spatial>,
    /// Inverse masses, renumbered.
    pub inv: Vec<Spatial>,
    /// Mobility flags, renumbered.
    pub mobile: Vec<bool>,
    /// Body centres (m), renumbered.
    pub pos: Vec<[f64; 2]>,
}

impl BlockLayout {
    /// Copies the problem into the block-contiguous numbering for `blocks` slabs.
    #[allow(clippy::too_many_arguments)]
    pub fn gather(
        &mut self,
        rows: &[ContactRow],
        vel: &[Spatial],
        v_free: &[Spatial],
        inv: &[Spatial],
        mobile: &[bool],
        pos: &[[f64; 2]],
        blocks: usize,
    ) {
        let n = mobile.len();
        let blocks = blocks.max(1);
        slab_order(mobile, pos, &mut self.body_old);
        let m = self.body_old.len().max(1);
        self.body_old
            .extend((0..n as u32).filter(|&i| !mobile[i as usize]));
        self.body_new.clear();
        self.body_new.resize(n, 0);
        for (new, &old) in self.body_old.iter().enumerate() {
            self.body_new[old as usize] = new as u32;
        }
        let block_of = |body: u32| -> Option<u32> {
            let new = self.body_new[body as usize] as usize;
            (new < m && mobile[body as usize]).then(|| (new * blocks / m) as u32)
        };
        self.keys.clear();
        for (k, c) in rows.iter().enumerate() {
            let b = match (block_of(c.a), block_of(c.b)) {
                (Some(x), Some(y)) if x == y => x,
                (Some(_), Some(_)) => u32::MAX,
                (Some(x), None) | (None, Some(x)) => x,
                (None, None) => 0,
            };
            self.keys.push((b, k as u32));
        }
        self.keys.sort_unstable();
        self.row_old.clear();
        self.row_old.extend(self.keys.iter().map(|&(_, k)| k));
        self.rows.clear();
        self.rows.extend(self.row_old.iter().map(|&k| {
            let mut c = rows[k as usize];
            c.a = self.body_new[c.a as usize];
            c.b = self.body_new[c.b as usize];
            c
        }));
        let perm = |src: &[Spatial], dst: &mut Vec<Spatial>| {
            dst.clear();
            dst.extend(self.body_old.iter().map(|&i| src[i as usize]));
        };
        perm(vel, &mut self.vel);
        perm(v_free, &mut self.v_free);
        perm(inv, &mut self.inv);
        self.mobile.clear();
        self.mobile
            .extend(self.body_old.iter().map(|&i| mobile[i as usize]));
        self.pos.clear();
        self.pos
            .extend(self.body_old.iter().map(|&i| pos[i as usize]));
    }

    /// Old index of each new contact (the copy's row `j` is the problem's row `row_old()[j]`).
    pub fn row_old(&self) -> &[u32] {
        &self.row_old
    }

    /// Copies the impulses (with the Lemke basis bits that go with them) and velocities back
    /// to the world's numbering.
    pub fn scatter(&self, rows: &mut [ContactRow], vel: &mut [Spatial]) {
        for (c, &k) in self.rows.iter().zip(&self.row_old) {
            rows[k as usize].r = c.r;
            rows[k as usize].basis = c.basis;
        }
        for (v, &i) in self.vel.iter().zip(&self.body_old) {
            vel[i as usize] = *v;
        }
    }
}
