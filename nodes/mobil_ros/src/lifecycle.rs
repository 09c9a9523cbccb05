//! The managed (lifecycle) node, as `nav2_lifecycle_manager` and `ros2 lifecycle` drive one,
//! with Nav2's bond: the I/O around [`mobil_lifecycle`]'s state machine and heartbeats.
//!
//! [`Lifecycle::serve`] offers the five `lifecycle_msgs` services under the node's name
//! (`~/change_state`, `~/get_state`, `~/get_available_states`, `~/get_available_transitions`,
//! `~/get_transition_graph`) and publishes `~/transition_event` (reliable, volatile, depth 10),
//! answering as `rcl_lifecycle` does. A node's select loop takes [`Lifecycle::next`]: it
//! answers the queries and the bond on its own, and yields a [`Transition`] when a requested
//! transition needs the node's callback (ending a goal at deactivation); the node then calls
//! [`Lifecycle::complete`] with its answer, which replies to the request.
//!
//! With `autostart` (the default) the node configures and activates itself at start and
//! behaves as an unmanaged node; with `autostart:=false` it waits unconfigured for a manager.
//! The node is *active* only in the active state: its [`ActiveGate`], shared with its action
//! servers ([`crate::action::GoalServer::gate`]), refuses goals in every other state.
//!
//! The bond (topic `bond`, `bond/msg/Status`, id = the node's name): heartbeats every
//! `bond_heartbeat_period` from an activation a manager asked for until the node leaves the
//! active state, then `active = false` three times over 100 ms. A self-started node has no
//! manager and sends none. The manager's own heartbeats are watched, and its loss logged.

use crate::config::Decl;
use crate::log::LogThrottle;
use crate::node::{respond, RosNode};
use crate::warn_throttled;
use anyhow::anyhow;
use mobil_lifecycle::{BondSettings, Event, Heart, Machine, PeerChange, TransitionDef, GRAPH};
pub use mobil_lifecycle::{CallbackReturn, State, Step};
use mobil_msgs::bond::msg::Status;
use mobil_msgs::lifecycle_msgs::msg::{
    State as StateMsg, Transition as TransitionMsg, TransitionDescription, TransitionEvent,
};
use mobil_msgs::lifecycle_msgs::srv::{
    ChangeState, ChangeStateRequest, ChangeStateResponse, GetAvailableStates, GetAvailableStatesRequest,
    GetAvailableStatesResponse, GetAvailableTransitions, GetAvailableTransitionsRequest,
    GetAvailableTransitionsResponse, GetState, GetStateRequest, GetStateResponse,
};
use ros2_client::{Publisher, RmwRequestId, Server, Subscription};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tracing::{info, warn};

/// Nav2's bond heartbeat timeout (`nav2_util::LifecycleNode::createBond`): 4 s.
pub const BOND_TIMEOUT: Duration = Duration::from_secs(4);
/// The largest `bond_heartbeat_period` (s): a heartbeat rarer than the timeout breaks the bond.
pub const MAX_HEARTBEAT_PERIOD_S: f64 = 2.0;
/// The shortest heartbeat period (s): a smaller positive value is taken as this, so that no
/// setting makes the node flood `bond`.
pub const MIN_HEARTBEAT_PERIOD_S: f64 = 0.01;

/// The parameters of a managed node, nested by each node's configuration.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Managed {
    /// Configure and activate at start, with no manager (`autostart`).
    pub autostart: bool,
    /// Bond heartbeat period (s); 0 disables the bond (`bond_heartbeat_period`).
    pub bond_heartbeat_period: f64,
}

impl Managed {
    /// Declares `autostart` (true, read-only) and `bond_heartbeat_period` (0.1 s, Nav2's name
    /// and default; 0 disables the bond; read-only, as Nav2 reads it once).
    pub fn declare(d: &mut Decl<Managed>) {
        d.boolean(
            "autostart",
            true,
            "configure and activate at start; false: wait unconfigured for a lifecycle manager \
             (nav2_lifecycle_manager) to drive ~/change_state",
            |c, v| c.autostart = v,
        )
        .read_only();
        d.double(
            "bond_heartbeat_period",
            0.1,
            "period of the bond heartbeats to the lifecycle manager while active after its activate \
             (Nav2's parameter); 0 disables the bond; a positive value below 0.01 is taken as 0.01 [s]",
            |c, v| c.bond_heartbeat_period = v,
        )
        .min(0.0)
        .max(MAX_HEARTBEAT_PERIOD_S)
        .read_only();
    }

