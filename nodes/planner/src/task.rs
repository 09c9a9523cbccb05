//! The planner's goal, whichever law drives it: one type for the node's motion session.
//!
//! A goal of the planner node is one of five tasks: a route waiting for its pre-check (the
//! robot stands meanwhile), a docking, a route by the goal approach, an undocking, or a route by
//! VFO, whose steps run off the node's event loop (a segment's optimisation takes up to a
//! second) with the law lent out meanwhile ([`mobil_motion::slot`]). Here is what the node
//! decides about them without ROS: the status' mode, waypoint and figures, one step of the
//! laws stepped on the event loop, the turn from a pre-check into a route or a refusal, the
//! VFO law's lending and return (a late step's command dropped), and Nav2's codes for the ends
//! the node makes itself ([`Action`]).
//!
//! ```
//! use mobil_chassis::ChassisParams;
//! use mobil_geom::Pose2;
//! use mobil_planner::task::{Mode, PreCheck, Task};
//! use mobil_planner::{FollowConfig, RouteReport};
//! use nalgebra::Point2;
//!
//! let points = vec![Point2::new(3.0, 4.0)];
//! let mut task = Task::PreCheck(PreCheck::new(Pose2::identity(), points, vec![2]));
//! assert_eq!((task.mode(), task.waypoint()), (Mode::PreCheck, Some(2)));
//! let clear = RouteReport { problems: vec![], path: vec![], reached: vec![true] };
//! let rules = (FollowConfig::default(), &ChassisParams::omr3());
//! assert_eq!(task.pre_checked(&clear, rules, false), Some(Ok(vec![])));
//! // Now the goal approach, 5 m from the start to (3, 4).
//! let figures = task.figures(None);
//! assert_eq!((figures.mode, figures.distance), (Mode::Approach, 5.0));
//! ```

use crate::goals::{
    after_pre_check, route_infeasible, DockGoal, Missed, PreChecked, RouteEvent, RouteGoal, UndockGoal,
    MISSED_BY_THE_RUN,
};
use crate::path::{PathLaw, PathTask};
use crate::vfo::{
    vfo_gains, ObstacleMap, OptimiseWarning, SegmentReport, VfoEvent, VfoGoal, VfoSettings, VfoStep, VfoView,
    MAX_SETTLE_S,
};
use crate::view::Drawing;
use crate::{DockingPhase, FollowConfig, RouteReport};
use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_motion::slot::{late_bound, Handback, LawSlot};
use mobil_motion::status::{NavStatusView, VfoFigures};
use mobil_motion::{nav2, BodyTwist, EndCause, GoalLaw, Nav2Codes, Notice, Outcome, Step, StepInput};
use nalgebra::Point2;
use std::time::{Duration, Instant};

/// What the node is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// No goal.
    Idle,
    /// A route's pre-check (the virtual robot drives it first; the robot waits).
    PreCheck,
    /// Docking by the Lyapunov law.
    Dock,
    /// Docking's final in-place rotation.
    Rotate,
    /// Following waypoints by the goal approach.
    Approach,
    /// Following waypoints by VFO (SPEC §5).
    Vfo,
    /// Backing out of the dock.
    Undock,
}

impl Mode {
    /// The status' mode string.
    pub fn as_str(self) -> &'static str {
        match self {
            Mode::Idle => "idle",
            Mode::PreCheck => "pre_check",
            Mode::Dock => "dock",
            Mode::Rotate => "rotate",
            Mode::Approach => "approach",
            Mode::Vfo => "vfo",
            Mode::Undock => "undock",
        }
    }
}

/// A route waiting for its pre-check; the robot stands meanwhile.
#[derive(Debug, Clone, PartialEq)]
pub struct PreCheck {
    /// Where the robot stood when the route came (the pre-check's start).
    pub start: Pose2,
    /// The route's waypoints.
    pub points: Vec<Point2<f64>>,
    /// The request's index of each.
    pub request_index: Vec<usize>,
    /// The problems the pre-check found, kept for the result of a route it refuses.
    pub problems: Vec<Missed>,
}

