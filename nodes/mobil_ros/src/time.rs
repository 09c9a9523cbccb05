//! Time: which clock for what, and conversions between ROS message stamps and seconds.
//!
//! **The rule.** A node has two clocks, and each question has one of them:
//! - **ROS time** ([`crate::RosNode::now_nanos`]: `/clock` under `use_sim_time`, else the system
//!   clock) stamps messages and gives an algorithm its `dt`. Under a simulator running at 4×
//!   real time, a 50 Hz control tick spans 80 ms of ROS time, and a planner integrating over
//!   20 ms of wall time would be 4× wrong. Take `dt` from [`DtClock`] fed with ROS time (or from
//!   the stamps of the messages integrated, as odometry does).
//! - **The steady clock** ([`std::time::Instant`]) runs watchdogs, freshness
//!   ([`crate::latest::Latest`]) and tick periods ([`crate::ticker::Ticker`]): a stalled, reset
//!   or paused `/clock` must never keep a wheel turning or a stale input alive.
//!
//! ```
//! use mobil_ros::time::{DtClock, DtError};
//! let mut dt = DtClock::new();
//! assert_eq!(dt.step(1_000_000_000), Ok(None)); // the first tick only starts the clock
//! assert_eq!(dt.step(1_080_000_000), Ok(Some(0.08)));
//! assert_eq!(dt.step(1_080_000_000), Err(DtError::Zero));
//! assert!(matches!(dt.step(500_000_000), Err(DtError::Backwards { .. })));
//! assert_eq!(dt.step(520_000_000), Ok(Some(0.02))); // restarted at the reset
//! ```

use mobil_msgs::builtin_interfaces::msg::{Duration as RosDuration, Time};
use thiserror::Error;

/// Why [`DtClock::step`] yields no `dt`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum DtError {
    /// ROS time did not advance since the last tick (a paused or stalled `/clock`): skip the
    /// step.
    #[error("ROS time did not advance since the last tick (clock paused or stalled)")]
    Zero,
    /// ROS time went backwards (a restarted simulation, a clock reset): the clock restarts at
    /// the new time, so the next tick gives a `dt` again.
    #[error("ROS time went backwards by {by_nanos} ns (clock reset?); restarted at the new time")]
    Backwards {
        /// How far back, in nanoseconds.
        by_nanos: i64,
    },
}

/// The `dt` of an algorithm between ticks, measured in ROS time (see the module's rule).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DtClock {
    last_nanos: Option<i64>,
}

impl DtClock {
    /// A clock that has not ticked.
    pub fn new() -> Self {
        Self::default()
    }

    /// Ticks at ROS time `now_nanos`: `Ok(None)` on the first tick, `Ok(Some(dt))` in seconds
    /// after that; zero or negative steps are refused with the reason.
    pub fn step(&mut self, now_nanos: i64) -> Result<Option<f64>, DtError> {
        let Some(last) = self.last_nanos else {
            self.last_nanos = Some(now_nanos);
            return Ok(None);
        };
        match now_nanos.checked_sub(last) {
            Some(0) => Err(DtError::Zero),
            Some(d) if d > 0 => {
                self.last_nanos = Some(now_nanos);
                Ok(Some(d as f64 / 1e9))
            }
            d => {
                self.last_nanos = Some(now_nanos);
                Err(DtError::Backwards {
                    by_nanos: d.map_or(i64::MAX, |d| -d),
                })
            }
        }
    }

    /// Forgets the last tick (the next one starts the clock again).
    pub fn reset(&mut self) {
        self.last_nanos = None;
    }
}

/// What ROS time did since a node last looked ([`ClockWatch::observe`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ClockState {
    /// It advanced (or this is the first look).
    Running,
    /// It has not advanced for this long (steady clock): a paused or stalled `/clock`.
    Stopped(std::time::Duration),
    /// It went back by this many seconds (a restarted simulation, a clock reset); the watch
    /// restarts at the new time.
    Back(f64),
}

/// Watches ROS time on the steady clock: how long it has stood still, and whether it went back.
/// A motion node looks at every watchdog tick (the time rule: a stopped `/clock` must not keep
/// a robot moving, and the node can tell only by the steady clock).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ClockWatch {
    last: Option<(i64, std::time::Instant)>,
}

impl ClockWatch {
    /// A watch that has not looked yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// ROS time is `ros_nanos` at steady instant `now`.
    pub fn observe(&mut self, ros_nanos: i64, now: std::time::Instant) -> ClockState {
        let Some((last, moved_at)) = self.last else {
            self.last = Some((ros_nanos, now));
            return ClockState::Running;
        };
        if ros_nanos == last {
            return ClockState::Stopped(now.saturating_duration_since(moved_at));
        }
        self.last = Some((ros_nanos, now));
        if ros_nanos > last {
            ClockState::Running
        } else {
            ClockState::Back((last - ros_nanos) as f64 * 1e-9)
        }
    }
}

/// A stamp from nanoseconds since the epoch (negative values clamp to 0, as ROS time cannot be).
pub fn stamp_from_nanos(nanos: i64) -> Time {
    let nanos = nanos.max(0);
    Time {
        sec: (nanos / 1_000_000_000).min(i64::from(i32::MAX)) as i32,
        nanosec: (nanos % 1_000_000_000) as u32,
    }
}

