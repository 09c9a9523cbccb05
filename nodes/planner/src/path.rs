//! Nav2's controller role for the planner: a `FollowPath` goal followed by the goal approach
//! (SPEC §4) or by VFO (SPEC §5), whichever `controller_id` names.
//!
//! The path becomes sub-goals `lookahead` apart ([`PathGoals`]); the law drives through them
//! and only the path's end ends the goal. Nav2's navigator sends a re-planned path about once a
//! second, and the goal goes on with it ([`PathTask::replace`]):
//! - **goal approach**: the new path's sub-goals replace the old ones at once (the sub-goal
//!   pursued kept when the new path passes within half a lookahead of it); the follower is
//!   built anew on them, which costs nothing, so the robot drives on without a pause;
//! - **VFO**: a segment's left/right decisions are optimised by virtual robots when it starts,
//!   and the robot stands while an optimisation runs (for up to `vfo.optimise_budget_s` near
//!   obstacles). So the running law is kept as long as the new path ends where the old one did
//!   (within [`SAME_END`]) and passes near the sub-goal pursued, since VFO itself steers round
//!   what the scan shows: the new path is then not taken (nor the way it takes round a new
//!   obstacle, which VFO finds itself). A path that ends elsewhere, or leaves the sub-goal
//!   pursued, replaces the law, once it is back from a step it may be taking off the event loop
//!   ([`PathTask::take_pending`]); that step's end, made on the old path, does not end the goal
//!   ([`PathTask::vfo_returned`]).
//!
//! The goal approach makes each sub-goal a waypoint of [`WaypointFollower`]: it slows down at
//! the path's end only, and its stops apply (a sub-goal passed by is given up for the next
//! one; the end passed by, or the robot stalled, fails the goal `FAILED_TO_MAKE_PROGRESS`).
//! Both laws are watched by Nav2's progress checker ([`ProgressChecker`], on ROS time), kept
//! across re-planned paths. Neither sees obstacles the way a costmap does: the goal approach
//! none at all (Nav2's planner placed the path in free space; a collision monitor guards the
//! rest), VFO those in the scan.
//!
//! ```
//! use mobil_chassis::ChassisParams;
//! use mobil_geom::path::PathGoals;
//! use mobil_geom::Pose2;
//! use mobil_motion::progress::ProgressSettings;
//! use mobil_motion::{GoalLaw, Step, StepInput};
//! use mobil_planner::path::PathTask;
//! use mobil_planner::FollowConfig;
//! use nalgebra::Point2;
//!
//! let path = [Point2::new(0.0, 0.0), Point2::new(3.0, 0.0)];
//! let goals = PathGoals::new(&path, Point2::origin(), 1.0).unwrap();
//! let rules = (FollowConfig::default(), &ChassisParams::omr3(), ProgressSettings::default());
//! let mut task = PathTask::approach(goals, rules).unwrap();
//! let step = task.step_approach(&StepInput::new(0.0, 0.02, Pose2::identity()));
//! // The omni chassis drives straight at the first sub-goal at the cruise speed, 0.3 m/s.
//! assert!(matches!(step, Step::Command { twist, .. } if (twist.vx - 0.3).abs() < 1e-9));
//! ```

use mobil_chassis::ChassisParams;
use mobil_geom::path::PathGoals;
use mobil_motion::nav2::{follow_path, follow_waypoints};
use mobil_motion::progress::{no_progress, Progress, ProgressChecker, ProgressSettings};
use mobil_motion::{Outcome, Step, StepInput};
use nalgebra::Point2;

use crate::follow::{FollowConfig, FollowEnd, FollowEvent, WaypointFollower};
use crate::route::ProblemKind;
use crate::task::VfoRun;
use crate::vfo::WaypointMethod;

/// Two path ends nearer than this (m) are the same: a re-planned path to the same goal pose.
pub const SAME_END: f64 = 0.01;

/// The laws `controller_id` names, by their names.
pub const CONTROLLERS: [WaypointMethod; 2] = [WaypointMethod::Approach, WaypointMethod::Vfo];

