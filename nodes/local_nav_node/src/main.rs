//! `local_nav_node`: reactive navigation to a goal by the vector-distance function (SPEC §2),
//! the shell of [`mobil_local_nav`]. Goals come from `goal_pose` (PoseStamped in `odom`, as
//! RViz's "2D Goal Pose" sends it) and from Nav2's `navigate_to_pose` action; both drive one
//! navigator, and a new goal from either pre-empts the old one.
//!
//! **One step per scan**: each valid scan, with fresh odometry, is one navigator step and one
//! `cmd_vel`. The method works on the scan, so a step between scans would repeat the last one,
//! and stepping on arrival adds no queueing delay to the scan-to-command latency. A 20 Hz
//! watchdog tick on the steady clock ends a goal whose scan or odometry went stale and sends the
//! action feedback; status and markers follow at `status_rate_hz` (and the status on every
//! change of state or mode).
//!
//! Goals run through the kit's motion server ([`MotionSession`]), the navigator being the goal
//! law: `cmd_vel` only while a goal is active, exactly one zero `cmd_vel` when a goal that moved
//! the robot ends (reached, no path, no progress, stale input, canceled, refused), none between
//! a goal and the newer goal that pre-empts it; every command is held to the chassis limits
//! ([`VelocityCommand::for_chassis`]). A refused input while a goal runs (scan, laser pose, odometry)
//! stops the robot with one zero command; the navigator refusing its input on 20 scans in a row
//! ends the goal `INVALID_INPUT`. At shutdown with a goal under way, its zero command is the last
//! one, waited for ([`mobil_ros::stop::final_stop`]); an idle node sends none.

use mobil_geom::path::PathGoals;
use mobil_geom::Pose2;
use mobil_local_nav::{Mode, MotionLimits, Navigator, Progress, ProgressChecker, StepOutput, VelocityCommand};
use mobil_local_nav_node::{
    clear_markers, end_answer, goal_heading, goal_point, invalid_goal, markers, no_progress, reconfigured_progress,
    LocalNavConfig, MarkerView,
};
use mobil_motion::{BodyTwist, GoalLaw, Nav2Codes, Step, StepInput};
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::{Pose, PoseStamped, Twist};
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::nav2_msgs::action::{
    FollowPath, FollowPathGoal, FollowPathResult, NavigateToPose, NavigateToPoseFeedback, NavigateToPoseGoal,
    NavigateToPoseResult,
};
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_msgs::sensor_msgs::msg::LaserScan;
use mobil_msgs::std_msgs::msg::Header;
use mobil_ros::action::{goal_end, nav2_result, ActionEvent, GoalRequest, GoalServer, GoalServerConfig};
use mobil_ros::diagnostics::MotionDiagnostics;
use mobil_ros::geometry::{odom_pose, pose_msg, twist_msg};
use mobil_ros::input::Inputs;
use mobil_ros::latest::Latest;
use mobil_ros::lifecycle::{CallbackReturn, Lifecycle, Transition};
use mobil_ros::motion::{
    Applied, ClockCheck, CmdVel, EndCause, Ended, MotionSession, Outputs, SessionSettings, Watched,
};
use mobil_ros::plan::PlanOut;
use mobil_ros::scan::{checked_scan, tf_static_subscription, CheckedScan, LaserPoseFrom, ScanRefusal, StaticFrames};
use mobil_ros::status::{NavStatusView, RateGate};
use mobil_ros::stop::FINAL_STOP_WAIT;
use mobil_ros::tf::GoalTf;
use mobil_ros::ticker::Ticker;
use mobil_ros::time::duration_msg;
use mobil_ros::{qos, run_node, shutdown_signal, warn_throttled, ConfigError, LogThrottle, NodeDecl, RosNode};
use nalgebra::Point2;
use ros2_client::Subscription;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tracing::{info, warn};

/// The watchdog tick (steady clock): stale inputs are noticed within 50 ms of their timeout.
const WATCHDOG_RATE_HZ: f64 = 20.0;

mod follow;

fn decl() -> NodeDecl {
    NodeDecl::for_config::<LocalNavConfig>(
        "local_nav",
        "Reactive navigation to a goal by the vector-distance function (R/L/T modes): goal_pose and \
         navigate_to_pose in, cmd_vel out",
    )
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(serve(node)))
}

/// Where the active goal came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    Topic,
    Action,
    Path,
}

