//! The planner's goals as goal laws: the command at the steered point, the ends with their
//! reasons and Nav2 codes, the request's waypoint indices, the undocking's ramp and time limit.
//! Figures worked out by hand from the laws (SPEC §3, §4) and DistanceDrive's ramp.

use approx::assert_relative_eq;
use mobil_chassis::model::ChassisConfig;
use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_motion::{GoalLaw, Notice, Step, StepInput};
use mobil_planner::goals::{
    after_pre_check, docking_failure, docking_offset, DockGoal, PreChecked, RouteAnswer, RouteEvent, RouteGoal,
    UndockGoal,
};
use mobil_planner::{
    DockingConfig, DockingController, DockingFailure, DockingGains, Finish, FollowConfig, ProblemKind, Residual,
    RouteProblem, RouteReport, VelocityLimits, WaypointFollower,
};
use nalgebra::Point2;

/// The paper's gains, limits that never bind, the dock at the origin moved back by `offset`.
fn dock(finish: Finish, offset: f64) -> DockGoal {
    let controller = DockingController::new(
        DockingGains::new(0.5, 0.3, 0.5, 0.55).unwrap(),
        DockingConfig::default(),
        VelocityLimits::new(10.0, 10.0).unwrap(),
        finish,
        Pose2::new(0.0, 0.0, 0.0).ahead(-offset),
    )
    .unwrap();
    DockGoal::new(controller, offset)
}

fn at(t: f64, x: f64, y: f64, yaw: f64) -> StepInput {
    StepInput::new(t, 0.02, Pose2::new(x, y, yaw))
}

