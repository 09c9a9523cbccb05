//! How a run is resumed and how it ends: a checkpoint continues only the run it is of (what
//! differs is named), a retired score is refused, and the summary reports the generation the
//! outputs hold in one line.

use mobil_ga_step::{
    check_resume, Crossover, EvaluatorTag, FitnessConfig, GaConfig, GaSetup, GaState, NaoModel, ResumeRefusal,
    RunSummary, StopReason, TestLandscape,
};
use std::ops::ControlFlow;
use std::path::Path;
use std::time::Duration;

const PHYSICS: EvaluatorTag = EvaluatorTag::Physics { physics_version: 3 };

fn setup() -> GaSetup {
    GaSetup {
        ga: GaConfig {
            population: 6,
            offspring: 6,
            stop_at_step: false,
            ..GaConfig::default()
        },
        ..GaSetup::default()
    }
}

/// A run of `setup` with seed 5, to generation 2.
fn state(setup: GaSetup) -> GaState {
    let e = TestLandscape::new(NaoModel::default(), FitnessConfig::default());
    let mut s = GaState::start(setup, 5, &e, 1).unwrap();
    s.run(&e, 1, 2, |_| ControlFlow::Continue(()));
    s
}

fn differences(r: Result<(), ResumeRefusal>) -> Vec<String> {
    match r {
        Err(ResumeRefusal::OtherRun(d)) => d,
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_checkpoint_continues_only_its_own_run() {
    let s = state(setup());
    assert_eq!(check_resume(&s, &PHYSICS, 5, &setup(), &PHYSICS), Ok(()));
    // Seed and evaluator differ: both named, with the checkpoint's value and the one asked.
    let d = differences(check_resume(&s, &PHYSICS, 6, &setup(), &EvaluatorTag::Ros));
    assert_eq!(d.len(), 2, "{d:?}");
    assert!(d[1] == "seed 5 (asked 6)", "{d:?}");
    let mut other = setup();
    other.ga.crossover = Crossover::Arithmetic;
    other.ga.level_window = 7;
    let d = differences(check_resume(&s, &PHYSICS, 5, &other, &PHYSICS));
    assert_eq!(d, ["crossover blx (asked arithmetic)", "level window 20 (asked 7)"]);
    // A parameter without a phrase of its own.
    let mut other = setup();
    other.model.step_time = 2.4;
    let d = differences(check_resume(&s, &PHYSICS, 5, &other, &PHYSICS));
    assert_eq!(
        d,
        ["other parameters of the robot, the algorithm or the fitness (--params)"]
    );
}

#[test]
fn the_robust_switch_counts_for_the_physics_alone() {
    let s = state(setup());
    let mut robust = setup();
    robust.fitness.robust_check = !s.setup.fitness.robust_check;
    let d = differences(check_resume(&s, &PHYSICS, 5, &robust, &PHYSICS));
    assert_eq!(d.len(), 1);
    assert!(d[0].starts_with("robust_check "), "{d:?}");
    // An external simulator ignores it: the same run.
    assert_eq!(
        check_resume(&s, &EvaluatorTag::Ros, 5, &robust, &EvaluatorTag::Ros),
        Ok(())
    );
}

#[test]
fn a_retired_score_is_refused() {
    let mut retired = setup();
    retired.fitness.robust_check = true;
    retired.fitness.distance_on_fall = true;
    let mut s = state(setup());
    s.setup = retired.clone();
    assert_eq!(
        check_resume(&s, &PHYSICS, 5, &retired, &PHYSICS),
        Err(ResumeRefusal::Retired)
    );
    // Scored by an external simulator, the switch meant nothing: not refused for it.
    assert_eq!(
        check_resume(&s, &EvaluatorTag::Ros, 5, &retired, &EvaluatorTag::Ros),
        Ok(())
    );
}

#[test]
fn the_summary_reports_the_generation_the_outputs_hold() {
    let s = state(setup());
    let wall = Duration::from_millis(1234);
    let done = RunSummary::of(&s, StopReason::MaxGenerations, false, wall, None).unwrap();
    let row = &s.history[2];
    assert_eq!((done.generation, done.best_fitness), (2, row.max));
    let line = done.line(Path::new("out/dir"));
    assert!(
        line.starts_with("ga_step: stopped at generation 2 by the requested generations; best fitness "),
        "{line}"
    );
    assert!(line.ends_with("; no forward step yet; 1.2 s; wrote out/dir"), "{line}");
    // A lost generation: the one before it, and the external simulator's void scores.
    let lost = RunSummary::of(&s, StopReason::Interrupted, true, wall, Some(3)).unwrap();
    assert_eq!((lost.generation, lost.best_fitness), (1, s.history[1].max));
    let line = lost.line(Path::new("d"));
    assert!(
        line.starts_with("ga_step: stopped at generation 1 by an interrupt (resume with --resume);"),
        "{line}"
    );
    assert!(line.contains("; 3 unanswered candidates scored 0; 1.2 s;"), "{line}");
    // A forward step found later than the generation reported is not reported.
    let mut stepped = s.clone();
    stepped.first_step_generation = Some(2);
    let lost = RunSummary::of(&stepped, StopReason::Interrupted, true, wall, None).unwrap();
    assert_eq!(lost.first_step_generation, None);
    let done = RunSummary::of(&stepped, StopReason::ForwardStep, false, wall, None).unwrap();
    assert!(done
        .line(Path::new("d"))
        .contains("by a non-falling forward step; best fitness"));
    assert!(done
        .line(Path::new("d"))
        .contains("; first forward step at generation 2; "));
}

#[test]
fn the_line_gives_the_best_and_how_it_moved() {
    let summary = RunSummary {
        reason: StopReason::Levelled,
        generation: 40,
        best_fitness: 3.21456,
        best_fell: false,
        best_forward: 0.1,
        first_step_generation: Some(31),
        wall: Duration::from_secs_f64(61.26),
        void_scores: None,
    };
    assert_eq!(
        summary.line(Path::new("runs/blx-1")),
        "ga_step: stopped at generation 40 by the mean fitness levelled off; best fitness 3.2146 (stands, +0.100 m forward); \
         first forward step at generation 31; 61.3 s; wrote runs/blx-1"
    );
}
