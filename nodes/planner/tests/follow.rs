//! The online waypoint follower against the offline goal approach, hand-worked commands, the
//! stops and bad input.

use approx::assert_relative_eq;
use mobil_chassis::{BodyTwist, ChassisConfig, ChassisParams};
use mobil_geom::Pose2;
use mobil_planner::sim::advance;
use mobil_planner::{
    approach, check_route, ApproachConfig, ApproachEnd, FollowConfig, FollowEnd, FollowEvent, Motion, PlannerError,
    RouteCheckConfig, Steering, UnreachableCause, WaypointFollower,
};
use mobil_world::World;
use nalgebra::Point2;

fn mobil2_motion() -> Motion {
    Motion::from_chassis(&ChassisParams::mobil2())
}

/// No slow-down, so that every step has the approach's length.
fn plain() -> FollowConfig {
    FollowConfig {
        slow_down_distance: 0.0,
        ..FollowConfig::default()
    }
}

/// Drives the follower with the approach's own step: ϑ += ω·dt, then x, y advance by v·dt
/// along the new heading (the origin; offset 0). Returns the poses (the start first), the
/// events and how it ended.
fn drive_stepwise(
    follower: &mut WaypointFollower,
    start: Pose2,
    dt: f64,
    max_ticks: usize,
) -> (Vec<Pose2>, Vec<FollowEvent>, Option<FollowEnd>) {
    let mut pose = start;
    let mut path = vec![pose];
    let mut events = Vec::new();
    for k in 0..max_ticks {
        let out = follower.update(&pose, dt, k as f64 * dt).expect("valid tick");
        events.extend(out.events.iter().copied());
        if out.end.is_some() {
            return (path, events, out.end);
        }
        let t = out.twist;
        let yaw = pose.yaw + t.wz * dt;
        let (s, c) = pose.yaw.sin_cos();
        // Body → world for the omni case (wz = 0 there); the car has vy = 0 at offset 0.
        let (wx, wy) = if t.wz == 0.0 {
            (c * t.vx - s * t.vy, s * t.vx + c * t.vy)
        } else {
            (t.vx * yaw.cos(), t.vx * yaw.sin())
        };
        pose = Pose2::new(pose.x + wx * dt, pose.y + wy * dt, yaw);
        path.push(pose);
    }
    (path, events, None)
}

#[test]
fn online_follower_drives_the_offline_approach_step_for_step() {
    // 0.4 m/s at 20 Hz is the pre-check's 0.02 m step: the same law, the same stops.
    let start = Pose2::new(0.0, 0.0, 0.3);
    for (start, goal, critical, end) in [
        (start, Point2::new(2.0, 1.5), 0.16, ApproachEnd::Reached),
        (start, Point2::new(-1.0, 0.4), 0.16, ApproachEnd::Reached),
        // tests/approach.rs: passed a few centimetres off, outside Z_crit = 0.01 (the progress
        // stop, armed from the start).
        (Pose2::identity(), Point2::new(1.0, 0.5), 0.01, ApproachEnd::NoProgress),
    ] {
        let approach_config = ApproachConfig {
            critical_distance: critical,
            ..ApproachConfig::default()
        };
        let config = FollowConfig {
            speed: 0.4,
            critical_distance: critical,
            ..plain()
        };
        let offline = approach(&start, &goal, &mobil2_motion(), &approach_config).expect("valid");
        assert_eq!(offline.end, end, "{goal:?}");
        let mut follower = WaypointFollower::with_motion(config, mobil2_motion(), 0.0, vec![goal]).expect("valid");
        let (path, events, ended) = drive_stepwise(&mut follower, start, 0.05, 5000);
        assert_eq!(ended, Some(FollowEnd::Done));
        // The follower sees the pose after the last step at the next tick: the same poses.
        assert_eq!(path.len(), offline.path.len(), "{goal:?}");
        for (a, b) in path.iter().zip(&offline.path) {
            assert_relative_eq!(a.x, b.x, epsilon = 1e-9);
            assert_relative_eq!(a.y, b.y, epsilon = 1e-9);
            assert_relative_eq!(a.yaw, b.yaw, epsilon = 1e-9);
        }
        match end {
            ApproachEnd::Reached => assert_eq!(events, vec![FollowEvent::Reached { index: 0 }]),
            _ => match events.as_slice() {
                [FollowEvent::Missed {
                    index: 0,
                    cause: UnreachableCause::PassedBy { closest },
                }] => assert_relative_eq!(*closest, offline.closest, epsilon = 1e-9),
                other => panic!("expected one missed waypoint, got {other:?}"),
            },
        }
    }
}

