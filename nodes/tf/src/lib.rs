//! ROS-free transform buffer of the mobil suite: the frame tree `/tf` and `/tf_static` build,
//! looked up as tf2's `Buffer` looks it up.
//!
//! The storage, the interpolation and the chaining are the `transforms` crate's
//! ([`transforms::Registry`]): a tree keyed by child frame, each edge a time-ordered history
//! (or one static transform), a lookup walking both frames up to their common ancestor and
//! composing the edges sampled at one instant. It was chosen over writing one because it does
//! what tf2 does where it matters here, and is tested for it: linear interpolation of the
//! translation and slerp of the rotation between the two samples around the instant, static
//! edges valid at every instant, no extrapolation either way, a history kept for a cache
//! length behind each edge's newest sample, and errors that tell an unknown frame from a
//! disconnected tree from a time outside the history. What this crate adds is tf2's
//! conventions on top: frame names without their leading `/` (tf2 strips it on insert and
//! refuses it in a lookup; here both strip it), "time 0" as the latest instant every edge of
//! the chain covers (tf2's `TimePointZero`), ROS time in nanoseconds, the history cleared when
//! ROS time jumps back (as tf2_ros clears its buffer), and the planar pose a wheeled robot's goal
//! needs ([`FrameTree::planar`]).
//!
//! Where it differs from tf2: a child frame keeps the parent its first transform gave it (tf2
//! takes a new parent from the latest message; here the transform is refused with
//! [`TfError::Rejected`], so two publishers that disagree cannot wipe each other's history),
//! and a frame is static or dynamic for good.
//!
//! ```
//! use mobil_tf::{At, FrameTree};
//! use nalgebra::{Isometry3, Translation3, UnitQuaternion};
//! use std::time::Duration;
//!
//! let mut tree = FrameTree::new(Duration::from_secs(10));
//! let odom_in_map = Isometry3::from_parts(Translation3::new(1.0, 2.0, 0.0), UnitQuaternion::identity());
//! tree.insert("map", "odom", &odom_in_map, Some(1_000_000_000)).unwrap();
//! let pose = tree.planar("map", "odom", At::Latest).unwrap();
//! assert_eq!((pose.x, pose.y), (1.0, 2.0));
//! ```

#![warn(missing_docs)]

use mobil_geom::Pose2;
use nalgebra::{Isometry3, Quaternion as NaQuaternion, Translation3, UnitQuaternion};
use std::time::Duration;
use thiserror::Error;
use transforms::errors::RegistryError;
use transforms::geometry::{Quaternion, Transform, Vector3};
use transforms::time::{Stamp, Timestamp};
use transforms::Registry;

/// tf2's default cache length (s).
pub const DEFAULT_CACHE_S: f64 = 10.0;

/// The instant of a lookup.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum At {
    /// The latest instant every edge of the chain covers (tf2's time 0); any instant for a
    /// chain of static edges.
    Latest,
    /// ROS time in nanoseconds.
    Nanos(u64),
}

/// Why a transform is refused or a lookup fails.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TfError {
    /// A frame no transform names.
    #[error("frame `{0}` does not exist")]
    UnknownFrame(String),
    /// Both frames exist, in trees no transform joins.
    #[error("`{target}` and `{from}` are not connected (two unconnected trees)")]
    Disconnected {
        /// The lookup's target frame.
        target: String,
        /// The lookup's source frame.
        from: String,
    },
    /// The instant lies outside an edge's history (extrapolation into the future or the past).
    #[error("no transform from `{from}` to `{target}` at {requested_s:.3} s: {detail}")]
    Extrapolation {
        /// The lookup's target frame.
        target: String,
        /// The lookup's source frame.
        from: String,
        /// The instant asked for (s).
        requested_s: f64,
        /// The edge whose history does not cover it, and what it covers.
        detail: String,
    },
    /// No instant is covered by every edge of the chain (a [`At::Latest`] lookup).
    #[error("no instant common to every transform between `{target}` and `{from}`: {detail}")]
    NoCommonTime {
        /// The lookup's target frame.
        target: String,
        /// The lookup's source frame.
        from: String,
        /// The edges and what they cover.
        detail: String,
    },
    /// A lookup that failed otherwise (a transform that cannot be composed or inverted).
    #[error("no transform from `{from}` to `{target}`: {detail}")]
    Lookup {
        /// The lookup's target frame.
        target: String,
        /// The lookup's source frame.
        from: String,
        /// Why.
        detail: String,
    },
    /// The latest transform between the frames is older than the tolerance allows (a localiser
    /// that stopped, a publisher gone), or dated further ahead of now than the cache reaches
    /// (a negative age: a clock that jumped back under it).
    #[error(
        "the transform from `{from}` to `{target}` is {age_s:.3} s old (negative: dated ahead of now), beyond transform_tolerance {tolerance_s} s or the cache ahead"
    )]
    Stale {
        /// The lookup's target frame.
        target: String,
        /// The lookup's source frame.
        from: String,
        /// How old its latest instant is (s).
        age_s: f64,
        /// The tolerance (s).
        tolerance_s: f64,
    },
    /// A transform refused: not finite, not a rotation, a frame its own parent, a loop, a new
    /// parent for a frame, a static transform for a dynamic frame or the reverse.
    #[error("transform `{parent}` → `{child}` refused: {why}")]
    Rejected {
        /// Its parent frame.
        parent: String,
        /// Its child frame.
        child: String,
        /// Why.
        why: String,
    },
}

