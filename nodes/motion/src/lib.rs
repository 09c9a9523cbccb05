//! One interface for every goal law of the suite, ROS-free.
//!
//! A *goal law* drives the robot towards one goal — a dock, a route, a distance, a position
//! behind obstacles — one step at a time. Its step takes the time, the robot's pose and
//! velocity and whatever the law senses besides (a checked scan, an obstacle map), and answers
//! one of three things ([`Step`]):
//! - a command, the body twist to drive, with the law's feedback;
//! - the end of the goal, succeeded or failed, with a reason and Nav2's error code
//!   ([`Outcome`]) and whatever the law reports at its end;
//! - a refusal of this step's input: the law could not use it (a non-finite pose, a scan it
//!   cannot read), and the robot is to be stopped for this step.
//!
//! The law never reads a clock, never publishes and never decides what happens around it: the
//! motion server of the node kit (`mobil_ros::motion`) owns the goals, their pre-emption, the
//! time step, the count of refused steps, the one zero command at every end, the feedback and
//! the status, as Nav2's `controller_server` owns them around a `nav2_core::Controller`.
//!
//! ```
//! use mobil_motion::{BodyTwist, GoalLaw, Outcome, Pose2, Step, StepInput};
//!
//! /// Drives forward until x passes 1 m.
//! struct ToOneMetre;
//!
//! impl GoalLaw for ToOneMetre {
//!     type Sensors = ();
//!     type Feedback = f64;
//!     type Report = ();
//!     fn step(&mut self, input: &StepInput, _: &()) -> Step<f64, ()> {
//!         if !input.pose.is_finite() {
//!             return Step::Refused("non-finite pose".into());
//!         }
//!         let left = 1.0 - input.pose.x;
//!         if left <= 0.0 {
//!             return Step::end(Outcome::succeeded("at 1 m"), ());
//!         }
//!         Step::Command { twist: BodyTwist::new(0.2, 0.0, 0.0), feedback: left }
//!     }
//! }
//!
//! let mut law = ToOneMetre;
//! let at = |x| StepInput::new(0.0, 0.05, Pose2::new(x, 0.0, 0.0));
//! assert!(matches!(law.step(&at(0.5), &()), Step::Command { feedback, .. } if (feedback - 0.5).abs() < 1e-12));
//! assert!(matches!(law.step(&at(1.2), &()), Step::End(end) if end.outcome.is_success()));
//! ```
#![warn(missing_docs)]

pub mod health;
pub mod progress;
pub mod slot;
pub mod status;

pub use mobil_chassis::BodyTwist;
pub use mobil_geom::Pose2;

/// What a law sees at one step, besides its own sensors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInput {
    /// ROS time (s, any origin; simulated time under `use_sim_time`), never decreasing over a
    /// goal's steps.
    pub t: f64,
    /// The time since the goal's previous step (s), held by the server to the law's range; the
    /// first step gets the server's first step.
    pub dt: f64,
    /// The robot's pose (the reference point, `base_link`, in the goal's frame).
    pub pose: Pose2,
    /// The robot's measured body twist at the reference point (zero when unknown).
    pub velocity: BodyTwist,
}

impl StepInput {
    /// An input at `t` with time step `dt` and pose `pose`, the velocity unknown (zero).
    pub fn new(t: f64, dt: f64, pose: Pose2) -> Self {
        StepInput {
            t,
            dt,
            pose,
            velocity: BodyTwist::ZERO,
        }
    }

    /// The same input with a measured velocity.
    pub fn with_velocity(self, velocity: BodyTwist) -> Self {
        StepInput { velocity, ..self }
    }
}

/// What a law, or a goal's turn, has for the node's log: the law decides what is said, the
/// node only writes it.
#[derive(Debug, Clone, PartialEq)]
pub enum Notice {
    /// An info line.
    Info(String),
    /// A warning.
    Warn(String),
    /// A warning that may recur at every step: the node rate-limits it under its key.
    Recurring(&'static str, String),
}

/// How a goal ended: Nav2's view of it.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// The goal was reached.
    Succeeded {
        /// What was reached, for the log and the status.
        detail: String,
    },
    /// The goal ended without being reached.
    Failed {
        /// The status reason's code, upper case (`RESIDUAL`, `NO_PATH`, `STALLED`, …).
        code: &'static str,
        /// The figures behind it, for the log and the status.
        detail: String,
        /// Nav2's error code for the action that serves the law (0 when it has none).
        nav2_error: u16,
    },
}

