//! `planner/check_route`: a route's pre-check as a service, answered on threads of its own
//! ([`ServiceThreads`]): a request wakes the thread that checks it and sends the reply, with no
//! hand-off through the event loop or a pool (the loop's turn and the pool's wake-up were two
//! of the five thread wake-ups a call cost). What a check reads from the loop's state (the
//! configuration, the latest odometry, the transforms) the loop shares with the threads:
//! [`CheckView`] and [`SharedTf`].

use crate::*;
use mobil_planner::RouteCheckConfig;
use mobil_ros::node::NodeClock;
use mobil_ros::offloop::{Places, ServiceThreads};
use mobil_ros::tf::GoalTf;
use mobil_ros::time::stamp_from_nanos;

/// The goal frames and their transforms, shared by the event loop (goals) and the check
/// threads (each request placed through tf as a goal is). The time a placement is made at is
/// read under the lock: the tree takes a time older than the last it saw for ROS time going
/// back (and clears its history), so the threads must hand it their times in order.
#[derive(Clone)]
pub(crate) struct SharedTf(Arc<Mutex<GoalTf>>);

/// A frame placed through tf at a time ([`SharedTf::place`]).
pub(crate) struct Placement {
    /// The frame (the header's, or the odometry frame for none).
    pub(crate) frame: String,
    /// Whether it is the odometry frame.
    pub(crate) is_odom: bool,
    /// ROS time (ns) it was placed at.
    pub(crate) now: i64,
    /// The odometry frame's pose in it, or why there is none (for a TF_ERROR).
    pub(crate) odom_in: Result<Pose2, String>,
}

impl SharedTf {
    pub(crate) fn new(tf: GoalTf) -> Self {
        SharedTf(Arc::new(Mutex::new(tf)))
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, GoalTf> {
        self.0.lock().unwrap_or_else(|poisoned| {
            // A panic while the tree was being updated (a defect, in the log above): its
            // history may be half-updated; it goes on, and the next transforms mend it.
            tracing::error!("the goal transforms' lock was poisoned by a panic: carrying on with them");
            self.0.clear_poison();
            poisoned.into_inner()
        })
    }

    /// [`GoalTf::frame_of`].
    pub(crate) fn frame_of(&self, frame_id: &str) -> String {
        self.lock().frame_of(frame_id)
    }

    /// Whether `frame` is the odometry frame.
    pub(crate) fn is_odom(&self, frame: &str) -> bool {
        self.lock().frames().is_odom(frame)
    }

    /// [`GoalTf::accept`] at the ROS time `now()` reads, read under the lock.
    pub(crate) fn accept(&self, goal_frame: &str, now: impl FnOnce() -> i64) -> Result<Pose2, String> {
        let mut tf = self.lock();
        tf.accept(goal_frame, now())
    }

    /// The frame a header names, placed ([`GoalTf::accept`]) at the ROS time `now()` reads,
    /// all under one lock.
    pub(crate) fn place(&self, frame_id: &str, now: impl FnOnce() -> i64) -> Placement {
        let mut tf = self.lock();
        let frame = tf.frame_of(frame_id);
        let is_odom = tf.frames().is_odom(&frame);
        let now = now();
        let odom_in = tf.accept(&frame, now);
        Placement {
            frame,
            is_odom,
            now,
            odom_in,
        }
    }

    /// [`GoalTf::odom_in`].
    pub(crate) fn odom_in(&self, goal_frame: &str, now: i64) -> Result<Pose2, String> {
        self.lock().odom_in(goal_frame, now)
    }

    /// [`GoalTf::set_tolerance`].
    pub(crate) fn set_tolerance(&self, tolerance: Duration) {
        self.lock().set_tolerance(tolerance);
    }
}

/// What a check reads from the event loop's state, kept current by the loop: the node's
/// parameters as they apply now and its latest odometry (for a request without a start).
pub(crate) struct CheckInputs {
    pub(crate) world: Arc<World>,
    pub(crate) chassis: ChassisParams,
    pub(crate) config: RouteCheckConfig,
    /// `follow.check_length` (m): the step of the reply's driven length.
    pub(crate) step: f64,
    pub(crate) odom_timeout: Duration,
    /// The latest odometry pose; `None` while the last sample was refused.
    pub(crate) odom: Option<Latest<Pose2>>,
    /// The node's clock, following `use_sim_time` as the event loop does (the tf tree gets
    /// both their times). Under `use_sim_time` it is the latest `/clock` the event loop has
    /// read (at every tick and event), so a check's time may lag the simulation by a tick.
    pub(crate) clock: NodeClock,
}

impl CheckInputs {
    /// The inputs of a node with `config`, before any odometry.
    pub(crate) fn new(config: &PlannerConfig, chassis: ChassisParams, world: Arc<World>, clock: NodeClock) -> Self {
        CheckInputs {
            world,
            chassis,
            config: config.route_check(),
            step: config.follow.check_length,
            odom_timeout: config.timeouts.odom_timeout(),
            odom: Some(Latest::new()),
            clock,
        }
    }

