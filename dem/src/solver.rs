//! Nonlinear Gauss–Seidel (NLGS) over contacts with body velocities kept up to date.
//!
//! The Delassus operator `W = H M⁻¹ Hᵀ` is never assembled. Body velocities
//! `v = v_free + M⁻¹ Hᵀ R` are kept current: for contact α,
//!
//! ```text
//! u_α  = H_α v + shift_α                (current local velocity, O(1))
//! q̃_α  = u_α − W_αα r_α                  (everything but contact α itself)
//! r_α' = solve_local(W_αα, q̃_α, μ_α)    (exact fixed point of the bipotential predictor–corrector)
//! v   += M⁻¹ H_αᵀ (r_α' − r_α)          (O(1): two bodies)
//! ```
//!
//! so one contact update costs O(1) whatever the number of contacts. Each update is the exact
//! minimisation of the local problem, which is what makes the sweep converge on disk contacts
//! (a single predictor–corrector step with ρ = 1/W_nn does not: W_tt = 3 W_nn).
//!
//! Once the contact statuses stop changing a sweep is an affine map of the impulses and
//! Gauss–Seidel converges linearly and slowly (the weight of a pile diffuses through the
//! network). After [`PLAIN_SWEEPS`] plain sweeps, the sweeps are accelerated by Anderson mixing
//! of the impulse vector (GMRES on an affine map, [`crate::anderson`]); after each mix the
//! body velocities are rebuilt, `v = v_free + M⁻¹ Hᵀ R` (O(N)). The iteration, the mixing and
//! its safeguard are the driver shared with [`crate::fc::nsgs`], [`crate::nlgs::drive`]: no
//! progress by a factor 0.7 over [`STAGNATION_WINDOW`] sweeps clears the history and continues
//! with plain sweeps for a while; an error that blows up restores the best iterate. A solve that
//! does not converge returns its best iterate. This module supplies what is the engine's own
//! ([`crate::nlgs::SweepProblem`]): the O(1) contact update, the sweep order (natural or
//! coloured, shuffled on a stall), the error measure and the approach-speed limit.
//!
//! Convergence is judged on the error measure of `docs/formats.md` §1.2 (Siconos'
//! natural-map error): `e = ‖r − proj_K(r − ū)‖ / max(‖q‖, ‖r‖, ‖u‖)`, `q` the local velocity at
//! zero impulse, `ū = u + μ|u_t| n`.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::assemble::contact_problem_with;
use crate::cell_coupling::CellCoupling;
use crate::colouring::ContactColouring;
use crate::cone::FrictionCone;
use crate::contact::ContactRow;
use crate::fc::auto::{run_auto, AutoStages, Backoff};
use crate::fc::method::{exact_finish, Finish, SolverMethod};
use crate::fc::newton::{self, NewtonParams, NewtonWork};
use crate::fc::FcOptions;
use crate::local::select;
use crate::math::Spatial;
use crate::nlgs::{drive, CheckSchedule, DriveParams, DriveWork, SweepProblem};
use crate::parallel::{
    coloured_sweep, max_over, reduce_chunks, runs_inline, scatter_velocities, CHUNK,
    MIN_CHUNKS_PER_TASK,
};
use crate::sweep::{sweep, update};
use crate::wavefront::Wavefront;

/// The status of a contact, and of each contact, from its impulse (the step reads them here).
pub use crate::sweep::{classify, status};

/// The scale a solve's convergence is judged on ([`SolverParams::error_scale`]).
///
/// Both measures share the residual `‖r − proj_K(r − ū)‖` of the natural map; they differ by
/// their scale ([`error_measures`], docs/physics.md §1.6):
/// `Problem` divides by `max(‖q‖, ‖r‖, ‖u‖)`, the measure of Siconos and of the fc-problem
/// files, in which the gap-closing shifts `s_α = g⁻_α / (θ h)` of the pairs open within the
/// detection gap enter `q` and `u` and nothing else; `Loaded` requires the same residual over
/// `max(‖q − s⁺‖, ‖r‖, ‖u − s⁺‖)` too, the scale of the contacts that carry the load.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ErrorScale {
    /// The error measure of the step's problem, open pairs' shifts included (the default).
    #[default]
    Problem,
    /// The larger of the two measures: the tolerance holds on the loaded contacts' scale.
    Loaded,
}

impl ErrorScale {
    /// The name used in TOML files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ErrorScale::Problem => "problem",
            ErrorScale::Loaded => "loaded",
        }
    }

    /// The error a solve is judged on, from both measures `[e, e']` of [`error_measures`].
    pub fn governing(self, errors: [f64; 2]) -> f64 {
        match self {
            ErrorScale::Problem => errors[0],
            // A NaN in either measure fails the test.
            ErrorScale::Loaded => worst(errors[0], errors[1]),
        }
    }
}

