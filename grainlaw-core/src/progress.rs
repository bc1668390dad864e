//! Progress reporting: indicatif bars on a terminal for anything longer than a second, one
//! line per finished phase on stderr otherwise; nothing at all with `--quiet`.

use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How much to tell the user.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verbosity {
    /// Bars and phase lines.
    Normal,
    /// Nothing but errors and warnings.
    Quiet,
}

/// A progress bar for one phase, measured in steps (or any unit).
pub struct Phase {
    bar: ProgressBar,
    name: String,
    start: Instant,
    verbosity: Verbosity,
}

impl Phase {
    /// A phase of `len` units; the bar appears only on a terminal after a second.
    pub fn new(verbosity: Verbosity, name: &str, len: u64) -> Self {
        let bar = if verbosity == Verbosity::Quiet {
            ProgressBar::hidden()
        } else {
            let b = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
            b.set_style(
                ProgressStyle::with_template(
                    "{prefix:>12} [{bar:32}] {percent:>3}% {msg} ({elapsed}, eta {eta})",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            b.set_prefix(name.to_string());
            b.enable_steady_tick(Duration::from_millis(200));
            b
        };
        Self {
            bar,
            name: name.to_string(),
            start: Instant::now(),
            verbosity,
        }
    }

    /// Sets the position.
    pub fn set(&self, pos: u64) {
        self.bar.set_position(pos);
    }

    /// Sets the message shown after the bar.
    pub fn message(&self, msg: String) {
        self.bar.set_message(msg);
    }

    /// Ends the phase and prints one summary line (not with `--quiet`).
    pub fn finish(self, line: &str) {
        self.bar.finish_and_clear();
        if self.verbosity == Verbosity::Normal {
            eprintln!(
                "{:>12}: {line} ({:.1} s)",
                self.name,
                self.start.elapsed().as_secs_f64()
            );
        }
    }
}

/// Prints a warning line on stderr (always, even with `--quiet`: never silent).
pub fn warn(msg: &str) {
    eprintln!("warning: {msg}");
}

/// Prints a note on stderr (always, even with `--quiet`): a choice of the plan the run obeys
/// that changes what it delivers (a law left out).
pub fn note(msg: &str) {
    eprintln!("note: {msg}");
}

/// Prints an informational line on stderr unless quiet.
pub fn info(v: Verbosity, msg: &str) {
    if v == Verbosity::Normal {
        eprintln!("{msg}");
    }
}
