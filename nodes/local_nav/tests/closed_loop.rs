//! Closed loop in pure Rust: the navigator's command integrated by an omni (or unicycle) model
//! over a synthetic world of circles and segments, scanned by a tiny raycaster.

use crate::harness;

use harness::{config_for, drive, drive_config, drive_with, rect, scenario, Ending, Plant, Shape, World, SIM};
use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_local_nav::{Mode, NavConfig, NoPathReason, Side, TrackMethod};
use nalgebra::Point2;

#[test]
fn open_space_goes_straight_to_the_goal() {
    let world = World(vec![]);
    let run = drive(
        &world,
        ChassisParams::omr3(),
        Pose2::identity(),
        Point2::new(4.0, 1.0),
        400,
    );
    assert_eq!(run.modes, vec![Mode::Rotate, Mode::Reached]);
    // Straight line from (0, 0) to (4, 1): |y − x/4| stays tiny, final within 0.10 m.
    let p = run.final_pose;
    assert!((p.y - p.x / 4.0).abs() < 1e-6, "{p:?}");
    assert!(((p.x - 4.0).powi(2) + (p.y - 1.0).powi(2)).sqrt() <= 0.10);
}

#[test]
fn convex_obstacle_locks_then_reaches_the_goal() {
    // A disc of radius 0.5 at (3, 0) on the line from (0, 0) to G (6, 0).
    let world = World(vec![Shape::Circle(Point2::new(3.0, 0.0), 0.5)]);
    let run = drive(
        &world,
        ChassisParams::omr3(),
        Pose2::identity(),
        Point2::new(6.0, 0.0),
        1200,
    );
    assert_eq!(run.final_mode, Mode::Reached, "{:?}", run.modes);
    // Symmetric world: the tie goes left.
    assert!(run.modes.contains(&Mode::Lock(Side::Left)), "{:?}", run.modes);
    assert!(
        !run.modes.iter().any(|m| matches!(m, Mode::Track(_))),
        "{:?}",
        run.modes
    );
    // Never closer to the disc than the robot radius (0.25 m).
    assert!(run.min_clearance > 0.25, "clearance {}", run.min_clearance);
}

fn u_trap() -> World {
    // A U open toward the robot: bottom x = 3 from y = −1.5 to 1.5, arms back to x = 1.5.
    let p = Point2::new;
    World(vec![
        Shape::Segment(p(3.0, -1.5), p(3.0, 1.5)),
        Shape::Segment(p(1.5, 1.5), p(3.0, 1.5)),
        Shape::Segment(p(1.5, -1.5), p(3.0, -1.5)),
    ])
}

#[test]
fn u_trap_needs_track_mode_and_escapes() {
    // Needs: 004 §4.3.3 says rotate and lock alone manage only small convex obstacles. With
    // T-mode off, in the U-trap the lock slides into the corner of the bottom and an arm, its
    // progress window fails (eq. 3.58) and, with no T-mode to go to, it locks again where it
    // stands: a stall Nav2's progress checker (0.5 m in 10 s) would abort.
    let off = scenario_run("u_trap", ChassisParams::omr3(), TrackMethod::Off, 60.0);
    assert_eq!(Ending::of(&off), Ending::Stalls, "{:?}", off.modes);
    assert!(
        !off.modes.iter().any(|m| matches!(m, Mode::Track(_))),
        "{:?}",
        off.modes
    );
    assert!(off.first_abort.is_some_and(|t| t < 30.0), "{:?}", off.first_abort);
    // Escapes: the same run with T-mode (the default tangent follower) reaches G.
    let tangent = scenario_run("u_trap", ChassisParams::omr3(), TrackMethod::Tangent, 60.0);
    assert_eq!(Ending::of(&tangent), Ending::Reached, "{:?}", tangent.modes);
    assert_eq!(tangent.first_abort, None);
    // And on the ideal plant, with H and L where they belong.
    let world = u_trap();
    let run = drive(
        &world,
        ChassisParams::omr3(),
        Pose2::identity(),
        Point2::new(6.0, 0.0),
        4000,
    );
    assert_eq!(run.final_mode, Mode::Reached, "{:?}", run.modes);
    assert!(run.modes.iter().any(|m| matches!(m, Mode::Track(_))), "{:?}", run.modes);
    let h = run.hit.expect("a hit point");
    // H inside the U (x between the mouth and the bottom), the leave point beyond it, on HG.
    assert!(h.x > 1.5 && h.x < 3.0, "H {h}");
    let l = run.leave.expect("a leave point");
    assert!(
        (Point2::new(6.0, 0.0) - l).norm() < (Point2::new(6.0, 0.0) - h).norm(),
        "L {l} H {h}"
    );
    assert!(run.min_clearance > 0.25, "clearance {}", run.min_clearance);
}

