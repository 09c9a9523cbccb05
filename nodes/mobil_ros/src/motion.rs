//! The motion server: one goal at a time, for every node that moves the robot.
//!
//! A motion node takes goals from topics and actions and drives them with a goal law
//! ([`mobil_motion::GoalLaw`]). What happens around the law is the same in every such node and
//! lives here, once, testable without DDS:
//! - **one goal at a time**: [`MotionSession::start`] makes a goal the active one and ends the
//!   one it replaces, `PREEMPTED`;
//! - **the time step**: [`MotionSession::advance`] takes ROS time ([`DtClock`]), refuses a
//!   step when the clock stood still or went back (the goal's own time carries on), gives the
//!   first step [`SessionSettings::first_dt`] and holds every later one to
//!   [`SessionSettings::max_dt`];
//! - **refused input**: a step whose input the law refuses stops the robot (one zero command,
//!   not one per refusal), and [`SessionSettings::max_refused_steps`] in a row end the goal
//!   `INVALID_INPUT`;
//! - **the zero command**: every end sends one zero command if the goal commanded the robot or
//!   the robot may still be moving on an earlier command, and never more than one; a goal that
//!   never moved the robot ends without one. A goal that replaces a moving one sends none
//!   between them (it commands at its first step); one that cannot command yet
//!   ([`MotionSession::hold`]: a pre-check, a first optimisation) stops the robot;
//! - **stale input**: [`MotionSession::stale`] names the inputs older than their timeout, a
//!   goal getting one timeout from its start for them to arrive;
//! - **a stopped clock**: [`MotionSession::watch_clock`], at every watchdog tick, holds the
//!   robot (one zero command, no command until it moves again) while ROS time has not advanced
//!   for longer than the node's `clock_timeout_s` (steady clock: a paused or stalled `/clock`),
//!   and ends the goal `CLOCK_BACKWARDS` when ROS time goes back;
//! - **shutdown**: [`MotionSession::shutdown`] ends the goal `SHUTDOWN` and says whether the
//!   node's last word must be a zero command ([`crate::stop::final_stop`], waited for).
//!
//! The node keeps what differs: validating a goal, the law, converting its command to the
//! chassis' limits, its status and feedback messages, and its action servers, which it answers
//! with each [`Ended`] the session returns.
//!
//! ```
//! use mobil_ros::motion::{CommandSink, EndCause, MotionSession, SessionSettings};
//! use mobil_msgs::geometry_msgs::msg::Twist;
//! use std::time::Instant;
//!
//! let mut sent: Vec<Twist> = Vec::new();
//! let mut session = MotionSession::<&str, &str>::new(SessionSettings::default());
//! let (_, old) = session.start("to the dock", "dock_pose", Instant::now());
//! assert!(old.is_none());
//! let mut t = Twist::default();
//! t.linear.x = 0.2;
//! session.command(t, &mut sent);
//! let ended = session.end(EndCause::Canceled, &mut sent).unwrap();
//! assert_eq!((ended.goal, ended.cause.code()), ("to the dock", "CANCELED"));
//! assert_eq!(sent.len(), 2); // the command, then one zero
//! assert_eq!(sent[1], Twist::default());
//! ```

use crate::cmd_vel::CmdVelOut;
use crate::log::LogThrottle;
use crate::status::{NavStatusView, StatusMessage};
use crate::time::{ClockState, ClockWatch, DtClock, DtError};
use mobil_motion::health::{InputAge, MotionReport};
use mobil_motion::{BodyTwist, End, Step};
pub use mobil_motion::{EndCause, EndKind};
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::Twist;
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::visualization_msgs::msg::MarkerArray;
use ros2_client::Publisher;
use std::time::{Duration, Instant};

/// Where the session's commands go: `cmd_vel` in a node, a recorder in a test.
pub trait CommandSink {
    /// Sends one command.
    fn send(&mut self, twist: &Twist);
}

/// A recorder of every command, in order (a test's sink).
impl CommandSink for Vec<Twist> {
    fn send(&mut self, twist: &Twist) {
        self.push(twist.clone());
    }
}

/// `cmd_vel` as the session's sink: each command published, a failure logged (rate-limited).
pub struct CmdVel<'a> {
    publisher: &'a CmdVelOut,
    throttle: LogThrottle,
}

impl<'a> CmdVel<'a> {
    /// Commands go to `publisher`.
    pub fn new(publisher: &'a CmdVelOut) -> Self {
        CmdVel {
            publisher,
            throttle: LogThrottle::new(Duration::from_secs(2)),
        }
    }
}

impl CommandSink for CmdVel<'_> {
    fn send(&mut self, twist: &Twist) {
        if let Err(e) = self.publisher.publish(twist.clone()) {
            crate::warn_throttled!(self.throttle, "cmd", "cannot publish cmd_vel: {e}");
        }
    }
}

/// The session's rules that a node may set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SessionSettings {
    /// The `dt` (s) of a goal's first step, which has no step before it.
    pub first_dt: f64,
    /// The largest `dt` (s) a step gets: a gap in the input (a late odometry message, a paused
    /// simulation) is not integrated as one long step.
    pub max_dt: f64,
    /// Refused steps in a row that end the goal `INVALID_INPUT`.
    pub max_refused_steps: u32,
}

impl Default for SessionSettings {
    /// 20 ms first (one period of a 50 Hz odometry), at most 0.1 s, 20 refusals in a row.
    fn default() -> Self {
        SessionSettings {
            first_dt: 0.02,
            max_dt: 0.1,
            max_refused_steps: 20,
        }
    }
}

/// What a navigating motion node publishes: `cmd_vel`, its latched `<name>/status` (the last
/// one reaches a late subscriber) and `<name>/markers`.
pub struct Outputs {
    /// The commands (Twist or TwistStamped).
    pub cmd: CmdVelOut,
    /// The status.
    pub status: Publisher<NavStatus>,
    /// RViz markers.
    pub markers: Publisher<MarkerArray>,
    /// The node's name, for the topics' names in warnings.
    name: String,
}

