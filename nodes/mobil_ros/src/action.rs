//! An action server for a node's main loop: at most one active goal, accepted or rejected with a
//! reason, feedback while it runs, a result however it ends, cancel, and pre-emption by a newer
//! goal.
//!
//! [`GoalServer`] wraps ros2-client's `AsyncActionServer` for the way the suite's nodes run: one
//! `tokio::select!` over topics, a ticker and [`GoalServer::next_event`]. The node owns the
//! decisions (is this goal valid? is it done?), the server owns the protocol:
//!
//! - **QoS as rcl_action has it**, which Fast DDS clients need to match: the three services and
//!   the feedback topic reliable and volatile (depth 10), the status topic reliable and transient
//!   local (depth 1). A transient-local request reader does not match rclpy's volatile request
//!   writers, and goals would never arrive.
//! - **Accept or reject with a reason**: ROS 2's goal response carries only accepted/rejected, so
//!   the reason is logged (info) with the goal id.
//! - **Pre-emption**: accepting a new goal while one is active ends the old one **ABORTED**, with a
//!   result the node builds (its reason says "preempted"), as Nav2's `SimpleActionServer` does —
//!   so a Nav2-style client sees the same status from this suite as from Nav2. (CANCELED is kept
//!   for what a client asked for; an old goal that was already being canceled ends CANCELED.)
//! - **Cancel**: a cancel request that names the active goal is agreed to at once (the goal goes
//!   CANCELING) and reported, once, as [`ActionEvent::CancelRequested`] with the goal's id, if it
//!   is still the active goal then; the node stops and calls [`GoalServer::finish`] with
//!   [`GoalEnd::Canceled`]. A further cancel of a goal already canceling is refused
//!   (ERROR_REJECTED), as rcl_action refuses a goal that cannot move to CANCELING, and not
//!   reported again. Requests for other goals are refused.
//! - **Results with a bounded wait**: ros2-client sends a result only once the client has asked
//!   for it (`get_result`). [`GoalServer::finish`] hands the result to a background task that
//!   delivers each finished goal's result concurrently with the others, each waiting at most
//!   [`GoalServerConfig::result_timeout`] for its client's request: the node's loop never blocks
//!   on a client, and a client that never asks holds up no other goal's result. A result nobody
//!   asked for in time is dropped with a warning. ros2-client sets a goal's end status only when
//!   it sends the result, so such a goal that ended ABORTED is then marked ABORTED, while one
//!   that ended SUCCEEDED or CANCELED keeps the status last published for it (EXECUTING or
//!   CANCELING) rather than being reported ABORTED. The timeout must exceed Fast DDS's 3 s repair
//!   of a request lost during discovery (ROS2-NOTES), hence the 10 s default.
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
//!                 server.accept(request, |_old| result(travelled, "preempted by a newer goal")).await?;
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

use crate::RosNode;
use mobil_msgs::RosAction;
use ros2_client::action::{
    ActionServerQosPolicies, AsyncActionServer, CancelHandle, ExecutingGoalHandle, NewGoalHandle,
};
pub use ros2_client::action::{GoalEndStatus as GoalEnd, GoalId};

use mobil_motion::{EndCause, EndKind, Nav2Codes};
use mobil_msgs::nav2_msgs::action::{DockRobotResult, FollowWaypointsResult, NavigateToPoseResult, UndockRobotResult};

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

/// The result `R` of a goal that ended with `cause`, for an action with `codes`.
pub fn nav2_result<R: Nav2Result>(cause: &EndCause, codes: Nav2Codes) -> R {
    R::ended(cause, codes)
}
use ros2_client::{Name, Node, ServiceMapping};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use thiserror::Error;
use tokio::sync::mpsc;
use tracing::{info, warn};

type Server<A> = AsyncActionServer<<A as RosAction>::Goal, <A as RosAction>::Result, <A as RosAction>::Feedback>;

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
    /// ros2-client refused a goal transition, or DDS failed to send.
    #[error("goal {0:?}: {1}")]
    Goal(GoalId, String),
}

/// The longest [`GoalServer::close`] waits for queued results.
pub const CLOSE_WAIT: Duration = Duration::from_secs(2);

/// The longest [`GoalServer::close`] then waits for the clients to acknowledge the results.
pub const RESULT_ACK_WAIT: Duration = Duration::from_millis(500);

/// Settings of a [`GoalServer`].
#[derive(Debug, Clone, PartialEq)]
pub struct GoalServerConfig {
    /// How long a finished goal's result waits for the client's `get_result` request.
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
    handle: NewGoalHandle<G>,
    goal: G,
}

impl<G> GoalRequest<G> {
    /// What the client asks for.
    pub fn goal(&self) -> &G {
        &self.goal
    }