    /// The heartbeat period: zero (no bond), or at least [`MIN_HEARTBEAT_PERIOD_S`].
    pub fn heartbeat_period(&self) -> Duration {
        let p = self.bond_heartbeat_period;
        let p = if p > 0.0 { p.max(MIN_HEARTBEAT_PERIOD_S) } else { 0.0 };
        crate::time::seconds(p, MAX_HEARTBEAT_PERIOD_S)
    }
}

/// Whether the node is active, shared by whatever must refuse work otherwise.
#[derive(Debug, Clone, Default)]
pub struct ActiveGate(Arc<AtomicBool>);

impl ActiveGate {
    /// A gate that is always open: an unmanaged server.
    pub fn open() -> Self {
        ActiveGate(Arc::new(AtomicBool::new(true)))
    }

    /// Whether the node is active.
    pub fn is_open(&self) -> bool {
        self.0.load(Ordering::Acquire)
    }

    fn set(&self, open: bool) {
        self.0.store(open, Ordering::Release);
    }
}

/// A requested transition waiting for the node's callback: answer it with
/// [`Lifecycle::complete`].
#[derive(Debug)]
#[must_use = "a transition is answered with Lifecycle::complete"]
pub struct Transition {
    step: Step,
    from: State,
    request: RmwRequestId,
}

impl Transition {
    /// The callback to run.
    pub fn step(&self) -> Step {
        self.step
    }

    /// The state the transition started from.
    pub fn from(&self) -> State {
        self.from
    }

    /// Whether it leaves the active state (deactivate, or shutdown from active): a goal under
    /// way ends, with the one zero command.
    pub fn leaves_active(&self) -> bool {
        self.from == State::Active
    }
}

fn state_msg(s: State) -> StateMsg {
    StateMsg {
        id: s.id(),
        label: s.label().to_owned(),
    }
}

fn description(t: &TransitionDef) -> TransitionDescription {
    TransitionDescription {
        transition: TransitionMsg {
            id: t.id,
            label: t.label.to_owned(),
        },
        start_state: state_msg(t.start),
        goal_state: state_msg(t.goal),
    }
}

/// A request or a message the lifecycle handles.
enum Incoming {
    Change(RmwRequestId, ChangeStateRequest),
    GetState(RmwRequestId),
    States(RmwRequestId),
    Transitions(RmwRequestId),
    Graph(RmwRequestId),
    Bond(Status),
    Due,
    Undecodable(&'static str, String),
}

/// The managed-node interface of one node.
pub struct Lifecycle {
    machine: Machine,
    change: Server<ChangeStateRequest, ChangeStateResponse>,
    get_state: Server<GetStateRequest, GetStateResponse>,
    states: Server<GetAvailableStatesRequest, GetAvailableStatesResponse>,
    transitions: Server<GetAvailableTransitionsRequest, GetAvailableTransitionsResponse>,
    graph: Server<GetAvailableTransitionsRequest, GetAvailableTransitionsResponse>,
    events: Publisher<TransitionEvent>,
    bond_out: Publisher<Status>,
    bond_in: Subscription<Status>,
    heart: Heart,
    gate: ActiveGate,
    /// A manager activated the node (its bond runs while active).
    bonded: bool,
    fqn: String,
    throttle: LogThrottle,
}

impl Lifecycle {
    /// Serves the managed-node interface on `node`; with `autostart` the node is configured and
    /// activated at once (its events published, no bond).
    pub fn serve(node: &mut RosNode, managed: &Managed) -> anyhow::Result<Self> {
        let id = node.names().node().to_owned();
        let fqn = node.names().fully_qualified_node();
        let qos = crate::qos::reliable(10);
        let mut lifecycle = Lifecycle {
            machine: Machine::new(),
            change: node.service::<ChangeState>("~/change_state")?,
            get_state: node.service::<GetState>("~/get_state")?,
            states: node.service::<GetAvailableStates>("~/get_available_states")?,
            transitions: node.service::<GetAvailableTransitions>("~/get_available_transitions")?,
            graph: node.service::<GetAvailableTransitions>("~/get_transition_graph")?,
            events: node.publisher::<TransitionEvent>("~/transition_event", &qos)?,
            bond_out: node.publisher::<Status>("bond", &crate::qos::reliable(5))?,
            bond_in: node.subscription::<Status>("bond", &crate::qos::reliable(100))?,
            heart: Heart::new(BondSettings {
                id,
                period: managed.heartbeat_period(),
                timeout: BOND_TIMEOUT,
            }),
            gate: ActiveGate::default(),
            bonded: false,
            fqn,
            throttle: LogThrottle::new(Duration::from_secs(2)),
        };
        if managed.autostart {
            for id in [1, 3] {
                lifecycle
                    .machine
                    .change(id, "", |_, _| CallbackReturn::Success)
                    .map_err(|e| anyhow!("autostart: {e}"))?
                    .events
                    .into_iter()
                    .for_each(|e| lifecycle.publish(e));
            }
            lifecycle.gate.set(true);
            info!("{}: autostart: active", lifecycle.fqn);
        } else {
            info!(
                "{}: unconfigured, waiting for a lifecycle manager (autostart false)",
                lifecycle.fqn
            );
        }
        Ok(lifecycle)
    }

