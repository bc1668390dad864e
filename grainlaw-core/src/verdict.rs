//! Verdicts: every scenario run, and every result it exports, is judged `ok`, `suspect` or
//! `refused` by checks with stated thresholds, so that no wrong number looks right
//! (`docs/outputs.md` §2.1).
//!
//! A check compares one measured value with its thresholds: beyond the *suspect* threshold the
//! result is suspect, beyond the *refused* one it is refused. Each failed check is kept as a
//! [`Reason`] (check name, measured value, threshold, one sentence). The verdict of a result is
//! the worst of its reasons (`ok` without any); the verdict of the run is the worst of its own
//! reasons and of its results.
//!
//! The checks judge the steps that feed a result (its averaging window, or the measured step),
//! not the preparation phases: a preparation leads to a state that is then checked on its own
//! (equilibrium, overlap, convergence of the measured step). The thresholds:
//!
//! | check | suspect above | refused above |
//! |---|---|---|
//! | unconverged steps in the window ([`SOLVER_UNCONVERGED_SUSPECT`], [`SOLVER_UNCONVERGED_REFUSED`]) | 1 % of its steps (not judged where the sensitivity below was measured and passed) | 25 % (windows of ≥ [`MIN_STEPS_FOR_FRACTION_REFUSAL`] steps; idem) |
//! | worst solver error in the window / tolerance ([`SOLVER_ERROR_SUSPECT`], [`SOLVER_ERROR_REFUSED`]) | 10 | 1000 |
//! | the same over the loaded contacts' scale (`dem::SolveReport::error_without_gap_shifts`) / tolerance | 10 (unless the sensitivity below was measured and passed) | 1000 |
//! | change of the window's μ when its samples' steps are solved to 10⁻⁸ ([`Sensitivity`]), with the samples' scatter, `√(Δμ² + SE(Δμ)²)` ([`Sensitivity::measured_changes`]) | a quarter of μ's standard error where the scenario gives it ([`SENSITIVITY_SE_FRACTION`]: simple-shear), else 0.005 | 0.02 |
//! | relative change of its pressure under the same re-solve, idem | a quarter of the larger of its relative standard error and `SE(μ) / 0.2` where given ([`pressure_limit`]), else 2.5 % | 10 % |
//! | samples whose re-solve did not reach 10⁻⁸ | 10 % | — |
//! | steps of the window whose energy grew beyond `ENERGY_GROWTH_TOLERANCE` | 1 % | 25 % (≥ 20 steps) |
//! | energy gained by any one step of the window / E_load ([`ENERGY_STEP_SUSPECT`], [`ENERGY_STEP_REFUSED`]) | 1 % | 100 % |
//! | largest overlap in the window / smallest radius ([`OVERLAP_SUSPECT`], [`OVERLAP_REFUSED`]) | 0.1 % | 1 % |
//! | solid fraction | — | outside (0, [`max_solid_fraction`]) |
//!
//! The second error check reads the same residuals over a scale that leaves out the
//! gap-closing shifts `g / (θ h)` of the pairs open within the detection gap
//! (`dem::SolveReport::error_without_gap_shifts`, docs/physics.md §1.6): those shifts enter the
//! error's scale `max(‖q‖, ‖r‖, ‖u‖)` and nothing else, so a solve can meet its tolerance while
//! the contacts that carry the load are solved tens of times less accurately (the Janssen
//! release: 56×). A window must meet both; the second is judged only where it exceeds the
//! first (under `solver.error_scale = "loaded"` the error already includes it).
//!
//! Where a scenario measures it ([`Sensitivity`]: the shear cell, simple-shear, the biaxial's
//! axial compressions; Janssen has its own measure on its fit), the solver's effect on what
//! the window reports is measured instead of bounded by a proxy: the step of each sampled state
//! (every averaging sample in the shear cell) is solved again from the same state to
//! [`SENSITIVITY_TOLERANCE`] (`dem::World::last_step_problem`, `dem::fc::solve_by` with `auto`
//! and Lemke's method, `dem::World::snapshot_with_last_impulses`), and the window's μ and
//! pressure are taken both ways. When at least [`SENSITIVITY_MIN_SAMPLES`] samples were
//! re-solved, at most [`SENSITIVITY_UNRESOLVED_SUSPECT`] of them failed, and both changes are
//! within their suspect limits, the loaded-scale error and the worst error are judged only
//! against their refusal limits and the fraction of steps above the tolerance is not judged:
//! the residual was shown not to move the numbers, and the precision of the result is the
//! criterion (where some re-solves stopped short of 10⁻⁸, within a fifth of the run's own
//! error on the problem's measure, the loaded-scale error keeps its suspect limit:
//! [`Measured`]). A change is judged with the scatter of its samples (`√(Δ² + SE(Δ)²)`): it
//! passes only if it is small and the samples are enough to tell. The re-solve measures the solver's
//! effect on the forces of each sampled state, not on the trajectory that led there (positions
//! move by `θ h Δv` only); the trajectory's drift is what the overlap and energy checks bound.
//!
//! and the scenario's own checks (force balance, inertial number against its target, steady
//! state, the biaxial's dilatancy), documented where they are made.
//!
//! The verdict is as loud wherever a result leaves grainlaw: `grainlaw run` exits with 3 for a
//! refused run, or a suspect one without `--allow-suspect` ([`RunVerdict::passes`]); Python's
//! `grainlaw.run` raises `ResultRefused` / `ResultSuspect` (unless `allow_suspect=True`) with the
//! verdict, its reasons and the result; every law JSON carries its `verdict`, `ok` for a law of
//! `grainlaw fit` or a Python fit, which return only laws that passed every check
//! (`identify::user_fit::FIT_VERDICT`). What a plan cannot identify is not left to a verdict
//! at the end: a plan short of the data a law needs is refused before the run
//! (`crate::scenarios::common::laws`), unless it leaves that law out.
//!
//! An interval says which kind it is: the block averages of one sample's window
//! (`homogenise::averaging`) measure that sample's noise and understate the scatter between
//! independent samples; where there are replicas (seeds, or pressures for rigid grains) the
//! interval comes from their scatter (`identify::critical_state::IntervalKind`,
//! `docs/outputs.md` §2.1).

use std::fmt;

use dem::solver::worst;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

use crate::error::Result;
use crate::output::{OutputDir, Summary};
use crate::scenarios::phases::PhaseStats;

/// Fraction of unconverged steps in a window above which the result is suspect (1).
pub const SOLVER_UNCONVERGED_SUSPECT: f64 = 0.01;
/// Fraction of unconverged steps above which the result is refused (1), for windows of at least
/// [`MIN_STEPS_FOR_FRACTION_REFUSAL`] steps (a single measured step is judged by its error).
pub const SOLVER_UNCONVERGED_REFUSED: f64 = 0.25;
/// Smallest window on which a fraction of bad steps can refuse a result.
pub const MIN_STEPS_FOR_FRACTION_REFUSAL: u64 = 20;
/// Worst error over the tolerance above which the result is suspect (1).
pub const SOLVER_ERROR_SUSPECT: f64 = 10.0;
/// Worst error over the tolerance above which the result is refused (1).
pub const SOLVER_ERROR_REFUSED: f64 = 1000.0;
/// Change of a window's μ = |σ_xy| / (−σ_yy) when its samples' steps are solved to
/// [`SENSITIVITY_TOLERANCE`] above which the result is suspect (absolute): half the
/// interval half-width of the shear cell's μ₀ (±0.01), a quarter of the change that its steady
/// check calls a drift (0.02).
pub const SENSITIVITY_MU_SUSPECT: f64 = 0.005;
/// The same, above which the result is refused (absolute).
pub const SENSITIVITY_MU_REFUSED: f64 = 0.02;
/// Relative change of a window's pressure `−σ_yy` under the same re-solve above which the
/// result is suspect (1). The pressure enters the results through μ (checked on its own) and
/// `I = γ̇ d / √(P/ρ)`: `ΔI/I = ΔP/2P`, 1.25 % here, which moves μ by 0.0025 (half its limit)
/// where μ(I) is steepest in the default cell ([`SENSITIVITY_MU_SLOPE`]): the one rule of
/// [`pressure_limit`], `SENSITIVITY_MU_SUSPECT / SENSITIVITY_MU_SLOPE`. The slow shear
/// (I = 0.005) measures 0.3–1.3 % at the default tolerance, from one lead stage to the next.
pub const SENSITIVITY_PRESSURE_SUSPECT: f64 = SENSITIVITY_MU_SUSPECT / SENSITIVITY_MU_SLOPE;
/// The same, above which the result is refused (1): I off by 5 %.
pub const SENSITIVITY_PRESSURE_REFUSED: f64 = 0.10;
/// Largest solver effect on a reported mean, as a fraction of its statistical error, before
/// the result is suspect ([`Checks::sensitivity`], where the window's statistical errors are
/// known): a bias of a quarter of the standard error widens the interval by 3 % in quadrature
/// (the Janssen fit's criterion, a quarter of its half-width). The default simple shear
/// measures 0.13 of μ's standard error at I = 0.04 (1.6·10⁻³ against 1.26·10⁻²).
pub const SENSITIVITY_SE_FRACTION: f64 = 0.25;
/// Steepest `dμ / d ln I` of the μ(I) curves the scenarios measure (the default simple-shear
/// cell: 0.2 at I ≈ 0.2), by which a relative change of the pressure moves μ through the
/// inertial number, `δμ = (dμ/d ln I) · ΔP / 2P` ([`pressure_limit`]).
pub const SENSITIVITY_MU_SLOPE: f64 = 0.2;

