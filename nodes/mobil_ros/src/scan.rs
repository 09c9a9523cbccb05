//! Laser scans at the edge: a `sensor_msgs/LaserScan` becomes a checked
//! [`mobil_geom::Scan`] once, on arrival, with the laser's pose in the base frame, taken from a
//! parameter or from `/tf_static` ([`StaticFrames`]).
//!
//! ```
//! use mobil_msgs::geometry_msgs::msg::TransformStamped;
//! use mobil_msgs::sensor_msgs::msg::LaserScan;
//! use mobil_msgs::tf2_msgs::msg::TFMessage;
//! use mobil_ros::geometry::yaw_quaternion;
//! use mobil_ros::scan::{scan_from_msg, StaticFrames};
//!
//! // sim_node's tf_static: the laser 0.3 m ahead of base_link.
//! let mut mount = TransformStamped::default();
//! mount.header.frame_id = "base_link".into();
//! mount.child_frame_id = "laser".into();
//! mount.transform.translation.x = 0.3;
//! mount.transform.rotation = yaw_quaternion(0.0);
//! let mut frames = StaticFrames::default();
//! frames.add(&TFMessage { transforms: vec![mount] });
//! let base_from_laser = frames.lookup("base_link", "laser").unwrap();
//!
//! let msg = LaserScan {
//!     angle_min: -0.5, angle_max: 0.5, angle_increment: 0.5,
//!     range_min: 0.1, range_max: 10.0, ranges: vec![1.0, 2.0, f32::INFINITY],
//!     ..Default::default()
//! };
//! let scan = scan_from_msg(&msg, base_from_laser).unwrap();
//! // The straight-ahead echo at 2 m is 2.3 m ahead of base_link.
//! assert!((scan.points_in_base().nth(1).unwrap().x - 2.3).abs() < 1e-6);
//! ```

use crate::geometry::yaw_of;
use crate::log::LogThrottle;
use crate::RosNode;
use mobil_geom::{Pose2, Scan, ScanError};
use mobil_msgs::sensor_msgs::msg::LaserScan;
use mobil_msgs::tf2_msgs::msg::TFMessage;
use ros2_client::Subscription;
use std::collections::HashMap;
use thiserror::Error;

/// The checked scan of a LaserScan message, the laser at `base_from_laser` in the base frame.
pub fn scan_from_msg(msg: &LaserScan, base_from_laser: Pose2) -> Result<Scan, ScanError> {
    Scan::new(
        f64::from(msg.angle_min),
        f64::from(msg.angle_max),
        f64::from(msg.angle_increment),
        f64::from(msg.range_min),
        f64::from(msg.range_max),
        msg.ranges.clone(),
        msg.intensities.clone(),
        base_from_laser,
    )
}

/// The static transforms seen on `/tf_static` (planar part: x, y, yaw), by child frame.
///
/// Feed it every `tf2_msgs/TFMessage` of `tf_static` (subscribed with [`crate::qos::tf_static`],
/// so that a node started after the publishers still gets them) and ask
/// [`StaticFrames::lookup`] for `base_frame → laser_frame`, which composes the chain between
/// them (e.g. base_link → mount → laser), in either direction. Until the chain is known, a node
/// uses the laser pose parameter or waits; it never guesses.
#[derive(Debug, Clone, Default)]
pub struct StaticFrames {
    /// child → (parent, parent_from_child).
    parents: HashMap<String, (String, Pose2)>,
}

/// The largest roll or pitch (rad) of a static transform taken as planar: 1°.
pub const MAX_TILT_RAD: f64 = 0.017_453_292_519_943_295;

/// Whether a rotation keeps the z axis within [`MAX_TILT_RAD`] of vertical (a non-finite or
/// zero quaternion is not). For a unit quaternion the rotated z axis has z component
/// 1 − 2(x² + y²); the norm divides out so that an unnormalised one is judged alike.
fn is_planar(q: &mobil_msgs::geometry_msgs::msg::Quaternion) -> bool {
    let n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
    if !n.is_finite() || n <= 0.0 {
        return false;
    }
    let cos_tilt = 1.0 - 2.0 * (q.x * q.x + q.y * q.y) / n;
    cos_tilt >= MAX_TILT_RAD.cos()
}