/// A frame name as tf2 takes it: without a leading `/`.
pub fn frame_name(name: &str) -> &str {
    name.strip_prefix('/').unwrap_or(name)
}

/// The transform tree: every frame's transform into its parent, over a cache length of time.
#[derive(Debug)]
pub struct FrameTree {
    registry: Registry<Timestamp>,
    cache: Duration,
    /// The latest ROS time the tree was told of ([`FrameTree::observe_time`]).
    now: Option<u64>,
}

impl FrameTree {
    /// An empty tree keeping each dynamic edge's history `cache` behind its newest sample.
    pub fn new(cache: Duration) -> Self {
        FrameTree {
            registry: Registry::with_max_age(cache),
            cache,
            now: None,
        }
    }

    /// ROS time is now `now` (ns): when it went back (a restarted simulation, a clock reset),
    /// every dynamic edge's history is cleared, as tf2_ros clears its buffer, so samples of the
    /// new time are not dropped behind the old ones; static edges stay. True when it cleared.
    /// Time 0 (a simulated clock not started yet) tells nothing and is ignored.
    pub fn observe_time(&mut self, now: u64) -> bool {
        if now == 0 {
            return false;
        }
        let back = self.now.is_some_and(|before| now < before);
        self.now = Some(now);
        if back {
            self.registry.remove_transforms_before(Timestamp::from_nanos(u64::MAX));
        }
        back
    }

    /// Adds `child`'s pose in `parent`, `transform`, at ROS time `stamp` (ns; `None`: static,
    /// valid at every instant, as on `/tf_static`). A frame keeps its first parent and its
    /// kind (static or dynamic); a sample older than the cache behind the newest is dropped;
    /// one dated more than the cache ahead of the ROS time last observed
    /// ([`FrameTree::observe_time`]) is refused: after a clock jump back, a sample of the old
    /// time still in flight would otherwise pin the edge's history there.
    pub fn insert(
        &mut self,
        parent: &str,
        child: &str,
        transform: &Isometry3<f64>,
        stamp: Option<u64>,
    ) -> Result<(), TfError> {
        let (parent, child) = (frame_name(parent), frame_name(child));
        let rejected = |why: String| TfError::Rejected {
            parent: parent.to_owned(),
            child: child.to_owned(),
            why,
        };
        if parent.is_empty() || child.is_empty() {
            return Err(rejected("a frame name is empty".into()));
        }
        if let (Some(ns), Some(now)) = (stamp, self.now) {
            let ahead = Duration::from_nanos(ns.saturating_sub(now));
            if ahead > self.cache {
                return Err(rejected(format!(
                    "dated {:.3} s ahead of ROS time, beyond the {} s cache",
                    ahead.as_secs_f64(),
                    self.cache.as_secs_f64()
                )));
            }
        }
        let t = transform.translation.vector;
        let q = transform.rotation.quaternion();
        let stamp = stamp.map_or(Stamp::Static, |ns| Stamp::At(Timestamp::from_nanos(ns)));
        let sample = Transform::new(
            parent,
            child,
            Vector3::new(t.x, t.y, t.z),
            Quaternion::from_wxyz(q.w, q.i, q.j, q.k),
            stamp,
        )
        .map_err(|e| rejected(e.to_string()))?;
        self.registry.add_transform(sample).map_err(|e| rejected(e.to_string()))
    }

