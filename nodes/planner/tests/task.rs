//! The planner's goal as one type: the status' mode, waypoint and figures of each task, the
//! steps taken on the loop and those that are not, a pre-check's turn into a route or a
//! refusal, the VFO law lent out and taken back (a late command dropped), and the Nav2 codes
//! of the ends the node makes. Figures by hand from the routes and poses given.

use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_motion::slot::Handback;
use mobil_motion::{BodyTwist, EndCause, GoalLaw, Notice, Outcome, Step, StepInput};
use mobil_planner::goals::{DockGoal, UndockGoal};
use mobil_planner::task::{Action, Mode, PreCheck, Source, Stepped, Task, VfoRun, VfoStart};
use mobil_planner::vfo::{
    ObstacleMap, OptimiseConfig, OptimiseWarning, Reoptimised, ScanObstacleConfig, VfoEvent, VfoFollower, VfoGains,
    VfoGoal, VfoSettings, VfoStep, VfoTick, VfoWaypoint,
};
use mobil_planner::{
    DockingConfig, DockingController, DockingGains, Finish, FollowConfig, ProblemKind, RouteProblem, RouteReport,
    VelocityLimits,
};
use nalgebra::Point2;
use std::time::{Duration, Instant};

/// Waypoints (1, 0), (2, 0), (2, 1), the request's poses 4, 5, 6, from the origin.
fn pre_check() -> Task {
    let points = vec![Point2::new(1.0, 0.0), Point2::new(2.0, 0.0), Point2::new(2.0, 1.0)];
    Task::PreCheck(PreCheck::new(Pose2::identity(), points, vec![4, 5, 6]))
}

/// The pre-check found a collision on the way to the second waypoint (request index 5).
fn blocked() -> RouteReport {
    RouteReport {
        problems: vec![RouteProblem {
            index: 1,
            kind: ProblemKind::Collision {
                at: Point2::new(1.6, 0.1),
                clearance: -0.1,
            },
        }],
        path: Vec::new(),
        reached: vec![true, true, true],
    }
}

fn at(x: f64, y: f64, yaw: f64) -> StepInput {
    StepInput::new(0.0, 0.02, Pose2::new(x, y, yaw))
}

#[test]
fn a_route_waits_for_its_pre_check_then_is_refused_or_driven() {
    let omr3 = ChassisParams::omr3();
    let rules = (FollowConfig::default(), &omr3);
    let mut task = pre_check();
    let f = task.figures(None);
    // Waiting: the first waypoint shown, by its request index, no distance yet, no step.
    assert_eq!(
        (f.mode, f.waypoint, f.goal),
        (Mode::PreCheck, Some(4), Some(Pose2::new(1.0, 0.0, 0.0)))
    );
    assert!(f.distance.is_nan());
    assert_eq!(task.step(&at(0.0, 0.0, 0.0), 0.0), Stepped::Waiting);
    // Refused (execute_infeasible_routes false): ROUTE_INFEASIBLE (FollowWaypoints 601), the
    // problem kept by its request index for the result; still the pre-check.
    let refused = task.pre_checked(&blocked(), rules, false).unwrap().unwrap_err();
    assert!(refused
        .reason()
        .starts_with("ROUTE_INFEASIBLE: 1 problem(s): waypoint 5: collision"));
    assert_eq!(refused.nav2_error(), 601);
    let Task::PreCheck(p) = &task else { panic!("{task:?}") };
    assert_eq!(p.problems.iter().map(|m| m.index).collect::<Vec<_>>(), vec![5]);
    // Driven through (true): the goal approach towards (1, 0), 1 m from the start.
    let mut task = pre_check();
    let problems = task.pre_checked(&blocked(), rules, true).unwrap().unwrap();
    assert_eq!(problems.len(), 1);
    let f = task.figures(None);
    assert_eq!((f.mode, f.waypoint, f.distance), (Mode::Approach, Some(4), 1.0));
    assert!(matches!(
        task.step(&at(0.0, 0.0, 0.0), 0.0),
        Stepped::Law(Step::Command { .. })
    ));
    // A task that is no pre-check takes no report.
    assert_eq!(task.pre_checked(&blocked(), rules, true), None);
}

