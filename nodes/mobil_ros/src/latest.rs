//! The latest value of an input, with its age: the one way a node decides that an input is
//! stale.
//!
//! A [`Latest`] keeps the last value, the stamp it carried (ROS time, for the algorithm) and the
//! steady-clock instant it arrived (for freshness). Freshness is judged on the steady clock only
//! (see [`crate::time`]): a stalled or reset `/clock` must not make a dead input look alive.
//!
//! ```
//! use mobil_ros::latest::{Freshness, Latest};
//! use std::time::{Duration, Instant};
//!
//! let mut scan = Latest::new();
//! let t0 = Instant::now();
//! assert_eq!(scan.status_at(Duration::from_millis(500), t0), Freshness::Never);
//! scan.set_at(42u32, Default::default(), t0);
//! assert_eq!(scan.get_at(Duration::from_millis(500), t0 + Duration::from_millis(200)), Some(&42));
//! assert_eq!(
//!     scan.status_at(Duration::from_millis(500), t0 + Duration::from_millis(700)),
//!     Freshness::Stale { age: Duration::from_millis(700) }
//! );
//! ```

use mobil_msgs::builtin_interfaces::msg::Time;
use std::time::{Duration, Instant};

/// How fresh an input is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Freshness {
    /// Received no longer than `max_age` ago.
    Fresh,
    /// Received, but longer ago than `max_age`.
    Stale {
        /// Time since it arrived (steady clock).
        age: Duration,
    },
    /// Never received (or cleared).
    Never,
}

/// The latest value of an input, its message stamp and its steady receive instant.
#[derive(Debug, Clone)]
pub struct Latest<T> {
    last: Option<(T, Time, Instant)>,
}

impl<T> Default for Latest<T> {
    fn default() -> Self {
        Latest { last: None }
    }
}

impl<T> Latest<T> {
    /// Nothing received yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Stores a value that arrives now.
    pub fn set(&mut self, value: T, stamp: Time) {
        self.set_at(value, stamp, Instant::now());
    }

    /// Stores a value that arrived at `received` (steady clock).
    pub fn set_at(&mut self, value: T, stamp: Time, received: Instant) {
        self.last = Some((value, stamp, received));
    }

    /// Forgets the value (e.g. after the source was found invalid): the input counts as never
    /// received.
    pub fn clear(&mut self) {
        self.last = None;
    }

    /// How fresh the input is now, for a maximum age.
    pub fn status(&self, max_age: Duration) -> Freshness {
        self.status_at(max_age, Instant::now())
    }

    /// How fresh the input is at `now` (steady clock). An arrival "after" `now` counts as age 0.
    pub fn status_at(&self, max_age: Duration, now: Instant) -> Freshness {
        match self.age_at(now) {
            None => Freshness::Never,
            Some(age) => {
                if age <= max_age {
                    Freshness::Fresh
                } else {
                    Freshness::Stale { age }
                }
            }
        }
    }

    /// Time since the value arrived (steady clock), `None` if never received: for a safety gate
    /// that applies its own timeout (see `ChassisController::gate`).
    pub fn age(&self) -> Option<Duration> {
        self.age_at(Instant::now())
    }

    /// Time since the value arrived, at `now` (steady clock); an arrival "after" `now` is age 0.
    pub fn age_at(&self, now: Instant) -> Option<Duration> {
        self.last
            .as_ref()
            .map(|(_, _, received)| now.saturating_duration_since(*received))
    }

    /// The value if it is fresh now.
    pub fn get(&self, max_age: Duration) -> Option<&T> {
        self.get_at(max_age, Instant::now())
    }

    /// The value if it is fresh at `now` (steady clock).
    pub fn get_at(&self, max_age: Duration, now: Instant) -> Option<&T> {
        match self.status_at(max_age, now) {
            Freshness::Fresh => self.last.as_ref().map(|(v, _, _)| v),
            _ => None,
        }
    }

    /// The value, however old (for reports; decisions use [`Latest::get`]).
    pub fn value(&self) -> Option<&T> {
        self.last.as_ref().map(|(v, _, _)| v)
    }

    /// The stamp the value carried (ROS time).
    pub fn stamp(&self) -> Option<&Time> {
        self.last.as_ref().map(|(_, s, _)| s)
    }

    /// When the value arrived (steady clock).
    pub fn received(&self) -> Option<Instant> {
        self.last.as_ref().map(|(_, _, r)| *r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn freshness_follows_the_steady_age_not_the_stamp() {
        let ms = Duration::from_millis;
        let t0 = Instant::now();
        let mut l = Latest::new();
        assert_eq!(l.status_at(ms(500), t0), Freshness::Never);
        assert_eq!(l.get_at(ms(500), t0), None);
        // A stamp far in the past (a sim clock at 3 s) does not make the value stale...
        l.set_at("a", Time { sec: 3, nanosec: 0 }, t0);
        assert_eq!(
            l.get_at(ms(500), t0 + ms(500)),
            Some(&"a"),
            "exactly max_age: still fresh"
        );
        // ...its arrival 501 ms ago does.
        assert_eq!(l.status_at(ms(500), t0 + ms(501)), Freshness::Stale { age: ms(501) });
        assert_eq!(l.age_at(t0 + ms(501)), Some(ms(501)));
        assert_eq!(
            l.age_at(t0 - ms(1)),
            Some(ms(0)),
            "an instant before the arrival: age 0"
        );
        assert_eq!(l.get_at(ms(500), t0 + ms(501)), None);
        assert_eq!(l.value(), Some(&"a"), "the value stays readable for reports");
        assert_eq!(l.stamp().map(|s| s.sec), Some(3));
        // A newer value makes it fresh again; an arrival after `now` counts as age 0.
        l.set_at("b", Time::default(), t0 + ms(900));
        assert_eq!(l.status_at(ms(100), t0 + ms(800)), Freshness::Fresh);
        assert_eq!(l.get_at(ms(100), t0 + ms(1000)), Some(&"b"));
        l.clear();
        assert_eq!(l.status_at(ms(100), t0 + ms(1000)), Freshness::Never);
        assert_eq!(l.age_at(t0 + ms(1000)), None);
    }
}