impl Outcome {
    /// A success with `detail`.
    pub fn succeeded(detail: impl Into<String>) -> Self {
        Outcome::Succeeded { detail: detail.into() }
    }

    /// A failure with its code, detail and Nav2 error code.
    pub fn failed(code: &'static str, detail: impl Into<String>, nav2_error: u16) -> Self {
        Outcome::Failed {
            code,
            detail: detail.into(),
            nav2_error,
        }
    }

    /// Whether the goal was reached.
    pub fn is_success(&self) -> bool {
        matches!(self, Outcome::Succeeded { .. })
    }

    /// The status reason, "CODE: detail" (`SUCCEEDED` alone for a success without detail).
    pub fn reason(&self) -> String {
        let (code, detail) = match self {
            Outcome::Succeeded { detail } => ("SUCCEEDED", detail.as_str()),
            Outcome::Failed { code, detail, .. } => (*code, detail.as_str()),
        };
        if detail.is_empty() {
            code.to_owned()
        } else {
            format!("{code}: {detail}")
        }
    }

    /// Nav2's error code: 0 for a success.
    pub fn nav2_error(&self) -> u16 {
        match self {
            Outcome::Succeeded { .. } => 0,
            Outcome::Failed { nav2_error, .. } => *nav2_error,
        }
    }
}

/// The end of a goal: its outcome and what the law reports with it (the distance travelled,
/// the waypoints missed, the residual left, …).
#[derive(Debug, Clone, PartialEq)]
pub struct End<R> {
    /// How it ended.
    pub outcome: Outcome,
    /// The law's report.
    pub report: R,
}

/// One step's answer.
#[derive(Debug, Clone, PartialEq)]
pub enum Step<F, R> {
    /// Drive this body twist (at the point the law says it steers; finite), and report this.
    Command {
        /// The command.
        twist: BodyTwist,
        /// The law's feedback for this step.
        feedback: F,
    },
    /// The goal is over; the robot is to stop.
    End(End<R>),
    /// This step's input could not be used (the reason says why); the robot is to stop for
    /// this step, and the goal goes on.
    Refused(String),
}

impl<F, R> Step<F, R> {
    /// The end with `outcome` and `report`.
    pub fn end(outcome: Outcome, report: R) -> Self {
        Step::End(End { outcome, report })
    }
}

/// A goal law: one goal, stepped until it ends.
pub trait GoalLaw {
    /// What the law senses besides the pose and velocity (`()` for none; a checked scan, an
    /// obstacle map, …).
    type Sensors: ?Sized;
    /// What each commanding step reports.
    type Feedback;
    /// What the end reports besides its outcome.
    type Report;

    /// One step. After an [`Step::End`] the law is not stepped again.
    fn step(&mut self, input: &StepInput, sensors: &Self::Sensors) -> Step<Self::Feedback, Self::Report>;
}

