//! Standalone frictional-contact problems (fc-problem-v1).
//!
//! A 2D frictional-contact problem in local form, as in FCLIB and Siconos:
//!
//! ```text
//! find r, u:  u = W r + q,   r ∈ K_μ,   ū = u + μ|u_t| n ∈ K_μ*,   r · ū = 0   (per contact)
//! ```
//!
//! - [`problem`]: the data ([`FcProblem`]), W in [`block_csr`] storage;
//! - [`reader`]: fc-problem-v1 JSON (plain or gzip) with typed errors ([`FcError`]);
//! - [`measure`]: the error measure (Siconos' fc2d error);
//! - [`nsgs`]: nonlinear block Gauss–Seidel with the exact local solver of [`crate::local`];
//! - [`newton`]: a proximal semismooth Newton method for dense, hyperstatic problems;
//! - [`method`]: one entry point choosing between them (`nlgs`, `newton`, `lemke`, `auto`);
//! - [`auto`]: the `auto` composite (Gauss–Seidel, Newton, the exact finish) and its stages,
//!   shared with the engine's solver, which uses this layer (nothing here imports the engine);
//! - [`crate::assemble`]: the problem of an engine step, for the Newton solver and for files;
//! - [`ordering`]: contact orderings of the sweeps;
//! - [`crate::anderson`]: Anderson acceleration of the sweeps (shared with the engine);
//! - [`output`]: the solution file, written atomically.
//!
//! What `grainlaw solve-fc` does around them (read, solve, report, write) and the reference
//! benchmark table are the command line's (`grainlaw::fc_cmd`, `grainlaw::fc_bench`).
//!
//! ```no_run
//! use dem::fc::{read_problem, solve, FcOptions};
//! let p = read_problem("datasets/fc-problems/piles/pile_pert_1000.json.gz")?;
//! let s = solve(&p, &FcOptions { tolerance: 1e-6, ..FcOptions::default() })?;
//! assert!(s.converged && s.error <= 1e-6);
//! # Ok::<(), dem::fc::FcError>(())
//! ```
//!
//! # Speed
//!
//! Tolerance 1e-6 from `r = 0`, one core, the same session on a shared 2 vCPU Xeon
//! (`cargo bench --bench fc_table` in the root package; Siconos 4.4 fc2d NSGS, see `datasets/fc-problems/README.md`):
//!
//! | problem | contacts | Siconos its / s | dem::fc its / s | ratio |
//! |---|---|---|---|---|
//! | pile_pert_100 | 89 | 118 / 0.0022 | 35 / 0.0001 | ≈ 22× |
//! | pile_pert_1000 | 1020 | 862 / 0.202 | 93 / 0.0030 | ≈ 67× |
//! | granularflowonwall 2020 | 2020 | 1064 / 0.161 | 115 / 0.0049 | ≈ 33× |
//! | granularflowonwall 7002 | 7002 | 1461 / 1.44 | 316 / 0.090 | ≈ 16× |
//! | pile_pert_10000 | 9891 | 5926 / 14.7 | 247 / 0.092 | ≈ 160× |
//!
//! One plain sweep runs at 30–130 million contact updates per second (the row product and
//! `solve_local`; the branches of the local solve dominate where statuses are mixed).
//!
//! What reduced the iterations, measured on pile_pert_1000 / flow 2020 / flow 7002 (plain
//! Gauss–Seidel: 855 / 1074 / 1497 sweeps; the 9891-contact pile: 5881):
//! - Anderson mixing of the sweeps ([`Acceleration::Anderson`], memory 4): 93 / 115 / 316, and
//!   247 on the large pile. Memory 3–8 behaves alike; 10 stalls on the 7002 flow. Unguarded, it
//!   can stall for thousands of sweeps (random contact orders on the 7002 flow: up to 45 790);
//!   the stagnation safeguard bounds this (six random orders: 241–951 sweeps, plain
//!   Gauss–Seidel 1441–1481; on pile_pert_1000: 58–80 against 951–961).
//! - Over-relaxation alone: ω = 1.4 gives 368 / 489 / 673; ω ≥ 1.6 helps piles (1.8: 109) but
//!   stalls on the flows (no convergence in 10⁵ sweeps), also when applied to sticking contacts
//!   only; with Anderson, ω > 1 does not help. Kept as an option, default 1.
//! - Did not help: the contact order for the iteration count (natural, breadth-first from the
//!   loaded contacts, its reverse: within 5 %; breadth-first is kept because its memory locality
//!   makes sweeps faster, 32 vs 23 M updates/s on the 7002 flow), symmetric (forward–backward)
//!   sweeps (981 / 1505 / 2689, and they break Anderson), nonlinear conjugate gradient on the
//!   sweeps (Fletcher–Reeves with restarts: 524 / 296 / 993), Anderson every second sweep,
//!   projecting the mixed iterate on the cones, restarting Anderson on a non-decreasing step.
//! - Warm start ([`FcOptions::initial_guess`]) from a solution stops at once (0 sweeps).

pub mod auto;
pub mod block_csr;
pub mod error;
pub mod lemke;
pub mod measure;
pub mod method;
pub mod newton;
pub mod nsgs;
pub mod ordering;
pub mod output;
pub mod problem;
pub mod reader;

pub use block_csr::BlockCsr2;
pub use error::FcError;
pub use measure::fc_error;
pub use method::{solve_by, MethodReport, SolverMethod};
pub use newton::{NewtonParams, NewtonStats};
pub use nsgs::{solve, Acceleration, FcOptions, FcSolution};
pub use ordering::ContactOrdering;
pub use output::{write_problem, write_solution};
pub use problem::{FcProblem, LowRank, ProblemCone, LOW_RANK_EXPAND_MAX_CONTACTS};
pub use reader::read_problem;