impl StaticFrames {
    /// Adds (or replaces) the transforms of one message; transforms with non-finite values,
    /// empty frame names, or a tilt out of the plane (roll or pitch beyond
    /// [`MAX_TILT_RAD`], e.g. a scanner mounted upside down, whose beams a planar pose would
    /// mirror) are skipped, and their count returned.
    pub fn add(&mut self, msg: &TFMessage) -> usize {
        let mut skipped = 0;
        for t in &msg.transforms {
            if !is_planar(&t.transform.rotation) {
                skipped += 1;
                continue;
            }
            let pose = Pose2::new(
                t.transform.translation.x,
                t.transform.translation.y,
                yaw_of(&t.transform.rotation),
            );
            let parent = t.header.frame_id.trim_start_matches('/');
            let child = t.child_frame_id.trim_start_matches('/');
            if !pose.is_finite() || parent.is_empty() || child.is_empty() || parent == child {
                skipped += 1;
                continue;
            }
            self.parents.insert(child.to_owned(), (parent.to_owned(), pose));
        }
        skipped
    }

    /// Takes every `tf_static` message waiting on `sub` (non-blocking) and [`add`s](Self::add)
    /// it; returns how many transforms were skipped as invalid (an undecodable sample counts as
    /// one).
    pub fn take_all(&mut self, sub: &Subscription<TFMessage>) -> usize {
        let mut skipped = 0;
        loop {
            match sub.take() {
                Ok(Some((msg, _))) => skipped += self.add(&msg),
                Ok(None) => break,
                Err(_) => skipped += 1,
            }
        }
        skipped
    }

    /// [`take_all`](Self::take_all), the transforms skipped told in one warning, rate-limited
    /// by `throttle` (a node calls it before it reads a scan).
    pub fn refresh(&mut self, sub: &Subscription<TFMessage>, throttle: &mut LogThrottle) {
        let skipped = self.take_all(sub);
        if skipped > 0 {
            crate::warn_throttled!(
                throttle,
                "tf-static",
                "{skipped} invalid tf_static transform(s) skipped"
            );
        }
    }

    /// The chain from `frame` up to its root: (root, root_from_frame); `None` when the chain
    /// loops (a → b → a), which no tree has.
    fn to_root(&self, frame: &str) -> Option<(String, Pose2)> {
        let mut pose = Pose2::identity();
        let mut at = frame.to_owned();
        // A chain without a loop has at most as many links as there are frames.
        for _ in 0..=self.parents.len() {
            match self.parents.get(&at) {
                Some((parent, parent_from_at)) => {
                    pose = *parent_from_at * pose;
                    at = parent.clone();
                }
                None => return Some((at, pose)),
            }
        }
        None
    }

    /// `parent_from_child` between two frames of the same tree, composing the chain between
    /// them; `None` while they are not connected.
    pub fn lookup(&self, parent: &str, child: &str) -> Option<Pose2> {
        let (parent, child) = (parent.trim_start_matches('/'), child.trim_start_matches('/'));
        let (root_p, root_from_parent) = self.to_root(parent)?;
        let (root_c, root_from_child) = self.to_root(child)?;
        (root_p == root_c).then(|| root_from_parent.inverse() * root_from_child)
    }
}

/// The laser's pose in the base frame for a node that reads scans: from `tf_static` when the
/// chain `base_frame → … → laser_frame` is known there, else from the node's laser pose
/// parameter (`fallback`), else unknown (the node waits for it; it never guesses).
///
/// **Precedence: `tf_static` wins over the parameter.** `tf_static` describes the robot as it is
/// mounted (and is what every other ROS tool uses), so the parameter is only for a robot that
/// publishes no static transforms. Once known, the `tf_static` pose stays, and a later message
/// that changes a link of the chain replaces it.
///
/// Feed it from [`tf_static_subscription`] with [`LaserPose::poll`] (or [`LaserPose::add`] for
/// each message of a stream).
#[derive(Debug, Clone)]
pub struct LaserPose {
    frames: StaticFrames,
    base_frame: String,
    laser_frame: String,
    fallback: Option<Pose2>,
}