#[test]
fn a_result_lists_a_refused_route_s_problems_a_vfo_route_s_unreached_waypoints_a_docking_none() {
    let omr3 = ChassisParams::omr3();
    let rules = (FollowConfig::default(), &omr3);
    // Refused by its pre-check: the collision on the way to request pose 5, as ComputePathToPose's
    // NO_VALID_PATH (208; a collision is no blocked goal), whether it succeeded or not.
    let mut task = pre_check();
    assert!(task.pre_checked(&blocked(), rules, false).unwrap().is_err());
    assert_eq!(task.result_missed(false), vec![(5, 208)]);
    assert_eq!(task.result_missed(true), vec![(5, 208)]);
    // Driven through its problems: the run has missed nothing yet.
    let mut task = pre_check();
    assert!(task.pre_checked(&blocked(), rules, true).unwrap().is_ok());
    assert_eq!(task.result_missed(true), vec![]);
    // A VFO route ending before its only waypoint (request index 7): FollowPath's
    // FAILED_TO_MAKE_PROGRESS (105); once done, nothing.
    let task = Task::Vfo(vfo());
    assert_eq!(task.result_missed(false), vec![(7, 105)]);
    assert_eq!(task.result_missed(true), vec![]);
    let task = Task::Undock(UndockGoal::new(0.5, 0.15, 30.0));
    assert_eq!(task.result_missed(false), vec![]);
}

#[test]
fn a_vfo_route_past_its_first_waypoint_lists_the_rest_by_request_index() {
    // A route of request poses 1, 2, 0 (a goal_index 1 with a loop, cut short) through (1, 0),
    // (2, 0), (3, 0); the robot stands on the first waypoint, so the law's step passes it.
    let w: Vec<VfoWaypoint> = (1..=3)
        .map(|x| VfoWaypoint::new(f64::from(x), 0.0, 0.0, 0.5).unwrap())
        .collect();
    let follower = VfoFollower::new(VfoGains::default(), OptimiseConfig::default(), w, Vec::new()).unwrap();
    let law = VfoGoal::new(follower, vec![1, 2, 0], 0.0, &Pose2::identity(), Vec::new());
    let mut run = VfoRun::new(law, Duration::from_secs(1));
    assert_eq!(run.unreached(), vec![1, 2, 0]);
    let map = ObstacleMap::new(ScanObstacleConfig::default()).unwrap();
    let t0 = Instant::now();
    let mut law = run.lend(t0, &map).unwrap();
    let step = law.step(&at(1.0, 0.0, 0.0), &VfoTick::uninterrupted(0.0));
    run.give_back(law, step, t0);
    assert_eq!(run.view().index, 1, "the first waypoint passed");
    assert_eq!(run.unreached(), vec![2, 0]);
    let task = Task::Vfo(run);
    assert_eq!(task.result_missed(false), vec![(2, 105), (0, 105)]);
}

#[test]
fn a_docking_shows_its_figures_at_the_latest_pose_before_its_first_step() {
    let controller = DockingController::new(
        DockingGains::paper(),
        DockingConfig::default(),
        VelocityLimits::new(10.0, 10.0).unwrap(),
        Finish::RotateInPlace,
        Pose2::new(0.0, 0.0, 0.0),
    )
    .unwrap();
    let task = Task::Dock(DockGoal::new(controller, 0.0));
    let f = task.figures(None);
    assert_eq!(
        (f.mode, f.waypoint, f.goal),
        (Mode::Dock, None, Some(Pose2::identity()))
    );
    assert!(f.distance.is_nan() && f.docking.unwrap().iter().all(|v| v.is_nan()));
    // 3 m behind the dock, facing it: e = 3 m, Ω = 0 so α = Θ = 0, and (SPEC §3)
    // V = ½(λe² + α² + hΘ²) = ½·0.55·9 = 2.475 with the paper's λ = 0.55.
    let f = task.figures(Some(&Pose2::new(-3.0, 0.0, 0.0)));
    let [e, alpha, theta, v] = f.docking.unwrap();
    assert_eq!((f.distance, e, alpha, theta), (3.0, 3.0, 0.0, 0.0));
    assert!((v - 2.475).abs() < 1e-12, "{v}");
}