#[test]
fn the_omni_translates_straight_at_the_waypoint_heading_held() {
    // From (0, 0) facing 1 rad toward (3, 4): world velocity 0.3·(0.6, 0.8) = (0.18, 0.24);
    // in the body frame (rotated by −1 rad): vx = 0.18 cos 1 + 0.24 sin 1 = 0.097254 + 0.201953
    // = 0.299207, vy = −0.18 sin 1 + 0.24 cos 1 = −0.151465 + 0.129672 = −0.021792.
    let mut f = WaypointFollower::new(plain(), &ChassisParams::omr3(), vec![Point2::new(3.0, 4.0)]).expect("valid");
    let out = f.update(&Pose2::new(0.0, 0.0, 1.0), 0.02, 0.0).expect("valid");
    assert_relative_eq!(out.twist.vx, 0.299_207, epsilon = 1e-6);
    assert_relative_eq!(out.twist.vy, -0.021_792, epsilon = 1e-6);
    assert_eq!(out.twist.wz, 0.0);
    assert_relative_eq!(out.distance, 5.0);
    assert_eq!((out.index, out.end), (0, None));
}

#[test]
fn the_car_steers_its_origin_and_the_twist_is_given_at_the_reference_point() {
    // MOBIL-II, reference point 0.30 m ahead at (0, 0) facing +x: origin (−0.3, 0). Waypoint
    // (0, 2) lies at bearing atan2(2, 0.3) = 1.4219 rad > δ_eff: δ = δ_eff, ω = v·tan δ_eff / L
    // = 0.3 / 0.73 = 0.410959 rad/s; at the reference point vy = ω·0.3 = 0.123288.
    let mobil2 = ChassisParams::new(ChassisConfig {
        reference_offset: 0.30,
        ..ChassisConfig::mobil2()
    })
    .expect("valid");
    let mut f = WaypointFollower::new(plain(), &mobil2, vec![Point2::new(0.0, 2.0)]).expect("valid");
    let out = f.update(&Pose2::identity(), 0.05, 0.0).expect("valid");
    assert_relative_eq!(out.twist.vx, 0.3, epsilon = 1e-12);
    assert_relative_eq!(out.twist.wz, 0.3 / 0.73, epsilon = 1e-9);
    assert_relative_eq!(out.twist.vy, 0.3 * 0.3 / 0.73, epsilon = 1e-9);
    assert_relative_eq!(out.steering, (0.60f64 / 0.73).atan(), epsilon = 1e-12);
}

#[test]
fn the_last_waypoint_is_approached_slowly() {
    // speed 0.3, slow-down over 0.6 m, min 0.05: at Z = 0.3 → 0.15; at Z = 0.2 → 0.1; a
    // waypoint before the last one keeps 0.3 at Z = 0.3.
    let config = FollowConfig::default();
    let omr3 = ChassisParams::omr3();
    let speed = |route: Vec<Point2<f64>>, x: f64| {
        let mut f = WaypointFollower::new(config, &omr3, route).expect("valid");
        let t = f.update(&Pose2::new(x, 0.0, 0.0), 0.02, 0.0).expect("valid").twist;
        t.vx.hypot(t.vy)
    };
    assert_relative_eq!(speed(vec![Point2::new(1.0, 0.0)], 0.7), 0.15, epsilon = 1e-12);
    assert_relative_eq!(speed(vec![Point2::new(1.0, 0.0)], 0.8), 0.1, epsilon = 1e-12);
    assert_relative_eq!(
        speed(vec![Point2::new(1.0, 0.0), Point2::new(3.0, 0.0)], 0.7),
        0.3,
        epsilon = 1e-12
    );
    let slow = FollowConfig {
        min_speed: 0.12,
        ..config
    };
    let mut f = WaypointFollower::new(slow, &omr3, vec![Point2::new(1.0, 0.0)]).expect("valid");
    let t = f.update(&Pose2::new(0.8, 0.0, 0.0), 0.02, 0.0).expect("valid").twist;
    assert_relative_eq!(t.vx, 0.12, epsilon = 1e-12);
}

