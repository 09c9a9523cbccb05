//! The bookkeeping of a pool of external simulators (`ga_step --evaluator ros` with several
//! simulators; the transport is the executable's): which simulator gets the next candidate,
//! what a candidate does after an attempt, and when the pool has given up.
//!
//! The rules:
//! - One candidate in flight per simulator.
//! - A candidate goes to a free simulator among those with the fewest attempts missed in a row
//!   (left unanswered within the timeout), the least recently used first. A simulator that
//!   missed an answer therefore gets no candidate while another one answers, until it answers
//!   again, restarts ([`SimulatorPool::restarted`]: a new reader of its candidates) or is gone.
//!   With a single simulator this is the one-simulator rule: it is always the one.
//! - When every simulator present has missed [`SimulatorPool::new`]'s `max_missed` attempts in a
//!   row, the pool is exhausted and the run ends.
//! - A candidate whose simulator was lost during the attempt (its endpoints gone) is sent again,
//!   to another simulator or the same one restarted, without counting an attempt, up to
//!   [`LOST_PER_MISS`] times; each further loss counts as a missed attempt, so a candidate that
//!   makes every simulator leave cannot hold a run forever. One whose attempt was missed counts
//!   it; after `attempts` missed attempts it scores as a void ([`CandidateTries`]).
//! - Presence: a simulator is present while its candidates have a reader and its outcomes a
//!   writer; a new reader while present is a restart ([`SimulatorPool::observe`]). A missed
//!   attempt at a simulator that left meanwhile is not held against it.
//! - Which simulators: those that serve the contract in a namespace below the node's
//!   ([`pool_base`], [`pool_namespaces`]).
//!
//! Which simulator evaluated a candidate never changes its score: the run's results depend on
//! the seed alone.

/// How an attempt at one simulator ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AttemptEnd {
    /// The simulator answered the candidate.
    Answered,
    /// No answer within the timeout.
    Missed,
    /// The simulator's endpoints vanished during the attempt.
    Lost,
}

/// The pool's answer to "which simulator next".
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Pick {
    /// Send the candidate to this simulator (now marked busy).
    Use(String),
    /// Every usable simulator is busy, or none is present: wait.
    Wait,
    /// Every simulator present missed `max_missed` attempts in a row.
    Exhausted,
}

/// What [`SimulatorPool::observe`] found changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Change {
    /// Nothing that matters.
    None,
    /// The simulator is present now and was not.
    Joined,
    /// A new reader of its candidates while present: a restarted simulator (or a first sample
    /// lost during discovery, or a tool echoing the candidates); a waiting candidate is sent
    /// again, and its misses are forgotten.
    Restarted,
    /// Its endpoints are gone.
    Left,
}

#[derive(Debug, Clone)]
struct Slot {
    id: String,
    busy: bool,
    present: bool,
    missed_in_a_row: u32,
    last_used: u64,
    /// Readers of its candidates at the last [`SimulatorPool::observe`].
    readers: usize,
}

/// The simulators known to a run and their state.
#[derive(Debug, Clone)]
pub struct SimulatorPool {
    slots: Vec<Slot>,
    max_missed: u32,
    tick: u64,
}

impl SimulatorPool {
    /// An empty pool that gives up when every simulator missed `max_missed` attempts in a row.
    pub fn new(max_missed: u32) -> SimulatorPool {
        SimulatorPool {
            slots: Vec::new(),
            max_missed: max_missed.max(1),
            tick: 0,
        }
    }

    fn slot(&mut self, id: &str) -> Option<&mut Slot> {
        self.slots.iter_mut().find(|s| s.id == id)
    }

    /// A simulator is present (its endpoints are matched); true if it was not before.
    pub fn seen(&mut self, id: &str) -> bool {
        match self.slot(id) {
            Some(s) => !std::mem::replace(&mut s.present, true),
            None => {
                self.slots.push(Slot {
                    id: id.to_string(),
                    busy: false,
                    present: true,
                    missed_in_a_row: 0,
                    last_used: 0,
                    readers: 0,
                });
                true
            }
        }
    }