impl PreCheck {
    /// A route through `points` (the request's index of each alongside) from `start`.
    pub fn new(start: Pose2, points: Vec<Point2<f64>>, request_index: Vec<usize>) -> Self {
        PreCheck {
            start,
            points,
            request_index,
            problems: Vec::new(),
        }
    }
}

/// A VFO route: its law at home or out on a step off the event loop, what the status shows of
/// it meanwhile, and whether the obstacle map changed since the law last took it.
#[derive(Debug)]
pub struct VfoRun {
    slot: LawSlot<VfoGoal>,
    view: VfoView,
    /// The request's index of each waypoint, in driving order.
    request_index: Vec<usize>,
    /// `Some(true)`: changed with new obstacles, which re-optimise the segment.
    map_changed: Option<bool>,
}

impl VfoRun {
    /// A route by `law`, whose steps may come back at most `max_delay` after they went out.
    pub fn new(law: VfoGoal, max_delay: Duration) -> Self {
        VfoRun {
            view: law.view(),
            request_index: (0..law.follower().waypoints().len()).map(|i| law.request(i)).collect(),
            slot: LawSlot::new(law, max_delay),
            map_changed: None,
        }
    }

    /// A VFO route through `route` (points, their headings where given, the request's index
    /// of each) from `start`, the latest fresh odometry pose, round `map`'s obstacles on
    /// `chassis` with `settings`; a step's command that comes back later than two periods of
    /// the odometry (`odom_period`, as measured; else one control step) is dropped
    /// ([`late_bound`]). Refused STALE_INPUT without fresh odometry, or without a fresh scan
    /// (`scan_fresh`: the obstacles are unknown, and the first step would optimise the segment
    /// through a map with nothing in it); else as [`VfoGoal::for_route`] refuses it.
    pub fn start(
        route: (&[Point2<f64>], &[Option<f64>], &[usize]),
        start: Option<Pose2>,
        scan_fresh: bool,
        (settings, chassis, map): (&VfoSettings, &ChassisParams, &ObstacleMap),
        odom_period: Option<Duration>,
    ) -> Result<VfoStart, Outcome> {
        let start = start.ok_or_else(|| Action::Follow.stale_at_start("odom"))?;
        if !scan_fresh {
            return Err(Action::Follow.stale_at_start("scan"));
        }
        let setup = settings.setup();
        let law = VfoGoal::for_route(route, &start, &setup, chassis, map)?;
        let gains = vfo_gains(&setup.gains, chassis);
        let summary = format!(
            "{} waypoints by VFO ({} obstacles known; U_2 {:.2} m/s, |ω| ≤ {:.2} rad/s, T_p {:.3} s)",
            route.0.len(),
            law.follower().obstacles().len(),
            gains.speed,
            gains.omega_max,
            settings.optimise.time_step
        );
        let chassis_warning = chassis.model().is_nonholonomic().then(|| {
            format!(
                "the VFO law is a unicycle's: on this {} chassis the virtual robots turn no tighter than at \
                 U_2 over R_min, but slower commands are held to R_min too, so the robot may turn wider than \
                 they did (waypoint_method approach is this chassis' default)",
                chassis.model().as_str()
            )
        });
        let max_delay = late_bound(odom_period, settings.optimise.time_step);
        Ok(VfoStart {
            run: VfoRun::new(law, max_delay),
            summary,
            chassis_warning,
        })
    }

    /// The status' figures as the law last came back.
    pub fn view(&self) -> &VfoView {
        &self.view
    }

    /// The request's indices of the waypoints not reached: the one pursued as the law last
    /// came back, and every one after it.
    pub fn unreached(&self) -> Vec<usize> {
        self.request_index.iter().skip(self.view.index).copied().collect()
    }

    /// The law, unless it is out on a step.
    pub fn law(&self) -> Option<&VfoGoal> {
        self.slot.law()
    }

    /// How late a step may come back and still command.
    pub fn max_delay(&self) -> Duration {
        self.slot.max_delay()
    }

    /// Whether the law has a map change to take at its next step (`Some(true)`: with new
    /// obstacles, which re-optimise the segment).
    pub fn map_pending(&self) -> Option<bool> {
        self.map_changed
    }

