//! gait_node's shell without DDS: requests to queries and refusals, plans to messages, the
//! node's stop causes, the UNEVEN reaction, the walk, the markers and the params file.
//! Expected numbers are worked out by hand from SPEC §7 (body 2 × 3, hips at (±1, ±1.5), legs
//! nominal at 1.5 [j] from the hip along ∓x_r).

use mobil_gait::{BodyPose, Evaluation, GaitState, Plan, PlanFailure, PlanStep, Rule, RuleSet, WalkNext, Walker};
use mobil_gait_node::{
    body_outline, body_pose, chunk_reason, goal_from_pose, ground_from_assessment, header, markers, plan_reason,
    query_from_request, refused_plan, reply_plan, run_query, support_triangle, GaitNodeConfig, GoalRefusal, Ground,
    RequestRefusal, StopCause, PREEMPTED,
};
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::PoseStamped;
use mobil_msgs::mobil_msgs::msg::TerrainAssessment;
use mobil_msgs::mobil_msgs::srv::PlanGaitRequest;
use mobil_msgs::visualization_msgs::msg::Marker;
use mobil_ros::config::{load, Decl};
use mobil_ros::params::initial_params;
use nalgebra::Point2;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

fn request(start: (f64, f64, f64), goal: (f64, f64), set: &str, eval: u8, max: u32) -> PlanGaitRequest {
    let mut r = PlanGaitRequest::default();
    (r.start.x, r.start.y, r.start.theta) = start;
    (r.goal.x, r.goal.y) = goal;
    r.rule_set = set.into();
    r.evaluation = eval;
    r.max_expansions = max;
    r
}

fn close(a: Point2<f64>, b: (f64, f64)) -> bool {
    (a.x - b.0).abs() < 1e-9 && (a.y - b.1).abs() < 1e-9
}

#[test]
fn the_papers_request_becomes_the_nominal_start_and_its_query() {
    let cfg = GaitNodeConfig::default();
    let q = query_from_request(
        &request((0.0, 0.0, FRAC_PI_4), (-10.0, 10.0), "A", 1, 0),
        &cfg,
        Ground::Even,
    )
    .unwrap();
    assert_eq!((q.set, q.evaluation), (RuleSet::A, Evaluation::One));
    assert!(close(q.goal, (-10.0, 10.0)));
    // 0 asks for the configured limit (200 000, the library's default), which the memory
    // bound caps: set A's 11 rules make at most 22 successors, 2 000 000 / 22 = 90 909.
    assert_eq!((q.max_expansions, q.capped_from), (90_909, Some(200_000)));
    // Feet at (±2.5, ±1.5) in the body frame rotated by π/4: (x cos − y sin, x sin + y cos).
    let r = std::f64::consts::FRAC_1_SQRT_2;
    let expected = [
        (-2.5 * r - 1.5 * r, -2.5 * r + 1.5 * r),
        (-2.5 * r + 1.5 * r, -2.5 * r - 1.5 * r),
        (2.5 * r - 1.5 * r, 2.5 * r + 1.5 * r),
        (2.5 * r + 1.5 * r, 2.5 * r - 1.5 * r),
    ];
    for (foot, e) in q.start.feet.iter().zip(expected) {
        assert!(close(*foot, e), "{foot:?} vs {e:?}");
    }
    assert_eq!(
        (q.start.body.x, q.start.body.y, q.start.body.phi),
        (0.0, 0.0, FRAC_PI_4)
    );
}