/// The law a `FollowPath` goal's `controller_id` names: `approach` or `vfo`, empty or Nav2's
/// default plugin name `FollowPath` for `default` (the node's `waypoint_method`); any other is
/// Nav2's INVALID_CONTROLLER.
pub fn controller(id: &str, default: WaypointMethod) -> Result<WaypointMethod, Outcome> {
    if id.is_empty() || id == follow_path::DEFAULT_CONTROLLER_ID {
        return Ok(default);
    }
    CONTROLLERS.into_iter().find(|m| m.as_str() == id).ok_or_else(|| {
        Outcome::failed(
            "INVALID_CONTROLLER",
            format!(
                "controller_id `{id}`: this node's controllers are `approach` and `vfo` (or empty, or \
                 `FollowPath`: its waypoint_method)"
            ),
            follow_path::INVALID_CONTROLLER,
        )
    })
}

/// An end made with FollowWaypoints' codes (the VFO law's, the planner's refusals) given
/// FollowPath's: TASK_EXECUTOR_FAILED is NO_VALID_CONTROL, UNKNOWN is UNKNOWN; any other code
/// (FollowPath's own) stays.
pub fn as_follow_path(outcome: Outcome) -> Outcome {
    match outcome {
        Outcome::Failed {
            code,
            detail,
            nav2_error,
        } => {
            let nav2_error = match nav2_error {
                follow_waypoints::TASK_EXECUTOR_FAILED => follow_path::NO_VALID_CONTROL,
                follow_waypoints::UNKNOWN => follow_path::UNKNOWN,
                other => other,
            };
            Outcome::Failed {
                code,
                detail,
                nav2_error,
            }
        }
        succeeded => succeeded,
    }
}

/// The law that follows the path.
#[derive(Debug)]
#[allow(clippy::large_enum_variant)]
pub enum PathLaw {
    /// The goal approach through the sub-goals.
    Approach {
        /// The follower on the sub-goals from the one pursued when it was built.
        follower: WaypointFollower,
        /// Its settings and chassis, to build it anew on new sub-goals.
        config: FollowConfig,
        /// The chassis.
        chassis: ChassisParams,
        /// Distance Z (m) to the sub-goal pursued at the last step.
        distance: f64,
    },
    /// VFO through the sub-goals, its steps off the event loop.
    Vfo(VfoRun),
}

/// One step of the goal approach along a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathStep {
    /// The sub-goal pursued changed at this step.
    pub changed: bool,
}

/// What became of a re-planned path ([`PathTask::replace`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Replaced {
    /// Its sub-goals replace the old ones; `kept`: the sub-goal pursued stayed.
    Swapped {
        /// The sub-goal pursued stayed (the new path passes near it).
        kept: bool,
    },
    /// VFO's law is kept (the new path ends where the old one did and passes within half a
    /// lookahead of the sub-goal pursued); the new path is not taken.
    LawKept,
    /// VFO's law is to be built anew on the new sub-goals ([`PathTask::take_pending`]).
    Pending,
}

/// A `FollowPath` goal: the sub-goals, the law through them, the progress checker.
#[derive(Debug)]
pub struct PathTask {
    goals: PathGoals,
    /// The sub-goal index the law's first waypoint is.
    base: usize,
    law: PathLaw,
    progress: ProgressChecker,
    /// VFO: new sub-goals waiting for the law to come home.
    pending: Option<PathGoals>,
    /// VFO: the law ended on a path a newer one replaced (its end dropped): it is not to be
    /// kept, whatever path comes next.
    spent: bool,
}

impl PathTask {
    /// The goal approach through `goals` on `chassis` with `config`, watched by a progress
    /// checker with `progress`; refused (INVALID_PATH) when the follower refuses them.
    pub fn approach(
        goals: PathGoals,
        (config, chassis, progress): (FollowConfig, &ChassisParams, ProgressSettings),
    ) -> Result<Self, Outcome> {
        let follower = approach_on(&goals, config, chassis)?;
        Ok(PathTask {
            base: goals.index(),
            goals,
            law: PathLaw::Approach {
                follower,
                config,
                chassis: *chassis,
                distance: f64::NAN,
            },
            progress: ProgressChecker::new(progress),
            pending: None,
            spent: false,
        })
    }

    /// VFO through `goals` by `run`, a law built on [`PathTask::vfo_route`]'s waypoints,
    /// watched by a progress checker with `progress`.
    pub fn vfo(goals: PathGoals, run: VfoRun, progress: ProgressSettings) -> Self {
        PathTask {
            base: goals.index(),
            goals,
            law: PathLaw::Vfo(run),
            progress: ProgressChecker::new(progress),
            pending: None,
            spent: false,
        }
    }

    /// The waypoints a VFO law takes of `goals`: the sub-goals from the one pursued, no
    /// headings, each its own index.
    pub fn vfo_route(goals: &PathGoals) -> (Vec<Point2<f64>>, Vec<Option<f64>>, Vec<usize>) {
        let points = goals.goals()[goals.index()..].to_vec();
        let n = points.len();
        (points, vec![None; n], (0..n).collect())
    }

