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
//! run ([`RosEvalError::NoSimulator`]). A candidate without an answer within the timeout (counted
//! from its publication) scores 0, with a warning, and the run goes on; if the simulator drops
//! out while a candidate waits, the candidate is sent again when it is back. Three candidates in
//! a row without an answer end the run ([`RosEvalError::Unanswered`]): the simulator hears but
//! does not answer. An interrupt (Ctrl-C) stops the waiting at once ([`RosEvalError::Interrupted`]).
//! Once stopped, every later call returns at once, and `ga_step` exits without writing the
//! generation in flight, so the run resumes from its last checkpoint. Evaluations are sequential
//! (one simulator): run this evaluator on one thread.

use mobil_ga_step::{Evaluation, Evaluator, FitnessConfig, Individual, NaoModel, INTERVALS, KNOTS};
use mobil_msgs::builtin_interfaces::msg::{Duration as RosDuration, Time};
use mobil_msgs::sensor_msgs::msg::JointState;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::trajectory_msgs::msg::{JointTrajectory, JointTrajectoryPoint};
use mobil_ros::args::RosArgs;
use mobil_ros::node::{NodeDecl, RosNode};
use mobil_ros::{qos, warn_throttled, LogThrottle};
use ros2_client::{Publisher, Subscription};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

/// Topic of the candidates.
pub const CANDIDATE_TOPIC: &str = "ga_step/candidate";
/// Topic of the simulator's answers.
pub const OUTCOME_TOPIC: &str = "ga_step/outcome";
/// Candidates in a row without an answer that end the run.
pub const MAX_UNANSWERED_IN_A_ROW: u32 = 3;

/// Why the external evaluator stopped.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum RosEvalError {
    /// No simulator subscribed to the candidates and published outcomes in time.
    #[error("no simulator subscribed to {CANDIDATE_TOPIC} and publishing {OUTCOME_TOPIC} within {0:.1} s")]
    NoSimulator(f64),
    /// Several candidates in a row went unanswered.
    #[error("the simulator left {MAX_UNANSWERED_IN_A_ROW} candidates in a row (the last {candidate}) unanswered within {timeout:.1} s each")]
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
        frame_id: format!("candidate {n}"),
    }
}

