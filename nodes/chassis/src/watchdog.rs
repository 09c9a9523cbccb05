//! cmd_vel watchdog: stop the chassis when commands stop arriving (SPEC §1, LOW-LEVEL safety).

use crate::error::ChassisError;

/// Expires when no command was fed for longer than `timeout_s`; a timeout of 0 disables it.
///
/// Safe by default: before the first feed, and when time goes backwards (now earlier than the
/// last feed), an enabled watchdog reports expired.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CmdVelWatchdog {
    timeout_s: f64,
    last_feed: Option<f64>,
}

impl CmdVelWatchdog {
    /// A watchdog with `timeout_s` ≥ 0 (0 = disabled); refuses negative or non-finite values.
    pub fn new(timeout_s: f64) -> Result<Self, ChassisError> {
        if !(timeout_s.is_finite() && timeout_s >= 0.0) {
            return Err(ChassisError::InvalidParameter {
                name: "cmd_vel_timeout_s",
                value: timeout_s,
                reason: "must be finite and non-negative (0 disables the watchdog)",
            });
        }
        Ok(Self {
            timeout_s,
            last_feed: None,
        })
    }

    /// The timeout (s); 0 means disabled.
    pub fn timeout_s(&self) -> f64 {
        self.timeout_s
    }

    /// True if the watchdog is disabled (timeout 0).
    pub fn is_disabled(&self) -> bool {
        self.timeout_s == 0.0
    }

    /// Records a valid command at time `t` (s); a non-finite `t` is ignored and returns false.
    ///
    /// A feed earlier than the previous one is accepted (e.g. a restarted simulation clock).
    pub fn feed(&mut self, t: f64) -> bool {
        if t.is_finite() {
            self.last_feed = Some(t);
            true
        } else {
            false
        }
    }

    /// Time (s) of the last accepted feed.
    pub fn last_feed(&self) -> Option<f64> {
        self.last_feed
    }

    /// Forgets the last feed (the watchdog is then expired until fed, unless disabled).
    pub fn reset(&mut self) {
        self.last_feed = None;
    }

    /// True if the chassis must stop at time `now` (s): never when disabled; otherwise when never
    /// fed, `now` is non-finite, `now` is before the last feed, or `now − last feed > timeout_s`.
    pub fn expired(&self, now: f64) -> bool {
        if self.is_disabled() {
            return false;
        }
        match self.last_feed {
            None => true,
            Some(last) => !now.is_finite() || now < last || now - last > self.timeout_s,
        }
    }
}
