//! Nav2's controller role: `follow_path` (nav2_msgs/action/FollowPath) by the goal approach or
//! VFO, as `controller_id` names them ([`mobil_planner::path`]).
//!
//! A new `follow_path` goal while one runs is taken as controller_server takes it: the running
//! goal's action ends ABORTED (error NONE) and the new path goes on from where the robot is,
//! with no zero command between them and the progress checker kept ([`PathTask::replace`]). A
//! goal that cannot be followed is accepted and ended at once with Nav2's code
//! (INVALID_CONTROLLER, TF_ERROR, INVALID_PATH), as controller_server ends it. The path is
//! followed without the route pre-check: Nav2's planner has placed it in free space already.

use super::routes::map_seen;
use crate::*;
use mobil_motion::progress::ProgressChecker;
use mobil_msgs::nav2_msgs::action::FollowPathFeedback;
use mobil_planner::path::{as_follow_path, controller, PathTask, Replaced};
use mobil_planner::vfo::WaypointMethod;
use mobil_ros::goal::path_goals;
use nalgebra::Point2;
use tracing::debug;

impl Shell {
    pub(crate) async fn path_action(&mut self, io: &mut Io<'_, '_>, request: GoalRequest<FollowPathGoal>) {
        let goal = request.goal();
        for line in mobil_ros::goal::ignored_checkers(goal, "critical_distance") {
            warn_throttled!(self.throttle, "checker-id", "{line}");
        }
        // The path's frame must reach odometry through a fresh transform (TF_ERROR); the
        // sub-goals start from the robot seen from there.
        let frame = self.tf.frame_of(&goal.path.header.frame_id);
        let placed = self.goal_frame(io.node, &frame, Action::Path);
        let from = match (self.fresh_odom(), &placed, goal.path.poses.first()) {
            (Some(o), Ok(p), _) => p.odom_in.compose(&o).position(),
            (_, _, Some(p)) => Point2::new(p.pose.position.x, p.pose.position.y),
            (_, _, None) => Point2::origin(),
        };
        let lookahead = self.config.controller.path_lookahead;
        let checked = controller(&goal.controller_id, self.config.waypoint_method).and_then(|method| {
            let goals = path_goals(&goal.path, from, lookahead)?;
            Ok((method, goals, placed?))
        });
        // A running path in the same frame by the same law goes on with the new one; by the
        // other law, its progress checker goes on.
        let running = self
            .session
            .active()
            .filter(|a| a.source == Source::PathAction && a.goal.frame == frame);
        let (continuing, progress) = match running.map(|a| &a.goal.task) {
            Some(Task::Path(p)) => (Some(p.method()), Some(p.progress().clone())),
            _ => (None, None),
        };
        // The server ends a running follow_path goal itself on accept, as controller_server.
        let preempted = nav2_result(&EndCause::Preempted("follow_path"), Action::Path.codes());
        let accept = io
            .servers
            .path
            .accept(request, |_| preempted, io.node.now_nanos())
            .await;
        if !self.accepted(io, accept, Source::PathAction) {
            return;
        }
        match checked {
            Err(outcome) => self.refuse(io, Source::PathAction, outcome),
            Ok((method, goals, _)) if continuing == Some(method) => self.replace_path(io, goals),
            Ok((method, goals, placed)) => self.start_path(io, method, (goals, placed), progress),
        }
    }

