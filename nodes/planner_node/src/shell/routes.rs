//! Routes: a route's pre-check off the event loop and its turn into a goal approach, VFO
//! routes with their steps off the event loop, and the scans that feed VFO's obstacle map.

use crate::*;
use mobil_planner::vfo::ObstacleMap;
use std::borrow::Cow;

impl Shell {
    /// Validates a route and starts its pre-check off the event loop (or refuses it).
    pub(crate) fn start_route(
        &mut self,
        io: &mut Io<'_, '_>,
        jobs: &mut Jobs,
        route: Result<Route, GoalError>,
        (start, placed): (Option<Pose2>, Placed),
        source: Source,
    ) {
        let route = match route {
            Ok(r) => r,
            Err(e) => return self.refuse(io, source, source.action().invalid_goal(&e)),
        };
        if self.config.waypoint_method == WaypointMethod::Vfo {
            return self.start_vfo(io, route, (start, placed), source);
        }
        if let Some(i) = route.first_oriented() {
            info!(
                "goal ({}): waypoint {i} (and any other) carries an orientation: ignored, the goal approach \
                 reaches each waypoint's position only",
                source.name()
            );
        }
        let Some(start) = start else {
            return self.refuse(io, source, source.action().stale_at_start("odom"));
        };
        let (points, world, chassis, config) = (
            route.points.clone(),
            self.world_in(&placed),
            self.chassis,
            self.config.route_check(),
        );
        info!(
            "goal ({}): pre-check of {} waypoints (the virtual robot drives them first)",
            source.name(),
            route.points.len()
        );
        let task = Task::PreCheck(PreCheck::new(start, points.clone(), route.request_index.clone()));
        // The route until its check draws the prediction: the goal's start publishes it.
        self.drawing = Drawing {
            route: points.clone(),
            ..Drawing::default()
        };
        let id = self.begin(io, (task, placed), Some(route), source);
        // The robot waits for the pre-check.
        self.session.hold(io.sink);
        jobs.goal.start(move |cancel| PreCheckDone {
            id,
            report: check_route_until(&start, &points, &chassis, &world, &config, || cancel.is_cancelled())
                .map_err(|e| e.to_string()),
        });
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
    }

    /// A pre-check is done: the route it was for (if still the active goal) starts or is
    /// refused.
    pub(crate) fn pre_checked(&mut self, io: &mut Io<'_, '_>, done: PreCheckDone) {
        let Some(active) = self.session.active_mut().filter(|a| a.id() == done.id) else {
            return;
        };
        let source = active.source;
        let goal = &mut active.goal;
        let (follow, execute) = (goal.config.follow, goal.config.execute_infeasible_routes);
        let report = match done.report {
            Ok(r) => r,
            Err(e) => return self.end_goal(io, Action::Follow.refused_goal(e).into()),
        };
        let Some(turn) = goal.task.turn_after_check(&report, (follow, &goal.chassis), execute) else {
            return;
        };
        self.drawing = turn.drawing;
        if let Err(outcome) = turn.outcome {
            return self.end_goal(io, outcome.into());
        }
        if let Some(w) = &turn.driven_through {
            warn!("goal ({}): {w}", source.name());
        }
        info!("goal ({}): {}", source.name(), turn.summary);
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
        self.publish_markers(io.node, io.out);
    }

    /// The pre-check's world (given in the odometry frame) seen from a goal's frame.
    pub(crate) fn world_in(&self, placed: &Placed) -> Arc<World> {
        super::check::world_seen(Arc::clone(&self.world), self.tf.is_odom(&placed.frame), &placed.odom_in)
    }

