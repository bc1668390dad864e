//! The command line's error: every failure of the stages, rendered as one line.

use thiserror::Error;

/// Everything `grainlaw` can fail with. [`CliError::one_line`] is what is printed; the exit code
/// ([`CliError::exit_code`]) is 2 for all of them (bad input, unreadable file, failed run),
/// after no partial output that looks complete, except 130 for [`CliError::Interrupted`] and 3
/// for a refused result ([`CliError::FitRefused`], [`CliError::Verdict`], ...) or an external
/// solver that is missing or failed ([`CliError::ExternalSolver`]).
#[derive(Debug, Error)]
pub enum CliError {
    /// Scenario loading, validation, generation.
    #[error("{0}")]
    Dataset(#[from] datasets::DatasetError),
    /// The engine (non-finite state, bad world).
    #[error("engine: {0}")]
    Dem(#[from] dem::DemError),
    /// Homogenisation.
    #[error("homogenise: {0}")]
    Homogenise(#[from] homogenise::HomogeniseError),
    /// Identification (fits, CSV tables, law JSON).
    #[error("{0}")]
    Identify(#[from] identify::IdentifyError),
    /// Frictional-contact problems.
    #[error("{0}")]
    Fc(#[from] dem::fc::FcError),
    /// A data file the command read is wrong (a fit that cannot be done on its content, a value
    /// out of its domain, too few rows, ...): the message names the file first.
    #[error("{path}: {reason}")]
    Input {
        /// The data file.
        path: String,
        /// What is wrong with it (one line).
        reason: String,
    },
    /// `grainlaw fit` read the data but refused the fit (not identifiable, an interval crossing a
    /// physical bound, R² too low, ...): exit code 3. The message names the file first.
    #[error("{path}: {reason}")]
    FitRefused {
        /// The data file.
        path: String,
        /// Why the fit was refused (one line), with the simpler form when there is one.
        reason: String,
    },
    /// A solve ran to its end without reaching its tolerance (`grainlaw solve-fc`): its result
    /// was written, marked `converged: false`, and the exit code is 3.
    #[error("{path}: {reason}")]
    NotConverged {
        /// The problem file.
        path: String,
        /// What was reached (one line).
        reason: String,
    },
    /// A scenario run finished but a result is refused or suspect ([`crate::verdict`]; suspect
    /// passes with `--allow-suspect`): every file is written, refused laws as
    /// `NAME_law.rejected.json`, and the exit code is 3.
    #[error("{dir}: {reason}")]
    Verdict {
        /// The output directory.
        dir: String,
        /// The verdict and the checks that failed (one line).
        reason: String,
    },
    /// Reading or writing a file.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: String,
        /// What went wrong.
        reason: String,
    },
    /// Drawing a figure.
    #[error("figure {file}: {reason}")]
    Plot {
        /// The figure's file.
        file: String,
        /// What went wrong.
        reason: String,
    },
    /// The user stopped the run (Ctrl-C): a checkpoint was written, the run can be resumed.
    #[error(
        "interrupted at step {step} of phase `{phase}`: checkpoint written to {dir}/checkpoint, no summary.json; continue with: grainlaw run --resume {dir}"
    )]
    Interrupted {
        /// The phase stopped.
        phase: String,
        /// Steps the phase had done.
        step: u64,
        /// The output directory (as to type it).
        dir: String,
    },
    /// A run checkpoint cannot be written, read, or used for this resume.
    #[error("{path}: {reason}")]
    Checkpoint {
        /// The checkpoint file (or output directory).
        path: String,
        /// What is wrong.
        reason: String,
    },
    /// A command-line argument is wrong.
    #[error("{0}")]
    Usage(String),
    /// An external solver (Gerris) is missing or failed: its case directory is left in place
    /// to be rerun by hand, and the exit code is 3 (`grainlaw continuum`, `docs/continuum.md`).
    #[error("{solver}: {reason}; the case is left in {dir}: rerun it there with `{rerun}`")]
    ExternalSolver {
        /// The solver's command (`gerris2D`).
        solver: String,
        /// What happened, with the last lines of its stderr (folded onto one line).
        reason: String,
        /// The case directory.
        dir: String,
        /// The command that reruns the case in `dir`.
        rerun: String,
    },
    /// A campaign was stopped (Ctrl-C, SIGTERM): its running runs wrote their checkpoints.
    #[error(
        "campaign stopped: the running runs wrote their checkpoints; continue with the same command (finished runs are not redone), in {dir}"
    )]
    CampaignStopped {
        /// The campaign directory.
        dir: String,
    },
}

impl CliError {
    /// An I/O error on `path`.
    pub fn io(path: impl AsRef<std::path::Path>, e: impl std::fmt::Display) -> Self {
        CliError::Io {
            path: path.as_ref().display().to_string(),
            reason: e.to_string(),
        }
    }

    /// The process exit code: 130 (128 + SIGINT, the shells' convention) for a run stopped by
    /// the user, which can be resumed; 3 for a fit refused on valid data or a run whose verdict
    /// fails; 2 for every other
    /// error.
    pub fn exit_code(&self) -> i32 {
        match self {
            CliError::Interrupted { .. } | CliError::CampaignStopped { .. } => 130,
            CliError::FitRefused { .. }
            | CliError::NotConverged { .. }
            | CliError::Verdict { .. }
            | CliError::ExternalSolver { .. }
            | CliError::Dem(
                dem::DemError::NonFinite { .. } | dem::DemError::NonFiniteCell { .. },
            ) => 3,
            _ => 2,
        }
    }

    /// The message on one line (newlines and runs of spaces folded).
    pub fn one_line(&self) -> String {
        let s = self.to_string();
        s.split_whitespace().collect::<Vec<_>>().join(" ")
    }
}

/// Result with [`CliError`].
pub type Result<T> = std::result::Result<T, CliError>;