impl Outputs {
    /// The three publishers of node `name` (`planner`, `local_nav`); `cmd_vel` stamped in
    /// `base_frame` when `stamped` ([`crate::cmd_vel`]).
    pub fn create(node: &mut crate::RosNode, name: &str, stamped: bool, base_frame: &str) -> anyhow::Result<Self> {
        Ok(Outputs {
            cmd: CmdVelOut::create(node, "cmd_vel", stamped, base_frame)?,
            status: node.publisher::<NavStatus>(&format!("{name}/status"), &crate::qos::latched())?,
            markers: node.publisher::<MarkerArray>(&format!("{name}/markers"), &crate::qos::default_qos())?,
            name: name.to_owned(),
        })
    }

    /// Publishes the status of `view`, stamped `stamp`, in `frame` (a failure: one rate-limited
    /// warning).
    pub fn send_status(&self, view: &NavStatusView, stamp: Time, frame: &str, throttle: &mut LogThrottle) {
        if let Err(e) = self.status.publish(view.message(stamp, frame)) {
            crate::warn_throttled!(throttle, "status", "cannot publish {}/status: {e:?}", self.name);
        }
    }

    /// Publishes `markers` (a failure: one rate-limited warning).
    pub fn send_markers(&self, markers: MarkerArray, throttle: &mut LogThrottle) {
        if let Err(e) = self.markers.publish(markers) {
            crate::warn_throttled!(throttle, "markers", "cannot publish {}/markers: {e:?}", self.name);
        }
    }
}

/// Which goal: unique over a session's life, so a result computed for a goal that has since
/// ended (off the event loop) can be recognised and dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct GoalId(u64);

/// A goal that ended, handed back to the node to tell its client and its status.
#[derive(Debug, Clone, PartialEq)]
pub struct Ended<G, S> {
    /// Which goal.
    pub id: GoalId,
    /// The node's goal state as it ended.
    pub goal: G,
    /// Where it came from.
    pub source: S,
    /// Why it ended.
    pub cause: EndCause,
    /// Its own time at the end (s since its first step).
    pub t: f64,
    /// Whether a zero command went out at this end.
    pub zeroed: bool,
    /// Replaced by a goal from its own source: an action server ended it itself (PREEMPTED)
    /// when it accepted the newer goal, so the node answers it no more (a topic's goal has no
    /// client to answer either way).
    pub server_ended: bool,
}

/// The active goal.
#[derive(Debug, Clone)]
pub struct Active<G, S> {
    id: GoalId,
    /// The node's goal state (its law and what the node keeps with it).
    pub goal: G,
    /// Where it came from.
    pub source: S,
    started: Instant,
    clock: DtClock,
    t: f64,
    refused: u32,
    commanded: bool,
}

impl<G, S> Active<G, S> {
    /// Which goal.
    pub fn id(&self) -> GoalId {
        self.id
    }

    /// Its own time (s): the sum of its steps' `dt`, so a clock reset never makes it jump.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// How long it has run (steady clock) at `now`.
    pub fn age(&self, now: Instant) -> Duration {
        now.saturating_duration_since(self.started)
    }
}

/// What [`MotionSession::apply`] did with a law's step.
#[derive(Debug, Clone, PartialEq)]
pub enum Applied<F, R, G, S> {
    /// The command went out; the law's feedback.
    Commanded(F),
    /// The input was refused; the robot stopped. `Some` when this refusal ended the goal.
    Refused(Option<Ended<G, S>>),
    /// The law ended the goal; its report.
    Ended(Ended<G, S>, R),
    /// No goal was active: nothing was sent.
    Idle,
}

/// One input a goal depends on, for [`MotionSession::stale`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Watched {
    /// Its name in the reason (`odom`, `scan`).
    pub name: &'static str,
    /// The age of its last valid message (`None`: never).
    pub age: Option<Duration>,
    /// How old it may get.
    pub timeout: Duration,
}

/// One goal at a time, its time, its commands and its end (module docs).
#[derive(Debug, Clone)]
pub struct MotionSession<G, S> {
    settings: SessionSettings,
    active: Option<Active<G, S>>,
    /// The last command sent moved the robot (not zero).
    moving: bool,
    next_id: u64,
    clock: ClockWatch,
    /// How long ROS time had stood still when last looked at, while the robot is held for it.
    clock_held: Option<Duration>,
    /// How the last goal ended (its code), for `/diagnostics`.
    last_end: Option<String>,
}

/// What [`MotionSession::watch_clock`] found.
#[derive(Debug, Clone, PartialEq)]
pub enum ClockCheck<G, S> {
    /// ROS time runs, or has stood still for no longer than the timeout, or no goal runs.
    Running,
    /// ROS time moved again after the robot was held: the goal commands again.
    Resumed,
    /// ROS time has not advanced for `stopped` (beyond the timeout): the robot is held until it
    /// moves again; `newly` at the first look of the hold (the one that stopped the robot).
    Held {
        /// How long ROS time has stood still.
        stopped: Duration,
        /// This look began the hold.
        newly: bool,
    },
    /// ROS time went back: the active goal ended `CLOCK_BACKWARDS`.
    Back(Ended<G, S>),
}

impl<G, S> ClockCheck<G, S> {
    /// What the node tells of it: a warning when the hold begins, a line when time moves again
    /// (a goal that ended is told by its end).
    pub fn notice(&self) -> Option<mobil_motion::Notice> {
        match self {
            ClockCheck::Held { stopped, newly: true } => Some(mobil_motion::Notice::Warn(format!(
                "ROS time has not advanced for {:.2} s (clock paused or stalled): robot held until it moves again",
                stopped.as_secs_f64()
            ))),
            ClockCheck::Resumed => Some(mobil_motion::Notice::Info(
                "ROS time moves again: the goal goes on".to_owned(),
            )),
            ClockCheck::Held { newly: false, .. } | ClockCheck::Running | ClockCheck::Back(_) => None,
        }
    }
}

