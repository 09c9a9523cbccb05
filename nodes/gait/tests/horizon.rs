//! Short-time plans: the receding horizon walks to the paper's goal, one chunk at a time.

use mobil_gait::{
    vzd, BodyPose, Evaluation, GaitConfig, GaitState, PlanFailure, QuadrupedModel, RecedingHorizon, RuleSet,
};
use nalgebra::Point2;
use std::f64::consts::PI;

#[test]
fn the_receding_horizon_reaches_the_papers_goal() {
    let goal = Point2::new(-10.0, 10.0);
    for (set, phi) in [(RuleSet::A, PI / 4.0), (RuleSet::B, 1.5 * PI)] {
        for eval in [Evaluation::One, Evaluation::Three] {
            let h = RecedingHorizon {
                chunk_expansions: 200,
                ..RecedingHorizon::new(GaitConfig::default(), set, eval)
            };
            let start = GaitState::nominal(&QuadrupedModel::default(), BodyPose { x: 0.0, y: 0.0, phi });
            let walk = h.run(&start, goal, 100, &mut || false);
            assert!(walk.reached, "{set},{eval:?}: {:?}", walk.failure);
            let last = walk.steps.last().unwrap().state;
            assert!(vzd(&last, goal) <= h.cfg.goal_tolerance);
            // Each chunk executes 1 to 4 moves (a partial plan may end after fewer).
            assert!(walk.steps.len() - 1 <= 4 * walk.chunks as usize);
            assert!(walk.steps.len() > walk.chunks as usize);
            // Chunks are chained: each executed state is exactly its rule applied to the one
            // before (to 1e-12 in every coordinate), across the chunks' seams too.
            for w in walk.steps.windows(2) {
                let rule = w[1].rule.unwrap();
                let next = rule.apply(&h.model, &h.cfg, &w[0].state, goal);
                assert!(next.iter().flatten().any(|s| {
                    let (a, b) = (s, &w[1].state);
                    (a.body.x - b.body.x).abs() <= 1e-12
                        && (a.body.y - b.body.y).abs() <= 1e-12
                        && ((a.body.phi - b.body.phi + PI).rem_euclid(2.0 * PI) - PI).abs() <= 1e-12
                        && a.feet.iter().zip(&b.feet).all(|(p, q)| (p - q).abs().max() <= 1e-12)
                }));
            }
        }
    }
}

#[test]
fn a_chunk_executes_the_first_moves_of_its_plan() {
    let h = RecedingHorizon::new(GaitConfig::default(), RuleSet::B, Evaluation::Three);
    let start = GaitState::nominal(
        &h.model,
        BodyPose {
            x: 0.0,
            y: 0.0,
            phi: 1.5 * PI,
        },
    );
    let chunk = h.next_chunk(&start, Point2::new(-10.0, 10.0), &mut || false);
    assert_eq!(chunk.executed.len(), 4);
    assert_eq!(chunk.executed[..], chunk.plan.steps[1..5]);
    assert_eq!(chunk.reached(), Some(&chunk.plan.steps[4].state));
    // At the goal already: nothing to execute.
    let done = h.next_chunk(&start, Point2::new(0.1, 0.1), &mut || false);
    assert!(done.executed.is_empty() && done.plan.success);
}

#[test]
fn a_walk_out_of_short_time_plans_says_so_not_expansion_limit() {
    // Two plans of at most 4 moves each cannot cover the 14.1 [j] to the paper's goal (a body
    // move shifts at most about 1.3 [j]): the walk ends on its plan count.
    let h = RecedingHorizon::new(GaitConfig::default(), RuleSet::A, Evaluation::Three);
    let start = GaitState::nominal(
        &h.model,
        BodyPose {
            x: 0.0,
            y: 0.0,
            phi: PI / 4.0,
        },
    );
    let walk = h.run(&start, Point2::new(-10.0, 10.0), 2, &mut || false);
    assert!(!walk.reached);
    assert_eq!(walk.chunks, 2);
    assert_eq!(walk.failure, Some(PlanFailure::ChunkLimit(2)));
    assert!(walk
        .failure
        .unwrap()
        .to_string()
        .starts_with("CHUNK_LIMIT: 2 short-time plans"));
}
