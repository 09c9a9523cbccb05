//! The production rules: hand-worked examples (numbers derived in the comments), and property
//! tests that every rule keeps the workspace and stability invariants, the workspace checked
//! along the whole motion by sampling (a second method beside the library's closed form).

use approx::assert_relative_eq;
use mobil_gait::model::{is_stable, is_supported, max_rotation, max_translation, rotate, unit, wrap};
use mobil_gait::rules::{
    leg_max_length_max_angle, leg_min_angle, leg_nominal, rotate_toward_goal, translate_max_toward_goal, translate_step,
};
use mobil_gait::{BodyPose, GaitConfig, GaitState, LegAngleReading, QuadrupedModel, Rule, RuleSet};
use nalgebra::{Point2, Vector2};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_4, PI, SQRT_2};

const MARGIN: f64 = 0.02;

fn nominal_at_origin(model: &QuadrupedModel) -> GaitState {
    GaitState::nominal(
        model,
        BodyPose {
            x: 0.0,
            y: 0.0,
            phi: 0.0,
        },
    )
}

#[test]
fn rule_names_numbers_and_legs() {
    assert_eq!(Rule::all(RuleSet::A).count(), 11);
    assert_eq!(Rule::all(RuleSet::B).count(), 27);
    let r = |n| Rule::new(n).unwrap();
    assert_eq!((r(1).name(), r(1).moving_leg()), ("rotate_toward_goal", None));
    assert_eq!((r(3).name(), r(3).moving_leg()), ("translate_max_toward_goal", None));
    assert_eq!((r(4).name(), r(4).moving_leg()), ("leg0_max_length_max_angle", Some(0)));
    assert_eq!((r(11).name(), r(11).moving_leg()), ("leg3_nominal", Some(3)));
    assert_eq!((r(14).name(), r(14).moving_leg()), ("leg2_max_length", Some(2)));
    assert_eq!((r(17).name(), r(17).moving_leg()), ("leg1_min_length", Some(1)));
    assert_eq!((r(23).name(), r(23).moving_leg()), ("leg3_max_angle", Some(3)));
    assert_eq!((r(24).name(), r(24).moving_leg()), ("leg0_min_angle", Some(0)));
    assert!(Rule::new(0).is_err() && Rule::new(28).is_err());
    assert!("C".parse::<RuleSet>().is_err());
    assert_eq!("B".parse::<RuleSet>(), Ok(RuleSet::B));
}

#[test]
fn nominal_stance_matches_the_spec() {
    // SPEC §7: nominal feet at (±2.5, ±1.5) in the body frame; legs 0, 2 front (+y_r).
    let m = QuadrupedModel::default();
    let s = GaitState::nominal(
        &m,
        BodyPose {
            x: 1.0,
            y: 2.0,
            phi: PI / 2.0,
        },
    );
    // φ = π/2: x_r = world +y, y_r = world −x. Leg 0 at (−2.5, 1.5) body → world (1 − 1.5, 2 − 2.5).
    assert_relative_eq!(s.feet[0], Point2::new(-0.5, -0.5), epsilon = 1e-12);
    assert_relative_eq!(s.feet[3], Point2::new(2.5, 4.5), epsilon = 1e-12);
    for leg in 0..4 {
        let (l, _) = s.polar(&m, leg);
        assert_relative_eq!(l, 1.5, epsilon = 1e-12);
    }
}

#[test]
fn rule3_max_translation_from_nominal_is_sqrt_1_75() {
    // Feet at (∓1.5, 0) from their hips. Moving the body by s along y_r moves each foot by −s:
    // L² = 1.5² + s² ≤ 2² gives s ≤ √1.75 = 1.3229; the sector −px ≥ |py| gives s ≤ 1.5; the
    // hull's front edge y = 1.5 keeps the centre inside by 0.02 up to s = 1.48. So √1.75.
    let m = QuadrupedModel::default();
    let s = nominal_at_origin(&m);
    let next = translate_max_toward_goal(&m, MARGIN, &s, Point2::new(0.0, 100.0)).unwrap();
    assert_relative_eq!(next.body.y, 1.75f64.sqrt(), epsilon = 1e-9);
    assert_relative_eq!(next.body.x, 0.0, epsilon = 1e-12);
    assert_eq!(next.feet, s.feet, "planted feet stay where they are");
    // Capped at the goal's projection on y_r: a goal 0.7 ahead (and off to the side).
    let capped = translate_max_toward_goal(&m, MARGIN, &s, Point2::new(3.0, 0.7)).unwrap();
    assert_relative_eq!(capped.body.y, 0.7, epsilon = 1e-12);
    // Backward by symmetry.
    let back = translate_max_toward_goal(&m, MARGIN, &s, Point2::new(0.0, -100.0)).unwrap();
    assert_relative_eq!(back.body.y, -(1.75f64.sqrt()), epsilon = 1e-9);
}

