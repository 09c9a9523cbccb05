//! `planner_node`: MOBIL-II's HIGH-LEVEL, the shell of [`mobil_planner`]. Lyapunov docking onto
//! a pose (`dock_pose`, Nav2's `dock_robot`), backing out of a dock (`undock_robot`), and
//! waypoint following (`waypoints`, Nav2's `follow_waypoints`) by the goal approach, each route
//! first driven by a virtual robot against the known map (the pre-check, also served as
//! `planner/check_route`), or with `waypoint_method: vfo` by VFO round the obstacles the LIDAR
//! sees (`scan`), each segment's left/right decisions optimised by virtual robots
//! ([`mobil_planner_node::vfo`]: the ticks run off the event loop and the robot stops while a
//! segment is optimised). Every source feeds one session: a new goal from any of them
//! pre-empts the running one.
//!
//! **One step per odometry message**: each valid `odom` (50 Hz from chassis_node) is one
//! control step and one `cmd_vel`; the law's time and `dt` are ROS time (simulated under
//! `use_sim_time`). A 20 Hz watchdog tick on the steady clock ends a goal whose odometry went
//! stale and sends the action feedback; the status follows at `status_rate_hz` (and on every
//! change), the markers at `markers_rate_hz`.
//!
//! `cmd_vel` goes out only while a goal is active, and exactly one zero `cmd_vel` when a goal
//! ends, however it ends; every command is held to the chassis limits as chassis_node holds
//! them ([`clamp_twist`]). A refused odometry message or step while a goal runs stops the robot
//! with one zero command. At shutdown with a goal under way, that goal's zero command is the
//! last one, waited for ([`final_stop`]); an idle node sends none.

//! Every goal runs through the motion server ([`MotionSession`]): one goal at a time, its time
//! step, refusals, pre-emption and the zero command follow its rules (`cmd_vel` goes out only
//! while a goal is active; one zero `cmd_vel` when a goal that moved the robot ends, however it
//! ends, none between a goal and the newer one that replaces it and commands at its next step;
//! a goal that must wait, a route's pre-check or a VFO segment's optimisation, stops the robot
//! meanwhile). Every command is held to the chassis limits as chassis_node holds them
//! ([`clamp_twist`]). A refused odometry message or step stops the robot. At shutdown with a
//! goal that moved the robot, its zero command is the last one, waited for ([`final_stop`]);
//! an idle node sends none.

use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_motion::slot::{late_bound, ArrivalPeriod, Handback, LawSlot};
use mobil_motion::{BodyTwist, GoalLaw, Step, StepInput};
use mobil_msgs::geometry_msgs::msg::{PoseStamped, Twist};
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::mobil_msgs::srv::{CheckRoute, CheckRouteRequest, CheckRouteResponse};
use mobil_msgs::nav2_msgs::action::{
    DockRobot, DockRobotFeedback, DockRobotGoal, FollowWaypoints, FollowWaypointsFeedback, FollowWaypointsGoal,
    FollowWaypointsResult, UndockRobot, UndockRobotFeedback, UndockRobotGoal,
};
use mobil_msgs::nav_msgs::msg::{Odometry, Path};
use mobil_msgs::sensor_msgs::msg::LaserScan;
use mobil_msgs::tf2_msgs::msg::TFMessage;
use mobil_msgs::visualization_msgs::msg::MarkerArray;
use mobil_planner::goals::{
    after_pre_check, route_infeasible, DockGoal, PreChecked, RouteEvent, RouteGoal, UndockGoal,
};
use mobil_planner::vfo::{
    vfo_gains, Interrupt, ObstacleMap, OptimiseWarning, PoseHistory, ScanSkipped, VfoDrawing, VfoEvent, VfoGoal,
    VfoStep, VfoTick, VfoView, MAX_SETTLE_S,
};
use mobil_planner::{check_route_until, DockingPhase, Finish, RouteReport};
use mobil_planner_node::vfo::WaypointMethod;
use mobil_planner_node::{
    check_reply, clamp_twist, dock_result, end_state, follow_result, invalid_goal, load_world, markers,
    no_dock_database, refused_goal, refused_reply, stale_at_start, status_message, undock_result, vfo_follow_result,
    Action, GoalError, MarkerView, Missed, Mode, PlannerConfig, Route, StatusView, ROUTE_LIMITS,
};
use mobil_ros::action::{ActionEvent, GoalEnd, GoalRequest, GoalServer, GoalServerConfig};
use mobil_ros::geometry::odom_pose;
use mobil_ros::goal::{goal_pose, pose_in_frame, route_from_path, route_from_poses};
use mobil_ros::input::Inputs;
use mobil_ros::latest::Latest;
use mobil_ros::motion::{Applied, CmdVel, EndCause, EndKind, Ended, GoalId, MotionSession, SessionSettings, Watched};
use mobil_ros::offloop::CancelToken;
use mobil_ros::scan::{scan_from_msg, scan_laser_pose, tf_static_subscription, StaticFrames};
use mobil_ros::stop::{final_stop, FINAL_STOP_WAIT};
use mobil_ros::ticker::Ticker;
use mobil_ros::time::{duration_msg, secs_from_stamp, DtError};
use mobil_ros::OffLoop;
use mobil_ros::{qos, run_node, shutdown_signal, warn_throttled, ConfigError, LogThrottle, NodeDecl, RosNode};
use mobil_world::World;
use nalgebra::Point2;
use ros2_client::{Publisher, RmwRequestId, Server, Subscription};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};
use tokio::sync::mpsc;
use tracing::{info, warn};

/// The watchdog tick (steady clock): stale odometry is noticed within 50 ms of its timeout.
const WATCHDOG_RATE_HZ: f64 = 20.0;

fn decl() -> NodeDecl {
    NodeDecl::for_config::<PlannerConfig>(
        "planner",
        "HIGH-LEVEL planner: Lyapunov docking (dock_pose, dock_robot), undocking (undock_robot), waypoint \
         following by the goal approach after a route pre-check or by VFO round the obstacles in scan \
         (waypoint_method; waypoints, follow_waypoints, planner/check_route); cmd_vel out",
    )
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(serve(node)))
}

/// Where the active goal came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    DockPose,
    Waypoints,
    DockAction,
    UndockAction,
    FollowAction,
}

impl From<Source> for &'static str {
    fn from(s: Source) -> &'static str {
        match s {
            Source::DockPose => "dock_pose",
            Source::Waypoints => "waypoints",
            Source::DockAction => "dock_robot",
            Source::UndockAction => "undock_robot",
            Source::FollowAction => "follow_waypoints",
        }
    }
}

impl Source {
    fn name(self) -> &'static str {
        self.into()
    }

    fn is_action(self) -> bool {
        matches!(self, Source::DockAction | Source::UndockAction | Source::FollowAction)
    }

    fn action(self) -> Action {
        match self {
            Source::DockPose | Source::DockAction => Action::Dock,
            Source::UndockAction => Action::Undock,
            Source::Waypoints | Source::FollowAction => Action::Follow,
        }
    }
}

/// A VFO route: the law at home or out on a step ([`LawSlot`]), and what the status shows of it
/// meanwhile.
struct VfoRun {
    slot: LawSlot<VfoGoal>,
    route: Route,
    /// The status' figures as the law last came back.
    view: VfoView,
    /// The obstacle map changed since the law last took it (`Some(true)`: with new obstacles,
    /// which re-optimise the segment).
    map_changed: Option<bool>,
    /// Cancelled when the goal ends: a step's optimisation under way stops at once.
    stop: CancelToken,
}

