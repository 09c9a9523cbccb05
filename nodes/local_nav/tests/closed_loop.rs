//! Closed loop in pure Rust: the navigator's command integrated by an omni (or unicycle) model
//! over a synthetic world of circles and segments, scanned by a tiny raycaster.

use mobil_chassis::ChassisParams;
use mobil_geom::{Pose2, Scan};
use mobil_local_nav::{
    Mode, MotionLimits, NavConfig, Navigator, NoPathReason, Progress, ProgressChecker, ProgressSettings, Side,
};
use nalgebra::{Point2, Vector2};

enum Shape {
    Circle(Point2<f64>, f64),
    Segment(Point2<f64>, Point2<f64>),
}

struct World(Vec<Shape>);

/// The four edges of the rectangle [x0, x1] × [y0, y1] (a wall of a world file).
fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> [Shape; 4] {
    let p = Point2::new;
    [
        Shape::Segment(p(x0, y0), p(x1, y0)),
        Shape::Segment(p(x1, y0), p(x1, y1)),
        Shape::Segment(p(x1, y1), p(x0, y1)),
        Shape::Segment(p(x0, y1), p(x0, y0)),
    ]
}

impl World {
    /// Distance along the ray o + t·u to the first shape, if within `max`.
    fn ray(&self, o: Point2<f64>, u: Vector2<f64>, max: f64) -> Option<f64> {
        let mut best = f64::INFINITY;
        for s in &self.0 {
            let t = match *s {
                Shape::Circle(c, r) => {
                    // |o + t u − c|² = r²: t² + 2 b t + k = 0.
                    let oc = o - c;
                    let b = oc.dot(&u);
                    let k = oc.norm_squared() - r * r;
                    let disc = b * b - k;
                    if disc < 0.0 {
                        continue;
                    }
                    let t = -b - disc.sqrt();
                    if t >= 0.0 {
                        t
                    } else {
                        continue;
                    }
                }
                Shape::Segment(a, b) => {
                    let e = b - a;
                    let den = u.x * e.y - u.y * e.x;
                    if den.abs() < 1e-12 {
                        continue;
                    }
                    let ao = a - o;
                    let t = (ao.x * e.y - ao.y * e.x) / den;
                    let s = (ao.x * u.y - ao.y * u.x) / den;
                    if t >= 0.0 && (0.0..=1.0).contains(&s) {
                        t
                    } else {
                        continue;
                    }
                }
            };
            best = best.min(t);
        }
        (best <= max).then_some(best)
    }

