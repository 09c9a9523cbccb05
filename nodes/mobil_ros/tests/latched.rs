//! A latched topic (reliable, transient local, keep last `depth`) gives a late-joining
//! participant the publisher's last `depth` samples and nothing older.
//!
//! Each test publishes numbered samples `0..HISTORY` with nobody listening (or with an early
//! reader that acknowledged them all), then a new participant subscribes. The samples it receives
//! before the live ones (numbers `>= HISTORY`) must be exactly the last `depth` of the publisher:
//! `HISTORY - depth .. HISTORY`. A reliable reader receives a writer's samples in sequence-number
//! order, so once a live sample has arrived no history can follow it.
//!
//! Publisher, early reader and late joiner are separate DDS participants (one `Context` each), on
//! a domain and topic of this test process only, so parallel runs do not meet.

use std::time::{Duration, Instant};

use crate::common;
use mobil_msgs::std_msgs::msg::String as StringMsg;
use mobil_msgs::RosMessage;

use ros2_client::{Context, Name, Node, Publisher, QosProfile, Subscription};

/// Samples published before the late joiner subscribes.
const HISTORY: u32 = 200;
const TIMEOUT: Duration = Duration::from_secs(15);

struct Participant {
    _context: Context,
    node: Node,
}

fn participant(name: &str) -> Participant {
    let (context, node) = common::participant(name);
    Participant {
        _context: context,
        node,
    }
}

fn topic_name(case: &str) -> Name {
    Name::new("/", &format!("latched_{case}_{}", std::process::id())).expect("topic name")
}

fn publisher(p: &mut Participant, topic: &Name, qos: &QosProfile) -> Publisher<StringMsg> {
    let t = p.node.create_topic(topic, StringMsg::type_name(), qos).expect("topic");
    p.node.create_publisher(&t, Some(qos.clone())).expect("publisher")
}

fn subscription(p: &mut Participant, topic: &Name, qos: &QosProfile) -> Subscription<StringMsg> {
    let t = p.node.create_topic(topic, StringMsg::type_name(), qos).expect("topic");
    p.node.create_subscription(&t, Some(qos.clone())).expect("subscription")
}

fn sample(n: u32) -> StringMsg {
    StringMsg { data: n.to_string() }
}

/// Every sample available now, as numbers.
fn drain(sub: &Subscription<StringMsg>, into: &mut Vec<u32>) {
    while let Ok(Some((msg, _))) = sub.take() {
        into.push(msg.data.parse().expect("the test publishes numbers"));
    }
}

/// Polls `sub` until a sample satisfying `done` has arrived; panics after [`TIMEOUT`].
fn receive_until(
    sub: &Subscription<StringMsg>,
    received: &mut Vec<u32>,
    mut on_poll: impl FnMut(),
    done: impl Fn(&[u32]) -> bool,
) {
    let deadline = Instant::now() + TIMEOUT;
    while !done(received) {
        assert!(Instant::now() < deadline, "timed out; received so far: {received:?}");
        on_poll();
        std::thread::sleep(Duration::from_millis(5));
        drain(sub, received);
    }
}

/// Publishes `0..HISTORY` on a latched topic of depth `publisher_depth` (optionally to an early
/// reader that receives and acknowledges them all), then returns what a late joiner subscribing
/// with depth `reader_depth` receives up to and including the first live sample.
fn late_joiner_receives(case: &str, publisher_depth: usize, reader_depth: usize, early_reader: bool) -> Vec<u32> {
    let topic = topic_name(case);
    let mut publishing = participant(&format!("latched_pub_{case}"));
    let pub_qos = mobil_ros::qos::reliable(publisher_depth).durability(ros2_client::qos::Durability::TransientLocal);
    let publisher = publisher(&mut publishing, &topic, &pub_qos);

    let mut early = early_reader.then(|| participant(&format!("latched_early_{case}")));
    if let Some(early) = early.as_mut() {
        let sub = subscription(early, &topic, &mobil_ros::qos::latched());
        // Until it has matched, a sample may reach it as history or not at all: publish 0 until
        // it arrives, then the rest, and wait until the early reader has the last one.
        let mut got = Vec::new();
        receive_until(
            &sub,
            &mut got,
            || {
                let _ = publisher.publish(sample(0));
            },
            |r| !r.is_empty(),
        );
        for n in 1..HISTORY {
            publisher.publish(sample(n)).expect("publish");
        }
        receive_until(&sub, &mut got, || {}, |r| r.contains(&(HISTORY - 1)));
    } else {
        for n in 0..HISTORY {
            publisher.publish(sample(n)).expect("publish");
        }
    }

    let mut late = participant(&format!("latched_late_{case}"));
    let late_qos = mobil_ros::qos::reliable(reader_depth).durability(ros2_client::qos::Durability::TransientLocal);
    let sub = subscription(&mut late, &topic, &late_qos);
    let mut received = Vec::new();
    // Nothing is published until the history has arrived, so the first sample proves the match.
    receive_until(&sub, &mut received, || {}, |r| !r.is_empty());
    let mut live = HISTORY;
    receive_until(
        &sub,
        &mut received,
        || {
            publisher.publish(sample(live)).expect("publish");
            live += 1;
        },
        |r| r.iter().any(|&n| n >= HISTORY),
    );
    drop(early);
    received
}

fn history_part(received: &[u32]) -> Vec<u32> {
    received.iter().copied().take_while(|&n| n < HISTORY).collect()
}

#[test]
fn late_joiner_gets_only_the_last_sample_of_a_depth_1_publisher() {
    // Publisher depth 1: only sample 199 is history, whatever the reader's depth.
    let received = late_joiner_receives("d1r10", 1, 10, false);
    assert_eq!(history_part(&received), vec![HISTORY - 1], "received {received:?}");
    // Then live samples, in order, the first one being 200.
    assert_eq!(received[1], HISTORY, "received {received:?}");
}

#[test]
fn late_joiner_gets_the_last_depth_samples_of_a_deeper_publisher() {
    // Publisher depth 3, reader depth 10: samples 197, 198, 199.
    let received = late_joiner_receives("d3r10", 3, 10, false);
    assert_eq!(history_part(&received), vec![197, 198, 199], "received {received:?}");
}

#[test]
fn late_joiner_gets_only_the_last_sample_while_an_early_reader_is_matched() {
    // The early reader acknowledged 0..199; the writer still holds them until its next cache
    // cleaning, but the late joiner must only get 199.
    let received = late_joiner_receives("early", 1, 10, true);
    assert_eq!(history_part(&received), vec![HISTORY - 1], "received {received:?}");
}