/// What the active goal does: each a goal law of [`mobil_planner::goals`] but the pre-check
/// (a wait, off the event loop) and VFO (its ticks off the event loop).
#[allow(clippy::large_enum_variant)]
enum Task {
    /// A route waiting for its pre-check; the robot stopped meanwhile.
    PreCheck {
        route: Route,
        start: Pose2,
        /// The problems it found, kept for the result of a route it refuses.
        problems: Vec<Missed>,
    },
    Dock(DockGoal),
    Follow {
        goal: RouteGoal,
        route: Route,
    },
    Undock(UndockGoal),
    Vfo(VfoRun),
}

/// The goal state the session holds.
struct Goal {
    task: Task,
    /// The chassis and parameters when the goal began: a parameter change applies from the
    /// next goal, so the limits the controller scales by stay those the commands are held to.
    chassis: ChassisParams,
    config: PlannerConfig,
}

impl Goal {
    fn mode(&self) -> Mode {
        match &self.task {
            Task::Dock(d) => match d.last().map(|o| o.phase) {
                Some(DockingPhase::Rotate) => Mode::Rotate,
                _ => Mode::Dock,
            },
            Task::PreCheck { .. } => Mode::PreCheck,
            Task::Follow { .. } => Mode::Approach,
            Task::Undock(_) => Mode::Undock,
            Task::Vfo(_) => Mode::Vfo,
        }
    }

    /// The route's request index pursued, if a route.
    fn waypoint(&self) -> Option<usize> {
        let at = |route: &Route, i: usize| {
            let i = i.min(route.points.len().saturating_sub(1));
            route.request_index.get(i).copied().unwrap_or(0)
        };
        match &self.task {
            Task::Follow { goal, .. } => Some(goal.waypoint()),
            Task::Vfo(v) => Some(v.view.waypoint),
            Task::PreCheck { route, .. } => Some(at(route, 0)),
            Task::Dock(_) | Task::Undock(_) => None,
        }
    }
}

type Session = MotionSession<Goal, Source>;
type PlannerEnded = Ended<Goal, Source>;

struct Outputs {
    cmd: Publisher<Twist>,
    status: Publisher<NavStatus>,
    markers: Publisher<MarkerArray>,
}

struct Servers {
    dock: GoalServer<DockRobot>,
    undock: GoalServer<UndockRobot>,
    follow: GoalServer<FollowWaypoints>,
}

/// What a handler reaches of the node: its clock, its outputs and commands, its action servers.
struct Io<'a, 'c> {
    node: &'a RosNode,
    out: &'a Outputs,
    sink: &'a mut CmdVel<'c>,
    servers: &'a mut Servers,
}

/// A route pre-check done off the event loop, for goal `id`.
struct PreCheckDone {
    id: GoalId,
    report: Result<RouteReport, String>,
}

/// Most route checks computed at once, goal pre-checks and `planner/check_route` requests
/// together (each may take up to 0.6 s of one core). The goal's pre-check keeps one of them
/// (its [`OffLoop`] runs one at a time, a newer goal's waiting until the superseded check has
/// stopped); service requests beyond the rest are answered BUSY at once.
const MAX_CHECKS: usize = 4;

/// Odometry poses kept to place scans by their stamps: 2 s at 50 Hz, far beyond
/// `vfo.scan_odom_max_gap_s`'s range.
const ODOM_HISTORY: usize = 100;

/// One VFO step done on the blocking pool: the law back, and its step.
struct VfoTickDone {
    id: GoalId,
    law: Box<VfoGoal>,
    step: Step<VfoStep, Vec<usize>>,
}

/// The pre-checks off the event loop: the goal's (a newer goal stops the older one's) and
/// the service's (each request answered, in any order); the VFO ticks.
struct Jobs {
    goal: OffLoop<PreCheckDone>,
    vfo: OffLoop<VfoTickDone>,
    replies_tx: mpsc::UnboundedSender<(RmwRequestId, CheckRouteResponse)>,
    replies: mpsc::UnboundedReceiver<(RmwRequestId, CheckRouteResponse)>,
    pending: usize,
}

/// What the markers show between goals: the last route, its prediction and problems, the dock.
#[derive(Default)]
struct Drawing {
    route: Vec<Point2<f64>>,
    predicted: Vec<Pose2>,
    problems: Vec<Missed>,
    dock: Option<Pose2>,
    vfo: Option<VfoDrawing>,
}

/// Everything the loop holds between events.
struct Shell {
    config: PlannerConfig,
    chassis: ChassisParams,
    world: Arc<World>,
    session: Session,
    odom: Latest<Pose2>,
    odom_refused: bool,
    last_status: Option<Instant>,
    last_markers: Option<Instant>,
    drawing: Drawing,
    throttle: LogThrottle,
    /// Obstacles seen by the LIDAR, in odom (VFO); kept between goals.
    map: ObstacleMap,
    /// A parameter change asked for a new map while a goal ran: built once none runs.
    map_rebuild: bool,
    /// The odometry poses of the last seconds by stamp: a scan is placed with the pose at its
    /// own stamp.
    odom_history: PoseHistory,
    /// The stamp (s) of the last odometry sample taken, the VFO rest test's clock.
    odom_stamp: f64,
    /// When the last valid scan arrived.
    scan_seen: Latest<()>,
    /// The odometry's measured period (steady clock): a VFO tick's command later than two of
    /// them is dropped.
    odom_period: ArrivalPeriod,
    /// The laser's pose from `tf_static`.
    laser: StaticFrames,
}

#[allow(clippy::large_enum_variant)]
enum Event {
    Shutdown,
    Config(Result<PlannerConfig, ConfigError>),
    Odom(Odometry),
    Scan(LaserScan),
    VfoTicked(VfoTickDone),
    DockPose(PoseStamped),
    Waypoints(Path),
    Dock(ActionEvent<DockRobotGoal>),
    Undock(ActionEvent<UndockRobotGoal>),
    Follow(ActionEvent<FollowWaypointsGoal>),
    Check(RmwRequestId, CheckRouteRequest),
    Checked(RmwRequestId, CheckRouteResponse),
    RouteChecked(PreCheckDone),
    Tick,
}

async fn serve(node: &mut RosNode) -> anyhow::Result<()> {
    let config: PlannerConfig = node.config()?;
    let outputs = Outputs {
        cmd: node.publisher::<Twist>("cmd_vel", &qos::default_qos())?,
        status: node.publisher::<NavStatus>("planner/status", &qos::latched())?,
        markers: node.publisher::<MarkerArray>("planner/markers", &qos::default_qos())?,
    };
    start(node, &outputs, config).await?
}

