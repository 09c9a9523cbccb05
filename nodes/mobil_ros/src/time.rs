//! Conversions between ROS message stamps and seconds.

use mobil_msgs::builtin_interfaces::msg::Time;

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