/// The larger of two errors, NaN if either is: the worst of several solves (`f64::max` returns
/// the other number, which would hide a solve that produced NaN).
pub fn worst(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// Parameters of the contact solver of a step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverParams {
    /// Tolerance on the error measure (dimensionless).
    pub tolerance: f64,
    /// Maximum number of sweeps per step.
    pub max_iterations: usize,
    /// Relaxation factor ω of the impulse update, `r ← proj_K(r + ω (r_local − r))`, in (0, 2).
    #[serde(default = "one")]
    pub relaxation: f64,
    /// Memory of the Anderson acceleration of the sweeps (0: plain Gauss–Seidel).
    #[serde(default = "anderson_memory")]
    pub anderson_memory: usize,
    /// Sweep the contacts in colour order ([`crate::colouring`]) on all rayon threads. The
    /// numbers do not depend on the thread count (one thread gives the same bits); they differ
    /// from the natural order's (`false`) within the solver tolerance.
    #[serde(default)]
    pub parallel: bool,
    /// The algorithm ([`SolverMethod`], default `auto`).
    #[serde(default)]
    pub method: SolverMethod,
    /// Gauss–Seidel sweeps between two progress checks of `auto`: Newton takes over after a
    /// chunk whose rate would not reach the tolerance within the sweep cap
    /// ([`crate::fc::auto::gauss_seidel_will_finish`]).
    #[serde(default = "auto_sweeps")]
    pub auto_sweeps: usize,
    /// Parameters of the Newton solver (`newton` and `auto`).
    #[serde(default)]
    pub newton: NewtonParams,
    /// Largest number of contacts for which `auto` ends an unconverged solve with Lemke's
    /// method. Default 0 (off): a cold path costs 2–26 pivots per contact, 1–7 s a step at 700
    /// contacts, and the default stick-slip run took 17 min instead of 2 with it on its
    /// 380-contact steps; raise it per phase to trade time for converged steps.
    #[serde(default = "lemke_max_contacts")]
    pub lemke_max_contacts: usize,
    /// Largest number of halvings of a step whose solve does not converge: the step is done
    /// again from its start as two half steps, recursively, up to `2^max_halvings` sub-steps
    /// ([`crate::step_control::step_subdivided`]). Honoured by the steppers that call
    /// `step_subdivided` (every scenario phase); [`crate::World::step`] itself does one step.
    /// Default 0 (off).
    #[serde(default)]
    pub max_halvings: u32,
    /// Whether the attempts of a step that can still be halved are solved by Gauss–Seidel
    /// alone (`auto` → `nlgs`, [`crate::step_control::step_subdivided`]): a smaller step is
    /// cheaper than the global stages on stalled attempts. Default true; `false` tries the
    /// whole step with the method asked for first (the Janssen measured step).
    #[serde(default = "yes")]
    pub gauss_seidel_attempts: bool,
    /// When the Gauss–Seidel stages evaluate the error (an O(n) pass costing about two thirds
    /// of a sweep). 0 (the default): after every sweep for the first twenty, then every
    /// `max(1, k/10)` sweeps, at most 16 ([`CheckSchedule::Growing`]). `N ≥ 1`: in natural
    /// order the sweeps measure their change `‖Δr‖/‖r‖` and the error is evaluated when that
    /// change, scaled by the error / change ratio of the last evaluation, predicts convergence,
    /// and at least every `N` sweeps ([`CheckSchedule::Every`]; the colour-ordered and
    /// cell-coupled sweeps keep the growing schedule). Either way a solve stops only where its
    /// true error meets the tolerance, which is the error it reports. Most useful for many
    /// short solves, where the growing schedule evaluates about once per sweep: the poured
    /// 2000-grain column ([`MEASURED_CHECK_EVERY`]).
    #[serde(default)]
    pub check_every: usize,
    /// Sweep budget, in multiples of `max_iterations`, of a Gauss–Seidel (`nlgs`) solve at the
    /// largest subdivision of a step ([`crate::step_control::step_subdivided`]), whose
    /// sub-steps are kept whatever their convergence: the last resort of `nlgs` is more
    /// sweeps, as that of `auto` is its global stages. Default 1 (the cap holds everywhere);
    /// the poured benchmark column uses [`crate::step_control::LAST_LEVEL_SWEEPS`].
    #[serde(default = "one_usize")]
    pub last_level_sweeps: usize,
    /// The scale the tolerance applies to ([`ErrorScale`]): `problem` (default), or `loaded`,
    /// where a solve converges only when its error over the loaded contacts' scale meets the
    /// tolerance too, and reports the larger of the two as its error.
    #[serde(default)]
    pub error_scale: ErrorScale,
}

fn one_usize() -> usize {
    1
}

fn yes() -> bool {
    true
}

fn auto_sweeps() -> usize {
    100
}

/// Default of [`SolverParams::lemke_max_contacts`]: 0, Lemke's method off in the engine's
/// `auto` (see the field).
pub fn lemke_max_contacts() -> usize {
    0
}

fn anderson_memory() -> usize {
    4
}

fn one() -> f64 {
    1.0
}

impl Default for SolverParams {
    fn default() -> Self {
        SolverParams {
            tolerance: 1e-6,
            max_iterations: 10_000,
            relaxation: 1.0,
            anderson_memory: 4,
            parallel: false,
            method: SolverMethod::Auto,
            auto_sweeps: auto_sweeps(),
            newton: NewtonParams::default(),
            lemke_max_contacts: lemke_max_contacts(),
            max_halvings: 0,
            gauss_seidel_attempts: true,
            check_every: 0,
            last_level_sweeps: 1,
            error_scale: ErrorScale::Problem,
        }
    }
}

/// Outcome of one contact solve.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct SolveReport {
    /// Sweeps done.
    pub iterations: usize,
    /// The error at the returned impulses that convergence is judged on
    /// ([`ErrorScale::governing`]): the error measure of the step's problem, or with
    /// [`ErrorScale::Loaded`] the larger of it and [`SolveReport::error_without_gap_shifts`].
    pub error: f64,
    /// Whether `error ≤ tolerance` and the approach speed is within its limit.
    pub converged: bool,
    /// Largest approach speed of a closed or loaded contact at the returned impulses (m/s),
    /// see [`approach_speed`].
    #[serde(default)]
    pub approach_speed: f64,
    /// Newton iterations (factorisations) done after the sweeps (0 with `nlgs`).
    #[serde(default)]
    pub newton_iterations: usize,
    /// Pivots of Lemke's method (0 unless it ran).
    #[serde(default)]
    pub pivots: usize,
    /// The error measure at the returned impulses with a scale that leaves out the gap-closing
    /// shifts of open pairs ([`error_measures`]): the residual relative to the velocities of
    /// the bodies and the impulses alone: above `error` where open pairs far from closing
    /// dominate the scale, possibly below it where pairs close within the step (their shift
    /// then enters `‖u − s⁺‖` and not `‖u‖`). Convergence is decided on `error`, which
    /// includes it with [`ErrorScale::Loaded`]. 0 without contacts.
    #[serde(default)]
    pub error_without_gap_shifts: f64,
}

pub use crate::nlgs::{STAGNATION_WINDOW, STALL_SWEEPS};

