//! Logging: `tracing` to stderr and `/rosout` (also capturing ros2-client's and RustDDS's `log`
//! records on stderr), with
//! the level from `--log-level` or `RUST_LOG`, and a throttle so that a flood of bad input
//! produces one clear line per period, with a count of what was suppressed.
//!
//! Besides the throttles a node sets on purpose ([`LogThrottle`], [`crate::warn_throttled!`]),
//! every line at info and above has a budget per call site ([`LineBudget`]): a burst of
//! [`BURST_LINES`], then one line per [`LINE_PERIOD`]; the next line let through says how many
//! were suppressed. A storm of goals, a `/clock` at 100 Hz with bad stamps (ros2-client warns of
//! each), any line a node writes per message: none floods stderr or `/rosout`.

use ros2_client::log::LogLevel;
use ros2_client::{NodeLoggingHandle, RosoutRaw};
use std::collections::HashMap;
use std::sync::Mutex;
use std::time::{Duration, Instant};
use tracing::field::{Field, Visit};
use tracing::{Event, Level, Subscriber};
use tracing_subscriber::layer::{self, Layer, SubscriberExt};
use tracing_subscriber::registry::{LookupSpan, SpanRef};
use tracing_subscriber::util::SubscriberInitExt;
use tracing_subscriber::{filter, EnvFilter};

/// Installs the global subscriber. `level` is `--log-level` (`debug`, `info`, …), if given.
/// Calling it twice is harmless (the second call does nothing).
///
/// Besides stderr, the suite's own events at info and above go to `/rosout` (as rclcpp's logs
/// do, so rqt_console and `ros2 topic echo /rosout` show them) once a node is attached with
/// [`attach_rosout`].
pub fn init(level: Option<&str>) {
    let base = match level.map(|l| l.rsplit(":=").next().unwrap_or(l).to_ascii_lowercase()) {
        Some(l) if l == "fatal" => "error".to_owned(),
        Some(l) => l,
        None => std::env::var("RUST_LOG").unwrap_or_else(|_| "info".to_owned()),
    };
    let filter = env_filter(&base);
    // ros2-client echoes every /rosout publication as a tracing event inside a `rosout_raw` span;
    // the console already has the original line.
    let not_an_echo = filter::dynamic_filter_fn(|_, cx| !in_rosout_echo(cx.lookup_current()));
    let fmt = tracing_subscriber::fmt::layer()
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .with_target(false)
        .fmt_fields(NotedFields)
        .with_filter(not_an_echo);
    let _ = tracing_subscriber::registry()
        .with(filter)
        .with(LineBudgetLayer(Mutex::new(LineBudget::default())))
        .with(fmt)
        .with(RosoutLayer)
        .try_init();
}

/// Lines one call site may write at once before its budget holds it back.
pub const BURST_LINES: u32 = 10;

/// Once its burst is spent, a call site may write one line per this period.
pub const LINE_PERIOD: Duration = Duration::from_secs(1);

/// The budget of log lines per call site (module docs), with the clock as an input.
#[derive(Debug, Default)]
pub struct LineBudget {
    sites: HashMap<u64, Site>,
}

/// One call site's budget: its tokens at `at`, and the lines it was refused since it last wrote.
#[derive(Debug, Clone, Copy)]
struct Site {
    tokens: f64,
    at: Instant,
    suppressed: u64,
}

impl LineBudget {
    /// Whether a line of call site `site` may be written at `now`: `Some(n)`, `n` lines of it
    /// having been suppressed since the last one written; `None` to suppress this one.
    pub fn allow(&mut self, site: u64, now: Instant) -> Option<u64> {
        let burst = f64::from(BURST_LINES);
        let s = self.sites.entry(site).or_insert(Site {
            tokens: burst,
            at: now,
            suppressed: 0,
        });
        let refill = now.saturating_duration_since(s.at).as_secs_f64() / LINE_PERIOD.as_secs_f64();
        s.tokens = (s.tokens + refill).min(burst);
        s.at = now;
        if s.tokens < 1.0 {
            s.suppressed += 1;
            return None;
        }
        s.tokens -= 1.0;
        Some(std::mem::take(&mut s.suppressed))
    }
}