/// The suspect limit of a window's relative pressure change under the re-solve, from its
/// statistical errors `[SE(μ), SE(P)/P]`: [`SENSITIVITY_SE_FRACTION`] of the larger of the
/// pressure's own relative standard error and of `SE(μ) / SENSITIVITY_MU_SLOPE`, the pressure
/// change that moves μ through `I = γ̇ d / √(P/ρ)` by half of μ's own limit
/// ([`SENSITIVITY_MU_SLOPE`]; the rule of [`SENSITIVITY_PRESSURE_SUSPECT`]). Under a stress control the pressure is held and its own standard
/// error is tiny (10⁻⁴ of P in the 2000-grain cell at I = 0.01); what its change does to the
/// reported point is through `I` and μ, whose precision is μ's. NaN or 0 when neither is known.
pub fn pressure_limit(statistical: [f64; 2]) -> f64 {
    let known = |v: f64| if v.is_finite() && v > 0.0 { v } else { 0.0 };
    SENSITIVITY_SE_FRACTION
        * known(statistical[1]).max(known(statistical[0]) / SENSITIVITY_MU_SLOPE)
}
/// Tolerance of the re-solve of a sample's step (the error measure of the step's problem,
/// `dem::fc::fc_error`): 10⁻⁸, tens of thousands of times below the runs' 10⁻⁴ and, with the
/// open pairs' shifts at most a few hundred times the loaded contacts' scale, below 10⁻⁵ on it.
pub const SENSITIVITY_TOLERANCE: f64 = 1e-8;
/// Fewest re-solved samples for a measured sensitivity to stand in for the loaded-scale error
/// check.
pub const SENSITIVITY_MIN_SAMPLES: u64 = 10;

/// What a window's measured solver sensitivity ([`Checks::sensitivity`]) stands in for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measured {
    /// Not measured, too few samples, or a change beyond its limit: the solver's proxies
    /// (steps above the tolerance, worst errors) are judged as without a measure.
    No,
    /// Measured and passed, with re-solves short of [`SENSITIVITY_TOLERANCE`] within a fifth of
    /// the run's own error on the problem's error measure (`Sensitivity::near`): it stands in
    /// for the proxies on that scale (the fraction of steps above the tolerance, the worst
    /// error) but not for the loaded contacts' one, whose scale those re-solves were not
    /// judged on.
    ProblemScale,
    /// Measured and passed with every re-solve at the tolerance: it stands in for the
    /// loaded contacts' proxy too.
    LoadedScale,
}
/// Largest fraction of samples whose re-solve may fail (left out of the measure) for the
/// measure to stand; beyond it the check is suspect.
pub const SENSITIVITY_UNRESOLVED_SUSPECT: f64 = 0.1;
/// Fraction of window steps whose energy grew above which the result is suspect (1).
pub const ENERGY_GROWTH_SUSPECT: f64 = 0.01;
/// Fraction of window steps whose energy grew above which the result is refused (1).
pub const ENERGY_GROWTH_REFUSED: f64 = 0.25;
/// Energy gained by one step of the window over the load energy `E_load` (`δ / E_load`,
/// `dem::energy::load_energy_scale`: the work of every load over one mean diameter) above which the
/// result is suspect, however few such steps there are (1): a thousand times the growth that counts
/// a step (`crate::scenarios::phases::ENERGY_GROWTH_TOLERANCE`), the energy of the loads moving by
/// a hundredth of a diameter created in one step. The fraction check cannot see it: one step in a
/// hundred is not above its 1 % (an I = 0.25 window of simple shear: one step gained 22 % of E_load
/// and the fraction check passed).
pub const ENERGY_STEP_SUSPECT: f64 = 0.01;
/// The same, above which the result is refused (1): one step created more energy than the work
/// of every load over a whole diameter.
pub const ENERGY_STEP_REFUSED: f64 = 1.0;
/// Largest overlap over the smallest radius above which the result is suspect (1).
pub const OVERLAP_SUSPECT: f64 = 0.001;
/// Largest overlap over the smallest radius above which the result is refused (1).
pub const OVERLAP_REFUSED: f64 = 0.01;

/// Densest packing of equal disks, `π / (2√3)` (Thue; Fejes Tóth 1940).
pub const HEXAGONAL_PACKING: f64 = 0.906_899_682_117_108_9;
/// Bound on the solid fraction of a polydisperse disk sample (1): above the densest known
/// packings of disks of two sizes (about 0.93 for size ratios down to 0.2, the compact binary
/// packings of Kennedy, Discrete Comput. Geom. 35, 2006), which exceed the hexagonal packing
/// because small disks fill the holes between large ones. A measured φ above it is a counting
/// or overlap error, not a packing.
pub const POLYDISPERSE_PACKING_BOUND: f64 = 0.95;

/// The bound on the solid fraction of disks with radii `R̄ ± spread`: the hexagonal packing
/// `π/(2√3) ≈ 0.9069` for equal disks, [`POLYDISPERSE_PACKING_BOUND`] otherwise.
pub fn max_solid_fraction(radius_spread: f64) -> f64 {
    if radius_spread > 0.0 {
        POLYDISPERSE_PACKING_BOUND
    } else {
        HEXAGONAL_PACKING
    }
}

/// How a result is judged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Every check passed.
    Ok,
    /// A check failed by a little: the number may be right but nothing guarantees it.
    Suspect,
    /// A check failed by far, or the physics of the result is impossible.
    Refused,
}

impl Verdict {
    /// `ok`, `suspect` or `refused`.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Ok => "ok",
            Verdict::Suspect => "suspect",
            Verdict::Refused => "refused",
        }
    }
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One failed check.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reason {
    /// Check name (`solver.unconverged_fraction`, `janssen.force_balance`, …).
    pub check: String,
    /// What it leads to.
    pub verdict: Verdict,
    /// Measured value.
    pub value: f64,
    /// The threshold it crossed.
    pub threshold: f64,
    /// One sentence.
    pub message: String,
}

impl Reason {
    /// As JSON (`check`, `verdict`, `value`, `threshold`, `message`; non-finite numbers null).
    pub fn to_json(&self) -> Value {
        let n = |v: f64| serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number);
        json!({
            "check": self.check,
            "verdict": self.verdict.as_str(),
            "value": n(self.value),
            "threshold": n(self.threshold),
            "message": self.message,
        })
    }
}

/// The failed checks of one result (or of a run).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Checks {
    /// The reasons, in the order the checks were made.
    pub reasons: Vec<Reason>,
}

impl Checks {
    /// No check failed yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// The worst verdict of the reasons (`Ok` without any).
    pub fn verdict(&self) -> Verdict {
        self.reasons
            .iter()
            .map(|r| r.verdict)
            .max()
            .unwrap_or(Verdict::Ok)
    }

    /// Adds a reason.
    pub fn fail(
        &mut self,
        check: &str,
        verdict: Verdict,
        value: f64,
        threshold: f64,
        message: String,
    ) {
        if verdict != Verdict::Ok {
            self.reasons.push(Reason {
                check: check.into(),
                verdict,
                value,
                threshold,
                message,
            });
        }
    }

    /// `value` must stay at or below `suspect` (else suspect) and `refused` (else refused); a
    /// value that is not a number is refused. `what(threshold)` says it in one sentence.
    pub fn at_most(
        &mut self,
        check: &str,
        value: f64,
        suspect: f64,
        refused: Option<f64>,
        what: impl Fn(f64) -> String,
    ) {
        if value.is_nan() {
            self.fail(check, Verdict::Refused, value, suspect, what(suspect));
        } else if let Some(r) = refused.filter(|r| value > *r) {
            self.fail(check, Verdict::Refused, value, r, what(r));
        } else if value > suspect {
            self.fail(check, Verdict::Suspect, value, suspect, what(suspect));
        }
    }

    /// Adds the reasons of `other`.
    pub fn extend(&mut self, other: &Checks) {
        self.reasons.extend(other.reasons.iter().cloned());
    }

    /// The solid fraction `phi` (named `what`) must lie in (0, `bound`): refused otherwise.
    pub fn solid_fraction(&mut self, check: &str, what: &str, phi: f64, bound: f64) {
        if phi.is_nan() || phi <= 0.0 {
            self.fail(
                check,
                Verdict::Refused,
                phi,
                0.0,
                format!("{what} φ = {phi:.4} is not positive"),
            );
        } else if phi >= bound {
            self.fail(
                check,
                Verdict::Refused,
                phi,
                bound,
                format!(
                    "{what} φ = {phi:.4} is at or above the densest packing of these disks ({bound:.4})"
                ),
            );
        }
    }

