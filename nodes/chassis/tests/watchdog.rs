//! cmd_vel watchdog (angle wrapping is tested in mobil_geom).

use mobil_chassis::CmdVelWatchdog;

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