    /// New parameters.
    pub(crate) fn configure(&mut self, config: &PlannerConfig, chassis: ChassisParams) {
        self.chassis = chassis;
        self.config = config.route_check();
        self.step = config.follow.check_length;
        self.odom_timeout = config.timeouts.odom_timeout();
    }
}

/// The loop's side of [`CheckInputs`]: it replaces them as they change.
#[derive(Clone)]
pub(crate) struct CheckView(Arc<Mutex<CheckInputs>>);

impl CheckView {
    pub(crate) fn new(inputs: CheckInputs) -> Self {
        CheckView(Arc::new(Mutex::new(inputs)))
    }

    /// Changes what the checks read (new parameters, a new odometry sample).
    pub(crate) fn update(&self, change: impl FnOnce(&mut CheckInputs)) {
        change(&mut self.lock());
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, CheckInputs> {
        self.0.lock().unwrap_or_else(|poisoned| {
            self.0.clear_poison();
            poisoned.into_inner()
        })
    }
}

/// A request ready to check: its start and route in the route's frame, and what to check it
/// with.
struct Prepared {
    start: Pose2,
    route: Route,
    frame: String,
    world: Arc<World>,
    chassis: ChassisParams,
    config: RouteCheckConfig,
    step: f64,
    stamp: mobil_msgs::builtin_interfaces::msg::Time,
}

/// Receive errors in a row from which on a thread waits 10 ms after each.
const FAILING_IN_A_ROW: usize = 8;

/// `planner/check_route` served.
pub(crate) struct CheckService {
    threads: ServiceThreads,
}

impl CheckService {
    /// Serves `server` on `places + 1` threads (at most `places` checks at once; a request
    /// beyond them is answered BUSY at once).
    pub(crate) fn start(
        server: Arc<Server<CheckRouteRequest, CheckRouteResponse>>,
        places: usize,
        inputs: CheckView,
        tf: SharedTf,
    ) -> anyhow::Result<Self> {
        let throttle = Mutex::new(LogThrottle::new(Duration::from_secs(2)));
        // Receive errors in a row: a reader that keeps failing must not spin the threads.
        let failing = std::sync::atomic::AtomicUsize::new(0);
        let receiving = Arc::clone(&server);
        let receive = move || {
            let server = Arc::clone(&receiving);
            async move { server.async_receive_request().await }
        };
        let serve = move |request: Result<(RmwRequestId, CheckRouteRequest), _>, places: &Places| {
            let warn = |key: &'static str, what: std::fmt::Arguments<'_>| {
                let mut throttle = throttle.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
                warn_throttled!(throttle, key, "{CHECK_ROUTE}: {what}");
            };
            let (id, req) = match request {
                Ok(request) => {
                    failing.store(0, std::sync::atomic::Ordering::Relaxed);
                    request
                }
                Err(e) => {
                    warn("request", format_args!("request dropped: {e:?}"));
                    // One malformed request is just dropped; a reader failing again and again
                    // is given time.
                    if failing.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1 >= FAILING_IN_A_ROW {
                        std::thread::sleep(Duration::from_millis(10));
                    }
                    return;
                }
            };
            // A defect (a panic) in the preparation or the check is still answered.
            let answered =
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match prepare(&inputs, &tf, &req) {
                    Err(refusal) => refusal,
                    Ok(prepared) => match places.take() {
                        Ok(place) => {
                            let reply = compute(&prepared);
                            drop(place);
                            reply
                        }
                        Err(running) => refused_reply(format!(
                            "BUSY: {running} route checks are already being computed; ask again"
                        )),
                    },
                }));
            let reply = answered.unwrap_or_else(|_| {
                refused_reply("INTERNAL_ERROR: the route check failed (see the node's log)".to_owned())
            });
            if let Err(e) = server.send_response(id, reply) {
                warn("reply", format_args!("cannot send the reply: {e:?}"));
            }
        };
        let threads = ServiceThreads::start("check_route", places, receive, serve)
            .map_err(|e| anyhow::anyhow!("{CHECK_ROUTE}: cannot start its threads: {e}"))?;
        Ok(CheckService { threads })
    }