impl From<Source> for &'static str {
    fn from(s: Source) -> &'static str {
        match s {
            Source::Topic => "goal_pose",
            Source::Action => "navigate_to_pose",
            Source::Path => "follow_path",
        }
    }
}

impl Source {
    fn name(self) -> &'static str {
        self.into()
    }
}

/// What the node keeps with the active goal (the navigator, the goal law, is the shell's: it
/// is rebuilt on a parameter change and keeps the goal).
#[derive(Debug, Clone)]
struct NavGoal {
    /// The point driven to, in `frame`.
    goal: Point2<f64>,
    /// The goal's frame: the navigator sees the robot from there ([`GoalTf::robot`]).
    frame: String,
    started_ros_nanos: i64,
    /// A `follow_path` goal's path, as sub-goals: `goal` is the current one.
    path: Option<PathGoals>,
}

/// What a goal drives to: a point (its heading, if given, is not kept), or a path's sub-goals.
enum Target {
    Point { goal: Point2<f64>, heading: Option<f64> },
    Path(PathGoals),
}

type Session = MotionSession<NavGoal, Source>;
type NavEnded = Ended<NavGoal, Source>;

/// The latest valid odometry: the pose for the navigator, the message pose and speed for the
/// action feedback.
#[derive(Debug, Clone)]
struct OdomSample {
    pose: Pose2,
    msg_pose: Pose,
    speed: f64,
}

/// Everything the loop holds between events.
struct Shell {
    config: LocalNavConfig,
    limits: MotionLimits,
    nav: Navigator,
    progress: ProgressChecker,
    session: Session,
    scan_seen: Latest<()>,
    odom: Latest<OdomSample>,
    /// The latest odometry message was refused: no step until a valid one comes (the last
    /// valid one still times the watchdog).
    odom_refused: bool,
    last_step: Option<StepOutput>,
    status_gate: RateGate,
    throttle: LogThrottle,
    /// Looks for a `cmd_vel` endpoint of the other type.
    types: mobil_ros::cmd_vel::TypeWatch,
    /// `local_plan`: from the robot to the point the navigator heads for.
    plans: PlanOut,
    /// `tf` and `tf_static`: goals in other frames than odometry's.
    tf: GoalTf,
    /// The latest goal's frame (odometry's before the first): the frame of the status, the
    /// markers, `local_plan` and the feedback.
    frame: String,
    /// `/diagnostics`.
    diagnostics: MotionDiagnostics,
}

/// What woke the loop. One lives at a time, on the stack, so its size does not matter.
#[allow(clippy::large_enum_variant)]
enum Event {
    Shutdown,
    Config(Result<LocalNavConfig, ConfigError>),
    Scan(LaserScan),
    Odom(Odometry),
    GoalPose(PoseStamped),
    Action(ActionEvent<NavigateToPoseGoal>),
    Path(ActionEvent<FollowPathGoal>),
    Lifecycle(Transition),
    Tick,
}

async fn serve(node: &mut RosNode) -> anyhow::Result<()> {
    let config: LocalNavConfig = node.config()?;
    let stamped = config.cmd_vel.enable_stamped_cmd_vel;
    let outputs = Outputs::create(node, "local_nav", stamped, &config.frames.base_frame)?;
    let (outcome, final_zero) = run(node, &outputs, config).await;
    // A goal under way at the end gets its zero command, waited for (the loop sends it; this
    // one for a loop that failed with a goal under way); an idle node sends none (another node,
    // teleop or a twist_mux input, may be commanding the robot).
    if final_zero {
        outputs.cmd.final_stop(FINAL_STOP_WAIT).await;
    }
    outcome
}

fn result(cause: &EndCause) -> NavigateToPoseResult {
    nav2_result(cause, Nav2Codes::FOLLOW_PATH)
}

fn path_result(cause: &EndCause) -> FollowPathResult {
    nav2_result(cause, Nav2Codes::FOLLOW_PATH)
}

/// The node's action servers.
struct Servers {
    nav: GoalServer<NavigateToPose>,
    path: GoalServer<FollowPath>,
}

/// The loop's outcome, and whether the node's last word must be a zero command.
async fn run(node: &mut RosNode, out: &Outputs, config: LocalNavConfig) -> (anyhow::Result<()>, bool) {
    match start(node, out, config).await {
        Ok(r) => r,
        Err(e) => (Err(e), false),
    }
}

