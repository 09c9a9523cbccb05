//! cmd_vel watchdog and angle wrapping.

use std::f64::consts::{PI, TAU};

use mobil_chassis::angles::wrap;
use mobil_chassis::CmdVelWatchdog;
use proptest::prelude::*;

#[test]
fn watchdog_expires_after_the_timeout() {
    let mut w = CmdVelWatchdog::new(0.5).unwrap();
    assert!(w.expired(0.0), "never fed: safe");
    assert!(w.feed(10.0));
    assert!(!w.expired(10.0));
    assert!(!w.expired(10.5), "exactly at the timeout: still alive");
    assert!(w.expired(10.51));
    w.feed(10.4);
    assert!(!w.expired(10.8));
}

#[test]
fn watchdog_disabled_at_zero() {
    let w = CmdVelWatchdog::new(0.0).unwrap();
    assert!(w.is_disabled());
    assert!(!w.expired(1e9));
}

#[test]
fn watchdog_time_backwards_counts_as_expired() {
    let mut w = CmdVelWatchdog::new(0.5).unwrap();
    w.feed(10.0);
    assert!(w.expired(9.99));
    assert!(w.expired(f64::NAN));
    assert!(!w.feed(f64::NAN));
    assert_eq!(w.last_feed(), Some(10.0));
}

#[test]
fn watchdog_refuses_bad_timeouts() {
    assert!(CmdVelWatchdog::new(-0.1).is_err());
    assert!(CmdVelWatchdog::new(f64::NAN).is_err());
}

#[test]
fn wrap_golden() {
    assert_eq!(wrap(-PI), PI);
    assert_eq!(wrap(PI), PI);
    assert_eq!(wrap(0.0), 0.0);
    assert!((wrap(3.0 * PI) - PI).abs() < 1e-15);
    assert!((wrap(-3.0 * PI) - PI).abs() < 1e-15);
    assert!((wrap(1.5 * PI) + 0.5 * PI).abs() < 1e-15);
    assert!((wrap(-7.0) - (-7.0 + TAU)).abs() < 1e-15);
    assert!(wrap(f64::NAN).is_nan());
    assert!(wrap(f64::INFINITY).is_nan());
}

proptest! {
    #[test]
    fn wrap_lands_in_range_and_differs_by_whole_turns(a in -1e4..1e4f64) {
        let w = wrap(a);
        prop_assert!(w > -PI && w <= PI, "{a} → {w}");
        let turns = (a - w) / TAU;
        prop_assert!((turns - turns.round()).abs() < 1e-9, "{a} → {w}");
        prop_assert_eq!(wrap(w), w);
    }
}
