//! The nonlinear Gauss–Seidel (NLGS) driver shared by the engine's contact solver
//! ([`crate::solver`]) and the standalone one ([`crate::fc::nsgs`]): the iteration, its Anderson
//! acceleration and the safeguard of that acceleration, written once.
//!
//! One driver, two problems. [`drive`] is the only NLGS iteration of the crate; what differs is
//! the problem it sweeps ([`SweepProblem`]):
//!
//! | problem | where | its sweep | driven by |
//! |---|---|---|---|
//! | the engine's step (`solver::Step`) | [`crate::solver`] | O(1) per contact, body velocities kept current, `W` never assembled | `solver::nlgs_stage`, the Gauss–Seidel stage of [`crate::solver::solve`] |
//! | a standalone problem (`fc::nsgs::FcSweeps`) | [`crate::fc::nsgs`] | the rows of an assembled `W` (block CSR, sweep order) | [`crate::fc::nsgs::solve`] |
//!
//! "NSGS" (Siconos' name, kept for the standalone module) and "NLGS" name the same iteration;
//! [`crate::fc::SolverMethod::Nlgs`] selects it for either problem.
//!
//! A problem ([`SweepProblem`]) holds impulses `r ∈ ℝ^{2n}` (`(r_n, r_t)` per contact) and knows
//! how to do one Gauss–Seidel sweep `r ← G(r)` (each contact's local problem solved exactly with
//! the others fixed), how to evaluate the true error measure `e(r)` of
//! `docs/formats.md` §1.2, and how to copy `r` to and from a flat vector. What it keeps
//! besides `r` (the engine's body velocities, the standalone solver's permuted copy of `W`) is
//! its own business. [`drive`] iterates:
//!
//! 1. If accelerating (Anderson memory `m > 0`, outside a plain phase): `x_k ← r`.
//! 2. Sweep: `r ← G(r)`, in a fresh order each time once the plain iteration has stalled (6);
//!    accelerating, `g_k ← r` after it (the copies of 1. and 2. made by
//!    [`SweepProblem::sweep_saving`], during the sweep where the problem can).
//! 3. When a check is due ([`CheckSchedule`]): `e ← e(r)`. If `e < e_best` the iterate is kept
//!    as the best one; if `e` is not finite or `e > 10³ e_best` (the mixing went astray), the
//!    best iterate is restored, the mixing history cleared and a plain phase begins.
//! 4. Stop if the problem accepts `r` ([`SweepProblem::converged`]: `e ≤ tolerance`, plus the
//!    engine's approach-speed limit).
//! 5. Stagnation (accelerated): over windows of [`STAGNATION_WINDOW`] = 60 sweeps outside plain
//!    phases, the smallest error must fall below 0.7 × the window's reference (the previous
//!    window's smallest error); if not, the history is cleared and a plain phase begins. Plain
//!    phases last 32 sweeps, doubling at each new one, so the worst case is plain Gauss–Seidel
//!    plus bounded overhead.
//! 6. Stall (not accelerated): Gauss–Seidel in a fixed order can cycle on statically
//!    indeterminate clusters of sticking contacts; when the error has not halved over
//!    [`STALL_SWEEPS`] sweeps, the problem is asked to shuffle its order before every sweep from
//!    then on ([`SweepProblem::shuffle`]).
//! 7. Mix (accelerated, unless the safeguard just began a plain phase or this was the last
//!    sweep, so that the returned `r` is one whose error was evaluated): with `g_k = G(x_k)` the
//!    sweep's result, residuals `f_k = g_k − x_k` and the last `m` differences `ΔF`, `ΔG`
//!    ([`crate::anderson`], type II),
//!
//!    ```text
//!    γ = argmin_γ ‖f_k − ΔF γ‖₂,      r ← g_k − ΔG γ
//!    ```
//!
//!    which is GMRES on an affine map: one sweep is affine once the contact statuses stop
//!    changing, where Gauss–Seidel has its slow linear tail.
//!
//! A solve that does not converge returns its best iterate (the one with the smallest error
//! seen), whose error is evaluated again: the reported error is always the true error at the
//! returned impulses.
//!
//! References: D. G. Anderson, *Iterative procedures for nonlinear integral equations*, J. ACM
//! 12 (1965) 547–560; H. F. Walker and P. Ni, *Anderson acceleration for fixed-point
//! iterations*, SIAM J. Numer. Anal. 49 (2011) 1715–1735.

