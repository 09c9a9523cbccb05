//! The executor of short-time plans: a quadruped that walks to a goal one move at a time,
//! asking its caller for the next plan whenever the moves of the last one are done. Time is the
//! caller's (one [`Walker::step`] per move period) and so is planning (the caller makes the
//! plan from [`Walker::state`], off its loop if it likes, and hands it back with the
//! [`Walker::epoch`] it was asked for, so a plan made for an older goal, ground or configuration
//! is dropped).

use crate::horizon::Chunk;
use crate::model::GaitState;
use crate::planner::PlanStep;
use crate::rules::vzd;
use nalgebra::Point2;
use std::collections::VecDeque;

/// What the walk asks of the shell after a move or a plan.
#[derive(Debug, Clone, PartialEq)]
pub enum WalkNext {
    /// Make the next short-time plan from [`Walker::state`].
    Plan,
    /// Wait for the move ticker: moves are queued.
    Move,
    /// The body centre is within the goal tolerance: the walk is over.
    Reached,
    /// The walk gave up (no move possible, or `walk_max_chunks` plans made).
    GaveUp(String),
    /// No goal.
    Idle,
}

/// The simulated quadruped: its state, the goal, the moves of the current short-time plan
/// still to execute. Time is the caller's: one [`Walker::step`] per move period.
#[derive(Debug, Clone)]
pub struct Walker {
    state: GaitState,
    goal: Option<Point2<f64>>,
    queue: VecDeque<PlanStep>,
    plan: Vec<PlanStep>,
    current: Option<PlanStep>,
    chunks: u32,
    epoch: u64,
}

impl Walker {
    /// Standing at `state`, no goal.
    pub fn new(state: GaitState) -> Self {
        Walker {
            state,
            goal: None,
            queue: VecDeque::new(),
            plan: Vec::new(),
            current: None,
            chunks: 0,
            epoch: 0,
        }
    }

    /// The state the quadruped stands in.
    pub fn state(&self) -> &GaitState {
        &self.state
    }

    /// The goal walked to, if any.
    pub fn goal(&self) -> Option<Point2<f64>> {
        self.goal
    }

    /// The short-time plan being executed (empty before the first).
    pub fn plan(&self) -> &[PlanStep] {
        &self.plan
    }

    /// The move last executed (`None` before the first of a walk).
    pub fn current(&self) -> Option<&PlanStep> {
        self.current.as_ref()
    }

    /// Short-time plans made for the current goal.
    pub fn chunks(&self) -> u32 {
        self.chunks
    }

    /// A new goal: the moves queued are dropped (the quadruped stands on four feet between
    /// moves); the next plan starts from where it stands.
    pub fn set_goal(&mut self, goal: Point2<f64>) {
        self.goal = Some(goal);
        self.queue.clear();
        self.current = None;
        self.chunks = 0;
        self.epoch += 1;
    }

    /// Stops the walk where it is: no goal, no moves queued, no plan or last move to draw.
    pub fn stop(&mut self) {
        self.goal = None;
        self.queue.clear();
        self.plan.clear();
        self.current = None;
        self.epoch += 1;
    }

    /// The plans made so far no longer hold (the ground or the configuration changed): the
    /// moves queued are dropped, and a plan asked for before now is refused by
    /// [`Walker::take_chunk`]; the next plan starts from where the quadruped stands.
    pub fn replan(&mut self) {
        self.queue.clear();
        self.epoch += 1;
    }

    /// The walk's plan counter: bumped by every new goal, stop and [`Walker::replan`]. A plan
    /// is asked for with the counter of the moment and taken only while it is unchanged.
    pub fn epoch(&self) -> u64 {
        self.epoch
    }

    /// Takes a short-time plan made from [`Walker::state`] when the counter was `epoch`: its
    /// executed moves are queued. A plan from an older counter (made for another goal, ground
    /// or configuration) is dropped: `None`, nothing changes.
    pub fn take_chunk(&mut self, epoch: u64, chunk: Chunk, tolerance: f64, max_chunks: u32) -> Option<WalkNext> {
        if epoch != self.epoch || self.goal.is_none() {
            return None;
        }
        Some(self.take_current_chunk(chunk, tolerance, max_chunks))
    }

    fn take_current_chunk(&mut self, chunk: Chunk, tolerance: f64, max_chunks: u32) -> WalkNext {
        self.chunks += 1;
        self.plan = chunk.plan.steps.clone();
        self.queue = chunk.executed.into_iter().collect();
        if self.queue.is_empty() {
            let why = chunk
                .plan
                .failure
                .map_or_else(|| "the short-time plan has no move".to_owned(), |f| f.to_string());
            self.goal = None;
            return WalkNext::GaveUp(why);
        }
        self.next(tolerance, max_chunks)
    }

    /// Executes the next queued move, if any, and returns it.
    pub fn step(&mut self) -> Option<&PlanStep> {
        let s = self.queue.pop_front()?;
        self.state = s.state;
        self.current = Some(s);
        self.current.as_ref()
    }

    /// What comes next: moves to execute, a plan to make, or the end of the walk.
    pub fn next(&mut self, tolerance: f64, max_chunks: u32) -> WalkNext {
        let Some(goal) = self.goal else {
            return WalkNext::Idle;
        };
        if !self.queue.is_empty() {
            return WalkNext::Move;
        }
        if vzd(&self.state, goal) <= tolerance {
            self.goal = None;
            return WalkNext::Reached;
        }
        if self.chunks >= max_chunks {
            self.goal = None;
            return WalkNext::GaveUp(format!("{max_chunks} short-time plans made without reaching the goal"));
        }
        WalkNext::Plan
    }
}
