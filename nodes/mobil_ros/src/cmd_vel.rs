//! `cmd_vel` as `geometry_msgs/Twist` or, with `enable_stamped_cmd_vel` (Nav2 Jazzy's
//! parameter, default false as in Jazzy), `geometry_msgs/TwistStamped`, which Nav2's
//! `TwistPublisher`/`TwistSubscriber` and Jazzy's ros2_controllers use.
//!
//! - [`CmdVelOut`]: a node's command publisher of either type; a stamped command carries the
//!   node's ROS time and `base_frame`.
//! - [`stamped_twist`]: what a subscriber takes of either: the twist. The header is never read:
//!   watchdogs judge commands by their arrival on the steady clock (the time rule,
//!   [`crate::time`]), so a command from a machine whose clock is off still drives, and an old
//!   one replayed still stops at its timeout.
//! - [`type_mismatch`]: an endpoint of the other type on the topic (DDS does not match them, so
//!   the robot would silently not move), told with what to set.

use crate::config::Decl;
use crate::node::{NodeClock, RosNode};
use crate::stop::{final_stop, FinalStop};
use mobil_msgs::geometry_msgs::msg::{Twist, TwistStamped};
use mobil_msgs::std_msgs::msg::Header;
use ros2_client::Publisher;
use std::time::Duration;

/// The parameter, nested by every node that publishes or subscribes `cmd_vel`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CmdVelType {
    /// `cmd_vel` is `TwistStamped` (`enable_stamped_cmd_vel`).
    pub enable_stamped_cmd_vel: bool,
}

impl CmdVelType {
    /// Declares `enable_stamped_cmd_vel` (false, read-only: the topic's type is fixed at start).
    pub fn declare(d: &mut Decl<CmdVelType>) {
        d.boolean(
            "enable_stamped_cmd_vel",
            false,
            "cmd_vel is geometry_msgs/TwistStamped instead of Twist (Nav2 Jazzy's parameter; Jazzy's \
             ros2_controllers take stamped commands)",
            |c, v| c.enable_stamped_cmd_vel = v,
        )
        .read_only();
    }
}

/// The DDS type names of the two (ROS 2's mangling).
const TWIST_DDS: &str = "geometry_msgs::msg::dds_::Twist_";
const STAMPED_DDS: &str = "geometry_msgs::msg::dds_::TwistStamped_";

/// A node's `cmd_vel` publisher.
pub struct CmdVelOut {
    out: Out,
    frame_id: String,
    clock: NodeClock,
}

enum Out {
    Plain(Publisher<Twist>),
    Stamped(Publisher<TwistStamped>),
}

impl CmdVelOut {
    /// Publishes `topic` (normally `cmd_vel`, resolved and remapped) as `TwistStamped` in
    /// `frame_id` when `stamped`, else as `Twist`; reliable, volatile, depth 10.
    pub fn create(node: &mut RosNode, topic: &str, stamped: bool, frame_id: &str) -> anyhow::Result<Self> {
        let qos = crate::qos::default_qos();
        let out = if stamped {
            Out::Stamped(node.publisher::<TwistStamped>(topic, &qos)?)
        } else {
            Out::Plain(node.publisher::<Twist>(topic, &qos)?)
        };
        Ok(CmdVelOut {
            out,
            frame_id: frame_id.to_owned(),
            clock: node.clock(),
        })
    }

    /// Whether commands go out stamped.
    pub fn is_stamped(&self) -> bool {
        matches!(self.out, Out::Stamped(_))
    }

    fn stamped(&self, twist: Twist) -> TwistStamped {
        TwistStamped {
            header: Header {
                stamp: crate::time::stamp_from_nanos(self.clock.now_nanos()),
                frame_id: self.frame_id.clone(),
            },
            twist,
        }
    }

    /// Publishes one command.
    pub fn publish(&self, twist: Twist) -> Result<(), String> {
        match &self.out {
            Out::Plain(p) => p.publish(twist).map_err(|e| format!("{e:?}")),
            Out::Stamped(p) => p.publish(self.stamped(twist)).map_err(|e| format!("{e:?}")),
        }
    }

    /// The last zero command, waited for ([`final_stop`]).
    pub async fn final_stop(&self, max_wait: Duration) -> FinalStop {
        match &self.out {
            Out::Plain(p) => final_stop(p, Twist::default(), max_wait).await,
            Out::Stamped(p) => final_stop(p, self.stamped(Twist::default()), max_wait).await,
        }
    }

