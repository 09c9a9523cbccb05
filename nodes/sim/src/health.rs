//! What the simulation reports on `/diagnostics` ([`sim_health`]): the rate simulated time
//! runs at against the one asked for, the simulated motor drivers' command watchdog, commands
//! refused, a collision. No clock and no ROS: the node gives what it measured.
//!
//! ```
//! use mobil_chassis::health::Level;
//! use mobil_sim::health::{sim_health, SimReport};
//!
//! let report = SimReport {
//!     factor_asked: 5.0,
//!     factor_measured: Some(3.1),
//!     command_age_s: Some(0.01),
//!     command_timeout_s: 0.5,
//!     commands_refused: 0,
//!     collision: None,
//! };
//! let health = sim_health(&report);
//! assert_eq!(health.level, Level::Warn);
//! assert_eq!(health.message, "simulated time runs at 3.10× real time, 5.00× asked: short of CPU");
//! ```

use mobil_chassis::health::{age_text, Health, Level};

/// The share of the asked real-time factor below which the simulation is reported slow.
pub const SLOW_SHARE: f64 = 0.8;

/// What the simulation reports from, once a period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimReport {
    /// Simulated seconds per wall second asked for (`real_time_factor`).
    pub factor_asked: f64,
    /// Simulated seconds per wall second over the last period (`None`: no period yet).
    pub factor_measured: Option<f64>,
    /// The age of the last valid `wheel_commands` (s; `None`: none yet).
    pub command_age_s: Option<f64>,
    /// The simulated drivers' command timeout (s).
    pub command_timeout_s: f64,
    /// `wheel_commands` refused or dropped since the last report.
    pub commands_refused: u64,
    /// Where the robot first hit an obstacle (x, y), if it did.
    pub collision: Option<(f64, f64)>,
}

/// The simulation's health, the worst first: ERROR once the robot hit an obstacle; WARN when
/// simulated time runs below [`SLOW_SHARE`] of the factor asked (the machine is short of CPU),
/// or commands were refused since the last report; else OK, driven (commands within the
/// drivers' timeout) or idle (wheels stopped). The values: both factors, the command's age and
/// the timeout, the refusals, the collision.
pub fn sim_health(r: &SimReport) -> Health {
    // A timeout of 0 never expires: the drivers keep the last command.
    let driven = r
        .command_age_s
        .is_some_and(|a| r.command_timeout_s <= 0.0 || a <= r.command_timeout_s);
    let slow = r
        .factor_measured
        .filter(|m| m.is_nan() || *m < SLOW_SHARE * r.factor_asked);
    let (level, message) = match (r.collision, slow) {
        (Some((x, y)), _) => (Level::Error, format!("the robot hit an obstacle at ({x:.2}, {y:.2})")),
        (None, Some(m)) => (
            Level::Warn,
            format!(
                "simulated time runs at {m:.2}× real time, {:.2}× asked: short of CPU",
                r.factor_asked
            ),
        ),
        (None, None) if r.commands_refused > 0 => (
            Level::Warn,
            format!(
                "{} wheel_commands refused or dropped since the last report",
                r.commands_refused
            ),
        ),
        (None, None) if driven => (Level::Ok, "driven".to_owned()),
        (None, None) => (Level::Ok, "idle: no wheel_commands, wheels stopped".to_owned()),
    };
    let values = [
        ("real_time_factor asked", format!("{:.3}", r.factor_asked)),
        (
            "real_time_factor measured",
            r.factor_measured
                .map_or_else(|| "not yet".to_owned(), |m| format!("{m:.3}")),
        ),
        ("wheel_commands age [s]", age_text(r.command_age_s)),
        ("command_timeout_s", format!("{:.3}", r.command_timeout_s)),
        ("wheel_commands refused", r.commands_refused.to_string()),
        (
            "collision",
            r.collision
                .map_or_else(|| "none".to_owned(), |(x, y)| format!("({x:.3}, {y:.3})")),
        ),
    ];
    Health::new(level, message, values)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report() -> SimReport {
        SimReport {
            factor_asked: 5.0,
            factor_measured: Some(4.9),
            command_age_s: Some(0.02),
            command_timeout_s: 0.5,
            commands_refused: 0,
            collision: None,
        }
    }

    #[test]
    fn the_worst_first() {
        let ok = sim_health(&report());
        assert_eq!((ok.level, ok.message.as_str()), (Level::Ok, "driven"));
        assert_eq!(
            ok.values[1],
            ("real_time_factor measured".to_owned(), "4.900".to_owned())
        );
        let idle = sim_health(&SimReport {
            command_age_s: Some(0.6),
            ..report()
        });
        assert_eq!(idle.message, "idle: no wheel_commands, wheels stopped");
        // No timeout (0): the drivers keep the last command, however old.
        let kept = sim_health(&SimReport {
            command_age_s: Some(60.0),
            command_timeout_s: 0.0,
            ..report()
        });
        assert_eq!(kept.message, "driven");
        // 4.0 is 0.8 of 5: not slow; 3.99 is.
        let at_share = sim_health(&SimReport {
            factor_measured: Some(4.0),
            ..report()
        });
        assert_eq!(at_share.level, Level::Ok);
        let slow = sim_health(&SimReport {
            factor_measured: Some(3.99),
            ..report()
        });
        assert_eq!(slow.level, Level::Warn);
        let refused = sim_health(&SimReport {
            commands_refused: 3,
            ..report()
        });
        assert_eq!(
            (refused.level, refused.message.as_str()),
            (Level::Warn, "3 wheel_commands refused or dropped since the last report")
        );
        let hit = sim_health(&SimReport {
            collision: Some((1.0, -2.5)),
            factor_measured: Some(1.0),
            ..report()
        });
        assert_eq!(
            (hit.level, hit.message.as_str()),
            (Level::Error, "the robot hit an obstacle at (1.00, -2.50)")
        );
        assert_eq!(hit.values[5].1, "(1.000, -2.500)");
        // No period yet: not slow.
        let first = sim_health(&SimReport {
            factor_measured: None,
            ..report()
        });
        assert_eq!((first.level, first.values[1].1.as_str()), (Level::Ok, "not yet"));
    }
}
