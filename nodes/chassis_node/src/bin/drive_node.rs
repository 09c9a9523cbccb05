//! `drive_node`: short motions on request, following `odom` and commanding `cmd_vel`:
//! - `drive_distance` (`mobil_msgs/action/DriveDistance`): straight ahead or back by a distance;
//! - Nav2's behavior server's actions (Jazzy): `backup` (BackUp), `drive_on_heading`
//!   (DriveOnHeading) and `spin` (Spin), with `time_allowance` and, when a scan is fresh, the
//!   check for an obstacle in the robot's way (COLLISION_AHEAD).
//!
//! The laws are `mobil_tools::drive` and `mobil_tools::behavior`; this is their shell. Every
//! goal runs through the kit's motion server ([`MotionSession`]): `cmd_vel` only while a goal
//! runs, one zero `cmd_vel` when it ends — reached, canceled, odometry stale for
//! `odom_timeout_s` (steady clock; ABORTED), timed out, blocked — and none between a goal and
//! the newer goal (of any of the four actions) that pre-empts it. A node leaving (shutdown or a
//! failure) with a goal under way sends a last zero `cmd_vel`, waited for until the readers
//! acknowledge it (at most `mobil_ros::stop::FINAL_STOP_WAIT`); an idle one sends none. The
//! node is a managed node ([`Lifecycle`]): goals only while active.

use mobil_motion::nav2::behavior::{Codes, BACK_UP, DRIVE_ON_HEADING, SPIN};
use mobil_motion::{BodyTwist, GoalLaw, Nav2Codes, Outcome, StepInput};
use mobil_msgs::builtin_interfaces::msg::Duration as DurationMsg;
use mobil_msgs::geometry_msgs::msg::{Point, Twist};
use mobil_msgs::mobil_msgs::action::{DriveDistance, DriveDistanceFeedback, DriveDistanceResult};
use mobil_msgs::nav2_msgs::action::{
    BackUp, BackUpFeedback, BackUpResult, DriveOnHeading, DriveOnHeadingFeedback, DriveOnHeadingResult, Spin,
    SpinFeedback, SpinResult,
};
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_msgs::sensor_msgs::msg::LaserScan;
use mobil_ros::action::{goal_end, ActionEvent, GoalEnd, GoalRequest, GoalServer, GoalServerConfig};
use mobil_ros::cmd_vel::{CmdVelOut, CmdVelType, TypeWatch};
use mobil_ros::config::{Config, ConfigError, Decl};
use mobil_ros::diagnostics::MotionDiagnostics;
use mobil_ros::geometry::planar_pose;
use mobil_ros::groups::{GoalTimeouts, MAX_INPUT_TIMEOUT_S};
use mobil_ros::input::Inputs;
use mobil_ros::latest::Latest;
use mobil_ros::lifecycle::{CallbackReturn, Lifecycle, Managed};
use mobil_ros::motion::Watched;
use mobil_ros::motion::{Applied, ClockCheck, CmdVel, EndCause, EndKind, Ended, MotionSession, SessionSettings};
use mobil_ros::node::NodeClock;
use mobil_ros::scan::{checked_scan, tf_static_subscription, LaserParams, StaticFrames};
use mobil_ros::stop::FINAL_STOP_WAIT;
use mobil_ros::ticker::Ticker;
use mobil_ros::time::{duration_msg, seconds, secs_from_duration};
use mobil_ros::{qos, run_node, shutdown_signal, warn_throttled, LogThrottle, NodeDecl, RosNode};
use mobil_tools::behavior::{Behavior, Guard, SpinSettings};
use mobil_tools::drive::Pose2;
use mobil_tools::drive::{DistanceDrive, DriveSettings};
use nalgebra::Point2;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tracing::{info, warn};

/// The node's configuration: each parameter declared once, bound to its field.
#[derive(Debug, Clone, Default, PartialEq)]
struct DriveConfig {
    max_speed: f64,
    min_speed: f64,
    decel: f64,
    tolerance: f64,
    rate_hz: f64,
    spin: SpinSettings,
    robot_radius: f64,
    simulate_ahead_time: f64,
    scan_timeout_s: f64,
    base_frame: String,
    laser: LaserParams,
    timeouts: GoalTimeouts,
    managed: Managed,
    cmd_vel: CmdVelType,
}

