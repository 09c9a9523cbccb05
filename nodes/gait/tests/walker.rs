//! The walker: queued moves executed one per call, plans asked for and taken by epoch, the end
//! at the goal, and giving up.

use mobil_gait::{BodyPose, Chunk, GaitState, Plan, PlanFailure, PlanStep, QuadrupedModel, Rule, WalkNext, Walker};
use nalgebra::Point2;

fn step(state: GaitState, rule: Option<u8>, evaluation: f64) -> PlanStep {
    PlanStep {
        state,
        rule: rule.map(|n| Rule::new(n).unwrap()),
        evaluation,
    }
}

#[test]
fn the_walker_executes_queued_moves_and_ends_at_the_goal() {
    let model = QuadrupedModel::default();
    let s0 = GaitState::nominal(
        &model,
        BodyPose {
            x: 0.0,
            y: 0.0,
            phi: 0.0,
        },
    );
    let mut walker = Walker::new(s0);
    assert_eq!(walker.next(0.5, 10), WalkNext::Idle);
    walker.set_goal(Point2::new(0.0, 2.0));
    assert_eq!(walker.next(0.5, 10), WalkNext::Plan);
    // A hand-made short-time plan: two body moves of 1 along y.
    let mut s1 = s0;
    s1.body.y = 1.0;
    let mut s2 = s0;
    s2.body.y = 2.0;
    let chunk = |from: GaitState, to: GaitState| Chunk {
        plan: Plan {
            steps: vec![step(from, None, 2.0), step(to, Some(2), 1.0)],
            success: false,
            failure: Some(PlanFailure::ExpansionLimit(5)),
            expanded: 5,
            generated: 9,
        },
        executed: vec![step(to, Some(2), 1.0)],
    };
    assert_eq!(
        walker.take_chunk(walker.epoch(), chunk(s0, s1), 0.5, 10),
        Some(WalkNext::Move)
    );
    assert_eq!(walker.state().body.y, 0.0, "a queued move waits for its tick");
    assert_eq!(walker.step().map(|s| s.state.body.y), Some(1.0));
    assert_eq!(walker.step(), None);
    // 1 from the goal, above the 0.5 tolerance: plan again.
    assert_eq!(walker.next(0.5, 10), WalkNext::Plan);
    assert_eq!(
        walker.take_chunk(walker.epoch(), chunk(s1, s2), 0.5, 10),
        Some(WalkNext::Move)
    );
    walker.step();
    assert_eq!(walker.next(0.5, 10), WalkNext::Reached);
    assert_eq!(walker.chunks(), 2);
    assert_eq!(walker.next(0.5, 10), WalkNext::Idle);

    // A plan without a move gives up with the plan's reason; so does the chunk limit.
    walker.set_goal(Point2::new(0.0, 9.0));
    let empty = Chunk {
        plan: Plan {
            steps: vec![],
            success: false,
            failure: Some(PlanFailure::NoSuccessor),
            expanded: 0,
            generated: 0,
        },
        executed: vec![],
    };
    match walker.take_chunk(walker.epoch(), empty, 0.5, 10) {
        Some(WalkNext::GaveUp(why)) => assert!(why.starts_with("NO_SUCCESSOR"), "{why}"),
        other => panic!("{other:?}"),
    }
    walker.set_goal(Point2::new(0.0, 9.0));
    walker.take_chunk(walker.epoch(), chunk(s2, s1), 0.5, 1);
    walker.step();
    assert_eq!(
        walker.next(0.5, 1),
        WalkNext::GaveUp("1 short-time plans made without reaching the goal".into())
    );
    // A new goal drops the queued moves.
    walker.set_goal(Point2::new(0.0, 9.0));
    walker.take_chunk(walker.epoch(), chunk(s1, s0), 0.5, 10);
    walker.set_goal(Point2::new(5.0, 9.0));
    assert_eq!(walker.step(), None);
}
