//! Rust types for the `mobil_msgs` interface package and for the standard ROS 2 messages the
//! suite uses, generated at build time from their `.msg` / `.srv` files (see `build.rs`).
//!
//! Module paths follow the ROS names: `geometry_msgs::msg::Twist`, `mobil_msgs::msg::NavStatus`,
//! `mobil_msgs::srv::CheckRoute`, `nav2_msgs::action::NavigateToPose`. Every message implements
//! [`RosMessage`], which knows its ROS type name, and `ros2_client::Message`, so it can be published
//! and subscribed with ros2-client. An action `pkg/action/Name` is the marker type
//! `pkg::action::Name` implementing [`RosAction`], with its parts `NameGoal`, `NameResult` and
//! `NameFeedback` beside it; the goal-id wrappers of the action's services and feedback topic
//! (`SendGoal`, `GetResult`, `FeedbackMessage`) are ros2-client's (`ros2_client::action`).

#[allow(clippy::all)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/generated.rs"));
}
pub use generated::*;

pub mod idl;

/// The REP-2011 type hash (`RIHS01_…`) of a type built here, computed at build time from its
/// definition and its nested types', as rosidl computes it: a message (`geometry_msgs/msg/Twist`),
/// a service or action part (`lifecycle_msgs/srv/GetState_Request`,
/// `nav2_msgs/action/Spin_FeedbackMessage`) or the service, event or action type itself
/// (`lifecycle_msgs/srv/GetState`); `None` for a type not built here.
pub fn type_hash(type_name: &str) -> Option<&'static str> {
    TYPE_HASHES
        .binary_search_by(|(name, _)| (*name).cmp(type_name))
        .ok()
        .map(|i| TYPE_HASHES[i].1)
}

use ros2_client::{ActionTypeName, MessageTypeName, ServiceTypeName};

/// A message type generated from a `.msg` file.
pub trait RosMessage:
    ros2_client::Message + Clone + Default + PartialEq + std::fmt::Debug + Send + Sync + 'static
{
    /// ROS package, e.g. `geometry_msgs`.
    const PACKAGE: &'static str;
    /// Type name inside the package, e.g. `Twist`.
    const NAME: &'static str;

    /// The name ros2-client uses to create a topic of this type.
    fn type_name() -> MessageTypeName {
        MessageTypeName::new(Self::PACKAGE, Self::NAME)
    }
}

/// A service type generated from a `.srv` file.
pub trait RosService {
    /// The request half.
    type Request: RosMessage;
    /// The response half.
    type Response: RosMessage;
    /// ROS package.
    const PACKAGE: &'static str;
    /// Service name inside the package.
    const NAME: &'static str;

    /// The name ros2-client uses to create a server or client of this service.
    fn type_name() -> ServiceTypeName {
        ServiceTypeName::new(Self::PACKAGE, Self::NAME)
    }
}

/// An action type generated from an `.action` file.
pub trait RosAction {
    /// What a client asks for.
    type Goal: RosMessage;
    /// What the server answers when the goal ends (whatever its status).
    type Result: RosMessage;
    /// What the server reports while the goal executes.
    type Feedback: RosMessage;
    /// ROS package.
    const PACKAGE: &'static str;
    /// Action name inside the package.
    const NAME: &'static str;

    /// The name ros2-client uses to create a server or client of this action (`pkg/action/Name`;
    /// ros2-client derives the DDS names of the parts, e.g. `pkg::action::dds_::Name_SendGoal_Request_`).
    fn type_name() -> ActionTypeName {
        ActionTypeName::new(Self::PACKAGE, Self::NAME)
    }
}
