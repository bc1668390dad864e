//! Run checkpoints: everything `grainlaw run --resume DIR` needs to finish an interrupted run
//! with the same output files, byte for byte, as a run never interrupted (`wall_seconds`
//! aside).
//!
//! One file, `DIR/checkpoint/run.json.gz` (gzip JSON, floats as their shortest round-trip
//! decimal, non-finite ones as strings), written atomically (temporary file, then rename): an
//! interruption while it is written leaves the previous checkpoint whole, so only the last one
//! is kept. It holds
//! - the scenario as run: name, source, effective TOML (overrides applied) and the `--set`
//!   overrides, so that a resume cannot mix two scenarios;
//! - the cursor: which phase (index and plan: name, stop rule) and where in it
//!   ([`PhaseProgress`]: the phase's statistics and loop counters);
//! - the world ([`dem::checkpoint::WorldState`]: bodies, contacts with their impulses, time);
//! - the scenario's own state, collected step by step (histories, VTK frame lists, earlier
//!   phases' statistics...), whatever its runner declares (`PhasedRun::State`);
//! - the steps and wall-clock seconds spent so far.
//!
//! A successful run removes the checkpoint directory after writing `summary.json`; a new run
//! (without `--resume`) removes a stale one when it starts.

use std::fs::File;
use std::io::{self, BufReader, Write};
use std::path::{Path, PathBuf};

use dem::checkpoint::WorldState;
use flate2::read::MultiGzDecoder;
use flate2::write::GzEncoder;
use flate2::Compression;
use rayon::prelude::*;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::error::{CliError, Result};
use crate::scenarios::phases::{PhaseProgress, RunUntilRest};

/// Format tag of run checkpoints. v2: a biperiodic cell may be under the implicit control
/// (`dem::cell::CellControl::implicit`), the default of `simple-shear` and `biaxial`, whose
/// stored scenario of a v1 run would not say so: a v1 checkpoint is refused (run again).
/// v3: steps whose solve does not converge are subdivided (`solver.max_halvings`, default 3,
/// `dem::step_control::step_subdivided`), and the phase's progress holds where the
/// subdivision stands; a v2 run did not subdivide, and its stored scenario would make the
/// resumed part do so: a v2 checkpoint is refused (run again).
/// v4: a converged step whose energy grew is solved again at a tenth of the tolerance
/// (`dem::step_control::step_subdivided_checked`), judged on the phase's load energy scale
/// stored in its progress; a v3 run did not, so a v3 checkpoint is refused (run again).
pub const FORMAT: &str = "grainlaw-run-checkpoint-v5";

/// Buffer between the gzip stream and the JSON deserialiser (bytes).
const BUFFER: usize = 1 << 20;

/// Uncompressed bytes per gzip member of a checkpoint.
const MEMBER: usize = 4 << 20;

/// A gzip writer that compresses on every thread: the stream is cut into members of
/// [`MEMBER`] bytes, compressed in parallel by batches (rayon) at level 1 and written in order.
/// A file of several members is one gzip file (RFC 1952 §2.2: a gzip file is a series of
/// members); `gzip -d` and [`MultiGzDecoder`] read it whole. Serde's small writes land in a
/// buffer, never in the compressor one by one (which is slow: flate2 compresses on every write).
struct ParallelGz<W: Write> {
    out: W,
    current: Vec<u8>,
    batch: Vec<Vec<u8>>,
    members: usize,
}

impl<W: Write> ParallelGz<W> {
    fn new(out: W) -> Self {
        ParallelGz {
            out,
            current: Vec::with_capacity(MEMBER),
            batch: Vec::new(),
            members: 0,
        }
    }