    /// The law's method.
    pub fn method(&self) -> WaypointMethod {
        match self.law {
            PathLaw::Approach { .. } => WaypointMethod::Approach,
            PathLaw::Vfo(_) => WaypointMethod::Vfo,
        }
    }

    /// The sub-goals, and which one is pursued.
    pub fn goals(&self) -> &PathGoals {
        &self.goals
    }

    /// The law.
    pub fn law(&self) -> &PathLaw {
        &self.law
    }

    /// The VFO law's run, if the law is VFO.
    pub fn vfo_run(&mut self) -> Option<&mut VfoRun> {
        match &mut self.law {
            PathLaw::Vfo(run) => Some(run),
            PathLaw::Approach { .. } => None,
        }
    }

    /// Distance (m) to the sub-goal pursued, as the law last measured it (NaN before).
    pub fn distance(&self) -> f64 {
        match &self.law {
            PathLaw::Approach { distance, .. } => *distance,
            PathLaw::Vfo(run) => run.view().distance,
        }
    }

    /// Distance still to go from `position`: to the sub-goal pursued, then along the rest.
    pub fn remaining(&self, position: Point2<f64>) -> f64 {
        self.goals.remaining(position)
    }

    /// Nav2's progress checker at `position` at ROS time `t` (s): the end (FAILED_TO_MAKE_PROGRESS)
    /// when the robot did not move its radius within its allowance.
    pub fn check_progress(&mut self, position: Point2<f64>, t: f64) -> Option<Outcome> {
        match self.progress.check(position, t) {
            Progress::Ok => None,
            Progress::Stuck { since } => Some(no_progress(since, self.progress.settings().required_movement_radius)),
        }
    }

    /// A re-planned path's sub-goals `new` (module docs): the goal approach takes them at once,
    /// VFO keeps its law while the new path ends where the old one did and passes near the
    /// sub-goal pursued, else takes them when its law is home.
    pub fn replace(&mut self, mut new: PathGoals) -> Result<Replaced, Outcome> {
        let current = self.goals.goal();
        let same_end = match (new.goals().last(), self.goals.goals().last()) {
            (Some(a), Some(b)) => (a - b).norm() <= SAME_END,
            _ => false,
        };
        let near = new.passes_near(current);
        let kept = new.keep(current) || (same_end && self.goals.is_last());
        match &mut self.law {
            PathLaw::Approach {
                follower,
                config,
                chassis,
                ..
            } => {
                *follower = approach_on(&new, *config, chassis)?;
                self.base = new.index();
                self.goals = new;
                Ok(Replaced::Swapped { kept })
            }
            PathLaw::Vfo(_) if near && same_end && !self.spent => {
                self.pending = None;
                Ok(Replaced::LawKept)
            }
            PathLaw::Vfo(_) => {
                self.pending = Some(new);
                Ok(Replaced::Pending)
            }
        }
    }

    /// VFO: the sub-goals waiting for a new law, if any and the law is home (not out on a
    /// step); the caller builds the law on [`PathTask::vfo_route`] of them and gives it with
    /// [`PathTask::rebuilt`].
    pub fn take_pending(&mut self) -> Option<PathGoals> {
        match &self.law {
            PathLaw::Vfo(run) if run.law().is_some() => self.pending.take(),
            _ => None,
        }
    }

    /// VFO: the law `run` built on `goals` (from [`PathTask::take_pending`]) replaces the old.
    pub fn rebuilt(&mut self, goals: PathGoals, run: VfoRun) {
        self.base = goals.index();
        self.goals = goals;
        self.law = PathLaw::Vfo(run);
        self.spent = false;
    }

    /// VFO: the law came back from a step with `step` ([`VfoRun::give_back`] done): the
    /// sub-goal pursued follows its waypoint, and the step is what the goal does, its end given
    /// FollowPath's codes ([`as_follow_path`]); `None` when a new path waits for the law
    /// ([`PathTask::take_pending`]) and the step ended the goal on the old one (a success at the
    /// same end stands): the goal goes on with the new path, the robot held meanwhile.
    pub fn vfo_returned<F, R>(&mut self, step: Step<F, R>) -> Option<Step<F, R>> {
        if let PathLaw::Vfo(run) = &self.law {
            self.goals.pursue(self.base + run.view().index);
        }
        match step {
            Step::End(end) => {
                let same_end = match (&self.pending, self.goals.goals().last()) {
                    (None, _) => true,
                    (Some(new), Some(old)) => new.goals().last().is_some_and(|e| (e - old).norm() <= SAME_END),
                    (Some(_), None) => false,
                };
                if self.pending.is_some() && !(end.outcome.is_success() && same_end) {
                    self.spent = true;
                    return None;
                }
                Some(Step::end(as_follow_path(end.outcome), end.report))
            }
            other => Some(other),
        }
    }