use crate::anderson::Anderson;

/// Sweeps without the error halving after which an unaccelerated solve shuffles its order.
pub const STALL_SWEEPS: usize = 500;
/// Stagnation window of the Anderson safeguard (sweeps).
pub const STAGNATION_WINDOW: usize = 60;
/// Error reduction required over one stagnation window.
pub const STAGNATION_FACTOR: f64 = 0.7;
/// First plain phase after a stagnation or a blow-up (sweeps); doubles at each new one.
pub const PLAIN_PHASE: usize = 32;
/// An error this many times the best one seen restores the best iterate.
pub const BLOW_UP: f64 = 1e3;

/// What differs between the Gauss–Seidel solvers driven by [`drive`].
pub trait SweepProblem {
    /// Length of the flat impulse vector (2 per contact).
    fn dim(&self) -> usize;

    /// One Gauss–Seidel sweep over all contacts. Returns the relative change of the impulses
    /// `‖Δr‖ / ‖r‖` when the problem measures it ([`CheckSchedule::Every`] then checks the
    /// error early when the change predicts convergence), `None` otherwise.
    fn sweep(&mut self) -> Option<f64>;

    /// One sweep ([`Self::sweep`]) with the impulses copied to `before` just before it and to
    /// `after` just after it (as [`Self::save`] would). A problem may make the copies during the
    /// sweep; by default it saves, sweeps and saves.
    fn sweep_saving(&mut self, before: &mut [f64], after: &mut [f64]) -> Option<f64> {
        self.save(before);
        let change = self.sweep();
        self.save(after);
        change
    }

    /// The true error measure at the current impulses.
    fn error(&mut self) -> f64;

    /// Whether the current impulses, whose error is `error`, solve the problem: by default
    /// `error ≤ tolerance`; a problem may add conditions.
    fn converged(&self, error: f64, tolerance: f64) -> bool {
        error <= tolerance
    }

    /// Copies the impulses to `x` (length [`Self::dim`]).
    fn save(&self, x: &mut [f64]);

    /// Sets the impulses from `x` (length [`Self::dim`]), and whatever the problem keeps that
    /// depends on them.
    fn load(&mut self, x: &[f64]);

    /// Changes the sweep order; called before every sweep once an unaccelerated solve has
    /// stalled (see the module documentation). By default the order stays.
    fn shuffle(&mut self) {}
}

/// When [`drive`] evaluates the true error (an O(n) pass, as costly as a sweep or more).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckSchedule {
    /// After every sweep for the first ten, then every `max(1, k/10)` sweeps, at most 16 (`k`
    /// the sweeps done), and after the last one.
    Growing,
    /// At least every this many sweeps and after the last one; earlier when the sweep's
    /// relative impulse change ([`SweepProblem::sweep`]), scaled by the error / change ratio
    /// seen at the last evaluation, predicts convergence (`≤ 0.9 × tolerance`), and after
    /// every sweep as long as no ratio is known.
    Every(usize),
}

/// Parameters of [`drive`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveParams {
    /// Tolerance on the error measure, passed to [`SweepProblem::converged`].
    pub tolerance: f64,
    /// Maximum number of sweeps.
    pub max_sweeps: usize,
    /// Memory of the Anderson acceleration (0: plain Gauss–Seidel).
    pub anderson_memory: usize,
    /// Plain sweeps before the mixing starts.
    pub plain_sweeps: usize,
    /// When the error is evaluated.
    pub schedule: CheckSchedule,
    /// Sweep once before the first evaluation (when `max_sweeps > 0`): for warm-started
    /// problems that almost never meet the tolerance as they come, where an evaluation costs
    /// nearly as much as a sweep. A problem that already met it then returns after one sweep.
    pub sweep_first: bool,
}

/// Outcome of [`drive`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveReport {
    /// Sweeps done.
    pub iterations: usize,
    /// True error measure at the impulses the problem holds on return.
    pub error: f64,
    /// Whether the problem accepted them ([`SweepProblem::converged`]).
    pub converged: bool,
}

