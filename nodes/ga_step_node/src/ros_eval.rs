//! The external evaluator: an individual is evaluated by a simulator the user runs (Webots,
//! Gazebo, …) over ROS 2.
//!
//! For each individual, `ga_step` publishes the candidate on **`ga_step/candidate`**
//! (`trajectory_msgs/JointTrajectory`: the ten joints in genome order with Webots' names, 21
//! points at i·T/20 with positions only, `header.frame_id` = `candidate <n>`, counted from 1), then
//! waits for the simulator's answer:
//! - **`ga_step/fell`** (`std_msgs/Bool`): whether the robot fell during the step and the settle
//!   time after it (T_sim = T + 1 s);
//! - **`ga_step/forward_distance`** (`std_msgs/Float64`, m): the torso's displacement along the
//!   robot's initial forward axis, at the fall or at the end;
//! - optionally **`ga_step/fall_time`** (`std_msgs/Float64`, s from the start of the step),
//!   published before `fell`; a fall without it counts as a fall at 0 s.
//!
//! All four topics are reliable, volatile, depth 10. The answer must arrive within the timeout
//! (`--eval-timeout`), counted from the publication; the first candidate also waits up to the
//! timeout for the simulator's subscription to match. A missing answer is an error: the
//! evaluator stops evaluating (every later call returns at once), and `ga_step` exits with the
//! error without writing the generation in flight, so the run resumes from its last checkpoint.
//! Evaluations are sequential (one simulator): run this evaluator on one thread.

use mobil_ga_step::{Evaluation, Evaluator, FitnessConfig, Individual, NaoModel, INTERVALS, KNOTS};
use mobil_msgs::builtin_interfaces::msg::Duration as RosDuration;
use mobil_msgs::std_msgs::msg::{Bool, Float64, Header};
use mobil_msgs::trajectory_msgs::msg::{JointTrajectory, JointTrajectoryPoint};
use mobil_ros::node::{NodeDecl, RosNode};
use mobil_ros::qos;
use ros2_client::{Publisher, Subscription};
use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

/// Topic of the candidates.
pub const CANDIDATE_TOPIC: &str = "ga_step/candidate";
/// Topic of the fall flag.
pub const FELL_TOPIC: &str = "ga_step/fell";
/// Topic of the forward distance.
pub const FORWARD_TOPIC: &str = "ga_step/forward_distance";
/// Topic of the optional fall time.
pub const FALL_TIME_TOPIC: &str = "ga_step/fall_time";

/// Why the external evaluation failed.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
pub enum RosEvalError {
    /// No simulator subscribed to the candidates in time.
    #[error("no simulator subscribed to {CANDIDATE_TOPIC} within {0:.1} s")]
    NoSubscriber(f64),
    /// The answer did not arrive in time.
    #[error("no answer to candidate {candidate} on {missing} within {timeout:.1} s")]
    Timeout {
        /// The candidate's number.
        candidate: u64,
        /// The topic(s) still silent.
        missing: String,
        /// The timeout (s).
        timeout: f64,
    },
    /// The answer was not a number.
    #[error("candidate {candidate}: forward distance {value} is not finite")]
    BadAnswer {
        /// The candidate's number.
        candidate: u64,
        /// The value received.
        value: f64,
    },
    /// Publishing failed.
    #[error("cannot publish candidate {0}: {1}")]
    Publish(u64, String),
}

/// The candidate as a `trajectory_msgs/JointTrajectory`: joints in genome order, one
/// positions-only point per knot at i·T/20.
pub fn candidate_message(model: &NaoModel, individual: &Individual, candidate: u64) -> JointTrajectory {
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
        header: Header {
            frame_id: format!("candidate {candidate}"),
            ..Default::default()
        },
        joint_names: names.iter().map(|n| n.to_string()).collect(),
        points,
    }
}

struct Link {
    node: RosNode,
    candidates: Publisher<JointTrajectory>,
    fell: Subscription<Bool>,
    forward: Subscription<Float64>,
    fall_time: Subscription<Float64>,
    matched: bool,
    sent: u64,
    failed: Option<RosEvalError>,
}

/// The evaluator over ROS 2 (see the module's documentation).
pub struct RosEvaluator {
    link: Mutex<Link>,
    model: NaoModel,
    fitness: FitnessConfig,
    timeout: Duration,
    runtime: tokio::runtime::Runtime,
}

