//! Input timeouts (angle wrapping is tested in mobil_geom).

use mobil_chassis::InputTimeout;

#[test]
fn timeout_expires_after_its_length() {
    let w = InputTimeout::new("cmd_vel_timeout_s", 0.5).unwrap();
    assert!(w.expired(None), "never received: safe");
    assert!(!w.expired(Some(0.0)));
    assert!(!w.expired(Some(0.5)), "exactly at the timeout: still alive");
    assert!(w.expired(Some(0.51)));
}

#[test]
fn timeout_disabled_at_zero() {
    let w = InputTimeout::new("cmd_vel_timeout_s", 0.0).unwrap();
    assert!(w.is_disabled());
    assert!(!w.expired(Some(1e9)));
    assert!(!w.expired(None));
}

#[test]
fn an_impossible_age_counts_as_expired() {
    let w = InputTimeout::new("feedback_timeout_s", 0.5).unwrap();
    assert!(w.expired(Some(-0.01)));
    assert!(w.expired(Some(f64::NAN)));
    assert!(w.expired(Some(f64::INFINITY)));
}

#[test]
fn timeout_refuses_bad_lengths() {
    assert!(InputTimeout::new("cmd_vel_timeout_s", -0.1).is_err());
    assert!(InputTimeout::new("cmd_vel_timeout_s", f64::NAN).is_err());
}
