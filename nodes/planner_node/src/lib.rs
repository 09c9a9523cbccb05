//! The ROS side of [`mobil_planner`]: the `planner_node` executable (src/main.rs) and what its
//! shell does that can be checked without DDS — the configuration (every parameter declared
//! once), goal and route validation, the command clamp, how a goal ends (status reason, Nav2
//! result codes), the status, the route pre-check's reply and the markers.
//!
//! The methods themselves (Lyapunov docking, the goal approach, the online follower, the route
//! pre-check) are in [`mobil_planner`]; nothing here decides where the robot goes.

#![warn(missing_docs)]

use mobil_chassis::model::ChassisConfig;
use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::PoseStamped;
use mobil_msgs::mobil_msgs::msg::RouteProblem as ProblemMsg;
use mobil_msgs::mobil_msgs::srv::CheckRouteResponse;
use mobil_msgs::nav2_msgs::action::FollowWaypointsResult;
use mobil_msgs::nav2_msgs::msg::MissedWaypoint;
use mobil_msgs::nav_msgs::msg::Path;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::visualization_msgs::msg::MarkerArray;
use mobil_planner::docks::{DockDatabase, DockFields};
pub use mobil_planner::goals::{Missed, RouteAnswer};
use mobil_planner::{DockingConfig, DockingGains, FollowConfig, RouteCheckConfig};
use mobil_ros::action::nav2_result;
use mobil_ros::chassis::{chassis_params, declare_chassis};
use mobil_ros::cmd_vel::CmdVelType;
use mobil_ros::config::{Config, ConfigError, Decl};
use mobil_ros::geometry::pose_msg;
use mobil_ros::goal::RouteLimits;
pub use mobil_ros::goal::{GoalError, Route};
use mobil_ros::groups::{Controller, Frames, GoalTimeouts};
use mobil_ros::lifecycle::Managed;
use mobil_ros::markers::{point, Markers};
use mobil_ros::motion::EndCause;
use mobil_world::World;
use ros2_client::ParameterValue;

pub mod vfo;

pub use mobil_planner::task::{Action, Figures, Mode};
pub use mobil_planner::vfo::{VfoSettings, WaypointMethod};

/// Everything the node is configured with, each field filled by one declared parameter.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlannerConfig {
    /// The chassis geometry and limits (the params file's `/**` section).
    pub chassis: ChassisConfig,
    /// Footprint radius around the reference point (m), for the route pre-check.
    pub robot_radius: f64,
    /// Lyapunov gains γ, k, h, λ.
    pub gamma: f64,
    /// k.
    pub k: f64,
    /// h.
    pub h: f64,
    /// λ.
    pub lambda: f64,
    /// The docking's thresholds and timers.
    pub docking: DockingConfig,
    /// The online follower's settings.
    pub follow: FollowConfig,
    /// The world file of the pre-check: empty = the sim's built-in world, `none` = no obstacles.
    pub world_file: String,
    /// The dock instances' names (`docks`; each one's `type`, `frame`, `pose`, `id` come as
    /// `<name>.pose` … parameters).
    pub docks: Vec<String>,
    /// A dock database file in opennav_docking's form (`dock_database`); empty: `docks`.
    pub dock_database: String,
    /// Drive a route the pre-check found problems on (default false: refused).
    pub execute_infeasible_routes: bool,
    /// How far `undock_robot` backs out (m).
    pub staging_distance: f64,
    /// Reversing speed of `undock_robot` (m/s).
    pub undock_speed: f64,
    /// Status rate while a goal is active (Hz).
    pub status_rate_hz: f64,
    /// Markers rate while a goal is active (Hz).
    pub markers_rate_hz: f64,
    /// How long a goal waits for odometry, and its result for the client.
    pub timeouts: GoalTimeouts,
    /// The managed-node parameters (`autostart`, `bond_heartbeat_period`).
    pub managed: Managed,
    /// `cmd_vel`'s type (`enable_stamped_cmd_vel`).
    pub cmd_vel: CmdVelType,
    /// The frames of odometry, goals and the robot.
    pub frames: Frames,
    /// How `waypoints` and `follow_waypoints` are followed, and `follow_path` by default.
    pub waypoint_method: WaypointMethod,
    /// Nav2's controller role (`follow_path`): the progress checker, the sub-goal spacing.
    pub controller: Controller,
    /// VFO waypoint following's settings.
    pub vfo: VfoSettings,
}

