//! Parallel kernels of the contact solve, with results independent of the number of threads.
//!
//! - [`coloured_sweep`]: one Gauss–Seidel sweep visiting the colour classes of a
//!   [`ContactColouring`] in turn; the contacts of a class share no mobile body, so they are
//!   updated concurrently on the rayon pool and the numbers are exactly those of the same
//!   class order swept by one thread.
//! - [`scatter_velocities`]: `v = v_free + M⁻¹ Hᵀ R`, each contact's impulse added to its
//!   bodies in the same colour order (no two tasks on one body).
//! - [`reduce_chunks`]: sums over contacts as partial sums over fixed chunks of [`CHUNK`]
//!   contacts added in chunk order, so the rounding does not depend on the thread count.
//!
//! The thread count is rayon's (`RAYON_NUM_THREADS`, or a pool installed by the caller); with
//! one thread the same code runs sequentially and gives bit-identical results.

use rayon::prelude::*;

use crate::colouring::ContactColouring;
use crate::contact::ContactRow;
use crate::math::Spatial;
use crate::sweep::local_update;

/// Contacts per chunk of the fixed-partition reductions.
pub const CHUNK: usize = 1024;
/// Fewest chunks per parallel task of the chunked passes: below `2 × 4 × CHUNK` contacts a pass
/// runs on the calling thread (the same partial sums in the same order, so the same bits),
/// where forking would cost more than the pass ([`runs_inline`]).
pub const MIN_CHUNKS_PER_TASK: usize = 4;

/// Whether a chunked pass of `chunks` chunks runs as a plain loop on the calling thread: when
/// it is one task's worth (fewer than `2 ×` [`MIN_CHUNKS_PER_TASK`] chunks, which rayon would
/// not split either) or the pool has one thread. Handing such a pass to rayon from a thread
/// outside its pool (the main thread of a run) is not free even when it makes one task: the job
/// is injected into the pool, a worker is woken to run it and the caller sleeps until it is
/// done, a round trip of microseconds per pass (a step that forks runs on a worker instead,
/// `World::step`). The chunks and the order in which their partial results are combined are the
/// same either way, so are the bits.
#[inline]
pub fn runs_inline(chunks: usize) -> bool {
    chunks < 2 * MIN_CHUNKS_PER_TASK || rayon::current_num_threads() == 1
}
/// Fewest contacts per parallel task inside a colour class (rayon splits adaptively above).
pub const TASK: usize = 256;
/// Classes with fewer contacts than this are swept on the calling thread (the same numbers, no
/// fork–join overhead).
pub const PARALLEL_MIN: usize = 4 * TASK;

/// A raw pointer shared between the tasks of one colour class.
#[derive(Clone, Copy)]
pub(crate) struct Shared<T>(pub(crate) *mut T);
// SAFETY: a `Shared` is only dereferenced at indices that no other task of the same class
// touches (see `update_shared`); the pointee outlives the parallel section.
unsafe impl<T> Send for Shared<T> {}
unsafe impl<T> Sync for Shared<T> {}

impl<T> Shared<T> {
    /// The pointer (a method, so that closures capture the whole `Shared`, not its field).
    #[inline(always)]
    pub(crate) fn ptr(self) -> *mut T {
        self.0
    }
}

/// Updates contact `i` through shared pointers, writing back only the velocities of mobile
/// bodies.
///
/// # Safety
/// No other thread may access row `i` or the velocity of a mobile body of row `i` at the same
/// time; immobile bodies are only read (their velocity is never written by the solver).
#[inline(always)]
pub(crate) unsafe fn update_shared(
    rows: Shared<ContactRow>,
    i: usize,
    vel: Shared<Spatial>,
    inv: &[Spatial],
    mobile: &[bool],
    omega: f64,
) -> bool {
    // SAFETY: guaranteed by the caller (colour classes, `i` in bounds).
    let c = unsafe { &mut *rows.ptr().add(i) };
    let (a, b) = (c.a as usize, c.b as usize);
    assert!(a < inv.len() && b < inv.len(), "contact body out of range");
    let (pa, pb) = unsafe { (vel.ptr().add(a), vel.ptr().add(b)) };
    let (mut va, mut vb) = unsafe { (*pa, *pb) };
    let changed = local_update(c, &mut va, &inv[a], &mut vb, &inv[b], omega);
    if changed {
        if mobile[a] {
            unsafe { *pa = va };
        }
        if mobile[b] {
            unsafe { *pb = vb };
        }
    }
    changed
}

