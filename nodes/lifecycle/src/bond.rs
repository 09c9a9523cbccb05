//! The node side of the bond Nav2's lifecycle manager keeps with every node it manages
//! (`bond/msg/Status` on the topic `bond`, as `bondcpp` speaks it).
//!
//! While the node is active it sends `active = true` every `period` (Nav2's
//! `bond_heartbeat_period`, 0.1 s) under its bond id (the node's name) and an instance id new
//! at each activation. The manager counts the bond formed at the first such message and broken
//! when none came for its timeout (4 s), or at an `active = false`. On deactivation the node
//! breaks the bond as `bondcpp`'s destructor does: `active = false` three times over 100 ms
//! ([`DYING_BEATS`] at bond's `DEAD_PUBLISH_PERIOD`), then silence — never longer, since a
//! manager that activates the node again must not read a stale `active = false` first.
//!
//! The node also watches the manager's heartbeats (same id, another instance): formed at the
//! first, lost after `timeout` without one, or left at the manager's `active = false`
//! ([`PeerChange`]). Nav2's nodes disable this side; a mobil node reports it in its log and
//! keeps its state: the manager, not the node, decides what the node does.
//!
//! ```
//! use mobil_lifecycle::{Beat, BondSettings, Heart};
//! use std::time::{Duration, Instant};
//! let t0 = Instant::now();
//! let mut heart = Heart::new(BondSettings::nav2("controller_server"));
//! heart.start(t0, "5e2c…".into());
//! assert_eq!(heart.poll(t0), Some(Beat { active: true }));
//! assert_eq!(heart.poll(t0 + Duration::from_millis(50)), None);
//! assert_eq!(heart.poll(t0 + Duration::from_millis(100)), Some(Beat { active: true }));
//! ```

use std::time::{Duration, Instant};

/// bond's `DEAD_PUBLISH_PERIOD`: the spacing of the `active = false` messages.
pub const DEAD_PUBLISH_PERIOD: Duration = Duration::from_millis(50);
/// How many `active = false` a breaking node sends (at 0, 50 and 100 ms).
pub const DYING_BEATS: u8 = 3;

/// The bond's id and timing.
#[derive(Debug, Clone, PartialEq)]
pub struct BondSettings {
    /// The bond id: the node's name as the manager lists it in `node_names`.
    pub id: String,
    /// Heartbeat period; zero disables the bond (no message at all).
    pub period: Duration,
    /// After this long without the manager's heartbeat the node counts the manager lost; also
    /// the `heartbeat_timeout` the node's messages carry.
    pub timeout: Duration,
}

impl BondSettings {
    /// Nav2's values: period 0.1 s, timeout 4.0 s.
    pub fn nav2(id: &str) -> Self {
        BondSettings {
            id: id.to_owned(),
            period: Duration::from_millis(100),
            timeout: Duration::from_secs(4),
        }
    }

    /// Whether the bond is on (a positive period).
    pub fn enabled(&self) -> bool {
        !self.period.is_zero()
    }
}

/// One status message to send now.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Beat {
    pub active: bool,
}

/// A change in what the node knows of the manager's side.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PeerChange {
    /// The manager's first heartbeat since the node started (or since it was lost).
    Formed,
    /// No heartbeat for this long (at least the timeout).
    Lost(Duration),
    /// The manager said `active = false`.
    Left,
}

#[derive(Debug, Clone, PartialEq)]
enum Phase {
    Idle,
    Beating { next: Instant },
    Dying { next: Instant, left: u8 },
}

/// The node's side of one bond.
#[derive(Debug, Clone)]
pub struct Heart {
    settings: BondSettings,
    instance_id: String,
    phase: Phase,
    /// The manager's last heartbeat, once the bond formed.
    peer_seen: Option<Instant>,
}

impl Heart {
    /// A bond not started.
    pub fn new(settings: BondSettings) -> Self {
        Heart {
            settings,
            instance_id: String::new(),
            phase: Phase::Idle,
            peer_seen: None,
        }
    }