async fn start(
    node: &mut RosNode,
    out: &Outputs,
    config: LocalNavConfig,
) -> anyhow::Result<(anyhow::Result<()>, bool)> {
    let limits = config.motion_limits()?;
    let nav = Navigator::new(config.nav_config()?, limits)?;
    let scan_sub = node.subscription::<LaserScan>("scan", &qos::sensor_data())?;
    let odom_sub = node.subscription::<Odometry>("odom", &qos::default_qos())?;
    let goal_sub = node.subscription::<PoseStamped>("goal_pose", &qos::default_qos())?;
    let tf_sub = tf_static_subscription(node)?;
    let mut lifecycle = Lifecycle::serve(node, &config.managed)?;
    let server_config = GoalServerConfig {
        result_timeout: config.timeouts.result_timeout(),
    };
    let mut servers = Servers {
        nav: GoalServer::create(node, "navigate_to_pose", server_config.clone())?.gate(lifecycle.gate()),
        path: GoalServer::create(node, "follow_path", server_config)?.gate(lifecycle.gate()),
    };
    let mut laser = StaticFrames::default();
    let plans = PlanOut::create(node)?;
    let tf = GoalTf::create(node, &config.frames.odom_frame, config.controller.transform_tolerance())?;
    let model = mobil_ros::chassis::chassis_params(&config.chassis)?.model().as_str();
    let diagnostics = MotionDiagnostics::create(node, model)?;
    let mut shell = Shell {
        diagnostics,
        tf,
        frame: config.frames.odom_frame.clone(),
        progress: ProgressChecker::new(config.controller.progress),
        config,
        limits,
        nav,
        session: Session::new(SessionSettings::default()),
        scan_seen: Latest::new(),
        odom: Latest::new(),
        odom_refused: false,
        last_step: None,
        status_gate: RateGate::default(),
        throttle: LogThrottle::new(Duration::from_secs(2)),
        types: Default::default(),
        plans,
    };
    shell.publish_status(node, out, NavStatus::IDLE, String::new());
    info!(
        "waiting for goals on goal_pose, navigate_to_pose and follow_path (in `{}`, or a frame tf connects to it)",
        shell.config.frames.odom_frame
    );
    let outcome = event_loop(
        node,
        out,
        &mut shell,
        &mut servers,
        &mut lifecycle,
        &mut laser,
        &scan_sub,
        &odom_sub,
        &goal_sub,
        &tf_sub,
    )
    .await;
    // A goal under way ends, and its zero command, waited for, goes out before anything that
    // may take time; then the bond breaks and the servers close (each waits up to 2 s for its
    // results).
    let (ended, final_zero) = shell.session.shutdown();
    if let Some(ended) = ended {
        shell.report(node, out, &mut servers, ended);
    }
    if final_zero {
        out.cmd.final_stop(FINAL_STOP_WAIT).await;
    }
    lifecycle.close().await;
    let Servers { nav, path } = servers;
    tokio::join!(
        nav.close(result(&EndCause::Shutdown)),
        path.close(path_result(&EndCause::Shutdown))
    );
    Ok((outcome, false))
}

