//! Short-time plans (a receding horizon), as a robot uses the planner online: plan with a small
//! expansion cap, execute the first moves, replan from the state reached.

use crate::config::{Evaluation, GaitConfig, RuleSet};
use crate::model::GaitState;
use crate::model::QuadrupedModel;
use crate::planner::{plan, Plan, PlanFailure, PlanStep};
use crate::rules::vzd;
use nalgebra::Point2;

/// A receding-horizon planner.
#[derive(Debug, Clone)]
pub struct RecedingHorizon {
    /// The robot.
    pub model: QuadrupedModel,
    /// The parameters (`goal_tolerance` ends the walk).
    pub cfg: GaitConfig,
    /// The rule set.
    pub set: RuleSet,
    /// The evaluation.
    pub eval: Evaluation,
    /// Expansion cap of each short-time plan.
    pub chunk_expansions: u32,
    /// Moves executed from each plan before replanning (≥ 1).
    pub execute_steps: usize,
}

/// One short-time plan and the moves taken from it.
#[derive(Debug, Clone)]
pub struct Chunk {
    /// The short-time plan (complete or the best partial one).
    pub plan: Plan,
    /// The moves executed: the plan's first `execute_steps` steps after its start.
    pub executed: Vec<PlanStep>,
}

impl Chunk {
    /// The state the executed moves reach (`None` if nothing was executed).
    pub fn reached(&self) -> Option<&GaitState> {
        self.executed.last().map(|s| &s.state)
    }
}

/// A whole walk of short-time plans.
#[derive(Debug, Clone)]
pub struct Walk {
    /// Every state walked through, the start first.
    pub steps: Vec<PlanStep>,
    /// Short-time plans made.
    pub chunks: u32,
    /// States expanded over all plans.
    pub expanded: u64,
    /// Whether the goal was reached.
    pub reached: bool,
    /// Why not, when it was not.
    pub failure: Option<PlanFailure>,
}

impl RecedingHorizon {
    /// The paper's robot and the configuration's reading, with a set and evaluation; 2000
    /// expansions per plan and 4 moves executed (one gait cycle's worth: each leg once).
    pub fn new(cfg: GaitConfig, set: RuleSet, eval: Evaluation) -> Self {
        RecedingHorizon {
            model: QuadrupedModel::paper(cfg.reading),
            cfg,
            set,
            eval,
            chunk_expansions: 2000,
            execute_steps: 4,
        }
    }

    /// The next short-time plan from `current` toward `goal`, and its first moves. Empty when
    /// `current` is already within the goal tolerance. When no state generated within the cap
    /// is nearer the goal than `current` (a plateau of leg configurations that tie under (1)
    /// and (2)), the cap is doubled and the plan made again, up to `cfg.max_expansions`.
    pub fn next_chunk(&self, current: &GaitState, goal: Point2<f64>, stop: &mut dyn FnMut() -> bool) -> Chunk {
        let mut cap = self.chunk_expansions.max(1);
        loop {
            let plan = plan(&self.model, &self.cfg, current, goal, self.set, self.eval, cap, stop);
            let executed: Vec<PlanStep> = plan
                .steps
                .iter()
                .skip(1)
                .take(self.execute_steps.max(1))
                .cloned()
                .collect();
            let plateau = executed.is_empty() && matches!(plan.failure, Some(PlanFailure::ExpansionLimit(_)));
            if !plateau || cap >= self.cfg.max_expansions {
                return Chunk { plan, executed };
            }
            cap = cap.saturating_mul(2).min(self.cfg.max_expansions);
        }
    }

    /// Plans and executes chunks from `start` until the goal is reached, `max_chunks` plans
    /// were made, a plan makes no move, or `stop()` says stop.
    pub fn run(&self, start: &GaitState, goal: Point2<f64>, max_chunks: u32, stop: &mut dyn FnMut() -> bool) -> Walk {
        let mut walk = Walk {
            steps: vec![PlanStep {
                state: *start,
                rule: None,
                evaluation: 0.0,
            }],
            chunks: 0,
            expanded: 0,
            reached: false,
            failure: None,
        };
        let mut current = *start;
        loop {
            if vzd(&current, goal) <= self.cfg.goal_tolerance {
                walk.reached = true;
                return walk;
            }
            if walk.chunks >= max_chunks {
                walk.failure = Some(PlanFailure::ChunkLimit(max_chunks));
                return walk;
            }
            let chunk = self.next_chunk(&current, goal, stop);
            walk.chunks += 1;
            walk.expanded += u64::from(chunk.plan.expanded);
            match chunk.reached() {
                Some(s) => current = *s,
                None => {
                    walk.failure = chunk.plan.failure.clone().or(Some(PlanFailure::NoSuccessor));
                    return walk;
                }
            }
            if matches!(chunk.plan.failure, Some(PlanFailure::Stopped)) {
                walk.steps.extend(chunk.executed);
                walk.failure = Some(PlanFailure::Stopped);
                return walk;
            }
            walk.steps.extend(chunk.executed);
        }
    }
}