/// The spin parameters' declarations (Nav2's names).
struct SpinSettingsParams;

impl SpinSettingsParams {
    fn declare(d: &mut Decl<SpinSettings>) {
        let s = SpinSettings::default();
        d.double(
            "max_rotational_vel",
            s.max_speed,
            "spin: highest turn rate (Nav2's parameter) [rad/s]",
            |c, v| c.max_speed = v,
        )
        .above(0.0);
        d.double(
            "min_rotational_vel",
            s.min_speed,
            "spin: slowest turn rate before arrival [rad/s]",
            |c, v| c.min_speed = v,
        )
        .above(0.0);
        d.double(
            "rotational_acc_lim",
            s.decel,
            "spin: deceleration of the ramp-down before arrival [rad/s²]",
            |c, v| c.decel = v,
        )
        .above(0.0);
        d.double(
            "yaw_tolerance",
            s.tolerance,
            "spin: arrived when this close to target_yaw [rad]",
            |c, v| c.tolerance = v,
        )
        .above(0.0);
    }
}

impl Config for DriveConfig {
    fn declare(d: &mut Decl<Self>) {
        d.double("max_speed", 0.5, "highest speed a goal may ask for [m/s]", |c, v| {
            c.max_speed = v
        })
        .above(0.0);
        d.double("min_speed", 0.03, "slowest speed before arrival [m/s]", |c, v| {
            c.min_speed = v
        })
        .above(0.0);
        d.double(
            "decel",
            0.5,
            "deceleration of the ramp-down before arrival [m/s²]",
            |c, v| c.decel = v,
        )
        .above(0.0);
        d.double(
            "tolerance",
            0.005,
            "arrived when this close to the distance [m]",
            |c, v| c.tolerance = v,
        )
        .above(0.0);
        d.double(
            "rate_hz",
            20.0,
            "cmd_vel and feedback rate while driving [Hz]",
            |c, v| c.rate_hz = v,
        )
        .within(1.0, 200.0);
        d.nest(|c: &mut DriveConfig| &mut c.spin, SpinSettingsParams::declare);
        d.double(
            "robot_radius",
            0.25,
            "radius of the round footprint the collision check sweeps (as the params files' /** section gives it) [m]",
            |c, v| c.robot_radius = v,
        )
        .above(0.0);
        d.double(
            "simulate_ahead_time",
            2.0,
            "backup, drive_on_heading: the motion of the next this many seconds is checked against the scan \
             (Nav2's parameter) [s]",
            |c, v| c.simulate_ahead_time = v,
        )
        .min(0.0)
        .max(60.0);
        d.double(
            "scan_timeout_s",
            0.5,
            "the collision check uses a scan no older than this (steady clock); without one it is off [s]",
            |c, v| c.scan_timeout_s = v,
        )
        .above(0.0)
        .max(MAX_INPUT_TIMEOUT_S);
        d.string("base_frame", "base_link", "robot frame (reference point)", |c, v| {
            c.base_frame = v
        })
        .read_only();
        d.nest(|c: &mut DriveConfig| &mut c.laser, LaserParams::declare);
        d.nest(|c: &mut DriveConfig| &mut c.timeouts, GoalTimeouts::declare);
        d.nest(|c: &mut DriveConfig| &mut c.managed, Managed::declare);
        d.nest(|c: &mut DriveConfig| &mut c.cmd_vel, CmdVelType::declare);
    }

    fn validate(&self) -> Result<(), ConfigError> {
        if self.min_speed > self.max_speed {
            return Err(ConfigError::inconsistent(format!(
                "min_speed {} is above max_speed {}",
                self.min_speed, self.max_speed
            )));
        }
        if self.spin.min_speed > self.spin.max_speed {
            return Err(ConfigError::inconsistent(format!(
                "min_rotational_vel {} is above max_rotational_vel {}",
                self.spin.min_speed, self.spin.max_speed
            )));
        }
        self.laser.validate()
    }
}

