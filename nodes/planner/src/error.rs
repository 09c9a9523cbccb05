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
    /// A pose, goal or waypoint lies further than [`COORDINATE_LIMIT`] from the origin on an
    /// axis (or a heading beyond it): outside any map the suite drives, and where squared
    /// distances would overflow.
    #[error("{what} is out of range: ({x}, {y}, {yaw}); every coordinate must lie within ±{limit}")]
    OutOfRange {
        /// What the value is (e.g. `goal`, `waypoint 3`).
        what: String,
        /// x (m).
        x: f64,
        /// y (m).
        y: f64,
        /// Heading (rad; 0 for a point).
        yaw: f64,
        /// The bound, [`COORDINATE_LIMIT`].
        limit: f64,
    },
    /// A route without waypoints.
    #[error("the route has no waypoints")]
    EmptyRoute,
    /// A laser scan is malformed (empty, bad angles or range limits).
    #[error("scan refused: {0}")]
    Scan(#[from] mobil_geom::ScanError),
    /// A computation was stopped by its caller before it finished (a newer request superseded
    /// it); its partial result is not given.
    #[error("stopped by the caller before the end")]
    Stopped,
}

/// Largest |x|, |y| (m) and |ϑ| (rad) the library accepts: 1000 km, far beyond any map, and
/// far below where e² (≈ 1.3e154 m) overflows, so V, V̇ and every distance stay finite.
pub const COORDINATE_LIMIT: f64 = 1e6;

/// Refuses a non-finite or out-of-range pose (x, y, yaw).
pub(crate) fn check_coordinates(what: &str, x: f64, y: f64, yaw: f64) -> Result<(), PlannerError> {
    if !(x.is_finite() && y.is_finite() && yaw.is_finite()) {
        return Err(PlannerError::NonFinite {
            what: what.to_owned(),
            x,
            y,
            yaw,
        });
    }
    if x.abs() > COORDINATE_LIMIT || y.abs() > COORDINATE_LIMIT || yaw.abs() > COORDINATE_LIMIT {
        return Err(PlannerError::OutOfRange {
            what: what.to_owned(),
            x,
            y,
            yaw,
            limit: COORDINATE_LIMIT,
        });
    }
    Ok(())
}

/// Refuses a length that is not finite and positive or that exceeds `max`.
pub(crate) fn bounded_length(name: &'static str, value: f64, max: f64) -> Result<f64, PlannerError> {
    positive_finite(name, value)?;
    if value > max {
        return Err(PlannerError::InvalidConfig {
            name,
            value,
            reason: "too large (see the crate's limits)",
        });
    }
    Ok(value)
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
