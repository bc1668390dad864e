//! The height profile and the front of a granular deposit on the floor y = 0, and the published
//! runout scalings of collapsed columns.
//!
//! ## Profile
//!
//! Bins of width `b` (one mean grain diameter) from the symmetry wall x = 0. The height of bin
//! `k` is that of the topmost grain surface over it,
//!
//! `h_k = max_i [ y_i + √(R_i² − (clamp(x_i, k b, (k+1) b) − x_i)²) ]`
//!
//! over the disks `i` (centre `x_i, y_i`, radius `R_i`) that overlap the bin's column
//! `[k b, (k+1) b]`, and 0 over an empty bin (the floor). The *continuous mass* is the run of
//! bins from x = 0 up to the first empty bin: a grain ahead of a gap is not part of it.
//!
//! ## Front
//!
//! The front `x_f` is the right edge `(k+1) b` of the last bin of the run from x = 0 whose
//! height exceeds the threshold (one mean diameter): the front of the mass at least two grains
//! thick, not a lone grain or a single rolling layer ahead of it. Its resolution is one bin.

use serde::{Deserialize, Serialize};

/// Height profile of a deposit (module documentation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HeightProfile {
    /// Bin width `b` (m).
    #[serde(with = "dem::serde_float")]
    pub bin: f64,
    /// Height of the topmost grain surface over each bin above the floor y = 0 (m), 0 for an
    /// empty bin; from x = 0 to the bin of the rightmost grain.
    #[serde(with = "crate::floats::vec")]
    pub h: Vec<f64>,
}

impl HeightProfile {
    /// The profile of the disks `(x, y, R)` (m) on bins of width `bin` (m) from x = 0; disks
    /// at x < 0 count over the bins they reach at x ≥ 0 only.
    pub fn of_disks(disks: impl IntoIterator<Item = (f64, f64, f64)>, bin: f64) -> Self {
        let mut h: Vec<f64> = Vec::new();
        if !(bin.is_finite() && bin > 0.0) {
            return Self { bin, h };
        }
        for (x, y, r) in disks {
            if !(x.is_finite() && y.is_finite() && r.is_finite() && r > 0.0) || x + r < 0.0 {
                continue;
            }
            let first = ((x - r) / bin).floor().max(0.0) as usize;
            // bins overlapped over a positive width: a disk whose edge is a bin's edge is not
            // over the next bin
            let last = (((x + r) / bin).ceil() - 1.0).max(0.0) as usize;
            if last >= h.len() {
                h.resize(last + 1, 0.0);
            }
            for (k, hk) in h.iter_mut().enumerate().take(last + 1).skip(first) {
                let (x0, x1) = (k as f64 * bin, (k + 1) as f64 * bin);
                let dx = x.clamp(x0, x1) - x;
                let s = r * r - dx * dx;
                if s >= 0.0 {
                    *hk = hk.max(y + s.sqrt());
                }
            }
        }
        Self { bin, h }
    }

    /// The profile of the grains of `snap`.
    pub fn of_snapshot(snap: &dem::Snapshot, bin: f64) -> Self {
        Self::of_disks(
            snap.bodies
                .iter()
                .filter(|b| b.kind == dem::BodyKind::Grain)
                .map(|b| (b.position.x, b.position.y, b.radius)),
            bin,
        )
    }

    /// The profile of the grains of `world`.
    pub fn of_world(world: &dem::World, bin: f64) -> Self {
        Self::of_disks(
            world
                .bodies
                .iter()
                .filter(|b| b.kind == dem::BodyKind::Grain)
                .map(|b| (b.position.x, b.position.y, b.radius)),
            bin,
        )
    }

    /// Number of bins of the continuous mass: from x = 0 up to the first empty bin.
    pub fn mass_bins(&self) -> usize {
        self.h
            .iter()
            .position(|&h| h <= 0.0)
            .unwrap_or(self.h.len())
    }

    /// The front `x_f` (m): the right edge of the last bin of the run from x = 0 whose height
    /// exceeds `threshold` (m); 0 when the first bin does not.
    pub fn front(&self, threshold: f64) -> f64 {
        let n = self.h.iter().take_while(|&&h| h > threshold).count();
        n as f64 * self.bin
    }

    /// Height of the first bin, `h` at x = 0 (m; 0 without grains).
    pub fn height_at_wall(&self) -> f64 {
        self.h.first().copied().unwrap_or(0.0)
    }

    /// `(x, h)` at the bin centres of the continuous mass (m).
    pub fn points(&self) -> Vec<(f64, f64)> {
        self.h[..self.mass_bins()]
            .iter()
            .enumerate()
            .map(|(k, &h)| ((k as f64 + 0.5) * self.bin, h))
            .collect()
    }
}