/// Apply the impulses currently stored in `rows` to the velocities (warm start):
/// `v ← v + M⁻¹ Hᵀ R`.
pub fn apply_impulses(rows: &[ContactRow], vel: &mut [Spatial], inv: &[Spatial]) {
    for c in rows {
        if c.r != [0.0, 0.0] {
            let (a, b) = (c.a as usize, c.b as usize);
            let (mut va, mut vb) = (vel[a], vel[b]);
            c.apply(c.r, &mut va, &inv[a], &mut vb, &inv[b]);
            vel[a] = va;
            vel[b] = vb;
        }
    }
}

/// Error measure of the current state: `‖r − proj_K(r − ū)‖ / max(q_norm, ‖r‖, ‖u‖)`.
/// Summed over fixed chunks ([`reduce_chunks`]): the same bits on any number of threads.
pub fn error_measure(rows: &[ContactRow], vel: &[Spatial], q_norm: f64) -> f64 {
    error_measures(rows, vel, [q_norm, q_norm])[0]
}

/// The error measure ([`error_measure`], first) and the same residual over a scale that
/// leaves out the positive gap-closing shifts `s⁺_α = max(s_α, 0)` of §1.3 (physics.md),
/// second:
///
/// ```text
/// e  = ‖r − proj_K(r − ū)‖ / max(‖q‖, ‖r‖, ‖u‖),
/// e' = ‖r − proj_K(r − ū)‖ / max(‖q − s⁺‖, ‖r‖, ‖u − s⁺‖),
/// ```
///
/// `q_norms = [‖q‖, ‖q − s⁺‖]` ([`free_velocity_norms`]). An open pair within the detection gap
/// adds `g / (θ h)` to `q_n` and `u_n` and nothing to the residual: it inflates the first scale,
/// by up to hundreds of times at small steps (physics.md §1.6), not the second. (A pair that
/// closes within the step, or approaches fast, can make the second scale the larger.) One
/// pass; the first value's sums are those of the measure alone, bit for bit.
pub fn error_measures(rows: &[ContactRow], vel: &[Spatial], q_norms: [f64; 2]) -> [f64; 2] {
    let [e2, r2, u2, w2] = reduce_chunks(rows, |c| {
        let u = c.velocity(&vel[c.a as usize], &vel[c.b as usize]);
        let e = c.cone().natural_map_residual(c.r, u);
        let w = u[0] - c.shift.max(0.0);
        [
            e[0] * e[0] + e[1] * e[1],
            c.r[0] * c.r[0] + c.r[1] * c.r[1],
            u[0] * u[0] + u[1] * u[1],
            w * w + u[1] * u[1],
        ]
    });
    let relative = |den: f64| if den > 0.0 { e2.sqrt() / den } else { 0.0 };
    [
        relative(q_norms[0].max(r2.sqrt()).max(u2.sqrt())),
        relative(q_norms[1].max(r2.sqrt()).max(w2.sqrt())),
    ]
}

/// Largest approach speed `max(0, −u_n)` (m/s) over the contacts that are closed (no
/// gap-closing shift) or loaded (`r_n > 0`): the rate at which the current iterate would make
/// them overlap. Open contacts closing within the step are not counted (their `u_n` includes the
/// gap shift, so `u_n ≥ 0` already means "stops at contact").
pub fn approach_speed(rows: &[ContactRow], vel: &[Spatial]) -> f64 {
    max_over(rows, |c| {
        let un = c.velocity(&vel[c.a as usize], &vel[c.b as usize])[0];
        select(c.shift <= 0.0 || c.r[0] > 0.0, -un, 0.0)
    })
    .max(0.0)
}

/// `[‖q‖, ‖q − s⁺‖]`: the norm of the free local velocities, `q_α = H_α v_free + shift_α`,
/// computed from the velocities *before* the warm-start impulses are applied, and the same
/// norm without the positive gap-closing shifts: the two scales of [`error_measures`]. One
/// pass.
pub fn free_velocity_norms(rows: &[ContactRow], vel: &[Spatial]) -> [f64; 2] {
    let [s, w] = reduce_chunks(rows, |c| {
        let u = c.velocity(&vel[c.a as usize], &vel[c.b as usize]);
        let wn = u[0] - c.shift.max(0.0);
        [u[0] * u[0] + u[1] * u[1], wn * wn + u[1] * u[1]]
    });
    [s.sqrt(), w.sqrt()]
}

/// [`sweep`] (the same impulses and velocities, bit for bit), handing `record(α, r_before,
/// r_after)` each contact's impulses as it goes (the drive's copies before and after a sweep,
/// without two more passes) and returning `(Σ_α ‖Δr_α‖², Σ_α ‖r_α‖²)` over the sweep (the
/// new impulses): the change that [`SolverParams::check_every`] predicts from.
#[inline(always)]
fn sweep_recorded(
    rows: &mut [ContactRow],
    order: &[u32],
    vel: &mut [Spatial],
    inv: &[Spatial],
    omega: f64,
    mut record: impl FnMut(usize, [f64; 2], [f64; 2]),
) -> (f64, f64) {
    let (mut d2, mut r2) = (0.0, 0.0);
    for &i in order {
        let c = &mut rows[i as usize];
        let before = c.r;
        update(c, vel, inv, omega);
        record(i as usize, before, c.r);
        let d = [c.r[0] - before[0], c.r[1] - before[1]];
        d2 += d[0] * d[0] + d[1] * d[1];
        r2 += c.r[0] * c.r[0] + c.r[1] * c.r[1];
    }
    (d2, r2)
}

/// `‖Δr‖ / ‖r‖` from the sums of [`sweep_recorded`].
fn relative_change((d2, r2): (f64, f64)) -> f64 {
    d2.sqrt() / r2.sqrt().max(f64::MIN_POSITIVE)
}

/// Plain sweeps before Anderson mixing starts (easy, warm-started steps never pay for it).
pub const PLAIN_SWEEPS: usize = 6;