/// Runs scenario `name` for `chassis` with T-mode by `method`, at sim_node's rates, for at
/// most `seconds` of simulated time.
fn scenario_run(name: &str, chassis: ChassisParams, method: TrackMethod, seconds: f64) -> harness::Run {
    let s = scenario(name, chassis.model().is_nonholonomic());
    let config = NavConfig {
        track_method: method,
        ..config_for(&chassis)
    };
    let steps = (seconds / SIM.dt) as usize;
    drive_config(&s.world, chassis, config, Pose2::identity(), s.goal, steps, SIM)
}

#[test]
fn u_trap_with_a_180_degree_scanner_stalls_in_track_mode() {
    // MOBIL-II's lesson (004 §4.3.4): 180° of scan is not enough. In T-mode inside the U,
    // OMR-III turns in place toward a tracking direction outside the 180° scan; each turn
    // changes the nearest reading and so the direction, and the robot swings between about
    // −14° and −20° at (1.8, 0.7) without moving. With 270° (u_trap_needs_track_mode_and_escapes)
    // it escapes.
    let s = scenario("u_trap", false);
    let plant = Plant {
        fov: std::f64::consts::PI,
        ..SIM
    };
    let steps = (60.0 / plant.dt) as usize;
    let config = config_for(&ChassisParams::omr3());
    let run = drive_config(
        &s.world,
        ChassisParams::omr3(),
        config,
        Pose2::identity(),
        s.goal,
        steps,
        plant,
    );
    assert_eq!(Ending::of(&run), Ending::Stalls, "{:?}", run.modes);
    assert!(run.modes.iter().any(|m| matches!(m, Mode::Track(_))), "{:?}", run.modes);
    assert!(run.first_abort.is_some(), "the progress checker would abort");
}

#[test]
fn enclosure_without_track_mode_is_never_given_up() {
    // Without T-mode there is no no-path verdict (eq. 3.60 and the return to H belong to it):
    // round the closed box the robot locks and releases for as long as it runs, still moving
    // at the end, and the progress checker never fires. Both T-modes end it NO_PATH.
    for chassis in [ChassisParams::omr3(), ChassisParams::mobil2()] {
        let off = scenario_run("enclosed", chassis, TrackMethod::Off, 120.0);
        assert_eq!(Ending::of(&off), Ending::Loops, "{:?}", off.modes);
        assert!(off.path > 40.0, "{} m", off.path);
        assert!(
            !off.modes.iter().any(|m| matches!(m, Mode::Track(_))),
            "{:?}",
            off.modes
        );
        assert_eq!(off.first_abort, None, "the progress checker fired");
        for method in [TrackMethod::Tangent, TrackMethod::VectorDistance] {
            let run = scenario_run("enclosed", chassis, method, 120.0);
            assert_eq!(Ending::of(&run), Ending::NoPath, "{method:?} {:?}", run.modes);
        }
    }
}

