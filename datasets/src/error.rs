//! Typed errors of the scenario loader, the generators and the world builders.
//!
//! Every variant renders as one line that names the scenario key, file or line at fault.

use thiserror::Error;

/// What can go wrong while loading a scenario or building its world.
#[derive(Debug, Error)]
pub enum DatasetError {
    /// Neither a built-in scenario name nor a readable TOML file.
    #[error("unknown scenario `{name}` (built-ins: {known}; or give the path of a TOML file)")]
    UnknownScenario {
        /// What the user gave.
        name: String,
        /// Built-in names, comma separated.
        known: String,
    },
    /// The scenario file could not be read.
    #[error("{path}: cannot read: {reason}")]
    Io {
        /// File path.
        path: String,
        /// The operating system's message.
        reason: String,
    },
    /// The TOML text does not parse.
    #[error("{source_name}:{line}:{column}: invalid TOML: {message}")]
    Syntax {
        /// File path or `builtin:NAME`.
        source_name: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The parser's message (first line).
        message: String,
    },
    /// A `--set KEY=VALUE` argument is malformed.
    #[error("--set `{arg}`: {reason}")]
    BadOverride {
        /// The argument as given.
        arg: String,
        /// What is wrong.
        reason: String,
    },
    /// A key that the scenario does not have (in the file or in `--set`).
    #[error("{source_name}: unknown key `{key}` (known keys here: {known})")]
    UnknownKey {
        /// File path or `builtin:NAME`.
        source_name: String,
        /// Dotted key.
        key: String,
        /// Known keys at that level.
        known: String,
    },
    /// A key has a value of the wrong type, or is missing.
    #[error("{source_name}: key `{key}`: {reason}")]
    Type {
        /// File path or `builtin:NAME`.
        source_name: String,
        /// Dotted key.
        key: String,
        /// What is wrong.
        reason: String,
    },
    /// A value is out of its physical range (negative radius, NaN, slope ≥ 90°, ...).
    #[error("{}key `{key}`: {reason}", source_prefix(.source_name))]
    Invalid {
        /// File path or `builtin:NAME` followed by `: ` in the message; empty when the value was
        /// checked outside a loaded file (see [`DatasetError::in_source`]).
        source_name: String,
        /// Dotted key.
        key: String,
        /// What is wrong, with the value found.
        reason: String,
    },
    /// The generator could not place the grains (box too small, too many grains, ...).
    #[error("generator: {0}")]
    Generator(String),
    /// The engine refused the built world.
    #[error("world: {0}")]
    World(#[from] dem::DemError),
}

/// `"{source}: "`, or nothing for an empty source.
fn source_prefix(source: &str) -> String {
    if source.is_empty() {
        String::new()
    } else {
        format!("{source}: ")
    }
}

impl DatasetError {
    /// [`DatasetError::Invalid`] for `key` (no source yet; [`DatasetError::in_source`] adds it).
    pub fn invalid(key: impl Into<String>, reason: impl Into<String>) -> Self {
        DatasetError::Invalid {
            source_name: String::new(),
            key: key.into(),
            reason: reason.into(),
        }
    }

    /// Names `source` (file path or `builtin:NAME`) in an [`DatasetError::Invalid`] that does not
    /// name one yet; other errors are returned unchanged.
    pub fn in_source(self, source: &str) -> Self {
        match self {
            DatasetError::Invalid {
                source_name,
                key,
                reason,
            } if source_name.is_empty() => DatasetError::Invalid {
                source_name: source.to_string(),
                key,
                reason,
            },
            other => other,
        }
    }
}

/// Result with [`DatasetError`].
pub type Result<T> = std::result::Result<T, DatasetError>;

/// `v` as written in messages: plain decimal for 10⁻⁴ ≤ |v| < 10⁹ (and 0), else scientific
/// (`1e-300`, not three hundred zeros).
pub fn num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e9).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// `key` must be finite and > 0.
pub fn positive(key: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(DatasetError::invalid(
            key,
            format!("must be a finite number > 0, got {}", num(v)),
        ))
    }
}

/// `key` must be finite and ≥ 0.
pub fn non_negative(key: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(DatasetError::invalid(
            key,
            format!("must be a finite number ≥ 0, got {}", num(v)),
        ))
    }
}

/// `key` must be finite and in `[lo, hi]`.
pub fn in_range(key: &str, v: f64, lo: f64, hi: f64) -> Result<f64> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(v)
    } else {
        Err(DatasetError::invalid(
            key,
            format!("must lie in [{}, {}], got {}", num(lo), num(hi), num(v)),
        ))
    }
}

/// `key` (a count) must be ≥ `min`.
pub fn at_least(key: &str, v: usize, min: usize) -> Result<usize> {
    if v >= min {
        Ok(v)
    } else {
        Err(DatasetError::invalid(
            key,
            format!("must be ≥ {min}, got {v}"),
        ))
    }
}
