//! The solver sensitivity of the Janssen fit: the measured steps solved again from the same
//! states to [`crate::verdict::SENSITIVITY_TOLERANCE`] ([`crate::scenarios::sensitivity`]),
//! their profiles averaged and fitted as the run's, and the fitted K and μ_w compared with the
//! run's against the half-widths of the run's 95 % intervals (docs/outputs.md §2.1).

use super::fit::JanssenOutcome;
use crate::output::Summary;
use crate::verdict::{Checks, Verdict, SENSITIVITY_TOLERANCE};

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
    /// Measured steps.
    pub measured: u64,
    /// Measured steps whose re-solve failed.
    pub failed: u64,
    /// Measured steps whose problem was not available (no re-solve tried).
    pub unavailable: u64,
    /// Re-solved steps that stopped short of the tolerance, within a fifth of the run's own
    /// error (counted in `resolved`): they measure the fit, but do not stand in for the loaded
    /// contacts' proxy.
    pub near: u64,
    /// The fit of the re-solved steps' profile with the run's data and mode
    /// ([`super::fit_profile_like`]), when every measured step was re-solved and the run's fit
    /// succeeded.
    pub fit: Option<Result<JanssenOutcome, String>>,
    /// Whether the re-solved profile would select τ_w otherwise than the run's (a bin's mean
    /// wall shear stress changing sign).
    pub tau_w_flipped: bool,
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
        // μ_w is fitted only in the joint mode (both fits share the run's mode).
        let dmu = if run.mode == "joint" {
            over_half_width(f.mu_w.value, g.mu_w.value, g.mu_w.ci_low, g.mu_w.ci_high)
        } else {
            f64::NAN
        };
        Some(([dk, dmu], [f.k.value, f.mu_w.value]))
    }

    /// The check `solver.sensitivity_janssen`: the larger change over its half-width, against
    /// [`SENSITIVITY_CI_SUSPECT`] and [`SENSITIVITY_CI_REFUSED`], a NaN refused; suspect when
    /// not every measured step was re-solved (failed or unavailable: one reason), when the
    /// re-solved profile cannot be fitted as the run's was, or when it would select τ_w
    /// otherwise. Nothing where the run's own fit failed (`janssen.fit` refuses it).
    ///
    /// Returns whether the measure was made on every measured step, each re-solve reaching the
    /// tolerance, and passed (no reason added): then it stands in for the loaded contacts'
    /// proxy of the measurement window ([`Checks::window_measured`]); a re-solve accepted short
    /// of the tolerance was not judged on that scale.
    pub fn check(&self, checks: &mut Checks, run: Option<&JanssenOutcome>) -> bool {
        let Some(run) = run else {
            return false;
        };
        let before = checks.reasons.len();
        if self.resolved < self.measured {
            checks.fail(
                "solver.sensitivity_janssen",
                Verdict::Suspect,
                (self.measured - self.resolved) as f64 / self.measured as f64,
                0.0,
                format!(
                    "only {} of the {} measured steps could be solved again to {SENSITIVITY_TOLERANCE:.0e}: the fit's solver sensitivity is not measured",
                    self.resolved, self.measured
                ),
            );
            return false;
        }
        if self.tau_w_flipped {
            checks.fail(
                "solver.sensitivity_janssen",
                Verdict::Suspect,
                1.0,
                0.0,
                format!(
                    "solved to {SENSITIVITY_TOLERANCE:.0e}, the measured steps' wall shear stress would be {} the fit (a depth bin's mean τ_w changes sign)",
                    if run.uses_tau_w { "left out of" } else { "used in" }
                ),
            );
        }
        match (&self.fit, self.changes(run)) {
            (Some(Err(e)), _) => checks.fail(
                "solver.sensitivity_janssen",
                Verdict::Suspect,
                f64::NAN,
                SENSITIVITY_CI_SUSPECT,
                format!("the measured steps solved to {SENSITIVITY_TOLERANCE:.0e} cannot be fitted: {e}"),
            ),
            (_, Some(([dk, dmu], [k, mu]))) => {
                let worst = if run.mode == "joint" {
                    dem::solver::worst(dk, dmu)
                } else {
                    dk
                };
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
        self.measured > 0 && self.fit.is_some() && self.near == 0 && checks.reasons.len() == before
    }

    /// Summary keys `resolved_samples`, `resolved_near_samples`, `resolved_unresolved_samples`,
    /// `resolved_unavailable_samples`, `resolved_janssen_K`, `resolved_janssen_mu_w`,
    /// `resolved_K_change_over_half_width`, `resolved_mu_w_change_over_half_width` (NaN where
    /// there is nothing to compare).
    pub fn keys(&self, s: &mut Summary, run: Option<&JanssenOutcome>) {
        let ([dk, dmu], [k, mu]) = run
            .and_then(|r| self.changes(r))
            .unwrap_or(([f64::NAN; 2], [f64::NAN; 2]));
        s.int("resolved_samples", self.resolved)
            .int("resolved_near_samples", self.near)
            .int("resolved_unresolved_samples", self.failed)
            .int("resolved_unavailable_samples", self.unavailable)
            .num("resolved_janssen_K", k)
            .num("resolved_janssen_mu_w", mu)
            .num("resolved_K_change_over_half_width", dk)
            .num("resolved_mu_w_change_over_half_width", dmu);
    }
}

#[cfg(test)]
mod tests {
    use identify::janssen::JanssenSetup;

    use super::super::fit::{fit_profile, fit_profile_like};
    use super::super::measure::ColumnProfile;
    use super::*;

    const SETUP: JanssenSetup = JanssenSetup {
        width_m: 0.05,
        bulk_density_kg_m3: 1500.0,
        gravity_m_s2: 9.81,
        wall_friction: 0.5,
    };
    const WINDOW: (f64, f64) = (0.0, 0.2);

    /// Janssen's profile `σ_v = ρ g (1 − e^{−a z})/a`, `a = 2 K μ_w / D`, `σ_h = K σ_v`,
    /// `τ_w = μ_w σ_h` in 8 bins, with ±`noise` (relative, alternating) on σ_v and σ_h.
    fn profile(k: f64, mu: f64, noise: f64) -> ColumnProfile {
        let a = 2.0 * k * mu / SETUP.width_m;
        let rg = SETUP.bulk_density_kg_m3 * SETUP.gravity_m_s2;
        let z: Vec<f64> = (0..8).map(|i| 0.01 + 0.02 * i as f64).collect();
        let wobble = |i: usize, m: usize| 1.0 + if i.is_multiple_of(m) { noise } else { -noise };
        let sigma_v: Vec<f64> = z
            .iter()
            .enumerate()
            .map(|(i, &z)| rg * (1.0 - (-a * z).exp()) / a * wobble(i, 2))
            .collect();
        let sigma_h: Vec<f64> = sigma_v
            .iter()
            .enumerate()
            .map(|(i, s)| k * s * wobble(i, 3))
            .collect();
        ColumnProfile {
            tau_w: sigma_h.iter().map(|s| mu * s).collect(),
            z,
            sigma_v,
            sigma_h,
            surface: 0.17,
        }
    }

    fn sensitivity(fit: Option<Result<JanssenOutcome, String>>) -> JanssenSensitivity {
        JanssenSensitivity {
            resolved: 4,
            measured: 4,
            failed: 0,
            unavailable: 0,
            near: 0,
            fit,
            tau_w_flipped: false,
        }
    }

    fn names(c: &Checks) -> Vec<(String, Verdict)> {
        c.reasons
            .iter()
            .map(|r| (r.check.clone(), r.verdict))
            .collect()
    }

    /// The same data give no change; K moved by 0.1 moves it by many half-widths (refused);
    /// μ_w moved by a hundredth of its half-width passes; an incomplete re-solve, a flipped τ_w
    /// selection and a failed re-fit are suspect.
    #[test]
    fn the_janssen_fit_is_judged_on_its_re_solved_profile() {
        let p = profile(0.8, 0.2, 0.01);
        let run = fit_profile(&p, &SETUP, WINDOW).unwrap();
        assert_eq!(run.mode, "joint");
        let half = 0.5 * (run.fit.k.ci_high - run.fit.k.ci_low);
        assert!(half > 0.0 && half < 0.1, "K ± {half}");
        // The reasons, and whether the measure passed (then standing in for the window's
        // loaded-contacts proxy): exactly when it adds no reason.
        let judge = |s: &JanssenSensitivity| {
            let mut c = Checks::new();
            let passed = s.check(&mut c, Some(&run));
            assert_eq!(passed, c.reasons.is_empty(), "{:?}", c.reasons);
            c
        };
        let same = sensitivity(Some(
            fit_profile_like(&p, &SETUP, WINDOW, &run).map_err(|e| e.to_string()),
        ));
        assert!(judge(&same).reasons.is_empty());
        // Without the run's fit there is nothing to measure: no reason, and no pass.
        assert!(!same.check(&mut Checks::new(), None));
        // A re-solve accepted short of the tolerance measures the fit (no reason) but does
        // not pass for the loaded contacts' proxy.
        let mut near = sensitivity(same.fit.clone());
        near.near = 1;
        let mut c = Checks::new();
        assert!(!near.check(&mut c, Some(&run)));
        assert!(c.reasons.is_empty());
        let ([dk, dmu], _) = same.changes(&run).unwrap();
        assert!(dk < 1e-9 && dmu < 1e-9, "{dk} {dmu}");
        let moved = profile(0.9, 0.2, 0.01);
        let far = sensitivity(Some(
            fit_profile_like(&moved, &SETUP, WINDOW, &run).map_err(|e| e.to_string()),
        ));
        assert_eq!(
            names(&judge(&far)),
            [("solver.sensitivity_janssen".to_string(), Verdict::Refused)]
        );
        let mut incomplete = sensitivity(None);
        incomplete.resolved = 3;
        let c = judge(&incomplete);
        assert_eq!(
            names(&c),
            [("solver.sensitivity_janssen".to_string(), Verdict::Suspect)]
        );
        assert!((c.reasons[0].value - 0.25).abs() < 1e-12);
        let mut flipped = sensitivity(same.fit.clone());
        flipped.tau_w_flipped = true;
        assert_eq!(
            names(&judge(&flipped)),
            [("solver.sensitivity_janssen".to_string(), Verdict::Suspect)]
        );
        let failed = sensitivity(Some(Err("no fit".into())));
        assert_eq!(
            names(&judge(&failed)),
            [("solver.sensitivity_janssen".to_string(), Verdict::Suspect)]
        );
    }

    /// The re-solved profile is fitted with the run's model: a run that left τ_w out (a
    /// negative bin) fits the re-solved profile without it too, though that one has none; a
    /// run that used τ_w cannot fit a re-solved profile with a negative bin (refused, not
    /// switched silently).
    #[test]
    fn the_re_solved_profile_is_fitted_like_the_run_s() {
        let p = profile(0.8, 0.2, 0.01);
        let mut q = p.clone();
        q.tau_w[3] = -1.0;
        let run_without = fit_profile(&q, &SETUP, WINDOW).unwrap();
        assert!(!run_without.uses_tau_w);
        assert!(fit_profile(&p, &SETUP, WINDOW).unwrap().uses_tau_w);
        let like = fit_profile_like(&p, &SETUP, WINDOW, &run_without).unwrap();
        assert!(!like.uses_tau_w && like.mode == "joint");
        let run_with = fit_profile(&p, &SETUP, WINDOW).unwrap();
        let e = fit_profile_like(&q, &SETUP, WINDOW, &run_with).unwrap_err();
        assert!(e.to_string().contains("tau_w"), "{e}");
    }
}