    /// Compresses the batch (in parallel) and writes it.
    fn flush_batch(&mut self) -> io::Result<()> {
        let batch = std::mem::take(&mut self.batch);
        let compressed: Vec<io::Result<Vec<u8>>> = batch
            .par_iter()
            .map(|chunk| {
                let mut gz =
                    GzEncoder::new(Vec::with_capacity(chunk.len() / 3), Compression::fast());
                gz.write_all(chunk)?;
                gz.finish()
            })
            .collect();
        for c in compressed {
            self.out.write_all(&c?)?;
            self.members += 1;
        }
        Ok(())
    }

    /// Writes what is left (at least one member, so that an empty stream is a gzip file too).
    fn finish(mut self) -> io::Result<()> {
        if !self.current.is_empty() || self.members + self.batch.len() == 0 {
            let last = std::mem::take(&mut self.current);
            self.batch.push(last);
        }
        self.flush_batch()?;
        self.out.flush()
    }
}

impl<W: Write> Write for ParallelGz<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.current.extend_from_slice(buf);
        if self.current.len() >= MEMBER {
            let full = std::mem::replace(&mut self.current, Vec::with_capacity(MEMBER));
            self.batch.push(full);
            if self.batch.len() >= 2 * rayon::current_num_threads() {
                self.flush_batch()?;
            }
        }
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Checkpoint directory inside the output directory.
pub const DIR: &str = "checkpoint";

/// Checkpoint file inside [`DIR`].
pub const FILE: &str = "run.json.gz";

/// The checkpoint directory of output directory `out`.
pub fn dir_of(out: &Path) -> PathBuf {
    out.join(DIR)
}

/// The checkpoint file of output directory `out`.
pub fn file_of(out: &Path) -> PathBuf {
    dir_of(out).join(FILE)
}

/// The scenario a run was started with.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ScenarioRecord {
    /// Name (built-in's, or the file stem).
    pub name: String,
    /// `builtin:NAME` or the TOML file path.
    pub source: String,
    /// The TOML actually run, overrides applied (as written to `scenario.toml`).
    pub effective_toml: String,
    /// The `--set KEY=VALUE` overrides given.
    pub sets: Vec<String>,
    /// `--allow-suspect` was given (a resume keeps it).
    #[serde(default)]
    pub allow_suspect: bool,
}

impl ScenarioRecord {
    /// `SOURCE --set A --set B`, for messages.
    pub fn describe(&self) -> String {
        let mut s = self.source.clone();
        for o in &self.sets {
            s.push_str(" --set ");
            s.push_str(o);
        }
        s
    }
}

/// When a phase stops (part of its plan, [`PhasePlan`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Stop {
    /// At rest (kinetic energy criterion) or at the time limit.
    UntilRest(RunUntilRest),
    /// After a number of steps.
    Steps(u64),
}

/// One phase as planned when it started.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhasePlan {
    /// Name shown in progress lines and messages.
    pub name: String,
    /// When it stops.
    pub stop: Stop,
}

impl PhasePlan {
    /// The phase `name` stopping at `stop`.
    pub fn new(name: impl Into<String>, stop: Stop) -> Self {
        PhasePlan {
            name: name.into(),
            stop,
        }
    }
}

/// Where a run stands: inside phase `phase`, planned as `plan`, with `progress`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cursor {
    /// Index of the phase in the scenario's sequence.
    pub phase: usize,
    /// The phase's plan.
    pub plan: PhasePlan,
    /// Steps, statistics and loop counters of the phase so far.
    pub progress: PhaseProgress,
}

/// A run checkpoint; `S` is the scenario's state (or [`serde::de::IgnoredAny`] to read the
/// rest without it).
#[derive(Debug, Serialize, Deserialize)]
pub struct RunCheckpoint<S> {
    /// [`FORMAT`].
    pub format: String,
    /// Version of the grainlaw that wrote it (a resume needs the same code to be exact).
    pub grainlaw_version: String,
    /// The scenario.
    pub scenario: ScenarioRecord,
    /// Where the run stands.
    pub cursor: Cursor,
    /// Steps done over the whole run, all phases (and worlds) together.
    pub steps_total: u64,
    /// Wall-clock seconds spent by the run so far, over every invocation (s).
    pub wall_seconds: f64,
    /// The run's start date and input hashes, recorded in the laws it writes.
    #[serde(default)]
    pub origin: crate::provenance::RunOrigin,
    /// The world.
    pub world: WorldState,
    /// The scenario's state.
    pub state: S,
}