#[test]
fn expansions_above_the_limit_are_capped_and_the_reason_says_so() {
    let mut cfg = GaitNodeConfig::default();
    cfg.node.max_expansions_limit = 30;
    let q = query_from_request(
        &request((0.0, 0.0, FRAC_PI_4), (-10.0, 10.0), "B", 3, 5000),
        &cfg,
        Ground::Even,
    )
    .unwrap();
    assert_eq!((q.max_expansions, q.capped_from), (30, Some(5000)));
    let (plan, cause) = run_query(&q, &cfg.gait, &|| false, &mut || false);
    assert_eq!(cause, StopCause::None);
    assert!(!plan.success);
    assert_eq!(plan.expanded, 30);
    let reason = plan_reason(&plan, cause, &q, 2.0);
    assert!(reason.starts_with("EXPANSION_LIMIT"), "{reason}");
    assert!(
        reason.contains("the request's 5000 was capped to max_expansions_limit"),
        "{reason}"
    );
    // A request within the limit is not capped.
    let q = query_from_request(&request((0.0, 0.0, 0.0), (0.0, 5.0), "A", 2, 30), &cfg, Ground::Even).unwrap();
    assert_eq!((q.max_expansions, q.capped_from), (30, None));
}

#[test]
fn bad_requests_are_refused_with_the_reason() {
    let cfg = GaitNodeConfig::default();
    let ok = request((0.0, 0.0, 0.0), (1.0, 5.0), "A", 1, 0);
    let refuse = |r: PlanGaitRequest| query_from_request(&r, &cfg, Ground::Even).unwrap_err();
    for set in ["C", "a", "", "AB"] {
        assert_eq!(
            refuse(PlanGaitRequest {
                rule_set: set.into(),
                ..ok.clone()
            }),
            RequestRefusal::RuleSet(set.into())
        );
    }
    for eval in [0, 4, 255] {
        assert_eq!(
            refuse(PlanGaitRequest {
                evaluation: eval,
                ..ok.clone()
            }),
            RequestRefusal::Evaluation(eval)
        );
    }
    let mut nan = ok.clone();
    nan.goal.y = f64::NAN;
    assert_eq!(refuse(nan), RequestRefusal::NotFinite("goal.y"));
    let mut inf = ok.clone();
    inf.start.theta = f64::INFINITY;
    assert_eq!(refuse(inf), RequestRefusal::NotFinite("start.theta"));
    let mut far = ok.clone();
    far.start.x = -1000.5;
    let e = refuse(far);
    assert_eq!(
        e,
        RequestRefusal::TooFar {
            what: "start.x",
            value: -1000.5
        }
    );
    assert!(
        e.to_string()
            .starts_with("INVALID_REQUEST: start.x -1000.5 is beyond ±1000"),
        "{e}"
    );
    // 1000 itself is served.
    let mut edge = ok.clone();
    edge.goal.x = 1000.0;
    assert!(query_from_request(&edge, &cfg, Ground::Even).is_ok());
    // The refused reply: no steps, success false, the request's set and evaluation.
    let msg = refused_plan(&ok, header(Time::default(), ""), e.to_string());
    assert!(!msg.success && msg.steps.is_empty());
    assert_eq!((msg.rule_set.as_str(), msg.evaluation), ("A", 1));
}

fn step(state: GaitState, rule: Option<u8>, evaluation: f64) -> PlanStep {
    PlanStep {
        state,
        rule: rule.map(|n| Rule::new(n).unwrap()),
        evaluation,
    }
}

