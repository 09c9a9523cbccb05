//! The transform buffer on `tf` and `tf_static` ([`mobil_tf::FrameTree`]), as tf2_ros'
//! `TransformListener` fills a `Buffer`: `tf` reliable and volatile (depth 100), `tf_static`
//! reliable and transient local (a node started after the publishers still gets their
//! transforms). Both names are relative, so `-r __ns:=/robot1` moves them with the publishers.
//!
//! A node drains both subscriptions before it looks a transform up ([`TfListener::poll`]);
//! a transform refused is dropped and told in one rate-limited warning: non-finite, an empty
//! frame name, a frame given a second parent, a quaternion off unit norm (|‖q‖² − 1| ≥ 0.01,
//! tf2's rule; closer ones are normalised), a stamp with `nanosec` out of range, and on `tf` a
//! zero stamp (unstamped: a fixed transform belongs on `tf_static`). When ROS time goes back,
//! the dynamic history is cleared ([`mobil_tf::FrameTree::observe_time`]).
//!
//! ```
//! use mobil_msgs::geometry_msgs::msg::TransformStamped;
//! use mobil_msgs::tf2_msgs::msg::TFMessage;
//! use mobil_ros::tf::add_message;
//! use mobil_tf::{At, FrameTree};
//! use std::time::Duration;
//!
//! let mut t = TransformStamped::default();
//! (t.header.frame_id, t.child_frame_id) = ("map".into(), "odom".into());
//! t.header.stamp.sec = 3;
//! t.transform.translation.x = 1.5;
//! t.transform.rotation.w = 1.0;
//! let mut tree = FrameTree::new(Duration::from_secs(10));
//! let refused = add_message(&mut tree, &TFMessage { transforms: vec![t] }, false);
//! assert!(refused.is_empty());
//! assert_eq!(tree.planar("map", "odom", At::Latest).unwrap().x, 1.5);
//! ```

use crate::log::LogThrottle;
use crate::node::RosNode;
use crate::time::nanos_from_stamp;
use crate::warn_throttled;
use mobil_geom::Pose2;
use mobil_msgs::tf2_msgs::msg::TFMessage;
use mobil_tf::{FrameTree, GoalFrames, TfError};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use ros2_client::Subscription;
use std::time::Duration;

/// `tf`'s QoS, tf2_ros' dynamic listener's: reliable, volatile, depth 100.
pub fn tf_qos() -> ros2_client::QosProfile {
    crate::qos::reliable(100)
}

/// Adds every transform of `msg` to `tree` (`is_static`: from `tf_static`, valid at every
/// instant); the ones refused, with why.
pub fn add_message(tree: &mut FrameTree, msg: &TFMessage, is_static: bool) -> Vec<TfError> {
    let mut refused = Vec::new();
    for t in &msg.transforms {
        let (parent, child) = (&t.header.frame_id, &t.child_frame_id);
        let refuse = |why: &str| TfError::Rejected {
            parent: parent.clone(),
            child: child.clone(),
            why: why.to_owned(),
        };
        let stamp = match (is_static, nanos_from_stamp(&t.header.stamp)) {
            (true, _) => None,
            (false, Some(0)) => {
                refused.push(refuse(
                    "unstamped (time 0) on tf: a fixed transform belongs on tf_static",
                ));
                continue;
            }
            (false, Some(ns)) if ns > 0 => Some(ns as u64),
            (false, _) => {
                refused.push(refuse("its stamp is invalid (nanosec ≥ 1e9) or before the epoch"));
                continue;
            }
        };
        let (v, q) = (&t.transform.translation, &t.transform.rotation);
        // tf2's rule: a quaternion within 0.01 of unit norm squared is taken (normalised), any
        // other refused.
        let raw = Quaternion::new(q.w, q.x, q.y, q.z);
        let off_unit = (raw.norm_squared() - 1.0).abs();
        if off_unit.is_nan() || off_unit >= 1e-2 {
            refused.push(refuse("its rotation is not a unit quaternion (|‖q‖² − 1| ≥ 0.01)"));
            continue;
        }
        let rotation = UnitQuaternion::from_quaternion(raw);
        let iso = Isometry3::from_parts(Translation3::new(v.x, v.y, v.z), rotation);
        if let Err(e) = tree.insert(parent, child, &iso, stamp) {
            refused.push(e);
        }
    }
    refused
}

