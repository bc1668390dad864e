//! The `auto` composite of the contact solvers, written once for the engine's step
//! (`crate::solver`) and for a standalone problem ([`super::method::solve_by`]): Gauss–Seidel
//! while it converges fast enough, then Newton, then the exact finish (the active-set solve,
//! then Lemke's method), then Gauss–Seidel for the sweeps left ([`run_auto`]). Each problem
//! supplies the stages ([`AutoStages`]); the engine also supplies a [`Backoff`] that spares
//! Newton and Lemke's method on the steps after they failed.
//!
//! This module, like the rest of [`crate::fc`], does not depend on the engine: the engine's
//! solver uses it.

use serde::{Deserialize, Serialize};

/// The stall test of `auto`: Gauss–Seidel, whose error went from `before` to `after` over the
/// last `chunk` sweeps, continues when at that linear rate it reaches `tolerance` within
/// `left` sweeps and [`AUTO_HORIZON`] chunks, `chunk · ln(tol/after) / ln(after/before) ≤
/// min(left, AUTO_HORIZON · chunk)`. One Newton iteration costs
/// as much as 10–1000 sweeps on the reference problems, so a Gauss–Seidel that converges is
/// left to finish; Newton takes over where the sweeps stall.
pub fn gauss_seidel_will_finish(
    before: f64,
    after: f64,
    chunk: usize,
    tolerance: f64,
    left: usize,
) -> bool {
    if left == 0 || after.is_nan() || after >= before || after <= 0.0 {
        return false;
    }
    let needed = chunk as f64 * (tolerance / after).ln() / (after / before).ln();
    needed <= (left as f64).min((AUTO_HORIZON * chunk) as f64)
}

/// `auto` hands over to Newton when Gauss–Seidel would need more than this many chunks to reach
/// the tolerance at its current rate (on 700-contact columns a Newton iteration costs about 20
/// sweeps, and the ones Gauss–Seidel cannot finish in 400 sweeps are those it stalls on).
pub const AUTO_HORIZON: usize = 4;

/// The two stages that `auto` alternates ([`run_auto`]), as the engine and standalone problems
/// ([`crate::fc::solve_by`]) provide them. Each continues from the current iterate.
pub trait AutoStages {
    /// What a stage can fail with.
    type Error;
    /// At most `sweeps` Gauss–Seidel sweeps: `(sweeps done, error, converged)`.
    fn sweeps(&mut self, sweeps: usize) -> Result<(usize, f64, bool), Self::Error>;
    /// The Newton stage, with at most `sweeps` smoothing sweeps: `(smoothing sweeps, converged)`.
    fn newton(&mut self, sweeps: usize) -> Result<(usize, bool), Self::Error>;
    /// The exact finish ([`crate::fc::method::exact_finish`]: the active-set solve, then, if
    /// `lemke`, Lemke's method) from the current iterate, kept when it lowers the error:
    /// whether the solve has now converged, and whether Lemke's method ran.
    fn finish(&mut self, lemke: bool) -> Result<(bool, bool), Self::Error>;
}

