//! The external evaluator: an individual is evaluated by a simulator the user runs (Webots,
//! Gazebo, …) over ROS 2.
//!
//! The contract with the simulator, per individual (topic names relative to the node's
//! namespace, so `--ros-args -r __ns:=/sim1` or `-r ga_step/candidate:=/webots/candidate` move
//! them):
//! - `ga_step` publishes the candidate on **`ga_step/candidate`** (`trajectory_msgs/JointTrajectory`:
//!   the ten joints in genome order with Webots' names, 21 points at i·T/20 with positions only).
//!   Its header identifies it: `frame_id` = `candidate <n>` (n counted from 1 in this run) and
//!   `stamp` = the time it was sent, unique within and across runs.
//! - The simulator answers on **`ga_step/outcome`** (`sensor_msgs/JointState`) with the
//!   candidate's header echoed exactly (stamp and frame_id) and the results as named values,
//!   `name[i]` ↔ `position[i]`: `fell` (1 if the robot fell during the step and the settle time
//!   after it, T_sim = T + 1 s; 0 if not), `forward_distance` (m, the torso's displacement along
//!   the robot's initial forward axis, at the fall or at the end) and, when it fell, `fall_time`
//!   (s from the start of the step). `velocity` and `effort` stay empty.
//!
//! One message carries the whole answer, so no field can arrive after the others. An answer
//! whose header is not the candidate's (a late answer to an earlier candidate, another run's, a
//! foreign publisher's) is discarded with a rate-limited warning; an answer with the candidate's
//! header but missing or non-finite values scores 0 (as a fall at 0 s), with a warning.
//!
//! Both topics are reliable, volatile, depth 10. Before each candidate the evaluator waits, up to
//! the timeout (`--eval-timeout`), until a simulator subscribes to the candidates and publishes
//! outcomes: a simulator that restarts is found again. No simulator within the timeout ends the
//! run ([`RosEvalError::NoSimulator`]). While a candidate waits for its answer it is sent again,
//! with the same header, every [`RESEND_EVERY`] and whenever a new reader of the candidates is
//! matched (a simulator that restarted, even within the old one's lease; a first sample lost
//! during discovery): a simulator that answers every copy evaluates the candidate again, and the
//! answers to the copies are discarded. A candidate is given [`ATTEMPTS`] attempts of the
//! timeout each (counted from the attempt's first publication); unanswered after all of them it
//! scores 0 (a void score, with a warning; [`RosEvaluator::void_scores`] counts them, and
//! `ga_step` reports them) and the run goes on. [`MAX_UNANSWERED_IN_A_ROW`] unanswered attempts
//! in a row end the run ([`RosEvalError::Unanswered`]): the simulator hears but does not
//! answer. An interrupt (Ctrl-C) stops the waiting at once ([`RosEvalError::Interrupted`]).
//! Once stopped, every later call returns at once, and `ga_step` exits without writing the
//! generation in flight, so the run resumes from its last checkpoint. Evaluations are sequential
//! (one simulator): run this evaluator on one thread.

use mobil_ga_step::external::{candidate_name, Outcome, VOID};
use mobil_ga_step::{Evaluation, Evaluator, FitnessConfig, Individual, NaoModel, KNOTS};
use mobil_msgs::builtin_interfaces::msg::{Duration as RosDuration, Time};
use mobil_msgs::sensor_msgs::msg::JointState;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::trajectory_msgs::msg::{JointTrajectory, JointTrajectoryPoint};
use mobil_ros::args::RosArgs;
use mobil_ros::node::{NodeDecl, RosNode};
use mobil_ros::{qos, warn_throttled, LogThrottle};
use ros2_client::{EntityKind, GraphEvent, NodeEvent, Publisher, Subscription};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

/// Topic of the candidates.
pub const CANDIDATE_TOPIC: &str = "ga_step/candidate";
/// Topic of the simulator's answers.
pub const OUTCOME_TOPIC: &str = "ga_step/outcome";
/// Attempts in a row without an answer (of the timeout each, over one or more candidates)
/// that end the run.
pub const MAX_UNANSWERED_IN_A_ROW: u32 = 3;
/// Attempts per candidate, each with its own timeout, before it scores 0.
pub const ATTEMPTS: u32 = 2;
/// How often a candidate that waits for its answer is sent again.
pub const RESEND_EVERY: Duration = Duration::from_secs(5);