fn is_zero(t: &Twist) -> bool {
    [
        t.linear.x,
        t.linear.y,
        t.linear.z,
        t.angular.x,
        t.angular.y,
        t.angular.z,
    ]
    .iter()
    .all(|v| *v == 0.0)
}

impl<G, S> MotionSession<G, S> {
    /// A session with no goal.
    pub fn new(settings: SessionSettings) -> Self {
        MotionSession {
            settings,
            active: None,
            moving: false,
            next_id: 0,
            clock: ClockWatch::new(),
            clock_held: None,
            last_end: None,
        }
    }

    /// The rules it follows.
    pub fn settings(&self) -> &SessionSettings {
        &self.settings
    }

    /// New rules, from the next step on.
    pub fn set_settings(&mut self, settings: SessionSettings) {
        self.settings = settings;
    }

    /// The active goal.
    pub fn active(&self) -> Option<&Active<G, S>> {
        self.active.as_ref()
    }

    /// The active goal, to change the node's goal state.
    pub fn active_mut(&mut self) -> Option<&mut Active<G, S>> {
        self.active.as_mut()
    }

    /// Whether goal `id` is still the active one.
    pub fn is_current(&self, id: GoalId) -> bool {
        self.active.as_ref().is_some_and(|a| a.id == id)
    }

    /// Whether the last command sent moved the robot.
    pub fn moving(&self) -> bool {
        self.moving
    }

    /// Makes `goal` the active goal at `now`; the goal it replaces, if any, ends `PREEMPTED`
    /// (named by the new goal's source) without a zero command: the new goal commands at its
    /// first step, or [`MotionSession::hold`]s.
    pub fn start(&mut self, goal: G, source: S, now: Instant) -> (GoalId, Option<Ended<G, S>>)
    where
        S: Copy + PartialEq + Into<&'static str>,
    {
        let old = self.active.take().map(|a| Ended {
            id: a.id,
            server_ended: a.source == source,
            goal: a.goal,
            source: a.source,
            cause: EndCause::Preempted(source.into()),
            t: a.t,
            zeroed: false,
        });
        if let Some(old) = &old {
            self.last_end = Some(old.cause.code().to_owned());
        }
        let id = GoalId(self.next_id);
        self.next_id += 1;
        self.active = Some(Active {
            id,
            goal,
            source,
            started: now,
            clock: DtClock::new(),
            t: 0.0,
            refused: 0,
            commanded: false,
        });
        (id, old)
    }

    /// The active goal's time step at ROS time `now_nanos` (s): the first step gets
    /// [`SessionSettings::first_dt`], a later one the time since the previous step held to
    /// [`SessionSettings::max_dt`]. A clock that stood still or went back gives no step (the
    /// error says which), and the goal's own time carries on from where it was. `None` without
    /// a goal.
    pub fn advance(&mut self, now_nanos: i64) -> Option<Result<f64, DtError>> {
        let settings = self.settings;
        let active = self.active.as_mut()?;
        let dt = match active.clock.step(now_nanos) {
            Ok(None) => settings.first_dt,
            Ok(Some(dt)) => dt.min(settings.max_dt),
            Err(e) => {
                if let DtError::Backwards { .. } = e {
                    // Seen here first: the watch starts again from the new time, so the jump is
                    // not told again, to this goal's end or to the next goal.
                    self.clock = ClockWatch::new();
                }
                return Some(Err(e));
            }
        };
        active.t += dt;
        Some(Ok(dt))
    }

    /// Sends a command for the active goal (none without one; while ROS time stands still, the
    /// robot is held instead: [`MotionSession::watch_clock`]).
    pub fn command(&mut self, twist: Twist, sink: &mut impl CommandSink) {
        if self.clock_held.is_some() {
            return self.hold(sink);
        }
        let Some(active) = self.active.as_mut() else { return };
        active.commanded = true;
        active.refused = 0;
        self.moving = !is_zero(&twist);
        sink.send(&twist);
    }

    /// Stops the robot while the active goal cannot command (waiting for a pre-check or an
    /// optimisation): one zero command if it is moving, none otherwise.
    pub fn hold(&mut self, sink: &mut impl CommandSink) {
        if self.active.is_some() && self.moving {
            self.send_zero(sink);
        }
    }

    fn send_zero(&mut self, sink: &mut impl CommandSink) {
        if let Some(a) = self.active.as_mut() {
            a.commanded = true;
        }
        self.moving = false;
        sink.send(&Twist::default());
    }

    /// The active goal's input was refused (`why`): the robot stops (one zero command while it
    /// moves), and the goal ends `INVALID_INPUT` at the
    /// [`SessionSettings::max_refused_steps`]-th refusal in a row.
    pub fn refuse(&mut self, why: String, sink: &mut impl CommandSink) -> Option<Ended<G, S>> {
        let limit = self.settings.max_refused_steps;
        let active = self.active.as_mut()?;
        active.refused = active.refused.saturating_add(1);
        let count = active.refused;
        if count >= limit {
            return self.end(EndCause::Refused { count, last: why }, sink);
        }
        self.hold(sink);
        None
    }

    /// Ends the active goal with `cause`: one zero command if the goal commanded the robot or
    /// the robot may still be moving, none otherwise. `None` without a goal.
    pub fn end(&mut self, cause: EndCause, sink: &mut impl CommandSink) -> Option<Ended<G, S>> {
        let commanded = self.active.as_ref()?.commanded;
        let zeroed = commanded || self.moving;
        if zeroed {
            self.send_zero(sink);
        }
        let a = self.active.take()?;
        self.last_end = Some(cause.code().to_owned());
        Some(Ended {
            id: a.id,
            goal: a.goal,
            source: a.source,
            cause,
            t: a.t,
            zeroed,
            server_ended: false,
        })
    }

