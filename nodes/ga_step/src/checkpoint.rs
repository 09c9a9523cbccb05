//! Checkpoints: a [`GaState`] as one JSON document, written atomically.
//!
//! JSON (serde_json, with its exact float parsing): readable with any tool, and every f64 is
//! written in its shortest round-trip form and read back to the same bits, so a resumed run
//! equals the uninterrupted one. The document starts with a format tag and a version:
//! `{"format": "mobil_ga_step checkpoint", "version": 4, …}`; the generator is stored as its seed
//! and its position in the stream (ChaCha8, 32-bit words), and the evaluator that scored the
//! population as an [`EvaluatorTag`] (a resume under another evaluator, or another version of the
//! physics, would mix fitness values of two different measures). A file that is not JSON or has
//! another tag is [`CheckpointError::Foreign`], another version
//! [`CheckpointError::UnsupportedVersion`], a damaged or inconsistent one
//! [`CheckpointError::Corrupt`], a file above [`MAX_CHECKPOINT_BYTES`]
//! [`CheckpointError::TooLarge`] (read no further than that).
//!
//! Writing goes to `<file>.tmp` in the same directory, is flushed to disk, then renamed over the
//! file: a reader sees the old checkpoint or the new one, never half of one.

use crate::error::CheckpointError;
use crate::ga::{GaSetup, GaState, GenerationStats};
use crate::selection::Scored;
use serde::{Deserialize, Serialize};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

/// The format tag of a checkpoint.
pub const CHECKPOINT_FORMAT: &str = "mobil_ga_step checkpoint";
/// The format version this library writes. Version 4: the document records the evaluator
/// ([`EvaluatorTag`]). Earlier versions do not say which evaluator (or which version of the
/// physics) scored their population, so they are refused rather than resumed under a measure
/// they may not have been scored by.
pub const CHECKPOINT_VERSION: u64 = 4;

/// The oldest version read: 4, the first that records its evaluator.
pub const CHECKPOINT_OLDEST_READ: u64 = 4;

/// The largest checkpoint read (128 MiB); a larger file (or a device such as `/dev/zero`) is
/// refused after reading this much and one byte more. An individual takes about 4.0 KB of JSON (210 knots in
/// shortest round-trip form and its evaluation), so the largest population the executable
/// accepts (10 000) is about 40 MB, leaving room for a history of more than 400 000 generations
/// (about 200 bytes each).
pub const MAX_CHECKPOINT_BYTES: u64 = 128 * 1024 * 1024;

/// Who scored a run's individuals, as its checkpoint records it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum EvaluatorTag {
    /// The built-in physics simulation, at the version of its model (`mobil_ga_step_sim`'s
    /// `PHYSICS_VERSION`): another version scores the same individual differently.
    Physics {
        /// The physics model's version.
        physics_version: u32,
    },
    /// An external simulator over ROS 2 (its model is the user's; ga_step cannot know its
    /// version).
    Ros,
}

impl std::fmt::Display for EvaluatorTag {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EvaluatorTag::Physics { physics_version } => write!(f, "physics (model version {physics_version})"),
            EvaluatorTag::Ros => f.write_str("ros (an external simulator)"),
        }
    }
}

#[derive(Serialize, Deserialize)]
struct Header {
    format: Option<String>,
    version: Option<u64>,
}

#[derive(Serialize, Deserialize)]
struct Document {
    format: String,
    version: u64,
    evaluator: EvaluatorTag,
    seed: u64,
    /// The generator's position (32-bit words), as a decimal string (beyond JSON's safe integers).
    rng_word_pos: String,
    generation: u32,
    first_step_generation: Option<u32>,
    setup: GaSetup,
    population: Vec<Scored>,
    history: Vec<GenerationStats>,
}

