//! Plans as `nav_msgs/Path`, on Nav2's topic names: `plan` (the path a goal is to follow, as
//! Nav2's planner server publishes it) and `local_plan` (what the controller steers along now,
//! as Nav2's controller server publishes it). Both are relative (remappable) and latched
//! (reliable, transient local, depth 1), so RViz's Path display, rosbag and late joiners get
//! the last one. A path goes out when it changes, not again while it stays the same, and an
//! empty one (header only) when the goal ends ([`PlanOut::clear`]), so no ended goal's plan
//! stays latched. A path keeps at most [`MAX_PATH_POSES`] poses, its first and last among them
//! (about 80 bytes each in CDR plus the frame name, which each pose repeats: 36 KB with
//! `odom`).
//!
//! ```
//! use mobil_geom::Pose2;
//! use mobil_msgs::builtin_interfaces::msg::Time;
//! use mobil_ros::plan::path_msg;
//!
//! let poses: Vec<Pose2> = (0..1000).map(|i| Pose2::new(i as f64 * 0.01, 0.0, 0.0)).collect();
//! let path = path_msg(&poses, "odom", Time::default());
//! assert_eq!(path.poses.len(), 400);
//! assert_eq!(path.poses.last().unwrap().pose.position.x, 9.99);
//! ```

use crate::geometry::pose_msg;
use crate::log::LogThrottle;
use crate::node::RosNode;
use mobil_geom::{downsample, Pose2};
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::PoseStamped;
use mobil_msgs::nav_msgs::msg::Path;
use mobil_msgs::std_msgs::msg::Header;
use ros2_client::Publisher;

/// Most poses of one published path: about 90 bytes each in CDR with a short frame name, 36 KB,
/// well under the 64 KB a sample should stay below.
pub const MAX_PATH_POSES: usize = 400;

/// The path of `poses` in `frame`, stamped `stamp`, at most [`MAX_PATH_POSES`] of them.
pub fn path_msg(poses: &[Pose2], frame: &str, stamp: Time) -> Path {
    let header = Header {
        stamp,
        frame_id: frame.to_owned(),
    };
    Path {
        poses: downsample(poses, MAX_PATH_POSES)
            .iter()
            .map(|p| PoseStamped {
                header: header.clone(),
                pose: pose_msg(p),
            })
            .collect(),
        header,
    }
}

/// The `plan` and `local_plan` publishers of a node, and what each last sent.
pub struct PlanOut {
    plan: Publisher<Path>,
    local_plan: Publisher<Path>,
    sent_plan: Vec<Pose2>,
    sent_local: Vec<Pose2>,
}

impl PlanOut {
    /// Creates `plan` and `local_plan` (latched).
    pub fn create(node: &mut RosNode) -> anyhow::Result<Self> {
        Ok(PlanOut {
            plan: node.publisher::<Path>("plan", &crate::qos::latched())?,
            local_plan: node.publisher::<Path>("local_plan", &crate::qos::latched())?,
            sent_plan: Vec::new(),
            sent_local: Vec::new(),
        })
    }

    /// Publishes `poses` in `frame` on `plan`, unless they are what it last sent (a failure:
    /// one rate-limited warning).
    pub fn send_plan(&mut self, poses: &[Pose2], frame: &str, stamp: Time, throttle: &mut LogThrottle) {
        send(&self.plan, &mut self.sent_plan, poses, (frame, stamp), throttle);
    }

    /// Publishes `poses` in `frame` on `local_plan`, unless they are what it last sent.
    pub fn send_local(&mut self, poses: &[Pose2], frame: &str, stamp: Time, throttle: &mut LogThrottle) {
        send(&self.local_plan, &mut self.sent_local, poses, (frame, stamp), throttle);
    }

    /// A goal ended: an empty path on each topic that carries one.
    pub fn clear(&mut self, frame: &str, stamp: Time, throttle: &mut LogThrottle) {
        send(&self.plan, &mut self.sent_plan, &[], (frame, stamp.clone()), throttle);
        send(&self.local_plan, &mut self.sent_local, &[], (frame, stamp), throttle);
    }
}

fn send(
    publisher: &Publisher<Path>,
    sent: &mut Vec<Pose2>,
    poses: &[Pose2],
    (frame, stamp): (&str, Time),
    throttle: &mut LogThrottle,
) {
    let poses = downsample(poses, MAX_PATH_POSES);
    if poses == *sent {
        return;
    }
    match publisher.publish(path_msg(&poses, frame, stamp)) {
        Ok(()) => *sent = poses,
        Err(e) => crate::warn_throttled!(throttle, "plan", "cannot publish a plan: {e:?}"),
    }
}