impl DriveConfig {
    fn settings(&self) -> DriveSettings {
        DriveSettings {
            max_speed: self.max_speed,
            min_speed: self.min_speed,
            decel: self.decel,
            tolerance: self.tolerance,
        }
    }

    fn guard(&self) -> Guard {
        Guard {
            robot_radius: self.robot_radius,
            simulate_ahead_time: self.simulate_ahead_time,
        }
    }
}

fn decl() -> NodeDecl {
    NodeDecl::for_config::<DriveConfig>(
        "drive",
        "Short motions on request: DriveDistance, and Nav2's BackUp, DriveOnHeading and Spin; follows odom, \
         commands cmd_vel",
    )
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(serve(node)))
}

/// The action a goal came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Distance,
    BackUp,
    Heading,
    Spin,
}

impl From<Kind> for &'static str {
    fn from(k: Kind) -> &'static str {
        match k {
            Kind::Distance => "drive_distance",
            Kind::BackUp => "backup",
            Kind::Heading => "drive_on_heading",
            Kind::Spin => "spin",
        }
    }
}

impl Kind {
    /// The Nav2 behavior's codes (none for DriveDistance).
    fn codes(self) -> Option<Codes> {
        match self {
            Kind::Distance => None,
            Kind::BackUp => Some(BACK_UP),
            Kind::Heading => Some(DRIVE_ON_HEADING),
            Kind::Spin => Some(SPIN),
        }
    }
}

type Session = MotionSession<Behavior, Kind>;
type DriveEnded = Ended<Behavior, Kind>;

/// The node's action servers.
struct Servers {
    distance: GoalServer<DriveDistance>,
    backup: GoalServer<BackUp>,
    heading: GoalServer<DriveOnHeading>,
    spin: GoalServer<Spin>,
    /// The node's clock, and the ROS time the running goal started at: its elapsed time, for
    /// `time_allowance` and `total_elapsed_time` (Nav2's, in ROS time).
    clock: NodeClock,
    started_nanos: i64,
}

fn distance_result(travelled: f64, reason: &str) -> DriveDistanceResult {
    DriveDistanceResult {
        travelled,
        reason: reason.to_owned(),
    }
}

/// The reason DriveDistance's result has always given.
fn distance_reason(cause: &EndCause) -> String {
    match cause {
        EndCause::Outcome(o) if o.is_success() => "reached".to_owned(),
        EndCause::Canceled => "canceled".to_owned(),
        EndCause::Preempted(_) => "preempted by a newer goal".to_owned(),
        EndCause::Stale(_) => "odometry stale".to_owned(),
        EndCause::Shutdown => "shutting down".to_owned(),
        other => other.reason(),
    }
}

/// The result of a Nav2 behavior: BackUp, DriveOnHeading and Spin share its fields.
trait BehaviorResult {
    fn of(total_elapsed_time: DurationMsg, error_code: u16, error_msg: String) -> Self;
}

macro_rules! behavior_results {
    ($($result:ty),*) => {$(
        impl BehaviorResult for $result {
            fn of(total_elapsed_time: DurationMsg, error_code: u16, error_msg: String) -> Self {
                Self { total_elapsed_time, error_code, error_msg }
            }
        }
    )*};
}

behavior_results!(BackUpResult, DriveOnHeadingResult, SpinResult);

/// `kind`'s result for a goal that ended with `cause` after `elapsed` seconds of ROS time:
/// Nav2's code of the behavior, the reason as `error_msg`.
fn behavior_result<R: BehaviorResult>(kind: Kind, cause: &EndCause, elapsed: f64) -> R {
    let codes = kind.codes().map_or(Nav2Codes::FOLLOW_PATH, Nav2Codes::behavior);
    R::of(duration_msg(elapsed), cause.nav2_error(codes), cause.reason())
}

impl Servers {
    /// ROS time since the running goal started (s, never negative).
    fn elapsed(&self) -> f64 {
        (self.clock.now_nanos().saturating_sub(self.started_nanos)).max(0) as f64 * 1e-9
    }

