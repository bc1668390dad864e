//! The solver-sensitivity measure of a sampled state ([`crate::verdict::Sensitivity`]): the
//! step that led to it solved again, from the same state, to
//! [`crate::verdict::SENSITIVITY_TOLERANCE`] or a hundredth of the run's own error, whichever is
//! larger ([`resolve_tolerance`]), and the state as that solve would have left it.
//!
//! The re-solve takes the step's problem `u = W r + q` as the run assembled it
//! ([`dem::World::last_step_problem`]; for a subdivided step, its last sub-step's), starts from
//! the impulses the run's solver returned and uses `auto` on the standalone problem
//! ([`dem::fc::solve_by`]: Gauss–Seidel while it makes progress, the proximal semismooth Newton
//! method, then the active-set solve and Lemke's method, exact for the 2D problem; Acary,
//! Brémond & Huber 2018 for the formulations). Its impulses then give the state through
//! Moreau–Jean's velocity update ([`dem::World::snapshot_with_last_impulses`]). Differences
//! between the two states' measured stresses are the run's solver residual seen by the
//! measurement.
//!
//! Some problems have no reachable solution at 10⁻⁸: the Janssen column's measured steps at
//! seed 8 (689 contacts, a hyperstatic column sliding along its walls, 433 062 sweeps a step to
//! reach the run's 10⁻⁶) stall at 4.6–14·10⁻⁸ after 2000 sweeps and the exact finish, at
//! 4.5–7.5·10⁻⁸ after 5000 ([`SENSITIVITY_SWEEPS`]) and 4.5–7.1·10⁻⁸ after 20 000. A re-solve
//! whose error is at most a fifth of the run's own error on the same problem
//! ([`RESOLVE_MARGIN`], `dem::fc::fc_error` of the run's impulses) is taken as the measure all
//! the same: its residual is then a fifth of the run's. (A residual bounds the distance to a
//! solution only where the solution is unique: in a hyperstatic packing the impulses are not,
//! and both solves pick one; the measure is of the stresses each gives.) Such re-solves are
//! counted apart (`Sensitivity::near`, Janssen's own count): they measure the stress but do not
//! stand in for the loaded contacts' proxy, whose scale they were not judged on.

use std::collections::VecDeque;
use std::sync::mpsc::{channel, Receiver, TryRecvError};

use dem::fc::{fc_error, solve_by, FcOptions, NewtonParams, SolverMethod};
use dem::{Snapshot, World};

use crate::verdict::{Sensitivity, SENSITIVITY_TOLERANCE};

/// Gauss–Seidel sweeps of a re-solve before its global stages end it (spent only where the
/// re-solve is slow: seed 8's Janssen steps ended at 4.6–14·10⁻⁸ after 2000 sweeps,
/// 4.5–7.5·10⁻⁸ after 5000).
pub const SENSITIVITY_SWEEPS: usize = 5000;

/// A re-solve needs to be this many times more accurate than the run, no more: it is made to
/// [`SENSITIVITY_TOLERANCE`] or to the run's own error on the same problem over this factor,
/// whichever is larger ([`resolve_tolerance`]). The measured change then differs from the
/// run's distance to the exact solution by about a hundredth of it (the residual bounds the
/// error of the stresses linearly near a solution, where the solution is unique). Measured on a
/// 2000-grain step of the simple-shear cell at I = 0.01 (error 1.3·10⁻³ on the problem's
/// measure): Gauss–Seidel reaches 2.1·10⁻⁴ in 5000 sweeps and 1.7·10⁻⁴ in 20 000, Newton
/// 1.1·10⁻³: neither that hundredth nor 10⁻⁸ is reached there (`docs/solver.md`).
pub const RESOLVE_ACCURACY: f64 = 100.0;

/// The tolerance of a re-solve of a step whose run left the error `run_error`
/// (`dem::fc::fc_error`): `max(SENSITIVITY_TOLERANCE, run_error / RESOLVE_ACCURACY)`.
pub fn resolve_tolerance(run_error: f64) -> f64 {
    if run_error.is_finite() {
        SENSITIVITY_TOLERANCE.max(run_error / RESOLVE_ACCURACY)
    } else {
        SENSITIVITY_TOLERANCE
    }
}

/// A re-solve that stops short of [`resolve_tolerance`] still measures the run when its
/// error is at most the run's own error on the same problem over this factor (module
/// documentation): its change then differs from the change to an exact solution by about a
/// fifth of it where the error bounds the distance linearly. Measured on the 2000-grain
/// simple-shear cell at I = 0.01 (300 Gauss–Seidel sweeps a step, run errors 4–7·10⁻³, 18
/// window steps re-solved from the run's impulses): 5000 sweeps reach 4.8–18× below the run
/// (median 8.2), 10 000 sweeps 6.7–25× (median 14.7), and the two give per-sample changes of μ
/// that differ by 1.8·10⁻³ (rms) against a scatter of 5.5·10⁻³ between samples and means of
/// 5.4·10⁻⁴ and 4.8·10⁻⁴; at a tenth (the factor until 2026-12-06), 17 of 20 such re-solves
/// were counted as failed.
pub const RESOLVE_MARGIN: f64 = 5.0;

