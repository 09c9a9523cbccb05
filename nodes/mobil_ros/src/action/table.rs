//! The goals an action server knows, and what it answers about them, as `rcl_action` (and so
//! rclpy's and rclcpp's servers) answers: testable without DDS.
//!
//! A goal is known from its acceptance until its result expires, [`GoalTable::new`]'s `keep`
//! after it ended (Nav2's `action_server_result_timeout`, rcl's default 10 s; ROS 2 Kilted's
//! rule: Jazzy's rcl counts from the acceptance, which drops a long goal's result as it ends).
//! While it is known:
//! - a `send_goal` with its id is refused (`accepted = false`, stamp zero) without asking the
//!   node ([`GoalTable::knows`]);
//! - a `get_result` for it is answered with its terminal status and result as often as asked,
//!   or, while it runs, when it ends ([`GoalTable::result`], [`GoalTable::finish`]);
//! - a `cancel_goal` naming it is agreed to while it runs (EXECUTING → CANCELING) and refused
//!   with ERROR_GOAL_TERMINATED once it cannot move to CANCELING (ended, or CANCELING
//!   already) ([`GoalTable::cancel`]).
//!
//! An unknown id (never seen, or expired) gets `get_result` STATUS_UNKNOWN with a default
//! result and `cancel_goal` ERROR_UNKNOWN_GOAL_ID, at once. Nothing is kept for a request
//! answered at once, and at most [`MOST_KEPT`] ended goals are kept however fast goals come,
//! so no stream of requests grows the table.
//!
//! ```
//! use mobil_ros::action::table::{Cancel, GoalTable, ResultAnswer};
//! use ros2_client::action::{GoalId, GoalInfo, GoalStatusEnum};
//! use ros2_client::builtin_interfaces::Time;
//! use std::time::{Duration, Instant};
//!
//! let mut table = GoalTable::<f64, &str>::new(Duration::from_secs(10));
//! let (id, t0) = (GoalId::new_random(), Instant::now());
//! table.accept(id, Time::from_nanos(5));
//! assert!(table.knows(&id));
//! assert_eq!(table.result(id, "asked early"), ResultAnswer::Later);
//! assert_eq!(table.finish(id, GoalStatusEnum::Succeeded, 1.5, t0), vec!["asked early"]);
//! assert_eq!(table.result(id, "asked late"), ResultAnswer::Now(GoalStatusEnum::Succeeded, 1.5));
//! let once_more = table.cancel(&GoalInfo { goal_id: id, stamp: Time::ZERO });
//! assert!(matches!(once_more, Cancel::GoalTerminated));
//! table.expire(t0 + Duration::from_secs(11));
//! assert_eq!(table.result(id, "too late"), ResultAnswer::Now(GoalStatusEnum::Unknown, 0.0));
//! ```

use ros2_client::action::{GoalId, GoalInfo, GoalStatusEnum};
use ros2_client::action_msgs::{CancelGoalResponseEnum, GoalStatus};
use ros2_client::builtin_interfaces::Time;
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

/// The most ended goals kept (the oldest beyond are forgotten first): a client flooding the
/// server with goals cannot grow it without bound within `keep`.
pub const MOST_KEPT: usize = 256;

/// The most `get_result` requests waiting for one running goal (the oldest beyond are dropped
/// unanswered): a client asking again and again cannot grow the table without bound.
pub const MOST_WAITING: usize = 64;

/// What a `get_result` request gets.
#[derive(Debug, Clone, PartialEq)]
pub enum ResultAnswer<R> {
    /// This answer, now: the goal's terminal status and result, or STATUS_UNKNOWN with a
    /// default result for an unknown id.
    Now(GoalStatusEnum, R),
    /// The goal runs: the request is answered when it ends ([`GoalTable::finish`]).
    Later,
}