    /// The obstacle map changed (`new_obstacles`: with obstacles it had not got); the law takes
    /// the map at its next step. A change with new obstacles stays one until the law took it.
    pub fn map_updated(&mut self, new_obstacles: bool) {
        self.map_changed = Some(new_obstacles || self.map_changed.unwrap_or(false));
    }

    /// The law lent out at `now` for a step, with `map`'s obstacles if the map changed since
    /// it last took them; `None` while it is out on a step (the robot is to stand).
    pub fn lend(&mut self, now: Instant, map: &ObstacleMap) -> Option<Box<VfoGoal>> {
        let mut law = self.slot.lend(now)?;
        if let Some(new) = self.map_changed.take() {
            law.follow_map(map, new);
        }
        Some(law)
    }

    /// The law back at `now` with the step it took: the step, its command dropped (zero) when
    /// it came back later than [`VfoRun::max_delay`], and whether it did.
    pub fn give_back(
        &mut self,
        law: Box<VfoGoal>,
        mut step: Step<VfoStep, Vec<usize>>,
        now: Instant,
    ) -> (Step<VfoStep, Vec<usize>>, Handback) {
        self.view = law.view();
        let handback = self.slot.give_back(law, now);
        if let (Step::Command { twist, .. }, Handback::Late) = (&mut step, handback) {
            *twist = BodyTwist::new(0.0, 0.0, 0.0);
        }
        (step, handback)
    }

    /// What the node logs of a step given back ([`VfoRun::give_back`]): each event as the law
    /// describes it, the optimisation's warnings (but that no Σ is safe, which the event says),
    /// a robot held while it settles inside an influence zone, a command dropped as late.
    pub fn notices(&self, step: &Step<VfoStep, Vec<usize>>, handback: Handback) -> Vec<Notice> {
        let (Step::Command { feedback, .. }, Some(law)) = (step, self.law()) else {
            return Vec::new();
        };
        let mut notices = Vec::new();
        for event in &feedback.events {
            notices.push(Notice::Info(law.describe(event)));
            if let VfoEvent::Optimised { warnings, .. } = event {
                let shown = warnings.iter().filter(|w| !matches!(w, OptimiseWarning::NoSafeSigma));
                notices.extend(shown.map(|w| Notice::Recurring("vfo-caps", format!("segment optimisation: {w:?}"))));
            }
        }
        if feedback.settling {
            let text = format!(
                "robot held at zero inside an influence zone until it stands (at most {MAX_SETTLE_S} s), then the \
                 segment to waypoint {} is optimised from there",
                self.view.waypoint
            );
            notices.push(Notice::Recurring("vfo-settle", text));
        }
        if handback == Handback::Late {
            let text = format!(
                "a tick took longer than {:.0} ms (an optimisation): its command is dropped, the robot stops meanwhile",
                self.max_delay().as_secs_f64() * 1e3
            );
            notices.push(Notice::Recurring("vfo-late", text));
        }
        notices
    }
}

/// A pre-check's turn ([`Task::turn_after_check`]): the route driven (`Ok`) or refused with
/// the outcome to end the goal with, and what the node shows and tells of it.
#[derive(Debug)]
pub struct PreCheckTurn {
    /// Driven, or refused.
    pub outcome: Result<(), Outcome>,
    /// The route, the virtual robot's path and the problems found.
    pub drawing: Drawing,
    /// The waypoints, the check's finding, the predicted length.
    pub summary: String,
    /// A route driven through problems (`execute_infeasible_routes`): which.
    pub driven_through: Option<String>,
}

/// A VFO route that starts ([`VfoRun::start`]): the run, and what the node tells of it.
#[derive(Debug)]
pub struct VfoStart {
    /// The route's run.
    pub run: VfoRun,
    /// Its waypoints, the obstacles known, the law's speed, turn rate and control step.
    pub summary: String,
    /// On a steered chassis: that the robot may turn wider than the virtual robots did.
    pub chassis_warning: Option<String>,
}

