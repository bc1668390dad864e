//! Seeded polydisperse radii.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::config::GrainSpec;

/// `n` radii uniform in `[mean − spread, mean + spread]` (m), drawn from `rng`.
pub fn uniform_radii(rng: &mut ChaCha8Rng, n: usize, spec: &GrainSpec) -> Vec<f64> {
    (0..n)
        .map(|_| {
            if spec.radius_spread > 0.0 {
                rng.random_range(spec.radius_min()..=spec.radius_max())
            } else {
                spec.radius_mean
            }
        })
        .collect()
}

/// Total planar area `Σ π R²` (m²).
pub fn total_area(radii: &[f64]) -> f64 {
    radii.iter().map(|r| std::f64::consts::PI * r * r).sum()
}