/// `tf` and `tf_static` into one frame tree.
pub struct TfListener {
    tree: FrameTree,
    tf: Subscription<TFMessage>,
    tf_static: Subscription<TFMessage>,
}

impl TfListener {
    /// Subscribes `tf` and `tf_static`; the tree keeps `cache` of each dynamic edge's history.
    pub fn create(node: &mut RosNode, cache: Duration) -> anyhow::Result<Self> {
        Ok(TfListener {
            tree: FrameTree::new(cache),
            tf: node.subscription::<TFMessage>("tf", &tf_qos())?,
            tf_static: crate::scan::tf_static_subscription(node)?,
        })
    }

    /// Takes every message waiting on both topics (non-blocking) into the tree at ROS time
    /// `now` (ns; a time gone back clears the dynamic history first); the transforms refused
    /// are told in one warning at most every throttle period. Returns how many transforms were
    /// taken.
    pub fn poll(&mut self, now: u64, throttle: &mut LogThrottle) -> usize {
        if self.tree.observe_time(now) {
            warn_throttled!(throttle, "tf-time", "ROS time went back: the tf history is cleared");
        }
        let mut taken = 0;
        let mut refused = Vec::new();
        for (sub, is_static) in [(&self.tf_static, true), (&self.tf, false)] {
            loop {
                match sub.take() {
                    Ok(Some((msg, _))) => {
                        taken += msg.transforms.len();
                        refused.extend(add_message(&mut self.tree, &msg, is_static));
                    }
                    Ok(None) => break,
                    Err(e) => {
                        warn_throttled!(throttle, "tf-read", "a tf message could not be read: {e:?}");
                        break;
                    }
                }
            }
        }
        if let Some(first) = refused.first() {
            warn_throttled!(
                throttle,
                "tf-refused",
                "{} transform(s) refused, e.g. {first}",
                refused.len()
            );
        }
        taken - refused.len().min(taken)
    }

    /// The frame tree.
    pub fn tree(&self) -> &FrameTree {
        &self.tree
    }
}

/// A motion node's goal frames: the listener, and the frame rule ([`GoalFrames`]) with the
/// node's `odom_frame` and `transform_tolerance`. Every goal a motion node takes, from a topic
/// or an action, is placed here: [`GoalTf::accept`] when it comes (refused TF_ERROR when its
/// frame does not connect to odometry, or its transform is stale), [`GoalTf::robot`] at every
/// step (the goal ends TF_ERROR when the transform is lost while it runs).
pub struct GoalTf {
    listener: TfListener,
    frames: GoalFrames,
    throttle: LogThrottle,
}

impl GoalTf {
    /// Subscribes `tf` and `tf_static` (tf2's cache length, 10 s) for goals relative to
    /// `odom_frame`, through transforms at most `tolerance` old.
    pub fn create(node: &mut RosNode, odom_frame: &str, tolerance: Duration) -> anyhow::Result<Self> {
        Ok(GoalTf {
            listener: TfListener::create(node, Duration::from_secs_f64(mobil_tf::DEFAULT_CACHE_S))?,
            frames: GoalFrames::new(odom_frame, tolerance),
            throttle: LogThrottle::new(Duration::from_secs(2)),
        })
    }

    /// A new tolerance (a parameter change).
    pub fn set_tolerance(&mut self, tolerance: Duration) {
        self.frames = GoalFrames::new(self.frames.odom(), tolerance);
    }

    /// The frame rule.
    pub fn frames(&self) -> &GoalFrames {
        &self.frames
    }

    /// The frame of a goal whose header names `frame_id` (empty: the odometry frame).
    pub fn frame_of(&self, frame_id: &str) -> String {
        self.frames.frame_of(frame_id)
    }

    /// Takes the transforms waiting, at ROS time `now` (ns).
    pub fn refresh(&mut self, now: i64) {
        let now = u64::try_from(now).unwrap_or(0);
        self.listener.poll(now, &mut self.throttle);
    }

