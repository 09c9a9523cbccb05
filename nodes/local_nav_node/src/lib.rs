//! The ROS side of [`mobil_local_nav`]: the `local_nav_node` executable (src/main.rs) and what
//! its shell does that can be checked without DDS — the configuration (every parameter declared
//! once), goal validation, the command clamp, the stale-input decision, how a goal ends (status
//! reason and Nav2 error code), and the status and marker messages.
//!
//! The method itself (sectors, the vector-distance function, the R/L/T modes, the progress
//! checker) is in [`mobil_local_nav`]; nothing here decides where the robot goes.

#![warn(missing_docs)]

use mobil_chassis::model::ChassisConfig;
use mobil_geom::path::PathGoals;
use mobil_geom::Pose2;
use mobil_local_nav::{
    Mode, MotionLimits, NavConfig, ProgressChecker, ProgressSettings, Sectors, Side, TrackMethod, UnseenSectors,
    WeightProfile,
};
use mobil_motion::{Nav2Codes, Outcome};
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::{Point, PoseStamped};
use mobil_msgs::nav2_msgs::action::FollowPathGoal;
use mobil_msgs::visualization_msgs::msg::{Marker, MarkerArray};
use mobil_ros::chassis::{chassis_params, declare_chassis};
use mobil_ros::cmd_vel::CmdVelType;
use mobil_ros::config::{Config, ConfigError, Decl};
use mobil_ros::goal::goal_pose;
pub use mobil_ros::goal::{goal_heading, GoalError};
use mobil_ros::groups::{Controller, Frames, GoalTimeouts, MAX_INPUT_TIMEOUT_S};
use mobil_ros::lifecycle::Managed;
use mobil_ros::markers::{point, rgb, Markers};
use mobil_ros::motion::EndCause;
use mobil_ros::scan::LaserParams;
use mobil_ros::status::end_state;
use mobil_ros::time::seconds;
use nalgebra::{Point2, Vector2};
use std::time::Duration;

/// Nav2's Jazzy error codes used in `NavigateToPose` results. Jazzy's NavigateToPose defines
/// only `NONE`; its navigator passes on the code of the failing server, so a failure here gets
/// the code Nav2's controller (`FollowPath`, 100…) or planner (`ComputePathToPose`, 200…) server
/// gives the same failure.
pub mod nav2_error {
    pub use mobil_motion::nav2::compute_path::NO_VALID_PATH;
    pub use mobil_motion::nav2::follow_path::{
        DEFAULT_CONTROLLER_ID, FAILED_TO_MAKE_PROGRESS, INVALID_CONTROLLER, INVALID_PATH, NONE, NO_VALID_CONTROL,
        TF_ERROR, UNKNOWN,
    };
}

/// Everything the node is configured with, each field filled by one declared parameter.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LocalNavConfig {
    /// The chassis geometry and limits (the params file's `/**` section).
    pub chassis: ChassisConfig,
    /// The navigator's configuration (weights filled from `weights` or the default profile).
    pub nav: NavConfig,
    /// The weight profile as given (empty: the default profile for `sector_count`).
    pub weights: Vec<f64>,
    /// Nav2's controller role: the progress checker, `follow_path`'s sub-goal spacing.
    pub controller: Controller,
    /// A goal fails STALE_INPUT when no scan arrived for this long (steady clock), in seconds.
    pub scan_timeout_s: f64,
    /// Status and markers rate while a goal is active, in Hz.
    pub status_rate_hz: f64,
    /// How long a goal waits for odometry, and its result for the client.
    pub timeouts: GoalTimeouts,
    /// The frames of odometry, goals and the robot.
    pub frames: Frames,
    /// The laser's frame and `laser_pose` parameter.
    pub laser: LaserParams,
    /// The managed-node parameters (`autostart`, `bond_heartbeat_period`).
    pub managed: Managed,
    /// `cmd_vel`'s type (`enable_stamped_cmd_vel`).
    pub cmd_vel: CmdVelType,
}