/// Whether a re-solve that ended with `error` (`converged`: at [`SENSITIVITY_TOLERANCE`])
/// measures a run whose impulses have `run_error` on the same problem and measure
/// (`dem::fc::fc_error`): converged, or a finite error at most `run_error / RESOLVE_MARGIN`.
pub fn measures_the_run(converged: bool, error: f64, run_error: f64) -> bool {
    converged || (error.is_finite() && error <= run_error / RESOLVE_MARGIN)
}

/// The outcome of a re-solve of a sample's step.
#[derive(Debug, Clone, PartialEq)]
pub enum Resolved<T> {
    /// Solved to the tolerance, or to a fifth of the run's ([`measures_the_run`]): what the
    /// measure gives on the re-solved state.
    Solved(T),
    /// The re-solve reached neither the tolerance nor a fifth of the run's own error, or failed
    /// (a singular factorisation, a non-finite state): counted as unresolved, left out of the
    /// measure.
    Failed,
    /// The step's problem is not available (no step since a resume, a
    /// cell under an explicit control): no measure, counted apart.
    Unavailable,
}

impl<T> Resolved<T> {
    /// Applies `f` to a solved state.
    pub fn and_then<U>(self, f: impl FnOnce(T) -> Resolved<U>) -> Resolved<U> {
        match self {
            Resolved::Solved(t) => f(t),
            Resolved::Failed => Resolved::Failed,
            Resolved::Unavailable => Resolved::Unavailable,
        }
    }
}

/// The world's snapshot with its last step's contact problem solved to
/// [`SENSITIVITY_TOLERANCE`], or as close as [`measures_the_run`] accepts (module
/// documentation), with whether it reached that tolerance. A failure of the re-solve is an
/// outcome of the measure, never an error of the run.
pub fn resolve_last_step(w: &World) -> Resolved<(Snapshot, bool)> {
    let Some((problem, r)) = w.last_step_problem() else {
        return Resolved::Unavailable;
    };
    // The run's own error on the assembled problem (the problem's measure, whatever scale the
    // run's tolerance was on): what a re-solve short of the tolerance must improve on.
    let run_error = fc_error(&problem, &r);
    let options = FcOptions {
        tolerance: resolve_tolerance(run_error),
        max_iterations: SENSITIVITY_SWEEPS,
        initial_guess: Some(r),
        ..FcOptions::default()
    };
    match solve_by(
        &problem,
        &options,
        SolverMethod::Auto,
        &NewtonParams::default(),
    ) {
        Ok((solution, _)) if measures_the_run(solution.converged, solution.error, run_error) => w
            .snapshot_with_last_impulses(&solution.r)
            .map_or(Resolved::Failed, |snap| {
                Resolved::Solved((snap, solution.converged))
            }),
        _ => Resolved::Failed,
    }
}

/// The stress pair `[shear, normal]` (Pa) that `pair` takes from the last step's state
/// re-solved ([`resolve_last_step`]), with whether the re-solve reached the tolerance; `pair`
/// returning `None` (the state cannot be measured) is a failed sample. The one form of every
/// stress-window measure ([`record`]).
pub fn resolved_pair(
    w: &World,
    pair: impl FnOnce(&Snapshot) -> Option<[f64; 2]>,
) -> Resolved<([f64; 2], bool)> {
    resolve_last_step(w).and_then(|(snap, exact)| match pair(&snap) {
        Some(p) => Resolved::Solved((p, exact)),
        None => Resolved::Failed,
    })
}

/// Adds a sample to `s`: its bulk `[σ_xy, σ_yy]` as run and the outcome of its re-solve
/// (with whether it reached the tolerance, [`resolve_last_step`]; [`Sensitivity::add`], a
/// re-solve short of it counted in [`Sensitivity::near`] too; an unavailable problem is
/// counted apart).
pub fn record(s: &mut Sensitivity, run: [f64; 2], resolved: Resolved<([f64; 2], bool)>) {
    match resolved {
        Resolved::Solved((r, exact)) => {
            s.add(run, Some(r));
            s.near += u64::from(!exact);
        }
        Resolved::Failed => s.add(run, None),
        Resolved::Unavailable => s.unavailable += 1,
    }
}

/// The stress pair a window measures on a state (`None`: the state cannot be measured), as
/// [`resolved_pair`] takes it: a plain function, so that a re-solve can run on another thread.
pub type PairOf = fn(&Snapshot) -> Option<[f64; 2]>;

