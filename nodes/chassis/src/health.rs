//! What a node reports on `/diagnostics`: a level (diagnostic_msgs' OK, WARN, ERROR, STALE), a
//! one-line message and key–value pairs ([`Health`]), and the chassis' own rule
//! ([`chassis_health`]): the watchdogs, refused and rejected inputs, the limits that bound.
//! No clock and no ROS: the node gives the ages and counts it measured.
//!
//! ```
//! use mobil_chassis::health::{chassis_health, ChassisReport, Level};
//! use mobil_chassis::controller::InputAges;
//! use mobil_chassis::{ClampReasons, Safety};
//!
//! let safety = Safety { cmd_vel_expired: false, cmd_vel_refused: false, feedback_stale: true };
//! let ages = InputAges { cmd_vel_s: Some(0.02), feedback_s: Some(0.7) };
//! let report = ChassisReport { safety, ages, clamped: ClampReasons::NONE, rejected_total: 0, rejected_new: 0 };
//! let health = chassis_health(&report);
//! assert_eq!(health.level, Level::Error);
//! assert_eq!(health.message, "no valid joint_states for 0.70 s: odometry stale, wheels stopped");
//! ```

use crate::controller::{InputAges, Safety};
use crate::limits::ClampReasons;

/// diagnostic_msgs/DiagnosticStatus' levels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// All is well (0).
    Ok,
    /// Working, with something to look at (1).
    Warn,
    /// Not working as it should (2).
    Error,
    /// No recent information (3).
    Stale,
}

impl Level {
    /// The message's byte.
    pub fn byte(self) -> u8 {
        match self {
            Level::Ok => 0,
            Level::Warn => 1,
            Level::Error => 2,
            Level::Stale => 3,
        }
    }
}

/// One diagnostic status: a level, a message, the figures behind it.
#[derive(Debug, Clone, PartialEq)]
pub struct Health {
    /// The level.
    pub level: Level,
    /// One line: what is wrong, or what the node is doing.
    pub message: String,
    /// Key–value pairs, in a fixed order.
    pub values: Vec<(String, String)>,
}

impl Health {
    /// A status of `level` with `message` and the fixed-order `values` (key, value).
    pub fn new<const N: usize>(level: Level, message: String, values: [(&str, String); N]) -> Self {
        Health {
            level,
            message,
            values: values.into_iter().map(|(k, v)| (k.to_owned(), v)).collect(),
        }
    }
}

/// The age of an input for a value: seconds with three decimals, or `never`.
pub fn age_text(age: Option<f64>) -> String {
    age.map_or_else(|| "never".to_owned(), |a| format!("{a:.3}"))
}

/// What the chassis reports from, once a period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChassisReport {
    /// The safety gate's state now.
    pub safety: Safety,
    /// The inputs' ages now.
    pub ages: InputAges,
    /// What the limits changed in the last command.
    pub clamped: ClampReasons,
    /// Input messages rejected since the start.
    pub rejected_total: u64,
    /// Input messages rejected since the last report.
    pub rejected_new: u64,
}

/// The chassis' health, the worst first: ERROR while the wheel feedback is stale (the
/// odometry stops and the wheels are held); WARN after a non-finite `cmd_vel` (the wheels
/// stopped for it) or when input messages were rejected since the last report; else OK,
/// driving or idle (no `cmd_vel` within its timeout: an idle robot is well). The values: both
/// inputs' ages, the watchdogs, the limits that bound the last command, the rejections.
pub fn chassis_health(r: &ChassisReport) -> Health {
    let s = &r.safety;
    let (level, message) = if s.feedback_stale {
        let text = match r.ages.feedback_s {
            Some(a) => format!("no valid joint_states for {a:.2} s: odometry stale, wheels stopped"),
            None => "no valid joint_states yet: odometry stale, wheels stopped".to_owned(),
        };
        (Level::Error, text)
    } else if s.cmd_vel_refused {
        (
            Level::Warn,
            "the last cmd_vel was not finite: wheels stopped".to_owned(),
        )
    } else if r.rejected_new > 0 {
        (
            Level::Warn,
            format!("{} input message(s) rejected since the last report", r.rejected_new),
        )
    } else if s.cmd_vel_expired {
        (Level::Ok, "idle: no cmd_vel, wheels stopped".to_owned())
    } else {
        (Level::Ok, "driving".to_owned())
    };
    let clamped: Vec<&str> = r.clamped.iter().map(|c| c.as_str()).collect();
    let values = [
        ("cmd_vel age [s]", age_text(r.ages.cmd_vel_s)),
        ("joint_states age [s]", age_text(r.ages.feedback_s)),
        (
            "cmd_vel watchdog",
            if s.cmd_vel_expired { "expired" } else { "ok" }.to_owned(),
        ),
        (
            "feedback watchdog",
            if s.feedback_stale { "stale" } else { "ok" }.to_owned(),
        ),
        (
            "clamped",
            if clamped.is_empty() {
                "none".to_owned()
            } else {
                clamped.join(", ")
            },
        ),
        ("rejected messages", r.rejected_total.to_string()),
    ];
    Health::new(level, message, values)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::ClampReason;

    fn report(expired: bool, refused: bool, stale: bool, rejected_new: u64) -> ChassisReport {
        ChassisReport {
            safety: Safety {
                cmd_vel_expired: expired,
                cmd_vel_refused: refused,
                feedback_stale: stale,
            },
            ages: InputAges {
                cmd_vel_s: Some(0.1),
                feedback_s: None,
            },
            clamped: [ClampReason::Speed, ClampReason::MinRadius].into_iter().collect(),
            rejected_total: 7,
            rejected_new,
        }
    }

    /// The worst state decides: stale feedback over a refused cmd_vel over rejections over
    /// idleness.
    #[test]
    fn the_worst_state_decides_the_level() {
        let h = chassis_health(&report(true, true, true, 3));
        assert_eq!(h.level, Level::Error);
        assert_eq!(h.message, "no valid joint_states yet: odometry stale, wheels stopped");
        assert_eq!(chassis_health(&report(true, true, false, 3)).level, Level::Warn);
        let rejected = chassis_health(&report(false, false, false, 3));
        assert_eq!(
            (rejected.level, rejected.message.as_str()),
            (Level::Warn, "3 input message(s) rejected since the last report")
        );
        let idle = chassis_health(&report(true, false, false, 0));
        assert_eq!(
            (idle.level, idle.message.as_str()),
            (Level::Ok, "idle: no cmd_vel, wheels stopped")
        );
        assert_eq!(chassis_health(&report(false, false, false, 0)).message, "driving");
    }

    #[test]
    fn the_values_carry_the_figures() {
        let h = chassis_health(&report(false, false, true, 0));
        let get = |k: &str| h.values.iter().find(|(key, _)| key == k).map(|(_, v)| v.as_str());
        assert_eq!(get("cmd_vel age [s]"), Some("0.100"));
        assert_eq!(get("joint_states age [s]"), Some("never"));
        assert_eq!(get("feedback watchdog"), Some("stale"));
        assert_eq!(get("clamped"), Some("speed, min_radius"));
        assert_eq!(get("rejected messages"), Some("7"));
        assert_eq!(
            [Level::Ok, Level::Warn, Level::Error, Level::Stale].map(Level::byte),
            [0, 1, 2, 3]
        );
    }
}
