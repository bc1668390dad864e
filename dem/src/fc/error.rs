//! Typed errors of the frictional-contact module: reading, validating and writing problems.

use thiserror::Error;

/// What can go wrong when reading, building or writing a frictional-contact problem.
///
/// Every variant that comes from the file names the JSON key it is about (`q`, `W.row`, ...);
/// [`crate::fc::read_problem`] wraps them in [`FcError::InFile`] so that the message also names
/// the file (`path: key mu[1]: …`).
#[derive(Debug, Error)]
pub enum FcError {
    /// A global method (Newton, the active-set finish, Lemke) was asked to solve a problem with
    /// a low-rank term ([`super::LowRank`], a biperiodic cell's stress-controlled components)
    /// on more contacts than they take ([`super::FcProblem::check_global`]).
    #[error("{contacts} contacts with a cell's low-rank term: more than the {limit} a global method takes")]
    LowRankTooLarge {
        /// Contacts of the problem.
        contacts: usize,
        /// [`super::LOW_RANK_EXPAND_MAX_CONTACTS`].
        limit: usize,
    },
    /// An error in the content of a problem file, with the file's path in front.
    #[error("{path}: {source}")]
    InFile {
        /// File path.
        path: String,
        /// What is wrong in it (a variant naming the key, or a JSON syntax error).
        #[source]
        source: Box<FcError>,
    },
    /// The file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// File path.
        path: String,
        /// Underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The text is not valid JSON (truncated file, stray token, `NaN` literal, ...).
    #[error("invalid JSON at line {line}, column {column}{near}: {message}")]
    Json {
        /// 1-based line of the error.
        line: usize,
        /// 1-based column of the error.
        column: usize,
        /// ` (in key "…")` when the enclosing key could be found, else empty.
        near: String,
        /// serde_json's message.
        message: String,
    },
    /// A required key is absent.
    #[error("missing key `{key}`")]
    MissingKey {
        /// Key path, e.g. `W.val`.
        key: String,
    },
    /// A key holds a value of the wrong type or an invalid value.
    #[error("key `{key}`: {reason}")]
    InvalidValue {
        /// Key path, e.g. `mu[3]`.
        key: String,
        /// What is wrong.
        reason: String,
    },
    /// A number is NaN or infinite.
    #[error("key `{key}`: non-finite value")]
    NonFinite {
        /// Key path with index, e.g. `q[12]`.
        key: String,
    },
    /// The solve overflowed: some `W r + q` or `r` is not finite (entries of `W` or `q` too
    /// large for double precision).
    #[error("the solve overflowed: W r + q is not finite (entries of W or q too large for double precision)")]
    Overflow,
    /// A friction coefficient is negative.
    #[error("key `mu[{contact}]`: friction coefficient {value} < 0")]
    NegativeFriction {
        /// Contact index.
        contact: usize,
        /// The value read.
        value: f64,
    },
    /// An array does not have the length the problem size requires.
    #[error("key `{key}`: length {found}, expected {expected}")]
    SizeMismatch {
        /// Key path.
        key: String,
        /// Expected length.
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// The Delassus matrix is not square.
    #[error("key `{key}`: W is {rows}×{cols}, not square")]
    NotSquare {
        /// Key path (`W.shape` or `W.data`).
        key: String,
        /// Number of rows.
        rows: usize,
        /// Number of columns.
        cols: usize,
    },
    /// A sparse index points outside the matrix.
    #[error("key `{key}[{entry}]`: index {index} out of range 0..{size}")]
    IndexOutOfRange {
        /// Key path (`W.row` or `W.col`).
        key: String,
        /// Position in the triplet arrays.
        entry: usize,
        /// The index read.
        index: usize,
        /// Matrix size.
        size: usize,
    },
    /// Only 2D problems are solved.
    #[error("key `dimension`: 3D problems are not supported yet (dimension = {dimension})")]
    Unsupported3D {
        /// The dimension read (3).
        dimension: usize,
    },
    /// A diagonal block of W (symmetric part) is not positive definite: the one-contact problem
    /// has no unique solution.
    #[error(
        "key `W`: diagonal block of contact {contact} is not positive definite \
         (W_nn = {nn:e}, W_nt = {nt:e}, W_tt = {tt:e})"
    )]
    NotPositiveDefinite {
        /// Contact index.
        contact: usize,
        /// `W_nn`.
        nn: f64,
        /// Symmetric part of `W_nt`.
        nt: f64,
        /// `W_tt`.
        tt: f64,
    },
    /// An initial guess or option has the wrong size or value.
    #[error("solver option `{name}`: {reason}")]
    Option {
        /// Option name.
        name: String,
        /// What is wrong.
        reason: String,
    },
}

impl FcError {
    /// The error without its file context: the inner error of [`FcError::InFile`] (recursively),
    /// `self` otherwise. Lets callers match on the kind of error whatever the source.
    pub fn kind(&self) -> &FcError {
        match self {
            FcError::InFile { source, .. } => source.kind(),
            other => other,
        }
    }
}
