//! Goals from ROS messages, checked: a pose or a route of poses in the frame the node works
//! in, every number finite and in range, or the reason it is refused ([`GoalError`], the text
//! of an `INVALID_GOAL`). Every motion node reads its goals here, so a goal is refused the same
//! way whichever node it was sent to.
//!
//! ```
//! use mobil_msgs::geometry_msgs::msg::PoseStamped;
//! use mobil_ros::goal::{goal_pose, GoalError};
//!
//! let mut g = PoseStamped::default();
//! g.header.frame_id = "/odom".into(); // a leading `/` is ignored, as tf2 ignores it
//! g.pose.position.x = 2.0;
//! g.pose.orientation.w = 1.0;
//! assert_eq!(goal_pose("goal", &g, "odom").unwrap().x, 2.0);
//! g.header.frame_id = "map".into();
//! let e = goal_pose("goal", &g, "odom").unwrap_err();
//! assert_eq!(e.to_string(), "goal in frame `map`, but goals must be in `odom`");
//! ```

use crate::geometry::yaw_of;
use mobil_geom::path::PathGoals;
use mobil_geom::Pose2;
use mobil_motion::{nav2::follow_path, Outcome};
use mobil_msgs::geometry_msgs::msg::{Pose, PoseStamped, Quaternion};
use mobil_msgs::nav2_msgs::action::FollowPathGoal;
use mobil_msgs::nav_msgs::msg::Path;
use nalgebra::Point2;
use thiserror::Error;

/// The largest |x| and |y| of a goal or waypoint (m): farther than any drive can mean, and
/// far from where f64 loses the millimetre.
pub const MAX_GOAL_COORD: f64 = 1e4;

/// Why a goal or route is refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GoalError {
    /// Not in the node's frame.
    #[error("{what} in frame `{got}`, but goals must be in `{want}`")]
    Frame {
        /// What (`goal`, `dock pose`, `waypoint 2`, `route`).
        what: String,
        /// Its frame.
        got: String,
        /// The node's frame.
        want: String,
    },
    /// NaN or infinity in the position or orientation.
    #[error("{what} is not finite")]
    NotFinite {
        /// What (`goal pose`, `waypoint 2`).
        what: String,
    },
    /// A coordinate beyond ±[`MAX_GOAL_COORD`].
    #[error("{what} ({x}, {y}) is beyond ±{MAX_GOAL_COORD} m")]
    TooFar {
        /// What.
        what: String,
        /// x (m).
        x: f64,
        /// y (m).
        y: f64,
    },
    /// A route without waypoints.
    #[error("the route has no waypoints")]
    EmptyRoute,
    /// A route longer than the node takes.
    #[error("the route has {count} waypoints; at most {max} are taken")]
    TooLong {
        /// Waypoints asked for, repeats included.
        count: usize,
        /// The most taken.
        max: usize,
    },
    /// A route whose waypoints all lie on the first one and on the robot: nothing to drive.
    #[error("zero-length route: every waypoint lies within {0} m of the first and of the start")]
    ZeroLength(f64),
    /// `goal_index` beyond the poses.
    #[error("goal_index {index} is not below the {len} poses")]
    GoalIndex {
        /// The index asked for.
        index: u32,
        /// How many poses there are.
        len: usize,
    },
}

/// What a `follow_path` goal names that a node with one goal checker (its tolerance parameter
/// `tolerance`) and one progress checker ignores: one line per non-empty `goal_checker_id` or
/// `progress_checker_id`, for the log.
pub fn ignored_checkers(goal: &FollowPathGoal, tolerance: &str) -> Vec<String> {
    [
        ("goal_checker_id", &goal.goal_checker_id),
        ("progress_checker_id", &goal.progress_checker_id),
    ]
    .into_iter()
    .filter(|(_, id)| !id.is_empty())
    .map(|(what, id)| {
        format!(
            "follow_path: {what} `{id}` ignored: the node has one goal checker ({tolerance}) and one progress checker"
        )
    })
    .collect()
}

