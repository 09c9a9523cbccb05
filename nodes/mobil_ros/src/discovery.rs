//! How far a node looks for peers: ROS 2 Jazzy's `ROS_AUTOMATIC_DISCOVERY_RANGE` and
//! `ROS_STATIC_PEERS` (and the deprecated `ROS_LOCALHOST_ONLY`), read as rcl reads them and
//! applied to the DDS participant as the rmw layers apply them.
//!
//! | range | multicast | announced to | finds |
//! |---|---|---|---|
//! | `SUBNET` (unset, empty) | on | multicast, `127.0.0.1`, the static peers | the subnet, this host, the static peers |
//! | `LOCALHOST` | off | `127.0.0.1`, the static peers | this host, the static peers |
//! | `OFF` | off | nobody (static peers ignored, with a warning) | none by itself (one that announces itself to it is answered) |
//! | `SYSTEM_DEFAULT` | as `SUBNET` (the participant's own defaults) | | |
//!
//! A static peer is an IP address or a host name (resolved once, at start-up), separated by
//! `;`; announcements go to its well-known discovery ports of the first participant ids, so a
//! node there in any range but `OFF` finds this one, and answers.

use std::net::{IpAddr, ToSocketAddrs};

use rustdds::DomainParticipantBuilder;
use thiserror::Error;

/// `ROS_AUTOMATIC_DISCOVERY_RANGE`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Range {
    /// Every node multicast reaches (the default).
    Subnet,
    /// This host only.
    Localhost,
    /// No automatic discovery.
    Off,
    /// The middleware's own settings.
    SystemDefault,
}

/// The discovery settings of a node's participant.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Discovery {
    /// How far automatic discovery goes.
    pub range: Range,
    /// The static peers as given (addresses or host names).
    pub static_peers: Vec<String>,
    /// What the environment said that the node should log (a deprecated or ignored variable).
    pub notes: Vec<String>,
}

/// An environment the node cannot run with.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum DiscoveryError {
    /// `ROS_AUTOMATIC_DISCOVERY_RANGE` names no range.
    #[error("ROS_AUTOMATIC_DISCOVERY_RANGE `{0}` is not one of SUBNET, LOCALHOST, OFF, SYSTEM_DEFAULT")]
    Range(String),
    /// A static peer that is not an address and does not resolve.
    #[error("ROS_STATIC_PEERS: `{0}` is not an IP address and does not resolve to one")]
    Peer(String),
}

impl Discovery {
    /// The settings from the variables' values (`None`: unset).
    pub fn from_values(
        range: Option<&str>,
        static_peers: Option<&str>,
        localhost_only: Option<&str>,
    ) -> Result<Self, DiscoveryError> {
        let mut notes = Vec::new();
        let mut range = match range.map(str::trim) {
            None | Some("") => None,
            Some("SUBNET") => Some(Range::Subnet),
            Some("LOCALHOST") => Some(Range::Localhost),
            Some("OFF") => Some(Range::Off),
            Some("SYSTEM_DEFAULT") => Some(Range::SystemDefault),
            Some(other) => return Err(DiscoveryError::Range(other.to_owned())),
        };
        if localhost_only.map(str::trim) == Some("1") {
            if range.is_none() {
                range = Some(Range::Localhost);
                notes.push(
                    "ROS_LOCALHOST_ONLY is deprecated; it is read as ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST".into(),
                );
            } else {
                notes.push("ROS_LOCALHOST_ONLY ignored: ROS_AUTOMATIC_DISCOVERY_RANGE is set".into());
            }
        }
        let range = range.unwrap_or(Range::Subnet);
        let mut static_peers: Vec<String> = static_peers
            .unwrap_or("")
            .split(';')
            .map(str::trim)
            .filter(|p| !p.is_empty())
            .map(str::to_owned)
            .collect();
        if range == Range::Off && !static_peers.is_empty() {
            notes.push("ROS_STATIC_PEERS ignored: ROS_AUTOMATIC_DISCOVERY_RANGE is OFF".into());
            static_peers.clear();
        }
        Ok(Discovery {
            range,
            static_peers,
            notes,
        })
    }

