//! The planner's goals as goal laws ([`mobil_motion::GoalLaw`]): a docking by the Lyapunov law,
//! a route by the goal approach, an undocking by [`DistanceDrive`], a route by VFO
//! ([`VfoGoal`]). Each takes the robot's reference point (`base_link`) and steers the point its
//! law steers, answers with a body twist at that point, and ends with the planner's reasons and
//! Nav2's codes. A node runs them through its motion server; nothing here reads a clock or
//! publishes.

use crate::docking::{
    DockingConfig, DockingController, DockingFailure, DockingGains, DockingOutput, DockingPhase, Finish, PolarError,
    Residual, VelocityLimits,
};
use crate::error::PlannerError;
use crate::follow::{FollowConfig, FollowEnd, FollowEvent, WaypointFollower};
use crate::route::{ProblemKind, RouteProblem, RouteReport, UnreachableCause};
use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_motion::{nav2, GoalLaw, Notice, Outcome, Step, StepInput};
use mobil_tools::drive::{DistanceDrive, DriveSettings, Progress};
use nalgebra::Point2;

pub use crate::vfo::goal::VfoGoal;

/// How a docking that failed is told: `TIME_LIMIT`, `NOT_CONVERGING`, or `RESIDUAL` — the
/// heading left when a steered chassis reached ε_e, and a steered chassis' stall too (V stops
/// falling there for one reason only: the law asks for turns tighter than the chassis' minimum
/// radius). Nav2's `FAILED_TO_CONTROL` for all.
pub fn docking_failure(failure: DockingFailure, residual: Residual, finish: Finish) -> Outcome {
    let figures = format!(
        "e = {:.3} m, heading error {:.3} rad ({:.1}°)",
        residual.e,
        residual.heading,
        residual.heading.to_degrees()
    );
    let (code, detail) = match (failure, finish) {
        (DockingFailure::NotConverging, Finish::ReportResidual) => (
            "RESIDUAL",
            format!(
                "V stopped falling: the law asks for turns tighter than the chassis' minimum radius (no turn in \
                 place): {figures}"
            ),
        ),
        (DockingFailure::TimeLimit, _) => ("TIME_LIMIT", format!("{}: {figures}", failure.as_str())),
        (DockingFailure::NotConverging, _) => ("NOT_CONVERGING", format!("{}: {figures}", failure.as_str())),
        (DockingFailure::HeadingResidual, _) => ("RESIDUAL", format!("{}: {figures}", failure.as_str())),
    };
    Outcome::failed(code, detail, nav2::docking::FAILED_TO_CONTROL)
}

/// A docking onto a pose.
///
/// The law steers the chassis' kinematic origin, `offset` behind the reference point (the rear
/// axle of a steered chassis, the one point that moves as the law's unicycle; 0 on the omni
/// chassis), onto the dock pose moved back by the same offset.
#[derive(Debug, Clone, PartialEq)]
pub struct DockGoal {
    controller: DockingController,
    offset: f64,
    last: Option<DockingOutput>,
}

/// One step of a docking: the controller's output, and whether its phase changed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DockStep {
    /// The controller's output.
    pub output: DockingOutput,
    /// The phase differs from the previous step's (the first step's always does).
    pub phase_changed: bool,
}

/// The offset (m) of the point the docking law steers, behind the reference point: on a steered
/// chassis the kinematic origin (`reference_offset` behind), the one point that moves as the
/// law's unicycle does (no sideways speed), so V̇ ≤ 0 holds wherever the curvature limit does
/// not bind; on the omni chassis the reference point itself (any twist is executed there).
pub fn docking_offset(chassis: &ChassisParams) -> f64 {
    if chassis.model().is_nonholonomic() {
        chassis.reference_offset()
    } else {
        0.0
    }
}

