//! The fifth act's summary and figure on a hand-made plan: two body moves and two leg moves.

use mobil_tools::gait::{figure, outline, summary, support, GaitWalk, WalkState};
use std::f64::consts::FRAC_PI_2;

fn nominal(x: f64, y: f64) -> [(f64, f64); 4] {
    [
        (x - 2.5, y + 1.5),
        (x - 2.5, y - 1.5),
        (x + 2.5, y + 1.5),
        (x + 2.5, y - 1.5),
    ]
}

fn walk() -> GaitWalk {
    let state = |body: (f64, f64, f64), feet, moving_leg, rule: &str| WalkState {
        body,
        feet,
        moving_leg,
        rule: rule.into(),
    };
    let mut lifted = nominal(0.0, 0.0);
    lifted[0] = (-2.5, 2.5);
    let mut second = lifted;
    second[3] = (2.5, -0.5);
    GaitWalk {
        rule_set: "B".into(),
        evaluation: 3,
        goal: (0.0, 1.2),
        success: true,
        reason: String::new(),
        expanded: 12,
        generated: 80,
        steps: vec![
            state((0.0, 0.0, 0.0), nominal(0.0, 0.0), -1, "start"),
            state((0.0, 0.0, 0.0), lifted, 0, "leg0_max_length"),
            state((0.0, 0.0, 0.0), second, 3, "leg3_nominal"),
            state((0.0, 1.0, 0.0), second, -1, "translate_step"),
        ],
        call_s: 0.0234,
        body_size: (2.0, 3.0),
    }
}

#[test]
fn the_summary_counts_the_moves_and_the_distance_left() {
    let w = walk();
    assert_eq!((w.leg_moves(), w.body_moves()), (2, 1));
    // The last body (0, 1) is 0.2 from the goal (0, 1.2).
    assert!((w.goal_distance() - 0.2).abs() < 1e-12);
    assert_eq!(
        summary(&w, "out.svg"),
        "demo: quadruped free gait B,(3) from (0, 0, φ 0°) to (0, 1.2): 4 states, 1 body and 2 leg moves, \
         ends 0.20 [j] from it; 12 expanded, 80 generated, answered in 23 ms; plot out.svg"
    );
    let mut failed = w.clone();
    failed.success = false;
    failed.reason = "EXPANSION_LIMIT: …".into();
    assert!(summary(&failed, "x.svg").contains("NO PLAN (EXPANSION_LIMIT: …)"));
}

#[test]
fn outline_and_support_triangle() {
    // Body at (1, 2) turned by π/2: body (u, v) → world (1 − v, 2 + u). Front left (−1, 1.5)
    // → (−0.5, 1); front right (1, 1.5) → (−0.5, 3); rear right (1, −1.5) → (2.5, 3); rear
    // left (−1, −1.5) → (2.5, 1).
    let corners = outline((1.0, 2.0, FRAC_PI_2), (2.0, 3.0));
    let expected = [(-0.5, 1.0), (-0.5, 3.0), (2.5, 3.0), (2.5, 1.0)];
    for (c, e) in corners.iter().zip(expected) {
        assert!((c.0 - e.0).abs() < 1e-12 && (c.1 - e.1).abs() < 1e-12, "{c:?} vs {e:?}");
    }
    let w = walk();
    assert_eq!(
        support(&w.steps[2]),
        vec![w.steps[2].feet[0], w.steps[2].feet[1], w.steps[2].feet[2]]
    );
}

#[test]
fn the_figure_draws_every_outline_and_a_triangle_and_frame_per_leg_move() {
    let w = walk();
    let svg = figure(&w, "title");
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    // Two leg moves: a triangle on the map and one in each frame.
    assert_eq!(svg.matches("<polygon").count(), 4);
    // Polylines: 4 outlines and the body path on the map; per frame an outline and the moving
    // foot's dashed line.
    assert_eq!(svg.matches("<polyline").count(), 4 + 1 + 2 * 2);
    assert_eq!(svg.matches("stroke-dasharray").count(), 2);
    assert!(svg.contains("1: leg0_max_length") && svg.contains("2: leg3_nominal"));
    assert!(svg.contains("goal (0, 1.2)"));
}

#[test]
fn a_reply_with_out_of_range_legs_is_drawn_without_them() {
    // moving_leg is an int8 from the reply: 4..=127 and −2 are no leg of the quadruped.
    let mut w = walk();
    w.steps[1].moving_leg = 9;
    w.steps[2].moving_leg = 127;
    w.steps[3].moving_leg = -2;
    assert_eq!((w.leg_moves(), w.body_moves()), (0, 3));
    let svg = figure(&w, "title");
    // No leg move left: no triangle, no frame; the 4 outlines and the path.
    assert_eq!(svg.matches("<polygon").count(), 0);
    assert_eq!(svg.matches("<polyline").count(), 4 + 1);
    // A reply whose every state, the start too, claims a leg move: 4 leg moves, 0 body moves
    // (not an underflow).
    let mut all = walk();
    for (k, s) in all.steps.iter_mut().enumerate() {
        s.moving_leg = k as i8;
    }
    assert_eq!((all.leg_moves(), all.body_moves()), (4, 0));
}

#[test]
fn the_map_axes_are_in_the_plans_unit() {
    let svg = figure(&walk(), "title");
    assert!(svg.contains("x [j] →, y [j] ↑"));
    assert!(!svg.contains("[m]"));
}