    /// Ends the active goal `PREEMPTED` by a goal from `by` that does not start (its action
    /// server accepted it, then the node refused it, or its start failed): one zero command, as
    /// at any end; [`Ended::server_ended`] when the goal came from `by` too, whose server ended
    /// it on accepting the newer one. `None` without a goal.
    pub fn preempt(&mut self, by: S, sink: &mut impl CommandSink) -> Option<Ended<G, S>>
    where
        S: Copy + PartialEq + Into<&'static str>,
    {
        let mut ended = self.end(EndCause::Preempted(by.into()), sink)?;
        ended.server_ended = ended.source == by;
        Some(ended)
    }

    /// Ends goal `id` with `cause` if it is still the active one (a cancel, a result computed
    /// off the loop); `None` if it already ended.
    pub fn end_if_current(&mut self, id: GoalId, cause: EndCause, sink: &mut impl CommandSink) -> Option<Ended<G, S>> {
        if self.is_current(id) {
            self.end(cause, sink)
        } else {
            None
        }
    }

    /// What the node does with one law step of the active goal: a command goes out through
    /// `to_twist` (the node's conversion and chassis limits), a refusal stops the robot, an
    /// end ends the goal.
    pub fn apply<F, R>(
        &mut self,
        step: Step<F, R>,
        to_twist: impl FnOnce(BodyTwist) -> Twist,
        sink: &mut impl CommandSink,
    ) -> Applied<F, R, G, S> {
        if self.active.is_none() {
            return Applied::Idle;
        }
        match step {
            Step::Command { twist, feedback } => {
                self.command(to_twist(twist), sink);
                Applied::Commanded(feedback)
            }
            Step::Refused(why) => Applied::Refused(self.refuse(why, sink)),
            Step::End(End { outcome, report }) => match self.end(EndCause::Outcome(outcome), sink) {
                Some(ended) => Applied::Ended(ended, report),
                None => Applied::Idle,
            },
        }
    }

    /// What the node reports on `/diagnostics` at `now` ([`mobil_motion::health::motion_health`]):
    /// the active goal as `goal` describes it (ignored when idle), the law's `mode`, the
    /// `inputs` (with a goal, an input counts no older than the goal, as in
    /// [`MotionSession::stale`]), the stopped clock the robot is held for, the last end's code.
    pub fn health_report(&self, now: Instant, inputs: &[Watched], goal: Option<String>, mode: &str) -> MotionReport {
        let goal_age = self.active.as_ref().map(|a| a.age(now));
        MotionReport {
            goal: self.active.as_ref().and(goal),
            mode: mode.to_owned(),
            inputs: inputs
                .iter()
                .map(|w| InputAge {
                    name: w.name,
                    age_s: match (w.age, goal_age) {
                        (Some(a), Some(g)) => Some(a.min(g).as_secs_f64()),
                        (None, Some(g)) => Some(g.as_secs_f64()),
                        (age, None) => age.map(|a| a.as_secs_f64()),
                    },
                    timeout_s: w.timeout.as_secs_f64(),
                })
                .collect(),
            clock_held_s: self.clock_held.map(|d| d.as_secs_f64()),
            last_end: self.last_end.clone(),
        }
    }

    /// The inputs of the active goal that are stale at `now`, named and joined with "and"
    /// (`None`: all fresh, or no goal). An input counts as old as its last valid message, but
    /// never older than the goal: a goal gets one timeout from its start for each input to
    /// arrive.
    pub fn stale(&self, now: Instant, inputs: &[Watched]) -> Option<String> {
        let goal_age = self.active.as_ref()?.age(now);
        let stale: Vec<&str> = inputs
            .iter()
            .filter(|w| w.age.map_or(goal_age, |a| a.min(goal_age)) > w.timeout)
            .map(|w| w.name)
            .collect();
        (!stale.is_empty()).then(|| stale.join(" and "))
    }

    /// ROS time is `ros_nanos` at steady instant `now`, looked at on every watchdog tick, with a
    /// goal or without (a node on `/clock`: a system clock neither stops nor, but for a step,
    /// goes back): with a goal active, time that has not advanced for longer than `timeout`
    /// holds the robot (one zero command if it moves, no command until time moves again), and
    /// time gone back ends the goal `CLOCK_BACKWARDS` (with its zero command).
    pub fn watch_clock(
        &mut self,
        ros_nanos: i64,
        now: Instant,
        timeout: Duration,
        sink: &mut impl CommandSink,
    ) -> ClockCheck<G, S> {
        match self.clock.observe(ros_nanos, now) {
            ClockState::Back(by) => {
                self.clock_held = None;
                self.end(EndCause::ClockBack(by), sink)
                    .map_or(ClockCheck::Running, ClockCheck::Back)
            }
            ClockState::Stopped(stopped) if stopped > timeout && self.active.is_some() => {
                let newly = self.clock_held.is_none();
                if newly {
                    self.hold(sink);
                }
                self.clock_held = Some(stopped);
                ClockCheck::Held { stopped, newly }
            }
            ClockState::Stopped(_) | ClockState::Running => match self.clock_held.take() {
                Some(_) if self.active.is_some() => ClockCheck::Resumed,
                _ => ClockCheck::Running,
            },
        }
    }

    /// While the robot is held for a stopped clock: the status reason that says so.
    pub fn clock_hold_reason(&self) -> Option<String> {
        self.clock_held.map(|d| {
            format!(
                "STALE_INPUT: ROS time has not advanced for {:.1} s (clock paused or stalled): robot stopped",
                d.as_secs_f64()
            )
        })
    }

