//! VFO waypoint following as a goal law: the first step optimises and commands, the ends carry
//! their reasons, Nav2's code and the waypoints not reached by the request's indices, the gains
//! are held to the chassis, and an optimisation is reported and drawn. Figures by hand from the
//! law (SPEC §5) where a figure is asserted.

use approx::assert_relative_eq;
use mobil_chassis::model::ChassisConfig;
use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_motion::{GoalLaw, Outcome, Step, StepInput};
use mobil_planner::vfo::{
    find_sigmas, vfo_gains, vfo_waypoints, Interrupt, Obstacle, ObstacleMap, OptimiseConfig, Reoptimised,
    ScanObstacleConfig, Segment, SegmentReport, VfoController, VfoDrawing, VfoEvent, VfoFollower, VfoGains, VfoGoal,
    VfoSetup, VfoTick, VfoWaypoint, MAX_BUDGET_RETRIES,
};
use nalgebra::Point2;

fn goal(waypoints: &[(f64, f64)], obstacles: Vec<Obstacle>, request_index: Vec<usize>) -> VfoGoal {
    let w = waypoints
        .iter()
        .map(|&(x, y)| VfoWaypoint::new(x, y, 0.0, 0.5).unwrap())
        .collect();
    let follower = VfoFollower::new(VfoGains::default(), OptimiseConfig::default(), w, obstacles).unwrap();
    VfoGoal::new(follower, request_index, 0.0, &Pose2::identity(), Vec::new())
}

fn at(t: f64, x: f64, y: f64) -> StepInput {
    StepInput::new(t, 0.02, Pose2::new(x, y, 0.0))
}