    /// The gate the node's servers refuse goals by.
    pub fn gate(&self) -> ActiveGate {
        self.gate.clone()
    }

    /// Whether the node is active.
    pub fn is_active(&self) -> bool {
        self.gate.is_open()
    }

    /// The current state.
    pub fn state(&self) -> State {
        self.machine.state()
    }

    /// Waits for a transition that needs the node's callback, answering the queries, the bond
    /// and the refused requests on the way. Cancel-safe (for `tokio::select!`): a request is
    /// never half taken.
    pub async fn next(&mut self) -> Transition {
        loop {
            match self.receive().await {
                Incoming::Change(request, ChangeStateRequest { transition }) => {
                    let from = self.machine.state();
                    match self.machine.begin(transition.id, &transition.label) {
                        Ok((step, event)) => {
                            info!("{}: lifecycle {step:?} from {from}", self.fqn);
                            self.moved(event);
                            return Transition { step, from, request };
                        }
                        Err(refused) => {
                            warn_throttled!(
                                self.throttle,
                                "refused",
                                "{}: change_state refused: {refused}",
                                self.fqn
                            );
                            self.reply_change(request, false);
                        }
                    }
                }
                Incoming::GetState(request) => {
                    let reply = GetStateResponse {
                        current_state: state_msg(self.machine.state()),
                    };
                    respond(&self.get_state, request, reply, "get_state", &mut self.throttle);
                }
                Incoming::States(request) => {
                    let reply = GetAvailableStatesResponse {
                        available_states: State::ALL.into_iter().map(state_msg).collect(),
                    };
                    respond(&self.states, request, reply, "get_available_states", &mut self.throttle);
                }
                Incoming::Transitions(request) => {
                    let reply = GetAvailableTransitionsResponse {
                        available_transitions: self.machine.available().map(description).collect(),
                    };
                    respond(
                        &self.transitions,
                        request,
                        reply,
                        "get_available_transitions",
                        &mut self.throttle,
                    );
                }
                Incoming::Graph(request) => {
                    let reply = GetAvailableTransitionsResponse {
                        available_transitions: GRAPH.iter().map(description).collect(),
                    };
                    respond(&self.graph, request, reply, "get_transition_graph", &mut self.throttle);
                }
                Incoming::Bond(status) => {
                    let change = self
                        .heart
                        .receive(&status.id, &status.instance_id, status.active, Instant::now());
                    self.tell_peer(change);
                }
                Incoming::Due => self.beat(Instant::now()),
                Incoming::Undecodable(what, e) => {
                    warn_throttled!(
                        self.throttle,
                        "undecodable",
                        "{}: undecodable {what} dropped: {e}",
                        self.fqn
                    );
                }
            }
        }
    }