/// Rebuild the body velocities from the free velocities and the impulses:
/// `v = v_free + M⁻¹ Hᵀ R`.
pub fn rebuild_velocities(
    rows: &[ContactRow],
    vel: &mut [Spatial],
    v_free: &[Spatial],
    inv: &[Spatial],
    order: &SweepOrder,
) {
    match order {
        SweepOrder::Natural(_) => {
            vel.copy_from_slice(v_free);
            apply_impulses(rows, vel, inv)
        }
        SweepOrder::Coloured { colouring, mobile } => {
            scatter_velocities(rows, colouring, vel, v_free, inv, mobile)
        }
    }
}

/// The order of the Gauss–Seidel sweeps.
#[derive(Debug)]
pub enum SweepOrder<'a> {
    /// One thread, contacts in the given order (a permutation of `0..n`).
    Natural(&'a mut [u32]),
    /// Colour classes in turn, each class on all rayon threads ([`crate::parallel`]).
    Coloured {
        /// Colour classes of the rows.
        colouring: &'a mut ContactColouring,
        /// Whether each body has a non-zero inverse mass component.
        mobile: &'a [bool],
    },
}

impl SweepOrder<'_> {
    fn sweep(&mut self, rows: &mut [ContactRow], vel: &mut [Spatial], inv: &[Spatial], omega: f64) {
        match self {
            SweepOrder::Natural(order) => sweep(rows, order, vel, inv, omega),
            SweepOrder::Coloured { colouring, mobile } => {
                coloured_sweep(rows, colouring, vel, inv, mobile, omega)
            }
        }
    }

    /// Shuffles the order (within each colour class when coloured) with the LCG state `seed`.
    fn shuffle(&mut self, seed: &mut u64) {
        let mut shuffle = |order: &mut [u32]| {
            for i in (1..order.len()).rev() {
                *seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                order.swap(i, ((*seed >> 33) as usize) % (i + 1));
            }
        };
        match self {
            SweepOrder::Natural(order) => shuffle(order),
            SweepOrder::Coloured { colouring, .. } => {
                for k in 0..colouring.blocks() {
                    let (lo, hi) = (colouring.block_offsets[k], colouring.block_offsets[k + 1]);
                    shuffle(&mut colouring.block_order[lo..hi]);
                }
                for k in 0..colouring.colours() {
                    let (lo, hi) = (colouring.offsets[k], colouring.offsets[k + 1]);
                    shuffle(&mut colouring.order[lo..hi]);
                }
            }
        }
    }
}

/// Solve the contact problem of a step with the method of `params` ([`SolverMethod`]),
/// starting from the impulses stored in `rows`. Converged means `error ≤ tolerance` and
/// [`approach_speed`] `≤ approach_limit` (m/s): the relative error alone is normalised by the
/// largest velocities of the step, so while some grains fall fast it lets resting contacts
/// approach at up to `tolerance × ‖q‖`, and their overlaps add up over the steps. On entry `vel`
/// must equal `v_free + M⁻¹ Hᵀ R` for those impulses (see [`apply_impulses`]); `q_norms` is
/// [`free_velocity_norms`]. On return `vel` matches the returned impulses.
///
/// `nlgs` sweeps up to `max_iterations` times ([`crate::nlgs::drive`]); `newton` assembles the
/// step's problem ([`crate::assemble::contact_problem`]) and runs [`crate::fc::newton`] from the
/// warm start, then sweeps for what is left; `auto` follows [`crate::fc::auto::run_auto`] (sweeps while they
/// converge fast enough, Newton, sweeps), with the back-off of [`NewtonBackoff`]. In every mode
/// `max_iterations` bounds the sweeps in all, smoothing sweeps included.
///
/// With `cell`, the stress-controlled components of a biperiodic cell are unknowns of the
/// problem ([`crate::cell_coupling`]): the sweeps keep them current (in natural order on one
/// thread, in colour order on all threads with the coupled contacts last,
/// [`CellCoupling::sweep_coupled`]) and the global methods assemble the augmented operator; on return
/// [`CellCoupling::delta`] is the change of `L` that goes with the returned impulses.
///
/// Without a cell, the sweeps of [`SweepOrder::Natural`] run in the wavefront schedule of the
/// given order ([`crate::wavefront`]): each sweep gives the same impulses and velocities bit
/// for bit, faster, and so does the solve with `check_every = 0`; with `check_every ≥ 1` the
/// sweeps' measured change is summed in the schedule's order, which may (rarely) move an error
/// check by a sweep. A stall shuffle returns to the given order.
#[allow(clippy::too_many_arguments)]
pub fn solve(
    rows: &mut [ContactRow],
    order: SweepOrder,
    vel: &mut [Spatial],
    v_free: &[Spatial],
    inv: &[Spatial],
    q_norms: [f64; 2],
    approach_limit: f64,
    params: &SolverParams,
    work: &mut SolverWork,
    mut cell: Option<&mut CellCoupling>,
) -> SolveReport {
    if let Some(c) = cell.as_deref_mut() {
        c.attach(rows);
    }
    // Natural order without a coupled cell (whose unknowns every update touches): the sweeps
    // run in the wavefront schedule of that order, the same sweeps bit for bit.
    let mut wave = std::mem::take(&mut work.wavefront);
    let scheduled = match (&order, cell.is_none()) {
        (SweepOrder::Natural(given), true) => {
            wave.build(rows, given, vel.len());
            true
        }
        _ => false,
    };
    let mut step = Step {
        rows,
        order,
        vel,
        v_free,
        inv,
        q_norms,
        last_errors: [f64::NAN; 2],
        scale: params.error_scale,
        approach_limit,
        omega: params.relaxation,
        seed: SHUFFLE_SEED,
        cell,
        measure: false,
        wave: scheduled.then_some(wave.order.as_slice()),
    };
    let mut report = solve_step(&mut step, params, work);
    // The second measure of the last evaluation belongs to the returned impulses when that
    // evaluation gave the reported error; otherwise (none made, or the last one of impulses
    // a stage rejected and put back) they are evaluated here.
    if step.scale.governing(step.last_errors).to_bits() != report.error.to_bits() {
        step.error();
    }
    report.error_without_gap_shifts = step.last_errors[1];
    if let Some(c) = step.cell.as_deref_mut() {
        c.detach(step.rows);
    }
    work.wavefront = wave;
    report
}