#[test]
fn an_undocking_steps_on_the_loop_and_shows_what_is_left() {
    let mut task = Task::Undock(UndockGoal::new(0.5, 0.15, 30.0));
    let f = task.figures(None);
    assert_eq!((f.mode, f.waypoint, f.distance), (Mode::Undock, None, 0.5));
    match task.step(&at(0.0, 0.0, 0.0), 0.0) {
        Stepped::Law(Step::Command { twist, feedback }) => {
            assert!(twist.vx < 0.0, "backs out: {twist:?}");
            assert!(!feedback.changed && feedback.events.is_empty());
        }
        other => panic!("{other:?}"),
    }
}

/// A VFO route to (2, 0) (request index 7), no obstacles, from the origin.
fn vfo() -> VfoRun {
    let w = vec![VfoWaypoint::new(2.0, 0.0, 0.0, 0.5).unwrap()];
    let follower = VfoFollower::new(VfoGains::default(), OptimiseConfig::default(), w, Vec::new()).unwrap();
    let law = VfoGoal::new(follower, vec![7], 0.0, &Pose2::identity(), Vec::new());
    VfoRun::new(law, Duration::from_millis(40))
}

fn command(vx: f64, wz: f64) -> Step<VfoStep, Vec<usize>> {
    Step::Command {
        twist: BodyTwist::new(vx, 0.0, wz),
        feedback: VfoStep {
            events: Vec::new(),
            settling: false,
            drawing: None,
        },
    }
}

#[test]
fn a_vfo_law_is_lent_once_and_a_late_command_is_dropped() {
    let map = ObstacleMap::new(ScanObstacleConfig::default()).unwrap();
    let mut task = Task::Vfo(vfo());
    let f = task.figures(None);
    assert_eq!(
        (f.mode, f.waypoint, f.goal, f.distance),
        (Mode::Vfo, Some(7), Some(Pose2::new(2.0, 0.0, 0.0)), 2.0)
    );
    assert_eq!(task.step(&at(0.0, 0.0, 0.0), 0.0), Stepped::OffLoop);
    let Task::Vfo(run) = &mut task else { unreachable!() };
    let t0 = Instant::now();
    // A change with new obstacles stays one until the law takes it, at its next lending.
    assert_eq!(run.map_pending(), None);
    run.map_updated(true);
    run.map_updated(false);
    assert_eq!(run.map_pending(), Some(true));
    let law = run.lend(t0, &map).expect("at home");
    assert_eq!(run.map_pending(), None);
    assert!(run.lend(t0, &map).is_none() && run.law().is_none(), "out on its step");
    // Back within 40 ms: the command stands.
    let (step, back) = run.give_back(law, command(0.3, 0.1), t0 + Duration::from_millis(10));
    assert_eq!(back, Handback::Fresh);
    assert!(matches!(step, Step::Command { twist, .. } if twist == BodyTwist::new(0.3, 0.0, 0.1)));
    // Back after a second: dropped, zero.
    let law = run.lend(t0, &map).unwrap();
    let (step, back) = run.give_back(law, command(0.3, 0.1), t0 + Duration::from_secs(1));
    assert_eq!(back, Handback::Late);
    assert!(matches!(step, Step::Command { twist, .. } if twist == BodyTwist::new(0.0, 0.0, 0.0)));
    assert!(run.law().is_some());
}

