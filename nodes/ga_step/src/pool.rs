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
//!   to another simulator or the same one restarted, without counting an attempt; one whose
//!   attempt was missed counts it; after `attempts` missed attempts it scores as a void
//!   ([`CandidateTries`]).
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

#[derive(Debug, Clone)]
struct Slot {
    id: String,
    busy: bool,
    present: bool,
    missed_in_a_row: u32,
    last_used: u64,
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
                AttemptEnd::Missed => s.missed_in_a_row += 1,
                AttemptEnd::Lost => {}
            }
        }
    }
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

/// A candidate's attempts: `attempts` missed ones make it void; a lost simulator costs none.
#[derive(Debug, Clone, Copy)]
pub struct CandidateTries {
    attempts: u32,
    missed: u32,
}

impl CandidateTries {
    /// A candidate allowed `attempts` missed attempts (at least one).
    pub fn new(attempts: u32) -> CandidateTries {
        CandidateTries {
            attempts: attempts.max(1),
            missed: 0,
        }
    }

    /// The attempts missed so far.
    pub fn missed(&self) -> u32 {
        self.missed
    }

    /// After an attempt that ended as `end`.
    pub fn after(&mut self, end: AttemptEnd) -> NextTry {
        match end {
            AttemptEnd::Answered => NextTry::Done,
            AttemptEnd::Lost => NextTry::Again,
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
}
