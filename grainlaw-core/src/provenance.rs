//! Provenance of the laws a scenario run writes (`janssen_law.json`, `mu_i_law.json`, …): the
//! scenario, every `--set` override as typed, the seed, the grainlaw version, the date the run
//! started and the SHA-256 (FIPS 180-4) of its input files.
//!
//! The date and the hashes are fixed when a run starts ([`RunOrigin::now`]) and kept in its
//! checkpoint, so that `grainlaw run --resume` writes the laws an uninterrupted run started at
//! the same time would have written. The date is the current UTC time, or the time given by the
//! environment variable `SOURCE_DATE_EPOCH` (seconds since 1970-01-01T00:00:00Z, the
//! reproducible-builds convention) when it is set, for outputs that must not depend on when they
//! were made. The provenance of a law is made from it by
//! [`RunControl::law_provenance`](crate::scenarios::RunControl::law_provenance).

use identify::law::{epoch_seconds, sha256_hex, utc_date, InputFile};
use serde::{Deserialize, Serialize};

use crate::scenarios::loader::LoadedScenario;

/// What a run records about its start: the date and the input files with their SHA-256.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct RunOrigin {
    /// UTC date and time the run started, `YYYY-MM-DDTHH:MM:SSZ`.
    pub date: Option<String>,
    /// Input files: `scenario.toml` (the scenario as run, the file written in the output
    /// directory) and, for a scenario given as a file, that file as read when the run started.
    pub inputs: Vec<InputFile>,
}

impl RunOrigin {
    /// The origin of a run of `loaded` starting now.
    pub fn now(loaded: &LoadedScenario) -> Self {
        let mut inputs = vec![InputFile {
            path: "scenario.toml".into(),
            sha256: sha256_hex(loaded.effective_toml.as_bytes()),
        }];
        if !loaded.source.starts_with("builtin:") {
            if let Ok(bytes) = std::fs::read(&loaded.source) {
                inputs.push(InputFile {
                    path: loaded.source.clone(),
                    sha256: sha256_hex(&bytes),
                });
            }
        }
        RunOrigin {
            date: Some(utc_date(epoch_seconds())),
            inputs,
        }
    }
}
