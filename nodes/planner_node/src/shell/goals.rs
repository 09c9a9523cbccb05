//! The goal lifecycle of the planner's shell: parameters, status and markers, a goal's
//! start, end and report, each odometry step through the motion session, the watchdog tick
//! and the action feedback.

use crate::*;
use mobil_geom::downsample;
use mobil_geom::path::headed;
use mobil_motion::Outcome;
use mobil_ros::plan::MAX_PATH_POSES;

impl Shell {
    pub(crate) fn reconfigure(&mut self, c: PlannerConfig) {
        let chassis = match c.chassis_params() {
            Ok(chassis) => chassis,
            Err(e) => return warn!("parameters not applied: {e}"),
        };
        let running = self.session.active().is_some();
        // A goal keeps the map its parameters built (its obstacles and σ stay valid).
        match self.map.reconfigure(c.vfo.scan_config(c.robot_radius), running) {
            Err(e) => return warn!("parameters not applied: {e}"),
            Ok(change) => mobil_ros::tell!(self.throttle, change.notice()),
        }
        self.chassis = chassis;
        self.tf.set_tolerance(c.controller.transform_tolerance());
        self.check.update(|inputs| inputs.configure(&c, chassis));
        self.config = c;
        if running {
            info!("parameters changed: they apply from the next goal");
        }
    }

    pub(crate) fn fresh_odom(&self) -> Option<Pose2> {
        self.odom
            .get(self.config.timeouts.odom_timeout())
            .filter(|_| !self.odom_refused)
            .copied()
    }

    /// Whether a goal in `frame` for `action` can be followed now: where it is placed, or the
    /// refusal (TF_ERROR with the action's code) when the frame does not reach odometry
    /// through a fresh transform.
    pub(crate) fn goal_frame(&mut self, node: &RosNode, frame: &str, action: Action) -> Result<Placed, Outcome> {
        match self.tf.accept(frame, || node.now_nanos()) {
            Ok(odom_in) => Ok(Placed {
                frame: frame.to_owned(),
                odom_in,
            }),
            Err(why) => Err(action.tf_error(why)),
        }
    }

    /// Where odometry goals are (undocking, a goal with no frame of its own).
    pub(crate) fn in_odom(&self) -> Placed {
        Placed {
            frame: self.config.frames.odom_frame.clone(),
            odom_in: Pose2::identity(),
        }
    }

    /// The latest odometry pose seen from the latest goal's frame at ROS time `now` (ns),
    /// through the transforms taken so far; `None` without odometry or transform.
    pub(crate) fn robot_seen(&self, now: i64) -> Option<Pose2> {
        let odom = self.odom.value()?;
        Some(self.tf.odom_in(&self.frame, now).ok()?.compose(odom))
    }

    pub(crate) fn send_status(&mut self, node: &RosNode, out: &Outputs, view: &NavStatusView) {
        out.send_status(view, node.stamp(), &self.frame, &mut self.throttle);
        self.status_gate.sent(Instant::now());
    }

    pub(crate) fn send_idle_status(&mut self, node: &RosNode, out: &Outputs) {
        let view = self.status_view(None, NavStatus::IDLE, String::new(), node.now_nanos());
        self.send_status(node, out, &view);
    }

    /// The status of `goal` (none: idle, or a refusal) in `state` with `reason` at ROS time
    /// `now` (ns).
    pub(crate) fn status_view(&self, goal: Option<&Goal>, state: u8, reason: String, now: i64) -> NavStatusView {
        status_view(goal.map(|g| &g.task), self.robot_seen(now).as_ref(), state, reason)
    }

    /// The active goal's status in `state` with `reason` (none given: the stopped clock's, if the
    /// robot is held for it).
    pub(crate) fn publish_status(&mut self, node: &RosNode, out: &Outputs, state: u8, reason: String) {
        let reason = match reason.is_empty() {
            true => self.session.clock_hold_reason().unwrap_or_default(),
            false => reason,
        };
        let view = self.status_view(self.session.active().map(|a| &a.goal), state, reason, node.now_nanos());
        self.send_status(node, out, &view);
    }