/// What the active goal does.
#[derive(Debug)]
#[allow(clippy::large_enum_variant)]
pub enum Task {
    /// A route waiting for its pre-check.
    PreCheck(PreCheck),
    /// Docking onto a pose.
    Dock(DockGoal),
    /// A route by the goal approach, after its pre-check.
    Follow(RouteGoal),
    /// Backing out of a dock.
    Undock(UndockGoal),
    /// A route by VFO.
    Vfo(VfoRun),
    /// A path (Nav2's `follow_path`) by the goal approach or VFO.
    Path(PathTask),
}

/// What the status shows of a goal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Figures {
    /// The mode.
    pub mode: Mode,
    /// The request's index of the waypoint pursued (a route).
    pub waypoint: Option<usize>,
    /// The pose (a dock) or position (a waypoint, yaw 0) pursued, if known.
    pub goal: Option<Pose2>,
    /// Distance to it (m; an undocking: left to back out), NaN when unknown.
    pub distance: f64,
    /// A docking's (e, α, θ, V), NaN before the first pose.
    pub docking: Option<[f64; 4]>,
    /// A VFO route's segment optimisation.
    pub vfo: Option<SegmentReport>,
}

impl Figures {
    /// The status of a goal with these figures, in `state` (NavStatus' numbering) with `reason`.
    pub fn view(&self, state: u8, reason: String) -> NavStatusView {
        NavStatusView {
            goal: self.goal,
            distance_to_goal: self.distance,
            waypoint_index: self.waypoint,
            docking: self.docking,
            vfo: self.vfo.map(|s| VfoFigures {
                psi_z: s.psi_z,
                indices: s.indices,
                virtual_robots: s.virtual_robots,
                candidates: s.candidates,
            }),
            ..NavStatusView::new(state, self.mode.as_str(), reason)
        }
    }
}

/// The planner's status in `state` with `reason`: of `task`, its figures at `latest`, the
/// latest pose; with no task (idle, or a goal refused before it started), mode `idle` alone.
pub fn status_view(task: Option<&Task>, latest: Option<&Pose2>, state: u8, reason: String) -> NavStatusView {
    match task {
        Some(task) => task.figures(latest).view(state, reason),
        None => NavStatusView::new(state, Mode::Idle.as_str(), reason),
    }
}

/// A step's feedback, whichever law took it on the event loop.
#[derive(Debug, Clone, PartialEq)]
pub struct TaskStep {
    /// The status changed (a docking's phase, a waypoint reached or missed).
    pub changed: bool,
    /// A route's waypoints reached or missed at this step.
    pub events: Vec<RouteEvent>,
}

/// What one step of the task is.
#[derive(Debug, Clone, PartialEq)]
pub enum Stepped {
    /// The law's step, taken here.
    Law(Step<TaskStep, ()>),
    /// A VFO route: its law steps off the event loop ([`VfoRun::lend`]).
    OffLoop,
    /// A route waiting for its pre-check: no command yet.
    Waiting,
}

fn unified<F, R>(step: Step<F, R>, feedback: impl FnOnce(F) -> TaskStep) -> Step<TaskStep, ()> {
    match step {
        Step::Command { twist, feedback: f } => Step::Command {
            twist,
            feedback: feedback(f),
        },
        Step::End(end) => Step::end(end.outcome, ()),
        Step::Refused(why) => Step::Refused(why),
    }
}

impl Task {
    /// The status' mode.
    pub fn mode(&self) -> Mode {
        match self {
            Task::Dock(d) => match d.last().map(|o| o.phase) {
                Some(DockingPhase::Rotate) => Mode::Rotate,
                _ => Mode::Dock,
            },
            Task::PreCheck(_) => Mode::PreCheck,
            Task::Follow(_) => Mode::Approach,
            Task::Undock(_) => Mode::Undock,
            Task::Vfo(_) => Mode::Vfo,
            Task::Path(p) => match p.law() {
                PathLaw::Approach { .. } => Mode::Approach,
                PathLaw::Vfo(_) => Mode::Vfo,
            },
        }
    }

