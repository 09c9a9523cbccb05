//! `gait_node`: quadruped free-gait planning (SPEC §7), the shell of [`mobil_gait`].
//!
//! - `gait/compute_plan` (mobil_msgs/srv/PlanGait): one complete search from the request's
//!   start (legs nominal) to its goal, off the event loop; a newer request pre-empts a running
//!   one, whose caller is answered at once with `success` false and the reason "pre-empted".
//! - `goal_pose` (geometry_msgs/PoseStamped, metres in `frame`): the node's simulated quadruped
//!   walks there by short-time plans (plan, execute the first `walk_execute_moves` moves, one per
//!   `walk_move_period_s`, replan); each plan goes out on `gait/plan` (latched) as it is
//!   executed, the walk on `gait/markers` and the body on `gait/body` after every move.
//! - `terrain/assessment` (latched, from terrain_node): while its class is UNEVEN, plans use the
//!   larger `uneven_stability_margin` and the shorter `uneven_translation_step`. A change of
//!   ground or of the parameters during a walk drops the moves queued and the plan being made,
//!   and the walk replans at once from where it stands.
//!
//! The rules for bad input are in the crate docs.

use mobil_gait::{Chunk, Evaluation, RuleSet, WalkNext, Walker};
use mobil_gait_node::{
    body_pose, chunk_reason, goal_from_pose, ground_from_assessment, header, markers, plan_reason, query_from_request,
    refused_plan, reply_plan, run_query, GaitNodeConfig, Ground, StopCause, PREEMPTED,
};
use mobil_msgs::geometry_msgs::msg::PoseStamped;
use mobil_msgs::mobil_msgs::msg::{GaitPlan, TerrainAssessment};
use mobil_msgs::mobil_msgs::srv::{PlanGait, PlanGaitRequest, PlanGaitResponse};
use mobil_msgs::visualization_msgs::msg::MarkerArray;
use mobil_ros::input::Inputs;
use mobil_ros::{
    qos, respond, run_node, shutdown_signal, warn_throttled, ConfigError, LogThrottle, NodeDecl, OffLoop, RosNode,
};
use ros2_client::{Publisher, RmwRequestId, Server};
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tracing::{info, warn};

fn decl() -> NodeDecl {
    NodeDecl::for_config::<GaitNodeConfig>(
        "gait",
        "Quadruped free-gait planning by best-first search: gait/compute_plan (PlanGait); goal_pose walked by \
         receding-horizon plans on gait/plan, gait/markers and gait/body; terrain/assessment's UNEVEN makes plans \
         more cautious",
    )
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(serve(node)))
}

struct Outputs {
    plan: Publisher<GaitPlan>,
    markers: Publisher<MarkerArray>,
    body: Publisher<PoseStamped>,
}

/// The planning service.
const COMPUTE_PLAN: &str = "gait/compute_plan";

/// A finished `gait/compute_plan` search, its reply built off the loop (a long plan is
/// truncated there), the header left to stamp.
struct Answered {
    id: RmwRequestId,
    reply: GaitPlan,
    /// States in the whole plan (the reply may hold fewer).
    states: usize,
    took: Duration,
}

/// A finished short-time plan of the walk: the walker's plan counter when it was asked for,
/// and the set and evaluation it was made with.
struct Chunked {
    epoch: u64,
    chunk: Chunk,
    set: RuleSet,
    evaluation: Evaluation,
    cause: StopCause,
    took: Duration,
}

/// The request being searched: its id and what was asked (for the pre-empted reply).
struct Running {
    id: RmwRequestId,
    request: PlanGaitRequest,
}

struct Shell {
    config: GaitNodeConfig,
    ground: Ground,
    walker: Walker,
    /// When the next move may be executed (steady clock).
    next_move: Option<Instant>,
    running: Option<Running>,
    throttle: LogThrottle,
}

enum Event {
    Shutdown,
    Config(Result<GaitNodeConfig, ConfigError>),
    Request(RmwRequestId, PlanGaitRequest),
    Answered(Answered),
    Goal(PoseStamped),
    /// An undecodable `goal_pose` (already logged): refused like a bad one.
    BadGoal,
    Assessment(TerrainAssessment),
    Chunked(Chunked),
    Move,
}

