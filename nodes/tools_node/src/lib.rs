//! What the demo's executables share. Their records, summaries, figures and decisions are
//! ROS-free, in `mobil_tools` (tested there on recorded data); the binaries in `src/bin` are the
//! shells, and this library holds the message work more than one of them does: goals and routes
//! in `odom` stamped now, a service client, a status read for `mobil_tools`.
#![warn(missing_docs)]

use mobil_geom::Pose2;
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::PoseStamped;
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::nav_msgs::msg::Path;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::RosService;
use mobil_ros::geometry::pose_stamped;
use mobil_ros::time::{nanos_from_stamp, stamp_from_nanos};
use mobil_ros::{qos, RosNode};
use mobil_tools::status::{GoalState, Status};
use ros2_client::{Client, Name, ServiceMapping};

/// The frame the demo's goals and routes are given in.
pub const FRAME: &str = "odom";

/// A header in [`FRAME`] stamped now (the node's ROS time).
pub fn header_now(node: &RosNode) -> Header {
    Header {
        stamp: stamp_from_nanos(node.now_nanos()),
        frame_id: FRAME.into(),
    }
}

/// The pose (x, y, yaw) in [`FRAME`], stamped now: a goal or a dock.
pub fn pose_now(node: &RosNode, (x, y, yaw): (f64, f64, f64)) -> PoseStamped {
    pose_stamped(header_now(node), &Pose2::new(x, y, yaw))
}

/// A waypoint route in [`FRAME`], stamped now, every pose with the path's header and yaw 0.
pub fn route_now(node: &RosNode, route: &[(f64, f64)]) -> Path {
    let header = header_now(node);
    let poses = route
        .iter()
        .map(|&(x, y)| PoseStamped {
            header: header.clone(),
            ..pose_now(node, (x, y, 0.0))
        })
        .collect();
    Path { header, poses }
}

/// A client of the service `name` (resolved in the node's namespace; reliable, depth 10, both
/// ways), sending in the request/reply layout of the servers it reaches: Cyclone DDS's when
/// every one is Cyclone DDS, Fast DDS's otherwise (which the suite's servers also answer).
pub fn service_client<S: RosService>(
    node: &mut RosNode,
    name: &str,
) -> anyhow::Result<Client<S::Request, S::Response>> {
    let name = node.names().resolve(name)?;
    let name = Name::parse(&name).map_err(|e| anyhow::anyhow!("bad service name {name}: {e:?}"))?;
    let qos = qos::reliable(10);
    node.inner()
        .create_client::<S::Request, S::Response>(ServiceMapping::Auto, &name, &S::type_name(), qos.clone(), qos)
        .map_err(|e| anyhow::anyhow!("cannot create a client of {name}: {e:?}"))
}

/// A stamp in nanoseconds, `now` for a zero or invalid one (a status sent before its node's
/// clock ran).
pub fn stamp_or(stamp: &Time, now: i64) -> i64 {
    nanos_from_stamp(stamp).filter(|&t| t > 0).unwrap_or(now)
}

/// A navigation node's status as `mobil_tools` reads it (an unknown state is idle).
pub fn status_of(s: &NavStatus) -> Status {
    let state = match s.state {
        NavStatus::ACTIVE => GoalState::Active,
        NavStatus::SUCCEEDED => GoalState::Succeeded,
        NavStatus::FAILED => GoalState::Failed,
        _ => GoalState::Idle,
    };
    Status {
        state,
        waypoint_index: s.waypoint_index,
        mode: s.mode.clone(),
        reason: s.reason.clone(),
        docking: (s.e, s.alpha, s.theta, s.lyapunov),
    }
}