impl DockGoal {
    /// A docking of the reference point onto `dock` on `chassis`, the law scaled to its limits
    /// and finishing as it can ([`Finish::for_chassis`]), steering the point [`docking_offset`]
    /// behind.
    pub fn onto(
        dock: Pose2,
        gains: DockingGains,
        config: DockingConfig,
        chassis: &ChassisParams,
    ) -> Result<Self, PlannerError> {
        let offset = docking_offset(chassis);
        let controller = DockingController::new(
            gains,
            config,
            VelocityLimits::from_chassis(chassis),
            Finish::for_chassis(chassis),
            dock.ahead(-offset),
        )?;
        Ok(DockGoal::new(controller, offset))
    }

    /// A docking by `controller`, whose goal is the dock pose moved back by `offset` (m).
    pub fn new(controller: DockingController, offset: f64) -> Self {
        DockGoal {
            controller,
            offset,
            last: None,
        }
    }

    /// The dock pose of the reference point.
    pub fn target(&self) -> Pose2 {
        self.controller.goal().ahead(self.offset)
    }

    /// The steered point's offset behind the reference point (m).
    pub fn offset(&self) -> f64 {
        self.offset
    }

    /// The controller.
    pub fn controller(&self) -> &DockingController {
        &self.controller
    }

    /// The last step's output (`None` before the first).
    pub fn last(&self) -> Option<&DockingOutput> {
        self.last.as_ref()
    }

    /// The polar error and V with the reference point at `pose`: the last step's, or before
    /// the first step the figures at `pose`.
    pub fn figures(&self, pose: Option<&Pose2>) -> Option<(PolarError, f64)> {
        self.last.map(|o| (o.polar, o.lyapunov)).or_else(|| {
            pose.map(|p| {
                let polar = crate::docking::polar_error(&p.ahead(-self.offset), &self.controller.goal());
                (polar, self.controller.gains().lyapunov(&polar))
            })
        })
    }
}

impl GoalLaw for DockGoal {
    type Sensors = ();
    type Feedback = DockStep;
    type Report = DockingOutput;

    fn step(&mut self, input: &StepInput, _: &()) -> Step<DockStep, DockingOutput> {
        let o = match self.controller.update(&input.pose.ahead(-self.offset), input.t) {
            Ok(o) => o,
            Err(e) => return Step::Refused(e.to_string()),
        };
        let phase_changed = self.last.is_none_or(|l| l.phase != o.phase);
        self.last = Some(o);
        match o.phase {
            DockingPhase::Docked => {
                let detail = format!(
                    "docked: e = {:.3} m, heading error {:.3} rad",
                    o.polar.e, o.heading_error
                );
                Step::end(Outcome::succeeded(detail), o)
            }
            DockingPhase::Failed(f) => {
                let residual = o.residual.unwrap_or(Residual {
                    e: o.polar.e,
                    heading: o.heading_error,
                });
                Step::end(docking_failure(f, residual, self.controller.finish()), o)
            }
            DockingPhase::Approach | DockingPhase::Rotate => Step::Command {
                twist: o.command.to_twist(),
                feedback: DockStep {
                    output: o,
                    phase_changed,
                },
            },
        }
    }
}

/// A waypoint a route did not take: its index in the request and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Missed {
    /// Index in the request's poses.
    pub index: usize,
    /// Where (odom).
    pub position: Point2<f64>,
    /// The problem (from the pre-check or the run).
    pub kind: ProblemKind,
    /// True when the pre-check found it, false when the run missed it.
    pub pre_check: bool,
}

/// The MissedWaypoint code of a waypoint the run gave up: FollowPath's FAILED_TO_MAKE_PROGRESS.
pub const MISSED_BY_THE_RUN: u16 = nav2::follow_path::FAILED_TO_MAKE_PROGRESS;

impl Missed {
    /// "waypoint 2: turn_radius: turn radius 0.50 m below the chassis minimum 0.73 m".
    pub fn describe(&self) -> String {
        format!("waypoint {}: {}: {}", self.index, self.kind.as_str(), self.kind)
    }