/// Published runout scalings of collapsed granular columns, `(r_∞ − R₀)/R₀` against the aspect
/// ratio `a = H₀/R₀`: the two-dimensional (channel) experiments of Lube, Huppert, Sparks &
/// Freundt (Phys. Rev. E 72, 041301, 2005), `1.2 a` for `a ≲ 1.8` and `1.9 a^{2/3}` for
/// `a ≳ 2.8`. The axisymmetric experiments (Lajeunesse, Mangeney-Castelnau & Vilotte, Phys.
/// Fluids 16, 2004; Lube, Huppert, Sparks & Hallworth, J. Fluid Mech. 508, 2004) give the same
/// linear law for small `a` (`1.24 a`, `a ≲ 1.7`) and `1.6 a^{1/2}` above; the two-dimensional
/// contact-dynamics simulations of Staron & Hinch (J. Fluid Mech. 545, 2005) follow a power
/// `≈ 2/3` at large `a`.
pub mod scaling {
    /// Prefactor λ of the linear regime `(r_∞ − R₀)/R₀ = λ a` (Lube et al. 2005, 2D).
    pub const LINEAR: f64 = 1.2;
    /// Upper end of the linear regime (Lube et al. 2005).
    pub const LINEAR_MAX_A: f64 = 1.8;
    /// Prefactor λ' of the power regime `(r_∞ − R₀)/R₀ = λ' a^{2/3}` (Lube et al. 2005, 2D).
    pub const POWER: f64 = 1.9;
    /// Lower end of the power regime (Lube et al. 2005).
    pub const POWER_MIN_A: f64 = 2.8;

    /// `(r_∞ − R₀)/R₀ = λ a` (linear regime).
    pub fn linear(a: f64) -> f64 {
        LINEAR * a
    }

    /// `(r_∞ − R₀)/R₀ = λ' a^{2/3}` (power regime).
    pub fn power(a: f64) -> f64 {
        POWER * a.powf(2.0 / 3.0)
    }

    /// The scaling of the regime of `a`: [`linear`] below [`POWER_MIN_A`], [`power`] from it.
    /// The two are fits over separate ranges and do not join: between the regimes' ends they
    /// differ by up to 25 % (at a = 1.8: 2.16 and 2.81).
    pub fn normalised_runout(a: f64) -> f64 {
        if a < POWER_MIN_A {
            linear(a)
        } else {
            power(a)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One disk of radius 1 centred at (2.5, 1) on bins of width 1: it covers bins 1..=3; the
    /// middle bin holds its top (h = 2), the side bins the circle at 0.5 from the centre,
    /// `1 + √(1 − 0.25)`; bin 0 is empty.
    #[test]
    fn one_disk_has_the_circle_as_profile() {
        let p = HeightProfile::of_disks([(2.5, 1.0, 1.0)], 1.0);
        let side = 1.0 + 0.75f64.sqrt();
        assert_eq!(p.h.len(), 4);
        assert_eq!(p.h[0], 0.0);
        assert!((p.h[1] - side).abs() < 1e-15 && (p.h[3] - side).abs() < 1e-15);
        assert_eq!(p.h[2], 2.0);
        assert_eq!(p.mass_bins(), 0, "a gap at x = 0: no continuous mass");
        assert_eq!(p.front(0.5), 0.0);
    }

    /// A rectangle of stacked unit disks, 3 columns × 4 rows, then a lone disk after a gap:
    /// the mass ends at the gap, the front at the rectangle's edge (x = 6, height 8 > 1), the
    /// lone disk (height 2 > 1) being past an empty bin.
    #[test]
    fn the_front_is_the_edge_of_the_continuous_mass() {
        let mut disks = Vec::new();
        for i in 0..3 {
            for j in 0..4 {
                disks.push((1.0 + 2.0 * i as f64, 1.0 + 2.0 * j as f64, 1.0));
            }
        }
        disks.push((11.0, 1.0, 1.0));
        let p = HeightProfile::of_disks(disks, 1.0);
        assert_eq!(p.mass_bins(), 6);
        assert_eq!(p.front(1.0), 6.0);
        assert_eq!(p.height_at_wall(), 8.0);
        assert_eq!(p.points().len(), 6);
        assert_eq!(p.points()[0], (0.5, 8.0));
        // a thinner layer (one grain, height 2) in front: past the threshold 2.5 it is not front
        let mut thin = HeightProfile::of_disks([(1.0, 1.0, 1.0), (1.0, 3.0, 1.0)], 1.0);
        thin.h.extend([2.0, 2.0]);
        assert_eq!(thin.front(2.5), 2.0);
        assert_eq!(thin.front(1.5), 4.0);
    }
}