/// Drives the follower with exact arcs (the twist held over each tick, as a chassis does).
fn drive_arcs(
    follower: &mut WaypointFollower,
    start: Pose2,
    dt: f64,
    max_ticks: usize,
) -> (Vec<FollowEvent>, Option<FollowEnd>, Pose2) {
    let mut pose = start;
    let mut events = Vec::new();
    for k in 0..max_ticks {
        let out = follower.update(&pose, dt, k as f64 * dt).expect("valid tick");
        events.extend(out.events.iter().copied());
        if out.end.is_some() {
            assert_eq!(out.twist, BodyTwist::ZERO);
            return (events, out.end, pose);
        }
        pose = advance(&pose, &out.twist, dt);
    }
    (events, None, pose)
}

#[test]
fn mobil2_drives_the_route_the_pre_check_accepts() {
    // The demo loop's corners, from the reference point at (0, 0) facing east; the pre-check
    // (virtual robot, 0.02 m steps) reaches every one; so does the follower at 20 Hz with
    // exact arcs and the reference point 0.30 m ahead.
    let mobil2 = ChassisParams::new(ChassisConfig {
        reference_offset: 0.30,
        ..ChassisConfig::mobil2()
    })
    .expect("valid");
    let route = vec![
        Point2::new(2.0, 0.0),
        Point2::new(3.0, 1.0),
        Point2::new(3.0, 2.0),
        Point2::new(2.0, 3.0),
    ];
    let report = check_route(
        &Pose2::identity(),
        &route,
        &mobil2,
        &World::default(),
        &RouteCheckConfig::new(0.53),
    )
    .expect("valid");
    assert!(report.is_ok(), "{:?}", report.problems);
    let mut f = WaypointFollower::new(FollowConfig::default(), &mobil2, route.clone()).expect("valid");
    let (events, end, pose) = drive_arcs(&mut f, Pose2::identity(), 0.05, 4000);
    assert_eq!(end, Some(FollowEnd::Done));
    assert_eq!(
        events,
        (0..4).map(|index| FollowEvent::Reached { index }).collect::<Vec<_>>()
    );
    assert!((pose.position() - route[3]).norm() < 0.16 + 0.3 * 0.05);
    assert!(f.missed().is_empty());
}