#[allow(clippy::too_many_arguments)]
async fn event_loop(
    node: &mut RosNode,
    out: &Outputs,
    shell: &mut Shell,
    servers: &mut Servers,
    lifecycle: &mut Lifecycle,
    laser: &mut StaticFrames,
    scan_sub: &Subscription<LaserScan>,
    odom_sub: &Subscription<Odometry>,
    goal_sub: &Subscription<PoseStamped>,
    tf_sub: &Subscription<TFMessageAlias>,
) -> anyhow::Result<()> {
    let mut inputs = Inputs::new();
    inputs
        .add(scan_sub.async_stream(), "scan", "scan ignored", Event::Scan)
        .add(odom_sub.async_stream(), "odom", "sample ignored", Event::Odom)
        .add(goal_sub.async_stream(), "goal_pose", "goal ignored", Event::GoalPose);
    let shutdown = shutdown_signal();
    tokio::pin!(shutdown);
    let mut ticker = Ticker::new(WATCHDOG_RATE_HZ)?;
    loop {
        let event = tokio::select! {
            _ = &mut shutdown => Event::Shutdown,
            Some(changed) = node.config_changed::<LocalNavConfig>() => Event::Config(changed),
            e = inputs.next() => e?,
            e = servers.nav.next_event() => Event::Action(e),
            e = servers.path.next_event() => Event::Path(e),
            t = lifecycle.next() => Event::Lifecycle(t),
            _ = ticker.tick() => Event::Tick,
        };
        let mut sink = CmdVel::new(&out.cmd);
        match event {
            Event::Shutdown => return Ok(()),
            Event::Config(Ok(c)) => shell.reconfigure(c),
            Event::Config(Err(e)) => warn!("parameters not applied: {e}"),
            Event::Odom(m) => shell.odom_in(&mut sink, &m),
            Event::Scan(m) => {
                laser.refresh(tf_sub, &mut shell.throttle);
                shell.scan_in(node, out, &mut sink, servers, laser, &m);
            }
            Event::GoalPose(_) if !lifecycle.is_active() => warn_throttled!(
                shell.throttle,
                "inactive",
                "goal_pose refused: the node is {} (lifecycle): activate it first",
                lifecycle.state()
            ),
            Event::GoalPose(m) => shell.goal_pose_in(node, out, &mut sink, servers, &m),
            Event::Lifecycle(transition) => {
                // Leaving active (deactivate, shutdown): the goal under way ends, with its zero.
                if transition.leaves_active() {
                    shell.end_goal(node, out, &mut sink, servers, EndCause::Deactivated);
                }
                lifecycle.complete(transition, CallbackReturn::Success);
            }
            Event::Action(ActionEvent::Goal(request)) => {
                shell.action_goal_in(node, out, &mut sink, servers, request).await
            }
            Event::Path(ActionEvent::Goal(request)) => shell.path_goal_in(node, out, &mut sink, servers, request).await,
            Event::Action(ActionEvent::CancelRequested(id)) => {
                shell.cancel(node, out, &mut sink, servers, Source::Action, id)
            }
            Event::Path(ActionEvent::CancelRequested(id)) => {
                shell.cancel(node, out, &mut sink, servers, Source::Path, id)
            }
            Event::Tick => shell.tick(node, out, &mut sink, servers).await,
        }
    }
}

type TFMessageAlias = mobil_msgs::tf2_msgs::msg::TFMessage;

/// A command of the navigator (a body twist) held to the chassis limits.
fn limited(limits: &MotionLimits) -> impl Fn(BodyTwist) -> Twist + '_ {
    move |b| {
        let c = VelocityCommand {
            vx: b.vx,
            vy: b.vy,
            omega: b.wz,
        }
        .for_chassis(limits);
        twist_msg(BodyTwist::new(c.vx, c.vy, c.omega))
    }
}

impl Shell {
    fn reconfigure(&mut self, c: LocalNavConfig) {
        let built = c
            .motion_limits()
            .and_then(|l| Ok((l, c.nav_config()?)))
            .map_err(|e| e.to_string())
            .and_then(|(l, n)| Navigator::new(n, l).map(|nav| (l, nav)).map_err(|e| e.to_string()));
        match built {
            Ok((limits, mut nav)) => {
                if let Some(a) = self.session.active() {
                    // A valid goal stays valid; the new navigator starts it again in R-mode.
                    if nav.set_goal(a.goal.goal).is_err() {
                        warn!("goal could not be carried over the parameter change");
                    }
                    info!("parameters changed: the goal restarts in R-mode with them");
                }
                self.limits = limits;
                self.nav = nav;
                let old = std::mem::replace(&mut self.progress, ProgressChecker::new(c.controller.progress));
                self.progress = reconfigured_progress(old, c.controller.progress);
                self.tf.set_tolerance(c.controller.transform_tolerance());
                self.config = c;
            }
            Err(e) => warn!("parameters not applied: {e}"),
        }
    }

    /// A valid odometry message is kept; a refused one is dropped, and while a goal runs the
    /// robot stops (one zero command) until valid odometry comes again.
    fn odom_in(&mut self, sink: &mut CmdVel<'_>, m: &Odometry) {
        let speed = m.twist.twist.linear.x.hypot(m.twist.twist.linear.y);
        match odom_pose(m, &self.config.frames.odom_frame, &self.config.frames.base_frame) {
            Ok(pose) => {
                self.odom_refused = false;
                self.odom.set(
                    OdomSample {
                        pose,
                        msg_pose: m.pose.pose.clone(),
                        speed: if speed.is_finite() { speed } else { 0.0 },
                    },
                    m.header.stamp.clone(),
                );
            }
            Err(e) => {
                warn_throttled!(self.throttle, "odom-bad", "odom sample dropped: {e}; robot stopped");
                self.odom_refused = true;
                self.session.hold(sink);
            }
        }
    }

