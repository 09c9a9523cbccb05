//! A navigation node's status (`mobil_msgs/NavStatus` on `planner/status` or
//! `local_nav/status`) as the demo's acts read it: the shells fill a [`Status`] from the message.

/// The node's state in a status (the message's IDLE, ACTIVE, SUCCEEDED, FAILED).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GoalState {
    /// No goal.
    Idle,
    /// A goal runs.
    Active,
    /// The goal succeeded.
    Succeeded,
    /// The goal failed.
    Failed,
}

impl GoalState {
    /// Whether the goal has ended (succeeded or failed).
    pub fn finished(self) -> bool {
        matches!(self, GoalState::Succeeded | GoalState::Failed)
    }
}

/// What the acts read of one status.
#[derive(Debug, Clone, PartialEq)]
pub struct Status {
    /// The node's state.
    pub state: GoalState,
    /// The planner's waypoint pursued (from 0), −1 without a route.
    pub waypoint_index: i32,
    /// The node's mode (the planner's `approach`, `dock`, `rotate`, `vfo`, ...).
    pub mode: String,
    /// Why it failed (and notable transitions).
    pub reason: String,
    /// The planner's docking figures e (m), α, Θ (rad) and V; all 0 when not docking.
    pub docking: (f64, f64, f64, f64),
}