/// Most waypoints of one route (after `number_of_loops`): the pre-check of 200 legs each at the
/// 50 m leg bound takes 0.47–0.64 s at worst (measured; a real route is far shorter: see the
/// 20-waypoint bench in docs/planner_node.md and docs/performance.md), so every check runs off
/// the event loop, a superseded goal's check stopped within one virtual step.
pub const MAX_WAYPOINTS: usize = 200;
/// Most poses of `simulated_path` in a `check_route` reply (about 90 bytes each: 36 KB, well
/// under the 64 KB a reply should stay below).
pub const MAX_REPLY_POSES: usize = 400;
/// Most missed waypoints in a FollowWaypoints result: every one a route of [`MAX_WAYPOINTS`]
/// can miss while driving, and twice that from a pre-check; about 90 bytes each (index, pose,
/// code), 36 KB, well under the 64 KB a reply should stay below.
pub const MAX_RESULT_MISSED: usize = 2 * MAX_WAYPOINTS;

impl Config for PlannerConfig {
    fn declare(d: &mut Decl<Self>) {
        let g = DockingGains::paper();
        let dc = DockingConfig::default();
        let f = FollowConfig::default();
        d.nest(|c: &mut PlannerConfig| &mut c.chassis, declare_chassis);
        mobil_ros::params! { d;
            double "robot_radius" = 0.53 => robot_radius, above(0.0);
                "radius of the footprint around the reference point, for the route pre-check [m]";
            double "gamma" = g.gamma() => gamma, above(0.0); "γ: v = γ·e·cos α (eq. 3.43) [1/s]";
            double "k" = g.k() => k, above(0.0); "k: the turn gain on α (eq. 3.46) [1/s]";
            double "h" = g.h() => h, above(0.0); "h: the weight of Θ in V and ω (eq. 3.41, 3.46)";
            double "lambda" = g.lambda() => lambda, above(0.0); "λ: the weight of e² in V (eq. 3.41)";
            double "position_tolerance" = dc.position_tolerance => docking.position_tolerance, above(0.0);
                "ε_e: docked needs e below this [m]";
            double "heading_tolerance" = dc.heading_tolerance => docking.heading_tolerance, above(0.0);
                "ε_ϑ: docked needs the heading error below this [rad]";
            double "rotate_gain" = dc.rotate_gain => docking.rotate_gain, above(0.0);
                "gain of the final in-place rotation (omni) [1/s]";
        }
        d.double(
            "stall_time_s",
            dc.stall_time_s,
            "a docking whose V has not fallen by 0.1 % for this long fails NOT_CONVERGING; a route on \
             which the robot drove less than step_length for this long fails STALLED [s, ROS time]",
            |c, v| {
                c.docking.stall_time_s = v;
                c.follow.stall_time_s = v;
            },
        )
        .above(0.0);
        mobil_ros::params! { d;
            double "time_limit_s" = dc.time_limit_s => docking.time_limit_s, above(0.0);
                "a docking not done after this long fails TIME_LIMIT [s, ROS time]";
            double "approach_speed" = f.speed => follow.speed, above(0.0);
                "cruise speed of the waypoint approach [m/s]";
            double "min_speed" = f.min_speed => follow.min_speed, above(0.0);
                "slowest speed of the slow-down at the last waypoint [m/s]";
            double "slow_down_distance" = f.slow_down_distance => follow.slow_down_distance, min(0.0);
                "the speed falls linearly inside this distance to the last waypoint (0: no slow-down) [m]";
            double "critical_distance" = f.critical_distance => follow.critical_distance, above(0.0);
                "Z_crit: a waypoint nearer than this is reached (pre-check and run) [m]";
            double "step_length" = f.check_length => follow.check_length, above(0.0);
                "the pre-check's step, and the path between two progress checks of the run [m]";
            double "progress_epsilon" = f.progress_epsilon => follow.progress_epsilon, min(0.0);
                "ε: within steering reach, a step that brings the waypoint no nearer than this misses it [m]";
            string "world_file" = "" => world_file, read_only();
                "world YAML of the pre-check (the sim's format); empty: the sim's built-in world; none: no obstacles";
            boolean "execute_infeasible_routes" = false => execute_infeasible_routes;
                "drive a route the pre-check found problems on (false: refused, FAILED ROUTE_INFEASIBLE)";
            double "staging_distance" = 0.5 => staging_distance, above(0.0), max(10.0);
                "undock_robot backs straight out this far [m]";
            double "undock_speed" = 0.15 => undock_speed, above(0.0); "undock_robot's reversing speed [m/s]";
            double "status_rate_hz" = 5.0 => status_rate_hz, within(0.1, 50.0);
                "planner/status rate while a goal is active (and on every change) [Hz]";
            double "markers_rate_hz" = 1.0 => markers_rate_hz, within(0.1, 10.0);
                "planner/markers rate while a goal is active [Hz]";
        }
        d.strings(
            "docks",
            &[],
            "dock_robot's dock database (opennav_docking's form): the names of the dock instances, each \
             with NAME.pose [x, y, yaw], NAME.frame (default map), NAME.type, NAME.id",
            |c, v| c.docks = v,
        )
        .read_only();
        d.string(
            "dock_database",
            "",
            "a dock database YAML file (opennav_docking's: docks: {NAME: {type, frame, pose, id}}) read \
             instead of docks; empty: docks",
            |c, v| c.dock_database = v,
        )
        .read_only();
        d.nest(|c: &mut PlannerConfig| &mut c.controller, Controller::declare);
        d.nest(|c: &mut PlannerConfig| &mut c.timeouts, GoalTimeouts::declare);
        d.nest(|c: &mut PlannerConfig| &mut c.managed, Managed::declare);
        d.nest(|c: &mut PlannerConfig| &mut c.cmd_vel, CmdVelType::declare);
        d.nest(|c: &mut PlannerConfig| &mut c.frames, Frames::declare);
        vfo::declare_vfo(d);
    }