    /// Smallest distance from a point to any shape.
    fn clearance(&self, p: Point2<f64>) -> f64 {
        self.0
            .iter()
            .map(|s| match *s {
                Shape::Circle(c, r) => (p - c).norm() - r,
                Shape::Segment(a, b) => {
                    let e = b - a;
                    let t = ((p - a).dot(&e) / e.norm_squared()).clamp(0.0, 1.0);
                    (p - (a + e * t)).norm()
                }
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// A 270° scan of 541 beams (0.5°), range [0.05, 10], laser at the centre.
    fn scan(&self, pose: Pose2) -> Scan {
        let fov = 0.75 * std::f64::consts::PI;
        let inc = 2.0 * fov / 540.0;
        let ranges = (0..541)
            .map(|i| {
                let a = pose.yaw - fov + i as f64 * inc;
                match self.ray(pose.position(), Vector2::new(a.cos(), a.sin()), 10.0) {
                    Some(t) => t as f32,
                    None => f32::INFINITY,
                }
            })
            .collect();
        Scan::new(-fov, fov, inc, 0.05, 10.0, ranges, vec![], Pose2::identity()).expect("valid scan")
    }
}

/// MOBIL-II: body radius 0.53 m; d_sa must leave room for the 0.73 m turning radius, so
/// d_sa = 0.53 + 0.73 + 0.24 = 1.5 m; hard stop 0.12 m beyond the body.
fn mobil2_config() -> NavConfig {
    NavConfig {
        robot_radius: 0.53,
        stop_distance: 0.65,
        safe_distance: 1.5,
        ..NavConfig::default()
    }
}

struct Run {
    modes: Vec<Mode>,
    final_mode: Mode,
    min_clearance: f64,
    final_pose: Pose2,
    last_speed: f64,
    hit: Option<Point2<f64>>,
    leave: Option<Point2<f64>>,
    /// Simulated seconds until the final mode (or the step limit).
    time: f64,
    /// The longest time (s) Nav2's default progress checker (0.5 m in 10 s) saw without
    /// progress, had it been running; `None` if it never would have aborted.
    stuck: Option<f64>,
    /// Length of the path driven (m).
    path: f64,
}

/// How the robot is simulated between navigator steps.
#[derive(Clone, Copy)]
struct Plant {
    /// Seconds between navigator steps (one per scan).
    dt: f64,
    /// First-order lag of the body twist (s; 0 = ideal). For an omni chassis the wheel speeds
    /// are linear in the body twist, so this is the sim's motor lag.
    tau: f64,
    /// The scan the navigator gets was taken this many steps before the pose it gets.
    scan_age: usize,
}

/// The ideal plant: 20 Hz, no lag, no latency.
const IDEAL: Plant = Plant {
    dt: 0.05,
    tau: 0.0,
    scan_age: 0,
};

/// Drives from `start` to `goal` for at most `max_steps` of 0.05 s.
fn drive(world: &World, chassis: ChassisParams, start: Pose2, goal: Point2<f64>, max_steps: usize) -> Run {
    drive_with(world, chassis, start, goal, max_steps, IDEAL)
}

/// Drives from `start` to `goal` for at most `max_steps` steps of `plant.dt`.
fn drive_with(
    world: &World,
    chassis: ChassisParams,
    start: Pose2,
    goal: Point2<f64>,
    max_steps: usize,
    plant: Plant,
) -> Run {
    let config = if chassis.model().is_nonholonomic() {
        mobil2_config()
    } else {
        NavConfig::default()
    };
    let limits = MotionLimits::from_chassis(&chassis);
    let mut nav = Navigator::new(config, limits).expect("valid config");
    nav.set_goal(goal).expect("finite goal");
    let dt = plant.dt;
    let substeps = if plant.tau > 0.0 { 10 } else { 1 };
    let h = dt / substeps as f64;
    let mut pose = start;
    let mut past = std::collections::VecDeque::from(vec![start; plant.scan_age]);
    let mut twist = (0.0, 0.0, 0.0);
    let mut modes = vec![nav.mode()];
    let mut min_clearance = world.clearance(pose.position());
    let mut last_speed = f64::NAN;
    let mut hit = None;
    let mut leave = None;
    let mut checker = ProgressChecker::new(ProgressSettings::default());
    let mut stuck = None;
    let mut time = 0.0;
    let mut path = 0.0;
    for _ in 0..max_steps {
        if let Progress::Stuck { since } = checker.check(pose.position(), time) {
            stuck = Some(since);
        }
        past.push_back(pose);
        let scanned = past.pop_front().unwrap_or(pose);
        let out = nav.step(pose, &world.scan(scanned));
        if modes.last() != Some(&out.mode) {
            modes.push(out.mode);
        }
        hit = hit.or(out.hit_point);
        leave = out.leave_point.or(leave);
        let c = out.command;
        last_speed = c.speed() + c.omega.abs();
        if out.mode.is_final() {
            break;
        }
        // The twist follows the command with the lag (exact per sub-step), integrated in
        // sub-steps: exact enough at 5 ms.
        let follow = if plant.tau > 0.0 {
            1.0 - (-h / plant.tau).exp()
        } else {
            1.0
        };
        for _ in 0..substeps {
            twist.0 += (c.vx - twist.0) * follow;
            twist.1 += (c.vy - twist.1) * follow;
            twist.2 += (c.omega - twist.2) * follow;
            let v = pose.rotate(Vector2::new(twist.0, twist.1));
            let before = pose.position();
            pose = Pose2::new(pose.x + v.x * h, pose.y + v.y * h, pose.yaw + twist.2 * h);
            path += (pose.position() - before).norm();
        }
        time += dt;
        min_clearance = min_clearance.min(world.clearance(pose.position()));
    }
    Run {
        modes,
        final_mode: nav.mode(),
        min_clearance,
        final_pose: pose,
        last_speed,
        hit,
        leave,
        time,
        stuck,
        path,
    }
}

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
    let p = Point2::new;
    let world = World(
        rect(4.0, -1.0, 6.0, -0.9)
            .into_iter()
            .chain(rect(4.0, 0.9, 6.0, 1.0))
            .chain(rect(4.0, -1.0, 4.1, 1.0))
            .chain(rect(5.9, -1.0, 6.0, 1.0))
            .collect(),
    );
    // The scan the navigator steps on is one scan (25 ms) older than its pose.
    let plant = Plant {
        dt: 0.025,
        tau: 0.05,
        scan_age: 1,
    };
    let run = drive_with(
        &world,
        ChassisParams::omr3(),
        Pose2::identity(),
        p(5.0, 0.0),
        8000,
        plant,
    );
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