    /// The request's index of the waypoint pursued, if a route (a route waiting for its
    /// pre-check: its first; a path: its sub-goal).
    pub fn waypoint(&self) -> Option<usize> {
        match self {
            Task::Follow(goal) => Some(goal.waypoint()),
            Task::Vfo(v) => Some(v.view.waypoint),
            Task::PreCheck(p) => Some(p.request_index.first().copied().unwrap_or(0)),
            Task::Path(p) => Some(p.goals().index()),
            Task::Dock(_) | Task::Undock(_) => None,
        }
    }

    /// What the status shows; a docking before its first step shows its figures at `latest`,
    /// the latest pose.
    pub fn figures(&self, latest: Option<&Pose2>) -> Figures {
        let at = |p: Option<Point2<f64>>| p.map(|p| Pose2::new(p.x, p.y, 0.0));
        let mut f = Figures {
            mode: self.mode(),
            waypoint: self.waypoint(),
            goal: None,
            distance: f64::NAN,
            docking: None,
            vfo: None,
        };
        match self {
            Task::Dock(d) => {
                let figures = d.figures(latest);
                f.goal = Some(d.target());
                f.distance = figures.map_or(f64::NAN, |(p, _)| p.e);
                f.docking = Some(figures.map_or([f64::NAN; 4], |(p, v)| [p.e, p.alpha, p.theta, v]));
            }
            Task::Follow(goal) => {
                f.goal = at(goal.target());
                f.distance = goal.distance();
            }
            Task::Undock(u) => f.distance = u.remaining(),
            Task::Vfo(v) => {
                f.goal = at(v.view.target);
                f.distance = v.view.distance;
                f.vfo = Some(v.view.report);
            }
            Task::PreCheck(p) => f.goal = at(p.points.first().copied()),
            Task::Path(p) => {
                f.goal = at(Some(p.goals().goal()));
                f.distance = p.distance();
                if let PathLaw::Vfo(v) = p.law() {
                    f.vfo = Some(v.view.report);
                }
            }
        }
        f
    }

    /// One step at `input`: the docking's, the route's or the undocking's law here; a VFO
    /// route's goes off the loop, a route waiting for its pre-check does not step. A path is
    /// first checked for progress (either law) at ROS time `now` (s: Nav2's progress checker
    /// runs on ROS time, not on the goal's own time, whose steps are capped), then stepped as
    /// its law is.
    pub fn step(&mut self, input: &StepInput, now: f64) -> Stepped {
        let step = match self {
            Task::PreCheck(_) => return Stepped::Waiting,
            Task::Vfo(_) => return Stepped::OffLoop,
            Task::Path(p) => {
                if let Some(stuck) = p.check_progress(input.pose.position(), now) {
                    return Stepped::Law(Step::end(stuck, ()));
                }
                if matches!(p.law(), PathLaw::Vfo(_)) {
                    return Stepped::OffLoop;
                }
                unified(p.step_approach(input), |f| TaskStep {
                    changed: f.changed,
                    events: Vec::new(),
                })
            }
            Task::Dock(d) => unified(d.step(input, &()), |f| TaskStep {
                changed: f.phase_changed,
                events: Vec::new(),
            }),
            Task::Follow(goal) => unified(goal.step(input, &()), |f| TaskStep {
                changed: !f.events.is_empty(),
                events: f.events,
            }),
            Task::Undock(u) => unified(u.step(input, &()), |_| TaskStep {
                changed: false,
                events: Vec::new(),
            }),
        };
        Stepped::Law(step)
    }

    /// The waypoints a FollowWaypoints result lists when the goal ends (`succeeded` or not),
    /// each as the request's index and MissedWaypoint's error code: a goal-approach route's
    /// missed ones (Nav2 lists them on success too), a VFO route's not reached unless it
    /// succeeded ([`MISSED_BY_THE_RUN`]), a route refused by its pre-check its problems, none for
    /// a docking or an undocking.
    pub fn result_missed(&self, succeeded: bool) -> Vec<(usize, u16)> {
        let listed = |missed: &[Missed]| missed.iter().map(|m| (m.index, m.error_code())).collect();
        match self {
            Task::Follow(goal) => listed(goal.missed()),
            Task::PreCheck(p) => listed(&p.problems),
            Task::Vfo(_) if succeeded => Vec::new(),
            Task::Vfo(v) => v.unreached().into_iter().map(|i| (i, MISSED_BY_THE_RUN)).collect(),
            Task::Dock(_) | Task::Undock(_) | Task::Path(_) => Vec::new(),
        }
    }