    fn validate(&self) -> Result<(), ConfigError> {
        self.chassis_params()?;
        self.gains()?;
        self.docking.validate().map_err(ConfigError::inconsistent)?;
        self.follow.validate().map_err(ConfigError::inconsistent)?;
        if self.controller.path_lookahead / 2.0 <= self.follow.critical_distance {
            return Err(ConfigError::inconsistent(format!(
                "path_lookahead {} m: half of it must be above critical_distance {} m (a sub-goal would \
                 be reached before the next is taken)",
                self.controller.path_lookahead, self.follow.critical_distance
            )));
        }
        self.route_check().validate().map_err(ConfigError::inconsistent)?;
        self.vfo.gains.validate().map_err(ConfigError::inconsistent)?;
        mobil_planner::vfo::VfoWaypoint::new(0.0, 0.0, 0.0, self.vfo.guiding).map_err(ConfigError::inconsistent)?;
        self.vfo.optimise.validate().map_err(ConfigError::inconsistent)?;
        self.vfo
            .scan_config(self.robot_radius)
            .validate()
            .map_err(ConfigError::inconsistent)?;
        if !matches!(self.vfo.laser_pose.len(), 0 | 3) {
            return Err(ConfigError::inconsistent(format!(
                "vfo.laser_pose has {} values: give x, y, yaw (3) or none",
                self.vfo.laser_pose.len()
            )));
        }
        Ok(())
    }
}

impl PlannerConfig {
    /// The chassis (from `/**`).
    pub fn chassis_params(&self) -> Result<ChassisParams, ConfigError> {
        chassis_params(&self.chassis)
    }

    /// The Lyapunov gains.
    pub fn gains(&self) -> Result<DockingGains, ConfigError> {
        DockingGains::new(self.gamma, self.k, self.h, self.lambda).map_err(ConfigError::inconsistent)
    }

    /// The pre-check's settings: the run's Z_crit, ε and step, the footprint radius.
    pub fn route_check(&self) -> RouteCheckConfig {
        let mut c = RouteCheckConfig::new(self.robot_radius);
        c.approach.step_length = self.follow.check_length;
        c.approach.critical_distance = self.follow.critical_distance;
        c.approach.progress_epsilon = self.follow.progress_epsilon;
        c.detour_factor = self.follow.detour_factor;
        c.max_leg_length = self.follow.max_leg_length;
        c
    }
}

