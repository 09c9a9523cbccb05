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
//! generation in flight, so the run resumes from its last checkpoint.
//!
//! **A pool of simulators** (`--pool`, an extension of the contract above; without it a lone
//! simulator in the node's namespace is served exactly as before): every simulator that serves
//! the two topics in a namespace *below* the node's (`<ns>/ga_step/candidate` and
//! `<ns>/ga_step/outcome`, e.g. `/sim1/ga_step/…` and `/sim2/ga_step/…` for a node in `/`), and
//! the one in the node's own namespace if there is one, is found by discovery, from the writers
//! of its outcomes, as it appears, and is named by its namespace. Each simulator has one
//! candidate in flight at a time. The rules of which one gets the next candidate, when a
//! candidate is sent again and when the pool gives up are `mobil_ga_step::pool`'s: a candidate
//! goes to a free simulator among those with the fewest attempts missed in a row; one whose
//! simulator leaves (its endpoints vanish) is sent again to another without counting an attempt
//! (up to three times); a simulator that missed an answer gets no candidate while another
//! answers; the run ends when every simulator present has missed [`MAX_UNANSWERED_IN_A_ROW`]
//! attempts in a row, or when none has been present for the timeout. Headers are as above (a
//! candidate sent to a second simulator keeps its header), so a simulator never needs to know
//! of the others. Which simulator scored a candidate does not change its score, so the results
//! depend on the seed alone. The candidates in flight are at most the threads the evaluator runs
//! on ([`MAX_IN_FLIGHT`] with `--threads 0`). When the outcome topic is remapped to a name that
//! does not end in `ga_step/outcome`, only that one simulator is used.

use mobil_ga_step::external::{candidate_name, Outcome, VOID};
use mobil_ga_step::pool::{
    pool_base, pool_namespaces, AttemptEnd, CandidateTries, Change, NextTry, Pick, SimulatorPool, OUTCOME_SUFFIX,
};
use mobil_ga_step::{Evaluation, Evaluator, FitnessConfig, Individual, NaoModel, KNOTS};
use mobil_msgs::builtin_interfaces::msg::{Duration as RosDuration, Time};
use mobil_msgs::sensor_msgs::msg::JointState;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::trajectory_msgs::msg::{JointTrajectory, JointTrajectoryPoint};
use mobil_ros::args::RosArgs;
use mobil_ros::node::{NodeDecl, RosNode};
use mobil_ros::{qos, warn_throttled, LogThrottle};
use ros2_client::{NodeEvent, Publisher, Subscription};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

/// Topic of the candidates.
pub const CANDIDATE_TOPIC: &str = "ga_step/candidate";
/// Topic of the simulator's answers.
pub const OUTCOME_TOPIC: &str = "ga_step/outcome";
/// Attempts in a row without an answer (of the timeout each, over one or more candidates) at
/// every simulator present that end the run.
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
    #[error("every simulator left {MAX_UNANSWERED_IN_A_ROW} attempts in a row (the last for candidate {candidate}) unanswered within {timeout:.1} s each")]
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

/// One simulator: its name and its two topics.
struct SimLink {
    /// The simulator's name: the namespace its topics are in (`/` for the root), or its outcome
    /// topic when that is remapped to another form.
    id: String,
    io: Mutex<SimIo>,
}

/// A simulator's topics and what its waiting candidate needs to know.
// Field order is drop order: the writer and reader go before the node that owns their
// participant (mobil_ros: readers and writers must go while their participant exists), which
// `Shared` drops after its links.
struct SimIo {
    candidates: Publisher<JointTrajectory>,
    outcome: Subscription<JointState>,
    /// A new reader of the candidates was matched (a restarted simulator, even within the old
    /// one's lease; a first sample lost during discovery): the waiting candidate is sent again.
    new_reader: bool,
    throttle: LogThrottle,
}