    /// The client's id for the goal.
    pub fn id(&self) -> GoalId {
        self.handle.goal_id()
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
    handle: ExecutingGoalHandle<G>,
    goal: G,
    canceling: bool,
}

struct Finished<A: RosAction> {
    handle: ExecutingGoalHandle<A::Goal>,
    status: GoalEnd,
    result: A::Result,
}

/// An action server owning at most one active goal (see the module docs).
pub struct GoalServer<A: RosAction> {
    server: Arc<Server<A>>,
    name: String,
    active: Option<Active<A::Goal>>,
    /// A cancel request read but not yet answered, with the goal agreed to (taken before the
    /// answer is awaited, so a dropped [`GoalServer::next_event`] future never answers twice).
    pending_cancel: Option<(CancelHandle, Option<GoalId>)>,
    /// A goal that went CANCELING and that the node has not yet been told of (kept so that a
    /// dropped [`GoalServer::next_event`] future reports it on the next call).
    unreported_cancel: Option<GoalId>,
    results: Option<mpsc::UnboundedSender<Finished<A>>>,
    delivery: Option<tokio::task::JoinHandle<()>>,
    result_timeout: Duration,
    throttle: Mutex<crate::LogThrottle>,
}

impl<A> GoalServer<A>
where
    A: RosAction + 'static,
{
    /// Serves `action` (resolved and remapped like a topic name) on a running node. Needs a tokio
    /// runtime (the result delivery task is spawned on it).
    pub fn create(node: &mut RosNode, action: &str, config: GoalServerConfig) -> Result<Self, ActionError> {
        let full = node
            .names()
            .resolve(action)
            .map_err(|e| ActionError::Name(action.to_owned(), e.to_string()))?;
        let name = Name::parse(&full).map_err(|e| ActionError::Name(full.clone(), format!("{e:?}")))?;
        Self::on_node(node.inner(), &name, config)
    }

    /// Serves the action `name` on a bare ros2-client node. Needs a tokio runtime.
    pub fn on_node(node: &mut Node, name: &Name, config: GoalServerConfig) -> Result<Self, ActionError> {
        let server = node
            .create_action_server::<A::Goal, A::Result, A::Feedback>(
                ServiceMapping::Enhanced,
                name,
                &A::type_name(),
                server_qos(),
            )
            .map_err(|e| ActionError::Create(name.to_string(), format!("{e:?}")))?;
        let server = Arc::new(AsyncActionServer::new(server));
        let (tx, rx) = mpsc::unbounded_channel();
        let delivery = tokio::spawn(deliver_results::<A>(
            server.clone(),
            rx,
            config.result_timeout,
            name.to_string(),
        ));
        Ok(GoalServer {
            server,
            name: name.to_string(),
            active: None,
            pending_cancel: None,
            unreported_cancel: None,
            results: Some(tx),
            delivery: Some(delivery),
            result_timeout: config.result_timeout,
            throttle: Mutex::new(crate::LogThrottle::new(Duration::from_secs(2))),
        })
    }

    /// The active goal, if any (also while it is being canceled).
    pub fn active_goal(&self) -> Option<&A::Goal> {
        self.active.as_ref().map(|a| &a.goal)
    }

    /// The active goal's id.
    pub fn active_id(&self) -> Option<GoalId> {
        self.active.as_ref().map(|a| a.handle.goal_id())
    }

    /// Whether the active goal is being canceled.
    pub fn is_canceling(&self) -> bool {
        self.active.as_ref().is_some_and(|a| a.canceling)
    }

    /// Waits for the next goal or cancel request. Cancel-safe: a request is never half taken, so
    /// this can be one branch of a `tokio::select!` that other branches win.
    pub async fn next_event(&mut self) -> ActionEvent<A::Goal> {
        loop {
            if let Some((handle, goal)) = self.pending_cancel.take()
                && let Err(e) = self.server.respond_to_cancel_requests(&handle, goal.into_iter()).await
            {
                self.warn(
                    "cancel-response",
                    format_args!("{}: cannot answer a cancel request: {e:?}", self.name),
                );
            }
            if let Some(id) = self.unreported_cancel.take() {
                // The goal may have ended since (pre-empted while this future was dropped).
                if self.active_id() == Some(id) {
                    return ActionEvent::CancelRequested(id);
                }
            }
            tokio::select! {
                goal = self.server.receive_new_goal() => match goal {
                    Ok(handle) => match self.server.get_new_goal(handle.clone()) {
                        Some(goal) => return ActionEvent::Goal(GoalRequest { handle, goal }),
                        None => self.warn("goal-lost", format_args!("{}: goal {:?} vanished before it was read", self.name, handle.goal_id())),
                    },
                    Err(e) => self.warn("goal-read", format_args!("{}: undecodable goal request dropped: {e:?}", self.name)),
                },
                cancel = self.server.receive_cancel_request() => match cancel {
                    Ok(handle) => {
                        let named = self.active.as_mut().filter(|a| handle.contains_goal(&a.handle.goal_id()));
                        let agreed = match named {
                            Some(a) if a.canceling => {
                                // rcl_action refuses it too: a CANCELING goal cannot move to
                                // CANCELING again (`rcl_action_goal_handle_is_cancelable`).
                                info!("{}: goal {:?} is already canceling: repeated cancel refused", self.name, a.handle.goal_id());
                                None
                            }
                            Some(a) => {
                                a.canceling = true;
                                let id = a.handle.goal_id();
                                info!("{}: goal {id:?} is canceling", self.name);
                                self.unreported_cancel = Some(id);
                                Some(id)
                            }
                            None => {
                                info!("{}: cancel request refused: it names no active goal", self.name);
                                None
                            }
                        };
                        self.pending_cancel = Some((handle, agreed));
                    }
                    Err(e) => self.warn("cancel-read", format_args!("{}: undecodable cancel request dropped: {e:?}", self.name)),
                },
            }
        }
    }

    /// Accepts a goal and makes it the active one. If a goal was active, it ends first:
    /// ABORTED with the result `preempted` builds from it (CANCELED if it was being canceled).
    pub async fn accept(
        &mut self,
        request: GoalRequest<A::Goal>,
        preempted: impl FnOnce(&A::Goal) -> A::Result,
    ) -> Result<(), ActionError> {
        let id = request.id();
        if let Some(old) = self.active.take() {
            let status = if old.canceling {
                GoalEnd::Canceled
            } else {
                GoalEnd::Aborted
            };
            info!(
                "{}: goal {:?} preempted by goal {id:?}: it ends {status:?}",
                self.name,
                old.handle.goal_id()
            );
            let result = preempted(&old.goal);
            self.queue(old.handle, status, result);
        }
        let accepted = self
            .server
            .accept_goal(request.handle)
            .await
            .map_err(|e| ActionError::Goal(id, format!("cannot accept: {e:?}")))?;
        let executing = self
            .server
            .start_executing_goal(accepted)
            .await
            .map_err(|e| ActionError::Goal(id, format!("cannot start: {e:?}")))?;
        info!("{}: goal {id:?} accepted", self.name);
        self.active = Some(Active {
            handle: executing,
            goal: request.goal,
            canceling: false,
        });
        Ok(())
    }

    /// Rejects a goal; the reason is logged (a ROS 2 goal response cannot carry it).
    pub async fn reject(&mut self, request: GoalRequest<A::Goal>, reason: &str) {
        let id = request.id();
        info!("{}: goal {id:?} rejected: {reason}", self.name);
        if let Err(e) = self.server.reject_goal(request.handle).await {
            self.warn(
                "reject",
                format_args!("{}: cannot send the rejection of {id:?}: {e:?}", self.name),
            );
        }
    }

    /// Publishes feedback on the active goal.
    pub async fn feedback(&self, feedback: A::Feedback) -> Result<(), ActionError> {
        let active = self.active.as_ref().ok_or(ActionError::NoActiveGoal)?;
        let id = active.handle.goal_id();
        self.server
            .publish_feedback(active.handle.clone(), feedback)
            .await
            .map_err(|e| ActionError::Goal(id, format!("cannot publish feedback: {e:?}")))
    }

    /// Ends the active goal with `status` and `result` (delivered in the background, see the
    /// module docs). Returns the goal's id, or `None` when no goal was active.
    pub fn finish(&mut self, status: GoalEnd, result: A::Result) -> Option<GoalId> {
        let active = self.active.take()?;
        let id = active.handle.goal_id();
        info!("{}: goal {id:?} ends {status:?}", self.name);
        self.queue(active.handle, status, result);
        Some(id)
    }

    /// Ends the active goal (if any) ABORTED with `result`, then waits until the queued results
    /// are delivered, at most [`CLOSE_WAIT`] (a node shutting down must not hang on a client
    /// that never asks for its result); what is left then is dropped with a warning. Last, it
    /// waits up to [`RESULT_ACK_WAIT`] for the clients to acknowledge the results sent: the
    /// server's endpoints are disposed when it is dropped, and a peer that learns of the dispose
    /// before it has taken a result in flight drops the result (Fast DDS reads discovery and
    /// data on different threads: an rclpy client's result at shutdown went missing that way).
    pub async fn close(mut self, result: A::Result) {
        if self.active.is_some() {
            self.finish(GoalEnd::Aborted, result);
        }
        self.results = None;
        if let Some(mut task) = self.delivery.take() {
            let wait = CLOSE_WAIT.min(self.result_timeout + Duration::from_millis(100));
            if tokio::time::timeout(wait, &mut task).await.is_err() {
                warn!(
                    "{}: results still undelivered after {wait:?} at close: dropped",
                    self.name
                );
                task.abort();
            }
        }
        let server = self.server.clone();
        match tokio::task::spawn_blocking(move || server.wait_for_result_acknowledgments(RESULT_ACK_WAIT)).await {
            Ok(Ok(true)) => {}
            Ok(Ok(false)) => warn!(
                "{}: results not acknowledged by every client within {RESULT_ACK_WAIT:?} at close",
                self.name
            ),
            Ok(Err(e)) => warn!("{}: cannot wait for the results' acknowledgments: {e:?}", self.name),
            Err(e) => warn!("{}: the wait for the results' acknowledgments failed: {e}", self.name),
        }
    }

    fn queue(&self, handle: ExecutingGoalHandle<A::Goal>, status: GoalEnd, result: A::Result) {
        let id = handle.goal_id();
        let sent = self
            .results
            .as_ref()
            .is_some_and(|tx| tx.send(Finished { handle, status, result }).is_ok());
        if !sent {
            warn!(
                "{}: result of goal {id:?} not delivered: the server is closing",
                self.name
            );
        }
    }

    fn warn(&self, key: &'static str, message: std::fmt::Arguments<'_>) {
        if let Ok(mut throttle) = self.throttle.lock() {
            crate::warn_throttled!(throttle, key, "{message}");
        }
    }
}

impl<A: RosAction> Drop for GoalServer<A> {
    fn drop(&mut self) {
        if let Some(active) = &self.active {
            warn!(
                "{}: dropped with goal {:?} active; its client gets no result",
                self.name,
                active.handle.goal_id()
            );
        }
    }
}

/// How long one attempt to send a result waits for its `get_result` request before it looks again.
/// Each attempt reads the result service's requests and keeps those of other goals in
/// ros2-client's table, where their own attempts find them on their next look: this bounds how
/// long a request taken by another goal's attempt waits.
const RESULT_LOOK: Duration = Duration::from_millis(50);

/// Delivers each queued result in a task of its own, so a client that never asks for its result
/// holds up no other goal's; each waits at most `timeout`. Ends once the queue is closed and every
/// delivery has ended.
async fn deliver_results<A: RosAction + 'static>(
    server: Arc<Server<A>>,
    mut queue: mpsc::UnboundedReceiver<Finished<A>>,
    timeout: Duration,
    name: String,
) {
    let mut deliveries = tokio::task::JoinSet::new();
    loop {
        tokio::select! {
            finished = queue.recv() => match finished {
                Some(finished) => {
                    deliveries.spawn(deliver_one::<A>(server.clone(), finished, timeout, name.clone()));
                }
                None => break,
            },
            Some(_) = deliveries.join_next(), if !deliveries.is_empty() => {}
        }
    }
    while deliveries.join_next().await.is_some() {}
}

