//! An action server for a node's main loop: at most one active goal, accepted or rejected with a
//! reason, feedback while it runs, a result however it ends, cancel, and pre-emption by a newer
//! goal.
//!
//! [`GoalServer`] serves ros2-client's `ActionServer` (its three services and two topics) for
//! the way the suite's nodes run: one `tokio::select!` over topics, a ticker and
//! [`GoalServer::next_event`]. The node owns the decisions (is this goal valid? is it done?),
//! the server owns the protocol, answering every request as `rcl_action` (rclpy's and rclcpp's
//! servers) answers it, from its [`table::GoalTable`]:
//!
//! - **QoS as rcl_action has it**, which Fast DDS clients need to match: the three services and
//!   the feedback topic reliable and volatile (depth 10), the status topic reliable and transient
//!   local (depth 1). A transient-local request reader does not match rclpy's volatile request
//!   writers, and goals would never arrive.
//! - **Accept or reject with a reason**: ROS 2's goal response carries only accepted/rejected, so
//!   the reason is logged (info) with the goal id. A goal whose id the server knows (running, or
//!   ended with its result kept) is refused at once, without the node.
//! - **Pre-emption**: accepting a new goal while one is active ends the old one **ABORTED**, with a
//!   result the node builds (its reason says "preempted"), as Nav2's `SimpleActionServer` does —
//!   so a Nav2-style client sees the same status from this suite as from Nav2. (CANCELED is kept
//!   for what a client asked for; an old goal that was already being canceled ends CANCELED.)
//! - **Cancel**: a cancel request that names the active goal (or all goals, or goals up to a
//!   stamp) is agreed to at once (the goal goes CANCELING, the status is published, then the
//!   reply) and reported, once, as [`ActionEvent::CancelRequested`] with the goal's id, if it is
//!   still the active goal then; the node stops and calls [`GoalServer::finish`] with
//!   [`GoalEnd::Canceled`]. A goal that cannot move to CANCELING (ended, or canceling already)
//!   gets ERROR_GOAL_TERMINATED, an unknown id ERROR_UNKNOWN_GOAL_ID, and neither is reported.
//! - **Results kept**: an ended goal's status is published, then its result goes to every
//!   `get_result` request waiting for it; it is then kept for
//!   [`GoalServerConfig::result_timeout`] and answered at once, as often as asked. An unknown or
//!   expired id is answered STATUS_UNKNOWN with a default result, at once. Nothing is kept for a
//!   request answered at once, and the table is bounded ([`table::MOST_KEPT`]): no stream of
//!   requests grows the node's memory. The timeout must exceed Fast DDS's 3 s repair of a
//!   request lost during discovery (ROS2-NOTES), hence the 10 s default (Nav2's too).
//!
//! ```no_run
//! # async fn demo(node: &mut mobil_ros::RosNode) -> anyhow::Result<()> {
//! use mobil_msgs::mobil_msgs::action::{DriveDistance, DriveDistanceFeedback, DriveDistanceResult};
//! use mobil_ros::action::{ActionEvent, GoalEnd, GoalServer, GoalServerConfig};
//! use std::time::Duration;
//! let mut server = GoalServer::<DriveDistance>::create(node, "drive_distance", GoalServerConfig::default())?;
//! let mut ticker = tokio::time::interval(Duration::from_millis(50));
//! let mut travelled = 0.0;
//! let result = |travelled: f64, reason: &str| DriveDistanceResult { travelled, reason: reason.into() };
//! loop {
//!     tokio::select! {
//!         event = server.next_event() => match event {
//!             ActionEvent::Goal(request) if request.goal().speed <= 0.0 => {
//!                 server.reject(request, "speed must be above zero").await;
//!             }
//!             ActionEvent::Goal(request) => {
//!                 let preempted = |_: &_| result(travelled, "preempted by a newer goal");
//!                 server.accept(request, preempted, node.now_nanos()).await?;
//!                 travelled = 0.0;
//!             }
//!             ActionEvent::CancelRequested(_) => {
//!                 server.finish(GoalEnd::Canceled, result(travelled, "canceled"));
//!             }
//!         },
//!         _ = ticker.tick() => {
//!             let Some(goal) = server.active_goal() else { continue };
//!             let distance = goal.distance;
//!             travelled += 0.01;
//!             if travelled >= distance {
//!                 server.finish(GoalEnd::Succeeded, result(travelled, "reached"));
//!             } else {
//!                 server.feedback(DriveDistanceFeedback { travelled, remaining: distance - travelled }).await?;
//!             }
//!         }
//!     }
//! }
//! # }
//! ```

