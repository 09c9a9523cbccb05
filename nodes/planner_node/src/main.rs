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

use mobil_chassis::{BodyTwist, ChassisParams};
use mobil_geom::Pose2;
use mobil_msgs::geometry_msgs::msg::{PoseStamped, Twist};
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::mobil_msgs::srv::{CheckRoute, CheckRouteRequest, CheckRouteResponse};
use mobil_msgs::nav2_msgs::action::{
    DockRobot, DockRobotFeedback, DockRobotGoal, FollowWaypoints, FollowWaypointsFeedback, FollowWaypointsGoal,
    UndockRobot, UndockRobotFeedback, UndockRobotGoal,
};
use mobil_msgs::nav_msgs::msg::{Odometry, Path};
use mobil_msgs::sensor_msgs::msg::LaserScan;
use mobil_msgs::tf2_msgs::msg::TFMessage;
use mobil_msgs::visualization_msgs::msg::MarkerArray;
use mobil_planner::vfo::{
    Interrupt, ObstacleMap, OptimiseWarning, PoseHistory, VfoEnd, VfoEvent, VfoFollower, VfoOutput, MAX_BUDGET_RETRIES,
    MAX_SETTLE_S,
};
use mobil_planner::{
    check_route_until, polar_error, DockingController, DockingOutput, DockingPhase, Finish, FollowEnd, FollowEvent,
    PlannerError, ProblemKind, RouteReport, VelocityLimits, WaypointFollower,
};
use mobil_planner_node::vfo::{
    segment_report, vfo_command, vfo_drawing, vfo_gains, vfo_max_delay, vfo_waypoints, ArrivalPeriod, Handback,
    SegmentReport, VfoDrawing, VfoSlot, WaypointMethod,
};
use mobil_planner_node::{
    backed_out, check_reply, clamp_twist, dock_goal, docking_offset, docking_outcome, load_world, markers,
    missed_from_report, odom_stale, pose_in_odom, refused_reply, route_from_path, route_from_poses, status_message,
    GoalError, MarkerView, Missed, Mode, Outcome, PlannerConfig, Route, StatusView,
};
use mobil_ros::action::{ActionEvent, GoalEnd, GoalRequest, GoalServer, GoalServerConfig};
use mobil_ros::geometry::odom_pose;
use mobil_ros::input::Inputs;
use mobil_ros::latest::Latest;
use mobil_ros::offloop::CancelToken;
use mobil_ros::scan::scan_laser_pose;
use mobil_ros::scan::{scan_from_msg, tf_static_subscription, StaticFrames};
use mobil_ros::stop::CommandGate;
use mobil_ros::stop::{final_stop, FINAL_STOP_WAIT};
use mobil_ros::ticker::Ticker;
use mobil_ros::time::duration_msg;
use mobil_ros::time::{secs_from_stamp, DtClock, DtError};
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
/// The follower's `dt` on a goal's first step, before ROS time has ticked twice (it sets only
/// the step's length, not its direction or speed).
const FIRST_DT: f64 = 0.02;
/// The follower's longest `dt` (s): a tick after a gap in odometry (five 50 Hz periods) steps
/// no further than this, so one step stays a short one of the approach.
const MAX_FOLLOW_DT: f64 = 0.1;
/// After this many refused steps in a row the goal ends.
const MAX_REFUSED_STEPS: u32 = 20;
/// A route shorter than this (m), start included, is refused as zero-length.
const MIN_ROUTE_LENGTH: f64 = 1e-3;
/// Undocking succeeds within this of the staging distance (m).
const UNDOCK_TOLERANCE: f64 = 0.005;
/// The slowest reversing speed near the staging distance (m/s).
const UNDOCK_MIN_SPEED: f64 = 0.03;

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

impl Source {
    fn name(self) -> &'static str {
        match self {
            Source::DockPose => "dock_pose",
            Source::Waypoints => "waypoints",
            Source::DockAction => "dock_robot",
            Source::UndockAction => "undock_robot",
            Source::FollowAction => "follow_waypoints",
        }
    }
}

/// What the active goal does.
#[allow(clippy::large_enum_variant)]
enum Task {
    /// A route waiting for its pre-check (off the event loop); no command meanwhile.
    PreCheck { route: Route, start: Pose2, seq: u64 },
    Dock {
        controller: DockingController,
        last: Option<DockingOutput>,
        /// The steered point's offset behind the reference point ([`docking_offset`]).
        offset: f64,
    },
    Follow {
        follower: WaypointFollower,
        route: Route,
        missed: Vec<Missed>,
        distance: f64,
    },
    Undock {
        start: Option<Pose2>,
        distance: f64,
        limit_s: f64,
        backed: f64,
    },
    /// VFO waypoint following: the follower at home or out on a tick ([`VfoSlot`]).
    Vfo {
        slot: VfoSlot,
        route: Route,
        /// The goal's number: a tick's result for another goal is dropped.
        seq: u64,
        /// The steered point's offset behind the reference point ([`docking_offset`]).
        offset: f64,
        /// The waypoint pursued (route index) and ‖e*‖ to it.
        index: usize,
        distance: f64,
        report: SegmentReport,
        /// The obstacle map changed since the follower last saw it (`Some(true)`: with new
        /// obstacles, which re-optimise the segment).
        obstacles_changed: Option<bool>,
        /// The map's ids of the obstacles the follower holds, by its index: its σ follow them
        /// over removals from the map.
        ids: Vec<u64>,
        /// Cancelled when the goal ends: a tick's optimisation under way stops at once.
        stop: CancelToken,
    },
}

struct Active {
    task: Task,
    source: Source,
    /// The chassis and parameters when the goal began: a parameter change applies from the
    /// next goal, so the limits the controller scales by stay those the commands are held to.
    chassis: ChassisParams,
    config: PlannerConfig,
    started: Instant,
    clock: DtClock,
    t: f64,
    refused: u32,
    /// Whether this goal has sent a command (its end then sends the zero one).
    commanded: bool,
}

impl Active {
    fn mode(&self) -> Mode {
        match &self.task {
            Task::Dock { last, .. } => match last.map(|o| o.phase) {
                Some(DockingPhase::Rotate) => Mode::Rotate,
                _ => Mode::Dock,
            },
            Task::PreCheck { .. } => Mode::PreCheck,
            Task::Follow { .. } => Mode::Approach,
            Task::Undock { .. } => Mode::Undock,
            Task::Vfo { .. } => Mode::Vfo,
        }
    }
}

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

