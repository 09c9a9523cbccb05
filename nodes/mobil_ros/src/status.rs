//! The latched `mobil_msgs/NavStatus` of a navigating node (`local_nav/status`,
//! `planner/status`): one view of what a node says, one message built from it, and the rate
//! gate both status and markers follow while a goal is active.
//!
//! The view is ROS-free ([`mobil_motion::status`]): each node fills the fields it has; the rest
//! take the message's documented "none" values: `waypoint_index` −1, the docking figures 0, the
//! VFO figures NaN (counts 0), no hit or leave point, an identity goal orientation when there
//! is no goal.
//!
//! ```
//! use mobil_ros::status::{NavStatusView, StatusMessage};
//! use mobil_msgs::mobil_msgs::msg::NavStatus;
//!
//! let view = NavStatusView::new(NavStatus::FAILED, "idle", "INVALID_GOAL: no frame".into());
//! let m = view.message(Default::default(), "odom");
//! assert_eq!((m.state, m.waypoint_index, m.goal.orientation.w), (NavStatus::FAILED, -1, 1.0));
//! assert!(m.distance_to_goal.is_nan() && m.psi_z.is_nan() && !m.has_hit_point);
//! ```

use crate::geometry::pose_msg;
use crate::markers::point;
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::std_msgs::msg::Header;
use std::time::{Duration, Instant};

pub use mobil_motion::status::{end_state, NavStatusView, VfoFigures};

/// The `mobil_msgs/NavStatus` message of a [`NavStatusView`].
pub trait StatusMessage {
    /// The message, stamped `stamp`, in `frame`.
    fn message(&self, stamp: Time, frame: &str) -> NavStatus;
}

impl StatusMessage for NavStatusView {
    fn message(&self, stamp: Time, frame: &str) -> NavStatus {
        let goal = pose_msg(&self.goal.unwrap_or_default());
        let [e, alpha, theta, lyapunov] = self.docking.unwrap_or_default();
        let vfo = self.vfo.unwrap_or(VfoFigures {
            psi_z: f64::NAN,
            indices: [f64::NAN; 4],
            virtual_robots: 0,
            candidates: 0,
        });
        let [chi_length, chi_danger, chi_control, chi_smoothness] = vfo.indices;
        let count = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
        NavStatus {
            header: Header {
                stamp,
                frame_id: frame.to_owned(),
            },
            state: self.state,
            mode: self.mode.to_owned(),
            goal,
            distance_to_goal: self.distance_to_goal,
            reason: self.reason.clone(),
            has_hit_point: self.hit_point.is_some(),
            hit_point: self.hit_point.map(point).unwrap_or_default(),
            has_leave_point: self.leave_point.is_some(),
            leave_point: self.leave_point.map(point).unwrap_or_default(),
            waypoint_index: self.waypoint_index.map_or(-1, |i| i32::try_from(i).unwrap_or(i32::MAX)),
            e,
            alpha,
            theta,
            lyapunov,
            psi_z: vfo.psi_z,
            chi_length,
            chi_danger,
            chi_control,
            chi_smoothness,
            virtual_robots: count(vfo.virtual_robots),
            candidates: count(vfo.candidates),
        }
    }
}

/// When a periodic message (a status, markers) is next due: at most one per period of its
/// rate, the first at once (steady clock).
#[derive(Debug, Clone, Copy, Default)]
pub struct RateGate {
    last: Option<Instant>,
}

impl RateGate {
    /// Whether a message at `rate_hz` is due at `now` (a rate that is not positive and finite
    /// is never due again after the first).
    pub fn due(&self, now: Instant, rate_hz: f64) -> bool {
        let Some(last) = self.last else { return true };
        let period = Duration::try_from_secs_f64(1.0 / rate_hz).unwrap_or(Duration::MAX);
        now.saturating_duration_since(last) >= period
    }

    /// One was sent at `at`.
    pub fn sent(&mut self, at: Instant) {
        self.last = Some(at);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mobil_geom::Pose2;
    use mobil_motion::status::state;
    use nalgebra::Point2;

    #[test]
    fn the_states_are_numbered_as_the_message_numbers_them() {
        assert_eq!(
            [state::IDLE, state::ACTIVE, state::SUCCEEDED, state::FAILED],
            [
                NavStatus::IDLE,
                NavStatus::ACTIVE,
                NavStatus::SUCCEEDED,
                NavStatus::FAILED
            ]
        );
    }

    #[test]
    fn every_field_a_node_gives_is_carried_and_the_rest_say_none() {
        let view = NavStatusView {
            goal: Some(Pose2::new(1.0, 2.0, std::f64::consts::FRAC_PI_2)),
            distance_to_goal: 1.5,
            waypoint_index: Some(3),
            hit_point: Some(Point2::new(0.5, 0.25)),
            docking: Some([0.4, 0.1, -0.2, 0.3]),
            vfo: Some(VfoFigures {
                psi_z: 3.25,
                indices: [4.5, 0.75, 1.5, 0.5],
                virtual_robots: 9,
                candidates: 5,
            }),
            ..NavStatusView::new(NavStatus::ACTIVE, "vfo", String::new())
        };
        let m = view.message(Time::default(), "map");
        assert_eq!(
            (m.header.frame_id.as_str(), m.mode.as_str(), m.state),
            ("map", "vfo", 1)
        );
        assert_eq!((m.goal.position.x, m.goal.position.y), (1.0, 2.0));
        // yaw π/2: (w, z) = (cos π/4, sin π/4).
        assert!((m.goal.orientation.w - 0.5f64.sqrt()).abs() < 1e-12);
        assert!((m.goal.orientation.z - 0.5f64.sqrt()).abs() < 1e-12);
        assert_eq!((m.waypoint_index, m.has_hit_point, m.hit_point.y), (3, true, 0.25));
        assert!(!m.has_leave_point);
        assert_eq!((m.e, m.alpha, m.theta, m.lyapunov), (0.4, 0.1, -0.2, 0.3));
        assert_eq!(
            (m.psi_z, m.chi_length, m.chi_danger, m.chi_control, m.chi_smoothness),
            (3.25, 4.5, 0.75, 1.5, 0.5)
        );
        assert_eq!((m.virtual_robots, m.candidates), (9, 5));
        let none = NavStatusView::new(NavStatus::IDLE, "idle", String::new()).message(Time::default(), "odom");
        assert_eq!(
            (none.e, none.lyapunov, none.virtual_robots, none.candidates),
            (0.0, 0.0, 0, 0)
        );
        assert!(none.chi_smoothness.is_nan());
        let huge = NavStatusView {
            waypoint_index: Some(usize::MAX),
            ..NavStatusView::new(NavStatus::ACTIVE, "approach", String::new())
        };
        assert_eq!(huge.message(Time::default(), "odom").waypoint_index, i32::MAX);
    }

    #[test]
    fn the_gate_opens_once_per_period() {
        let t0 = Instant::now();
        let mut gate = RateGate::default();
        assert!(gate.due(t0, 5.0));
        gate.sent(t0);
        assert!(!gate.due(t0 + Duration::from_millis(199), 5.0));
        assert!(gate.due(t0 + Duration::from_millis(200), 5.0));
        assert!(!gate.due(t0, 5.0));
        assert!(!gate.due(t0 + Duration::from_secs(3600), 0.0));
    }
}
