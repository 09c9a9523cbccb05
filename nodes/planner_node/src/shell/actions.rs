//! The action servers' goals and cancels: `dock_robot`, `undock_robot`, `follow_waypoints`
//! (`follow_path`'s are in `path.rs`).

use crate::*;

impl Shell {
    pub(crate) async fn dock_action(&mut self, io: &mut Io<'_, '_>, request: GoalRequest<DockRobotGoal>) {
        let g = request.goal();
        // The dock's pose in its frame (the database's, or the request's), placed through tf.
        let target = if g.use_dock_id {
            self.docks.get(&g.dock_id).map(|d| (d.pose, self.tf.frame_of(&d.frame)))
        } else {
            let frame = self.tf.frame_of(&g.dock_pose.header.frame_id);
            goal_pose("dock pose", &g.dock_pose, &frame)
                .map(|p| (p, frame))
                .map_err(|e| Action::Dock.invalid_goal(&e))
        };
        let target = target.and_then(|(p, frame)| Ok((p, self.goal_frame(io.node, &frame, Action::Dock)?)));
        if !g.use_dock_id {
            let notice = dock_request_notice(g.max_staging_time, g.navigate_to_staging_pose, &g.dock_type);
            mobil_ros::tell!(self.throttle, [notice]);
        }
        let preempted = nav2_result(&EndCause::Preempted("dock_robot"), Action::Dock.codes());
        let accept = io
            .servers
            .dock
            .accept(request, |_| preempted, io.node.now_nanos())
            .await;
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
        if e.ended_active()
            && self.session.active().is_some_and(|a| a.source == source)
            && let Some(ended) = self.session.preempt(source, io.sink)
        {
            self.report(io, ended);
        }
        false
    }

    pub(crate) async fn undock_action(&mut self, io: &mut Io<'_, '_>, request: GoalRequest<UndockRobotGoal>) {
        let limit = request.goal().max_undocking_time;
        let preempted = nav2_result(&EndCause::Preempted("undock_robot"), Action::Undock.codes());
        let accept = io
            .servers
            .undock
            .accept(request, |_| preempted, io.node.now_nanos())
            .await;
        if !self.accepted(io, accept, Source::UndockAction) {
            return;
        }
        let (undock, notices) = UndockGoal::for_request(self.config.staging_distance, self.config.undock_speed, limit);
        mobil_ros::tell!(self.throttle, notices);
        let task = Task::Undock(undock);
        // The drawing first: the goal's start publishes the plans of the new goal, not the old.
        self.drawing = Drawing::default();
        let placed = self.in_odom();
        self.begin(io, (task, placed), None, Source::UndockAction);
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
    }

    pub(crate) async fn follow_action(
        &mut self,
        io: &mut Io<'_, '_>,
        jobs: &mut Jobs,
        request: GoalRequest<FollowWaypointsGoal>,
    ) {
        let g = request.goal();
        // The route's frame is its first pose's (every pose must be in it, or name none); the
        // route is placed through tf and starts from the robot seen from there.
        let frame = self
            .tf
            .frame_of(g.poses.first().map_or("", |p| p.header.frame_id.as_str()));
        let placed = self.goal_frame(io.node, &frame, Action::Follow);
        let start = match &placed {
            Ok(p) => self.fresh_odom().map(|o| p.odom_in.compose(&o)),
            Err(_) => None,
        };
        let round = (g.goal_index, g.number_of_loops);
        let route = route_from_poses(
            &g.poses,
            &frame,
            &frame,
            round,
            start.map(|p| p.position()),
            ROUTE_LIMITS,
        );
        // A follow_waypoints goal pre-empted by this one lists what it had missed.
        let by = EndCause::Preempted("follow_waypoints");
        let running = self.session.active().filter(|a| a.source == Source::FollowAction);
        let preempted = follow_answer(running.map(|a| &a.goal), &by);
        let accept = io
            .servers
            .follow
            .accept(request, |_| preempted, io.node.now_nanos())
            .await;
        if self.accepted(io, accept, Source::FollowAction) {
            match placed {
                Ok(placed) => self.start_route(io, jobs, route, (start, placed), Source::FollowAction),
                Err(refusal) => self.refuse(io, Source::FollowAction, refusal),
            }
        }
    }

    /// A cancel of goal `id` of action `source`: the active goal ends CANCELED if it is that one.
    pub(crate) fn cancel(&mut self, io: &mut Io<'_, '_>, source: Source, id: mobil_ros::action::GoalId) {
        let active_id = match source {
            Source::DockAction => io.servers.dock.active_id(),
            Source::UndockAction => io.servers.undock.active_id(),
            Source::FollowAction => io.servers.follow.active_id(),
            Source::PathAction => io.servers.path.active_id(),
            Source::DockPose | Source::Waypoints => None,
        };
        if active_id == Some(id) && self.session.active().is_some_and(|a| a.source == source) {
            self.end_goal(io, EndCause::Canceled);
        }
    }
}

/// FollowWaypoints' result for `goal` (none: refused before it started) ending with `cause`.
fn follow_answer(goal: Option<&Goal>, cause: &EndCause) -> FollowWaypointsResult {
    let succeeded = cause.kind() == EndKind::Succeeded;
    match goal.and_then(|g| Some((g.route.as_ref()?, g.task.result_missed(succeeded)))) {
        Some((route, missed)) => follow_result(cause, &route.poses, &missed),
        None => follow_result(cause, &[], &[]),
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
                self.follow.finish(end, follow_answer(goal, cause));
            }
            Source::PathAction => {
                self.path.finish(end, nav2_result(cause, Action::Path.codes()));
            }
            Source::DockPose | Source::Waypoints => {}
        }
    }
}
