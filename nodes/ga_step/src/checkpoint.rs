//! Checkpoints: a [`GaState`] as one JSON document, written atomically.
//!
//! JSON (serde_json, with its exact float parsing): readable with any tool, and every f64 is
//! written in its shortest round-trip form and read back to the same bits, so a resumed run
//! equals the uninterrupted one. The document starts with a format tag and a version:
//! `{"format": "mobil_ga_step checkpoint", "version": 3, …}`; the generator is stored as its seed
//! and its position in the stream (ChaCha8, 32-bit words). A file that is not JSON or has
//! another tag is [`CheckpointError::Foreign`], another version
//! [`CheckpointError::UnsupportedVersion`], a damaged or inconsistent one
//! [`CheckpointError::Corrupt`].
//!
//! Writing goes to `<file>.tmp` in the same directory, is flushed to disk, then renamed over the
//! file: a reader sees the old checkpoint or the new one, never half of one.

use crate::error::CheckpointError;
use crate::ga::{GaSetup, GaState, GenerationStats};
use crate::selection::Scored;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The format tag of a checkpoint.
pub const CHECKPOINT_FORMAT: &str = "mobil_ga_step checkpoint";
/// The format version this library writes. Version 3: the setup's fitness carries
/// `backward_allowance` besides `distance_on_fall`. A version-2 checkpoint is read as the shape
/// it was evolved under, a backward allowance of 0 (the field did not exist); a version-1
/// checkpoint was evolved under the SPEC's example shape and names no shape, so it is refused
/// rather than resumed under another fitness.
pub const CHECKPOINT_VERSION: u64 = 3;

/// The oldest version read: 2, whose fitness had no backward allowance (b = 0).
pub const CHECKPOINT_OLDEST_READ: u64 = 2;

#[derive(Serialize, Deserialize)]
struct Header {
    format: Option<String>,
    version: Option<u64>,
}

#[derive(Serialize, Deserialize)]
struct Document {
    format: String,
    version: u64,
    seed: u64,
    /// The generator's position (32-bit words), as a decimal string (beyond JSON's safe integers).
    rng_word_pos: String,
    generation: u32,
    first_step_generation: Option<u32>,
    setup: GaSetup,
    population: Vec<Scored>,
    history: Vec<GenerationStats>,
}

/// The checkpoint's text.
pub fn to_json(state: &GaState) -> String {
    let doc = Document {
        format: CHECKPOINT_FORMAT.to_owned(),
        version: CHECKPOINT_VERSION,
        seed: state.seed,
        rng_word_pos: state.rng_word_pos().to_string(),
        generation: state.generation,
        first_step_generation: state.first_step_generation,
        setup: state.setup.clone(),
        population: state.population.clone(),
        history: state.history.clone(),
    };
    // Serialising plain structs of numbers, strings and vectors cannot fail, except for a
    // non-finite f64, which serde_json writes as null; the reader then refuses it as corrupt.
    serde_json::to_string(&doc).unwrap_or_default()
}

/// A state from a checkpoint's text.
pub fn from_json(text: &str) -> Result<GaState, CheckpointError> {
    let header: Header = serde_json::from_str(text).map_err(|e| {
        // Our tag at the start of a file that does not parse: a damaged (e.g. truncated) checkpoint.
        let tag = format!("{{\"format\":\"{CHECKPOINT_FORMAT}\"");
        if text.starts_with(&tag) {
            CheckpointError::Corrupt(e.to_string())
        } else {
            CheckpointError::Foreign(format!("not a JSON object with a format tag: {e}"))
        }
    })?;
    match header.format.as_deref() {
        Some(CHECKPOINT_FORMAT) => {}
        Some(other) => return Err(CheckpointError::Foreign(format!("format tag `{other}`"))),
        None => return Err(CheckpointError::Foreign("no format tag".into())),
    }
    let version = match header.version {
        Some(v @ CHECKPOINT_OLDEST_READ..=CHECKPOINT_VERSION) => v,
        Some(found) => {
            return Err(CheckpointError::UnsupportedVersion {
                found,
                expected: CHECKPOINT_VERSION,
            })
        }
        None => return Err(CheckpointError::Corrupt("no version".into())),
    };
    let mut doc: Document = serde_json::from_str(text).map_err(|e| CheckpointError::Corrupt(e.to_string()))?;
    if version == 2 {
        // Evolved before the allowance existed, under f = 1 + w·max(0, Δx) without a fall.
        doc.setup.fitness.backward_allowance = 0.0;
    }
    let word_pos: u128 = doc
        .rng_word_pos
        .parse()
        .map_err(|_| CheckpointError::Corrupt(format!("generator position `{}`", doc.rng_word_pos)))?;
    GaState::from_parts(
        doc.setup,
        doc.seed,
        doc.generation,
        doc.population,
        doc.history,
        doc.first_step_generation,
        word_pos,
    )
    .map_err(|e| CheckpointError::Corrupt(e.to_string()))
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> CheckpointError + '_ {
    move |source| CheckpointError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// The temporary file a checkpoint is written to before the rename: `<path>.tmp`.
pub fn temp_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".tmp");
    path.with_file_name(name)
}

/// Writes the checkpoint atomically: to [`temp_path`], flushed to disk, renamed over `path`.
/// On failure the temporary file is removed and `path` is untouched.
pub fn write_checkpoint(state: &GaState, path: &Path) -> Result<(), CheckpointError> {
    let tmp = temp_path(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp).map_err(io_error(&tmp))?;
        f.write_all(to_json(state).as_bytes()).map_err(io_error(&tmp))?;
        f.sync_all().map_err(io_error(&tmp))?;
        std::fs::rename(&tmp, path).map_err(io_error(path))
    })();
    if result.is_err() {
        // Best effort: the temporary file may not exist.
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Reads a checkpoint written by [`write_checkpoint`].
pub fn read_checkpoint(path: &Path) -> Result<GaState, CheckpointError> {
    let bytes = std::fs::read(path).map_err(io_error(path))?;
    let text = String::from_utf8(bytes).map_err(|_| CheckpointError::Foreign("not UTF-8 text".into()))?;
    from_json(&text)
}