/// Runs `f(i)` for every contact `i`: first the blocks' interiors (blocks concurrently, each in
/// ascending order), then the colour classes in turn, the contacts of a parallel class
/// concurrently ([`coloured_units`] without a state between the units).
#[inline]
fn for_each_coloured(colouring: &ContactColouring, f: impl Fn(usize) + Sync) {
    coloured_units(
        colouring,
        &mut (),
        |_, ids| ids.iter().for_each(|&i| f(i as usize)),
        |_, ()| {},
    );
}

/// The colour-ordered traversal in fixed *units* with a state `S` between them: the blocks' interiors (one unit per block, concurrently), then each colour
/// class in turn (one unit if it is sequential or smaller than [`PARALLEL_MIN`], else chunks
/// of [`TASK`] contacts, concurrently). Every unit of a phase reads the state as it was at the
/// phase's start and returns its change `A`; the changes are merged into the state in unit
/// order after the phase (`merge`). The units and the merge order are fixed by the colouring,
/// not by the thread count, so the results have the same bits on any number of threads. The
/// cell-coupled sweep of the grains following the cell within the step uses it
/// ([`crate::cell_coupling::CellCoupling::sweep_coupled`]: `S` the cell's change `δ`).
pub(crate) fn coloured_units<S: Sync, A: Send>(
    colouring: &ContactColouring,
    state: &mut S,
    unit: impl Fn(&S, &[u32]) -> A + Sync,
    merge: impl Fn(&mut S, A),
) {
    match colouring.blocks() {
        0 => {}
        1 => {
            let a = unit(state, colouring.block(0));
            merge(state, a);
        }
        b => {
            let st: &S = state;
            let changes: Vec<A> = (0..b)
                .into_par_iter()
                .map(|k| unit(st, colouring.block(k)))
                .collect();
            for a in changes {
                merge(state, a);
            }
        }
    }
    for k in 0..colouring.colours() {
        let class = colouring.class(k);
        if colouring.is_sequential(k) || class.len() < PARALLEL_MIN {
            let a = unit(state, class);
            merge(state, a);
        } else {
            let st: &S = state;
            let changes: Vec<A> = class.par_chunks(TASK).map(|ids| unit(st, ids)).collect();
            for a in changes {
                merge(state, a);
            }
        }
    }
}

/// One Gauss–Seidel sweep in colour order (see the module documentation). `mobile[i]` is true
/// when body `i` has a non-zero inverse mass component; `colouring` must have been built from
/// `rows` and `mobile`.
pub fn coloured_sweep(
    rows: &mut [ContactRow],
    colouring: &ContactColouring,
    vel: &mut [Spatial],
    inv: &[Spatial],
    mobile: &[bool],
    omega: f64,
) {
    coloured_sweep_where(rows, colouring, vel, inv, mobile, omega, |_| true)
}

/// [`coloured_sweep`] over the contacts `i` with `keep(i)` only, the others left as they are
/// (the cell-coupled sweep, [`crate::cell_coupling::CellCoupling::sweep_coupled`], updates
/// the contacts coupled to a cell after the others).
pub(crate) fn coloured_sweep_where(
    rows: &mut [ContactRow],
    colouring: &ContactColouring,
    vel: &mut [Spatial],
    inv: &[Spatial],
    mobile: &[bool],
    omega: f64,
    keep: impl Fn(usize) -> bool + Sync,
) {
    let (n_rows, pr, pv) = shared_sweep_inputs(rows, colouring, vel, inv, mobile);
    for_each_coloured(colouring, |i| {
        assert!(i < n_rows);
        if !keep(i) {
            return;
        }
        // SAFETY: within a parallel class no two contacts share a row or a mobile body
        // (`ContactColouring::build`); sequential classes run on one thread; `i` checked, body
        // indices checked in `update_shared`.
        unsafe { update_shared(pr, i, pv, inv, mobile, omega) };
    });
}

/// The checked inputs of a colour-ordered sweep as shared pointers: the colouring is of `rows`
/// and the bodies' arrays agree in length; returns the row count and the rows' and velocities'
/// pointers (dereferenced only under the colouring's exclusivity, [`update_shared`]).
pub(crate) fn shared_sweep_inputs(
    rows: &mut [ContactRow],
    colouring: &ContactColouring,
    vel: &mut [Spatial],
    inv: &[Spatial],
    mobile: &[bool],
) -> (usize, Shared<ContactRow>, Shared<Spatial>) {
    assert_eq!(
        colouring.order.len() + colouring.block_order.len(),
        rows.len(),
        "colouring of other rows"
    );
    assert!(vel.len() == inv.len() && vel.len() == mobile.len());
    (
        rows.len(),
        Shared(rows.as_mut_ptr()),
        Shared(vel.as_mut_ptr()),
    )
}