    /// The progress checker, to carry into a path by another law.
    pub fn progress(&self) -> &ProgressChecker {
        &self.progress
    }

    /// This path watched by `progress` (a running path's, by another law): its window goes on.
    pub fn with_progress(mut self, progress: ProgressChecker) -> Self {
        if progress.settings() == self.progress.settings() {
            self.progress = progress;
        }
        self
    }

    /// One step of the goal approach at `input` (a VFO law steps off the event loop, and this
    /// refuses): the next sub-goal once the robot is within half a lookahead of the one
    /// pursued, the follower's command toward it; the end reached succeeds, passed by or a
    /// stalled robot fails FAILED_TO_MAKE_PROGRESS. The progress checker is the caller's
    /// ([`PathTask::check_progress`]).
    pub fn step_approach(&mut self, input: &StepInput) -> Step<PathStep, ()> {
        let PathLaw::Approach {
            follower,
            config,
            chassis,
            distance,
        } = &mut self.law
        else {
            return Step::Refused("a VFO law steps off the event loop".into());
        };
        let position = input.pose.position();
        let mut changed = false;
        if self.goals.advance(position) {
            match approach_on(&self.goals, *config, chassis) {
                Ok(f) => *follower = f,
                Err(outcome) => return Step::end(outcome, ()),
            }
            self.base = self.goals.index();
            changed = true;
        }
        let o = match follower.update(&input.pose, input.dt, input.t) {
            Ok(o) => o,
            Err(e) => return Step::Refused(e.to_string()),
        };
        *distance = o.distance;
        changed |= self.goals.pursue(self.base + o.index);
        let end_missed = o.events.iter().find_map(|e| match e {
            FollowEvent::Missed { index, cause } if *index + 1 == follower.waypoints().len() => Some(*cause),
            _ => None,
        });
        match (o.end, end_missed) {
            (Some(FollowEnd::Done), None) => Step::end(Outcome::succeeded("the path's end reached"), ()),
            (Some(FollowEnd::Done), Some(cause)) => Step::end(
                Outcome::failed(
                    "ABORTED",
                    format!("the path's end was given up, {}", ProblemKind::Unreachable(cause)),
                    follow_path::FAILED_TO_MAKE_PROGRESS,
                ),
                (),
            ),
            (Some(FollowEnd::Stalled), _) => Step::end(
                Outcome::failed(
                    "STALLED",
                    format!(
                        "the robot did not move for {} s on its way to sub-goal {}",
                        config.stall_time_s,
                        self.goals.index()
                    ),
                    follow_path::FAILED_TO_MAKE_PROGRESS,
                ),
                (),
            ),
            (None, _) => Step::Command {
                twist: o.twist,
                feedback: PathStep { changed },
            },
        }
    }
}