/// Why the external evaluator stopped.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum RosEvalError {
    /// No simulator subscribed to the candidates and published outcomes in time.
    #[error("no simulator subscribed to {CANDIDATE_TOPIC} and publishing {OUTCOME_TOPIC} within {0:.1} s")]
    NoSimulator(f64),
    /// Several attempts in a row went unanswered.
    #[error("the simulator left {MAX_UNANSWERED_IN_A_ROW} attempts in a row (the last for candidate {candidate}) unanswered within {timeout:.1} s each")]
    Unanswered {
        /// The last candidate's number.
        candidate: u64,
        /// The timeout (s).
        timeout: f64,
    },
    /// Publishing failed.
    #[error("cannot publish candidate {0}: {1}")]
    Publish(u64, String),
    /// An interrupt stopped the waiting.
    #[error("interrupted while candidate {0} was evaluated")]
    Interrupted(u64),
}

/// The header that identifies candidate `n` sent at `stamp`.
pub fn candidate_header(n: u64, stamp: Time) -> Header {
    Header {
        stamp,
        frame_id: candidate_name(n),
    }
}

/// The candidate as a `trajectory_msgs/JointTrajectory`: joints in genome order, one
/// positions-only point per knot at i·T/20, and `header` identifying it.
pub fn candidate_message(model: &NaoModel, individual: &Individual, header: Header) -> JointTrajectory {
    let names = mobil_ga_step::joint_names();
    let points = (0..KNOTS)
        .map(|k| {
            let ns = model.knot_time_ns(k);
            JointTrajectoryPoint {
                positions: individual.knots.iter().map(|s| s[k]).collect(),
                time_from_start: RosDuration {
                    sec: (ns / 1_000_000_000) as i32,
                    nanosec: (ns % 1_000_000_000) as u32,
                },
                ..Default::default()
            }
        })
        .collect();
    JointTrajectory {
        header,
        joint_names: names.iter().map(|n| n.to_string()).collect(),
        points,
    }
}

/// Reads the named values of an outcome (`mobil_ga_step::external::Outcome::from_named`): the
/// reason when one is missing or bad.
pub fn parse_outcome(m: &JointState) -> Result<Outcome, String> {
    Outcome::from_named(&m.name, &m.position)
}

// Field order is drop order: the writer and reader go before the node that owns their
// participant (mobil_ros: readers and writers must go while their participant exists).
struct Link {
    candidates: Publisher<JointTrajectory>,
    outcome: Subscription<JointState>,
    /// The node's graph events, taken once: a remote reader matched while a candidate waits
    /// (a simulator that restarted) is told by them. `None` without a spinner.
    events: Option<async_channel::Receiver<NodeEvent>>,
    node: RosNode,
    sent: u64,
    unanswered_in_a_row: u32,
    void_scores: u64,
    failed: Option<RosEvalError>,
    throttle: LogThrottle,
}

/// The evaluator over ROS 2 (see the module's documentation).
pub struct RosEvaluator {
    link: Mutex<Option<Link>>,
    model: NaoModel,
    fitness: FitnessConfig,
    timeout: Duration,
    resend_every: Duration,
    interrupt: Arc<AtomicBool>,
    runtime: tokio::runtime::Runtime,
}

/// How often the wait for a simulator looks at the interrupt.
const POLL: Duration = Duration::from_millis(10);
/// Answers taken in one pass before the deadline and the interrupt are looked at again (a
/// publisher flooding the outcome topic cannot hold the wait).
const ANSWERS_PER_PASS: usize = 64;

