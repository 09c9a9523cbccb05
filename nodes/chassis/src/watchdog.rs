//! Input timeouts: stop the chassis when an input stops arriving (SPEC §1, LOW-LEVEL safety).
//!
//! The timeout only decides; the age of an input is measured where it arrives (the node holds
//! each input with its steady-clock receive instant and passes the age in), so an input's
//! freshness is measured in one place and decided in one place.

use crate::error::ChassisError;

/// Expired when an input is older than `timeout_s`; a timeout of 0 disables it.
///
/// Safe by default: an input never received (age `None`) or of a non-finite or negative age
/// counts as expired while the timeout is enabled.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputTimeout {
    timeout_s: f64,
}

impl InputTimeout {
    /// A timeout of `timeout_s` ≥ 0 (0 = disabled); refuses negative or non-finite values.
    /// `name` is the parameter it comes from, for the error.
    pub fn new(name: &'static str, timeout_s: f64) -> Result<Self, ChassisError> {
        if !(timeout_s.is_finite() && timeout_s >= 0.0) {
            return Err(ChassisError::InvalidParameter {
                name,
                value: timeout_s,
                reason: "must be finite and non-negative (0 disables the watchdog)",
            });
        }
        Ok(Self { timeout_s })
    }

    /// The timeout (s); 0 means disabled.
    pub fn timeout_s(&self) -> f64 {
        self.timeout_s
    }

    /// True if the timeout is disabled (0).
    pub fn is_disabled(&self) -> bool {
        self.timeout_s == 0.0
    }

    /// True if the chassis must stop for an input last received `age_s` seconds ago (`None`:
    /// never): never when disabled; otherwise when never received, the age is not a finite
    /// non-negative number, or it exceeds the timeout (exactly the timeout is still alive).
    pub fn expired(&self, age_s: Option<f64>) -> bool {
        if self.is_disabled() {
            return false;
        }
        match age_s {
            None => true,
            Some(age) => !(age.is_finite() && age >= 0.0) || age > self.timeout_s,
        }
    }
}