/// [`solve`] on the assembled step.
fn solve_step(step: &mut Step, params: &SolverParams, work: &mut SolverWork) -> SolveReport {
    let SolverWork {
        newton: newton_work,
        nlgs: drive_work,
        backoff,
        ..
    } = work;
    if params.method == SolverMethod::Nlgs {
        return nlgs_stage(step, params, params.max_iterations, drive_work);
    }
    if backoff.params != Some(*params) {
        // New solver settings (a new phase): Newton gets a fresh chance.
        *backoff = NewtonBackoff {
            params: Some(*params),
            ..NewtonBackoff::default()
        };
    }
    let (chunk, backoff) = match params.method {
        SolverMethod::Auto => (params.auto_sweeps.min(params.max_iterations), Some(backoff)),
        _ => (0, None),
    };
    let start_error = step.error();
    let mut stages = EngineStages {
        step,
        params,
        drive_work,
        newton_work,
        report: SolveReport::default(),
    };
    if params.method == SolverMethod::Lemke {
        if let Ok((true, _)) = stages.finish(true) {
            return stages.report;
        }
        // The path failed (or the stored impulses were already the best): sweeps.
        let SolveReport {
            pivots,
            newton_iterations,
            ..
        } = stages.report;
        let r = nlgs_stage(
            stages.step,
            params,
            params.max_iterations,
            stages.drive_work,
        );
        return SolveReport {
            pivots,
            newton_iterations,
            ..r
        };
    }
    let Ok(()) = run_auto(
        &mut stages,
        start_error,
        chunk,
        params.tolerance,
        params.max_iterations,
        backoff,
    );
    stages.report
}

/// The engine's stages of [`run_auto`], accumulating one [`SolveReport`].
struct EngineStages<'s, 'a> {
    step: &'s mut Step<'a>,
    params: &'s SolverParams,
    drive_work: &'s mut DriveWork,
    newton_work: &'s mut NewtonWork,
    report: SolveReport,
}

impl AutoStages for EngineStages<'_, '_> {
    type Error = std::convert::Infallible;

    fn sweeps(&mut self, sweeps: usize) -> Result<(usize, f64, bool), Self::Error> {
        let r = nlgs_stage(self.step, self.params, sweeps, self.drive_work);
        self.report = SolveReport {
            iterations: self.report.iterations + r.iterations,
            newton_iterations: self.report.newton_iterations,
            ..r
        };
        Ok((r.iterations, r.error, r.converged))
    }

    fn newton(&mut self, sweeps: usize) -> Result<(usize, bool), Self::Error> {
        let r = global(self.step, self.params, sweeps, self.newton_work);
        self.report = SolveReport {
            iterations: self.report.iterations + r.iterations,
            newton_iterations: self.report.newton_iterations + r.newton_iterations,
            ..r
        };
        Ok((r.iterations, r.converged))
    }

    fn finish(&mut self, lemke: bool) -> Result<(bool, bool), Self::Error> {
        let step = &mut *self.step;
        let error_now = step.error();
        if error_now.is_nan() {
            return Ok((false, false));
        }
        let max_contacts = match (lemke, self.params.method) {
            (false, _) => 0,
            (true, SolverMethod::Lemke) => usize::MAX,
            (true, _) => self.params.lemke_max_contacts,
        };
        if step.rows.len() > max_contacts && !newton::active_set_applies(error_now) {
            // Neither stage would run: do not assemble the problem (every stalled step of a
            // run with Lemke off comes here).
            return Ok((false, false));
        }
        let problem = step.problem();
        let r: Vec<f64> = step.rows.iter().flat_map(|c| c.r).collect();
        let warm_basis: Vec<u8> = step.rows.iter().map(|c| c.basis).collect();
        let Ok(out) = exact_finish(
            &problem,
            &r,
            error_now,
            step.problem_tolerance(self.params.tolerance),
            max_contacts,
            Some(&warm_basis),
            self.newton_work,
        ) else {
            return Ok((false, false));
        };
        self.report.pivots += out.pivots;
        self.report.newton_iterations += usize::from(out.active_set);
        let Some(Finish {
            r: better, basis, ..
        }) = out.better
        else {
            return Ok((false, out.lemke_ran));
        };
        for (c, x) in step.rows.iter_mut().zip(better.chunks_exact(2)) {
            c.r = [x[0], x[1]];
        }
        step.rebuild();
        let error = step.error();
        if error >= error_now {
            // Rounding between the two measures: keep what the sweeps left.
            for (c, x) in step.rows.iter_mut().zip(r.chunks_exact(2)) {
                c.r = [x[0], x[1]];
            }
            step.rebuild();
            return Ok((false, out.lemke_ran));
        }
        // The basis of an accepted Lemke solution is the next step's warm start.
        if let Some(basis) = &basis {
            for (c, &b) in step.rows.iter_mut().zip(basis) {
                c.basis = b;
            }
        }
        let approach = step.approach_speed();
        let converged = error <= self.params.tolerance && approach <= step.approach_limit;
        self.report = SolveReport {
            error,
            converged,
            approach_speed: approach,
            ..self.report
        };
        Ok((converged, out.lemke_ran))
    }
}

/// Seed of the LCG that shuffles the sweep order on a stall (every solve starts from it, so runs
/// are reproducible).
const SHUFFLE_SEED: u64 = 0x9E37_79B9_7F4A_7C15;

