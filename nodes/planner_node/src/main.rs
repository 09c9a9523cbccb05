//! `planner_node`: MOBIL-II's HIGH-LEVEL, the shell of [`mobil_planner`]. Lyapunov docking onto
//! a pose (`dock_pose`, Nav2's `dock_robot`), backing out of a dock (`undock_robot`), and
//! waypoint following (`waypoints`, Nav2's `follow_waypoints`) by the goal approach, each route
//! first driven by a virtual robot against the known map (the pre-check, also served as
//! `planner/check_route`), or with `waypoint_method: vfo` by VFO round the obstacles the LIDAR
//! sees (`scan`), each segment's left/right decisions optimised by virtual robots
//! ([`mobil_planner_node::vfo`]: the ticks run off the event loop and the robot stops while a
//! segment is optimised). Nav2's controller role, `follow_path`, follows a path by either law
//! (`shell/path.rs`). Every source feeds one session: a new goal from any of them pre-empts the
//! running one.
//!
//! **One step per odometry message**: each valid `odom` (50 Hz from chassis_node) is one
//! control step and one `cmd_vel`; the law's time and `dt` are ROS time (simulated under
//! `use_sim_time`). A 20 Hz watchdog tick on the steady clock ends a goal whose odometry went
//! stale and sends the action feedback; the status follows at `status_rate_hz` (and on every
//! change), the markers at `markers_rate_hz`.
//!
//! Every goal runs through the motion server ([`MotionSession`]): one goal at a time, its time
//! step, refusals, pre-emption and the zero command follow its rules (`cmd_vel` goes out only
//! while a goal is active; one zero `cmd_vel` when a goal that moved the robot ends, however it
//! ends, none between a goal and the newer one that replaces it and commands at its next step;
//! a goal that must wait, a route's pre-check or a VFO segment's optimisation, stops the robot
//! meanwhile). Every command is held to the chassis limits as chassis_node holds them
//! ([`clamp_at_reference`]). A refused odometry message or step stops the robot. At shutdown with a
//! goal that moved the robot, its zero command is the last one, waited for ([`mobil_ros::stop::final_stop`]);
//! an idle node sends none.

// The shell's modules (`shell::*`) take every name from here (`use crate::*`).
use mobil_chassis::{clamp_at_reference, ChassisParams};
use mobil_geom::path::PathGoals;
use mobil_geom::Pose2;
use mobil_motion::slot::ArrivalPeriod;
use mobil_motion::{BodyTwist, GoalLaw, Step, StepInput};
use mobil_msgs::geometry_msgs::msg::{PoseStamped, Twist};
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::mobil_msgs::srv::{CheckRoute, CheckRouteRequest, CheckRouteResponse};
use mobil_msgs::nav2_msgs::action::{
    DockRobot, DockRobotFeedback, DockRobotGoal, FollowPath, FollowPathGoal, FollowWaypoints, FollowWaypointsFeedback,
    FollowWaypointsGoal, FollowWaypointsResult, UndockRobot, UndockRobotFeedback, UndockRobotGoal,
};
use mobil_msgs::nav_msgs::msg::{Odometry, Path};
use mobil_msgs::sensor_msgs::msg::LaserScan;
use mobil_msgs::tf2_msgs::msg::TFMessage;
use mobil_planner::docks::DockDatabase;
use mobil_planner::goals::{DockGoal, RouteEvent, UndockGoal};
use mobil_planner::task::{dock_request_notice, status_view, PreCheck, Source, Stepped, Task, VfoRun};
use mobil_planner::vfo::{Interrupt, KeptMap, PoseHistory, ScanSkipped, VfoGoal, VfoStep, VfoTick, WaypointMethod};
use mobil_planner::view::Drawing;
use mobil_planner::{check_route_until, Finish, RouteReport};
use mobil_planner_node::{
    check_reply, follow_result, load_world, markers, refused_reply, Action, GoalError, PlannerConfig, Route,
    RouteAnswer, MAX_REPLY_POSES, ROUTE_LIMITS,
};
use mobil_ros::action::{goal_end, nav2_result, ActionEvent, GoalRequest, GoalServer, GoalServerConfig};
use mobil_ros::diagnostics::MotionDiagnostics;
use mobil_ros::geometry::{odom_pose, twist_msg};
use mobil_ros::goal::{goal_pose, pose_in_frame, route_from_path, route_from_poses};
use mobil_ros::input::Inputs;
use mobil_ros::latest::Latest;
use mobil_ros::lifecycle::{CallbackReturn, Lifecycle, Transition};
use mobil_ros::motion::{
    Applied, ClockCheck, CmdVel, EndCause, EndKind, Ended, GoalId, MotionSession, Outputs, SessionSettings, Watched,
};
use mobil_ros::offloop::CancelToken;
use mobil_ros::plan::PlanOut;
use mobil_ros::scan::{checked_scan, tf_static_subscription, LaserMount, StaticFrames};
use mobil_ros::status::{end_state, NavStatusView, RateGate};
use mobil_ros::stop::FINAL_STOP_WAIT;
use mobil_ros::tf::GoalTf;
use mobil_ros::ticker::Ticker;
use mobil_ros::time::{duration_msg, secs_from_stamp, DtError};
use mobil_ros::OffLoop;
use mobil_ros::{qos, run_node, shutdown_signal, warn_throttled, ConfigError, LogThrottle, NodeDecl, RosNode};
use mobil_world::World;
use ros2_client::{RmwRequestId, Server, Subscription};
use shell::check::{CheckInputs, CheckService, CheckView, SharedTf};
use std::process::ExitCode;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tracing::{info, warn};