    /// The MissedWaypoint error code: the pre-check's problems are Nav2's ComputePathToPose
    /// codes (a waypoint inside an obstacle 206 GOAL_OCCUPIED, any other 208 NO_VALID_PATH);
    /// a waypoint the run gave up is FollowPath's 105 FAILED_TO_MAKE_PROGRESS.
    pub fn error_code(&self) -> u16 {
        match (self.pre_check, self.kind) {
            (true, ProblemKind::Unreachable(UnreachableCause::Blocked { .. })) => nav2::compute_path::GOAL_OCCUPIED,
            (true, _) => nav2::compute_path::NO_VALID_PATH,
            (false, _) => MISSED_BY_THE_RUN,
        }
    }
}

/// At most this many missed waypoints (or pre-check problems) are listed in a reason.
pub const MAX_LISTED_MISSED: usize = 50;

/// "waypoint 1: …; waypoint 3: …; and 2 more".
pub fn list_missed(missed: &[Missed]) -> String {
    let mut s = missed
        .iter()
        .take(MAX_LISTED_MISSED)
        .map(Missed::describe)
        .collect::<Vec<_>>()
        .join("; ");
    if missed.len() > MAX_LISTED_MISSED {
        s += &format!("; and {} more", missed.len() - MAX_LISTED_MISSED);
    }
    s
}

/// "route done: all 4 waypoints reached", or the waypoints missed.
pub fn route_done(count: usize, missed: &[Missed]) -> String {
    if missed.is_empty() {
        format!("route done: all {count} waypoints reached")
    } else {
        format!(
            "route done: {} of {count} waypoints missed: {}",
            missed.len(),
            list_missed(missed)
        )
    }
}

/// The pre-check's problems as missed waypoints: each with the request's index of its waypoint
/// (`request_index`, by route index; a missing one is its own), where it is (a collision where
/// it begins, else its waypoint of `points`).
pub fn missed_from_report(problems: &[RouteProblem], points: &[Point2<f64>], request_index: &[usize]) -> Vec<Missed> {
    problems
        .iter()
        .map(|p| Missed {
            index: request_index.get(p.index).copied().unwrap_or(p.index),
            position: match p.kind {
                ProblemKind::Collision { at, .. } => at,
                _ => points.get(p.index).copied().unwrap_or_else(Point2::origin),
            },
            kind: p.kind,
            pre_check: true,
        })
        .collect()
}

/// The route the pre-check found `problems` on: `ROUTE_INFEASIBLE`, every problem listed (up
/// to [`MAX_LISTED_MISSED`]), FollowWaypoints' TASK_EXECUTOR_FAILED.
pub fn route_infeasible(problems: &[Missed]) -> Outcome {
    Outcome::failed(
        "ROUTE_INFEASIBLE",
        format!("{} problem(s): {}", problems.len(), list_missed(problems)),
        nav2::follow_waypoints::TASK_EXECUTOR_FAILED,
    )
}

/// What a route check answers (the node's `planner/check_route` service): the problems found,
/// each by the request's index, up to [`MAX_LISTED_MISSED`]; ROUTE_INFEASIBLE's reason (empty
/// when feasible); the first problem's waypoint; the virtual robot's path, downsampled to at
/// most `max_poses`; and its length without the jumps ([`RouteReport::driven_length`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RouteAnswer {
    /// The problems listed.
    pub problems: Vec<Missed>,
    /// Empty when feasible; else the reason, every problem counted.
    pub reason: String,
    /// The request's index of the first problem's waypoint.
    pub failed_waypoint: Option<usize>,
    /// The predicted path, downsampled.
    pub path: Vec<Pose2>,
    /// The predicted path's length (m).
    pub length: f64,
}