use crate::lifecycle::ActiveGate;
use crate::RosNode;
use mobil_msgs::RosAction;
use ros2_client::action::ActionServerQosPolicies;
pub use ros2_client::action::{GoalEndStatus as GoalEnd, GoalId};

use mobil_motion::{EndCause, EndKind, Nav2Codes};
use mobil_msgs::nav2_msgs::action::{
    DockRobotResult, FollowPathResult, FollowWaypointsResult, NavigateToPoseResult, UndockRobotResult,
};

/// The action status a motion goal's end gives its client: SUCCEEDED, CANCELED, else ABORTED.
pub fn goal_end(cause: &EndCause) -> GoalEnd {
    match cause.kind() {
        EndKind::Succeeded => GoalEnd::Succeeded,
        EndKind::Canceled => GoalEnd::Canceled,
        EndKind::Aborted => GoalEnd::Aborted,
    }
}

/// A Nav2 action's result made from a goal's end, the same way by every node: `success` where
/// the result has one, the error code by [`EndCause::nav2_error`] with the action's `codes`,
/// the end's reason as `error_msg`; lists (FollowWaypoints' missed waypoints) empty, for the
/// caller to fill.
pub trait Nav2Result {
    /// The result of a goal that ended with `cause`.
    fn ended(cause: &EndCause, codes: Nav2Codes) -> Self;
}

impl Nav2Result for NavigateToPoseResult {
    fn ended(cause: &EndCause, codes: Nav2Codes) -> Self {
        NavigateToPoseResult {
            error_code: cause.nav2_error(codes),
            error_msg: cause.reason(),
        }
    }
}

impl Nav2Result for DockRobotResult {
    fn ended(cause: &EndCause, codes: Nav2Codes) -> Self {
        DockRobotResult {
            success: cause.kind() == EndKind::Succeeded,
            error_code: cause.nav2_error(codes),
            num_retries: 0,
            error_msg: cause.reason(),
        }
    }
}

impl Nav2Result for UndockRobotResult {
    fn ended(cause: &EndCause, codes: Nav2Codes) -> Self {
        UndockRobotResult {
            success: cause.kind() == EndKind::Succeeded,
            error_code: cause.nav2_error(codes),
            error_msg: cause.reason(),
        }
    }
}

impl Nav2Result for FollowWaypointsResult {
    fn ended(cause: &EndCause, codes: Nav2Codes) -> Self {
        FollowWaypointsResult {
            missed_waypoints: Vec::new(),
            error_code: cause.nav2_error(codes),
            error_msg: cause.reason(),
        }
    }
}

impl Nav2Result for FollowPathResult {
    fn ended(cause: &EndCause, codes: Nav2Codes) -> Self {
        FollowPathResult {
            result: Default::default(),
            error_code: cause.nav2_error(codes),
            error_msg: cause.reason(),
        }
    }
}

/// The result `R` of a goal that ended with `cause`, for an action with `codes`.
pub fn nav2_result<R: Nav2Result>(cause: &EndCause, codes: Nav2Codes) -> R {
    R::ended(cause, codes)
}
use ros2_client::action::{
    ActionServer, CancelGoalResponse, GetResultRequest, GetResultResponse, GoalInfo, GoalStatusEnum, SendGoalRequest,
    SendGoalResponse,
};
use ros2_client::action_msgs::GoalStatusArray;
use ros2_client::builtin_interfaces::Time as RosTime;
use ros2_client::service::RmwRequestId;
use ros2_client::{Name, Node, ServiceMapping};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use table::{GoalTable, ResultAnswer};
use thiserror::Error;
use tracing::{info, warn};