/// The route-check service.
const CHECK_ROUTE: &str = "planner/check_route";

/// The watchdog tick (steady clock): stale odometry is noticed within 50 ms of its timeout.
const WATCHDOG_RATE_HZ: f64 = 20.0;

fn decl() -> NodeDecl {
    NodeDecl::for_config::<PlannerConfig>(
        "planner",
        "HIGH-LEVEL planner: Lyapunov docking (dock_pose, dock_robot), undocking (undock_robot), waypoint \
         following by the goal approach after a route pre-check or by VFO round the obstacles in scan \
         (waypoint_method; waypoints, follow_waypoints, planner/check_route); cmd_vel out",
    )
    // The dock instances' fields (docks: [dock1] with dock1.pose …), as opennav_docking takes them.
    .extra(mobil_planner_node::is_dock_field)
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(serve(node)))
}

/// The shell's handlers, by concern; what they share is declared here.
mod shell {
    mod actions;
    pub(crate) mod check;
    mod goals;
    mod path;
    mod routes;
}

/// The goal state the session holds.
struct Goal {
    task: Task,
    /// The request's route (a route goal): its result lists the missed waypoints' poses.
    route: Option<Route>,
    /// The chassis and parameters when the goal began: a parameter change applies from the
    /// next goal, so the limits the controller scales by stay those the commands are held to.
    chassis: ChassisParams,
    config: PlannerConfig,
    /// Cancelled when the goal ends: a VFO step's optimisation under way stops at once.
    stop: CancelToken,
    /// The goal's frame: its law sees the robot (and VFO the obstacles) from there.
    frame: String,
    /// The odometry frame's pose in `frame` when a VFO law last took the obstacle map: a
    /// localiser's correction since moves the map's obstacles for the law.
    map_seen_from: Pose2,
}

/// A goal's frame, and the odometry frame's pose in it when the goal came
/// ([`Shell::goal_frame`]).
#[derive(Debug, Clone)]
struct Placed {
    frame: String,
    odom_in: Pose2,
}

type Session = MotionSession<Goal, Source>;
type PlannerEnded = Ended<Goal, Source>;