    /// The markers, and while a goal runs the plans as paths (when they changed): `plan` the
    /// pre-check's predicted path, else the route headed along its legs (not for `follow_path`,
    /// whose plan is Nav2's planner's), `local_plan` VFO's chosen path; with no goal, empty ones.
    pub(crate) fn publish_markers(&mut self, node: &RosNode, out: &Outputs) {
        let view = self
            .drawing
            .view(self.robot_seen(node.now_nanos()).map(|p| p.position()));
        let (stamp, frame) = (node.stamp(), &self.frame);
        out.send_markers(markers(&view, stamp.clone(), frame), &mut self.throttle);
        self.markers_gate.sent(Instant::now());
        let Some(active) = self.session.active() else {
            return self.plans.clear(frame, stamp, &mut self.throttle);
        };
        // A follow_path goal's plan is Nav2's planner's: an empty one (sent only if this node
        // had latched one of its own) leaves it alone.
        let plan = match (active.source, self.drawing.predicted.is_empty()) {
            (Source::PathAction, _) => Vec::new(),
            (_, true) => headed(&downsample(&self.drawing.route, MAX_PATH_POSES)),
            (_, false) => self.drawing.predicted.clone(),
        };
        self.plans.send_plan(&plan, frame, stamp.clone(), &mut self.throttle);
        let chosen = self.drawing.vfo.as_ref().map_or(&[][..], |v| &v.chosen[..]);
        self.plans.send_local(&headed(chosen), frame, stamp, &mut self.throttle);
    }

    /// Ends the active goal with `outcome` (the session sends its zero command, if one is due)
    /// and reports it.
    pub(crate) fn end_goal(&mut self, io: &mut Io<'_, '_>, cause: EndCause) {
        if let Some(ended) = self.session.end(cause, io.sink) {
            self.report(io, ended);
        }
    }

    /// Tells an ended goal's end: the action's result (unless its server ended it:
    /// [`Ended::server_ended`]), the log, the status with the goal's last figures, the markers;
    /// a VFO optimisation under way stops.
    pub(crate) fn report(&mut self, io: &mut Io<'_, '_>, ended: PlannerEnded) {
        let Ended {
            goal,
            source,
            cause,
            server_ended,
            ..
        } = ended;
        goal.stop.cancel();
        if !server_ended {
            io.servers.finish(source, &cause, Some(&goal));
        }
        mobil_ros::tell!(self.throttle, [cause.notice(source.name())]);
        let view = self.status_view(Some(&goal), end_state(&cause), cause.reason(), io.node.now_nanos());
        self.send_status(io.node, io.out, &view);
        if self.session.active().is_none() && self.map.goal_ended() {
            info!("the obstacle map starts afresh with the new extraction parameters");
        }
        self.publish_markers(io.node, io.out);
    }

    /// Makes `task` (of `route`, if one) from `source` the active goal: the goal it replaces ends PREEMPTED
    /// (reported; an action goal on the same server was ended by the server's accept).
    pub(crate) fn begin(
        &mut self,
        io: &mut Io<'_, '_>,
        (task, placed): (Task, Placed),
        route: Option<Route>,
        source: Source,
    ) -> GoalId {
        let goal = Goal {
            task,
            route,
            chassis: self.chassis,
            config: self.config.clone(),
            stop: CancelToken::new(),
            frame: placed.frame.clone(),
            map_seen_from: placed.odom_in,
        };
        let (id, old) = self.session.start(goal, source, Instant::now());
        if let Some(old) = old {
            self.report(io, old);
        }
        self.frame = placed.frame;
        id
    }

    /// A goal from `source` refused before it started: the goal it was to replace ends
    /// PREEMPTED (the robot stops with it); an action goal (accepted already) gets its result;
    /// the status is FAILED with the reason.
    pub(crate) fn refuse(&mut self, io: &mut Io<'_, '_>, source: Source, refusal: mobil_motion::Outcome) {
        if let Some(old) = self.session.preempt(source, io.sink) {
            self.report(io, old);
        }
        let cause = EndCause::Outcome(refusal);
        warn!("goal ({}) refused: {}", source.name(), cause.reason());
        io.servers.finish(source, &cause, None);
        let view = self.status_view(None, NavStatus::FAILED, cause.reason(), io.node.now_nanos());
        self.send_status(io.node, io.out, &view);
    }

    /// Starts a docking onto `target`, placed in its frame (or refuses it).
    pub(crate) fn start_dock(&mut self, io: &mut Io<'_, '_>, target: Result<(Pose2, Placed), Outcome>, source: Source) {
        let action = source.action();
        let built = target.and_then(|(dock, placed)| {
            let gains = self.config.gains().map_err(|e| action.refused_goal(e))?;
            let law = DockGoal::onto(dock, gains, self.config.docking, &self.chassis);
            Ok((law.map_err(|e| action.refused_goal(e))?, placed))
        });
        let (dock, placed) = match built {
            Ok(dock) => dock,
            Err(refusal) => return self.refuse(io, source, refusal),
        };
        let goal = dock.target();
        info!(
            "goal ({}): dock at ({:.3}, {:.3}, {:.3} rad) in {}",
            source.name(),
            goal.x,
            goal.y,
            goal.yaw,
            placed.frame
        );
        if dock.controller().finish() == Finish::ReportResidual {
            info!(
                "a steered chassis cannot turn in place: the law steers its kinematic origin ({:.2} m behind), \
                 and the heading left at the dock is reported as RESIDUAL",
                dock.offset()
            );
        }
        self.drawing = Drawing {
            dock: Some(goal),
            ..Drawing::default()
        };
        self.begin(io, (Task::Dock(dock), placed), None, source);
        self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
        self.publish_markers(io.node, io.out);
    }