impl Config for LocalNavConfig {
    fn declare(d: &mut Decl<Self>) {
        let n = NavConfig::default();
        d.nest(|c: &mut LocalNavConfig| &mut c.chassis, declare_chassis);
        d.double(
            "robot_radius",
            n.robot_radius,
            "radius of the circle around the body, centred on the reference point [m]",
            |c, v| c.nav.robot_radius = v,
        )
        .min(0.0);
        d.count(
            "sector_count",
            n.sector_count,
            "N, the number of sectors the scan is reduced to (eq. 3.50)",
            |c, v| c.nav.sector_count = v,
        )
        .within(4.0, 360.0);
        d.double_list(
            "weights",
            &[],
            "w'0 … w'(N−1) of the right-turning set (eq. 3.53–3.55); empty: the default linear profile",
            |c, v| c.weights = v,
        );
        d.string(
            "unseen_sectors",
            "blocked",
            "sectors outside the scan's field of view: blocked (|f| = 0) or free (|f| = d_sa)",
            |c, v| {
                c.nav.unseen = if v == "free" {
                    UnseenSectors::Free
                } else {
                    UnseenSectors::Blocked
                }
            },
        )
        .choices(&["blocked", "free"]);
        d.double(
            "stop_distance",
            n.stop_distance,
            "hard stop: no forward motion with an obstacle nearer than this ahead [m]",
            |c, v| c.nav.stop_distance = v,
        )
        .above(0.0);
        d.double(
            "safe_distance",
            n.safe_distance,
            "d_sa, the safe distance (eq. 3.52) and the boundary-following distance [m]",
            |c, v| c.nav.safe_distance = v,
        )
        .above(0.0);
        d.double(
            "release_hysteresis",
            n.release_hysteresis,
            "added to d_sa before a blocked goal sector counts as clear again [m]",
            |c, v| c.nav.release_hysteresis = v,
        )
        .min(0.0);
        d.double(
            "step_length",
            n.step_length,
            "ds, the path increment that makes one step [m]",
            |c, v| c.nav.step_length = v,
        )
        .above(0.0);
        d.count(
            "lock_steps",
            n.lock_steps,
            "n: L-mode steps over which the progress must reach c1 (eq. 3.58)",
            |c, v| c.nav.lock_steps = v,
        )
        .within(1.0, 1e6);
        d.double(
            "lock_min_progress",
            n.lock_min_progress,
            "c1: least progress toward G over n steps in L-mode, else hit point H [m]",
            |c, v| c.nav.lock_min_progress = v,
        );
        d.count(
            "track_steps",
            n.track_steps,
            "m: T-mode steps over which the progress must reach c2 (eq. 3.60)",
            |c, v| c.nav.track_steps = v,
        )
        .within(1.0, 1e6);
        d.double(
            "track_min_progress",
            n.track_min_progress,
            "c2: least progress toward G over m steps in T-mode, else NO_PATH [m]",
            |c, v| c.nav.track_min_progress = v,
        );
        d.double(
            "stall_speed",
            n.stall_speed,
            "an L-mode command slower than this is a stall: hit point H at once [m/s]",
            |c, v| c.nav.stall_speed = v,
        )
        .min(0.0);
        d.double(
            "min_turn_speed",
            n.min_turn_speed,
            "car-like: least speed of a turn whose arc is clear of the scan [m/s]",
            |c, v| c.nav.min_turn_speed = v,
        )
        .min(0.0);
        d.double(
            "hit_radius",
            n.hit_radius,
            "a return within this of H (after leaving twice as far) is NO_PATH [m]",
            |c, v| c.nav.hit_radius = v,
        )
        .above(0.0);
        d.double(
            "xy_goal_tolerance",
            n.goal_tolerance,
            "the goal is reached within this distance (Nav2's name) [m]",
            |c, v| c.nav.goal_tolerance = v,
        )
        .above(0.0);
        d.double(
            "slow_down_radius",
            n.slow_down_radius,
            "the speed falls linearly toward zero inside this distance to the goal [m]",
            |c, v| c.nav.slow_down_radius = v,
        )
        .above(0.0);
        d.double(
            "track_gain",
            n.track_gain,
            "T-mode (track_method tangent): bend of the tracking direction per metre of distance error [rad/m]",
            |c, v| c.nav.track_gain = v,
        )
        .min(0.0);
        d.parsed::<TrackMethod>(
            "track_method",
            n.track_method.name(),
            "T-mode's direction: tangent (the nearest reading's tangent), vector_distance (eq. 3.50 with the chosen side's weights) or off (rotate and lock only, for experiments: no NO_PATH verdict)",
            |c, v| c.nav.track_method = v,
        )
        .choices(&TrackMethod::NAMES);
        d.double(
            "heading_gain",
            n.heading_gain,
            "omni: gain of the turn toward a direction outside the field of view, and in T-mode toward the direction of motion [1/s]",
            |c, v| c.nav.heading_gain = v,
        )
        .above(0.0);
        d.double(
            "scan_timeout_s",
            0.5,
            "a goal fails STALE_INPUT when no valid scan arrived for this long (steady clock) [s]",
            |c, v| c.scan_timeout_s = v,
        )
        .above(0.0)
        .max(MAX_INPUT_TIMEOUT_S);
        d.double(
            "status_rate_hz",
            2.0,
            "local_nav/status and markers rate while a goal is active (action feedback: 20 Hz) [Hz]",
            |c, v| c.status_rate_hz = v,
        )
        .within(0.1, 50.0);
        d.nest(|c: &mut LocalNavConfig| &mut c.controller, Controller::declare);
        d.nest(|c: &mut LocalNavConfig| &mut c.timeouts, GoalTimeouts::declare);
        d.nest(|c: &mut LocalNavConfig| &mut c.managed, Managed::declare);
        d.nest(|c: &mut LocalNavConfig| &mut c.cmd_vel, CmdVelType::declare);
        d.nest(|c: &mut LocalNavConfig| &mut c.frames, Frames::declare);
        d.nest(|c: &mut LocalNavConfig| &mut c.laser, LaserParams::declare);
    }