#[test]
fn a_plan_maps_onto_gait_plan_step_for_step() {
    let cfg = GaitNodeConfig::default();
    let model = cfg.model();
    let s0 = GaitState::nominal(
        &model,
        BodyPose {
            x: 0.0,
            y: 0.0,
            phi: 0.0,
        },
    );
    let mut s1 = s0;
    s1.body.y = 1.0;
    let mut s2 = s1;
    s2.feet[0] = Point2::new(-2.0, 2.5);
    let mut s3 = s2;
    s3.feet[3] = Point2::new(2.5, -0.25);
    let plan = Plan {
        steps: vec![
            step(s0, None, 14.1),
            step(s1, Some(3), 13.4),
            step(s2, Some(8), 13.4),
            step(s3, Some(27), 13.4),
        ],
        success: true,
        failure: None,
        expanded: 17,
        generated: 41,
    };
    let msg = reply_plan(&plan, RuleSet::B, Evaluation::Three, String::new(), 400);
    assert_eq!((msg.rule_set.as_str(), msg.evaluation, msg.success), ("B", 3, true));
    assert_eq!(
        (msg.states_expanded, msg.states_generated, msg.steps.len()),
        (17, 41, 4)
    );
    // Rule 0 "start" and −1 for the start; rule 3 moves the body (−1); rule 8 (leg0_nominal)
    // moves leg 0; rule 27 (leg3_min_angle) leg (27 − 4) mod 4 = 3.
    let heads: Vec<(u8, &str, i8)> = msg
        .steps
        .iter()
        .map(|s| (s.rule, s.rule_name.as_str(), s.moving_leg))
        .collect();
    assert_eq!(
        heads,
        vec![
            (0, "start", -1),
            (3, "translate_max_toward_goal", -1),
            (8, "leg0_nominal", 0),
            (27, "leg3_min_angle", 3),
        ]
    );
    assert_eq!(
        (msg.steps[1].body.x, msg.steps[1].body.y, msg.steps[1].body.theta),
        (0.0, 1.0, 0.0)
    );
    assert_eq!((msg.steps[2].feet[0].x, msg.steps[2].feet[0].y), (-2.0, 2.5));
    assert_eq!((msg.steps[3].feet[3].x, msg.steps[3].feet[3].y), (2.5, -0.25));
    // Nominal feet at the start: (−2.5, 1.5), (−2.5, −1.5), (2.5, 1.5), (2.5, −1.5).
    for (f, e) in msg.steps[0]
        .feet
        .iter()
        .zip([(-2.5, 1.5), (-2.5, -1.5), (2.5, 1.5), (2.5, -1.5)])
    {
        assert!(close(Point2::new(f.x, f.y), e), "{f:?} vs {e:?}");
    }
    assert_eq!(msg.steps[0].evaluation, 14.1);
}

#[test]
fn stop_causes_name_the_node_limits() {
    let cfg = GaitNodeConfig::default();
    // A long search (B,(3) toward a goal 1270 [j] away): the library asks its stop callback
    // every few hundred expansions, so it is asked.
    let far = query_from_request(
        &request((0.0, 0.0, 1.5 * PI), (-900.0, 900.0), "B", 3, 0),
        &cfg,
        Ground::Even,
    )
    .unwrap();
    let q = query_from_request(
        &request((0.0, 0.0, FRAC_PI_4), (-10.0, 10.0), "A", 1, 0),
        &cfg,
        Ground::Even,
    )
    .unwrap();
    // Pre-empted: the caller is told so, whatever the plan.
    let (plan, cause) = run_query(&far, &cfg.gait, &|| true, &mut || false);
    assert_eq!(
        (cause, plan.failure.clone()),
        (StopCause::Preempted, Some(PlanFailure::Stopped))
    );
    assert_eq!(plan_reason(&plan, cause, &far, 2.0), PREEMPTED);
    // The time limit: the best partial plan, from the start.
    let (plan, cause) = run_query(&far, &cfg.gait, &|| false, &mut || true);
    assert_eq!(cause, StopCause::TimeLimit);
    assert!(!plan.success && !plan.steps.is_empty());
    assert_eq!(plan.steps[0].state, far.start);
    let reason = plan_reason(&plan, cause, &far, 0.25);
    assert!(
        reason.starts_with("TIME_LIMIT: no goal within the time limit of 0.25 s"),
        "{reason}"
    );
    // Unhindered: the paper's A,(1) reaches the goal; the reason is empty.
    let (plan, cause) = run_query(&q, &cfg.gait, &|| false, &mut || false);
    assert_eq!(cause, StopCause::None);
    assert!(plan.success);
    assert_eq!(plan_reason(&plan, cause, &q, 2.0), "");
    let last = plan.steps.last().unwrap().state.body.centre();
    assert!((last - Point2::new(-10.0, 10.0)).norm() <= cfg.gait.goal_tolerance + 1e-9);
}