/// The goal approach's follower on `goals`' sub-goals from the one pursued.
fn approach_on(goals: &PathGoals, config: FollowConfig, chassis: &ChassisParams) -> Result<WaypointFollower, Outcome> {
    WaypointFollower::new(config, chassis, goals.goals()[goals.index()..].to_vec())
        .map_err(|e| Outcome::failed("INVALID_PATH", e.to_string(), follow_path::INVALID_PATH))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mobil_chassis::kinematics::twist_at_reference;
    use mobil_geom::Pose2;

    fn p(x: f64, y: f64) -> Point2<f64> {
        Point2::new(x, y)
    }

    fn omni_task(path: &[Point2<f64>]) -> PathTask {
        let goals = PathGoals::new(path, path[0], 1.0).unwrap();
        PathTask::approach(
            goals,
            (
                FollowConfig::default(),
                &ChassisParams::omr3(),
                ProgressSettings::default(),
            ),
        )
        .unwrap()
    }

    /// Drives the omni robot by its own commands (exact integration of a body twist with no
    /// turn: a straight step), 50 Hz, until the goal ends; the poses and the end.
    fn drive(task: &mut PathTask, mut pose: Pose2, max_steps: usize) -> (Vec<Pose2>, Option<Outcome>) {
        let dt = 0.02;
        let mut poses = vec![pose];
        for k in 0..max_steps {
            match task.step_approach(&StepInput::new(k as f64 * dt, dt, pose)) {
                Step::Command { twist, .. } => {
                    let (s, c) = pose.yaw.sin_cos();
                    pose = Pose2::new(
                        pose.x + (c * twist.vx - s * twist.vy) * dt,
                        pose.y + (s * twist.vx + c * twist.vy) * dt,
                        pose.yaw + twist.wz * dt,
                    );
                    poses.push(pose);
                }
                Step::End(end) => return (poses, Some(end.outcome)),
                Step::Refused(why) => panic!("refused: {why}"),
            }
        }
        (poses, None)
    }

    #[test]
    fn controller_ids_name_the_laws() {
        assert_eq!(controller("", WaypointMethod::Vfo), Ok(WaypointMethod::Vfo));
        assert_eq!(
            controller("approach", WaypointMethod::Vfo),
            Ok(WaypointMethod::Approach)
        );
        assert_eq!(controller("vfo", WaypointMethod::Approach), Ok(WaypointMethod::Vfo));
        assert_eq!(controller("FollowPath", WaypointMethod::Vfo), Ok(WaypointMethod::Vfo));
        let e = controller("dwb", WaypointMethod::Approach).unwrap_err();
        assert_eq!(e.nav2_error(), 101);
    }

    #[test]
    fn follow_waypoints_codes_become_follow_path_codes() {
        let f = |code| as_follow_path(Outcome::failed("X", "", code)).nav2_error();
        assert_eq!((f(601), f(600), f(105), f(0)), (106, 100, 105, 0));
        assert!(as_follow_path(Outcome::succeeded("")).is_success());
    }

    /// An L-shaped path on the omni chassis: the robot passes every sub-goal without stopping
    /// (the speed stays 0.3 m/s until the slow-down 0.6 m before the end) and ends within
    /// Z_crit (0.16 m) of the end, having kept within half a lookahead (0.5 m) of the path.
    #[test]
    fn the_omni_robot_follows_an_l_without_stopping_at_sub_goals() {
        let path = [p(0.0, 0.0), p(3.0, 0.0), p(3.0, 2.0)];
        let mut task = omni_task(&path);
        let (poses, end) = drive(&mut task, Pose2::identity(), 2000);
        let end = end.expect("ends");
        assert!(end.is_success(), "{end:?}");
        let last = poses.last().unwrap().position();
        assert!((last - p(3.0, 2.0)).norm() < 0.16, "{last}");
        // Off the polyline by at most half a lookahead (the corner is cut toward the sub-goal
        // after it).
        for q in &poses {
            let d1 = mobil_geom::segment::segment_distance(q.position(), path[0], path[1]);
            let d2 = mobil_geom::segment::segment_distance(q.position(), path[1], path[2]);
            assert!(d1.min(d2) < 0.5, "{q:?}");
        }
        // Sub-goals (1, 0), (2, 0), (3, 0), (3, 1), (3, 2). Straight to (2.5, 0), where (3, 1) is
        // taken: 2.5 m; toward (3, 1) until 0.5 m from it, at (2.776, 0.553): 1.118 − 0.5 =
        // 0.618 m; then to the end, √(0.224² + 1.447²) = 1.464 m. 4.582 m in all, at 0.3 m/s to
        // the slow-down's start 0.6 m from the end: 3.982 / 0.3 = 13.27 s; inside it the speed is
        // 0.5·z m/s down to Z_crit, 2·ln(0.6 / 0.16) = 2.64 s: 15.92 s, a step either way.
        let seconds = (poses.len() - 1) as f64 * 0.02;
        assert!((15.85..16.0).contains(&seconds), "{seconds}");
        for w in poses.windows(2) {
            if (w[1].position() - p(3.0, 2.0)).norm() > 0.6 {
                let speed = (w[1].position() - w[0].position()).norm() / 0.02;
                assert!((speed - 0.3).abs() < 1e-6, "{speed} at {:?} from {:?}", w[1], w[0]);
            }
        }
    }

    /// A re-planned path from the robot's position along the same way keeps the sub-goal
    /// pursued; one elsewhere takes its own; the progress checker is not reset by either.
    #[test]
    fn a_replanned_path_is_taken_at_once_by_the_approach() {
        let mut task = omni_task(&[p(0.0, 0.0), p(4.0, 0.0)]);
        let (poses, _) = drive(&mut task, Pose2::identity(), 50);
        let here = poses.last().unwrap().position();
        assert_eq!(task.goals().goal(), p(1.0, 0.0));
        let same = PathGoals::new(&[here, p(4.0, 0.0)], here, 1.0).unwrap();
        assert_eq!(task.replace(same), Ok(Replaced::Swapped { kept: true }));
        assert_eq!(task.goals().goal(), p(1.0, 0.0));
        let other = PathGoals::new(&[here, p(here.x, 3.0)], here, 1.0).unwrap();
        assert_eq!(task.replace(other), Ok(Replaced::Swapped { kept: false }));
        assert!((task.goals().goal() - p(here.x, 1.0)).norm() < 1e-12);
        // The robot now heads up, (0, 0.3) m/s.
        let step = task.step_approach(&StepInput::new(1.0, 0.02, Pose2::new(here.x, here.y, 0.0)));
        let Step::Command { twist, .. } = step else {
            panic!("{step:?}")
        };
        assert!(twist.vx.abs() < 1e-9 && (twist.vy - 0.3).abs() < 1e-9, "{twist:?}");
    }

    /// Standing still: the progress checker's window (10 s, 0.5 m) runs on across re-planned
    /// paths and ends the goal FAILED_TO_MAKE_PROGRESS.
    #[test]
    fn no_progress_fails_across_replans() {
        let mut task = omni_task(&[p(0.0, 0.0), p(4.0, 0.0)]);
        for k in 0..=20 {
            let t = k as f64 * 0.5;
            assert_eq!(task.check_progress(p(0.1, 0.0), t), None, "{t}");
            let again = PathGoals::new(&[p(0.1, 0.0), p(4.0, 0.0)], p(0.1, 0.0), 1.0).unwrap();
            task.replace(again).unwrap();
        }
        let end = task.check_progress(p(0.1, 0.0), 10.5).expect("stuck");
        assert_eq!(end.nav2_error(), follow_path::FAILED_TO_MAKE_PROGRESS);
    }

    /// The car's exact arc at the model's origin over `dt` under `twist` (at the reference
    /// point), moved back to the reference point.
    fn car_step(chassis: &ChassisParams, pose: Pose2, twist: mobil_chassis::BodyTwist, dt: f64) -> Pose2 {
        let offset = chassis.reference_offset();
        let origin = pose.ahead(-offset);
        let at_origin = twist_at_reference(twist, -offset);
        assert!(at_origin.vy.abs() < 1e-9, "a car does not slide: {at_origin:?}");
        let (v, w) = (at_origin.vx, at_origin.wz);
        let yaw = origin.yaw + w * dt;
        let moved = if w.abs() < 1e-12 {
            p(
                origin.x + v * dt * origin.yaw.cos(),
                origin.y + v * dt * origin.yaw.sin(),
            )
        } else {
            p(
                origin.x + v / w * (yaw.sin() - origin.yaw.sin()),
                origin.y - v / w * (yaw.cos() - origin.yaw.cos()),
            )
        };
        Pose2::new(moved.x, moved.y, yaw).ahead(offset)
    }

    /// MOBIL-II along an L with 3 m legs: its corner needs no turn tighter than R_min (0.73 m)
    /// once cut toward the sub-goal after it, so it ends within Z_crit (0.16 m) of the end.
    #[test]
    fn the_car_follows_an_l() {
        let chassis = ChassisParams::mobil2();
        let path = [p(0.0, 0.0), p(3.0, 0.0), p(3.0, 3.0)];
        let goals = PathGoals::new(&path, p(0.0, 0.0), 1.0).unwrap();
        let mut task =
            PathTask::approach(goals, (FollowConfig::default(), &chassis, ProgressSettings::default())).unwrap();
        let (mut pose, dt) = (Pose2::identity(), 0.02);
        for k in 0..5000 {
            match task.step_approach(&StepInput::new(k as f64 * dt, dt, pose)) {
                Step::Command { twist, .. } => pose = car_step(&chassis, pose, twist, dt),
                Step::End(e) => {
                    assert!(e.outcome.is_success(), "{:?} at {pose:?}", e.outcome);
                    assert!((pose.position() - p(3.0, 3.0)).norm() < 0.16, "{pose:?}");
                    return;
                }
                Step::Refused(why) => panic!("{why}"),
            }
        }
        panic!("not ended at {pose:?}");
    }

    /// MOBIL-II (car-like, R_min 0.73 m) cannot turn into an end 0.3 m to its side: the end is
    /// passed by, and the goal fails FAILED_TO_MAKE_PROGRESS rather than succeeding.
    #[test]
    fn an_end_the_car_cannot_reach_fails() {
        let chassis = ChassisParams::mobil2();
        let goals = PathGoals::new(&[p(0.0, 0.0), p(0.05, 0.3)], p(0.0, 0.0), 1.0).unwrap();
        let mut task =
            PathTask::approach(goals, (FollowConfig::default(), &chassis, ProgressSettings::default())).unwrap();
        let (mut pose, dt) = (Pose2::identity(), 0.02);
        let mut end = None;
        for k in 0..3000 {
            match task.step_approach(&StepInput::new(k as f64 * dt, dt, pose)) {
                Step::Command { twist, .. } => pose = car_step(&chassis, pose, twist, dt),
                Step::End(e) => {
                    end = Some(e.outcome);
                    break;
                }
                Step::Refused(why) => panic!("{why}"),
            }
        }
        let end = end.expect("ends");
        assert!(!end.is_success(), "{end:?} at {pose:?}");
        assert_eq!(end.nav2_error(), follow_path::FAILED_TO_MAKE_PROGRESS, "{end:?}");
        assert!(
            end.reason().contains("end was given up"),
            "passed by, not stalled: {end:?}"
        );
    }
}