/// Runs the node; the outer error is a start-up failure (no goal can have run), the inner one
/// the event loop's.
async fn start(node: &mut RosNode, out: &Outputs, config: PlannerConfig) -> anyhow::Result<anyhow::Result<()>> {
    let chassis = config.chassis_params()?;
    let world =
        load_world(&config.world_file).map_err(|e| anyhow::anyhow!("world_file `{}`: {e}", config.world_file))?;
    for w in config.gains()?.warnings() {
        warn!("{w} (accepted: stability needs only positive gains)");
    }
    let odom_sub = node.subscription::<Odometry>("odom", &qos::default_qos())?;
    let dock_sub = node.subscription::<PoseStamped>("dock_pose", &qos::default_qos())?;
    let route_sub = node.subscription::<Path>("waypoints", &qos::default_qos())?;
    let scan_sub = node.subscription::<LaserScan>("scan", &qos::sensor_data())?;
    let tf_sub = tf_static_subscription(node)?;
    let map = ObstacleMap::new(config.vfo.scan_config(config.robot_radius))
        .map_err(|e| anyhow::anyhow!("vfo obstacle extraction: {e}"))?;
    let check = node.service::<CheckRoute>("planner/check_route")?;
    let server_config = GoalServerConfig {
        result_timeout: config.timeouts.result_timeout(),
    };
    let mut servers = Servers {
        dock: GoalServer::create(node, "dock_robot", server_config.clone())?,
        undock: GoalServer::create(node, "undock_robot", server_config.clone())?,
        follow: GoalServer::create(node, "follow_waypoints", server_config)?,
    };
    info!(
        "{} chassis, pre-check world: {} ({} obstacles); waiting for dock_pose, waypoints, dock_robot, \
         undock_robot, follow_waypoints (frame `{}`)",
        chassis.model().as_str(),
        match config.world_file.as_str() {
            "" => "the sim's built-in world",
            "none" => "none",
            f => f,
        },
        world.obstacles.len(),
        config.frames.odom_frame
    );
    let mut shell = Shell {
        config,
        chassis,
        world: Arc::new(world),
        session: Session::new(SessionSettings::default()),
        odom: Latest::new(),
        odom_refused: false,
        last_status: None,
        last_markers: None,
        drawing: Drawing::default(),
        throttle: LogThrottle::new(Duration::from_secs(2)),
        map,
        map_rebuild: false,
        odom_history: PoseHistory::new(ODOM_HISTORY),
        odom_stamp: f64::NAN,
        scan_seen: Latest::new(),
        odom_period: ArrivalPeriod::default(),
        laser: StaticFrames::default(),
    };
    shell.send_idle_status(node, out);
    let (replies_tx, replies) = mpsc::unbounded_channel();
    let mut jobs = Jobs {
        goal: OffLoop::new(),
        vfo: OffLoop::new(),
        replies_tx,
        replies,
        pending: 0,
    };
    let mut sink = CmdVel::new(&out.cmd);
    let outcome = event_loop(
        node,
        out,
        &mut sink,
        &mut shell,
        &mut servers,
        &mut jobs,
        (&odom_sub, &dock_sub, &route_sub),
        (&scan_sub, &tf_sub),
        &check,
    )
    .await;
    // A goal under way (a pre-check included: it stopped a robot a goal before it moved) ends,
    // and its zero command, waited for, goes out before anything that may take time; then the
    // three servers close at once (each waits up to 2 s for its results).
    jobs.vfo.cancel();
    jobs.goal.cancel();
    let (ended, final_zero) = shell.session.shutdown();
    if let Some(ended) = ended {
        let mut io = Io {
            node,
            out,
            sink: &mut sink,
            servers: &mut servers,
        };
        shell.report(&mut io, ended, true);
    }
    if final_zero {
        final_stop(&out.cmd, Twist::default(), FINAL_STOP_WAIT).await;
    }
    let down = EndCause::Shutdown;
    let Servers { dock, undock, follow } = servers;
    tokio::join!(
        dock.close(dock_result(&down)),
        undock.close(undock_result(&down)),
        follow.close(follow_result(&down, &[], &[])),
    );
    Ok(outcome)
}

#[allow(clippy::too_many_arguments)]
async fn event_loop(
    node: &mut RosNode,
    out: &Outputs,
    sink: &mut CmdVel<'_>,
    shell: &mut Shell,
    servers: &mut Servers,
    jobs: &mut Jobs,
    (odom_sub, dock_sub, route_sub): (&Subscription<Odometry>, &Subscription<PoseStamped>, &Subscription<Path>),
    (scan_sub, tf_sub): (&Subscription<LaserScan>, &Subscription<TFMessage>),
    check: &Server<CheckRouteRequest, CheckRouteResponse>,
) -> anyhow::Result<()> {
    let mut inputs = Inputs::new();
    inputs
        .add(odom_sub.async_stream(), "odom", "sample ignored", Event::Odom)
        .add(scan_sub.async_stream(), "scan", "scan ignored", Event::Scan)
        .add(dock_sub.async_stream(), "dock_pose", "goal ignored", Event::DockPose)
        .add(route_sub.async_stream(), "waypoints", "route ignored", Event::Waypoints)
        .add_requests(check.receive_request_stream(), "planner/check_route", Event::Check);
    let shutdown = shutdown_signal();
    tokio::pin!(shutdown);
    let mut ticker = Ticker::new(WATCHDOG_RATE_HZ)?;
    loop {
        let event = tokio::select! {
            _ = &mut shutdown => Event::Shutdown,
            Some(changed) = node.config_changed::<PlannerConfig>() => Event::Config(changed),
            e = inputs.next() => e?,
            done = jobs.goal.result() => Event::RouteChecked(done),
            done = jobs.vfo.result() => Event::VfoTicked(done),
            Some((id, reply)) = jobs.replies.recv() => Event::Checked(id, reply),
            e = servers.dock.next_event() => Event::Dock(e),
            e = servers.undock.next_event() => Event::Undock(e),
            e = servers.follow.next_event() => Event::Follow(e),
            _ = ticker.tick() => Event::Tick,
        };
        let mut io = Io {
            node,
            out,
            sink,
            servers,
        };
        match event {
            Event::Shutdown => return Ok(()),
            Event::Config(Ok(c)) => shell.reconfigure(c),
            Event::Config(Err(e)) => warn!("parameters not applied: {e}"),
            Event::Odom(m) => shell.odom_in(&mut io, jobs, &m),
            Event::Scan(m) => {
                let skipped = shell.laser.take_all(tf_sub);
                if skipped > 0 {
                    warn_throttled!(
                        shell.throttle,
                        "tf-static",
                        "{skipped} invalid tf_static transform(s) skipped"
                    );
                }
                shell.scan_in(&m);
            }
            Event::VfoTicked(done) => shell.vfo_ticked(&mut io, done),
            Event::DockPose(m) => {
                let target = goal_pose("dock pose", &m, &shell.config.frames.odom_frame);
                let target = target.map_err(|e| invalid_goal(&e, Action::Dock));
                shell.start_dock(&mut io, target, Source::DockPose);
            }
            Event::Waypoints(m) => {
                let start = shell.fresh_odom();
                let route = route_from_path(
                    &m,
                    &shell.config.frames.odom_frame,
                    start.map(|p| p.position()),
                    ROUTE_LIMITS,
                );
                shell.start_route(&mut io, jobs, route, start, Source::Waypoints);
            }
            Event::Dock(ActionEvent::Goal(request)) => shell.dock_action(&mut io, request).await,
            Event::Undock(ActionEvent::Goal(request)) => shell.undock_action(&mut io, request).await,
            Event::Follow(ActionEvent::Goal(request)) => shell.follow_action(&mut io, jobs, request).await,
            Event::Dock(ActionEvent::CancelRequested(id)) => {
                let is_active = io.servers.dock.active_id() == Some(id);
                shell.cancel(&mut io, Source::DockAction, is_active)
            }
            Event::Undock(ActionEvent::CancelRequested(id)) => {
                let is_active = io.servers.undock.active_id() == Some(id);
                shell.cancel(&mut io, Source::UndockAction, is_active)
            }
            Event::Follow(ActionEvent::CancelRequested(id)) => {
                let is_active = io.servers.follow.active_id() == Some(id);
                shell.cancel(&mut io, Source::FollowAction, is_active)
            }
            Event::Check(id, req) => shell.check_in(io.node, jobs, check, id, &req),
            Event::Checked(id, reply) => {
                jobs.pending = jobs.pending.saturating_sub(1);
                respond(check, id, reply, &mut shell.throttle);
            }
            Event::RouteChecked(done) => shell.pre_checked(&mut io, done),
            Event::Tick => shell.tick(&mut io).await,
        }
    }
}