#[test]
fn track_mode_by_eq_3_50_passes_the_wall_but_stalls_in_the_u_trap() {
    // T-mode by the vector-distance function (weights of the chosen side, w'0 toward G) goes
    // round the wall's end like the tangent follower. In the U-trap, from H in the corner it
    // slides along the bottom, turned to face its motion, until F points into the bottom and
    // the robot stops (at about (2.65, −0.20)); a stop closes no progress window (steps are
    // path), so only the progress checker ends it.
    let wall = scenario_run("wall", ChassisParams::omr3(), TrackMethod::VectorDistance, 60.0);
    assert_eq!(Ending::of(&wall), Ending::Reached, "{:?}", wall.modes);
    assert!(
        wall.modes.iter().any(|m| matches!(m, Mode::Track(_))),
        "{:?}",
        wall.modes
    );
    assert!(wall.min_clearance > 0.25, "clearance {}", wall.min_clearance);
    let u = scenario_run("u_trap", ChassisParams::omr3(), TrackMethod::VectorDistance, 60.0);
    assert_eq!(Ending::of(&u), Ending::Stalls, "{:?}", u.modes);
    assert!(u.modes.iter().any(|m| matches!(m, Mode::Track(_))), "{:?}", u.modes);
    assert!(u.first_abort.is_some(), "the progress checker would abort");
}

#[test]
fn enclosed_goal_is_no_path_and_the_robot_stops() {
    // G (5, 0) inside a closed 2 × 2 m box.
    let p = Point2::new;
    let world = World(vec![
        Shape::Segment(p(4.0, -1.0), p(6.0, -1.0)),
        Shape::Segment(p(6.0, -1.0), p(6.0, 1.0)),
        Shape::Segment(p(6.0, 1.0), p(4.0, 1.0)),
        Shape::Segment(p(4.0, 1.0), p(4.0, -1.0)),
    ]);
    let run = drive(&world, ChassisParams::omr3(), Pose2::identity(), p(5.0, 0.0), 6000);
    assert_eq!(
        run.final_mode,
        Mode::NoPath(NoPathReason::ReturnedToHitPoint),
        "{:?}",
        run.modes
    );
    assert_eq!(run.last_speed, 0.0);
    assert!(run.min_clearance > 0.25, "clearance {}", run.min_clearance);
}

#[test]
fn car_like_goes_round_a_convex_obstacle() {
    // MOBIL-II (0.73 m turning radius, robot radius 0.53): a 0.4 m disc at (4, 0), G (8, 0).
    let world = World(vec![Shape::Circle(Point2::new(4.0, 0.0), 0.4)]);
    let run = drive(
        &world,
        ChassisParams::mobil2(),
        Pose2::identity(),
        Point2::new(8.0, 0.0),
        1500,
    );
    assert_eq!(run.final_mode, Mode::Reached, "{:?}", run.modes);
    assert!(run.modes.contains(&Mode::Lock(Side::Left)), "{:?}", run.modes);
    assert!(run.min_clearance > 0.53, "clearance {}", run.min_clearance);
}

#[test]
fn wide_wall_is_followed_in_track_mode_to_its_end() {
    // A 6 m wall square to the goal line at x = 3 (y from −2.5 to 3.5, longer on the left, where
    // the tie sends the robot), G (6, 0) behind it: the lock slides along it without progress,
    // so T-mode takes the robot round the end.
    let p = Point2::new;
    let world = World(vec![Shape::Segment(p(3.0, -2.5), p(3.0, 3.5))]);
    let run = drive(&world, ChassisParams::omr3(), Pose2::identity(), p(6.0, 0.0), 6000);
    assert_eq!(run.final_mode, Mode::Reached, "{:?}", run.modes);
    assert!(run.modes.contains(&Mode::Track(Side::Left)), "{:?}", run.modes);
    let h = run.hit.expect("a hit point");
    assert!(h.x < 3.0, "H {h}");
    assert!(run.min_clearance > 0.25, "clearance {}", run.min_clearance);
}

#[test]
fn car_like_turns_away_from_a_wall_without_creeping() {
    // Scenario (c) of the rclpy tests (params/worlds/local_nav_wall.yaml): a 5 m wall, 0.1 m
    // thick, at x = 4 (y from −2.5 to 2.5), G (7, 1) behind it. MOBIL-II meets the wall inside
    // d_sa and must turn away along it. Bound: the path round the wall's end is about
    // 4 + 2·2.5 + 3 = 12 m, at 0.5 m/s 24 s; with the slow turns and the slide along the
    // wall at most twice that. Nav2's default progress checker (0.5 m in 10 s) must never fire.
    let world = World(rect(4.0, -2.5, 4.1, 2.5).into());
    let run = drive(
        &world,
        ChassisParams::mobil2(),
        Pose2::identity(),
        Point2::new(7.0, 1.0),
        2000,
    );
    eprintln!(
        "wall, MOBIL-II: {:.1} s, modes {:?}, clearance {:.3}",
        run.time, run.modes, run.min_clearance
    );
    assert_eq!(run.final_mode, Mode::Reached, "{:?}", run.modes);
    assert!(run.time < 50.0, "{} s", run.time);
    assert_eq!(run.stuck, None, "{:?}", run.modes);
    assert!(run.min_clearance > 0.53, "clearance {}", run.min_clearance);
}

