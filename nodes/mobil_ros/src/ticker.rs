//! A periodic tick that follows a rate parameter.
//!
//! [`Ticker`] wraps a tokio interval: it refuses rates that are not positive and finite, keeps
//! its missed-tick behaviour ([`MissedTickBehavior::Delay`] unless asked otherwise) when the
//! rate changes, and restarts only when the rate really changes. Ticks run on the steady clock:
//! a control loop's period is wall time; what the algorithm integrates over comes from ROS time
//! (see [`crate::time::DtClock`]).
//!
//! ```
//! # #[tokio::main(flavor = "current_thread")]
//! # async fn main() -> Result<(), mobil_ros::ticker::RateError> {
//! use mobil_ros::ticker::Ticker;
//! let mut tick = Ticker::new(1000.0)?;
//! tick.tick().await; // the first tick is immediate
//! tick.set_rate(500.0)?; // e.g. from a parameter change
//! assert!(tick.set_rate(0.0).is_err() && tick.rate_hz() == 500.0);
//! tick.tick().await;
//! # Ok(()) }
//! ```

use std::time::Duration;
use thiserror::Error;
use tokio::time::{Instant, Interval, MissedTickBehavior};

/// A rate that cannot drive a ticker.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
#[error("rate {0} Hz is not a positive finite number")]
pub struct RateError(pub f64);

/// A periodic tick at a rate that may change.
#[derive(Debug)]
pub struct Ticker {
    interval: Interval,
    rate_hz: f64,
}

/// The period of a rate, or why the rate cannot drive a ticker (vet a rate parameter with it
/// before applying a change).
pub fn period(rate_hz: f64) -> Result<Duration, RateError> {
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        return Err(RateError(rate_hz));
    }
    Duration::try_from_secs_f64(1.0 / rate_hz)
        .ok()
        .filter(|p| !p.is_zero())
        .ok_or(RateError(rate_hz))
}

impl Ticker {
    /// Ticks at `rate_hz`, delaying after a missed tick (no burst of catch-up ticks).
    pub fn new(rate_hz: f64) -> Result<Self, RateError> {
        Self::with_missed_tick_behavior(rate_hz, MissedTickBehavior::Delay)
    }

    /// Ticks at `rate_hz` with another missed-tick behaviour (a simulator that must catch up
    /// uses [`MissedTickBehavior::Burst`]).
    pub fn with_missed_tick_behavior(rate_hz: f64, behavior: MissedTickBehavior) -> Result<Self, RateError> {
        let mut interval = tokio::time::interval(period(rate_hz)?);
        interval.set_missed_tick_behavior(behavior);
        Ok(Ticker { interval, rate_hz })
    }

    /// The current rate.
    pub fn rate_hz(&self) -> f64 {
        self.rate_hz
    }

    /// The missed-tick behaviour (kept across rate changes).
    pub fn missed_tick_behavior(&self) -> MissedTickBehavior {
        self.interval.missed_tick_behavior()
    }

    /// Changes the rate; the next tick comes one new period from now. The same rate changes
    /// nothing; a bad rate is refused and the old one kept.
    pub fn set_rate(&mut self, rate_hz: f64) -> Result<(), RateError> {
        let p = period(rate_hz)?;
        if rate_hz != self.rate_hz {
            let behavior = self.interval.missed_tick_behavior();
            self.interval = tokio::time::interval_at(Instant::now() + p, p);
            self.interval.set_missed_tick_behavior(behavior);
            self.rate_hz = rate_hz;
        }
        Ok(())
    }

    /// Waits for the next tick.
    pub async fn tick(&mut self) -> Instant {
        self.interval.tick().await
    }

