//! Parameter groups every motion node shares, declared once here and nested by each node
//! ([`crate::config::Decl::nest`]), so a name, its default, range and description are the same
//! wherever they appear: the frames a node reads odometry and goals in ([`Frames`]), the
//! timeouts of its goals ([`GoalTimeouts`]) and Nav2's controller role ([`Controller`]). The chassis group is [`crate::chassis`].
//!
//! ```
//! use mobil_ros::config::{Config, Decl};
//! use mobil_ros::groups::{Frames, GoalTimeouts};
//!
//! #[derive(Debug, Clone, Default)]
//! struct NavConfig {
//!     frames: Frames,
//!     timeouts: GoalTimeouts,
//! }
//!
//! impl Config for NavConfig {
//!     fn declare(d: &mut Decl<Self>) {
//!         d.nest(|c: &mut NavConfig| &mut c.frames, Frames::declare);
//!         d.nest(|c: &mut NavConfig| &mut c.timeouts, GoalTimeouts::declare);
//!     }
//! }
//!
//! let specs = Decl::<NavConfig>::of().specs();
//! let names: Vec<&str> = specs.iter().map(|s| s.name.as_str()).collect();
//! assert_eq!(names, ["odom_frame", "base_frame", "odom_timeout_s", "clock_timeout_s", "result_timeout_s"]);
//! ```

use crate::config::Decl;
use crate::time::seconds;
use mobil_motion::progress::ProgressSettings;
use std::time::Duration;

pub use mobil_motion::MAX_INPUT_TIMEOUT_S;
/// The largest `result_timeout_s` (s).
pub const MAX_RESULT_TIMEOUT_S: f64 = 3600.0;

/// Nav2's controller role (`follow_path`): its progress checker, and the spacing of the
/// sub-goals a path becomes ([`mobil_geom::path::PathGoals`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Controller {
    /// Nav2's progress checker (`required_movement_radius`, `movement_time_allowance`).
    pub progress: ProgressSettings,
    /// The sub-goals' spacing along a path (`path_lookahead`, m).
    pub path_lookahead: f64,
    /// The oldest a transform from a goal's frame to the odometry frame may be
    /// (`transform_tolerance`, s).
    pub transform_tolerance: f64,
}

/// Nav2's progress checker defaults, sub-goals 1 m apart (the declared defaults).
impl Default for Controller {
    fn default() -> Self {
        Controller {
            progress: ProgressSettings::default(),
            path_lookahead: 1.0,
            transform_tolerance: 0.1,
        }
    }
}

impl Controller {
    /// Declares Nav2's `required_movement_radius` (0.5 m) and `movement_time_allowance`
    /// (10 s, ROS time), and `path_lookahead` (1 m, up to 100 m).
    pub fn declare(d: &mut Decl<Controller>) {
        let p = ProgressSettings::default();
        d.double(
            "required_movement_radius",
            p.required_movement_radius,
            "progress checker: the robot must move this far … [m]",
            |c, v| c.progress.required_movement_radius = v,
        )
        .above(0.0);
        d.double(
            "movement_time_allowance",
            p.movement_time_allowance,
            "… within this time (ROS time), else the goal fails ABORTED (FAILED_TO_MAKE_PROGRESS) [s]",
            |c, v| c.progress.movement_time_allowance = v,
        )
        .above(0.0);
        d.double(
            "path_lookahead",
            Controller::default().path_lookahead,
            "follow_path: the path becomes sub-goals this far apart along it, the path's end last; the \
             next one is taken within half of it (planner_node's VFO: at vfo.switch_epsilon) [m]",
            |c, v| c.path_lookahead = v,
        )
        .above(0.0)
        .max(100.0);
        d.double(
            "transform_tolerance",
            Controller::default().transform_tolerance,
            "a goal in another frame than odom_frame needs a transform from it to odom_frame on tf or tf_static \
             no older than this (ROS time), else it is refused or ends TF_ERROR [s]",
            |c, v| c.transform_tolerance = v,
        )
        .within(0.0, 10.0);
    }

    /// `transform_tolerance` as a duration.
    pub fn transform_tolerance(&self) -> Duration {
        seconds(self.transform_tolerance, 10.0)
    }
}

/// The frames of odometry and goals.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frames {
    /// The frame of odometry, in which a goal in another frame is followed (`odom_frame`).
    pub odom_frame: String,
    /// The robot frame, its reference point (`base_frame`).
    pub base_frame: String,
}

impl Frames {
    /// Declares `odom_frame` (`odom`) and `base_frame` (`base_link`), both read-only.
    pub fn declare(d: &mut Decl<Frames>) {
        d.string(
            "odom_frame",
            "odom",
            "frame of odom; a goal in another frame is followed through tf (transform_tolerance)",
            |c, v| c.odom_frame = v,
        )
        .read_only();
        d.string("base_frame", "base_link", "robot frame (reference point)", |c, v| {
            c.base_frame = v
        })
        .read_only();
    }
}