    /// The ended goal's action result, unless its server ended it already.
    fn finish(&mut self, ended: &DriveEnded) {
        let cause = &ended.cause;
        match cause.kind() {
            EndKind::Succeeded | EndKind::Canceled => {
                info!("goal ({}) ends: {}", <&str>::from(ended.source), cause.reason())
            }
            EndKind::Aborted => warn!("goal ({}) ends: {}", <&str>::from(ended.source), cause.reason()),
        }
        if ended.server_ended {
            return;
        }
        let travelled = ended.goal.progress().travelled;
        self.end(ended.source, goal_end(cause), cause, self.elapsed(), travelled);
    }

    /// Ends `kind`'s active goal with `status` and the result of `cause`.
    fn end(&mut self, kind: Kind, status: GoalEnd, cause: &EndCause, elapsed: f64, travelled: f64) {
        match kind {
            Kind::Distance => self
                .distance
                .finish(status, distance_result(travelled, &distance_reason(cause))),
            Kind::BackUp => self.backup.finish(status, behavior_result(kind, cause, elapsed)),
            Kind::Heading => self.heading.finish(status, behavior_result(kind, cause, elapsed)),
            Kind::Spin => self.spin.finish(status, behavior_result(kind, cause, elapsed)),
        };
    }

    /// The active goal's feedback.
    async fn feedback(&self, kind: Kind, goal: &Behavior) -> Result<(), mobil_ros::action::ActionError> {
        let p = goal.progress();
        let done = p.travelled.abs() as f32;
        match kind {
            Kind::Distance => {
                let f = DriveDistanceFeedback {
                    travelled: p.travelled,
                    remaining: p.remaining,
                };
                self.distance.feedback(f).await
            }
            Kind::BackUp => {
                self.backup
                    .feedback(BackUpFeedback {
                        distance_traveled: done,
                    })
                    .await
            }
            Kind::Heading => {
                let f = DriveOnHeadingFeedback {
                    distance_traveled: done,
                };
                self.heading.feedback(f).await
            }
            Kind::Spin => {
                let f = SpinFeedback {
                    angular_distance_traveled: done,
                };
                self.spin.feedback(f).await
            }
        }
    }

    fn active_id(&self, kind: Kind) -> Option<mobil_ros::action::GoalId> {
        match kind {
            Kind::Distance => self.distance.active_id(),
            Kind::BackUp => self.backup.active_id(),
            Kind::Heading => self.heading.active_id(),
            Kind::Spin => self.spin.active_id(),
        }
    }

    async fn close(self, travelled: f64, reason: &str) {
        let (cause, elapsed) = (EndCause::Shutdown, self.elapsed());
        tokio::join!(
            self.distance.close(distance_result(travelled, reason)),
            self.backup.close(behavior_result(Kind::BackUp, &cause, elapsed)),
            self.heading.close(behavior_result(Kind::Heading, &cause, elapsed)),
            self.spin.close(behavior_result(Kind::Spin, &cause, elapsed)),
        );
    }
}

fn twist(b: BodyTwist) -> Twist {
    let mut t = Twist::default();
    t.linear.x = b.vx;
    t.angular.z = b.wz;
    t
}

async fn serve(node: &mut RosNode) -> anyhow::Result<()> {
    let config: DriveConfig = node.config()?;
    let stamped = config.cmd_vel.enable_stamped_cmd_vel;
    let cmd = CmdVelOut::create(node, "cmd_vel", stamped, &config.base_frame)?;
    let mut session = Session::new(SessionSettings::default());
    let outcome = drive_loop(node, &cmd, &mut session, config).await;
    // Whatever ends the loop (shutdown or a failure), a goal under way gets its zero command,
    // waited for, so the chassis does not keep the last speed until its own watchdog fires.
    if session.shutdown().1 {
        cmd.final_stop(FINAL_STOP_WAIT).await;
    }
    outcome
}