    /// What the status says: the last step's distance, H and L (else the distance from the
    /// latest odometry, else NaN).
    fn status_view(&self, state: u8, reason: String, mode: Mode, goal: Option<Point2<f64>>, now: i64) -> NavStatusView {
        let last = self.last_step.as_ref();
        let distance = match (last, goal, self.robot_seen(now)) {
            (Some(s), _, _) => s.goal_distance,
            (None, Some(g), Some(robot)) => (g - robot.position()).norm(),
            _ => f64::NAN,
        };
        NavStatusView {
            goal: goal.map(|g| Pose2::new(g.x, g.y, 0.0)),
            distance_to_goal: distance,
            hit_point: last.and_then(|s| s.hit_point),
            leave_point: last.and_then(|s| s.leave_point),
            ..NavStatusView::new(state, mobil_local_nav_node::mode_name(mode), reason)
        }
    }

    /// The latest valid odometry pose seen from the latest goal's frame at ROS time `now`
    /// (ns), through the transforms taken so far; `None` without odometry or transform.
    fn robot_seen(&self, now: i64) -> Option<Pose2> {
        let odom = self.odom.value()?;
        let odom_in = self.tf.odom_in(&self.frame, now).ok()?;
        Some(odom_in.compose(&odom.pose))
    }

    fn send_status(&mut self, node: &RosNode, out: &Outputs, view: &NavStatusView) {
        out.send_status(view, node.stamp(), &self.frame, &mut self.throttle);
        self.status_gate.sent(Instant::now());
    }

    /// The status of the current goal (or of none); with no reason given, the stopped clock's if
    /// the robot is held for it.
    fn publish_status(&mut self, node: &RosNode, out: &Outputs, state: u8, reason: String) {
        let reason = match reason.is_empty() {
            true => self.session.clock_hold_reason().unwrap_or_default(),
            false => reason,
        };
        let goal = self.session.active().map(|a| a.goal.goal).or(self.nav.goal());
        let view = self.status_view(state, reason, self.nav.mode(), goal, node.now_nanos());
        self.send_status(node, out, &view);
    }

    fn publish_status_with_mode(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        state: u8,
        reason: String,
        mode: Mode,
        goal: Option<Point2<f64>>,
    ) {
        let view = self.status_view(state, reason, mode, goal, node.now_nanos());
        self.send_status(node, out, &view);
    }

    /// Ends the active goal with `cause` (the session sends its zero command, if one is due)
    /// and reports it.
    fn end_goal(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        sink: &mut CmdVel<'_>,
        servers: &mut Servers,
        cause: EndCause,
    ) {
        if let Some(ended) = self.session.end(cause, sink) {
            self.report(node, out, servers, ended);
        }
    }

    /// Whether a goal in `frame` can be followed now: `Err` with the TF_ERROR reason if not.
    fn goal_frame(&mut self, frame: &str, node: &RosNode) -> Result<(), String> {
        match self.tf.accept(frame, node.now_nanos()) {
            Ok(_) => Ok(()),
            Err(why) => Err(format!("TF_ERROR: {why}")),
        }
    }

    /// Tells an ended goal's end: the action's result (unless the server already ended it,
    /// when a newer action goal took its place), the log, the status with the last step's mode,
    /// distance, H and L; the navigator and the progress checker are cleared and the markers
    /// deleted.
    fn report(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers, ended: NavEnded) {
        let (state, reason, _) = end_answer(&ended.cause);
        if !ended.server_ended {
            match ended.source {
                Source::Action => {
                    servers.nav.finish(goal_end(&ended.cause), result(&ended.cause));
                }
                Source::Path => {
                    servers.path.finish(goal_end(&ended.cause), path_result(&ended.cause));
                }
                Source::Topic => {}
            }
        }
        mobil_ros::tell!(self.throttle, [ended.cause.notice(ended.source.name())]);
        let mode_before = self.nav.mode();
        self.publish_status_with_mode(node, out, state, reason, mode_before, Some(ended.goal.goal));
        self.nav.cancel();
        self.progress.reset();
        self.last_step = None;
        let clear = clear_markers(node.stamp(), &self.frame);
        out.send_markers(clear, &mut self.throttle);
        self.plans.clear(&self.frame, node.stamp(), &mut self.throttle);
    }