#[test]
fn rule2_steps_by_delta_y_both_ways_and_not_beyond_reach() {
    let m = QuadrupedModel::default();
    let s = nominal_at_origin(&m);
    let fwd = translate_step(&m, MARGIN, &s, 1.0).unwrap();
    let back = translate_step(&m, MARGIN, &s, -1.0).unwrap();
    assert_relative_eq!(fwd.body.y, 1.0, epsilon = 1e-12);
    assert_relative_eq!(back.body.y, -1.0, epsilon = 1e-12);
    // A second step would take the body 2 > √1.75 from the nominal footholds.
    assert!(translate_step(&m, MARGIN, &fwd, 1.0).is_none());
}

#[test]
fn rule1_max_rotation_from_nominal() {
    // Rotating the body by θ turns the feet by −θ in the body frame. For a counter-clockwise
    // turn leg 1 (hip (−1, −1.5), foot q = (−2.5, −1.5) from the centre) lengthens first:
    // L² = |q|² + |h|² − 2 h·R(−θ)q = 11.75 − 9.5 cos θ + 4.5 sin θ = 4, i.e.
    // 9.5 cos θ − 4.5 sin θ = 7.75, θ = acos(7.75/√110.5) − atan(4.5/9.5) = 0.29942 rad.
    // (A scan at 1e-6 rad steps of all four legs' L and β found the same angle.)
    let expected = (7.75 / 110.5f64.sqrt()).acos() - (4.5f64 / 9.5).atan();
    let m = QuadrupedModel::default();
    let s = nominal_at_origin(&m);
    // The goal straight to the left: dev = π/2, counter-clockwise.
    let next = rotate_toward_goal(&m, &s, Point2::new(-10.0, 0.0)).unwrap();
    assert_relative_eq!(next.body.phi, expected, epsilon = 1e-9);
    let (l1, _) = next.polar(&m, 1);
    assert_relative_eq!(l1, 2.0, epsilon = 1e-9);
    // To the right: clockwise by the same angle (the stance is symmetric).
    let cw = rotate_toward_goal(&m, &s, Point2::new(10.0, 0.0)).unwrap();
    assert_relative_eq!(cw.body.phi, -expected, epsilon = 1e-9);
    // A goal 0.1 rad off y_r: rotate by exactly dev.
    let g = Point2::new(-(0.1f64.sin()), 0.1f64.cos()) * 10.0;
    let small = rotate_toward_goal(&m, &s, g).unwrap();
    assert_relative_eq!(small.body.phi, 0.1, epsilon = 1e-12);
    // Already facing the goal: nothing.
    assert!(rotate_toward_goal(&m, &small, g).is_none());
}

#[test]
fn a_leg_cannot_lift_on_the_diagonal_with_a_margin() {
    // Nominal: the centre lies on the diagonal of feet 1 and 2, the edge of the triangle that
    // holds the robot while leg 0 lifts: margin 0, stable only with a zero margin.
    let m = QuadrupedModel::default();
    let s = nominal_at_origin(&m);
    assert!(!is_stable(&m, MARGIN, &s, 0));
    assert!(is_stable(&m, 0.0, &s, 0));
    assert!(leg_max_length_max_angle(&m, MARGIN, &s, 0).is_none());
    // With a zero margin rule 4 puts foot 0 at hip + 2·(cos 3π/4, sin 3π/4) (forward reading).
    let next = leg_max_length_max_angle(&m, 0.0, &s, 0).unwrap();
    assert_relative_eq!(next.feet[0], Point2::new(-1.0 - SQRT_2, 1.5 + SQRT_2), epsilon = 1e-12);
    // The rearward reading's max angle is 5π/4: behind the hip.
    let r = QuadrupedModel::paper(LegAngleReading::Rearward);
    let rear = leg_max_length_max_angle(&r, 0.0, &s, 0).unwrap();
    assert_relative_eq!(rear.feet[0], Point2::new(-1.0 - SQRT_2, 1.5 - SQRT_2), epsilon = 1e-12);
}

