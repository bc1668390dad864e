//! Colouring of the contact graph for the parallel Gauss–Seidel sweep, with spatial blocks.
//!
//! With blocks ([`ContactColouring::build_blocked`], used by the world), the mobile bodies are
//! split into slabs; contacts inside one slab are swept slab by slab concurrently, and only the
//! contacts across slabs (the separator, a few percent) are coloured as below.
//!
//! Two contacts conflict when they act on a common *mobile* body (one with a non-zero inverse
//! mass component): updating both at once would race on that body's velocity. Contacts that
//! share only immobile bodies (fixed or driven walls, whose velocity the solver never changes)
//! do not conflict. A colouring assigns each contact a colour so that no two contacts of one
//! colour conflict; the sweep then visits the colours in turn and updates the contacts of a
//! colour in any order, in parallel, with exactly the same result as one after the other:
//!
//! ```text
//! for c in colours:           (sequential)
//!     for α in class(c):      (independent: parallel, any order, same numbers)
//!         r_α ← local solve, v_a, v_b updated
//! ```
//!
//! The colouring is greedy first-fit in contact order (the collider-pair order of detection, so
//! the same input gives the same colouring): contact α takes the lowest colour used by neither
//! of its mobile bodies, `c_α = min{c : c ∉ C(a) ∪ C(b)}`, with `C(i)` a 64-bit mask of the
//! colours already at body `i`. A disk packing has at most about 6 contacts per grain, so the
//! line graph has degree ≤ 2·(6 − 1) and first-fit needs at most 11 colours; a body with more
//! than 64 contacts (a clump) sends the contacts that find no free colour to a last class that
//! is swept sequentially. Cost O(contacts), no allocation in the steady state.

use crate::contact::ContactRow;

/// Colour classes of the contacts of a step: `order[offsets[c]..offsets[c + 1]]` are the
/// contacts of colour `c`, ascending within the class. The last class is sequential when
/// [`ContactColouring::sequential_tail`] is set.
#[derive(Debug, Clone, Default)]
pub struct ContactColouring {
    /// Contact indices grouped by colour.
    pub order: Vec<u32>,
    /// Start of each colour class in `order`, plus the end (`colours + 1` entries).
    pub offsets: Vec<usize>,
    /// True when the last class holds contacts that found no free colour among 64 and must be
    /// updated one after the other.
    pub sequential_tail: bool,
    /// Interior contacts of each spatial block (see [`ContactColouring::build_blocked`]):
    /// `block_order[block_offsets[k]..block_offsets[k + 1]]`, ascending. Empty without blocks.
    pub block_order: Vec<u32>,
    /// Offsets into `block_order` (`blocks + 1` entries, or none).
    pub block_offsets: Vec<usize>,
    masks: Vec<u64>,
    body_block: Vec<u32>,
    contact_block: Vec<u32>,
    sort_buf: Vec<u32>,
    colour: Vec<u8>,
    counts: Vec<usize>,
}

/// The mobile bodies sorted along the longer side of their bounding box (ties by index), into
/// `out`: the order that cuts them into slabs of equal count.
pub fn slab_order(mobile: &[bool], pos: &[[f64; 2]], out: &mut Vec<u32>) {
    out.clear();
    out.extend((0..mobile.len() as u32).filter(|&i| mobile[i as usize]));
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for &i in out.iter() {
        for d in 0..2 {
            lo[d] = lo[d].min(pos[i as usize][d]);
            hi[d] = hi[d].max(pos[i as usize][d]);
        }
    }
    let axis = usize::from(hi[1] - lo[1] > hi[0] - lo[0]);
    out.sort_unstable_by(|&i, &j| {
        pos[i as usize][axis]
            .total_cmp(&pos[j as usize][axis])
            .then(i.cmp(&j))
    });
}

/// Colour of the contacts that found no free colour (swept sequentially).
const OVERFLOW: u8 = 64;
/// Marker of the contacts interior to a block (not coloured).
const INTERIOR: u8 = 255;
/// Block of the separator contacts.
const SEPARATOR: u32 = u32::MAX;

