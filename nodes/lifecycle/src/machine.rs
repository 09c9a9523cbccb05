//! The managed-node state machine of ROS 2, as `rcl_lifecycle` registers its default one.
//!
//! Four primary states (unconfigured, inactive, active, finalized), six transition states in
//! which the node's callback runs (configuring, cleaningup, shuttingdown, activating,
//! deactivating, errorprocessing), and the 25 transitions between them ([`GRAPH`], in
//! `rcl_lifecycle`'s registration order, which `get_transition_graph` answers in).
//!
//! A request ([`Machine::begin`]) names a transition by id, or by label (a non-empty label wins
//! and is looked up among the current state's transitions, so `shutdown` is 5, 6 or 7). It
//! moves the machine into the transition state and names the callback the node runs
//! ([`Step`]); the callback's answer ([`Machine::finish`]) moves it on: SUCCESS to the target
//! primary state, FAILURE back to where it started (shutting down goes to finalized either
//! way), ERROR to errorprocessing, where the error callback decides between unconfigured
//! (SUCCESS) and finalized. Every move is one [`Event`] (`~/transition_event`). A request the
//! current state does not offer is refused ([`Refused`]) and changes nothing; unlike
//! `rclpy.lifecycle`, whose executor dies on it, the node answers `success = false` and goes on.
//!
//! ```
//! use mobil_lifecycle::{CallbackReturn, Machine, State, Step};
//! let mut m = Machine::new();
//! let (step, _) = m.begin(1, "").unwrap(); // configure
//! assert_eq!(step, Step::Configure);
//! assert_eq!(m.state(), State::Configuring);
//! let (event, next) = m.finish(CallbackReturn::Success);
//! assert_eq!((event.start, event.goal, next), (State::Configuring, State::Inactive, None));
//! assert!(m.begin(4, "").is_err()); // deactivate: not from inactive
//! let change = m.change(0, "activate", |_, _| CallbackReturn::Success).unwrap();
//! assert!(change.success);
//! assert_eq!(m.state(), State::Active);
//! ```

use thiserror::Error;

/// A state of the managed node (`lifecycle_msgs/msg/State` ids and labels).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum State {
    Unknown,
    Unconfigured,
    Inactive,
    Active,
    Finalized,
    Configuring,
    CleaningUp,
    ShuttingDown,
    Activating,
    Deactivating,
    ErrorProcessing,
}

impl State {
    /// Every state, in id order (the answer of `get_available_states`).
    pub const ALL: [State; 11] = [
        State::Unknown,
        State::Unconfigured,
        State::Inactive,
        State::Active,
        State::Finalized,
        State::Configuring,
        State::CleaningUp,
        State::ShuttingDown,
        State::Activating,
        State::Deactivating,
        State::ErrorProcessing,
    ];

    /// The id in `lifecycle_msgs/msg/State`.
    pub fn id(self) -> u8 {
        match self {
            State::Unknown => 0,
            State::Unconfigured => 1,
            State::Inactive => 2,
            State::Active => 3,
            State::Finalized => 4,
            State::Configuring => 10,
            State::CleaningUp => 11,
            State::ShuttingDown => 12,
            State::Activating => 13,
            State::Deactivating => 14,
            State::ErrorProcessing => 15,
        }
    }

    /// The label `rcl_lifecycle` gives it.
    pub fn label(self) -> &'static str {
        match self {
            State::Unknown => "unknown",
            State::Unconfigured => "unconfigured",
            State::Inactive => "inactive",
            State::Active => "active",
            State::Finalized => "finalized",
            State::Configuring => "configuring",
            State::CleaningUp => "cleaningup",
            State::ShuttingDown => "shuttingdown",
            State::Activating => "activating",
            State::Deactivating => "deactivating",
            State::ErrorProcessing => "errorprocessing",
        }
    }

    /// A primary state (one a node rests in), not a transition state.
    pub fn is_primary(self) -> bool {
        self.id() <= 4
    }

    /// The callback the node runs in this transition state.
    fn step(self) -> Option<Step> {
        match self {
            State::Configuring => Some(Step::Configure),
            State::CleaningUp => Some(Step::CleanUp),
            State::ShuttingDown => Some(Step::Shutdown),
            State::Activating => Some(Step::Activate),
            State::Deactivating => Some(Step::Deactivate),
            State::ErrorProcessing => Some(Step::Error),
            _ => None,
        }
    }
}