impl RouteAnswer {
    /// The answer of `report` for the route through `points` (the request's index of each
    /// alongside), checked with step length `step`.
    pub fn of(
        report: &RouteReport,
        (points, request_index): (&[Point2<f64>], &[usize]),
        step: f64,
        max_poses: usize,
    ) -> Self {
        let mut missed = missed_from_report(&report.problems, points, request_index);
        let reason = if missed.is_empty() {
            String::new()
        } else {
            route_infeasible(&missed).reason()
        };
        missed.truncate(MAX_LISTED_MISSED);
        RouteAnswer {
            failed_waypoint: missed.first().map(|m| m.index),
            problems: missed,
            reason,
            path: mobil_geom::downsample(&report.path, max_poses),
            length: report.driven_length(step),
        }
    }

    /// Whether the route has no problem.
    pub fn feasible(&self) -> bool {
        self.problems.is_empty()
    }
}

/// What comes of a route's pre-check ([`after_pre_check`]).
#[derive(Debug, Clone, PartialEq)]
pub enum PreChecked {
    /// Drive it, by `goal`; `problems` found (only when infeasible routes are driven).
    Drive {
        /// The route goal.
        goal: Box<RouteGoal>,
        /// The problems found, driven through.
        problems: Vec<Missed>,
    },
    /// The route is refused: `ROUTE_INFEASIBLE` with `problems`, or the follower refused it.
    Refuse {
        /// Why.
        outcome: Outcome,
        /// The problems found.
        problems: Vec<Missed>,
    },
}

/// The decision after a route's pre-check `report`: a route with problems is refused unless
/// `execute_infeasible`; else it is driven from `start` by the goal approach (`follow` on
/// `chassis`), the request's index of each waypoint alongside.
pub fn after_pre_check(
    report: &RouteReport,
    (points, request_index): (&[Point2<f64>], &[usize]),
    start: &Pose2,
    (follow, chassis): (FollowConfig, &ChassisParams),
    execute_infeasible: bool,
) -> PreChecked {
    let problems = missed_from_report(&report.problems, points, request_index);
    if !problems.is_empty() && !execute_infeasible {
        return PreChecked::Refuse {
            outcome: route_infeasible(&problems),
            problems,
        };
    }
    match WaypointFollower::new(follow, chassis, points.to_vec()) {
        Ok(follower) => {
            let distance = points.first().map_or(f64::NAN, |p| (p - start.position()).norm());
            PreChecked::Drive {
                goal: Box::new(RouteGoal::new(follower, request_index.to_vec(), distance)),
                problems,
            }
        }
        Err(e) => PreChecked::Refuse {
            outcome: Outcome::failed(
                "INVALID_INPUT",
                format!("the planner refused its input: {e}; robot stopped"),
                nav2::follow_waypoints::TASK_EXECUTOR_FAILED,
            ),
            problems,
        },
    }
}

/// A route by the goal approach, after its pre-check: the follower, the request's index of
/// each waypoint, and the waypoints missed so far.
#[derive(Debug, Clone, PartialEq)]
pub struct RouteGoal {
    follower: WaypointFollower,
    request_index: Vec<usize>,
    missed: Vec<Missed>,
    distance: f64,
}

/// What happened to a waypoint in a step, by its index in the request.
#[derive(Debug, Clone, PartialEq)]
pub enum RouteEvent {
    /// Reached within Z_crit.
    Reached(usize),
    /// Given up, the next one taken.
    Missed(Missed),
}

impl RouteEvent {
    /// Its log line: a waypoint reached, or missed (a warning).
    pub fn notice(&self) -> Notice {
        match self {
            RouteEvent::Reached(i) => Notice::Info(format!("waypoint {i} reached")),
            RouteEvent::Missed(m) => Notice::Warn(format!("{} (missed; the next one is taken)", m.describe())),
        }
    }
}

/// One step of a route.
#[derive(Debug, Clone, PartialEq)]
pub struct RouteStep {
    /// The waypoint pursued (the request's index).
    pub waypoint: usize,
    /// Distance Z (m) of the reference point to it.
    pub distance: f64,
    /// Waypoints reached or missed in this step.
    pub events: Vec<RouteEvent>,
}

