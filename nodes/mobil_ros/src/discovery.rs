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
//! | anything else | as `LOCALHOST`, with a warning (rcl's rule) | | |
//!
//! A static peer is an IPv4 address or a host name (resolved once, at start-up; one that does
//! not resolve is left out with a warning), separated by `;`; announcements go to its
//! well-known discovery ports of the first 12 participant ids (so, as for `LOCALHOST`, to the
//! first 12 DDS participants of that host), so a node there in any range but `OFF` finds this
//! one, and answers.

use std::net::{IpAddr, ToSocketAddrs};

use rustdds::DomainParticipantBuilder;

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

impl Discovery {
    /// The settings from the variables' values (`None`: unset), as Jazzy's rcl reads them:
    /// `ROS_LOCALHOST_ONLY=1` wins (LOCALHOST, the range and the static peers ignored, with a
    /// warning); an unknown range is LOCALHOST, with a warning; values are compared exactly.
    pub fn from_values(range: Option<&str>, static_peers: Option<&str>, localhost_only: Option<&str>) -> Self {
        let mut notes = Vec::new();
        let mut static_peers: Vec<String> = static_peers
            .unwrap_or("")
            .split(';')
            .map(str::trim)
            .filter(|p| !p.is_empty())
            .map(str::to_owned)
            .collect();
        if localhost_only == Some("1") {
            notes.push(
                "ROS_LOCALHOST_ONLY=1 (deprecated): discovery range LOCALHOST; ROS_AUTOMATIC_DISCOVERY_RANGE and ROS_STATIC_PEERS ignored"
                    .into(),
            );
            return Discovery {
                range: Range::Localhost,
                static_peers: Vec::new(),
                notes,
            };
        }
        let range = match range {
            None | Some("") => Range::Subnet,
            Some("SUBNET") => Range::Subnet,
            Some("LOCALHOST") => Range::Localhost,
            Some("OFF") => Range::Off,
            Some("SYSTEM_DEFAULT") => Range::SystemDefault,
            Some(other) => {
                notes.push(format!(
                    "ROS_AUTOMATIC_DISCOVERY_RANGE `{other}` is not one of SUBNET, LOCALHOST, OFF, SYSTEM_DEFAULT: LOCALHOST assumed"
                ));
                Range::Localhost
            }
        };
        if range == Range::Off && !static_peers.is_empty() {
            notes.push("ROS_STATIC_PEERS ignored: ROS_AUTOMATIC_DISCOVERY_RANGE is OFF".into());
            static_peers.clear();
        }
        Discovery {
            range,
            static_peers,
            notes,
        }
    }

    /// The settings from the process environment.
    pub fn from_env() -> Self {
        let var = |name: &str| std::env::var(name).ok();
        Self::from_values(
            var("ROS_AUTOMATIC_DISCOVERY_RANGE").as_deref(),
            var("ROS_STATIC_PEERS").as_deref(),
            var("ROS_LOCALHOST_ONLY").as_deref(),
        )
    }

    /// The static peers' IPv4 addresses (host names resolved, IPv4 preferred), and a note for
    /// each peer left out: one that does not resolve (the network may not be up yet), or IPv6
    /// only (RustDDS's unicast socket is IPv4).
    pub fn peer_addresses(&self) -> (Vec<IpAddr>, Vec<String>) {
        let mut addresses = Vec::new();
        let mut notes = Vec::new();
        for peer in &self.static_peers {
            let resolved: Vec<IpAddr> = match peer.parse::<IpAddr>() {
                Ok(ip) => vec![ip],
                Err(_) => (peer.as_str(), 0)
                    .to_socket_addrs()
                    .map(|a| a.map(|a| a.ip()).collect())
                    .unwrap_or_default(),
            };
            match resolved.iter().find(|ip| ip.is_ipv4()) {
                Some(ip) => addresses.push(*ip),
                None if resolved.is_empty() => {
                    notes.push(format!("ROS_STATIC_PEERS: `{peer}` does not resolve: left out"))
                }
                None => notes.push(format!(
                    "ROS_STATIC_PEERS: `{peer}` has no IPv4 address (IPv6 peers are not supported): left out"
                )),
            }
        }
        (addresses, notes)
    }

    /// The participant builder set up for these settings, with a note for each static peer left
    /// out.
    pub fn apply(&self, builder: DomainParticipantBuilder) -> (DomainParticipantBuilder, Vec<String>) {
        let (peers, notes) = self.peer_addresses();
        let builder = match self.range {
            Range::Subnet | Range::SystemDefault => builder.with_static_peers(peers),
            Range::Localhost => builder.multicast(false).with_static_peers(peers),
            Range::Off => builder.multicast(false).same_host_loopback(false),
        };
        (builder, notes)
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
        let d = Discovery::from_values(None, None, None);
        assert_eq!(d.range, Range::Subnet);
        assert!(d.static_peers.is_empty() && d.notes.is_empty());
        assert_eq!(Discovery::from_values(Some(""), Some(""), None).range, Range::Subnet);
    }

    #[test]
    fn ranges_and_peers_are_read_as_rcl_reads_them() {
        let d = Discovery::from_values(Some("LOCALHOST"), Some("10.0.0.2; robot.local;;"), None);
        assert_eq!(d.range, Range::Localhost);
        assert_eq!(d.static_peers, vec!["10.0.0.2".to_string(), "robot.local".to_string()]);
        assert_eq!(
            Discovery::from_values(Some("SYSTEM_DEFAULT"), None, None).range,
            Range::SystemDefault
        );
        // rcl: an unknown value (compared exactly) is LOCALHOST, with a warning.
        let d = Discovery::from_values(Some("subnet"), None, None);
        assert_eq!(d.range, Range::Localhost);
        assert!(d.notes[0].contains("`subnet`"), "{:?}", d.notes);
    }

    #[test]
    fn off_ignores_static_peers_and_localhost_only_wins() {
        let d = Discovery::from_values(Some("OFF"), Some("10.0.0.2"), None);
        assert_eq!(d.range, Range::Off);
        assert!(d.static_peers.is_empty());
        assert_eq!(d.notes.len(), 1);
        // rcl: ROS_LOCALHOST_ONLY=1 forces LOCALHOST and drops the range and the peers.
        let d = Discovery::from_values(Some("SUBNET"), Some("10.0.0.2"), Some("1"));
        assert_eq!(d.range, Range::Localhost);
        assert!(d.static_peers.is_empty());
        assert!(d.notes[0].contains("deprecated"));
        assert_eq!(Discovery::from_values(None, None, Some("0")).range, Range::Subnet);
    }

    #[test]
    fn peers_resolve_to_ipv4_or_are_left_out_with_a_note() {
        let d = Discovery::from_values(None, Some("127.0.0.1;::1;localhost;no-such-host.invalid"), None);
        let (a, notes) = d.peer_addresses();
        assert_eq!(a, vec![IpAddr::from([127, 0, 0, 1]), IpAddr::from([127, 0, 0, 1])]);
        assert_eq!(notes.len(), 2, "{notes:?}");
        assert!(notes[0].contains("`::1`") && notes[0].contains("IPv6"));
        assert!(notes[1].contains("does not resolve"));
    }
}