impl std::fmt::Display for State {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

/// One registered transition (`lifecycle_msgs/msg/TransitionDescription`): its id and label,
/// the state it starts from and the state it goes to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TransitionDef {
    pub id: u8,
    pub label: &'static str,
    pub start: State,
    pub goal: State,
}

const fn t(id: u8, label: &'static str, start: State, goal: State) -> TransitionDef {
    TransitionDef { id, label, start, goal }
}

const SUCCESS: &str = "transition_success";
const FAILURE: &str = "transition_failure";
const ERROR: &str = "transition_error";

/// The transition graph of `rcl_lifecycle`'s default state machine, in its registration order
/// (`default_state_machine.c`): the answer of `get_transition_graph`.
pub const GRAPH: [TransitionDef; 25] = {
    use State::*;
    [
        t(1, "configure", Unconfigured, Configuring),
        t(10, SUCCESS, Configuring, Inactive),
        t(11, FAILURE, Configuring, Unconfigured),
        t(12, ERROR, Configuring, ErrorProcessing),
        t(2, "cleanup", Inactive, CleaningUp),
        t(20, SUCCESS, CleaningUp, Unconfigured),
        t(21, FAILURE, CleaningUp, Inactive),
        t(22, ERROR, CleaningUp, ErrorProcessing),
        t(3, "activate", Inactive, Activating),
        t(30, SUCCESS, Activating, Active),
        t(31, FAILURE, Activating, Inactive),
        t(32, ERROR, Activating, ErrorProcessing),
        t(4, "deactivate", Active, Deactivating),
        t(40, SUCCESS, Deactivating, Inactive),
        t(41, FAILURE, Deactivating, Active),
        t(42, ERROR, Deactivating, ErrorProcessing),
        t(5, "shutdown", Unconfigured, ShuttingDown),
        t(6, "shutdown", Inactive, ShuttingDown),
        t(7, "shutdown", Active, ShuttingDown),
        t(50, SUCCESS, ShuttingDown, Finalized),
        t(51, FAILURE, ShuttingDown, Finalized),
        t(52, ERROR, ShuttingDown, ErrorProcessing),
        t(60, SUCCESS, ErrorProcessing, Unconfigured),
        t(61, FAILURE, ErrorProcessing, Finalized),
        t(62, ERROR, ErrorProcessing, Finalized),
    ]
};

/// The callback a node runs inside a transition (rclpy's `on_configure` … `on_error`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    Configure,
    CleanUp,
    Activate,
    Deactivate,
    Shutdown,
    /// `on_error`, after a callback answered ERROR.
    Error,
}

/// What a transition callback answers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CallbackReturn {
    Success,
    Failure,
    Error,
}

impl CallbackReturn {
    /// The label of the transition it triggers out of the transition state.
    pub fn label(self) -> &'static str {
        match self {
            CallbackReturn::Success => SUCCESS,
            CallbackReturn::Failure => FAILURE,
            CallbackReturn::Error => ERROR,
        }
    }
}

/// One move of the machine (`lifecycle_msgs/msg/TransitionEvent`'s start and goal states;
/// `rcl_lifecycle` leaves its `timestamp` and `transition` zero, and so does a mobil node).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Event {
    pub start: State,
    pub goal: State,
}

/// A request the current state does not offer: nothing changes.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum Refused {
    #[error("no transition labelled `{label}` from state {state}")]
    Label { label: String, state: State },
    #[error("no transition {id} from state {state}")]
    Id { id: u8, state: State },
}

/// The managed node's state machine.
#[derive(Debug, Clone)]
pub struct Machine {
    state: State,
    /// The primary state the running request started from (what the callbacks are given).
    started_from: State,
}

impl Default for Machine {
    fn default() -> Self {
        Self::new()
    }
}

