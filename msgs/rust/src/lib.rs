//! Rust types for the `mobil_msgs` interface package and for the standard ROS 2 messages the
//! suite uses, generated at build time from their `.msg` / `.srv` files (see `build.rs`).
//!
//! Module paths follow the ROS names: `geometry_msgs::msg::Twist`, `mobil_msgs::msg::NavStatus`,
//! `mobil_msgs::srv::CheckRoute`. Every message implements [`RosMessage`], which knows its ROS type
//! name, and `ros2_client::Message`, so it can be published and subscribed with ros2-client.

#[allow(clippy::all)]
mod generated {
    include!(concat!(env!("OUT_DIR"), "/generated.rs"));
}
pub use generated::*;

pub mod idl;

use ros2_client::{MessageTypeName, ServiceTypeName};

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