    /// A simulator restarted (a new reader of its candidates): its missed attempts are forgotten.
    pub fn restarted(&mut self, id: &str) {
        if let Some(s) = self.slot(id) {
            s.missed_in_a_row = 0;
        }
    }

    /// A simulator's endpoints are gone. It is kept (a simulator that comes back under the same
    /// name is the same slot) but not picked until [`Self::seen`] again; its missed attempts are
    /// forgotten, as a simulator that comes back is a restarted one.
    pub fn gone(&mut self, id: &str) {
        if let Some(s) = self.slot(id) {
            s.present = false;
            s.missed_in_a_row = 0;
        }
    }

    /// What the graph shows of simulator `id` now: `readers` of its candidates and `writers` of
    /// its outcomes. Present while both are matched; a reader more than last time while present
    /// is a restart, and means a waiting candidate should be sent again.
    pub fn observe(&mut self, id: &str, readers: usize, writers: usize) -> Change {
        if self.slot(id).is_none() {
            if readers == 0 || writers == 0 {
                return Change::None;
            }
            self.seen(id);
            if let Some(s) = self.slot(id) {
                s.readers = readers;
            }
            return Change::Joined;
        }
        let Some(s) = self.slot(id) else {
            return Change::None;
        };
        let more = readers > s.readers;
        s.readers = readers;
        let was = s.present;
        if readers > 0 && writers > 0 {
            if !was {
                s.present = true;
                return Change::Joined;
            }
            if more {
                s.missed_in_a_row = 0;
                return Change::Restarted;
            }
            Change::None
        } else if was {
            s.present = false;
            s.missed_in_a_row = 0;
            Change::Left
        } else {
            Change::None
        }
    }

    /// The simulators present.
    pub fn present(&self) -> usize {
        self.slots.iter().filter(|s| s.present).count()
    }

    /// Whether `id` is present.
    pub fn is_present(&self, id: &str) -> bool {
        self.slots.iter().any(|s| s.id == id && s.present)
    }

    /// The simulator for the next candidate (see the module's rules).
    pub fn pick(&mut self) -> Pick {
        let Some(fewest) = self.slots.iter().filter(|s| s.present).map(|s| s.missed_in_a_row).min() else {
            return Pick::Wait;
        };
        if fewest >= self.max_missed {
            return Pick::Exhausted;
        }
        let chosen = self
            .slots
            .iter_mut()
            .filter(|s| s.present && !s.busy && s.missed_in_a_row == fewest)
            .min_by_key(|s| s.last_used);
        match chosen {
            Some(s) => {
                self.tick += 1;
                s.busy = true;
                s.last_used = self.tick;
                Pick::Use(s.id.clone())
            }
            None => Pick::Wait,
        }
    }

    /// The attempt at `id` ended.
    pub fn release(&mut self, id: &str, end: AttemptEnd) {
        if let Some(s) = self.slot(id) {
            s.busy = false;
            match end {
                AttemptEnd::Answered => s.missed_in_a_row = 0,
                // A simulator that left meanwhile comes back fresh (see `gone`).
                AttemptEnd::Missed if s.present => s.missed_in_a_row += 1,
                AttemptEnd::Missed => {}
                AttemptEnd::Lost => {}
            }
        }
    }
}

/// The last two levels of the contract's outcome topic.
pub const OUTCOME_SUFFIX: &str = "/ga_step/outcome";

/// The namespace under which a node whose outcome topic resolved to `own_outcome` looks for
/// more simulators (ending with `/`), and the name of its own simulator (its namespace, `/` for
/// the root). No base when the topic was remapped to a name that does not end in
/// `/ga_step/outcome`: that one simulator alone serves.
pub fn pool_base(own_outcome: &str) -> (Option<String>, String) {
    match own_outcome.strip_suffix(OUTCOME_SUFFIX) {
        Some("") => (Some("/".into()), "/".into()),
        Some(ns) => (Some(format!("{ns}/")), ns.into()),
        None => (None, own_outcome.to_string()),
    }
}