    /// The measured solver sensitivity of a window ([`Sensitivity`], module documentation):
    /// its μ change, relative pressure change (each with its samples' scatter,
    /// [`Sensitivity::measured_changes`]) and failed re-solves against their limits.
    /// `statistical = [SE(μ), SE(P)/P]` of the window's means (0 or NaN: not known): where
    /// known, a μ change above [`SENSITIVITY_SE_FRACTION`] of SE(μ) is suspect (the solver's
    /// effect must stay a small part of the result's error), a pressure change above
    /// [`pressure_limit`]; otherwise the absolute limits
    /// [`SENSITIVITY_MU_SUSPECT`], [`SENSITIVITY_PRESSURE_SUSPECT`]. The refusal limits are
    /// absolute ([`SENSITIVITY_MU_REFUSED`], [`SENSITIVITY_PRESSURE_REFUSED`]). Returns what
    /// the measure stands in for ([`Measured`]: the suspect limits of the solver's proxies,
    /// [`Checks::window_measured`]). Nothing is checked where nothing was re-solved.
    pub fn sensitivity(&mut self, label: &str, s: &Sensitivity, statistical: [f64; 2]) -> Measured {
        let tried = s.samples + s.unresolved;
        if tried == 0 {
            return Measured::No;
        }
        let before = self.reasons.len();
        let failed = s.unresolved as f64 / tried as f64;
        self.at_most(
            "solver.sensitivity_unresolved",
            failed,
            SENSITIVITY_UNRESOLVED_SUSPECT,
            None,
            |t| {
                format!(
                    "{label}: the re-solve to {SENSITIVITY_TOLERANCE:.0e} failed on {} of {tried} samples ({:.0} %, limit {:.0} %)",
                    s.unresolved,
                    100.0 * failed,
                    100.0 * t
                )
            },
        );
        let relative = |limit: f64, absolute: f64| -> (f64, bool) {
            if limit.is_finite() && limit > 0.0 {
                (limit, true)
            } else {
                (absolute, false)
            }
        };
        if s.samples > 0 {
            let [dmu, dp] = s.measured_changes();
            let [se_dmu, se_dp] = s.change_errors();
            let noise = |se: f64, scale: f64, unit: &str| {
                if se.is_finite() {
                    format!(" ± {:.2e}{unit}", scale * se)
                } else {
                    String::new()
                }
            };
            let (limit, of_se) = relative(
                SENSITIVITY_SE_FRACTION * statistical[0],
                SENSITIVITY_MU_SUSPECT,
            );
            self.at_most(
                "solver.sensitivity_mu",
                dmu,
                limit,
                Some(SENSITIVITY_MU_REFUSED.max(limit)),
                |t| {
                    format!(
                        "{label}: μ moves by {:.2e}{} when its {} samples are solved to {SENSITIVITY_TOLERANCE:.0e} (judged {dmu:.2e} with the samples' scatter; limit {t:.2e}{})",
                        s.mu_change(),
                        noise(se_dmu, 1.0, ""),
                        s.samples,
                        if of_se {
                            format!(", {SENSITIVITY_SE_FRACTION} of μ's standard error {:.2e}", statistical[0])
                        } else {
                            String::new()
                        }
                    )
                },
            );
            let (limit, of_se) =
                relative(pressure_limit(statistical), SENSITIVITY_PRESSURE_SUSPECT);
            self.at_most(
                "solver.sensitivity_pressure",
                dp,
                limit,
                Some(SENSITIVITY_PRESSURE_REFUSED.max(limit)),
                |t| {
                    format!(
                        "{label}: the pressure moves by {:.3} %{} when its {} samples are solved to {SENSITIVITY_TOLERANCE:.0e} (judged {:.3} % with the samples' scatter; limit {:.3} %{})",
                        100.0 * s.pressure_change(),
                        noise(se_dp, 100.0, " %"),
                        s.samples,
                        100.0 * dp,
                        100.0 * t,
                        if of_se {
                            format!(
                                ", from the statistical errors: {SENSITIVITY_SE_FRACTION} of max(SE(P)/P = {:.2e}, SE(μ) / {SENSITIVITY_MU_SLOPE} = {:.2e})",
                                statistical[1],
                                statistical[0] / SENSITIVITY_MU_SLOPE
                            )
                        } else {
                            String::new()
                        }
                    )
                },
            );
        }
        let passed = self.reasons.len() == before && s.samples >= SENSITIVITY_MIN_SAMPLES;
        match (passed, s.near == 0) {
            (false, _) => Measured::No,
            (true, false) => Measured::ProblemScale,
            (true, true) => Measured::LoadedScale,
        }
    }

    /// [`Checks::at_most`] for a solver error over the tolerance: refused above
    /// [`SOLVER_ERROR_REFUSED`]; suspect above [`SOLVER_ERROR_SUSPECT`] unless the solver's
    /// effect on the result was `measured` (and passed), which stands in for the suspect limit.
    fn solver_error(
        &mut self,
        check: &str,
        ratio: f64,
        measured: bool,
        what: impl Fn(f64) -> String,
    ) {
        let suspect = if measured {
            SOLVER_ERROR_REFUSED
        } else {
            SOLVER_ERROR_SUSPECT
        };
        self.at_most(check, ratio, suspect, Some(SOLVER_ERROR_REFUSED), what);
    }

    /// The numerics of the steps that feed a result: unconverged steps and worst error over the
    /// tolerance, energy growth, largest overlap ([module documentation](self)).
    pub fn window(&mut self, label: &str, w: &WindowStats) {
        self.window_measured(label, w, false);
    }

    /// [`Checks::window`] for a window whose result has its own direct measure of the solver's
    /// effect (`measured_passed`: that measure was made on every step of the window and passed,
    /// e.g. Janssen's fit solved again, `solver.sensitivity_janssen`): like a passing
    /// [`Checks::sensitivity`] of the window's samples, it stands in for the suspect limit of
    /// the loaded contacts' proxy `solver.loaded_error_over_tolerance` (its refusal limit is
    /// kept). The measure, judged by its own check, must have been made before.
    pub fn window_measured(&mut self, label: &str, w: &WindowStats, measured_passed: bool) {
        if w.steps == 0 {
            return;
        }
        let n = w.steps as f64;
        let long = w.steps >= MIN_STEPS_FOR_FRACTION_REFUSAL;
        // The solver's effect on the result measured and within its limits: the proxies
        // (steps above the tolerance, the worst error) are judged against their refusal limits
        // only; the precision of the result is the criterion, not a residual.
        let by_samples = self.sensitivity(label, &w.sensitivity, w.statistical_errors);
        let measured = by_samples != Measured::No || measured_passed;
        let measured_loaded = by_samples == Measured::LoadedScale || measured_passed;
        // Steps above the tolerance are a proxy of the solver's effect on the result: where
        // that effect was measured and passed, they are not judged (the solves may stop at a
        // sweep cap, the worst error's refusal limit still bounds them).
        if !measured {
            let f = w.unconverged as f64 / n;
            self.at_most(
                "solver.unconverged_fraction",
                f,
                SOLVER_UNCONVERGED_SUSPECT,
                long.then_some(SOLVER_UNCONVERGED_REFUSED),
                |t| {
                    format!(
                        "{label}: {} of {} steps stopped above the solver tolerance ({:.1} %, limit {:.0} %)",
                        w.unconverged,
                        w.steps,
                        100.0 * f,
                        100.0 * t
                    )
                },
            );
        }
        let e = w.worst_error / w.tolerance;
        self.solver_error(
            "solver.worst_error_over_tolerance",
            e,
            measured,
            |t| {
                format!(
                    "{label}: worst solver error {:.2e} is {e:.0} times the tolerance {:.0e} (limit {t:.0}×)",
                    w.worst_error, w.tolerance
                )
            },
        );
        // The same residuals over the loaded contacts' scale: a window whose solves met the
        // tolerance only because open pairs' gap-closing shifts inflate the error's scale.
        // Judged where it exceeds the error (not under `error_scale = "loaded"`, whose error
        // already includes it): one cause, one reason.
        let loaded = w.worst_error_without_gap_shifts;
        if loaded > w.worst_error || loaded.is_nan() {
            let e0 = loaded / w.tolerance;
            self.solver_error(
                "solver.loaded_error_over_tolerance",
                e0,
                // A measured sensitivity that passed stands in for the suspect limit, where
                // every re-solve reached the tolerance (one short of it was judged on the
                // problem's scale only).
                measured_loaded,
                |t| {
                    format!(
                        "{label}: worst solver error over the loaded contacts' scale (without the gap-closing shifts of open pairs) {loaded:.2e} is {e0:.0} times the tolerance {:.0e} (limit {t:.0}×)",
                        w.tolerance
                    )
                },
            );
        }
        let g = w.energy_growth as f64 / n;
        self.at_most(
            "energy.growth_fraction",
            g,
            ENERGY_GROWTH_SUSPECT,
            long.then_some(ENERGY_GROWTH_REFUSED),
            |t| {
                format!(
                    "{label}: the mechanical energy grew beyond its tolerance in {} of {} steps ({:.1} %, limit {:.0} %)",
                    w.energy_growth,
                    w.steps,
                    100.0 * g,
                    100.0 * t
                )
            },
        );
        let step = w
            .worst_energy_growth_step
            .map_or_else(|| "?".to_string(), |k| k.to_string());
        self.at_most(
            "energy.worst_step_growth",
            w.worst_energy_growth,
            ENERGY_STEP_SUSPECT,
            Some(ENERGY_STEP_REFUSED),
            |t| {
                format!(
                    "{label}: one step (step {step}) gained {:.1} % of the load energy E_load (limit {} % in any single step, whatever the fraction of such steps)",
                    100.0 * w.worst_energy_growth,
                    100.0 * t
                )
            },
        );
        self.at_most(
            "overlap.max_over_radius",
            w.max_overlap_ratio,
            OVERLAP_SUSPECT,
            Some(OVERLAP_REFUSED),
            |t| {
                format!(
                    "{label}: largest overlap {:.3} % of the smallest radius (limit {:.1} %)",
                    100.0 * w.max_overlap_ratio,
                    100.0 * t
                )
            },
        );
    }
}