#[cfg(test)]
mod vfo_tests {
    use super::*;
    use crate::vfo::{ObstacleMap, ScanObstacleConfig, VfoSettings};
    use mobil_geom::Pose2;
    use std::time::Duration;

    fn p(x: f64, y: f64) -> Point2<f64> {
        Point2::new(x, y)
    }

    fn vfo_task(path: &[Point2<f64>], from: Point2<f64>) -> PathTask {
        let goals = PathGoals::new(path, from, 1.0).unwrap();
        let (points, headings, index) = PathTask::vfo_route(&goals);
        let map = ObstacleMap::new(ScanObstacleConfig::default()).unwrap();
        let start = Pose2::new(from.x, from.y, 0.0);
        let rules = (&VfoSettings::default(), &ChassisParams::omr3(), &map);
        let run = VfoRun::start(
            (&points, &headings, &index),
            Some(start),
            true,
            rules,
            Some(Duration::from_millis(20)),
        );
        PathTask::vfo(goals, run.unwrap().run, ProgressSettings::default())
    }

    /// VFO keeps its law for a path re-planned to the same end along the same way, and waits
    /// to build a new one for a path to another end, or one that leaves the sub-goal pursued.
    #[test]
    fn vfo_keeps_its_law_for_the_same_end() {
        let route = [p(0.0, 0.0), p(3.0, 0.0), p(3.0, 3.0)];
        let mut task = vfo_task(&route, p(0.0, 0.0));
        let from = p(0.3, 0.0);
        let same = PathGoals::new(&[from, p(3.0, 0.0), p(3.0, 3.0)], from, 1.0).unwrap();
        assert_eq!(task.replace(same), Ok(Replaced::LawKept));
        // From (0.7, 0): the sub-goal pursued, (1, 0), lies between the robot and the new
        // path's first sub-goal (1.7, 0), on the path.
        let on = p(0.7, 0.0);
        let ahead = PathGoals::new(&[on, p(3.0, 0.0), p(3.0, 3.0)], on, 1.0).unwrap();
        assert_eq!(task.replace(ahead), Ok(Replaced::LawKept));
        // A path 0.6 m to the side of (1, 0), to the same end: not near.
        let side = PathGoals::new(&[p(0.7, 0.6), p(3.0, 0.6), p(3.0, 3.0)], on, 1.0).unwrap();
        assert_eq!(task.replace(side), Ok(Replaced::Pending));
        let elsewhere = PathGoals::new(&[from, p(3.0, 0.0), p(3.0, -3.0)], from, 1.0).unwrap();
        assert_eq!(task.replace(elsewhere), Ok(Replaced::Pending));
        // The law is home: the new sub-goals are handed out once, the sub-goal pursued (1, 0)
        // kept in place of (1.3, 0), the new end last.
        let pending = task.take_pending().expect("pending");
        assert_eq!(
            (pending.goal(), pending.goals().last()),
            (p(1.0, 0.0), Some(&p(3.0, -3.0)))
        );
        assert_eq!(task.take_pending(), None);
    }