/// The whole of one request run through [`Machine::change`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Change {
    /// `ChangeState`'s answer: true only when the transition's own callback succeeded.
    pub success: bool,
    /// The events, in order (two, or three after an error).
    pub events: Vec<Event>,
}

impl Machine {
    /// A new node: unconfigured.
    pub fn new() -> Self {
        Machine {
            state: State::Unconfigured,
            started_from: State::Unconfigured,
        }
    }

    /// The current state.
    pub fn state(&self) -> State {
        self.state
    }

    /// The primary state the running (or last) request started from: what a callback is given
    /// as the previous state.
    pub fn started_from(&self) -> State {
        self.started_from
    }

    /// The transitions the current state offers, in graph order (`get_available_transitions`).
    pub fn available(&self) -> impl Iterator<Item = &'static TransitionDef> + '_ {
        GRAPH.iter().filter(move |t| t.start == self.state)
    }

    /// The transition a request names: by `label` when it is not empty, else by `id`, among
    /// the current state's transitions.
    pub fn resolve(&self, id: u8, label: &str) -> Result<&'static TransitionDef, Refused> {
        if label.is_empty() {
            self.available()
                .find(|t| t.id == id)
                .ok_or(Refused::Id { id, state: self.state })
        } else {
            self.available()
                .find(|t| t.label == label)
                .ok_or_else(|| Refused::Label {
                    label: label.to_owned(),
                    state: self.state,
                })
        }
    }

    /// Starts the transition a request names: the machine enters its transition state. Returns
    /// the callback to run and the event; then [`Machine::finish`] with the callback's answer.
    /// Refused while a callback runs (a transition state offers only the callback's answers,
    /// which are not requests).
    pub fn begin(&mut self, id: u8, label: &str) -> Result<(Step, Event), Refused> {
        let t = self.resolve(id, label)?;
        let Some(step) = t.goal.step() else {
            // Only the callback answers leave a transition state, and they go to primary states.
            return Err(Refused::Id { id, state: self.state });
        };
        if !self.state.is_primary() {
            return Err(Refused::Id { id, state: self.state });
        }
        self.started_from = self.state;
        self.state = t.goal;
        Ok((
            step,
            Event {
                start: t.start,
                goal: t.goal,
            },
        ))
    }

    /// Ends the running callback with its answer: the event, and the next callback to run when
    /// the machine went to errorprocessing (`Step::Error`; then `finish` again with its answer).
    /// Called outside a transition state it changes nothing and returns a still event.
    pub fn finish(&mut self, answer: CallbackReturn) -> (Event, Option<Step>) {
        let from = self.state;
        let Some(t) = GRAPH.iter().find(|t| t.start == from && t.label == answer.label()) else {
            return (
                Event {
                    start: from,
                    goal: from,
                },
                None,
            );
        };
        self.state = t.goal;
        let next = (t.goal == State::ErrorProcessing).then_some(Step::Error);
        (
            Event {
                start: from,
                goal: t.goal,
            },
            next,
        )
    }

    /// Runs one request whole, with `callback` for each step (given the state the request
    /// started from), as a node without asynchronous callbacks would.
    pub fn change(
        &mut self,
        id: u8,
        label: &str,
        mut callback: impl FnMut(Step, State) -> CallbackReturn,
    ) -> Result<Change, Refused> {
        let (step, first) = self.begin(id, label)?;
        let mut events = vec![first];
        let answer = callback(step, self.started_from);
        let (event, mut next) = self.finish(answer);
        events.push(event);
        while let Some(step) = next {
            let (event, after) = self.finish(callback(step, self.started_from));
            events.push(event);
            next = after;
        }
        Ok(Change {
            success: answer == CallbackReturn::Success,
            events,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use State::*;

    fn ev(start: State, goal: State) -> Event {
        Event { start, goal }
    }

    fn ok(_: Step, _: State) -> CallbackReturn {
        CallbackReturn::Success
    }

    /// The ids and labels of lifecycle_msgs/msg/State (its constants and rcl's labels).
    #[test]
    fn state_ids_and_labels_are_lifecycle_msgs() {
        let table: Vec<(u8, &str)> = State::ALL.iter().map(|s| (s.id(), s.label())).collect();
        assert_eq!(
            table,
            [
                (0, "unknown"),
                (1, "unconfigured"),
                (2, "inactive"),
                (3, "active"),
                (4, "finalized"),
                (10, "configuring"),
                (11, "cleaningup"),
                (12, "shuttingdown"),
                (13, "activating"),
                (14, "deactivating"),
                (15, "errorprocessing"),
            ]
        );
    }

    /// What `get_available_transitions` answers in each primary state, observed on an
    /// rclpy.lifecycle node (Jazzy): ids in order.
    #[test]
    fn available_transitions_per_state_match_rclpy() {
        let ids = |s: State| {
            let m = Machine {
                state: s,
                started_from: s,
            };
            m.available().map(|t| t.id).collect::<Vec<_>>()
        };
        assert_eq!(ids(Unconfigured), [1, 5]);
        assert_eq!(ids(Inactive), [2, 3, 6]);
        assert_eq!(ids(Active), [4, 7]);
        assert_eq!(ids(Finalized), Vec::<u8>::new());
        assert_eq!(ids(Unknown), Vec::<u8>::new());
        assert_eq!(ids(Configuring), [10, 11, 12]);
        assert_eq!(ids(ErrorProcessing), [60, 61, 62]);
    }

    /// Every transition id appears once, and the graph's shape: from each transition state
    /// exactly a success, a failure and an error transition leave.
    #[test]
    fn graph_has_unique_ids_and_three_exits_per_transition_state() {
        let mut ids: Vec<u8> = GRAPH.iter().map(|t| t.id).collect();
        ids.sort_unstable();
        ids.dedup();
        assert_eq!(ids.len(), 25);
        for s in State::ALL.iter().filter(|s| !s.is_primary()) {
            let labels: Vec<&str> = GRAPH.iter().filter(|t| t.start == *s).map(|t| t.label).collect();
            assert_eq!(labels, [SUCCESS, FAILURE, ERROR], "{s}");
        }
    }

    /// The sequence a Nav2 lifecycle manager sends, with the events an rclpy node publishes.
    #[test]
    fn bringup_and_teardown_give_two_events_each() {
        let mut m = Machine::new();
        let c = m.change(1, "", ok).unwrap();
        assert!(c.success);
        assert_eq!(c.events, [ev(Unconfigured, Configuring), ev(Configuring, Inactive)]);
        let c = m.change(3, "", ok).unwrap();
        assert_eq!(c.events, [ev(Inactive, Activating), ev(Activating, Active)]);
        let c = m.change(4, "", ok).unwrap();
        assert_eq!(c.events, [ev(Active, Deactivating), ev(Deactivating, Inactive)]);
        let c = m.change(2, "", ok).unwrap();
        assert_eq!(c.events, [ev(Inactive, CleaningUp), ev(CleaningUp, Unconfigured)]);
        let c = m.change(5, "", ok).unwrap();
        assert_eq!(c.events, [ev(Unconfigured, ShuttingDown), ev(ShuttingDown, Finalized)]);
        assert_eq!(m.state(), Finalized);
        assert_eq!(
            m.change(1, "", ok),
            Err(Refused::Id {
                id: 1,
                state: Finalized
            })
        );
    }

    /// A label wins over the id and is resolved in the current state: `shutdown` from active
    /// is transition 7.
    #[test]
    fn label_wins_and_resolves_in_the_current_state() {
        let mut m = Machine::new();
        m.change(99, "configure", ok).unwrap();
        m.change(0, "activate", ok).unwrap();
        assert_eq!(m.resolve(0, "shutdown").unwrap().id, 7);
        assert_eq!(m.resolve(5, "").unwrap_err(), Refused::Id { id: 5, state: Active });
        let refused = m.change(3, "bogus", ok).unwrap_err();
        assert_eq!(refused.to_string(), "no transition labelled `bogus` from state active");
        assert_eq!(m.state(), Active);
        let c = m.change(0, "shutdown", ok).unwrap();
        assert_eq!(c.events, [ev(Active, ShuttingDown), ev(ShuttingDown, Finalized)]);
    }

    /// FAILURE goes back where the request started (shutting down goes on to finalized);
    /// success is false.
    #[test]
    fn failure_returns_to_the_start_state() {
        let fail = |_: Step, _: State| CallbackReturn::Failure;
        let mut m = Machine::new();
        let c = m.change(1, "", fail).unwrap();
        assert!(!c.success);
        assert_eq!(c.events, [ev(Unconfigured, Configuring), ev(Configuring, Unconfigured)]);
        m.change(1, "", ok).unwrap();
        m.change(3, "", fail).unwrap();
        assert_eq!(m.state(), Inactive);
        m.change(3, "", ok).unwrap();
        m.change(4, "", fail).unwrap();
        assert_eq!(m.state(), Active);
        let c = m.change(7, "", fail).unwrap();
        assert_eq!(c.events, [ev(Active, ShuttingDown), ev(ShuttingDown, Finalized)]);
        assert!(!c.success);
    }

    /// ERROR passes through errorprocessing: on_error SUCCESS → unconfigured (even from an
    /// activate, as rclpy shows), FAILURE or ERROR → finalized; three events; the error callback
    /// is given the state the request started from.
    #[test]
    fn error_goes_through_errorprocessing() {
        let mut m = Machine::new();
        m.change(1, "", ok).unwrap();
        let mut seen = Vec::new();
        let c = m
            .change(3, "", |step, from| {
                seen.push((step, from));
                match step {
                    Step::Activate => CallbackReturn::Error,
                    _ => CallbackReturn::Success,
                }
            })
            .unwrap();
        assert!(!c.success);
        assert_eq!(
            c.events,
            [
                ev(Inactive, Activating),
                ev(Activating, ErrorProcessing),
                ev(ErrorProcessing, Unconfigured)
            ]
        );
        assert_eq!(seen, [(Step::Activate, Inactive), (Step::Error, Inactive)]);
        let c = m
            .change(1, "", |step, _| match step {
                Step::Configure => CallbackReturn::Error,
                _ => CallbackReturn::Failure,
            })
            .unwrap();
        assert_eq!(c.events[2], ev(ErrorProcessing, Finalized));
        assert_eq!(m.state(), Finalized);
    }

    /// While a callback runs, no request is taken, and `finish` outside a transition is still.
    #[test]
    fn no_request_while_a_callback_runs() {
        let mut m = Machine::new();
        let (step, _) = m.begin(1, "").unwrap();
        assert_eq!(step, Step::Configure);
        assert!(m.begin(10, "").is_err());
        assert!(m.begin(0, "transition_success").is_err());
        assert_eq!(m.state(), Configuring);
        m.finish(CallbackReturn::Success);
        let (event, next) = m.finish(CallbackReturn::Success);
        assert_eq!((event, next), (ev(Inactive, Inactive), None));
        assert_eq!(m.state(), Inactive);
    }

    proptest::proptest! {
        /// Any sequence of requests and answers leaves the machine in a primary state between
        /// requests, every event chain starts where the last ended, and a refused request
        /// changes nothing.
        #[test]
        fn any_sequence_stays_consistent(
            requests in proptest::collection::vec((0u8..100, 0usize..8, 0usize..3, 0usize..3), 0..60)
        ) {
            let labels = ["", "configure", "cleanup", "activate", "deactivate", "shutdown", "bogus", "transition_success"];
            let answers = [CallbackReturn::Success, CallbackReturn::Failure, CallbackReturn::Error];
            let mut m = Machine::new();
            for (id, label, a, b) in requests {
                let before = m.state();
                let mut n = 0;
                match m.change(id, labels[label], |_, _| { n += 1; answers[if n == 1 { a } else { b }] }) {
                    Ok(c) => {
                        proptest::prop_assert_eq!(c.events[0].start, before);
                        for w in c.events.windows(2) {
                            proptest::prop_assert_eq!(w[0].goal, w[1].start);
                        }
                        proptest::prop_assert_eq!(c.events.last().unwrap().goal, m.state());
                        proptest::prop_assert_eq!(c.success, a == 0);
                    }
                    Err(_) => proptest::prop_assert_eq!(m.state(), before),
                }
                proptest::prop_assert!(m.state().is_primary());
            }
        }
    }
}