#[test]
fn the_first_step_optimises_the_segment_and_commands() {
    // One obstacle on the way to (4, 0): two ways round, three virtual robots (the first to the
    // zone's edge, then one each way).
    let obstacle = Obstacle::new(Point2::new(2.0, 0.0), 0.5, 1.0).unwrap();
    let mut g = goal(&[(4.0, 0.0)], vec![obstacle], vec![3]);
    assert_eq!(g.view().distance, 4.0);
    assert_eq!((g.view().waypoint, g.unreached()), (3, vec![3]));
    match g.step(&at(0.0, 0.0, 0.0), &VfoTick::uninterrupted(0.0)) {
        Step::Command { twist, feedback } => {
            // At the start d = 2 > R = 1: no avoidance yet, H* = k_p·e* + v* = (4, 0) − 0.5·4·(1, 0)
            // = (2, 0) points at the waypoint straight ahead, e_a = 0: ω = 0 and, the waypoint
            // being the last, v = min(U_2, ‖H*‖)·cos 0 = 0.3.
            assert_relative_eq!(twist.wz, 0.0, epsilon = 1e-12);
            assert_relative_eq!(twist.vx, 0.3, epsilon = 1e-12);
            assert_eq!(twist.vy, 0.0);
            assert!(feedback
                .events
                .iter()
                .any(|e| matches!(e, VfoEvent::Optimised { index: 0, .. })));
            let drawing = feedback.drawing.expect("optimised: drawn");
            assert_eq!(drawing.robots.len(), 3);
            assert_eq!(drawing.obstacles, vec![obstacle]);
            assert!(!feedback.settling);
        }
        other => panic!("{other:?}"),
    }
    let report = g.view().report;
    assert_eq!((report.virtual_robots, report.candidates), (3, 2));
    assert!(report.psi_z.is_finite() && report.indices.iter().all(|x| x.is_finite()));
    // A later step without an optimisation draws nothing new.
    match g.step(&at(0.02, 0.006, 0.0), &VfoTick::uninterrupted(0.02)) {
        Step::Command { feedback, .. } => assert!(feedback.drawing.is_none() && feedback.events.is_empty()),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_collision_ends_the_route_with_the_figures_and_the_waypoints_left() {
    // The robot at the origin, an obstacle centred 0.3 m ahead with r = 0.5: inside it.
    let obstacle = Obstacle::new(Point2::new(0.3, 0.0), 0.5, 1.0).unwrap();
    let mut g = goal(&[(2.0, 1.0), (4.0, 0.0)], vec![obstacle], vec![5, 6]);
    match g.step(&at(0.0, 0.0, 0.0), &VfoTick::uninterrupted(0.0)) {
        Step::End(end) => {
            assert_eq!(end.report, vec![5, 6]);
            assert_eq!(end.outcome.nav2_error(), 601);
            assert_eq!(
                end.outcome.reason(),
                "COLLISION: the robot is 0.30 m from the centre of the obstacle at (0.30, 0.00), inside its \
                 forbidden radius r = 0.50 m (an obstacle seen too late or moving): robot stopped"
            );
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_waypoint_no_path_reaches_ends_no_safe_path() {
    // The only waypoint at an obstacle's centre: every virtual robot collides on the way.
    let obstacle = Obstacle::new(Point2::new(2.0, 0.0), 0.5, 1.0).unwrap();
    let mut g = goal(&[(2.0, 0.0)], vec![obstacle], vec![7]);
    match g.step(&at(0.0, 0.0, 0.0), &VfoTick::uninterrupted(0.0)) {
        Step::End(end) => {
            let reason = end.outcome.reason();
            assert!(reason.starts_with("NO_SAFE_PATH: "), "{reason}");
            assert!(reason.contains("to waypoint 7 without a collision"), "{reason}");
            assert!(!reason.contains("  "), "one space between words: {reason}");
            assert_eq!((end.report, end.outcome.nav2_error()), (vec![7], 601));
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_budget_spent_every_time_ends_optimisation_budget() {
    let obstacle = Obstacle::new(Point2::new(2.0, 0.0), 0.5, 1.0).unwrap();
    let mut g = goal(&[(4.0, 0.0)], vec![obstacle], vec![1]);
    let spent = || VfoTick {
        stamp: 0.0,
        interrupt: Box::new(|| Some(Interrupt::Budget)),
    };
    let mut commands = 0;
    let end = (0..200)
        .find_map(|k| {
            let t = f64::from(k) * 0.02;
            let mut tick = spent();
            tick.stamp = t;
            match g.step(&at(t, 0.0, 0.0), &tick) {
                Step::End(end) => Some(end),
                Step::Command { twist, .. } => {
                    // No path proven safe: the robot is held at zero meanwhile.
                    assert_eq!((twist.vx, twist.wz), (0.0, 0.0));
                    commands += 1;
                    None
                }
                Step::Refused(why) => panic!("{why}"),
            }
        })
        .expect("ends");
    let reason = end.outcome.reason();
    assert!(
        reason.starts_with(&format!(
            "OPTIMISATION_BUDGET: optimisation budget exhausted: {MAX_BUDGET_RETRIES} optimisations in a row"
        )),
        "{reason}"
    );
    assert!(
        reason.contains("waypoint 1") && !reason.contains("NO_SAFE_PATH"),
        "{reason}"
    );
    assert_eq!(end.report, vec![1]);
    assert!(commands < 200);
}

#[test]
fn a_route_done_succeeds_and_a_bad_pose_is_refused() {
    let mut g = goal(&[(0.5, 0.0)], Vec::new(), vec![0]);
    assert!(matches!(
        g.step(&at(0.0, f64::NAN, 0.0), &VfoTick::uninterrupted(0.0)),
        Step::Refused(_)
    ));
    // Driven straight along x by its own commands (an exact unicycle on a line): done.
    let mut x = 0.0;
    let end = (0..2000)
        .find_map(|k| {
            let t = f64::from(k) * 0.02;
            match g.step(&at(t, x, 0.0), &VfoTick::uninterrupted(t)) {
                Step::End(end) => Some(end),
                Step::Command { twist, .. } => {
                    x += twist.vx * 0.02;
                    None
                }
                Step::Refused(why) => panic!("{why}"),
            }
        })
        .expect("ends");
    assert_eq!(end.outcome, Outcome::succeeded("route done: all 1 waypoints reached"));
    assert!(end.report.is_empty() && g.unreached().is_empty());
    assert!(x > 0.3, "{x}");
}

#[test]
fn gains_are_held_to_the_chassis() {
    // OMR-III: v_max 0.5, ω_max 1.5; U_2 0.3 stays, |ω| ≤ 4 becomes 1.5.
    let g = vfo_gains(&VfoGains::default(), &ChassisParams::omr3());
    assert_eq!((g.speed, g.omega_max, g.k_a), (0.3, 1.5, 5.0));
    // A U_2 above v_max is held to it.
    let fast = VfoGains {
        speed: 0.8,
        ..VfoGains::default()
    };
    assert_eq!(vfo_gains(&fast, &ChassisParams::omr3()).speed, 0.5);
    // MOBIL-II turns no tighter than R_min = 0.73 m: |ω| ≤ 0.3 / 0.73 = 0.411 rad/s.
    let mobil2 = ChassisParams::new(ChassisConfig::mobil2()).unwrap();
    assert_relative_eq!(mobil2.min_turning_radius(), 0.73, epsilon = 0.005);
    let g = vfo_gains(&VfoGains::default(), &mobil2);
    assert_relative_eq!(g.omega_max, 0.3 / mobil2.min_turning_radius(), epsilon = 1e-12);
    assert_relative_eq!(g.omega_max, 0.411, epsilon = 0.003);
}

#[test]
fn the_report_and_the_drawing_of_an_optimisation() {
    let obstacles = [Obstacle::new(Point2::new(2.0, 0.0), 0.5, 1.0).unwrap()];
    let segment = Segment {
        waypoint: VfoWaypoint::new(4.0, 0.0, 0.0, 0.5).unwrap(),
        last: true,
        obstacles: &obstacles,
    };
    let controller = VfoController::new(VfoGains::default()).unwrap();
    let o = find_sigmas(&Pose2::identity(), &controller, &segment, &OptimiseConfig::default()).unwrap();
    let d = VfoDrawing::of(&o, &obstacles);
    assert_eq!(d.robots.len(), 3);
    assert!(d.robots.iter().all(|r| !r.dropped && r.points.len() >= 2));
    // The chosen path runs from the start to within ϵ of the waypoint.
    let (first, last) = (d.chosen[0], d.chosen[d.chosen.len() - 1]);
    assert!((first - Point2::origin()).norm() < 1e-9);
    assert!((last - Point2::new(4.0, 0.0)).norm() < 0.1);
    // It passes the obstacle outside r = 0.5.
    assert!(d.chosen.iter().all(|p| (p - Point2::new(2.0, 0.0)).norm() > 0.5));
    assert_eq!(SegmentReport::of(&o).candidates, 2);
    let r = SegmentReport::default();
    assert!(r.psi_z.is_nan() && r.virtual_robots == 0);
}

#[test]
fn waypoint_headings_follow_the_legs_unless_given() {
    use std::f64::consts::PI;
    // From (0, 0) facing 0.3 rad: (1, 0) along +x (0); (1, 0) again keeps 0; (1, 2) along +y
    // (π/2); (0, 2) along −x (π).
    let points = [
        Point2::new(1.0, 0.0),
        Point2::new(1.0, 0.0),
        Point2::new(1.0, 2.0),
        Point2::new(0.0, 2.0),
    ];
    let w = vfo_waypoints(&points, &[None; 4], &Pose2::new(0.0, 0.0, 0.3), 0.4).unwrap();
    let headings: Vec<f64> = w.iter().map(|w| w.heading).collect();
    for (got, want) in headings.iter().zip([0.0, 0.0, PI / 2.0, PI]) {
        assert_relative_eq!(*got, want, epsilon = 1e-12);
    }
    assert!(w.iter().all(|w| w.guiding == 0.4) && w[2].position == Point2::new(1.0, 2.0));
    // A given heading is taken (0 rad at (0, 2), not the leg's π); the next leg's follows.
    let given = [None, Some(0.5), Some(0.0), None];
    let w = vfo_waypoints(&points, &given, &Pose2::new(0.0, 0.0, 0.3), 0.4).unwrap();
    assert_relative_eq!(w[1].heading, 0.5, epsilon = 1e-12);
    assert_relative_eq!(w[2].heading, 0.0, epsilon = 1e-12);
    // A waypoint on the start keeps the start's heading; a non-finite one is refused by index.
    let w = vfo_waypoints(&[Point2::origin()], &[None], &Pose2::new(0.0, 0.0, 0.3), 0.5).unwrap();
    assert_relative_eq!(w[0].heading, 0.3, epsilon = 1e-12);
    let bad = [Point2::new(1.0, 0.0), Point2::new(f64::NAN, 0.0)];
    assert_eq!(vfo_waypoints(&bad, &[None; 2], &Pose2::identity(), 0.5), Err(1));
}

#[test]
fn a_route_goal_is_built_for_the_chassis_and_tells_its_events() {
    let map = ObstacleMap::new(ScanObstacleConfig::default()).unwrap();
    let setup = VfoSetup {
        gains: VfoGains::default(),
        optimise: OptimiseConfig::default(),
        guiding: 0.5,
    };
    let points = [Point2::new(2.0, 0.0), Point2::new(2.0, 2.0)];
    let g = VfoGoal::for_route(
        (&points, &[None, None], &[7, 8]),
        &Pose2::identity(),
        &setup,
        &ChassisParams::omr3(),
        &map,
    )
    .unwrap();
    // OMR-III holds |ω| ≤ 4 to its 1.5 rad/s; the first waypoint 2 m from the start.
    assert_eq!(g.follower().waypoints().len(), 2);
    assert_eq!((g.view().waypoint, g.view().distance), (7, 2.0));
    let reached = VfoEvent::Reached { index: 1, vortex: true };
    assert_eq!(
        g.describe(&reached),
        "waypoint 8 reached (early: the robot was caught between obstacles, Algorithm 3)"
    );
    let optimised = VfoEvent::Optimised {
        index: 0,
        reason: Reoptimised::SegmentStart,
        score: None,
        warnings: Vec::new(),
    };
    assert_eq!(
        g.describe(&optimised),
        "segment to waypoint 7 optimised (SegmentStart): Ψ_z none, 0 virtual robots, 0 candidates"
    );
    // A bad waypoint or bad settings are refused with the request's index and the codes.
    let bad = [Point2::new(2.0, 0.0), Point2::new(f64::INFINITY, 0.0)];
    let e = VfoGoal::for_route(
        (&bad, &[None, None], &[7, 8]),
        &Pose2::identity(),
        &setup,
        &ChassisParams::omr3(),
        &map,
    )
    .unwrap_err();
    assert_eq!(
        (e.reason().as_str(), e.nav2_error()),
        ("INVALID_GOAL: waypoint 8 is not finite", 600)
    );
    let broken = VfoSetup {
        optimise: OptimiseConfig {
            time_step: -1.0,
            ..OptimiseConfig::default()
        },
        ..setup
    };
    let e = VfoGoal::for_route(
        (&points, &[None, None], &[7, 8]),
        &Pose2::identity(),
        &broken,
        &ChassisParams::omr3(),
        &map,
    )
    .unwrap_err();
    assert!(
        e.reason().starts_with("INVALID_INPUT: the planner refused its input"),
        "{}",
        e.reason()
    );
}