/// The `auto` schedule, for both the engine and `solve-fc`: Gauss–Seidel in chunks of `chunk`
/// sweeps as long as [`gauss_seidel_will_finish`] (from the error `start_error` of the starting
/// iterate); then, unless `backoff` says to skip it, Newton; then the exact finish (the
/// active-set solve, then Lemke's method); then, if that failed, Gauss–Seidel for the sweeps
/// left of `max_sweeps` and one more active-set solve from where they end. `chunk = 0` goes
/// straight to Newton (the `newton` method). The back-off records the Newton stage's outcome.
/// The stages keep their own report.
pub fn run_auto<S: AutoStages, P>(
    stages: &mut S,
    start_error: f64,
    chunk: usize,
    tolerance: f64,
    max_sweeps: usize,
    backoff: Option<&mut Backoff<P>>,
) -> Result<(), S::Error> {
    let (mut done, mut error, converged) = stages.sweeps(chunk.min(max_sweeps))?;
    if converged {
        return Ok(());
    }
    let mut reference = start_error;
    while chunk > 0
        && gauss_seidel_will_finish(reference, error, chunk, tolerance, max_sweeps - done)
    {
        reference = error;
        let (n, e, c) = stages.sweeps(chunk.min(max_sweeps - done))?;
        (done, error) = (done + n, e);
        if c {
            return Ok(());
        }
    }
    let mut backoff = backoff;
    match backoff.as_deref_mut() {
        Some(b) if b.skip > 0 => {
            // Newton failed on a recent step: Gauss–Seidel alone for the sweeps left.
            b.skip -= 1;
        }
        b => {
            let (used, converged) = stages.newton(max_sweeps - done)?;
            if let Some(b) = b {
                b.record(converged);
            }
            done += used;
            if converged {
                return Ok(());
            }
        }
    }
    let lemke = match backoff.as_deref_mut() {
        Some(b) if b.lemke_skip > 0 => {
            // Lemke's path failed on a recent step.
            b.lemke_skip -= 1;
            false
        }
        _ => true,
    };
    let (converged, lemke_ran) = stages.finish(lemke)?;
    if let (Some(b), true) = (backoff, lemke_ran) {
        b.record_lemke(converged);
    }
    if converged {
        return Ok(());
    }
    if done < max_sweeps && !stages.sweeps(max_sweeps - done)?.2 {
        stages.finish(false)?;
    }
    Ok(())
}

/// Back-off of `auto`'s Newton stage: after a step where Newton did not converge, the next
/// `skip` steps that stall use Gauss–Seidel alone; `skip` starts at 1 and doubles with every
/// further failure (up to [`Backoff::MAX_SKIP`]); a converged Newton stage, or new solver
/// settings, reset it.
/// In a regime where Newton does not help (many contacts on the stick–slip boundary) this
/// spares its cost on most steps while still trying it regularly. `P` is the solver settings
/// type: the engine's back-off is `Backoff<SolverParams>` (`crate::solver::NewtonBackoff`),
/// part of the world's state (checkpointed), so a resumed run takes the same decisions.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Backoff<P> {
    /// Stalled steps left before Newton is tried again.
    pub skip: u32,
    /// The `skip` that the next failure sets.
    pub next: u32,
    /// The solver settings this back-off was learnt with: other settings (a new phase, a
    /// tighter tolerance) start afresh.
    #[serde(default)]
    pub params: Option<P>,
    /// Stalled steps left before Lemke's method is tried again (the same doubling rule: a
    /// path that ends on a ray, as in a jammed packing whose deformation is imposed, where the
    /// contact problem has no solution, is not retried on every step).
    #[serde(default)]
    pub lemke_skip: u32,
    /// The `lemke_skip` that the next failure of Lemke's method sets.
    #[serde(default)]
    pub lemke_next: u32,
}

impl<P> Backoff<P> {
    /// Longest back-off (steps).
    pub const MAX_SKIP: u32 = 8;

    /// Records the outcome of a Newton stage.
    pub fn record(&mut self, converged: bool) {
        Self::update(&mut self.skip, &mut self.next, converged);
    }

    /// Records the outcome of Lemke's method (converged or not), as [`Backoff::record`].
    pub fn record_lemke(&mut self, converged: bool) {
        Self::update(&mut self.lemke_skip, &mut self.lemke_next, converged);
    }

    /// The doubling rule: reset on success, else skip `max(next, 1)` steps and double `next`
    /// up to [`Backoff::MAX_SKIP`].
    fn update(skip: &mut u32, next: &mut u32, converged: bool) {
        if converged {
            *skip = 0;
            *next = 0;
        } else {
            *skip = (*next).max(1);
            *next = (*skip * 2).min(Self::MAX_SKIP);
        }
    }
}