    /// Starts a validated goal: the goal it replaces, if any, ends PREEMPTED (reported; an
    /// action goal replaced by the next one its server accepted was ended by the server).
    fn start_goal(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        servers: &mut Servers,
        source: Source,
        (target, frame): (Target, String),
    ) {
        let (goal, heading, path) = match target {
            Target::Point { goal, heading } => (goal, heading, None),
            Target::Path(path) => (path.goal(), None, Some(path)),
        };
        let new = NavGoal {
            goal,
            frame: frame.clone(),
            started_ros_nanos: node.now_nanos(),
            path,
        };
        let (_, old) = self.session.start(new, source, Instant::now());
        if let Some(old) = old {
            self.report(node, out, servers, old);
        }
        self.frame = frame;
        if let Err(e) = self.nav.set_goal(goal) {
            // goal_point checked it: unreachable in practice, and safe if reached.
            warn!("goal refused by the navigator: {e}");
        }
        self.progress.reset();
        self.last_step = None;
        info!(
            "goal ({}): ({:.3}, {:.3}) in {}",
            source.name(),
            goal.x,
            goal.y,
            self.frame
        );
        if let Some(yaw) = heading {
            info!(
                "goal ({}): its heading {yaw:.3} rad is not kept: the robot stops within xy_goal_tolerance \
                 ({} m) of the position, facing where it arrives",
                source.name(),
                self.config.nav.goal_tolerance
            );
        }
        self.publish_status(node, out, NavStatus::ACTIVE, String::new());
    }

    fn goal_pose_in(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        sink: &mut CmdVel<'_>,
        servers: &mut Servers,
        m: &PoseStamped,
    ) {
        let frame = self.tf.frame_of(&m.header.frame_id);
        let checked = goal_point(m, &frame)
            .map_err(|e| invalid_goal(&e))
            .and_then(|goal| Ok((goal, self.goal_frame(&frame, node)?)));
        match checked {
            Ok((goal, ())) => {
                let heading = goal_heading(m);
                let target = Target::Point { goal, heading };
                self.start_goal(node, out, servers, Source::Topic, (target, frame))
            }
            Err(reason) => {
                // A goal the user meant to replace the old one with: the old one stops too.
                self.end_goal(node, out, sink, servers, EndCause::Preempted("goal_pose, refused"));
                warn!("goal_pose refused: {reason}");
                self.publish_status_with_mode(node, out, NavStatus::FAILED, reason, Mode::Idle, None);
            }
        }
    }

    async fn action_goal_in(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        sink: &mut CmdVel<'_>,
        servers: &mut Servers,
        request: GoalRequest<NavigateToPoseGoal>,
    ) {
        let frame = self.tf.frame_of(&request.goal().pose.header.frame_id);
        let checked = goal_point(&request.goal().pose, &frame)
            .map_err(|e| invalid_goal(&e))
            .and_then(|goal| Ok((goal, self.goal_frame(&frame, node)?)));
        let goal = match checked {
            Ok((g, ())) => g,
            Err(reason) => {
                warn!("navigate_to_pose goal rejected: {reason}");
                servers.nav.reject(request, &reason).await;
                // The status says so too; a running goal keeps running (unlike a refused
                // goal_pose, a rejected action goal never replaces the active one), and its
                // ACTIVE status follows, so that the latched status is the running goal's.
                self.publish_status_with_mode(node, out, NavStatus::FAILED, reason, Mode::Idle, None);
                if self.session.active().is_some() {
                    self.publish_status(node, out, NavStatus::ACTIVE, String::new());
                }
                return;
            }
        };
        if !request.goal().behavior_tree.is_empty() {
            warn_throttled!(
                self.throttle,
                "behavior-tree",
                "navigate_to_pose: behavior_tree `{}` ignored (this navigator has no behaviour trees)",
                request.goal().behavior_tree
            );
        }
        let heading = goal_heading(&request.goal().pose);
        // The server ends a running action goal itself on accept, with this result.
        let preempted = result(&EndCause::Preempted("navigate_to_pose"));
        match servers.nav.accept(request, |_| preempted, node.now_nanos()).await {
            Ok(()) => {
                let target = Target::Point { goal, heading };
                self.start_goal(node, out, servers, Source::Action, (target, frame))
            }
            Err(e) => {
                warn_throttled!(self.throttle, "accept", "navigate_to_pose goal not started: {e}");
                // A running action goal was ended by the server: the robot stops with it (and
                // with a topic's goal, which the action's goal was to replace); a request refused
                // for its id leaves the running goal alone.
                if e.ended_active()
                    && let Some(ended) = self.session.preempt(Source::Action, sink)
                {
                    self.report(node, out, servers, ended);
                }
            }
        }
    }

