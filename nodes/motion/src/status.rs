//! What a navigating node's status says (`local_nav/status`, `planner/status`), ROS-free: one
//! view each node fills with the figures it has, the rest taking the message's documented
//! "none" values; the node kit (`mobil_ros::status`) builds the `mobil_msgs/NavStatus` message
//! from it.
//!
//! ```
//! use mobil_motion::status::{end_state, state, NavStatusView};
//! use mobil_motion::EndCause;
//!
//! let view = NavStatusView::new(end_state(&EndCause::Canceled), "idle", "CANCELED".into());
//! assert_eq!((view.state, view.waypoint_index), (state::FAILED, None));
//! assert!(view.distance_to_goal.is_nan() && view.goal.is_none());
//! ```

use crate::{EndCause, EndKind};
use mobil_geom::Pose2;
use nalgebra::Point2;

/// The status states, numbered as `mobil_msgs/NavStatus` numbers them.
pub mod state {
    /// No goal.
    pub const IDLE: u8 = 0;
    /// A goal is pursued.
    pub const ACTIVE: u8 = 1;
    /// The last goal was reached.
    pub const SUCCEEDED: u8 = 2;
    /// The last goal was not reached (failed, canceled, pre-empted or refused).
    pub const FAILED: u8 = 3;
}

/// A VFO segment's last optimisation as the status carries it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VfoFigures {
    /// Ψ_z of the chosen decisions.
    pub psi_z: f64,
    /// χ_D, χ_B, χ_E, χ_S of the chosen path.
    pub indices: [f64; 4],
    /// Virtual robots simulated.
    pub virtual_robots: usize,
    /// Paths that reached the waypoint.
    pub candidates: usize,
}

/// What a status message says.
#[derive(Debug, Clone, PartialEq)]
pub struct NavStatusView {
    /// The state ([`state`]: IDLE, ACTIVE, SUCCEEDED, FAILED).
    pub state: u8,
    /// The mode's name.
    pub mode: &'static str,
    /// The goal pursued (the node's frame), if any.
    pub goal: Option<Pose2>,
    /// Distance to it (m), NaN when unknown.
    pub distance_to_goal: f64,
    /// The reason (empty while active).
    pub reason: String,
    /// The waypoint pursued (request index), if a route is active.
    pub waypoint_index: Option<usize>,
    /// Hit point H (local_nav).
    pub hit_point: Option<Point2<f64>>,
    /// Leave point L (local_nav).
    pub leave_point: Option<Point2<f64>>,
    /// The docking's e, α, Θ and V (planner, while docking; NaN before the first pose).
    pub docking: Option<[f64; 4]>,
    /// A VFO route's current segment (planner).
    pub vfo: Option<VfoFigures>,
}

impl NavStatusView {
    /// A view in `state` and `mode` with `reason`, nothing else known.
    pub fn new(state: u8, mode: &'static str, reason: String) -> Self {
        NavStatusView {
            state,
            mode,
            goal: None,
            distance_to_goal: f64::NAN,
            reason,
            waypoint_index: None,
            hit_point: None,
            leave_point: None,
            docking: None,
            vfo: None,
        }
    }
}

/// The state a goal's end leaves: SUCCEEDED, else FAILED (a cancel and a pre-emption included:
/// the goal was not reached).
pub fn end_state(cause: &EndCause) -> u8 {
    match cause.kind() {
        EndKind::Succeeded => state::SUCCEEDED,
        EndKind::Canceled | EndKind::Aborted => state::FAILED,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Outcome;

    #[test]
    fn only_a_goal_reached_ends_succeeded() {
        assert_eq!(
            end_state(&EndCause::Outcome(Outcome::succeeded("there"))),
            state::SUCCEEDED
        );
        for cause in [
            EndCause::Canceled,
            EndCause::Preempted("waypoints"),
            EndCause::Shutdown,
            EndCause::Stale("odom".into()),
            EndCause::Outcome(Outcome::failed("STALLED", "", 105)),
        ] {
            assert_eq!(end_state(&cause), state::FAILED, "{cause:?}");
        }
    }
}