/// Sends one result once its client asks for it, waiting at most `timeout`.
async fn deliver_one<A: RosAction>(server: Arc<Server<A>>, finished: Finished<A>, timeout: Duration, name: String) {
    let Finished { handle, status, result } = finished;
    let id = handle.goal_id();
    let started = tokio::time::Instant::now();
    let deadline = started + timeout;
    loop {
        let left = deadline.saturating_duration_since(tokio::time::Instant::now());
        if left.is_zero() {
            break;
        }
        // Cancel-safe: ros2-client takes a request and files or answers it in the same poll.
        let attempt = server.send_result_response(handle.clone(), status, result.clone());
        match tokio::time::timeout(RESULT_LOOK.min(left), attempt).await {
            Ok(Ok(())) => {
                tracing::debug!("{name}: result of {id:?} sent after {:?}", started.elapsed());
                return;
            }
            Ok(Err(e)) => {
                warn!("{name}: cannot send the result of goal {id:?}: {e:?}");
                return;
            }
            Err(_) => {}
        }
    }
    warn!("{name}: no client asked for the result of goal {id:?} within {timeout:?}; dropped");
    if status == GoalEnd::Aborted {
        // ros2-client sets a goal's end status only when it sends the result: without this the
        // goal would be reported EXECUTING for ever. A SUCCEEDED or CANCELED goal is left as it
        // was last reported rather than labelled ABORTED, which it is not.
        let _ = server.abort_executing_goal(handle).await;
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