    fn validate(&self) -> Result<(), ConfigError> {
        self.laser.validate()?;
        self.motion_limits()?;
        self.nav_config()?;
        if self.controller.path_lookahead / 2.0 <= self.nav.goal_tolerance {
            return Err(ConfigError::inconsistent(format!(
                "path_lookahead {} m: half of it must be above xy_goal_tolerance {} m (a sub-goal \
                 would be reached before the next is taken)",
                self.controller.path_lookahead, self.nav.goal_tolerance
            )));
        }
        Ok(())
    }
}

impl LocalNavConfig {
    /// The navigator's configuration: the declared fields and the weight profile (the given
    /// one, checked against eq. 3.53–3.55, or the default linear one for N sectors).
    pub fn nav_config(&self) -> Result<NavConfig, ConfigError> {
        let mut nav = self.nav.clone();
        nav.weights = if self.weights.is_empty() {
            WeightProfile::linear(nav.sector_count)
        } else {
            WeightProfile::new(self.weights.clone()).map_err(ConfigError::inconsistent)?
        };
        nav.validate().map_err(ConfigError::inconsistent)?;
        Ok(nav)
    }

    /// The chassis limits the commands respect (δ_eff for a car-like chassis).
    pub fn motion_limits(&self) -> Result<MotionLimits, ConfigError> {
        Ok(MotionLimits::from_chassis(&chassis_params(&self.chassis)?))
    }

    /// The laser pose parameter as a pose; `None` when not set (or not finite).
    pub fn laser_pose(&self) -> Option<Pose2> {
        self.laser.pose()
    }

    /// The scan timeout.
    pub fn scan_timeout(&self) -> Duration {
        seconds(self.scan_timeout_s, MAX_INPUT_TIMEOUT_S)
    }
}

/// The goal point in `frame` (the goal's own, resolved by [`mobil_ros::tf::GoalTf::frame_of`]),
/// or why it is refused ([`mobil_ros::goal::goal_pose`]: anything non-finite, a coordinate
/// beyond ±10 km).
pub fn goal_point(goal: &PoseStamped, frame: &str) -> Result<Point2<f64>, GoalError> {
    goal_pose("goal", goal, frame).map(|p| p.position())
}

/// The progress checker after a parameter change: the same one (its window and anchor kept)
/// unless its own settings changed, so that setting other parameters again and again cannot
/// keep a stuck goal alive.
pub fn reconfigured_progress(old: ProgressChecker, settings: ProgressSettings) -> ProgressChecker {
    if old.settings() == settings {
        old
    } else {
        ProgressChecker::new(settings)
    }
}

/// The mode's name in the status: idle, rotate, lock_left, lock_right, track_left, track_right,
/// reached, no_path.
pub fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Idle => "idle",
        Mode::Rotate => "rotate",
        Mode::Lock(Side::Left) => "lock_left",
        Mode::Lock(Side::Right) => "lock_right",
        Mode::Track(Side::Left) => "track_left",
        Mode::Track(Side::Right) => "track_right",
        Mode::Reached => "reached",
        Mode::NoPath(_) => "no_path",
    }
}

