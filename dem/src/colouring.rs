//! Colouring of the contact graph for the parallel Gauss–Seidel sweep.
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
    /// Contacts of each mobile body: `body_contacts[body_offsets[i]..body_offsets[i + 1]]`, each
    /// `(contact << 1) | side` with side 0 when the body is the contact's `a`, 1 for `b`,
    /// ascending by contact. Empty for immobile bodies.
    pub body_contacts: Vec<u32>,
    /// Offsets into `body_contacts`, `bodies + 1` entries.
    pub body_offsets: Vec<u32>,
    masks: Vec<u64>,
    colour: Vec<u8>,
    counts: Vec<usize>,
}

/// Colour of the contacts that found no free colour (swept sequentially).
const OVERFLOW: u8 = 64;

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

    /// Colours `rows` greedily; `mobile[i]` tells whether body `i` has a non-zero inverse mass
    /// component.
    pub fn build(&mut self, rows: &[ContactRow], mobile: &[bool]) {
        self.masks.clear();
        self.masks.resize(mobile.len(), 0);
        self.colour.clear();
        self.counts.clear();
        self.counts.resize(OVERFLOW as usize + 1, 0);
        for c in rows {
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
        // Body → contacts adjacency (counting sort, ascending contact index per body).
        self.body_offsets.clear();
        self.body_offsets.resize(mobile.len() + 1, 0);
        for c in rows {
            for (body, m) in [(c.a as usize, mobile[c.a as usize]), (c.b as usize, mobile[c.b as usize])] {
                if m {
                    self.body_offsets[body + 1] += 1;
                }
            }
        }
        for i in 0..mobile.len() {
            self.body_offsets[i + 1] += self.body_offsets[i];
        }
        self.body_contacts.clear();
        self.body_contacts
            .resize(self.body_offsets[mobile.len()] as usize, 0);
        self.masks.clear();
        self.masks
            .extend(self.body_offsets[..mobile.len()].iter().map(|&o| o as u64));
        for (k, c) in rows.iter().enumerate() {
            for (side, body) in [(0u32, c.a as usize), (1u32, c.b as usize)] {
                if mobile[body] {
                    self.body_contacts[self.masks[body] as usize] = ((k as u32) << 1) | side;
                    self.masks[body] += 1;
                }
            }
        }
        self.order.clear();
        self.order.resize(total, 0);
        for (i, &c) in self.colour.iter().enumerate() {
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
        for &i in &self.order {
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