/// Where [`LaserPose::get`]'s pose comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LaserPoseSource {
    /// The `tf_static` chain between the two frames.
    TfStatic,
    /// The node's parameter (no `tf_static` chain seen yet).
    Parameter,
}

impl LaserPose {
    /// Looks for `base_frame → laser_frame`; `fallback` is the parameter's pose, if the node has
    /// one.
    pub fn new(base_frame: &str, laser_frame: &str, fallback: Option<Pose2>) -> Self {
        LaserPose {
            frames: StaticFrames::default(),
            base_frame: base_frame.to_owned(),
            laser_frame: laser_frame.to_owned(),
            fallback,
        }
    }

    /// Takes one `tf_static` message; returns how many transforms it skipped as invalid.
    pub fn add(&mut self, msg: &TFMessage) -> usize {
        self.frames.add(msg)
    }

    /// Takes every message waiting on `sub` (non-blocking); returns how many transforms were
    /// skipped as invalid. A sample that cannot be decoded is skipped too (counted as one).
    pub fn poll(&mut self, sub: &Subscription<TFMessage>) -> usize {
        self.frames.take_all(sub)
    }

    /// The laser pose in the base frame and where it comes from; `None` while neither
    /// `tf_static` nor the parameter gives one.
    pub fn get(&self) -> Option<(Pose2, LaserPoseSource)> {
        match self.frames.lookup(&self.base_frame, &self.laser_frame) {
            Some(pose) => Some((pose, LaserPoseSource::TfStatic)),
            None => self.fallback.map(|p| (p, LaserPoseSource::Parameter)),
        }
    }
}

/// Subscribes `tf_static` (relative, so `-r __ns:=/robot1` moves it with the publishers) with
/// [`crate::qos::tf_static`]: a node started after the publishers still gets their transforms.
pub fn tf_static_subscription(node: &mut RosNode) -> anyhow::Result<Subscription<TFMessage>> {
    node.subscription::<TFMessage>("tf_static", &crate::qos::tf_static())
}

/// Why a scan gives no navigator step.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ScanRefusal {
    /// The scan's frame has no pose in the base frame: not in `tf_static`, and no `laser_pose`
    /// parameter was given.
    #[error("no laser pose: frame `{frame}` not in tf_static (from `{base}`) and no laser_pose parameter set")]
    NoLaserPose {
        /// The scan's frame.
        frame: String,
        /// The base frame.
        base: String,
    },
    /// The scan itself is malformed.
    #[error("scan refused: {0}")]
    Invalid(String),
}

/// Where the laser pose of a scan came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LaserPoseFrom {
    /// `tf_static`, for the scan's own frame.
    TfStatic,
    /// The `laser_pose` parameter (the scan's frame is not in `tf_static`).
    Parameter,
}

/// The pose in `base_frame` of the laser of a scan in `scan_frame` (empty: `laser_frame`): the
/// `tf_static` chain to the scan's own frame, else the `laser_pose` parameter if one was given,
/// else refused, naming the frame.
pub fn scan_laser_pose(
    frames: &StaticFrames,
    base_frame: &str,
    scan_frame: &str,
    laser_frame: &str,
    parameter: Option<Pose2>,
) -> Result<(Pose2, LaserPoseFrom), ScanRefusal> {
    let frame = match scan_frame.trim_start_matches('/') {
        "" => laser_frame.trim_start_matches('/'),
        f => f,
    };
    if let Some(p) = frames.lookup(base_frame, frame) {
        return Ok((p, LaserPoseFrom::TfStatic));
    }
    parameter
        .map(|p| (p, LaserPoseFrom::Parameter))
        .ok_or_else(|| ScanRefusal::NoLaserPose {
            frame: frame.to_owned(),
            base: base_frame.to_owned(),
        })
}

/// Where a node takes a scan's laser pose from: its base frame, the laser frame of a scan whose
/// header names none, and the `laser_pose` parameter for a frame `tf_static` does not give.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaserMount<'a> {
    /// The robot's base frame.
    pub base_frame: &'a str,
    /// The scan's frame when its header has none.
    pub laser_frame: &'a str,
    /// The `laser_pose` parameter, if given.
    pub parameter: Option<Pose2>,
}