async fn drive_loop(
    node: &mut RosNode,
    cmd: &CmdVelOut,
    session: &mut Session,
    config: DriveConfig,
) -> anyhow::Result<()> {
    let mut lifecycle = Lifecycle::serve(node, &config.managed)?;
    let server_config = GoalServerConfig {
        result_timeout: config.timeouts.result_timeout(),
    };
    let gate = lifecycle.gate();
    let mut servers = Servers {
        distance: GoalServer::create(node, "drive_distance", server_config.clone())?.gate(gate.clone()),
        backup: GoalServer::create(node, "backup", server_config.clone())?.gate(gate.clone()),
        heading: GoalServer::create(node, "drive_on_heading", server_config.clone())?.gate(gate.clone()),
        spin: GoalServer::create(node, "spin", server_config)?.gate(gate),
        clock: node.clock(),
        started_nanos: 0,
    };
    let mut shell = Shell {
        diagnostics: MotionDiagnostics::create(node, &config.base_frame)?,
        config,
        latest: Latest::new(),
        echoes: Latest::new(),
        laser: StaticFrames::default(),
        types: TypeWatch::default(),
        throttle: LogThrottle::new(Duration::from_secs(2)),
    };
    let outcome = shell.event_loop(node, cmd, &mut servers, &mut lifecycle, session).await;
    let travelled = session.active().map_or(0.0, |a| a.goal.progress().travelled);
    let reason = if outcome.is_ok() {
        "shutting down"
    } else {
        "node failed"
    };
    // A goal under way gets its zero command first, waited for; then the bond breaks and the
    // servers close (each waits up to 2 s for its results, the running goal's among them).
    if session.shutdown().1 {
        cmd.final_stop(FINAL_STOP_WAIT).await;
    }
    lifecycle.close().await;
    servers.close(travelled, reason).await;
    outcome
}

/// What woke the loop.
#[allow(clippy::large_enum_variant)]
enum Event {
    Shutdown,
    Config(Result<DriveConfig, ConfigError>),
    Odom(Odometry),
    Scan(LaserScan),
    Lifecycle(mobil_ros::lifecycle::Transition),
    Distance(ActionEvent<mobil_msgs::mobil_msgs::action::DriveDistanceGoal>),
    BackUp(ActionEvent<mobil_msgs::nav2_msgs::action::BackUpGoal>),
    Heading(ActionEvent<mobil_msgs::nav2_msgs::action::DriveOnHeadingGoal>),
    Spin(ActionEvent<mobil_msgs::nav2_msgs::action::SpinGoal>),
    Tick,
}

/// What the loop keeps between events.
struct Shell {
    config: DriveConfig,
    /// The latest valid odometry pose, with its stamp and steady receive instant: the one
    /// place odom freshness is judged.
    latest: Latest<Pose2>,
    /// The latest scan's echoes in the base frame (the collision check's input).
    echoes: Latest<Vec<Point2<f64>>>,
    laser: StaticFrames,
    types: TypeWatch,
    throttle: LogThrottle,
    /// `/diagnostics`.
    diagnostics: MotionDiagnostics,
}

/// A Nav2 behavior's goal: the law, or the end Nav2's behavior server gives it at once.
type Built = Result<Behavior, Outcome>;