/// The numerics of the steps of an averaging window (or of a measured step), recorded step by
/// step. Serialisable, for run checkpoints.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct WindowStats {
    /// Steps in the window.
    pub steps: u64,
    /// Of which the solve stopped above its tolerance.
    pub unconverged: u64,
    /// Largest error measure at the end of a solve (1).
    #[serde(with = "dem::serde_float")]
    pub worst_error: f64,
    /// Largest error of a solve over a scale without the gap-closing shifts of open pairs
    /// (`dem::SolveReport::error_without_gap_shifts`; 1).
    #[serde(default, with = "dem::serde_float")]
    pub worst_error_without_gap_shifts: f64,
    /// Largest solver tolerance of the window's steps (1).
    #[serde(with = "dem::serde_float")]
    pub tolerance: f64,
    /// Steps whose energy residual exceeded the tolerance (`PhaseStats::energy_growth_steps`).
    pub energy_growth: u64,
    /// Largest energy residual of one step of the window over E_load, `max(δ / E_load, 0)`
    /// (`PhaseStats::last_energy_growth` of each step; 1).
    #[serde(default, with = "dem::serde_float")]
    pub worst_energy_growth: f64,
    /// World step index of that step (`None` while no step grew).
    #[serde(default)]
    pub worst_energy_growth_step: Option<u64>,
    /// Largest overlap at the start of a step over the smallest grain radius (1).
    #[serde(with = "dem::serde_float")]
    pub max_overlap_ratio: f64,
    /// The phase's energy-growth count after the last step seen (to count this step's).
    seen_growth: u64,
    /// The solver's measured effect on the window's stress, where the scenario measures it.
    #[serde(default)]
    pub sensitivity: Sensitivity,
    /// The statistical errors of what the window reports, `[SE(μ), SE(P)/P]` (block
    /// averages), where the scenario sets them before judging (0: not known): the solver's
    /// measured effect is judged against them ([`Checks::sensitivity`]).
    #[serde(default)]
    pub statistical_errors: [f64; 2],
}

/// The solver's effect on an averaging window's stress (module documentation): the sums of the
/// bulk stress components of its samples as the run solved them and as re-solved to
/// [`SENSITIVITY_TOLERANCE`] (or to a fifth of the run's own error where that is out of reach,
/// `crate::scenarios::sensitivity::measures_the_run`), over the samples so re-solved.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Sensitivity {
    /// Samples re-solved (to the tolerance, or to a fifth of the run's own error).
    pub samples: u64,
    /// Samples whose re-solve reached neither (left out of the sums).
    pub unresolved: u64,
    /// Of `samples`, those re-solved short of the tolerance, within a fifth of the run's own
    /// error: they measure the stress, but a measure with any of them does not stand in for
    /// the loaded contacts' proxy, whose scale they were not judged on.
    #[serde(default)]
    pub near: u64,
    /// Samples whose step's problem was not available to re-solve (no step since a resume, a
    /// cell under an explicit control): left out, not a failure of the solver.
    #[serde(default)]
    pub unavailable: u64,
    /// Σ σ_xy, Σ σ_yy of the re-solved samples as run (Pa, tension positive).
    #[serde(with = "dem::serde_float")]
    pub sxy: f64,
    /// See `sxy`.
    #[serde(with = "dem::serde_float")]
    pub syy: f64,
    /// The same sums with the re-solved impulses (Pa).
    #[serde(with = "dem::serde_float")]
    pub sxy_resolved: f64,
    /// See `sxy_resolved`.
    #[serde(with = "dem::serde_float")]
    pub syy_resolved: f64,
    /// Second moments of the per-sample changes `Δxy = σ_xy' − σ_xy`, `Δyy = σ_yy' − σ_yy`:
    /// `Σ Δxy²`, `Σ Δyy²`, `Σ Δxy Δyy` (Pa²), for the noise of the means
    /// ([`Sensitivity::upper_bounds`]).
    #[serde(default, with = "dem::serde_float")]
    pub dxy2: f64,
    /// See `dxy2`.
    #[serde(default, with = "dem::serde_float")]
    pub dyy2: f64,
    /// See `dxy2`.
    #[serde(default, with = "dem::serde_float")]
    pub dxy_dyy: f64,
}

impl Sensitivity {
    /// Adds a sample: its bulk `[σ_xy, σ_yy]` as run and, when the re-solve converged, as
    /// re-solved (`None`: counted as unresolved).
    pub fn add(&mut self, run: [f64; 2], resolved: Option<[f64; 2]>) {
        match resolved {
            Some([xy, yy]) => {
                self.samples += 1;
                self.sxy += run[0];
                self.syy += run[1];
                self.sxy_resolved += xy;
                self.syy_resolved += yy;
                let (dxy, dyy) = (xy - run[0], yy - run[1]);
                self.dxy2 += dxy * dxy;
                self.dyy2 += dyy * dyy;
                self.dxy_dyy += dxy * dyy;
            }
            None => self.unresolved += 1,
        }
    }

    /// `|Δμ|`, μ = |Σσ_xy| / (−Σσ_yy) of the re-solved samples against the same as run (NaN
    /// without samples).
    pub fn mu_change(&self) -> f64 {
        let mu = |xy: f64, yy: f64| xy.abs() / -yy;
        if self.samples == 0 {
            return f64::NAN;
        }
        (mu(self.sxy_resolved, self.syy_resolved) - mu(self.sxy, self.syy)).abs()
    }

    /// `|ΔP| / P` of the pressure `P = −Σσ_yy / n` (NaN without samples).
    pub fn pressure_change(&self) -> f64 {
        if self.samples == 0 {
            return f64::NAN;
        }
        ((self.syy_resolved - self.syy) / self.syy).abs()
    }

    /// Standard errors `[SE(Δμ), SE(ΔP/P)]` of the mean changes [`Sensitivity::mu_change`] and
    /// [`Sensitivity::pressure_change`] over the samples: the scatter of the per-sample changes
    /// over √n, the samples taken as independent, with the per-sample change of μ linearised,
    /// `δμ_i = (s Δxy_i + μ Δyy_i) / P` (`s` the sign of `Σσ_xy`, `μ`, `P` of the run's
    /// samples). NaN with fewer than two samples.
    pub fn change_errors(&self) -> [f64; 2] {
        if self.samples < 2 {
            return [f64::NAN; 2];
        }
        let n = self.samples as f64;
        let (mxy, myy) = (
            (self.sxy_resolved - self.sxy) / n,
            (self.syy_resolved - self.syy) / n,
        );
        let var = |sum2: f64, m: f64| ((sum2 / n - m * m) * n / (n - 1.0)).max(0.0);
        let cov = (self.dxy_dyy / n - mxy * myy) * n / (n - 1.0);
        let p = -self.syy / n;
        let mu = self.sxy.abs() / -self.syy;
        let sign = self.sxy.signum();
        let var_mu = (var(self.dxy2, mxy) + 2.0 * sign * mu * cov + mu * mu * var(self.dyy2, myy))
            .max(0.0)
            / (p * p);
        let var_p = var(self.dyy2, myy) / (p * p);
        [(var_mu / n).sqrt(), (var_p / n).sqrt()]
    }

    /// Upper bounds `[|Δμ|, |ΔP|/P]` of the changes that another set of samples of the same
    /// flow would show: each change plus `z` of its standard errors
    /// ([`Sensitivity::change_errors`]). NaN with fewer than two samples.
    pub fn upper_bounds(&self, z: f64) -> [f64; 2] {
        let [se_mu, se_p] = self.change_errors();
        [
            self.mu_change() + z * se_mu,
            self.pressure_change() + z * se_p,
        ]
    }

