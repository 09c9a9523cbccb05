//! Errors of the genetic-algorithm library: each names what was refused and why.

use thiserror::Error;

/// A refused configuration, individual, input file or run state.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GaError {
    /// A configuration value out of its range.
    #[error("invalid {name} = {value}: {reason}")]
    InvalidConfig {
        /// The parameter's name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        reason: &'static str,
    },
    /// A standing-pose angle outside its servo's limits.
    #[error("standing pose of {servo} = {value} rad is outside the servo's limits [{min}, {max}]")]
    StandingPoseOutOfLimits {
        /// The servo's name.
        servo: &'static str,
        /// The angle (rad).
        value: f64,
        /// Lower limit (rad).
        min: f64,
        /// Upper limit (rad).
        max: f64,
    },
    /// An individual with a knot outside the limits, not finite, or ends off the standing pose.
    #[error("invalid individual: {0}")]
    InvalidIndividual(String),
    /// An unknown crossover name.
    #[error("unknown crossover `{0}` (expected blx, arithmetic, one-point, geometric or linear)")]
    UnknownCrossover(String),
    /// A run state that does not fit the configuration it is continued with.
    #[error("run state does not fit: {0}")]
    StateMismatch(String),
}

/// Why a checkpoint could not be written or read.
#[derive(Debug, Error)]
pub enum CheckpointError {
    /// The file system refused (the path names the file).
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The file is not a checkpoint of this program (not JSON, or no or another format tag).
    #[error("not a ga_step checkpoint ({0})")]
    Foreign(String),
    /// A checkpoint of another format version.
    #[error("checkpoint format version {found}, this program reads version {expected}")]
    UnsupportedVersion {
        /// The file's version.
        found: u64,
        /// The version this library reads.
        expected: u64,
    },
    /// A checkpoint whose content is damaged or inconsistent.
    #[error("corrupt checkpoint: {0}")]
    Corrupt(String),
    /// A file larger than any checkpoint this program writes (or a device without an end).
    #[error("{path}: larger than {limit} bytes, not a ga_step checkpoint")]
    TooLarge {
        /// The file.
        path: String,
        /// The largest size read (bytes).
        limit: u64,
    },
}

/// A parameter file that cannot be read or does not describe a valid setup: one line, naming
/// the file.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{0}")]
pub struct ParamsError(pub String);

/// Why a motion file could not be read.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MotionError {
    /// Reading failed.
    #[error("read failed: {0}")]
    Io(String),
    /// The first line is not `#WEBOTS_MOTION,V1.0,` followed by joint names.
    #[error("line 1: not a Webots motion header (expected `#WEBOTS_MOTION,V1.0,<joint>,…`)")]
    BadHeader,
    /// A row that does not parse.
    #[error("line {line}: {reason}")]
    BadRow {
        /// Line number (from 1).
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// The motion is not one `write_motion` wrote for the model: a joint missing, another
    /// length, or a knot no row pins down.
    #[error("not a step of this model: {0}")]
    NotAStep(String),
}