    /// Starts following `goals` by `method` (or refuses it), watched by `progress` when a path
    /// by the other law ran until now.
    fn start_path(
        &mut self,
        io: &mut Io<'_, '_>,
        method: WaypointMethod,
        (goals, placed): (PathGoals, Placed),
        progress: Option<ProgressChecker>,
    ) {
        let settings = self.config.controller.progress;
        let start = self.fresh_odom().map(|p| placed.odom_in.compose(&p));
        let task = match method {
            WaypointMethod::Approach if start.is_none() => Err(Action::Path.stale_at_start("odom")),
            WaypointMethod::Approach => PathTask::approach(goals, (self.config.follow, &self.chassis, settings)),
            WaypointMethod::Vfo => {
                let scan_fresh = self.scan_seen.get(self.config.vfo.scan_timeout()).is_some();
                let (points, headings, index) = PathTask::vfo_route(&goals);
                let map = self.map_in(&placed.frame, &placed.odom_in);
                let rules = (&self.config.vfo, &self.chassis, map.as_ref());
                let period = self.odom_period.period();
                VfoRun::start((&points, &headings, &index), start, scan_fresh, rules, period)
                    .map(|started| {
                        if let Some(w) = &started.chassis_warning {
                            warn!("goal (follow_path): {w}");
                        }
                        PathTask::vfo(goals, started.run, settings)
                    })
                    .map_err(as_follow_path)
            }
        };
        let task = match (task, progress) {
            (Ok(task), Some(progress)) => task.with_progress(progress),
            (Ok(task), None) => task,
            (Err(refusal), _) => return self.refuse(io, Source::PathAction, refusal),
        };
        let end = *task.goals().goals().last().unwrap_or(&task.goals().goal());
        info!(
            "goal (follow_path): {} sub-goals to ({:.3}, {:.3}) by {}",
            task.goals().goals().len(),
            end.x,
            end.y,
            method.as_str()
        );
        self.drawing = Drawing {
            route: task.goals().goals().to_vec(),
            ..Drawing::default()
        };
        self.begin(io, (Task::Path(task), placed), None, Source::PathAction);
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
        self.publish_markers(io.node, io.out);
    }

    /// A new path for the running `follow_path` goal: no stop, the progress checker kept; the
    /// goal approach takes it at once, VFO keeps its law or rebuilds it ([`PathTask::replace`]).
    fn replace_path(&mut self, io: &mut Io<'_, '_>, goals: PathGoals) {
        let Some(Task::Path(task)) = self.session.active_mut().map(|a| &mut a.goal.task) else {
            return;
        };
        let route = goals.goals().to_vec();
        match task.replace(goals) {
            Err(outcome) => self.end_goal(io, outcome.into()),
            Ok(Replaced::Swapped { kept }) => {
                self.drawing.route = route;
                debug!("follow_path: new path, sub-goal {}", if kept { "kept" } else { "new" });
            }
            Ok(Replaced::LawKept) => debug!("follow_path: new path to the same end; the VFO law goes on"),
            Ok(Replaced::Pending) => {
                self.drawing.route = route;
                let Some(frame) = self.session.active().map(|a| a.goal.frame.clone()) else {
                    return;
                };
                match self.goal_frame(io.node, &frame, Action::Path) {
                    Ok(placed) => self.rebuild_path_vfo(io, placed.odom_in),
                    Err(refusal) => self.end_goal(io, refusal.into()),
                }
            }
        }
    }

    /// A `follow_path` goal by VFO whose new path waits for its law: the law built on it, once
    /// the old one is home (no step off the event loop); the goal ends if it cannot be.
    pub(crate) fn rebuild_path_vfo(&mut self, io: &mut Io<'_, '_>, odom_in: Pose2) {
        let start = self.fresh_odom().map(|p| odom_in.compose(&p));
        let scan_fresh = self.scan_seen.get(self.config.vfo.scan_timeout()).is_some();
        let period = self.odom_period.period();
        let Some(active) = self.session.active_mut() else {
            return;
        };
        let Task::Path(task) = &mut active.goal.task else {
            return;
        };
        let Some(goals) = task.take_pending() else { return };
        let (points, headings, index) = PathTask::vfo_route(&goals);
        let map = map_seen(&self.map, self.tf.is_odom(&active.goal.frame), &odom_in, true);
        let rules = (&active.goal.config.vfo, &active.goal.chassis, map.as_ref());
        match VfoRun::start((&points, &headings, &index), start, scan_fresh, rules, period) {
            Ok(started) => {
                info!(
                    "follow_path: a new path to another end, or away from the sub-goal pursued; VFO starts anew: {}",
                    started.summary
                );
                task.rebuilt(goals, started.run);
                active.goal.map_seen_from = odom_in;
            }
            Err(refusal) => self.end_goal(io, as_follow_path(refusal).into()),
        }
    }

    /// `follow_path` feedback: the distance along the sub-goals to the end, and the speed.
    pub(crate) fn path_feedback(&self, goal: &Goal, now: i64) -> Option<FollowPathFeedback> {
        let odom = self.fresh_odom()?;
        let odom_in = self.tf.odom_in(&goal.frame, now).ok()?;
        let (odom, Task::Path(task)) = (odom_in.compose(&odom), &goal.task) else {
            return None;
        };
        Some(FollowPathFeedback {
            distance_to_goal: task.remaining(odom.position()) as f32,
            speed: self.odom_speed as f32,
        })
    }
}
