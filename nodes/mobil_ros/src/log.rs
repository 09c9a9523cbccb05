//! Logging: `tracing` to stderr (also capturing ros2-client's and RustDDS's `log` records), with
//! the level from `--log-level` or `RUST_LOG`, and a throttle so that a flood of bad input
//! produces one clear line per period, with a count of what was suppressed.

use std::collections::HashMap;
use std::time::{Duration, Instant};
use tracing_subscriber::EnvFilter;

/// Installs the global subscriber. `level` is `--log-level` (`debug`, `info`, …), if given.
/// Calling it twice is harmless (the second call does nothing).
pub fn init(level: Option<&str>) {
    let base = match level.map(|l| l.rsplit(":=").next().unwrap_or(l).to_ascii_lowercase()) {
        Some(l) if l == "fatal" => "error".to_owned(),
        Some(l) => l,
        None => std::env::var("RUST_LOG").unwrap_or_else(|_| "info".to_owned()),
    };
    // The DDS stack is chatty at info; keep it at warn unless asked for explicitly. RustDDS's
    // discovery database reports an "inconsistent topic" error for /clock in every process:
    // ros2-client's spinner subscribes to it as builtin_interfaces/Time while rclpy, Gazebo and
    // sim_node publish rosgraph_msgs/Clock (same bytes). Only that module is silenced.
    const QUIET: &str = "rustdds=warn,ros2_client=warn,rustdds::discovery::discovery_db=off";
    let spec = if base.contains('=') {
        base
    } else {
        format!("{base},{QUIET}")
    };
    let filter = EnvFilter::try_new(&spec).unwrap_or_else(|_| EnvFilter::new(format!("info,{QUIET}")));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .with_target(false)
        .try_init();
}

/// Rate limit for log lines, per key.
#[derive(Debug)]
pub struct LogThrottle {
    period: Duration,
    last: HashMap<&'static str, (Instant, u64)>,
}

impl LogThrottle {
    /// At most one line per key per `period`.
    pub fn new(period: Duration) -> Self {
        LogThrottle {
            period,
            last: HashMap::new(),
        }
    }

    /// `Some(n)` when a line for `key` may be written now, `n` being how many were suppressed
    /// since the last one; `None` to stay quiet.
    pub fn allow(&mut self, key: &'static str, now: Instant) -> Option<u64> {
        match self.last.get_mut(key) {
            Some((at, suppressed)) if now.saturating_duration_since(*at) < self.period => {
                *suppressed += 1;
                None
            }
            Some((at, suppressed)) => {
                let n = *suppressed;
                *at = now;
                *suppressed = 0;
                Some(n)
            }
            None => {
                self.last.insert(key, (now, 0));
                Some(0)
            }
        }
    }
}

impl Default for LogThrottle {
    /// One line per key every 2 s.
    fn default() -> Self {
        Self::new(Duration::from_secs(2))
    }
}

/// Logs a warning through a [`LogThrottle`]: `warn_throttled!(throttle, "key", "text {}", x)`.
#[macro_export]
macro_rules! warn_throttled {
    ($throttle:expr, $key:expr, $($arg:tt)+) => {
        if let Some(suppressed) = $throttle.allow($key, ::std::time::Instant::now()) {
            if suppressed > 0 {
                ::tracing::warn!("{} ({} similar suppressed)", format_args!($($arg)+), suppressed);
            } else {
                ::tracing::warn!($($arg)+);
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn throttles_per_key_and_counts_suppressed() {
        let mut t = LogThrottle::new(Duration::from_secs(1));
        let t0 = Instant::now();
        assert_eq!(t.allow("nan", t0), Some(0));
        assert_eq!(t.allow("nan", t0 + Duration::from_millis(10)), None);
        assert_eq!(t.allow("nan", t0 + Duration::from_millis(20)), None);
        assert_eq!(t.allow("len", t0 + Duration::from_millis(30)), Some(0));
        assert_eq!(t.allow("nan", t0 + Duration::from_millis(1001)), Some(2));
    }
}