/// The contact problem of a step as [`crate::nlgs::drive`] sees it: the impulses live in the
/// rows, the body velocities `v = v_free + M⁻¹ Hᵀ R` are kept current.
struct Step<'a> {
    rows: &'a mut [ContactRow],
    order: SweepOrder<'a>,
    vel: &'a mut [Spatial],
    v_free: &'a [Spatial],
    inv: &'a [Spatial],
    /// `[‖q‖, ‖q − s⁺‖]`, the scales of [`error_measures`].
    q_norms: [f64; 2],
    /// Both measures of [`error_measures`] at the last evaluation (NaN before any).
    last_errors: [f64; 2],
    /// Which of them (or their larger) [`SweepProblem::error`] returns.
    scale: ErrorScale,
    approach_limit: f64,
    /// Relaxation factor of the contact updates.
    omega: f64,
    /// State of the shuffling LCG.
    seed: u64,
    /// The cell's stress-controlled components as unknowns, if any ([`crate::cell_coupling`]).
    cell: Option<&'a mut CellCoupling>,
    /// Whether the sweeps measure their change (set by [`nlgs_stage`]: `check_every ≥ 1` and
    /// [`Step::can_measure`]); otherwise the contact loop does no more than [`sweep`]'s.
    measure: bool,
    /// The wavefront schedule of the natural order ([`crate::wavefront`]), used by its sweeps
    /// until a stall shuffles the order.
    wave: Option<&'a [u32]>,
}

impl Step<'_> {
    /// `v = v_free + M⁻¹ Hᵀ R` for the impulses in the rows (and the cell's `δ` from them).
    fn rebuild(&mut self) {
        rebuild_velocities(self.rows, self.vel, self.v_free, self.inv, &self.order);
        if let Some(c) = self.cell.as_deref_mut() {
            c.refresh(self.rows);
        }
    }

    /// The tolerance on the assembled problem's own measure that stands for `tolerance` on
    /// the governing error, for the methods that measure on the assembled problem (Newton, the
    /// exact finish): under [`ErrorScale::Loaded`], when the loaded measure `e'` of the last
    /// evaluation is the larger, `tolerance · e / e'` (the same residual over the two scales:
    /// below it on the problem's scale is below `tolerance` on the loaded one, to the change
    /// of the scales over the stage, which the engine's own evaluation after it judges);
    /// otherwise `tolerance`.
    fn problem_tolerance(&self, tolerance: f64) -> f64 {
        let [e, e_loaded] = self.last_errors;
        match self.scale {
            ErrorScale::Loaded if e_loaded > e && e > 0.0 => tolerance * (e / e_loaded),
            _ => tolerance,
        }
    }

    /// The step's problem assembled ([`contact_problem_with`]), the cell's term included.
    fn problem(&self) -> crate::fc::FcProblem {
        contact_problem_with(self.rows, self.v_free, self.inv, self.cell.as_deref())
    }

    fn approach_speed(&self) -> f64 {
        approach_speed(self.rows, self.vel)
    }

    /// Whether the sweeps can measure their change (natural order, no coupled cell).
    fn can_measure(&self) -> bool {
        matches!((&self.order, &self.cell), (SweepOrder::Natural(_), None))
    }
}

/// [`SolverParams::check_every`] of the poured benchmark column: the longest run of sweeps
/// without an error evaluation, between which the error is evaluated only when the sweeps'
/// change predicts convergence. An evaluation costs about four fifths of a sweep (the poured
/// column, 2026-12-02: 9 % of the run for 18 235 evaluations, 45 % for 72 842 sweeps); after every
/// sweep, as the growing schedule does for the first twenty, the evaluations took 24 % of the
/// poured 2000-grain column's run (most solves end within 20 sweeps), 11 % with this schedule
/// (6 seeds: 15 % less time in all, with the copies of the Anderson mixing made by the sweep).
/// Not the default: the scenarios' trajectories, validated with the growing schedule, would
/// change (the Janssen main job's default column then settles into a state its checks refuse,
/// as seeds 3, 5 and 6 of it already do).
pub const MEASURED_CHECK_EVERY: usize = 16;

