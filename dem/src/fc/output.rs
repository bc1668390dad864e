//! Writing a solution as JSON, atomically.

use std::path::Path;

use serde::Serialize;

use super::error::FcError;
use super::nsgs::FcSolution;
use super::problem::FcProblem;

/// The solution file `{"r": [...], "u": [...], "iterations": n, "error": e, "seconds": s,
/// "converged": b}` (impulses in N·s, velocities in m/s, interleaved `(n, t)` per contact).
#[derive(Debug, Serialize)]
struct SolutionFile<'a> {
    r: &'a [f64],
    u: &'a [f64],
    iterations: usize,
    error: f64,
    seconds: f64,
    converged: bool,
}

/// Writes `solution` to `path` as JSON, atomically: the text goes to a temporary file in the same
/// directory, which is flushed to disk and then renamed over `path`, so a reader never sees a
/// partial file (and an interrupted write leaves no file looking complete).
pub fn write_solution(path: impl AsRef<Path>, solution: &FcSolution) -> Result<(), FcError> {
    let file = SolutionFile {
        r: &solution.r,
        u: &solution.u,
        iterations: solution.iterations,
        error: solution.error,
        seconds: solution.seconds,
        converged: solution.converged,
    };
    let text = serde_json::to_vec(&file).map_err(|e| FcError::InvalidValue {
        key: "solution".into(),
        reason: e.to_string(),
    })?;
    write_atomically(path.as_ref(), &text)
}

/// Writes `bytes` to `path` through a temporary sibling file and a rename
/// ([`crate::atomic`]).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), FcError> {
    crate::atomic::write_bytes_atomic(path, bytes).map_err(|source| FcError::Io {
        path: path.display().to_string(),
        source,
    })
}

/// Writes `problem` as fc-problem-v1 JSON (`W` in COO triplets, block by block), gzip-compressed
/// when `path` ends in `.gz`, atomically; `meta` is stored under `"meta"` as given. What
/// [`super::read_problem`] reads back bit for bit (floats are written in shortest round-trip
/// form).
pub fn write_problem(
    path: impl AsRef<Path>,
    problem: &FcProblem,
    meta: serde_json::Value,
) -> Result<(), FcError> {
    let path = path.as_ref();
    // A cell's low-rank term is written folded into W (fc-problem-v1 has one W).
    let expanded;
    let problem = if problem.low_rank().is_some() {
        expanded = problem.expanded()?;
        &expanded
    } else {
        problem
    };
    let w = problem.w();
    let nnz = 4 * w.nnz_blocks();
    let (mut row, mut col, mut val) = (
        Vec::with_capacity(nnz),
        Vec::with_capacity(nnz),
        Vec::with_capacity(nnz),
    );
    for i in 0..w.n() {
        for (j, b) in w.row(i) {
            for (k, &x) in b.iter().enumerate() {
                row.push(2 * i + k / 2);
                col.push(2 * j + k % 2);
                val.push(x);
            }
        }
    }
    let n = 2 * problem.contacts();
    let doc = serde_json::json!({
        "format": "fc-problem-v1",
        "dimension": 2,
        "nc": problem.contacts(),
        "mu": problem.mu(),
        "q": problem.q(),
        "W": {"storage": "coo", "shape": [n, n], "row": row, "col": col, "val": val},
        "meta": meta,
    });
    let text = serde_json::to_vec(&doc).map_err(|e| FcError::InvalidValue {
        key: "problem".into(),
        reason: e.to_string(),
    })?;
    let bytes = if path.extension().is_some_and(|e| e == "gz") {
        use std::io::Write;
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        enc.write_all(&text)
            .and_then(|_| enc.finish())
            .map_err(|source| FcError::Io {
                path: path.display().to_string(),
                source,
            })?
    } else {
        text
    };
    write_atomically(path, &bytes)
}
