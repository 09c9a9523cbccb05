//! A ROS-free closed loop for the navigator, shared by `tests/closed_loop.rs` and the
//! `track_ablation` example: the navigator's command integrated by an omni (or unicycle) model
//! over a synthetic world of circles, segments and moving discs, scanned by a tiny raycaster.
// Each user (the tests, the example) takes part of it.
#![allow(dead_code)]

use mobil_chassis::ChassisParams;
use mobil_geom::{Pose2, Scan};
use mobil_local_nav::{Mode, MotionLimits, NavConfig, Navigator, Progress, ProgressChecker, ProgressSettings};
use nalgebra::{Point2, Vector2};

/// One obstacle.
pub enum Shape {
    /// A disc: centre, radius.
    Circle(Point2<f64>, f64),
    /// A segment between two points.
    Segment(Point2<f64>, Point2<f64>),
    /// A disc moving at a constant velocity: centre at time 0, velocity (m/s), radius.
    Moving(Point2<f64>, Vector2<f64>, f64),
}

/// The obstacles.
pub struct World(pub Vec<Shape>);

/// The four edges of the rectangle [x0, x1] × [y0, y1] (a wall of a world file).
pub fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> [Shape; 4] {
    let p = Point2::new;
    [
        Shape::Segment(p(x0, y0), p(x1, y0)),
        Shape::Segment(p(x1, y0), p(x1, y1)),
        Shape::Segment(p(x1, y1), p(x0, y1)),
        Shape::Segment(p(x0, y1), p(x0, y0)),
    ]
}

/// Distance along o + t·u (t ≥ 0) to the circle (c, r), if the ray meets it.
fn ray_circle(o: Point2<f64>, u: Vector2<f64>, c: Point2<f64>, r: f64) -> Option<f64> {
    // |o + t u − c|² = r²: t² + 2 b t + k = 0.
    let oc = o - c;
    let b = oc.dot(&u);
    let k = oc.norm_squared() - r * r;
    let disc = b * b - k;
    if disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    (t >= 0.0).then_some(t)
}

impl World {
    /// Distance along the ray o + t·u to the first shape at time `time`, if within `max`.
    pub fn ray(&self, o: Point2<f64>, u: Vector2<f64>, max: f64, time: f64) -> Option<f64> {
        let mut best = f64::INFINITY;
        for s in &self.0 {
            let t = match *s {
                Shape::Circle(c, r) => ray_circle(o, u, c, r),
                Shape::Moving(c, v, r) => ray_circle(o, u, c + v * time, r),
                Shape::Segment(a, b) => {
                    let e = b - a;
                    let den = u.x * e.y - u.y * e.x;
                    if den.abs() < 1e-12 {
                        continue;
                    }
                    let ao = a - o;
                    let t = (ao.x * e.y - ao.y * e.x) / den;
                    let s = (ao.x * u.y - ao.y * u.x) / den;
                    (t >= 0.0 && (0.0..=1.0).contains(&s)).then_some(t)
                }
            };
            if let Some(t) = t {
                best = best.min(t);
            }
        }
        (best <= max).then_some(best)
    }