async fn serve(node: &mut RosNode) -> anyhow::Result<()> {
    let config: GaitNodeConfig = node.config()?;
    let out = Outputs {
        plan: node.publisher::<GaitPlan>("gait/plan", &qos::latched())?,
        markers: node.publisher::<MarkerArray>("gait/markers", &qos::default_qos())?,
        body: node.publisher::<PoseStamped>("gait/body", &qos::default_qos())?,
    };
    let service = node.service::<PlanGait>(COMPUTE_PLAN)?;
    let goal_sub = node.subscription::<PoseStamped>("goal_pose", &qos::default_qos())?;
    let terrain_sub = node.subscription::<TerrainAssessment>("terrain/assessment", &qos::latched())?;
    let mut shell = Shell {
        walker: Walker::new(config.walk_start_state()),
        config,
        ground: Ground::Even,
        next_move: None,
        running: None,
        throttle: LogThrottle::new(Duration::from_secs(2)),
    };
    info!(
        "serving gait/compute_plan; the quadruped stands at ({:.2}, {:.2}) [j], φ {:.3} rad; waiting for goal_pose \
         (frame `{}`, {} m per [j])",
        shell.config.node.walk_start[0],
        shell.config.node.walk_start[1],
        shell.config.node.walk_start[2],
        shell.config.node.frame,
        shell.config.node.unit_length
    );
    shell.publish_walk(node, &out);
    let mut searches: OffLoop<Answered> = OffLoop::new();
    let mut walk: OffLoop<Chunked> = OffLoop::new();
    let mut inputs = Inputs::new();
    inputs
        .add_requests(service.receive_request_stream(), COMPUTE_PLAN, Event::Request)
        // An undecodable goal stops the walk where it is, as a refused one does.
        .add_guarded(
            goal_sub.async_stream(),
            "goal_pose",
            "goal ignored",
            Event::Goal,
            || Some(Event::BadGoal),
        )
        .add(
            terrain_sub.async_stream(),
            "terrain/assessment",
            "assessment ignored",
            Event::Assessment,
        );
    let shutdown = shutdown_signal();
    tokio::pin!(shutdown);
    loop {
        let move_at = shell.next_move;
        let event = tokio::select! {
            _ = &mut shutdown => Event::Shutdown,
            Some(changed) = node.config_changed::<GaitNodeConfig>() => Event::Config(changed),
            e = inputs.next() => e?,
            done = searches.result() => Event::Answered(done),
            done = walk.result() => Event::Chunked(done),
            _ = sleep_until(move_at) => Event::Move,
        };
        match event {
            Event::Shutdown => break,
            Event::Config(Ok(c)) => {
                info!("parameters changed: the walk, if any, replans with them now; requests get them from the next");
                shell.config = c;
                shell.replan(node, &out, &mut walk);
            }
            Event::Config(Err(e)) => warn!("parameters not applied: {e}"),
            Event::Request(id, req) => shell.request(node, &service, &mut searches, id, req),
            Event::Answered(done) => shell.answered(node, &service, done),
            Event::Goal(m) => shell.goal(node, &out, &mut walk, &m),
            Event::BadGoal => shell.stop_walk(node, &out, &mut walk),
            Event::Assessment(a) => match ground_from_assessment(&a) {
                Ok(ground) => {
                    if ground != shell.ground {
                        // Terrain can flip at touchdown rate: one line per throttle period.
                        if let Some(suppressed) = shell.throttle.allow("ground", Instant::now()) {
                            info!(
                                "terrain: {} ground from now on (stability margin {}, translation step {} [j]; {} \
                                 changes not logged before this)",
                                match ground {
                                    Ground::Uneven => "UNEVEN",
                                    Ground::Even => "even",
                                },
                                shell.config.gait_for(ground).stability_margin,
                                shell.config.gait_for(ground).translation_step,
                                suppressed
                            );
                        }
                        shell.ground = ground;
                        shell.replan(node, &out, &mut walk);
                    }
                }
                Err(why) => warn_throttled!(shell.throttle, "terrain", "{why}"),
            },
            Event::Chunked(done) => shell.chunked(node, &out, &mut walk, done),
            Event::Move => shell.step(node, &out, &mut walk),
        }
    }
    searches.cancel();
    walk.cancel();
    if let Some(r) = shell.running.take() {
        let reply = refused_plan(&r.request, header(node.stamp(), ""), "shutting down".into());
        respond(
            &service,
            r.id,
            PlanGaitResponse { plan: reply },
            COMPUTE_PLAN,
            &mut shell.throttle,
        );
    }
    Ok(())
}

/// Resolves at `at`, never without one.
async fn sleep_until(at: Option<Instant>) {
    match at {
        Some(t) => tokio::time::sleep_until(t.into()).await,
        None => std::future::pending().await,
    }
}

/// A deadline check for the search's stop callback.
fn deadline(seconds: f64) -> impl FnMut() -> bool {
    let until = Instant::now() + Duration::from_secs_f64(seconds);
    move || Instant::now() >= until
}