    /// Whether a goal in `goal_frame` can be followed at ROS time `now` (ns): the odometry
    /// frame's pose in it, or the reason it cannot (for a TF_ERROR), the transforms waiting
    /// taken first.
    pub fn accept(&mut self, goal_frame: &str, now: i64) -> Result<Pose2, String> {
        self.refresh(now);
        self.odom_in(goal_frame, now)
    }

    /// The odometry frame's pose in `goal_frame` at ROS time `now` (ns), from the transforms
    /// taken so far; or the reason (for a TF_ERROR).
    pub fn odom_in(&self, goal_frame: &str, now: i64) -> Result<Pose2, String> {
        let now = u64::try_from(now).unwrap_or(0);
        self.frames
            .odom_in(self.listener.tree(), goal_frame, now)
            .map_err(|e| tf_reason(goal_frame, self.frames.odom(), &e))
    }

    /// The robot's pose `odom_pose` (odometry frame) in `goal_frame` at ROS time `now` (ns),
    /// the transforms waiting taken first; or the reason (for a TF_ERROR).
    pub fn robot(&mut self, goal_frame: &str, odom_pose: &Pose2, now: i64) -> Result<Pose2, String> {
        if self.frames.is_odom(goal_frame) {
            return Ok(*odom_pose);
        }
        self.refresh(now);
        self.odom_in(goal_frame, now).map(|t| t.compose(odom_pose))
    }
}

/// The reason a goal in `goal_frame` cannot be followed from odometry frame `odom`.
pub fn tf_reason(goal_frame: &str, odom: &str, e: &TfError) -> String {
    format!("goal frame `{goal_frame}` has no usable transform to `{odom}`: {e}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use mobil_msgs::geometry_msgs::msg::TransformStamped;
    use mobil_tf::At;

    fn tf(parent: &str, child: &str, sec: i32, x: f64, yaw: f64) -> TransformStamped {
        let mut t = TransformStamped::default();
        (t.header.frame_id, t.child_frame_id) = (parent.into(), child.into());
        t.header.stamp.sec = sec;
        t.transform.translation.x = x;
        (t.transform.rotation.z, t.transform.rotation.w) = ((yaw / 2.0).sin(), (yaw / 2.0).cos());
        t
    }

    /// A message's transforms go in; a bad stamp, a NaN, a zero quaternion are refused one by
    /// one while the rest are taken; a static message is valid at any instant.
    #[test]
    fn messages_fill_the_tree_and_bad_transforms_are_refused() {
        let mut tree = FrameTree::new(Duration::from_secs(10));
        let mut bad_stamp = tf("map", "a", 1, 0.0, 0.0);
        bad_stamp.header.stamp.nanosec = 1_000_000_000;
        let nan = tf("map", "b", 1, f64::NAN, 0.0);
        let mut zero_q = tf("map", "c", 1, 0.0, 0.0);
        zero_q.transform.rotation.w = 0.0;
        // A quaternion off by rounding (norm 1.0001) is taken, normalised; norm 2 is refused.
        let mut rounded = tf("map", "odom", 2, 1.0, 0.0);
        rounded.transform.rotation.w = 1.0001;
        let mut doubled = tf("map", "d", 1, 0.0, 0.0);
        doubled.transform.rotation.w = 2.0;
        let unstamped = tf("map", "e", 0, 0.0, 0.0);
        let msg = TFMessage {
            transforms: vec![bad_stamp, nan, zero_q, doubled, unstamped, rounded],
        };
        let refused = add_message(&mut tree, &msg, false);
        assert_eq!(refused.len(), 5, "{refused:?}");
        assert_eq!(tree.planar("map", "odom", At::Latest).unwrap().x, 1.0);
        let laser = TFMessage {
            transforms: vec![tf("odom", "laser", 0, 0.2, std::f64::consts::PI)],
        };
        assert!(add_message(&mut tree, &laser, true).is_empty());
        let p = tree.planar("map", "laser", At::Nanos(2_000_000_000)).unwrap();
        assert!(
            (p.x - 1.2).abs() < 1e-12 && (p.yaw.abs() - std::f64::consts::PI).abs() < 1e-9,
            "{p:?}"
        );
    }
}