struct Servers {
    dock: GoalServer<DockRobot>,
    undock: GoalServer<UndockRobot>,
    follow: GoalServer<FollowWaypoints>,
    path: GoalServer<FollowPath>,
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
/// stopped); service requests beyond the rest are answered BUSY at once (by whichever of the
/// service's threads takes them: [`shell::check::CheckService`]).
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

/// The work off the event loop: the goal's pre-check (a newer goal stops the older one's) and
/// the VFO ticks.
struct Jobs {
    goal: OffLoop<PreCheckDone>,
    vfo: OffLoop<VfoTickDone>,
}

/// Everything the loop holds between events.
struct Shell {
    config: PlannerConfig,
    chassis: ChassisParams,
    world: Arc<World>,
    session: Session,
    odom: Latest<Pose2>,
    /// The robot's speed (m/s) in the latest odometry, for `follow_path`'s feedback.
    odom_speed: f64,
    odom_refused: bool,
    status_gate: RateGate,
    markers_gate: RateGate,
    drawing: Drawing,
    throttle: LogThrottle,
    /// Looks for a `cmd_vel` endpoint of the other type.
    types: mobil_ros::cmd_vel::TypeWatch,
    /// Obstacles seen by the LIDAR, in odom (VFO); kept between goals, new extraction
    /// parameters applied once no goal runs.
    map: KeptMap,
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
    /// dock_robot's dock database.
    docks: DockDatabase,
    /// `plan` (the route, or the pre-check's predicted path) and `local_plan` (VFO's chosen
    /// path).
    plans: PlanOut,
    /// `tf` and `tf_static`: goals in other frames than odometry's (shared with the
    /// `planner/check_route` threads).
    tf: SharedTf,
    /// What the `planner/check_route` threads read of the above.
    check: CheckView,
    /// The latest goal's frame (odometry's before the first): the frame of the status, the
    /// markers and the plans.
    frame: String,
    /// `/diagnostics`.
    diagnostics: MotionDiagnostics,
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
    Path(ActionEvent<FollowPathGoal>),
    Lifecycle(Transition),
    RouteChecked(PreCheckDone),
    Tick,
}

async fn serve(node: &mut RosNode) -> anyhow::Result<()> {
    let config: PlannerConfig = node.config()?;
    let stamped = config.cmd_vel.enable_stamped_cmd_vel;
    let outputs = Outputs::create(node, "planner", stamped, &config.frames.base_frame)?;
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
    let docks = load_docks(node, &config)?;
    let plans = PlanOut::create(node)?;
    let tf = SharedTf::new(GoalTf::create(
        node,
        &config.frames.odom_frame,
        config.controller.transform_tolerance(),
    )?);
    let odom_sub = node.subscription::<Odometry>("odom", &qos::default_qos())?;
    let dock_sub = node.subscription::<PoseStamped>("dock_pose", &qos::default_qos())?;
    let route_sub = node.subscription::<Path>("waypoints", &qos::default_qos())?;
    let scan_sub = node.subscription::<LaserScan>("scan", &qos::sensor_data())?;
    let tf_sub = tf_static_subscription(node)?;
    let map = KeptMap::new(config.vfo.scan_config(config.robot_radius))
        .map_err(|e| anyhow::anyhow!("vfo obstacle extraction: {e}"))?;
    let check = Arc::new(node.service::<CheckRoute>(CHECK_ROUTE)?);
    let server_config = GoalServerConfig {
        result_timeout: config.timeouts.result_timeout(),
    };
    let mut lifecycle = Lifecycle::serve(node, &config.managed)?;
    let mut servers = Servers {
        dock: GoalServer::create(node, "dock_robot", server_config.clone())?.gate(lifecycle.gate()),
        undock: GoalServer::create(node, "undock_robot", server_config.clone())?.gate(lifecycle.gate()),
        follow: GoalServer::create(node, "follow_waypoints", server_config.clone())?.gate(lifecycle.gate()),
        path: GoalServer::create(node, "follow_path", server_config)?.gate(lifecycle.gate()),
    };
    info!(
        "{} chassis, pre-check world: {} ({} obstacles); waiting for dock_pose, waypoints, dock_robot, \
         undock_robot, follow_waypoints, follow_path (in `{}`, or a frame tf connects to it)",
        chassis.model().as_str(),
        match config.world_file.as_str() {
            "" => "the sim's built-in world",
            "none" => "none",
            f => f,
        },
        world.obstacles.len(),
        config.frames.odom_frame
    );
    let world = Arc::new(world);
    let check_view = CheckView::new(CheckInputs::new(
        &config,
        chassis,
        Arc::clone(&world),
        node.following_clock(),
    ));
    let mut shell = Shell {
        diagnostics: MotionDiagnostics::create(node, chassis.model().as_str())?,
        tf,
        check: check_view,
        frame: config.frames.odom_frame.clone(),
        config,
        chassis,
        world,
        session: Session::new(SessionSettings::default()),
        odom: Latest::new(),
        odom_speed: 0.0,
        odom_refused: false,
        status_gate: RateGate::default(),
        markers_gate: RateGate::default(),
        drawing: Drawing::default(),
        throttle: LogThrottle::new(Duration::from_secs(2)),
        types: Default::default(),
        map,
        odom_history: PoseHistory::new(ODOM_HISTORY),
        odom_stamp: f64::NAN,
        scan_seen: Latest::new(),
        odom_period: ArrivalPeriod::default(),
        laser: StaticFrames::default(),
        docks,
        plans,
    };
    shell.send_idle_status(node, out);
    let mut jobs = Jobs {
        goal: OffLoop::new(),
        vfo: OffLoop::new(),
    };
    // The goal's pre-check keeps one of the MAX_CHECKS.
    let check_service = CheckService::start(
        Arc::clone(&check),
        MAX_CHECKS - 1,
        shell.check.clone(),
        shell.tf.clone(),
    )?;
    let mut sink = CmdVel::new(&out.cmd);
    let outcome = event_loop(
        node,
        out,
        &mut sink,
        &mut shell,
        &mut servers,
        &mut jobs,
        &mut lifecycle,
        (&odom_sub, &dock_sub, &route_sub),
        (&scan_sub, &tf_sub),
    )
    .await;
    // No request is taken once the loop has ended (the odometry and the clock a check reads no
    // longer move); the checks under way are waited for below.
    check_service.stop();
    // A goal under way (a pre-check included: it stopped a robot a goal before it moved) ends,
    // and its zero command, waited for, goes out before anything that may take time; then the
    // four servers close at once (each waits up to 2 s for its results).
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
        shell.report(&mut io, ended);
    }
    if final_zero {
        out.cmd.final_stop(FINAL_STOP_WAIT).await;
    }
    // The route checks under way answer before the node leaves: their server must not outlive
    // the participant (a check takes at most about 0.6 s).
    let left = check_service.shut_down(Duration::from_secs(1)).await;
    if left > 0 {
        warn!("{CHECK_ROUTE}: {left} thread(s) still answering at shutdown may answer after the node has left");
    }
    lifecycle.close().await;
    let down = EndCause::Shutdown;
    let Servers {
        dock,
        undock,
        follow,
        path,
    } = servers;
    tokio::join!(
        dock.close(nav2_result(&down, Action::Dock.codes())),
        undock.close(nav2_result(&down, Action::Undock.codes())),
        follow.close(follow_result(&down, &[], &[])),
        path.close(nav2_result(&down, Action::Path.codes())),
    );
    Ok(outcome)
}

