//! Typed subscription streams that survive bad input.
//!
//! [`decoded`] turns a subscription's stream of decode results into a stream of [`Input`]s: a
//! sample that cannot be decoded (malformed CDR, a publisher of another type under the same
//! name) is logged — rate-limited under a throttle key, with the reason — and yields
//! [`Input::Undecodable`] instead of ending the stream or panicking. A motion node goes safe on
//! it (the previous command must not keep running); a sensor consumer just skips it.
//!
//! ```no_run
//! # async fn demo(node: &mut mobil_ros::RosNode) -> anyhow::Result<()> {
//! use futures::StreamExt;
//! use mobil_msgs::geometry_msgs::msg::Twist;
//! use mobil_ros::input::{decoded, Input};
//! let sub = node.subscription::<Twist>("cmd_vel", &mobil_ros::qos::default_qos())?;
//! let cmds = decoded(sub.async_stream(), "cmd_vel", "cmd_decode", "wheels stopped");
//! futures::pin_mut!(cmds);
//! while let Some(input) = cmds.next().await {
//!     match input {
//!         Input::Message(twist) => { /* command the wheels */ }
//!         Input::Undecodable => { /* logged already: stop the wheels */ }
//!     }
//! }
//! # Ok(()) }
//! ```

use crate::log::LogThrottle;
use futures::{Stream, StreamExt};

/// One sample of a subscription.
#[derive(Debug, Clone, PartialEq)]
pub enum Input<M> {
    /// A decoded message.
    Message(M),
    /// A sample that could not be decoded; it was logged (rate-limited) and dropped.
    Undecodable,
}

/// Decoded messages of `stream` (a subscription's `async_stream()`, whose items are
/// `(message, MessageInfo)`); an undecodable sample is
/// logged under throttle `key` as "undecodable `topic` dropped: `consequence`" at most once per
/// throttle period (with the count of those suppressed) and yields [`Input::Undecodable`].
pub fn decoded<M, I, E, S>(
    stream: S,
    topic: &'static str,
    key: &'static str,
    consequence: &'static str,
) -> impl Stream<Item = Input<M>>
where
    S: Stream<Item = Result<(M, I), E>>,
    E: std::fmt::Debug,
{
    let mut throttle = LogThrottle::default();
    stream.map(move |sample| match sample {
        Ok((msg, _)) => Input::Message(msg),
        Err(e) => {
            crate::warn_throttled!(throttle, key, "undecodable {topic} dropped: {consequence} ({e:?})");
            Input::Undecodable
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use futures::stream;
    use std::sync::{Arc, Mutex};
    use tracing::{Event, Subscriber};
    use tracing_subscriber::layer::{Context, Layer, SubscriberExt};

    struct Lines(Arc<Mutex<Vec<String>>>);

    impl<S: Subscriber> Layer<S> for Lines {
        fn on_event(&self, event: &Event<'_>, _: Context<'_, S>) {
            struct V(String);
            impl tracing::field::Visit for V {
                fn record_debug(&mut self, _: &tracing::field::Field, value: &dyn std::fmt::Debug) {
                    self.0 = format!("{value:?}");
                }
            }
            let mut v = V(String::new());
            event.record(&mut v);
            if let Ok(mut lines) = self.0.lock() {
                lines.push(v.0);
            }
        }
    }

    #[test]
    fn undecodable_samples_are_dropped_logged_once_and_the_stream_goes_on() {
        let lines = Arc::new(Mutex::new(Vec::new()));
        let subscriber = tracing_subscriber::registry().with(Lines(lines.clone()));
        let samples: Vec<Result<(u32, ()), String>> = vec![
            Ok((1, ())),
            Err("bad CDR".into()),
            Err("bad CDR".into()),
            Err("bad CDR".into()),
            Ok((2, ())),
        ];
        let out: Vec<Input<u32>> = tracing::subscriber::with_default(subscriber, || {
            futures::executor::block_on(
                decoded(stream::iter(samples), "cmd_vel", "cmd_decode", "wheels stopped").collect(),
            )
        });
        assert_eq!(
            out,
            [
                Input::Message(1),
                Input::Undecodable,
                Input::Undecodable,
                Input::Undecodable,
                Input::Message(2)
            ]
        );
        // Three bad samples within the 2 s throttle period: one line.
        let lines = lines.lock().map(|l| l.clone()).unwrap_or_default();
        assert_eq!(lines, ["undecodable cmd_vel dropped: wheels stopped (\"bad CDR\")"]);
    }
}