impl Shell {
    async fn event_loop(
        &mut self,
        node: &mut RosNode,
        cmd: &CmdVelOut,
        servers: &mut Servers,
        lifecycle: &mut Lifecycle,
        session: &mut Session,
    ) -> anyhow::Result<()> {
        let odom_sub = node.subscription::<Odometry>("odom", &qos::default_qos())?;
        let scan_sub = node.subscription::<LaserScan>("scan", &qos::sensor_data())?;
        let tf_sub = tf_static_subscription(node)?;
        let mut inputs = Inputs::new();
        inputs
            .add(odom_sub.async_stream(), "odom", "sample ignored", Event::Odom)
            .add(scan_sub.async_stream(), "scan", "scan ignored", Event::Scan);
        let shutdown = shutdown_signal();
        tokio::pin!(shutdown);
        let mut ticker = Ticker::new(self.config.rate_hz)?;
        let mut sink = CmdVel::new(cmd);
        info!("serving drive_distance, backup, drive_on_heading, spin");
        loop {
            let event = tokio::select! {
                _ = &mut shutdown => Event::Shutdown,
                Some(changed) = node.config_changed::<DriveConfig>() => Event::Config(changed),
                e = inputs.next() => e?,
                t = lifecycle.next() => Event::Lifecycle(t),
                e = servers.distance.next_event() => Event::Distance(e),
                e = servers.backup.next_event() => Event::BackUp(e),
                e = servers.heading.next_event() => Event::Heading(e),
                e = servers.spin.next_event() => Event::Spin(e),
                _ = ticker.tick() => Event::Tick,
            };
            match event {
                Event::Shutdown => return Ok(()),
                Event::Config(Ok(c)) => match ticker.set_rate(c.rate_hz) {
                    Ok(()) => self.config = c,
                    Err(e) => warn!("parameters not applied: {e}"),
                },
                Event::Config(Err(e)) => warn!("parameters not applied: {e}"),
                Event::Odom(m) => match planar_pose(&m.pose.pose) {
                    Ok(pose) => self.latest.set(pose, m.header.stamp),
                    Err(e) => warn_throttled!(self.throttle, "odom-bad", "{e}: sample dropped"),
                },
                Event::Scan(m) => {
                    self.laser.refresh(&tf_sub, &mut self.throttle);
                    self.scan_in(&m);
                }
                Event::Lifecycle(transition) => {
                    // Leaving active (deactivate, shutdown): the goal under way ends, with its zero.
                    if transition.leaves_active()
                        && let Some(ended) = session.end(EndCause::Deactivated, &mut sink)
                    {
                        servers.finish(&ended);
                    }
                    lifecycle.complete(transition, CallbackReturn::Success);
                }
                Event::Distance(ActionEvent::Goal(request)) => {
                    self.distance_goal(node, servers, session, &mut sink, request).await
                }
                Event::BackUp(ActionEvent::Goal(request)) => {
                    let g = request.goal();
                    let built = self.straight(Kind::BackUp, &g.target, g.speed, &g.time_allowance);
                    let elapsed = servers.elapsed();
                    let accepted = servers
                        .backup
                        .accept(request, |_| preempted(Kind::BackUp, elapsed), node.now_nanos())
                        .await;
                    self.begin(servers, session, &mut sink, Kind::BackUp, accepted, built);
                }
                Event::Heading(ActionEvent::Goal(request)) => {
                    let g = request.goal();
                    let built = self.straight(Kind::Heading, &g.target, g.speed, &g.time_allowance);
                    let elapsed = servers.elapsed();
                    let accepted = servers
                        .heading
                        .accept(request, |_| preempted(Kind::Heading, elapsed), node.now_nanos())
                        .await;
                    self.begin(servers, session, &mut sink, Kind::Heading, accepted, built);
                }
                Event::Spin(ActionEvent::Goal(request)) => {
                    let g = request.goal();
                    let (target, allowance) = (f64::from(g.target_yaw), g.time_allowance.clone());
                    let (settings, guard) = (self.config.spin, self.config.guard());
                    let build = |start| Behavior::spin(start, target, secs_from_duration(&allowance), settings, guard);
                    let built = self.nav2_start(Kind::Spin).and_then(build);
                    let elapsed = servers.elapsed();
                    let accepted = servers
                        .spin
                        .accept(request, |_| preempted(Kind::Spin, elapsed), node.now_nanos())
                        .await;
                    self.begin(servers, session, &mut sink, Kind::Spin, accepted, built);
                }
                Event::Distance(ActionEvent::CancelRequested(id)) => {
                    cancel(servers, session, &mut sink, Kind::Distance, id)
                }
                Event::BackUp(ActionEvent::CancelRequested(id)) => {
                    cancel(servers, session, &mut sink, Kind::BackUp, id)
                }
                Event::Heading(ActionEvent::CancelRequested(id)) => {
                    cancel(servers, session, &mut sink, Kind::Heading, id)
                }
                Event::Spin(ActionEvent::CancelRequested(id)) => cancel(servers, session, &mut sink, Kind::Spin, id),
                Event::Tick => self.tick(node, servers, session, &mut sink).await,
            }
        }
    }