/// The dock database (`dock_database` file, else `docks`), each dock logged; a dock in another
/// frame than odometry's is told (goals to it fail DOCK_NOT_VALID).
fn load_docks(node: &RosNode, config: &PlannerConfig) -> anyhow::Result<DockDatabase> {
    let text = match config.dock_database.as_str() {
        "" => None,
        path => Some(std::fs::read_to_string(path).map_err(|e| anyhow::anyhow!("dock_database `{path}`: {e}"))?),
    };
    let docks = mobil_planner_node::dock_database(config, node.extra_params(), text.as_deref())
        .map_err(|e| anyhow::anyhow!("dock database: {e}"))?;
    for d in docks.docks() {
        info!(
            "dock `{}` ({}) at ({:.3}, {:.3}, {:.3} rad) in {}",
            d.name, d.dock_type, d.pose.x, d.pose.y, d.pose.yaw, d.frame
        );
        if d.frame != config.frames.odom_frame {
            info!(
                "dock `{}` is in frame `{}`: a goal to it needs `{}` → `{}` on tf or tf_static",
                d.name, d.frame, d.frame, config.frames.odom_frame
            );
        }
    }
    Ok(docks)
}

#[allow(clippy::too_many_arguments)]
async fn event_loop(
    node: &mut RosNode,
    out: &Outputs,
    sink: &mut CmdVel<'_>,
    shell: &mut Shell,
    servers: &mut Servers,
    jobs: &mut Jobs,
    lifecycle: &mut Lifecycle,
    (odom_sub, dock_sub, route_sub): (&Subscription<Odometry>, &Subscription<PoseStamped>, &Subscription<Path>),
    (scan_sub, tf_sub): (&Subscription<LaserScan>, &Subscription<TFMessage>),
) -> anyhow::Result<()> {
    let mut inputs = Inputs::new();
    inputs
        .add(odom_sub.async_stream(), "odom", "sample ignored", Event::Odom)
        .add(scan_sub.async_stream(), "scan", "scan ignored", Event::Scan)
        .add(dock_sub.async_stream(), "dock_pose", "goal ignored", Event::DockPose)
        .add(route_sub.async_stream(), "waypoints", "route ignored", Event::Waypoints);
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
            e = servers.dock.next_event() => Event::Dock(e),
            e = servers.undock.next_event() => Event::Undock(e),
            e = servers.follow.next_event() => Event::Follow(e),
            e = servers.path.next_event() => Event::Path(e),
            t = lifecycle.next() => Event::Lifecycle(t),
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
            Event::Lifecycle(transition) => {
                // Leaving active (deactivate, shutdown): the goal under way ends, with its zero.
                if transition.leaves_active() {
                    shell.end_goal(&mut io, EndCause::Deactivated);
                }
                lifecycle.complete(transition, CallbackReturn::Success);
            }
            Event::DockPose(_) | Event::Waypoints(_) if !lifecycle.is_active() => warn_throttled!(
                shell.throttle,
                "inactive",
                "topic goal refused: the node is {} (lifecycle): activate it first",
                lifecycle.state()
            ),
            Event::Config(Err(e)) => warn!("parameters not applied: {e}"),
            Event::Odom(m) => shell.odom_in(&mut io, jobs, &m),
            Event::Scan(m) => {
                shell.laser.refresh(tf_sub, &mut shell.throttle);
                shell.scan_in(&m);
            }
            Event::VfoTicked(done) => shell.vfo_ticked(&mut io, done),
            Event::DockPose(m) => {
                let frame = shell.tf.frame_of(&m.header.frame_id);
                let target = goal_pose("dock pose", &m, &frame).map_err(|e| Action::Dock.invalid_goal(&e));
                let target = target.and_then(|p| Ok((p, shell.goal_frame(io.node, &frame, Action::Dock)?)));
                shell.start_dock(&mut io, target, Source::DockPose);
            }
            Event::Waypoints(m) => {
                let frame = shell.tf.frame_of(&m.header.frame_id);
                match shell.goal_frame(io.node, &frame, Action::Follow) {
                    Ok(placed) => {
                        let start = shell.fresh_odom().map(|p| placed.odom_in.compose(&p));
                        let route = route_from_path(&m, &frame, start.map(|p| p.position()), ROUTE_LIMITS);
                        shell.start_route(&mut io, jobs, route, (start, placed), Source::Waypoints);
                    }
                    Err(refusal) => shell.refuse(&mut io, Source::Waypoints, refusal),
                }
            }
            Event::Dock(ActionEvent::Goal(request)) => shell.dock_action(&mut io, request).await,
            Event::Undock(ActionEvent::Goal(request)) => shell.undock_action(&mut io, request).await,
            Event::Follow(ActionEvent::Goal(request)) => shell.follow_action(&mut io, jobs, request).await,
            Event::Path(ActionEvent::Goal(request)) => shell.path_action(&mut io, request).await,
            Event::Dock(ActionEvent::CancelRequested(id)) => shell.cancel(&mut io, Source::DockAction, id),
            Event::Undock(ActionEvent::CancelRequested(id)) => shell.cancel(&mut io, Source::UndockAction, id),
            Event::Follow(ActionEvent::CancelRequested(id)) => shell.cancel(&mut io, Source::FollowAction, id),
            Event::Path(ActionEvent::CancelRequested(id)) => shell.cancel(&mut io, Source::PathAction, id),
            Event::RouteChecked(done) => shell.pre_checked(&mut io, done),
            Event::Tick => shell.tick(&mut io).await,
        }
    }
}