/// `v ← v_free + M⁻¹ Hᵀ R` by scattering each contact's impulse onto its two bodies, contacts
/// visited in the colour order of [`coloured_sweep`] (blocks concurrently, then the classes):
/// each mobile body receives its contributions in an order fixed by the colouring, so the
/// result has the same bits on any thread count. It streams the contact rows once: a gather
/// body by body over a body → contacts adjacency, which reads each row twice in body order, took
/// 1.5× as long at 10⁴ and 10⁵ contacts.
pub fn scatter_velocities(
    rows: &[ContactRow],
    colouring: &ContactColouring,
    vel: &mut [Spatial],
    v_free: &[Spatial],
    inv: &[Spatial],
    mobile: &[bool],
) {
    assert!(vel.len() == v_free.len() && vel.len() == inv.len() && vel.len() == mobile.len());
    assert_eq!(
        colouring.order.len() + colouring.block_order.len(),
        rows.len(),
        "colouring of other rows"
    );
    vel.copy_from_slice(v_free);
    let pv = Shared(vel.as_mut_ptr());
    let n_rows = rows.len();
    for_each_coloured(colouring, |i| {
        assert!(i < n_rows);
        let c = &rows[i];
        if c.r == [0.0, 0.0] {
            return;
        }
        let (a, b) = (c.a as usize, c.b as usize);
        assert!(a < inv.len() && b < inv.len(), "contact body out of range");
        for (side, body) in [(0u32, a), (1u32, b)] {
            if mobile[body] {
                let d = c.impulse_on(side, c.r);
                let m = inv[body];
                // SAFETY: within a parallel class (or block) no two contacts share a mobile
                // body (`ContactColouring`), so no other task touches `vel[body]`; `body` is in
                // bounds (checked above).
                let v = unsafe { &mut *pv.ptr().add(body) };
                v[0] += m[0] * d[0];
                v[1] += m[1] * d[1];
                v[2] += m[2] * d[2];
            }
        }
    });
}

/// `max_α f(α)` over the contacts, chunk by chunk on the rayon pool (−∞ when there is none).
pub fn max_over(rows: &[ContactRow], f: impl Fn(&ContactRow) -> f64 + Sync) -> f64 {
    let chunk_max = |ch: &[ContactRow]| ch.iter().map(&f).fold(f64::NEG_INFINITY, f64::max);
    if runs_inline(rows.len().div_ceil(CHUNK)) {
        return rows
            .chunks(CHUNK)
            .map(chunk_max)
            .fold(f64::NEG_INFINITY, f64::max);
    }
    rows.par_chunks(CHUNK)
        .with_min_len(MIN_CHUNKS_PER_TASK)
        .map(chunk_max)
        .reduce(|| f64::NEG_INFINITY, f64::max)
}

/// `Σ_α f(α)` over the contacts as partial sums over fixed chunks of [`CHUNK`] contacts, added
/// in chunk order: the result does not depend on the thread count. `N` sums at once.
pub fn reduce_chunks<const N: usize>(
    rows: &[ContactRow],
    f: impl Fn(&ContactRow) -> [f64; N] + Sync,
) -> [f64; N] {
    let partial = |chunk: &[ContactRow]| {
        let mut s = [0.0; N];
        for c in chunk {
            let v = f(c);
            for k in 0..N {
                s[k] += v[k];
            }
        }
        s
    };
    let mut total = [0.0; N];
    if rows.len() <= CHUNK {
        total = partial(rows);
    } else if runs_inline(rows.len().div_ceil(CHUNK)) {
        for p in rows.chunks(CHUNK).map(partial) {
            for k in 0..N {
                total[k] += p[k];
            }
        }
    } else {
        let parts: Vec<[f64; N]> = rows
            .par_chunks(CHUNK)
            .with_min_len(MIN_CHUNKS_PER_TASK)
            .map(partial)
            .collect();
        for p in parts {
            for k in 0..N {
                total[k] += p[k];
            }
        }
    }
    total
}
