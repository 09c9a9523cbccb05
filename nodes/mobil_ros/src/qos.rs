//! The QoS presets of the interface contract (INTERFACES.md): reliable/volatile depth 10 by
//! default, best effort depth 5 for sensor streams, reliable transient-local depth 1 for latched
//! status and plans. A reliable subscription does not match a best-effort publisher, so sensor
//! subscriptions are best effort (they then match either kind of publisher).

use ros2_client::qos::{Durability, History, Reliability, WhenFull};
use ros2_client::QosProfile;

/// Reliable, volatile, keep last `depth` (ROS 2's default, `rclpy`'s `10`).
pub fn reliable(depth: usize) -> QosProfile {
    QosProfile::publisher_default()
        .reliability(Reliability::Reliable {
            when_full: WhenFull::DEFAULT,
        })
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth })
}

/// The default for commands, odometry and feedback: reliable, volatile, depth 10.
pub fn default_qos() -> QosProfile {
    reliable(10)
}

/// Sensor data (`qos_profile_sensor_data`): best effort, volatile, depth 5.
pub fn sensor_data() -> QosProfile {
    QosProfile::subscription_default()
        .reliability(Reliability::BestEffort)
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 5 })
}

/// Latched status and plans: reliable, transient local, depth 1 (late joiners get the last one).
pub fn latched() -> QosProfile {
    reliable(1).durability(Durability::TransientLocal)
}

/// Reading `/tf_static` (tf2's static listener QoS): reliable, transient local, depth 100, so a
/// late reader gets every static transform of every publisher, not only the last message.
pub fn tf_static() -> QosProfile {
    reliable(100).durability(Durability::TransientLocal)
}