/// A `follow_path` goal's path as sub-goals `lookahead` apart for a robot at `from` (in the
/// path's frame), or the end Nav2's controller server gives such a goal at once: INVALID_PATH
/// for an empty path, a non-finite pose, a pose beyond ±10 000 m or a path of more than
/// 100 000 sub-goals. The `controller_id` and the path's frame (TF_ERROR) are the node's to
/// check.
pub fn path_goals(path: &Path, from: Point2<f64>, lookahead: f64) -> Result<PathGoals, Outcome> {
    let points: Vec<Point2<f64>> = path
        .poses
        .iter()
        .map(|p| Point2::new(p.pose.position.x, p.pose.position.y))
        .collect();
    PathGoals::new(&points, from, lookahead)
        .map_err(|e| Outcome::failed("INVALID_PATH", e.to_string(), follow_path::INVALID_PATH))
}

/// The end Nav2's controller server gives a `follow_path` goal whose frame has no usable
/// transform (`why`): TF_ERROR.
pub fn path_tf_error(why: String) -> Outcome {
    Outcome::failed("TF_ERROR", why, follow_path::TF_ERROR)
}

/// Whether frame `got` names frame `want` (a leading `/` ignored on either).
pub fn same_frame(got: &str, want: &str) -> bool {
    got.trim_start_matches('/') == want.trim_start_matches('/')
}

/// `p`, given in `frame`, as a pose in `want`, or why not: the frames must be the same (an
/// empty `frame` is none: a pose names its frame, as tf2 needs), every number finite (the
/// quaternion's too), |x| and |y| within [`MAX_GOAL_COORD`].
pub fn pose_in_frame(what: &str, frame: &str, p: &Pose, want: &str) -> Result<Pose2, GoalError> {
    if !same_frame(frame, want) {
        return Err(GoalError::Frame {
            what: what.to_owned(),
            got: frame.to_owned(),
            want: want.to_owned(),
        });
    }
    let (a, q) = (&p.position, &p.orientation);
    if ![a.x, a.y, a.z, q.x, q.y, q.z, q.w].iter().all(|v| v.is_finite()) {
        return Err(GoalError::NotFinite { what: what.to_owned() });
    }
    if a.x.abs() > MAX_GOAL_COORD || a.y.abs() > MAX_GOAL_COORD {
        return Err(GoalError::TooFar {
            what: what.to_owned(),
            x: a.x,
            y: a.y,
        });
    }
    Ok(Pose2::new(a.x, a.y, yaw_of(q)))
}

/// A goal pose in `frame` ([`pose_in_frame`] with the message's own frame).
pub fn goal_pose(what: &str, goal: &PoseStamped, frame: &str) -> Result<Pose2, GoalError> {
    pose_in_frame(what, &goal.header.frame_id, &goal.pose, frame)
}

/// The heading a goal asks for, when it asks for one: the yaw of its orientation, `None` for
/// the identity (or a quaternion within 1 mrad of it, or a zero one). A node that reaches a
/// position only says the heading is not kept.
pub fn goal_heading(goal: &PoseStamped) -> Option<f64> {
    let q = &goal.pose.orientation;
    let n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
    if !(n.is_finite() && n > 0.0) {
        return None;
    }
    let yaw = yaw_of(q);
    (yaw.abs() > 1e-3).then_some(yaw)
}

/// Whether a quaternion carries an orientation: not all-zero (never set) and not within 1e-6
/// of ±identity.
pub fn oriented(q: &Quaternion) -> bool {
    let unset = q.x == 0.0 && q.y == 0.0 && q.z == 0.0 && q.w == 0.0;
    let identity = q.x.abs() < 1e-6 && q.y.abs() < 1e-6 && q.z.abs() < 1e-6 && (q.w.abs() - 1.0).abs() < 1e-6;
    !(unset || identity)
}

/// A route to drive: the waypoints and, for each, its index in the request (Nav2's
/// FollowWaypoints with `goal_index` or `number_of_loops` skips or repeats poses).
#[derive(Debug, Clone, PartialEq)]
pub struct Route {
    /// The waypoints in driving order (in the node's frame).
    pub points: Vec<Point2<f64>>,
    /// For each, its index in the request's poses.
    pub request_index: Vec<usize>,
    /// The request's poses (a result lists the missed ones with their poses).
    pub poses: Vec<PoseStamped>,
}

impl Route {
    /// The index (in the request) of the first waypoint that carries an orientation
    /// ([`oriented`]).
    pub fn first_oriented(&self) -> Option<usize> {
        self.poses.iter().position(|p| oriented(&p.pose.orientation))
    }