impl Shell {
    fn request(
        &mut self,
        node: &RosNode,
        service: &Server<PlanGaitRequest, PlanGaitResponse>,
        searches: &mut OffLoop<Answered>,
        id: RmwRequestId,
        req: PlanGaitRequest,
    ) {
        let query = match query_from_request(&req, &self.config, self.ground) {
            Ok(q) => q,
            Err(why) => {
                warn_throttled!(self.throttle, "refused", "gait/compute_plan refused: {why}");
                let plan = refused_plan(&req, header(node.stamp(), ""), why.to_string());
                respond(service, id, PlanGaitResponse { plan }, COMPUTE_PLAN, &mut self.throttle);
                return;
            }
        };
        if let Some(old) = self.running.take() {
            info!("gait/compute_plan: a newer request pre-empts the running search");
            let plan = refused_plan(&old.request, header(node.stamp(), ""), PREEMPTED.into());
            respond(
                service,
                old.id,
                PlanGaitResponse { plan },
                COMPUTE_PLAN,
                &mut self.throttle,
            );
        }
        if let Some(asked) = query.capped_from {
            info!(
                "gait/compute_plan: the request's {asked} expansions capped to max_expansions_limit {}",
                query.max_expansions
            );
        }
        let cfg = self.config.gait_for(self.ground);
        let time_limit = self.config.node.time_limit_s;
        let max_plan_states = self.config.node.max_plan_states;
        info!(
            "gait/compute_plan: searching {},({}) from ({}, {}, φ {}) to ({}, {}) [j] within {} expansions and {} s",
            query.set,
            query.evaluation.number(),
            query.start.body.x,
            query.start.body.y,
            query.start.body.phi,
            query.goal.x,
            query.goal.y,
            query.max_expansions,
            time_limit
        );
        self.running = Some(Running { id, request: req });
        searches.start(move |cancel| {
            let began = Instant::now();
            let (plan, cause) = run_query(&query, &cfg, &|| cancel.is_cancelled(), &mut deadline(time_limit));
            let reason = plan_reason(&plan, cause, &query, time_limit);
            Answered {
                id,
                reply: reply_plan(&plan, query.set, query.evaluation, reason, max_plan_states),
                states: plan.steps.len(),
                took: began.elapsed(),
            }
        });
    }

    fn answered(&mut self, node: &RosNode, service: &Server<PlanGaitRequest, PlanGaitResponse>, done: Answered) {
        if self.running.as_ref().map(|r| r.id) == Some(done.id) {
            self.running = None;
        }
        let mut msg = done.reply;
        info!(
            "gait/compute_plan: {} {},({}): {} states in the plan ({} sent), {} expanded, {} generated, {:.1} ms{}",
            if msg.success { "plan found" } else { "no plan" },
            msg.rule_set,
            msg.evaluation,
            done.states,
            msg.steps.len(),
            msg.states_expanded,
            msg.states_generated,
            done.took.as_secs_f64() * 1e3,
            if msg.reason.is_empty() {
                String::new()
            } else {
                format!("; {}", msg.reason)
            }
        );
        msg.header = header(node.stamp(), "");
        respond(
            service,
            done.id,
            PlanGaitResponse { plan: msg },
            COMPUTE_PLAN,
            &mut self.throttle,
        );
    }

    fn goal(&mut self, node: &RosNode, out: &Outputs, walk: &mut OffLoop<Chunked>, m: &PoseStamped) {
        let n = &self.config.node;
        match goal_from_pose(m, &n.frame, n.unit_length) {
            Ok(goal) => {
                info!("goal_pose ({:.3}, {:.3}) [j]: walking there", goal.x, goal.y);
                self.walker.set_goal(goal);
                self.next_move = None;
                walk.cancel();
                self.advance(node, out, walk);
            }
            Err(why) => {
                warn_throttled!(self.throttle, "goal", "{why}; the walk stops where it is");
                self.stop_walk(node, out, walk);
            }
        }
    }

    /// A refused `goal_pose`: the walk stops where it is (a quadruped standing on four feet is
    /// safe).
    fn stop_walk(&mut self, node: &RosNode, out: &Outputs, walk: &mut OffLoop<Chunked>) {
        walk.cancel();
        self.walker.stop();
        self.next_move = None;
        self.publish_walk(node, out);
    }

    /// The ground or the parameters changed: the moves queued and the plan being made were
    /// made under the old ones; a walk under way replans from where it stands.
    fn replan(&mut self, node: &RosNode, out: &Outputs, walk: &mut OffLoop<Chunked>) {
        if self.walker.goal().is_none() {
            return;
        }
        walk.cancel();
        self.walker.replan();
        self.next_move = None;
        self.advance(node, out, walk);
    }

    /// Asks the walk what comes next and does it.
    fn advance(&mut self, node: &RosNode, out: &Outputs, walk: &mut OffLoop<Chunked>) {
        let next = self
            .walker
            .next(self.config.gait.goal_tolerance, self.config.node.walk_max_chunks);
        self.follow(node, out, walk, next);
    }

