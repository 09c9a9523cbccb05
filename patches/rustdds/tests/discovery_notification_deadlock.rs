//! Regression test for a three-way deadlock between the discovery thread,
//! `dp_event_loop` and a user thread creating an endpoint, all on one
//! `DomainParticipant`:
//!
//! * The discovery thread, adding a new local reader (`add_local_reader`), sent
//!   one `WriterUpdated` notification per writer on the reader's topic while it
//!   still held `discovery_db.read()`. The notification channel to
//!   `dp_event_loop` is bounded (32), so with more writers than that the send
//!   blocks until `dp_event_loop` takes some.
//! * A user thread creating another endpoint waits for `discovery_db.write()`
//!   behind that read lock.
//! * `dp_event_loop`, handling a `ParticipantUpdated` notification (any remote
//!   participant's announcement), asks for `discovery_db.read()`, which the
//!   writer-preferring lock queues behind the waiting writer. It never returns
//!   to the channel, so the discovery thread never finishes its send.
//!
//! Seen as a ROS 2 node that hung at start-up, in the middle of creating its
//! subscriptions, when a dozen other nodes started at the same time. The
//! discovery thread now collects the notifications, drops the lock, then sends
//! (`add_local_reader`, `add_local_writer`).
//!
//! Here one participant has more writers on a topic than the channel holds;
//! two threads keep creating readers on that topic while a third keeps other
//! participants joining the domain (each announcement is a `ParticipantUpdated`
//! for the first participant). As in `lock_order_discovery_db.rs`, the race runs
//! in a child process, so a deadlock fails the test instead of hanging it.

use std::{
  env,
  process::{Command, Stdio},
  sync::{
    atomic::{AtomicBool, Ordering},
    Arc,
  },
  thread,
  time::{Duration, Instant},
};

use rustdds::{policy, DomainParticipant, QosPolicies, QosPolicyBuilder, TopicKind};
use serde::{Deserialize, Serialize};

#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
struct Sample {
  seq: u32,
}

const CHILD_ENV: &str = "RUSTDDS_NOTIFICATION_DEADLOCK_CHILD";
const DOMAIN_ENV: &str = "RUSTDDS_NOTIFICATION_DEADLOCK_DOMAIN";
/// Must match the name of the `#[test]` function below.
const RACE_TEST_NAME: &str = "new_readers_on_a_busy_topic_while_participants_join";
/// Proves the child completed the race; libtest also exits with 0 if no test
/// matched.
const CHILD_SUCCESS_EXIT_CODE: i32 = 42;
/// How long the parent waits for the child before declaring a deadlock.
const CHILD_DEADLINE: Duration = Duration::from_secs(30);
/// Writers on the shared topic: more than the notification channel's 32.
const WRITERS: usize = 48;
const CREATOR_THREADS: usize = 2;
/// Threads that keep other participants joining.
const JOINER_THREADS: usize = 2;
/// How long the creator threads keep creating (and dropping) readers on the
/// shared topic. Without the fix the child deadlocked in 4 runs of 10 (with
/// it, in none of 10): a failure is proof, a pass is not.
const RACE_TIME: Duration = Duration::from_secs(3);

fn test_qos() -> QosPolicies {
  QosPolicyBuilder::new()
    .reliability(policy::Reliability::BestEffort)
    .durability(policy::Durability::Volatile)
    .history(policy::History::KeepLast { depth: 1 })
    .build()
}

fn run_race() {
  let domain_id: u16 = env::var(DOMAIN_ENV)
    .expect("child started without a domain id")
    .parse()
    .expect("domain id is not a u16");
  let qos = test_qos();
  let dp = DomainParticipant::new(domain_id).expect("failed to create DomainParticipant");
  let topic = dp
    .create_topic(
      "notification_deadlock_topic".to_string(),
      "Sample".to_string(),
      &qos,
      TopicKind::NoKey,
    )
    .expect("failed to create Topic");
  let publisher = dp
    .create_publisher(&qos)
    .expect("failed to create Publisher");
  let _writers: Vec<_> = (0..WRITERS)
    .map(|_| {
      publisher
        .create_datawriter_no_key_cdr::<Sample>(&topic, None)
        .expect("failed to create DataWriter")
    })
    .collect();

  let done = Arc::new(AtomicBool::new(false));
  let joiners: Vec<_> = (0..JOINER_THREADS)
    .map(|_| {
      let done = Arc::clone(&done);
      thread::spawn(move || {
        // Each new participant announces itself (SPDP) to the first one.
        while !done.load(Ordering::SeqCst) {
          let other =
            DomainParticipant::new(domain_id).expect("failed to create a second participant");
          thread::sleep(Duration::from_millis(30));
          drop(other);
        }
      })
    })
    .collect();
  let creators: Vec<_> = (0..CREATOR_THREADS)
    .map(|_| {
      let subscriber = dp
        .create_subscriber(&qos)
        .expect("failed to create Subscriber");
      let topic = topic.clone();
      thread::spawn(move || {
        let started = Instant::now();
        while started.elapsed() < RACE_TIME {
          let _reader = subscriber
            .create_datareader_no_key_cdr::<Sample>(&topic, None)
            .expect("failed to create DataReader");
        }
      })
    })
    .collect();
  for c in creators {
    c.join().expect("a creator thread panicked");
  }
  done.store(true, Ordering::SeqCst);
  for j in joiners {
    j.join().expect("a joining thread panicked");
  }
}

#[test]
fn new_readers_on_a_busy_topic_while_participants_join() {
  if env::var_os(CHILD_ENV).is_some() {
    run_race();
    std::process::exit(CHILD_SUCCESS_EXIT_CODE);
  }
  let exe = env::current_exe().expect("cannot locate the test executable");
  let domain_id = 180 + (std::process::id() % 20) as u16;
  let started = Instant::now();
  let mut child = Command::new(&exe)
    .arg(RACE_TEST_NAME)
    .arg("--exact")
    .arg("--nocapture")
    .arg("--test-threads=1")
    .env(CHILD_ENV, "1")
    .env(DOMAIN_ENV, domain_id.to_string())
    .stdin(Stdio::null())
    .stdout(Stdio::null())
    .spawn()
    .expect("cannot re-execute the test binary");
  let deadline = started + CHILD_DEADLINE;
  let status = loop {
    match child.try_wait().expect("cannot poll the child process") {
      Some(status) => break Some(status),
      None if Instant::now() >= deadline => break None,
      None => thread::sleep(Duration::from_millis(20)),
    }
  };
  match status {
    Some(status) if status.code() == Some(CHILD_SUCCESS_EXIT_CODE) => (),
    Some(status) => panic!(
      "the child did not report completion (domain {domain_id}, exit {status}) after {:.1} s",
      started.elapsed().as_secs_f64()
    ),
    None => {
      let _ = child.kill();
      let _ = child.wait();
      panic!(
        "the child (domain {domain_id}) did not finish within {} s and was killed: discovery \
         thread, dp_event_loop and endpoint creation deadlocked",
        CHILD_DEADLINE.as_secs()
      )
    }
  }
}