pub mod table;

type Server<A> = ActionServer<<A as RosAction>::Goal, <A as RosAction>::Result, <A as RosAction>::Feedback>;

/// What can go wrong serving an action.
#[derive(Debug, Error)]
pub enum ActionError {
    /// The action name does not resolve or is not a valid ROS name.
    #[error("bad action name `{0}`: {1}")]
    Name(String, String),
    /// ros2-client could not create the action's services and topics.
    #[error("cannot create action server {0}: {1}")]
    Create(String, String),
    /// A call that needs an active goal came without one.
    #[error("no active goal")]
    NoActiveGoal,
    /// DDS failed to send.
    #[error("goal {0:?}: {1}")]
    Goal(GoalId, String),
    /// Another request with this goal's id was accepted first: this one is refused, and the
    /// goal that was running runs on.
    #[error("goal {0:?}: its id is in use")]
    IdInUse(GoalId),
}

impl ActionError {
    /// Whether a failed [`GoalServer::accept`] ended the goal that was running (it did unless
    /// the id was in use): the node then stops that goal's robot.
    pub fn ended_active(&self) -> bool {
        !matches!(self, ActionError::IdInUse(_))
    }
}

/// The longest [`GoalServer::close`] waits for the results no client has asked for yet.
pub const CLOSE_WAIT: Duration = Duration::from_secs(2);

/// The longest [`GoalServer::close`] then waits for the clients to acknowledge the results.
pub const RESULT_ACK_WAIT: Duration = Duration::from_millis(500);

/// Settings of a [`GoalServer`].
#[derive(Debug, Clone, PartialEq)]
pub struct GoalServerConfig {
    /// How long an ended goal's result is kept for its clients' `get_result` requests (Nav2's
    /// `action_server_result_timeout`).
    pub result_timeout: Duration,
}

impl Default for GoalServerConfig {
    fn default() -> Self {
        GoalServerConfig {
            result_timeout: Duration::from_secs(10),
        }
    }
}

/// The QoS of an action server as rcl_action sets it (see the module docs).
pub fn server_qos() -> ActionServerQosPolicies {
    let service = crate::qos::reliable(10);
    ActionServerQosPolicies {
        goal_service: service.clone(),
        result_service: service.clone(),
        cancel_service: service.clone(),
        feedback_publisher: service,
        status_publisher: crate::qos::latched(),
    }
}

/// A goal a client sent, waiting for [`GoalServer::accept`] or [`GoalServer::reject`].
pub struct GoalRequest<G> {
    request: RmwRequestId,
    id: GoalId,
    goal: G,
}

impl<G> GoalRequest<G> {
    /// What the client asks for.
    pub fn goal(&self) -> &G {
        &self.goal
    }

    /// The client's id for the goal.
    pub fn id(&self) -> GoalId {
        self.id
    }
}

/// Something the node has to react to.
pub enum ActionEvent<G> {
    /// A client sent a goal: accept it (pre-empting the active one, if any) or reject it.
    Goal(GoalRequest<G>),
    /// A client asked to cancel the active goal, whose id this is, and the server agreed (it is
    /// CANCELING): stop, then [`GoalServer::finish`] it, normally with [`GoalEnd::Canceled`].
    CancelRequested(GoalId),
}

struct Active<G> {
    id: GoalId,
    goal: G,
    canceling: bool,
}