/// What the markers show: the sectors and F (base frame), the goal, H and L (odom).
#[derive(Debug, Clone, Copy)]
pub struct MarkerView<'a> {
    /// The sectors of the last step.
    pub sectors: &'a Sectors,
    /// The direction the robot was sent (base frame), scaled as the navigator gave it.
    pub direction: Vector2<f64>,
    /// The goal.
    pub goal: Option<Point2<f64>>,
    /// Hit point H.
    pub hit_point: Option<Point2<f64>>,
    /// Leave point L.
    pub leave_point: Option<Point2<f64>>,
}

/// Longest sector vector drawn (m): an open sector is drawn at this length.
const MAX_DRAWN: f64 = 5.0;

/// The marker array: one LINE_LIST of the N sector vectors (each along its centre, as long as
/// its effective distance, at most 5 m), one ARROW for F, and a SPHERE each for the goal, H and
/// L when known (a DELETE for those not, so RViz drops stale ones). At most 5 markers and
/// 2·N + 2 points: a few kilobytes.
pub fn markers(view: &MarkerView<'_>, stamp: Time, odom_frame: &str, base_frame: &str) -> MarkerArray {
    let mut m = Markers::new(stamp, base_frame);
    let tips = (0..view.sectors.len()).flat_map(|i| {
        let d = view.sectors.effective_distance(i).min(MAX_DRAWN);
        let d = if d.is_finite() { d } else { 0.0 };
        let (s, c) = view.sectors.bearing(i).sin_cos();
        [Point2::origin(), Point2::new(d * c, d * s)]
    });
    m.line_list(NS, 0, tips, 0.02, rgb(0.2, 0.6, 1.0));
    let tip = if view.direction.iter().all(|v| v.is_finite()) {
        view.direction
    } else {
        Vector2::zeros()
    };
    let f = m.add(NS, 1, Marker::ARROW, [0.05, 0.1, 0.1], rgb(1.0, 0.5, 0.0));
    f.points = vec![Point::default(), point(Point2::from(tip))];
    m.set_frame(odom_frame);
    let spots = [
        (2, view.goal, rgb(0.0, 0.8, 0.0)),
        (3, view.hit_point, rgb(0.9, 0.0, 0.0)),
        (4, view.leave_point, rgb(0.8, 0.0, 0.8)),
    ];
    for (id, at, c) in spots {
        match at {
            Some(p) if p.x.is_finite() && p.y.is_finite() => {
                m.sphere(NS, id, p, 0.15, c);
            }
            _ => m.delete(NS, id),
        }
    }
    m.array()
}

/// The namespace of every local_nav marker.
const NS: &str = "local_nav";

/// The marker array that removes every local_nav marker (sent when a goal ends, so RViz does not
/// keep showing the sectors and points of a goal that is over).
pub fn clear_markers(stamp: Time, frame: &str) -> MarkerArray {
    Markers::replacing(stamp, frame).array()
}

/// How the progress checker ends a goal ([`mobil_motion::progress::no_progress`]).
pub fn no_progress(since: f64, radius: f64) -> EndCause {
    EndCause::Outcome(mobil_motion::progress::no_progress(since, radius))
}

/// How a goal's end is told: the status state, the status reason (also the action's
/// `error_msg`) and `navigate_to_pose`'s error code. Stale or refused input is Nav2's
/// `NO_VALID_CONTROL`, a shutdown `UNKNOWN`, a cancel or a pre-emption no error.
pub fn end_answer(cause: &EndCause) -> (u8, String, u16) {
    (
        end_state(cause),
        cause.reason(),
        cause.nav2_error(Nav2Codes::FOLLOW_PATH),
    )
}

/// The `controller_id`s `follow_path` takes: the node's one law, by its name, by none, or by the
/// name of Nav2's default controller plugin (`FollowPath`, what Nav2's default trees send).
pub const CONTROLLERS: [&str; 3] = ["", "vector_distance", nav2_error::DEFAULT_CONTROLLER_ID];

