//! How a run ended, as `ga_step` reports it: [`RunSummary`], taken from the state the outputs
//! hold, and its one line.

use crate::ga::{GaState, StopReason};
use std::path::Path;
use std::time::Duration;

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    /// Why it stopped.
    pub reason: StopReason,
    /// Generations done.
    pub generation: u32,
    /// Best fitness.
    pub best_fitness: f64,
    /// Whether the best falls.
    pub best_fell: bool,
    /// The best's forward distance (m).
    pub best_forward: f64,
    /// First generation with a non-falling forward step.
    pub first_step_generation: Option<u32>,
    /// Wall time of this invocation.
    pub wall: Duration,
    /// With an external simulator: the candidates it left unanswered after every attempt,
    /// scored 0 (void scores). `None` with the built-in physics.
    pub void_scores: Option<u64>,
}

impl RunSummary {
    /// The summary of `state`, stopped by `reason` after `wall`. `lost`: the generation just
    /// made is void (an interrupted external evaluation) and the outputs hold the one before,
    /// so that is the generation reported. `None` when the history has no row of it.
    pub fn of(
        state: &GaState,
        reason: StopReason,
        lost: bool,
        wall: Duration,
        void_scores: Option<u64>,
    ) -> Option<RunSummary> {
        let generation = if lost {
            state.generation.checked_sub(1)?
        } else {
            state.generation
        };
        let row = state.history.get(generation as usize)?;
        Some(RunSummary {
            reason,
            generation,
            best_fitness: row.max,
            best_fell: row.best_fell,
            best_forward: row.best_forward,
            first_step_generation: state.first_step_generation.filter(|g| *g <= generation),
            wall,
            void_scores,
        })
    }

    /// The line printed at the end; `out` is the output directory.
    pub fn line(&self, out: &Path) -> String {
        let why = match self.reason {
            StopReason::ForwardStep => "a non-falling forward step",
            StopReason::Levelled => "the mean fitness levelled off",
            StopReason::MaxGenerations => "the requested generations",
            StopReason::Interrupted => "an interrupt (resume with --resume)",
        };
        let step = match self.first_step_generation {
            Some(g) => format!("first forward step at generation {g}"),
            None => "no forward step yet".to_owned(),
        };
        let void = match self.void_scores {
            Some(v) => format!("; {v} unanswered candidates scored 0"),
            None => String::new(),
        };
        format!(
            "ga_step: stopped at generation {} by {why}; best fitness {:.4} ({}, {:+.3} m forward); {step}{void}; {:.1} s; wrote {}",
            self.generation,
            self.best_fitness,
            if self.best_fell { "falls" } else { "stands" },
            self.best_forward,
            self.wall.as_secs_f64(),
            out.display()
        )
    }
}
