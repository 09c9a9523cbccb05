//! `planner/check_route`: a route's pre-check as a service, computed and answered on the
//! blocking pool.

use crate::*;

impl Shell {
    /// A `planner/check_route` request: refused at once, answered BUSY when too many are being
    /// computed, or checked on the blocking pool and answered from there: the reply leaves from
    /// the thread that computed it, without a hand-off back to the event loop.
    pub(crate) fn check_in(
        &mut self,
        node: &RosNode,
        jobs: &mut Jobs,
        check: &Arc<Server<CheckRouteRequest, CheckRouteResponse>>,
        id: RmwRequestId,
        req: &CheckRouteRequest,
    ) {
        let (start, route, placed) = match self.check_request(node, req) {
            Err(reply) => return respond(check, id, reply, CHECK_ROUTE, &mut self.throttle),
            Ok(checked) => checked,
        };
        let (world, chassis, config) = (self.world_in(&placed), self.chassis, self.config.route_check());
        let (stamp, frame, step) = (node.stamp(), placed.frame, self.config.follow.check_length);
        let (server, throttle) = (Arc::clone(check), Arc::clone(&self.reply_throttle));
        let answer = move |reply| {
            if let Err(e) = server.send_response(id, reply) {
                let mut throttle = throttle.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
                warn_throttled!(throttle, "service-reply", "{CHECK_ROUTE}: cannot send the reply: {e:?}");
            }
        };
        let job = move || {
            let began = Instant::now();
            // A check that panics (a defect) is still answered; the panic is in the log.
            let checked = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                match check_route_until(&start, &route.points, &chassis, &world, &config, || false) {
                    Ok(report) => {
                        let of_route = (&route.points[..], &route.request_index[..]);
                        check_reply(
                            &RouteAnswer::of(&report, of_route, step, MAX_REPLY_POSES),
                            stamp,
                            &frame,
                        )
                    }
                    Err(e) => refused_reply(Action::Follow.refused_goal(e).reason()),
                }
            }));
            let reply = checked.unwrap_or_else(|_| {
                refused_reply("INTERNAL_ERROR: the route check failed (see the node's log)".to_owned())
            });
            info!(
                "planner/check_route: {} waypoints, {} in {:.2} ms",
                route.points.len(),
                if reply.feasible {
                    "feasible".to_owned()
                } else {
                    format!("{} problem(s)", reply.problems.len())
                },
                began.elapsed().as_secs_f64() * 1e3
            );
            reply
        };
        if let Err(running) = jobs.checks.start(job, answer) {
            let reply = refused_reply(format!(
                "BUSY: {running} route checks are already being computed; ask again"
            ));
            respond(check, id, reply, CHECK_ROUTE, &mut self.throttle);
        }
    }

    /// The start and route of a `planner/check_route` request, in the route's frame (placed
    /// through tf; the reply is in it too), or the reply refusing it.
    pub(crate) fn check_request(
        &mut self,
        node: &RosNode,
        req: &CheckRouteRequest,
    ) -> Result<(Pose2, Route, Placed), CheckRouteResponse> {
        let frame = self.tf.frame_of(&req.route.header.frame_id);
        let placed = self
            .goal_frame(node, &frame, Action::Follow)
            .map_err(|refusal| refused_reply(refusal.reason()))?;
        let start = if req.use_start {
            pose_in_frame("start", &frame, &req.start, &frame)
                .map_err(|e| refused_reply(Action::Follow.invalid_goal(&e).reason()))?
        } else {
            let seen = self.fresh_odom().map(|p| placed.odom_in.compose(&p));
            seen.ok_or_else(|| {
                refused_reply(
                    "STALE_INPUT: no fresh odometry for the start (set use_start and start to check from a given pose)"
                        .to_owned(),
                )
            })?
        };
        let route = route_from_path(&req.route, &frame, Some(start.position()), ROUTE_LIMITS)
            .map_err(|e| refused_reply(Action::Follow.invalid_goal(&e).reason()))?;
        Ok((start, route, placed))
    }
}