fn respond(
    check: &Server<CheckRouteRequest, CheckRouteResponse>,
    id: RmwRequestId,
    reply: CheckRouteResponse,
    throttle: &mut LogThrottle,
) {
    if let Err(e) = check.send_response(id, reply) {
        warn_throttled!(
            throttle,
            "check-reply",
            "planner/check_route: cannot send the reply: {e:?}"
        );
    }
}

fn goal_end(cause: &EndCause) -> GoalEnd {
    match cause.kind() {
        EndKind::Succeeded => GoalEnd::Succeeded,
        EndKind::Canceled => GoalEnd::Canceled,
        EndKind::Aborted => GoalEnd::Aborted,
    }
}

/// FollowWaypoints' result for a route goal ending with `cause`: the waypoints missed so far
/// (the pre-check's problems for a route it refused; a VFO route: those not reached), the
/// request's poses.
fn follow_answer(task: &Task, cause: &EndCause) -> FollowWaypointsResult {
    match task {
        Task::Follow { goal, route } => follow_result(cause, &route.poses, goal.missed()),
        Task::Vfo(v) => vfo_follow_result(cause, &v.route.poses, &v.route.unreached_from(v.view.index)),
        Task::PreCheck { route, problems, .. } => follow_result(cause, &route.poses, problems),
        Task::Dock(_) | Task::Undock(_) => follow_result(cause, &[], &[]),
    }
}

/// Holds a law's body twist to the chassis limits, as a `cmd_vel`.
fn limited(chassis: &ChassisParams) -> impl Fn(BodyTwist) -> Twist + '_ {
    move |b| clamp_twist(b, chassis)
}

impl Shell {
    fn reconfigure(&mut self, c: PlannerConfig) {
        let scan = c.vfo.scan_config(c.robot_radius);
        if scan != self.config.vfo.scan_config(self.config.robot_radius) {
            if let Err(e) = ObstacleMap::new(scan) {
                return warn!("parameters not applied: {e}");
            }
            if self.session.active().is_some() {
                // The goal keeps the map its parameters built (its obstacles and σ stay valid).
                info!("vfo obstacle extraction changed: the obstacle map starts afresh once the goal ends");
                self.map_rebuild = true;
            } else {
                info!("vfo obstacle extraction changed: the obstacle map starts afresh");
                self.map_rebuild = false;
                if let Ok(map) = ObstacleMap::new(scan) {
                    self.map = map;
                }
            }
        }
        match c.chassis_params() {
            Ok(chassis) => {
                self.chassis = chassis;
                self.config = c;
                if self.session.active().is_some() {
                    info!("parameters changed: they apply from the next goal");
                }
            }
            Err(e) => warn!("parameters not applied: {e}"),
        }
    }

    fn fresh_odom(&self) -> Option<Pose2> {
        self.odom
            .get(self.config.timeouts.odom_timeout())
            .filter(|_| !self.odom_refused)
            .copied()
    }

    fn send_status(&mut self, node: &RosNode, out: &Outputs, view: &StatusView) {
        let msg = status_message(view, node.stamp(), &self.config.frames.odom_frame);
        if let Err(e) = out.status.publish(msg) {
            warn_throttled!(self.throttle, "status", "cannot publish planner/status: {e:?}");
        }
        self.last_status = Some(Instant::now());
    }

    fn send_idle_status(&mut self, node: &RosNode, out: &Outputs) {
        self.send_status(node, out, &self.status_view(None, NavStatus::IDLE, String::new()));
    }

    /// The status of `goal` (none: idle, or a refusal) in `state` with `reason`.
    fn status_view(&self, goal: Option<&Goal>, state: u8, reason: String) -> StatusView {
        let mut view = StatusView {
            state,
            mode: Mode::Idle,
            goal: None,
            distance_to_goal: f64::NAN,
            reason,
            waypoint_index: -1,
            docking: None,
            vfo: None,
        };
        let Some(g) = goal else { return view };
        view.mode = g.mode();
        view.waypoint_index = g.waypoint().map_or(-1, |i| i32::try_from(i).unwrap_or(i32::MAX));
        let at = |p: Option<Point2<f64>>| p.map(|p| Pose2::new(p.x, p.y, 0.0));
        match &g.task {
            Task::Dock(d) => {
                // Before the first step, the figures at the latest pose.
                let figures = d.figures(self.odom.value());
                view.goal = Some(d.target());
                view.distance_to_goal = figures.map_or(f64::NAN, |(p, _)| p.e);
                view.docking = Some(figures.map_or([f64::NAN; 4], |(p, v)| [p.e, p.alpha, p.theta, v]));
            }
            Task::Follow { goal, .. } => {
                view.goal = at(goal.target());
                view.distance_to_goal = goal.distance();
            }
            Task::Undock(u) => view.distance_to_goal = u.remaining(),
            Task::Vfo(v) => {
                view.goal = at(v.view.target);
                view.distance_to_goal = v.view.distance;
                view.vfo = Some(v.view.report);
            }
            Task::PreCheck { route, .. } => view.goal = at(route.points.first().copied()),
        }
        view
    }

    /// The active goal's status in `state` with `reason`.
    fn publish_status(&mut self, node: &RosNode, out: &Outputs, state: u8, reason: String) {
        let view = self.status_view(self.session.active().map(|a| &a.goal), state, reason);
        self.send_status(node, out, &view);
    }

    fn publish_markers(&mut self, node: &RosNode, out: &Outputs) {
        let view = MarkerView {
            route: &self.drawing.route,
            predicted: &self.drawing.predicted,
            problems: &self.drawing.problems,
            dock: self.drawing.dock,
            vfo: self.drawing.vfo.as_ref(),
            robot: self.odom.value().map(|p| p.position()),
        };
        let array = markers(&view, node.stamp(), &self.config.frames.odom_frame);
        if let Err(e) = out.markers.publish(array) {
            warn_throttled!(self.throttle, "markers", "cannot publish planner/markers: {e:?}");
        }
        self.last_markers = Some(Instant::now());
    }

    /// Ends the active goal with `outcome` (the session sends its zero command, if one is due)
    /// and reports it.
    fn end_goal(&mut self, io: &mut Io<'_, '_>, cause: EndCause) {
        if let Some(ended) = self.session.end(cause, io.sink) {
            self.report(io, ended, true);
        }
    }