/// Nav2 Jazzy's error codes the suite's laws end with, by the action that serves them.
pub mod nav2 {
    /// No error, in every action's result.
    pub const NONE: u16 = 0;
    /// `FollowPath`'s (the controller server's) codes, which Nav2's navigator passes on.
    pub mod follow_path {
        /// No error.
        pub const NONE: u16 = 0;
        /// Unknown.
        pub const UNKNOWN: u16 = 100;
        /// `controller_id` names no controller of the node.
        pub const INVALID_CONTROLLER: u16 = 101;
        /// The path's frame cannot be used.
        pub const TF_ERROR: u16 = 102;
        /// The path is empty or not finite.
        pub const INVALID_PATH: u16 = 103;
        /// The robot did not move enough within the progress checker's time.
        pub const FAILED_TO_MAKE_PROGRESS: u16 = 105;
        /// No valid control could be computed.
        pub const NO_VALID_CONTROL: u16 = 106;
        /// The `controller_id` Nav2's default configuration and behavior trees send (the name of
        /// controller_server's one default plugin): a node with a default law takes it as that.
        pub const DEFAULT_CONTROLLER_ID: &str = "FollowPath";
    }
    /// `ComputePathToPose`'s (the planner server's) codes.
    pub mod compute_path {
        /// The goal lies inside an obstacle.
        pub const GOAL_OCCUPIED: u16 = 206;
        /// No valid path.
        pub const NO_VALID_PATH: u16 = 208;
    }
    /// `DockRobot`'s and `UndockRobot`'s codes.
    pub mod docking {
        /// The dock is not in the database.
        pub const DOCK_NOT_IN_DB: u16 = 901;
        /// The dock is not valid.
        pub const DOCK_NOT_VALID: u16 = 902;
        /// The controller failed.
        pub const FAILED_TO_CONTROL: u16 = 905;
        /// Unknown.
        pub const UNKNOWN: u16 = 999;
    }
    /// `FollowWaypoints`'s codes.
    pub mod follow_waypoints {
        /// Unknown.
        pub const UNKNOWN: u16 = 600;
        /// The task executor (the law following the route) failed.
        pub const TASK_EXECUTOR_FAILED: u16 = 601;
    }
    /// The behavior server's codes: one block per action (`Spin` 70x, `BackUp` 71x,
    /// `DriveOnHeading` 72x), each with its own UNKNOWN, TIMEOUT, TF_ERROR, COLLISION_AHEAD and
    /// (not Spin) INVALID_INPUT.
    pub mod behavior {
        /// A behavior's codes.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub struct Codes {
            /// Unknown.
            pub unknown: u16,
            /// `time_allowance` exceeded.
            pub timeout: u16,
            /// The robot's pose is not available (stale or refused odometry).
            pub tf_error: u16,
            /// An obstacle in the way of the motion.
            pub collision_ahead: u16,
            /// A goal the behavior cannot run (Spin has none: 0).
            pub invalid_input: u16,
        }
        /// `Spin`.
        pub const SPIN: Codes = Codes {
            unknown: 700,
            timeout: 701,
            tf_error: 702,
            collision_ahead: 703,
            invalid_input: 0,
        };
        /// `BackUp`.
        pub const BACK_UP: Codes = Codes {
            unknown: 710,
            timeout: 711,
            tf_error: 712,
            collision_ahead: 714,
            invalid_input: 713,
        };
        /// `DriveOnHeading`.
        pub const DRIVE_ON_HEADING: Codes = Codes {
            unknown: 720,
            timeout: 721,
            tf_error: 722,
            collision_ahead: 723,
            invalid_input: 724,
        };
    }
}

/// The codes an action's result gives for the ends the node makes itself (a law's end carries
/// its own code): a goal that lost control (stale or refused input), and a shutdown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Nav2Codes {
    /// Stale or refused input.
    pub control_failure: u16,
    /// The goal's frame lost its transform to the odometry frame (missing or stale).
    pub tf_error: u16,
    /// The node shut down under the goal.
    pub unknown: u16,
}

impl Nav2Codes {
    /// `FollowPath` (and `NavigateToPose`, whose navigator passes the controller's codes on):
    /// NO_VALID_CONTROL, UNKNOWN.
    pub const FOLLOW_PATH: Nav2Codes = Nav2Codes {
        control_failure: nav2::follow_path::NO_VALID_CONTROL,
        tf_error: nav2::follow_path::TF_ERROR,
        unknown: nav2::follow_path::UNKNOWN,
    };
    /// `DockRobot` and `UndockRobot`: FAILED_TO_CONTROL, UNKNOWN (also for a transform lost:
    /// docking_server catches tf2's exception as any other, UNKNOWN).
    pub const DOCKING: Nav2Codes = Nav2Codes {
        control_failure: nav2::docking::FAILED_TO_CONTROL,
        tf_error: nav2::docking::UNKNOWN,
        unknown: nav2::docking::UNKNOWN,
    };
    /// `FollowWaypoints`: TASK_EXECUTOR_FAILED, UNKNOWN (also for a transform lost: the
    /// action has no TF code).
    pub const FOLLOW_WAYPOINTS: Nav2Codes = Nav2Codes {
        control_failure: nav2::follow_waypoints::TASK_EXECUTOR_FAILED,
        tf_error: nav2::follow_waypoints::UNKNOWN,
        unknown: nav2::follow_waypoints::UNKNOWN,
    };

