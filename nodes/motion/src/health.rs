//! What a motion node (one that drives goals through the motion server) reports on
//! `/diagnostics`: its state, the goal, the ages of the inputs a goal needs and whether the
//! robot is held for a stopped clock ([`motion_health`]). No clock and no ROS: the node gives
//! what it measured.
//!
//! ```
//! use mobil_chassis::health::Level;
//! use mobil_motion::health::{motion_health, InputAge, MotionReport};
//!
//! let report = MotionReport {
//!     goal: None,
//!     mode: "idle".into(),
//!     inputs: vec![InputAge { name: "odom", age_s: Some(3.5), timeout_s: 2.0 }],
//!     clock_held_s: None,
//!     last_end: Some("SUCCEEDED".into()),
//! };
//! let health = motion_health(&report);
//! assert_eq!(health.level, Level::Warn);
//! assert_eq!(health.message, "idle; odom 3.50 s old (timeout 2.00 s): a goal would fail (stale input)");
//! ```

use mobil_chassis::health::{age_text, Health, Level};

/// The age of one input a goal needs, against its timeout.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputAge {
    /// Its name (`odom`, `scan`).
    pub name: &'static str,
    /// The age of its last valid message (s; `None`: never).
    pub age_s: Option<f64>,
    /// How old it may get (s).
    pub timeout_s: f64,
}

impl InputAge {
    /// Older than its timeout, or never received.
    pub fn stale(&self) -> bool {
        self.age_s.is_none_or(|a| a.is_nan() || a > self.timeout_s)
    }
}

/// What a motion node reports from, once a period.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionReport {
    /// The active goal, as the log names it (its source, target and frame); `None`: idle.
    pub goal: Option<String>,
    /// The law's mode or phase (`idle` with no goal).
    pub mode: String,
    /// The inputs a goal needs.
    pub inputs: Vec<InputAge>,
    /// How long ROS time has stood still while the robot is held for it (s).
    pub clock_held_s: Option<f64>,
    /// How the last goal ended (its code), if one did.
    pub last_end: Option<String>,
}

/// The node's health, the worst first: with a goal, ERROR while the robot is held for a
/// stopped clock or an input is stale (the goal is ending `STALE_INPUT`); idle, WARN when an
/// input is stale (a goal would fail (stale input) or end at once); else OK, active or idle. The
/// values: the state, the goal, the mode, each input's age and timeout, the last end.
pub fn motion_health(r: &MotionReport) -> Health {
    let stale: Vec<String> = r
        .inputs
        .iter()
        .filter(|i| i.stale())
        .map(|i| match i.age_s {
            Some(a) => format!("{} {a:.2} s old (timeout {:.2} s)", i.name, i.timeout_s),
            None => format!("{} never received", i.name),
        })
        .collect();
    let (level, message) = match (&r.goal, r.clock_held_s, stale.is_empty()) {
        (Some(_), Some(held), _) => (
            Level::Error,
            format!("goal active, robot held: ROS time has not advanced for {held:.1} s"),
        ),
        (Some(_), None, false) => (
            Level::Error,
            format!("goal active; {}: robot stopped", stale.join(", ")),
        ),
        (Some(goal), None, true) => (Level::Ok, format!("active: {goal} ({})", r.mode)),
        (None, _, false) => (
            Level::Warn,
            format!("idle; {}: a goal would fail (stale input)", stale.join(", ")),
        ),
        (None, _, true) => (Level::Ok, "idle".to_owned()),
    };
    let mut values = vec![
        (
            "state".to_owned(),
            if r.goal.is_some() { "active" } else { "idle" }.to_owned(),
        ),
        ("goal".to_owned(), r.goal.clone().unwrap_or_else(|| "none".to_owned())),
        ("mode".to_owned(), r.mode.clone()),
    ];
    for i in &r.inputs {
        values.push((format!("{} age [s]", i.name), age_text(i.age_s)));
        values.push((format!("{} timeout [s]", i.name), format!("{:.3}", i.timeout_s)));
    }
    values.push((
        "clock".to_owned(),
        r.clock_held_s
            .map_or_else(|| "running".to_owned(), |s| format!("stopped {s:.1} s")),
    ));
    values.push((
        "last end".to_owned(),
        r.last_end.clone().unwrap_or_else(|| "none".to_owned()),
    ));
    Health { level, message, values }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(goal: bool, odom_age: Option<f64>, held: Option<f64>) -> MotionReport {
        MotionReport {
            goal: goal.then(|| "dock_pose (1.000, 0.500) in map".to_owned()),
            mode: if goal { "dock" } else { "idle" }.to_owned(),
            inputs: vec![
                InputAge {
                    name: "odom",
                    age_s: odom_age,
                    timeout_s: 0.5,
                },
                InputAge {
                    name: "scan",
                    age_s: Some(0.1),
                    timeout_s: 1.0,
                },
            ],
            clock_held_s: held,
            last_end: None,
        }
    }

    #[test]
    fn the_worst_first_and_every_figure_in_the_values() {
        let ok = motion_health(&report(true, Some(0.02), None));
        assert_eq!(
            (ok.level, ok.message.as_str()),
            (Level::Ok, "active: dock_pose (1.000, 0.500) in map (dock)")
        );
        let keys: Vec<&str> = ok.values.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(
            keys,
            [
                "state",
                "goal",
                "mode",
                "odom age [s]",
                "odom timeout [s]",
                "scan age [s]",
                "scan timeout [s]",
                "clock",
                "last end"
            ]
        );
        assert_eq!(ok.values[3].1, "0.020");
        let held = motion_health(&report(true, Some(0.02), Some(2.5)));
        assert_eq!(
            (held.level, held.message.as_str()),
            (
                Level::Error,
                "goal active, robot held: ROS time has not advanced for 2.5 s"
            )
        );
        assert_eq!(held.values[7].1, "stopped 2.5 s");
        let stale = motion_health(&report(true, Some(0.75), None));
        assert_eq!(
            (stale.level, stale.message.as_str()),
            (
                Level::Error,
                "goal active; odom 0.75 s old (timeout 0.50 s): robot stopped"
            )
        );
        let never = motion_health(&report(false, None, None));
        assert_eq!(
            (never.level, never.message.as_str()),
            (
                Level::Warn,
                "idle; odom never received: a goal would fail (stale input)"
            )
        );
        assert_eq!(never.values[3].1, "never");
        let idle = motion_health(&report(false, Some(0.4), None));
        assert_eq!((idle.level, idle.message.as_str()), (Level::Ok, "idle"));
        // A NaN age is no fresh input.
        assert!(InputAge {
            name: "odom",
            age_s: Some(f64::NAN),
            timeout_s: 1.0
        }
        .stale());
    }
}