    /// The heading each waypoint asks for, by one rule for the whole route (a ROS pose's
    /// orientation defaults to the identity, so a single identity cannot tell "heading 0" from
    /// "no heading"): in a route in which some pose carries an orientation
    /// ([`Route::first_oriented`]) every waypoint's is its pose's yaw, the identity's 0 rad
    /// included, but for an all-zero quaternion (never set); in any other route none.
    pub fn headings(&self) -> Vec<Option<f64>> {
        let oriented_route = self.first_oriented().is_some();
        (0..self.points.len())
            .map(|k| {
                let q = &self.poses.get(self.request(k))?.pose.orientation;
                let unset = q.x == 0.0 && q.y == 0.0 && q.z == 0.0 && q.w == 0.0;
                (oriented_route && !unset).then(|| yaw_of(q))
            })
            .collect()
    }

    /// The request's index of route waypoint `i` (its own index if none is known).
    pub fn request(&self, i: usize) -> usize {
        self.request_index.get(i).copied().unwrap_or(i)
    }
}

/// What a route must be beyond its poses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RouteLimits {
    /// A route whose every waypoint lies within this of the first and of the robot is
    /// refused as zero-length (m).
    pub min_length: f64,
    /// The most waypoints taken, repeats included.
    pub max_waypoints: usize,
}

/// A route from `poses` (each in `frame`; a pose without a frame takes `default_frame`, the
/// path's own header), starting at `goal_index` and driven `1 + number_of_loops` times (Nav2's
/// FollowWaypoints: later rounds from index 0). Refuses an empty route, other frames, NaN, far
/// points, more than `limits.max_waypoints` in all, and a route of zero length (every waypoint
/// within `limits.min_length` of the first and of `start`, when known).
pub fn route_from_poses(
    poses: &[PoseStamped],
    default_frame: &str,
    frame: &str,
    (goal_index, number_of_loops): (u32, u32),
    start: Option<Point2<f64>>,
    limits: RouteLimits,
) -> Result<Route, GoalError> {
    if poses.is_empty() {
        return Err(GoalError::EmptyRoute);
    }
    let mut points = Vec::with_capacity(poses.len());
    for (i, p) in poses.iter().enumerate() {
        let own = if p.header.frame_id.is_empty() {
            default_frame
        } else {
            &p.header.frame_id
        };
        points.push(pose_in_frame(&format!("waypoint {i}"), own, &p.pose, frame)?.position());
    }
    let first = goal_index as usize;
    if first >= poses.len() {
        return Err(GoalError::GoalIndex {
            index: goal_index,
            len: poses.len(),
        });
    }
    let count = (poses.len() - first).saturating_add(poses.len().saturating_mul(number_of_loops as usize));
    if count > limits.max_waypoints {
        return Err(GoalError::TooLong {
            count,
            max: limits.max_waypoints,
        });
    }
    let mut request_index: Vec<usize> = (first..poses.len()).collect();
    for _ in 0..number_of_loops {
        request_index.extend(0..poses.len());
    }
    let route_points: Vec<Point2<f64>> = request_index.iter().map(|&i| points[i]).collect();
    let (anchor, min) = (route_points[0], limits.min_length);
    let near = |p: &Point2<f64>| (p - anchor).norm() < min && start.is_none_or(|s| (p - s).norm() < min);
    if route_points.iter().all(near) {
        return Err(GoalError::ZeroLength(min));
    }
    Ok(Route {
        points: route_points,
        request_index,
        poses: poses.to_vec(),
    })
}

