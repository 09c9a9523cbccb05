//! Planar poses and twists in ROS messages (REP-103: x forward, y left, z up, yaw about z).

use mobil_geom::Pose2;
use mobil_motion::BodyTwist;
use mobil_msgs::geometry_msgs::msg::{Point, Pose, PoseStamped, Quaternion, Twist};
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_msgs::std_msgs::msg::Header;
use thiserror::Error;

/// A planar pose as a message pose (z 0, the rotation about z).
pub fn pose_msg(p: &Pose2) -> Pose {
    Pose {
        position: Point { x: p.x, y: p.y, z: 0.0 },
        orientation: yaw_quaternion(p.yaw),
    }
}

/// A planar pose with its header (a goal, a dock, a waypoint).
pub fn pose_stamped(header: Header, p: &Pose2) -> PoseStamped {
    PoseStamped {
        header,
        pose: pose_msg(p),
    }
}

/// A header in `frame`, stamped zero (a test's message, a goal whose stamp does not matter).
pub fn header_in(frame: &str) -> Header {
    Header {
        frame_id: frame.to_owned(),
        ..Default::default()
    }
}

/// A planar body twist as a `cmd_vel` Twist (linear.x, linear.y, angular.z; the rest zero).
pub fn twist_msg(t: BodyTwist) -> Twist {
    let mut m = Twist::default();
    m.linear.x = t.vx;
    m.linear.y = t.vy;
    m.angular.z = t.wz;
    m
}

/// The quaternion of a rotation by `yaw` about z.
pub fn yaw_quaternion(yaw: f64) -> Quaternion {
    Quaternion {
        x: 0.0,
        y: 0.0,
        z: (0.5 * yaw).sin(),
        w: (0.5 * yaw).cos(),
    }
}

/// The yaw of a quaternion (its rotation about z, for a planar robot).
pub fn yaw_of(q: &Quaternion) -> f64 {
    (2.0 * (q.w * q.z + q.x * q.y)).atan2(1.0 - 2.0 * (q.y * q.y + q.z * q.z))
}

/// An Odometry message of a planar robot: `pose` = (x, y, yaw) in `header.frame_id`, `twist` =
/// (vx, vy, ω) in `child_frame_id`; covariances left zero for the caller to fill.
pub fn planar_odometry(header: Header, child_frame_id: &str, pose: [f64; 3], twist: [f64; 3]) -> Odometry {
    let mut msg = Odometry {
        header,
        child_frame_id: child_frame_id.to_owned(),
        ..Default::default()
    };
    msg.pose.pose.position.x = pose[0];
    msg.pose.pose.position.y = pose[1];
    msg.pose.pose.orientation = yaw_quaternion(pose[2]);
    msg.twist.twist.linear.x = twist[0];
    msg.twist.twist.linear.y = twist[1];
    msg.twist.twist.angular.z = twist[2];
    msg
}

/// Why an odometry message is refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OdomError {
    /// `header.frame_id` or `child_frame_id` is not the configured frame (a leading `/` and an
    /// empty frame are accepted, as many drivers leave it empty).
    #[error("odom in frames `{frame}` → `{child}`, expected `{want_frame}` → `{want_child}`")]
    Frames {
        /// The message's `header.frame_id`.
        frame: String,
        /// The message's `child_frame_id`.
        child: String,
        /// `odom_frame`.
        want_frame: String,
        /// `base_frame`.
        want_child: String,
    },
    /// NaN or infinity in the pose.
    #[error("odom with a non-finite pose")]
    NotFinite,
    /// A position beyond ±[`MAX_ODOM_COORD`]: what follows from it (a distance, a time to
    /// go) could not be represented.
    #[error("odom position ({}, {}) beyond ±{MAX_ODOM_COORD:e} m", short(*x), short(*y))]
    TooFar {
        /// x (m).
        x: f64,
        /// y (m).
        y: f64,
    },
}