/// The simulators (their namespaces) that the outcome topics in `topics` show below `base`:
/// each `<base><ns>/ga_step/outcome` with `<ns>` not empty gives `<base><ns>`; `own_outcome`,
/// the node's own simulator's topic, is not among them.
pub fn pool_namespaces(topics: &[String], base: &str, own_outcome: &str) -> Vec<String> {
    topics
        .iter()
        .filter(|t| t.as_str() != own_outcome)
        .filter_map(|t| t.strip_suffix(OUTCOME_SUFFIX))
        .filter(|ns| ns.len() > base.len() && ns.starts_with(base))
        .map(str::to_string)
        .collect()
}

/// What a candidate does after an attempt.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NextTry {
    /// It has its answer.
    Done,
    /// Send it again (to whichever simulator the pool picks).
    Again,
    /// Every attempt was missed: it scores as a void.
    Void,
}

/// Losses of a simulator a candidate may suffer before each further one counts as a miss.
pub const LOST_PER_MISS: u32 = 3;

/// A candidate's attempts: `attempts` missed ones make it void; a lost simulator costs none,
/// up to [`LOST_PER_MISS`] losses.
#[derive(Debug, Clone, Copy)]
pub struct CandidateTries {
    attempts: u32,
    missed: u32,
    lost: u32,
}

impl CandidateTries {
    /// A candidate allowed `attempts` missed attempts (at least one).
    pub fn new(attempts: u32) -> CandidateTries {
        CandidateTries {
            attempts: attempts.max(1),
            missed: 0,
            lost: 0,
        }
    }

    /// The attempts missed so far.
    pub fn missed(&self) -> u32 {
        self.missed
    }