impl RosEvaluator {
    /// Joins the DDS domain of `ROS_DOMAIN_ID` as node `ga_step` and creates the topics.
    pub fn new(model: NaoModel, fitness: FitnessConfig, timeout: Duration) -> anyhow::Result<RosEvaluator> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()?;
        let link = {
            let _entered = runtime.enter();
            let decl = NodeDecl::new("ga_step", "evolves a humanoid step; evaluates candidates over ROS 2");
            let mut node = RosNode::start(&decl, &Default::default())?;
            let q = qos::reliable(10);
            let candidates = node.publisher::<JointTrajectory>(CANDIDATE_TOPIC, &q)?;
            let fell = node.subscription::<Bool>(FELL_TOPIC, &q)?;
            let forward = node.subscription::<Float64>(FORWARD_TOPIC, &q)?;
            let fall_time = node.subscription::<Float64>(FALL_TIME_TOPIC, &q)?;
            Link {
                node,
                candidates,
                fell,
                forward,
                fall_time,
                matched: false,
                sent: 0,
                failed: None,
            }
        };
        Ok(RosEvaluator {
            link: Mutex::new(link),
            model,
            fitness,
            timeout,
            runtime,
        })
    }

    /// The error that stopped the evaluator, if one did.
    pub fn failure(&self) -> Option<RosEvalError> {
        self.link.lock().unwrap_or_else(PoisonError::into_inner).failed.clone()
    }

    fn round_trip(&self, link: &mut Link, individual: &Individual) -> Result<Evaluation, RosEvalError> {
        let timeout_s = self.timeout.as_secs_f64();
        if !link.matched {
            let Link { node, candidates, .. } = &mut *link;
            let wait = candidates.wait_for_subscription(node.inner());
            self.runtime
                .block_on(async { tokio::time::timeout(self.timeout, wait).await })
                .map_err(|_| RosEvalError::NoSubscriber(timeout_s))?;
            link.matched = true;
        }
        // Anything still queued answers an earlier candidate: drop it.
        while let Ok(Some(_)) = link.fell.take() {}
        while let Ok(Some(_)) = link.forward.take() {}
        while let Ok(Some(_)) = link.fall_time.take() {}
        link.sent += 1;
        let n = link.sent;
        link.candidates
            .publish(candidate_message(&self.model, individual, n))
            .map_err(|e| RosEvalError::Publish(n, format!("{e:?}")))?;
        let deadline = Instant::now() + self.timeout;
        let (mut fell, mut forward, mut fall_time) = (None, None, None);
        loop {
            if let Ok(Some((m, _))) = link.fall_time.take() {
                fall_time = Some(m.data);
            }
            if fell.is_none()
                && let Ok(Some((m, _))) = link.fell.take()
            {
                fell = Some(m.data);
            }
            if forward.is_none()
                && let Ok(Some((m, _))) = link.forward.take()
            {
                forward = Some(m.data);
            }
            if let (Some(fell), Some(dx)) = (fell, forward) {
                if let Ok(Some((m, _))) = link.fall_time.take() {
                    fall_time = Some(m.data);
                }
                if !dx.is_finite() {
                    return Err(RosEvalError::BadAnswer {
                        candidate: n,
                        value: dx,
                    });
                }
                let t_fall = fall_time.filter(|t| t.is_finite() && *t >= 0.0).unwrap_or(0.0);
                return Ok(Evaluation::from_outcome(
                    &self.fitness,
                    self.model.step_time,
                    fell,
                    t_fall,
                    dx,
                ));
            }
            if Instant::now() >= deadline {
                let missing = [(fell.is_none(), FELL_TOPIC), (forward.is_none(), FORWARD_TOPIC)]
                    .iter()
                    .filter(|(m, _)| *m)
                    .map(|(_, t)| *t)
                    .collect::<Vec<_>>()
                    .join(" and ");
                return Err(RosEvalError::Timeout {
                    candidate: n,
                    missing,
                    timeout: timeout_s,
                });
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }
}

impl Evaluator for RosEvaluator {
    fn evaluate(&self, individual: &Individual) -> Evaluation {
        let mut link = self.link.lock().unwrap_or_else(PoisonError::into_inner);
        let zero = Evaluation {
            fitness: 0.0,
            fell: true,
            t_fall: 0.0,
            forward_distance: 0.0,
        };
        if link.failed.is_some() {
            return zero;
        }
        match self.round_trip(&mut link, individual) {
            Ok(e) => e,
            Err(e) => {
                link.failed = Some(e);
                zero
            }
        }
    }
}
