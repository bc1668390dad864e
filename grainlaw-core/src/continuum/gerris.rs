//! Running Gerris on a case directory.
//!
//! The case's `.gfs` is run in its directory with stdout and stderr captured to `gerris.log`
//! (stderr) and `gerris.out` (stdout). A solver that cannot be started (not installed) or that
//! exits with a failure is [`CliError::ExternalSolver`] (exit code 3), quoting the last lines of
//! its stderr; the case directory stays in place to be rerun by hand.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

use crate::error::{CliError, Result};
use crate::output::Summary;

/// The Gerris 2D solver's command when none is given.
pub const DEFAULT_GERRIS: &str = "gerris2D";

/// Lines of stderr quoted when Gerris fails.
pub const QUOTED_LINES: usize = 3;

/// A finished Gerris run.
#[derive(Debug, Clone, PartialEq)]
pub struct GerrisRun {
    /// Wall-clock time of the run (s).
    pub wall_seconds: f64,
    /// The solver's version line (`gerris2D -V`), when it gives one.
    pub version: Option<String>,
}

/// The first line of `gerris -V` (it prints its version on stderr), or `None` when the command
/// cannot be run.
pub fn version(gerris: &Path) -> Option<String> {
    let out = Command::new(gerris)
        .arg("-V")
        .stdin(Stdio::null())
        .output()
        .ok()?;
    let text =
        String::from_utf8_lossy(&out.stderr).to_string() + &String::from_utf8_lossy(&out.stdout);
    text.lines()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .map(String::from)
}

/// Runs `gerris file` in `dir` (stdout to `gerris.out`, stderr to `gerris.log`). Errors:
/// [`CliError::ExternalSolver`] when it cannot be started or exits with a failure (the last
/// [`QUOTED_LINES`] non-empty lines of its stderr quoted), [`CliError::Io`] when the log files
/// cannot be created.
pub fn run(gerris: &Path, dir: &Path, file: &str) -> Result<GerrisRun> {
    let log = dir.join("gerris.log");
    let out = dir.join("gerris.out");
    let stderr = std::fs::File::create(&log).map_err(|e| CliError::io(&log, e))?;
    let stdout = std::fs::File::create(&out).map_err(|e| CliError::io(&out, e))?;
    let shown = gerris.display().to_string();
    let failure = |reason: String| CliError::ExternalSolver {
        solver: shown.clone(),
        reason,
        dir: dir.display().to_string(),
        rerun: format!("{shown} {file}"),
    };
    let start = Instant::now();
    let status = Command::new(gerris)
        .arg(file)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(stderr)
        .status()
        .map_err(|e| {
            failure(if e.kind() == std::io::ErrorKind::NotFound {
                format!(
                    "not found ({e}): install Gerris (Debian/Ubuntu: apt-get install gerris) or give its path with --gerris"
                )
            } else {
                format!("cannot be started: {e}")
            })
        })?;
    let wall_seconds = start.elapsed().as_secs_f64();
    if !status.success() {
        let text = std::fs::read_to_string(&log).unwrap_or_default();
        let last = last_lines(&text, QUOTED_LINES);
        return Err(failure(format!(
            "failed ({status}){}",
            if last.is_empty() {
                ", nothing on stderr".to_string()
            } else {
                format!(", its stderr ends: {}", last.join(" | "))
            }
        )));
    }
    Ok(GerrisRun {
        wall_seconds,
        version: version(gerris),
    })
}

/// The last `n` non-empty lines of `text`, trimmed, oldest first.
pub fn last_lines(text: &str, n: usize) -> Vec<String> {
    let mut v: Vec<String> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .rev()
        .take(n)
        .map(String::from)
        .collect();
    v.reverse();
    v
}

/// The command to run: `given`, else [`DEFAULT_GERRIS`].
pub fn command(given: Option<&Path>) -> PathBuf {
    given
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from(DEFAULT_GERRIS))
}

/// Whether `gerris` can be started (for tests that need it).
pub fn available(gerris: &Path) -> bool {
    version(gerris).is_some()
}

/// The first keys of the summary of a continuum case run by Gerris: `scenario`, `solver`,
/// `solver_version`, `solver_wall_seconds`, `law_file` and `law` (the law's name).
pub fn summary_head(scenario: &str, run: &GerrisRun, law_file: &str, law: &str) -> Summary {
    let mut s = Summary::new();
    s.text("scenario", scenario)
        .text("solver", "gerris")
        .text("solver_version", run.version.as_deref().unwrap_or(""))
        .num("solver_wall_seconds", run.wall_seconds)
        .text("law_file", law_file)
        .text("law", law);
    s
}