    /// After an attempt that ended as `end`.
    pub fn after(&mut self, end: AttemptEnd) -> NextTry {
        let end = match end {
            AttemptEnd::Lost => {
                self.lost += 1;
                if self.lost <= LOST_PER_MISS {
                    return NextTry::Again;
                }
                AttemptEnd::Missed
            }
            other => other,
        };
        match end {
            AttemptEnd::Answered | AttemptEnd::Lost => NextTry::Done,
            AttemptEnd::Missed => {
                self.missed += 1;
                if self.missed >= self.attempts {
                    NextTry::Void
                } else {
                    NextTry::Again
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn used(p: &mut SimulatorPool) -> String {
        match p.pick() {
            Pick::Use(id) => id,
            other => panic!("expected a simulator, got {other:?}"),
        }
    }

    #[test]
    fn an_empty_pool_waits() {
        let mut p = SimulatorPool::new(3);
        assert_eq!(p.pick(), Pick::Wait);
        assert_eq!(p.present(), 0);
    }

    #[test]
    fn one_candidate_in_flight_per_simulator_least_recently_used_first() {
        let mut p = SimulatorPool::new(3);
        for id in ["a", "b", "c"] {
            assert!(p.seen(id));
        }
        assert!(!p.seen("b"), "seen twice is not new");
        assert_eq!([used(&mut p), used(&mut p), used(&mut p)], ["a", "b", "c"]);
        assert_eq!(p.pick(), Pick::Wait, "all three busy");
        p.release("b", AttemptEnd::Answered);
        p.release("a", AttemptEnd::Answered);
        // b and a are free; a was used before b.
        assert_eq!(used(&mut p), "a");
        assert_eq!(used(&mut p), "b");
        assert_eq!(p.pick(), Pick::Wait);
    }

    #[test]
    fn a_simulator_that_missed_gets_nothing_while_another_answers() {
        let mut p = SimulatorPool::new(3);
        p.seen("a");
        p.seen("b");
        assert_eq!(used(&mut p), "a");
        assert_eq!(used(&mut p), "b");
        p.release("a", AttemptEnd::Missed);
        // a is free but missed; b is busy and has missed nothing: wait for b.
        assert_eq!(p.pick(), Pick::Wait);
        p.release("b", AttemptEnd::Answered);
        assert_eq!(used(&mut p), "b");
        p.release("b", AttemptEnd::Answered);
        assert_eq!(used(&mut p), "b", "still b");
        p.release("b", AttemptEnd::Answered);
        // a restarted: its misses are forgotten, and it was used longest ago.
        p.restarted("a");
        assert_eq!(used(&mut p), "a");
    }

    #[test]
    fn a_single_simulator_is_always_the_one_until_it_missed_max_in_a_row() {
        let mut p = SimulatorPool::new(3);
        p.seen("only");
        for _ in 0..2 {
            assert_eq!(used(&mut p), "only");
            p.release("only", AttemptEnd::Missed);
        }
        assert_eq!(used(&mut p), "only");
        p.release("only", AttemptEnd::Answered);
        for _ in 0..3 {
            assert_eq!(used(&mut p), "only");
            p.release("only", AttemptEnd::Missed);
        }
        assert_eq!(p.pick(), Pick::Exhausted);
    }

    #[test]
    fn the_pool_is_exhausted_only_when_every_present_simulator_missed_max() {
        let mut p = SimulatorPool::new(2);
        p.seen("a");
        p.seen("b");
        for _ in 0..2 {
            assert_eq!(used(&mut p), "a");
            p.release("a", AttemptEnd::Missed);
            // b has missed fewer: it goes next.
            assert_eq!(used(&mut p), "b");
            p.release("b", AttemptEnd::Missed);
        }
        assert_eq!(p.pick(), Pick::Exhausted);
        // A third simulator appears: the pool goes on with it.
        p.seen("c");
        assert_eq!(used(&mut p), "c");
    }

    #[test]
    fn a_gone_simulator_is_not_picked_and_comes_back_fresh() {
        let mut p = SimulatorPool::new(3);
        p.seen("a");
        p.seen("b");
        assert_eq!(used(&mut p), "a");
        p.release("a", AttemptEnd::Missed);
        p.gone("a");
        assert!(!p.is_present("a"));
        assert_eq!(p.present(), 1);
        assert_eq!(used(&mut p), "b");
        assert_eq!(p.pick(), Pick::Wait, "a is gone, b busy");
        p.release("b", AttemptEnd::Answered);
        assert!(p.seen("a"), "back");
        // Back with its misses forgotten, and used longer ago than b.
        assert_eq!(used(&mut p), "a");
    }

    #[test]
    fn a_busy_simulator_that_goes_is_released_without_a_miss() {
        let mut p = SimulatorPool::new(1);
        p.seen("a");
        p.seen("b");
        assert_eq!(used(&mut p), "a");
        p.gone("a");
        p.release("a", AttemptEnd::Lost);
        assert_eq!(used(&mut p), "b");
        p.release("b", AttemptEnd::Answered);
        p.seen("a");
        assert_eq!(used(&mut p), "a", "not counted as a miss, so not exhausted at max 1");
    }

    #[test]
    fn presence_follows_the_readers_and_writers_and_a_new_reader_is_a_restart() {
        let mut p = SimulatorPool::new(3);
        assert_eq!(p.observe("a", 1, 0), Change::None, "a reader alone is not a simulator");
        assert_eq!(p.present(), 0);
        assert_eq!(p.observe("a", 1, 1), Change::Joined);
        assert_eq!(p.observe("a", 1, 1), Change::None);
        assert_eq!(used(&mut p), "a");
        p.release("a", AttemptEnd::Missed);
        // A second reader (a restart within the old one's lease): misses forgotten.
        assert_eq!(p.observe("a", 2, 1), Change::Restarted);
        assert_eq!(used(&mut p), "a");
        p.release("a", AttemptEnd::Missed);
        // The old reader's lease ends: fewer readers, still present, nothing to do.
        assert_eq!(p.observe("a", 1, 1), Change::None);
        assert_eq!(p.observe("a", 0, 1), Change::Left);
        assert_eq!(p.pick(), Pick::Wait);
        assert_eq!(p.observe("a", 0, 0), Change::None);
        assert_eq!(p.observe("a", 1, 1), Change::Joined);
    }

    #[test]
    fn a_miss_at_a_simulator_that_left_meanwhile_is_not_held_against_it() {
        let mut p = SimulatorPool::new(1);
        p.observe("a", 1, 1);
        p.observe("b", 1, 1);
        assert_eq!(used(&mut p), "a");
        assert_eq!(p.observe("a", 0, 0), Change::Left);
        p.release("a", AttemptEnd::Missed);
        assert_eq!(p.observe("a", 1, 1), Change::Joined);
        // b was never used, so it goes first; then a, whose miss was not counted (else, at a
        // maximum of 1, the pool would be exhausted or a left out).
        assert_eq!(used(&mut p), "b");
        assert_eq!(used(&mut p), "a");
    }

    #[test]
    fn a_gone_simulator_does_not_keep_the_pool_from_being_exhausted() {
        let mut p = SimulatorPool::new(1);
        p.seen("a");
        p.seen("b");
        assert_eq!(used(&mut p), "a");
        p.release("a", AttemptEnd::Missed);
        p.gone("b");
        // b had missed nothing but is gone: a alone counts, and it missed the maximum.
        assert_eq!(p.pick(), Pick::Exhausted);
    }

    #[test]
    fn the_pool_is_below_the_nodes_namespace() {
        assert_eq!(pool_base("/ga_step/outcome"), (Some("/".into()), "/".into()));
        assert_eq!(pool_base("/ga/ga_step/outcome"), (Some("/ga/".into()), "/ga".into()));
        assert_eq!(pool_base("/webots/answers"), (None, "/webots/answers".into()));
        let topics: Vec<String> = [
            "/ga_step/outcome",
            "/sim1/ga_step/outcome",
            "/lab/pc2/sim/ga_step/outcome",
            "/ga/sim1/ga_step/outcome",
            "/ga/ga_step/outcome",
            "/gax/ga_step/outcome",
            "/sim1/other/outcome",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        assert_eq!(
            pool_namespaces(&topics, "/", "/ga_step/outcome"),
            ["/sim1", "/lab/pc2/sim", "/ga/sim1", "/ga", "/gax"]
        );
        // Below /ga only: not /gax, not /ga itself (the node's own simulator).
        assert_eq!(pool_namespaces(&topics, "/ga/", "/ga/ga_step/outcome"), ["/ga/sim1"]);
    }

    #[test]
    fn a_candidate_is_void_after_its_attempts_and_a_lost_simulator_costs_none() {
        let mut t = CandidateTries::new(2);
        assert_eq!(t.after(AttemptEnd::Lost), NextTry::Again);
        assert_eq!(t.after(AttemptEnd::Lost), NextTry::Again);
        assert_eq!(t.missed(), 0);
        assert_eq!(t.after(AttemptEnd::Missed), NextTry::Again);
        assert_eq!(t.after(AttemptEnd::Lost), NextTry::Again);
        assert_eq!(t.after(AttemptEnd::Missed), NextTry::Void);
        let mut t = CandidateTries::new(2);
        assert_eq!(t.after(AttemptEnd::Missed), NextTry::Again);
        assert_eq!(t.after(AttemptEnd::Answered), NextTry::Done);
        assert_eq!(
            CandidateTries::new(0).after(AttemptEnd::Missed),
            NextTry::Void,
            "at least one attempt"
        );
    }

    #[test]
    fn losses_beyond_the_allowance_count_as_misses() {
        let mut t = CandidateTries::new(2);
        for _ in 0..LOST_PER_MISS {
            assert_eq!(t.after(AttemptEnd::Lost), NextTry::Again);
        }
        assert_eq!(t.missed(), 0);
        assert_eq!(t.after(AttemptEnd::Lost), NextTry::Again, "the first miss");
        assert_eq!(t.missed(), 1);
        assert_eq!(
            t.after(AttemptEnd::Lost),
            NextTry::Void,
            "the second: void, not forever"
        );
    }
}