/// What a `cancel_goal` request gets (`action_msgs/srv/CancelGoal`'s return codes).
#[derive(Debug, Clone)]
pub enum Cancel {
    /// ERROR_NONE: these goals went CANCELING (none, for a cancel of all goals when none runs).
    Canceling(Vec<GoalInfo>),
    /// ERROR_UNKNOWN_GOAL_ID: the goal named is not known.
    UnknownGoal,
    /// ERROR_GOAL_TERMINATED: the goal named cannot move to CANCELING (ended, or canceling).
    GoalTerminated,
}

impl Cancel {
    /// The return code.
    pub fn code(&self) -> CancelGoalResponseEnum {
        match self {
            Cancel::Canceling(_) => CancelGoalResponseEnum::None,
            Cancel::UnknownGoal => CancelGoalResponseEnum::UnknownGoal,
            Cancel::GoalTerminated => CancelGoalResponseEnum::GoalTerminated,
        }
    }

    /// The goals that went CANCELING.
    pub fn canceling(&self) -> &[GoalInfo] {
        match self {
            Cancel::Canceling(goals) => goals,
            Cancel::UnknownGoal | Cancel::GoalTerminated => &[],
        }
    }
}

/// A known goal.
#[derive(Debug)]
struct Known<R, K> {
    /// When it was accepted (the node's clock): its stamp in the status and a cancel's reply.
    stamp: Time,
    status: GoalStatusEnum,
    /// When it ended (steady clock): its result is kept `keep` from then.
    ended: Option<Instant>,
    result: Option<R>,
    /// `get_result` requests waiting for it to end.
    waiting: Vec<K>,
    /// A client asked for its result.
    asked: bool,
}

fn is_terminal(status: GoalStatusEnum) -> bool {
    matches!(
        status,
        GoalStatusEnum::Succeeded | GoalStatusEnum::Canceled | GoalStatusEnum::Aborted
    )
}

fn is_cancelable(status: GoalStatusEnum) -> bool {
    matches!(status, GoalStatusEnum::Accepted | GoalStatusEnum::Executing)
}

/// The goals an action server knows (module docs); `R` is the action's result, `K` the id of
/// a `get_result` request to answer.
#[derive(Debug)]
pub struct GoalTable<R, K> {
    goals: BTreeMap<GoalId, Known<R, K>>,
    keep: Duration,
}

impl<R: Clone + Default, K> GoalTable<R, K> {
    /// A table keeping each result `keep` after its goal ended.
    pub fn new(keep: Duration) -> Self {
        GoalTable {
            goals: BTreeMap::new(),
            keep,
        }
    }

    /// Whether goal `id` is known (running, or ended with its result kept).
    pub fn knows(&self, id: &GoalId) -> bool {
        self.goals.contains_key(id)
    }

    /// How many goals are known.
    pub fn len(&self) -> usize {
        self.goals.len()
    }

    /// Whether no goal is known.
    pub fn is_empty(&self) -> bool {
        self.goals.is_empty()
    }

    /// Goal `id`, accepted at `stamp`, runs (EXECUTING). An id already known is left as it is
    /// (the server refuses it before: [`GoalTable::knows`]).
    pub fn accept(&mut self, id: GoalId, stamp: Time) {
        self.goals.entry(id).or_insert(Known {
            stamp,
            status: GoalStatusEnum::Executing,
            ended: None,
            result: None,
            waiting: Vec::new(),
            asked: false,
        });
    }

    /// Forgets the ended goals whose result is older than `keep` at `now`, then the oldest
    /// ended ones beyond [`MOST_KEPT`].
    pub fn expire(&mut self, now: Instant) {
        let keep = self.keep;
        self.goals
            .retain(|_, g| g.ended.is_none_or(|ended| now.saturating_duration_since(ended) <= keep));
        let ended = self.goals.values().filter(|g| g.ended.is_some()).count();
        if ended > MOST_KEPT {
            let mut by_age: Vec<(Instant, GoalId)> = self
                .goals
                .iter()
                .filter_map(|(id, g)| g.ended.map(|at| (at, *id)))
                .collect();
            by_age.sort();
            for (_, id) in by_age.into_iter().take(ended - MOST_KEPT) {
                self.goals.remove(&id);
            }
        }
    }

