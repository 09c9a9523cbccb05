//! `/diagnostics` (diagnostic_msgs/DiagnosticArray), as diagnostic_updater publishes it: once a
//! second (a node may send at once when a level changes, as diagnostic_updater's
//! `force_update`), each status named `<node>: <task>` (the node's fully qualified name), so
//! rqt_robot_monitor and diagnostic_aggregator group it by node. The topic is absolute, as
//! diagnostic_updater's: a namespaced robot's nodes still report where the aggregator listens.
//!
//! ```
//! use mobil_chassis::health::{Health, Level};
//! use mobil_ros::diagnostics::status_msg;
//!
//! let health = Health { level: Level::Warn, message: "2 rejected".into(), values: vec![("k".into(), "v".into())] };
//! let s = status_msg(&health, "/chassis", "watchdogs", "omni");
//! assert_eq!((s.level, s.name.as_str(), s.hardware_id.as_str()), (1, "/chassis: watchdogs", "omni"));
//! assert_eq!(s.values[0].key, "k");
//! ```

use crate::log::LogThrottle;
use crate::node::RosNode;
use mobil_chassis::health::Health;
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::diagnostic_msgs::msg::{DiagnosticArray, DiagnosticStatus, KeyValue};
use mobil_msgs::std_msgs::msg::Header;
use ros2_client::Publisher;
use std::time::{Duration, Instant};

/// diagnostic_updater's default period.
pub const DIAGNOSTICS_PERIOD: Duration = Duration::from_secs(1);

/// How early a report may go out on a tick that falls just short of the period.
pub const DUE_SLACK: Duration = Duration::from_millis(50);

/// The status of `health` for task `task` of node `node` (its fully qualified name), about
/// `hardware_id`.
pub fn status_msg(health: &Health, node: &str, task: &str, hardware_id: &str) -> DiagnosticStatus {
    DiagnosticStatus {
        level: health.level.byte(),
        name: format!("{node}: {task}"),
        message: health.message.clone(),
        hardware_id: hardware_id.to_owned(),
        values: health
            .values
            .iter()
            .map(|(key, value)| KeyValue {
                key: key.clone(),
                value: value.clone(),
            })
            .collect(),
    }
}

/// A node's `/diagnostics` publisher, and when it last sent.
pub struct DiagnosticsOut {
    publisher: Publisher<DiagnosticArray>,
    node: String,
    last: Option<Instant>,
}

impl DiagnosticsOut {
    /// The publisher of `node` (reliable, volatile, depth 10).
    pub fn create(node: &mut RosNode) -> anyhow::Result<Self> {
        Ok(DiagnosticsOut {
            publisher: node.publisher::<DiagnosticArray>("/diagnostics", &crate::qos::default_qos())?,
            node: node.names().fully_qualified_node(),
            last: None,
        })
    }

    /// Whether a report is due at `now` ([`DIAGNOSTICS_PERIOD`] since the last, less
    /// [`DUE_SLACK`], or none yet): a node that looks once a second on a jittery tick still
    /// reports once a second, not every other one.
    pub fn due(&self, now: Instant) -> bool {
        self.since_last(now).is_none_or(|d| d + DUE_SLACK >= DIAGNOSTICS_PERIOD)
    }

    /// How long since the last report at `now` (`None`: none yet).
    pub fn since_last(&self, now: Instant) -> Option<Duration> {
        self.last.map(|t| now.duration_since(t))
    }

    /// Sends the node's statuses, each `(task, hardware_id, health)`, stamped `stamp`, at `now`
    /// (a failure: one rate-limited warning).
    pub fn send(&mut self, statuses: &[(&str, &str, Health)], stamp: Time, now: Instant, throttle: &mut LogThrottle) {
        let array = DiagnosticArray {
            header: Header {
                stamp,
                frame_id: String::new(),
            },
            status: statuses
                .iter()
                .map(|(task, hw, health)| status_msg(health, &self.node, task, hw))
                .collect(),
        };
        self.last = Some(now);
        if let Err(e) = self.publisher.publish(array) {
            crate::warn_throttled!(throttle, "diagnostics", "cannot publish /diagnostics: {e:?}");
        }
    }
}

/// A motion node's `/diagnostics`: one status, `<node>: motion`, from its motion session
/// ([`crate::motion::MotionSession::health_report`], [`mobil_motion::health::motion_health`]),
/// once a second.
pub struct MotionDiagnostics {
    out: DiagnosticsOut,
    hardware_id: String,
}

impl MotionDiagnostics {
    /// The publisher of `node`; `hardware_id` names the robot (its chassis model).
    pub fn create(node: &mut RosNode, hardware_id: &str) -> anyhow::Result<Self> {
        Ok(MotionDiagnostics {
            out: DiagnosticsOut::create(node)?,
            hardware_id: hardware_id.to_owned(),
        })
    }

    /// At a watchdog tick at `now`: when a report is due, the session's, with the `inputs` a
    /// goal needs, the active goal as `goal` describes it and the law's `mode`, stamped `stamp`.
    #[allow(clippy::too_many_arguments)]
    pub fn tick<G, S>(
        &mut self,
        session: &crate::motion::MotionSession<G, S>,
        now: Instant,
        inputs: &[crate::motion::Watched],
        goal: impl FnOnce() -> Option<String>,
        mode: &str,
        stamp: Time,
        throttle: &mut LogThrottle,
    ) {
        if !self.out.due(now) {
            return;
        }
        let report = session.health_report(now, inputs, goal(), mode);
        let health = mobil_motion::health::motion_health(&report);
        self.out
            .send(&[("motion", &self.hardware_id, health)], stamp, now, throttle);
    }
}