impl RosEvaluator {
    /// Joins the DDS domain of `ROS_DOMAIN_ID` as node `ga_step` (its name, namespace and topics
    /// remapped by `args`) and creates the topics. `interrupt` set stops any waiting.
    pub fn new(
        model: NaoModel,
        fitness: FitnessConfig,
        timeout: Duration,
        args: &RosArgs,
        interrupt: Arc<AtomicBool>,
    ) -> anyhow::Result<RosEvaluator> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()?;
        let link = {
            let _entered = runtime.enter();
            let decl = NodeDecl::new("ga_step", "evolves a humanoid step; evaluates candidates over ROS 2");
            let mut node = RosNode::start(&decl, args)?;
            let q = qos::reliable(10);
            let candidates = node.publisher::<JointTrajectory>(CANDIDATE_TOPIC, &q)?;
            let outcome = node.subscription::<JointState>(OUTCOME_TOPIC, &q)?;
            let events = node.inner().status_receiver();
            Link {
                candidates,
                outcome,
                events,
                node,
                sent: 0,
                unanswered_in_a_row: 0,
                void_scores: 0,
                failed: None,
                throttle: LogThrottle::default(),
            }
        };
        Ok(RosEvaluator {
            link: Mutex::new(Some(link)),
            model,
            fitness,
            timeout,
            resend_every: RESEND_EVERY,
            interrupt,
            runtime,
        })
    }

    /// The same evaluator re-sending a waiting candidate every `every` instead of every
    /// [`RESEND_EVERY`].
    pub fn with_resend_every(mut self, every: Duration) -> RosEvaluator {
        self.resend_every = every;
        self
    }

    /// The error that stopped the evaluator, if one did.
    pub fn failure(&self) -> Option<RosEvalError> {
        let link = self.link.lock().unwrap_or_else(PoisonError::into_inner);
        link.as_ref().and_then(|l| l.failed.clone())
    }

    /// Candidates that went unanswered after every attempt and scored 0 (void scores).
    pub fn void_scores(&self) -> u64 {
        let link = self.link.lock().unwrap_or_else(PoisonError::into_inner);
        link.as_ref().map_or(0, |l| l.void_scores)
    }

    /// Waits until a simulator is matched on both topics, up to the timeout. The two match
    /// futures (each holds a graph-event channel of the node) are made at the start and again
    /// only when the graph changed: a future's channel holds 8 events, and one that overflowed
    /// while the other future was waiting could miss its match.
    fn await_simulator(&self, link: &mut Link, n: u64) -> Result<(), RosEvalError> {
        let deadline = Instant::now() + self.timeout;
        loop {
            let Link {
                node,
                candidates,
                outcome,
                events,
                ..
            } = &mut *link;
            let node = &*node.inner();
            // Events from before the futures are made are in their own first look at the graph.
            Self::readers_changed(events);
            let reader = candidates.wait_for_subscription(node);
            let writer = outcome.wait_for_publisher(node);
            let waited = self.runtime.block_on(async {
                let both = async {
                    tokio::join!(reader, writer);
                };
                tokio::pin!(both);
                loop {
                    if tokio::time::timeout(POLL, &mut both).await.is_ok() {
                        return Some(Ok(()));
                    }
                    if self.interrupt.load(Ordering::SeqCst) {
                        return Some(Err(RosEvalError::Interrupted(n)));
                    }
                    if Instant::now() >= deadline {
                        return Some(Err(RosEvalError::NoSimulator(self.timeout.as_secs_f64())));
                    }
                    if Self::graph_changed(events) {
                        return None;
                    }
                }
            });
            if let Some(result) = waited {
                return result;
            }
        }
    }

    /// Whether the graph changed since the last call (draining the node's events).
    fn graph_changed(events: &Option<async_channel::Receiver<NodeEvent>>) -> bool {
        let Some(events) = events else {
            return false;
        };
        let mut changed = false;
        while events.try_recv().is_ok() {
            changed = true;
        }
        changed
    }

    /// Whether a remote reader was matched or lost since the last call (draining the node's
    /// events). The events name the remote entity only, not the local writer it matched.
    fn readers_changed(events: &Option<async_channel::Receiver<NodeEvent>>) -> bool {
        let Some(events) = events else {
            return false;
        };
        let mut changed = false;
        while let Ok(event) = events.try_recv() {
            if let NodeEvent::Graph(GraphEvent::EntityDeclared(e) | GraphEvent::EntityUndeclared(e)) = event {
                changed |= e.kind == EntityKind::Subscription;
            }
        }
        changed
    }

    /// The readers matched to the candidates now (the candidates' writer has been matched
    /// before, so ros2-client knows it).
    fn candidate_readers(link: &mut Link) -> usize {
        let Link { node, candidates, .. } = link;
        candidates.get_subscription_count(node.inner())
    }

    /// Whether the candidates gained a reader since `known` readers were counted (updated),
    /// looked at only when the graph changed.
    fn new_reader(link: &mut Link, known: &mut usize) -> bool {
        if !Self::readers_changed(&link.events) {
            return false;
        }
        let now = Self::candidate_readers(link);
        let grew = now > *known;
        *known = now;
        grew
    }

    /// One candidate: its outcome, `None` when every attempt went unanswered.
    fn round_trip(&self, link: &mut Link, individual: &Individual) -> Result<Option<Evaluation>, RosEvalError> {
        let n = link.sent + 1;
        self.await_simulator(link, n)?;
        link.sent = n;
        // Wall-clock time: unique across runs even under use_sim_time.
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos() as i64)
            .unwrap_or(0);
        let header = candidate_header(n, mobil_ros::time::stamp_from_nanos(nanos));
        let message = candidate_message(&self.model, individual, header.clone());
        for attempt in 1..=ATTEMPTS {
            if attempt > 1 {
                self.await_simulator(link, n)?;
            }
            // Matches from before this publication say nothing about who heard it.
            Self::readers_changed(&link.events);
            let mut readers = Self::candidate_readers(link);
            link.candidates
                .publish(message.clone())
                .map_err(|e| RosEvalError::Publish(n, format!("{e:?}")))?;
            if let Some(e) = self.await_answer(link, n, &header, &message, &mut readers)? {
                return Ok(Some(e));
            }
            link.unanswered_in_a_row += 1;
            warn_throttled!(
                link.throttle,
                "timeout",
                "candidate {n}: no outcome within {:.1} s (attempt {attempt} of {ATTEMPTS})",
                self.timeout.as_secs_f64()
            );
            if link.unanswered_in_a_row >= MAX_UNANSWERED_IN_A_ROW {
                return Err(RosEvalError::Unanswered {
                    candidate: n,
                    timeout: self.timeout.as_secs_f64(),
                });
            }
        }
        Ok(None)
    }

    /// Waits up to the timeout for the answer to the candidate just published, sending it again
    /// every `resend_every` and whenever a new remote reader is matched (a simulator that
    /// restarted, even before the old one's lease ended, or a first sample lost during
    /// discovery). `readers`: the candidates' readers when it was published. `None`: no answer
    /// in time.
    fn await_answer(
        &self,
        link: &mut Link,
        n: u64,
        header: &Header,
        message: &JointTrajectory,
        readers: &mut usize,
    ) -> Result<Option<Evaluation>, RosEvalError> {
        let deadline = Instant::now() + self.timeout;
        let mut next_send = Instant::now() + self.resend_every;
        loop {
            for _ in 0..ANSWERS_PER_PASS {
                let Ok(Some((m, _))) = link.outcome.take() else {
                    break;
                };
                if m.header != *header {
                    warn_throttled!(
                        link.throttle,
                        "stale",
                        "discarded an outcome for `{}` at {}.{:09} while waiting for `{}` at {}.{:09}",
                        m.header.frame_id,
                        m.header.stamp.sec,
                        m.header.stamp.nanosec,
                        header.frame_id,
                        header.stamp.sec,
                        header.stamp.nanosec
                    );
                    continue;
                }
                return Ok(Some(match parse_outcome(&m) {
                    Ok(o) => o.evaluation(&self.fitness, &self.model),
                    Err(reason) => {
                        warn_throttled!(
                            link.throttle,
                            "bad",
                            "candidate {n}: bad outcome ({reason}); scored 0 as a fall at 0 s"
                        );
                        VOID
                    }
                }));
            }
            if self.interrupt.load(Ordering::SeqCst) {
                return Err(RosEvalError::Interrupted(n));
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(None);
            }
            // The same candidate again (same header: the answers to the copies are discarded).
            if Self::new_reader(link, readers) || now >= next_send {
                link.candidates
                    .publish(message.clone())
                    .map_err(|e| RosEvalError::Publish(n, format!("{e:?}")))?;
                next_send = now + self.resend_every;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}

impl Evaluator for RosEvaluator {
    fn evaluate(&self, individual: &Individual) -> Evaluation {
        let mut guard = self.link.lock().unwrap_or_else(PoisonError::into_inner);
        let Some(link) = guard.as_mut() else {
            return VOID;
        };
        if link.failed.is_some() {
            return VOID;
        }
        match self.round_trip(link, individual) {
            Ok(Some(e)) => {
                link.unanswered_in_a_row = 0;
                e
            }
            Ok(None) => {
                link.void_scores += 1;
                let n = link.sent;
                warn_throttled!(
                    link.throttle,
                    "void",
                    "candidate {n}: unanswered after {ATTEMPTS} attempts; scored 0 as a fall at 0 s ({} so far)",
                    link.void_scores
                );
                VOID
            }
            Err(e) => {
                link.failed = Some(e);
                VOID
            }
        }
    }
}

impl Drop for RosEvaluator {
    /// Leaves the DDS domain cleanly: writer and reader first, then the node and its participant.
    fn drop(&mut self) {
        let link = self.link.get_mut().unwrap_or_else(PoisonError::into_inner).take();
        if let Some(Link {
            candidates,
            outcome,
            node,
            ..
        }) = link
        {
            drop(candidates);
            drop(outcome);
            self.runtime.block_on(node.shutdown());
        }
    }
}