/// The laser's parameters every node that reads scans declares: `laser_frame` and
/// `laser_pose` (the pose for scans whose frame `tf_static` does not give).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LaserParams {
    /// The scan's frame when its header has none (`laser_frame`).
    pub laser_frame: String,
    /// x, y, yaw in the base frame, or empty (`laser_pose`).
    pub laser_pose: Vec<f64>,
}

impl LaserParams {
    /// Declares `laser_frame` (`laser`) and `laser_pose` (empty), both read-only.
    pub fn declare(d: &mut crate::config::Decl<LaserParams>) {
        d.string(
            "laser_frame",
            "laser",
            "the scan's frame: its pose in base_frame comes from tf_static",
            |c, v| c.laser_frame = v,
        )
        .read_only();
        d.double_list(
            "laser_pose",
            &[],
            "x, y, yaw of the laser in the base frame for scans whose frame tf_static does not give; \
             empty (default): such scans are refused",
            |c, v| c.laser_pose = v,
        )
        .read_only();
    }

    /// `laser_pose` holds three values or none.
    pub fn validate(&self) -> Result<(), crate::config::ConfigError> {
        match self.laser_pose.len() {
            0 | 3 => Ok(()),
            n => Err(crate::config::ConfigError::inconsistent(format!(
                "laser_pose has {n} values: give x, y, yaw (3) or none"
            ))),
        }
    }

    /// The `laser_pose` parameter as a pose, if set.
    pub fn pose(&self) -> Option<Pose2> {
        laser_pose_param(&self.laser_pose)
    }

    /// How the laser sits on a robot whose base frame is `base_frame`.
    pub fn mount<'a>(&'a self, base_frame: &'a str) -> LaserMount<'a> {
        LaserMount {
            base_frame,
            laser_frame: &self.laser_frame,
            parameter: self.pose(),
        }
    }
}

/// The `laser_pose` parameter (x, y, yaw in the base frame) as a pose: `None` unless it holds
/// three finite values.
pub fn laser_pose_param(values: &[f64]) -> Option<Pose2> {
    Pose2::from_values(values)
}

/// A LaserScan read at the edge: the checked scan in the base frame, where the laser is and
/// whence its pose came.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedScan {
    /// The scan.
    pub scan: Scan,
    /// The laser in the base frame.
    pub base_from_laser: Pose2,
    /// Whence that pose.
    pub from: LaserPoseFrom,
}