thread_local! {
    /// Lines suppressed before the event being written now, from its call site (0: none).
    static SUPPRESSED: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// The call site of an event: its level, target, file and line (a `log` record's own, not the
/// one `tracing-log` forwards every record of a level through; the level tells apart the lines
/// one macro call writes at different levels, as `tell!` does).
fn site_of(event: &Event<'_>) -> u64 {
    use std::hash::{Hash, Hasher};
    use tracing_log::NormalizeEvent;
    let normalized = event.normalized_metadata();
    let meta = normalized.as_ref().unwrap_or_else(|| event.metadata());
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (meta.level().as_str(), meta.target(), meta.file(), meta.line()).hash(&mut h);
    h.finish()
}

/// Holds every event at info and above to its call site's [`LineBudget`]; the count of what it
/// suppressed goes with the next line it lets through ([`NotedFields`], `/rosout`).
struct LineBudgetLayer(Mutex<LineBudget>);

impl<S: Subscriber> Layer<S> for LineBudgetLayer {
    fn event_enabled(&self, event: &Event<'_>, _: layer::Context<'_, S>) -> bool {
        SUPPRESSED.with(|c| c.set(0));
        if *event.metadata().level() > Level::INFO {
            return true;
        }
        let Ok(mut budget) = self.0.lock() else { return true };
        match budget.allow(site_of(event), Instant::now()) {
            Some(n) => {
                SUPPRESSED.with(|c| c.set(n));
                true
            }
            None => false,
        }
    }
}

/// The fields of an event as `tracing-subscriber` writes them, then the count of lines its call
/// site had suppressed before it, if any.
struct NotedFields;

impl<'w> tracing_subscriber::fmt::FormatFields<'w> for NotedFields {
    fn format_fields<R: tracing_subscriber::field::RecordFields>(
        &self,
        mut writer: tracing_subscriber::fmt::format::Writer<'w>,
        fields: R,
    ) -> std::fmt::Result {
        tracing_subscriber::fmt::format::DefaultFields::new().format_fields(writer.by_ref(), fields)?;
        match SUPPRESSED.with(|c| c.get()) {
            0 => Ok(()),
            n => write!(writer, " ({n} similar lines suppressed)"),
        }
    }
}

/// The filter for a base level (`info`, …), or exactly the directives given when `base` holds
/// any (`RUST_LOG=rustdds=debug`).
///
/// The DDS stack is chatty at info; it is kept at warn unless asked for explicitly. RustDDS's
/// discovery database reports an "inconsistent topic" error for /clock in every process:
/// ros2-client's spinner subscribes to it as builtin_interfaces/Time while rclpy, Gazebo and
/// sim_node publish rosgraph_msgs/Clock (same bytes). Only that module is silenced. The CDR
/// decoder warns once per malformed sample, unthrottled, about a fault the node reports itself
/// (rate-limited, with the same reason), so a flood of bad input would flood the log and
/// `/rosout`: it is kept at error.
fn env_filter(base: &str) -> EnvFilter {
    const QUIET: &str = "rustdds=warn,ros2_client=warn,rustdds::discovery::discovery_db=off,cdr_encoding=error";
    let spec = if base.contains('=') {
        base.to_owned()
    } else {
        format!("{base},{QUIET}")
    };
    EnvFilter::try_new(&spec).unwrap_or_else(|_| EnvFilter::new(format!("info,{QUIET}")))
}

fn in_rosout_echo<S: for<'a> LookupSpan<'a>>(span: Option<SpanRef<'_, S>>) -> bool {
    span.is_some_and(|s| s.scope().any(|s| s.name() == "rosout_raw"))
}

/// Where [`RosoutLayer`] publishes: the running node's `/rosout` writer.
static ROSOUT: Mutex<Option<NodeLoggingHandle>> = Mutex::new(None);

/// Sends the process's log lines to this node's `/rosout` from now on.
pub fn attach_rosout(handle: NodeLoggingHandle) {
    if let Ok(mut slot) = ROSOUT.lock() {
        *slot = Some(handle);
    }
}

/// Stops sending to `/rosout` (before the node's writers go away at shutdown).
pub fn detach_rosout() {
    if let Ok(mut slot) = ROSOUT.lock() {
        *slot = None;
    }
}

/// Forwards the suite's own events (info and above) to `/rosout`. The outermost layer: it sees
/// each event last.
struct RosoutLayer;

impl<S: Subscriber + for<'a> LookupSpan<'a>> Layer<S> for RosoutLayer {
    fn on_event(&self, event: &Event<'_>, cx: layer::Context<'_, S>) {
        // The last layer to see the event: the count goes with it and no further (a span's
        // fields formatted later must not carry it).
        let suppressed = SUPPRESSED.with(|c| c.replace(0));
        let meta = event.metadata();
        let level = match *meta.level() {
            Level::ERROR => LogLevel::Error,
            Level::WARN => LogLevel::Warn,
            Level::INFO => LogLevel::Info,
            _ => return,
        };
        if meta.target().starts_with("rustdds") || meta.target().starts_with("ros2_client") {
            return;
        }
        if in_rosout_echo(cx.event_span(event)) || in_rosout_echo(cx.lookup_current()) {
            return;
        }
        // try_lock: an event raised while publishing (nested) is not forwarded again.
        let Ok(slot) = ROSOUT.try_lock() else { return };
        let Some(handle) = slot.as_ref() else { return };
        let mut text = MessageText(String::new());
        event.record(&mut text);
        if suppressed > 0 {
            text.0 += &format!(" ({suppressed} similar lines suppressed)");
        }
        handle.rosout_raw(
            ros2_client::builtin_interfaces::Time::now(),
            level,
            handle.base_name(),
            &text.0,
            meta.file().unwrap_or(""),
            meta.module_path().unwrap_or(""),
            meta.line().unwrap_or(0),
        );
    }
}

/// The `message` field of an event.
struct MessageText(String);

impl Visit for MessageText {
    fn record_debug(&mut self, field: &Field, value: &dyn std::fmt::Debug) {
        if field.name() == "message" {
            self.0 = format!("{value:?}");
        }
    }

    fn record_str(&mut self, field: &Field, value: &str) {
        if field.name() == "message" {
            self.0 = value.to_owned();
        }
    }
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

/// Logs notices ([`mobil_motion::Notice`]) where the macro is called, so each line carries the
/// node's target, file and line: `tell!(throttle, notices)`, each info and warning as it is, a
/// recurring warning rate-limited under its key by the [`LogThrottle`] `throttle`.
#[macro_export]
macro_rules! tell {
    ($throttle:expr, $notices:expr) => {
        for notice in ::std::iter::IntoIterator::into_iter($notices) {
            match notice {
                $crate::Notice::Info(text) => ::tracing::info!("{text}"),
                $crate::Notice::Warn(text) => ::tracing::warn!("{text}"),
                $crate::Notice::Recurring(key, text) => $crate::warn_throttled!($throttle, key, "{text}"),
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    /// Records the level and target of every event that passes the filter.
    struct Count(Arc<Mutex<Vec<String>>>);

    impl<S: Subscriber> Layer<S> for Count {
        fn on_event(&self, event: &Event<'_>, _: layer::Context<'_, S>) {
            if let Ok(mut seen) = self.0.lock() {
                seen.push(format!("{} {}", event.metadata().level(), event.metadata().target()));
            }
        }
    }

    #[test]
    fn the_cdr_decoder_does_not_log_each_malformed_sample() {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let subscriber = tracing_subscriber::registry()
            .with(env_filter("info"))
            .with(Count(seen.clone()));
        tracing::subscriber::with_default(subscriber, || {
            for _ in 0..100 {
                tracing::warn!(target: "cdr_encoding::cdr_deserializer", "deserialize_str: Expected string null terminator");
            }
            tracing::error!(target: "cdr_encoding::cdr_deserializer", "an error is still shown");
            tracing::warn!(target: "rustdds::dds::reader", "so is RustDDS at warn");
            tracing::info!(target: "rustdds::dds::reader", "but not at info");
            tracing::warn!(target: "chassis_node", "undecodable cmd_vel dropped");
            tracing::info!(target: "chassis_node", "and the node's own info");
        });
        let seen = seen.lock().map(|s| s.clone()).unwrap_or_default();
        assert_eq!(
            seen,
            [
                "ERROR cdr_encoding::cdr_deserializer",
                "WARN rustdds::dds::reader",
                "WARN chassis_node",
                "INFO chassis_node"
            ]
        );
        // Directives given in full are taken as they are.
        let seen_all = Arc::new(Mutex::new(Vec::new()));
        let subscriber = tracing_subscriber::registry()
            .with(env_filter("cdr_encoding=warn"))
            .with(Count(seen_all.clone()));
        tracing::subscriber::with_default(subscriber, || {
            tracing::warn!(target: "cdr_encoding::cdr_deserializer", "shown when asked for");
        });
        assert_eq!(seen_all.lock().map(|s| s.len()).unwrap_or_default(), 1);
    }

    #[test]
    fn notices_are_told_at_their_level_and_a_recurring_one_once_per_period() {
        use mobil_motion::Notice;
        let seen = Arc::new(Mutex::new(Vec::new()));
        let subscriber = tracing_subscriber::registry().with(Count(seen.clone()));
        let mut throttle = LogThrottle::new(Duration::from_secs(60));
        tracing::subscriber::with_default(subscriber, || {
            for _ in 0..3 {
                crate::tell!(
                    throttle,
                    [
                        Notice::Info("reached".into()),
                        Notice::Warn("missed".into()),
                        Notice::Recurring("late", "a tick came late".into()),
                    ]
                );
            }
        });
        let seen = seen.lock().map(|s| s.clone()).unwrap_or_default();
        let here = module_path!();
        let lines = |level: &str| seen.iter().filter(|s| **s == format!("{level} {here}")).count();
        // Three of each line as it is; the recurring warning once in the minute.
        assert_eq!((lines("INFO"), lines("WARN")), (3, 3 + 1), "{seen:?}");
        assert_eq!(
            throttle.allow("late", Instant::now()),
            None,
            "two suppressed, still quiet"
        );
    }

    #[test]
    fn a_call_site_writes_its_burst_then_one_line_per_period_and_tells_what_it_held_back() {
        let mut b = LineBudget::default();
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        for _ in 0..BURST_LINES {
            assert_eq!(b.allow(1, t0), Some(0));
        }
        for _ in 0..5 {
            assert_eq!(b.allow(1, t0), None);
        }
        // Another call site has a budget of its own.
        assert_eq!(b.allow(2, t0), Some(0));
        // Half a period later half a line has come back: still held.
        assert_eq!(b.allow(1, t0 + ms(500)), None);
        // A period: one line, telling the six held back.
        assert_eq!(b.allow(1, t0 + ms(1000)), Some(6));
        assert_eq!(b.allow(1, t0 + ms(1000)), None);
        // A quiet minute refills the burst, and no more than the burst.
        let t1 = t0 + Duration::from_secs(61);
        assert_eq!(b.allow(1, t1), Some(1));
        for _ in 1..BURST_LINES {
            assert_eq!(b.allow(1, t1), Some(0));
        }
        assert_eq!(b.allow(1, t1), None);
    }

    #[test]
    fn the_budget_holds_back_a_flood_from_one_site_and_the_next_line_tells_the_count() {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let subscriber = tracing_subscriber::registry()
            .with(LineBudgetLayer(Mutex::new(LineBudget::default())))
            .with(Count(seen.clone()));
        tracing::subscriber::with_default(subscriber, || {
            for _ in 0..100 {
                tracing::warn!("goal refused");
            }
            tracing::info!("another site");
            for _ in 0..100 {
                tracing::debug!("debug lines are not held back");
            }
        });
        let seen = seen.lock().map(|s| s.clone()).unwrap_or_default();
        let count = |level: &str| seen.iter().filter(|s| s.starts_with(level)).count();
        assert_eq!((count("WARN"), count("INFO"), count("DEBUG")), (10, 1, 100));

        // The line that follows a suppression carries its count.
        let out = Arc::new(Mutex::new(Vec::<u8>::new()));
        let sink = out.clone();
        let writer = move || Buffer(sink.clone());
        let subscriber = tracing_subscriber::registry().with(
            tracing_subscriber::fmt::layer()
                .with_writer(writer)
                .with_ansi(false)
                .fmt_fields(NotedFields),
        );
        tracing::subscriber::with_default(subscriber, || {
            SUPPRESSED.with(|c| c.set(4));
            tracing::warn!("goal refused");
            SUPPRESSED.with(|c| c.set(0));
            tracing::warn!("goal refused");
        });
        let text = String::from_utf8(out.lock().map(|o| o.clone()).unwrap_or_default()).unwrap_or_default();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 2, "{text}");
        assert!(
            lines[0].ends_with("goal refused (4 similar lines suppressed)"),
            "{text}"
        );
        assert!(lines[1].ends_with("goal refused"), "{text}");
    }

    /// A writer into a shared buffer.
    struct Buffer(Arc<Mutex<Vec<u8>>>);

    impl std::io::Write for Buffer {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            if let Ok(mut out) = self.0.lock() {
                out.extend_from_slice(buf);
            }
            Ok(buf.len())
        }

        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

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
