//! A small library API for embedding `grainlaw run` (the Python package `grainlaw`, built from
//! `python/`): the same run as the command line, without its signal handler and with the
//! output directory and the stop flag chosen by the caller.
//!
//! [`run_scenario`] loads a built-in scenario or a TOML file with `--set`-style overrides, runs
//! it end to end into `out` (CSV, figures, VTK, laws, `summary.json` written last, atomically)
//! and returns the summary as a value. [`read_csv_table`] reads one of the CSV tables a run
//! writes (`# text` comments, `# key = value` constants, a header with the unit in each name)
//! back into columns.

use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use crate::error::{CliError, Result};
use crate::output::OutputDir;
use crate::progress::Verbosity;
use crate::scenarios::{self, CheckpointPolicy, RunContext, RunControl, RunOutcome};

/// Runs `spec` (a built-in name or a TOML path) with the overrides `sets` (`KEY=VALUE`, dotted
/// keys for tables) into the directory `out`, exactly as `grainlaw run SPEC --out OUT --set …`
/// does (same seed, same files, same `summary.json` but its `wall_seconds`), with periodic
/// checkpoints every [`crate::scenarios::phased::DEFAULT_CHECKPOINT_SECONDS`]. Setting
/// `interrupted` stops the run after the current step with a checkpoint in `out` and
/// [`CliError::Interrupted`]; no signal handler is installed (the embedding program owns its
/// signals). `quiet` turns off the progress lines on stderr (warnings are still printed).
/// `allow_suspect` is `--allow-suspect`: suspect laws are exported as `NAME_law.json` (marked
/// suspect) instead of `NAME_law.rejected.json`. The run's verdict is in the outcome
/// ([`RunOutcome::verdict`]), not an error: the caller decides how loud it is (the command line
/// exits 3, Python raises).
///
/// Errors: a bad scenario or override ([`CliError::Dataset`]), an `out` that is a file or holds
/// another scenario's outputs ([`CliError::Usage`]), a failed step ([`CliError::Dem`]), a file
/// that cannot be written ([`CliError::Io`]).
pub fn run_scenario(
    spec: &str,
    sets: &[String],
    out: &Path,
    quiet: bool,
    allow_suspect: bool,
    interrupted: Arc<AtomicBool>,
) -> Result<RunOutcome> {
    let loaded = scenarios::registry::load(spec, sets)?;
    crate::output::dir::check_out_dir(out, loaded.config.kind())?;
    let mut ctx = RunContext {
        out: OutputDir::create(out)?,
        verbosity: if quiet {
            Verbosity::Quiet
        } else {
            Verbosity::Normal
        },
        loaded,
        interrupted,
        dump: None,
    };
    let mut ctl = RunControl::new(sets.to_vec(), CheckpointPolicy::default());
    ctl.allow_suspect = allow_suspect;
    scenarios::run_controlled(&mut ctx, &mut ctl)
}

/// A CSV table as a run writes it ([`crate::output::csv_table`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CsvColumns {
    /// `# key = value` lines whose value is a number.
    pub constants: Vec<(String, f64)>,
    /// Headers, in file order (the unit is part of the name: `depth_m`, `sigma_v_Pa`).
    pub headers: Vec<String>,
    /// `columns[j]` holds the column `headers[j]`; an empty or non-numeric cell is NaN.
    pub columns: Vec<Vec<f64>>,
}

/// Reads a CSV table written by a run: lines starting with `#` are comments, those of the form
/// `# key = number` are kept as constants; the first other line is the header. Errors:
/// [`CliError::Io`] naming the file (unreadable, or a row whose field count differs from the
/// header's, with its line).
pub fn read_csv_table(path: &Path) -> Result<CsvColumns> {
    let text = std::fs::read_to_string(path).map_err(|e| CliError::io(path, e))?;
    let mut table = CsvColumns::default();
    let mut body = String::new();
    for line in text.lines() {
        match line.trim_start().strip_prefix('#') {
            Some(comment) => {
                if let Some((k, v)) = comment.split_once('=') {
                    if let Ok(x) = v.trim().parse::<f64>() {
                        table.constants.push((k.trim().to_string(), x));
                    }
                }
            }
            None => {
                body.push_str(line);
                body.push('\n');
            }
        }
    }
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .from_reader(body.as_bytes());
    table.headers = reader
        .headers()
        .map_err(|e| CliError::io(path, e))?
        .iter()
        .map(String::from)
        .collect();
    table.columns = vec![Vec::new(); table.headers.len()];
    for record in reader.records() {
        let record = record.map_err(|e| CliError::io(path, e))?;
        for (col, cell) in table.columns.iter_mut().zip(record.iter()) {
            col.push(cell.parse::<f64>().unwrap_or(f64::NAN));
        }
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_table_round_trips_constants_headers_and_numbers() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        std::fs::write(
            &path,
            "# a comment\n# width_m = 0.0125\ndepth_m,sigma_v_Pa\n0.1,1e3\n0.2,\n",
        )
        .unwrap();
        let t = read_csv_table(&path).unwrap();
        assert_eq!(t.constants, vec![("width_m".to_string(), 0.0125)]);
        assert_eq!(t.headers, vec!["depth_m", "sigma_v_Pa"]);
        assert_eq!(t.columns[0], vec![0.1, 0.2]);
        assert_eq!(t.columns[1][0], 1e3);
        assert!(t.columns[1][1].is_nan());
    }
}