#[test]
fn after_a_forward_shift_the_rear_leg_steps_forward() {
    // Body forward by s = √1.75: leg 1's foot is at L = 2 behind its hip. Lifting it leaves feet
    // 0, 2, 3; the centre (0, s) lies 5s/√34 = 1.134 inside their diagonal 3x + 5y = 0,
    // 1.5 − s = 0.177 behind the front edge: stable. Rule 9 puts it back at nominal, 1.5 to the
    // left of its hip: world (−2.5, s − 1.5).
    let m = QuadrupedModel::default();
    let s0 = nominal_at_origin(&m);
    let s1 = translate_max_toward_goal(&m, MARGIN, &s0, Point2::new(0.0, 100.0)).unwrap();
    let (l1, _) = s1.polar(&m, 1);
    assert_relative_eq!(l1, 2.0, epsilon = 1e-9);
    assert!(is_stable(&m, 0.17, &s1, 1) && !is_stable(&m, 0.18, &s1, 1));
    let s2 = leg_nominal(&m, MARGIN, &s1, 1).unwrap();
    assert_relative_eq!(s2.feet[1], Point2::new(-2.5, 1.75f64.sqrt() - 1.5), epsilon = 1e-9);
    // A front leg may not lift: the centre is ahead of the diagonal of feet 1 and 2.
    assert!(leg_nominal(&m, MARGIN, &s1, 0).is_none() && !is_stable(&m, 0.0, &s1, 0));
    // Setting a leg where it already is changes nothing: no successor.
    assert!(leg_nominal(&m, MARGIN, &s2, 1).is_none());
}

/// The state of the next test: legs 0, 1, 3 at L = 2 on their forward edge, leg 2 at L = 1 on
/// its forward edge (0.707, 0.707) from the hip.
fn foot_near_inner_circle(m: &QuadrupedModel) -> GaitState {
    let body = BodyPose::default();
    let mut s = GaitState::nominal(m, body);
    for (leg, l) in [(0, 2.0), (1, 2.0), (2, 1.0), (3, 2.0)] {
        let p = m.foot_in_body(leg, l, m.workspaces[leg].forward_angle());
        s.feet[leg] = Point2::from(p);
    }
    s
}

#[test]
fn a_translation_valid_at_both_ends_but_not_between_is_refused() {
    // Leg 2's foot is at (0.707, 0.707) from its hip. Moving the body forward by √2 puts it at
    // (0.707, −0.707): again L = 1 (the sector's rear edge), and the other feet at L = √2, so the
    // end state is valid. Half-way, at (0.707, 0), L = 0.707 < 1: the leg would have to shrink
    // below its minimum. An end-point check would accept the move; the rule must not.
    let m = QuadrupedModel::default();
    let s = foot_near_inner_circle(&m);
    assert!(s.in_workspaces(&m) && is_supported(MARGIN, &s));
    let mut end = s;
    end.body.y = SQRT_2;
    assert!(end.in_workspaces(&m), "the end state alone is valid");
    let mut mid = s;
    mid.body.y = SQRT_2 / 2.0;
    assert!(!mid.in_workspaces(&m), "half-way the foot is inside L = 1");
    assert!(translate_step(&m, MARGIN, &s, SQRT_2).is_none());
    assert_relative_eq!(max_translation(&m, MARGIN, &s, 1.0, 5.0), 0.0, epsilon = 1e-12);
    // Backward, leg 2 gets longer: allowed until the first foot reaches L = 2 or its sector's
    // edge. Legs 0, 1, 3 are on their forward edges at L = 2: moving the body back moves them
    // forward, out of the sector at once. So backward is blocked too.
    assert_relative_eq!(max_translation(&m, MARGIN, &s, -1.0, 5.0), 0.0, epsilon = 1e-12);
}

#[test]
fn min_angle_keeps_the_length() {
    // Rule 24 (leg 0 to min angle, forward reading: the rearward extreme 5π/4) from a shifted
    // stance where leg 0 may lift (centre behind the diagonal of feet 1, 2).
    let m = QuadrupedModel::default();
    let s0 = nominal_at_origin(&m);
    let back = translate_max_toward_goal(&m, MARGIN, &s0, Point2::new(0.0, -100.0)).unwrap();
    let (l, _) = back.polar(&m, 0);
    let next = leg_min_angle(&m, MARGIN, &back, 0).unwrap();
    let (l2, b2) = next.polar(&m, 0);
    assert_relative_eq!(l2, l, epsilon = 1e-9);
    assert_relative_eq!(wrap(b2 - 5.0 * FRAC_PI_4), 0.0, epsilon = 1e-9);
}

/// A random state with every foot in its workspace and the centre inside the feet's hull.
fn valid_state() -> impl Strategy<Value = GaitState> {
    (
        -5.0..5.0f64,
        -5.0..5.0f64,
        -PI..PI,
        proptest::array::uniform4((1.0..2.0f64, -FRAC_PI_4..FRAC_PI_4)),
    )
        .prop_map(|(x, y, phi, legs)| {
            let m = QuadrupedModel::default();
            let body = BodyPose { x, y, phi };
            let mut s = GaitState::nominal(&m, body);
            for (leg, (l, db)) in legs.into_iter().enumerate() {
                let p = m.foot_in_body(leg, l, m.workspaces[leg].nominal_angle() + db);
                s.feet[leg] = body.centre() + rotate(p, phi);
            }
            s
        })
        .prop_filter("centre inside the hull by the margin", |s| is_supported(MARGIN, s))
}