/// A `nav_msgs/Path` as a route in `frame` (the path's frame for poses without one; a path in
/// another frame is refused as a whole).
pub fn route_from_path(
    path: &Path,
    frame: &str,
    start: Option<Point2<f64>>,
    limits: RouteLimits,
) -> Result<Route, GoalError> {
    let own = &path.header.frame_id;
    if !own.is_empty() && !same_frame(own, frame) {
        return Err(GoalError::Frame {
            what: "route".into(),
            got: own.clone(),
            want: frame.to_owned(),
        });
    }
    let default = if own.is_empty() { frame } else { own };
    route_from_poses(&path.poses, default, frame, (0, 0), start, limits)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A named checker is told as ignored, an empty one not.
    #[test]
    fn named_checkers_are_told_as_ignored() {
        let mut goal = FollowPathGoal::default();
        assert!(ignored_checkers(&goal, "xy_goal_tolerance").is_empty());
        goal.progress_checker_id = "progress".into();
        assert_eq!(
            ignored_checkers(&goal, "xy_goal_tolerance"),
            [
                "follow_path: progress_checker_id `progress` ignored: the node has one goal checker \
              (xy_goal_tolerance) and one progress checker"
            ]
        );
    }
    use crate::geometry::{header_in, pose_stamped, yaw_quaternion};
    use mobil_msgs::std_msgs::msg::Header;

    fn stamped(frame: &str, x: f64, y: f64) -> PoseStamped {
        pose_stamped(header_in(frame), &Pose2::new(x, y, 0.0))
    }

    const LIMITS: RouteLimits = RouteLimits {
        min_length: 0.01,
        max_waypoints: 200,
    };

    #[test]
    fn goals_outside_the_frame_or_with_nan_or_far_are_refused() {
        let g = goal_pose("dock pose", &stamped("odom", 1.5, -0.5), "odom").unwrap();
        assert_eq!((g.x, g.y, g.yaw), (1.5, -0.5, 0.0));
        assert!(goal_pose("goal", &stamped("/odom", 1.0, 0.0), "odom").is_ok());
        let e = goal_pose("goal", &stamped("map", 1.0, 0.0), "odom").unwrap_err();
        assert_eq!(e.to_string(), "goal in frame `map`, but goals must be in `odom`");
        // No frame at all is not the node's frame.
        assert!(matches!(
            goal_pose("goal", &stamped("", 1.0, 0.0), "odom"),
            Err(GoalError::Frame { .. })
        ));
        let e = goal_pose("goal", &stamped("odom", f64::NAN, 0.0), "odom").unwrap_err();
        assert_eq!(e.to_string(), "goal is not finite");
        let mut q = stamped("odom", 1.0, 0.0);
        q.pose.orientation.z = f64::INFINITY;
        assert_eq!(
            goal_pose("dock pose", &q, "odom"),
            Err(GoalError::NotFinite {
                what: "dock pose".into()
            })
        );
        // 1e4 m is the last accepted coordinate; 1e200 (finite) and −10 000.5 are refused.
        assert!(goal_pose("goal", &stamped("odom", 1e4, -1e4), "odom").is_ok());
        let e = goal_pose("goal", &stamped("odom", 2e4, 0.0), "odom").unwrap_err();
        assert_eq!(e.to_string(), "goal (20000, 0) is beyond ±10000 m");
        assert!(matches!(
            goal_pose("goal", &stamped("odom", 0.0, -10_000.5), "odom"),
            Err(GoalError::TooFar { .. })
        ));
    }

    #[test]
    fn a_goal_heading_and_a_waypoint_orientation_are_noticed_only_when_given() {
        let mut g = stamped("odom", 1.0, 0.0);
        assert_eq!(goal_heading(&g), None);
        // 90°: (0, 0, sin 45°, cos 45°).
        g.pose.orientation = yaw_quaternion(std::f64::consts::FRAC_PI_2);
        let yaw = goal_heading(&g).unwrap();
        assert!((yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!(oriented(&g.pose.orientation));
        // An all-zero quaternion (tools without RViz often send it) asks for nothing.
        g.pose.orientation = Quaternion::default();
        g.pose.orientation.w = 0.0;
        assert_eq!(goal_heading(&g), None);
        assert!(!oriented(&g.pose.orientation));
        let q = |x: f64, y: f64, z: f64, w: f64| Quaternion { x, y, z, w };
        // Identity and −identity: none.
        assert!(!oriented(&q(0.0, 0.0, 0.0, 1.0)) && !oriented(&q(0.0, 0.0, 0.0, -1.0)));
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let mut poses = vec![stamped("odom", 0.0, 0.0); 3];
        poses[1].pose.orientation = q(0.0, 0.0, h, h);
        let r = Route {
            points: vec![Point2::origin(); 3],
            request_index: vec![0, 1, 2],
            poses,
        };
        assert_eq!(r.first_oriented(), Some(1));
    }

    #[test]
    fn a_route_carries_headings_only_when_some_pose_is_oriented() {
        let posed = |x: f64, yaw: Option<f64>| {
            let mut p = stamped("odom", x, 0.0);
            if let Some(yaw) = yaw {
                p.pose.orientation = yaw_quaternion(yaw);
            }
            p
        };
        // Every orientation the identity: no heading anywhere.
        let plain = vec![posed(1.0, None), posed(2.0, None)];
        let r = route_from_poses(&plain, "odom", "odom", (0, 0), None, LIMITS).unwrap();
        assert_eq!(r.headings(), vec![None, None]);
        // One pose at 0.5 rad: the identity of the next is a heading of 0 rad, an unset
        // (all-zero) quaternion none; a loop repeats the request's headings.
        let mut unset = posed(3.0, None);
        unset.pose.orientation.w = 0.0;
        let oriented = vec![posed(1.0, Some(0.5)), posed(2.0, None), unset];
        let r = route_from_poses(&oriented, "odom", "odom", (1, 1), None, LIMITS).unwrap();
        let h = r.headings();
        assert_eq!(r.request_index, vec![1, 2, 0, 1, 2]);
        assert_eq!((h[0], h[1], h[3], h[4]), (Some(0.0), None, Some(0.0), None));
        assert!((h[2].unwrap() - 0.5).abs() < 1e-9);
    }

    #[test]
    fn routes_are_checked_and_loops_repeat_from_the_first_pose() {
        let poses = vec![
            stamped("odom", 1.0, 0.0),
            stamped("", 2.0, 0.0),
            stamped("odom", 2.0, 1.0),
        ];
        let r = route_from_poses(&poses, "odom", "odom", (1, 1), None, LIMITS).unwrap();
        // From index 1, then one more round from 0: 1, 2, 0, 1, 2.
        assert_eq!(r.request_index, vec![1, 2, 0, 1, 2]);
        assert_eq!(r.points[2], Point2::new(1.0, 0.0));
        assert_eq!(
            route_from_poses(&poses, "odom", "odom", (3, 0), None, LIMITS),
            Err(GoalError::GoalIndex { index: 3, len: 3 })
        );
        assert_eq!(
            route_from_poses(&[], "odom", "odom", (0, 0), None, LIMITS),
            Err(GoalError::EmptyRoute)
        );
        let mut bad = poses.clone();
        bad[2].header.frame_id = "map".into();
        assert!(matches!(
            route_from_poses(&bad, "odom", "odom", (0, 0), None, LIMITS),
            Err(GoalError::Frame { what, .. }) if what == "waypoint 2"
        ));
        bad[2] = stamped("odom", 0.0, f64::NAN);
        assert!(matches!(
            route_from_poses(&bad, "odom", "odom", (0, 0), None, LIMITS),
            Err(GoalError::NotFinite { .. })
        ));
        // 100 poses × (1 + 1 loop) = 200 is the most; one loop more is refused.
        let many: Vec<_> = (0..100).map(|i| stamped("odom", i as f64, 0.0)).collect();
        assert!(route_from_poses(&many, "odom", "odom", (0, 1), None, LIMITS).is_ok());
        let e = route_from_poses(&many, "odom", "odom", (0, 2), None, LIMITS).unwrap_err();
        assert_eq!(e, GoalError::TooLong { count: 300, max: 200 });
        assert_eq!(e.to_string(), "the route has 300 waypoints; at most 200 are taken");
        // Zero length: every point on the first and on the robot.
        let same = vec![stamped("odom", 0.0, 0.0), stamped("odom", 0.001, 0.0)];
        assert_eq!(
            route_from_poses(&same, "odom", "odom", (0, 0), Some(Point2::origin()), LIMITS),
            Err(GoalError::ZeroLength(0.01))
        );
        // A single waypoint away from the robot is a route.
        assert!(route_from_poses(&same[..1], "odom", "odom", (0, 0), Some(Point2::new(1.0, 0.0)), LIMITS).is_ok());
        // A Path in `map` is refused as a whole; one without a frame lends its poses none.
        let mut path = Path {
            header: Header {
                frame_id: "map".into(),
                ..Default::default()
            },
            poses: poses.clone(),
        };
        assert!(matches!(
            route_from_path(&path, "odom", None, LIMITS),
            Err(GoalError::Frame { what, .. }) if what == "route"
        ));
        path.header.frame_id.clear();
        assert_eq!(route_from_path(&path, "odom", None, LIMITS).unwrap().points.len(), 3);
    }
}
