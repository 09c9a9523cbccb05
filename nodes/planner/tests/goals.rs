//! The planner's goals as goal laws: the command at the steered point, the ends with their
//! reasons and Nav2 codes, the request's waypoint indices, the undocking's ramp and time limit.
//! Figures worked out by hand from the laws (SPEC §3, §4) and DistanceDrive's ramp.

use approx::assert_relative_eq;
use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_motion::{GoalLaw, Step, StepInput};
use mobil_planner::goals::{docking_failure, DockGoal, RouteEvent, RouteGoal, UndockGoal};
use mobil_planner::{
    DockingConfig, DockingController, DockingFailure, DockingGains, Finish, FollowConfig, Residual, VelocityLimits,
    WaypointFollower,
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