/// How long a goal waits for odometry, and its result for the client.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GoalTimeouts {
    /// A goal ends `STALE_INPUT` when no valid odometry arrived for this long (s, steady clock).
    pub odom_timeout_s: f64,
    /// A goal's robot is held while ROS time has not advanced for this long (s, steady clock).
    pub clock_timeout_s: f64,
    /// How long an ended action goal's result is kept for its clients (s).
    pub result_timeout_s: f64,
}

impl GoalTimeouts {
    /// Declares `odom_timeout_s` and `clock_timeout_s` (0.5 s, up to [`MAX_INPUT_TIMEOUT_S`])
    /// and `result_timeout_s`
    /// (10 s, up to [`MAX_RESULT_TIMEOUT_S`], read-only: the action servers take it at start).
    pub fn declare(d: &mut Decl<GoalTimeouts>) {
        d.double(
            "odom_timeout_s",
            0.5,
            "a goal is aborted when no valid odom arrived for this long (steady clock) [s]",
            |c, v| c.odom_timeout_s = v,
        )
        .above(0.0)
        .max(MAX_INPUT_TIMEOUT_S);
        d.double(
            "clock_timeout_s",
            0.5,
            "a goal's robot is held (zero cmd_vel, STALE_INPUT) while ROS time has not advanced for this long \
             (a paused or stalled /clock; steady clock) [s]",
            |c, v| c.clock_timeout_s = v,
        )
        .above(0.0)
        .max(MAX_INPUT_TIMEOUT_S);
        d.double(
            "result_timeout_s",
            10.0,
            "how long an ended action goal's result is kept for its clients' get_result requests (Nav2's \
             action_server_result_timeout) [s]",
            |c, v| c.result_timeout_s = v,
        )
        .above(0.0)
        .max(MAX_RESULT_TIMEOUT_S)
        .read_only();
    }

    /// How long odometry may be missing.
    pub fn odom_timeout(&self) -> Duration {
        seconds(self.odom_timeout_s, MAX_INPUT_TIMEOUT_S)
    }

    /// How long ROS time may stand still before a goal's robot is held.
    pub fn clock_timeout(&self) -> Duration {
        seconds(self.clock_timeout_s, MAX_INPUT_TIMEOUT_S)
    }

    /// How long an ended action goal's result is kept for its clients.
    pub fn result_timeout(&self) -> Duration {
        seconds(self.result_timeout_s, MAX_RESULT_TIMEOUT_S)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{load, Config};
    use crate::params::ParamValues;
    use ros2_client::ParameterValue;

    #[derive(Debug, Clone, Default)]
    struct Node {
        frames: Frames,
        timeouts: GoalTimeouts,
    }

    impl Config for Node {
        fn declare(d: &mut Decl<Self>) {
            d.nest(|c: &mut Node| &mut c.frames, Frames::declare);
            d.nest(|c: &mut Node| &mut c.timeouts, GoalTimeouts::declare);
        }
    }

    #[test]
    fn the_groups_declare_their_defaults_bounds_and_read_only_flags() {
        let specs = Decl::<Node>::of().specs();
        let spec = |name: &str| specs.iter().find(|s| s.name == name).unwrap();
        let c: Node = load(&ParamValues::defaults(&specs)).unwrap();
        assert_eq!(
            (c.frames.odom_frame.as_str(), c.frames.base_frame.as_str()),
            ("odom", "base_link")
        );
        assert_eq!(c.timeouts.odom_timeout(), Duration::from_millis(500));
        assert_eq!(c.timeouts.clock_timeout(), Duration::from_millis(500));
        assert_eq!(c.timeouts.result_timeout(), Duration::from_secs(10));
        for name in ["odom_frame", "base_frame", "result_timeout_s"] {
            assert!(spec(name).read_only, "{name}");
        }
        assert!(!spec("odom_timeout_s").read_only && !spec("clock_timeout_s").read_only);
        // 1e300 s is finite and positive, and would panic in Duration::from_secs_f64.
        for (name, max) in [
            ("odom_timeout_s", 60.0),
            ("clock_timeout_s", 60.0),
            ("result_timeout_s", 3600.0),
        ] {
            let check = |v: f64| spec(name).check(&ParameterValue::Double(v));
            assert!(check(1e300).is_err() && check(0.0).is_err(), "{name}");
            assert!(check(max).is_ok() && check(max * 1.001).is_err(), "{name}");
        }
        let t = GoalTimeouts {
            odom_timeout_s: f64::NAN,
            clock_timeout_s: 0.5,
            result_timeout_s: 1e300,
        };
        assert_eq!(
            (t.odom_timeout(), t.result_timeout()),
            (Duration::from_secs(60), Duration::from_secs(3600))
        );
    }
}