    /// The node shuts down: the active goal ends `SHUTDOWN` without a zero command here, and
    /// the answer says whether the node's last word must be a zero command (waited for): the
    /// goal commanded the robot, or it may still be moving. An idle node sends none at exit,
    /// so it never cuts into another node commanding the robot.
    pub fn shutdown(&mut self) -> (Option<Ended<G, S>>, bool) {
        let Some(a) = self.active.take() else {
            return (None, false);
        };
        let final_zero = a.commanded || self.moving;
        self.moving = false;
        (
            Some(Ended {
                id: a.id,
                goal: a.goal,
                source: a.source,
                cause: EndCause::Shutdown,
                t: a.t,
                zeroed: false,
                server_ended: false,
            }),
            final_zero,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use mobil_motion::{GoalLaw, Outcome, Pose2, StepInput};

    /// The goal source of the tests.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    enum Src {
        Topic,
        Action,
    }

    impl From<Src> for &'static str {
        fn from(s: Src) -> &'static str {
            match s {
                Src::Topic => "goal_pose",
                Src::Action => "navigate_to_pose",
            }
        }
    }

    /// A law that drives at 0.5 m/s until x reaches `to`, refuses a non-finite pose, and fails
    /// `BLOCKED` beyond x = 100.
    #[derive(Debug, Clone, PartialEq)]
    struct ToX {
        to: f64,
    }

    impl GoalLaw for ToX {
        type Sensors = ();
        type Feedback = f64;
        type Report = f64;
        fn step(&mut self, input: &StepInput, _: &()) -> Step<f64, f64> {
            let x = input.pose.x;
            if !x.is_finite() {
                return Step::Refused("non-finite pose".into());
            }
            if x > 100.0 {
                return Step::end(Outcome::failed("BLOCKED", "beyond 100 m", 106), x);
            }
            if x >= self.to {
                return Step::end(Outcome::succeeded("arrived"), x);
            }
            Step::Command {
                twist: BodyTwist::new(0.5, 0.0, 0.0),
                feedback: self.to - x,
            }
        }
    }

    fn twist(b: BodyTwist) -> Twist {
        let mut t = Twist::default();
        t.linear.x = b.vx;
        t.linear.y = b.vy;
        t.angular.z = b.wz;
        t
    }

    fn zeros(sent: &[Twist]) -> usize {
        sent.iter().filter(|t| is_zero(t)).count()
    }

    type Session = MotionSession<ToX, Src>;

    fn session() -> Session {
        MotionSession::new(SessionSettings::default())
    }

    /// Steps the active goal's law once at x.
    fn step_at(s: &mut Session, x: f64, sent: &mut Vec<Twist>) -> Applied<f64, f64, ToX, Src> {
        let input = StepInput::new(0.0, 0.02, Pose2::new(x, 0.0, 0.0));
        let Some(a) = s.active_mut() else { return Applied::Idle };
        let step = a.goal.step(&input, &());
        s.apply(step, twist, sent)
    }

    #[test]
    fn every_kind_of_end_after_motion_sends_exactly_one_zero() {
        let causes = [
            EndCause::Outcome(Outcome::succeeded("arrived")),
            EndCause::Outcome(Outcome::failed("BLOCKED", "", 106)),
            EndCause::Canceled,
            EndCause::Stale("odom".into()),
        ];
        for cause in causes {
            let mut s = session();
            let mut sent = Vec::new();
            s.start(ToX { to: 5.0 }, Src::Topic, Instant::now());
            assert!(matches!(step_at(&mut s, 1.0, &mut sent), Applied::Commanded(f) if f == 4.0));
            let ended = s.end(cause.clone(), &mut sent).unwrap();
            assert!(ended.zeroed);
            assert_eq!((sent.len(), zeros(&sent)), (2, 1), "{cause:?}");
            assert!(is_zero(sent.last().unwrap()));
            // Nothing more: no goal, no command, no second zero.
            assert!(s.end(EndCause::Canceled, &mut sent).is_none());
            assert!(matches!(step_at(&mut s, 1.0, &mut sent), Applied::Idle));
            s.hold(&mut sent);
            assert_eq!(sent.len(), 2);
        }
    }

    #[test]
    fn the_law_ends_its_goal_with_one_zero_and_its_report() {
        let mut s = session();
        let mut sent = Vec::new();
        s.start(ToX { to: 2.0 }, Src::Action, Instant::now());
        step_at(&mut s, 1.0, &mut sent);
        match step_at(&mut s, 2.5, &mut sent) {
            Applied::Ended(ended, report) => {
                assert_eq!(report, 2.5);
                assert_eq!(ended.cause.kind(), EndKind::Succeeded);
                assert_eq!(ended.cause.reason(), "SUCCEEDED: arrived");
                assert_eq!(ended.source, Src::Action);
            }
            other => panic!("{other:?}"),
        }
        assert_eq!((sent.len(), zeros(&sent)), (2, 1));
        // A failure the same way.
        s.start(ToX { to: 200.0 }, Src::Action, Instant::now());
        step_at(&mut s, 99.0, &mut sent);
        match step_at(&mut s, 101.0, &mut sent) {
            Applied::Ended(ended, _) => {
                assert_eq!(ended.cause.code(), "BLOCKED");
                assert_eq!(ended.cause.kind(), EndKind::Aborted);
            }
            other => panic!("{other:?}"),
        }
        assert_eq!((sent.len(), zeros(&sent)), (4, 2));
    }

    #[test]
    fn a_goal_that_never_moved_the_robot_ends_without_a_zero() {
        let mut s = session();
        let mut sent = Vec::new();
        s.start(ToX { to: 5.0 }, Src::Topic, Instant::now());
        let ended = s.end(EndCause::Stale("scan".into()), &mut sent).unwrap();
        assert!(!ended.zeroed);
        assert!(sent.is_empty());
        assert_eq!(ended.cause.reason(), "STALE_INPUT: scan stale: robot stopped");
        // At shutdown an idle node has no last word either.
        assert_eq!(s.shutdown(), (None, false));
    }

    #[test]
    fn a_newer_goal_preempts_without_a_zero_between_and_the_old_one_says_why() {
        let mut s = session();
        let mut sent = Vec::new();
        let (first, none) = s.start(ToX { to: 5.0 }, Src::Topic, Instant::now());
        assert!(none.is_none());
        step_at(&mut s, 1.0, &mut sent);
        let (second, old) = s.start(ToX { to: 9.0 }, Src::Action, Instant::now());
        let old = old.unwrap();
        assert_ne!(first, second);
        assert_eq!((old.id, old.source), (first, Src::Topic));
        assert_eq!(old.cause, EndCause::Preempted("navigate_to_pose"));
        assert_eq!(
            old.cause.reason(),
            "PREEMPTED: preempted by a newer goal (navigate_to_pose)"
        );
        assert_eq!(old.cause.kind(), EndKind::Aborted);
        assert!(!old.zeroed);
        // Of another source: the node answers it (its server did not).
        assert!(!old.server_ended);
        // The new goal continues the motion: no zero between the two goals' commands.
        step_at(&mut s, 1.1, &mut sent);
        assert_eq!((sent.len(), zeros(&sent)), (2, 0));
        assert!(s.is_current(second) && !s.is_current(first));
        // A third from the same action server: that server ended the second on accepting it.
        let (_, old) = s.start(ToX { to: 12.0 }, Src::Action, Instant::now());
        assert!(old.unwrap().server_ended);
        // It ends with one zero, as any goal that moved the robot.
        step_at(&mut s, 1.2, &mut sent);
        let ended = s.end(EndCause::Canceled, &mut sent).unwrap();
        assert_eq!(zeros(&sent), 1);
        assert!(!ended.server_ended);
    }

    #[test]
    fn a_goal_preempted_by_one_that_does_not_start_stops_the_robot_once() {
        let mut s = session();
        let mut sent = Vec::new();
        s.start(ToX { to: 5.0 }, Src::Action, Instant::now());
        step_at(&mut s, 1.0, &mut sent);
        // A topic goal refused: the action goal ends PREEMPTED, answered by the node, one zero.
        let ended = s.preempt(Src::Topic, &mut sent).unwrap();
        assert_eq!(ended.cause, EndCause::Preempted("goal_pose"));
        assert!(ended.zeroed && !ended.server_ended && s.active().is_none());
        assert_eq!((sent.len(), zeros(&sent)), (2, 1));
        // An action goal whose start failed after its server accepted it: the server ended
        // the goal it replaced.
        s.start(ToX { to: 5.0 }, Src::Action, Instant::now());
        step_at(&mut s, 1.0, &mut sent);
        let ended = s.preempt(Src::Action, &mut sent).unwrap();
        assert!(ended.zeroed && ended.server_ended);
        assert_eq!(zeros(&sent), 2);
        assert!(s.preempt(Src::Action, &mut sent).is_none());
        assert_eq!(zeros(&sent), 2, "no goal: nothing sent");
    }

    #[test]
    fn a_preempting_goal_that_must_wait_stops_the_robot_once_and_ends_with_one_zero() {
        let mut s = session();
        let mut sent = Vec::new();
        s.start(ToX { to: 5.0 }, Src::Topic, Instant::now());
        step_at(&mut s, 1.0, &mut sent);
        s.start(ToX { to: 9.0 }, Src::Topic, Instant::now());
        // Waiting for a pre-check: one zero, however long it waits.
        s.hold(&mut sent);
        s.hold(&mut sent);
        assert_eq!((sent.len(), zeros(&sent)), (2, 1));
        // Its end sends one zero more: it commanded the robot (the hold), so a client that
        // reads the last command sees zero.
        let ended = s.end(
            EndCause::Outcome(Outcome::failed("ROUTE_INFEASIBLE", "", 601)),
            &mut sent,
        );
        assert!(ended.unwrap().zeroed);
        assert_eq!((sent.len(), zeros(&sent)), (3, 2));
        // A goal that pre-empts a moving one and ends before commanding still stops it.
        s.start(ToX { to: 5.0 }, Src::Topic, Instant::now());
        step_at(&mut s, 1.0, &mut sent);
        s.start(ToX { to: 9.0 }, Src::Topic, Instant::now());
        assert!(s.end(EndCause::Canceled, &mut sent).unwrap().zeroed);
        assert_eq!(zeros(&sent), 3);
    }

    #[test]
    fn refused_inputs_stop_the_robot_once_and_end_the_goal_at_the_limit() {
        let mut s = MotionSession::new(SessionSettings {
            max_refused_steps: 3,
            ..SessionSettings::default()
        });
        let mut sent = Vec::new();
        s.start(ToX { to: 5.0 }, Src::Topic, Instant::now());
        step_at(&mut s, 1.0, &mut sent);
        assert!(matches!(step_at(&mut s, f64::NAN, &mut sent), Applied::Refused(None)));
        assert!(matches!(step_at(&mut s, f64::NAN, &mut sent), Applied::Refused(None)));
        // One zero for the two refusals; a good step in between restarts the count.
        assert_eq!((sent.len(), zeros(&sent)), (2, 1));
        step_at(&mut s, 1.1, &mut sent);
        step_at(&mut s, f64::NAN, &mut sent);
        step_at(&mut s, f64::NAN, &mut sent);
        match step_at(&mut s, f64::NAN, &mut sent) {
            Applied::Refused(Some(ended)) => {
                assert_eq!(ended.cause.code(), "INVALID_INPUT");
                assert!(ended
                    .cause
                    .reason()
                    .contains("refused on 3 steps in a row (non-finite pose)"));
            }
            other => panic!("{other:?}"),
        }
        // Commands: 1.0, zero, 1.1, zero (first refusal), and the end's zero.
        assert_eq!((sent.len(), zeros(&sent)), (5, 3));
        assert!(s.active().is_none());
    }

    #[test]
    fn the_time_step_starts_at_first_dt_is_held_to_max_dt_and_skips_a_stopped_clock() {
        let mut s = session();
        assert_eq!(s.advance(0), None);
        s.start(ToX { to: 5.0 }, Src::Topic, Instant::now());
        let ms = 1_000_000;
        assert_eq!(s.advance(1_000 * ms), Some(Ok(0.02)));
        assert_eq!(s.advance(1_050 * ms), Some(Ok(0.05)));
        // A gap of 2 s counts as 0.1 s.
        assert_eq!(s.advance(3_050 * ms), Some(Ok(0.1)));
        assert_eq!(s.advance(3_050 * ms), Some(Err(DtError::Zero)));
        assert!(matches!(s.advance(1_000 * ms), Some(Err(DtError::Backwards { .. }))));
        // After the reset the clock runs from the new time; the goal's time carried on.
        assert_eq!(s.advance(1_020 * ms), Some(Ok(0.02)));
        let t = s.active().unwrap().t();
        assert!((t - (0.02 + 0.05 + 0.1 + 0.02)).abs() < 1e-12, "{t}");
        // A new goal starts its own time.
        s.start(ToX { to: 5.0 }, Src::Topic, Instant::now());
        assert_eq!(s.active().unwrap().t(), 0.0);
    }

    #[test]
    fn inputs_go_stale_after_their_timeout_but_a_new_goal_gets_one_timeout() {
        let mut s = session();
        let start = Instant::now();
        s.start(ToX { to: 5.0 }, Src::Topic, start);
        let w = |name, age: Option<u64>, timeout| Watched {
            name,
            age: age.map(Duration::from_millis),
            timeout: Duration::from_millis(timeout),
        };
        let at = |ms| start + Duration::from_millis(ms);
        // Never seen, but the goal is 0.3 s old: fresh for now.
        assert_eq!(
            s.stale(at(300), &[w("scan", None, 500), w("odom", Some(100), 500)]),
            None
        );
        // 0.6 s in: the scan never came.
        assert_eq!(
            s.stale(at(600), &[w("scan", None, 500), w("odom", Some(100), 500)])
                .as_deref(),
            Some("scan")
        );
        // An old message counts no older than the goal.
        assert_eq!(s.stale(at(400), &[w("odom", Some(9_000), 500)]), None);
        assert_eq!(
            s.stale(at(2_000), &[w("scan", Some(900), 500), w("odom", Some(800), 500)])
                .as_deref(),
            Some("scan and odom")
        );
        let mut sent = Vec::new();
        s.end(EndCause::Canceled, &mut sent);
        assert_eq!(s.stale(at(2_000), &[w("scan", None, 500)]), None);
    }

    #[test]
    fn a_result_for_a_goal_that_ended_meanwhile_is_dropped() {
        // A computation off the loop (a pre-check, an optimisation) holds its goal's id.
        let mut s = session();
        let mut sent = Vec::new();
        let (first, _) = s.start(ToX { to: 5.0 }, Src::Action, Instant::now());
        step_at(&mut s, 1.0, &mut sent);
        // The client cancels while the computation runs.
        assert!(s.end_if_current(first, EndCause::Canceled, &mut sent).is_some());
        // Its result comes back for a goal that is no more: nothing is sent, nothing ends.
        assert!(!s.is_current(first));
        assert!(s
            .end_if_current(first, EndCause::Outcome(Outcome::succeeded("")), &mut sent)
            .is_none());
        // The same when a newer goal took over.
        let (second, _) = s.start(ToX { to: 5.0 }, Src::Topic, Instant::now());
        let (_, old) = s.start(ToX { to: 7.0 }, Src::Topic, Instant::now());
        assert_eq!(old.unwrap().id, second);
        assert!(s.end_if_current(second, EndCause::Canceled, &mut sent).is_none());
        assert_eq!((sent.len(), zeros(&sent)), (2, 1));
    }

    #[test]
    fn a_stopped_clock_holds_the_robot_once_until_time_moves_and_time_gone_back_ends_the_goal() {
        let mut s = session();
        let mut sent = Vec::new();
        let t0 = Instant::now();
        let (ms, timeout) = (Duration::from_millis, Duration::from_millis(500));
        let at = |k: u64| t0 + ms(50 * k);
        s.start(ToX { to: 5.0 }, Src::Topic, t0);
        // Ticks every 50 ms, ROS time running: the goal commands.
        for k in 0..4 {
            assert_eq!(
                s.watch_clock(1_000_000_000 + 50_000_000 * k as i64, at(k), timeout, &mut sent),
                ClockCheck::Running
            );
            step_at(&mut s, 1.0, &mut sent);
        }
        assert_eq!((sent.len(), zeros(&sent)), (4, 0));
        // ROS time stands at 1.15 s from tick 3 on: still commanding for 500 ms of it (ticks
        // 4..=13), held from the first tick beyond it (tick 14: 550 ms), with one zero.
        let frozen = 1_150_000_000;
        for k in 4..=13 {
            assert_eq!(
                s.watch_clock(frozen, at(k), timeout, &mut sent),
                ClockCheck::Running,
                "tick {k}"
            );
        }
        assert_eq!(
            s.watch_clock(frozen, at(14), timeout, &mut sent),
            ClockCheck::Held {
                stopped: ms(550),
                newly: true
            }
        );
        assert_eq!(zeros(&sent), 1);
        assert!(s
            .clock_hold_reason()
            .unwrap()
            .starts_with("STALE_INPUT: ROS time has not advanced for 0.6 s"));
        let held: ClockCheck<ToX, Src> = ClockCheck::Held {
            stopped: ms(550),
            newly: true,
        };
        let told = held.notice();
        assert!(
            matches!(&told, Some(mobil_motion::Notice::Warn(w)) if w.starts_with("ROS time has not advanced for 0.55 s")),
            "{told:?}"
        );
        // Held: a law's command is not sent, no second zero, and the goal goes on.
        let before = sent.len();
        step_at(&mut s, 1.0, &mut sent);
        assert_eq!(
            s.watch_clock(frozen, at(15), timeout, &mut sent),
            ClockCheck::Held {
                stopped: ms(600),
                newly: false
            }
        );
        assert_eq!(sent.len(), before, "nothing sent while held");
        assert!(s.active().is_some());
        // Time moves: resumed, commanding again.
        assert_eq!(
            s.watch_clock(frozen + 1, at(16), timeout, &mut sent),
            ClockCheck::Resumed
        );
        assert_eq!(s.clock_hold_reason(), None);
        step_at(&mut s, 1.0, &mut sent);
        assert_eq!((sent.len(), zeros(&sent)), (before + 1, 1));
        // Time back by 0.5 s: the goal ends CLOCK_BACKWARDS with its one zero.
        let ClockCheck::Back(ended) = s.watch_clock(frozen - 499_999_999, at(17), timeout, &mut sent) else {
            panic!("not ended")
        };
        assert_eq!(ended.cause, EndCause::ClockBack(0.5));
        assert!(ended.zeroed && s.active().is_none());
        assert_eq!(zeros(&sent), 2);
        // No goal: a stopped clock holds nothing and sends nothing.
        let n = sent.len();
        assert_eq!(s.watch_clock(frozen, at(40), timeout, &mut sent), ClockCheck::Running);
        assert_eq!(sent.len(), n);
    }

    #[test]
    fn a_clock_reset_between_goals_or_seen_first_by_a_step_ends_no_later_goal() {
        let mut s = session();
        let mut sent = Vec::new();
        let t0 = Instant::now();
        let (ms, timeout) = (Duration::from_millis, Duration::from_millis(500));
        // A goal runs to 130 s of ROS time and ends; idle ticks go on watching.
        s.start(ToX { to: 5.0 }, Src::Topic, t0);
        assert_eq!(
            s.watch_clock(130_000_000_000, t0, timeout, &mut sent),
            ClockCheck::Running
        );
        s.end(EndCause::Canceled, &mut sent);
        // The simulation restarts at 20 s while no goal runs: told to nobody.
        assert_eq!(
            s.watch_clock(20_000_000_000, t0 + ms(50), timeout, &mut sent),
            ClockCheck::Running
        );
        // The next goal runs on.
        s.start(ToX { to: 5.0 }, Src::Topic, t0 + ms(60));
        assert_eq!(
            s.watch_clock(20_050_000_000, t0 + ms(100), timeout, &mut sent),
            ClockCheck::Running
        );
        assert!(s.active().is_some());
        // A jump back seen first by a step: the step reports it, and the watch does not tell it
        // again (the node ends the goal; a new goal is not ended for it).
        assert_eq!(s.advance(20_100_000_000), Some(Ok(0.02)));
        assert!(matches!(s.advance(1_000_000_000), Some(Err(DtError::Backwards { .. }))));
        s.end(EndCause::ClockBack(19.1), &mut sent);
        s.start(ToX { to: 5.0 }, Src::Topic, t0 + ms(120));
        assert_eq!(
            s.watch_clock(1_000_000_000, t0 + ms(150), timeout, &mut sent),
            ClockCheck::Running
        );
        assert!(s.active().is_some());
    }

    #[test]
    fn shutdown_under_a_moving_goal_asks_for_the_final_zero_and_sends_none_itself() {
        let mut s = session();
        let mut sent = Vec::new();
        s.start(ToX { to: 5.0 }, Src::Action, Instant::now());
        step_at(&mut s, 1.0, &mut sent);
        let (ended, final_zero) = s.shutdown();
        let ended = ended.unwrap();
        assert!(final_zero);
        assert_eq!(ended.cause.code(), "SHUTDOWN");
        assert_eq!(ended.cause.kind(), EndKind::Aborted);
        assert_eq!(
            sent.len(),
            1,
            "the final zero is the caller's (acknowledged), not the session's"
        );
        // A goal that never commanded an idle robot needs none.
        s.start(ToX { to: 5.0 }, Src::Action, Instant::now());
        assert!(!s.shutdown().1);
    }

    /// `/diagnostics`' report: idle, an input's own age; with a goal, no older than the goal;
    /// the goal described only while active; the last end's code; a held clock.
    #[test]
    fn the_health_report_follows_the_session() {
        let mut sent: Vec<Twist> = Vec::new();
        let mut s = MotionSession::<&str, &str>::new(SessionSettings::default());
        let t0 = Instant::now();
        let odom = |age: Option<u64>| Watched {
            name: "odom",
            age: age.map(Duration::from_millis),
            timeout: Duration::from_millis(500),
        };
        let idle = s.health_report(t0, &[odom(Some(3000))], Some("ignored".into()), "idle");
        assert_eq!(
            (idle.goal, idle.inputs[0].age_s, idle.last_end),
            (None, Some(3.0), None)
        );
        s.start("g", "dock_pose", t0);
        let at = t0 + Duration::from_millis(200);
        let active = s.health_report(at, &[odom(Some(3000)), odom(None)], Some("dock".into()), "dock");
        assert_eq!(active.goal.as_deref(), Some("dock"));
        assert_eq!((active.inputs[0].age_s, active.inputs[1].age_s), (Some(0.2), Some(0.2)));
        s.end(EndCause::Canceled, &mut sent);
        let after = s.health_report(at, &[], None, "idle");
        assert_eq!(after.last_end.as_deref(), Some("CANCELED"));
        assert_eq!(after.clock_held_s, None);
    }
}