    /// Tells an ended goal's end: the action's result (unless the server already ended it:
    /// a newer goal on the same action server took its place), the log, the status with the
    /// goal's last figures, the markers; a VFO optimisation under way stops.
    fn report(&mut self, io: &mut Io<'_, '_>, ended: PlannerEnded, finish_action: bool) {
        let Ended {
            goal, source, cause, ..
        } = ended;
        if let Task::Vfo(v) = &goal.task {
            v.stop.cancel();
        }
        if finish_action {
            let end = goal_end(&cause);
            match source {
                Source::DockAction => {
                    io.servers.dock.finish(end, dock_result(&cause));
                }
                Source::UndockAction => {
                    io.servers.undock.finish(end, undock_result(&cause));
                }
                Source::FollowAction => {
                    io.servers.follow.finish(end, follow_answer(&goal.task, &cause));
                }
                Source::DockPose | Source::Waypoints => {}
            }
        }
        let reason = cause.reason();
        match (cause.kind(), &cause) {
            (EndKind::Succeeded | EndKind::Canceled, _) | (_, EndCause::Preempted(_)) => {
                info!("goal ({}) ends: {reason}", source.name())
            }
            _ => warn!("goal ({}) ends: {reason}", source.name()),
        }
        let view = self.status_view(Some(&goal), end_state(&cause), reason);
        self.send_status(io.node, io.out, &view);
        if self.session.active().is_none() && std::mem::take(&mut self.map_rebuild) {
            match ObstacleMap::new(self.config.vfo.scan_config(self.config.robot_radius)) {
                Ok(map) => {
                    info!("the obstacle map starts afresh with the new extraction parameters");
                    self.map = map;
                }
                Err(e) => warn!("the obstacle map keeps its old parameters: {e}"),
            }
        }
        self.publish_markers(io.node, io.out);
    }

    /// Makes `task` from `source` the active goal: the goal it replaces ends PREEMPTED
    /// (reported; an action goal on the same server was ended by the server's accept).
    fn begin(&mut self, io: &mut Io<'_, '_>, task: Task, source: Source) -> GoalId {
        let goal = Goal {
            task,
            chassis: self.chassis,
            config: self.config.clone(),
        };
        let (id, old) = self.session.start(goal, source, Instant::now());
        if let Some(old) = old {
            let by_server = source.is_action() && old.source == source;
            self.report(io, old, !by_server);
        }
        id
    }

    /// A goal from `source` refused before it started: the goal it was to replace ends
    /// PREEMPTED (the robot stops with it); an action goal (accepted already) gets its result;
    /// the status is FAILED with the reason.
    fn refuse(&mut self, io: &mut Io<'_, '_>, source: Source, refusal: mobil_motion::Outcome) {
        if let Some(old) = self.session.end(EndCause::Preempted(source.name()), io.sink) {
            let by_server = source.is_action() && old.source == source;
            self.report(io, old, !by_server);
        }
        let cause = EndCause::Outcome(refusal);
        warn!("goal ({}) refused: {}", source.name(), cause.reason());
        match source {
            Source::DockAction => {
                io.servers.dock.finish(GoalEnd::Aborted, dock_result(&cause));
            }
            Source::UndockAction => {
                io.servers.undock.finish(GoalEnd::Aborted, undock_result(&cause));
            }
            Source::FollowAction => {
                io.servers
                    .follow
                    .finish(GoalEnd::Aborted, follow_result(&cause, &[], &[]));
            }
            Source::DockPose | Source::Waypoints => {}
        }
        let view = self.status_view(None, NavStatus::FAILED, cause.reason());
        self.send_status(io.node, io.out, &view);
    }

    /// Starts a docking onto `target` (or refuses it).
    fn start_dock(&mut self, io: &mut Io<'_, '_>, target: Result<Pose2, mobil_motion::Outcome>, source: Source) {
        let action = source.action();
        let built = target.and_then(|dock| {
            let gains = self.config.gains().map_err(|e| refused_goal(e, action))?;
            DockGoal::onto(dock, gains, self.config.docking, &self.chassis).map_err(|e| refused_goal(e, action))
        });
        let dock = match built {
            Ok(dock) => dock,
            Err(refusal) => return self.refuse(io, source, refusal),
        };
        let goal = dock.target();
        info!(
            "goal ({}): dock at ({:.3}, {:.3}, {:.3} rad) in {}",
            source.name(),
            goal.x,
            goal.y,
            goal.yaw,
            self.config.frames.odom_frame
        );
        if dock.controller().finish() == Finish::ReportResidual {
            info!(
                "a steered chassis cannot turn in place: the law steers its kinematic origin ({:.2} m behind), \
                 and the heading left at the dock is reported as RESIDUAL",
                dock.offset()
            );
        }
        self.begin(io, Task::Dock(dock), source);
        self.drawing = Drawing {
            dock: Some(goal),
            ..Drawing::default()
        };
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
        self.publish_markers(io.node, io.out);
    }

    /// Validates a route and starts its pre-check off the event loop (or refuses it).
    fn start_route(
        &mut self,
        io: &mut Io<'_, '_>,
        jobs: &mut Jobs,
        route: Result<Route, GoalError>,
        start: Option<Pose2>,
        source: Source,
    ) {
        let route = match route {
            Ok(r) => r,
            Err(e) => return self.refuse(io, source, invalid_goal(&e, source.action())),
        };
        if self.config.waypoint_method == WaypointMethod::Vfo {
            return self.start_vfo(io, route, start, source);
        }
        if let Some(i) = route.first_oriented() {
            info!(
                "goal ({}): waypoint {i} (and any other) carries an orientation: ignored, the goal approach \
                 reaches each waypoint's position only",
                source.name()
            );
        }
        let Some(start) = start else {
            return self.refuse(io, source, stale_at_start("odom", source.action()));
        };
        let (points, world, chassis, config) = (
            route.points.clone(),
            self.world.clone(),
            self.chassis,
            self.config.route_check(),
        );
        info!(
            "goal ({}): pre-check of {} waypoints (the virtual robot drives them first)",
            source.name(),
            route.points.len()
        );
        let problems = Vec::new();
        let id = self.begin(io, Task::PreCheck { route, start, problems }, source);
        // The robot waits for the pre-check.
        self.session.hold(io.sink);
        jobs.goal.start(move |cancel| PreCheckDone {
            id,
            report: check_route_until(&start, &points, &chassis, &world, &config, || cancel.is_cancelled())
                .map_err(|e| e.to_string()),
        });
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
    }

    /// Starts VFO waypoint following of `route` from `start` (or refuses it).
    fn start_vfo(&mut self, io: &mut Io<'_, '_>, route: Route, start: Option<Pose2>, source: Source) {
        let Some(start) = start else {
            return self.refuse(io, source, stale_at_start("odom", source.action()));
        };
        // Without a fresh scan the obstacles are unknown: the first tick would optimise the
        // segment through a map with nothing in it.
        if self.scan_seen.get(self.config.vfo.scan_timeout()).is_none() {
            return self.refuse(io, source, stale_at_start("scan", source.action()));
        }
        let settings = &self.config.vfo;
        let setup = settings.setup();
        let of_route = (&route.points[..], &route.headings()[..], &route.request_index[..]);
        let law = match VfoGoal::for_route(of_route, &start, &setup, &self.chassis, &self.map) {
            Ok(law) => law,
            Err(refusal) => return self.refuse(io, source, refusal),
        };
        let gains = vfo_gains(&setup.gains, &self.chassis);
        info!(
            "goal ({}): {} waypoints by VFO ({} obstacles known; U_2 {:.2} m/s, |ω| ≤ {:.2} rad/s, T_p {:.3} s)",
            source.name(),
            route.points.len(),
            law.follower().obstacles().len(),
            gains.speed,
            gains.omega_max,
            settings.optimise.time_step
        );
        if self.chassis.model().is_nonholonomic() {
            warn!(
                "goal ({}): the VFO law is a unicycle's: on this {} chassis the virtual robots turn no \
                 tighter than at U_2 over R_min, but slower commands are held to R_min too, so the robot may \
                 turn wider than they did (waypoint_method approach is this chassis' default)",
                source.name(),
                self.chassis.model().as_str()
            );
        }
        // A step's command later than the next odometry or two is dropped (the robot stops).
        let max_delay = late_bound(self.odom_period.period(), settings.optimise.time_step);
        self.drawing = Drawing {
            route: route.points.clone(),
            ..Drawing::default()
        };
        let task = VfoRun {
            view: law.view(),
            slot: LawSlot::new(law, max_delay),
            route,
            map_changed: None,
            stop: CancelToken::new(),
        };
        self.begin(io, Task::Vfo(task), source);
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
        self.publish_markers(io.node, io.out);
    }