/// A route pre-check done off the event loop, for the goal numbered `seq`.
struct PreCheckDone {
    seq: u64,
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

/// One VFO tick done on the blocking pool: the follower back, its output, and when the tick
/// optimised, what the status and markers show of it.
struct VfoTickDone {
    seq: u64,
    follower: Box<VfoFollower>,
    output: Result<VfoOutput, PlannerError>,
    optimised: Option<(SegmentReport, VfoDrawing)>,
}

/// The pre-checks off the event loop: the goal's (a newer goal stops the older one's) and
/// the service's (each request answered, in any order); the VFO ticks.
struct Jobs {
    goal: OffLoop<PreCheckDone>,
    vfo: OffLoop<VfoTickDone>,
    seq: u64,
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
    active: Option<Active>,
    odom: Latest<Pose2>,
    odom_refused: bool,
    last_status: Option<Instant>,
    last_markers: Option<Instant>,
    drawing: Drawing,
    gate: CommandGate,
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
    PreChecked(PreCheckDone),
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
        result_timeout: config.result_timeout(),
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
        config.odom_frame
    );
    let mut shell = Shell {
        config,
        chassis,
        world: Arc::new(world),
        active: None,
        odom: Latest::new(),
        odom_refused: false,
        last_status: None,
        last_markers: None,
        drawing: Drawing::default(),
        gate: CommandGate::default(),
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
        seq: 0,
        replies_tx,
        replies,
        pending: 0,
    };
    let outcome = event_loop(
        node,
        out,
        &mut shell,
        &mut servers,
        &mut jobs,
        (&odom_sub, &dock_sub, &route_sub),
        (&scan_sub, &tf_sub),
        &check,
    )
    .await;
    jobs.vfo.cancel();
    // A goal under way (a pre-check included: a command may be in flight from a goal it
    // pre-empted) ends, and its zero command, waited for, goes out before anything that may
    // take time; then the three servers close at once (each waits up to 2 s for its results).
    jobs.goal.cancel();
    if shell.active.is_some() {
        shell.end_goal_without_zero(node, out, &mut servers, Outcome::ShuttingDown);
        final_stop(&out.cmd, Twist::default(), FINAL_STOP_WAIT).await;
    }
    let down = Outcome::ShuttingDown;
    let Servers { dock, undock, follow } = servers;
    tokio::join!(
        dock.close(down.dock_result()),
        undock.close(down.undock_result()),
        follow.close(down.follow_result(&[], &[])),
    );
    Ok(outcome)
}

