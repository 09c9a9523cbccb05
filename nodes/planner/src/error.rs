//! Errors of the planner library: every one names what was refused and why.

use thiserror::Error;

/// Why a gain, a configuration or an input was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PlannerError {
    /// A Lyapunov gain is zero, negative, NaN or infinite (SPEC §3 Decision: refused).
    #[error("gain {name} = {value} must be finite and positive (Lyapunov stability needs γ, k, h, λ > 0)")]
    InvalidGain {
        /// The gain's name (`gamma`, `k`, `h`, `lambda`).
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A configuration value is out of range.
    #[error("{name} = {value}: {reason}")]
    InvalidConfig {
        /// The field's name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The rule it breaks.
        reason: &'static str,
    },
    /// A pose, goal or waypoint has a NaN or infinite coordinate.
    #[error("{what} is not finite: ({x}, {y}, {yaw})")]
    NonFinite {
        /// What the value is (e.g. `goal`, `waypoint 3`).
        what: String,
        /// x (m).
        x: f64,
        /// y (m).
        y: f64,
        /// Heading (rad; 0 for a point).
        yaw: f64,
    },
    /// A route without waypoints.
    #[error("the route has no waypoints")]
    EmptyRoute,
}

pub(crate) fn positive_finite(name: &'static str, value: f64) -> Result<f64, PlannerError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(PlannerError::InvalidConfig {
            name,
            value,
            reason: "must be finite and positive",
        })
    }
}