    /// A pre-check is done: the route it was for (if still the active goal) starts or is
    /// refused.
    fn pre_checked(&mut self, io: &mut Io<'_, '_>, done: PreCheckDone) {
        let Some(active) = self.session.active_mut().filter(|a| a.id() == done.id) else {
            return;
        };
        let source = active.source;
        let (chassis, follow, execute) = (
            active.goal.chassis,
            active.goal.config.follow,
            active.goal.config.execute_infeasible_routes,
        );
        let Task::PreCheck { route, start, problems } = &mut active.goal.task else {
            return;
        };
        let report = match done.report {
            Ok(r) => r,
            Err(e) => return self.end_goal(io, refused_goal(e, Action::Follow).into()),
        };
        let of_route = (&route.points[..], &route.request_index[..]);
        let checked = after_pre_check(&report, of_route, start, (follow, &chassis), execute);
        let found = match &checked {
            PreChecked::Drive { problems, .. } | PreChecked::Refuse { problems, .. } => problems.clone(),
        };
        problems.clone_from(&found);
        let route = route.clone();
        self.drawing = Drawing {
            route: route.points.clone(),
            predicted: report.path.clone(),
            problems: found.clone(),
            dock: None,
            vfo: None,
        };
        let goal = match checked {
            PreChecked::Refuse { outcome, .. } => return self.end_goal(io, outcome.into()),
            PreChecked::Drive { goal, .. } => goal,
        };
        if !found.is_empty() {
            let reason = route_infeasible(&found).reason();
            warn!(
                "goal ({}): driven although execute_infeasible_routes: {reason}",
                source.name()
            );
        }
        info!(
            "goal ({}): {} waypoints, pre-check {} ({:.2} m predicted)",
            source.name(),
            route.points.len(),
            if found.is_empty() {
                "clear".to_owned()
            } else {
                format!("{} problem(s)", found.len())
            },
            report.driven_length(follow.check_length)
        );
        if let Some(active) = self.session.active_mut() {
            active.goal.task = Task::Follow { goal: *goal, route };
        }
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
        self.publish_markers(io.node, io.out);
    }

    async fn dock_action(&mut self, io: &mut Io<'_, '_>, request: GoalRequest<DockRobotGoal>) {
        let g = request.goal();
        let target = if g.use_dock_id {
            Err(no_dock_database())
        } else {
            goal_pose("dock pose", &g.dock_pose, &self.config.frames.odom_frame)
                .map_err(|e| invalid_goal(&e, Action::Dock))
        };
        if !g.use_dock_id {
            info!(
                "dock_robot: max_staging_time ({}) and navigate_to_staging_pose ({}) ignored: the Lyapunov law \
                 docks from wherever the robot is{}",
                g.max_staging_time,
                g.navigate_to_staging_pose,
                if g.dock_type.is_empty() {
                    String::new()
                } else {
                    format!("; dock_type `{}` ignored", g.dock_type)
                }
            );
        }
        let preempted = dock_result(&EndCause::Preempted("dock_robot"));
        let accept = io.servers.dock.accept(request, |_| preempted).await;
        if self.accepted(io, accept, Source::DockAction) {
            self.start_dock(io, target, Source::DockAction);
        }
    }

    /// Whether an action goal from `source` was accepted; if not, a goal of the same server that
    /// was running was ended by the server, and the robot stops with it.
    fn accepted(
        &mut self,
        io: &mut Io<'_, '_>,
        accept: Result<(), mobil_ros::action::ActionError>,
        source: Source,
    ) -> bool {
        let Err(e) = accept else { return true };
        warn_throttled!(self.throttle, "accept", "{} goal not started: {e}", source.name());
        let ours = self.session.active().is_some_and(|a| a.source == source);
        if let Some(ended) = ours
            .then(|| self.session.end(EndCause::Preempted(source.name()), io.sink))
            .flatten()
        {
            self.report(io, ended, false);
        }
        false
    }

    async fn undock_action(&mut self, io: &mut Io<'_, '_>, request: GoalRequest<UndockRobotGoal>) {
        let limit = request.goal().max_undocking_time;
        let limit_s = if limit.is_finite() && limit > 0.0 {
            f64::from(limit)
        } else {
            warn!("undock_robot: max_undocking_time {limit} is not a positive time: 30 s (its default) taken");
            30.0
        };
        let preempted = undock_result(&EndCause::Preempted("undock_robot"));
        let accept = io.servers.undock.accept(request, |_| preempted).await;
        if !self.accepted(io, accept, Source::UndockAction) {
            return;
        }
        let (distance, speed) = (self.config.staging_distance, self.config.undock_speed);
        info!("goal (undock_robot): back out {distance:.3} m along the heading, within {limit_s:.1} s");
        self.begin(
            io,
            Task::Undock(UndockGoal::new(distance, speed, limit_s)),
            Source::UndockAction,
        );
        self.drawing = Drawing::default();
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
    }

    async fn follow_action(&mut self, io: &mut Io<'_, '_>, jobs: &mut Jobs, request: GoalRequest<FollowWaypointsGoal>) {
        let start = self.fresh_odom();
        let g = request.goal();
        let frame = &self.config.frames.odom_frame;
        let (round, at) = ((g.goal_index, g.number_of_loops), start.map(|p| p.position()));
        let route = route_from_poses(&g.poses, frame, frame, round, at, ROUTE_LIMITS);
        // A follow_waypoints goal pre-empted by this one lists what it had missed.
        let by = EndCause::Preempted("follow_waypoints");
        let preempted = match self.session.active() {
            Some(a) if a.source == Source::FollowAction => follow_answer(&a.goal.task, &by),
            _ => follow_result(&by, &[], &[]),
        };
        let accept = io.servers.follow.accept(request, |_| preempted).await;
        if self.accepted(io, accept, Source::FollowAction) {
            self.start_route(io, jobs, route, start, Source::FollowAction);
        }
    }

    fn cancel(&mut self, io: &mut Io<'_, '_>, source: Source, is_active: bool) {
        if is_active && self.session.active().is_some_and(|a| a.source == source) {
            self.end_goal(io, EndCause::Canceled);
        }
    }