#[test]
fn car_like_leaves_the_wide_u_trap_without_creeping() {
    // Scenario (d) for MOBIL-II (params/worlds/local_nav_u_trap_wide.yaml): the U 6 m wide
    // inside, mouth at x = 2.5, bottom at x = 5, walls 0.1 m thick; G (9, 0). Bound: in, along
    // the bottom and an arm at d_sa, out round the arm's end and back to the goal line is
    // about 2.5 + 3 + 4 + 4 + 5 = 18.5 m, at 0.5 m/s 37 s; at most twice that.
    let mut shapes: Vec<Shape> = rect(5.0, -3.0, 5.1, 3.0).into();
    shapes.extend(rect(2.5, 2.9, 5.0, 3.0));
    shapes.extend(rect(2.5, -3.0, 5.0, -2.9));
    let world = World(shapes);
    let run = drive(
        &world,
        ChassisParams::mobil2(),
        Pose2::identity(),
        Point2::new(9.0, 0.0),
        3000,
    );
    eprintln!(
        "wide U, MOBIL-II: {:.1} s, modes {:?}, clearance {:.3}",
        run.time, run.modes, run.min_clearance
    );
    assert_eq!(run.final_mode, Mode::Reached, "{:?}", run.modes);
    assert!(run.modes.iter().any(|m| matches!(m, Mode::Track(_))), "{:?}", run.modes);
    assert!(run.time < 75.0, "{} s", run.time);
    assert_eq!(run.stuck, None, "{:?}", run.modes);
    assert!(run.min_clearance > 0.53, "clearance {}", run.min_clearance);
}

#[test]
fn omni_tracks_the_enclosure_with_the_sims_scan_rate_and_motor_lag() {
    // The world file local_nav_enclosed.yaml (walls 0.1 m thick round G (5, 0)), scanned at the
    // sim's 40 Hz, one scan late, with its 0.05 s motor lag. Tracking the box with the obstacle
    // on the right, the robot goes south past the far side (x = 6) with that wall to its west:
    // holding the start heading (east), the wall lies in the 270° scanner's 90° rear blind spot
    // and the tracking stalls there for good (at (6.94, −0.24) without the turn). It must
    // instead go round at about d_sa = 0.8 m outside the 2 m box (4·(2 + 1.6) ≈ 14 m of
    // boundary plus the ~4 m approach and locks: < 25 m, < 50 s at 0.5 m/s; 60 s allowed for
    // the slow-downs), and stop back at H.
    let s = scenario("enclosed", false);
    // The scan the navigator steps on is one scan (25 ms) older than its pose.
    let run = drive_with(&s.world, ChassisParams::omr3(), Pose2::identity(), s.goal, 8000, SIM);
    assert_eq!(
        run.final_mode,
        Mode::NoPath(NoPathReason::ReturnedToHitPoint),
        "{:?} at {:?}",
        run.modes,
        run.final_pose
    );
    assert!(run.time < 60.0, "{} s", run.time);
    assert!(run.path < 25.0, "{} m", run.path);
    assert_eq!(run.stuck, None, "Nav2's progress checker would have aborted");
    assert_eq!(run.last_speed, 0.0);
    assert!(run.min_clearance > 0.25, "clearance {}", run.min_clearance);
    // Back within hit_radius (0.4 m) of H.
    let h = run.hit.expect("a hit point");
    assert!(
        (run.final_pose.position() - h).norm() < 0.4,
        "end {:?} H {h}",
        run.final_pose
    );
}