    /// The settings.
    pub fn settings(&self) -> &BondSettings {
        &self.settings
    }

    /// This activation's instance id (empty before the first start).
    pub fn instance_id(&self) -> &str {
        &self.instance_id
    }

    /// Whether heartbeats are being sent.
    pub fn is_beating(&self) -> bool {
        matches!(self.phase, Phase::Beating { .. })
    }

    /// Starts the bond at activation, under a new `instance_id`: the first heartbeat is due
    /// now. Does nothing when the bond is disabled.
    pub fn start(&mut self, now: Instant, instance_id: String) {
        if !self.settings.enabled() {
            return;
        }
        self.instance_id = instance_id;
        self.phase = Phase::Beating { next: now };
        self.peer_seen = None;
    }

    /// Breaks the bond at deactivation: `active = false` now and [`DYING_BEATS`] − 1 more,
    /// then silence. Does nothing unless the bond is beating.
    pub fn stop(&mut self, now: Instant) {
        if self.is_beating() {
            self.phase = Phase::Dying {
                next: now,
                left: DYING_BEATS,
            };
        }
        self.peer_seen = None;
    }

    /// When [`Heart::poll`] has something to send, or the manager's loss to check: the
    /// instant to wake at.
    pub fn due(&self) -> Option<Instant> {
        let send = match self.phase {
            Phase::Idle => None,
            Phase::Beating { next } | Phase::Dying { next, .. } => Some(next),
        };
        let lost = self.peer_seen.map(|seen| seen + self.settings.timeout);
        match (send, lost) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// The message to send at `now`, if one is due. A late call sends one message, not the
    /// ones missed, and the next is due a period after it.
    pub fn poll(&mut self, now: Instant) -> Option<Beat> {
        match self.phase {
            Phase::Beating { next } if now >= next => {
                self.phase = Phase::Beating {
                    next: now + self.settings.period,
                };
                Some(Beat { active: true })
            }
            Phase::Dying { next, left } if now >= next => {
                self.phase = if left > 1 {
                    Phase::Dying {
                        next: now + DEAD_PUBLISH_PERIOD,
                        left: left - 1,
                    }
                } else {
                    Phase::Idle
                };
                Some(Beat { active: false })
            }
            _ => None,
        }
    }

    /// A `bond/msg/Status` received at `now`: the node's own and other bonds' are ignored;
    /// the manager's are watched while the node beats.
    pub fn receive(&mut self, id: &str, instance_id: &str, active: bool, now: Instant) -> Option<PeerChange> {
        if id != self.settings.id || instance_id == self.instance_id || !self.is_beating() {
            return None;
        }
        if !active {
            return self.peer_seen.take().map(|_| PeerChange::Left);
        }
        let formed = self.peer_seen.is_none();
        self.peer_seen = Some(now);
        formed.then_some(PeerChange::Formed)
    }

    /// Whether the manager was lost by `now` (no heartbeat for the timeout since the last):
    /// reported once; a later heartbeat forms the bond again.
    pub fn check_peer(&mut self, now: Instant) -> Option<PeerChange> {
        let seen = self.peer_seen?;
        let silent = now.saturating_duration_since(seen);
        if silent >= self.settings.timeout {
            self.peer_seen = None;
            return Some(PeerChange::Lost(silent));
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(n: u64) -> Duration {
        Duration::from_millis(n)
    }

    /// Beats of a run sampled every 10 ms: the instants (ms) each message goes out.
    fn sends(heart: &mut Heart, t0: Instant, until_ms: u64) -> Vec<(u64, bool)> {
        (0..=until_ms / 10)
            .filter_map(|k| heart.poll(t0 + ms(10 * k)).map(|b| (10 * k, b.active)))
            .collect()
    }

    /// Heartbeats at the period from activation; three `active = false` 50 ms apart at
    /// deactivation, then silence; a new activation beats again, never `false` first.
    #[test]
    fn beats_at_the_period_and_dies_in_three_messages() {
        let t0 = Instant::now();
        let mut h = Heart::new(BondSettings::nav2("local_nav"));
        h.start(t0, "a".into());
        assert_eq!(
            sends(&mut h, t0, 300),
            [(0, true), (100, true), (200, true), (300, true)]
        );
        h.stop(t0 + ms(350));
        let after: Vec<_> = (35..60)
            .filter_map(|k| h.poll(t0 + ms(10 * k)).map(|b| (10 * k, b.active)))
            .collect();
        assert_eq!(after, [(350, false), (400, false), (450, false)]);
        assert_eq!(h.due(), None);
        h.start(t0 + ms(1000), "b".into());
        assert_eq!(h.poll(t0 + ms(1000)), Some(Beat { active: true }));
        assert_eq!(h.instance_id(), "b");
    }

    /// A zero period: no message, ever.
    #[test]
    fn disabled_bond_sends_nothing() {
        let t0 = Instant::now();
        let mut settings = BondSettings::nav2("n");
        settings.period = Duration::ZERO;
        let mut h = Heart::new(settings);
        h.start(t0, "a".into());
        h.stop(t0 + ms(10));
        assert_eq!(sends(&mut h, t0, 500), []);
    }

    /// A late poll sends one message and the next is a period later (no burst).
    #[test]
    fn a_late_poll_sends_once() {
        let t0 = Instant::now();
        let mut h = Heart::new(BondSettings::nav2("n"));
        h.start(t0, "a".into());
        h.poll(t0);
        assert_eq!(h.poll(t0 + ms(730)), Some(Beat { active: true }));
        assert_eq!(h.poll(t0 + ms(731)), None);
        assert_eq!(h.due(), Some(t0 + ms(830)));
    }

    /// The manager's heartbeats: formed at the first, lost 4 s after the last, formed again
    /// by a later one; its `active = false` is a leave; own and foreign messages are ignored.
    #[test]
    fn watches_the_managers_heartbeats() {
        let t0 = Instant::now();
        let mut h = Heart::new(BondSettings::nav2("planner"));
        assert_eq!(h.receive("planner", "mgr", true, t0), None, "not beating yet");
        h.start(t0, "me".into());
        assert_eq!(h.receive("planner", "me", true, t0), None, "own message");
        assert_eq!(h.receive("other", "mgr", true, t0), None, "another bond");
        assert_eq!(
            h.receive("planner", "mgr", true, t0 + ms(100)),
            Some(PeerChange::Formed)
        );
        assert_eq!(h.receive("planner", "mgr", true, t0 + ms(200)), None);
        assert_eq!(h.check_peer(t0 + ms(4199)), None);
        assert_eq!(h.poll(t0), Some(Beat { active: true }));
        assert_eq!(h.due(), Some(t0 + ms(100)), "the next beat comes before the loss");
        assert_eq!(h.check_peer(t0 + ms(4200)), Some(PeerChange::Lost(ms(4000))));
        assert_eq!(h.check_peer(t0 + ms(5000)), None, "reported once");
        assert_eq!(
            h.receive("planner", "mgr2", true, t0 + ms(6000)),
            Some(PeerChange::Formed)
        );
        assert_eq!(
            h.receive("planner", "mgr2", false, t0 + ms(6100)),
            Some(PeerChange::Left)
        );
        assert_eq!(h.receive("planner", "mgr2", false, t0 + ms(6150)), None);
    }

    /// Breaking the bond forgets the manager: no loss is reported for a bond the node ended.
    #[test]
    fn no_loss_after_the_node_broke_the_bond() {
        let t0 = Instant::now();
        let mut h = Heart::new(BondSettings::nav2("n"));
        h.start(t0, "me".into());
        h.receive("n", "mgr", true, t0);
        h.stop(t0 + ms(100));
        assert_eq!(h.check_peer(t0 + ms(10_000)), None);
        assert_eq!(h.receive("n", "mgr", true, t0 + ms(10_000)), None);
    }
}