    /// An endpoint of the other type on the topic, told (see [`type_mismatch`]).
    pub fn mismatch(&self, node: &RosNode, topic: &str) -> Option<String> {
        type_mismatch(&node.endpoint_types(topic), self.is_stamped(), topic)
    }
}

/// How often [`TypeWatch`] looks at the topic's endpoints.
pub const TYPE_CHECK_PERIOD: Duration = Duration::from_secs(2);

/// Looks for an endpoint of the other type on `cmd_vel` every [`TYPE_CHECK_PERIOD`] (from a
/// node's periodic tick), so that a graph mixing Twist and TwistStamped is told in the log.
#[derive(Debug, Clone, Default)]
pub struct TypeWatch {
    next: Option<std::time::Instant>,
}

impl TypeWatch {
    /// At `now`, if a check is due: the mismatch on `topic` for a node whose `cmd_vel` is
    /// `stamped`, if any (the caller logs it, rate-limited).
    pub fn check(&mut self, node: &RosNode, stamped: bool, topic: &str, now: std::time::Instant) -> Option<String> {
        if self.next.is_some_and(|next| now < next) {
            return None;
        }
        self.next = Some(now + TYPE_CHECK_PERIOD);
        type_mismatch(&node.endpoint_types(topic), stamped, topic)
    }
}

/// The twist of a stamped command; its header is not read (module docs).
pub fn stamped_twist(m: TwistStamped) -> Twist {
    m.twist
}

/// A line saying what to set, when `endpoints` (from [`RosNode::endpoint_types`]) hold one of
/// the other type than this node's (`stamped`) on `topic`; `None` when all agree.
pub fn type_mismatch(endpoints: &[(bool, String)], stamped: bool, topic: &str) -> Option<String> {
    let theirs = if stamped { TWIST_DDS } else { STAMPED_DDS };
    let (is_writer, _) = endpoints.iter().find(|(_, t)| t == theirs)?;
    let what = if *is_writer { "a publisher" } else { "a subscriber" };
    let (their_type, set) = if stamped {
        (
            "geometry_msgs/msg/Twist",
            "enable_stamped_cmd_vel:=false here, or stamped commands there",
        )
    } else {
        (
            "geometry_msgs/msg/TwistStamped",
            "enable_stamped_cmd_vel:=true here (Nav2: the same parameter)",
        )
    };
    Some(format!(
        "{topic}: {what} of {their_type} is on the topic, which this node has as {}: they do not match; set {set}",
        if stamped {
            "geometry_msgs/msg/TwistStamped"
        } else {
            "geometry_msgs/msg/Twist"
        }
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_peer_of_the_other_type_is_told_with_what_to_set() {
        let plain_pub = vec![(true, TWIST_DDS.to_owned())];
        let stamped_sub = vec![(false, STAMPED_DDS.to_owned())];
        assert_eq!(type_mismatch(&plain_pub, false, "/cmd_vel"), None);
        let told = type_mismatch(&plain_pub, true, "/cmd_vel").unwrap();
        assert!(
            told.starts_with("/cmd_vel: a publisher of geometry_msgs/msg/Twist"),
            "{told}"
        );
        assert!(told.contains("enable_stamped_cmd_vel:=false"));
        let told = type_mismatch(&stamped_sub, false, "/cmd_vel").unwrap();
        assert!(
            told.contains("a subscriber of geometry_msgs/msg/TwistStamped"),
            "{told}"
        );
        assert!(told.contains("enable_stamped_cmd_vel:=true"));
        assert_eq!(type_mismatch(&[(true, "other".into())], true, "/cmd_vel"), None);
    }

    #[test]
    fn stamped_twist_ignores_the_header() {
        let mut m = TwistStamped::default();
        m.header.stamp.sec = -5;
        m.twist.linear.x = 0.3;
        assert_eq!(stamped_twist(m).linear.x, 0.3);
    }

    /// The DDS names are the ones a Jazzy rmw gives (ros2-client's mangling of the types).
    #[test]
    fn dds_type_names_match_ros2_clients_mangling() {
        use mobil_msgs::RosMessage;
        assert_eq!(Twist::type_name().dds_msg_type(), TWIST_DDS);
        assert_eq!(TwistStamped::type_name().dds_msg_type(), STAMPED_DDS);
    }
}