    /// A law out on a step: a new path waits for it; the step's end, made on the old path,
    /// does not end the goal (but a success at the new path's own end would); once home, the
    /// law is built anew on the new sub-goals.
    #[test]
    fn a_new_path_waits_for_the_law_out_on_a_step() {
        let route = [p(0.0, 0.0), p(3.0, 0.0), p(3.0, 3.0)];
        let mut task = vfo_task(&route, p(0.0, 0.0));
        let map = ObstacleMap::new(ScanObstacleConfig::default()).unwrap();
        let now = std::time::Instant::now();
        let lent = task.vfo_run().unwrap().lend(now, &map).expect("home");
        let from = p(0.3, 0.0);
        let elsewhere = PathGoals::new(&[from, p(3.0, 0.0), p(3.0, -3.0)], from, 1.0).unwrap();
        assert_eq!(task.replace(elsewhere), Ok(Replaced::Pending));
        assert_eq!(task.take_pending(), None, "the law is out");
        // Back with an end on the old path: dropped, whether it failed or reached the old end.
        let back = Step::<crate::vfo::VfoStep, Vec<usize>>::end(Outcome::succeeded("old end"), vec![]);
        let (back, _) = task.vfo_run().unwrap().give_back(lent, back, now);
        assert_eq!(task.vfo_returned(back), None);
        let failed = Step::<(), ()>::end(Outcome::failed("NO_SAFE_PATH", "", 601), ());
        assert_eq!(task.vfo_returned(failed), None);
        // The law ended: a path to the old end, near the sub-goal, does not keep it now.
        let same = PathGoals::new(&[from, p(3.0, 0.0), p(3.0, 3.0)], from, 1.0).unwrap();
        assert_eq!(task.replace(same), Ok(Replaced::Pending));
        let elsewhere = PathGoals::new(&[from, p(3.0, 0.0), p(3.0, -3.0)], from, 1.0).unwrap();
        assert_eq!(task.replace(elsewhere), Ok(Replaced::Pending));
        let new = task.take_pending().expect("home now");
        let (points, headings, index) = PathTask::vfo_route(&new);
        let rules = (&VfoSettings::default(), &ChassisParams::omr3(), &map);
        let start = Some(Pose2::new(from.x, from.y, 0.0));
        let run = VfoRun::start((&points, &headings, &index), start, true, rules, None).unwrap();
        task.rebuilt(new, run.run);
        assert_eq!(task.goals().goals().last(), Some(&p(3.0, -3.0)));
        // With nothing pending, an end passes, with FollowPath's codes.
        let failed = Step::<(), ()>::end(Outcome::failed("NO_SAFE_PATH", "", 601), ());
        let Some(Step::End(end)) = task.vfo_returned(failed) else {
            panic!("the end stands")
        };
        assert_eq!(end.outcome.nav2_error(), follow_path::NO_VALID_CONTROL);
    }