#[test]
fn the_ends_the_node_makes_carry_each_action_s_nav2_code() {
    // DockRobot/UndockRobot: FAILED_TO_CONTROL 905, UNKNOWN 999, DOCK_NOT_VALID 902,
    // DOCK_NOT_IN_DB 901; FollowWaypoints: TASK_EXECUTOR_FAILED 601, UNKNOWN 600.
    let stale = EndCause::Stale("odom".into());
    let refused = EndCause::Refused {
        count: 20,
        last: "pose is not finite".into(),
    };
    for (cause, codes) in [
        (&stale, [905, 905, 601]),
        (&refused, [905, 905, 601]),
        (&EndCause::Shutdown, [999, 999, 600]),
        (&EndCause::Canceled, [0, 0, 0]),
        (&EndCause::Preempted("dock_pose"), [0, 0, 0]),
        (&EndCause::Outcome(Outcome::failed("BLOCKED", "", 106)), [106, 106, 106]),
    ] {
        let got = [Action::Dock, Action::Undock, Action::Follow].map(|a| a.error_code(cause));
        assert_eq!(got, codes, "{cause:?}");
    }
    assert_eq!(Action::Dock.invalid_goal("dock pose is not finite").nav2_error(), 902);
    assert_eq!(Action::Undock.invalid_goal("x").nav2_error(), 999);
    assert_eq!(Action::Follow.invalid_goal("x").nav2_error(), 600);
    assert_eq!(
        Action::Dock.invalid_goal("dock pose is not finite").reason(),
        "INVALID_GOAL: dock pose is not finite"
    );
    let r = Action::Follow.refused_goal("gamma 0 is not positive");
    assert_eq!(
        (r.reason().as_str(), r.nav2_error()),
        (
            "INVALID_INPUT: the planner refused its input: gamma 0 is not positive; robot stopped",
            601
        )
    );
    let s = Action::Dock.stale_at_start("scan");
    assert_eq!(
        (s.reason().as_str(), s.nav2_error()),
        ("STALE_INPUT: scan stale: robot stopped", 905)
    );
}

#[test]
fn sources_name_their_topic_or_action_and_stand_for_an_action_s_codes() {
    use Source::*;
    let all = [DockPose, Waypoints, DockAction, UndockAction, FollowAction];
    // Topics stand for the actions whose codes their ends take.
    let actions: Vec<Action> = all.iter().map(|s| s.action()).collect();
    use Action::{Dock, Follow, Undock};
    assert_eq!(actions, vec![Dock, Follow, Dock, Undock, Follow]);
    let names: Vec<&str> = all.iter().map(|s| s.name()).collect();
    assert_eq!(
        names,
        [
            "dock_pose",
            "waypoints",
            "dock_robot",
            "undock_robot",
            "follow_waypoints"
        ]
    );
}

#[test]
fn a_vfo_route_starts_with_fresh_odometry_and_a_fresh_scan_its_late_bound_from_the_odometry() {
    let map = ObstacleMap::new(ScanObstacleConfig::default()).unwrap();
    let settings = VfoSettings::default();
    let (omr3, mobil2) = (ChassisParams::omr3(), ChassisParams::mobil2());
    let route = (&[Point2::new(2.0, 0.0)][..], &[None][..], &[7][..]);
    let start = Some(Pose2::identity());
    let ms = Duration::from_millis;
    let reason = |r: Result<VfoStart, Outcome>| r.map(|_| ()).unwrap_err().reason();
    let rules = (&settings, &omr3, &map);
    assert_eq!(
        reason(VfoRun::start(route, None, true, rules, Some(ms(20)))),
        "STALE_INPUT: odom stale: robot stopped"
    );
    assert_eq!(
        reason(VfoRun::start(route, start, false, rules, Some(ms(20)))),
        "STALE_INPUT: scan stale: robot stopped"
    );
    let bad = (&[Point2::new(f64::NAN, 0.0)][..], &[None][..], &[7][..]);
    assert_eq!(
        reason(VfoRun::start(bad, start, true, rules, None)),
        "INVALID_GOAL: waypoint 7 is not finite"
    );
    // OMR-III: U_2 0.3 m/s (under v_max 0.5), |ω| its ω_max 1.5 (under the law's 4); two
    // odometry periods of 20 ms.
    let s = VfoRun::start(route, start, true, rules, Some(ms(20))).unwrap();
    assert_eq!(
        s.summary,
        "1 waypoints by VFO (0 obstacles known; U_2 0.30 m/s, |ω| ≤ 1.50 rad/s, T_p 0.010 s)"
    );
    assert_eq!((s.chassis_warning, s.run.max_delay()), (None, ms(40)));
    assert_eq!(s.run.view().waypoint, 7);
    // MOBIL-II: |ω| ≤ U_2 / R_min = 0.3 / 0.73 = 0.41 rad/s, and the warning; no period measured
    // yet: one control step of 50 ms.
    let mut slow = settings.clone();
    slow.optimise.time_step = 0.05;
    let s = VfoRun::start(route, start, true, (&slow, &mobil2, &map), None).unwrap();
    assert!(s.summary.contains("|ω| ≤ 0.41 rad/s, T_p 0.050 s"), "{}", s.summary);
    assert!(s
        .chassis_warning
        .unwrap()
        .starts_with("the VFO law is a unicycle's: on this car_like chassis"));
    assert_eq!(s.run.max_delay(), ms(50));
}

