//! Orders in which Gauss–Seidel visits the contacts.
//!
//! Nonlinear Gauss–Seidel carries information along the sweep direction within one sweep, so the
//! order matters. In a pile the free velocity is non-zero only at the contacts pressed by the
//! free motion (the floor), and the weight has to travel from there through the whole network.

use super::block_csr::BlockCsr2;

/// The contact order of a Gauss–Seidel sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ContactOrdering {
    /// The order of the input.
    Natural,
    /// Breadth-first over the contact graph (contacts linked by a non-zero block of W), starting
    /// from the contacts the free motion presses (`q_n < 0`): level by level away from where the
    /// load enters (bottom-up in a pile). Contacts not reached follow in input order.
    #[default]
    LoadFront,
    /// [`ContactOrdering::LoadFront`] reversed (top-down in a pile).
    ReverseLoadFront,
}

/// The permutation `perm[new] = old` for `ordering`, given the block pattern of W and `q`
/// (interleaved, length 2 nc).
pub fn contact_order(ordering: ContactOrdering, w: &BlockCsr2, q: &[f64]) -> Vec<u32> {
    let n = w.n();
    match ordering {
        ContactOrdering::Natural => (0..n as u32).collect(),
        ContactOrdering::LoadFront => load_front(w, q),
        ContactOrdering::ReverseLoadFront => {
            let mut p = load_front(w, q);
            p.reverse();
            p
        }
    }
}

fn load_front(w: &BlockCsr2, q: &[f64]) -> Vec<u32> {
    let n = w.n();
    let mut seen = vec![false; n];
    let mut order: Vec<u32> = Vec::with_capacity(n);
    for a in 0..n {
        if q[2 * a] < 0.0 {
            seen[a] = true;
            order.push(a as u32);
        }
    }
    let mut head = 0;
    let mut cursor = 0;
    loop {
        while head < order.len() {
            let a = order[head] as usize;
            head += 1;
            for (b, _) in w.row(a) {
                if !seen[b] {
                    seen[b] = true;
                    order.push(b as u32);
                }
            }
        }
        // Start again from the first contact not reached (disconnected parts).
        while cursor < n && seen[cursor] {
            cursor += 1;
        }
        if cursor == n {
            break;
        }
        seen[cursor] = true;
        order.push(cursor as u32);
    }
    order
}
