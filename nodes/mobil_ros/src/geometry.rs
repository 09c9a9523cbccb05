//! Planar poses and twists in ROS messages (REP-103: x forward, y left, z up, yaw about z).

use mobil_msgs::geometry_msgs::msg::Quaternion;
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_msgs::std_msgs::msg::Header;

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
}