/// Buffers of [`drive`], kept between solves (no allocation in the steady state).
#[derive(Debug, Clone, Default)]
pub struct DriveWork {
    anderson: Option<Anderson>,
    shape: (usize, usize),
    x: Vec<f64>,
    g: Vec<f64>,
    best: Vec<f64>,
}

impl DriveWork {
    /// A cleared Anderson history of memory `memory` for vectors of length `dim`.
    fn prepare(&mut self, memory: usize, dim: usize) {
        match self.anderson.as_mut() {
            Some(a) if self.shape.0 == memory => {
                a.reset_to_length(dim);
                self.shape = (memory, dim);
            }
            _ => {
                self.anderson = Some(Anderson::new(memory, dim));
                self.shape = (memory, dim);
            }
        }
        self.x.resize(dim, 0.0);
        self.g.resize(dim, 0.0);
    }
}

/// When the next error evaluation is due.
struct Checks {
    schedule: CheckSchedule,
    /// `Growing`: the sweep count of the next evaluation.
    next: usize,
    /// `Every`: the sweep count of the last evaluation.
    last: usize,
    /// `Every`: error / relative change at the last evaluation (NaN while unknown).
    ratio: f64,
}

impl Checks {
    fn new(schedule: CheckSchedule) -> Self {
        Self {
            schedule,
            next: 1,
            last: 0,
            ratio: f64::NAN,
        }
    }

    /// Whether to evaluate the error after sweep `it` of at most `max`, whose relative change
    /// was `change`.
    fn due(&self, it: usize, max: usize, change: Option<f64>, tolerance: f64) -> bool {
        if it >= max {
            return true;
        }
        match self.schedule {
            CheckSchedule::Growing => it >= self.next,
            CheckSchedule::Every(every) => {
                let predicted = change.map(|c| self.ratio * c);
                it - self.last >= every
                    || predicted.is_some_and(|p| p.is_nan() || p <= 0.9 * tolerance)
            }
        }
    }

    /// Records an evaluation after sweep `it` that gave `error`.
    fn checked(&mut self, it: usize, error: f64, change: Option<f64>) {
        self.next = it + if it < 10 { 1 } else { (it / 10).clamp(1, 16) };
        self.last = it;
        if let Some(c) = change.filter(|&c| c > 0.0) {
            self.ratio = error / c;
        }
    }
}

/// State of the Anderson safeguard: plain phases and the stagnation window.
struct Safeguard {
    /// Sweeps before which no mixing is done.
    plain_until: usize,
    /// Length of the next plain phase.
    plain_phase: usize,
    window_start: usize,
    window_error: f64,
    window_best: f64,
}

impl Safeguard {
    fn new(plain_sweeps: usize, error: f64) -> Self {
        Self {
            plain_until: plain_sweeps,
            plain_phase: PLAIN_PHASE,
            window_start: 0,
            window_error: error,
            window_best: error,
        }
    }

    /// Clears the history and begins a plain phase after sweep `it`.
    fn plain_phase(&mut self, it: usize, anderson: Option<&mut Anderson>) {
        if let Some(a) = anderson {
            a.reset();
        }
        self.plain_until = it + self.plain_phase;
        self.plain_phase = self.plain_phase.saturating_mul(2);
    }

    /// Records the error after sweep `it`; true when the window just closed without enough
    /// progress.
    fn stagnated(&mut self, it: usize, error: f64) -> bool {
        if it <= self.plain_until {
            (self.window_start, self.window_error, self.window_best) = (it, error, error);
            return false;
        }
        self.window_best = self.window_best.min(error);
        if it - self.window_start < STAGNATION_WINDOW {
            return false;
        }
        let stagnated = self.window_best > STAGNATION_FACTOR * self.window_error;
        (self.window_start, self.window_error, self.window_best) = (it, self.window_best, error);
        stagnated
    }
}

/// Stall detection of the unaccelerated iteration (step 6 of the module documentation).
struct Stall {
    reference: f64,
    since: usize,
    shuffling: bool,
}

impl Stall {
    fn observe(&mut self, it: usize, error: f64) {
        if error < 0.5 * self.reference {
            (self.reference, self.since) = (error, it);
        } else if !self.shuffling && it - self.since >= STALL_SWEEPS {
            self.shuffling = true;
        }
    }
}