/// The checkpoint's text: `state` as scored by `evaluator`.
pub fn to_json(state: &GaState, evaluator: &EvaluatorTag) -> String {
    let doc = Document {
        format: CHECKPOINT_FORMAT.to_owned(),
        version: CHECKPOINT_VERSION,
        evaluator: evaluator.clone(),
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

/// A state from a checkpoint's text (the evaluator's record dropped: see [`from_json_tagged`]).
pub fn from_json(text: &str) -> Result<GaState, CheckpointError> {
    from_json_tagged(text).map(|(state, _)| state)
}

/// A state from a checkpoint's text, with the evaluator that scored it.
pub fn from_json_tagged(text: &str) -> Result<(GaState, EvaluatorTag), CheckpointError> {
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
    match header.version {
        Some(v @ CHECKPOINT_OLDEST_READ..=CHECKPOINT_VERSION) => v,
        Some(found) => {
            return Err(CheckpointError::UnsupportedVersion {
                found,
                expected: CHECKPOINT_VERSION,
            })
        }
        None => return Err(CheckpointError::Corrupt("no version".into())),
    };
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| CheckpointError::Corrupt(e.to_string()))?;
    // A checkpoint written before the robust score existed was scored without it (a missing
    // key elsewhere takes its default, which for this one is on).
    let named = value.pointer("/setup/fitness/robust_check").is_some();
    // One written before the physics model could be chosen was scored by the DC-motor model.
    let physics_named = value.pointer("/setup/fitness/physics").is_some();
    let mut doc: Document = serde_json::from_value(value).map_err(|e| CheckpointError::Corrupt(e.to_string()))?;
    if !named {
        doc.setup.fitness.robust_check = false;
    }
    if !physics_named {
        doc.setup.fitness.physics = crate::config::PhysicsModel::DcMotor;
    }
    let word_pos: u128 = doc
        .rng_word_pos
        .parse()
        .map_err(|_| CheckpointError::Corrupt(format!("generator position `{}`", doc.rng_word_pos)))?;
    let state = GaState::from_parts(
        doc.setup,
        doc.seed,
        doc.generation,
        doc.population,
        doc.history,
        doc.first_step_generation,
        word_pos,
    )
    .map_err(|e| CheckpointError::Corrupt(e.to_string()))?;
    Ok((state, doc.evaluator))
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

/// Writes the checkpoint atomically: to [`temp_path`], flushed to disk, renamed over `path`,
/// and the directory flushed so the rename itself survives a power loss. On failure the
/// temporary file is removed and `path` is untouched.
pub fn write_checkpoint(state: &GaState, evaluator: &EvaluatorTag, path: &Path) -> Result<(), CheckpointError> {
    let tmp = temp_path(path);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp).map_err(io_error(&tmp))?;
        f.write_all(to_json(state, evaluator).as_bytes())
            .map_err(io_error(&tmp))?;
        f.sync_all().map_err(io_error(&tmp))?;
        std::fs::rename(&tmp, path).map_err(io_error(path))?;
        sync_parent(path).map_err(io_error(path))
    })();
    if result.is_err() {
        // Best effort: the temporary file may not exist.
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Flushes the directory holding `path` to disk (on Unix; elsewhere a no-op), so that a rename
/// into it is durable. A file system that cannot sync a directory (the call fails with EINVAL
/// or ENOTSUP: some network and FUSE file systems) is not an error: the rename is done, and
/// such a file system offers no stronger promise.
pub fn sync_parent(path: &Path) -> std::io::Result<()> {
    #[cfg(unix)]
    {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        unsupported_is_done(std::fs::File::open(dir)?.sync_all())
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        Ok(())
    }
}

/// A directory sync's result, with EINVAL and ENOTSUP (the file system cannot sync a
/// directory) taken as done.
#[cfg(unix)]
fn unsupported_is_done(result: std::io::Result<()>) -> std::io::Result<()> {
    use std::io::ErrorKind;
    // The standard library names EINVAL `InvalidInput` and ENOTSUP/EOPNOTSUPP `Unsupported`.
    match result {
        Err(e) if matches!(e.kind(), ErrorKind::InvalidInput | ErrorKind::Unsupported) => Ok(()),
        other => other,
    }
}

/// Reads a checkpoint written by [`write_checkpoint`] (the evaluator's record dropped).
pub fn read_checkpoint(path: &Path) -> Result<GaState, CheckpointError> {
    read_checkpoint_tagged(path).map(|(state, _)| state)
}

/// Reads a checkpoint written by [`write_checkpoint`], with the evaluator that scored it. Reads
/// at most [`MAX_CHECKPOINT_BYTES`] (+1 to tell a larger file).
pub fn read_checkpoint_tagged(path: &Path) -> Result<(GaState, EvaluatorTag), CheckpointError> {
    let file = std::fs::File::open(path).map_err(io_error(path))?;
    let mut bytes = Vec::new();
    file.take(MAX_CHECKPOINT_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io_error(path))?;
    if bytes.len() as u64 > MAX_CHECKPOINT_BYTES {
        return Err(CheckpointError::TooLarge {
            path: path.display().to_string(),
            limit: MAX_CHECKPOINT_BYTES,
        });
    }
    let text = String::from_utf8(bytes).map_err(|_| CheckpointError::Foreign("not UTF-8 text".into()))?;
    from_json_tagged(&text)
}

#[cfg(all(test, unix))]
mod tests {
    use super::unsupported_is_done;
    use std::io::Error;

    #[test]
    fn a_directory_sync_the_file_system_cannot_do_is_not_an_error() {
        // Linux's errno values: EINVAL 22, EOPNOTSUPP (= ENOTSUP) 95; EIO 5, ENOSPC 28.
        assert!(unsupported_is_done(Err(Error::from_raw_os_error(22))).is_ok());
        assert!(unsupported_is_done(Err(Error::from_raw_os_error(95))).is_ok());
        assert!(unsupported_is_done(Ok(())).is_ok());
        let eio = unsupported_is_done(Err(Error::from_raw_os_error(5))).unwrap_err();
        assert_eq!(eio.raw_os_error(), Some(5));
        assert!(unsupported_is_done(Err(Error::from_raw_os_error(28))).is_err());
    }
}