    /// The pose of `source` in `target` at `at`: the transform that takes a point in `source`
    /// into `target` (tf2's `lookupTransform(target, source, time)`).
    pub fn lookup(&self, target: &str, source: &str, at: At) -> Result<Isometry3<f64>, TfError> {
        let (target, source) = (frame_name(target), frame_name(source));
        let time = match at {
            At::Nanos(ns) => Timestamp::from_nanos(ns),
            At::Latest => match self.registry.latest_common_time(target, source) {
                Ok(Stamp::At(t)) => t,
                // Static all the way (or the same frame): any instant.
                Ok(Stamp::Static) => Timestamp::zero(),
                Err(e) => return Err(tf_error(e, target, source)),
            },
        };
        let found = self
            .registry
            .get_transform(target, source, time)
            .map_err(|e| tf_error(e, target, source))?;
        let (t, q) = (found.translation(), found.rotation());
        let rotation = UnitQuaternion::from_quaternion(NaQuaternion::new(q.w, q.x, q.y, q.z));
        Ok(Isometry3::from_parts(Translation3::new(t.x, t.y, t.z), rotation))
    }

    /// The latest instant (ns) every edge between the frames covers; `None` when they are
    /// joined by static edges only (or are one frame).
    pub fn latest_time(&self, target: &str, source: &str) -> Result<Option<u64>, TfError> {
        let (target, source) = (frame_name(target), frame_name(source));
        match self.registry.latest_common_time(target, source) {
            Ok(Stamp::At(t)) => Ok(Some(t.as_nanos())),
            Ok(Stamp::Static) => Ok(None),
            Err(e) => Err(tf_error(e, target, source)),
        }
    }

    /// The planar pose of `source` in `target` at the latest instant, refused ([`TfError::Stale`])
    /// when that instant is more than `tolerance` before ROS time `now` (ns): the age check of
    /// ROS 1's costmap_2d on a goal's transform, with Nav2's parameter name
    /// `transform_tolerance`. A chain of static edges (and one frame) is never stale. A latest
    /// instant after `now` (a localiser dating its transform ahead, as AMCL does) is fresh,
    /// up to the cache length ahead.
    pub fn planar_fresh(&self, target: &str, source: &str, now: u64, tolerance: Duration) -> Result<Pose2, TfError> {
        if frame_name(target) == frame_name(source) {
            return Ok(Pose2::identity());
        }
        if let Some(latest) = self.latest_time(target, source)? {
            let age_s = (now as f64 - latest as f64) * 1e-9;
            if age_s > tolerance.as_secs_f64() || -age_s > self.cache.as_secs_f64() {
                return Err(TfError::Stale {
                    target: frame_name(target).to_owned(),
                    from: frame_name(source).to_owned(),
                    age_s,
                    tolerance_s: tolerance.as_secs_f64(),
                });
            }
        }
        self.planar(target, source, At::Latest)
    }

    /// `pose`, known in `source` (the robot's odometry pose in `odom`), in `target` (a goal's
    /// frame) through the latest transform, refused as [`FrameTree::planar_fresh`] refuses it.
    /// A law that steers the robot to a goal in `target` is given this pose at every step, so a
    /// localiser's correction of `target → source` moves the robot relative to the goal, as it
    /// moves a Nav2 controller's goal.
    pub fn pose_in(
        &self,
        target: &str,
        source: &str,
        pose: &Pose2,
        now: u64,
        tolerance: Duration,
    ) -> Result<Pose2, TfError> {
        Ok(self.planar_fresh(target, source, now, tolerance)?.compose(pose))
    }

    /// [`FrameTree::lookup`] in the plane: x, y and the yaw of `source` in `target` (the yaw
    /// of the rotation's x axis seen from above; any roll or pitch is dropped, as a wheeled
    /// robot's goal has none).
    pub fn planar(&self, target: &str, source: &str, at: At) -> Result<Pose2, TfError> {
        let iso = self.lookup(target, source, at)?;
        let x_axis = iso.rotation * nalgebra::Vector3::x();
        let t = iso.translation.vector;
        Ok(Pose2::new(t.x, t.y, x_axis.y.atan2(x_axis.x)))
    }
}