/// A number for a log line: as it is when short, else in scientific notation (1e308 has 309
/// digits written out).
fn short(v: f64) -> String {
    if v.abs() < 1e7 {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// The largest |x| and |y| of an odometry position the nodes take (m): 1000 km, far beyond any
/// drive (mobil_planner's own coordinate limit), and far below where a distance, its square or
/// a time computed from it overflows, even as an `f32` in a Nav2 feedback.
pub const MAX_ODOM_COORD: f64 = 1e6;

/// The planar robot pose of an odometry pose, or why it is refused: NaN or infinity in it (the
/// quaternion included), or a position beyond ±[`MAX_ODOM_COORD`].
pub fn planar_pose(p: &Pose) -> Result<Pose2, OdomError> {
    let q = &p.orientation;
    let pose = Pose2::new(p.position.x, p.position.y, yaw_of(q));
    // The yaw of a quaternion with an infinity in it can come out finite: each part is checked.
    if !(pose.is_finite() && [q.x, q.y, q.z, q.w].iter().all(|v| v.is_finite())) {
        return Err(OdomError::NotFinite);
    }
    if pose.x.abs() > MAX_ODOM_COORD || pose.y.abs() > MAX_ODOM_COORD {
        return Err(OdomError::TooFar { x: pose.x, y: pose.y });
    }
    Ok(pose)
}

/// The robot pose of an odometry message, or why it is refused: frames other than
/// `odom_frame` → `base_frame` (an empty frame passes), or a pose [`planar_pose`] refuses.
pub fn odom_pose(m: &Odometry, odom_frame: &str, base_frame: &str) -> Result<Pose2, OdomError> {
    let same = |got: &str, want: &str| {
        let got = got.trim_start_matches('/');
        got.is_empty() || got == want.trim_start_matches('/')
    };
    if !same(&m.header.frame_id, odom_frame) || !same(&m.child_frame_id, base_frame) {
        return Err(OdomError::Frames {
            frame: m.header.frame_id.clone(),
            child: m.child_frame_id.clone(),
            want_frame: odom_frame.to_owned(),
            want_child: base_frame.to_owned(),
        });
    }
    planar_pose(&m.pose.pose)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaw_round_trips_and_matches_hand_values() {
        // 90° about z: (0, 0, sin 45°, cos 45°).
        let q = yaw_quaternion(std::f64::consts::FRAC_PI_2);
        assert!((q.z - 0.5f64.sqrt()).abs() < 1e-15 && (q.w - 0.5f64.sqrt()).abs() < 1e-15);
        for yaw in [-3.1, -1.0, 0.0, 0.5, 3.1] {
            assert!((yaw_of(&yaw_quaternion(yaw)) - yaw).abs() < 1e-12);
        }
    }

    fn odom(frame: &str, child: &str, x: f64) -> Odometry {
        let mut m = Odometry::default();
        m.header.frame_id = frame.into();
        m.child_frame_id = child.into();
        m.pose.pose.position.x = x;
        m.pose.pose.orientation.w = 1.0;
        m
    }

    #[test]
    fn odometry_in_other_frames_or_with_nan_is_refused() {
        assert_eq!(
            odom_pose(&odom("odom", "base_link", 1.5), "odom", "base_link"),
            Ok(Pose2::new(1.5, 0.0, 0.0))
        );
        // Empty frames (many drivers) and a leading slash pass.
        assert!(odom_pose(&odom("", "", 1.0), "odom", "base_link").is_ok());
        assert!(odom_pose(&odom("/odom", "base_link", 1.0), "odom", "base_link").is_ok());
        let e = odom_pose(&odom("map", "base_link", 1.0), "odom", "base_link").unwrap_err();
        assert_eq!(
            e.to_string(),
            "odom in frames `map` → `base_link`, expected `odom` → `base_link`"
        );
        assert!(matches!(
            odom_pose(&odom("odom", "laser", 1.0), "odom", "base_link"),
            Err(OdomError::Frames { .. })
        ));
        assert_eq!(
            odom_pose(&odom("odom", "base_link", f64::NAN), "odom", "base_link"),
            Err(OdomError::NotFinite)
        );
        let mut q_inf = odom("odom", "base_link", 0.0);
        q_inf.pose.pose.orientation.z = f64::INFINITY;
        assert_eq!(odom_pose(&q_inf, "odom", "base_link"), Err(OdomError::NotFinite));
        // Finite, but so far that a distance from it overflows an f32 (1e308 m), or beyond the
        // 1000 km bound: refused; the bound itself is taken.
        for x in [1e308, -1e308, 1.0000001e6] {
            assert_eq!(
                odom_pose(&odom("odom", "base_link", x), "odom", "base_link"),
                Err(OdomError::TooFar { x, y: 0.0 })
            );
        }
        assert!(odom_pose(&odom("odom", "base_link", -1e6), "odom", "base_link").is_ok());
        let far = OdomError::TooFar { x: 1e308, y: -2.5 };
        assert_eq!(far.to_string(), "odom position (1e308, -2.5) beyond ±1e6 m");
    }
}