    /// Takes no more requests (those under way are still answered).
    pub(crate) fn stop(&self) {
        self.threads.stop();
    }

    /// Takes no more requests and waits, at most `limit`, for the checks under way to answer;
    /// the threads not ended then, or 0.
    pub(crate) async fn shut_down(&self, limit: Duration) -> usize {
        self.threads.shut_down(limit).await
    }
}

/// The start and route of a request, in the route's frame (placed through tf; the reply is in
/// it too), with what to check them with; or the reply refusing it.
fn prepare(inputs: &CheckView, tf: &SharedTf, req: &CheckRouteRequest) -> Result<Prepared, CheckRouteResponse> {
    let (world, chassis, config, step, odom, clock) = {
        let i = inputs.lock();
        let odom = i.odom.as_ref().and_then(|o| o.get(i.odom_timeout).copied());
        (Arc::clone(&i.world), i.chassis, i.config, i.step, odom, i.clock.clone())
    };
    let Placement {
        frame,
        is_odom,
        now,
        odom_in,
    } = tf.place(&req.route.header.frame_id, || clock.now_nanos());
    let odom_in = odom_in.map_err(|why| refused_reply(Action::Follow.tf_error(why).reason()))?;
    let start = if req.use_start {
        pose_in_frame("start", &frame, &req.start, &frame)
            .map_err(|e| refused_reply(Action::Follow.invalid_goal(&e).reason()))?
    } else {
        let seen = odom.map(|p| odom_in.compose(&p));
        seen.ok_or_else(|| {
            refused_reply(
                "STALE_INPUT: no fresh odometry for the start (set use_start and start to check from a given pose)"
                    .to_owned(),
            )
        })?
    };
    let route = route_from_path(&req.route, &frame, Some(start.position()), ROUTE_LIMITS)
        .map_err(|e| refused_reply(Action::Follow.invalid_goal(&e).reason()))?;
    let world = world_seen(world, is_odom, &odom_in);
    Ok(Prepared {
        start,
        route,
        frame,
        world,
        chassis,
        config,
        step,
        stamp: stamp_from_nanos(now),
    })
}

/// The pre-check's world (given in the odometry frame) seen from a route's frame, through the
/// odometry frame's pose `odom_in` in it.
pub(crate) fn world_seen(world: Arc<World>, is_odom: bool, odom_in: &Pose2) -> Arc<World> {
    match is_odom {
        true => world,
        false => Arc::new(world.moved(odom_in)),
    }
}

/// The check of a prepared request and its reply. A check that panics (a defect) is still
/// answered; the panic is in the log.
fn compute(p: &Prepared) -> CheckRouteResponse {
    let began = Instant::now();
    let checked = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        match check_route_until(&p.start, &p.route.points, &p.chassis, &p.world, &p.config, || false) {
            Ok(report) => {
                let of_route = (&p.route.points[..], &p.route.request_index[..]);
                check_reply(
                    &RouteAnswer::of(&report, of_route, p.step, MAX_REPLY_POSES),
                    p.stamp.clone(),
                    &p.frame,
                )
            }
            Err(e) => refused_reply(Action::Follow.refused_goal(e).reason()),
        }
    }));
    let reply = checked
        .unwrap_or_else(|_| refused_reply("INTERNAL_ERROR: the route check failed (see the node's log)".to_owned()));
    info!(
        "{CHECK_ROUTE}: {} waypoints, {} in {:.2} ms",
        p.route.points.len(),
        if reply.feasible {
            "feasible".to_owned()
        } else {
            format!("{} problem(s)", reply.problems.len())
        },
        began.elapsed().as_secs_f64() * 1e3
    );
    reply
}