    /// Ends a transition with the node's answer: the state moves on (an error through
    /// errorprocessing, whose callback succeeds: back to unconfigured), the events go out, the
    /// bond starts at an activation and the request is answered.
    pub fn complete(&mut self, transition: Transition, answer: CallbackReturn) {
        let (event, mut next) = self.machine.finish(answer);
        self.moved(event);
        while next.is_some() {
            let (event, after) = self.machine.finish(CallbackReturn::Success);
            self.moved(event);
            next = after;
        }
        if transition.step == Step::Activate && self.machine.state() == State::Active {
            self.bonded = true;
            self.heart.start(Instant::now(), new_instance_id());
            self.beat(Instant::now());
            if self.heart.is_beating() {
                info!("{}: bond to the lifecycle manager started", self.fqn);
            }
        }
        info!(
            "{}: lifecycle {:?}: {}",
            self.fqn,
            transition.step,
            self.machine.state()
        );
        self.reply_change(transition.request, answer == CallbackReturn::Success);
    }

    /// Breaks a running bond as the node leaves: its `active = false` three times over 100 ms,
    /// as at a deactivation (call it first at shutdown, before anything that may take time).
    pub async fn close(mut self) {
        if !self.heart.is_beating() {
            return;
        }
        self.heart.stop(Instant::now());
        while let Some(due) = self.heart.due() {
            tokio::time::sleep_until(tokio::time::Instant::from_std(due)).await;
            self.beat(Instant::now());
        }
        info!("{}: bond to the lifecycle manager broken (shutting down)", self.fqn);
    }

    fn reply_change(&mut self, request: RmwRequestId, success: bool) {
        respond(
            &self.change,
            request,
            ChangeStateResponse { success },
            "change_state",
            &mut self.throttle,
        );
    }

    /// A move of the machine: its event, the gate, and the bond broken when leaving active
    /// (and started again when a failed deactivation goes back to active).
    fn moved(&mut self, event: Event) {
        self.publish(event);
        self.gate.set(self.machine.state() == State::Active);
        if event.start == State::Active && self.heart.is_beating() {
            self.heart.stop(Instant::now());
            self.beat(Instant::now());
            info!("{}: bond to the lifecycle manager broken (leaving active)", self.fqn);
        }
        if event.start == State::Deactivating && event.goal == State::Active && self.bonded {
            self.heart.start(Instant::now(), new_instance_id());
            self.beat(Instant::now());
        }
    }

    fn publish(&mut self, event: Event) {
        // rcl_lifecycle leaves the timestamp and the transition zero; so does this.
        let msg = TransitionEvent {
            timestamp: 0,
            transition: TransitionMsg::default(),
            start_state: state_msg(event.start),
            goal_state: state_msg(event.goal),
        };
        if let Err(e) = self.events.publish(msg) {
            warn_throttled!(
                self.throttle,
                "event",
                "{}: cannot publish a transition event: {e:?}",
                self.fqn
            );
        }
    }

    /// Sends what the bond has due, and checks the manager's heartbeats.
    fn beat(&mut self, now: Instant) {
        if let Some(beat) = self.heart.poll(now) {
            let settings = self.heart.settings();
            let msg = Status {
                header: mobil_msgs::std_msgs::msg::Header {
                    stamp: crate::time::stamp_from_nanos(steady_nanos()),
                    frame_id: String::new(),
                },
                id: settings.id.clone(),
                instance_id: self.heart.instance_id().to_owned(),
                active: beat.active,
                heartbeat_timeout: settings.timeout.as_secs_f32(),
                heartbeat_period: settings.period.as_secs_f32(),
            };
            if let Err(e) = self.bond_out.publish(msg) {
                warn_throttled!(
                    self.throttle,
                    "bond",
                    "{}: cannot send a bond heartbeat: {e:?}",
                    self.fqn
                );
            }
        }
        let change = self.heart.check_peer(now);
        self.tell_peer(change);
    }

    fn tell_peer(&mut self, change: Option<PeerChange>) {
        match change {
            Some(PeerChange::Formed) => info!("{}: bond formed with the lifecycle manager", self.fqn),
            Some(PeerChange::Lost(silent)) => warn!(
                "{}: bond broken: no heartbeat from the lifecycle manager for {:.1} s (the node stays {})",
                self.fqn,
                silent.as_secs_f64(),
                self.machine.state()
            ),
            Some(PeerChange::Left) => warn!(
                "{}: bond broken by the lifecycle manager (the node stays {})",
                self.fqn,
                self.machine.state()
            ),
            None => {}
        }
    }