impl RouteGoal {
    /// A route for `follower`, the request's index of each of its waypoints alongside
    /// (missing ones count as their own index).
    pub fn new(follower: WaypointFollower, request_index: Vec<usize>, distance: f64) -> Self {
        RouteGoal {
            follower,
            request_index,
            missed: Vec::new(),
            distance,
        }
    }

    fn request(&self, i: usize) -> usize {
        self.request_index.get(i).copied().unwrap_or(i)
    }

    /// The waypoint pursued (the request's index; the last once every one was taken).
    pub fn waypoint(&self) -> usize {
        let n = self.follower.waypoints().len();
        self.request(self.follower.index().min(n.saturating_sub(1)))
    }

    /// The position of the waypoint pursued.
    pub fn target(&self) -> Option<Point2<f64>> {
        let w = self.follower.waypoints();
        w.get(self.follower.index().min(w.len().saturating_sub(1))).copied()
    }

    /// Distance Z (m) to the waypoint pursued at the last step.
    pub fn distance(&self) -> f64 {
        self.distance
    }

    /// The waypoints missed so far.
    pub fn missed(&self) -> &[Missed] {
        &self.missed
    }

    /// The waypoints of the route, in driving order.
    pub fn count(&self) -> usize {
        self.follower.waypoints().len()
    }
}

impl GoalLaw for RouteGoal {
    type Sensors = ();
    type Feedback = RouteStep;
    type Report = Vec<Missed>;

    fn step(&mut self, input: &StepInput, _: &()) -> Step<RouteStep, Vec<Missed>> {
        let o = match self.follower.update(&input.pose, input.dt, input.t) {
            Ok(o) => o,
            Err(e) => return Step::Refused(e.to_string()),
        };
        let mut events = Vec::with_capacity(o.events.len());
        for event in &o.events {
            match *event {
                FollowEvent::Reached { index } => events.push(RouteEvent::Reached(self.request(index))),
                FollowEvent::Missed { index, cause } => {
                    let m = Missed {
                        index: self.request(index),
                        position: self
                            .follower
                            .waypoints()
                            .get(index)
                            .copied()
                            .unwrap_or_else(Point2::origin),
                        kind: ProblemKind::Unreachable(cause),
                        pre_check: false,
                    };
                    self.missed.push(m.clone());
                    events.push(RouteEvent::Missed(m));
                }
            }
        }
        self.distance = o.distance;
        match o.end {
            Some(FollowEnd::Done) => Step::end(
                Outcome::succeeded(route_done(self.count(), &self.missed)),
                self.missed.clone(),
            ),
            Some(FollowEnd::Stalled) => Step::end(
                Outcome::failed(
                    "STALLED",
                    format!(
                        "the robot did not move on its way to waypoint {}: robot stopped",
                        self.request(o.index)
                    ),
                    nav2::follow_waypoints::TASK_EXECUTOR_FAILED,
                ),
                self.missed.clone(),
            ),
            None => Step::Command {
                twist: o.twist,
                feedback: RouteStep {
                    waypoint: self.request(o.index),
                    distance: o.distance,
                    events,
                },
            },
        }
    }
}

/// The ramp-down of an undocking (m/s²): √(2·0.075·d) reaches the default undocking speed,
/// 0.15 m/s, 0.15 m before the end, and the last centimetres go at the floor speed.
pub const UNDOCK_DECEL: f64 = 0.075;

/// The slowest undocking speed before the end (m/s).
pub const UNDOCK_MIN_SPEED: f64 = 0.03;

/// Undocked when this close to the staging distance (m).
pub const UNDOCK_TOLERANCE: f64 = 0.005;

/// UndockRobot's `max_undocking_time` default (s), taken for a request's time that is none.
pub const DEFAULT_UNDOCK_TIME_S: f64 = 30.0;

