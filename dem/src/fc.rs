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
//! - [`ordering`]: contact orderings of the sweeps;
//! - [`anderson`]: Anderson acceleration of the sweeps;
//! - [`output`]: the solution file, written atomically;
//! - [`command`]: what `grainlaw solve-fc` does ([`solve_fc`]);
//! - [`bench`]: the reference benchmark ([`run_reference_benchmarks`]).

pub mod anderson;
pub mod bench;
pub mod block_csr;
pub mod command;
pub mod error;
pub mod measure;
pub mod nsgs;
pub mod ordering;
pub mod output;
pub mod problem;
pub mod reader;

pub use bench::{run_reference_benchmarks, BenchRow};
pub use block_csr::BlockCsr2;
pub use command::{solve_fc, solve_file, SolveReport};
pub use error::FcError;
pub use measure::fc_error;
pub use nsgs::{solve, Acceleration, FcOptions, FcSolution};
pub use ordering::ContactOrdering;
pub use output::write_solution;
pub use problem::FcProblem;
pub use reader::read_problem;
