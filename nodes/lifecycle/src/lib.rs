//! The managed (lifecycle) node of ROS 2, and the node side of Nav2's bond, ROS-free.
//!
//! - [`machine`]: the states and transitions of the ROS 2 managed-node design exactly as
//!   `rcl_lifecycle`'s default state machine registers them — the same ids, labels, order of
//!   the transition graph, transition events and answers to a refused request — so that a
//!   lifecycle manager (Nav2's `nav2_lifecycle_manager`, `ros2 lifecycle`) cannot tell a mobil
//!   node from an `rclcpp_lifecycle` or `rclpy.lifecycle` one.
//! - [`bond`]: when the node sends its `bond/msg/Status` heartbeats to the lifecycle manager,
//!   when it says the bond is broken, and when it notices the manager's loss.
//!
//! Neither reads a clock nor does I/O: the node kit (`mobil_ros::lifecycle`) serves the
//! `lifecycle_msgs` services and the `bond` topic around them.

pub mod bond;
pub mod machine;

pub use bond::{Beat, BondSettings, Heart, PeerChange};
pub use machine::{CallbackReturn, Change, Event, Machine, Refused, State, Step, TransitionDef, GRAPH};