#[test]
fn uneven_ground_raises_the_margin_and_shortens_the_step() {
    let mut a = TerrainAssessment::default();
    let classes = [
        (TerrainAssessment::FLAT, Ground::Even),
        (TerrainAssessment::SLOPE, Ground::Even),
        (TerrainAssessment::UNEVEN, Ground::Uneven),
        (TerrainAssessment::BEYOND_LIMITS, Ground::Even),
    ];
    for (class, ground) in classes {
        a.terrain_class = class;
        assert_eq!(ground_from_assessment(&a), Ok(ground));
    }
    a.terrain_class = 7;
    assert!(ground_from_assessment(&a).unwrap_err().contains("unknown class 7"));

    let mut cfg = GaitNodeConfig::default();
    (cfg.gait.stability_margin, cfg.gait.translation_step) = (0.02, 1.0);
    (cfg.node.uneven_stability_margin, cfg.node.uneven_translation_step) = (0.15, 0.5);
    let even = cfg.gait_for(Ground::Even);
    assert_eq!((even.stability_margin, even.translation_step), (0.02, 1.0));
    let uneven = cfg.gait_for(Ground::Uneven);
    assert_eq!((uneven.stability_margin, uneven.translation_step), (0.15, 0.5));
    // The reaction never makes plans less cautious than the base configuration.
    (cfg.gait.stability_margin, cfg.gait.translation_step) = (0.3, 0.4);
    let uneven = cfg.gait_for(Ground::Uneven);
    assert_eq!((uneven.stability_margin, uneven.translation_step), (0.3, 0.4));
    // The other settings are untouched.
    assert_eq!(uneven.goal_tolerance, cfg.gait.goal_tolerance);
    // And the walk's planner takes it.
    assert_eq!(cfg.horizon(Ground::Uneven).unwrap().cfg, uneven);
}

#[test]
fn goal_pose_to_the_walks_goal() {
    let mut m = PoseStamped::default();
    m.header.frame_id = "odom".into();
    (m.pose.position.x, m.pose.position.y) = (3.0, -4.0);
    // 0.5 m per [j]: 3 m is 6 [j].
    assert_eq!(goal_from_pose(&m, "odom", 0.5), Ok(Point2::new(6.0, -8.0)));
    m.header.frame_id = "/odom".into();
    assert_eq!(goal_from_pose(&m, "odom", 1.0), Ok(Point2::new(3.0, -4.0)));
    m.header.frame_id = "map".into();
    assert_eq!(
        goal_from_pose(&m, "odom", 1.0),
        Err(GoalRefusal::Frame {
            got: "map".into(),
            expected: "odom".into()
        })
    );
    m.header.frame_id = "odom".into();
    m.pose.position.x = f64::NAN;
    assert!(matches!(
        goal_from_pose(&m, "odom", 1.0),
        Err(GoalRefusal::Invalid { .. })
    ));
    m.pose.position.x = 1000.5;
    assert!(matches!(
        goal_from_pose(&m, "odom", 1.0),
        Err(GoalRefusal::Invalid { .. })
    ));
}