fn bad(path: &Path, reason: impl std::fmt::Display) -> CliError {
    CliError::Checkpoint {
        path: path.display().to_string(),
        reason: reason.to_string(),
    }
}

/// Writes `cp` to `path` atomically (gzip JSON; temporary file in the same directory, then
/// rename), creating the directory.
pub fn write<S: Serialize>(path: &Path, cp: &RunCheckpoint<S>) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| CliError::io(dir, e))?;
    }
    dem::atomic::write_atomic(path, |w| {
        let mut gz = ParallelGz::new(w);
        serde_json::to_writer(&mut gz, cp).map_err(std::io::Error::other)?;
        gz.finish()
    })
    .map_err(|e| bad(path, format!("cannot write the checkpoint ({e})")))
}

/// Reads the checkpoint of output directory `out`, refusing a missing file, one that is not a
/// readable checkpoint (truncated, not gzip JSON, not this scenario's state) and one written
/// by another format or grainlaw version.
pub fn read<S: DeserializeOwned>(out: &Path) -> Result<RunCheckpoint<S>> {
    let path = file_of(out);
    let f = File::open(&path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            let done = if out.join("summary.json").exists() {
                " (the run there finished: summary.json is written)"
            } else {
                ""
            };
            bad(
                &path,
                format!("no checkpoint to resume from{done}; run the scenario without --resume"),
            )
        } else {
            bad(&path, e)
        }
    })?;
    // serde_json reads byte by byte: buffer the decompressed stream, not only the file.
    let cp: RunCheckpoint<S> = serde_json::from_reader(BufReader::with_capacity(
        BUFFER,
        MultiGzDecoder::new(BufReader::new(f)),
    ))
    .map_err(|e| bad(&path, format!("not a readable checkpoint ({e})")))?;
    if cp.format != FORMAT {
        return Err(bad(
            &path,
            format!("format `{}` is not `{FORMAT}`", cp.format),
        ));
    }
    let version = env!("CARGO_PKG_VERSION");
    if cp.grainlaw_version != version {
        return Err(bad(
            &path,
            format!(
                "written by grainlaw {}, this is {version}: a resume would not be exact; run the scenario again",
                cp.grainlaw_version
            ),
        ));
    }
    Ok(cp)
}