/// Re-solves pending at most per thread of the pool ([`ResolveQueue::submit`]). On the
/// 10⁴-grain cell with parallel sweeps (two threads, strain 0.3, 20 samples) the run took
/// 83.3 s with one per thread, 80.2 s with four (283 MB at most) and 73.9 s unbounded (a
/// forked step waits behind queued re-solves; unbounded, the backlog is left for both
/// threads at the window's end), against 134.6 s on one thread.
pub const PENDING_PER_THREAD: usize = 4;

/// What a re-solve on the pool sends back: its outcome, or the payload of its panic.
type Sent = std::thread::Result<ResolvedPair>;

/// The outcome of a re-solve handed to rayon's pool. Called from a thread of the pool (a run
/// inside a caller's pool), it runs the pool's pending work meanwhile (`rayon::yield_now`), its
/// own re-solve included, so that runs waiting on all the pool's threads cannot wait for each
/// other (test `runs_on_every_thread_of_a_pool_do_not_wait_for_each_other`: a blocking wait
/// hangs there); once the pool has nothing to run (the re-solve runs elsewhere) or from outside
/// the pool, it blocks until the outcome comes. A re-solve that panicked panics here, on the
/// run's thread, as it would have in line; one that never ran (its sender dropped) is failed.
fn wait_for(rx: &Receiver<Sent>) -> ResolvedPair {
    let sent = loop {
        match rx.try_recv() {
            Ok(sent) => break sent,
            Err(TryRecvError::Disconnected) => return Resolved::Failed,
            Err(TryRecvError::Empty) => {
                if rayon::yield_now() != Some(rayon::Yield::Executed) {
                    match rx.recv() {
                        Ok(sent) => break sent,
                        Err(_) => return Resolved::Failed,
                    }
                }
            }
        }
    };
    sent.unwrap_or_else(|payload| std::panic::resume_unwind(payload))
}

/// A sample's re-solved stress pair with whether it reached the tolerance ([`resolved_pair`]).
pub type ResolvedPair = Resolved<([f64; 2], bool)>;

/// The re-solves of a window's samples, run beside the simulation.
///
/// A sample's re-solve ([`resolved_pair`]) reads only the world as the sampled step left it, so
/// it can run on a copy of that world while the run goes on: with two or more threads in
/// rayon's pool, [`ResolveQueue::submit`] hands the copy to the pool (`rayon::spawn`) and
/// [`ResolveQueue::settle`] records the outcomes in the order the samples were taken. Each
/// outcome is a function of its copy alone, so the recorded sums are the same, bit for bit, as
/// when every re-solve is made in line (one thread: [`ResolveQueue::submit`] records at once).
/// Settle before reading the window's [`Sensitivity`] and before a checkpoint: pending
/// re-solves are not saved.
///
/// The re-solves share the pool with the run's own parallel work: where the run's steps do not
/// fork (the default `solver.parallel = false` below 8192 contacts) they take a thread the run
/// leaves idle; a step that forks may wait for a thread busy with a re-solve. At most
/// [`PENDING_PER_THREAD`] re-solves per thread of the pool are pending at once: a sample beyond
/// waits for the oldest and records it first, which bounds the copies held (and keeps the
/// order). A queue dropped
/// unsettled (a run that failed) cancels the re-solves that have not started.
#[derive(Default)]
pub struct ResolveQueue {
    /// The samples submitted and not yet recorded: the stress as run, the outcome's channel.
    pending: VecDeque<([f64; 2], Receiver<Sent>)>,
    /// Set when the queue is dropped: re-solves not yet started do nothing.
    cancelled: std::sync::Arc<std::sync::atomic::AtomicBool>,
}

impl std::fmt::Debug for ResolveQueue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ResolveQueue({} pending)", self.pending.len())
    }
}

impl Drop for ResolveQueue {
    fn drop(&mut self) {
        self.cancelled
            .store(true, std::sync::atomic::Ordering::Relaxed);
    }
}