    /// A scan's echoes in the base frame, kept for the collision check; a scan that cannot be
    /// placed is dropped (the check then goes off once the last one is older than the timeout).
    fn scan_in(&mut self, m: &LaserScan) {
        let mount = self.config.laser.mount(&self.config.base_frame);
        match checked_scan(&self.laser, &mount, m, None) {
            Ok(c) => self
                .echoes
                .set(c.scan.points_in_base().collect(), m.header.stamp.clone()),
            Err(e) => warn_throttled!(self.throttle, "scan-bad", "{e}; scan not used for the collision check"),
        }
    }

    /// A BackUp or DriveOnHeading goal (the two share their fields) as the law, or its end.
    fn straight(&self, kind: Kind, target: &Point, speed: f32, allowance: &DurationMsg) -> Built {
        let target = [target.x, target.y, target.z];
        let (settings, guard) = (self.config.settings(), self.config.guard());
        let (speed, allowance) = (f64::from(speed), secs_from_duration(allowance));
        let start = self.nav2_start(kind)?;
        match kind {
            Kind::BackUp => Behavior::back_up(start, target, speed, settings, allowance, guard),
            _ => Behavior::drive_on_heading(start, target, speed, settings, allowance, guard),
        }
    }

    /// The pose a Nav2 behavior starts from, or TF_ERROR (Nav2: "current robot pose is not
    /// available").
    fn nav2_start(&self, kind: Kind) -> Result<Pose2, Outcome> {
        let codes = kind.codes().unwrap_or(BACK_UP);
        self.latest
            .get(self.config.timeouts.odom_timeout())
            .copied()
            .ok_or_else(|| Outcome::failed("TF_ERROR", "no recent odom: is the chassis running?", codes.tf_error))
    }

    async fn distance_goal(
        &mut self,
        node: &RosNode,
        servers: &mut Servers,
        session: &mut Session,
        sink: &mut CmdVel<'_>,
        request: GoalRequest<mobil_msgs::mobil_msgs::action::DriveDistanceGoal>,
    ) {
        let goal = request.goal().clone();
        let Some(&start) = self.latest.get(self.config.timeouts.odom_timeout()) else {
            servers
                .distance
                .reject(request, "no recent odom: is the chassis running?")
                .await;
            return;
        };
        match DistanceDrive::new(start, goal.distance, goal.speed, self.config.settings()) {
            Err(e) => servers.distance.reject(request, &e.to_string()).await,
            Ok(drive) => {
                let travelled = session.active().map_or(0.0, |a| a.goal.progress().travelled);
                // The server ends the goal it replaces itself, with this result.
                let preempted = |_: &_| distance_result(travelled, "preempted by a newer goal");
                let accepted = servers.distance.accept(request, preempted, node.now_nanos()).await;
                if accepted.is_ok() {
                    info!("driving {} m at {} m/s", goal.distance, goal.speed);
                }
                self.begin(
                    servers,
                    session,
                    sink,
                    Kind::Distance,
                    accepted,
                    Ok(Behavior::distance(drive)),
                );
            }
        }
    }

    /// After an accept: the goal starts, or ends at once with Nav2's code (accepted first, as
    /// the behavior server does); a failed accept stops the goal it was to replace.
    fn begin(
        &mut self,
        servers: &mut Servers,
        session: &mut Session,
        sink: &mut CmdVel<'_>,
        kind: Kind,
        accepted: Result<(), mobil_ros::action::ActionError>,
        built: Built,
    ) {
        if let Err(e) = accepted {
            // One client's goal (a DDS send failed): logged, and the node goes on serving the
            // others; a goal it replaced was ended.
            warn_throttled!(self.throttle, "accept", "goal not started: {e}");
            if e.ended_active()
                && let Some(ended) = session.preempt(kind, sink)
            {
                servers.finish(&ended);
            }
            return;
        }
        match built {
            Ok(law) => {
                if let (_, Some(old)) = session.start(law, kind, Instant::now()) {
                    servers.finish(&old);
                }
                servers.started_nanos = servers.clock.now_nanos();
            }
            Err(outcome) => {
                let cause = EndCause::Outcome(outcome);
                warn!("goal ({}) ends at once: {}", <&str>::from(kind), cause.reason());
                servers.end(kind, GoalEnd::Aborted, &cause, 0.0, 0.0);
                // The goal it was to replace stops (its robot would otherwise drive on).
                if let Some(ended) = session.preempt(kind, sink) {
                    servers.finish(&ended);
                }
            }
        }
    }

