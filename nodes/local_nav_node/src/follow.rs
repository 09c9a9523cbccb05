//! Nav2's controller role: `follow_path` (nav2_msgs/action/FollowPath), the path as sub-goals
//! of the navigator ([`PathGoals`]).
//!
//! Nav2's navigator sends the controller a new path about once a second. A new `follow_path`
//! goal while one runs is taken as controller_server takes it: the running goal's action ends
//! ABORTED (error NONE) and the new path goes on from where the robot is, with no zero command
//! between them; the navigator keeps its sub-goal, and so its mode, when the new path passes
//! within half a lookahead of it, and its progress checker in any case. A goal that cannot be
//! followed is accepted and ended at once with Nav2's code (INVALID_CONTROLLER, TF_ERROR,
//! INVALID_PATH), as controller_server ends it.

use super::*;
use mobil_local_nav_node::follow_path_goal;
use mobil_msgs::nav2_msgs::action::FollowPathFeedback;
use mobil_ros::action::GoalEnd;
use mobil_ros::goal::path_tf_error;
use tracing::debug;

impl Shell {
    pub(super) async fn path_goal_in(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        sink: &mut CmdVel<'_>,
        servers: &mut Servers,
        request: GoalRequest<FollowPathGoal>,
    ) {
        let goal = request.goal();
        for line in mobil_ros::goal::ignored_checkers(goal, "xy_goal_tolerance") {
            warn_throttled!(self.throttle, "checker-id", "{line}");
        }
        // The path's frame must reach odometry through a fresh transform (TF_ERROR); the
        // sub-goals start from the robot seen from there.
        let frame = self.tf.frame_of(&goal.path.header.frame_id);
        let odom_in = self.tf.accept(&frame, node.now_nanos());
        let from = match (self.odom.value(), &odom_in, goal.path.poses.first()) {
            (Some(o), Ok(t), _) => t.compose(&o.pose).position(),
            (_, _, Some(p)) => Point2::new(p.pose.position.x, p.pose.position.y),
            (_, _, None) => Point2::origin(),
        };
        let checked = match odom_in {
            Ok(_) => follow_path_goal(goal, from, self.config.controller.path_lookahead),
            Err(why) => Err(path_tf_error(why)),
        };
        // A new path continues the running one when it is in the same frame.
        let continuing = self
            .session
            .active()
            .is_some_and(|a| a.source == Source::Path && a.goal.frame == frame);
        // The server ends a running follow_path goal itself on accept, as controller_server.
        let preempted = path_result(&EndCause::Preempted("follow_path"));
        if let Err(e) = servers.path.accept(request, |_| preempted, node.now_nanos()).await {
            warn_throttled!(self.throttle, "accept", "follow_path goal not started: {e}");
            if e.ended_active()
                && let Some(ended) = self.session.preempt(Source::Path, sink)
            {
                self.report(node, out, servers, ended);
            }
            return;
        }
        match checked {
            Err(outcome) => {
                let cause = EndCause::Outcome(outcome);
                warn!("follow_path goal ends at once: {}", cause.reason());
                servers.path.finish(GoalEnd::Aborted, path_result(&cause));
                // The goal it was to replace stops (its robot would otherwise drive on).
                if let Some(ended) = self.session.preempt(Source::Path, sink) {
                    self.report(node, out, servers, ended);
                }
            }
            Ok(path) if continuing => self.replace_path(path),
            Ok(path) => {
                let first = path.goal();
                info!(
                    "follow_path: {} sub-goals to ({:.3}, {:.3})",
                    path.goals().len(),
                    path.goals().last().map_or(first.x, |g| g.x),
                    path.goals().last().map_or(first.y, |g| g.y)
                );
                self.start_goal(node, out, servers, Source::Path, (Target::Path(path), frame));
            }
        }
    }

    /// A new path for the running `follow_path` goal: no stop, the sub-goal kept when the new
    /// path passes near it (the navigator's mode with it), the progress checker kept; any other
    /// goal, the end included, goes to the navigator as it is.
    fn replace_path(&mut self, mut path: PathGoals) {
        let Some(active) = self.session.active_mut() else {
            return;
        };
        let kept = path.keep(active.goal.goal);
        let goal = path.goal();
        let moved = goal != active.goal.goal;
        active.goal.goal = goal;
        active.goal.path = Some(path);
        if moved {
            if let Err(e) = self.nav.set_goal(goal) {
                warn!("sub-goal refused by the navigator: {e}");
            }
            self.last_step = None;
        }
        debug!(
            "follow_path: new path; sub-goal ({:.3}, {:.3}) {}",
            goal.x,
            goal.y,
            if kept { "kept" } else { "new" }
        );
    }

    /// Before a step of a `follow_path` goal: the next sub-goal once the robot at `position` is
    /// near the current one.
    pub(super) fn next_subgoal(&mut self, position: Point2<f64>) {
        let Some(active) = self.session.active_mut() else {
            return;
        };
        let Some(path) = active.goal.path.as_mut() else { return };
        if path.advance(position) {
            let goal = path.goal();
            active.goal.goal = goal;
            if let Err(e) = self.nav.set_goal(goal) {
                warn!("sub-goal refused by the navigator: {e}");
            }
        }
    }

    /// `follow_path` feedback: the distance along the sub-goals to the end, and the speed.
    pub(super) async fn path_feedback(&mut self, node: &RosNode, servers: &mut Servers, goal: &NavGoal) {
        let robot = self.robot_seen(node.now_nanos());
        let (Some(odom), Some(robot), Some(path)) = (self.odom.value(), robot, goal.path.as_ref()) else {
            return;
        };
        let feedback = FollowPathFeedback {
            distance_to_goal: path.remaining(robot.position()) as f32,
            speed: odom.speed as f32,
        };
        if let Err(e) = servers.path.feedback(feedback).await {
            warn_throttled!(self.throttle, "feedback", "{e}");
        }
    }

    /// A cancel request for the active goal of `source`'s server.
    pub(super) fn cancel(
        &mut self,
        node: &RosNode,
        out: &Outputs,
        sink: &mut CmdVel<'_>,
        servers: &mut Servers,
        source: Source,
        id: mobil_ros::action::GoalId,
    ) {
        let active_id = match source {
            Source::Action => servers.nav.active_id(),
            Source::Path => servers.path.active_id(),
            Source::Topic => None,
        };
        let ours = self.session.active().is_some_and(|a| a.source == source);
        if ours && active_id == Some(id) {
            self.end_goal(node, out, sink, servers, EndCause::Canceled);
        }
    }
}
