//! Typed subscription streams that survive bad input.
//!
//! [`decoded`] turns a subscription's stream of decode results into a stream of [`Input`]s: a
//! sample that cannot be decoded (malformed CDR, a publisher of another type under the same
//! name) is logged — rate-limited under a throttle key, with the reason — and yields
//! [`Input::Undecodable`] instead of ending the stream or panicking. A motion node goes safe on
//! it (the previous command must not keep running); a sensor consumer just skips it.
//!
//! [`Inputs`] is how a node declares its subscriptions once: each one's topic, what a message
//! becomes in the node's own event type, what an undecodable sample becomes (or nothing), all
//! merged into one stream, so a node's event loop has one arm for every subscription and a
//! subscription that ends is one error ([`InputEnded`]).
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
use futures::stream::{LocalBoxStream, SelectAll};
use futures::{Stream, StreamExt};
use thiserror::Error;

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

/// A subscription's stream ended: the node cannot go on without it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[error("the {0} subscription ended")]
pub struct InputEnded(pub &'static str);

/// Every subscription of a node as one stream of the node's events (module docs).
///
/// ```
/// use futures::stream;
/// use mobil_ros::input::{InputEnded, Inputs};
///
/// #[derive(Debug, Clone, PartialEq)]
/// enum Event { Speed(f64), Goal(u32), BadSpeed }
///
/// let speeds: Vec<Result<(f64, ()), &str>> = vec![Ok((0.5, ())), Err("bad CDR")];
/// let goals: Vec<Result<(u32, ()), &str>> = vec![Ok((7, ())), Err("bad CDR")];
/// let mut inputs = Inputs::new();
/// inputs
///     .add_guarded(stream::iter(speeds), "cmd_vel", "robot stopped", Event::Speed, || Some(Event::BadSpeed))
///     .add(stream::iter(goals), "goal_pose", "goal ignored", Event::Goal);
/// let (mut got, mut ended) = (Vec::new(), Vec::new());
/// futures::executor::block_on(async {
///     loop {
///         match inputs.next().await {
///             Ok(e) => got.push(e),
///             Err(InputEnded("every")) => break,
///             Err(InputEnded(topic)) => ended.push(topic),
///         }
///     }
/// });
/// // Both streams' events in their order of arrival: the bad speed as an event, the bad goal
/// // as nothing; then each stream's end.
/// got.sort_by_key(|e| format!("{e:?}"));
/// assert_eq!(got, [Event::BadSpeed, Event::Goal(7), Event::Speed(0.5)]);
/// ended.sort();
/// assert_eq!(ended, ["cmd_vel", "goal_pose"]);
/// ```
pub struct Inputs<'a, E> {
    streams: SelectAll<LocalBoxStream<'a, Result<E, InputEnded>>>,
}

impl<E> Default for Inputs<'_, E> {
    fn default() -> Self {
        Inputs {
            streams: SelectAll::new(),
        }
    }
}

impl<'a, E: 'a> Inputs<'a, E> {
    /// No subscription yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a subscription's stream (its `async_stream()`): each decoded message becomes
    /// `event(message)`; an undecodable sample is logged (rate-limited, "undecodable `topic`
    /// dropped: `consequence`") and becomes nothing; the end of the stream becomes
    /// [`InputEnded`].
    pub fn add<M, I, Er, S>(
        &mut self,
        stream: S,
        topic: &'static str,
        consequence: &'static str,
        event: impl Fn(M) -> E + 'a,
    ) -> &mut Self
    where
        S: Stream<Item = Result<(M, I), Er>> + 'a,
        Er: std::fmt::Debug + 'a,
        M: 'a,
        I: 'a,
    {
        self.push(stream, topic, consequence, move |m, _| event(m), || None)
    }

    /// As [`Inputs::add`], and an undecodable sample becomes `undecodable()` when that gives
    /// an event (a motion node's: the robot must stop).
    pub fn add_guarded<M, I, Er, S>(
        &mut self,
        stream: S,
        topic: &'static str,
        consequence: &'static str,
        event: impl Fn(M) -> E + 'a,
        undecodable: impl Fn() -> Option<E> + 'a,
    ) -> &mut Self
    where
        S: Stream<Item = Result<(M, I), Er>> + 'a,
        Er: std::fmt::Debug + 'a,
        M: 'a,
        I: 'a,
    {
        self.push(stream, topic, consequence, move |m, _| event(m), undecodable)
    }

    /// Adds a service's request stream (its `receive_request_stream()`): each request becomes
    /// `event(id, request)`; an undecodable one is logged (rate-limited) and dropped.
    pub fn add_requests<Id, R, Er, S>(
        &mut self,
        stream: S,
        service: &'static str,
        event: impl Fn(Id, R) -> E + 'a,
    ) -> &mut Self
    where
        S: Stream<Item = Result<(Id, R), Er>> + 'a,
        Er: std::fmt::Debug + 'a,
        Id: 'a,
        R: 'a,
    {
        self.push(stream, service, "request dropped", event, || None)
    }

    fn push<M, I, Er, S>(
        &mut self,
        stream: S,
        topic: &'static str,
        consequence: &'static str,
        event: impl Fn(M, I) -> E + 'a,
        undecodable: impl Fn() -> Option<E> + 'a,
    ) -> &mut Self
    where
        S: Stream<Item = Result<(M, I), Er>> + 'a,
        Er: std::fmt::Debug + 'a,
        M: 'a,
        I: 'a,
    {
        let mut throttle = LogThrottle::default();
        let events = stream.filter_map(move |sample| {
            let e = match sample {
                Ok((m, i)) => Some(Ok(event(m, i))),
                Err(e) => {
                    crate::warn_throttled!(throttle, topic, "undecodable {topic} dropped: {consequence} ({e:?})");
                    undecodable().map(Ok)
                }
            };
            futures::future::ready(e)
        });
        let ended = futures::stream::once(futures::future::ready(Err(InputEnded(topic))));
        self.streams.push(events.chain(ended).boxed_local());
        self
    }

    /// The next event of any subscription, or the first subscription that ended.
    pub async fn next(&mut self) -> Result<E, InputEnded> {
        self.streams.next().await.unwrap_or(Err(InputEnded("every")))
    }
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

    #[test]
    fn requests_keep_their_id_and_an_ended_stream_is_named() {
        #[derive(Debug, PartialEq)]
        enum E {
            Request(u8, &'static str),
            Stop,
        }
        let requests: Vec<Result<(u8, &str), &str>> = vec![Ok((1, "a")), Err("bad"), Ok((2, "b"))];
        let mut inputs = Inputs::new();
        inputs.add_requests(stream::iter(requests), "gait/compute_plan", E::Request);
        let mut got = Vec::new();
        let end = futures::executor::block_on(async {
            loop {
                match inputs.next().await {
                    Ok(e) => got.push(e),
                    Err(e) => return e,
                }
            }
        });
        assert_eq!(got, [E::Request(1, "a"), E::Request(2, "b")]);
        assert_eq!(end, InputEnded("gait/compute_plan"));
        assert_eq!(end.to_string(), "the gait/compute_plan subscription ended");
        // A guarded input turns an undecodable sample into its event.
        let samples: Vec<Result<(f64, ()), &str>> = vec![Err("bad")];
        let mut inputs = Inputs::new();
        inputs.add_guarded(
            stream::iter(samples),
            "cmd_vel",
            "wheels stopped",
            |_: f64| E::Stop,
            || Some(E::Stop),
        );
        assert_eq!(futures::executor::block_on(inputs.next()), Ok(E::Stop));
    }
}