#[allow(clippy::too_many_arguments)]
async fn event_loop(
    node: &mut RosNode,
    out: &Outputs,
    shell: &mut Shell,
    servers: &mut Servers,
    jobs: &mut Jobs,
    (odom_sub, dock_sub, route_sub): (
        &ros2_client::Subscription<Odometry>,
        &ros2_client::Subscription<PoseStamped>,
        &ros2_client::Subscription<Path>,
    ),
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
            done = jobs.goal.result() => Event::PreChecked(done),
            done = jobs.vfo.result() => Event::VfoTicked(done),
            Some((id, reply)) = jobs.replies.recv() => Event::Checked(id, reply),
            e = servers.dock.next_event() => Event::Dock(e),
            e = servers.undock.next_event() => Event::Undock(e),
            e = servers.follow.next_event() => Event::Follow(e),
            _ = ticker.tick() => Event::Tick,
        };
        match event {
            Event::Shutdown => return Ok(()),
            Event::Config(Ok(c)) => shell.reconfigure(c),
            Event::Config(Err(e)) => warn!("parameters not applied: {e}"),
            Event::Odom(m) => shell.odom_in(node, out, servers, jobs, &m),
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
            Event::VfoTicked(done) => shell.vfo_ticked(node, out, servers, done),
            Event::DockPose(m) => {
                let target = dock_goal(&m, &shell.config.odom_frame);
                shell.new_goal(node, out, servers, Source::DockPose).await;
                shell.start_dock(node, out, servers, target, Source::DockPose);
            }
            Event::Waypoints(m) => {
                shell.new_goal(node, out, servers, Source::Waypoints).await;
                let start = shell.fresh_odom();
                let route = route_from_path(
                    &m,
                    &shell.config.odom_frame,
                    start.map(|p| p.position()),
                    MIN_ROUTE_LENGTH,
                );
                shell.start_route(node, out, servers, jobs, route, start, Source::Waypoints);
            }
            Event::Dock(ActionEvent::Goal(request)) => shell.dock_action(node, out, servers, request).await,
            Event::Undock(ActionEvent::Goal(request)) => shell.undock_action(node, out, servers, request).await,
            Event::Follow(ActionEvent::Goal(request)) => shell.follow_action(node, out, servers, jobs, request).await,
            Event::Dock(ActionEvent::CancelRequested(id)) => {
                let is_active = servers.dock.active_id() == Some(id);
                shell.cancel(node, out, servers, Source::DockAction, is_active)
            }
            Event::Undock(ActionEvent::CancelRequested(id)) => {
                let is_active = servers.undock.active_id() == Some(id);
                shell.cancel(node, out, servers, Source::UndockAction, is_active)
            }
            Event::Follow(ActionEvent::CancelRequested(id)) => {
                let is_active = servers.follow.active_id() == Some(id);
                shell.cancel(node, out, servers, Source::FollowAction, is_active)
            }
            Event::Check(id, req) => match shell.check_request(&req) {
                Err(reply) => respond(check, id, reply, &mut shell.throttle),
                Ok(_) if jobs.pending + 1 >= MAX_CHECKS => {
                    let reply = refused_reply(format!(
                        "BUSY: {} route checks are already being computed; ask again",
                        jobs.pending
                    ));
                    respond(check, id, reply, &mut shell.throttle)
                }
                Ok((start, route)) => {
                    jobs.pending += 1;
                    let tx = jobs.replies_tx.clone();
                    let (world, chassis, config) = (shell.world.clone(), shell.chassis, shell.config.route_check());
                    let (stamp, frame, step) = (
                        node.stamp(),
                        shell.config.odom_frame.clone(),
                        shell.config.follow.check_length,
                    );
                    tokio::task::spawn_blocking(move || {
                        let began = Instant::now();
                        let reply = match check_route_until(&start, &route.points, &chassis, &world, &config, || false)
                        {
                            Ok(report) => check_reply(&report, &route, stamp, &frame, step),
                            Err(e) => refused_reply(Outcome::Refused(e.to_string()).reason()),
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
            },
            Event::Checked(id, reply) => {
                jobs.pending = jobs.pending.saturating_sub(1);
                respond(check, id, reply, &mut shell.throttle);
            }
            Event::PreChecked(done) => shell.pre_checked(node, out, servers, done),
            Event::Tick => shell.tick(node, out, servers).await,
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

fn goal_end(outcome: &Outcome) -> GoalEnd {
    if outcome.succeeded() {
        GoalEnd::Succeeded
    } else if *outcome == Outcome::Canceled {
        GoalEnd::Canceled
    } else {
        GoalEnd::Aborted
    }
}

impl Shell {
    fn reconfigure(&mut self, c: PlannerConfig) {
        let scan = c.vfo.scan_config(c.robot_radius);
        if scan != self.config.vfo.scan_config(self.config.robot_radius) {
            if let Err(e) = ObstacleMap::new(scan) {
                return warn!("parameters not applied: {e}");
            }
            if self.active.is_some() {
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
                if self.active.is_some() {
                    info!("parameters changed: they apply from the next goal");
                }
            }
            Err(e) => warn!("parameters not applied: {e}"),
        }
    }

    fn fresh_odom(&self) -> Option<Pose2> {
        self.odom
            .get(self.config.odom_timeout())
            .filter(|_| !self.odom_refused)
            .copied()
    }

    fn publish_cmd(&mut self, out: &Outputs, twist: Twist) {
        if let Some(a) = self.active.as_mut() {
            a.commanded = true;
        }
        self.gate.sent(&twist);
        if let Err(e) = out.cmd.publish(twist) {
            warn_throttled!(self.throttle, "cmd", "cannot publish cmd_vel: {e:?}");
        }
    }

    fn zero(&mut self, out: &Outputs) {
        self.publish_cmd(out, Twist::default());
    }

    /// A refused input while a goal runs: one zero command if the robot was moving.
    fn refused(&mut self, out: &Outputs) {
        if self.active.is_some() && self.gate.refused() {
            self.zero(out);
        }
    }

    fn send_status(&mut self, node: &RosNode, out: &Outputs, view: &StatusView) {
        let msg = status_message(view, node.stamp(), &self.config.odom_frame);
        if let Err(e) = out.status.publish(msg) {
            warn_throttled!(self.throttle, "status", "cannot publish planner/status: {e:?}");
        }
        self.last_status = Some(Instant::now());
    }

    fn send_idle_status(&mut self, node: &RosNode, out: &Outputs) {
        let view = StatusView {
            state: NavStatus::IDLE,
            mode: Mode::Idle,
            goal: None,
            distance_to_goal: f64::NAN,
            reason: String::new(),
            waypoint_index: -1,
            docking: None,
            vfo: None,
        };
        self.send_status(node, out, &view);
    }

    /// The status of the active goal in `state` with `reason`.
    fn status_view(&self, state: u8, reason: String) -> StatusView {
        let Some(active) = &self.active else {
            return StatusView {
                state,
                mode: Mode::Idle,
                goal: None,
                distance_to_goal: f64::NAN,
                reason,
                waypoint_index: -1,
                docking: None,
                vfo: None,
            };
        };
        let (goal, distance, index, docking) = match &active.task {
            Task::Dock {
                controller,
                last,
                offset,
            } => {
                // Before the first step, the figures at the latest pose.
                let figures = last.map(|o| (o.polar, o.lyapunov)).or_else(|| {
                    self.odom.value().map(|p| {
                        let polar = polar_error(&p.ahead(-*offset), &controller.goal());
                        (polar, controller.gains().lyapunov(&polar))
                    })
                });
                (
                    Some(controller.goal().ahead(*offset)),
                    figures.map_or(f64::NAN, |(p, _)| p.e),
                    -1,
                    Some(figures.map_or([f64::NAN; 4], |(p, v)| [p.e, p.alpha, p.theta, v])),
                )
            }
            Task::Follow {
                follower,
                route,
                distance,
                ..
            } => {
                let i = follower.index().min(route.points.len().saturating_sub(1));
                let index = route.request_index.get(i).copied().unwrap_or(0);
                (
                    route.points.get(i).map(|p| Pose2::new(p.x, p.y, 0.0)),
                    *distance,
                    i32::try_from(index).unwrap_or(i32::MAX),
                    None,
                )
            }
            Task::Undock { distance, backed, .. } => (None, distance - backed, -1, None),
            Task::Vfo {
                route, index, distance, ..
            } => {
                let i = (*index).min(route.points.len().saturating_sub(1));
                let request = route.request_index.get(i).copied().unwrap_or(0);
                (
                    route.points.get(i).map(|p| Pose2::new(p.x, p.y, 0.0)),
                    *distance,
                    i32::try_from(request).unwrap_or(i32::MAX),
                    None,
                )
            }
            Task::PreCheck { route, .. } => (
                route.points.first().map(|p| Pose2::new(p.x, p.y, 0.0)),
                f64::NAN,
                route
                    .request_index
                    .first()
                    .map_or(-1, |&i| i32::try_from(i).unwrap_or(i32::MAX)),
                None,
            ),
        };
        let vfo = match &active.task {
            Task::Vfo { report, .. } => Some(*report),
            _ => None,
        };
        StatusView {
            state,
            mode: active.mode(),
            goal,
            distance_to_goal: distance,
            reason,
            waypoint_index: index,
            docking,
            vfo,
        }
    }

    fn publish_status(&mut self, node: &RosNode, out: &Outputs, state: u8, reason: String) {
        let view = self.status_view(state, reason);
        self.send_status(node, out, &view);
    }

    /// A refused goal's status: FAILED with the reason, no goal.
    fn publish_refusal(&mut self, node: &RosNode, out: &Outputs, outcome: &Outcome) {
        let view = StatusView {
            state: NavStatus::FAILED,
            mode: Mode::Idle,
            goal: None,
            distance_to_goal: f64::NAN,
            reason: outcome.reason(),
            waypoint_index: -1,
            docking: None,
            vfo: None,
        };
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
        let array = markers(&view, node.stamp(), &self.config.odom_frame);
        if let Err(e) = out.markers.publish(array) {
            warn_throttled!(self.throttle, "markers", "cannot publish planner/markers: {e:?}");
        }
        self.last_markers = Some(Instant::now());
    }

    /// Ends the active goal: one zero command (if it commanded the robot at all), the status
    /// with the reason, the action's result.
    fn end_goal(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers, outcome: Outcome) {
        if self.active.as_ref().is_some_and(|a| a.commanded) {
            self.zero(out);
        }
        self.end_goal_without_zero(node, out, servers, outcome);
    }

    /// [`Shell::end_goal`] but for the zero command, which the caller sends.
    fn end_goal_without_zero(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers, outcome: Outcome) {
        let Some(active) = self.active.as_ref() else { return };
        if let Task::Vfo { stop, .. } = &active.task {
            stop.cancel();
        }
        let source = active.source;
        let end = goal_end(&outcome);
        match (source, &active.task) {
            (Source::DockAction, _) => {
                servers.dock.finish(end, outcome.dock_result());
            }
            (Source::UndockAction, _) => {
                servers.undock.finish(end, outcome.undock_result());
            }
            (Source::FollowAction, Task::Follow { route, missed, .. }) => {
                servers.follow.finish(end, outcome.follow_result(&route.poses, missed));
            }
            (Source::FollowAction, Task::Vfo { route, index, .. }) => {
                servers.follow.finish(
                    end,
                    outcome.vfo_follow_result(&route.poses, &route.unreached_from(*index)),
                );
            }
            (Source::FollowAction, Task::PreCheck { route, .. }) => {
                servers.follow.finish(end, outcome.follow_result(&route.poses, &[]));
            }
            (Source::FollowAction, _) => {
                servers.follow.finish(end, outcome.follow_result(&[], &[]));
            }
            _ => {}
        }
        match outcome {
            Outcome::Docked { .. }
            | Outcome::RouteDone { .. }
            | Outcome::Undocked { .. }
            | Outcome::Canceled
            | Outcome::Preempted(_) => info!("goal ({}) ends: {}", source.name(), outcome.reason()),
            _ => warn!("goal ({}) ends: {}", source.name(), outcome.reason()),
        }
        self.publish_status(node, out, outcome.state(), outcome.reason());
        self.active = None;
        if std::mem::take(&mut self.map_rebuild) {
            match ObstacleMap::new(self.config.vfo.scan_config(self.config.robot_radius)) {
                Ok(map) => {
                    info!("the obstacle map starts afresh with the new extraction parameters");
                    self.map = map;
                }
                Err(e) => warn!("the obstacle map keeps its old parameters: {e}"),
            }
        }
        self.publish_markers(node, out);
    }

    /// Before a new goal from `source` starts (or is refused): the running goal ends PREEMPTED
    /// with its zero command. An action goal on the same server is ended by the server's accept
    /// (with the result built there); here only its status and command.
    async fn new_goal(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers, source: Source) {
        let Some(active) = &self.active else { return };
        let outcome = Outcome::Preempted(source.name());
        if active.source == source && matches!(source, Source::DockAction | Source::UndockAction | Source::FollowAction)
        {
            let old = active.source;
            // The old goal's optimisation under way stops too (its result would be dropped).
            if let Task::Vfo { stop, .. } = &active.task {
                stop.cancel();
            }
            if active.commanded {
                self.zero(out);
            }
            info!("goal ({}) ends: {}", old.name(), outcome.reason());
            self.publish_status(node, out, NavStatus::FAILED, outcome.reason());
            self.active = None;
        } else {
            self.end_goal(node, out, servers, outcome);
        }
    }

    fn activate(&mut self, task: Task, source: Source) {
        self.gate = CommandGate::default();
        self.active = Some(Active {
            task,
            source,
            chassis: self.chassis,
            config: self.config.clone(),
            started: Instant::now(),
            clock: DtClock::new(),
            t: 0.0,
            refused: 0,
            commanded: false,
        });
    }

    /// Starts a docking onto `target` (or refuses it: status, and for an action its result).
    fn start_dock(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        servers: &mut Servers,
        target: Result<Pose2, GoalError>,
        source: Source,
    ) {
        let offset = docking_offset(&self.chassis);
        let built = target.map_err(Outcome::Invalid).and_then(|goal| {
            let gains = self.config.gains().map_err(|e| Outcome::Refused(e.to_string()))?;
            DockingController::new(
                gains,
                self.config.docking,
                VelocityLimits::from_chassis(&self.chassis),
                Finish::for_chassis(&self.chassis),
                goal.ahead(-offset),
            )
            .map_err(|e| Outcome::Refused(e.to_string()))
        });
        match built {
            Ok(controller) => {
                let goal = controller.goal().ahead(offset);
                info!(
                    "goal ({}): dock at ({:.3}, {:.3}, {:.3} rad) in {}",
                    source.name(),
                    goal.x,
                    goal.y,
                    goal.yaw,
                    self.config.odom_frame
                );
                if Finish::for_chassis(&self.chassis) == Finish::ReportResidual {
                    info!(
                        "a steered chassis cannot turn in place: the law steers its kinematic origin ({offset:.2} m \
                         behind), and the heading left at the dock is reported as RESIDUAL"
                    );
                }
                self.drawing = Drawing {
                    dock: Some(goal),
                    ..Drawing::default()
                };
                self.activate(
                    Task::Dock {
                        controller,
                        last: None,
                        offset,
                    },
                    source,
                );
                self.publish_status(node, out, NavStatus::ACTIVE, String::new());
                self.publish_markers(node, out);
            }
            Err(outcome) => self.refuse(node, out, servers, source, outcome),
        }
    }

    /// A goal refused before it started: for an action (accepted already) its result; the
    /// status FAILED with the reason.
    fn refuse(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers, source: Source, outcome: Outcome) {
        warn!("goal ({}) refused: {}", source.name(), outcome.reason());
        match source {
            Source::DockAction => {
                servers.dock.finish(GoalEnd::Aborted, outcome.dock_result());
            }
            Source::UndockAction => {
                servers.undock.finish(GoalEnd::Aborted, outcome.undock_result());
            }
            Source::FollowAction => {
                let poses = match &outcome {
                    Outcome::RouteInfeasible(_) => servers.follow.active_goal().map(|g| g.poses.clone()),
                    _ => None,
                };
                servers.follow.finish(
                    GoalEnd::Aborted,
                    outcome.follow_result(poses.as_deref().unwrap_or(&[]), &[]),
                );
            }
            _ => {}
        }
        self.publish_refusal(node, out, &outcome);
    }

    /// Validates a route and starts its pre-check off the event loop (or refuses it).
    #[allow(clippy::too_many_arguments)]
    fn start_route(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        servers: &mut Servers,
        jobs: &mut Jobs,
        route: Result<Route, GoalError>,
        start: Option<Pose2>,
        source: Source,
    ) {
        let route = match route {
            Ok(r) => r,
            Err(e) => return self.refuse(node, out, servers, source, Outcome::Invalid(e)),
        };
        if self.config.waypoint_method == WaypointMethod::Vfo {
            jobs.seq += 1;
            return self.start_vfo(node, out, servers, route, start, source, jobs.seq);
        }
        if let Some(i) = route.first_oriented() {
            info!(
                "goal ({}): waypoint {i} (and any other) carries an orientation: ignored, the goal approach \
                 reaches each waypoint's position only",
                source.name()
            );
        }
        let Some(start) = start else {
            return self.refuse(node, out, servers, source, Outcome::Stale);
        };
        jobs.seq += 1;
        let seq = jobs.seq;
        let (points, world, chassis, config) = (
            route.points.clone(),
            self.world.clone(),
            self.chassis,
            self.config.route_check(),
        );
        jobs.goal.start(move |cancel| PreCheckDone {
            seq,
            report: check_route_until(&start, &points, &chassis, &world, &config, || cancel.is_cancelled())
                .map_err(|e| e.to_string()),
        });
        info!(
            "goal ({}): pre-check of {} waypoints (the virtual robot drives them first)",
            source.name(),
            route.points.len()
        );
        self.activate(Task::PreCheck { route, start, seq }, source);
        self.publish_status(node, out, NavStatus::ACTIVE, String::new());
    }

    /// Starts VFO waypoint following of `route` from `start` (or refuses it).
    #[allow(clippy::too_many_arguments)]
    fn start_vfo(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        servers: &mut Servers,
        route: Route,
        start: Option<Pose2>,
        source: Source,
        seq: u64,
    ) {
        let Some(start) = start else {
            return self.refuse(node, out, servers, source, Outcome::Stale);
        };
        // Without a fresh scan the obstacles are unknown: the first tick would optimise the
        // segment through a map with nothing in it.
        if self.scan_seen.get(self.config.vfo.scan_timeout()).is_none() {
            return self.refuse(node, out, servers, source, Outcome::ScanStale);
        }
        let offset = docking_offset(&self.chassis);
        let settings = &self.config.vfo;
        let gains = vfo_gains(&settings.gains, &self.chassis);
        let built = vfo_waypoints(&route, &start.ahead(-offset), settings.guiding)
            .map_err(Outcome::Invalid)
            .and_then(|waypoints| {
                VfoFollower::new(gains, settings.optimise, waypoints, self.map.obstacles())
                    .map_err(|e| Outcome::Refused(e.to_string()))
            });
        let follower = match built {
            Ok(f) => f,
            Err(outcome) => return self.refuse(node, out, servers, source, outcome),
        };
        info!(
            "goal ({}): {} waypoints by VFO ({} obstacles known; U_2 {:.2} m/s, |ω| ≤ {:.2} rad/s, T_p {:.3} s)",
            source.name(),
            route.points.len(),
            follower.obstacles().len(),
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
        // A tick's command later than the next odometry or two is dropped (the robot stops).
        let max_delay = vfo_max_delay(self.odom_period.period(), settings.optimise.time_step);
        // Progress is the follower's: from the point the law steers (the guide point).
        let distance = (route.points[0] - start.ahead(-offset).position()).norm();
        self.drawing = Drawing {
            route: route.points.clone(),
            ..Drawing::default()
        };
        self.activate(
            Task::Vfo {
                slot: VfoSlot::new(follower, max_delay),
                route,
                seq,
                offset,
                index: 0,
                distance,
                report: SegmentReport::default(),
                obstacles_changed: None,
                ids: self.map.ids(),
                stop: CancelToken::new(),
            },
            source,
        );
        self.publish_status(node, out, NavStatus::ACTIVE, String::new());
        self.publish_markers(node, out);
    }

    /// A pre-check is done: the route it was for (if still the active goal) starts or is
    /// refused.
    fn pre_checked(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers, done: PreCheckDone) {
        let Some(Active {
            task: Task::PreCheck { seq, .. },
            source,
            ..
        }) = self.active.as_ref()
        else {
            return;
        };
        if *seq != done.seq {
            return;
        }
        let source = *source;
        let Some(Active {
            task: Task::PreCheck { route, start, .. },
            chassis,
            config,
            ..
        }) = self.active.as_ref()
        else {
            return;
        };
        let (route, start, chassis, follow, execute_infeasible) = (
            route.clone(),
            *start,
            *chassis,
            config.follow,
            config.execute_infeasible_routes,
        );
        let report = match done.report {
            Ok(r) => r,
            Err(e) => return self.end_goal(node, out, servers, Outcome::Refused(e)),
        };
        let problems = missed_from_report(&report.problems, &route);
        self.drawing = Drawing {
            route: route.points.clone(),
            predicted: report.path.clone(),
            problems: problems.clone(),
            dock: None,
            vfo: None,
        };
        if !problems.is_empty() {
            let outcome = Outcome::RouteInfeasible(problems.clone());
            if !execute_infeasible {
                return self.end_goal(node, out, servers, outcome);
            }
            warn!(
                "goal ({}): driven although execute_infeasible_routes: {}",
                source.name(),
                outcome.reason()
            );
        }
        let follower = match WaypointFollower::new(follow, &chassis, route.points.clone()) {
            Ok(f) => f,
            Err(e) => return self.end_goal(node, out, servers, Outcome::Refused(e.to_string())),
        };
        info!(
            "goal ({}): {} waypoints, pre-check {} ({:.2} m predicted)",
            source.name(),
            route.points.len(),
            if problems.is_empty() {
                "clear".to_owned()
            } else {
                format!("{} problem(s)", problems.len())
            },
            mobil_planner_node::path_length(&report.path, follow.check_length)
        );
        let distance = (route.points[0] - start.position()).norm();
        if let Some(active) = self.active.as_mut() {
            active.task = Task::Follow {
                follower,
                route,
                missed: Vec::new(),
                distance,
            };
        }
        self.publish_status(node, out, NavStatus::ACTIVE, String::new());
        self.publish_markers(node, out);
    }

    async fn dock_action(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        servers: &mut Servers,
        request: GoalRequest<DockRobotGoal>,
    ) {
        let g = request.goal();
        let target = if g.use_dock_id {
            Err(GoalError::NoDockDatabase)
        } else {
            dock_goal(&g.dock_pose, &self.config.odom_frame)
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
        self.new_goal(node, out, servers, Source::DockAction).await;
        let preempted = Outcome::Preempted("dock_robot").dock_result();
        if let Err(e) = servers.dock.accept(request, |_| preempted).await {
            warn_throttled!(self.throttle, "accept", "dock_robot goal not started: {e}");
            return;
        }
        self.start_dock(node, out, servers, target, Source::DockAction);
    }

    async fn undock_action(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        servers: &mut Servers,
        request: GoalRequest<UndockRobotGoal>,
    ) {
        let limit = request.goal().max_undocking_time;
        let limit_s = if limit.is_finite() && limit > 0.0 {
            f64::from(limit)
        } else {
            warn!("undock_robot: max_undocking_time {limit} is not a positive time: 30 s (its default) taken");
            30.0
        };
        self.new_goal(node, out, servers, Source::UndockAction).await;
        let preempted = Outcome::Preempted("undock_robot").undock_result();
        if let Err(e) = servers.undock.accept(request, |_| preempted).await {
            warn_throttled!(self.throttle, "accept", "undock_robot goal not started: {e}");
            return;
        }
        let distance = self.config.staging_distance;
        info!("goal (undock_robot): back out {distance:.3} m along the heading, within {limit_s:.1} s");
        self.drawing = Drawing::default();
        self.activate(
            Task::Undock {
                start: None,
                distance,
                limit_s,
                backed: 0.0,
            },
            Source::UndockAction,
        );
        self.publish_status(node, out, NavStatus::ACTIVE, String::new());
    }

    async fn follow_action(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        servers: &mut Servers,
        jobs: &mut Jobs,
        request: GoalRequest<FollowWaypointsGoal>,
    ) {
        let start = self.fresh_odom();
        let g = request.goal();
        let route = route_from_poses(
            &g.poses,
            &self.config.odom_frame,
            &self.config.odom_frame,
            g.goal_index,
            g.number_of_loops,
            start.map(|p| p.position()),
            MIN_ROUTE_LENGTH,
        );
        // A follow_waypoints goal pre-empted by this one lists what it had missed.
        let preempted = match &self.active {
            Some(Active {
                task: Task::Follow { route, missed, .. },
                source: Source::FollowAction,
                ..
            }) => Outcome::Preempted("follow_waypoints").follow_result(&route.poses, missed),
            Some(Active {
                task: Task::Vfo { route, index, .. },
                source: Source::FollowAction,
                ..
            }) => Outcome::Preempted("follow_waypoints").vfo_follow_result(&route.poses, &route.unreached_from(*index)),
            _ => Outcome::Preempted("follow_waypoints").follow_result(&[], &[]),
        };
        self.new_goal(node, out, servers, Source::FollowAction).await;
        if let Err(e) = servers.follow.accept(request, |_| preempted).await {
            warn_throttled!(self.throttle, "accept", "follow_waypoints goal not started: {e}");
            return;
        }
        self.start_route(node, out, servers, jobs, route, start, Source::FollowAction);
    }

    fn cancel(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers, source: Source, is_active: bool) {
        if is_active && self.active.as_ref().is_some_and(|a| a.source == source) {
            self.end_goal(node, out, servers, Outcome::Canceled);
        }
    }

    /// A `planner/check_route` request: the start and route to check, or the reply refusing it
    /// (at once, never hanging).
    fn check_request(&self, req: &CheckRouteRequest) -> Result<(Pose2, Route), CheckRouteResponse> {
        let frame = &self.config.odom_frame;
        let start = if req.use_start {
            pose_in_odom("start", frame, &req.start, frame).map_err(|e| refused_reply(Outcome::Invalid(e).reason()))?
        } else {
            self.fresh_odom().ok_or_else(|| {
                refused_reply(
                    "STALE_INPUT: no fresh odometry for the start (set use_start and start to check from a given pose)"
                        .to_owned(),
                )
            })?
        };
        let route = route_from_path(&req.route, frame, Some(start.position()), MIN_ROUTE_LENGTH)
            .map_err(|e| refused_reply(Outcome::Invalid(e).reason()))?;
        Ok((start, route))
    }

    fn odom_in(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers, jobs: &mut Jobs, m: &Odometry) {
        match odom_pose(m, &self.config.odom_frame, &self.config.base_frame) {
            Ok(pose) => {
                self.odom_refused = false;
                self.odom_stamp = secs_from_stamp(&m.header.stamp).unwrap_or(f64::NAN);
                if self.odom_stamp.is_finite() {
                    self.odom_history.push(self.odom_stamp, pose);
                }
                self.odom_period.arrived(Instant::now());
                self.odom.set(pose, m.header.stamp.clone());
                if self.active.is_some() {
                    self.step(node, out, servers, jobs, pose);
                }
            }
            Err(e) => {
                warn_throttled!(self.throttle, "odom-bad", "odom sample dropped: {e}; robot stopped");
                self.odom_refused = true;
                self.odom_history.clear();
                self.refused(out);
            }
        }
    }

    /// One control step at `pose`.
    fn step(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers, jobs: &mut Jobs, pose: Pose2) {
        let now = node.now_nanos();
        let Some(active) = self.active.as_mut() else { return };
        let dt = match active.clock.step(now) {
            Ok(dt) => dt,
            Err(DtError::Zero) => return,
            Err(e @ DtError::Backwards { .. }) => {
                warn_throttled!(
                    self.throttle,
                    "time-back",
                    "{e}; the step is skipped, the goal's time carries on"
                );
                return;
            }
        };
        active.t += dt.unwrap_or(0.0);
        let t = active.t;
        let chassis = active.chassis;
        let undock_speed = active.config.undock_speed;
        let finish = Finish::for_chassis(&chassis);
        if matches!(active.task, Task::Vfo { .. }) {
            return self.vfo_step(out, jobs, pose, t);
        }
        let mut ended: Option<Outcome> = None;
        let mut changed = false;
        let command: Result<BodyTwist, String> = match &mut active.task {
            Task::PreCheck { .. } => return,
            // Handled above.
            Task::Vfo { .. } => return,
            Task::Dock {
                controller,
                last,
                offset,
            } => match controller.update(&pose.ahead(-*offset), t) {
                Ok(o) => {
                    changed = last.is_none_or(|l| l.phase != o.phase);
                    *last = Some(o);
                    match o.phase {
                        DockingPhase::Docked => {
                            ended = Some(Outcome::Docked {
                                e: o.polar.e,
                                heading: o.heading_error,
                            })
                        }
                        DockingPhase::Failed(f) => {
                            let residual = o.residual.unwrap_or(mobil_planner::Residual {
                                e: o.polar.e,
                                heading: o.heading_error,
                            });
                            ended = Some(docking_outcome(f, residual, finish));
                        }
                        _ => {}
                    }
                    Ok(o.command.to_twist())
                }
                Err(e) => Err(e.to_string()),
            },
            Task::Follow {
                follower,
                route,
                missed,
                distance,
            } => match follower.update(&pose, dt.unwrap_or(FIRST_DT).min(MAX_FOLLOW_DT), t) {
                Ok(o) => {
                    for event in &o.events {
                        changed = true;
                        match *event {
                            FollowEvent::Reached { index } => {
                                let i = route.request_index.get(index).copied().unwrap_or(index);
                                info!("waypoint {i} reached");
                            }
                            FollowEvent::Missed { index, cause } => {
                                let m = Missed {
                                    index: route.request_index.get(index).copied().unwrap_or(index),
                                    position: route.points.get(index).copied().unwrap_or_else(Point2::origin),
                                    kind: ProblemKind::Unreachable(cause),
                                    pre_check: false,
                                };
                                warn!("{} (missed; the next one is taken)", m.describe());
                                missed.push(m);
                            }
                        }
                    }
                    *distance = o.distance;
                    match o.end {
                        Some(FollowEnd::Done) => {
                            ended = Some(Outcome::RouteDone {
                                count: route.points.len(),
                                missed: missed.clone(),
                            })
                        }
                        Some(FollowEnd::Stalled) => ended = Some(Outcome::Stalled { index: o.index }),
                        None => {}
                    }
                    Ok(o.twist)
                }
                Err(e) => Err(e.to_string()),
            },
            Task::Undock {
                start,
                distance,
                limit_s,
                backed,
            } => {
                let origin = *start.get_or_insert(pose);
                *backed = backed_out(&origin, &pose);
                let remaining = *distance - *backed;
                if remaining <= UNDOCK_TOLERANCE {
                    ended = Some(Outcome::Undocked { distance: *backed });
                } else if t > *limit_s {
                    ended = Some(Outcome::UndockTimeout {
                        limit: *limit_s,
                        distance: *backed,
                    });
                }
                let speed = undock_speed.min(remaining.max(UNDOCK_MIN_SPEED));
                Ok(BodyTwist::new(-speed, 0.0, 0.0))
            }
        };
        if let Some(outcome) = ended {
            return self.end_goal(node, out, servers, outcome);
        }
        match command {
            Ok(twist) => {
                active.refused = 0;
                let cmd = clamp_twist(twist, &chassis);
                self.publish_cmd(out, cmd);
                if changed {
                    self.publish_status(node, out, NavStatus::ACTIVE, String::new());
                }
            }
            Err(e) => self.refused_step(node, out, servers, e),
        }
    }

    /// A step whose input the planner refused: the robot stops, and after
    /// [`MAX_REFUSED_STEPS`] in a row the goal ends refused.
    fn refused_step(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers, e: String) {
        let Some(active) = self.active.as_mut() else { return };
        active.refused += 1;
        let refused = active.refused;
        warn_throttled!(
            self.throttle,
            "step",
            "the planner refused its input: {e}; robot stopped"
        );
        if refused >= MAX_REFUSED_STEPS {
            self.end_goal(node, out, servers, Outcome::Refused(e));
        } else {
            self.refused(out);
        }
    }

    /// A VFO tick at `pose`, time `t`: the follower goes to the blocking pool with the map's
    /// latest obstacles, or, while it is still out (optimising), the robot stops.
    fn vfo_step(&mut self, out: &Outputs, jobs: &mut Jobs, pose: Pose2, t: f64) {
        let Some(Active {
            task:
                Task::Vfo {
                    slot,
                    seq,
                    offset,
                    obstacles_changed,
                    ids,
                    stop,
                    ..
                },
            config,
            ..
        }) = self.active.as_mut()
        else {
            return;
        };
        let Some(mut follower) = slot.lend(Instant::now()) else {
            return self.zero(out);
        };
        if let Some(new) = obstacles_changed.take() {
            follower.follow_map(&self.map, ids, new);
        }
        let (seq, guide, stop, stamp) = (*seq, pose.ahead(-*offset), stop.clone(), self.odom_stamp);
        let budget = config.vfo.optimise_budget();
        jobs.vfo.start(move |cancel| {
            let started = Instant::now();
            let interrupt = || {
                if cancel.is_cancelled() || stop.is_cancelled() {
                    Some(Interrupt::Cancel)
                } else if started.elapsed() > budget {
                    Some(Interrupt::Budget)
                } else {
                    None
                }
            };
            let output = follower.update_stamped(&guide, t, stamp, &interrupt);
            let optimised = output
                .as_ref()
                .is_ok_and(|o| o.events.iter().any(|e| matches!(e, VfoEvent::Optimised { .. })))
                .then(|| follower.last_optimisation())
                .flatten()
                .map(|o| (segment_report(o), vfo_drawing(o, follower.obstacles())));
            VfoTickDone {
                seq,
                follower,
                output,
                optimised,
            }
        });
    }

    /// A VFO tick came back: its command goes out (zero when it came back late), its events
    /// are logged, the route may end.
    fn vfo_ticked(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers, done: VfoTickDone) {
        let Some(active) = self.active.as_mut() else { return };
        let chassis = active.chassis;
        let Task::Vfo {
            slot,
            route,
            seq,
            index,
            distance,
            report,
            offset,
            ..
        } = &mut active.task
        else {
            return;
        };
        if *seq != done.seq {
            return;
        }
        let handback = slot.give_back(done.follower, Instant::now());
        if let Some((r, drawing)) = done.optimised {
            *report = r;
            self.drawing.vfo = Some(drawing);
        }
        let o = match done.output {
            Ok(o) => o,
            Err(e) => return self.refused_step(node, out, servers, e.to_string()),
        };
        active.refused = 0;
        let request = |i: usize| route.request_index.get(i).copied().unwrap_or(i);
        let mut changed = false;
        for event in &o.events {
            changed = true;
            match event {
                VfoEvent::Reached { index, vortex } => info!(
                    "waypoint {} reached{}",
                    request(*index),
                    if *vortex {
                        " (early: the robot was caught between obstacles, Algorithm 3)"
                    } else {
                        ""
                    }
                ),
                VfoEvent::Optimised {
                    index,
                    reason,
                    score,
                    warnings,
                } => {
                    info!(
                        "segment to waypoint {} optimised ({reason:?}): Ψ_z {}, {} virtual robots, {} candidates",
                        request(*index),
                        score.map_or("none".to_owned(), |s| format!("{s:.3}")),
                        report.virtual_robots,
                        report.candidates
                    );
                    for w in warnings.iter().filter(|w| !matches!(w, OptimiseWarning::NoSafeSigma)) {
                        warn_throttled!(self.throttle, "vfo-caps", "segment optimisation: {w:?}");
                    }
                }
            }
        }
        if o.end.is_none() && slot.follower().is_some_and(|f| f.is_settling()) {
            warn_throttled!(
                self.throttle,
                "vfo-settle",
                "robot held at zero inside an influence zone until it stands (at most {MAX_SETTLE_S} s), then the \
                 segment to waypoint {} is optimised from there",
                request(o.index)
            );
        }
        *index = o.index;
        *distance = o.distance;
        let unreached = |from: usize| route.unreached_from(from);
        let ended = match o.end {
            None => None,
            Some(VfoEnd::Done) => Some(Outcome::RouteDone {
                count: route.points.len(),
                missed: Vec::new(),
            }),
            Some(VfoEnd::NoSafePath { index }) => Some(Outcome::NoSafePath {
                index: request(index),
                virtual_robots: report.virtual_robots,
                unreached: unreached(index),
            }),
            Some(VfoEnd::BudgetExhausted { index }) => Some(Outcome::OptimisationBudget {
                index: request(index),
                tries: MAX_BUDGET_RETRIES,
                unreached: unreached(index),
            }),
            Some(VfoEnd::Collision { obstacle }) => {
                let o = slot.follower().and_then(|f| f.obstacles().get(obstacle).copied());
                // The guide point's distance, as the follower measured the collision.
                let at = self.odom.value().map(|p| p.ahead(-*offset).position());
                Some(Outcome::Collision {
                    centre: o.map_or_else(Point2::origin, |o| o.centre()),
                    radius: o.map_or(f64::NAN, |o| o.forbidden_radius()),
                    distance: match (o, at) {
                        (Some(o), Some(at)) => o.distance(&at),
                        _ => f64::NAN,
                    },
                    unreached: unreached(*index),
                })
            }
        };
        if let Some(outcome) = ended {
            return self.end_goal(node, out, servers, outcome);
        }
        if handback == Handback::Late {
            warn_throttled!(
                self.throttle,
                "vfo-late",
                "a tick took longer than {:.0} ms (an optimisation): its command is dropped, the robot stops \
                 meanwhile",
                slot.max_delay().as_secs_f64() * 1e3
            );
        }
        let cmd = clamp_twist(vfo_command(&o, handback), &chassis);
        self.publish_cmd(out, cmd);
        if changed {
            self.publish_status(node, out, NavStatus::ACTIVE, String::new());
        }
    }

    /// A scan: its obstacles go into the map (in odom, with the odometry pose at the scan's
    /// stamp); a VFO route's follower gets them at its next tick. A goal's scans are read with
    /// the parameters it began with.
    fn scan_in(&mut self, m: &LaserScan) {
        let config = match &self.active {
            Some(a) if matches!(a.task, Task::Vfo { .. }) => &a.config,
            _ if self.config.waypoint_method == WaypointMethod::Vfo => &self.config,
            _ => return,
        };
        let (max_gap, scan_range) = (config.vfo.scan_odom_max_gap_s, config.vfo.scan_range);
        let checked = scan_laser_pose(
            &self.laser,
            &config.base_frame,
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
        let placed = self
            .fresh_odom()
            .and_then(|_| self.odom_history.placed_at(stamp, max_gap));
        let Some((odom_from_base, placement)) = placed else {
            return warn_throttled!(
                self.throttle,
                "scan-odom",
                "scan at {stamp:.3} s ignored: no fresh odometry within {max_gap} s of its stamp (obstacles are \
                 placed by the pose at the scan's time)"
            );
        };
        let update = match self.map.update_placed(&scan, &odom_from_base, placement, stamp) {
            Ok(u) => u,
            Err(e) => return warn_throttled!(self.throttle, "scan-bad", "scan refused: {e}; scan ignored"),
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
        if let Some(Active {
            task: Task::Vfo { obstacles_changed, .. },
            ..
        }) = self.active.as_mut()
        {
            let new = !update.new.is_empty() || obstacles_changed.unwrap_or(false);
            *obstacles_changed = Some(new);
        }
    }

    async fn tick(&mut self, node: &RosNode, out: &Outputs, servers: &mut Servers) {
        let Some(active) = &self.active else { return };
        let now = Instant::now();
        let goal_age = now.saturating_duration_since(active.started);
        if odom_stale(self.odom.age_at(now), goal_age, active.config.odom_timeout()) {
            return self.end_goal(node, out, servers, Outcome::Stale);
        }
        if matches!(active.task, Task::Vfo { .. })
            && odom_stale(self.scan_seen.age_at(now), goal_age, active.config.vfo.scan_timeout())
        {
            return self.end_goal(node, out, servers, Outcome::ScanStale);
        }
        let status_period = Duration::from_secs_f64(1.0 / self.config.status_rate_hz);
        if self
            .last_status
            .is_none_or(|t| now.saturating_duration_since(t) >= status_period)
        {
            self.publish_status(node, out, NavStatus::ACTIVE, String::new());
        }
        let markers_period = Duration::from_secs_f64(1.0 / self.config.markers_rate_hz);
        if self
            .last_markers
            .is_none_or(|t| now.saturating_duration_since(t) >= markers_period)
        {
            self.publish_markers(node, out);
        }
        self.feedback(servers).await;
    }

    /// Action feedback, on every watchdog tick (20 Hz) while an action goal is active.
    async fn feedback(&mut self, servers: &Servers) {
        let Some(active) = &self.active else { return };
        // The goal's own time: ROS time summed step by step, never running backwards (a step
        // whose clock went back is skipped), so docking_time never falls on a clock reset.
        let elapsed = active.t;
        let sent = match (&active.task, active.source) {
            (Task::Dock { .. }, Source::DockAction) => {
                servers
                    .dock
                    .feedback(DockRobotFeedback {
                        state: DockRobotFeedback::CONTROLLING,
                        docking_time: duration_msg(elapsed),
                        num_retries: 0,
                    })
                    .await
            }
            (Task::Follow { follower, route, .. }, Source::FollowAction) => {
                let i = follower.index().min(route.points.len().saturating_sub(1));
                let index = route.request_index.get(i).copied().unwrap_or(0);
                servers
                    .follow
                    .feedback(FollowWaypointsFeedback {
                        current_waypoint: u32::try_from(index).unwrap_or(u32::MAX),
                    })
                    .await
            }
            (Task::Vfo { route, index, .. }, Source::FollowAction) => {
                let i = (*index).min(route.points.len().saturating_sub(1));
                let index = route.request_index.get(i).copied().unwrap_or(0);
                servers
                    .follow
                    .feedback(FollowWaypointsFeedback {
                        current_waypoint: u32::try_from(index).unwrap_or(u32::MAX),
                    })
                    .await
            }
            (Task::PreCheck { route, .. }, Source::FollowAction) => {
                let index = route.request_index.first().copied().unwrap_or(0);
                servers
                    .follow
                    .feedback(FollowWaypointsFeedback {
                        current_waypoint: u32::try_from(index).unwrap_or(u32::MAX),
                    })
                    .await
            }
            (Task::Undock { .. }, Source::UndockAction) => {
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