    fn scan_in(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        sink: &mut CmdVel<'_>,
        servers: &mut Servers,
        laser: &StaticFrames,
        m: &LaserScan,
    ) {
        let mount = self.config.laser.mount(&self.config.frames.base_frame);
        let checked = checked_scan(laser, &mount, m, None);
        let CheckedScan {
            scan,
            base_from_laser,
            from,
        } = match checked {
            Ok(c) => c,
            Err(e) => {
                let key = match e {
                    ScanRefusal::NoLaserPose { .. } => "laser-pose",
                    ScanRefusal::Invalid(_) => "scan-bad",
                };
                warn_throttled!(self.throttle, key, "{e}; scan ignored");
                return self.session.hold(sink);
            }
        };
        if self.scan_seen.value().is_none() {
            info!(
                "first scan: {} beams, laser `{}` at ({:.3}, {:.3}, {:.3} rad) in {} (from {})",
                scan.len(),
                m.header.frame_id,
                base_from_laser.x,
                base_from_laser.y,
                base_from_laser.yaw,
                self.config.frames.base_frame,
                match from {
                    LaserPoseFrom::TfStatic => "tf_static",
                    LaserPoseFrom::Parameter => "laser_pose",
                }
            );
        }
        self.scan_seen.set((), m.header.stamp.clone());
        if self.session.active().is_none() {
            return;
        }
        let fresh = self
            .odom
            .get(self.config.timeouts.odom_timeout())
            .filter(|_| !self.odom_refused);
        let Some(odom) = fresh.cloned() else {
            // No command from stale or refused odometry: the robot stops; the watchdog ends the
            // goal if this lasts.
            warn_throttled!(
                self.throttle,
                "odom-stale",
                "scan ignored: odom stale or refused; robot stopped"
            );
            return self.session.hold(sink);
        };
        // The robot seen from the goal's frame: a localiser's correction moves it relative to
        // the goal; a transform lost ends the goal.
        let frame = self.session.active().map(|a| a.goal.frame.clone()).unwrap_or_default();
        let pose = match self.tf.robot(&frame, &odom.pose, node.now_nanos()) {
            Ok(pose) => pose,
            Err(why) => return self.end_goal(node, out, sink, servers, EndCause::Tf(why)),
        };
        self.next_subgoal(pose.position());
        // The method counts path, not time: the step's time is the progress checker's.
        let now = node.now_nanos() as f64 * 1e-9;
        let step = GoalLaw::step(&mut self.nav, &StepInput::new(now, 0.0, pose), &scan);
        // Progress is measured in odometry, as Nav2's checker measures it in its costmap's frame:
        // a localiser's correction is no movement.
        if let Step::Command { .. } = &step
            && let Progress::Stuck { since } = self.progress.check(odom.pose.position(), now)
        {
            let radius = self.progress.settings().required_movement_radius;
            return self.end_goal(node, out, sink, servers, no_progress(since, radius));
        }
        if let Step::Refused(why) = &step {
            warn_throttled!(
                self.throttle,
                "nav-input",
                "navigator refused its input: {why}; robot stopped"
            );
        }
        match self.session.apply(step, limited(&self.limits), sink) {
            Applied::Commanded(output) => {
                let changed = output.changed_from.is_some();
                let mode = output.mode;
                self.last_step = Some(output);
                if changed {
                    info!("mode {}", mobil_local_nav_node::mode_name(mode));
                    self.publish_status(node, out, NavStatus::ACTIVE, String::new());
                }
            }
            Applied::Refused(ended) => {
                if let Some(ended) = ended {
                    self.report(node, out, servers, ended);
                }
            }
            Applied::Ended(ended, output) => {
                self.last_step = Some(output);
                self.report(node, out, servers, ended);
            }
            Applied::Idle => {}
        }
    }

