//! Seeded polydisperse radii.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// `n` radii uniform in `[mean − spread, mean + spread]` (m), drawn from `rng`; all `mean` when
/// `spread` is not positive (a scenario's `grain` table: `radius_mean`, `radius_spread`).
pub fn uniform_radii(rng: &mut ChaCha8Rng, n: usize, mean: f64, spread: f64) -> Vec<f64> {
    (0..n)
        .map(|_| {
            if spread > 0.0 {
                rng.random_range((mean - spread)..=(mean + spread))
            } else {
                mean
            }
        })
        .collect()
}

/// Total planar area `Σ π R²` (m²).
pub fn total_area(radii: &[f64]) -> f64 {
    radii.iter().map(|r| std::f64::consts::PI * r * r).sum()
}