/// Runs the safeguarded, Anderson-accelerated Gauss–Seidel iteration of the module
/// documentation on `problem`, from the impulses it holds, for at most `params.max_sweeps`
/// sweeps. On return the problem holds the converged impulses, or else the best iterate whose
/// error was evaluated (with [`DriveParams::sweep_first`] the start is not, unless a blow-up
/// sends the iteration back to it); the report's error is the true error there.
pub fn drive<P: SweepProblem + ?Sized>(
    problem: &mut P,
    params: &DriveParams,
    work: &mut DriveWork,
) -> DriveReport {
    let tol = params.tolerance;
    // Unknown until the first evaluation when the first sweep comes before it.
    let mut error = if params.sweep_first && params.max_sweeps > 0 {
        f64::INFINITY
    } else {
        problem.error()
    };
    if error.is_finite() && problem.converged(error, tol) {
        return DriveReport {
            iterations: 0,
            error,
            converged: true,
        };
    }
    if params.max_sweeps == 0 {
        return DriveReport {
            iterations: 0,
            error,
            converged: false,
        };
    }
    let dim = problem.dim();
    let accelerated = params.anderson_memory > 0;
    if accelerated {
        work.prepare(params.anderson_memory, dim);
    }
    work.best.resize(dim, 0.0);
    problem.save(&mut work.best);
    let mut best_error = error;
    let mut checks = Checks::new(params.schedule);
    let mut guard = Safeguard::new(params.plain_sweeps, error);
    let mut stall = Stall {
        reference: error,
        since: 0,
        shuffling: false,
    };

    let mut it = 0;
    // Whether the impulses as they stand passed [`SweepProblem::converged`] at the last check.
    let mut converged = false;
    while it < params.max_sweeps {
        let mixing = accelerated && it >= guard.plain_until;
        if stall.shuffling {
            problem.shuffle();
        }
        // Mixing: x_k (before) and g_k = G(x_k) (after) for the Anderson step below.
        let change = if mixing {
            problem.sweep_saving(&mut work.x, &mut work.g)
        } else {
            problem.sweep()
        };
        it += 1;
        if checks.due(it, params.max_sweeps, change, tol) {
            error = problem.error();
            checks.checked(it, error, change);
            if error < best_error {
                best_error = error;
                problem.save(&mut work.best);
            } else if !error.is_finite() || error > BLOW_UP * best_error {
                problem.load(&work.best);
                error = problem.error();
                if !best_error.is_finite() {
                    // The start, never evaluated under `sweep_first`, is the best there is.
                    best_error = error;
                }
                guard.plain_phase(it, work.anderson.as_mut());
            }
            converged = problem.converged(error, tol);
            if converged {
                break;
            }
            if !accelerated {
                stall.observe(it, error);
            } else if guard.stagnated(it, error) {
                guard.plain_phase(it, work.anderson.as_mut());
            }
        }
        if mixing && it >= guard.plain_until && it < params.max_sweeps {
            if let Some(aa) = work.anderson.as_mut() {
                // `work.g` holds g_k: a check between the sweep and here either stopped the
                // iteration or restored the best iterate and began a plain phase (no mixing).
                aa.step(&work.x, &mut work.g);
                problem.load(&work.g);
            }
        }
    }
    // The loop ends on the impulses of its last check (a converged one, or the check after the
    // last sweep, which no mixing follows), so `converged` is theirs: not tested again (the
    // engine's test includes a pass over the contacts, the approach speed).
    if !converged && best_error < error {
        problem.load(&work.best);
        error = problem.error();
        converged = problem.converged(error, tol);
    }
    DriveReport {
        iterations: it,
        error,
        converged,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gauss–Seidel on the 1D Poisson system `2 x_i − x_{i−1} − x_{i+1} = 1` (slow linear
    /// convergence, as a loaded pile), or a sweep that only scales `x` (`scale`, to make the
    /// error stall or blow up).
    struct Poisson {
        x: Vec<f64>,
        scale: Option<f64>,
        evaluations: usize,
        shuffles: usize,
        /// Whether the sweep returns its relative change.
        measured: bool,
    }

    impl Poisson {
        fn new(n: usize, scale: Option<f64>) -> Self {
            Self {
                x: vec![0.5; n],
                scale,
                evaluations: 0,
                shuffles: 0,
                measured: false,
            }
        }
    }

    impl SweepProblem for Poisson {
        fn dim(&self) -> usize {
            self.x.len()
        }
        fn sweep(&mut self) -> Option<f64> {
            let n = self.x.len();
            if let Some(s) = self.scale {
                self.x.iter_mut().for_each(|x| *x *= s);
                return None;
            }
            let (mut d2, mut x2) = (0.0, 0.0);
            for i in 0..n {
                let l = if i > 0 { self.x[i - 1] } else { 0.0 };
                let r = if i + 1 < n { self.x[i + 1] } else { 0.0 };
                let new = 0.5 * (1.0 + l + r);
                d2 += (new - self.x[i]) * (new - self.x[i]);
                x2 += new * new;
                self.x[i] = new;
            }
            self.measured.then(|| (d2 / x2).sqrt())
        }
        fn error(&mut self) -> f64 {
            self.evaluations += 1;
            let n = self.x.len();
            let res2: f64 = (0..n)
                .map(|i| {
                    let l = if i > 0 { self.x[i - 1] } else { 0.0 };
                    let r = if i + 1 < n { self.x[i + 1] } else { 0.0 };
                    (2.0 * self.x[i] - l - r - 1.0).powi(2)
                })
                .sum();
            (res2 / n as f64).sqrt()
        }
        fn save(&self, x: &mut [f64]) {
            x.copy_from_slice(&self.x);
        }
        fn load(&mut self, x: &[f64]) {
            self.x.copy_from_slice(x);
        }
        fn shuffle(&mut self) {
            self.shuffles += 1;
        }
    }

    fn params(memory: usize, max_sweeps: usize, schedule: CheckSchedule) -> DriveParams {
        DriveParams {
            tolerance: 1e-8,
            max_sweeps,
            anderson_memory: memory,
            plain_sweeps: 0,
            schedule,
            sweep_first: false,
        }
    }

    /// [`drive`] with fresh buffers.
    fn run(
        p: &mut Poisson,
        memory: usize,
        max_sweeps: usize,
        schedule: CheckSchedule,
    ) -> DriveReport {
        drive(
            p,
            &params(memory, max_sweeps, schedule),
            &mut DriveWork::default(),
        )
    }

    #[test]
    fn anderson_converges_in_far_fewer_sweeps_than_plain_gauss_seidel() {
        let mut work = DriveWork::default();
        let mut plain = Poisson::new(40, None);
        let p = drive(
            &mut plain,
            &params(0, 100_000, CheckSchedule::Growing),
            &mut work,
        );
        let mut mixed = Poisson::new(40, None);
        let a = drive(
            &mut mixed,
            &params(4, 100_000, CheckSchedule::Every(10)),
            &mut work,
        );
        assert!(p.converged && a.converged, "{p:?} {a:?}");
        assert!(a.iterations * 5 < p.iterations, "{a:?} vs {p:?}");
        // The reported error is the one of the returned iterate.
        assert_eq!(a.error, mixed.error());
        assert_eq!(p.error, plain.error());
        assert_eq!(plain.shuffles, 0);
    }

    /// With sweeps that measure their change, `Every(16)` evaluates the error where the change
    /// predicts convergence: the same tolerance met (the reported error is the true one at the
    /// returned iterate), at most 16 sweeps more, and fewer evaluations than the growing
    /// schedule; for a short (accelerated) solve, where the growing schedule evaluates after
    /// every sweep, under a third of them.
    #[test]
    fn predicted_checks_meet_the_tolerance_with_few_evaluations() {
        for (memory, fraction) in [(0, 1), (4, 3)] {
            let mut growing = Poisson::new(40, None);
            growing.measured = true;
            let g = run(&mut growing, memory, 100_000, CheckSchedule::Growing);
            let mut every = Poisson::new(40, None);
            every.measured = true;
            let e = run(&mut every, memory, 100_000, CheckSchedule::Every(16));
            assert!(g.converged && e.converged, "{g:?} {e:?}");
            assert!(e.error <= 1e-8 && e.error == every.error());
            assert!(e.iterations <= g.iterations + 16, "{e:?} vs {g:?}");
            assert!(
                fraction * every.evaluations < growing.evaluations,
                "memory {memory}: {} vs {} evaluations, {} vs {} sweeps",
                every.evaluations,
                growing.evaluations,
                e.iterations,
                g.iterations
            );
        }
    }

    #[test]
    fn growing_schedule_checks_every_sweep_first_then_sparsely() {
        let mut p = Poisson::new(40, None);
        let r = run(&mut p, 0, 100, CheckSchedule::Growing);
        assert!(!r.converged && r.iterations == 100);
        // The initial one, after sweeps 1 to 20, 22 to 30 by 2, 33, 36, 39, 42, 46, 50, 55, 60,
        // 66, 72, 79, 86, 94, and after the last (100).
        assert_eq!(p.evaluations, 1 + 20 + 5 + 3 + 3 + 7 + 1);
    }

    #[test]
    fn a_blow_up_restores_the_best_iterate_and_it_is_returned() {
        // Every sweep doubles x: the error grows from the start, so the initial iterate is the
        // best one and comes back (with its error) whether mixing or not.
        for memory in [0, 4] {
            let mut p = Poisson::new(10, Some(2.0));
            let e0 = p.error();
            let r = run(&mut p, memory, 300, CheckSchedule::Every(10));
            assert!(!r.converged && r.iterations == 300);
            assert_eq!(r.error, e0);
            assert!(p.x.iter().all(|&x| x == 0.5));
        }
    }

    #[test]
    fn a_stalled_plain_iteration_shuffles_its_order() {
        let mut p = Poisson::new(10, Some(1.0));
        let r = run(&mut p, 0, 700, CheckSchedule::Growing);
        assert!(!r.converged && r.iterations == 700);
        assert!(p.shuffles > 100 && p.shuffles < 200, "{}", p.shuffles);
        let mut q = Poisson::new(10, Some(1.0));
        run(&mut q, 4, 700, CheckSchedule::Growing);
        assert_eq!(q.shuffles, 0);
    }

    #[test]
    fn a_converged_start_or_no_sweep_allowed_returns_at_once() {
        let mut p = Poisson::new(10, None);
        let r = run(&mut p, 4, 0, CheckSchedule::Growing);
        assert_eq!((r.iterations, r.converged, p.evaluations), (0, false, 1));
        let tol = DriveParams {
            tolerance: 1.0,
            ..params(4, 10, CheckSchedule::Growing)
        };
        let r = drive(&mut p, &tol, &mut DriveWork::default());
        assert_eq!((r.iterations, r.converged), (0, true));
    }

    #[test]
    fn sweep_first_skips_the_evaluation_before_the_first_sweep() {
        // A converged start still sweeps once, then stops at the first evaluation (no ratio
        // known yet: the measured schedule evaluates after the sweep).
        let mut p = Poisson::new(10, None);
        p.measured = true;
        let loose = DriveParams {
            tolerance: 1.0,
            sweep_first: true,
            ..params(4, 10, CheckSchedule::Every(16))
        };
        let r = drive(&mut p, &loose, &mut DriveWork::default());
        assert_eq!((r.iterations, r.converged, p.evaluations), (1, true, 1));
        // A hard problem: the same sweeps and error as without, one evaluation fewer.
        let schedule = CheckSchedule::Growing;
        let (mut a, mut b) = (Poisson::new(40, None), Poisson::new(40, None));
        let ra = drive(
            &mut a,
            &params(4, 2000, schedule),
            &mut DriveWork::default(),
        );
        let first = DriveParams {
            sweep_first: true,
            ..params(4, 2000, schedule)
        };
        let rb = drive(&mut b, &first, &mut DriveWork::default());
        assert!(ra.converged && rb.converged);
        assert_eq!(ra.iterations, rb.iterations);
        assert_eq!(ra.error.to_bits(), rb.error.to_bits());
        assert_eq!(b.evaluations + 1, a.evaluations);
        // No sweep allowed: the start is evaluated all the same.
        let mut c = Poisson::new(10, None);
        let none = DriveParams {
            sweep_first: true,
            ..params(4, 0, schedule)
        };
        let r = drive(&mut c, &none, &mut DriveWork::default());
        assert_eq!((r.iterations, r.converged, c.evaluations), (0, false, 1));
        assert!(r.error.is_finite());
    }
}