    pub(crate) fn odom_in(&mut self, io: &mut Io<'_, '_>, jobs: &mut Jobs, m: &Odometry) {
        match odom_pose(m, &self.config.frames.odom_frame, &self.config.frames.base_frame) {
            Ok(pose) => {
                self.odom_refused = false;
                let v = &m.twist.twist.linear;
                self.odom_speed = if v.x.is_finite() && v.y.is_finite() {
                    v.x.hypot(v.y)
                } else {
                    0.0
                };
                self.odom_stamp = secs_from_stamp(&m.header.stamp).unwrap_or(f64::NAN);
                if self.odom_stamp.is_finite() {
                    self.odom_history.push(self.odom_stamp, pose);
                }
                self.odom_period.arrived(Instant::now());
                self.odom.set(pose, m.header.stamp.clone());
                self.check.update(|inputs| inputs.odom = Some(self.odom.clone()));
                if self.session.active().is_some() {
                    self.step(io, jobs, pose);
                }
            }
            Err(e) => {
                warn_throttled!(self.throttle, "odom-bad", "odom sample dropped: {e}; robot stopped");
                self.odom_refused = true;
                self.check.update(|inputs| inputs.odom = None);
                self.odom_speed = 0.0;
                self.odom_history.clear();
                self.session.hold(io.sink);
            }
        }
    }

    /// One control step at `pose`: the active goal's law, its command out through the session.
    pub(crate) fn step(&mut self, io: &mut Io<'_, '_>, jobs: &mut Jobs, pose: Pose2) {
        let dt = match self.session.advance(io.node.now_nanos()) {
            Some(Ok(dt)) => dt,
            None | Some(Err(DtError::Zero)) => return,
            Some(Err(DtError::Backwards { by_nanos })) if io.node.uses_sim_time() => {
                return self.end_goal(io, EndCause::ClockBack(by_nanos as f64 * 1e-9));
            }
            Some(Err(e)) => {
                return warn_throttled!(
                    self.throttle,
                    "time-back",
                    "{e}; the step is skipped, the goal's time carries on"
                );
            }
        };
        // The robot seen from the goal's frame: a localiser's correction moves it relative to
        // the goal; a transform lost ends the goal.
        let Some(frame) = self.session.active().map(|a| a.goal.frame.clone()) else {
            return;
        };
        let odom_in = match self.tf.is_odom(&frame) {
            true => Pose2::identity(),
            false => match self.tf.accept(&frame, || io.node.now_nanos()) {
                Ok(t) => t,
                Err(why) => return self.end_goal(io, EndCause::Tf(why)),
            },
        };
        let pose = odom_in.compose(&pose);
        let Some(active) = self.session.active_mut() else {
            return;
        };
        let input = StepInput::new(active.t(), dt, pose);
        let chassis = active.goal.chassis;
        let now = io.node.now_nanos() as f64 * 1e-9;
        match active.goal.task.step(&input, now) {
            Stepped::Waiting => {}
            Stepped::OffLoop => self.vfo_step(io, jobs, input, odom_in),
            Stepped::Law(step) => {
                if let Step::Command { feedback, .. } = &step {
                    mobil_ros::tell!(self.throttle, feedback.events.iter().map(RouteEvent::notice));
                }
                self.apply(io, step, &chassis, |f| f.changed);
            }
        }
    }

    /// What comes of a law's step: its command held to the chassis limits, a refusal (the robot
    /// stops; the goal ends after the session's count of them in a row) or the goal's end. The
    /// status goes out when `changed` says the feedback changed it.
    pub(crate) fn apply<F, R>(
        &mut self,
        io: &mut Io<'_, '_>,
        step: Step<F, R>,
        chassis: &ChassisParams,
        changed: impl FnOnce(&F) -> bool,
    ) {
        if let Step::Refused(why) = &step {
            warn_throttled!(
                self.throttle,
                "step",
                "the planner refused its input: {why}; robot stopped"
            );
        }
        match self.session.apply(step, limited(chassis), io.sink) {
            Applied::Commanded(f) => {
                if changed(&f) {
                    self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
                }
            }
            Applied::Refused(Some(ended)) | Applied::Ended(ended, _) => self.report(io, ended),
            Applied::Refused(None) | Applied::Idle => {}
        }
    }