    /// The VFO law's run: a VFO route's, or a path's followed by VFO.
    pub fn vfo_mut(&mut self) -> Option<&mut VfoRun> {
        match self {
            Task::Vfo(v) => Some(v),
            Task::Path(p) => p.vfo_run(),
            _ => None,
        }
    }

    /// Whether the law is VFO's (it needs the scan).
    pub fn is_vfo(&self) -> bool {
        self.mode() == Mode::Vfo
    }

    /// A route's pre-check came back with `report`: the route becomes a goal approach from
    /// where the robot stood (`follow` on `chassis`) and the problems it drives through are
    /// returned (none unless `execute_infeasible`), or it is refused with the outcome to end
    /// the goal with (its problems kept for the result). `None` when the task is no pre-check.
    pub fn pre_checked(
        &mut self,
        report: &RouteReport,
        (follow, chassis): (FollowConfig, &ChassisParams),
        execute_infeasible: bool,
    ) -> Option<Result<Vec<Missed>, Outcome>> {
        let Task::PreCheck(p) = self else { return None };
        let route = (&p.points[..], &p.request_index[..]);
        match after_pre_check(report, route, &p.start, (follow, chassis), execute_infeasible) {
            PreChecked::Refuse { outcome, problems } => {
                p.problems = problems;
                Some(Err(outcome))
            }
            PreChecked::Drive { goal, problems } => {
                *self = Task::Follow(*goal);
                Some(Ok(problems))
            }
        }
    }

    /// [`Task::pre_checked`], with what the node shows and tells of it: the drawing (the route,
    /// the virtual robot's path, the problems found, driven or refusing), one line on the
    /// check, and a warning when a route is driven through problems.
    pub fn turn_after_check(
        &mut self,
        report: &RouteReport,
        (follow, chassis): (FollowConfig, &ChassisParams),
        execute_infeasible: bool,
    ) -> Option<PreCheckTurn> {
        let Task::PreCheck(p) = self else { return None };
        let route = p.points.clone();
        let checked = self.pre_checked(report, (follow, chassis), execute_infeasible)?;
        let found = match (&checked, &*self) {
            (Ok(problems), _) => problems.clone(),
            (Err(_), Task::PreCheck(p)) => p.problems.clone(),
            (Err(_), _) => Vec::new(),
        };
        let summary = format!(
            "{} waypoints, pre-check {} ({:.2} m predicted)",
            route.len(),
            match found.len() {
                0 => "clear".to_owned(),
                n => format!("{n} problem(s)"),
            },
            report.driven_length(follow.check_length)
        );
        let driven_through = (checked.is_ok() && !found.is_empty()).then(|| {
            let reason = route_infeasible(&found).reason();
            format!("driven although execute_infeasible_routes: {reason}")
        });
        let drawing = Drawing {
            predicted: report.path.clone(),
            problems: found,
            route,
            ..Drawing::default()
        };
        Some(PreCheckTurn {
            outcome: checked.map(|_| ()),
            drawing,
            summary,
            driven_through,
        })
    }
}

/// Where a goal came from: the node's two topics and four action servers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The `dock_pose` topic.
    DockPose,
    /// The `waypoints` topic.
    Waypoints,
    /// The `dock_robot` action.
    DockAction,
    /// The `undock_robot` action.
    UndockAction,
    /// The `follow_waypoints` action.
    FollowAction,
    /// The `follow_path` action.
    PathAction,
}

/// The topic's or action's name (the motion session names a goal's source by it).
impl From<Source> for &'static str {
    fn from(s: Source) -> &'static str {
        match s {
            Source::DockPose => "dock_pose",
            Source::Waypoints => "waypoints",
            Source::DockAction => "dock_robot",
            Source::UndockAction => "undock_robot",
            Source::FollowAction => "follow_waypoints",
            Source::PathAction => "follow_path",
        }
    }
}

