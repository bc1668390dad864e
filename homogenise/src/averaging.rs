//! Time averages with standard errors by block averaging (Flyvbjerg & Petersen 1989).
//!
//! A correlated series `x_1 … x_n` is cut into `n_k = ⌊n / 2^k⌋` blocks of `b = 2^k` samples; the
//! standard error of the mean estimated from the block means is
//! `SE_k = √(s_k² / n_k)`, `s_k²` their sample variance, with its own uncertainty
//! `δ_k = SE_k / √(2 (n_k − 1))`. `SE_k` grows with `b` until the blocks are longer than the
//! correlation time, then stays on a plateau. The plateau starts at the first level `k` such
//! that no deeper level (with at least `min_blocks` blocks) exceeds `SE_k` by more than `2 δ_j`;
//! since `SE_k` there still lacks a few per cent (its deficit decays like `τ/b`), the level
//! reported is the next one, `k + 1`. `converged` is false when no plateau starts before the
//! deepest level (series too short for its correlation time); the deepest level is then
//! reported, and is an underestimate.
//!
//! Measured on stationary AR(1) series of 2¹⁶ samples (200 seeds each): for correlation times
//! up to 50 samples the estimate lies within 0.80–1.25 of the exact standard error (mean
//! 0.95–1.0); for 200 samples (330 correlation times in the series), within 0.68–1.26.

use serde::{Deserialize, Serialize};

use crate::error::{HomogeniseError, Result};

/// Default minimum number of blocks of a level.
pub const MIN_BLOCKS: usize = 16;

/// One blocking level.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BlockLevel {
    /// Samples per block `b`.
    pub block_size: usize,
    /// Number of blocks `n_k`.
    pub blocks: usize,
    /// Standard error of the mean estimated at this level `SE_k`.
    pub std_error: f64,
    /// Uncertainty of that estimate `δ_k`.
    pub std_error_uncertainty: f64,
}

/// A time average and its standard error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TimeAverage {
    /// Mean of the samples.
    pub mean: f64,
    /// Standard error of the mean at the chosen level.
    pub std_error: f64,
    /// Number of samples used.
    pub samples: usize,
    /// Block size of the chosen level.
    pub block_size: usize,
    /// Whether a plateau was found.
    pub converged: bool,
    /// All levels, shallowest first.
    pub levels: Vec<BlockLevel>,
}

/// Mean and block-averaging standard error of `series` (see the module documentation); needs
/// at least `2 · min_blocks` finite samples and `min_blocks ≥ 2`. Non-finite values are an error.
pub fn block_average(series: &[f64], min_blocks: usize) -> Result<TimeAverage> {
    if min_blocks < 2 {
        return Err(HomogeniseError::InvalidParameter {
            name: "min_blocks",
            reason: format!("must be ≥ 2, got {min_blocks}"),
        });
    }
    if let Some(i) = series.iter().position(|v| !v.is_finite()) {
        return Err(HomogeniseError::InvalidParameter {
            name: "series",
            reason: format!("sample {i} is not finite"),
        });
    }
    let n = series.len();
    if n < 2 * min_blocks {
        return Err(HomogeniseError::NotEnoughData(format!(
            "block averaging needs ≥ {} samples, got {n}",
            2 * min_blocks
        )));
    }
    let mean = series.iter().sum::<f64>() / n as f64;
    let mut levels = Vec::new();
    let mut b = 1usize;
    while n / b >= min_blocks {
        let nb = n / b;
        let means: Vec<f64> = (0..nb)
            .map(|k| series[k * b..(k + 1) * b].iter().sum::<f64>() / b as f64)
            .collect();
        let m = means.iter().sum::<f64>() / nb as f64;
        let var = means.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (nb - 1) as f64;
        let se = (var / nb as f64).sqrt();
        levels.push(BlockLevel {
            block_size: b,
            blocks: nb,
            std_error: se,
            std_error_uncertainty: se / (2.0 * (nb - 1) as f64).sqrt(),
        });
        b *= 2;
    }
    let chosen = (0..levels.len()).find(|&k| {
        levels[k + 1..]
            .iter()
            .all(|l| l.std_error <= levels[k].std_error + 2.0 * l.std_error_uncertainty)
    });
    let last = levels.len() - 1;
    let (k, converged) = match chosen {
        Some(k) if k < last => (k + 1, true),
        _ => (last, false),
    };
    Ok(TimeAverage {
        mean,
        std_error: levels[k].std_error,
        samples: n,
        block_size: levels[k].block_size,
        converged,
        levels,
    })
}

/// Block average of the values whose time lies in `[t_start, t_end]`, skipping non-finite
/// values (missing entries of a history).
pub fn window_average(
    times: &[f64],
    values: &[f64],
    t_start: f64,
    t_end: f64,
    min_blocks: usize,
) -> Result<TimeAverage> {
    if times.len() != values.len() {
        return Err(HomogeniseError::InvalidParameter {
            name: "values",
            reason: format!("{} times but {} values", times.len(), values.len()),
        });
    }
    if !(t_start.is_finite() && t_end.is_finite() && t_end >= t_start) {
        return Err(HomogeniseError::InvalidParameter {
            name: "window",
            reason: format!("needs finite t_start ≤ t_end, got [{t_start}, {t_end}]"),
        });
    }
    let selected: Vec<f64> = times
        .iter()
        .zip(values)
        .filter(|(t, v)| **t >= t_start && **t <= t_end && v.is_finite())
        .map(|(_, v)| *v)
        .collect();
    block_average(&selected, min_blocks)
}