    async fn receive(&self) -> Incoming {
        let due = self.heart.due();
        let wake = async {
            match due {
                Some(at) => tokio::time::sleep_until(tokio::time::Instant::from_std(at)).await,
                None => std::future::pending().await,
            }
        };
        tokio::select! {
            r = self.change.async_receive_request() => match r {
                Ok((id, request)) => Incoming::Change(id, request),
                Err(e) => Incoming::Undecodable("change_state request", format!("{e:?}")),
            },
            r = self.get_state.async_receive_request() => match r {
                Ok((id, _)) => Incoming::GetState(id),
                Err(e) => Incoming::Undecodable("get_state request", format!("{e:?}")),
            },
            r = self.states.async_receive_request() => match r {
                Ok((id, _)) => Incoming::States(id),
                Err(e) => Incoming::Undecodable("get_available_states request", format!("{e:?}")),
            },
            r = self.transitions.async_receive_request() => match r {
                Ok((id, _)) => Incoming::Transitions(id),
                Err(e) => Incoming::Undecodable("get_available_transitions request", format!("{e:?}")),
            },
            r = self.graph.async_receive_request() => match r {
                Ok((id, _)) => Incoming::Graph(id),
                Err(e) => Incoming::Undecodable("get_transition_graph request", format!("{e:?}")),
            },
            r = self.bond_in.async_take() => match r {
                Ok((status, _)) => Incoming::Bond(status),
                Err(e) => Incoming::Undecodable("bond status", format!("{e:?}")),
            },
            _ = wake => Incoming::Due,
        }
    }
}

/// A random instance id, as bondcpp makes one (a v4 UUID in text).
fn new_instance_id() -> String {
    uuid::Uuid::new_v4().to_string()
}

/// Nanoseconds of the steady clock since the process's first call (the bond's stamp, as
/// bondcpp stamps it from the steady clock; nobody reads it).
fn steady_nanos() -> i64 {
    static ORIGIN: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    let origin = *ORIGIN.get_or_init(Instant::now);
    i64::try_from(origin.elapsed().as_nanos()).unwrap_or(i64::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{load, Config};
    use crate::params::ParamValues;
    use ros2_client::ParameterValue;

    #[derive(Debug, Clone, Default)]
    struct Node {
        managed: Managed,
    }

    impl Config for Node {
        fn declare(d: &mut Decl<Self>) {
            d.nest(|c: &mut Node| &mut c.managed, Managed::declare);
        }
    }

    #[test]
    fn managed_parameters_are_nav2s() {
        let specs = Decl::<Node>::of().specs();
        let c: Node = load(&ParamValues::defaults(&specs)).unwrap();
        assert!(c.managed.autostart);
        assert_eq!(c.managed.heartbeat_period(), Duration::from_millis(100));
        let spec = |name: &str| specs.iter().find(|s| s.name == name).unwrap();
        assert!(spec("autostart").read_only);
        let check = |v: f64| spec("bond_heartbeat_period").check(&ParameterValue::Double(v));
        assert!(check(0.0).is_ok() && check(2.0).is_ok());
        assert!(check(-0.1).is_err() && check(2.1).is_err() && check(f64::NAN).is_err());
        let off = Managed {
            autostart: false,
            bond_heartbeat_period: 0.0,
        };
        assert_eq!(off.heartbeat_period(), Duration::ZERO);
    }

    /// The messages of the graph as rcl's `get_transition_graph` gives them.
    #[test]
    fn descriptions_carry_ids_and_labels() {
        let d = description(&GRAPH[0]);
        assert_eq!((d.transition.id, d.transition.label.as_str()), (1, "configure"));
        assert_eq!((d.start_state.id, d.goal_state.id), (1, 10));
        assert_eq!(d.goal_state.label, "configuring");
        assert_eq!(new_instance_id().len(), 36);
        assert_ne!(new_instance_id(), new_instance_id());
    }
}