/// `msg` checked, the laser placed by [`scan_laser_pose`]; with `range_limit` (m), echoes
/// beyond it are no obstacles: it becomes the scan's `range_max` (a scan whose own `range_max`
/// is not finite is refused, not given the limit in its place).
pub fn checked_scan(
    frames: &StaticFrames,
    mount: &LaserMount<'_>,
    msg: &LaserScan,
    range_limit: Option<f64>,
) -> Result<CheckedScan, ScanRefusal> {
    let (base_from_laser, from) = scan_laser_pose(
        frames,
        mount.base_frame,
        &msg.header.frame_id,
        mount.laser_frame,
        mount.parameter,
    )?;
    let invalid = |e: ScanError| ScanRefusal::Invalid(e.to_string());
    let scan = match range_limit {
        None => scan_from_msg(msg, base_from_laser).map_err(invalid)?,
        Some(_) if !msg.range_max.is_finite() => {
            return Err(ScanRefusal::Invalid(format!(
                "range_max {} is not finite",
                msg.range_max
            )))
        }
        Some(limit) => {
            let mut limited = msg.clone();
            limited.range_max = limited.range_max.min(limit as f32);
            scan_from_msg(&limited, base_from_laser).map_err(invalid)?
        }
    };
    Ok(CheckedScan {
        scan,
        base_from_laser,
        from,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::yaw_quaternion;
    use mobil_msgs::geometry_msgs::msg::TransformStamped;
    use std::f64::consts::FRAC_PI_2;

    fn tf(parent: &str, child: &str, x: f64, y: f64, yaw: f64) -> TransformStamped {
        let mut t = TransformStamped::default();
        t.header.frame_id = parent.into();
        t.child_frame_id = child.into();
        t.transform.translation.x = x;
        t.transform.translation.y = y;
        t.transform.rotation = yaw_quaternion(yaw);
        t
    }

    #[test]
    fn tilted_transforms_are_refused_and_a_loop_has_no_root() {
        let mut f = StaticFrames::default();
        let mut upside_down = tf("base_link", "laser", 0.2, 0.0, 0.0);
        // Roll π: the quaternion (x, y, z, w) = (1, 0, 0, 0); its beams would be mirrored.
        upside_down.transform.rotation.x = 1.0;
        upside_down.transform.rotation.w = 0.0;
        let mut tilted_2deg = tf("base_link", "tilted", 0.2, 0.0, 0.0);
        // Pitch 2°: (0, sin 1°, 0, cos 1°).
        tilted_2deg.transform.rotation.y = 1f64.to_radians().sin();
        tilted_2deg.transform.rotation.w = 1f64.to_radians().cos();
        let mut tilted_half_deg = tf("base_link", "level", 0.2, 0.0, 0.0);
        tilted_half_deg.transform.rotation.y = 0.25f64.to_radians().sin();
        tilted_half_deg.transform.rotation.w = 0.25f64.to_radians().cos();
        let skipped = f.add(&TFMessage {
            transforms: vec![upside_down, tilted_2deg, tilted_half_deg],
        });
        assert_eq!(skipped, 2);
        assert_eq!(f.lookup("base_link", "laser"), None);
        assert_eq!(f.lookup("base_link", "tilted"), None);
        assert!(f.lookup("base_link", "level").is_some());
        // a → b → a: no root, so nothing is found through it.
        f.add(&TFMessage {
            transforms: vec![tf("a", "b", 1.0, 0.0, 0.0), tf("b", "a", 1.0, 0.0, 0.0)],
        });
        assert_eq!(f.lookup("a", "b"), None);
        assert_eq!(f.lookup("base_link", "a"), None);
    }

    #[test]
    fn a_chain_is_composed_in_either_direction() {
        let mut f = StaticFrames::default();
        // base_link → mount: 0.2 ahead, turned +90°; mount → laser: 0.1 along the mount's x.
        let skipped = f.add(&TFMessage {
            transforms: vec![
                tf("base_link", "mount", 0.2, 0.0, FRAC_PI_2),
                tf("/mount", "laser", 0.1, 0.0, 0.0),
                tf("base_link", "bad", f64::NAN, 0.0, 0.0),
            ],
        });
        assert_eq!(skipped, 1);
        f.add(&TFMessage {
            transforms: vec![tf("odom_other_tree", "x", 1.0, 0.0, 0.0)],
        });
        // The mount's x is base_link's +y: the laser is at (0.2, 0.1), facing +90°.
        let p = f.lookup("base_link", "laser").unwrap();
        assert!((p.x - 0.2).abs() < 1e-12 && (p.y - 0.1).abs() < 1e-12 && (p.yaw - FRAC_PI_2).abs() < 1e-12);
        // Inverse: base_link seen from the laser: the laser's x is base +y, so base_link's
        // origin, 0.2 behind and 0.1 to the right in base terms, is at (−0.1, 0.2) in it.
        let q = f.lookup("laser", "base_link").unwrap();
        assert!((q.x + 0.1).abs() < 1e-12 && (q.y - 0.2).abs() < 1e-12 && (q.yaw + FRAC_PI_2).abs() < 1e-12);
        assert_eq!(f.lookup("base_link", "x"), None, "different trees");
        assert_eq!(f.lookup("base_link", "bad"), None, "skipped");
        assert_eq!(f.lookup("laser", "laser"), Some(Pose2::identity()));
    }

    #[test]
    fn a_laser_scan_message_is_checked_at_the_edge() {
        let msg = LaserScan {
            angle_min: -1.0,
            angle_max: 1.0,
            angle_increment: 1.0,
            range_min: 0.1,
            range_max: 5.0,
            ranges: vec![1.0, 2.0],
            ..Default::default()
        };
        // Two beams of 1 rad from −1 end at 0, one increment short of angle_max 1: accepted.
        assert!(scan_from_msg(&msg, Pose2::identity()).is_ok());
        let mut bad = msg.clone();
        bad.angle_increment = -1.0;
        assert_eq!(
            scan_from_msg(&bad, Pose2::identity()),
            Err(ScanError::BadIncrement(-1.0))
        );
        let mut bad = msg;
        bad.ranges = vec![1.0; 7];
        assert!(matches!(
            scan_from_msg(&bad, Pose2::identity()),
            Err(ScanError::SpanMismatch { beams: 7, .. })
        ));
    }

    #[test]
    fn the_scan_s_own_frame_gives_the_laser_pose() {
        let mut frames = StaticFrames::default();
        frames.add(&mobil_msgs::tf2_msgs::msg::TFMessage {
            transforms: vec![
                tf("base_link", "laser", 0.3, 0.0, 0.0),
                tf("base_link", "rear_laser", -0.4, 0.0, 0.0),
            ],
        });
        let param = Some(Pose2::new(0.1, 0.0, 0.0));
        // The scan says rear_laser: its transform (−0.4 m), not laser_frame's (0.3 m).
        let (p, from) = scan_laser_pose(&frames, "base_link", "rear_laser", "laser", None).unwrap();
        assert_eq!((p.x, from), (-0.4, LaserPoseFrom::TfStatic));
        // tf_static wins over the parameter; an empty frame means laser_frame.
        let (p, from) = scan_laser_pose(&frames, "base_link", "", "laser", param).unwrap();
        assert_eq!((p.x, from), (0.3, LaserPoseFrom::TfStatic));
        // An unknown frame: the parameter if one was set, else refused, naming the frame.
        let (p, from) = scan_laser_pose(&frames, "base_link", "/other", "laser", param).unwrap();
        assert_eq!((p.x, from), (0.1, LaserPoseFrom::Parameter));
        let e = scan_laser_pose(&frames, "base_link", "other", "laser", None).unwrap_err();
        assert_eq!(
            e.to_string(),
            "no laser pose: frame `other` not in tf_static (from `base_link`) and no laser_pose parameter set"
        );
    }
    #[test]
    fn a_checked_scan_takes_tf_static_then_the_parameter_and_its_range_limit() {
        let mut frames = StaticFrames::default();
        frames.add(&TFMessage {
            transforms: vec![tf("base_link", "laser", 0.3, 0.0, 0.0)],
        });
        let mut msg = LaserScan {
            angle_min: 0.0,
            angle_max: 0.5,
            angle_increment: 0.5,
            range_min: 0.1,
            range_max: 10.0,
            ranges: vec![2.0, 6.0],
            ..Default::default()
        };
        msg.header.frame_id = "laser".into();
        let mut mount = LaserMount {
            base_frame: "base_link",
            laser_frame: "laser",
            parameter: None,
        };
        let c = checked_scan(&frames, &mount, &msg, None).unwrap();
        assert_eq!(
            (c.base_from_laser, c.from),
            (Pose2::new(0.3, 0.0, 0.0), LaserPoseFrom::TfStatic)
        );
        // The 2 m echo straight ahead is 2.3 m ahead of base_link; with a 4 m limit the 6 m
        // echo is beyond range_max: no point.
        assert!((c.scan.points_in_base().next().unwrap().x - 2.3).abs() < 1e-6);
        assert_eq!(c.scan.points_in_base().count(), 2);
        let limited = checked_scan(&frames, &mount, &msg, Some(4.0)).unwrap();
        assert_eq!(limited.scan.points_in_base().count(), 1);
        msg.header.frame_id = "other".into();
        assert!(matches!(
            checked_scan(&frames, &mount, &msg, None),
            Err(ScanRefusal::NoLaserPose { .. })
        ));
        assert_eq!(laser_pose_param(&[]), None);
        assert_eq!(laser_pose_param(&[0.1, 0.0]), None);
        assert_eq!(laser_pose_param(&[0.1, f64::NAN, 0.0]), None);
        mount.parameter = laser_pose_param(&[0.1, 0.0, 0.0]);
        assert_eq!(mount.parameter, Some(Pose2::new(0.1, 0.0, 0.0)));
        assert_eq!(
            checked_scan(&frames, &mount, &msg, None).unwrap().from,
            LaserPoseFrom::Parameter
        );
        msg.range_max = f32::NAN;
        assert_eq!(
            checked_scan(&frames, &mount, &msg, Some(4.0)).unwrap_err().to_string(),
            "scan refused: range_max NaN is not finite"
        );
    }
}