#[test]
fn a_pre_check_s_turn_draws_the_route_its_path_and_problems_and_tells_its_length() {
    let omr3 = ChassisParams::omr3();
    let rules = (FollowConfig::default(), &omr3);
    let step = FollowConfig::default().check_length;
    // A path of moves of one step along x, then a jump of 3 steps (a missed waypoint set down):
    // 2 steps driven.
    let mut report = blocked();
    report.path = [0.0, 1.0, 2.0, 5.0]
        .iter()
        .map(|&k| Pose2::new(k * step, 0.0, 0.0))
        .collect();
    let driven = format!("{:.2} m predicted", 2.0 * step);
    // Refused: the drawing holds the three waypoints, the path and the problem (request index 5).
    let turn = pre_check().turn_after_check(&report, rules, false).unwrap();
    assert!(turn
        .outcome
        .unwrap_err()
        .reason()
        .starts_with("ROUTE_INFEASIBLE: 1 problem(s)"));
    assert_eq!(turn.summary, format!("3 waypoints, pre-check 1 problem(s) ({driven})"));
    assert_eq!((turn.drawing.route.len(), turn.drawing.predicted.len()), (3, 4));
    assert_eq!(
        turn.drawing.problems.iter().map(|m| m.index).collect::<Vec<_>>(),
        vec![5]
    );
    assert_eq!(turn.driven_through, None);
    // Driven through: the same drawing, and the warning naming the problem.
    let turn = pre_check().turn_after_check(&report, rules, true).unwrap();
    assert!(turn.outcome.is_ok());
    let warning = turn.driven_through.unwrap();
    assert!(
        warning.starts_with("driven although execute_infeasible_routes: ROUTE_INFEASIBLE: 1 problem(s): waypoint 5"),
        "{warning}"
    );
    assert_eq!(turn.drawing.problems.len(), 1);
    // Clear: no problem drawn, no warning.
    report.problems.clear();
    let turn = pre_check().turn_after_check(&report, rules, false).unwrap();
    assert_eq!(turn.summary, format!("3 waypoints, pre-check clear ({driven})"));
    assert!(turn.outcome.is_ok() && turn.drawing.problems.is_empty() && turn.driven_through.is_none());
    // A task that is no pre-check takes no report.
    assert!(Task::Vfo(vfo()).turn_after_check(&report, rules, false).is_none());
}