    async fn tick(&mut self, node: &RosNode, servers: &mut Servers, session: &mut Session, sink: &mut CmdVel<'_>) {
        let stamped = self.config.cmd_vel.enable_stamped_cmd_vel;
        if let Some(line) = self.types.check(node, stamped, "cmd_vel", Instant::now()) {
            warn_throttled!(self.throttle, "cmd-type", "{line}");
        }
        if node.uses_sim_time() {
            let timeout = self.config.timeouts.clock_timeout();
            let clock = session.watch_clock(node.now_nanos(), Instant::now(), timeout, sink);
            mobil_ros::tell!(self.throttle, clock.notice());
            if let ClockCheck::Back(ended) = clock {
                servers.finish(&ended);
                return;
            }
        }
        let now = Instant::now();
        // The scan is not needed: without one the collision check is off (warned at a goal).
        let inputs = [Watched {
            name: "odom",
            age: self.latest.age_at(now),
            timeout: self.config.timeouts.odom_timeout(),
        }];
        let kind_now = session.active().map(|a| <&str>::from(a.source));
        self.diagnostics.tick(
            session,
            now,
            &inputs,
            || kind_now.map(str::to_owned),
            kind_now.unwrap_or("idle"),
            node.stamp(),
            &mut self.throttle,
        );
        let Some(kind) = session.active().map(|a| a.source) else {
            return;
        };
        let Some(&pose) = self.latest.get(self.config.timeouts.odom_timeout()) else {
            warn!("no odom for {:?}: goal aborted", self.config.timeouts.odom_timeout());
            if let Some(ended) = session.end(EndCause::Stale("odom".into()), sink) {
                servers.finish(&ended);
            }
            return;
        };
        // Only a Nav2 behavior checks for collisions: a drive_distance goal copies no echoes.
        let echoes = kind
            .codes()
            .and_then(|_| {
                self.echoes
                    .get(seconds(self.config.scan_timeout_s, MAX_INPUT_TIMEOUT_S))
            })
            .cloned();
        if echoes.is_none() && matches!(kind, Kind::BackUp | Kind::Heading) {
            warn_throttled!(
                self.throttle,
                "no-scan",
                "{}: no scan placed in {} within scan_timeout_s: the collision check is off",
                <&str>::from(kind),
                self.config.base_frame
            );
        }
        let dt = session.advance(node.now_nanos()).and_then(Result::ok).unwrap_or(0.0);
        // The goal's ROS time, not the session's sum of steps (each held to 0.1 s): a time
        // allowance is ROS time whatever the tick rate or the simulation's speed.
        let t = servers.elapsed();
        let Some(active) = session.active_mut() else { return };
        let step = active.goal.step(&StepInput::new(t, dt, pose), &echoes);
        match session.apply(step, twist, sink) {
            Applied::Commanded(_) => {
                if let Some(active) = session.active()
                    && let Err(e) = servers.feedback(kind, &active.goal).await
                {
                    warn_throttled!(self.throttle, "feedback", "{e}");
                }
            }
            Applied::Ended(ended, _) => servers.finish(&ended),
            Applied::Refused(ended) => {
                if let Some(ended) = ended {
                    servers.finish(&ended);
                }
            }
            Applied::Idle => {}
        }
    }
}

/// A cancel request for the active goal of `kind`'s server.
fn cancel(
    servers: &mut Servers,
    session: &mut Session,
    sink: &mut CmdVel<'_>,
    kind: Kind,
    id: mobil_ros::action::GoalId,
) {
    let ours = session.active().is_some_and(|a| a.source == kind);
    if ours
        && servers.active_id(kind) == Some(id)
        && let Some(ended) = session.end(EndCause::Canceled, sink)
    {
        servers.finish(&ended);
    }
}

/// The result of `kind`'s goal replaced by a newer one after `elapsed` seconds.
fn preempted<R: BehaviorResult>(kind: Kind, elapsed: f64) -> R {
    behavior_result(kind, &EndCause::Preempted(kind.into()), elapsed)
}
