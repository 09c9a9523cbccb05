//! Errors of the gait library: each names what was refused and why.

use thiserror::Error;

/// Why a configuration, a model, a state or a name was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GaitError {
    /// A configuration value out of its range (or not finite).
    #[error("parameter `{name}` = {value} is invalid: {reason}")]
    InvalidParameter {
        /// The parameter's name, as in `params/quadruped.yaml`.
        name: &'static str,
        /// The refused value.
        value: f64,
        /// What it must be.
        reason: &'static str,
    },
    /// A rule set other than "A" or "B".
    #[error("unknown rule set `{0}` (expected \"A\" or \"B\")")]
    UnknownRuleSet(String),
    /// An evaluation function other than 1, 2 or 3.
    #[error("unknown evaluation function {0} (expected 1, 2 or 3)")]
    UnknownEvaluation(u8),
    /// A rule number other than 1..=27.
    #[error("unknown rule {0} (expected 1..=27)")]
    UnknownRule(u8),
    /// A leg-angle reading other than "forward" or "rearward".
    #[error("unknown leg-angle reading `{0}` (expected \"forward\" or \"rearward\")")]
    UnknownReading(String),
    /// A tie rule other than "oldest" or "newest".
    #[error("unknown tie rule `{0}` (expected \"oldest\" or \"newest\")")]
    UnknownTieBreak(String),
    /// A state the model cannot stand in.
    #[error("invalid state: {0}")]
    InvalidState(String),
}
