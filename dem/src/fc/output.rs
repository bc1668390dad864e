//! Writing a solution as JSON, atomically.

use std::path::Path;

use serde::Serialize;

use super::error::FcError;
use super::nsgs::FcSolution;

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