/// The candidate as a `trajectory_msgs/JointTrajectory`: joints in genome order, one
/// positions-only point per knot at i·T/20, and `header` identifying it.
pub fn candidate_message(model: &NaoModel, individual: &Individual, header: Header) -> JointTrajectory {
    let names = mobil_ga_step::joint_names();
    let points = (0..KNOTS)
        .map(|k| {
            let ns = (k as u128 * model.step_time_ms() as u128 * 1_000_000) / INTERVALS as u128;
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

/// A simulator's answer, read from an outcome message (see the module's documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    /// Whether the robot fell.
    pub fell: bool,
    /// When it fell (s), 0 without a fall.
    pub fall_time: f64,
    /// The torso's forward displacement (m).
    pub forward_distance: f64,
}

/// Reads the named values of an outcome: `fell` (0 or 1), `forward_distance` (finite) and, for
/// a fall, `fall_time` (finite, ≥ 0). The reason when one is missing or bad.
pub fn parse_outcome(m: &JointState) -> Result<Outcome, String> {
    if m.name.len() != m.position.len() {
        return Err(format!("{} names but {} positions", m.name.len(), m.position.len()));
    }
    let value = |key: &str| m.name.iter().position(|n| n == key).map(|i| m.position[i]);
    let fell = match value("fell") {
        Some(1.0) => true,
        Some(0.0) => false,
        Some(v) => return Err(format!("fell = {v}, expected 0 or 1")),
        None => return Err("no `fell`".into()),
    };
    let forward_distance = match value("forward_distance") {
        Some(v) if v.is_finite() => v,
        Some(v) => return Err(format!("forward_distance = {v} is not finite")),
        None => return Err("no `forward_distance`".into()),
    };
    let fall_time = match (fell, value("fall_time")) {
        (false, _) => 0.0,
        (true, Some(t)) if t.is_finite() && t >= 0.0 => t,
        (true, Some(t)) => return Err(format!("fall_time = {t}, expected a finite time ≥ 0")),
        (true, None) => return Err("a fall without `fall_time`".into()),
    };
    Ok(Outcome {
        fell,
        fall_time,
        forward_distance,
    })
}

// Field order is drop order: the writer and reader go before the node that owns their
// participant (mobil_ros: readers and writers must go while their participant exists).
struct Link {
    candidates: Publisher<JointTrajectory>,
    outcome: Subscription<JointState>,
    node: RosNode,
    sent: u64,
    unanswered_in_a_row: u32,
    failed: Option<RosEvalError>,
    throttle: LogThrottle,
}

/// The evaluator over ROS 2 (see the module's documentation).
pub struct RosEvaluator {
    link: Mutex<Option<Link>>,
    model: NaoModel,
    fitness: FitnessConfig,
    timeout: Duration,
    interrupt: Arc<AtomicBool>,
    runtime: tokio::runtime::Runtime,
}

const ZERO: Evaluation = Evaluation {
    fitness: 0.0,
    fell: true,
    t_fall: 0.0,
    forward_distance: 0.0,
};

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
            Link {
                candidates,
                outcome,
                node,
                sent: 0,
                unanswered_in_a_row: 0,
                failed: None,
                throttle: LogThrottle::default(),
            }
        };
        Ok(RosEvaluator {
            link: Mutex::new(Some(link)),
            model,
            fitness,
            timeout,
            interrupt,
            runtime,
        })
    }

    /// The error that stopped the evaluator, if one did.
    pub fn failure(&self) -> Option<RosEvalError> {
        let link = self.link.lock().unwrap_or_else(PoisonError::into_inner);
        link.as_ref().and_then(|l| l.failed.clone())
    }

    /// Whether a simulator is matched on both topics now. (ros2-client's match futures, polled
    /// briefly: its match counts log an error for an entity that was never matched.)
    fn simulator_present(&self, link: &mut Link) -> bool {
        let Link {
            node,
            candidates,
            outcome,
            ..
        } = link;
        let node = &*node.inner();
        let reader = candidates.wait_for_subscription(node);
        let writer = outcome.wait_for_publisher(node);
        self.runtime.block_on(async {
            tokio::time::timeout(Duration::from_millis(2), async {
                reader.await;
                writer.await;
            })
            .await
            .is_ok()
        })
    }

    /// Waits until a simulator is matched on both topics, up to the timeout.
    fn await_simulator(&self, link: &mut Link, n: u64) -> Result<(), RosEvalError> {
        let deadline = Instant::now() + self.timeout;
        while !self.simulator_present(link) {
            if self.interrupt.load(Ordering::SeqCst) {
                return Err(RosEvalError::Interrupted(n));
            }
            if Instant::now() >= deadline {
                return Err(RosEvalError::NoSimulator(self.timeout.as_secs_f64()));
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        Ok(())
    }

    /// One candidate: its outcome, `None` when it went unanswered.
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
        link.candidates
            .publish(message.clone())
            .map_err(|e| RosEvalError::Publish(n, format!("{e:?}")))?;
        let deadline = Instant::now() + self.timeout;
        let mut present = true;
        loop {
            while let Ok(Some((m, _))) = link.outcome.take() {
                if m.header != header {
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
                    Ok(o) => Evaluation::from_outcome(
                        &self.fitness,
                        self.model.step_time,
                        o.fell,
                        o.fall_time,
                        o.forward_distance,
                    ),
                    Err(reason) => {
                        warn_throttled!(
                            link.throttle,
                            "bad",
                            "candidate {n}: bad outcome ({reason}); scored 0 as a fall at 0 s"
                        );
                        ZERO
                    }
                }));
            }
            if self.interrupt.load(Ordering::SeqCst) {
                return Err(RosEvalError::Interrupted(n));
            }
            if Instant::now() >= deadline {
                return Ok(None);
            }
            // A simulator that restarted never heard this candidate: send it again once it is back.
            let now_present = self.simulator_present(link);
            if now_present && !present {
                link.candidates
                    .publish(message.clone())
                    .map_err(|e| RosEvalError::Publish(n, format!("{e:?}")))?;
            }
            present = now_present;
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}

impl Evaluator for RosEvaluator {
    fn evaluate(&self, individual: &Individual) -> Evaluation {
        let mut guard = self.link.lock().unwrap_or_else(PoisonError::into_inner);
        let Some(link) = guard.as_mut() else {
            return ZERO;
        };
        if link.failed.is_some() {
            return ZERO;
        }
        match self.round_trip(link, individual) {
            Ok(Some(e)) => {
                link.unanswered_in_a_row = 0;
                e
            }
            Ok(None) => {
                link.unanswered_in_a_row += 1;
                let n = link.sent;
                warn_throttled!(
                    link.throttle,
                    "timeout",
                    "candidate {n}: no outcome within {:.1} s; scored 0 as a fall at 0 s",
                    self.timeout.as_secs_f64()
                );
                if link.unanswered_in_a_row >= MAX_UNANSWERED_IN_A_ROW {
                    link.failed = Some(RosEvalError::Unanswered {
                        candidate: n,
                        timeout: self.timeout.as_secs_f64(),
                    });
                }
                ZERO
            }
            Err(e) => {
                link.failed = Some(e);
                ZERO
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