    /// A `planner/check_route` request: refused at once, answered BUSY when too many are being
    /// computed, or checked on the blocking pool and answered from there.
    fn check_in(
        &mut self,
        node: &RosNode,
        jobs: &mut Jobs,
        check: &Server<CheckRouteRequest, CheckRouteResponse>,
        id: RmwRequestId,
        req: &CheckRouteRequest,
    ) {
        let (start, route) = match self.check_request(req) {
            Err(reply) => return respond(check, id, reply, &mut self.throttle),
            Ok(_) if jobs.pending + 1 >= MAX_CHECKS => {
                let reply = refused_reply(format!(
                    "BUSY: {} route checks are already being computed; ask again",
                    jobs.pending
                ));
                return respond(check, id, reply, &mut self.throttle);
            }
            Ok(checked) => checked,
        };
        jobs.pending += 1;
        let tx = jobs.replies_tx.clone();
        let (world, chassis, config) = (self.world.clone(), self.chassis, self.config.route_check());
        let (stamp, frame, step) = (
            node.stamp(),
            self.config.frames.odom_frame.clone(),
            self.config.follow.check_length,
        );
        tokio::task::spawn_blocking(move || {
            let began = Instant::now();
            let reply = match check_route_until(&start, &route.points, &chassis, &world, &config, || false) {
                Ok(report) => check_reply(&report, &route, stamp, &frame, step),
                Err(e) => refused_reply(refused_goal(e, Action::Follow).reason()),
            };
            info!(
                "planner/check_route: {} waypoints, {} in {:.2} ms",
                route.points.len(),
                if reply.feasible {
                    "feasible".to_owned()
                } else {
                    format!("{} problem(s)", reply.problems.len())
                },
                began.elapsed().as_secs_f64() * 1e3
            );
            // The receiver lives as long as the loop; if it is gone nobody waits.
            let _ = tx.send((id, reply));
        });
    }

    /// The start and route of a `planner/check_route` request, or the reply refusing it.
    fn check_request(&self, req: &CheckRouteRequest) -> Result<(Pose2, Route), CheckRouteResponse> {
        let frame = &self.config.frames.odom_frame;
        let start = if req.use_start {
            pose_in_frame("start", frame, &req.start, frame)
                .map_err(|e| refused_reply(invalid_goal(&e, Action::Follow).reason()))?
        } else {
            self.fresh_odom().ok_or_else(|| {
                refused_reply(
                    "STALE_INPUT: no fresh odometry for the start (set use_start and start to check from a given pose)"
                        .to_owned(),
                )
            })?
        };
        let route = route_from_path(&req.route, frame, Some(start.position()), ROUTE_LIMITS)
            .map_err(|e| refused_reply(invalid_goal(&e, Action::Follow).reason()))?;
        Ok((start, route))
    }

    fn odom_in(&mut self, io: &mut Io<'_, '_>, jobs: &mut Jobs, m: &Odometry) {
        match odom_pose(m, &self.config.frames.odom_frame, &self.config.frames.base_frame) {
            Ok(pose) => {
                self.odom_refused = false;
                self.odom_stamp = secs_from_stamp(&m.header.stamp).unwrap_or(f64::NAN);
                if self.odom_stamp.is_finite() {
                    self.odom_history.push(self.odom_stamp, pose);
                }
                self.odom_period.arrived(Instant::now());
                self.odom.set(pose, m.header.stamp.clone());
                if self.session.active().is_some() {
                    self.step(io, jobs, pose);
                }
            }
            Err(e) => {
                warn_throttled!(self.throttle, "odom-bad", "odom sample dropped: {e}; robot stopped");
                self.odom_refused = true;
                self.odom_history.clear();
                self.session.hold(io.sink);
            }
        }
    }

    /// One control step at `pose`: the active goal's law, its command out through the session.
    fn step(&mut self, io: &mut Io<'_, '_>, jobs: &mut Jobs, pose: Pose2) {
        let dt = match self.session.advance(io.node.now_nanos()) {
            Some(Ok(dt)) => dt,
            None | Some(Err(DtError::Zero)) => return,
            Some(Err(e)) => {
                return warn_throttled!(
                    self.throttle,
                    "time-back",
                    "{e}; the step is skipped, the goal's time carries on"
                )
            }
        };
        let Some(active) = self.session.active_mut() else {
            return;
        };
        let input = StepInput::new(active.t(), dt, pose);
        let chassis = active.goal.chassis;
        match &mut active.goal.task {
            Task::PreCheck { .. } => {}
            Task::Vfo(_) => self.vfo_step(io, jobs, input),
            Task::Dock(d) => {
                let step = d.step(&input, &());
                self.apply(io, step, &chassis, |f| f.phase_changed);
            }
            Task::Follow { goal, .. } => {
                let step = goal.step(&input, &());
                self.apply(io, step, &chassis, |f| {
                    for event in &f.events {
                        match event {
                            RouteEvent::Reached(i) => info!("waypoint {i} reached"),
                            RouteEvent::Missed(m) => warn!("{} (missed; the next one is taken)", m.describe()),
                        }
                    }
                    !f.events.is_empty()
                });
            }
            Task::Undock(u) => {
                let step = u.step(&input, &());
                self.apply(io, step, &chassis, |_| false);
            }
        }
    }

    /// What comes of a law's step: its command held to the chassis limits, a refusal (the robot
    /// stops; the goal ends after the session's count of them in a row) or the goal's end. The
    /// status goes out when `changed` says the feedback changed it.
    fn apply<F, R>(
        &mut self,
        io: &mut Io<'_, '_>,
        step: Step<F, R>,
        chassis: &ChassisParams,
        changed: impl FnOnce(&F) -> bool,
    ) {
        if let Step::Refused(why) = &step {
            warn_throttled!(
                self.throttle,
                "step",
                "the planner refused its input: {why}; robot stopped"
            );
        }
        match self.session.apply(step, limited(chassis), io.sink) {
            Applied::Commanded(f) => {
                if changed(&f) {
                    self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
                }
            }
            Applied::Refused(Some(ended)) | Applied::Ended(ended, _) => self.report(io, ended, true),
            Applied::Refused(None) | Applied::Idle => {}
        }
    }

    /// A VFO step: the law goes to the blocking pool with the map's latest obstacles, or,
    /// while it is still out (optimising), the robot stops.
    fn vfo_step(&mut self, io: &mut Io<'_, '_>, jobs: &mut Jobs, input: StepInput) {
        let Some(active) = self.session.active_mut() else {
            return;
        };
        let id = active.id();
        let budget = active.goal.config.vfo.optimise_budget();
        let Task::Vfo(v) = &mut active.goal.task else { return };
        let Some(mut law) = v.slot.lend(Instant::now()) else {
            return self.session.hold(io.sink);
        };
        if let Some(new) = v.map_changed.take() {
            law.follow_map(&self.map, new);
        }
        let (stop, stamp) = (v.stop.clone(), self.odom_stamp);
        jobs.vfo.start(move |cancel| {
            let (cancel, started) = (cancel.clone(), Instant::now());
            let interrupt = move || {
                if cancel.is_cancelled() || stop.is_cancelled() {
                    Some(Interrupt::Cancel)
                } else if started.elapsed() > budget {
                    Some(Interrupt::Budget)
                } else {
                    None
                }
            };
            let tick = VfoTick {
                stamp,
                interrupt: Box::new(interrupt),
            };
            let step = law.step(&input, &tick);
            VfoTickDone { id, law, step }
        });
    }