/// A stamp from seconds (non-finite or negative → 0).
pub fn stamp_from_secs(secs: f64) -> Time {
    if !secs.is_finite() || secs <= 0.0 {
        return Time::default();
    }
    stamp_from_nanos((secs * 1e9).round().min(i64::MAX as f64) as i64)
}

/// Seconds of a stamp; `None` when `nanosec` is out of range (≥ 1e9), i.e. the stamp is invalid.
pub fn secs_from_stamp(t: &Time) -> Option<f64> {
    (t.nanosec < 1_000_000_000).then(|| f64::from(t.sec) + f64::from(t.nanosec) * 1e-9)
}

/// Nanoseconds of a stamp, exactly; `None` when `nanosec` is out of range.
pub fn nanos_from_stamp(t: &Time) -> Option<i64> {
    (t.nanosec < 1_000_000_000).then(|| i64::from(t.sec) * 1_000_000_000 + i64::from(t.nanosec))
}

/// Whether a stamp is all zero (publishers that do not stamp).
pub fn is_zero(t: &Time) -> bool {
    t.sec == 0 && t.nanosec == 0
}

pub use mobil_motion::seconds;

/// A duration message of `seconds` (navigation time, time remaining): negative (the clock went
/// backwards), NaN or infinite give zero, and it saturates at 10⁹ s.
pub fn duration_msg(seconds: f64) -> RosDuration {
    let s = if seconds.is_finite() {
        seconds.clamp(0.0, 1e9)
    } else {
        0.0
    };
    let sec = s.floor();
    RosDuration {
        sec: sec as i32,
        nanosec: ((s - sec) * 1e9).min(999_999_999.0) as u32,
    }
}

/// The seconds of a duration message (a goal's `time_allowance`): `sec + nanosec·10⁻⁹`, as
/// rclcpp reads one (negative when `sec` is).
pub fn secs_from_duration(d: &RosDuration) -> f64 {
    f64::from(d.sec) + f64::from(d.nanosec) * 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dt_clock_steps_refuses_and_recovers() {
        let mut c = DtClock::new();
        assert_eq!(c.step(2_000_000_000), Ok(None));
        // 2.0 s → 2.25 s: 0.25 s.
        assert_eq!(c.step(2_250_000_000), Ok(Some(0.25)));
        assert_eq!(c.step(2_250_000_000), Err(DtError::Zero));
        // Still 0.25 s past 2.25 s after the refused zero step: 2.5 s − 2.25 s.
        assert_eq!(c.step(2_500_000_000), Ok(Some(0.25)));
        assert_eq!(
            c.step(1_000_000_000),
            Err(DtError::Backwards {
                by_nanos: 1_500_000_000
            })
        );
        assert_eq!(c.step(1_001_000_000), Ok(Some(0.001)));
        c.reset();
        assert_eq!(c.step(5), Ok(None));
    }

    #[test]
    fn a_clock_watch_tells_a_stand_still_by_the_steady_clock_and_a_jump_back() {
        use std::time::{Duration, Instant};
        let mut w = ClockWatch::new();
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        assert_eq!(w.observe(5_000_000_000, t0), ClockState::Running);
        assert_eq!(w.observe(5_000_000_000, t0 + ms(300)), ClockState::Stopped(ms(300)));
        // Still, measured from the last time it moved.
        assert_eq!(w.observe(5_000_000_000, t0 + ms(700)), ClockState::Stopped(ms(700)));
        assert_eq!(w.observe(5_000_000_001, t0 + ms(750)), ClockState::Running);
        assert_eq!(w.observe(5_000_000_001, t0 + ms(800)), ClockState::Stopped(ms(50)));
        // Back 4.5 s: told once, then the watch runs from there.
        assert_eq!(w.observe(500_000_001, t0 + ms(850)), ClockState::Back(4.5));
        assert_eq!(w.observe(600_000_001, t0 + ms(900)), ClockState::Running);
    }

    #[test]
    fn round_trips() {
        let t = stamp_from_secs(12.25);
        assert_eq!((t.sec, t.nanosec), (12, 250_000_000));
        assert_eq!(secs_from_stamp(&t), Some(12.25));
        assert_eq!(
            stamp_from_nanos(1_500_000_001),
            Time {
                sec: 1,
                nanosec: 500_000_001
            }
        );
        assert_eq!(stamp_from_secs(f64::NAN), Time::default());
        assert_eq!(stamp_from_secs(-3.0), Time::default());
        assert_eq!(
            secs_from_stamp(&Time {
                sec: 1,
                nanosec: 1_000_000_000
            }),
            None
        );
    }

    #[test]
    fn durations_never_go_negative() {
        let d = duration_msg(12.25);
        assert_eq!((d.sec, d.nanosec), (12, 250_000_000));
        for bad in [-3.0, f64::NAN, f64::INFINITY] {
            let d = duration_msg(bad);
            assert_eq!((d.sec, d.nanosec), (0, 0), "{bad}");
        }
        assert_eq!(duration_msg(5e9).sec, 1_000_000_000);
    }

    #[test]
    fn durations_read_back_as_seconds() {
        assert_eq!(secs_from_duration(&duration_msg(2.5)), 2.5);
        let d = RosDuration {
            sec: -1,
            nanosec: 500_000_000,
        };
        assert_eq!(secs_from_duration(&d), -0.5);
    }
}