    /// A behavior (`Spin`, `BackUp`, `DriveOnHeading`): its TF_ERROR (the pose lost, also
    /// for stale input) and UNKNOWN.
    pub const fn behavior(codes: nav2::behavior::Codes) -> Nav2Codes {
        Nav2Codes {
            control_failure: codes.tf_error,
            tf_error: codes.tf_error,
            unknown: codes.unknown,
        }
    }
}

/// Why a goal ended.
#[derive(Debug, Clone, PartialEq)]
pub enum EndCause {
    /// The law, or the node on the law's behalf (a pre-check that refuses the route), ended it.
    Outcome(Outcome),
    /// Its client canceled it.
    Canceled,
    /// A newer goal took its place (named by its source).
    Preempted(&'static str),
    /// The law refused its input on this many steps in a row (the last refusal's reason).
    Refused {
        /// Steps refused in a row.
        count: u32,
        /// The last reason.
        last: String,
    },
    /// An input went stale (named, e.g. `odom`, `scan and odom`).
    Stale(String),
    /// The transform from the goal's frame to the odometry frame is missing or older than
    /// `transform_tolerance` (why): the robot's pose relative to the goal is unknown.
    Tf(String),
    /// ROS time went back by this many seconds while the goal ran (a restarted simulation, a
    /// clock reset): the goal's time cannot go on.
    ClockBack(f64),
    /// The node shut down.
    Shutdown,
    /// The node left the active state (its lifecycle manager deactivated or shut it down).
    Deactivated,
}

/// How an end counts for the status and an action's result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndKind {
    /// The goal was reached.
    Succeeded,
    /// The client canceled it.
    Canceled,
    /// Any other end: failed, pre-empted, stale, refused, shut down.
    Aborted,
}

impl From<Outcome> for EndCause {
    fn from(o: Outcome) -> Self {
        EndCause::Outcome(o)
    }
}

impl EndCause {
    /// The log line of a goal from `source` ending so: a warning unless it succeeded, was
    /// canceled or was pre-empted by a newer goal.
    pub fn notice(&self, source: &str) -> Notice {
        let text = format!("goal ({source}) ends: {}", self.reason());
        match (self.kind(), self) {
            (EndKind::Succeeded | EndKind::Canceled, _) | (_, EndCause::Preempted(_)) => Notice::Info(text),
            _ => Notice::Warn(text),
        }
    }

    /// The status reason's code: the outcome's, or `CANCELED`, `PREEMPTED`, `INVALID_INPUT`,
    /// `STALE_INPUT`, `TF_ERROR`, `CLOCK_BACKWARDS`, `SHUTDOWN`, `DEACTIVATED`.
    pub fn code(&self) -> &str {
        match self {
            EndCause::Outcome(Outcome::Succeeded { .. }) => "SUCCEEDED",
            EndCause::Outcome(Outcome::Failed { code, .. }) => code,
            EndCause::Canceled => "CANCELED",
            EndCause::Preempted(_) => "PREEMPTED",
            EndCause::Refused { .. } => "INVALID_INPUT",
            EndCause::Stale(_) => "STALE_INPUT",
            EndCause::Tf(_) => "TF_ERROR",
            EndCause::ClockBack(_) => "CLOCK_BACKWARDS",
            EndCause::Shutdown => "SHUTDOWN",
            EndCause::Deactivated => "DEACTIVATED",
        }
    }

    /// The status reason, "CODE: detail".
    pub fn reason(&self) -> String {
        match self {
            EndCause::Outcome(o) => o.reason(),
            EndCause::Canceled => "CANCELED: canceled by the client".to_owned(),
            EndCause::Preempted(by) => format!("PREEMPTED: preempted by a newer goal ({by})"),
            EndCause::Refused { count, last } => {
                format!("INVALID_INPUT: the input was refused on {count} steps in a row ({last}): robot stopped")
            }
            EndCause::Stale(inputs) => format!("STALE_INPUT: {inputs} stale: robot stopped"),
            EndCause::Tf(why) => format!("TF_ERROR: {why}: robot stopped"),
            EndCause::ClockBack(by) => format!(
                "CLOCK_BACKWARDS: ROS time went back by {by:.3} s (a restarted simulation or a clock reset): \
                 robot stopped"
            ),
            EndCause::Shutdown => "SHUTDOWN: the node is shutting down".to_owned(),
            EndCause::Deactivated => "DEACTIVATED: the node was deactivated (lifecycle): robot stopped".to_owned(),
        }
    }