    /// A burst ticker that has fallen more than `max_lag` behind its schedule (the tick
    /// `scheduled` for then, handled at `now`) forgets the ticks it missed: the next one comes
    /// one period after this call. Returns whether it did. A simulator publishing its own clock
    /// calls it on every tick, so that after a stall simulated time goes on at its rate from
    /// where it stood instead of racing through the backlog faster than the nodes it drives can
    /// react; below `max_lag` the burst keeps the rate against timer jitter.
    pub fn drop_backlog(&mut self, scheduled: Instant, now: Instant, max_lag: Duration) -> bool {
        if now.saturating_duration_since(scheduled) > max_lag {
            self.interval.reset();
            true
        } else {
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_rates_are_refused() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e-320] {
            assert!(period(bad).is_err(), "{bad}");
            assert!(Ticker::new(bad).is_err(), "{bad}");
        }
        assert_eq!(period(50.0), Ok(Duration::from_millis(20)));
    }

    // Real time on a shared machine: only lower bounds are asserted (a loaded machine makes
    // ticks late, never early).
    #[tokio::test(flavor = "current_thread")]
    async fn follows_the_rate_and_keeps_delay_across_a_change() {
        let ms = Duration::from_millis;
        let mut t = Ticker::new(100.0).unwrap();
        let first = t.tick().await;
        for _ in 0..10 {
            t.tick().await;
        }
        // Ten periods of 10 ms after the immediate first tick.
        assert!(Instant::now() - first >= ms(99), "{:?}", Instant::now() - first);
        t.set_rate(50.0).unwrap();
        assert_eq!(t.missed_tick_behavior(), MissedTickBehavior::Delay);
        assert!(t.set_rate(f64::NAN).is_err());
        assert_eq!(t.rate_hz(), 50.0);
        let changed = Instant::now();
        t.tick().await;
        // The first tick at the new rate comes one new period (20 ms) after the change.
        assert!(Instant::now() - changed >= ms(19), "{:?}", Instant::now() - changed);
        // Delay: after a stall of 100 ms (five periods), the late tick fires at once and the
        // next one a full period later; a burst would fire the missed ones back to back.
        std::thread::sleep(ms(100));
        t.tick().await;
        let late = Instant::now();
        t.tick().await;
        assert!(Instant::now() - late >= ms(19), "{:?}", Instant::now() - late);
    }

    // A stall of 60 ms at 1 kHz: a burst ticker owes 60 ticks. Within the allowed lag it pays
    // them at once; beyond it (20 ms, less than the stall) the backlog is dropped and the next
    // tick is one period away.
    #[tokio::test(flavor = "current_thread")]
    async fn a_burst_ticker_drops_a_backlog_beyond_the_allowed_lag() {
        let ms = Duration::from_millis;
        let mut t = Ticker::with_missed_tick_behavior(1000.0, MissedTickBehavior::Burst).unwrap();
        t.tick().await;
        std::thread::sleep(ms(60));
        let scheduled = t.tick().await;
        let now = Instant::now();
        assert!(now - scheduled >= ms(59), "{:?}", now - scheduled);
        // Only lower bounds of the lag are known on a loaded machine: a bound of 10 s is never
        // exceeded here.
        assert!(!t.drop_backlog(scheduled, now, ms(10_000)), "within 10 s");
        // Kept: the next missed tick is due already, long before now.
        let next = t.tick().await;
        assert!(next < now, "{:?} after now", next - now);
        assert!(
            t.drop_backlog(next, Instant::now(), ms(20)),
            "about 60 ms behind, over 20 ms"
        );
        let after_drop = t.tick().await;
        assert!(
            after_drop > now,
            "after a drop the next tick is one period after the check"
        );
    }

    #[tokio::test(flavor = "current_thread")]
    async fn a_burst_ticker_keeps_burst_across_a_change() {
        let mut t = Ticker::with_missed_tick_behavior(100.0, MissedTickBehavior::Burst).unwrap();
        t.set_rate(200.0).unwrap();
        assert_eq!(t.missed_tick_behavior(), MissedTickBehavior::Burst);
        assert_eq!(t.rate_hz(), 200.0);
    }
}