/// Checks the body's motion from `a` to `b` at 2000 points (rotation about the centre, then
/// translation along y_r, as rules 1–3 make them): every foot in its workspace. A violation
/// between samples is at most (arc or segment length)/4000 deep, under 2e-3 [j].
fn motion_stays_in_workspaces(m: &QuadrupedModel, a: &GaitState, b: &GaitState) -> bool {
    let dphi = wrap(b.body.phi - a.body.phi);
    let dc: Vector2<f64> = b.body.centre() - a.body.centre();
    (0..=2000).all(|k| {
        let t = k as f64 / 2000.0;
        let mut s = *a;
        s.body.phi = a.body.phi + t * dphi;
        s.body.x = a.body.x + t * dc.x;
        s.body.y = a.body.y + t * dc.y;
        (0..4).all(|leg| {
            let p = s.foot_from_hip(m, leg);
            let w = &m.workspaces[leg];
            let db = wrap(p.y.atan2(p.x) - w.nominal_angle());
            // Sampled states may be off by the sampling bound: allow 2e-3.
            p.norm() >= 1.0 - 2e-3 && p.norm() <= 2.0 + 2e-3 && db.abs() <= FRAC_PI_4 + 2e-3
        })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn every_rule_keeps_workspaces_and_stability(s in valid_state(), gx in -20.0..20.0f64, gy in -20.0..20.0f64) {
        for reading in [LegAngleReading::Forward, LegAngleReading::Rearward] {
            let m = QuadrupedModel::paper(reading);
            let cfg = GaitConfig { stability_margin: MARGIN, reading, ..GaitConfig::default() };
            let goal = Point2::new(gx, gy);
            for rule in Rule::all(RuleSet::B) {
                for next in rule.apply(&m, &cfg, &s, goal).into_iter().flatten() {
                    prop_assert!(next.in_workspaces(&m), "rule {rule} left a workspace");
                    prop_assert!(is_supported(MARGIN, &next), "rule {rule} lost support");
                    prop_assert!(next != s, "rule {rule} left the state unchanged");
                    match rule.moving_leg() {
                        Some(leg) => {
                            // One foot moved; the others and the body did not; the lift was stable.
                            prop_assert!(is_stable(&m, MARGIN, &s, leg));
                            prop_assert_eq!(next.body, s.body);
                            for k in (0..4).filter(|&k| k != leg) {
                                prop_assert_eq!(next.feet[k], s.feet[k]);
                            }
                        }
                        None => {
                            prop_assert_eq!(next.feet, s.feet);
                            prop_assert!(motion_stays_in_workspaces(&m, &s, &next), "rule {rule} crossed a boundary mid-way");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn max_rotation_is_the_largest_allowed(s in valid_state(), sign in prop::bool::ANY) {
        // The closed form against a scan: rotating by the returned angle stays inside all the
        // way (sampled), and 1e-3 rad more leaves a workspace (unless the limit π/2 bound it).
        let m = QuadrupedModel::default();
        let sg = if sign { 1.0 } else { -1.0 };
        let t = max_rotation(&m, &s, sg, PI / 2.0);
        let mut end = s;
        end.body.phi = s.body.phi + sg * t;
        prop_assert!(motion_stays_in_workspaces(&m, &s, &end));
        if t < PI / 2.0 - 1e-3 {
            let mut beyond = s;
            beyond.body.phi = s.body.phi + sg * (t + 1e-3);
            prop_assert!(!beyond.in_workspaces(&m));
        }
    }

    #[test]
    fn max_translation_is_the_largest_allowed(s in valid_state(), sign in prop::bool::ANY) {
        let m = QuadrupedModel::default();
        let sg = if sign { 1.0 } else { -1.0 };
        let d = max_translation(&m, MARGIN, &s, sg, 10.0);
        let dir = sg * unit(s.body.phi + PI / 2.0);
        let moved = |dist: f64| {
            let mut e = s;
            e.body.x += dist * dir.x;
            e.body.y += dist * dir.y;
            e
        };
        prop_assert!(motion_stays_in_workspaces(&m, &s, &moved(d)));
        let beyond = moved(d + 1e-3);
        // Beyond the limit, a foot is out of its workspace or the centre is out of the hull by
        // the margin, at the end or somewhere on the way.
        prop_assert!(!beyond.in_workspaces(&m) || !is_supported(MARGIN, &beyond)
            || !motion_stays_in_workspaces(&m, &s, &beyond));
    }
}