/// Backing straight out of a dock by `distance` along the heading of the first step, at
/// `speed`, within a time limit: a [`DistanceDrive`] backwards.
#[derive(Debug, Clone, PartialEq)]
pub struct UndockGoal {
    distance: f64,
    speed: f64,
    limit_s: f64,
    drive: Option<DistanceDrive>,
}

impl UndockGoal {
    /// Backs out `distance` (m, > 0) at `speed` (m/s, > 0), failing after `limit_s` of the
    /// goal's time.
    pub fn new(distance: f64, speed: f64, limit_s: f64) -> Self {
        UndockGoal {
            distance,
            speed,
            limit_s,
            drive: None,
        }
    }

    /// An `undock_robot` request's undocking: back out `distance` at `speed` within the
    /// request's `max_undocking_time` (s), or [`DEFAULT_UNDOCK_TIME_S`] when that is no positive
    /// time; with what the node tells of it (the undocking, and a warning for a time not taken).
    pub fn for_request(distance: f64, speed: f64, max_undocking_time: f32) -> (Self, Vec<Notice>) {
        let mut notices = Vec::new();
        let limit_s = if max_undocking_time.is_finite() && max_undocking_time > 0.0 {
            f64::from(max_undocking_time)
        } else {
            notices.push(Notice::Warn(format!(
                "undock_robot: max_undocking_time {max_undocking_time} is not a positive time: \
                 {DEFAULT_UNDOCK_TIME_S} s (its default) taken"
            )));
            DEFAULT_UNDOCK_TIME_S
        };
        notices.push(Notice::Info(format!(
            "goal (undock_robot): back out {distance:.3} m along the heading, within {limit_s:.1} s"
        )));
        (UndockGoal::new(distance, speed, limit_s), notices)
    }

    /// How far it has backed out (m).
    pub fn backed(&self) -> f64 {
        self.drive.as_ref().map_or(0.0, |d| -d.progress().travelled)
    }

    /// What is left (m).
    pub fn remaining(&self) -> f64 {
        self.drive.as_ref().map_or(self.distance, |d| d.progress().remaining)
    }

    /// The distance to back out (m).
    pub fn distance(&self) -> f64 {
        self.distance
    }
}

impl GoalLaw for UndockGoal {
    type Sensors = ();
    type Feedback = Progress;
    type Report = f64;

    fn step(&mut self, input: &StepInput, _: &()) -> Step<Progress, f64> {
        if !input.pose.is_finite() {
            return Step::Refused("non-finite pose".to_owned());
        }
        if self.drive.is_none() {
            let settings = DriveSettings {
                max_speed: self.speed,
                min_speed: UNDOCK_MIN_SPEED.min(self.speed),
                decel: UNDOCK_DECEL,
                tolerance: UNDOCK_TOLERANCE,
            };
            match DistanceDrive::new(input.pose, -self.distance, self.speed, settings) {
                Ok(d) => self.drive = Some(d),
                Err(e) => return Step::Refused(e.to_string()),
            }
        }
        let Some(drive) = self.drive.as_mut() else {
            return Step::Refused("no drive".to_owned());
        };
        match GoalLaw::step(drive, input, &()) {
            Step::End(end) => {
                let backed = -end.report.travelled;
                Step::end(
                    Outcome::succeeded(format!("undocked: backed out {backed:.3} m")),
                    backed,
                )
            }
            Step::Command { .. } if input.t > self.limit_s => {
                let backed = self.backed();
                Step::end(
                    Outcome::failed(
                        "TIME_LIMIT",
                        format!(
                            "not undocked within max_undocking_time {:.1} s (backed out {backed:.3} m)",
                            self.limit_s
                        ),
                        nav2::docking::FAILED_TO_CONTROL,
                    ),
                    backed,
                )
            }
            Step::Command { twist, feedback } => Step::Command { twist, feedback },
            Step::Refused(why) => Step::Refused(why),
        }
    }
}