impl SimLink {
    fn io(&self) -> MutexGuard<'_, SimIo> {
        self.io.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// The evaluator's state behind its lock.
// Field order is drop order: the links go before the node.
struct Shared {
    links: Vec<Arc<SimLink>>,
    book: SimulatorPool,
    /// The node's graph events, taken once. `None` without a spinner.
    events: Option<async_channel::Receiver<NodeEvent>>,
    node: RosNode,
    /// With `--pool`, where more simulators are looked for: topics `<base><ns>/ga_step/outcome`.
    base: Option<String>,
    /// The outcome topic of the simulator in the node's own namespace (resolved and remapped).
    own_outcome: String,
    sent: u64,
    void_scores: u64,
    failed: Option<RosEvalError>,
    last_scan: Option<Instant>,
    /// Since when no simulator has been present.
    absent_since: Option<Instant>,
    throttle: LogThrottle,
}

/// The evaluator over ROS 2 (see the module's documentation).
pub struct RosEvaluator {
    shared: Mutex<Option<Shared>>,
    /// Told when a simulator is freed or joins, and when the evaluator fails.
    changed: Condvar,
    model: NaoModel,
    fitness: FitnessConfig,
    timeout: Duration,
    resend_every: Duration,
    interrupt: Arc<AtomicBool>,
    runtime: tokio::runtime::Runtime,
}

/// How often a waiting candidate looks at the graph, the interrupt and the evaluator's failure.
const POLL: Duration = Duration::from_millis(10);
/// How often a waiting candidate looks for its answer.
const ANSWER_POLL: Duration = Duration::from_millis(1);
/// How long a candidate waiting for a free simulator sleeps unless told of one.
const FREE_WAIT: Duration = Duration::from_millis(100);
/// How often the discovered topics are searched for simulators while candidates wait.
const SCAN_EVERY: Duration = Duration::from_millis(250);
/// Answers taken in one pass before the deadline and the interrupt are looked at again (a
/// publisher flooding the outcome topic cannot hold the wait).
const ANSWERS_PER_PASS: usize = 64;
/// The most candidates in flight at once with `--threads 0`.
pub const MAX_IN_FLIGHT: usize = 64;

/// How an attempt ended, with the answer's score.
enum Ended {
    Answered(Evaluation),
    Missed,
    Lost,
}

impl Ended {
    fn kind(&self) -> AttemptEnd {
        match self {
            Ended::Answered(_) => AttemptEnd::Answered,
            Ended::Missed => AttemptEnd::Missed,
            Ended::Lost => AttemptEnd::Lost,
        }
    }
}

impl RosEvaluator {
    /// Joins the DDS domain of `ROS_DOMAIN_ID` as node `ga_step` (its name, namespace and topics
    /// remapped by `args`) and creates the topics of the simulator in its namespace; with `pool`,
    /// simulators in namespaces below it are found as they appear. `interrupt` set stops any
    /// waiting.
    pub fn new(
        model: NaoModel,
        fitness: FitnessConfig,
        timeout: Duration,
        pool: bool,
        args: &RosArgs,
        interrupt: Arc<AtomicBool>,
    ) -> anyhow::Result<RosEvaluator> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()?;
        let shared = {
            let _entered = runtime.enter();
            let decl = NodeDecl::new("ga_step", "evolves a humanoid step; evaluates candidates over ROS 2");
            let mut node = RosNode::start(&decl, args)?;
            let q = qos::reliable(10);
            let own_outcome = node.names().resolve(OUTCOME_TOPIC)?;
            let (base, own_id) = pool_base(&own_outcome);
            let candidates = node.publisher::<JointTrajectory>(CANDIDATE_TOPIC, &q)?;
            let outcome = node.subscription::<JointState>(OUTCOME_TOPIC, &q)?;
            let events = node.inner().status_receiver();
            let own = SimLink {
                id: own_id,
                io: Mutex::new(SimIo {
                    candidates,
                    outcome,
                    new_reader: false,
                    throttle: LogThrottle::default(),
                }),
            };
            Shared {
                links: vec![Arc::new(own)],
                book: SimulatorPool::new(MAX_UNANSWERED_IN_A_ROW),
                events,
                node,
                base: base.filter(|_| pool),
                own_outcome,
                sent: 0,
                void_scores: 0,
                failed: None,
                last_scan: None,
                absent_since: Some(Instant::now()),
                throttle: LogThrottle::default(),
            }
        };
        Ok(RosEvaluator {
            shared: Mutex::new(Some(shared)),
            changed: Condvar::new(),
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

    fn lock(&self) -> MutexGuard<'_, Option<Shared>> {
        self.shared.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The error that stopped the evaluator, if one did.
    pub fn failure(&self) -> Option<RosEvalError> {
        self.lock().as_ref().and_then(|s| s.failed.clone())
    }

    /// Candidates that went unanswered after every attempt and scored 0 (void scores).
    pub fn void_scores(&self) -> u64 {
        self.lock().as_ref().map_or(0, |s| s.void_scores)
    }

    /// Brings the pool up to date with the graph: simulators found in new namespaces (with
    /// `--pool`), the readers and writers of each, who joined, restarted or left. Cheap unless
    /// the graph changed or [`SCAN_EVERY`] passed.
    fn refresh(&self, sh: &mut Shared) {
        let changed = match &sh.events {
            Some(events) => {
                let mut changed = false;
                while events.try_recv().is_ok() {
                    changed = true;
                }
                changed
            }
            None => false,
        };
        let now = Instant::now();
        if !changed && sh.last_scan.is_some_and(|t| now.duration_since(t) < SCAN_EVERY) {
            return;
        }
        sh.last_scan = Some(now);
        if let Some(base) = sh.base.clone() {
            let topics = sh.node.writer_topics::<JointState>();
            for ns in pool_namespaces(&topics, &base, &sh.own_outcome) {
                if sh.links.iter().any(|l| l.id == ns) {
                    continue;
                }
                let _entered = self.runtime.enter();
                let q = qos::reliable(10);
                let candidate_topic = format!("{ns}{}", CANDIDATE_SUFFIX);
                let outcome_topic = format!("{ns}{OUTCOME_SUFFIX}");
                let made = sh
                    .node
                    .publisher::<JointTrajectory>(&candidate_topic, &q)
                    .and_then(|c| Ok((c, sh.node.subscription::<JointState>(&outcome_topic, &q)?)));
                match made {
                    Ok((candidates, outcome)) => sh.links.push(Arc::new(SimLink {
                        id: ns,
                        io: Mutex::new(SimIo {
                            candidates,
                            outcome,
                            new_reader: false,
                            throttle: LogThrottle::default(),
                        }),
                    })),
                    Err(e) => warn_throttled!(sh.throttle, "link", "cannot reach the simulator in {ns}: {e:#}"),
                }
            }
        }
        let Shared { links, book, node, .. } = sh;
        let mut joined = false;
        for link in links.iter() {
            let mut io = link.io();
            let readers = io.candidates.get_subscription_count(node.inner());
            let writers = io.outcome.get_publisher_count(node.inner());
            match book.observe(&link.id, readers, writers) {
                Change::None => {}
                Change::Joined => {
                    joined = true;
                    tracing::info!("simulator {} joined ({} present)", link.id, book.present());
                }
                Change::Restarted => io.new_reader = true,
                Change::Left => tracing::warn!("simulator {} left ({} present)", link.id, book.present()),
            }
        }
        sh.absent_since = match (sh.book.present(), sh.absent_since) {
            (0, None) => Some(now),
            (0, since) => since,
            _ => None,
        };
        if joined {
            self.changed.notify_all();
        }
    }

    /// A simulator for a candidate: waits while every usable one is busy, up to the timeout
    /// while none is present. Gives the candidate its number (`ident`) on its first attempt.
    fn acquire(&self, ident: &mut Option<u64>) -> Result<Arc<SimLink>, RosEvalError> {
        let started = Instant::now();
        let mut guard = self.lock();
        loop {
            let Some(sh) = guard.as_mut() else {
                return Err(RosEvalError::Interrupted(ident.unwrap_or(0)));
            };
            // The number the candidate has or will have (for the errors).
            let n = ident.unwrap_or(sh.sent + 1);
            if let Some(e) = &sh.failed {
                return Err(e.clone());
            }
            if self.interrupt.load(Ordering::SeqCst) {
                return Err(RosEvalError::Interrupted(n));
            }
            self.refresh(sh);
            match sh.book.pick() {
                Pick::Use(id) => {
                    if let Some(link) = sh.links.iter().find(|l| l.id == id).cloned() {
                        if ident.is_none() {
                            sh.sent = n;
                            *ident = Some(n);
                        }
                        return Ok(link);
                    }
                    // Slots are made from links only; a slot without one is left out.
                    sh.book.release(&id, AttemptEnd::Lost);
                    sh.book.gone(&id);
                }
                Pick::Exhausted => {
                    return Err(RosEvalError::Unanswered {
                        candidate: sh.sent,
                        timeout: self.timeout.as_secs_f64(),
                    });
                }
                Pick::Wait => {
                    // None present for the timeout, counted from this wait's start at the earliest.
                    if sh
                        .absent_since
                        .is_some_and(|t| t.max(started).elapsed() >= self.timeout)
                    {
                        return Err(RosEvalError::NoSimulator(self.timeout.as_secs_f64()));
                    }
                }
            }
            // The first wait for a simulator to appear looks at the graph often; a wait for a
            // busy one is told when it is freed.
            let nap = if sh.book.present() == 0 { POLL } else { FREE_WAIT };
            guard = self
                .changed
                .wait_timeout(guard, nap)
                .unwrap_or_else(PoisonError::into_inner)
                .0;
        }
    }

    /// One attempt of candidate `n` at `link`: sends it, then waits up to the timeout for its
    /// answer, sending it again every `resend_every` and whenever a new reader of the
    /// candidates is matched; ends early when the simulator leaves or the evaluator fails.
    fn attempt(
        &self,
        link: &SimLink,
        n: u64,
        header: &Header,
        message: &JointTrajectory,
    ) -> Result<Ended, RosEvalError> {
        {
            let mut io = link.io();
            io.new_reader = false;
            io.candidates
                .publish(message.clone())
                .map_err(|e| RosEvalError::Publish(n, format!("{e:?}")))?;
        }
        let deadline = Instant::now() + self.timeout;
        let mut next_send = Instant::now() + self.resend_every;
        let mut next_look = Instant::now();
        loop {
            {
                let mut io = link.io();
                for _ in 0..ANSWERS_PER_PASS {
                    let Ok(Some((m, _))) = io.outcome.take() else {
                        break;
                    };
                    if m.header != *header {
                        warn_throttled!(
                            io.throttle,
                            "stale",
                            "discarded an outcome for `{}` at {}.{:09} while waiting for `{}` at {}.{:09} from {}",
                            m.header.frame_id,
                            m.header.stamp.sec,
                            m.header.stamp.nanosec,
                            header.frame_id,
                            header.stamp.sec,
                            header.stamp.nanosec,
                            link.id
                        );
                        continue;
                    }
                    return Ok(Ended::Answered(match parse_outcome(&m) {
                        Ok(o) => o.evaluation(&self.fitness, &self.model),
                        Err(reason) => {
                            warn_throttled!(
                                io.throttle,
                                "bad",
                                "candidate {n}: bad outcome from {} ({reason}); scored 0 as a fall at 0 s",
                                link.id
                            );
                            VOID
                        }
                    }));
                }
            }
            if self.interrupt.load(Ordering::SeqCst) {
                return Err(RosEvalError::Interrupted(n));
            }
            let now = Instant::now();
            if now >= next_look {
                next_look = now + POLL;
                let mut guard = self.lock();
                let Some(sh) = guard.as_mut() else {
                    return Err(RosEvalError::Interrupted(n));
                };
                if let Some(e) = &sh.failed {
                    return Err(e.clone());
                }
                self.refresh(sh);
                // Decided here, under the lock that `refresh` and `acquire` hold: a simulator
                // that left at any time since it was picked is gone from the pool.
                if !sh.book.is_present(&link.id) {
                    return Ok(Ended::Lost);
                }
            }
            if now >= deadline {
                return Ok(Ended::Missed);
            }
            let mut io = link.io();
            // The same candidate again (same header: the answers to the copies are discarded).
            if std::mem::take(&mut io.new_reader) || now >= next_send {
                io.candidates
                    .publish(message.clone())
                    .map_err(|e| RosEvalError::Publish(n, format!("{e:?}")))?;
                next_send = now + self.resend_every;
            }
            drop(io);
            std::thread::sleep(ANSWER_POLL);
        }
    }

    /// The attempt at `link` is over: the simulator is free again.
    fn release(&self, link: &SimLink, end: AttemptEnd) {
        if let Some(sh) = self.lock().as_mut() {
            sh.book.release(&link.id, end);
        }
        self.changed.notify_all();
    }

    fn fail(&self, e: RosEvalError) {
        if let Some(sh) = self.lock().as_mut() {
            sh.failed.get_or_insert(e);
        }
        self.changed.notify_all();
    }

    /// A candidate evaluated by the pool, or the error that stops the evaluator.
    fn evaluate_candidate(&self, individual: &Individual) -> Result<Evaluation, RosEvalError> {
        let mut tries = CandidateTries::new(ATTEMPTS);
        let mut ident = None;
        let mut sent: Option<(Header, JointTrajectory)> = None;
        loop {
            let link = self.acquire(&mut ident)?;
            let n = ident.unwrap_or(0);
            let (header, message) = sent.get_or_insert_with(|| {
                // Wall-clock time: unique across runs even under use_sim_time.
                let nanos = std::time::SystemTime::now()
                    .duration_since(std::time::UNIX_EPOCH)
                    .map(|d| d.as_nanos() as i64)
                    .unwrap_or(0);
                let header = candidate_header(n, mobil_ros::time::stamp_from_nanos(nanos));
                let message = candidate_message(&self.model, individual, header.clone());
                (header, message)
            });
            let ended = self.attempt(&link, n, header, message);
            self.release(&link, ended.as_ref().map_or(AttemptEnd::Lost, Ended::kind));
            let end = match ended? {
                Ended::Answered(e) => return Ok(e),
                Ended::Lost => {
                    tracing::warn!("candidate {n}: simulator {} left before answering; sent again", link.id);
                    AttemptEnd::Lost
                }
                Ended::Missed => {
                    let mut guard = self.lock();
                    if let Some(sh) = guard.as_mut() {
                        warn_throttled!(
                            sh.throttle,
                            "timeout",
                            "candidate {n}: no outcome from {} within {:.1} s (attempt {} of {ATTEMPTS})",
                            link.id,
                            self.timeout.as_secs_f64(),
                            tries.missed() + 1
                        );
                    }
                    AttemptEnd::Missed
                }
            };
            if tries.after(end) == NextTry::Void {
                let mut guard = self.lock();
                if let Some(sh) = guard.as_mut() {
                    sh.void_scores += 1;
                    warn_throttled!(
                        sh.throttle,
                        "void",
                        "candidate {n}: unanswered after {ATTEMPTS} attempts; scored 0 as a fall at 0 s ({} so far)",
                        sh.void_scores
                    );
                }
                return Ok(VOID);
            }
        }
    }
}

/// The last two levels of the contract's candidate topic.
const CANDIDATE_SUFFIX: &str = "/ga_step/candidate";

impl Evaluator for RosEvaluator {
    fn evaluate(&self, individual: &Individual) -> Evaluation {
        match self.evaluate_candidate(individual) {
            Ok(e) => e,
            Err(e) => {
                self.fail(e);
                VOID
            }
        }
    }
}

impl Drop for RosEvaluator {
    /// Leaves the DDS domain cleanly: writers and readers first, then the node and its
    /// participant.
    fn drop(&mut self) {
        let shared = self.shared.get_mut().unwrap_or_else(PoisonError::into_inner).take();
        if let Some(Shared { links, node, .. }) = shared {
            drop(links);
            self.runtime.block_on(node.shutdown());
        }
    }
}