    /// The measured changes with their sampling noise, `[√(Δμ² + SE(Δμ)²), √((ΔP/P)² +
    /// SE(ΔP/P)²)]` ([`Sensitivity::change_errors`]; the changes alone with fewer than two
    /// samples, whose scatter is unknown): what [`Checks::sensitivity`] judges. Each is at least
    /// the larger of the change and its standard error, so it stays below a limit only when the
    /// change is small *and* the samples resolve the limit: a change that the samples' scatter
    /// could hide does not pass for a small one. (The per-sample changes of a loose solve
    /// scatter about their mean: at 2000 grains and 300 sweeps a step, `δμ_i` has a standard
    /// deviation of 5.5·10⁻³ about a mean of 5·10⁻⁴; the mean is the solver's bias on the
    /// window's μ, the scatter is noise that the window's own standard error already holds.)
    pub fn measured_changes(&self) -> [f64; 2] {
        let [se_mu, se_p] = self.change_errors();
        let with = |d: f64, se: f64| if se.is_finite() { d.hypot(se) } else { d };
        [
            with(self.mu_change(), se_mu),
            with(self.pressure_change(), se_p),
        ]
    }

    /// Adds another window's samples.
    pub fn merge(&mut self, o: &Sensitivity) {
        self.samples += o.samples;
        self.unresolved += o.unresolved;
        self.near += o.near;
        self.unavailable += o.unavailable;
        self.sxy += o.sxy;
        self.syy += o.syy;
        self.sxy_resolved += o.sxy_resolved;
        self.syy_resolved += o.syy_resolved;
        self.dxy2 += o.dxy2;
        self.dyy2 += o.dyy2;
        self.dxy_dyy += o.dxy_dyy;
    }
}

impl WindowStats {
    /// Follows one step of a phase (`phase`: the phase's statistics after it, whose
    /// energy-growth count tells whether this step's energy grew); counts it when `in_window`.
    pub fn step(
        &mut self,
        in_window: bool,
        world: &dem::World,
        r: &dem::StepReport,
        phase: &PhaseStats,
    ) {
        let grew = phase.energy_growth_steps > self.seen_growth;
        self.seen_growth = phase.energy_growth_steps;
        if !in_window {
            return;
        }
        self.steps += 1;
        if !r.solver.converged {
            self.unconverged += 1;
        }
        self.worst_error = worst(self.worst_error, r.solver.error);
        self.worst_error_without_gap_shifts = worst(
            self.worst_error_without_gap_shifts,
            r.solver.error_without_gap_shifts,
        );
        self.tolerance = self.tolerance.max(world.params.solver.tolerance);
        if grew {
            self.energy_growth += 1;
        }
        if phase.last_energy_growth > self.worst_energy_growth {
            self.worst_energy_growth = phase.last_energy_growth;
            self.worst_energy_growth_step = Some(r.step);
        }
        let rmin = crate::scenarios::phases::min_grain_radius(world);
        if rmin > 0.0 {
            self.max_overlap_ratio = self.max_overlap_ratio.max(r.max_penetration / rmin);
        }
    }

    /// Starts a new window in a new phase (whose energy-growth count starts again too).
    pub fn reset(&mut self) {
        *self = WindowStats::default();
    }

    /// Starts a new window within the same phase.
    pub fn restart(&mut self) {
        *self = WindowStats {
            seen_growth: self.seen_growth,
            ..WindowStats::default()
        };
    }

    /// Adds another window's counts.
    pub fn merge(&mut self, o: &WindowStats) {
        self.steps += o.steps;
        self.unconverged += o.unconverged;
        self.worst_error = worst(self.worst_error, o.worst_error);
        self.worst_error_without_gap_shifts = worst(
            self.worst_error_without_gap_shifts,
            o.worst_error_without_gap_shifts,
        );
        self.tolerance = self.tolerance.max(o.tolerance);
        self.energy_growth += o.energy_growth;
        if o.worst_energy_growth > self.worst_energy_growth {
            self.worst_energy_growth = o.worst_energy_growth;
            self.worst_energy_growth_step = o.worst_energy_growth_step;
        }
        self.max_overlap_ratio = self.max_overlap_ratio.max(o.max_overlap_ratio);
        self.sensitivity.merge(&o.sensitivity);
    }

    /// Summary keys `PREFIX_steps`, `PREFIX_unconverged_steps`, `PREFIX_worst_error`,
    /// `PREFIX_worst_error_without_gap_shifts`, `PREFIX_energy_growth_steps`,
    /// `PREFIX_worst_energy_growth` (the largest growth of one step over E_load),
    /// `PREFIX_max_overlap_over_radius`; where the solver sensitivity was measured
    /// ([`Sensitivity`]), `PREFIX_resolved_samples`, `PREFIX_unresolved_samples`,
    /// `PREFIX_unavailable_samples`, `PREFIX_resolved_mu_change`,
    /// `PREFIX_resolved_pressure_change` and their standard errors
    /// `PREFIX_resolved_mu_change_se`, `PREFIX_resolved_pressure_change_se`
    /// ([`Sensitivity::change_errors`]; NaN with fewer than two samples).
    pub fn keys(&self, s: &mut Summary, prefix: &str) {
        s.int(&format!("{prefix}_steps"), self.steps)
            .int(&format!("{prefix}_unconverged_steps"), self.unconverged)
            .num(&format!("{prefix}_worst_error"), self.worst_error)
            .num(
                &format!("{prefix}_worst_error_without_gap_shifts"),
                self.worst_error_without_gap_shifts,
            )
            .int(&format!("{prefix}_energy_growth_steps"), self.energy_growth)
            .num(
                &format!("{prefix}_worst_energy_growth"),
                self.worst_energy_growth,
            )
            .num(
                &format!("{prefix}_max_overlap_over_radius"),
                self.max_overlap_ratio,
            );
        let sens = &self.sensitivity;
        if sens.samples + sens.unresolved + sens.unavailable > 0 {
            s.int(&format!("{prefix}_resolved_samples"), sens.samples)
                .int(&format!("{prefix}_resolved_near_samples"), sens.near)
                .int(&format!("{prefix}_unresolved_samples"), sens.unresolved)
                .int(&format!("{prefix}_unavailable_samples"), sens.unavailable)
                .num(&format!("{prefix}_resolved_mu_change"), sens.mu_change())
                .num(
                    &format!("{prefix}_resolved_pressure_change"),
                    sens.pressure_change(),
                );
            let [se_mu, se_p] = sens.change_errors();
            s.num(&format!("{prefix}_resolved_mu_change_se"), se_mu)
                .num(&format!("{prefix}_resolved_pressure_change_se"), se_p);
        }
    }
}

/// Steady state of a sampled history over its window: the means of its two halves must not
/// differ by more than [`STEADY_Z`] combined standard errors *and* by more than `tolerance`
/// (absolute, the smallest change that matters for the result). The standard error of each
/// half is that of its block means ([`STEADY_BLOCKS`] blocks per half, consecutive samples being
/// correlated; Flyvbjerg & Petersen, J. Chem. Phys. 91, 1989). Returns `(Δ, z)` of the halves,
/// `None` with fewer than `2 · STEADY_BLOCKS · 2` samples.
pub fn halves_drift(samples: &[f64]) -> Option<(f64, f64)> {
    let n = samples.len() / (2 * STEADY_BLOCKS) * (2 * STEADY_BLOCKS);
    if n < 4 * STEADY_BLOCKS {
        return None;
    }
    let s = &samples[samples.len() - n..];
    let b = n / (2 * STEADY_BLOCKS);
    let blocks: Vec<f64> = s
        .chunks(b)
        .map(|c| c.iter().sum::<f64>() / b as f64)
        .collect();
    let half = |h: &[f64]| {
        let m = h.iter().sum::<f64>() / h.len() as f64;
        let var = h.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (h.len() - 1) as f64;
        (m, var / h.len() as f64)
    };
    let (m1, v1) = half(&blocks[..STEADY_BLOCKS]);
    let (m2, v2) = half(&blocks[STEADY_BLOCKS..]);
    let d = m2 - m1;
    let se = (v1 + v2).sqrt();
    let z = if se > 0.0 {
        d.abs() / se
    } else if d == 0.0 {
        0.0
    } else {
        f64::INFINITY
    };
    Some((d, z))
}

/// Blocks per half of a window in [`halves_drift`].
pub const STEADY_BLOCKS: usize = 4;
/// Difference of the window halves, in combined standard errors, above which a history is not
/// steady (with 3 degrees of freedom per half, |t| > 4 has a probability of about 1 % for a
/// steady history).
pub const STEADY_Z: f64 = 4.0;

