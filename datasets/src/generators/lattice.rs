//! Regular stacks of equal disks in a box `[0, 2 R n] × [0, ∞)` (paper Fig. 5).
//!
//! - **rectangular**: `rows` rows of `n` disks, each disk on the one below (square lattice);
//! - **triangular**: rows of `n` and `n − 1` disks alternately, each upper disk in the notch of
//!   two lower ones (vertical pitch `√3 R`); the short rows do not touch the side walls;
//! - **cannonball**: a pyramid, rows of `n, n − 1, …, 1` disks in triangular packing.
//!
//! Rows are separated by an extra gap `gap · R` (and a random `[0, jitter · R]` per disk) so that
//! the stack settles under gravity into the contacts of the ideal lattice.

use dem::math::Vector;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// The three arrangements of the paper.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Arrangement {
    /// Square lattice.
    Rectangular,
    /// Triangular (hexagonal) lattice, rows alternately `n` and `n − 1` disks.
    Triangular,
    /// Pyramid of rows `n, n − 1, …, 1`.
    Cannonball,
}

impl Arrangement {
    /// All three, in the paper's order.
    pub const ALL: [Arrangement; 3] = [
        Arrangement::Rectangular,
        Arrangement::Triangular,
        Arrangement::Cannonball,
    ];

    /// Lower-case name (`rectangular`, `triangular`, `cannonball`).
    pub fn name(self) -> &'static str {
        match self {
            Arrangement::Rectangular => "rectangular",
            Arrangement::Triangular => "triangular",
            Arrangement::Cannonball => "cannonball",
        }
    }
}

/// Centres (m) of the disks of radius `r` for `n` disks in the bottom row and `rows` rows
/// (`cannonball` ignores `rows` and has `n` rows).
pub fn lattice(
    kind: Arrangement,
    n: usize,
    rows: usize,
    r: f64,
    gap: f64,
    jitter: f64,
    rng: &mut ChaCha8Rng,
) -> Vec<Vector> {
    let mut out = Vec::new();
    let (pitch, nrows) = match kind {
        Arrangement::Rectangular => (2.0 * r, rows),
        Arrangement::Triangular => (3f64.sqrt() * r, rows),
        Arrangement::Cannonball => (3f64.sqrt() * r, n),
    };
    let mut base = r + gap * r;
    for j in 0..nrows {
        let (count, x0) = match kind {
            Arrangement::Rectangular => (n, r),
            Arrangement::Triangular => {
                if j % 2 == 0 {
                    (n, r)
                } else {
                    (n - 1, 2.0 * r)
                }
            }
            Arrangement::Cannonball => (n - j, r * (1.0 + j as f64)),
        };
        for i in 0..count {
            let dy = if jitter > 0.0 {
                rng.random_range(0.0..=jitter) * r
            } else {
                0.0
            };
            out.push(Vector::new(x0 + 2.0 * r * i as f64, base + dy));
        }
        base += pitch + (gap + jitter) * r;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn counts_and_no_overlap() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let r = 0.005;
        for (kind, expected) in [
            (Arrangement::Rectangular, 36),
            (Arrangement::Triangular, 33),
            (Arrangement::Cannonball, 21),
        ] {
            let c = lattice(kind, 6, 6, r, 0.01, 0.02, &mut rng);
            assert_eq!(c.len(), expected, "{kind:?}");
            for i in 0..c.len() {
                assert!(c[i].x - r >= -1e-15 && c[i].x + r <= 12.0 * r + 1e-15);
                for j in 0..i {
                    assert!((c[i] - c[j]).norm() >= 2.0 * r * (1.0 - 1e-12));
                }
            }
        }
    }
}