impl ResolveQueue {
    /// Re-solves the sample the world `w` now holds (its stress as run: `run`) and records it
    /// into `s`: at once with one thread, else on a copy of `w` beside the run (recorded by
    /// [`ResolveQueue::settle`], or here when [`PENDING_PER_THREAD`] per thread are pending).
    pub fn submit(&mut self, s: &mut Sensitivity, w: &World, run: [f64; 2], pair: PairOf) {
        let threads = rayon::current_num_threads();
        if self.pending.is_empty() && threads < 2 {
            record(s, run, resolved_pair(w, pair));
            return;
        }
        while self.pending.len() >= PENDING_PER_THREAD * threads {
            if let Some((run, rx)) = self.pending.pop_front() {
                record(s, run, wait_for(&rx));
            }
        }
        let world = w.clone();
        let cancelled = self.cancelled.clone();
        let (tx, rx) = channel();
        rayon::spawn(move || {
            if cancelled.load(std::sync::atomic::Ordering::Relaxed) {
                return;
            }
            let sent = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                resolved_pair(&world, pair)
            }));
            // the receiver is gone only when the queue was dropped unsettled: nothing to keep
            let _ = tx.send(sent);
        });
        self.pending.push_back((run, rx));
    }

    /// Waits for the pending re-solves and records them into `s` in the order submitted.
    pub fn settle(&mut self, s: &mut Sensitivity) {
        while let Some((run, rx)) = self.pending.pop_front() {
            record(s, run, wait_for(&rx));
        }
    }

    /// Number of re-solves submitted and not yet recorded.
    pub fn pending(&self) -> usize {
        self.pending.len()
    }

    /// Whether every re-solve submitted has been recorded.
    pub fn is_settled(&self) -> bool {
        self.pending.is_empty()
    }
}

/// The serde form of a queue in a checkpointed state: a settled queue is not written
/// (`skip_serializing_if = "ResolveQueue::is_settled"`), and one with re-solves pending refuses
/// to be, so that a runner that does not settle before a checkpoint
/// ([`super::phased::PhasedRun::settle`]) fails its checkpoint with this error instead of
/// losing samples.
pub fn refuse_unsettled<S: serde::Serializer>(q: &ResolveQueue, _: S) -> Result<S::Ok, S::Error> {
    Err(serde::ser::Error::custom(format!(
        "{} re-solves of the solver-sensitivity measure are pending: the runner did not settle them before the checkpoint (PhasedRun::settle)",
        q.pending()
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With two threads a sample is pending until settled, and a pending queue refuses to be
    /// written into a checkpoint; once settled it is recorded (an empty world: its empty
    /// problem has no solve, a sample counted as unresolved) and nothing is pending.
    #[test]
    fn a_pending_re_solve_is_recorded_when_settled_and_refuses_a_checkpoint() {
        let w = World::new(
            dem::WorldParams::default(),
            dem::ContactLaws::new(&["grain"], 0.5),
        );
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        let mut s = Sensitivity::default();
        let mut q = ResolveQueue::default();
        pool.install(|| q.submit(&mut s, &w, [1.0, -2.0], |_| None));
        assert_eq!(q.pending(), 1);
        assert!(!q.is_settled());
        let e = refuse_unsettled(&q, serde_json::value::Serializer).unwrap_err();
        assert!(e.to_string().contains("1 re-solves"), "{e}");
        assert_eq!(s.unresolved, 0);
        pool.install(|| q.settle(&mut s));
        assert!(q.is_settled());
        assert_eq!((s.unresolved, s.samples, s.unavailable), (1, 0, 0), "{s:?}");
    }

    /// Converged at 1e-8 always measures; short of it, a finite error at most a fifth of the
    /// run's own (seed 8's Janssen re-solves: 4.6·10⁻⁸ and 1.4·10⁻⁷ against a run at
    /// 9.99·10⁻⁷, yes; 2.1·10⁻⁷, no); a NaN never; against a run that had (almost) converged,
    /// only a converged one.
    #[test]
    fn a_re_solve_measures_the_run_within_a_fifth_of_its_error() {
        assert!(measures_the_run(true, 1e-9, 1e-6));
        assert!(measures_the_run(false, 4.6e-8, 9.99e-7));
        assert!(measures_the_run(false, 1.36e-7, 9.99e-7));
        assert!(measures_the_run(false, 2e-7, 1e-6));
        assert!(!measures_the_run(false, 2.1e-7, 9.99e-7));
        assert!(!measures_the_run(false, f64::NAN, 1e-6));
        assert!(!measures_the_run(false, 9e-8, 3e-7));
        assert!(measures_the_run(false, 6e-8, 3e-7));
        assert!(!measures_the_run(false, 4.6e-8, 0.0));
        assert!(measures_the_run(false, 1.9e-5, 1e-4));
        assert_eq!(RESOLVE_MARGIN, 5.0);
    }

    /// The re-solve is made to a hundredth of the run's own error, never tighter than 10⁻⁸
    /// (a run at 10⁻⁶ or better is re-solved to 10⁻⁸ as before); a run without a finite error
    /// is re-solved to 10⁻⁸.
    #[test]
    fn a_re_solve_is_a_hundred_times_more_accurate_than_the_run() {
        assert_eq!(resolve_tolerance(1e-2), 1e-4);
        assert_eq!(resolve_tolerance(1e-6), SENSITIVITY_TOLERANCE);
        assert_eq!(resolve_tolerance(1e-9), SENSITIVITY_TOLERANCE);
        assert_eq!(resolve_tolerance(f64::NAN), SENSITIVITY_TOLERANCE);
    }
}
