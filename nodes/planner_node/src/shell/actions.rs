//! The three action servers' goals and cancels: `dock_robot`, `undock_robot`,
//! `follow_waypoints`.

use crate::*;

impl Shell {
    pub(crate) async fn dock_action(&mut self, io: &mut Io<'_, '_>, request: GoalRequest<DockRobotGoal>) {
        let g = request.goal();
        let target = if g.use_dock_id {
            Err(no_dock_database())
        } else {
            goal_pose("dock pose", &g.dock_pose, &self.config.frames.odom_frame)
                .map_err(|e| Action::Dock.invalid_goal(&e))
        };
        if !g.use_dock_id {
            info!(
                "dock_robot: max_staging_time ({}) and navigate_to_staging_pose ({}) ignored: the Lyapunov law \
                 docks from wherever the robot is{}",
                g.max_staging_time,
                g.navigate_to_staging_pose,
                if g.dock_type.is_empty() {
                    String::new()
                } else {
                    format!("; dock_type `{}` ignored", g.dock_type)
                }
            );
        }
        let preempted = nav2_result(&EndCause::Preempted("dock_robot"), Action::Dock.codes());
        let accept = io.servers.dock.accept(request, |_| preempted).await;
        if self.accepted(io, accept, Source::DockAction) {
            self.start_dock(io, target, Source::DockAction);
        }
    }

    /// Whether an action goal from `source` was accepted; if not, a goal of the same server that
    /// was running was ended by the server, and the robot stops with it.
    pub(crate) fn accepted(
        &mut self,
        io: &mut Io<'_, '_>,
        accept: Result<(), mobil_ros::action::ActionError>,
        source: Source,
    ) -> bool {
        let Err(e) = accept else { return true };
        warn_throttled!(self.throttle, "accept", "{} goal not started: {e}", source.name());
        let ours = self.session.active().is_some_and(|a| a.source == source);
        if let Some(ended) = ours
            .then(|| self.session.end(EndCause::Preempted(source.name()), io.sink))
            .flatten()
        {
            self.report(io, ended, false);
        }
        false
    }

    pub(crate) async fn undock_action(&mut self, io: &mut Io<'_, '_>, request: GoalRequest<UndockRobotGoal>) {
        let limit = request.goal().max_undocking_time;
        let limit_s = if limit.is_finite() && limit > 0.0 {
            f64::from(limit)
        } else {
            warn!("undock_robot: max_undocking_time {limit} is not a positive time: 30 s (its default) taken");
            30.0
        };
        let preempted = nav2_result(&EndCause::Preempted("undock_robot"), Action::Undock.codes());
        let accept = io.servers.undock.accept(request, |_| preempted).await;
        if !self.accepted(io, accept, Source::UndockAction) {
            return;
        }
        let (distance, speed) = (self.config.staging_distance, self.config.undock_speed);
        info!("goal (undock_robot): back out {distance:.3} m along the heading, within {limit_s:.1} s");
        let task = Task::Undock(UndockGoal::new(distance, speed, limit_s));
        self.begin(io, task, None, Source::UndockAction);
        self.drawing = Drawing::default();
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
    }

    pub(crate) async fn follow_action(
        &mut self,
        io: &mut Io<'_, '_>,
        jobs: &mut Jobs,
        request: GoalRequest<FollowWaypointsGoal>,
    ) {
        let start = self.fresh_odom();
        let g = request.goal();
        let frame = &self.config.frames.odom_frame;
        let (round, at) = ((g.goal_index, g.number_of_loops), start.map(|p| p.position()));
        let route = route_from_poses(&g.poses, frame, frame, round, at, ROUTE_LIMITS);
        // A follow_waypoints goal pre-empted by this one lists what it had missed.
        let by = EndCause::Preempted("follow_waypoints");
        let preempted = match self.session.active() {
            Some(a) if a.source == Source::FollowAction => follow_answer(&a.goal, &by),
            _ => follow_result(&by, &[], &[]),
        };
        let accept = io.servers.follow.accept(request, |_| preempted).await;
        if self.accepted(io, accept, Source::FollowAction) {
            self.start_route(io, jobs, route, start, Source::FollowAction);
        }
    }

    /// A cancel of goal `id` of action `source`: the active goal ends CANCELED if it is that one.
    pub(crate) fn cancel(&mut self, io: &mut Io<'_, '_>, source: Source, id: mobil_ros::action::GoalId) {
        let active_id = match source {
            Source::DockAction => io.servers.dock.active_id(),
            Source::UndockAction => io.servers.undock.active_id(),
            Source::FollowAction => io.servers.follow.active_id(),
            Source::DockPose | Source::Waypoints => None,
        };
        if active_id == Some(id) && self.session.active().is_some_and(|a| a.source == source) {
            self.end_goal(io, EndCause::Canceled);
        }
    }
}

/// FollowWaypoints' result for a goal ending with `cause`: the waypoints missed so far (the
/// pre-check's problems for a route it refused; a VFO route: those not reached), the request's
/// poses.
fn follow_answer(goal: &Goal, cause: &EndCause) -> FollowWaypointsResult {
    let Some(route) = &goal.route else {
        return follow_result(cause, &[], &[]);
    };
    match &goal.task {
        Task::Follow(g) => follow_result(cause, &route.poses, g.missed()),
        Task::Vfo(v) => vfo_follow_result(cause, &route.poses, &route.unreached_from(v.view().index)),
        Task::PreCheck(p) => follow_result(cause, &route.poses, &p.problems),
        Task::Dock(_) | Task::Undock(_) => follow_result(cause, &[], &[]),
    }
}

impl Servers {
    /// Ends the goal of action `source` (nothing for a topic) with `cause`: its status and
    /// result; `goal`, the goal that ended (none: refused before it started), lists the
    /// waypoints a route missed.
    pub(crate) fn finish(&mut self, source: Source, cause: &EndCause, goal: Option<&Goal>) {
        let end = goal_end(cause);
        match source {
            Source::DockAction => {
                self.dock.finish(end, nav2_result(cause, Action::Dock.codes()));
            }
            Source::UndockAction => {
                self.undock.finish(end, nav2_result(cause, Action::Undock.codes()));
            }
            Source::FollowAction => {
                let result = goal.map_or_else(|| follow_result(cause, &[], &[]), |g| follow_answer(g, cause));
                self.follow.finish(end, result);
            }
            Source::DockPose | Source::Waypoints => {}
        }
    }
}
