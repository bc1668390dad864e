//! The solver sensitivity of the Janssen fit: the measured steps solved again from the same
//! states to [`crate::verdict::SENSITIVITY_TOLERANCE`] ([`crate::scenarios::sensitivity`]),
//! their profiles averaged and fitted as the run's, and the fitted K and μ_w compared with the
//! run's against the half-widths of the run's 95 % intervals (docs/outputs.md §2.1).

use super::fit::JanssenOutcome;
use crate::output::Summary;
use crate::verdict::{Checks, Verdict, SENSITIVITY_TOLERANCE, SENSITIVITY_UNRESOLVED_SUSPECT};

/// Change of K or μ_w, over the half-width of the run's 95 % interval, above which the law is
/// suspect: a solver bias of a quarter of the stated uncertainty widens it by 3 % when added in
/// quadrature.
pub const SENSITIVITY_CI_SUSPECT: f64 = 0.25;
/// The same, above which the law is refused: the bias would reach the stated uncertainty.
pub const SENSITIVITY_CI_REFUSED: f64 = 1.0;

/// The re-solved measurement and its fit.
pub struct JanssenSensitivity {
    /// Measured steps re-solved to the tolerance.
    pub resolved: u64,
    /// Measured steps whose re-solve failed.
    pub failed: u64,
    /// Measured steps whose problem was not available (no re-solve tried).
    pub unavailable: u64,
    /// The fit of the re-solved steps' profile, when every measured step was re-solved.
    pub fit: Option<Result<JanssenOutcome, String>>,
}

/// `|a − b|` over the half-width of `b`'s interval.
fn over_half_width(a: f64, b: f64, lo: f64, hi: f64) -> f64 {
    (a - b).abs() / (0.5 * (hi - lo))
}

impl JanssenSensitivity {
    /// `[ΔK, Δμ_w]` over the run's half-widths (μ_w: NaN unless both fits are joint, where μ_w
    /// is fitted rather than set to the wall friction), and the re-solved K and μ_w.
    fn changes(&self, run: &JanssenOutcome) -> Option<([f64; 2], [f64; 2])> {
        let Some(Ok(o)) = &self.fit else {
            return None;
        };
        let (f, g) = (&o.fit, &run.fit);
        let dk = over_half_width(f.k.value, g.k.value, g.k.ci_low, g.k.ci_high);
        let dmu = if o.mode == "joint" && run.mode == "joint" {
            over_half_width(f.mu_w.value, g.mu_w.value, g.mu_w.ci_low, g.mu_w.ci_high)
        } else {
            f64::NAN
        };
        Some(([dk, dmu], [f.k.value, f.mu_w.value]))
    }

    /// The checks `solver.sensitivity_unresolved` (a failed re-solve) and
    /// `solver.sensitivity_janssen` (the larger change over its half-width, against
    /// [`SENSITIVITY_CI_SUSPECT`] and [`SENSITIVITY_CI_REFUSED`]; suspect when the re-solved
    /// profile cannot be fitted where the run's could).
    pub fn check(&self, checks: &mut Checks, run: Option<&JanssenOutcome>) {
        let tried = self.resolved + self.failed;
        if tried > 0 {
            let f = self.failed as f64 / tried as f64;
            checks.at_most(
                "solver.sensitivity_unresolved",
                f,
                SENSITIVITY_UNRESOLVED_SUSPECT,
                None,
                |_| {
                    format!(
                        "the re-solve of the measured steps to {SENSITIVITY_TOLERANCE:.0e} failed on {} of {tried}",
                        self.failed
                    )
                },
            );
        }
        let Some(run) = run else {
            return;
        };
        match (&self.fit, self.changes(run)) {
            (Some(Err(e)), _) => checks.fail(
                "solver.sensitivity_janssen",
                Verdict::Suspect,
                f64::NAN,
                SENSITIVITY_CI_SUSPECT,
                format!("the measured steps solved to {SENSITIVITY_TOLERANCE:.0e} cannot be fitted: {e}"),
            ),
            (_, Some(([dk, dmu], [k, mu]))) => {
                let worst = if dmu.is_nan() { dk } else { dk.max(dmu) };
                checks.at_most(
                    "solver.sensitivity_janssen",
                    worst,
                    SENSITIVITY_CI_SUSPECT,
                    Some(SENSITIVITY_CI_REFUSED),
                    |t| {
                        format!(
                            "the measured steps solved to {SENSITIVITY_TOLERANCE:.0e} give K = {k:.4}, μ_w = {mu:.4}: {dk:.2} and {dmu:.2} of the half-widths of their intervals (limit {t})"
                        )
                    },
                );
            }
            _ => {}
        }
    }

    /// Summary keys `resolved_samples`, `resolved_unresolved_samples`,
    /// `resolved_unavailable_samples`, `resolved_janssen_K`, `resolved_janssen_mu_w`,
    /// `resolved_K_change_over_half_width`, `resolved_mu_w_change_over_half_width` (NaN where
    /// there is nothing to compare).
    pub fn keys(&self, s: &mut Summary, run: Option<&JanssenOutcome>) {
        let ([dk, dmu], [k, mu]) = run
            .and_then(|r| self.changes(r))
            .unwrap_or(([f64::NAN; 2], [f64::NAN; 2]));
        s.int("resolved_samples", self.resolved)
            .int("resolved_unresolved_samples", self.failed)
            .int("resolved_unavailable_samples", self.unavailable)
            .num("resolved_janssen_K", k)
            .num("resolved_janssen_mu_w", mu)
            .num("resolved_K_change_over_half_width", dk)
            .num("resolved_mu_w_change_over_half_width", dmu);
    }
}
