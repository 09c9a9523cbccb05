//! Whether a checkpoint continues the run a caller asks for: the same evaluator, seed,
//! population, crossover, level window, fitness shape and every other parameter (a resume of
//! another run would mix two measures, or two streams, in one history), and not a run scored in
//! a way no longer offered.

use crate::checkpoint::EvaluatorTag;
use crate::ga::{GaSetup, GaState};

/// Why a checkpoint cannot be resumed as the run asked for.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ResumeRefusal {
    /// The run was scored by the built-in physics' robust score with a fall's distance
    /// counted, which is no longer offered (the worse of two outcomes is not the lower score
    /// there).
    Retired,
    /// The checkpoint is of another run: what differs, one phrase each ("seed 1 (asked 2)").
    OtherRun(Vec<String>),
}

/// Checks that `state`, scored by `recorded`, is the run asked for: `seed`, `setup` (the
/// parameter file's or the defaults, with the options' population, crossover and level window)
/// and the evaluator `asked`.
pub fn check_resume(
    state: &GaState,
    recorded: &EvaluatorTag,
    seed: u64,
    setup: &GaSetup,
    asked: &EvaluatorTag,
) -> Result<(), ResumeRefusal> {
    let f = &state.setup.fitness;
    if matches!(recorded, EvaluatorTag::Physics { .. }) && f.robust_check && f.distance_on_fall {
        return Err(ResumeRefusal::Retired);
    }
    let differences = run_differences(state, recorded, seed, setup, asked);
    if differences.is_empty() {
        Ok(())
    } else {
        Err(ResumeRefusal::OtherRun(differences))
    }
}

/// What differs between a checkpoint's run and the one asked for, one phrase each (empty: the
/// same run).
pub fn run_differences(
    state: &GaState,
    recorded: &EvaluatorTag,
    seed: u64,
    setup: &GaSetup,
    asked: &EvaluatorTag,
) -> Vec<String> {
    let mut differences = Vec::new();
    let mut differ = |same: bool, what: &str, theirs: String, ours: String| {
        if !same {
            differences.push(format!("{what} {theirs} (asked {ours})"));
        }
    };
    differ(recorded == asked, "evaluator", recorded.to_string(), asked.to_string());
    differ(state.seed == seed, "seed", state.seed.to_string(), seed.to_string());
    let (was, now) = (&state.setup.ga, &setup.ga);
    differ(
        was.population == now.population && was.offspring == now.offspring,
        "population",
        was.population.to_string(),
        now.population.to_string(),
    );
    differ(
        was.crossover == now.crossover,
        "crossover",
        was.crossover.to_string(),
        now.crossover.to_string(),
    );
    differ(
        was.level_window == now.level_window,
        "level window",
        was.level_window.to_string(),
        now.level_window.to_string(),
    );
    let (was_f, now_f) = (&state.setup.fitness, &setup.fitness);
    differ(
        was_f.distance_on_fall == now_f.distance_on_fall && was_f.backward_allowance == now_f.backward_allowance,
        "fitness",
        was_f.shape(),
        now_f.shape(),
    );
    // The robust score is the built-in physics' alone: other evaluators ignore the switch.
    let robust_counts = matches!(asked, EvaluatorTag::Physics { .. });
    differ(
        !robust_counts || was_f.robust_check == now_f.robust_check,
        "robust_check",
        was_f.robust_check.to_string(),
        now_f.robust_check.to_string(),
    );
    differ(
        !robust_counts || was_f.physics == now_f.physics,
        "physics",
        was_f.physics.to_string(),
        now_f.physics.to_string(),
    );
    let mut theirs = state.setup.clone();
    if !robust_counts {
        theirs.fitness.robust_check = now_f.robust_check;
        theirs.fitness.physics = now_f.physics;
    }
    if differences.is_empty() && theirs != *setup {
        differences.push("other parameters of the robot, the algorithm or the fitness (--params)".to_owned());
    }
    differences
}