    /// Smallest distance from a point to any shape at time `time`.
    pub fn clearance(&self, p: Point2<f64>, time: f64) -> f64 {
        self.0
            .iter()
            .map(|s| match *s {
                Shape::Circle(c, r) => (p - c).norm() - r,
                Shape::Moving(c, v, r) => (p - (c + v * time)).norm() - r,
                Shape::Segment(a, b) => {
                    let e = b - a;
                    let t = ((p - a).dot(&e) / e.norm_squared()).clamp(0.0, 1.0);
                    (p - (a + e * t)).norm()
                }
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// A scan of `fov` radians (centred ahead) at 0.5° spacing, range [0.05, 10], laser at the
    /// centre, taken at time `time`.
    pub fn scan(&self, pose: Pose2, fov: f64, time: f64) -> Scan {
        let half = 0.5 * fov;
        let beams = (fov.to_degrees() * 2.0).round() as usize + 1;
        let inc = fov / (beams - 1) as f64;
        let ranges = (0..beams)
            .map(|i| {
                let a = pose.yaw - half + i as f64 * inc;
                match self.ray(pose.position(), Vector2::new(a.cos(), a.sin()), 10.0, time) {
                    Some(t) => t as f32,
                    None => f32::INFINITY,
                }
            })
            .collect();
        Scan::new(-half, half, inc, 0.05, 10.0, ranges, vec![], Pose2::identity()).expect("valid scan")
    }
}

/// MOBIL-II (params/mobil2.yaml): body radius 0.53 m; d_sa must leave room for the 0.73 m
/// turning radius, so d_sa = 0.53 + 0.73 + 0.24 = 1.5 m; hard stop 0.12 m beyond the body.
pub fn mobil2_config() -> NavConfig {
    NavConfig {
        robot_radius: 0.53,
        stop_distance: 0.65,
        safe_distance: 1.5,
        ..NavConfig::default()
    }
}

/// The params file's navigator configuration for a chassis (OMR-III: the defaults).
pub fn config_for(chassis: &ChassisParams) -> NavConfig {
    if chassis.model().is_nonholonomic() {
        mobil2_config()
    } else {
        NavConfig::default()
    }
}

/// What one run did.
pub struct Run {
    /// The modes in order (consecutive repeats merged).
    pub modes: Vec<Mode>,
    /// The mode at the end.
    pub final_mode: Mode,
    /// Closest approach of the centre to any surface (m).
    pub min_clearance: f64,
    /// The pose at the end.
    pub final_pose: Pose2,
    /// |v| + |ω| of the last command.
    pub last_speed: f64,
    /// The first hit point H.
    pub hit: Option<Point2<f64>>,
    /// The last leave point L.
    pub leave: Option<Point2<f64>>,
    /// Simulated seconds until the final mode (or the step limit).
    pub time: f64,
    /// How long (s) the robot had gone without progress the last time Nav2's default progress
    /// checker (0.5 m in 10 s), had it been running, found it stuck; `None` if it never would
    /// have aborted.
    pub stuck: Option<f64>,
    /// When (simulated s) that checker would first have aborted the goal.
    pub first_abort: Option<f64>,
    /// Length of the path driven (m).
    pub path: f64,
    /// Path (m) driven in the last 10 simulated seconds of the run: a robot that ends the step
    /// limit still moving loops, one that does not stalls.
    pub recent_path: f64,
    /// The robot's speed (m/s, body twist) when an obstacle first came nearer the centre than
    /// the robot's radius: 0 when a moving obstacle ran into a standing robot.
    pub contact_speed: Option<f64>,
}

/// How the robot is simulated between navigator steps.
#[derive(Clone, Copy)]
pub struct Plant {
    /// Seconds between navigator steps (one per scan).
    pub dt: f64,
    /// First-order lag of the body twist (s; 0 = ideal). For an omni chassis the wheel speeds
    /// are linear in the body twist, so this is the sim's motor lag.
    pub tau: f64,
    /// The scan the navigator gets was taken this many steps before the pose it gets.
    pub scan_age: usize,
    /// The scanner's field of view (rad), centred ahead.
    pub fov: f64,
}

/// 270°, the params files' scanner.
pub const FOV_270: f64 = 1.5 * std::f64::consts::PI;

/// The ideal plant: 20 Hz, no lag, no latency, a 270° scan.
pub const IDEAL: Plant = Plant {
    dt: 0.05,
    tau: 0.0,
    scan_age: 0,
    fov: FOV_270,
};

/// sim_node's defaults: scans at 40 Hz, one scan late, 0.05 s motor lag, 270°.
pub const SIM: Plant = Plant {
    dt: 0.025,
    tau: 0.05,
    scan_age: 1,
    fov: FOV_270,
};

/// Drives from `start` to `goal` for at most `max_steps` of 0.05 s.
pub fn drive(world: &World, chassis: ChassisParams, start: Pose2, goal: Point2<f64>, max_steps: usize) -> Run {
    drive_with(world, chassis, start, goal, max_steps, IDEAL)
}

/// Drives from `start` to `goal` for at most `max_steps` steps of `plant.dt`, with the params
/// file's configuration for the chassis.
pub fn drive_with(
    world: &World,
    chassis: ChassisParams,
    start: Pose2,
    goal: Point2<f64>,
    max_steps: usize,
    plant: Plant,
) -> Run {
    let config = config_for(&chassis);
    drive_config(world, chassis, config, start, goal, max_steps, plant)
}

/// Drives from `start` to `goal` with `config` for at most `max_steps` steps of `plant.dt`.
pub fn drive_config(
    world: &World,
    chassis: ChassisParams,
    config: NavConfig,
    start: Pose2,
    goal: Point2<f64>,
    max_steps: usize,
    plant: Plant,
) -> Run {
    let limits = MotionLimits::from_chassis(&chassis);
    let radius = config.robot_radius;
    let mut nav = Navigator::new(config, limits).expect("valid config");
    nav.set_goal(goal).expect("finite goal");
    let dt = plant.dt;
    let substeps = if plant.tau > 0.0 { 10 } else { 1 };
    let h = dt / substeps as f64;
    let mut pose = start;
    let mut past = std::collections::VecDeque::from(vec![(start, 0.0); plant.scan_age]);
    let mut twist = (0.0, 0.0, 0.0);
    let mut modes = vec![nav.mode()];
    let mut min_clearance = world.clearance(pose.position(), 0.0);
    let mut last_speed = f64::NAN;
    let mut hit = None;
    let mut leave = None;
    let mut checker = ProgressChecker::new(ProgressSettings::default());
    let mut stuck = None;
    let mut first_abort = None;
    let mut time = 0.0;
    let mut path = 0.0;
    let window = (10.0 / dt).round() as usize;
    let mut recent = std::collections::VecDeque::with_capacity(window + 1);
    let mut contact_speed = None;
    for _ in 0..max_steps {
        if let Progress::Stuck { since } = checker.check(pose.position(), time) {
            stuck = Some(since);
            first_abort = first_abort.or(Some(time));
        }
        past.push_back((pose, time));
        let (scanned, scanned_at) = past.pop_front().unwrap_or((pose, time));
        let out = nav.step(pose, &world.scan(scanned, plant.fov, scanned_at));
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
        let mut step_path = 0.0;
        for _ in 0..substeps {
            twist.0 += (c.vx - twist.0) * follow;
            twist.1 += (c.vy - twist.1) * follow;
            twist.2 += (c.omega - twist.2) * follow;
            let v = pose.rotate(Vector2::new(twist.0, twist.1));
            let before = pose.position();
            pose = Pose2::new(pose.x + v.x * h, pose.y + v.y * h, pose.yaw + twist.2 * h);
            step_path += (pose.position() - before).norm();
        }
        path += step_path;
        recent.push_back(step_path);
        if recent.len() > window {
            recent.pop_front();
        }
        time += dt;
        let clearance = world.clearance(pose.position(), time);
        min_clearance = min_clearance.min(clearance);
        if clearance < radius && contact_speed.is_none() {
            contact_speed = Some(twist.0.hypot(twist.1));
        }
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
        first_abort,
        path,
        recent_path: recent.iter().sum(),
        contact_speed,
    }
}

/// One of the five local_nav scenarios of `tests/test_local_nav_scenarios.py`, the world file's
/// obstacles (walls 0.1 m thick) and goal; the start is the origin facing +x.
pub struct Scenario {
    /// Short name (the world file's suffix).
    pub name: &'static str,
    /// The goal.
    pub goal: Point2<f64>,
    /// The obstacles.
    pub world: World,
}

/// The five scenarios for a chassis: MOBIL-II's U-trap is the wide one (`local_nav_u_trap_wide`,
/// G (9, 0)), as in the rclpy scenario tests.
pub fn scenarios(car_like: bool) -> Vec<Scenario> {
    let p = Point2::new;
    let u_trap = if car_like {
        Scenario {
            name: "u_trap_wide",
            goal: p(9.0, 0.0),
            world: World(
                rect(5.0, -3.0, 5.1, 3.0)
                    .into_iter()
                    .chain(rect(2.5, 2.9, 5.0, 3.0))
                    .chain(rect(2.5, -3.0, 5.0, -2.9))
                    .collect(),
            ),
        }
    } else {
        Scenario {
            name: "u_trap",
            goal: p(6.0, 0.0),
            world: World(
                rect(3.0, -1.6, 3.1, 1.6)
                    .into_iter()
                    .chain(rect(1.5, 1.5, 3.0, 1.6))
                    .chain(rect(1.5, -1.6, 3.0, -1.5))
                    .collect(),
            ),
        }
    };
    vec![
        Scenario {
            name: "open",
            goal: p(3.0, 1.0),
            world: World(vec![]),
        },
        Scenario {
            name: "convex",
            goal: p(6.0, 0.0),
            world: World(vec![Shape::Circle(p(3.0, 0.0), 0.4)]),
        },
        Scenario {
            name: "wall",
            goal: p(7.0, 1.0),
            world: World(rect(4.0, -2.5, 4.1, 2.5).into()),
        },
        u_trap,
        Scenario {
            name: "enclosed",
            goal: p(5.0, 0.0),
            world: World(
                rect(4.0, -1.0, 6.0, -0.9)
                    .into_iter()
                    .chain(rect(4.0, 0.9, 6.0, 1.0))
                    .chain(rect(4.0, -1.0, 4.1, 1.0))
                    .chain(rect(5.9, -1.0, 6.0, 1.0))
                    .collect(),
            ),
        },
    ]
}

/// The scenario of that name for a chassis kind (see [`scenarios`]).
pub fn scenario(name: &str, car_like: bool) -> Scenario {
    scenarios(car_like)
        .into_iter()
        .find(|s| s.name == name)
        .unwrap_or_else(|| panic!("no scenario {name}"))
}

/// How a run ended, in the words of the docs' tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ending {
    /// Within the goal tolerance.
    Reached,
    /// The navigator's own no-path verdict (eq. 3.60 or back at H).
    NoPath,
    /// The step limit with the robot still moving (over 0.5 m in the last 10 s): a loop.
    Loops,
    /// The step limit with the robot (nearly) still: a stall.
    Stalls,
}

impl Ending {
    /// Classifies a run.
    pub fn of(run: &Run) -> Self {
        match run.final_mode {
            Mode::Reached => Ending::Reached,
            Mode::NoPath(_) => Ending::NoPath,
            _ if run.recent_path > 0.5 => Ending::Loops,
            _ => Ending::Stalls,
        }
    }

    /// The word for the table.
    pub fn word(self) -> &'static str {
        match self {
            Ending::Reached => "reached",
            Ending::NoPath => "no path",
            Ending::Loops => "loops",
            Ending::Stalls => "stalls",
        }
    }
}

/// The modes in order as letters (R, L, T); past 12 letters the first 8 and the count.
pub fn mode_letters(modes: &[Mode]) -> String {
    let letters: String = modes
        .iter()
        .filter_map(|m| match m {
            Mode::Rotate => Some('R'),
            Mode::Lock(_) => Some('L'),
            Mode::Track(_) => Some('T'),
            _ => None,
        })
        .collect();
    if letters.len() > 12 {
        format!("{}… ({} modes)", &letters[..8], letters.len())
    } else {
        letters
    }
}
