//! The output directory. Every file is written atomically: to a temporary file in the same
//! directory, flushed, then renamed over its final name, so a reader never sees half a file and
//! a run that fails leaves no complete-looking partial output. A stale `summary.json` from an
//! earlier run is removed when the directory is opened, and the new one is written last.

use std::fs;
use std::path::{Path, PathBuf};

use crate::error::{CliError, Result};

/// An output directory and the files written into it.
#[derive(Debug)]
pub struct OutputDir {
    root: PathBuf,
    written: Vec<String>,
}

impl OutputDir {
    /// Creates `root` (and parents) and removes a `summary.json` left by an earlier run.
    pub fn create(root: &Path) -> Result<Self> {
        fs::create_dir_all(root).map_err(|e| CliError::io(root, e))?;
        let stale = root.join("summary.json");
        if stale.exists() {
            fs::remove_file(&stale).map_err(|e| CliError::io(&stale, e))?;
        }
        Ok(Self {
            root: root.to_path_buf(),
            written: Vec::new(),
        })
    }

    /// An existing directory that is not a run's (e.g. a campaign's), to add files to: nothing
    /// in it is removed.
    pub fn open(root: &Path) -> Result<Self> {
        if !root.is_dir() {
            return Err(CliError::io(
                root,
                std::io::Error::new(std::io::ErrorKind::NotFound, "not a directory"),
            ));
        }
        Ok(Self {
            root: root.to_path_buf(),
            written: Vec::new(),
        })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.root
    }

    /// Full path of a file in the directory.
    pub fn file(&self, name: &str) -> PathBuf {
        self.root.join(name)
    }

    /// A temporary path next to `name` for writers that need a path (e.g. image encoders);
    /// pass it to [`OutputDir::commit`] once written. The extension is kept so that encoders
    /// that choose the format from it still work.
    pub fn temp_path(&self, name: &str) -> PathBuf {
        let p = Path::new(name);
        let stem = p.file_stem().and_then(|s| s.to_str()).unwrap_or("out");
        let ext = p.extension().and_then(|s| s.to_str()).unwrap_or("tmp");
        self.root
            .join(format!(".{stem}.{}.partial.{ext}", std::process::id()))
    }

    /// Renames a finished temporary file to its final name.
    pub fn commit(&mut self, temp: &Path, name: &str) -> Result<PathBuf> {
        let target = self.file(name);
        if let Some(parent) = target.parent() {
            fs::create_dir_all(parent).map_err(|e| CliError::io(parent, e))?;
        }
        fs::rename(temp, &target).map_err(|e| {
            let _ = fs::remove_file(temp);
            CliError::io(&target, e)
        })?;
        self.written.push(name.to_string());
        Ok(target)
    }

    /// Writes `bytes` to `name` atomically ([`dem::atomic`]).
    pub fn write(&mut self, name: &str, bytes: &[u8]) -> Result<PathBuf> {
        let target = self.file(name);
        write_atomic(&target, bytes)?;
        self.written.push(name.to_string());
        Ok(target)
    }

    /// Files written so far (names relative to the directory).
    pub fn written(&self) -> &[String] {
        &self.written
    }
}

/// Refuses an output directory that is a file, or that holds the outputs of a run of another
/// scenario (its `scenario.toml` names it): the files of two scenarios would mix. A directory
/// of an earlier run of the same scenario is reused (its stale `summary.json` is removed first).
pub fn check_out_dir(dir: &Path, kind: &str) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(CliError::Usage(format!(
            "--out {}: is a file, not a directory",
            dir.display()
        )));
    }
    let toml = dir.join("scenario.toml");
    let there = std::fs::read_to_string(&toml)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
        .and_then(|t| t.get("scenario").and_then(|v| v.as_str()).map(String::from));
    match there {
        Some(other) if other != kind => Err(CliError::Usage(format!(
            "--out {}: holds the outputs of a `{other}` run, not `{kind}`: choose another directory or remove it",
            dir.display()
        ))),
        _ => Ok(()),
    }
}

/// Writes `bytes` to `path` atomically (temporary file in the same directory, then rename;
/// [`dem::atomic`]), creating the directory if needed.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        fs::create_dir_all(dir).map_err(|e| CliError::io(dir, e))?;
    }
    dem::atomic::write_bytes_atomic(path, bytes).map_err(|e| CliError::io(path, e))
}