#[test]
fn a_waypoint_passed_by_or_out_of_reach_is_missed_and_the_next_one_taken() {
    // Exact arcs at 20 Hz. (1, 0.5) with Z_crit 0.01 is passed by (as in the offline test);
    // (0, 0.3) lies inside MOBIL-II's turning circle: never within reach, so the car circles
    // until the leg's bound (max_leg_length 1 m here) gives it up, 1 m round the circle at
    // (0.717, 0.580) heading 1.37 rad; (0.6, 1.3), 0.73 m on at a bearing of 21°, is then
    // reached.
    let mobil2 = ChassisParams::mobil2();
    let config = FollowConfig {
        critical_distance: 0.01,
        ..FollowConfig::default()
    };
    let mut f = WaypointFollower::new(config, &mobil2, vec![Point2::new(1.0, 0.5)]).expect("valid");
    let (events, end, _) = drive_arcs(&mut f, Pose2::identity(), 0.05, 4000);
    assert_eq!(end, Some(FollowEnd::Done));
    assert!(matches!(
        events.as_slice(),
        [FollowEvent::Missed {
            index: 0,
            cause: UnreachableCause::PassedBy { .. }
        }]
    ));
    let config = FollowConfig {
        max_leg_length: 1.0,
        ..FollowConfig::default()
    };
    let route = vec![Point2::new(0.0, 0.3), Point2::new(0.6, 1.3)];
    let mut f = WaypointFollower::new(config, &mobil2, route).expect("valid");
    let (events, end, _) = drive_arcs(&mut f, Pose2::identity(), 0.05, 4000);
    assert_eq!(end, Some(FollowEnd::Done));
    match events.as_slice() {
        [FollowEvent::Missed {
            index: 0,
            cause: UnreachableCause::DistanceBound { travelled, .. },
        }, FollowEvent::Reached { index: 1 }] => {
            // Given up at the first tick past 1 m of path: 0.3 m/s · 0.05 s = 0.015 m per tick.
            assert!(*travelled >= 1.0 && *travelled < 1.0 + 0.015 + 1e-9, "{travelled}");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(f.missed().len(), 1);
}

#[test]
fn a_robot_that_does_not_move_stalls_the_route() {
    let config = FollowConfig {
        stall_time_s: 2.0,
        ..FollowConfig::default()
    };
    let mut f = WaypointFollower::new(config, &ChassisParams::omr3(), vec![Point2::new(2.0, 0.0)]).expect("valid");
    let still = Pose2::identity();
    // 2.0 s without 0.02 m of path is not yet a stall (the limit is "more than"); 2.05 s is.
    for k in 0..=40 {
        let out = f.update(&still, 0.05, k as f64 * 0.05).expect("valid");
        assert_eq!(out.end, None, "tick {k}");
    }
    let out = f.update(&still, 0.05, 2.05).expect("valid");
    assert_eq!(out.end, Some(FollowEnd::Stalled));
    assert_eq!(out.twist, BodyTwist::ZERO);
}

#[test]
fn several_waypoints_within_z_crit_are_taken_in_one_tick() {
    let route = vec![Point2::new(0.05, 0.0), Point2::new(0.1, 0.0), Point2::new(1.0, 0.0)];
    let mut f = WaypointFollower::new(plain(), &ChassisParams::omr3(), route).expect("valid");
    let out = f.update(&Pose2::identity(), 0.05, 0.0).expect("valid");
    assert_eq!(
        out.events,
        vec![FollowEvent::Reached { index: 0 }, FollowEvent::Reached { index: 1 }]
    );
    assert_eq!(out.index, 2);
    assert_relative_eq!(out.distance, 1.0);
}

#[test]
fn bad_input_is_refused() {
    let omr3 = ChassisParams::omr3();
    assert_eq!(
        WaypointFollower::new(plain(), &omr3, vec![]).unwrap_err(),
        PlannerError::EmptyRoute
    );
    assert!(matches!(
        WaypointFollower::new(plain(), &omr3, vec![Point2::new(f64::NAN, 0.0)]),
        Err(PlannerError::NonFinite { .. })
    ));
    let bad_speed = FollowConfig { speed: 0.0, ..plain() };
    assert!(WaypointFollower::new(bad_speed, &omr3, vec![Point2::new(1.0, 0.0)]).is_err());
    let mut f = WaypointFollower::new(plain(), &omr3, vec![Point2::new(1.0, 0.0)]).expect("valid");
    assert!(f.update(&Pose2::new(f64::NAN, 0.0, 0.0), 0.05, 0.0).is_err());
    assert!(f.update(&Pose2::identity(), 0.0, 0.0).is_err());
    assert!(f.update(&Pose2::identity(), f64::INFINITY, 0.0).is_err());
    assert!(f.update(&Pose2::identity(), 0.05, f64::NAN).is_err());
    // Steering must be a real chassis' (the constructor of Motion::Steered checks it).
    assert!(Steering::new(0.6, 2.0).is_err());
}

#[test]
fn a_long_tick_turns_at_the_steering_rate() {
    // MOBIL-II at the origin facing +x, the waypoint 5 m to the left: the bearing (about 90°)
    // is beyond δ_eff, so δ = δ_eff and the origin turns at speed / R_min = speed·tan δ_eff / L
    // whatever the tick's length. At dt = 30 s the step's heading change (0.3·30 / 0.73 ≈
    // 12 rad) is far beyond π; the turn rate must not depend on it.
    let p = ChassisParams::mobil2();
    let by_hand = 0.3 * p.effective_steering_limit().tan() / p.wheelbase();
    for dt in [0.02, 1.0, 30.0] {
        let mut follower = WaypointFollower::new(plain(), &p, vec![Point2::new(0.0, 5.0)]).expect("valid");
        let out = follower.update(&Pose2::identity(), dt, 0.0).expect("valid tick");
        assert_relative_eq!(out.twist.vx, 0.3, epsilon = 1e-12);
        assert_relative_eq!(out.twist.wz, by_hand, epsilon = 1e-12);
    }
}
