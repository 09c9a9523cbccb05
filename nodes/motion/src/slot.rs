//! A law that steps off the event loop: lent out for a step, late when it comes back after the
//! pose it was given is old.
//!
//! Some laws take longer over a step than the odometry takes to bring the next pose (VFO
//! optimises a segment inside one step, 0.25–1 s). Their steps run on a worker; the node keeps
//! the law in a [`LawSlot`]: [`LawSlot::lend`] hands it out (and `None` while it is out: the node
//! then stops the robot), [`LawSlot::give_back`] takes it home and says whether its command is
//! still [`Handback::Fresh`], or [`Handback::Late`]: worked out for a pose the robot has left,
//! to be replaced by zero. The bound is two periods of the pose stream ([`late_bound`], the
//! period measured by [`ArrivalPeriod`]). Times are inputs: nothing here reads a clock.
//!
//! ```
//! use mobil_motion::slot::{Handback, LawSlot};
//! use std::time::{Duration, Instant};
//!
//! let t0 = Instant::now();
//! let mut slot = LawSlot::new("a law", Duration::from_millis(40));
//! let law = slot.lend(t0).unwrap();
//! assert!(slot.lend(t0).is_none()); // out on a step: the robot stops
//! assert_eq!(slot.give_back(law, t0 + Duration::from_millis(30)), Handback::Fresh);
//! let law = slot.lend(t0).unwrap();
//! assert_eq!(slot.give_back(law, t0 + Duration::from_millis(50)), Handback::Late);
//! ```

use std::time::{Duration, Instant};

/// A law at home, ready for its next step, or lent out for one.
#[derive(Debug)]
pub struct LawSlot<L> {
    home: Option<Box<L>>,
    lent: Option<Instant>,
    max_delay: Duration,
}

/// What to do with the command of a step that came back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Handback {
    /// Send it: it came back within the slot's delay of its pose.
    Fresh,
    /// Send zero instead: it came back later.
    Late,
}

impl<L> LawSlot<L> {
    /// A slot holding `law`; a step back later than `max_delay` after it was lent is late.
    pub fn new(law: L, max_delay: Duration) -> Self {
        LawSlot {
            home: Some(Box::new(law)),
            lent: None,
            max_delay,
        }
    }

    /// The law for a step starting at `now`, or `None` while it is out on one.
    pub fn lend(&mut self, now: Instant) -> Option<Box<L>> {
        let law = self.home.take()?;
        self.lent = Some(now);
        Some(law)
    }

    /// The law back from the step lent out by [`LawSlot::lend`], at `now`.
    pub fn give_back(&mut self, law: Box<L>, now: Instant) -> Handback {
        let since = self.lent.take().unwrap_or(now);
        self.home = Some(law);
        if now.saturating_duration_since(since) > self.max_delay {
            Handback::Late
        } else {
            Handback::Fresh
        }
    }

    /// Whether the law is out on a step.
    pub fn is_lent(&self) -> bool {
        self.home.is_none()
    }

    /// The law when at home.
    pub fn law(&self) -> Option<&L> {
        self.home.as_deref()
    }

    /// The law when at home, to change it between steps.
    pub fn law_mut(&mut self) -> Option<&mut L> {
        self.home.as_deref_mut()
    }

    /// The longest delay of a command that is still sent.
    pub fn max_delay(&self) -> Duration {
        self.max_delay
    }
}

/// The mean period of a stream's arrivals: an exponential mean giving each new interval a
/// weight of 0.1; an interval over [`ArrivalPeriod::PAUSE`] (the stream paused) is not counted.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ArrivalPeriod {
    last: Option<Instant>,
    mean: Option<f64>,
}

impl ArrivalPeriod {
    /// Intervals longer than this are a pause, not the period.
    pub const PAUSE: Duration = Duration::from_secs(1);

    /// One arrival at `at`.
    pub fn arrived(&mut self, at: Instant) {
        if let Some(last) = self.last {
            let gap = at.saturating_duration_since(last);
            if gap <= Self::PAUSE && !gap.is_zero() {
                let gap = gap.as_secs_f64();
                self.mean = Some(self.mean.map_or(gap, |m| m + 0.1 * (gap - m)));
            }
        }
        self.last = Some(at);
    }

    /// The mean period, once two arrivals were seen.
    pub fn period(&self) -> Option<Duration> {
        self.mean.map(Duration::from_secs_f64)
    }
}

/// The shortest [`late_bound`]: a scheduler's jitter.
pub const MIN_LATE_BOUND: Duration = Duration::from_millis(10);

/// The longest delay of a step's command after its pose: two periods of the pose stream (by
/// then a newer pose has come, and the command was worked out for a place the robot has left),
/// at least [`MIN_LATE_BOUND`]; the law's own control step `step_s` (s) until a period was
/// measured.
pub fn late_bound(period: Option<Duration>, step_s: f64) -> Duration {
    period
        .map_or_else(|| Duration::from_secs_f64(step_s.max(0.0)), |p| 2 * p)
        .max(MIN_LATE_BOUND)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slot_lends_once_and_a_late_step_is_told() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let mut slot = LawSlot::new(7_u32, ms(20));
        let law = slot.lend(t0).expect("at home");
        assert!(slot.is_lent());
        // Out on a step: the next step gets nothing.
        assert!(slot.lend(t0 + ms(10)).is_none());
        assert!(slot.law().is_none());
        // Back 20 ms after it went: exactly the bound is still fresh.
        assert_eq!(slot.give_back(law, t0 + ms(20)), Handback::Fresh);
        assert_eq!(slot.law(), Some(&7));
        let law = slot.lend(t0 + ms(30)).expect("home again");
        assert_eq!(slot.give_back(law, t0 + ms(51)), Handback::Late);
        assert!(!slot.is_lent());
        *slot.law_mut().expect("home") = 8;
        assert_eq!(slot.law(), Some(&8));
    }

    #[test]
    fn the_late_bound_is_two_measured_periods() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let mut p = ArrivalPeriod::default();
        assert_eq!(p.period(), None);
        // Before a period is measured: the control step (20 ms), floored at 10 ms.
        assert_eq!(late_bound(p.period(), 0.02), ms(20));
        assert_eq!(late_bound(p.period(), 0.001), MIN_LATE_BOUND);
        // Arrivals every 20 ms: the mean is 20 ms, the bound 40 ms.
        for k in 0..10 {
            p.arrived(t0 + ms(20 * k));
        }
        let period = p.period().expect("measured");
        assert!((period.as_secs_f64() - 0.020).abs() < 1e-9, "{period:?}");
        assert_eq!(late_bound(p.period(), 0.5), 2 * period);
        // A 3 s pause is not a period; one 30 ms interval moves the mean by a tenth: 21 ms.
        p.arrived(t0 + ms(180 + 3000));
        assert!((p.period().expect("kept").as_secs_f64() - 0.020).abs() < 1e-9);
        p.arrived(t0 + ms(180 + 3000 + 30));
        assert!((p.period().expect("kept").as_secs_f64() - 0.021).abs() < 1e-9);
        // Arrivals every 4 ms (odometry at 5× simulated time): the floor, 10 ms.
        let mut fast = ArrivalPeriod::default();
        for k in 0..10 {
            fast.arrived(t0 + ms(4 * k));
        }
        assert_eq!(late_bound(fast.period(), 0.02), MIN_LATE_BOUND);
    }
}