#[test]
fn a_docking_steers_the_point_behind_the_reference_point() {
    // Omni, no offset: from (−1, 0, 0), e = 1, α = Θ = 0, so v = γ·e = 0.5 and ω = 0.
    let mut g = dock(Finish::RotateInPlace, 0.0);
    match g.step(&at(0.0, -1.0, 0.0, 0.0), &()) {
        Step::Command { twist, feedback } => {
            assert_relative_eq!(twist.vx, 0.5, epsilon = 1e-12);
            assert_relative_eq!(twist.wz, 0.0, epsilon = 1e-12);
            assert!(feedback.phase_changed);
        }
        other => panic!("{other:?}"),
    }
    // Steered, 0.3 m offset: base_link at (−1.5, 0, 0) puts the origin at (−1.8, 0, 0) and the
    // goal it steers to at (−0.3, 0, 0): e = 1.5, v = 0.75 (0.6 if the offset were ignored).
    let mut g = dock(Finish::ReportResidual, 0.3);
    assert_eq!(g.target(), Pose2::new(0.0, 0.0, 0.0));
    match g.step(&at(0.0, -1.5, 0.0, 0.0), &()) {
        Step::Command { twist, .. } => assert_relative_eq!(twist.vx, 0.75, epsilon = 1e-12),
        other => panic!("{other:?}"),
    }
    // The second step in the same phase is no phase change.
    match g.step(&at(0.02, -1.49, 0.0, 0.0), &()) {
        Step::Command { feedback, .. } => assert!(!feedback.phase_changed),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_docking_ends_docked_or_with_its_residual() {
    let mut g = dock(Finish::RotateInPlace, 0.0);
    match g.step(&at(0.0, 0.0, 0.0, 0.0), &()) {
        Step::End(end) => assert_eq!(
            end.outcome.reason(),
            "SUCCEEDED: docked: e = 0.000 m, heading error 0.000 rad"
        ),
        other => panic!("{other:?}"),
    }
    // A steered chassis at e = 0.01 m (< ε_e 0.02) heading 0.5 rad: it cannot turn in place.
    let mut g = dock(Finish::ReportResidual, 0.0);
    match g.step(&at(0.0, 0.01, 0.0, 0.5), &()) {
        Step::End(end) => {
            assert_eq!(
                end.outcome.reason(),
                "RESIDUAL: position reached, heading residual: chassis cannot turn in place: e = 0.010 m, \
                 heading error -0.500 rad (-28.6°)"
            );
            assert_eq!(end.outcome.nav2_error(), 905);
        }
        other => panic!("{other:?}"),
    }
    // A non-finite pose is refused.
    let mut g = dock(Finish::RotateInPlace, 0.0);
    assert!(matches!(g.step(&at(0.0, f64::NAN, 0.0, 0.0), &()), Step::Refused(_)));
}

#[test]
fn docking_failures_have_their_codes() {
    let r = Residual {
        e: 0.097,
        heading: 0.356,
    };
    let stall = docking_failure(DockingFailure::NotConverging, r, Finish::ReportResidual);
    assert!(
        stall.reason().starts_with("RESIDUAL: V stopped falling"),
        "{}",
        stall.reason()
    );
    assert!(
        stall.reason().ends_with("e = 0.097 m, heading error 0.356 rad (20.4°)"),
        "{}",
        stall.reason()
    );
    let omni = docking_failure(DockingFailure::NotConverging, r, Finish::RotateInPlace);
    assert!(omni.reason().starts_with("NOT_CONVERGING: "));
    let late = docking_failure(DockingFailure::TimeLimit, r, Finish::RotateInPlace);
    assert!(late.reason().starts_with("TIME_LIMIT: time limit reached: "));
    assert_eq!(
        (stall.nav2_error(), omni.nav2_error(), late.nav2_error()),
        (905, 905, 905)
    );
}

#[test]
fn a_route_reports_the_requests_indices_and_ends_done() {
    // Two waypoints ahead on the omni chassis, the request's indices 3 and 4 (a goal_index).
    let follower = WaypointFollower::new(
        FollowConfig::default(),
        &ChassisParams::omr3(),
        vec![Point2::new(1.0, 0.0), Point2::new(2.0, 0.0)],
    )
    .unwrap();
    let mut g = RouteGoal::new(follower, vec![3, 4], 1.0);
    assert_eq!(g.waypoint(), 3);
    match g.step(&at(0.0, 0.0, 0.0, 0.0), &()) {
        Step::Command { twist, feedback } => {
            assert!(twist.vx > 0.0);
            assert_eq!(feedback.waypoint, 3);
            assert_relative_eq!(feedback.distance, 1.0, epsilon = 1e-9);
        }
        other => panic!("{other:?}"),
    }
    // 0.05 m short of waypoint 3, within Z_crit = 0.16 m: reached, the next one pursued.
    match g.step(&at(0.02, 0.95, 0.0, 0.0), &()) {
        Step::Command { feedback, .. } => {
            assert_eq!(feedback.events, vec![RouteEvent::Reached(3)]);
            assert_eq!(feedback.waypoint, 4);
        }
        other => panic!("{other:?}"),
    }
    match g.step(&at(0.04, 1.95, 0.0, 0.0), &()) {
        Step::End(end) => {
            assert_eq!(end.outcome.reason(), "SUCCEEDED: route done: all 2 waypoints reached");
            assert!(end.report.is_empty());
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn an_undocking_backs_out_on_the_ramp_and_ends_within_tolerance_or_time() {
    let mut g = UndockGoal::new(0.5, 0.15, 30.0);
    // 0.5 m to go: √(2·0.075·0.5) = 0.274 > 0.15, so the undocking speed, backwards.
    match g.step(&at(0.02, 0.0, 0.0, 0.0), &()) {
        Step::Command { twist, .. } => assert_relative_eq!(twist.vx, -0.15, epsilon = 1e-12),
        other => panic!("{other:?}"),
    }
    // 0.05 m to go: √(2·0.075·0.05) = 0.0866.
    match g.step(&at(0.5, -0.45, 0.0, 0.0), &()) {
        Step::Command { twist, .. } => assert_relative_eq!(twist.vx, -(0.0075f64).sqrt(), epsilon = 1e-12),
        other => panic!("{other:?}"),
    }
    assert_relative_eq!(g.backed(), 0.45, epsilon = 1e-12);
    // 3 mm to go, within the 5 mm tolerance.
    match g.step(&at(1.0, -0.497, 0.0, 0.0), &()) {
        Step::End(end) => {
            assert_eq!(end.outcome.reason(), "SUCCEEDED: undocked: backed out 0.497 m");
            assert_relative_eq!(end.report, 0.497, epsilon = 1e-12);
        }
        other => panic!("{other:?}"),
    }
    // Along the heading of the first step: facing +y, backing is toward −y.
    let mut g = UndockGoal::new(0.5, 0.15, 30.0);
    g.step(&at(0.02, 1.0, 1.0, std::f64::consts::FRAC_PI_2), &());
    g.step(&at(0.5, 1.0, 0.8, std::f64::consts::FRAC_PI_2), &());
    assert_relative_eq!(g.backed(), 0.2, epsilon = 1e-12);
    // Past the time limit with distance left: TIME_LIMIT, FAILED_TO_CONTROL.
    let mut g = UndockGoal::new(0.5, 0.15, 30.0);
    g.step(&at(1.0, 0.0, 0.0, 0.0), &());
    match g.step(&at(31.0, -0.1, 0.0, 0.0), &()) {
        Step::End(end) => {
            assert_eq!(
                end.outcome.reason(),
                "TIME_LIMIT: not undocked within max_undocking_time 30.0 s (backed out 0.100 m)"
            );
            assert_eq!(end.outcome.nav2_error(), 905);
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(g.step(&at(32.0, f64::NAN, 0.0, 0.0), &()), Step::Refused(_)));
}

#[test]
fn an_undock_request_s_time_limit_is_its_own_or_the_30_s_default_for_none() {
    // 12 s asked: taken, and the undocking fails TIME_LIMIT past it.
    let (mut g, notices) = UndockGoal::for_request(0.5, 0.15, 12.0);
    assert_eq!(
        notices,
        vec![Notice::Info(
            "goal (undock_robot): back out 0.500 m along the heading, within 12.0 s".into()
        )]
    );
    g.step(&at(1.0, 0.0, 0.0, 0.0), &());
    match g.step(&at(13.5, -0.1, 0.0, 0.0), &()) {
        Step::End(end) => {
            assert_eq!(
                end.outcome.reason(),
                "TIME_LIMIT: not undocked within max_undocking_time 12.0 s (backed out 0.100 m)"
            );
            assert_eq!(end.outcome.nav2_error(), 905);
        }
        other => panic!("{other:?}"),
    }
    // Zero, negative, NaN, infinite: Nav2's default of 30 s, with a warning; 13.5 s is in time.
    for bad in [0.0, -4.0, f32::NAN, f32::INFINITY] {
        let (mut g, notices) = UndockGoal::for_request(0.5, 0.15, bad);
        assert_eq!(notices.len(), 2, "{bad}");
        assert!(matches!(&notices[0], Notice::Warn(w) if w.contains("30 s (its default) taken")));
        assert!(matches!(&notices[1], Notice::Info(i) if i.ends_with("within 30.0 s")));
        g.step(&at(1.0, 0.0, 0.0, 0.0), &());
        assert!(matches!(g.step(&at(13.5, -0.1, 0.0, 0.0), &()), Step::Command { .. }));
    }
}

#[test]
fn a_docking_onto_a_pose_steers_the_kinematic_origin_of_a_steered_chassis() {
    // MOBIL-II with its reference point 0.30 m ahead of the rear axle (params/mobil2.yaml).
    let mobil2 = ChassisParams::new(ChassisConfig {
        reference_offset: 0.30,
        ..ChassisConfig::mobil2()
    })
    .unwrap();
    let (omni, steered) = (&ChassisParams::omr3(), &mobil2);
    assert_eq!((docking_offset(omni), docking_offset(steered)), (0.0, 0.30));
    let dock = Pose2::new(1.0, 0.5, 1.0);
    let g = DockGoal::onto(dock, DockingGains::paper(), DockingConfig::default(), steered).unwrap();
    // The law's goal is the dock pose moved back 0.30 m along its heading 1 rad.
    let goal = g.controller().goal();
    assert_relative_eq!(goal.x, 1.0 - 0.30 * 1.0f64.cos(), epsilon = 1e-12);
    assert_relative_eq!(goal.y, 0.5 - 0.30 * 1.0f64.sin(), epsilon = 1e-12);
    assert_relative_eq!(g.target().x, 1.0, epsilon = 1e-12);
    assert_eq!(g.controller().finish(), Finish::ReportResidual);
    let g = DockGoal::onto(dock, DockingGains::paper(), DockingConfig::default(), omni).unwrap();
    assert_eq!((g.controller().goal(), g.offset()), (dock, 0.0));
    assert!(DockGoal::onto(
        Pose2::new(f64::NAN, 0.0, 0.0),
        DockingGains::paper(),
        DockingConfig::default(),
        omni
    )
    .is_err());
}

#[test]
fn a_pre_check_with_problems_refuses_the_route_unless_told_to_drive_it() {
    // Route waypoints (1, 0), (2, 0), (2, 1) from the request's poses 4, 5, 6 (a goal_index).
    let points = [Point2::new(1.0, 0.0), Point2::new(2.0, 0.0), Point2::new(2.0, 1.0)];
    let request = [4, 5, 6];
    let hit = Point2::new(1.6, 0.1);
    let report = RouteReport {
        problems: vec![
            RouteProblem {
                index: 1,
                kind: ProblemKind::Collision {
                    at: hit,
                    clearance: -0.1,
                },
            },
            RouteProblem {
                index: 2,
                kind: ProblemKind::TurnRadius {
                    required: 0.2,
                    minimum: 0.73,
                },
            },
        ],
        path: Vec::new(),
        reached: vec![true, true, true],
    };
    let omr3 = ChassisParams::omr3();
    let start = Pose2::new(0.0, 0.0, 0.0);
    let rules = (FollowConfig::default(), &omr3);
    match after_pre_check(&report, (&points, &request), &start, rules, false) {
        PreChecked::Refuse { outcome, problems } => {
            // Each problem by the request's index, a collision where it begins, the other at its
            // waypoint.
            let got: Vec<_> = problems.iter().map(|m| (m.index, m.position, m.pre_check)).collect();
            assert_eq!(got, vec![(5, hit, true), (6, points[2], true)]);
            assert!(outcome
                .reason()
                .starts_with("ROUTE_INFEASIBLE: 2 problem(s): waypoint 5: collision"));
            assert_eq!(outcome.nav2_error(), 601);
        }
        other => panic!("{other:?}"),
    }
    match after_pre_check(&report, (&points, &request), &start, rules, true) {
        PreChecked::Drive { goal, problems } => {
            assert_eq!(problems.len(), 2);
            // Pursuing the first waypoint, 1 m from the start, by its request index.
            assert_eq!((goal.waypoint(), goal.distance()), (4, 1.0));
        }
        other => panic!("{other:?}"),
    }
    let clean = RouteReport {
        problems: Vec::new(),
        ..report
    };
    assert!(matches!(
        after_pre_check(&clean, (&points, &request), &start, rules, false),
        PreChecked::Drive { problems, .. } if problems.is_empty()
    ));
}

#[test]
fn a_route_check_answers_each_problem_by_request_index_a_short_path_and_its_driven_length() {
    // A straight predicted path of 20 000 poses 2 cm apart, then a 5 m jump (set down on a
    // missed waypoint), then one more 2 cm step; waypoint 1 of request indices (3, 8) collides at
    // (300, 0).
    let mut path: Vec<Pose2> = (0..20_000).map(|i| Pose2::new(i as f64 * 0.02, 0.0, 0.0)).collect();
    path.push(Pose2::new(404.98, 0.0, 0.0));
    path.push(Pose2::new(405.0, 0.0, 0.0));
    let points = [Point2::new(200.0, 0.0), Point2::new(405.0, 0.0)];
    let collision = RouteProblem {
        index: 1,
        kind: ProblemKind::Collision {
            at: Point2::new(300.0, 0.0),
            clearance: -0.1,
        },
    };
    let report = RouteReport {
        problems: vec![collision],
        path,
        reached: vec![true, false],
    };
    let a = RouteAnswer::of(&report, (&points, &[3, 8]), 0.02, 400);
    assert!(!a.feasible());
    assert_eq!(a.failed_waypoint, Some(8));
    let got: Vec<_> = a.problems.iter().map(|m| (m.index, m.position)).collect();
    assert_eq!(got, vec![(8, Point2::new(300.0, 0.0))]);
    assert!(a
        .reason
        .starts_with("ROUTE_INFEASIBLE: 1 problem(s): waypoint 8: collision"));
    // 400 poses, the first and the last kept; the length 19 999 steps of 2 cm and the last
    // one, the 5 m jump left out.
    assert_eq!(a.path.len(), 400);
    assert_eq!((a.path[0].x, a.path[399].x), (0.0, 405.0));
    assert_relative_eq!(a.length, 20_000.0 * 0.02, epsilon = 1e-6);
    // 60 problems: 50 listed, the reason counts all 60.
    let many = RouteReport {
        problems: vec![collision; 60],
        path: Vec::new(),
        reached: vec![true, false],
    };
    let a = RouteAnswer::of(&many, (&points, &[3, 8]), 0.02, 400);
    assert_eq!(a.problems.len(), 50);
    assert!(
        a.reason.starts_with("ROUTE_INFEASIBLE: 60 problem(s): "),
        "{}",
        a.reason
    );
    assert!(a.reason.ends_with("; and 10 more"), "{}", a.reason);
    // None: feasible, no reason, no failed waypoint.
    let clear = RouteReport {
        problems: Vec::new(),
        path: vec![Pose2::identity()],
        reached: vec![true, true],
    };
    let a = RouteAnswer::of(&clear, (&points, &[3, 8]), 0.02, 400);
    assert!(a.feasible() && a.reason.is_empty() && a.failed_waypoint.is_none());
    assert_eq!((a.path.len(), a.length), (1, 0.0));
}
