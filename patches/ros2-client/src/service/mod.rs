//! Implementation of ROS 2 [Services](https://docs.ros.org/en/rolling/Tutorials/Beginner-CLI-Tools/Understanding-ROS2-Services/Understanding-ROS2-Services.html)
#[allow(unused_imports)]
use log::{debug, error, info, warn};

pub mod client;
pub mod request_id;
pub mod server;
pub(super) mod wrappers;

pub use request_id::*;
use wrappers::*;
pub use server::*;
pub use client::*;

// --------------------------------------------
// --------------------------------------------

/// Selects how Service Requests and Responses are to be mapped to DDS.
///
/// There are different and incompatible ways to map Services onto DDS Topics.
/// In order to interoperate with ROS 2, you have to select the same mapping it
/// uses. The mapping used by ROS2 depends on the DDS implementation used and
/// its configuration.
///
/// For details, see OMG Specification
/// [RPC over DDS](https://www.omg.org/spec/DDS-RPC/1.0/About-DDS-RPC/)
/// Section "7.2.4 Basic and Enhanced Service Mapping for RPC over DDS",
/// which defines Service Mappings "Basic" and "Enhanced".
///
/// ServiceMapping::Cyclone represents a third mapping used by RMW for
/// CycloneDDS.
#[derive(Clone, Copy, Debug, Eq, PartialEq)]
pub enum ServiceMapping {
  /// "Basic" service mapping from RPC over DDS specification.
  /// * RTI Connext with `RMW_CONNEXT_REQUEST_REPLY_MAPPING=basic`, but this is
  ///   not tested, so may not work.
  Basic,

  /// "Enhanced" service mapping from RPC over DDS specification.
  /// * ROS2 Foxy with eProsima DDS,
  /// * ROS2 Galactic with RTI Connext (rmw_connextdds, not rmw_connext_cpp) -
  ///   set environment variable `RMW_CONNEXT_REQUEST_REPLY_MAPPING=extended`
  ///   before running ROS2 executable.
  Enhanced,

  /// CycloneDDS-specific service mapping.
  /// Specification for this mapping is unknown, technical details are
  /// reverse-engineered from ROS2 sources.
  /// * ROS2 Galactic with CycloneDDS - Seems to work on the same host only, not
  ///   over actual network.
  Cyclone,

  /// Per request, the mapping of the peer that sent it, so that one server
  /// answers the clients of both ROS 2 Tier 1 DDS RMWs at once:
  /// * a request written by Eclipse Cyclone DDS (vendor id 01.10, the first two
  ///   bytes of every GUID it makes) is decoded as `Cyclone` and answered in
  ///   that layout;
  /// * any other request (eProsima Fast DDS, RustDDS, ...) as `Enhanced`.
  ///
  /// The choice for a reply is read back from its `RmwRequestId`, whose writer
  /// GID starts with the request writer's GUID prefix in both layouts.
  ///
  /// A client created with `Auto` sends in the Cyclone layout when every server
  /// its request writer has matched is Cyclone DDS's, in `Enhanced` otherwise,
  /// and reads each reply in the layout of its writer's vendor.
  Auto,
}

/// RTPS vendor id of Eclipse Cyclone DDS, the first two bytes of every GUID
/// prefix it makes (RTPS 2.5, 9.3.1.5).
pub const VENDOR_ID_ECLIPSE_CYCLONE: [u8; 2] = [0x01, 0x10];

impl ServiceMapping {
  fn resolve(self, gid: &crate::gid::Gid) -> ServiceMapping {
    match self {
      ServiceMapping::Auto if gid.as_bytes()[..2] == VENDOR_ID_ECLIPSE_CYCLONE => {
        ServiceMapping::Cyclone
      }
      ServiceMapping::Auto => ServiceMapping::Enhanced,
      other => other,
    }
  }

  /// The mapping of a request or a reply written by the DDS writer `writer`
  /// (`Auto`: by the writer's vendor).
  pub fn of_writer(self, writer: &crate::gid::Gid) -> ServiceMapping {
    self.resolve(writer)
  }

  /// The mapping of the reply to the request `id` (as the server decoded it).
  pub fn of_reply(self, id: &RmwRequestId) -> ServiceMapping {
    self.resolve(&id.writer_gid)
  }

  /// The mapping a client sends in, given the GUIDs of the readers its request
  /// writer has matched (`Auto`: `Cyclone` when there is at least one and every
  /// one is Cyclone DDS's, otherwise `Enhanced`, which every server of this
  /// crate also answers).
  pub fn for_servers<'a>(self, matched: impl IntoIterator<Item = &'a rustdds::GUID>) -> ServiceMapping {
    match self {
      ServiceMapping::Auto => {
        let mut any = false;
        for reader in matched {
          if crate::gid::Gid::from(*reader).as_bytes()[..2] != VENDOR_ID_ECLIPSE_CYCLONE {
            return ServiceMapping::Enhanced;
          }
          any = true;
        }
        if any {
          ServiceMapping::Cyclone
        } else {
          ServiceMapping::Enhanced
        }
      }
      other => other,
    }
  }
}