#[test]
fn a_vfo_step_given_back_tells_its_events_its_capped_optimisation_a_settling_and_a_late_command() {
    let mut run = vfo();
    let map = ObstacleMap::new(ScanObstacleConfig::default()).unwrap();
    let law = run.lend(Instant::now(), &map).unwrap();
    let step = Step::Command {
        twist: BodyTwist::new(0.1, 0.0, 0.0),
        feedback: VfoStep {
            events: vec![
                VfoEvent::Optimised {
                    index: 0,
                    reason: Reoptimised::SegmentStart,
                    score: None,
                    warnings: vec![
                        OptimiseWarning::NoSafeSigma,
                        OptimiseWarning::VirtualRobotCap { limit: 9, pending: 2 },
                    ],
                },
                VfoEvent::Reached {
                    index: 0,
                    vortex: false,
                },
            ],
            settling: true,
            drawing: None,
        },
    };
    let (step, handback) = run.give_back(law, step, Instant::now() + Duration::from_millis(41));
    assert_eq!(handback, Handback::Late);
    let notices = run.notices(&step, handback);
    // The request's index 7 for waypoint 0; no safe Σ is in the event, not again as a warning;
    // the bound of 40 ms the run was made with.
    assert_eq!(
        notices,
        vec![
            Notice::Info(
                "segment to waypoint 7 optimised (SegmentStart): Ψ_z none, 0 virtual robots, 0 candidates".into()
            ),
            Notice::Recurring(
                "vfo-caps",
                "segment optimisation: VirtualRobotCap { limit: 9, pending: 2 }".into()
            ),
            Notice::Info("waypoint 7 reached".into()),
            Notice::Recurring(
                "vfo-settle",
                "robot held at zero inside an influence zone until it stands (at most 2 s), then the segment to \
                 waypoint 7 is optimised from there"
                    .into()
            ),
            Notice::Recurring(
                "vfo-late",
                "a tick took longer than 40 ms (an optimisation): its command is dropped, the robot stops meanwhile"
                    .into()
            ),
        ]
    );
    // A step that ends the route tells nothing here (the end is reported).
    assert!(run
        .notices(&Step::end(Outcome::succeeded("done"), vec![]), Handback::Fresh)
        .is_empty());
}

#[test]
fn the_status_carries_a_task_s_figures_and_with_no_task_the_idle_mode() {
    use mobil_motion::status::state;
    use mobil_planner::task::{status_view, Figures};
    use mobil_planner::vfo::SegmentReport;
    let figures = Figures {
        mode: Mode::Dock,
        waypoint: None,
        goal: Some(Pose2::new(1.0, 0.0, 0.0)),
        distance: 1.0,
        docking: Some([1.0, 0.5, -0.25, 0.7]),
        vfo: None,
    };
    let v = figures.view(state::ACTIVE, String::new());
    assert_eq!((v.state, v.mode, v.waypoint_index), (state::ACTIVE, "dock", None));
    assert_eq!((v.goal, v.distance_to_goal), (Some(Pose2::new(1.0, 0.0, 0.0)), 1.0));
    assert_eq!((v.docking, v.vfo), (Some([1.0, 0.5, -0.25, 0.7]), None));
    let vfo = Figures {
        mode: Mode::Vfo,
        waypoint: Some(2),
        docking: None,
        vfo: Some(SegmentReport {
            psi_z: 3.25,
            indices: [4.5, 0.75, 1.5, 0.5],
            virtual_robots: 9,
            candidates: 5,
        }),
        ..figures
    };
    let v = vfo.view(state::ACTIVE, String::new());
    assert_eq!((v.mode, v.waypoint_index, v.docking), ("vfo", Some(2), None));
    let f = v.vfo.unwrap();
    assert_eq!(
        (f.psi_z, f.indices[1], f.virtual_robots, f.candidates),
        (3.25, 0.75, 9, 5)
    );
    // No task: idle, whatever the state and reason; a task: its own figures at the pose.
    let idle = status_view(None, None, state::FAILED, "INVALID_GOAL: x".into());
    assert_eq!(
        (idle.mode, idle.state, idle.reason.as_str()),
        ("idle", state::FAILED, "INVALID_GOAL: x")
    );
    assert!(idle.distance_to_goal.is_nan() && idle.goal.is_none() && idle.vfo.is_none());
    let v = status_view(Some(&pre_check()), None, state::ACTIVE, String::new());
    assert_eq!((v.mode, v.waypoint_index), ("pre_check", Some(4)));
}

#[test]
fn a_dock_request_s_staging_and_dock_type_are_told_as_not_used() {
    use mobil_planner::task::dock_request_notice;
    assert_eq!(
        dock_request_notice(12.0, true, "charger"),
        Notice::Info(
            "dock_robot: max_staging_time (12) and navigate_to_staging_pose (true) ignored: the Lyapunov law \
             docks from wherever the robot is; dock_type `charger` ignored"
                .into()
        )
    );
    let Notice::Info(line) = dock_request_notice(1000.0, false, "") else {
        panic!()
    };
    assert!(
        line.ends_with("(false) ignored: the Lyapunov law docks from wherever the robot is"),
        "{line}"
    );
}