    /// Nav2's error code of this end in the result of an action with `codes`, one rule for
    /// every node: the law's own, none for a cancel or a pre-emption, the control failure for
    /// stale or refused input or a clock gone back, the TF code for a transform lost, unknown
    /// at shutdown or deactivation.
    pub fn nav2_error(&self, codes: Nav2Codes) -> u16 {
        match self {
            EndCause::Outcome(o) => o.nav2_error(),
            EndCause::Canceled | EndCause::Preempted(_) => nav2::NONE,
            EndCause::Refused { .. } | EndCause::Stale(_) | EndCause::ClockBack(_) => codes.control_failure,
            EndCause::Tf(_) => codes.tf_error,
            EndCause::Shutdown | EndCause::Deactivated => codes.unknown,
        }
    }

    /// How it counts for the status and the action.
    pub fn kind(&self) -> EndKind {
        match self {
            EndCause::Outcome(o) if o.is_success() => EndKind::Succeeded,
            EndCause::Canceled => EndKind::Canceled,
            _ => EndKind::Aborted,
        }
    }
}

/// The largest timeout of an input a goal depends on (`odom_timeout_s`, `scan_timeout_s`), s.
pub const MAX_INPUT_TIMEOUT_S: f64 = 60.0;

/// `s` seconds as a duration, held to [0, `max_s`] (NaN gives `max_s`): never a panic, whatever
/// the number.
pub fn seconds(s: f64, max_s: f64) -> std::time::Duration {
    let s = if s.is_nan() { max_s } else { s.clamp(0.0, max_s) };
    std::time::Duration::try_from_secs_f64(s).unwrap_or(std::time::Duration::ZERO)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn a_goal_s_end_is_a_warning_unless_reached_canceled_or_replaced() {
        let line = |cause: EndCause| cause.notice("waypoints");
        let info = |s: &str| Notice::Info(format!("goal (waypoints) ends: {s}"));
        let warn = |s: &str| Notice::Warn(format!("goal (waypoints) ends: {s}"));
        assert_eq!(
            line(EndCause::Outcome(Outcome::succeeded("reached"))),
            info("SUCCEEDED: reached")
        );
        assert_eq!(line(EndCause::Canceled), info("CANCELED: canceled by the client"));
        assert_eq!(
            line(EndCause::Preempted("follow_waypoints")),
            info("PREEMPTED: preempted by a newer goal (follow_waypoints)")
        );
        assert_eq!(
            line(EndCause::Outcome(Outcome::failed("STALLED", "", 1))),
            warn("STALLED")
        );
        assert_eq!(
            line(EndCause::Stale("odom".into())),
            warn("STALE_INPUT: odom stale: robot stopped")
        );
        assert_eq!(line(EndCause::Shutdown), warn("SHUTDOWN: the node is shutting down"));
        assert_eq!(
            line(EndCause::Deactivated),
            warn("DEACTIVATED: the node was deactivated (lifecycle): robot stopped")
        );
    }

    #[test]
    fn nav2_errors_are_the_law_s_none_the_control_failure_or_unknown() {
        let c = Nav2Codes::DOCKING;
        let failed = EndCause::Outcome(Outcome::failed("NOT_CONVERGING", "", 905));
        let ends = [
            (failed, 905),
            (EndCause::Outcome(Outcome::succeeded("docked")), 0),
            (EndCause::Canceled, 0),
            (EndCause::Preempted("dock_pose"), 0),
            (EndCause::Stale("odom".into()), 905),
            (
                EndCause::Refused {
                    count: 20,
                    last: String::new(),
                },
                905,
            ),
            (EndCause::ClockBack(4.5), 905),
            (EndCause::Shutdown, 999),
            (EndCause::Deactivated, 999),
        ];
        for (end, code) in ends {
            assert_eq!(end.nav2_error(c), code, "{end:?}");
        }
        let back = EndCause::ClockBack(4.5);
        assert_eq!(
            (back.code(), back.kind(), back.reason().as_str()),
            (
                "CLOCK_BACKWARDS",
                EndKind::Aborted,
                "CLOCK_BACKWARDS: ROS time went back by 4.500 s (a restarted simulation or a clock reset): robot stopped"
            )
        );
        assert_eq!(EndCause::Stale("scan".into()).nav2_error(Nav2Codes::FOLLOW_PATH), 106);
        assert_eq!(EndCause::Shutdown.nav2_error(Nav2Codes::FOLLOW_WAYPOINTS), 600);
        // A transform lost: FollowPath's (and so NavigateToPose's) TF_ERROR 102, a behavior's
        // own, UNKNOWN where the action has no TF code.
        let tf = EndCause::Tf("`map` does not exist".into());
        assert_eq!(
            (tf.code(), tf.kind(), tf.reason().as_str()),
            (
                "TF_ERROR",
                EndKind::Aborted,
                "TF_ERROR: `map` does not exist: robot stopped"
            )
        );
        let codes = [
            Nav2Codes::FOLLOW_PATH,
            Nav2Codes::DOCKING,
            Nav2Codes::FOLLOW_WAYPOINTS,
            Nav2Codes::behavior(nav2::behavior::BACK_UP),
        ];
        assert_eq!(codes.map(|c| tf.nav2_error(c)), [102, 999, 600, 712]);
    }

    #[test]
    fn outcomes_give_reasons_and_codes() {
        assert_eq!(Outcome::succeeded("").reason(), "SUCCEEDED");
        assert_eq!(Outcome::succeeded("docked").reason(), "SUCCEEDED: docked");
        let f = Outcome::failed("RESIDUAL", "e = 0.097 m", nav2::docking::FAILED_TO_CONTROL);
        assert_eq!(f.reason(), "RESIDUAL: e = 0.097 m");
        assert_eq!((f.is_success(), f.nav2_error()), (false, 905));
        assert_eq!(Outcome::succeeded("x").nav2_error(), 0);
        assert_eq!(Outcome::failed("STALLED", "", 601).reason(), "STALLED");
    }

    #[test]
    fn an_input_carries_its_velocity() {
        let i = StepInput::new(1.0, 0.02, Pose2::new(1.0, 2.0, 0.5));
        assert_eq!(i.velocity, BodyTwist::ZERO);
        let v = BodyTwist::new(0.3, 0.0, 0.1);
        assert_eq!(i.with_velocity(v).velocity, v);
        assert_eq!(i.with_velocity(v).pose, i.pose);
    }

    #[test]
    fn an_end_names_its_code_its_reason_and_how_it_counts() {
        let cases = [
            (
                EndCause::Outcome(Outcome::succeeded("at the dock")),
                "SUCCEEDED",
                EndKind::Succeeded,
            ),
            (
                EndCause::Outcome(Outcome::failed("BLOCKED", "wall", 106)),
                "BLOCKED",
                EndKind::Aborted,
            ),
            (EndCause::Canceled, "CANCELED", EndKind::Canceled),
            (EndCause::Preempted("waypoints"), "PREEMPTED", EndKind::Aborted),
            (
                EndCause::Refused {
                    count: 3,
                    last: "NaN pose".into(),
                },
                "INVALID_INPUT",
                EndKind::Aborted,
            ),
            (EndCause::Stale("odom".into()), "STALE_INPUT", EndKind::Aborted),
            (EndCause::Shutdown, "SHUTDOWN", EndKind::Aborted),
            (EndCause::Deactivated, "DEACTIVATED", EndKind::Aborted),
        ];
        for (cause, code, kind) in cases {
            assert_eq!((cause.code(), cause.kind()), (code, kind), "{cause:?}");
            assert!(cause.reason().starts_with(code), "{}", cause.reason());
        }
        assert_eq!(
            EndCause::Preempted("waypoints").reason(),
            "PREEMPTED: preempted by a newer goal (waypoints)"
        );
        assert_eq!(
            EndCause::Refused {
                count: 3,
                last: "NaN pose".into()
            }
            .reason(),
            "INVALID_INPUT: the input was refused on 3 steps in a row (NaN pose): robot stopped"
        );
    }

    #[test]
    fn seconds_are_held_to_their_range_and_never_panic() {
        assert_eq!(seconds(0.25, 60.0), Duration::from_millis(250));
        assert_eq!(seconds(1e300, 60.0), Duration::from_secs(60));
        assert_eq!(seconds(-1.0, 60.0), Duration::ZERO);
        assert_eq!(seconds(f64::NAN, 60.0), Duration::from_secs(60));
        assert_eq!(seconds(f64::INFINITY, 60.0), Duration::from_secs(60));
    }
}