    /// A `cancel_goal` request, answered as `rcl_action_process_cancel_request` answers it for
    /// a server that agrees to every cancel: a goal named alone (stamp zero) is canceled while
    /// it runs; otherwise every running goal accepted at or before the stamp (every one for a
    /// zero stamp and id) and the one named. Those go CANCELING.
    pub fn cancel(&mut self, request: &GoalInfo) -> Cancel {
        if request.goal_id != GoalId::ZERO && request.stamp == Time::ZERO {
            return match self.goals.get_mut(&request.goal_id) {
                None => Cancel::UnknownGoal,
                Some(g) if !is_cancelable(g.status) => Cancel::GoalTerminated,
                Some(g) => {
                    g.status = GoalStatusEnum::Canceling;
                    Cancel::Canceling(vec![GoalInfo {
                        goal_id: request.goal_id,
                        stamp: g.stamp,
                    }])
                }
            };
        }
        let until = if request.goal_id == GoalId::ZERO && request.stamp == Time::ZERO {
            None
        } else {
            Some(request.stamp)
        };
        let mut canceling = Vec::new();
        for (id, g) in &mut self.goals {
            let named = *id == request.goal_id || until.is_none_or(|t| g.stamp <= t);
            if named && is_cancelable(g.status) {
                g.status = GoalStatusEnum::Canceling;
                canceling.push(GoalInfo {
                    goal_id: *id,
                    stamp: g.stamp,
                });
            }
        }
        Cancel::Canceling(canceling)
    }

    /// A `get_result` request `key` for goal `id`: answered now (unknown: STATUS_UNKNOWN and a
    /// default result; ended: its status and result), or kept until the goal ends.
    pub fn result(&mut self, id: GoalId, key: K) -> ResultAnswer<R> {
        let Some(g) = self.goals.get_mut(&id) else {
            return ResultAnswer::Now(GoalStatusEnum::Unknown, R::default());
        };
        g.asked = true;
        match &g.result {
            Some(result) => ResultAnswer::Now(g.status, result.clone()),
            None => {
                if g.waiting.len() >= MOST_WAITING {
                    g.waiting.remove(0);
                }
                g.waiting.push(key);
                ResultAnswer::Later
            }
        }
    }

    /// Goal `id` ended at `now` with `status` (SUCCEEDED, CANCELED or ABORTED) and `result`:
    /// the `get_result` requests waiting for it, to answer with them. Nothing for a goal that is
    /// not running (unknown, or ended already).
    pub fn finish(&mut self, id: GoalId, status: GoalStatusEnum, result: R, now: Instant) -> Vec<K> {
        match self.goals.get_mut(&id) {
            Some(g) if g.ended.is_none() && is_terminal(status) => {
                g.status = status;
                g.result = Some(result);
                g.ended = Some(now);
                std::mem::take(&mut g.waiting)
            }
            _ => Vec::new(),
        }
    }

    /// How many goals ended with their results kept that no client has asked for yet.
    pub fn unasked(&self) -> usize {
        self.goals.values().filter(|g| g.ended.is_some() && !g.asked).count()
    }