    async fn tick(&mut self, node: &RosNode, out: &Outputs, sink: &mut CmdVel<'_>, servers: &mut Servers) {
        let now = Instant::now();
        let stamped = self.config.cmd_vel.enable_stamped_cmd_vel;
        if let Some(line) = self.types.check(node, stamped, "cmd_vel", now) {
            warn_throttled!(self.throttle, "cmd-type", "{line}");
        }
        if node.uses_sim_time() {
            let timeout = self.config.timeouts.clock_timeout();
            let clock = self.session.watch_clock(node.now_nanos(), now, timeout, sink);
            mobil_ros::tell!(self.throttle, clock.notice());
            match clock {
                ClockCheck::Back(ended) => return self.report(node, out, servers, ended),
                ClockCheck::Held { newly: true, .. } | ClockCheck::Resumed => {
                    self.publish_status(node, out, NavStatus::ACTIVE, String::new())
                }
                ClockCheck::Held { .. } | ClockCheck::Running => {}
            }
        }
        let inputs = [
            Watched {
                name: "scan",
                age: self.scan_seen.age_at(now),
                timeout: self.config.scan_timeout(),
            },
            Watched {
                name: "odom",
                age: self.odom.age_at(now),
                timeout: self.config.timeouts.odom_timeout(),
            },
        ];
        let described = |a: &mobil_ros::motion::Active<NavGoal, Source>| {
            let g = &a.goal;
            format!("{} ({:.3}, {:.3}) in {}", a.source.name(), g.goal.x, g.goal.y, g.frame)
        };
        let mode = mobil_local_nav_node::mode_name(self.nav.mode());
        let goal = || self.session.active().map(described);
        self.diagnostics.tick(
            &self.session,
            now,
            &inputs,
            goal,
            mode,
            node.stamp(),
            &mut self.throttle,
        );
        let Some(active) = self.session.active() else { return };
        let (goal, source) = (active.goal.clone(), active.source);
        // The displays and the feedback see the robot through the latest transforms.
        if !self.tf.frames().is_odom(&goal.frame) {
            self.tf.refresh(node.now_nanos());
        }
        if let Some(stale) = self.session.stale(now, &inputs) {
            return self.end_goal(node, out, sink, servers, EndCause::Stale(stale));
        }
        let stamp = node.stamp();
        if self.status_gate.due(now, self.config.status_rate_hz) {
            self.publish_status(node, out, NavStatus::ACTIVE, String::new());
            self.publish_markers(out, goal.goal, stamp.clone(), node.now_nanos());
        }
        match source {
            Source::Action => self.feedback(node, servers, &goal, stamp).await,
            Source::Path => self.path_feedback(node, servers, &goal).await,
            Source::Topic => {}
        }
    }

    /// The markers, and `local_plan`: the robot's pose, then the point the navigator heads for.
    fn publish_markers(&mut self, out: &Outputs, goal: Point2<f64>, stamp: Time, now: i64) {
        if let Some(robot) = self.robot_seen(now) {
            let target = mobil_geom::path::headed(&[robot.position(), goal]);
            let local = [robot, target[1]];
            self.plans
                .send_local(&local, &self.frame, stamp.clone(), &mut self.throttle);
        }
        if let Some(step) = &self.last_step {
            let view = MarkerView {
                sectors: self.nav.sectors(),
                direction: step.direction,
                goal: Some(goal),
                hit_point: step.hit_point,
                leave_point: step.leave_point,
            };
            let array = markers(&view, stamp, &self.frame, &self.config.frames.base_frame);
            out.send_markers(array, &mut self.throttle);
        }
    }

    /// Action feedback, on every watchdog tick (20 Hz) while an action goal is active.
    async fn feedback(&mut self, node: &RosNode, servers: &mut Servers, goal: &NavGoal, stamp: Time) {
        let (Some(odom), Some(robot)) = (self.odom.value(), self.robot_seen(node.now_nanos())) else {
            return;
        };
        let distance = (goal.goal - robot.position()).norm();
        let elapsed = (node.now_nanos().saturating_sub(goal.started_ros_nanos)) as f64 * 1e-9;
        let remaining = if odom.speed > 0.01 { distance / odom.speed } else { 0.0 };
        let feedback = NavigateToPoseFeedback {
            current_pose: PoseStamped {
                header: Header {
                    stamp: stamp.clone(),
                    frame_id: goal.frame.clone(),
                },
                // The message's own pose (its z, roll and pitch) where the goal is in odometry.
                pose: if self.tf.frames().is_odom(&goal.frame) {
                    odom.msg_pose.clone()
                } else {
                    pose_msg(&robot)
                },
            },
            navigation_time: duration_msg(elapsed),
            estimated_time_remaining: duration_msg(remaining),
            number_of_recoveries: 0,
            distance_remaining: distance as f32,
        };
        if let Err(e) = servers.nav.feedback(feedback).await {
            warn_throttled!(self.throttle, "feedback", "{e}");
        }
    }
}