    /// VFO's obstacle map (kept in the odometry frame) seen from a goal's frame, through the
    /// odometry frame's pose in it.
    pub(crate) fn map_in(&self, frame: &str, odom_in: &Pose2) -> Cow<'_, ObstacleMap> {
        map_seen(&self.map, self.tf.is_odom(frame), odom_in, true)
    }

    /// Starts VFO waypoint following of `route` from `start` (or refuses it).
    pub(crate) fn start_vfo(
        &mut self,
        io: &mut Io<'_, '_>,
        route: Route,
        (start, placed): (Option<Pose2>, Placed),
        source: Source,
    ) {
        let scan_fresh = self.scan_seen.get(self.config.vfo.scan_timeout()).is_some();
        let of_route = (&route.points[..], &route.headings()[..], &route.request_index[..]);
        let map = self.map_in(&placed.frame, &placed.odom_in);
        let rules = (&self.config.vfo, &self.chassis, map.as_ref());
        let started = match VfoRun::start(of_route, start, scan_fresh, rules, self.odom_period.period()) {
            Ok(started) => started,
            Err(refusal) => return self.refuse(io, source, refusal),
        };
        info!("goal ({}): {}", source.name(), started.summary);
        if let Some(w) = &started.chassis_warning {
            warn!("goal ({}): {w}", source.name());
        }
        self.drawing = Drawing {
            route: route.points.clone(),
            ..Drawing::default()
        };
        self.begin(io, (Task::Vfo(started.run), placed), Some(route), source);
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
        self.publish_markers(io.node, io.out);
    }

    /// A VFO step: the law goes to the blocking pool with the map's latest obstacles, or,
    /// while it is still out (optimising), the robot stops.
    pub(crate) fn vfo_step(&mut self, io: &mut Io<'_, '_>, jobs: &mut Jobs, input: StepInput, odom_in: Pose2) {
        // A path whose new sub-goals wait for the law: it is built now, while the law is home.
        self.rebuild_path_vfo(io, odom_in);
        let Some(active) = self.session.active_mut() else {
            return;
        };
        let id = active.id();
        let budget = active.goal.config.vfo.optimise_budget();
        let stop = active.goal.stop.clone();
        let (seen_from, frame) = (active.goal.map_seen_from, &active.goal.frame);
        let Some(v) = active.goal.task.vfo_mut() else { return };
        // The map seen from the goal's frame; a correction of the frame's transform since the
        // law last took it moves the obstacles for the law (no new obstacles: no re-optimising).
        if mobil_planner::vfo::frame_moved(&seen_from, &odom_in) {
            v.map_updated(false);
        }
        let taking = v.map_pending().is_some();
        let map = map_seen(&self.map, self.tf.is_odom(frame), &odom_in, taking);
        let Some(mut law) = v.lend(Instant::now(), &map) else {
            return self.session.hold(io.sink);
        };
        if taking {
            active.goal.map_seen_from = odom_in;
        }
        let stamp = self.odom_stamp;
        jobs.vfo.start(move |cancel| {
            let (cancel, started) = (cancel.clone(), Instant::now());
            let interrupt = move || {
                if cancel.is_cancelled() || stop.is_cancelled() {
                    Some(Interrupt::Cancel)
                } else if started.elapsed() > budget {
                    Some(Interrupt::Budget)
                } else {
                    None
                }
            };
            let tick = VfoTick {
                stamp,
                interrupt: Box::new(interrupt),
            };
            let step = law.step(&input, &tick);
            VfoTickDone { id, law, step }
        });
    }

    /// A VFO step came back: its events are logged, its command goes out (zero when it came
    /// back late), or the route ends.
    pub(crate) fn vfo_ticked(&mut self, io: &mut Io<'_, '_>, done: VfoTickDone) {
        if !self.session.is_current(done.id) {
            return;
        }
        let Some(active) = self.session.active_mut() else {
            return;
        };
        let chassis = active.goal.chassis;
        let Some(v) = active.goal.task.vfo_mut() else { return };
        let (mut step, handback) = v.give_back(done.law, done.step, Instant::now());
        mobil_ros::tell!(self.throttle, v.notices(&step, handback));
        // A path: the sub-goal pursued follows the law's waypoint, its ends take FollowPath's
        // codes, and an end made on a path a newer one replaces is dropped (the robot held until
        // the law is built on the new one, at the next step).
        if let Task::Path(path) = &mut active.goal.task {
            match path.vfo_returned(step) {
                Some(s) => step = s,
                None => return self.session.hold(io.sink),
            }
        }
        if let Step::Command { feedback, .. } = &mut step
            && let Some(drawing) = feedback.drawing.take()
        {
            self.drawing.vfo = Some(drawing);
        }
        self.apply(io, step, &chassis, |f| !f.events.is_empty());
    }

    /// A scan: its obstacles go into the map (in odom, with the odometry pose at the scan's
    /// stamp); a VFO route's follower gets them at its next tick. A goal's scans are read with
    /// the parameters it began with. The map is kept whatever `waypoint_method` is: a
    /// `follow_path` goal may name VFO.
    pub(crate) fn scan_in(&mut self, m: &LaserScan) {
        let config = match self.session.active() {
            Some(a) if a.goal.task.is_vfo() => &a.goal.config,
            _ => &self.config,
        };
        let (max_gap, scan_range) = (config.vfo.scan_odom_max_gap_s, config.vfo.scan_range);
        let mount = LaserMount {
            base_frame: &config.frames.base_frame,
            laser_frame: &config.vfo.laser_frame,
            parameter: config.vfo.laser_pose(),
        };
        let scan = match checked_scan(&self.laser, &mount, m, Some(scan_range)) {
            Ok(c) => c.scan,
            Err(e) => return warn_throttled!(self.throttle, "scan-bad", "{e}; scan ignored"),
        };
        let Some(stamp) = secs_from_stamp(&m.header.stamp) else {
            return warn_throttled!(
                self.throttle,
                "scan-bad",
                "scan stamp invalid (nanosec ≥ 1e9); scan ignored"
            );
        };
        let history = self.fresh_odom().map(|_| &self.odom_history);
        let update = match self.map.map_mut().add_scan(&scan, stamp, history, max_gap) {
            Ok(u) => u,
            Err(e @ ScanSkipped::NoPose { .. }) => return warn_throttled!(self.throttle, "scan-odom", "{e}"),
            Err(e) => return warn_throttled!(self.throttle, "scan-bad", "{e}; scan ignored"),
        };
        for (key, w) in update.warnings(stamp, self.map.map().config().max_obstacles) {
            warn_throttled!(self.throttle, key, "{w}");
        }
        if self.scan_seen.value().is_none() {
            info!(
                "first scan: {} beams, {} obstacles in the map (odom)",
                scan.len(),
                self.map.map().len()
            );
        }
        self.scan_seen.set((), m.header.stamp.clone());
        if let Some(v) = self.session.active_mut().and_then(|a| a.goal.task.vfo_mut()) {
            v.map_updated(!update.new.is_empty());
        }
    }
}

/// `map`'s obstacles (in the odometry frame) seen from a goal's frame through `odom_in` (the
/// odometry frame's pose in it), when the law is to take them (`needed`); the map as it is for
/// a goal in odometry, or when the law takes nothing (no copy).
pub(crate) fn map_seen<'a>(map: &'a KeptMap, in_odom: bool, odom_in: &Pose2, needed: bool) -> Cow<'a, ObstacleMap> {
    match in_odom || !needed {
        true => Cow::Borrowed(map.map()),
        false => Cow::Owned(map.map().moved(odom_in)),
    }
}