impl Checks {
    /// Steady state of `samples` ([`halves_drift`]): suspect when the halves differ by more than
    /// [`STEADY_Z`] standard errors and by more than `tolerance`; suspect too when there are too
    /// few samples to tell.
    pub fn steady(&mut self, check: &str, what: &str, samples: &[f64], tolerance: f64) {
        match halves_drift(samples) {
            None => self.fail(
                check,
                Verdict::Suspect,
                samples.len() as f64,
                (4 * STEADY_BLOCKS) as f64,
                format!(
                    "{what}: {} samples in the averaging window, too few to test a steady state (at least {})",
                    samples.len(),
                    4 * STEADY_BLOCKS
                ),
            ),
            Some((d, z)) if z > STEADY_Z && d.abs() > tolerance => self.fail(
                check,
                Verdict::Suspect,
                d,
                tolerance,
                format!(
                    "{what} not steady over the averaging window: its second half differs from the first by {d:+.3e} ({z:.1} standard errors; limits {STEADY_Z} standard errors and {tolerance:.3e})"
                ),
            ),
            Some(_) => {}
        }
    }
}

/// A result a run exports (a calibrated law) with its verdict.
#[derive(Debug, Clone)]
pub struct LawVerdict {
    /// Law name (`janssen`, `mu-i`, …).
    pub law: String,
    /// The file written (`NAME_law.json` or `NAME_law.rejected.json`), if any.
    pub file: Option<String>,
    /// Its checks.
    pub checks: Checks,
}

/// The verdict of a run: its own checks and its results'.
#[derive(Debug, Clone, Default)]
pub struct RunVerdict {
    /// Checks of the run as a whole.
    pub run: Checks,
    /// The exported results.
    pub laws: Vec<LawVerdict>,
    /// Whether suspect laws were exported as laws (`--allow-suspect`).
    pub allow_suspect: bool,
}

impl RunVerdict {
    /// The worst of the run's checks and of its laws'.
    pub fn verdict(&self) -> Verdict {
        self.laws
            .iter()
            .map(|l| l.checks.verdict())
            .chain(std::iter::once(self.run.verdict()))
            .max()
            .unwrap_or(Verdict::Ok)
    }

    /// The run's reasons, then every law's in the laws' order.
    fn reasons(&self) -> impl Iterator<Item = &Reason> {
        self.run
            .reasons
            .iter()
            .chain(self.laws.iter().flat_map(|l| l.checks.reasons.iter()))
    }

    /// Summary keys: `verdict`, `verdict_reasons` (the run's and every law's reasons, each once)
    /// and `law_verdicts` (per law: `law`, `file`, `verdict`, `reasons`).
    pub fn keys(&self, s: &mut Summary) {
        let mut all: Vec<Value> = Vec::new();
        for r in self.reasons() {
            let v = r.to_json();
            if !all.contains(&v) {
                all.push(v);
            }
        }
        s.text("verdict", self.verdict().as_str())
            .set("verdict_reasons", Value::Array(all))
            .set(
                "law_verdicts",
                Value::Array(
                    self.laws
                        .iter()
                        .map(|l| {
                            json!({
                                "law": l.law,
                                "file": l.file,
                                "verdict": l.checks.verdict().as_str(),
                                "reasons": l.checks.reasons.iter().map(Reason::to_json).collect::<Vec<_>>(),
                            })
                        })
                        .collect(),
                ),
            );
    }

    /// The block printed on stdout: `verdict: V`, one line per reason, one per law.
    pub fn lines(&self) -> Vec<String> {
        let mut out = vec![format!("verdict: {}", self.verdict())];
        let mut seen: Vec<(&str, &str)> = Vec::new();
        for r in self.reasons() {
            let key = (r.check.as_str(), r.message.as_str());
            if !seen.contains(&key) {
                seen.push(key);
                out.push(format!("  {:<8} {}: {}", r.verdict, r.check, r.message));
            }
        }
        for l in &self.laws {
            let v = l.checks.verdict();
            let what = match (&l.file, v) {
                (Some(f), Verdict::Ok) => format!("written to {f}"),
                (Some(f), Verdict::Suspect) if self.allow_suspect => {
                    format!("written to {f}, marked suspect (--allow-suspect)")
                }
                (Some(f), _) => format!("NOT exported as a calibrated law: written to {f}"),
                (None, _) => "not written".into(),
            };
            out.push(format!("  law {}: {v}, {what}", l.law));
        }
        out
    }

    /// Whether the run's exit status is 0: everything ok, or suspect at worst with
    /// `--allow-suspect`.
    pub fn passes(&self) -> bool {
        match self.verdict() {
            Verdict::Ok => true,
            Verdict::Suspect => self.allow_suspect,
            Verdict::Refused => false,
        }
    }

    /// One line saying what failed (for the exit-status message).
    pub fn failure_line(&self) -> String {
        let mut first: Vec<String> = Vec::new();
        for r in self.reasons() {
            let t = format!("{} ({})", r.check, r.verdict);
            if !first.contains(&t) {
                first.push(t);
            }
        }
        format!(
            "verdict {}: {}",
            self.verdict(),
            if first.is_empty() {
                "no reason recorded".into()
            } else {
                first.join(", ")
            }
        )
    }
}

/// How a law was exported ([`export_law`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exported {
    /// `NAME_law.json`, verdict ok: a calibrated law.
    Calibrated,
    /// `NAME_law.json` marked suspect (`--allow-suspect`).
    MarkedSuspect,
    /// `NAME_law.rejected.json`: not a calibrated law.
    Rejected,
}

impl Exported {
    /// The printed line that goes before a law's coefficients, so that a reader of the run's
    /// report meets the verdict on them before the numbers (None for a calibrated law).
    pub fn heading(self, law: &str) -> Option<String> {
        match self {
            Exported::Calibrated => None,
            Exported::MarkedSuspect => Some(format!(
                "law {law}: SUSPECT (exported marked, --allow-suspect); its coefficients, for inspection (reasons under the verdict below):"
            )),
            Exported::Rejected => Some(format!(
                "law {law}: REJECTED, not a calibrated law; its coefficients, for inspection only (reasons under the verdict below):"
            )),
        }
    }
}

/// Writes the calibrated law `law` (named `name`, e.g. `janssen`) with the verdict of
/// `checks` and records it in `verdict`: `NAME_law.json` when ok, or when suspect with
/// `verdict.allow_suspect` (marked `"verdict": "suspect"` with its reasons); otherwise
/// `NAME_law.rejected.json` (same schema, with the verdict and reasons), and a stale file of the
/// other name from an earlier run in the directory is removed. Returns which of these it was,
/// for the printed report ([`Exported::heading`]).
pub fn export_law(
    out: &mut OutputDir,
    verdict: &mut RunVerdict,
    name: &str,
    law: &identify::CalibratedLaw,
    checks: Checks,
) -> Result<Exported> {
    let v = checks.verdict();
    let accepted = v == Verdict::Ok || (v == Verdict::Suspect && verdict.allow_suspect);
    let exported = match (accepted, v) {
        (false, _) => Exported::Rejected,
        (true, Verdict::Ok) => Exported::Calibrated,
        (true, _) => Exported::MarkedSuspect,
    };
    let (file, stale) = if accepted {
        (
            format!("{name}_law.json"),
            format!("{name}_law.rejected.json"),
        )
    } else {
        (
            format!("{name}_law.rejected.json"),
            format!("{name}_law.json"),
        )
    };
    let mut law = law.clone();
    law.verdict = Some(v.as_str().to_string());
    law.verdict_reasons = checks.reasons.iter().map(Reason::to_json).collect();
    // the one writer of a law JSON (atomic, with a final newline)
    let text = law.to_json_string()?;
    out.write(&file, (text + "\n").as_bytes())?;
    let stale = out.file(&stale);
    if stale.exists() {
        std::fs::remove_file(&stale).map_err(|e| crate::error::CliError::io(&stale, e))?;
    }
    verdict.laws.push(LawVerdict {
        law: law.law.clone(),
        file: Some(file),
        checks,
    });
    Ok(exported)
}