    /// A VFO step came back: its events are logged, its command goes out (zero when it came
    /// back late), or the route ends.
    fn vfo_ticked(&mut self, io: &mut Io<'_, '_>, done: VfoTickDone) {
        if !self.session.is_current(done.id) {
            return;
        }
        let Some(active) = self.session.active_mut() else {
            return;
        };
        let chassis = active.goal.chassis;
        let Task::Vfo(v) = &mut active.goal.task else { return };
        v.view = done.law.view();
        let handback = v.slot.give_back(done.law, Instant::now());
        let Some(law) = v.slot.law() else { return };
        let mut step = done.step;
        if let Step::Command { twist, feedback } = &mut step {
            for event in &feedback.events {
                info!("{}", law.describe(event));
                if let VfoEvent::Optimised { warnings, .. } = event {
                    for w in warnings.iter().filter(|w| !matches!(w, OptimiseWarning::NoSafeSigma)) {
                        warn_throttled!(self.throttle, "vfo-caps", "segment optimisation: {w:?}");
                    }
                }
            }
            if feedback.settling {
                warn_throttled!(
                    self.throttle,
                    "vfo-settle",
                    "robot held at zero inside an influence zone until it stands (at most {MAX_SETTLE_S} s), then \
                     the segment to waypoint {} is optimised from there",
                    v.view.waypoint
                );
            }
            if let Some(drawing) = feedback.drawing.take() {
                self.drawing.vfo = Some(drawing);
            }
            if handback == Handback::Late {
                warn_throttled!(
                    self.throttle,
                    "vfo-late",
                    "a tick took longer than {:.0} ms (an optimisation): its command is dropped, the robot stops \
                     meanwhile",
                    v.slot.max_delay().as_secs_f64() * 1e3
                );
                *twist = BodyTwist::new(0.0, 0.0, 0.0);
            }
        }
        self.apply(io, step, &chassis, |f| !f.events.is_empty());
    }

    /// A scan: its obstacles go into the map (in odom, with the odometry pose at the scan's
    /// stamp); a VFO route's follower gets them at its next tick. A goal's scans are read with
    /// the parameters it began with.
    fn scan_in(&mut self, m: &LaserScan) {
        let config = match self.session.active() {
            Some(a) if matches!(a.goal.task, Task::Vfo(_)) => &a.goal.config,
            _ if self.config.waypoint_method == WaypointMethod::Vfo => &self.config,
            _ => return,
        };
        let (max_gap, scan_range) = (config.vfo.scan_odom_max_gap_s, config.vfo.scan_range);
        let checked = scan_laser_pose(
            &self.laser,
            &config.frames.base_frame,
            &m.header.frame_id,
            &config.vfo.laser_frame,
            config.vfo.laser_pose(),
        )
        .map_err(|e| e.to_string())
        .and_then(|(base_from_laser, _)| {
            // (f32::min would take scan_range in place of a NaN range_max.)
            if !m.range_max.is_finite() {
                return Err(format!("scan refused: range_max {} is not finite", m.range_max));
            }
            // Echoes beyond scan_range are no obstacles: the limit becomes the scan's range_max.
            let mut limited = m.clone();
            limited.range_max = limited.range_max.min(scan_range as f32);
            scan_from_msg(&limited, base_from_laser).map_err(|e| e.to_string())
        });
        let scan = match checked {
            Ok(s) => s,
            Err(e) => {
                return warn_throttled!(self.throttle, "scan-bad", "{e}; scan ignored");
            }
        };
        let Some(stamp) = secs_from_stamp(&m.header.stamp) else {
            return warn_throttled!(
                self.throttle,
                "scan-bad",
                "scan stamp invalid (nanosec ≥ 1e9); scan ignored"
            );
        };
        let history = self.fresh_odom().map(|_| &self.odom_history);
        let update = match self.map.add_scan(&scan, stamp, history, max_gap) {
            Ok(u) => u,
            Err(e @ ScanSkipped::NoPose { .. }) => return warn_throttled!(self.throttle, "scan-odom", "{e}"),
            Err(e) => return warn_throttled!(self.throttle, "scan-bad", "{e}; scan ignored"),
        };
        if !update.cleared.is_empty() {
            warn_throttled!(
                self.throttle,
                "map-reset",
                "scan at {stamp:.3} s is older than obstacles already seen (clock reset?): the {} obstacles forgotten",
                update.cleared.len()
            );
        }
        if !update.capped.is_empty() {
            warn_throttled!(
                self.throttle,
                "map-cap",
                "obstacle map full (vfo.max_obstacles {}): the {} least recently seen dropped",
                self.map.config().max_obstacles,
                update.capped.len()
            );
        }
        if self.scan_seen.value().is_none() {
            info!(
                "first scan: {} beams, {} obstacles in the map (odom)",
                scan.len(),
                self.map.len()
            );
        }
        self.scan_seen.set((), m.header.stamp.clone());
        if let Some(Task::Vfo(v)) = self.session.active_mut().map(|a| &mut a.goal.task) {
            let new = !update.new.is_empty() || v.map_changed.unwrap_or(false);
            v.map_changed = Some(new);
        }
    }

    async fn tick(&mut self, io: &mut Io<'_, '_>) {
        let Some(active) = self.session.active() else { return };
        let now = Instant::now();
        let mut inputs = vec![Watched {
            name: "odom",
            age: self.odom.age_at(now),
            timeout: active.goal.config.timeouts.odom_timeout(),
        }];
        if matches!(active.goal.task, Task::Vfo(_)) {
            inputs.push(Watched {
                name: "scan",
                age: self.scan_seen.age_at(now),
                timeout: active.goal.config.vfo.scan_timeout(),
            });
        }
        if let Some(stale) = self.session.stale(now, &inputs) {
            return self.end_goal(io, EndCause::Stale(stale));
        }
        let status_period = Duration::from_secs_f64(1.0 / self.config.status_rate_hz);
        if self
            .last_status
            .is_none_or(|t| now.saturating_duration_since(t) >= status_period)
        {
            self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
        }
        let markers_period = Duration::from_secs_f64(1.0 / self.config.markers_rate_hz);
        if self
            .last_markers
            .is_none_or(|t| now.saturating_duration_since(t) >= markers_period)
        {
            self.publish_markers(io.node, io.out);
        }
        self.feedback(io.servers).await;
    }

    /// Action feedback, on every watchdog tick (20 Hz) while an action goal is active.
    async fn feedback(&mut self, servers: &Servers) {
        let Some(active) = self.session.active() else { return };
        let sent = match (&active.goal.task, active.source) {
            // The goal's own time: its steps' dt summed, never running backwards (a step whose
            // clock went back is skipped), so docking_time never falls on a clock reset.
            (Task::Dock(_), Source::DockAction) => {
                servers
                    .dock
                    .feedback(DockRobotFeedback {
                        state: DockRobotFeedback::CONTROLLING,
                        docking_time: duration_msg(active.t()),
                        num_retries: 0,
                    })
                    .await
            }
            (_, Source::FollowAction) => {
                let index = active.goal.waypoint().unwrap_or(0);
                servers
                    .follow
                    .feedback(FollowWaypointsFeedback {
                        current_waypoint: u32::try_from(index).unwrap_or(u32::MAX),
                    })
                    .await
            }
            (Task::Undock(_), Source::UndockAction) => {
                servers
                    .undock
                    .feedback(UndockRobotFeedback {
                        structure_needs_at_least_one_member: 0,
                    })
                    .await
            }
            _ => Ok(()),
        };
        if let Err(e) = sent {
            warn_throttled!(self.throttle, "feedback", "{e}");
        }
    }
}