/// A `follow_path` goal as sub-goals for a robot at `from` (in the path's frame), or the end
/// Nav2's controller server gives such a goal at once: INVALID_CONTROLLER for a
/// `controller_id` not in [`CONTROLLERS`], INVALID_PATH for an empty path or a non-finite
/// pose. Its frame's transform (TF_ERROR) is checked by the node.
pub fn follow_path_goal(goal: &FollowPathGoal, from: Point2<f64>, lookahead: f64) -> Result<PathGoals, Outcome> {
    if !CONTROLLERS.contains(&goal.controller_id.as_str()) {
        return Err(Outcome::failed(
            "INVALID_CONTROLLER",
            format!(
                "controller_id `{}`: this node's controller is `vector_distance` (or empty, or `FollowPath`)",
                goal.controller_id
            ),
            nav2_error::INVALID_CONTROLLER,
        ));
    }
    mobil_ros::goal::path_goals(&goal.path, from, lookahead)
}

/// The status reason of a refused goal.
pub fn invalid_goal(e: &GoalError) -> String {
    format!("INVALID_GOAL: {e}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use mobil_geom::Scan;
    use mobil_local_nav::Drive;
    use mobil_msgs::mobil_msgs::msg::NavStatus;
    use mobil_ros::params::ParamValues;

    fn path_goal(points: &[(f64, f64)], frame: &str, controller: &str) -> FollowPathGoal {
        let mut g = FollowPathGoal::default();
        g.path.header.frame_id = frame.to_owned();
        g.controller_id = controller.to_owned();
        for &(x, y) in points {
            let mut p = PoseStamped::default();
            (p.pose.position.x, p.pose.position.y) = (x, y);
            g.path.poses.push(p);
        }
        g
    }

    /// Nav2's codes for goals that cannot be followed; a good one gives sub-goals a lookahead
    /// apart from the robot's nearest point.
    #[test]
    fn follow_path_goals_are_checked_with_nav2_codes() {
        let from = Point2::new(0.0, 0.0);
        let code = |g: &FollowPathGoal| follow_path_goal(g, from, 1.0).unwrap_err().nav2_error();
        assert_eq!(code(&path_goal(&[(1.0, 0.0)], "odom", "dwb")), 101);
        assert_eq!(code(&path_goal(&[], "odom", "")), 103);
        assert_eq!(code(&path_goal(&[(0.0, 0.0), (f64::NAN, 1.0)], "odom", "")), 103);
        assert!(follow_path_goal(&path_goal(&[(1.0, 0.0)], "odom", "FollowPath"), from, 1.0).is_ok());
        let ok = follow_path_goal(&path_goal(&[(0.0, 0.0), (2.5, 0.0)], "", "vector_distance"), from, 1.0);
        assert_eq!(
            ok.unwrap().goals(),
            &[Point2::new(1.0, 0.0), Point2::new(2.0, 0.0), Point2::new(2.5, 0.0)]
        );
    }

    #[test]
    fn defaults_build_the_library_defaults_and_bad_weights_are_refused() {
        let mut values = ParamValues::defaults(&Decl::<LocalNavConfig>::of().specs());
        let c: LocalNavConfig = mobil_ros::config::load(&values).unwrap();
        assert_eq!(c.nav_config().unwrap(), NavConfig::default());
        assert_eq!(c.controller.progress, ProgressSettings::default());
        // MOBIL-II chassis defaults: car-like, κ_max = 1 / 0.73.
        match c.motion_limits().unwrap().drive {
            Drive::CarLike { max_curvature } => assert!((max_curvature - 1.0 / 0.73).abs() < 1e-9),
            Drive::Omni => panic!("default chassis is MOBIL-II"),
        }
        // w'1 = 0.4 < w'7 = 0.5 breaks eq. 3.54: refused with the equation named.
        values.set(
            "weights",
            ros2_client::ParameterValue::DoubleArray(vec![1.0, 0.4, 0.3, 0.2, 0.1, 0.1, 0.1, 0.5]),
        );
        let e = mobil_ros::config::load::<LocalNavConfig>(&values).unwrap_err();
        assert!(e.to_string().contains("3.54"), "{e}");
        // Twelve sectors with eight weights: refused.
        values.set("weights", ros2_client::ParameterValue::DoubleArray(vec![]));
        values.set("sector_count", ros2_client::ParameterValue::Integer(12));
        let c: LocalNavConfig = mobil_ros::config::load(&values).unwrap();
        assert_eq!(c.nav_config().unwrap().weights.len(), 12);
        values.set("stop_distance", ros2_client::ParameterValue::Double(0.9));
        assert!(mobil_ros::config::load::<LocalNavConfig>(&values).is_err());
    }

    #[test]
    fn markers_stay_small_and_draw_the_sectors() {
        // Eight beams on the sector centres (−180° + 45°·k), all at 2 m except straight ahead
        // (the goal's sector 0) at 1 m.
        let ranges: Vec<f32> = (0..8).map(|k| if k == 4 { 1.0 } else { 2.0 }).collect();
        let step = std::f64::consts::FRAC_PI_4;
        let scan = Scan::new(
            -std::f64::consts::PI,
            0.75 * std::f64::consts::PI,
            step,
            0.05,
            10.0,
            ranges,
            vec![],
            Pose2::identity(),
        )
        .unwrap();
        let sectors = Sectors::compute(&scan, 0.0, 8, UnseenSectors::Blocked);
        let view = MarkerView {
            sectors: &sectors,
            direction: Vector2::new(0.5, 0.0),
            goal: Some(Point2::new(3.0, 0.0)),
            hit_point: None,
            leave_point: Some(Point2::new(1.0, 1.0)),
        };
        let a = markers(&view, Time::default(), "odom", "base_link");
        assert_eq!(a.markers.len(), 5);
        let lines = &a.markers[0];
        assert_eq!(lines.points.len(), 16);
        // Sector 0 straight ahead at 1 m; sector 2 at −90° at 2 m.
        assert!((lines.points[1].x - 1.0).abs() < 1e-9 && lines.points[1].y.abs() < 1e-9);
        assert!(lines.points[5].x.abs() < 1e-9 && (lines.points[5].y + 2.0).abs() < 1e-9);
        assert_eq!(a.markers[3].action, Marker::DELETE);
        assert_eq!(a.markers[4].pose.position.x, 1.0);
        assert_eq!(a.markers[2].header.frame_id, "odom");
        let cleared = clear_markers(Time::default(), "odom");
        assert_eq!(cleared.markers.len(), 1);
        assert_eq!(cleared.markers[0].action, Marker::DELETEALL);
    }

    #[test]
    fn timeouts_are_bounded_and_never_panic() {
        let specs = Decl::<LocalNavConfig>::of().specs();
        let mut values = ParamValues::defaults(&specs);
        // 1e300 s is finite and positive, and used to panic in Duration::from_secs_f64.
        let spec = |name: &str| specs.iter().find(|s| s.name == name).unwrap();
        for (name, max) in [
            ("scan_timeout_s", 60.0),
            ("odom_timeout_s", 60.0),
            ("result_timeout_s", 3600.0),
        ] {
            let check = |v: f64| spec(name).check(&ros2_client::ParameterValue::Double(v));
            assert!(check(1e300).is_err(), "{name}");
            assert!(check(max).is_ok() && check(max * 1.001).is_err(), "{name}");
            assert!(check(0.0).is_err(), "{name}");
        }
        values.set("odom_timeout_s", ros2_client::ParameterValue::Double(2.5));
        values.set("scan_timeout_s", ros2_client::ParameterValue::Double(60.0));
        values.set("result_timeout_s", ros2_client::ParameterValue::Double(3600.0));
        let c: LocalNavConfig = mobil_ros::config::load(&values).unwrap();
        assert_eq!(c.scan_timeout(), Duration::from_secs(60));
        assert_eq!(c.timeouts.odom_timeout(), Duration::from_millis(2500));
        assert_eq!(c.timeouts.result_timeout(), Duration::from_secs(3600));
        // The result timeout is read once, at start-up.
        assert!(specs.iter().any(|s| s.name == "result_timeout_s" && s.read_only));
    }

    #[test]
    fn laser_pose_is_unset_by_default_and_takes_three_values() {
        let mut values = ParamValues::defaults(&Decl::<LocalNavConfig>::of().specs());
        let c: LocalNavConfig = mobil_ros::config::load(&values).unwrap();
        assert_eq!(c.laser_pose(), None);
        values.set(
            "laser_pose",
            ros2_client::ParameterValue::DoubleArray(vec![0.2, -0.1, 0.5]),
        );
        let c: LocalNavConfig = mobil_ros::config::load(&values).unwrap();
        assert_eq!(c.laser_pose(), Some(Pose2::new(0.2, -0.1, 0.5)));
        values.set("laser_pose", ros2_client::ParameterValue::DoubleArray(vec![0.2, -0.1]));
        assert!(mobil_ros::config::load::<LocalNavConfig>(&values).is_err());
    }

    #[test]
    fn track_method_reaches_the_navigator_and_unknown_names_are_refused() {
        let mut values = ParamValues::defaults(&Decl::<LocalNavConfig>::of().specs());
        let c: LocalNavConfig = mobil_ros::config::load(&values).unwrap();
        assert_eq!(c.nav.track_method, TrackMethod::Tangent);
        for (name, method) in [
            ("vector_distance", TrackMethod::VectorDistance),
            ("off", TrackMethod::Off),
        ] {
            values.set("track_method", ros2_client::ParameterValue::String(name.into()));
            let c: LocalNavConfig = mobil_ros::config::load(&values).unwrap();
            assert_eq!(c.nav.track_method, method);
        }
        values.set("track_method", ros2_client::ParameterValue::String("bug2".into()));
        let e = mobil_ros::config::load::<LocalNavConfig>(&values)
            .unwrap_err()
            .to_string();
        assert!(e.contains("bug2"), "{e}");
    }

    #[test]
    fn a_parameter_change_keeps_the_progress_window_unless_its_settings_change() {
        let settings = ProgressSettings {
            required_movement_radius: 0.5,
            movement_time_allowance: 10.0,
        };
        let mut p = ProgressChecker::new(settings);
        assert_eq!(p.check(Point2::new(0.0, 0.0), 100.0), mobil_local_nav::Progress::Ok);
        // Other parameters set at 105 s: the window opened at 100 s stays, so at 110.5 s the
        // robot (0.1 m on) is stuck for 10.5 s.
        let mut p = reconfigured_progress(p, settings);
        assert_eq!(p.check(Point2::new(0.1, 0.0), 105.0), mobil_local_nav::Progress::Ok);
        assert_eq!(
            p.check(Point2::new(0.1, 0.0), 110.5),
            mobil_local_nav::Progress::Stuck { since: 10.5 }
        );
        // The allowance itself changed: a fresh window from the next check.
        let changed = ProgressSettings {
            movement_time_allowance: 20.0,
            ..settings
        };
        let mut p = reconfigured_progress(p, changed);
        assert_eq!(p.check(Point2::new(0.1, 0.0), 111.0), mobil_local_nav::Progress::Ok);
        assert_eq!(p.check(Point2::new(0.1, 0.0), 130.0), mobil_local_nav::Progress::Ok);
        assert_eq!(
            p.check(Point2::new(0.1, 0.0), 131.5),
            mobil_local_nav::Progress::Stuck { since: 20.5 }
        );
    }

    #[test]
    fn ends_give_status_reasons_and_nav2_codes() {
        use mobil_local_nav::NoPathReason;
        let stale = end_answer(&EndCause::Stale("scan".into()));
        assert_eq!(
            stale,
            (NavStatus::FAILED, "STALE_INPUT: scan stale: robot stopped".into(), 106)
        );
        let no_path = Outcome::failed("NO_PATH", NoPathReason::ReturnedToHitPoint.describe(), 208);
        assert_eq!(
            end_answer(&EndCause::Outcome(no_path)),
            (
                NavStatus::FAILED,
                "NO_PATH: boundary following returned to the hit point".into(),
                208
            )
        );
        assert_eq!(
            end_answer(&no_progress(10.25, 0.5)),
            (
                NavStatus::FAILED,
                "ABORTED: no progress: moved less than 0.5 m in 10.25 s".into(),
                105
            )
        );
        // Two decimals: 1.04 s is not "1.0 s".
        assert_eq!(
            end_answer(&no_progress(1.04, 5.0)).1,
            "ABORTED: no progress: moved less than 5 m in 1.04 s"
        );
        let refused = end_answer(&EndCause::Refused {
            count: 20,
            last: "bad".into(),
        });
        assert_eq!((refused.0, refused.2), (NavStatus::FAILED, 106));
        assert!(refused.1.starts_with("INVALID_INPUT: "), "{}", refused.1);
        let reached = end_answer(&EndCause::Outcome(Outcome::succeeded("goal reached")));
        assert_eq!(reached, (NavStatus::SUCCEEDED, "SUCCEEDED: goal reached".into(), 0));
        assert_eq!(end_answer(&EndCause::Canceled).2, 0);
        assert_eq!(
            end_answer(&EndCause::Preempted("goal_pose")).1,
            "PREEMPTED: preempted by a newer goal (goal_pose)"
        );
        assert_eq!(end_answer(&EndCause::Shutdown).2, 100);
        assert_eq!(
            invalid_goal(&GoalError::NotFinite { what: "goal".into() }),
            "INVALID_GOAL: goal is not finite"
        );
    }
}
