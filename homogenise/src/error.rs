//! Typed errors of the homogenisation stage.

use std::path::PathBuf;

use thiserror::Error;

/// Everything that can go wrong while homogenising snapshots or writing histories.
#[derive(Debug, Error)]
pub enum HomogeniseError {
    /// A parameter given by the caller is out of its domain (negative width, zero bins, NaN, ...).
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter {
        /// Name of the parameter.
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// A body of the snapshot is unusable (non-finite state, non-positive radius or mass, ...).
    #[error("body {index}: {reason}")]
    InvalidBody {
        /// Index in `Snapshot::bodies`.
        index: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// A contact of the snapshot is unusable (body index out of range, non-finite force, ...).
    #[error("contact {index}: {reason}")]
    InvalidContact {
        /// Index in `Snapshot::contacts`.
        index: usize,
        /// What is wrong with it.
        reason: String,
    },
    /// The region has zero area or contains no grain where grains are needed.
    #[error("region {0}")]
    EmptyRegion(String),
    /// No wall of that name in the snapshot.
    #[error("no wall named `{0}` in the snapshot")]
    UnknownWall(String),
    /// Not enough data for the requested estimate (too few grains, samples, blocks, ...).
    #[error("not enough data: {0}")]
    NotEnoughData(String),
    /// A table operation failed (row of the wrong length, unknown column, ...).
    #[error("table: {0}")]
    Table(String),
    /// An input/output error on a file.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A CSV error on a file.
    #[error("{path}: {source}")]
    Csv {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: csv::Error,
    },
}

/// Result type of this crate.
pub type Result<T> = std::result::Result<T, HomogeniseError>;

/// Checks that a parameter is finite and strictly positive.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(HomogeniseError::InvalidParameter {
            name,
            reason: format!("must be finite and > 0, got {value}"),
        })
    }
}

/// Checks that a parameter is finite.
pub(crate) fn finite(name: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(HomogeniseError::InvalidParameter {
            name,
            reason: format!("must be finite, got {value}"),
        })
    }
}