    /// A law back with a success while a path waits: it stands when the waiting path ends
    /// where the law did (it left the sub-goal pursued, not the end).
    #[test]
    fn a_success_at_the_same_end_stands() {
        let route = [p(0.0, 0.0), p(3.0, 0.0)];
        let mut task = vfo_task(&route, p(0.0, 0.0));
        let from = p(0.0, 1.0);
        let away = PathGoals::new(&[from, p(3.0, 1.0), p(3.0, 0.0)], from, 1.0).unwrap();
        assert_eq!(task.replace(away), Ok(Replaced::Pending));
        let done = Step::<(), ()>::end(Outcome::succeeded("end"), ());
        assert!(matches!(task.vfo_returned(done), Some(Step::End(e)) if e.outcome.is_success()));
    }

    /// As a task: the progress checker first, on ROS time (the goal's own time stays 0 here),
    /// then the VFO law off the event loop.
    #[test]
    fn a_path_task_checks_progress_on_ros_time_before_its_law() {
        use crate::task::{Stepped, Task};
        let mut task = Task::Path(vfo_task(&[p(0.0, 0.0), p(3.0, 0.0)], p(0.0, 0.0)));
        let at = StepInput::new(0.0, 0.02, Pose2::identity());
        assert_eq!(task.step(&at, 100.0), Stepped::OffLoop);
        assert_eq!(task.step(&at, 110.0), Stepped::OffLoop, "10 s: within the allowance");
        match task.step(&at, 110.5) {
            Stepped::Law(Step::End(end)) => assert_eq!(end.outcome.nav2_error(), follow_path::FAILED_TO_MAKE_PROGRESS),
            other => panic!("{other:?}"),
        }
    }
}
