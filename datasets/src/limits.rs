//! Upper and lower limits on scenario values, checked before any work starts.
//!
//! A value can be finite and of the right sign and still make a run impossible: a billion grains
//! exhaust the memory, a radius of 10²⁰⁰ m gives an infinite mass (`m = ρ π R²`), a time step of
//! 10⁻³⁰⁰ s asks for more steps than could ever run, and a histogram of 10¹⁴ bins is an
//! allocation that aborts the process. The limits below are far outside any sensible granular
//! simulation and far inside the range where `f64` and the memory break; each check names the key
//! at fault.

use crate::error::{DatasetError, Result};

/// Largest number of grains of a scenario (the engine holds about 1 kB per grain and contact).
pub const MAX_GRAINS: usize = 1_000_000;

/// Largest number of time steps of one phase (≈ 3 hours at 1 ms a step).
pub const MAX_STEPS: f64 = 1e7;

/// Largest number of bins of a profile or histogram.
pub const MAX_BINS: usize = 10_000;

/// Largest number of VTK frames written by a run.
pub const MAX_FRAMES: usize = 10_000;

/// Largest number of deposition sub-steps per scenario step.
pub const MAX_SUBSTEPS: usize = 1_000;

/// Range of grain radii (m): fine powders (1 µm) to boulders (10 m). Masses `ρ π R²` and
/// moments of inertia `m R² / 2` then stay far from `f64` overflow and underflow.
pub const RADIUS_RANGE: (f64, f64) = (1e-6, 10.0);

/// Range of grain densities ρ (kg/m³): aerogel-like to beyond osmium.
pub const DENSITY_RANGE: (f64, f64) = (1.0, 1e5);

/// Range of imposed pressures (Pa).
pub const PRESSURE_RANGE: (f64, f64) = (1e-3, 1e10);

/// Count `key` must be at most `max`.
pub fn at_most(key: &str, v: usize, max: usize) -> Result<usize> {
    if v <= max {
        Ok(v)
    } else {
        Err(DatasetError::invalid(
            key,
            format!("must be at most {max}, got {v}"),
        ))
    }
}

/// The number of grains must be in `[min, MAX_GRAINS]`.
pub fn grains(key: &str, n: usize, min: usize) -> Result<usize> {
    crate::error::at_least(key, n, min)?;
    at_most(key, n, MAX_GRAINS)
}

/// `v` (finite, > 0) must lie in `range`; `what` names the quantity and its unit in the message.
fn within(key: &str, v: f64, range: (f64, f64), unit: &str) -> Result<f64> {
    crate::error::positive(key, v)?;
    if v < range.0 || v > range.1 {
        return Err(DatasetError::invalid(
            key,
            format!(
                "must lie in [{:e}, {:e}] {unit}, got {v:e}",
                range.0, range.1
            ),
        ));
    }
    Ok(v)
}

/// A radius (m) within [`RADIUS_RANGE`].
pub fn radius(key: &str, r: f64) -> Result<f64> {
    within(key, r, RADIUS_RANGE, "m")
}

/// A density (kg/m³) within [`DENSITY_RANGE`].
pub fn density(key: &str, rho: f64) -> Result<f64> {
    within(key, rho, DENSITY_RANGE, "kg/m³")
}

/// A pressure (Pa) within [`PRESSURE_RANGE`].
pub fn pressure(key: &str, p: f64) -> Result<f64> {
    within(key, p, PRESSURE_RANGE, "Pa")
}

/// A phase of `duration` (s) at time step `dt` (s) must take at most [`MAX_STEPS`] steps,
/// `duration / dt ≤ MAX_STEPS`; `key` is the value to change and `what` describes the ratio in
/// the message (e.g. `"relax.max_time / dt"`).
pub fn steps(key: &str, what: &str, duration: f64, dt: f64) -> Result<f64> {
    let n = duration / dt;
    if n.is_finite() && n <= MAX_STEPS {
        Ok(n)
    } else {
        Err(DatasetError::invalid(
            key,
            format!("{what} = {n:.3e} time steps, more than {MAX_STEPS:e} (raise the time step or shorten the phase)"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_name_the_key_and_pass_ordinary_values() {
        assert!(radius("grain.radius_mean", 1.5e-3).is_ok());
        let e = radius("grain.radius_mean", 1e200).unwrap_err().to_string();
        assert!(
            e.contains("grain.radius_mean") && e.contains("1e200"),
            "{e}"
        );
        assert!(density("density", 0.5).is_err());
        assert!(grains("grains", MAX_GRAINS, 10).is_ok());
        assert!(grains("grains", MAX_GRAINS + 1, 10).is_err());
        assert!(steps("dt", "duration / dt", 1.0, 1e-3).is_ok());
        let e = steps("dt", "duration / dt", 1.0, 1e-300)
            .unwrap_err()
            .to_string();
        assert!(e.contains("key `dt`") && e.contains("1.000e300"), "{e}");
        assert!(pressure("pressure", f64::NAN).is_err());
    }
}