impl ContactColouring {
    /// Number of colour classes.
    pub fn colours(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// The contacts of class `c`.
    pub fn class(&self, c: usize) -> &[u32] {
        &self.order[self.offsets[c]..self.offsets[c + 1]]
    }

    /// Whether class `c` must be swept sequentially.
    pub fn is_sequential(&self, c: usize) -> bool {
        self.sequential_tail && c + 1 == self.colours()
    }

    /// Number of spatial blocks (0 without).
    pub fn blocks(&self) -> usize {
        self.block_offsets.len().saturating_sub(1)
    }

    /// The interior contacts of block `k`.
    pub fn block(&self, k: usize) -> &[u32] {
        &self.block_order[self.block_offsets[k]..self.block_offsets[k + 1]]
    }

    /// Colours all of `rows` greedily (no blocks); `mobile[i]` tells whether body `i` has a
    /// non-zero inverse mass component.
    pub fn build(&mut self, rows: &[ContactRow], mobile: &[bool]) {
        self.block_order.clear();
        self.block_offsets.clear();
        self.contact_block.clear();
        self.contact_block.resize(rows.len(), SEPARATOR);
        self.colour_separator(rows, mobile);
    }

    /// Splits the mobile bodies into `blocks` slabs of equal count along the longer side of
    /// their bounding box (`pos`: body centres, m); a contact whose mobile bodies all lie in one
    /// slab is interior to it, the others form the separator, coloured greedily. The sweep then
    /// runs the blocks' interiors concurrently (each in ascending contact order), then the
    /// separator classes: two synchronisations per sweep plus one per separator class, instead
    /// of one per colour. The split depends on the positions only, never on the thread count.
    pub fn build_blocked(
        &mut self,
        rows: &[ContactRow],
        mobile: &[bool],
        pos: &[[f64; 2]],
        blocks: usize,
    ) {
        let blocks = blocks.max(1);
        let n = mobile.len();
        slab_order(mobile, pos, &mut self.sort_buf);
        self.body_block.clear();
        self.body_block.resize(n, u32::MAX);
        let m = self.sort_buf.len().max(1);
        for (rank, &i) in self.sort_buf.iter().enumerate() {
            self.body_block[i as usize] = (rank * blocks / m) as u32;
        }
        self.contact_block.clear();
        let mut counts = vec![0usize; blocks + 1];
        for c in rows {
            let (a, b) = (c.a as usize, c.b as usize);
            let ba = mobile[a].then(|| self.body_block[a]);
            let bb = mobile[b].then(|| self.body_block[b]);
            let k = match (ba, bb) {
                (Some(x), Some(y)) if x == y => x,
                (Some(_), Some(_)) => SEPARATOR,
                (Some(x), None) | (None, Some(x)) => x,
                (None, None) => 0,
            };
            if k != SEPARATOR {
                counts[k as usize + 1] += 1;
            }
            self.contact_block.push(k);
        }
        for k in 0..blocks {
            counts[k + 1] += counts[k];
        }
        self.block_offsets.clear();
        self.block_offsets.extend_from_slice(&counts);
        self.block_order.clear();
        self.block_order.resize(counts[blocks], 0);
        for (i, &k) in self.contact_block.iter().enumerate() {
            if k != SEPARATOR {
                self.block_order[counts[k as usize]] = i as u32;
                counts[k as usize] += 1;
            }
        }
        self.colour_separator(rows, mobile);
    }

    /// Greedy first-fit colouring of the separator contacts (all, without blocks).
    fn colour_separator(&mut self, rows: &[ContactRow], mobile: &[bool]) {
        self.masks.clear();
        self.masks.resize(mobile.len(), 0);
        self.colour.clear();
        self.counts.clear();
        self.counts.resize(OVERFLOW as usize + 1, 0);
        for (c, &k) in rows.iter().zip(&self.contact_block) {
            if k != SEPARATOR {
                self.colour.push(INTERIOR);
                continue;
            }
            let (a, b) = (c.a as usize, c.b as usize);
            let (ma, mb) = (mobile[a], mobile[b]);
            let used = if ma { self.masks[a] } else { 0 } | if mb { self.masks[b] } else { 0 };
            let k = used.trailing_ones();
            let colour = if k >= 64 {
                OVERFLOW
            } else {
                let bit = 1u64 << k;
                if ma {
                    self.masks[a] |= bit;
                }
                if mb {
                    self.masks[b] |= bit;
                }
                k as u8
            };
            self.colour.push(colour);
            self.counts[colour as usize] += 1;
        }
        let used_colours = self.counts[..OVERFLOW as usize]
            .iter()
            .rposition(|&n| n > 0)
            .map_or(0, |p| p + 1);
        self.sequential_tail = self.counts[OVERFLOW as usize] > 0;
        // Counting sort into classes (stable: ascending contact index within a class).
        self.offsets.clear();
        self.offsets.push(0);
        let mut start = Vec::with_capacity(used_colours + 1);
        let mut total = 0;
        for c in 0..used_colours {
            start.push(total);
            total += self.counts[c];
            self.offsets.push(total);
        }
        if self.sequential_tail {
            start.push(total);
            total += self.counts[OVERFLOW as usize];
            self.offsets.push(total);
        }
        self.order.clear();
        self.order.resize(total, 0);
        for (i, &c) in self.colour.iter().enumerate() {
            if c == INTERIOR {
                continue;
            }
            let slot = if c == OVERFLOW {
                used_colours
            } else {
                c as usize
            };
            self.order[start[slot]] = i as u32;
            start[slot] += 1;
        }
    }

    /// Checks the defining property: within every parallel class no two contacts share a mobile
    /// body, and every contact appears exactly once. For tests.
    pub fn is_valid(&self, rows: &[ContactRow], mobile: &[bool]) -> bool {
        let mut seen = vec![false; rows.len()];
        // blocks: no mobile body in two blocks' interiors
        let mut owner = vec![usize::MAX; mobile.len()];
        for k in 0..self.blocks() {
            for &i in self.block(k) {
                let r = &rows[i as usize];
                for body in [r.a as usize, r.b as usize] {
                    if mobile[body] {
                        if owner[body] != usize::MAX && owner[body] != k {
                            return false;
                        }
                        owner[body] = k;
                    }
                }
            }
        }
        for &i in self.order.iter().chain(&self.block_order) {
            if std::mem::replace(&mut seen[i as usize], true) {
                return false;
            }
        }
        if !seen.iter().all(|&s| s) {
            return false;
        }
        let mut owner = vec![usize::MAX; mobile.len()];
        for c in 0..self.colours() {
            if self.is_sequential(c) {
                continue;
            }
            for &i in self.class(c) {
                let r = &rows[i as usize];
                for body in [r.a as usize, r.b as usize] {
                    if mobile[body] {
                        if owner[body] == c {
                            return false;
                        }
                        owner[body] = c;
                    }
                }
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(a: u32, b: u32) -> ContactRow {
        ContactRow {
            a,
            b,
            ..Default::default()
        }
    }

    #[test]
    fn chain_needs_two_colours_and_walls_do_not_conflict() {
        // A chain of 6 bodies 1..=6 plus a fixed wall 0 touching all of them.
        let mut rows: Vec<ContactRow> = (1..6).map(|i| row(i, i + 1)).collect();
        rows.extend((1..=6).map(|i| row(0, i)));
        let mut mobile = vec![true; 7];
        mobile[0] = false;
        let mut c = ContactColouring::default();
        c.build(&rows, &mobile);
        assert!(c.is_valid(&rows, &mobile));
        // chain edges alternate 2 colours; each wall contact conflicts with ≤ 2 chain edges
        assert!(c.colours() <= 3, "{} colours", c.colours());
        assert!(!c.sequential_tail);
        // a mobile body 0 makes all wall contacts conflict: at least 6 colours
        let all = vec![true; 7];
        c.build(&rows, &all);
        assert!(c.is_valid(&rows, &all));
        assert!(c.colours() >= 6);
    }

    #[test]
    fn a_body_with_more_than_64_contacts_overflows_to_a_sequential_class() {
        let rows: Vec<ContactRow> = (1..=100).map(|i| row(0, i)).collect();
        let mobile = vec![true; 101];
        let mut c = ContactColouring::default();
        c.build(&rows, &mobile);
        assert!(c.is_valid(&rows, &mobile));
        assert!(c.sequential_tail);
        assert_eq!(c.colours(), 65);
        assert_eq!(c.class(64).len(), 36);
    }
}
