//! Checkpoints: the complete state of a [`World`] (bodies, colliders, contact laws, parameters,
//! time, and the last step's contacts whose impulses warm-start the next step), written so that
//! a run resumed from it gives bit-identical results to an uninterrupted one.
//!
//! Format: gzip-compressed JSON `{"format": "grainlaw-checkpoint-v1", "world": {...}}`; floats
//! are written as their shortest round-trip decimal and read back exactly. Files are written
//! atomically (temporary file in the same directory, then rename), so an interrupted write never
//! leaves a file that looks complete.

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use flate2::read::GzDecoder;
use flate2::write::GzEncoder;
use flate2::Compression;
use serde::{Deserialize, Serialize};

use crate::error::DemError;
use crate::world::World;

/// Format tag of checkpoint files.
pub const FORMAT: &str = "grainlaw-checkpoint-v1";

/// Everything needed to continue a run exactly: the world's state, serialised.
pub use crate::world::WorldState;

#[derive(Serialize, Deserialize)]
struct File_ {
    format: String,
    world: WorldState,
}

fn err(path: &Path, reason: impl std::fmt::Display) -> DemError {
    DemError::Checkpoint {
        path: path.display().to_string(),
        reason: reason.to_string(),
    }
}

/// Write `world` to `path` atomically (gzip JSON, temp file then rename).
pub fn write_checkpoint(world: &World, path: &Path) -> Result<(), DemError> {
    // The state by reference: the same keys as `File_`, without cloning the world.
    #[derive(Serialize)]
    struct FileRef<'a> {
        format: &'a str,
        world: &'a WorldState,
    }
    let file = FileRef {
        format: FORMAT,
        world,
    };
    crate::atomic::write_atomic(path, |w| {
        let mut gz = GzEncoder::new(w, Compression::fast());
        serde_json::to_writer(&mut gz, &file).map_err(std::io::Error::other)?;
        gz.finish().map(|_| ())
    })
    .map_err(|e| err(path, e))
}

/// Read a checkpoint written by [`write_checkpoint`] and rebuild the world.
pub fn read_checkpoint(path: &Path) -> Result<World, DemError> {
    let f = File::open(path).map_err(|e| err(path, e))?;
    let file: File_ = serde_json::from_reader(GzDecoder::new(BufReader::new(f)))
        .map_err(|e| err(path, format!("not a readable checkpoint ({e})")))?;
    if file.format != FORMAT {
        return Err(err(
            path,
            format!("format `{}` is not `{FORMAT}`", file.format),
        ));
    }
    Ok(World::from_state(file.world))
}