/// The pre-check's world: `""` the sim's built-in world, `none` no obstacles, else the file.
pub fn load_world(world_file: &str) -> Result<World, mobil_world::WorldError> {
    match world_file {
        "" => Ok(World::builtin()),
        "none" => Ok(World::default()),
        path => World::load(path),
    }
}

/// The routes the planner takes: at most [`MAX_WAYPOINTS`] waypoints, repeats included; a
/// route shorter than 1 mm, start included, is refused as zero-length.
pub const ROUTE_LIMITS: RouteLimits = RouteLimits {
    min_length: 1e-3,
    max_waypoints: MAX_WAYPOINTS,
};

/// FollowWaypoints' result of `cause`, listing the waypoints `missed` (each the request's index
/// and its error code, as [`mobil_planner::task::Task::result_missed`] chooses them), up to
/// [`MAX_RESULT_MISSED`], each with its pose from `poses`.
pub fn follow_result(cause: &EndCause, poses: &[PoseStamped], missed: &[(usize, u16)]) -> FollowWaypointsResult {
    let listed = |&(index, error_code): &(usize, u16)| MissedWaypoint {
        index: u32::try_from(index).unwrap_or(u32::MAX),
        goal: poses.get(index).cloned().unwrap_or_default(),
        error_code,
    };
    FollowWaypointsResult {
        missed_waypoints: missed.iter().take(MAX_RESULT_MISSED).map(listed).collect(),
        ..nav2_result(cause, Action::Follow.codes())
    }
}

/// The `check_route` reply of `answer`: each problem with its index, kind, detail and
/// position; the simulated path stamped `stamp` in `frame`.
pub fn check_reply(answer: &RouteAnswer, stamp: Time, frame: &str) -> CheckRouteResponse {
    let header = Header {
        stamp,
        frame_id: frame.to_owned(),
    };
    let index = |i: usize| i32::try_from(i).unwrap_or(i32::MAX);
    let problem = |m: &Missed| ProblemMsg {
        index: index(m.index),
        kind: m.kind.as_str().to_owned(),
        detail: m.kind.to_string(),
        position: point(m.position),
    };
    let pose = |p: &Pose2| PoseStamped {
        header: header.clone(),
        pose: pose_msg(p),
    };
    CheckRouteResponse {
        feasible: answer.feasible(),
        reason: answer.reason.clone(),
        failed_waypoint: answer.failed_waypoint.map_or(-1, index),
        problems: answer.problems.iter().map(problem).collect(),
        simulated_path: Path {
            poses: answer.path.iter().map(pose).collect(),
            header,
        },
        length: answer.length,
    }
}

/// A refused `check_route` request: infeasible with the reason, nothing else.
pub fn refused_reply(reason: String) -> CheckRouteResponse {
    CheckRouteResponse {
        feasible: false,
        reason,
        failed_waypoint: -1,
        ..Default::default()
    }
}

pub use mobil_planner::view::{MarkerView, MAX_DRAWN_PATH, MAX_MARKER_POINTS};

/// The marker array of `view`: a DELETEALL first (so nothing stale stays), then its sketch
/// ([`MarkerView::sketch`]), one marker per shape.
pub fn markers(view: &MarkerView<'_>, stamp: Time, frame: &str) -> MarkerArray {
    let mut m = Markers::replacing(stamp, frame);
    m.sketch(&view.sketch());
    m.array()
}

/// The fields a dock instance's parameters fill (`NAME.type` …): what [`NodeDecl::extra`]
/// takes for the planner.
///
/// [`NodeDecl::extra`]: mobil_ros::NodeDecl::extra
pub const DOCK_FIELDS: [&str; 4] = ["type", "frame", "pose", "id"];

/// Whether an undeclared parameter is a dock instance's field (`NAME.pose`, …).
pub fn is_dock_field(name: &str) -> bool {
    name.rsplit_once('.')
        .is_some_and(|(dock, field)| !dock.is_empty() && DOCK_FIELDS.contains(&field))
}