    fn follow(&mut self, node: &RosNode, out: &Outputs, walk: &mut OffLoop<Chunked>, next: WalkNext) {
        match next {
            WalkNext::Idle => self.next_move = None,
            WalkNext::Move => {
                self.next_move = Some(Instant::now() + Duration::from_secs_f64(self.config.node.walk_move_period_s))
            }
            WalkNext::Plan => {
                self.next_move = None;
                let horizon = match self.config.horizon(self.ground) {
                    Ok(h) => h,
                    Err(e) => {
                        warn!("the walk stops: {e}");
                        self.walker.stop();
                        return;
                    }
                };
                let (start, epoch, time_limit) =
                    (*self.walker.state(), self.walker.epoch(), self.config.node.time_limit_s);
                let Some(goal) = self.walker.goal() else {
                    return;
                };
                walk.start(move |cancel| {
                    let began = Instant::now();
                    let mut timed_out = deadline(time_limit);
                    let mut cause = StopCause::None;
                    let chunk = horizon.next_chunk(&start, goal, &mut || {
                        if cancel.is_cancelled() {
                            cause = StopCause::Preempted;
                            true
                        } else if timed_out() {
                            cause = StopCause::TimeLimit;
                            true
                        } else {
                            false
                        }
                    });
                    Chunked {
                        epoch,
                        chunk,
                        set: horizon.set,
                        evaluation: horizon.eval,
                        cause,
                        took: began.elapsed(),
                    }
                });
            }
            WalkNext::Reached => {
                self.next_move = None;
                let s = self.walker.state().body;
                info!(
                    "walk: goal reached at ({:.3}, {:.3}) [j], φ {:.3} rad after {} short-time plans",
                    s.x,
                    s.y,
                    s.phi,
                    self.walker.chunks()
                );
                self.publish_walk(node, out);
            }
            WalkNext::GaveUp(why) => {
                self.next_move = None;
                warn!("walk: gave up: {why}; the quadruped stands where it is");
                self.publish_walk(node, out);
            }
        }
    }

    fn chunked(&mut self, node: &RosNode, out: &Outputs, walk: &mut OffLoop<Chunked>, done: Chunked) {
        // A plan made for another goal, ground or configuration is dropped.
        if done.epoch != self.walker.epoch() || self.walker.goal().is_none() {
            return;
        }
        let n = &self.config.node;
        let plan = &done.chunk.plan;
        let reason = chunk_reason(plan, done.cause, n.time_limit_s);
        info!(
            "walk: short-time plan {} of {} states, {},({}) ({} expanded, {:.1} ms), executing {} moves{}",
            self.walker.chunks() + 1,
            plan.steps.len(),
            done.set,
            done.evaluation.number(),
            plan.expanded,
            done.took.as_secs_f64() * 1e3,
            done.chunk.executed.len(),
            if reason.is_empty() {
                String::new()
            } else {
                format!("; {reason}")
            }
        );
        // Coordinates in [j], not metres of `frame`: the header names no frame.
        let mut msg = reply_plan(plan, done.set, done.evaluation, reason, n.max_plan_states);
        msg.header = header(node.stamp(), "");
        if let Err(e) = out.plan.publish(msg) {
            warn_throttled!(self.throttle, "plan", "cannot publish gait/plan: {e:?}");
        }
        let (tolerance, max_chunks) = (self.config.gait.goal_tolerance, self.config.node.walk_max_chunks);
        if let Some(next) = self.walker.take_chunk(done.epoch, done.chunk, tolerance, max_chunks) {
            self.follow(node, out, walk, next);
        }
    }

    fn step(&mut self, node: &RosNode, out: &Outputs, walk: &mut OffLoop<Chunked>) {
        self.walker.step();
        self.publish_walk(node, out);
        self.advance(node, out, walk);
    }

    /// The markers and the body after a move (or a change of goal).
    fn publish_walk(&mut self, node: &RosNode, out: &Outputs) {
        let n = &self.config.node;
        let h = header(node.stamp(), &n.frame);
        let array = markers(
            &self.config.model(),
            self.walker.state(),
            self.walker.current(),
            self.walker.plan(),
            self.walker.goal(),
            &h,
            n.unit_length,
        );
        if let Err(e) = out.markers.publish(array) {
            warn_throttled!(self.throttle, "markers", "cannot publish gait/markers: {e:?}");
        }
        if let Err(e) = out.body.publish(body_pose(&self.walker.state().body, h, n.unit_length)) {
            warn_throttled!(self.throttle, "body", "cannot publish gait/body: {e:?}");
        }
    }
}