impl SweepProblem for Step<'_> {
    fn dim(&self) -> usize {
        2 * self.rows.len()
    }

    /// The relative change `‖Δr‖ / ‖r‖` of the sweep when [`Step::measure`] (measured as it
    /// goes, for the check schedule of [`nlgs_stage`]); `None` otherwise.
    fn sweep(&mut self) -> Option<f64> {
        match (self.cell.as_deref_mut(), &mut self.order) {
            (Some(cell), SweepOrder::Natural(order)) => {
                cell.sweep(self.rows, order, self.vel, self.inv, self.omega);
                None
            }
            // All threads: the uncoupled contacts in colour order, then the coupled ones.
            (Some(cell), SweepOrder::Coloured { colouring, mobile }) => {
                cell.sweep_coupled(self.rows, colouring, self.vel, self.inv, mobile, self.omega);
                None
            }
            // One thread: in the wavefront schedule of the order while there is one.
            (None, SweepOrder::Natural(order)) => {
                let order = self.wave.unwrap_or(order);
                if self.measure {
                    Some(relative_change(sweep_recorded(
                        self.rows,
                        order,
                        self.vel,
                        self.inv,
                        self.omega,
                        |_, _, _| {},
                    )))
                } else {
                    sweep(self.rows, order, self.vel, self.inv, self.omega);
                    None
                }
            }
            (None, order) => {
                order.sweep(self.rows, self.vel, self.inv, self.omega);
                None
            }
        }
    }

    /// In natural order without a coupled cell, the copies are made by the sweep itself.
    fn sweep_saving(&mut self, before: &mut [f64], after: &mut [f64]) -> Option<f64> {
        let (None, SweepOrder::Natural(order)) = (self.cell.as_deref(), &self.order) else {
            self.save(before);
            let change = self.sweep();
            self.save(after);
            return change;
        };
        let sums = sweep_recorded(
            self.rows,
            self.wave.unwrap_or(order),
            self.vel,
            self.inv,
            self.omega,
            |i, r0, r1| {
                before[2 * i] = r0[0];
                before[2 * i + 1] = r0[1];
                after[2 * i] = r1[0];
                after[2 * i + 1] = r1[1];
            },
        );
        self.measure.then(|| relative_change(sums))
    }

    fn error(&mut self) -> f64 {
        self.last_errors = error_measures(self.rows, self.vel, self.q_norms);
        self.scale.governing(self.last_errors)
    }

    /// The error within the tolerance and no closed or loaded contact approaching faster than
    /// the limit.
    fn converged(&self, error: f64, tolerance: f64) -> bool {
        error <= tolerance && self.approach_speed() <= self.approach_limit
    }

    /// `x ← (r_α)` flattened, in parallel over fixed chunks.
    fn save(&self, x: &mut [f64]) {
        let copy = |(rs, x): (&[ContactRow], &mut [f64])| {
            for (c, x) in rs.iter().zip(x.chunks_exact_mut(2)) {
                x[0] = c.r[0];
                x[1] = c.r[1];
            }
        };
        if runs_inline(self.rows.len().div_ceil(CHUNK)) {
            self.rows
                .chunks(CHUNK)
                .zip(x.chunks_mut(2 * CHUNK))
                .for_each(copy);
        } else {
            self.rows
                .par_chunks(CHUNK)
                .zip(x.par_chunks_mut(2 * CHUNK))
                .with_min_len(MIN_CHUNKS_PER_TASK)
                .for_each(copy);
        }
    }

    /// `(r_α) ← x`, then the velocities rebuilt (O(N)).
    fn load(&mut self, x: &[f64]) {
        if let (SweepOrder::Natural(_), None) = (&self.order, &self.cell) {
            // One pass: each impulse set, then applied as `apply_impulses` applies it (the
            // same contributions to the velocities in the same order, so the same bits).
            self.vel.copy_from_slice(self.v_free);
            for (c, r) in self.rows.iter_mut().zip(x.chunks_exact(2)) {
                c.r = [r[0], r[1]];
                if c.r != [0.0, 0.0] {
                    let (a, b) = (c.a as usize, c.b as usize);
                    let (mut va, mut vb) = (self.vel[a], self.vel[b]);
                    c.apply(c.r, &mut va, &self.inv[a], &mut vb, &self.inv[b]);
                    self.vel[a] = va;
                    self.vel[b] = vb;
                }
            }
            return;
        }
        let copy = |(rs, x): (&mut [ContactRow], &[f64])| {
            for (c, r) in rs.iter_mut().zip(x.chunks_exact(2)) {
                c.r = [r[0], r[1]];
            }
        };
        if runs_inline(self.rows.len().div_ceil(CHUNK)) {
            self.rows
                .chunks_mut(CHUNK)
                .zip(x.chunks(2 * CHUNK))
                .for_each(copy);
        } else {
            self.rows
                .par_chunks_mut(CHUNK)
                .zip(x.par_chunks(2 * CHUNK))
                .with_min_len(MIN_CHUNKS_PER_TASK)
                .for_each(copy);
        }
        self.rebuild();
    }

    /// Shuffles the given order (the wavefront schedule is left from then on, so a shuffled
    /// solve is the one it was before the schedule existed).
    fn shuffle(&mut self) {
        self.wave = None;
        self.order.shuffle(&mut self.seed);
    }
}

/// The Newton stage of [`solve`] (at most `max_sweeps` smoothing sweeps, which the report
/// counts): assemble, solve from the current impulses, write the impulses back and rebuild the
/// velocities. The report's error and approach speed are the engine's own,
/// evaluated on the rebuilt velocities.
fn global(
    step: &mut Step,
    params: &SolverParams,
    max_sweeps: usize,
    newton_work: &mut NewtonWork,
) -> SolveReport {
    let problem = step.problem();
    if params.error_scale == ErrorScale::Loaded {
        // Both measures of the starting impulses, for the problem's tolerance.
        step.error();
    }
    let options = FcOptions {
        tolerance: step.problem_tolerance(params.tolerance),
        max_iterations: max_sweeps,
        initial_guess: Some(step.rows.iter().flat_map(|c| c.r).collect()),
        ..FcOptions::default()
    };
    let closed: Vec<bool> = step.rows.iter().map(|c| c.shift <= 0.0).collect();
    let approach_limit = step.approach_limit;
    let accept = |r: &[f64], u: &[f64]| {
        closed
            .iter()
            .enumerate()
            .all(|(a, &closed)| !(closed || r[2 * a] > 0.0) || -u[2 * a] <= approach_limit)
    };
    let outcome = newton::solve_with(&problem, &options, &params.newton, newton_work, accept);
    let (newton_iterations, smoothing) = match outcome {
        Ok((sol, stats)) => {
            for (c, r) in step.rows.iter_mut().zip(sol.r.chunks_exact(2)) {
                c.r = [r[0], r[1]];
            }
            (stats.iterations, stats.smoothing_sweeps)
        }
        // Only invalid parameters fail, and they are checked before a run starts.
        Err(_) => (0, 0),
    };
    step.rebuild();
    let error = step.error();
    let approach = step.approach_speed();
    SolveReport {
        iterations: smoothing,
        error,
        converged: error <= params.tolerance && approach <= approach_limit,
        approach_speed: approach,
        newton_iterations,
        pivots: 0,
        error_without_gap_shifts: 0.0,
    }
}

