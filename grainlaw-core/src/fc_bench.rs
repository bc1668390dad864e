//! Reference benchmark of `grainlaw bench` (and `cargo bench --bench fc_table`): solve every
//! problem of a folder (`datasets/fc-problems/`) with [`dem::fc`] at tolerance 1e-6 from `r = 0`
//! and report iterations, error, seconds and the raw sweep throughput, beside Siconos 4.4 fc2d
//! NSGS on the same problems.

use std::path::{Path, PathBuf};

use dem::fc::nsgs::sweep_rate;
use dem::fc::{read_problem, solve, FcError, FcOptions};

/// One line of the benchmark table.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchRow {
    /// Problem path relative to the benchmark folder, without `.json` / `.json.gz`.
    pub problem: String,
    /// Number of contacts.
    pub contacts: usize,
    /// Gauss–Seidel sweeps to reach the tolerance.
    pub iterations: usize,
    /// Error measure at the returned impulses.
    pub error: f64,
    /// Whether the tolerance was reached.
    pub converged: bool,
    /// Solve wall-clock seconds (best of a few runs).
    pub seconds: f64,
    /// Contact updates per second of plain Gauss–Seidel sweeps on one core (updates / s).
    pub updates_per_second: f64,
    /// Siconos 4.4 fc2d NSGS seconds on the same problem (tolerance 1e-6, `r = 0`, one core),
    /// measured with Siconos 4.4 (see `datasets/fc-problems/README.md`) on the development machine; `None` if not measured.
    pub siconos_seconds: Option<f64>,
    /// Siconos NSGS iterations on the same problem.
    pub siconos_iterations: Option<usize>,
}

impl BenchRow {
    /// `siconos_seconds / seconds` (how many times faster than Siconos), when Siconos' time
    /// is known and resolved (≥ 10⁻⁴ s).
    pub fn speedup(&self) -> Option<f64> {
        self.siconos_seconds
            .filter(|&s| s >= 1e-4)
            .map(|s| s / self.seconds.max(1e-9))
    }
}

/// Siconos 4.4 fc2d NSGS (sparse block storage) at tolerance 1e-6 from `r = 0`, one core,
/// best of three repeats (one for the large pile) on the development machine (2 vCPU Xeon, shared), fastest of two rounds
/// in the same session as the `dem::fc` figures of `datasets/fc-problems/README.md`:
/// (problem, iterations, seconds). Times below 10⁻⁴ s were not resolved (stored as 0).
/// These are *quoted* figures: `grainlaw bench` prints them, labelled as quoted, only when
/// Siconos is not installed; otherwise it measures Siconos in the same run
/// ([`crate::siconos_peer`]).
pub const SICONOS_REFERENCE: &[(&str, usize, f64)] = &[
    ("large/pile_pert_10000", 5926, 14.67),
    ("piles/pile_pert_100", 118, 0.0022),
    ("piles/pile_pert_1000", 862, 0.2021),
    ("siconos-2d/FC2D_SliderCrankLagrangian00000", 266, 0.0),
    ("siconos-2d/FC2D_SliderCrankLagrangian00001", 272, 0.0),
    ("siconos-2d/fc2d_granularflowonwall_00667_00000", 1, 0.0001),
    (
        "siconos-2d/fc2d_granularflowonwall_02020_00213",
        1064,
        0.1612,
    ),
    (
        "siconos-2d/fc2d_granularflowonwall_07002_00801",
        1461,
        1.4445,
    ),
];

/// The `.json` and `.json.gz` files under `dir` (recursively), sorted.
pub fn problem_files(dir: &Path) -> Result<Vec<PathBuf>, FcError> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let io = |source| FcError::Io {
            path: d.display().to_string(),
            source,
        };
        for entry in std::fs::read_dir(&d).map_err(io)? {
            let path = entry.map_err(io)?.path();
            if path.is_dir() {
                stack.push(path);
            } else if is_problem_file(&path) {
                out.push(path);
            }
        }
    }
    out.sort();
    Ok(out)
}

fn is_problem_file(p: &Path) -> bool {
    let name = p
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    name.ends_with(".json") || name.ends_with(".json.gz")
}

/// Name of a problem file relative to `dir`, without `.json` / `.json.gz`, `/`-separated.
pub fn problem_name(dir: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(dir).unwrap_or(file);
    let s = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/");
    s.trim_end_matches(".gz")
        .trim_end_matches(".json")
        .to_string()
}

/// Solves every problem under `dir` with the default options (tolerance 1e-6, from `r = 0`),
/// keeping the best wall-clock time of up to 5 runs (fewer for slow problems), and measures the
/// plain sweep throughput (best of 5 short runs). Rows are sorted by problem name.
pub fn run_reference_benchmarks(dir: impl AsRef<Path>) -> Result<Vec<BenchRow>, FcError> {
    let dir = dir.as_ref();
    let options = FcOptions::default();
    let mut rows = Vec::new();
    for file in problem_files(dir)? {
        let problem = read_problem(&file)?;
        let name = problem_name(dir, &file);
        let first = solve(&problem, &options)?;
        let mut seconds = first.seconds;
        let runs = if seconds < 0.05 {
            5
        } else if seconds < 1.0 {
            3
        } else {
            1
        };
        for _ in 1..runs {
            seconds = seconds.min(solve(&problem, &options)?.seconds);
        }
        // Plain sweeps, about 2·10⁶ block products per run (a few ms), best of 5 runs.
        let sweeps = (2_000_000 / problem.w().nnz_blocks().max(1)).clamp(5, 2000);
        let rate = (0..5)
            .map(|_| sweep_rate(&problem, sweeps))
            .fold(0.0, f64::max);
        let siconos = SICONOS_REFERENCE.iter().find(|(n, _, _)| *n == name);
        rows.push(BenchRow {
            problem: name,
            contacts: problem.contacts(),
            iterations: first.iterations,
            error: first.error,
            converged: first.converged,
            seconds,
            updates_per_second: rate,
            siconos_seconds: siconos.map(|s| s.2),
            siconos_iterations: siconos.map(|s| s.1),
        });
    }
    Ok(rows)
}

/// The rows as a plain-text table (one header line, one line per problem).
pub fn format_table(rows: &[BenchRow]) -> String {
    let mut s = format!(
        "{:<48} {:>8} {:>6} {:>10} {:>10} {:>12} {:>10} {:>8} {:>8}\n",
        "problem",
        "contacts",
        "iters",
        "error",
        "seconds",
        "Mupdates/s",
        "siconos_s",
        "sic_its",
        "speedup"
    );
    for r in rows {
        s.push_str(&format!(
            "{:<48} {:>8} {:>6} {:>10.3e} {:>10.5} {:>12.1} {:>10} {:>8} {:>8}{}\n",
            r.problem,
            r.contacts,
            r.iterations,
            r.error,
            r.seconds,
            r.updates_per_second / 1e6,
            r.siconos_seconds
                .map(|v| format!("{v:.4}"))
                .unwrap_or_else(|| "-".into()),
            r.siconos_iterations
                .map(|v| v.to_string())
                .unwrap_or_else(|| "-".into()),
            r.speedup()
                .filter(|v| v.is_finite())
                .map(|v| format!("{v:.1}x"))
                .unwrap_or_else(|| "-".into()),
            if r.converged { "" } else { "  NOT CONVERGED" }
        ));
    }
    s
}