    /// The settings from the process environment.
    pub fn from_env() -> Result<Self, DiscoveryError> {
        let var = |name: &str| std::env::var(name).ok();
        Self::from_values(
            var("ROS_AUTOMATIC_DISCOVERY_RANGE").as_deref(),
            var("ROS_STATIC_PEERS").as_deref(),
            var("ROS_LOCALHOST_ONLY").as_deref(),
        )
    }

    /// The static peers' addresses (host names resolved).
    pub fn peer_addresses(&self) -> Result<Vec<IpAddr>, DiscoveryError> {
        self.static_peers
            .iter()
            .map(|peer| {
                peer.parse::<IpAddr>().or_else(|_| {
                    (peer.as_str(), 0)
                        .to_socket_addrs()
                        .ok()
                        .and_then(|mut a| a.next())
                        .map(|a| a.ip())
                        .ok_or_else(|| DiscoveryError::Peer(peer.clone()))
                })
            })
            .collect()
    }

    /// The participant builder set up for these settings.
    pub fn apply(&self, builder: DomainParticipantBuilder) -> Result<DomainParticipantBuilder, DiscoveryError> {
        let peers = self.peer_addresses()?;
        Ok(match self.range {
            Range::Subnet | Range::SystemDefault => builder.with_static_peers(peers),
            Range::Localhost => builder.multicast(false).with_static_peers(peers),
            Range::Off => builder.multicast(false).same_host_loopback(false),
        })
    }

    /// One line for the node's start-up log.
    pub fn describe(&self) -> String {
        let range = match self.range {
            Range::Subnet => "SUBNET",
            Range::Localhost => "LOCALHOST",
            Range::Off => "OFF",
            Range::SystemDefault => "SYSTEM_DEFAULT",
        };
        if self.static_peers.is_empty() {
            format!("discovery range {range}")
        } else {
            format!("discovery range {range}, static peers {}", self.static_peers.join(";"))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unset_is_subnet_without_peers() {
        let d = Discovery::from_values(None, None, None).unwrap();
        assert_eq!(d.range, Range::Subnet);
        assert!(d.static_peers.is_empty() && d.notes.is_empty());
        assert_eq!(
            Discovery::from_values(Some(""), Some(""), None).unwrap().range,
            Range::Subnet
        );
    }

    #[test]
    fn ranges_and_peers_are_read_as_rcl_reads_them() {
        let d = Discovery::from_values(Some("LOCALHOST"), Some("10.0.0.2; robot.local;;"), None).unwrap();
        assert_eq!(d.range, Range::Localhost);
        assert_eq!(d.static_peers, vec!["10.0.0.2".to_string(), "robot.local".to_string()]);
        assert_eq!(
            Discovery::from_values(Some("SYSTEM_DEFAULT"), None, None)
                .unwrap()
                .range,
            Range::SystemDefault
        );
        let e = Discovery::from_values(Some("subnet"), None, None).unwrap_err();
        assert!(e.to_string().contains("`subnet`"), "{e}");
    }

    #[test]
    fn off_ignores_static_peers_and_localhost_only_is_a_deprecated_localhost() {
        let d = Discovery::from_values(Some("OFF"), Some("10.0.0.2"), None).unwrap();
        assert_eq!(d.range, Range::Off);
        assert!(d.static_peers.is_empty());
        assert_eq!(d.notes.len(), 1);
        let d = Discovery::from_values(None, None, Some("1")).unwrap();
        assert_eq!(d.range, Range::Localhost);
        assert!(d.notes[0].contains("deprecated"));
        let d = Discovery::from_values(Some("SUBNET"), None, Some("1")).unwrap();
        assert_eq!(d.range, Range::Subnet);
        assert!(d.notes[0].contains("ignored"));
    }

    #[test]
    fn peers_resolve_or_are_refused() {
        let d = Discovery::from_values(None, Some("127.0.0.1;::1;localhost"), None).unwrap();
        let a = d.peer_addresses().unwrap();
        assert_eq!(a[0], IpAddr::from([127, 0, 0, 1]));
        assert_eq!(a[1], "::1".parse::<IpAddr>().unwrap());
        assert!(a[2].is_loopback());
        let d = Discovery::from_values(None, Some("no-such-host.invalid"), None).unwrap();
        assert!(matches!(d.peer_addresses(), Err(DiscoveryError::Peer(_))));
    }
}