    /// The status of every known goal, by acceptance (`action_msgs/GoalStatusArray`).
    pub fn statuses(&self) -> Vec<GoalStatus> {
        let mut list: Vec<GoalStatus> = self
            .goals
            .iter()
            .map(|(id, g)| GoalStatus {
                goal_info: GoalInfo {
                    goal_id: *id,
                    stamp: g.stamp,
                },
                status: g.status,
            })
            .collect();
        list.sort_by_key(|s| (s.goal_info.stamp, s.goal_info.goal_id));
        list
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use GoalStatusEnum::*;

    fn id(n: u8) -> GoalId {
        let mut bytes = [0u8; 16];
        bytes[15] = n;
        GoalId {
            uuid: uuid::Uuid::from_bytes(bytes),
        }
    }

    fn named(n: u8) -> GoalInfo {
        GoalInfo {
            goal_id: id(n),
            stamp: Time::ZERO,
        }
    }

    fn at(n: i64) -> Time {
        Time::from_nanos(n)
    }

    fn table() -> GoalTable<u32, u32> {
        GoalTable::new(Duration::from_secs(10))
    }

    /// The return code, and the ids and stamps (ns) of the goals canceling.
    fn told(c: &Cancel) -> (CancelGoalResponseEnum, Vec<(GoalId, i64)>) {
        let goals = c.canceling().iter().map(|g| (g.goal_id, g.stamp.to_nanos())).collect();
        (c.code(), goals)
    }

    #[test]
    fn results_are_answered_at_once_when_known_or_unknown_and_later_while_the_goal_runs() {
        let mut t = table();
        let t0 = Instant::now();
        // Unknown: STATUS_UNKNOWN with a default result, nothing kept.
        assert_eq!(t.result(id(9), 1), ResultAnswer::Now(Unknown, 0));
        assert!(t.is_empty());
        t.accept(id(1), at(100));
        assert_eq!(t.result(id(1), 2), ResultAnswer::Later);
        assert_eq!(t.result(id(1), 3), ResultAnswer::Later);
        // Both waiting requests are answered when it ends; it is then answered again and again.
        assert_eq!(t.finish(id(1), Aborted, 42, t0), vec![2, 3]);
        assert_eq!(t.result(id(1), 4), ResultAnswer::Now(Aborted, 42));
        assert_eq!(t.result(id(1), 5), ResultAnswer::Now(Aborted, 42));
        // A second end changes nothing.
        assert_eq!(t.finish(id(1), Succeeded, 7, t0), Vec::<u32>::new());
        assert_eq!(t.result(id(1), 6), ResultAnswer::Now(Aborted, 42));
    }

    #[test]
    fn a_result_is_kept_for_keep_after_its_goal_ended_then_forgotten() {
        let mut t = table();
        let t0 = Instant::now();
        t.accept(id(1), at(1));
        t.accept(id(2), at(2));
        t.finish(id(1), Succeeded, 1, t0);
        // 10 s after its end: still known; the running goal is never forgotten.
        t.expire(t0 + Duration::from_secs(10));
        assert!(t.knows(&id(1)) && t.knows(&id(2)));
        t.expire(t0 + Duration::from_millis(10_001));
        assert!(!t.knows(&id(1)) && t.knows(&id(2)));
        assert_eq!(t.result(id(1), 1), ResultAnswer::Now(Unknown, 0));
        t.expire(t0 + Duration::from_secs(3600));
        assert!(t.knows(&id(2)));
    }

    #[test]
    fn a_flood_of_goals_keeps_the_newest_ended_ones_only() {
        let mut t = table();
        let t0 = Instant::now();
        let n = MOST_KEPT + 44;
        for k in 0..n {
            let g = GoalId::new_random();
            t.accept(g, at(k as i64));
            t.finish(g, Aborted, 0, t0 + Duration::from_millis(k as u64));
        }
        t.accept(id(1), at(0));
        t.expire(t0 + Duration::from_secs(1));
        assert_eq!(
            t.len(),
            MOST_KEPT + 1,
            "the newest {MOST_KEPT} ended goals and the running one"
        );
        // The oldest went first: what is left ended 44 ms or more after t0.
        let oldest = t.goals.values().filter_map(|g| g.ended).min().unwrap();
        assert_eq!(oldest, t0 + Duration::from_millis(44));
    }

    #[test]
    fn waiting_requests_for_one_goal_are_bounded() {
        let mut t = table();
        t.accept(id(1), at(1));
        for k in 0..(MOST_WAITING as u32 + 10) {
            assert_eq!(t.result(id(1), k), ResultAnswer::Later);
        }
        let answered = t.finish(id(1), Succeeded, 1, Instant::now());
        assert_eq!(answered.len(), MOST_WAITING);
        assert_eq!(answered[0], 10, "the oldest ten dropped");
    }

    #[test]
    fn a_cancel_named_alone_agrees_while_running_else_says_unknown_or_terminated() {
        let mut t = table();
        t.accept(id(1), at(100));
        assert_eq!(
            told(&t.cancel(&named(9))),
            (CancelGoalResponseEnum::UnknownGoal, vec![])
        );
        assert_eq!(
            told(&t.cancel(&named(1))),
            (CancelGoalResponseEnum::None, vec![(id(1), 100)])
        );
        assert_eq!(t.statuses()[0].status, Canceling);
        // CANCELING cannot move to CANCELING again: rcl's ERROR_GOAL_TERMINATED.
        let terminated = (CancelGoalResponseEnum::GoalTerminated, vec![]);
        assert_eq!(told(&t.cancel(&named(1))), terminated);
        t.finish(id(1), Canceled, 5, Instant::now());
        assert_eq!(told(&t.cancel(&named(1))), terminated);
    }

    #[test]
    fn a_cancel_of_all_or_by_stamp_takes_the_running_goals_accepted_until_then() {
        let mut t = table();
        let all = GoalInfo {
            goal_id: GoalId::ZERO,
            stamp: Time::ZERO,
        };
        // None running: ERROR_NONE with an empty list (rcl's answer).
        assert_eq!(told(&t.cancel(&all)), (CancelGoalResponseEnum::None, vec![]));
        t.accept(id(1), at(100));
        t.accept(id(2), at(200));
        t.accept(id(3), at(300));
        t.finish(id(3), Succeeded, 0, Instant::now());
        // By stamp: accepted at or before 200 (inclusive), and the id named (none here).
        let by_stamp = t.cancel(&GoalInfo {
            goal_id: GoalId::ZERO,
            stamp: at(200),
        });
        assert_eq!(
            told(&by_stamp),
            (CancelGoalResponseEnum::None, vec![(id(1), 100), (id(2), 200)])
        );
        // All: nothing runs now that is not canceling already, and the ended one stays ended.
        assert_eq!(told(&t.cancel(&all)), (CancelGoalResponseEnum::None, vec![]));
        let states: Vec<GoalStatusEnum> = t.statuses().iter().map(|s| s.status).collect();
        assert_eq!(states, vec![Canceling, Canceling, Succeeded]);
        // An id with a stamp: the id, or anything accepted until the stamp.
        let mut t = table();
        t.accept(id(1), at(100));
        t.accept(id(2), at(500));
        let both = t.cancel(&GoalInfo {
            goal_id: id(2),
            stamp: at(150),
        });
        assert_eq!(
            told(&both),
            (CancelGoalResponseEnum::None, vec![(id(1), 100), (id(2), 500)])
        );
    }

    #[test]
    fn the_status_lists_every_known_goal_by_acceptance() {
        let mut t = table();
        t.accept(id(7), at(300));
        t.accept(id(3), at(100));
        t.finish(id(3), Succeeded, 0, Instant::now());
        let s = t.statuses();
        let listed: Vec<(GoalId, i64, GoalStatusEnum)> = s
            .iter()
            .map(|s| (s.goal_info.goal_id, s.goal_info.stamp.to_nanos(), s.status))
            .collect();
        assert_eq!(listed, vec![(id(3), 100, Succeeded), (id(7), 300, Executing)]);
        // Nobody asked for the ended goal's result yet.
        assert_eq!(t.unasked(), 1);
        assert_eq!(t.result(id(3), 0), ResultAnswer::Now(Succeeded, 0));
        assert_eq!(t.unasked(), 0);
    }
}
