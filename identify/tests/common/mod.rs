//! Shared helpers of the integration tests: seeded Gaussian noise and synthetic data.
#![allow(dead_code)]

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use identify::janssen::{JanssenProfile, JanssenSetup};
use identify::laws::JanssenLaw;

/// `n` draws of N(0, sigma²) from `ChaCha8Rng::seed_from_u64(seed)`.
pub fn gaussian(seed: u64, n: usize, sigma: f64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let normal = Normal::new(0.0, sigma).unwrap();
    (0..n).map(|_| normal.sample(&mut rng)).collect()
}

/// The reference column: W = 3 cm, ρ_b = 1600 kg/m³, K = 0.6, μ_w = 0.2, μ_wall = 0.25
/// (λ = 12.5 cm), 30 depths from 1 cm to 30 cm.
pub fn janssen_truth() -> (JanssenLaw, JanssenSetup) {
    let setup = JanssenSetup::new(0.03, 1600.0, 0.25);
    let law = JanssenLaw {
        k: 0.6,
        mu_w: 0.2,
        width_m: setup.width_m,
        bulk_density_kg_m3: setup.bulk_density_kg_m3,
        gravity_m_s2: setup.gravity_m_s2,
    };
    (law, setup)
}

/// Synthetic profile from `law` with noise 30 Pa on σ_v and 15 Pa on σ_h (and 5 Pa on τ_w).
pub fn janssen_profile(law: &JanssenLaw, seed: u64, with_tau: bool) -> JanssenProfile {
    let z: Vec<f64> = (1..=30).map(|i| 0.01 * i as f64).collect();
    let ev = gaussian(seed, z.len(), 30.0);
    let eh = gaussian(seed.wrapping_add(1_000_003), z.len(), 15.0);
    let et = gaussian(seed.wrapping_add(2_000_003), z.len(), 5.0);
    JanssenProfile {
        sigma_v_pa: z
            .iter()
            .zip(&ev)
            .map(|(z, e)| law.sigma_v(*z) + e)
            .collect(),
        sigma_h_pa: Some(
            z.iter()
                .zip(&eh)
                .map(|(z, e)| law.sigma_h(*z) + e)
                .collect(),
        ),
        tau_w_pa: with_tau.then(|| z.iter().zip(&et).map(|(z, e)| law.tau_w(*z) + e).collect()),
        z_m: z,
    }
}