/// A request read from one of the action's three services.
enum Incoming<G> {
    Goal(RmwRequestId, SendGoalRequest<G>),
    Cancel(RmwRequestId, ros2_client::action::CancelGoalRequest),
    Result(RmwRequestId, GetResultRequest),
    /// An undecodable request, of which service.
    Undecodable(&'static str, String),
}

fn status_of(end: GoalEnd) -> GoalStatusEnum {
    match end {
        GoalEnd::Succeeded => GoalStatusEnum::Succeeded,
        GoalEnd::Aborted => GoalStatusEnum::Aborted,
        GoalEnd::Canceled => GoalStatusEnum::Canceled,
    }
}

/// A warning of `$server`, rate-limited under `$key` by its throttle, written where it is called
/// (so that each place has its own line budget, `crate::log`).
macro_rules! warn_at {
    ($server:expr, $key:expr, $($arg:tt)+) => {
        if let Ok(mut throttle) = $server.throttle.lock() {
            crate::warn_throttled!(throttle, $key, $($arg)+);
        }
    };
}

/// Requests [`GoalServer::next_event`] answers in a row before it lets the node's other work in
/// (a flood of `get_result` requests must not starve the node's loop).
const ANSWERED_IN_A_ROW: u32 = 64;

/// An action server owning at most one active goal (see the module docs).
pub struct GoalServer<A: RosAction> {
    server: Arc<Server<A>>,
    name: String,
    table: GoalTable<A::Result, RmwRequestId>,
    active: Option<Active<A::Goal>>,
    /// A goal that went CANCELING and that the node has not yet been told of (kept so that a
    /// dropped [`GoalServer::next_event`] future reports it on the next call).
    unreported_cancel: Option<GoalId>,
    result_timeout: Duration,
    /// Goals are refused while it is closed (the node is not active: [`crate::lifecycle`]).
    gate: ActiveGate,
    throttle: Mutex<crate::LogThrottle>,
}

impl<A> GoalServer<A>
where
    A: RosAction + 'static,
{
    /// Serves `action` (resolved and remapped like a topic name) on a running node.
    pub fn create(node: &mut RosNode, action: &str, config: GoalServerConfig) -> Result<Self, ActionError> {
        let full = node
            .names()
            .resolve(action)
            .map_err(|e| ActionError::Name(action.to_owned(), e.to_string()))?;
        let name = Name::parse(&full).map_err(|e| ActionError::Name(full.clone(), format!("{e:?}")))?;
        Self::on_node(node.inner(), &name, config)
    }

    /// Serves the action `name` on a bare ros2-client node; its three services answer each
    /// request in the layout of the client that sent it, Fast DDS's or Cyclone DDS's.
    pub fn on_node(node: &mut Node, name: &Name, config: GoalServerConfig) -> Result<Self, ActionError> {
        let server = node
            .create_action_server::<A::Goal, A::Result, A::Feedback>(
                ServiceMapping::Auto,
                name,
                &A::type_name(),
                server_qos(),
            )
            .map_err(|e| ActionError::Create(name.to_string(), format!("{e:?}")))?;
        Ok(GoalServer {
            server: Arc::new(server),
            name: name.to_string(),
            table: GoalTable::new(config.result_timeout),
            active: None,
            unreported_cancel: None,
            result_timeout: config.result_timeout,
            gate: ActiveGate::open(),
            throttle: Mutex::new(crate::LogThrottle::new(Duration::from_secs(2))),
        })
    }

    /// Refuses goals while `gate` is closed: a managed node's server takes goals only while the
    /// node is active ([`crate::lifecycle::Lifecycle::gate`]).
    pub fn gate(mut self, gate: ActiveGate) -> Self {
        self.gate = gate;
        self
    }

    /// The active goal, if any (also while it is being canceled).
    pub fn active_goal(&self) -> Option<&A::Goal> {
        self.active.as_ref().map(|a| &a.goal)
    }

    /// The active goal's id.
    pub fn active_id(&self) -> Option<GoalId> {
        self.active.as_ref().map(|a| a.id)
    }

    /// Whether the active goal is being canceled.
    pub fn is_canceling(&self) -> bool {
        self.active.as_ref().is_some_and(|a| a.canceling)
    }

    /// Waits for the next goal or cancel request; answers what needs no decision of the node on
    /// the way (module docs). Cancel-safe: a request is never half taken, so this can be one
    /// branch of a `tokio::select!` that other branches win.
    pub async fn next_event(&mut self) -> ActionEvent<A::Goal> {
        let mut answered = 0u32;
        loop {
            if let Some(id) = self.unreported_cancel.take()
                && self.active_id() == Some(id)
            {
                return ActionEvent::CancelRequested(id);
            }
            answered += 1;
            if answered.is_multiple_of(ANSWERED_IN_A_ROW) {
                tokio::task::yield_now().await;
            }
            let incoming = self.receive().await;
            self.table.expire(Instant::now());
            match incoming {
                Incoming::Goal(request, SendGoalRequest { goal_id, goal }) => {
                    if !self.gate.is_open() {
                        info!(
                            "{}: goal {goal_id:?} rejected: the node is not active (lifecycle: activate it first)",
                            self.name
                        );
                        self.send_goal_response(request, false, RosTime::ZERO, goal_id);
                    } else if !self.table.knows(&goal_id) {
                        return ActionEvent::Goal(GoalRequest {
                            request,
                            id: goal_id,
                            goal,
                        });
                    } else {
                        // rcl_action refuses a goal id it knows without asking the server.
                        info!("{}: goal {goal_id:?} refused: its id is in use", self.name);
                        self.send_goal_response(request, false, RosTime::ZERO, goal_id);
                    }
                }
                Incoming::Cancel(request, cancel) => self.cancel(request, cancel.goal_info()),
                Incoming::Result(request, GetResultRequest { goal_id }) => {
                    if let ResultAnswer::Now(status, result) = self.table.result(goal_id, request) {
                        self.send_result(request, goal_id, status, result);
                    }
                }
                Incoming::Undecodable(service, e) => {
                    warn_at!(
                        self,
                        "undecodable",
                        "{}: undecodable {service} request dropped: {e}",
                        self.name
                    );
                }
            }
        }
    }

    /// The next request on any of the three services (cancel-safe: each is taken whole).
    async fn receive(&self) -> Incoming<A::Goal> {
        let (goals, cancels, results) = self.server.services();
        tokio::select! {
            r = goals.async_receive_request() => match r {
                Ok((id, request)) => Incoming::Goal(id, request),
                Err(e) => Incoming::Undecodable("send_goal", format!("{e:?}")),
            },
            r = cancels.async_receive_request() => match r {
                Ok((id, request)) => Incoming::Cancel(id, request),
                Err(e) => Incoming::Undecodable("cancel_goal", format!("{e:?}")),
            },
            r = results.async_receive_request() => match r {
                Ok((id, request)) => Incoming::Result(id, request),
                Err(e) => Incoming::Undecodable("get_result", format!("{e:?}")),
            },
        }
    }

    /// A cancel request: answered as rcl_action answers it (the table); the active goal, if it
    /// went CANCELING, is reported to the node.
    fn cancel(&mut self, request: RmwRequestId, goal: &GoalInfo) {
        let answer = self.table.cancel(goal);
        if let Some(active) = self.active.as_mut()
            && answer.canceling().iter().any(|g| g.goal_id == active.id)
        {
            info!("{}: goal {:?} is canceling", self.name, active.id);
            active.canceling = true;
            self.unreported_cancel = Some(active.id);
        }
        if !answer.canceling().is_empty() {
            self.publish_statuses();
        } else {
            info!(
                "{}: cancel request answered {:?}: no goal canceling",
                self.name,
                answer.code()
            );
        }
        let response = CancelGoalResponse {
            return_code: answer.code(),
            goals_canceling: answer.canceling().to_vec(),
        };
        if let Err(e) = self.server.send_cancel_response(request, response) {
            warn_at!(
                self,
                "cancel-response",
                "{}: cannot answer a cancel request: {e:?}",
                self.name
            );
        }
    }

    /// Accepts a goal, stamped `now_nanos` of the node's clock (ROS time), and makes it the
    /// active one. If a goal was active, it ends first: ABORTED with the result `preempted`
    /// builds from it (CANCELED if it was being canceled).
    pub async fn accept(
        &mut self,
        request: GoalRequest<A::Goal>,
        preempted: impl FnOnce(&A::Goal) -> A::Result,
        now_nanos: i64,
    ) -> Result<(), ActionError> {
        let id = request.id;
        if self.table.knows(&id) {
            // Another request with this id was accepted since this one came (the node held two).
            self.send_goal_response(request.request, false, RosTime::ZERO, id);
            return Err(ActionError::IdInUse(id));
        }
        if let Some(old) = self.active.take() {
            let status = if old.canceling {
                GoalEnd::Canceled
            } else {
                GoalEnd::Aborted
            };
            info!(
                "{}: goal {:?} preempted by goal {id:?}: it ends {status:?}",
                self.name, old.id
            );
            let result = preempted(&old.goal);
            self.end(old.id, status, result);
        }
        let stamp = RosTime::from_nanos(now_nanos);
        self.table.accept(id, stamp);
        let sent = self
            .server
            .send_goal_response(request.request, SendGoalResponse { accepted: true, stamp });
        if let Err(e) = sent {
            // The client learns nothing of it: the goal ends at once, its result kept.
            self.end(id, GoalEnd::Aborted, A::Result::default());
            return Err(ActionError::Goal(id, format!("cannot send the acceptance: {e:?}")));
        }
        info!("{}: goal {id:?} accepted", self.name);
        self.publish_statuses();
        self.active = Some(Active {
            id,
            goal: request.goal,
            canceling: false,
        });
        Ok(())
    }

    /// Rejects a goal; the reason is logged (a ROS 2 goal response cannot carry it).
    pub async fn reject(&mut self, request: GoalRequest<A::Goal>, reason: &str) {
        let id = request.id;
        info!("{}: goal {id:?} rejected: {reason}", self.name);
        self.send_goal_response(request.request, false, RosTime::ZERO, id);
    }

    /// Publishes feedback on the active goal.
    pub async fn feedback(&self, feedback: A::Feedback) -> Result<(), ActionError> {
        let id = self.active_id().ok_or(ActionError::NoActiveGoal)?;
        self.server
            .send_feedback(id, feedback)
            .map_err(|e| ActionError::Goal(id, format!("cannot publish feedback: {e:?}")))
    }

    /// Ends the active goal with `status` and `result`: the status goes out, then the result to
    /// every client waiting for it; it is kept for later requests (module docs). Returns the
    /// goal's id, or `None` when no goal was active.
    pub fn finish(&mut self, status: GoalEnd, result: A::Result) -> Option<GoalId> {
        let active = self.active.take()?;
        info!("{}: goal {:?} ends {status:?}", self.name, active.id);
        self.end(active.id, status, result);
        Some(active.id)
    }

    /// Ends the active goal (if any) ABORTED with `result`, then answers `get_result` requests
    /// until every ended goal's result has been asked for, at most [`CLOSE_WAIT`] (a node
    /// shutting down must not hang on a client that never asks). Last, it waits up to
    /// [`RESULT_ACK_WAIT`] for the clients to acknowledge the results sent: the server's
    /// endpoints are disposed when it is dropped, and a peer that learns of the dispose before
    /// it has taken a result in flight drops the result (Fast DDS reads discovery and data on
    /// different threads: an rclpy client's result at shutdown went missing that way).
    pub async fn close(mut self, result: A::Result) {
        if self.active.is_some() {
            self.finish(GoalEnd::Aborted, result);
        }
        let deadline = tokio::time::Instant::now() + CLOSE_WAIT.min(self.result_timeout);
        while self.table.unasked() > 0 {
            let next = {
                let (_, _, results) = self.server.services();
                tokio::time::timeout_at(deadline, results.async_receive_request()).await
            };
            match next {
                Err(_) => {
                    warn!(
                        "{}: at close, no client asked for the result of {} ended goal(s)",
                        self.name,
                        self.table.unasked()
                    );
                    break;
                }
                Ok(Ok((request, GetResultRequest { goal_id }))) => {
                    if let ResultAnswer::Now(status, result) = self.table.result(goal_id, request) {
                        self.send_result(request, goal_id, status, result);
                    }
                }
                Ok(Err(e)) => {
                    warn_at!(
                        self,
                        "undecodable",
                        "{}: undecodable get_result request dropped: {e:?}",
                        self.name
                    );
                    // A reader that keeps failing must not spin the close.
                    tokio::time::sleep(Duration::from_millis(10)).await;
                }
            }
        }
        let name = self.name.clone();
        let server = self.server.clone();
        let waited = tokio::task::spawn_blocking(move || {
            let (_, _, results) = server.services();
            results.wait_for_acknowledgments(RESULT_ACK_WAIT)
        })
        .await;
        match waited {
            Ok(Ok(true)) => {}
            Ok(Ok(false)) => {
                warn!("{name}: results not acknowledged by every client within {RESULT_ACK_WAIT:?} at close")
            }
            Ok(Err(e)) => warn!("{name}: cannot wait for the results' acknowledgments: {e:?}"),
            Err(e) => warn!("{name}: the wait for the results' acknowledgments failed: {e}"),
        }
    }

    /// Goal `id` ends: the table keeps its result, the status goes out, then the result to the
    /// requests waiting for it (as rclpy orders them).
    fn end(&mut self, id: GoalId, status: GoalEnd, result: A::Result) {
        let now = Instant::now();
        self.table.expire(now);
        let status = status_of(status);
        let waiting = self.table.finish(id, status, result.clone(), now);
        self.publish_statuses();
        for request in waiting {
            self.send_result(request, id, status, result.clone());
        }
    }

    fn send_goal_response(&self, request: RmwRequestId, accepted: bool, stamp: RosTime, id: GoalId) {
        if let Err(e) = self
            .server
            .send_goal_response(request, SendGoalResponse { accepted, stamp })
        {
            warn_at!(
                self,
                "goal-response",
                "{}: cannot answer goal request {id:?}: {e:?}",
                self.name
            );
        }
    }

    fn send_result(&self, request: RmwRequestId, id: GoalId, status: GoalStatusEnum, result: A::Result) {
        if let Err(e) = self.server.send_result(request, GetResultResponse { status, result }) {
            warn_at!(
                self,
                "result",
                "{}: cannot send the result of goal {id:?}: {e:?}",
                self.name
            );
        }
    }

    fn publish_statuses(&self) {
        let statuses = GoalStatusArray {
            status_list: self.table.statuses(),
        };
        if let Err(e) = self.server.send_goal_statuses(statuses) {
            warn_at!(self, "status", "{}: cannot publish the goal status: {e:?}", self.name);
        }
    }
}

impl<A: RosAction> Drop for GoalServer<A> {
    fn drop(&mut self) {
        if let Some(active) = &self.active {
            warn!(
                "{}: dropped with goal {:?} active; its client gets no result",
                self.name, active.id
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mobil_motion::Outcome;

    #[test]
    fn results_carry_success_the_code_and_the_reason() {
        let failed = EndCause::Outcome(Outcome::failed("NOT_CONVERGING", "V stalled", 905));
        let dock: DockRobotResult = nav2_result(&failed, Nav2Codes::DOCKING);
        assert_eq!((dock.success, dock.error_code, dock.num_retries), (false, 905, 0));
        assert_eq!(dock.error_msg, "NOT_CONVERGING: V stalled");
        let undock: UndockRobotResult = nav2_result(&EndCause::Shutdown, Nav2Codes::DOCKING);
        assert_eq!((undock.success, undock.error_code), (false, 999));
        let ok = EndCause::Outcome(Outcome::succeeded("arrived"));
        let nav: NavigateToPoseResult = nav2_result(&ok, Nav2Codes::FOLLOW_PATH);
        assert_eq!((nav.error_code, nav.error_msg.as_str()), (0, "SUCCEEDED: arrived"));
        let follow: FollowWaypointsResult = nav2_result(&EndCause::Stale("odom".into()), Nav2Codes::FOLLOW_WAYPOINTS);
        assert_eq!((follow.error_code, follow.missed_waypoints.len()), (601, 0));
        assert_eq!(goal_end(&EndCause::Canceled), GoalEnd::Canceled);
        assert_eq!(
            crate::status::end_state(&EndCause::Canceled),
            mobil_msgs::mobil_msgs::msg::NavStatus::FAILED
        );
    }
}