/// Removes the temporary files this process may be writing in output directory `out` (in
/// `out`, `out/vtk` and `out/checkpoint`: `.NAME.tmp-PID` of [`dem::atomic`], `.NAME.PID.partial.EXT`
/// of [`crate::output::OutputDir::temp_path`]), for a stop at once (a second Ctrl-C) that does
/// not let the writers clean up. A file being renamed into place at that moment is either
/// complete under its name or removed here; errors are ignored (nothing to remove).
pub fn remove_temporaries(out: &Path) {
    let pid = std::process::id();
    let (tmp, partial) = (format!(".tmp-{pid}"), format!(".{pid}.partial."));
    for dir in [out.to_path_buf(), out.join("vtk"), dir_of(out)] {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().to_string();
            if name.starts_with('.') && (name.ends_with(&tmp) || name.contains(&partial)) {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
}

/// Removes the checkpoint directory of `out` (after a finished run, or a stale one before a
/// new run); a missing directory is not an error.
pub fn remove(out: &Path) -> Result<()> {
    let dir = dir_of(out);
    match std::fs::remove_dir_all(&dir) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(CliError::io(&dir, e)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::ser::{Error as _, SerializeSeq};

    /// A scenario state whose serialisation fails after `bytes` bytes of numbers, as a full disk
    /// or a bug in a state's serialiser would, half-way through a checkpoint.
    struct FailsAfter(usize);

    impl Serialize for FailsAfter {
        fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
            let mut seq = s.serialize_seq(None)?;
            for k in 0..self.0 / 8 {
                seq.serialize_element(&(k as u32 % 10_000_000 + 10_000_000))?;
            }
            Err(S::Error::custom("the state cannot be written"))
        }
    }

    fn checkpoint<S>(state: S) -> RunCheckpoint<S> {
        let world = dem::World::new(
            dem::WorldParams::default(),
            dem::ContactLaws::new(&["grain"], 0.3),
        );
        RunCheckpoint {
            format: FORMAT.into(),
            grainlaw_version: env!("CARGO_PKG_VERSION").into(),
            scenario: ScenarioRecord {
                name: "t".into(),
                source: "test".into(),
                effective_toml: String::new(),
                sets: vec!["grains=3".into()],
                allow_suspect: false,
            },
            cursor: Cursor {
                phase: 0,
                plan: PhasePlan {
                    name: "p".into(),
                    stop: Stop::Steps(1),
                },
                progress: PhaseProgress::default(),
            },
            steps_total: 7,
            wall_seconds: 1.5,
            origin: Default::default(),
            world: world.state(),
            state,
        }
    }

    /// A write that fails half-way (after several gzip members were compressed and written)
    /// returns the error, removes its temporary file and leaves the previous checkpoint whole.
    #[test]
    fn a_failed_write_keeps_the_previous_checkpoint_and_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = file_of(dir.path());
        write(&path, &checkpoint(vec![1u32, 2, 3])).unwrap();
        let e = write(&path, &checkpoint(FailsAfter(5 * 8 * MEMBER))).unwrap_err();
        assert!(e.to_string().contains("the state cannot be written"), "{e}");
        let names: Vec<String> = std::fs::read_dir(dir_of(dir.path()))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        assert_eq!(names, vec![FILE.to_string()], "no temporary file left");
        let back: RunCheckpoint<Vec<u32>> = read(dir.path()).unwrap();
        assert_eq!(back.state, vec![1, 2, 3]);
        assert_eq!(back.steps_total, 7);
    }

    /// A stop at once removes this process's temporary files (and only those).
    #[test]
    fn temporaries_of_this_process_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path();
        let cp = file_of(out);
        std::fs::create_dir_all(dir_of(out)).unwrap();
        std::fs::create_dir_all(out.join("vtk")).unwrap();
        let mine = [
            dem::atomic::temporary_path(&cp).unwrap(),
            dem::atomic::temporary_path(&out.join("vtk/grains_0001.vtp")).unwrap(),
            out.join(format!(".figure.{}.partial.png", std::process::id())),
        ];
        let kept = [
            cp.clone(),
            out.join("summary.json"),
            dir_of(out).join(".run.json.gz.tmp-1"),
        ];
        for p in mine.iter().chain(&kept) {
            std::fs::write(p, b"x").unwrap();
        }
        remove_temporaries(out);
        for p in &mine {
            assert!(!p.exists(), "{} left", p.display());
        }
        for p in &kept {
            assert!(p.exists(), "{} removed", p.display());
        }
    }

    /// A checkpoint of many members reads back whole, and is one gzip stream for `gzip -d`
    /// (members concatenated: RFC 1952 §2.2).
    #[test]
    fn a_checkpoint_of_several_members_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = file_of(dir.path());
        let state: Vec<u64> = (0..3 * MEMBER as u64 / 8).collect();
        write(&path, &checkpoint(state.clone())).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let members = bytes
            .windows(3)
            .filter(|w| w == &[0x1f, 0x8b, 0x08])
            .count();
        assert!(members >= 2, "{members} gzip members");
        let back: RunCheckpoint<Vec<u64>> = read(dir.path()).unwrap();
        assert_eq!(back.state, state);
        assert_eq!(back.scenario.sets, vec!["grains=3".to_string()]);
    }
}