impl Source {
    /// The topic's or action's name.
    pub fn name(self) -> &'static str {
        self.into()
    }

    /// The action whose codes the goal's ends take (a topic: the action it stands for).
    pub fn action(self) -> Action {
        match self {
            Source::DockPose | Source::DockAction => Action::Dock,
            Source::UndockAction => Action::Undock,
            Source::Waypoints | Source::FollowAction => Action::Follow,
            Source::PathAction => Action::Path,
        }
    }
}

/// The action a goal came from, for Nav2's error codes of the ends the node itself makes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// `dock_robot`, and the `dock_pose` topic (no result).
    Dock,
    /// `undock_robot`.
    Undock,
    /// `follow_waypoints`, and the `waypoints` topic (no result).
    Follow,
    /// `follow_path`.
    Path,
}

impl Action {
    /// The codes of the ends the node makes: DockRobot's and UndockRobot's FAILED_TO_CONTROL
    /// and UNKNOWN, FollowWaypoints' TASK_EXECUTOR_FAILED and UNKNOWN, FollowPath's
    /// NO_VALID_CONTROL and UNKNOWN.
    pub fn codes(self) -> Nav2Codes {
        match self {
            Action::Dock | Action::Undock => Nav2Codes::DOCKING,
            Action::Follow => Nav2Codes::FOLLOW_WAYPOINTS,
            Action::Path => Nav2Codes::FOLLOW_PATH,
        }
    }

    /// A goal that lost control (stale or refused input).
    pub fn control_failure(self) -> u16 {
        self.codes().control_failure
    }

    /// Shutdown, or a request the action cannot take: UNKNOWN.
    pub fn unknown(self) -> u16 {
        self.codes().unknown
    }

    /// Nav2's error code of a goal from this action ending with `cause`
    /// ([`EndCause::nav2_error`]).
    pub fn error_code(self, cause: &EndCause) -> u16 {
        cause.nav2_error(self.codes())
    }

    /// An invalid goal (`why`), refused before it starts: `INVALID_GOAL` with DockRobot's
    /// DOCK_NOT_VALID, FollowPath's INVALID_PATH or the action's UNKNOWN.
    pub fn invalid_goal(self, why: impl std::fmt::Display) -> Outcome {
        let code = match self {
            Action::Dock => nav2::docking::DOCK_NOT_VALID,
            Action::Path => nav2::follow_path::INVALID_PATH,
            Action::Undock | Action::Follow => self.unknown(),
        };
        Outcome::failed("INVALID_GOAL", why.to_string(), code)
    }

    /// A goal the planner cannot start (its parameters or the law refuse it): `INVALID_INPUT`.
    pub fn refused_goal(self, why: impl std::fmt::Display) -> Outcome {
        Outcome::failed(
            "INVALID_INPUT",
            format!("the planner refused its input: {why}; robot stopped"),
            self.control_failure(),
        )
    }

    /// A goal whose frame has no usable transform to the odometry frame (`why`): `TF_ERROR`,
    /// with the action's code for it ([`Nav2Codes::tf_error`]).
    pub fn tf_error(self, why: impl std::fmt::Display) -> Outcome {
        Outcome::failed("TF_ERROR", why.to_string(), self.codes().tf_error)
    }

    /// A goal that needs an input it has not got fresh (`odom`, `scan`): `STALE_INPUT`.
    pub fn stale_at_start(self, input: &str) -> Outcome {
        Outcome::failed(
            "STALE_INPUT",
            format!("{input} stale: robot stopped"),
            self.control_failure(),
        )
    }
}

/// What the node tells of a `dock_robot` request for a pose: the staging it asks for (time
/// limit, navigating to the staging pose) and a dock type are not used, since the Lyapunov law
/// docks from wherever the robot is.
pub fn dock_request_notice(max_staging_time: f32, navigate_to_staging_pose: bool, dock_type: &str) -> Notice {
    let dock_type = match dock_type {
        "" => String::new(),
        t => format!("; dock_type `{t}` ignored"),
    };
    Notice::Info(format!(
        "dock_robot: max_staging_time ({max_staging_time}) and navigate_to_staging_pose \
         ({navigate_to_staging_pose}) ignored: the Lyapunov law docks from wherever the robot is{dock_type}"
    ))
}