/// The frame rule of a goal: where it is given, and how the robot is seen from there.
///
/// A goal is given in any frame (`map` from RViz, a localiser's world); the robot's pose comes
/// in the odometry frame. A law steering the robot to the goal is given, at every step, the
/// robot's pose in the goal's frame ([`GoalFrames::robot`]), so the goal's pose in the
/// odometry frame follows the latest transform between them, as a Nav2 controller's goal
/// follows a localiser's correction; a body twist needs no transform. A goal whose frame does
/// not connect to the odometry frame, or whose transform is older than the tolerance, is
/// refused, and a running one ends (Nav2's TF_ERROR).
///
/// ```
/// use mobil_geom::Pose2;
/// use mobil_tf::{FrameTree, GoalFrames};
/// use nalgebra::{Isometry3, Translation3, UnitQuaternion};
/// use std::time::Duration;
///
/// let frames = GoalFrames::new("odom", Duration::from_millis(100));
/// let mut tree = FrameTree::new(Duration::from_secs(10));
/// let odom_in_map = Isometry3::from_parts(Translation3::new(2.0, 0.0, 0.0), UnitQuaternion::identity());
/// tree.insert("map", "odom", &odom_in_map, Some(1_000_000_000)).unwrap();
/// let goal_frame = frames.frame_of("/map");
/// let robot = frames.robot(&tree, &goal_frame, &Pose2::new(1.0, 0.0, 0.0), 1_050_000_000).unwrap();
/// assert_eq!((robot.x, robot.y), (3.0, 0.0));
/// // 0.2 s later the transform is stale: the goal cannot go on.
/// assert!(frames.robot(&tree, &goal_frame, &Pose2::identity(), 1_200_000_000).is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct GoalFrames {
    odom: String,
    tolerance: Duration,
}

impl GoalFrames {
    /// Goals relative to `odom_frame`, through transforms at most `tolerance` old
    /// (`transform_tolerance`).
    pub fn new(odom_frame: &str, tolerance: Duration) -> Self {
        GoalFrames {
            odom: frame_name(odom_frame).to_owned(),
            tolerance,
        }
    }

    /// The odometry frame.
    pub fn odom(&self) -> &str {
        &self.odom
    }

    /// The tolerance.
    pub fn tolerance(&self) -> Duration {
        self.tolerance
    }

    /// The frame a goal whose header names `frame_id` is in: that frame without its leading
    /// `/`, or the odometry frame when it names none (an empty `frame_id`: a hand-typed path's
    /// header; a node may still refuse a pose that names no frame).
    pub fn frame_of(&self, frame_id: &str) -> String {
        match frame_name(frame_id) {
            "" => self.odom.clone(),
            f => f.to_owned(),
        }
    }

    /// Whether `goal_frame` is the odometry frame (no transform needed).
    pub fn is_odom(&self, goal_frame: &str) -> bool {
        frame_name(goal_frame) == self.odom
    }

    /// The odometry frame's pose in `goal_frame` at ROS time `now` (ns): what takes a point in
    /// odometry into the goal's frame. Refused when the frames do not connect or the latest
    /// transform is older than the tolerance ([`FrameTree::planar_fresh`]).
    pub fn odom_in(&self, tree: &FrameTree, goal_frame: &str, now: u64) -> Result<Pose2, TfError> {
        tree.planar_fresh(goal_frame, &self.odom, now, self.tolerance)
    }

    /// The robot's pose `odom_pose` (in the odometry frame) in `goal_frame` at ROS time `now`;
    /// refused as [`GoalFrames::odom_in`].
    pub fn robot(&self, tree: &FrameTree, goal_frame: &str, odom_pose: &Pose2, now: u64) -> Result<Pose2, TfError> {
        Ok(self.odom_in(tree, goal_frame, now)?.compose(odom_pose))
    }
}

/// The crate's error as this one's, with the lookup's frames.
fn tf_error(e: RegistryError<Timestamp>, target: &str, source: &str) -> TfError {
    let text = e.to_string();
    let (target, source) = (target.to_owned(), source.to_owned());
    match e {
        RegistryError::UnknownFrame(f) => TfError::UnknownFrame(f),
        RegistryError::Disconnected { .. } => TfError::Disconnected { target, from: source },
        RegistryError::NotFoundAt { requested, .. } => TfError::Extrapolation {
            requested_s: requested.as_seconds_lossy(),
            detail: text,
            target,
            from: source,
        },
        RegistryError::NoCommonTime { .. } => TfError::NoCommonTime {
            target,
            from: source,
            detail: text,
        },
        _ => TfError::Lookup {
            target,
            from: source,
            detail: text,
        },
    }
}