/// The dock database from `docks` and the instances' parameters (`extra`: name, value), or
/// from the `dock_database` file's text when one is given.
pub fn dock_database(
    config: &PlannerConfig,
    extra: &[(String, ParameterValue)],
    file_text: Option<&str>,
) -> Result<DockDatabase, String> {
    let instances = match file_text {
        Some(text) => docks_from_yaml(text)?,
        None => config
            .docks
            .iter()
            .map(|name| dock_from_params(name, extra))
            .collect::<Result<Vec<_>, String>>()?,
    };
    DockDatabase::new(instances).map_err(|e| e.to_string())
}

/// One dock instance from its parameters (the last value of a name wins).
fn dock_from_params(name: &str, extra: &[(String, ParameterValue)]) -> Result<(String, DockFields), String> {
    let field = |f: &str| {
        let key = format!("{name}.{f}");
        extra.iter().rev().find(|(n, _)| *n == key).map(|(_, v)| v.clone())
    };
    let text = |f: &str| -> Result<Option<String>, String> {
        match field(f) {
            None => Ok(None),
            Some(ParameterValue::String(s)) => Ok(Some(s)),
            Some(other) => Err(format!("{name}.{f} must be a string, not {other:?}")),
        }
    };
    let pose = match field("pose") {
        None => None,
        Some(ParameterValue::DoubleArray(a)) => Some(a),
        Some(ParameterValue::IntegerArray(a)) => Some(a.iter().map(|i| *i as f64).collect()),
        Some(other) => return Err(format!("{name}.pose must be [x, y, yaw], not {other:?}")),
    };
    let fields = DockFields {
        dock_type: text("type")?,
        frame: text("frame")?,
        pose,
        id: text("id")?,
    };
    Ok((name.to_owned(), fields))
}