/// Accelerated NLGS (see the module documentation) for at most `max_sweeps` sweeps, starting
/// from the impulses stored in the rows: [`crate::nlgs::drive`] on the step. Converged means
/// `error ≤ tolerance` and [`approach_speed`] `≤ approach_limit` (m/s): the relative error alone
/// is normalised by the largest velocities of the step, so while some grains fall fast it lets
/// resting contacts approach at up to `tolerance × ‖q‖`, and their overlaps add up over the
/// steps. On entry the velocities must equal `v_free + M⁻¹ Hᵀ R` for those impulses (see
/// [`apply_impulses`]); its `q_norms` are [`free_velocity_norms`].
///
/// The error is evaluated after every sweep during the first ten, then every
/// `max(1, iterations/10)` sweeps (at most 16, [`CheckSchedule::Growing`]), or, with
/// [`SolverParams::check_every`] `= N ≥ 1` in natural order, when the sweeps' measured change
/// predicts convergence and at least every `N` sweeps ([`CheckSchedule::Every`]). Either way
/// the reported error is always the true error at the returned impulses.
///
/// Without acceleration, Gauss–Seidel in a fixed order can cycle on statically indeterminate
/// clusters of sticking contacts (closed loops of grains). When the error has not halved over
/// [`STALL_SWEEPS`] sweeps, the sweeps continue in a fresh pseudo-random order each time (seeded,
/// so runs stay reproducible), which breaks the cycle.
fn nlgs_stage(
    step: &mut Step,
    params: &SolverParams,
    max_sweeps: usize,
    drive_work: &mut DriveWork,
) -> SolveReport {
    if step.rows.is_empty() {
        return SolveReport {
            converged: true,
            ..SolveReport::default()
        };
    }
    step.seed = SHUFFLE_SEED;
    step.measure = params.check_every > 0 && step.can_measure();
    let report = drive(
        step,
        &DriveParams {
            tolerance: params.tolerance,
            max_sweeps,
            anderson_memory: params.anderson_memory,
            plain_sweeps: PLAIN_SWEEPS,
            schedule: if step.measure {
                CheckSchedule::Every(params.check_every)
            } else {
                CheckSchedule::Growing
            },
            // With the measured schedule, the warm start is not evaluated: a step's problem
            // almost never meets the tolerance as it comes (the poured column: 43 of 5657
            // sub-steps), and an evaluation costs about four fifths of a sweep.
            sweep_first: step.measure,
        },
        drive_work,
    );
    SolveReport {
        iterations: report.iterations,
        error: report.error,
        converged: report.converged,
        approach_speed: step.approach_speed(),
        newton_iterations: 0,
        pivots: 0,
        error_without_gap_shifts: 0.0,
    }
}

/// Buffers of the solver kept between steps (no allocation in the steady state), and the
/// back-off of `auto`'s Newton stage.
#[derive(Debug, Clone, Default)]
pub struct SolverWork {
    newton: NewtonWork,
    nlgs: DriveWork,
    /// The sweep schedule's buffers ([`crate::wavefront`]).
    wavefront: Wavefront,
    /// When `auto` next tries Newton.
    pub backoff: NewtonBackoff,
}

impl SolverWork {
    /// What carries over from one solve to the next (the back-off of `auto`, and the Newton
    /// stage's buffers), without the Gauss–Seidel driver's buffers, which every solve fills
    /// before it reads them (left empty).
    pub(crate) fn carried(&self) -> SolverWork {
        SolverWork {
            newton: self.newton.clone(),
            nlgs: DriveWork::default(),
            wavefront: Wavefront::default(),
            backoff: self.backoff,
        }
    }

    /// Sets what carries over from one solve to the next from `src` ([`SolverWork::carried`]),
    /// keeping the driver's buffers.
    pub(crate) fn restore_carried(&mut self, src: &SolverWork) {
        self.newton.clone_from(&src.newton);
        self.backoff = src.backoff;
    }
}

/// The back-off of the engine's `auto` ([`Backoff`]), learnt with a step's [`SolverParams`]:
/// part of the world's state (checkpointed).
pub type NewtonBackoff = Backoff<SolverParams>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::local::Delassus2;

    /// A frictional contact row between bodies `a` and `b` along `n = (0, 1)`, no levers.
    fn row(a: u32, b: u32, shift: f64, r: [f64; 2]) -> ContactRow {
        ContactRow {
            a,
            b,
            n: [0.0, 1.0],
            k: [0.0; 4],
            w: Delassus2 {
                nn: 1.0,
                nt: 0.0,
                tt: 1.0,
            },
            shift,
            affine: [-0.0, -0.0],
            mu: 0.5,
            r,
            basis: 0,
        }
    }

    /// Worked by hand. Body 0 is a fixed wall. Contact 0 (wall–body 1) is loaded, `r = (1, 0)`,
    /// its bodies separating at `u = (0.01, 0)`: the natural-map residual is `(0.01, 0)`.
    /// Contact 1 (wall–body 2) is open with a gap-closing shift of 2 m/s, body 2 falling at
    /// 0.1 m/s: `u = (1.9, 0)`, no residual. So `‖e‖ = 0.01`, `‖r‖ = 1`,
    /// `‖u‖ = √(0.01² + 1.9²)` and without the shift `√(0.01² + 0.1²)`. With the scales
    /// `‖q‖ = 2`, `‖q − s⁺‖ = 0.5`: `e = 0.01 / 2 = 0.005` and `e' = 0.01 / max(0.5, 1) = 0.01`.
    /// The norms of the free velocities (here the velocities themselves) are those of `u` with
    /// and without the shift.
    #[test]
    fn the_error_without_gap_shifts_leaves_the_open_pairs_out_of_its_scale() {
        let rows = [row(0, 1, 0.0, [1.0, 0.0]), row(0, 2, 2.0, [0.0, 0.0])];
        let vel = [[0.0; 3], [0.0, 0.01, 0.0], [0.0, -0.1, 0.0]];
        let [e, e_free] = error_measures(&rows, &vel, [2.0, 0.5]);
        assert!((e - 0.005).abs() <= 1e-15, "{e}");
        assert!((e_free - 0.01).abs() <= 1e-15, "{e_free}");
        assert_eq!(error_measure(&rows, &vel, 2.0), e);
        let [q, q_free] = free_velocity_norms(&rows, &vel);
        assert!((q - (0.01f64.powi(2) + 1.9f64.powi(2)).sqrt()).abs() <= 1e-15);
        assert!((q_free - (0.01f64.powi(2) + 0.1f64.powi(2)).sqrt()).abs() <= 1e-15);
        // Without the open pair's shift the two measures are one.
        let closed = [row(0, 1, 0.0, [1.0, 0.0])];
        let [q, q_free] = free_velocity_norms(&closed, &vel);
        assert_eq!(q, q_free);
        let [e, e_free] = error_measures(&closed, &vel, [q, q_free]);
        assert_eq!(e, e_free);
    }
}
