//! Route pre-check by a virtual robot (SPEC §4): every problem with its waypoint index.

#[path = "../benches/common/demo_loop.rs"]
mod demo_loop;

use std::f64::consts::PI;

use approx::assert_relative_eq;
use mobil_chassis::{ChassisConfig, ChassisParams};
use mobil_geom::Pose2;
use mobil_planner::{
    arc_radius, check_route, check_route_until, ApproachConfig, PlannerError, ProblemKind, RouteCheckConfig,
    RouteReport, UnreachableCause,
};
use mobil_world::{Obstacle, World};
use nalgebra::Point2;
use proptest::prelude::*;

fn default_world() -> World {
    World::load(concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/worlds/default.yaml")).expect("default world")
}

/// From (0, 0) facing +x: to (1, 0), then half a circle of radius 0.5 about (1, 0.5) in 30°
/// steps — (1 + 0.5 sin φ, 0.5 − 0.5 cos φ), φ = 30°…180° — then back to (0, 1).
fn tight_turn_route() -> Vec<Point2<f64>> {
    let mut route = vec![Point2::new(1.0, 0.0)];
    for k in 1..=6 {
        let phi = (30.0 * k as f64).to_radians();
        route.push(Point2::new(1.0 + 0.5 * phi.sin(), 0.5 - 0.5 * phi.cos()));
    }
    route.push(Point2::new(0.0, 1.0));
    route
}

fn kinds(report: &RouteReport) -> Vec<(usize, &'static str)> {
    report.problems.iter().map(|p| (p.index, p.kind.as_str())).collect()
}

#[test]
fn arc_radius_by_hand() {
    // From (1, 0) facing +x through (1 + 0.5 sin 30°, 0.5 − 0.5 cos 30°) = (1.25, 0.066987):
    // body (0.25, 0.066987), r = (0.0625 + 0.0044873) / (2·0.066987) = 0.5, the circle itself.
    let p = Point2::new(1.25, 0.5 - 0.5 * (PI / 6.0).cos());
    assert_relative_eq!(arc_radius(&Pose2::new(1.0, 0.0, 0.0), &p, 0.0), 0.5, epsilon = 1e-12);
    // A point on the centre line needs no turn.
    assert_eq!(
        arc_radius(&Pose2::identity(), &Point2::new(-2.0, 0.0), 0.0),
        f64::INFINITY
    );
}

#[test]
fn half_metre_turn_rejected_for_mobil2_accepted_for_omr3() {
    let world = World::default();
    let route = tight_turn_route();
    let start = Pose2::identity();
    // Footprint radii of params/*.yaml (they do not matter in the empty world).
    let omni = check_route(
        &start,
        &route,
        &ChassisParams::omr3(),
        &world,
        &RouteCheckConfig::new(0.25),
    )
    .expect("valid");
    assert!(omni.is_ok(), "{:?}", omni.problems);
    assert!(omni.reached.iter().all(|r| *r));
    // The tricycle preset turns down to 0.50 / tan 60° = 0.289 m: the 0.5 m turn is fine too.
    let tricycle = check_route(
        &start,
        &route,
        &ChassisParams::tricycle(),
        &world,
        &RouteCheckConfig::new(0.40),
    )
    .expect("valid");
    assert!(tricycle.is_ok(), "{:?}", tricycle.problems);

    let car = check_route(
        &start,
        &route,
        &ChassisParams::mobil2(),
        &world,
        &RouteCheckConfig::new(0.53),
    )
    .expect("valid");
    assert!(!car.is_ok());
    for p in &car.problems {
        // Only the arc's waypoints (1…6) can be too tight; (1, 0) and (0, 1) are wide.
        assert!((1..=6).contains(&p.index), "{p:?}");
        match p.kind {
            ProblemKind::TurnRadius { required, minimum } => {
                assert_relative_eq!(minimum, 0.73, epsilon = 1e-12);
                assert!(required < minimum, "{p:?}");
            }
            other => panic!("only turn-radius problems expected, got {other:?} at {}", p.index),
        }
    }
    println!("MOBIL-II on the 0.5 m turn: {:?}", car.problems);
}

#[test]
fn collision_reported_on_the_leg_that_hits_the_pillar() {
    // Default world, OMR-III (radius 0.25). Leg 0 to (2, 0) is clear (the pillar at (1, 1.5),
    // r 0.3, is 1.2 m off the line); leg 1 from there to (0, 3) runs through the pillar.
    let world = default_world();
    let route = [Point2::new(2.0, 0.0), Point2::new(0.0, 3.0), Point2::new(-1.0, 3.0)];
    let report = check_route(
        &Pose2::identity(),
        &route,
        &ChassisParams::omr3(),
        &world,
        &RouteCheckConfig::new(0.25),
    )
    .expect("valid");
    assert_eq!(kinds(&report), [(1, "collision")]);
    let ProblemKind::Collision { at, clearance } = report.problems[0].kind else {
        unreachable!()
    };
    // The footprint first overlaps where the centre comes within 0.3 + 0.25 = 0.55 m of the
    // pillar's centre, at most one 0.02 m step inside.
    let d = (at - Point2::new(1.0, 1.5)).norm();
    assert!(d < 0.55 && d > 0.53, "{d}");
    assert_relative_eq!(clearance, d - 0.55, epsilon = 1e-12);
    assert!(report.reached.iter().all(|r| *r), "a ghost drives on through");
}

#[test]
fn blocked_waypoint_is_unreachable_with_its_index() {
    // Waypoint 1 is inside the box x ∈ [4.5, 5.5], y ∈ [−0.5, 1.0]: at (5.0, 0.25) the nearest
    // faces are 0.5 m away, so the clearance is −0.5 − 0.25 = −0.75 m.
    let world = default_world();
    let route = [Point2::new(3.5, 0.0), Point2::new(5.0, 0.25), Point2::new(3.5, 0.5)];
    let report = check_route(
        &Pose2::identity(),
        &route,
        &ChassisParams::omr3(),
        &world,
        &RouteCheckConfig::new(0.25),
    )
    .expect("valid");
    // Driving into the box collides on leg 1; the waypoint itself is unreachable; leaving the
    // box on leg 2 is not a new collision.
    assert_eq!(kinds(&report), [(1, "collision"), (1, "unreachable")]);
    match report.problems[1].kind {
        ProblemKind::Unreachable(UnreachableCause::Blocked { clearance }) => {
            assert_relative_eq!(clearance, -0.75, epsilon = 1e-12)
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(report.reached, [true, false, true]);
}

#[test]
fn waypoint_beyond_the_distance_bound_is_unreachable() {
    // In an empty world, waypoint 1 is 60 m from waypoint 0: beyond the 50 m leg bound.
    let route = [Point2::new(1.0, 0.0), Point2::new(61.0, 0.0), Point2::new(62.0, 0.0)];
    let report = check_route(
        &Pose2::identity(),
        &route,
        &ChassisParams::omr3(),
        &World::default(),
        &RouteCheckConfig::new(0.25),
    )
    .expect("valid");
    assert_eq!(kinds(&report), [(1, "unreachable")]);
    match report.problems[0].kind {
        ProblemKind::Unreachable(UnreachableCause::DistanceBound { travelled, remaining }) => {
            // The robot stops at the first step past 50 m: 50.00…50.02 m driven, about 10 m short
            // (it started up to 0.16 m short of waypoint 0).
            assert!((50.0..50.02 + 1e-9).contains(&travelled), "{travelled}");
            assert!((remaining - 10.0).abs() < 0.2, "{remaining}");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(report.reached, [true, false, true], "set down on 1, it reaches 2");
}

#[test]
fn every_problem_of_one_route_is_reported() {
    // MOBIL-II (footprint 0.53 m) in the default world, from (0, 0) facing +x:
    // 0: (0, −0.3) lies inside the right turning circle (centre (0, −0.73)); the arc through it
    //    has r = 0.3² / (2·0.3) = 0.15 m < 0.73 m. The robot circles clear of everything (the
    //    left circle would clip the pillar), then is set down on it facing south.
    // 1: (1, 3.2): after a U-turn, the leg runs by the pillar (1, 1.5): the chord from
    //    (0, −0.3) passes 1.7 / √13.25 = 0.467 m from its centre, 0.167 m from its surface,
    //    less than the 0.53 m footprint: a collision.
    // 2: (5, 0.25) lies in the box: the leg collides, the waypoint is blocked.
    // 3: (5, 60.25) is 60 m on: beyond the 50 m leg bound (on the way it crosses the north
    //    wall, one more collision on that leg).
    let world = default_world();
    let config = RouteCheckConfig::new(0.53);
    let route = [
        Point2::new(0.0, -0.3),
        Point2::new(1.0, 3.2),
        Point2::new(5.0, 0.25),
        Point2::new(5.0, 60.25),
    ];
    let report = check_route(&Pose2::identity(), &route, &ChassisParams::mobil2(), &world, &config).expect("valid");
    assert_eq!(
        kinds(&report),
        [
            (0, "turn_radius"),
            (1, "collision"),
            (2, "collision"),
            (2, "unreachable"),
            (3, "collision"),
            (3, "unreachable"),
        ],
        "{:#?}",
        report.problems
    );
    match report.problems[0].kind {
        ProblemKind::TurnRadius { required, .. } => assert_relative_eq!(required, 0.15, epsilon = 1e-12),
        other => panic!("{other:?}"),
    }
    match report.problems[3].kind {
        // The box's nearest face to (5, 0.25) is 0.5 m away: −0.5 − 0.53 = −1.03 m.
        ProblemKind::Unreachable(UnreachableCause::Blocked { clearance }) => {
            assert_relative_eq!(clearance, -1.03, epsilon = 1e-12)
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        report.problems[5].kind,
        ProblemKind::Unreachable(UnreachableCause::DistanceBound { .. })
    ));
    // Leg 1's collision is the pillar's: the centre within 0.3 + 0.53 m of (1, 1.5), one step in.
    let ProblemKind::Collision { at, .. } = report.problems[1].kind else {
        unreachable!()
    };
    let d = (at - Point2::new(1.0, 1.5)).norm();
    assert!(d < 0.83 && d > 0.81, "{at:?}");
    // The north wall's inner face is y = 5.5: the footprint touches it at y ≈ 5.5 − 0.53.
    let ProblemKind::Collision { at, .. } = report.problems[4].kind else {
        unreachable!()
    };
    assert!((at.y - 4.97).abs() < 0.03, "{at:?}");
    assert_eq!(report.reached, [false, true, false, false]);
}

#[test]
fn the_demo_loop_passes_on_both_chassis() {
    let route = demo_loop::demo_loop(20);
    // Waypoint 5 (index 4) lies 12.2832·5/20 = 3.0708 m along: 2 m of straight, then 1.0708 rad
    // round the corner (2, 1) from −π/2: (2 + cos(−0.5), 1 + sin(−0.5)) = (2.877583, 0.520574).
    assert_relative_eq!(route[4].x, 2.877_583, epsilon = 1e-6);
    assert_relative_eq!(route[4].y, 0.520_574, epsilon = 1e-6);
    assert_relative_eq!((route[19] - Point2::new(0.0, 0.0)).norm(), 0.0, epsilon = 1e-12);
    let world = default_world();
    let omni = check_route(
        &Pose2::identity(),
        &route,
        &ChassisParams::omr3(),
        &world,
        &RouteCheckConfig::new(0.25),
    )
    .expect("valid");
    assert!(omni.is_ok(), "{:?}", omni.problems);
    assert_eq!(omni.reached, [true; 20]);
    // 12 waypoints, 12.2832 / 12 = 1.024 m apart, pass for MOBIL-II too (the paper's remedy:
    // waypoints far enough apart).
    let car = check_route(
        &Pose2::identity(),
        &demo_loop::demo_loop(12),
        &ChassisParams::mobil2(),
        &world,
        &RouteCheckConfig::new(0.53),
    )
    .expect("valid");
    assert!(car.is_ok(), "{:?}", car.problems);
    assert_eq!(car.reached, [true; 12]);
    // At 20 (0.614 m apart) MOBIL-II still reaches every one within Z_crit, but some corner
    // waypoints need a tighter arc from where the previous one was taken (0.16 m short of it,
    // heading along the chord): reported as turn radius, nothing else.
    let car = check_route(
        &Pose2::identity(),
        &route,
        &ChassisParams::mobil2(),
        &world,
        &RouteCheckConfig::new(0.53),
    )
    .expect("valid");
    assert_eq!(car.reached, [true; 20]);
    assert!(!car.is_ok());
    assert!(
        car.problems.iter().all(|p| p.kind.as_str() == "turn_radius"),
        "{:?}",
        car.problems
    );
}

#[test]
fn a_tight_turn_is_reported_even_when_the_waypoint_is_reached() {
    // From (0, 0) facing +x, MOBIL-II (R_min 0.73): the waypoint (0.6 sin 60°, 0.6(1 − cos 60°))
    // = (0.519615, 0.3) lies on the arc of radius (0.27 + 0.09) / (2·0.3) = 0.60 m. The full-lock
    // circle (centre (0, 0.73)) passes 0.73 − √(0.27 + 0.1849) = 0.73 − 0.674463 = 0.0555 m from it,
    // well within Z_crit = 0.16: the virtual robot reaches it, and the turn is still too tight.
    let w = Point2::new(0.6 * (PI / 3.0).sin(), 0.3);
    let report = check_route(
        &Pose2::identity(),
        &[w],
        &ChassisParams::mobil2(),
        &World::default(),
        &RouteCheckConfig::new(0.53),
    )
    .expect("valid");
    assert_eq!(report.reached, [true]);
    assert_eq!(kinds(&report), [(0, "turn_radius")]);
    match report.problems[0].kind {
        ProblemKind::TurnRadius { required, minimum } => {
            assert_relative_eq!(required, 0.60, epsilon = 1e-12);
            assert_relative_eq!(minimum, 0.73, epsilon = 1e-12);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn arc_radius_with_a_reference_offset_by_hand() {
    // Origin (−0.3, 0) facing +x, d = 0.3: the reference point passes through (−0.3, 0.73) when
    // the origin circles (−0.3, R) with |(0, 0.73 − R)|² = R² + 0.09 → R = (0.5329 − 0.09) / 1.46
    // = 0.303356. Check: the reference point's radius √(0.303356² + 0.09) = 0.426644 = 0.73 − R.
    let r = arc_radius(&Pose2::new(-0.3, 0.0, 0.0), &Point2::new(-0.3, 0.73), 0.3);
    assert_relative_eq!(r, 0.4429 / 1.46, epsilon = 1e-12);
    assert_relative_eq!((r * r + 0.09).sqrt(), 0.73 - r, epsilon = 1e-12);
}

#[test]
fn only_the_front_of_the_robot_hits_a_pillar() {
    // MOBIL-II with its reference point 0.30 m ahead of the rear axle (params/mobil2.yaml), the
    // start (0, 0) facing +x being the reference point's pose: the origin is at (−0.3, 0). The
    // waypoint (−0.3, 0.73) is the centre of the origin's full-lock circle, so the goal stays
    // near 90° (outside δ_eff: full lock, the progress stop never arms) and the robot circles
    // until the leg bound, 2·0.789240 + 2π·0.73 = 6.165 m, more than one 4.587 m circle.
    // Each step turns Δϑ = 0.02·tan δ_eff / 0.6 = 0.02 / 0.73 = 0.0273973 rad, then moves 0.02 m
    // straight: the origin's vertices lie on a circle of radius ρ = 0.02 / (2 sin(Δϑ/2)) =
    // 0.730023 about c = (−0.3 − ρ sin(Δϑ/2), ρ cos(Δϑ/2)) = (−0.310000, 0.729954); the reference
    // point, 0.3 m along the chord just driven (Δϑ/2 outward of the tangent), at radius
    // √(ρ² + 0.09 + 2·0.3·ρ·sin(Δϑ/2)) = √0.628934 = 0.793054.
    // A pillar of radius 0.1 at (−1.35, 0.73), 1.040000 m from c: a 0.2 m disc at the origin
    // keeps 1.04 − 0.730 − 0.1 − 0.2 = +0.010 m clear; at the reference point it comes
    // 1.04 − 0.793 − 0.3 = −0.053 m into the pillar: a collision.
    let params = ChassisParams::new(ChassisConfig {
        reference_offset: 0.30,
        ..ChassisConfig::mobil2()
    })
    .expect("valid chassis");
    let pillar = Point2::new(-1.35, 0.73);
    let world = World {
        obstacles: vec![Obstacle::Circle {
            center: [pillar.x, pillar.y],
            radius: 0.1,
        }],
    };
    let route = [Point2::new(-0.3, 0.73)];
    let config = RouteCheckConfig::new(0.2);
    let report = check_route(&Pose2::identity(), &route, &params, &world, &config).expect("valid");
    // The turn: the reference point through (−0.3, 0.73) needs R = 0.303356 m < 0.73 m.
    assert_eq!(
        kinds(&report),
        [(0, "collision"), (0, "turn_radius")],
        "{:?}",
        report.problems
    );
    let ProblemKind::Collision { at, clearance } = report.problems[0].kind else {
        unreachable!()
    };
    // Where the disc first touches: 0.1 + 0.2 = 0.3 m from the pillar's centre, at most one
    // 0.02 m step inside; on the reference point's circle.
    let d = (at - pillar).norm();
    assert!(d < 0.3 && d > 0.28, "{d}");
    assert_relative_eq!(clearance, d - 0.3, epsilon = 1e-12);
    assert!(
        ((at - Point2::new(-0.310_000, 0.729_954)).norm() - 0.793_054).abs() < 1e-4,
        "{at:?}"
    );
    // The path is the reference point's: it starts at the given start.
    assert_eq!(report.path[0], Pose2::identity());
    // Read as a rear-axle start (d = 0), the same route passes the pillar.
    let rear = check_route(&Pose2::identity(), &route, &ChassisParams::mobil2(), &world, &config).expect("valid");
    assert!(
        rear.problems.iter().all(|p| p.kind.as_str() != "collision"),
        "{:?}",
        rear.problems
    );
}

#[test]
fn a_waypoint_passed_by_is_unreachable_with_the_closest_approach() {
    // The paper's start S = [−1, 1, 3π/4], waypoint (0, 0): it lies straight behind the car
    // (body (−√2, 0)), so no turn radius applies (infinite). With Z_crit 0.001 the car turns
    // round, passes G a few centimetres off (004 §4.3.1: about 0.16 m at most) and the armed
    // progress stop ends the leg: passed by, the closest approach between 0.001 and 0.16 m.
    let config = RouteCheckConfig {
        approach: ApproachConfig {
            critical_distance: 1e-3,
            ..ApproachConfig::default()
        },
        ..RouteCheckConfig::new(0.53)
    };
    let start = Pose2::new(-1.0, 1.0, 0.75 * PI);
    // Straight behind up to rounding (y_b ≈ 1e-16): an arc far wider than any chassis' minimum.
    assert!(arc_radius(&start, &Point2::new(0.0, 0.0), 0.0) > 1e12);
    let report = check_route(
        &start,
        &[Point2::new(0.0, 0.0)],
        &ChassisParams::mobil2(),
        &World::default(),
        &config,
    )
    .expect("valid");
    assert_eq!(kinds(&report), [(0, "unreachable")]);
    match report.problems[0].kind {
        ProblemKind::Unreachable(UnreachableCause::PassedBy { closest }) => {
            assert!(closest > 1e-3 && closest < 0.16, "{closest}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn bad_routes_are_refused() {
    let world = World::default();
    let c = RouteCheckConfig::new(0.25);
    let p = ChassisParams::omr3();
    assert_eq!(
        check_route(&Pose2::identity(), &[], &p, &world, &c),
        Err(PlannerError::EmptyRoute)
    );
    let err = check_route(&Pose2::identity(), &[Point2::new(f64::NAN, 0.0)], &p, &world, &c).unwrap_err();
    assert!(
        matches!(err, PlannerError::NonFinite { ref what, .. } if what == "waypoint 0"),
        "{err}"
    );
    let bad = RouteCheckConfig {
        robot_radius: -1.0,
        ..c
    };
    assert!(check_route(&Pose2::identity(), &[Point2::new(1.0, 0.0)], &p, &world, &bad).is_err());
}

#[test]
fn a_stopped_check_ends_at_once_with_stopped() {
    // A long route: 20 legs of 10 m back and forth; each leg ends within Z_crit = 0.16 m of its
    // waypoint and starts within it of the last, so it drives at least (10 − 2·0.16) / 0.02 =
    // 484 virtual steps of 0.02 m.
    let route: Vec<Point2<f64>> = (0..20)
        .map(|i| Point2::new(if i % 2 == 0 { 10.0 } else { 0.0 }, 0.0))
        .collect();
    let (p, world, c) = (ChassisParams::omr3(), World::default(), RouteCheckConfig::new(0.25));
    // Never stopped: the same report as check_route, after one question per leg plus one per
    // step (20 legs × ≥ 484 steps).
    let mut asked = 0usize;
    let full = check_route_until(&Pose2::identity(), &route, &p, &world, &c, || {
        asked += 1;
        false
    });
    assert_eq!(full, check_route(&Pose2::identity(), &route, &p, &world, &c));
    assert!(asked > 20 * 484, "{asked}");
    // Stopped at the 100th question (in the first leg): the answer is Stopped and stop is not
    // asked again, so no further step was driven.
    let mut asked = 0usize;
    let stopped = check_route_until(&Pose2::identity(), &route, &p, &world, &c, || {
        asked += 1;
        asked >= 100
    });
    assert_eq!((stopped, asked), (Err(PlannerError::Stopped), 100));
    // Stopped before the first leg.
    let mut asked = 0usize;
    let stopped = check_route_until(&Pose2::identity(), &route, &p, &world, &c, || {
        asked += 1;
        true
    });
    assert_eq!((stopped, asked), (Err(PlannerError::Stopped), 1));
}

#[test]
fn the_driven_length_leaves_out_the_set_downs() {
    // Two steps of 0.02 m, a 1 m jump (a set-down), one more step: 0.06 m driven.
    let report = RouteReport {
        problems: Vec::new(),
        path: [0.0, 0.02, 0.04, 1.04, 1.06]
            .iter()
            .map(|&x| Pose2::new(x, 0.0, 0.0))
            .collect(),
        reached: vec![true],
    };
    assert_relative_eq!(report.driven_length(0.02), 0.06, epsilon = 1e-12);
    // With a 1 m step the jump is a move: 1.06 m.
    assert_relative_eq!(report.driven_length(1.0), 1.06, epsilon = 1e-12);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    #[test]
    fn arbitrary_routes_never_give_nan(
        x in proptest::num::f64::ANY, y in proptest::num::f64::ANY, yaw in proptest::num::f64::ANY,
        w in proptest::collection::vec((proptest::num::f64::ANY, proptest::num::f64::ANY), 1..4),
        radius in proptest::num::f64::ANY, car in proptest::bool::ANY,
    ) {
        let route: Vec<_> = w.iter().map(|&(a, b)| Point2::new(a, b)).collect();
        let params = if car { ChassisParams::mobil2() } else { ChassisParams::omr3() };
        if let Ok(r) = check_route(&Pose2 { x, y, yaw }, &route, &params, &default_world(), &RouteCheckConfig::new(radius)) {
            prop_assert!(r.path.iter().all(|p| p.x.is_finite() && p.y.is_finite() && p.yaw.is_finite()));
            prop_assert_eq!(r.reached.len(), route.len());
            for p in &r.problems {
                let finite = match p.kind {
                    ProblemKind::Collision { at, clearance } => at.x.is_finite() && at.y.is_finite() && clearance.is_finite(),
                    ProblemKind::TurnRadius { required, minimum } => !required.is_nan() && minimum.is_finite(),
                    ProblemKind::Unreachable(UnreachableCause::Blocked { clearance }) => clearance.is_finite(),
                    ProblemKind::Unreachable(UnreachableCause::PassedBy { closest }) => closest.is_finite(),
                    ProblemKind::Unreachable(UnreachableCause::DistanceBound { travelled, remaining }) => {
                        travelled.is_finite() && remaining.is_finite()
                    }
                };
                prop_assert!(finite, "{:?}", p);
            }
        }
    }
}