/// The instances of a dock database file: `docks:` mapping each name to its fields.
pub fn docks_from_yaml(text: &str) -> Result<Vec<(String, DockFields)>, String> {
    use serde_norway::Value;
    let root: Value = serde_norway::from_str(text).map_err(|e| format!("not YAML: {e}"))?;
    let Some(Value::Mapping(docks)) = root.get("docks") else {
        return Err("no `docks:` mapping each dock's name to its fields".to_owned());
    };
    docks
        .iter()
        .map(|(name, fields)| {
            let name = name.as_str().ok_or("a dock's name is not a string")?.to_owned();
            let text = |f: &str| fields.get(f).and_then(Value::as_str).map(str::to_owned);
            let pose = match fields.get("pose") {
                None => None,
                Some(Value::Sequence(items)) => Some(
                    items
                        .iter()
                        .map(|v| {
                            v.as_f64()
                                .ok_or_else(|| format!("dock `{name}`: pose holds a non-number"))
                        })
                        .collect::<Result<Vec<f64>, String>>()?,
                ),
                Some(_) => return Err(format!("dock `{name}`: pose must be [x, y, yaw]")),
            };
            let fields = DockFields {
                dock_type: text("type"),
                frame: text("frame"),
                pose,
                id: text("id"),
            };
            Ok((name, fields))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use mobil_geom::Pose2;
    use mobil_motion::Outcome;
    use mobil_msgs::mobil_msgs::msg::NavStatus;
    use mobil_msgs::nav2_msgs::action::{DockRobotResult, UndockRobotResult};
    use mobil_msgs::visualization_msgs::msg::Marker;
    use mobil_planner::ProblemKind;
    use mobil_ros::geometry::{header_in, pose_stamped, yaw_of};
    use mobil_ros::params::ParamValues;
    use mobil_ros::status::end_state;
    use nalgebra::Point2;

    fn dock_result(cause: &EndCause) -> DockRobotResult {
        nav2_result(cause, Action::Dock.codes())
    }

    fn undock_result(cause: &EndCause) -> UndockRobotResult {
        nav2_result(cause, Action::Undock.codes())
    }

    fn stamped(frame: &str, x: f64, y: f64) -> PoseStamped {
        pose_stamped(header_in(frame), &Pose2::new(x, y, 0.0))
    }

    #[test]
    fn defaults_are_the_library_s_and_bad_gains_are_refused() {
        let values = ParamValues::defaults(&Decl::<PlannerConfig>::of().specs());
        let c: PlannerConfig = mobil_ros::config::load(&values).expect("defaults valid");
        assert_eq!(c.gains().expect("valid"), DockingGains::paper());
        assert_eq!(c.docking, DockingConfig::default());
        assert_eq!(c.follow, FollowConfig::default());
        assert_eq!(c.route_check(), RouteCheckConfig::new(0.53));
        let mut bad = values.clone();
        bad.set("gamma", ros2_client::ParameterValue::Double(0.0));
        assert!(mobil_ros::config::load::<PlannerConfig>(&bad).is_err());
        let mut bad = values.clone();
        bad.set("min_speed", ros2_client::ParameterValue::Double(0.4));
        // min_speed above approach_speed (0.3) is inconsistent.
        assert!(mobil_ros::config::load::<PlannerConfig>(&bad).is_err());
        // follow_path: half the lookahead must exceed Z_crit (0.16 m): 0.32 m is refused, 0.34 m taken.
        let mut lookahead = values;
        lookahead.set("path_lookahead", ros2_client::ParameterValue::Double(0.32));
        assert!(mobil_ros::config::load::<PlannerConfig>(&lookahead).is_err());
        lookahead.set("path_lookahead", ros2_client::ParameterValue::Double(0.34));
        assert!(mobil_ros::config::load::<PlannerConfig>(&lookahead).is_ok());
    }

    #[test]
    fn ends_give_status_reasons_and_nav2_codes() {
        use mobil_planner::goals::{docking_failure, route_done, route_infeasible};
        use mobil_planner::{DockingFailure, Finish, Residual};
        // A law's end passes through: its reason, its state, its Nav2 code in every result.
        let residual = Residual { e: 0.015, heading: 0.5 };
        let law = EndCause::Outcome(docking_failure(
            DockingFailure::HeadingResidual,
            residual,
            Finish::RotateInPlace,
        ));
        assert_eq!((end_state(&law), law.code()), (NavStatus::FAILED, "RESIDUAL"));
        assert!(law.reason().contains("e = 0.015 m") && law.reason().contains("0.500 rad (28.6°)"));
        let r = dock_result(&law);
        assert_eq!((r.success, r.error_code), (false, 905));
        assert_eq!(r.error_msg, law.reason());
        let docked = EndCause::Outcome(Outcome::succeeded("docked: e = 0.010 m, heading error 0.020 rad"));
        let r = dock_result(&docked);
        assert_eq!(
            (r.success, r.error_code, end_state(&docked)),
            (true, 0, NavStatus::SUCCEEDED)
        );
        assert_eq!(r.error_msg, "SUCCEEDED: docked: e = 0.010 m, heading error 0.020 rad");
        // The ends the session makes reach every result with their action's code (the codes
        // themselves: mobil_planner's task tests).
        let stale = EndCause::Stale("odom".into());
        assert_eq!(end_state(&stale), NavStatus::FAILED);
        assert_eq!(undock_result(&stale).error_code, 905);
        assert_eq!(dock_result(&EndCause::Shutdown).error_code, 999);
        assert_eq!(follow_result(&EndCause::Shutdown, &[], &[]).error_code, 600);
        assert_eq!(follow_result(&stale, &[], &[]).error_code, 601);
        assert!(undock_result(&EndCause::Outcome(Outcome::succeeded("undocked"))).success);
        let nan = GoalError::NotFinite {
            what: "dock pose".into(),
        };
        assert_eq!(
            Action::Dock.invalid_goal(&nan).reason(),
            "INVALID_GOAL: dock pose is not finite"
        );
        // A refused route lists every problem, each with the request's index and its pose.
        let poses = vec![stamped("odom", 2.0, 0.0), stamped("odom", 2.0, 0.3)];
        let missed = vec![Missed {
            index: 1,
            position: Point2::new(2.0, 0.3),
            kind: ProblemKind::TurnRadius {
                required: 0.2,
                minimum: 0.73,
            },
            pre_check: true,
        }];
        let infeasible = EndCause::Outcome(route_infeasible(&missed));
        assert_eq!(
            infeasible.reason(),
            "ROUTE_INFEASIBLE: 1 problem(s): waypoint 1: turn_radius: turn radius 0.20 m below the chassis minimum 0.73 m"
        );
        let r = follow_result(&infeasible, &poses, &[(1, missed[0].error_code())]);
        assert_eq!(r.error_code, 601);
        let listed: Vec<(u32, u16)> = r.missed_waypoints.iter().map(|m| (m.index, m.error_code)).collect();
        assert_eq!(listed, vec![(1, 208)]);
        assert_eq!(r.missed_waypoints[0].goal.pose.position.y, 0.3);
        // A route done lists what the run missed (FollowPath's 105), with no error.
        let ran = Missed {
            pre_check: false,
            ..missed[0].clone()
        };
        let done = EndCause::Outcome(Outcome::succeeded(route_done(2, std::slice::from_ref(&ran))));
        assert_eq!(end_state(&done), NavStatus::SUCCEEDED);
        assert!(done
            .reason()
            .starts_with("SUCCEEDED: route done: 1 of 2 waypoints missed"));
        let r = follow_result(&done, &poses, &[(ran.index, ran.error_code())]);
        assert_eq!((r.error_code, r.missed_waypoints[0].error_code), (0, 105));
        // More missed than the 50 a reason lists: every one is in the result (60 here).
        let many: Vec<Missed> = (0..60)
            .map(|i| Missed {
                index: i,
                ..ran.clone()
            })
            .collect();
        let many: Vec<(usize, u16)> = many.iter().map(|m| (m.index, m.error_code())).collect();
        let r = follow_result(&done, &poses, &many);
        assert_eq!(r.missed_waypoints.len(), 60);
        assert_eq!(r.missed_waypoints[59].index, 59);
        // A stalled route: the law's TASK_EXECUTOR_FAILED.
        let stalled = EndCause::Outcome(Outcome::failed("STALLED", "did not move", 601));
        assert_eq!(follow_result(&stalled, &[], &[]).error_code, 601);
    }

    #[test]
    fn the_reply_names_each_problem_and_carries_the_answer_s_path() {
        // The answer's choices (which problems, how many poses): mobil_planner's goals tests.
        let answer = RouteAnswer {
            problems: vec![Missed {
                index: 8,
                position: Point2::new(300.0, 0.0),
                kind: ProblemKind::Collision {
                    at: Point2::new(300.0, 0.0),
                    clearance: -0.1,
                },
                pre_check: true,
            }],
            reason: "ROUTE_INFEASIBLE: 1 problem(s): waypoint 8: collision".into(),
            failed_waypoint: Some(8),
            path: vec![Pose2::new(0.0, 0.0, 0.0), Pose2::new(1.0, 0.5, 0.25)],
            length: 1.25,
        };
        let reply = check_reply(&answer, Time::default(), "odom");
        assert!(!reply.feasible);
        assert_eq!((reply.failed_waypoint, reply.length), (8, 1.25));
        assert_eq!(reply.reason, answer.reason);
        let p = &reply.problems[0];
        assert_eq!((p.index, p.kind.as_str(), p.position.x), (8, "collision", 300.0));
        assert_eq!(
            p.detail,
            "collision at (300.00, 0.00): footprint 0.10 m into an obstacle"
        );
        let poses = &reply.simulated_path.poses;
        assert_eq!((poses.len(), poses[1].pose.position.y), (2, 0.5));
        assert_eq!(reply.simulated_path.header.frame_id, "odom");
        assert_relative_eq!(yaw_of(&poses[1].pose.orientation), 0.25, epsilon = 1e-12);
        let clear = RouteAnswer {
            problems: Vec::new(),
            reason: String::new(),
            failed_waypoint: None,
            ..answer
        };
        let reply = check_reply(&clear, Time::default(), "odom");
        assert!(reply.feasible && reply.problems.is_empty());
        assert_eq!(reply.failed_waypoint, -1);
    }

    #[test]
    fn markers_stay_small() {
        let route: Vec<Point2<f64>> = (0..MAX_WAYPOINTS).map(|i| Point2::new(i as f64, 0.0)).collect();
        let predicted: Vec<Pose2> = (0..50_000).map(|i| Pose2::new(i as f64 * 0.01, 0.0, 0.0)).collect();
        let problems: Vec<Missed> = (0..80)
            .map(|i| Missed {
                index: i,
                position: Point2::new(i as f64, 0.0),
                kind: ProblemKind::Unreachable(mobil_planner::UnreachableCause::PassedBy { closest: 0.3 }),
                pre_check: true,
            })
            .collect();
        let view = MarkerView {
            route: &route,
            predicted: &predicted,
            problems: &problems,
            dock: Some(Pose2::new(1.0, 2.0, 0.5)),
            ..MarkerView::default()
        };
        let a = markers(&view, Time::default(), "odom");
        // DELETEALL, route line and dots, predicted path, 50 problems × 2, the dock arrow.
        // (mobil_planner::goals::MAX_LISTED_MISSED: 50 problems drawn.)
        assert_eq!(a.markers.len(), 1 + 2 + 1 + 2 * 50 + 1);
        assert_eq!(a.markers[0].action, Marker::DELETEALL);
        let points: usize = a.markers.iter().map(|m| m.points.len()).sum();
        // The route whole (200 ≤ a quarter of the budget each), the predicted path within a
        // quarter of the rest: (1000 − 400) / 4 = 150 points.
        assert_eq!(points, 2 * MAX_WAYPOINTS + (MAX_MARKER_POINTS - 2 * MAX_WAYPOINTS) / 4);
        assert_eq!(points, 550);
        let arrow = a.markers.last().expect("arrow");
        assert_eq!(arrow.r#type, Marker::ARROW);
        assert_relative_eq!(yaw_of(&arrow.pose.orientation), 0.5, epsilon = 1e-12);
    }

    #[test]
    fn the_world_file_names_the_builtin_none_or_a_file() {
        assert_eq!(load_world("").expect("builtin"), World::builtin());
        assert!(load_world("none").expect("empty").obstacles.is_empty());
        assert!(load_world("/nonexistent/world.yaml").is_err());
    }

    /// Docks from parameters (Nav2's form) and from a file; refusals say what is wrong.
    #[test]
    fn the_dock_database_comes_from_parameters_or_a_file() {
        let mut config: PlannerConfig =
            mobil_ros::config::load(&ParamValues::defaults(&Decl::<PlannerConfig>::of().specs())).unwrap();
        config.docks = vec!["dock1".into(), "dock2".into()];
        let extra = vec![
            ("dock1.type".to_owned(), ParameterValue::String("charging_dock".into())),
            ("dock1.frame".to_owned(), ParameterValue::String("odom".into())),
            (
                "dock1.pose".to_owned(),
                ParameterValue::DoubleArray(vec![1.0, 0.5, 1.0]),
            ),
            ("dock2.pose".to_owned(), ParameterValue::IntegerArray(vec![2, 0, 0])),
        ];
        let db = dock_database(&config, &extra, None).unwrap();
        assert_eq!(db.get("dock1").unwrap().pose, mobil_geom::Pose2::new(1.0, 0.5, 1.0));
        assert_eq!((db.docks()[1].frame.as_str(), db.docks()[1].pose.x), ("map", 2.0));
        assert!(is_dock_field("dock1.pose") && is_dock_field("a.b.id"));
        assert!(!is_dock_field("pose") && !is_dock_field(".pose") && !is_dock_field("dock1.colour"));
        let missing = dock_database(&config, &extra[..3], None).unwrap_err();
        assert_eq!(missing, "dock `dock2` has no pose: give `dock2.pose: [x, y, yaw]`");
        let bad_frame = [("dock1.frame".to_owned(), ParameterValue::Double(1.0))];
        assert!(dock_database(&config, &bad_frame, None)
            .unwrap_err()
            .contains("dock1.frame must be a string"));
        let file =
            "docks:\n  home:\n    type: charging_dock\n    frame: odom\n    pose: [0.3, -0.2, 3.0]\n    id: c67f\n";
        let db = dock_database(&config, &[], Some(file)).unwrap();
        assert_eq!(db.docks()[0].name, "home");
        assert_eq!(db.docks()[0].id, "c67f");
        assert_eq!(db.get("home").unwrap().pose.yaw, 3.0);
        assert!(dock_database(&config, &[], Some("docks: 3"))
            .unwrap_err()
            .starts_with("no `docks:`"));
        assert!(dock_database(&config, &[], Some("docks: {a: {pose: [1, x, 0]}}")).is_err());
        assert!(dock_database(&config, &[], Some(": : :"))
            .unwrap_err()
            .starts_with("not YAML"));
    }
}