    pub(crate) async fn tick(&mut self, io: &mut Io<'_, '_>) {
        let now = Instant::now();
        let stamped = self.config.cmd_vel.enable_stamped_cmd_vel;
        if let Some(line) = self.types.check(io.node, stamped, "cmd_vel", now) {
            warn_throttled!(self.throttle, "cmd-type", "{line}");
        }
        if io.node.uses_sim_time() {
            let timeout = self.session.active().map_or(self.config.timeouts.clock_timeout(), |a| {
                a.goal.config.timeouts.clock_timeout()
            });
            let clock = self.session.watch_clock(io.node.now_nanos(), now, timeout, io.sink);
            mobil_ros::tell!(self.throttle, clock.notice());
            match clock {
                ClockCheck::Back(ended) => return self.report(io, ended),
                ClockCheck::Held { newly: true, .. } | ClockCheck::Resumed => {
                    self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new())
                }
                ClockCheck::Held { .. } | ClockCheck::Running => {}
            }
        }
        // /diagnostics: odometry always, the scan for VFO (the method's, or the running goal's).
        let active = self.session.active();
        let config = active.map_or(&self.config, |a| &a.goal.config);
        let mut inputs = vec![Watched {
            name: "odom",
            age: self.odom.age_at(now),
            timeout: config.timeouts.odom_timeout(),
        }];
        let vfo = active.map_or(config.waypoint_method == WaypointMethod::Vfo, |a| a.goal.task.is_vfo());
        if vfo {
            inputs.push(Watched {
                name: "scan",
                age: self.scan_seen.age_at(now),
                timeout: config.vfo.scan_timeout(),
            });
        }
        let mode = active.map_or(mobil_planner::task::Mode::Idle, |a| a.goal.task.mode());
        let goal = || active.map(|a| format!("{} in {}", a.source.name(), a.goal.frame));
        self.diagnostics.tick(
            &self.session,
            now,
            &inputs,
            goal,
            mode.as_str(),
            io.node.stamp(),
            &mut self.throttle,
        );
        if self.session.active().is_none() {
            return;
        }
        if let Some(stale) = self.session.stale(now, &inputs) {
            return self.end_goal(io, EndCause::Stale(stale));
        }
        if self.status_gate.due(now, self.config.status_rate_hz) {
            self.publish_status(io.node, io.out, NavStatus::ACTIVE, String::new());
        }
        if self.markers_gate.due(now, self.config.markers_rate_hz) {
            self.publish_markers(io.node, io.out);
        }
        self.feedback(io.servers, io.node.now_nanos()).await;
    }

    /// Action feedback, on every watchdog tick (20 Hz) while an action goal is active (an
    /// action's goal is always its own kind of task).
    pub(crate) async fn feedback(&mut self, servers: &Servers, now: i64) {
        let Some(active) = self.session.active() else { return };
        let sent = match active.source {
            // The goal's own time: its steps' dt summed, never running backwards (a clock that
            // goes back ends the goal, or on the system clock skips the step), so docking_time
            // never falls.
            Source::DockAction => {
                let (state, docking_time) = (DockRobotFeedback::CONTROLLING, duration_msg(active.t()));
                let feedback = DockRobotFeedback {
                    state,
                    docking_time,
                    num_retries: 0,
                };
                servers.dock.feedback(feedback).await
            }
            Source::FollowAction => {
                let index = active.goal.task.waypoint().unwrap_or(0);
                let current_waypoint = u32::try_from(index).unwrap_or(u32::MAX);
                servers
                    .follow
                    .feedback(FollowWaypointsFeedback { current_waypoint })
                    .await
            }
            Source::UndockAction => servers.undock.feedback(UndockRobotFeedback::default()).await,
            Source::PathAction => match self.path_feedback(&active.goal, now) {
                Some(feedback) => servers.path.feedback(feedback).await,
                None => Ok(()),
            },
            Source::DockPose | Source::Waypoints => Ok(()),
        };
        if let Err(e) = sent {
            warn_throttled!(self.throttle, "feedback", "{e}");
        }
    }
}

/// Holds a law's body twist to the chassis limits, as a `cmd_vel`.
pub(crate) fn limited(chassis: &ChassisParams) -> impl Fn(BodyTwist) -> Twist + '_ {
    move |b| twist_msg(clamp_at_reference(chassis, b))
}