#[test]
fn markers_draw_the_body_feet_support_triangle_path_and_goal_in_metres() {
    let cfg = GaitNodeConfig::default();
    let model = cfg.model();
    // Body at (1, 2), φ = π/2: body vectors turn by +90°, (x, y) → (−y, x).
    let body = BodyPose {
        x: 1.0,
        y: 2.0,
        phi: FRAC_PI_2,
    };
    let outline = body_outline(&model, &body);
    // Hips 0 (−1, 1.5), 2 (1, 1.5), 3 (1, −1.5), 1 (−1, −1.5), then 0 again.
    let expected = [(-0.5, 1.0), (-0.5, 3.0), (2.5, 3.0), (2.5, 1.0), (-0.5, 1.0)];
    for (p, e) in outline.iter().zip(expected) {
        assert!(close(*p, e), "{p:?} vs {e:?}");
    }
    let state = GaitState::nominal(&model, body);
    let tri = support_triangle(&state, 1);
    assert_eq!(tri, vec![state.feet[0], state.feet[2], state.feet[3], state.feet[0]]);

    let moved = step(state, Some(5), 0.0); // leg1_max_length_max_angle: leg 1 moved
    let plan = vec![step(state, None, 0.0), moved.clone()];
    let h = header(Time::default(), "odom");
    let unit = 2.0;
    let array = markers(
        &model,
        &state,
        Some(&moved),
        &plan,
        Some(Point2::new(-10.0, 10.0)),
        &h,
        unit,
    );
    let kinds: Vec<(i32, i32)> = array.markers.iter().map(|m| (m.id, m.r#type)).collect();
    assert_eq!(array.markers[0].action, Marker::DELETEALL);
    assert_eq!(
        kinds[1..],
        [
            (0, Marker::LINE_STRIP),
            (1, Marker::SPHERE_LIST),
            (2, Marker::LINE_STRIP),
            (3, Marker::LINE_STRIP),
            (4, Marker::SPHERE)
        ]
    );
    // Metres: 2 m per [j]; the outline's first corner (−0.5, 1) [j] is (−1, 2) m.
    let first = &array.markers[1].points[0];
    assert_eq!((first.x, first.y), (-1.0, 2.0));
    assert_eq!(array.markers[3].points.len(), 4);
    assert_eq!(
        (array.markers[5].pose.position.x, array.markers[5].pose.position.y),
        (-20.0, 20.0)
    );
    assert!(array.markers.iter().all(|m| m.header.frame_id == "odom"));
    // One namespace, its DELETEALL included; every added marker unrotated.
    assert!(array.markers.iter().all(|m| m.ns == "gait"));
    assert!(array.markers[1..]
        .iter()
        .all(|m| m.action == Marker::ADD && m.pose.orientation.w == 1.0 && m.pose.orientation.z == 0.0));
    // Sizes scale with the unit (lines 0.02 m per [j]: the outline twice, the triangle 1.5 times),
    // each marker in its colour, opaque.
    let sizes = [0.08, 0.3, 0.06, 0.04, 0.6];
    let colours = [
        (0.2, 0.2, 0.2),
        (0.0, 0.35, 0.71),
        (0.9, 0.62, 0.0),
        (0.0, 0.6, 0.3),
        (0.8, 0.1, 0.1),
    ];
    for ((m, size), (r, g, b)) in array.markers[1..].iter().zip(sizes).zip(colours) {
        let s = &m.scale;
        assert!(
            [s.x, s.y, s.z].iter().all(|v| (v - size).abs() < 1e-12),
            "{}: {s:?}",
            m.id
        );
        assert_eq!((m.color.r, m.color.g, m.color.b, m.color.a), (r, g, b, 1.0), "{}", m.id);
    }
    // The feet and the path in metres.
    let feet: Vec<(f64, f64, f64)> = array.markers[2].points.iter().map(|p| (p.x, p.y, p.z)).collect();
    let expected: Vec<(f64, f64, f64)> = state.feet.iter().map(|f| (f.x * unit, f.y * unit, 0.0)).collect();
    assert_eq!(feet, expected);
    let path: Vec<(f64, f64)> = array.markers[4].points.iter().map(|p| (p.x, p.y)).collect();
    assert_eq!(path, vec![(2.0, 4.0), (2.0, 4.0)]);
    // A body move draws no support triangle.
    let array = markers(&model, &state, Some(&plan[0]), &plan, None, &h, 1.0);
    assert!(array.markers.iter().all(|m| m.id != 2 || m.action == Marker::DELETEALL));

    let pose = body_pose(&body, h, unit);
    assert_eq!((pose.pose.position.x, pose.pose.position.y), (2.0, 4.0));
    // Quaternion of a yaw of π/2: (0, 0, sin π/4, cos π/4).
    assert!((pose.pose.orientation.z - (PI / 4.0).sin()).abs() < 1e-12);
}

#[test]
fn the_params_file_sets_every_parameter_and_invalid_sets_are_refused() {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/quadruped.yaml")).unwrap();
    let decl = Decl::<GaitNodeConfig>::of();
    let initial = initial_params(&decl.specs(), &[("quadruped.yaml".into(), text)], &[], "/gait", "gait").unwrap();
    assert!(initial.warnings.is_empty(), "{:?}", initial.warnings);
    let cfg: GaitNodeConfig = load(&initial.values).unwrap();
    assert_eq!(cfg.node.frame, "odom");
    assert_eq!((cfg.node.walk_rule_set, cfg.node.walk_evaluation), (RuleSet::A, 3));
    assert_eq!(
        (cfg.node.uneven_stability_margin, cfg.node.uneven_translation_step),
        (0.15, 0.5)
    );
    assert_eq!(cfg.node.max_expansions_limit, 1_000_000);
    // Plans are sent whole by default.
    assert_eq!(
        (cfg.node.max_generated_states, cfg.node.max_plan_states),
        (2_000_000, 0)
    );

    let refused = |name: &str, value: ros2_client::ParameterValue| {
        let mut values = initial.values.clone();
        values.set(name, value);
        load::<GaitNodeConfig>(&values).unwrap_err().to_string()
    };
    use ros2_client::ParameterValue::{Double, DoubleArray, Integer};
    // The walk's start must be a stance the robot can stand in; the UNEVEN margin one the
    // planner takes.
    assert!(refused("walk_start", DoubleArray(vec![f64::NAN, 0.0, 0.0])).contains("walk_start"));
    assert!(refused("uneven_stability_margin", Double(1.5)).contains("stability_margin"));
    // Through the declared ranges (what set_parameters checks first).
    let spec = |name: &str| decl.specs().into_iter().find(|s| s.name == name).unwrap();
    assert!(spec("walk_evaluation").check(&Integer(4)).is_err());
    assert!(spec("walk_rule_set")
        .check(&ros2_client::ParameterValue::String("C".into()))
        .is_err());
    assert!(spec("time_limit_s").check(&Double(0.0)).is_err());
    assert!(spec("unit_length").check(&Double(-1.0)).is_err());
}

#[test]
fn a_far_goal_gets_a_bounded_search_and_a_truncated_reply() {
    // B,(3) from the paper's start toward (−900, 900), 1270 [j] away: thousands of states
    // away, so a search of 100 expansions ends on its limit with a partial plan.
    let mut cfg = GaitNodeConfig::default();
    cfg.node.max_generated_states = 5400;
    let q = query_from_request(
        &request((0.0, 0.0, 1.5 * PI), (-900.0, 900.0), "B", 3, 0),
        &cfg,
        Ground::Even,
    )
    .unwrap();
    // Set B's 27 rules give at most 2 successors each: 5400 / 54 = 100 expansions, below the
    // request's 200 000 (its 0: the max_expansions parameter) and max_expansions_limit.
    assert_eq!((q.max_expansions, q.capped_from), (100, Some(200_000)));
    let (plan, cause) = run_query(&q, &cfg.gait, &|| false, &mut || false);
    assert_eq!((plan.expanded, cause), (100, StopCause::None));
    assert!(plan.generated <= 5400, "{}", plan.generated);
    let reason = plan_reason(&plan, cause, &q, 2.0);
    assert!(
        reason.starts_with("EXPANSION_LIMIT: no goal within 100 expanded states"),
        "{reason}"
    );
    assert!(
        reason.contains("the request's 200000 was capped so that the search generates at most max_generated_states 5400 states, 54 per expansion at most"),
        "{reason}"
    );
    // Set A: 11 rules, 22 successors at most: 5400 / 22 = 245.
    let q = query_from_request(
        &request((0.0, 0.0, FRAC_PI_4), (-900.0, 900.0), "A", 3, 0),
        &cfg,
        Ground::Even,
    )
    .unwrap();
    assert_eq!(q.max_expansions, 245);
    // max_expansions_limit below the memory bound caps first, and is named.
    cfg.node.max_expansions_limit = 50;
    let q = query_from_request(
        &request((0.0, 0.0, FRAC_PI_4), (-900.0, 900.0), "A", 3, 0),
        &cfg,
        Ground::Even,
    )
    .unwrap();
    let (plan, cause) = run_query(&q, &cfg.gait, &|| false, &mut || false);
    assert_eq!(plan.expanded, 50);
    assert!(plan_reason(&plan, cause, &q, 2.0).ends_with("(the request's 200000 was capped to max_expansions_limit)"));

    // The default memory bound: 2 000 000 / 54 = 37 037 expansions of set B.
    let cfg = GaitNodeConfig::default();
    let q = query_from_request(
        &request((0.0, 0.0, 1.5 * PI), (-900.0, 900.0), "B", 3, 0),
        &cfg,
        Ground::Even,
    )
    .unwrap();
    assert_eq!(q.max_expansions, 37_037);
}

#[test]
fn a_plan_longer_than_max_plan_states_is_sent_truncated() {
    let model = GaitNodeConfig::default().model();
    let s0 = GaitState::nominal(
        &model,
        BodyPose {
            x: 0.0,
            y: 0.0,
            phi: 0.0,
        },
    );
    let steps: Vec<PlanStep> = (0..5)
        .map(|k| {
            let mut s = s0;
            s.body.y = f64::from(k);
            step(s, (k > 0).then_some(2), 5.0 - f64::from(k))
        })
        .collect();
    let reached = Plan {
        steps,
        success: true,
        failure: None,
        expanded: 4,
        generated: 9,
    };
    let msg = reply_plan(&reached, RuleSet::A, Evaluation::One, String::new(), 3);
    assert_eq!(msg.steps.len(), 3);
    assert_eq!(msg.steps[2].body.y, 2.0);
    assert!(!msg.success);
    assert_eq!(
        msg.reason,
        "TRUNCATED: the plan has 5 states, only the first 3 are sent (max_plan_states); the whole plan reaches the goal"
    );
    assert_eq!((msg.states_expanded, msg.states_generated), (4, 9));
    // A partial plan keeps its own reason after the truncation's.
    let partial = Plan {
        success: false,
        failure: Some(PlanFailure::ExpansionLimit(4)),
        ..reached.clone()
    };
    let msg = reply_plan(&partial, RuleSet::A, Evaluation::One, "EXPANSION_LIMIT: x".into(), 4);
    assert_eq!(msg.steps.len(), 4);
    assert!(msg
        .reason
        .ends_with("only the first 4 are sent (max_plan_states); EXPANSION_LIMIT: x"));
    // Five states within a limit of 5, or no limit (0, the default): sent whole.
    for limit in [5, 0] {
        let msg = reply_plan(&reached, RuleSet::A, Evaluation::One, String::new(), limit);
        assert_eq!((msg.steps.len(), msg.success, msg.reason.as_str()), (5, true, ""));
    }
}

/// Least distance of the body centre inside the triangle of the three feet other than `leg`,
/// negative outside: each edge's signed distance, by its normal.
fn support_margin(s: &GaitState, leg: usize) -> f64 {
    let t: Vec<Point2<f64>> = (0..4).filter(|&k| k != leg).map(|k| s.feet[k]).collect();
    let c = s.body.centre();
    let orient = (t[1] - t[0]).perp(&(t[2] - t[0])).signum();
    (0..3)
        .map(|i| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            orient * (b - a).perp(&(c - a)) / (b - a).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn uneven_ground_during_a_walk_drops_the_queued_moves_and_the_plan_under_way() {
    let mut cfg = GaitNodeConfig::default();
    cfg.node.walk_execute_moves = 8;
    let goal = Point2::new(0.0, 12.0);
    let mut walker = Walker::new(cfg.walk_start_state());
    walker.set_goal(goal);
    let even = cfg.horizon(Ground::Even).unwrap();
    let first = even.next_chunk(walker.state(), goal, &mut || false);
    // The even plan lifts legs closer to the triangle's edge than UNEVEN allows: without the
    // replan those moves would be executed.
    let leg_margins: Vec<f64> = first.executed[1..]
        .iter()
        .filter_map(|s| s.rule.and_then(Rule::moving_leg).map(|l| support_margin(&s.state, l)))
        .collect();
    assert!(leg_margins.iter().any(|&m| m < 0.15), "{leg_margins:?}");
    assert_eq!(walker.take_chunk(walker.epoch(), first, 0.5, 100), Some(WalkNext::Move));
    walker.step();
    // A plan asked for now, then UNEVEN: the queue goes, and that plan is refused on arrival.
    let asked = walker.epoch();
    let stale = even.next_chunk(walker.state(), goal, &mut || false);
    walker.replan();
    assert_eq!(walker.take_chunk(asked, stale, 0.5, 100), None);
    assert_eq!(walker.step(), None);
    assert_eq!(walker.next(0.5, 100), WalkNext::Plan);
    // From here on, plans under UNEVEN: every leg move keeps the centre 0.15 inside.
    let uneven = cfg.horizon(Ground::Uneven).unwrap();
    let mut leg_moves = 0;
    for _ in 0..100 {
        match walker.next(0.5, 100) {
            WalkNext::Plan => {
                let chunk = uneven.next_chunk(walker.state(), goal, &mut || false);
                walker.take_chunk(walker.epoch(), chunk, 0.5, 100);
            }
            WalkNext::Move => {
                let s = walker.step().unwrap();
                if let Some(leg) = s.rule.and_then(Rule::moving_leg) {
                    leg_moves += 1;
                    let m = support_margin(&s.state, leg);
                    assert!(m >= 0.15 - 1e-9, "leg {leg} lifted {m} inside");
                }
            }
            WalkNext::Reached => break,
            other => panic!("{other:?}"),
        }
    }
    assert_eq!(walker.next(0.5, 100), WalkNext::Idle, "the goal is reached");
    assert!(leg_moves > 4, "{leg_moves}");
}

#[test]
fn a_stopped_walk_draws_neither_its_old_plan_nor_its_last_move() {
    let cfg = GaitNodeConfig::default();
    let goal = Point2::new(0.0, 6.0);
    let mut walker = Walker::new(cfg.walk_start_state());
    walker.set_goal(goal);
    let chunk = cfg
        .horizon(Ground::Even)
        .unwrap()
        .next_chunk(walker.state(), goal, &mut || false);
    walker.take_chunk(walker.epoch(), chunk, 0.5, 100);
    walker.step();
    assert!(!walker.plan().is_empty() && walker.current().is_some());
    walker.stop();
    assert!(walker.plan().is_empty() && walker.current().is_none());
    let h = header(Time::default(), "odom");
    let m = markers(
        &cfg.model(),
        walker.state(),
        walker.current(),
        walker.plan(),
        walker.goal(),
        &h,
        1.0,
    );
    // DELETEALL, body outline, feet: no support triangle (2), no path (3), no goal (4).
    let ids: Vec<(i32, i32)> = m.markers.iter().map(|m| (m.id, m.action)).collect();
    assert_eq!(ids, vec![(0, Marker::DELETEALL), (0, Marker::ADD), (1, Marker::ADD)]);
}

#[test]
fn a_walks_plan_stopped_by_the_time_limit_says_time_limit() {
    let stopped = Plan {
        steps: vec![],
        success: false,
        failure: Some(PlanFailure::Stopped),
        expanded: 256,
        generated: 900,
    };
    assert_eq!(
        chunk_reason(&stopped, StopCause::TimeLimit, 2.0),
        "TIME_LIMIT: no goal within the time limit of 2 s (256 states expanded); the plan is the best partial one"
    );
    assert!(chunk_reason(&stopped, StopCause::Preempted, 2.0).starts_with("STOPPED"));
    let limit = Plan {
        failure: Some(PlanFailure::ExpansionLimit(2000)),
        ..stopped.clone()
    };
    assert!(chunk_reason(&limit, StopCause::None, 2.0).starts_with("EXPANSION_LIMIT: no goal within 2000"));
    let reached = Plan {
        success: true,
        failure: None,
        ..stopped
    };
    assert_eq!(chunk_reason(&reached, StopCause::TimeLimit, 2.0), "");
}