/// Removes `NAME_law.json` and `NAME_law.rejected.json` left in the directory by an earlier
/// run, when this run fitted no law `NAME`: a stale law must not look like this run's.
pub fn remove_stale_law(out: &OutputDir, name: &str) -> Result<()> {
    for f in [
        format!("{name}_law.json"),
        format!("{name}_law.rejected.json"),
    ] {
        let p = out.file(&f);
        if p.exists() {
            std::fs::remove_file(&p).map_err(|e| crate::error::CliError::io(&p, e))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn worst_reason_wins_and_thresholds_are_strict() {
        let mut c = Checks::new();
        c.at_most("a", 0.01, 0.01, Some(0.25), |_| String::new());
        assert_eq!(c.verdict(), Verdict::Ok, "at the threshold is ok");
        c.at_most("a", 0.02, 0.01, Some(0.25), |_| String::new());
        assert_eq!(c.verdict(), Verdict::Suspect);
        c.at_most("b", f64::NAN, 0.01, None, |_| String::new());
        assert_eq!(c.verdict(), Verdict::Refused, "a NaN measure is refused");
        assert_eq!(c.reasons[1].threshold, 0.01);
    }

    #[test]
    fn halves_of_a_linear_drift_and_of_noise() {
        // A ramp 0 → 1 over 64 samples: halves' means differ by 0.5 (32 samples apart, slope
        // 1/63 per sample → 32/63), with tiny block scatter: far beyond 4 standard errors.
        let ramp: Vec<f64> = (0..64).map(|k| k as f64 / 63.0).collect();
        let (d, z) = halves_drift(&ramp).unwrap();
        assert!((d - 32.0 / 63.0).abs() < 1e-12, "Δ = {d}");
        assert!(z > STEADY_Z, "z = {z}");
        // An alternating sequence is steady: equal halves.
        let flat: Vec<f64> = (0..64)
            .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let (d, z) = halves_drift(&flat).unwrap();
        assert_eq!(d, 0.0);
        assert_eq!(z, 0.0);
        assert!(halves_drift(&ramp[..15]).is_none());
    }

    #[test]
    fn converged_steps_are_judged_on_the_loaded_contacts_scale_too() {
        // Every step converged on the error measure (1e-6 at a tolerance of 1e-6); the same
        // residuals over the loaded contacts' scale are 2.8 (the main job's measured steps),
        // 50 and 2000 times the tolerance: ok, suspect (above 10×), refused (above 1000×).
        let judge = |loaded: f64| {
            let w = WindowStats {
                steps: 4,
                worst_error: 1e-6,
                worst_error_without_gap_shifts: loaded,
                tolerance: 1e-6,
                ..Default::default()
            };
            let mut c = Checks::new();
            c.window("measured steps", &w);
            c
        };
        assert_eq!(judge(2.8e-6).verdict(), Verdict::Ok);
        let c = judge(5e-5);
        assert_eq!(c.verdict(), Verdict::Suspect);
        assert_eq!(c.reasons[0].check, "solver.loaded_error_over_tolerance");
        assert!((c.reasons[0].value - 50.0).abs() < 1e-9);
        assert_eq!(judge(2e-3).verdict(), Verdict::Refused);
        // Under `error_scale = "loaded"` the error is the larger measure: one cause, one reason.
        let w = WindowStats {
            steps: 4,
            worst_error: 5e-5,
            worst_error_without_gap_shifts: 5e-5,
            tolerance: 1e-6,
            ..Default::default()
        };
        let mut c = Checks::new();
        c.window("measured steps", &w);
        assert_eq!(c.reasons.len(), 1, "{:?}", c.reasons);
        assert_eq!(c.reasons[0].check, "solver.worst_error_over_tolerance");
    }

    /// `n` samples of a window at μ = 0.1, P = 100 Pa as run; re-solved, σ_xy scaled by
    /// `1 + dmu / 0.1` (μ moves by `dmu`) and σ_yy by `1 + dp` (P moves by `dp`); `failed`
    /// re-solves that did not converge.
    fn resolved(n: u64, dmu: f64, dp: f64, failed: u64) -> Sensitivity {
        let mut s = Sensitivity::default();
        for _ in 0..n {
            let (xy, yy) = (-10.0, -100.0);
            s.add(
                [xy, yy],
                Some([xy * (1.0 + dmu / 0.1) * (1.0 + dp), yy * (1.0 + dp)]),
            );
        }
        for _ in 0..failed {
            s.add([-10.0, -100.0], None);
        }
        s
    }

    #[test]
    fn a_measured_sensitivity_is_the_ratio_of_the_sums() {
        let s = resolved(40, 0.01, 0.02, 3);
        assert_eq!((s.samples, s.unresolved), (40, 3));
        // μ 0.1 → 0.11 whatever the pressure; P 100 → 102 Pa.
        assert!((s.mu_change() - 0.01).abs() < 1e-12, "{}", s.mu_change());
        assert!((s.pressure_change() - 0.02).abs() < 1e-12);
        let mut m = s;
        m.merge(&resolved(40, 0.01, 0.02, 1));
        assert_eq!((m.samples, m.unresolved), (80, 4));
        assert!((m.mu_change() - 0.01).abs() < 1e-12);
        assert!(Sensitivity::default().mu_change().is_nan());
    }

    #[test]
    fn the_upper_bounds_add_the_noise_of_the_samples() {
        // Equal changes: no noise, the bounds are the changes.
        let s = resolved(40, 0.01, 0.02, 0);
        let [bm, bp] = s.upper_bounds(2.0);
        assert!(
            (bm - 0.01).abs() < 1e-9 && (bp - 0.02).abs() < 1e-9,
            "{bm} {bp}"
        );
        // Pressure changes of +5 % and −5 % Pa in turn (σ_xy unchanged): mean 0, standard
        // deviation 5 Pa · √(n/(n−1)) on P = 100 Pa, standard error of the mean over 40 samples
        // 0.05 / √39; μ = 0.1 changes by ∓0.1·5/100 per sample, mean 0.
        let mut s = Sensitivity::default();
        for i in 0..40 {
            let d = if i % 2 == 0 { -5.0 } else { 5.0 };
            s.add([-10.0, -100.0], Some([-10.0, -100.0 + d]));
        }
        let [bm, bp] = s.upper_bounds(2.0);
        assert!(s.pressure_change() < 1e-15);
        assert!((bp - 2.0 * 0.05 / 39f64.sqrt()).abs() < 1e-12, "{bp}");
        assert!((bm - 2.0 * 0.005 / 39f64.sqrt()).abs() < 1e-9, "{bm}");
        assert!(Sensitivity::default().upper_bounds(2.0)[0].is_nan());
        // Both components scaled by 1 ± 5 % in turn: each sample's μ is unchanged, so the
        // linearised δμ_i = (s Δxy_i + μ Δyy_i)/P vanishes (Δxy and Δyy fully correlated: the
        // covariance term cancels the variances), while P scatters by ±5 %.
        let mut s = Sensitivity::default();
        for i in 0..40 {
            let e = if i % 2 == 0 { -0.05 } else { 0.05 };
            s.add(
                [-10.0, -100.0],
                Some([-10.0 * (1.0 + e), -100.0 * (1.0 + e)]),
            );
        }
        let [bm, bp] = s.upper_bounds(2.0);
        assert!(bm.abs() < 1e-12, "{bm}");
        assert!((bp - 2.0 * 0.05 / 39f64.sqrt()).abs() < 1e-12, "{bp}");
    }

    #[test]
    fn a_measured_sensitivity_stands_in_for_the_loaded_scale_limit() {
        // The shear cell's windows: converged at 1e-4 on the problem's scale, 20 times that on
        // the loaded contacts' scale (suspect by the proxy).
        let judge = |loaded: f64, sens: Sensitivity| {
            let w = WindowStats {
                steps: 2000,
                worst_error: 1e-4,
                worst_error_without_gap_shifts: loaded,
                tolerance: 1e-4,
                sensitivity: sens,
                ..Default::default()
            };
            let mut c = Checks::new();
            c.window("I = 0.005", &w);
            c
        };
        let names = |c: &Checks| {
            c.reasons
                .iter()
                .map(|r| r.check.clone())
                .collect::<Vec<_>>()
        };
        // Not measured: the proxy's suspect.
        let c = judge(2e-3, Sensitivity::default());
        assert_eq!(names(&c), ["solver.loaded_error_over_tolerance"]);
        // Measured on 40 samples, μ moved by 4e-5 and P by 0.3 % (the default cell): ok.
        let c = judge(2e-3, resolved(40, 4e-5, 0.003, 1));
        assert_eq!(c.verdict(), Verdict::Ok, "{:?}", c.reasons);
        // Too few samples to stand in: the proxy judges.
        let c = judge(2e-3, resolved(5, 4e-5, 0.003, 0));
        assert_eq!(names(&c), ["solver.loaded_error_over_tolerance"]);
        // One of the 40 re-solved short of 1e-8 (within a fifth of the run's own error): the
        // measure passes but does not stand in, the proxy judges.
        let c = judge(
            2e-3,
            Sensitivity {
                near: 1,
                ..resolved(40, 4e-5, 0.003, 0)
            },
        );
        assert_eq!(names(&c), ["solver.loaded_error_over_tolerance"]);
        // μ moves by 0.01 (suspect) or 0.03 (refused); the proxy's suspect stays.
        let c = judge(2e-3, resolved(40, 0.01, 0.0, 0));
        assert_eq!(
            names(&c),
            [
                "solver.sensitivity_mu",
                "solver.loaded_error_over_tolerance"
            ]
        );
        assert_eq!(c.verdict(), Verdict::Suspect);
        assert_eq!(
            judge(2e-3, resolved(40, 0.03, 0.0, 0)).verdict(),
            Verdict::Refused
        );
        // P moves by 3 %: suspect; 12 %: refused.
        let c = judge(2e-3, resolved(40, 0.0, 0.03, 0));
        assert_eq!(c.reasons[0].check, "solver.sensitivity_pressure");
        assert_eq!(c.verdict(), Verdict::Suspect);
        assert_eq!(
            judge(2e-3, resolved(40, 0.0, 0.12, 0)).verdict(),
            Verdict::Refused
        );
        // 6 of 40 re-solves failed (13 %): suspect, and the proxy judges.
        let c = judge(2e-3, resolved(34, 0.0, 0.0, 6));
        assert_eq!(
            names(&c),
            [
                "solver.sensitivity_unresolved",
                "solver.loaded_error_over_tolerance"
            ]
        );
        // A residual beyond the refusal limit is refused whatever the measure says.
        let c = judge(0.2, resolved(40, 0.0, 0.0, 0));
        assert_eq!(c.verdict(), Verdict::Refused);
        assert_eq!(names(&c), ["solver.loaded_error_over_tolerance"]);
    }

    /// The change is judged with its samples' scatter, `√(Δμ² + SE(Δμ)²)`: the 2000-grain
    /// cell at I = 0.01 and 300 sweeps a step (2026-12-06: per-sample δμ of standard deviation
    /// 5.5·10⁻³ about a mean of 5·10⁻⁴, SE(μ) of the window 6·10⁻³, limit 1.5·10⁻³) passes on
    /// 40 samples (SE(Δμ) 8.7·10⁻⁴) and is suspect on 10 (1.7·10⁻³): the same small mean, not
    /// resolved by ten samples. Where it passes, the fraction of steps above the tolerance
    /// (every step at the sweep cap) is not judged; the pressure, held by the control (its own
    /// SE 10⁻⁴ of P), is judged against the change that moves μ through I by half of μ's
    /// limit, `0.25 · 6·10⁻³ / 0.2 = 0.75 %`.
    #[test]
    fn the_solver_effect_is_judged_with_its_samples_scatter() {
        let window = |n: usize, dp: f64| {
            let mut sens = Sensitivity::default();
            for i in 0..n {
                // σ_yy = −1000 Pa, μ = 0.3; δμ = 5e-4 ± 5.5e-3 in turn; P moves by dp.
                let d = if i % 2 == 0 { 5.5e-3 } else { -5.5e-3 };
                let mu = 0.3 + 5e-4 + d;
                let p = 1000.0 * (1.0 + dp);
                sens.add([300.0, -1000.0], Some([mu * p, -p]));
            }
            WindowStats {
                steps: 200,
                unconverged: 200,
                worst_error: 5e-3,
                worst_error_without_gap_shifts: 5e-3,
                tolerance: 1e-4,
                sensitivity: sens,
                statistical_errors: [6e-3, 1e-4],
                ..Default::default()
            }
        };
        let judge = |w: &WindowStats| {
            let mut c = Checks::new();
            c.window("I = 0.01", w);
            c
        };
        let w = window(40, 7e-4);
        let [se_mu, se_p] = w.sensitivity.change_errors();
        assert!(
            (se_mu - 5.5e-3 * (40.0f64 / 39.0).sqrt() / 40f64.sqrt()).abs() < 2e-5,
            "{se_mu}"
        );
        assert!(se_p < 1e-9, "{se_p}");
        let [dmu, dp] = w.sensitivity.measured_changes();
        assert!((dmu - (5e-4f64).hypot(se_mu)).abs() < 2e-5, "{dmu}");
        assert!((dp - 7e-4).abs() < 1e-9, "{dp}");
        assert!((pressure_limit(w.statistical_errors) - 0.0075).abs() < 1e-12);
        // Ok: the measure passed, so the worst error (50× the tolerance) is judged against the
        // refusal limit only (1000×) and the steps above the tolerance not at all.
        let c = judge(&w);
        assert_eq!(c.verdict(), Verdict::Ok, "{:?}", c.reasons);
        // Ten samples: the same mean change, not resolved: suspect by the measure, and the
        // proxies judge (every step above the tolerance: refused).
        let c = judge(&window(10, 7e-4));
        let names: Vec<_> = c.reasons.iter().map(|r| r.check.as_str()).collect();
        assert!(names.contains(&"solver.sensitivity_mu"), "{names:?}");
        assert!(names.contains(&"solver.unconverged_fraction"), "{names:?}");
        assert_eq!(c.verdict(), Verdict::Refused);
        // Every re-solve short of 1e-8, within a fifth of the run's error (the 2000-grain
        // cell's): the measure stands in for the steps above the tolerance and the worst error,
        // not for the loaded contacts' scale (20× the tolerance there: suspect).
        let mut w = window(40, 7e-4);
        w.sensitivity.near = 40;
        w.worst_error = 1e-3;
        w.worst_error_without_gap_shifts = 2e-3;
        let c = judge(&w);
        let names: Vec<_> = c.reasons.iter().map(|r| r.check.as_str()).collect();
        assert_eq!(names, ["solver.loaded_error_over_tolerance"]);
        assert_eq!(c.verdict(), Verdict::Suspect);
        // The pressure moving by 2 % (above 0.75 %): suspect by the measure.
        let c = judge(&window(40, 0.02));
        let names: Vec<_> = c.reasons.iter().map(|r| r.check.as_str()).collect();
        assert!(names.contains(&"solver.sensitivity_pressure"), "{names:?}");
    }

    #[test]
    fn a_direct_measure_that_passed_stands_in_for_the_proxy() {
        // Janssen's measurement window of seed 4 (2026-12-03): solved to 1e-6 on the problem's
        // scale, 2.48e-5 on the loaded contacts' (25× the tolerance, suspect beyond 10×), the
        // fit solved again moving K and μ_w by 0.05 and 0.08 of their half-widths.
        let w = WindowStats {
            steps: 4,
            worst_error: 1e-6,
            worst_error_without_gap_shifts: 2.48e-5,
            tolerance: 1e-6,
            ..Default::default()
        };
        let judged = |passed| {
            let mut c = Checks::new();
            c.window_measured("measurement window", &w, passed);
            c
        };
        let c = judged(false);
        assert_eq!(c.verdict(), Verdict::Suspect);
        assert_eq!(c.reasons[0].check, "solver.loaded_error_over_tolerance");
        assert_eq!(c.reasons[0].threshold, SOLVER_ERROR_SUSPECT);
        assert_eq!(judged(true).verdict(), Verdict::Ok);
        // `window` is the measure-less form.
        let mut c = Checks::new();
        c.window("measurement window", &w);
        assert_eq!(c.reasons, judged(false).reasons);
        // Beyond the refusal limit (here 2000×), refused whatever the measure says.
        let w = WindowStats {
            worst_error_without_gap_shifts: 2e-3,
            ..w
        };
        let mut c = Checks::new();
        c.window_measured("measurement window", &w, true);
        assert_eq!(c.verdict(), Verdict::Refused);
        assert_eq!(c.reasons[0].threshold, SOLVER_ERROR_REFUSED);
    }

    #[test]
    fn one_large_energy_growth_is_a_finding_whatever_the_fraction() {
        // One step in 100 grew (1 %, at the fraction's limit: passes it), by 22 % of E_load:
        // suspect by the single-step check; by 150 %, refused; by 0.5 %, nothing.
        let judge = |g: f64| {
            let w = WindowStats {
                steps: 100,
                energy_growth: 1,
                worst_energy_growth: g,
                worst_energy_growth_step: Some(4711),
                tolerance: 1e-4,
                ..Default::default()
            };
            let mut c = Checks::new();
            c.window("I = 0.25", &w);
            c
        };
        let c = judge(0.22);
        assert_eq!(c.verdict(), Verdict::Suspect, "{:?}", c.reasons);
        assert_eq!(c.reasons.len(), 1, "{:?}", c.reasons);
        assert_eq!(c.reasons[0].check, "energy.worst_step_growth");
        assert_eq!(c.reasons[0].value, 0.22);
        assert!(
            c.reasons[0].message.contains("step 4711"),
            "{}",
            c.reasons[0].message
        );
        assert!(
            c.reasons[0].message.contains("22.0 %"),
            "{}",
            c.reasons[0].message
        );
        assert_eq!(judge(1.5).verdict(), Verdict::Refused);
        assert_eq!(judge(0.005).verdict(), Verdict::Ok);
        // Merged windows keep the largest step and its index.
        let mut a = WindowStats {
            worst_energy_growth: 0.02,
            worst_energy_growth_step: Some(3),
            ..Default::default()
        };
        a.merge(&WindowStats {
            worst_energy_growth: 0.3,
            worst_energy_growth_step: Some(9),
            ..Default::default()
        });
        a.merge(&WindowStats::default());
        assert_eq!(
            (a.worst_energy_growth, a.worst_energy_growth_step),
            (0.3, Some(9))
        );
    }

    #[test]
    fn single_unconverged_step_is_judged_by_its_error() {
        let w = WindowStats {
            steps: 1,
            unconverged: 1,
            worst_error: 2e-6,
            tolerance: 1e-6,
            ..Default::default()
        };
        let mut c = Checks::new();
        c.window("measured step", &w);
        assert_eq!(c.verdict(), Verdict::Suspect);
        let w = WindowStats {
            worst_error: 2e-3,
            ..w
        };
        let mut c = Checks::new();
        c.window("measured step", &w);
        assert_eq!(c.verdict(), Verdict::Refused);
    }
}
