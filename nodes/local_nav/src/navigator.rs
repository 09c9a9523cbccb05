//! The mode machine R / L / T of SPEC §2 (004 §3.5, eq. 3.58–3.60) around the vector-distance
//! function. One [`Navigator::step`] per scan: pose (odom) and scan in, a velocity command and
//! the mode out. No clock: steps are path increments ds.

use crate::config::{ConfigError, NavConfig, TrackMethod};
use crate::field::{vector_distance, Side};
use crate::motion::{car_arc, command_along, Drive, MotionInput, MotionLimits, SpeedProfile, VelocityCommand};
use crate::sectors::Sectors;
use mobil_geom::{wrap, Pose2, Scan};
use mobil_motion::{nav2, BodyTwist, GoalLaw, Outcome, Step, StepInput};
use nalgebra::{Point2, Vector2};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_3};
use thiserror::Error;

/// Why the navigator gave up: no path to G (eq. 3.60).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoPathReason {
    /// T-mode came back within `hit_radius` of the hit point H.
    ReturnedToHitPoint,
    /// T-mode made less than c2 progress over m steps.
    NoProgress,
}

/// The navigator's mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// No goal.
    Idle,
    /// R-mode: weights turned toward G.
    Rotate,
    /// L-mode: weights locked in the world frame, turning to `side`.
    Lock(Side),
    /// T-mode: following the boundary, the obstacle on the side opposite `side`.
    Track(Side),
    /// Within the goal tolerance: stopped.
    Reached,
    /// No path: stopped.
    NoPath(NoPathReason),
}

impl Mode {
    /// Whether the navigation is over (goal reached or no path).
    pub fn is_final(&self) -> bool {
        matches!(self, Mode::Reached | Mode::NoPath(_))
    }
}

/// Input the navigator refuses (the command is then zero and the mode unchanged).
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum InputError {
    /// A pose with NaN or infinity.
    #[error("pose is not finite")]
    Pose,
    /// A goal with NaN or infinity.
    #[error("goal is not finite")]
    Goal,
    /// The scan's laser pose is not finite.
    #[error("laser pose in the base frame is not finite")]
    LaserPose,
}

/// What one step decided.
#[derive(Debug, Clone, PartialEq)]
pub struct StepOutput {
    /// The body-frame command (finite, within the limits).
    pub command: VelocityCommand,
    /// The mode after the step.
    pub mode: Mode,
    /// The mode before the step, when it changed.
    pub changed_from: Option<Mode>,
    /// The direction the robot was sent (F, or the tracking direction in T-mode), base frame.
    pub direction: Vector2<f64>,
    /// Distance to G (m).
    pub goal_distance: f64,
    /// Hit point H (odom), once T-mode has begun.
    pub hit_point: Option<Point2<f64>>,
    /// Leave point (odom) of the last T → R.
    pub leave_point: Option<Point2<f64>>,
    /// Input refused this step (command zero, mode unchanged).
    pub input_error: Option<InputError>,
}

#[derive(Debug, Clone, Copy)]
struct Counters {
    /// Path (m) since the last whole step.
    partial: f64,
    /// Whole steps since the mode was entered.
    steps: u64,
    /// Distance to G at the start of the current progress window.
    anchor_distance: f64,
}

/// The vector-distance navigator (SPEC §2).
#[derive(Debug, Clone)]
pub struct Navigator {
    config: NavConfig,
    limits: MotionLimits,
    goal: Option<Point2<f64>>,
    mode: Mode,
    locked_bearing: f64,
    hit: Option<Point2<f64>>,
    left_hit: bool,
    leave: Option<Point2<f64>>,
    last_position: Option<Point2<f64>>,
    counters: Counters,
    sectors: Sectors,
}

impl Navigator {
    /// A navigator without a goal; the configuration and the limits are checked.
    pub fn new(config: NavConfig, limits: MotionLimits) -> Result<Self, ConfigError> {
        config.validate()?;
        if !limits.is_valid() {
            return Err(ConfigError::Value {
                name: "motion limits",
                value: limits.v_max,
                reason: "v_max, omega_max and the curvature limit must be finite and > 0",
            });
        }
        let sectors = Sectors::new(config.sector_count, config.unseen);
        Ok(Navigator {
            config,
            limits,
            goal: None,
            mode: Mode::Idle,
            locked_bearing: 0.0,
            hit: None,
            left_hit: false,
            leave: None,
            last_position: None,
            counters: Counters {
                partial: 0.0,
                steps: 0,
                anchor_distance: 0.0,
            },
            sectors,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &NavConfig {
        &self.config
    }

    /// The current mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The goal (odom), if any.
    pub fn goal(&self) -> Option<Point2<f64>> {
        self.goal
    }

    /// The sectors of the last step.
    pub fn sectors(&self) -> &Sectors {
        &self.sectors
    }

    /// Sets a new goal in odom (pre-empting any other): R-mode, every counter and point cleared.
    pub fn set_goal(&mut self, goal: Point2<f64>) -> Result<(), InputError> {
        if !(goal.x.is_finite() && goal.y.is_finite()) {
            return Err(InputError::Goal);
        }
        self.goal = Some(goal);
        self.mode = Mode::Rotate;
        self.hit = None;
        self.left_hit = false;
        self.leave = None;
        self.last_position = None;
        self.counters = Counters {
            partial: 0.0,
            steps: 0,
            anchor_distance: f64::NAN,
        };
        Ok(())
    }

    /// Drops the goal: Idle, zero command from now on.
    pub fn cancel(&mut self) {
        self.goal = None;
        self.mode = Mode::Idle;
    }

    fn output(
        &self,
        command: VelocityCommand,
        before: Mode,
        direction: Vector2<f64>,
        goal_distance: f64,
    ) -> StepOutput {
        StepOutput {
            command: command.limited(&self.limits),
            mode: self.mode,
            changed_from: (before != self.mode).then_some(before),
            direction,
            goal_distance,
            hit_point: self.hit,
            leave_point: self.leave,
            input_error: None,
        }
    }

    fn enter(&mut self, mode: Mode, goal_distance: f64) {
        self.mode = mode;
        self.counters = Counters {
            partial: 0.0,
            steps: 0,
            anchor_distance: goal_distance,
        };
    }

    /// Advances the path counter (whole steps of ds) to `q`. When this closes a window of
    /// `window` steps, returns the progress toward G over it, |Q_j G| − |Q_{j+window} G|
    /// (eq. 3.58 / 3.60), and starts the next window here.
    fn close_progress_window(&mut self, q: Point2<f64>, goal_distance: f64, window: u32) -> Option<f64> {
        let travelled = self.last_position.map_or(0.0, |p| (q - p).norm());
        let travelled = if travelled.is_finite() { travelled } else { 0.0 };
        self.counters.partial += travelled;
        let whole = (self.counters.partial / self.config.step_length).floor();
        self.counters.partial -= whole * self.config.step_length;
        let before = self.counters.steps;
        self.counters.steps = before.saturating_add(whole as u64);
        let window = u64::from(window.max(1));
        if self.counters.steps / window > before / window {
            let progress = self.counters.anchor_distance - goal_distance;
            self.counters.anchor_distance = goal_distance;
            return Some(progress);
        }
        None
    }

    /// One control step: the robot at `odom_from_base`, the latest checked scan. Returns the
    /// command and the mode; a non-finite pose or laser pose gives the zero command.
    pub fn step(&mut self, odom_from_base: Pose2, scan: &Scan) -> StepOutput {
        let before = self.mode;
        let refuse = |s: &Self, e: InputError| StepOutput {
            command: VelocityCommand::ZERO,
            mode: s.mode,
            changed_from: None,
            direction: Vector2::zeros(),
            goal_distance: f64::NAN,
            hit_point: s.hit,
            leave_point: s.leave,
            input_error: Some(e),
        };
        if !odom_from_base.is_finite() {
            return refuse(self, InputError::Pose);
        }
        if !scan.base_from_laser().is_finite() {
            return refuse(self, InputError::LaserPose);
        }
        let Some(goal) = self.goal else {
            return self.output(VelocityCommand::ZERO, before, Vector2::zeros(), f64::NAN);
        };
        let q = odom_from_base.position();
        let to_goal = goal - q;
        let goal_distance = to_goal.norm();
        if !goal_distance.is_finite() {
            return refuse(self, InputError::Pose);
        }
        if self.mode.is_final() || self.mode == Mode::Idle {
            return self.output(VelocityCommand::ZERO, before, Vector2::zeros(), goal_distance);
        }
        if self.counters.anchor_distance.is_nan() {
            self.counters.anchor_distance = goal_distance;
        }
        if goal_distance <= self.config.goal_tolerance {
            self.mode = Mode::Reached;
            self.last_position = Some(q);
            return self.output(VelocityCommand::ZERO, before, Vector2::zeros(), goal_distance);
        }
        let yaw = odom_from_base.yaw;
        let goal_world = to_goal.y.atan2(to_goal.x);
        let goal_bearing = wrap(goal_world - yaw);
        let d_sa = self.config.safe_distance;
        let release = d_sa + self.config.release_hysteresis;
        let previous = self.last_position;

        // Transitions.
        match self.mode {
            Mode::Rotate => {
                self.sectors.update(scan, goal_bearing);
                let s0 = self.sectors.sector(0);
                if s0.known && s0.distance < d_sa {
                    let side = self.choose_side();
                    self.locked_bearing = goal_world;
                    self.enter(Mode::Lock(side), goal_distance);
                }
            }
            Mode::Lock(side) => {
                self.sectors.update(scan, wrap(self.locked_bearing - yaw));
                if self.sectors.is_clear(0, release) {
                    self.enter(Mode::Rotate, goal_distance);
                    self.sectors.update(scan, goal_bearing);
                } else if self
                    .close_progress_window(q, goal_distance, self.config.lock_steps)
                    .is_some_and(|p| p < self.config.lock_min_progress)
                    && self.config.track_method != TrackMethod::Off
                {
                    self.hit = Some(q);
                    self.left_hit = false;
                    self.leave = None;
                    self.enter(Mode::Track(side), goal_distance);
                    self.sectors.update(scan, goal_bearing);
                }
            }
            Mode::Track(_) => {
                self.sectors.update(scan, goal_bearing);
                let hit = self.hit.unwrap_or(q);
                let hit_distance = (goal - hit).norm();
                let margin = self.config.step_length;
                let from_hit = (q - hit).norm();
                if from_hit > 2.0 * self.config.hit_radius {
                    self.left_hit = true;
                }
                if let Some(l) = previous.and_then(|p| crossing_of_segment(p, q, hit, goal))
                    && (goal - l).norm() < hit_distance - margin
                {
                    self.leave = Some(l);
                    self.enter(Mode::Rotate, goal_distance);
                }
                if matches!(self.mode, Mode::Track(_)) {
                    // Goal sector clear: also nearer G than H, or a trap's mouth leads back in.
                    if self.sectors.is_clear(0, release) && goal_distance < hit_distance - margin {
                        self.leave = Some(q);
                        self.enter(Mode::Rotate, goal_distance);
                    } else if self.left_hit && from_hit < self.config.hit_radius {
                        self.mode = Mode::NoPath(NoPathReason::ReturnedToHitPoint);
                    } else if self
                        .close_progress_window(q, goal_distance, self.config.track_steps)
                        .is_some_and(|p| p < self.config.track_min_progress)
                    {
                        self.mode = Mode::NoPath(NoPathReason::NoProgress);
                    }
                }
            }
            Mode::Idle | Mode::Reached | Mode::NoPath(_) => {}
        }
        self.last_position = Some(q);
        if self.mode.is_final() {
            return self.output(VelocityCommand::ZERO, before, Vector2::zeros(), goal_distance);
        }
        if matches!(self.mode, Mode::Rotate) {
            // Steps only matter in L and T; keep R's path counter idle.
            self.counters.partial = 0.0;
        }

        // Direction of motion.
        let direction = match self.mode {
            Mode::Rotate => {
                let all_clear = self.sectors.sector(0).known
                    && self.sectors.sectors().iter().all(|s| !s.known || s.distance >= d_sa);
                if all_clear {
                    let (s, c) = goal_bearing.sin_cos();
                    Vector2::new(c, s) * (d_sa * self.config.weights.weight(None, 0))
                } else {
                    vector_distance(&self.sectors, &self.config.weights, None, d_sa)
                }
            }
            Mode::Lock(side) => vector_distance(&self.sectors, &self.config.weights, Some(side), d_sa),
            Mode::Track(side) => self.track_direction(side, goal_bearing),
            _ => Vector2::zeros(),
        };
        let (command, against) = self.move_along(direction, goal_distance);
        if let Mode::Lock(side) = self.mode {
            // A lock that cannot move (F into a concave corner, the hard stop) makes no progress
            // however long it waits, and steps are path increments: the hit point is here. So
            // for a car that must turn away from F because every arc toward it is blocked.
            let stalled = command.speed() < self.config.stall_speed || against;
            if stalled && self.config.track_method != TrackMethod::Off {
                self.hit = Some(q);
                self.left_hit = false;
                self.leave = None;
                self.enter(Mode::Track(side), goal_distance);
                self.sectors.update(scan, goal_bearing);
                let direction = self.track_direction(side, goal_bearing);
                let (command, _) = self.move_along(direction, goal_distance);
                return self.output(command, before, direction, goal_distance);
            }
        }
        self.output(command, before, direction, goal_distance)
    }

    /// L-mode side: the side with more free distance (the sum of its sectors' effective
    /// distances, each capped at 10·d_sa so a single open beam does not decide); ties → left.
    fn choose_side(&self) -> Side {
        let n = self.sectors.len();
        let cap = 10.0 * self.config.safe_distance;
        let (mut right, mut left) = (0.0, 0.0);
        for i in (1..n).take_while(|&i| i < n - i) {
            right += self.sectors.effective_distance(i).min(cap);
            left += self.sectors.effective_distance(n - i).min(cap);
        }
        if right > left + 1e-9 {
            Side::Right
        } else {
            Side::Left
        }
    }

    /// T-mode's direction by the configured [`TrackMethod`]; the sectors are referenced to G.
    fn track_direction(&self, side: Side, goal_bearing: f64) -> Vector2<f64> {
        match self.config.track_method {
            TrackMethod::VectorDistance => vector_distance(
                &self.sectors,
                &self.config.weights,
                Some(side),
                self.config.safe_distance,
            ),
            TrackMethod::Tangent | TrackMethod::Off => self.tangent_direction(side, goal_bearing),
        }
    }

    /// The tangent follower: along the boundary of the nearest obstacle, at d_sa. Turning left
    /// (Side::Left) keeps the obstacle on the right, so the tangent is the nearest reading's
    /// bearing + π/2, bent toward the obstacle by `track_gain`·(d − d_sa) (at most ±π/3) when
    /// farther than d_sa and away when nearer. With no reading at all: toward G.
    fn tangent_direction(&self, side: Side, goal_bearing: f64) -> Vector2<f64> {
        let bearing = match self.sectors.nearest() {
            Some((d, phi)) => {
                let bend = (self.config.track_gain * (d - self.config.safe_distance)).clamp(-FRAC_PI_3, FRAC_PI_3);
                match side {
                    Side::Left => phi + FRAC_PI_2 - bend,
                    Side::Right => phi - FRAC_PI_2 + bend,
                }
            }
            None => goal_bearing,
        };
        let (s, c) = bearing.sin_cos();
        Vector2::new(c, s) * self.config.safe_distance
    }

    /// Motion along `direction` (SPEC Decision). Inside d_sa the component of the direction
    /// toward the nearest reading is scaled down with the clearance, to zero at the stop
    /// distance, and the speed with it, while the component along the boundary is kept: F keeps
    /// pulling toward a wall it faces (|f_i| never goes negative), so without this the robot
    /// would settle at the hard stop instead of sliding along the obstacle as the locked weights
    /// ask.
    fn move_along(&self, direction: Vector2<f64>, goal_distance: f64) -> (VelocityCommand, bool) {
        let norm = direction.norm();
        if !norm.is_finite() || norm <= 1e-9 {
            return (VelocityCommand::ZERO, false);
        }
        let mut direction = direction;
        if let Some((d, phi)) = self.sectors.nearest() {
            let toward = Vector2::new(phi.cos(), phi.sin());
            let approach = direction.dot(&toward);
            if approach > 0.0 {
                let span = self.config.safe_distance - self.config.stop_distance;
                let keep = ((d - self.config.stop_distance) / span).clamp(0.0, 1.0);
                direction -= toward * (approach * (1.0 - keep));
            }
        }
        let ratio = (direction.norm() / norm).clamp(0.0, 1.0);
        if ratio.is_nan() || ratio <= 1e-6 {
            return (VelocityCommand::ZERO, false);
        }
        let bearing = direction.y.atan2(direction.x);
        let seen = match self.limits.drive {
            Drive::Omni => self.sectors.sector(self.sectors.index_of(bearing)).known,
            Drive::CarLike { .. } => true,
        };
        let free_ahead = match self.limits.drive {
            Drive::Omni => self.sectors.free_distance_along(bearing, self.config.robot_radius),
            // The car's arcs are checked against the points in `command_along`.
            Drive::CarLike { .. } => f64::INFINITY,
        };
        let profile = SpeedProfile {
            stop_distance: self.config.stop_distance,
            safe_distance: self.config.safe_distance,
            slow_down_radius: self.config.slow_down_radius,
            heading_gain: self.config.heading_gain,
            // The car's swept circle: the body plus half its margin to the hard stop, so that an
            // arc passing an obstacle keeps a margin to the side too (with the body alone, a car
            // could graze a wall's end at the robot radius plus millimetres).
            robot_radius: 0.5 * (self.config.robot_radius + self.config.stop_distance),
            min_turn_speed: self.config.min_turn_speed,
        };
        let input = MotionInput {
            bearing,
            bearing_seen: seen,
            free_ahead,
            obstacles: self.sectors.obstacles(),
            goal_distance,
            speed_scale: ratio,
        };
        let against = match self.limits.drive {
            Drive::Omni => false,
            Drive::CarLike { max_curvature } => car_arc(input.obstacles, bearing, max_curvature, &profile).against,
        };
        let mut command = command_along(&input, &profile, &self.limits);
        if matches!(self.limits.drive, Drive::Omni) && matches!(self.mode, Mode::Track(_)) {
            // T-mode follows the boundary beside the robot: an omni holding its heading would
            // carry it into the scanner's rear blind spot (going back along the box's far side
            // of a goal ahead), lose the nearest reading and stall. Facing the direction of
            // motion keeps the boundary abeam, in the middle of the field of view.
            command.omega = (profile.heading_gain * wrap(bearing)).clamp(-self.limits.omega_max, self.limits.omega_max);
        }
        (command.limited(&self.limits), against)
    }
}

/// Where the path segment p → q crosses the segment H → G strictly between H and G (∠HLG =
/// 180°, eq. 3.59), if it does.
fn crossing_of_segment(p: Point2<f64>, q: Point2<f64>, h: Point2<f64>, g: Point2<f64>) -> Option<Point2<f64>> {
    let line = g - h;
    let len2 = line.norm_squared();
    if !len2.is_finite() || len2 <= 0.0 {
        return None;
    }
    let side = |x: Point2<f64>| line.x * (x.y - h.y) - line.y * (x.x - h.x);
    let (sp, sq) = (side(p), side(q));
    if sp == sq || sp * sq > 0.0 {
        return None;
    }
    let l = p + (q - p) * (sp / (sp - sq));
    let t = (l - h).dot(&line) / len2;
    (t > 0.0 && t < 1.0).then_some(l)
}

impl NoPathReason {
    /// The reason in words.
    pub fn describe(self) -> &'static str {
        match self {
            NoPathReason::ReturnedToHitPoint => "boundary following returned to the hit point",
            NoPathReason::NoProgress => "boundary following made too little progress toward the goal",
        }
    }
}

/// The navigator as a goal law, stepped once per scan (the method counts path, not time): the
/// command along F or the boundary as the body twist, the step's output as the feedback and
/// the report. Within the goal tolerance it succeeds; no path ends it `NO_PATH` (Nav2's
/// `NO_VALID_PATH`); an input it refuses (a non-finite pose, no goal) is refused.
impl GoalLaw for Navigator {
    type Sensors = Scan;
    type Feedback = StepOutput;
    type Report = StepOutput;

    fn step(&mut self, input: &StepInput, scan: &Scan) -> Step<StepOutput, StepOutput> {
        let out = Navigator::step(self, input.pose, scan);
        if let Some(e) = &out.input_error {
            return Step::Refused(e.to_string());
        }
        match out.mode {
            Mode::Reached => Step::end(Outcome::succeeded("goal reached"), out),
            Mode::NoPath(r) => Step::end(
                Outcome::failed("NO_PATH", r.describe(), nav2::compute_path::NO_VALID_PATH),
                out,
            ),
            _ => Step::Command {
                twist: BodyTwist::new(out.command.vx, out.command.vy, out.command.omega),
                feedback: out,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// A navigator whose sectors come from eight beams on the sector centres (sector i at
    /// −45°·i), ranges given per sector, G straight ahead.
    fn with_sectors(method: TrackMethod, d: [f32; 8]) -> Navigator {
        let config = NavConfig {
            track_method: method,
            ..NavConfig::default()
        };
        let limits = MotionLimits::from_chassis(&mobil_chassis::ChassisParams::omr3());
        let mut nav = Navigator::new(config, limits).unwrap();
        nav.sectors = crate::field::tests::eight(d);
        nav
    }

    #[test]
    fn track_direction_by_each_method_by_hand() {
        // Sector 0 (toward G) blocked at 0.4 m, the seven others clear (|f| = d_sa = 0.8).
        let d = [0.4, 9.0, 9.0, 9.0, 9.0, 9.0, 9.0, 9.0];
        // Eq. 3.50 with the left-turning set (3.56): sector i carries w'_{(8−i) mod 8} of
        // [1, 0.775, 0.55, 0.325, 0.1, 0.1625, 0.275, 0.3875], along −45°·i:
        //   0: 0.4·1 at 0°; 1: 0.8·0.3875 = 0.31 at −45°; 2: 0.8·0.275 = 0.22 at −90°;
        //   3: 0.8·0.1625 = 0.13 at −135°; 4: 0.8·0.1 = 0.08 at 180°; 5: 0.8·0.325 = 0.26 at
        //   135°; 6: 0.8·0.55 = 0.44 at 90°; 7: 0.8·0.775 = 0.62 at 45°.
        //   x = 0.4 + (0.31 − 0.13 − 0.26 + 0.62)/√2 − 0.08 = 0.32 + 0.54/√2 = 0.701838
        //   y = (−0.31 − 0.13 + 0.26 + 0.62)/√2 − 0.22 + 0.44 = 0.22 + 0.44/√2 = 0.531127
        let nav = with_sectors(TrackMethod::VectorDistance, d);
        let f = nav.track_direction(Side::Left, 0.0);
        assert_relative_eq!(f.x, 0.32 + 0.54 / 2f64.sqrt(), epsilon = 1e-6);
        assert_relative_eq!(f.y, 0.22 + 0.44 / 2f64.sqrt(), epsilon = 1e-6);
        // The right-turning set mirrors it (3.57).
        let f = nav.track_direction(Side::Right, 0.0);
        assert_relative_eq!(f.x, 0.32 + 0.54 / 2f64.sqrt(), epsilon = 1e-6);
        assert_relative_eq!(f.y, -(0.22 + 0.44 / 2f64.sqrt()), epsilon = 1e-6);
        // The tangent follower: the nearest reading at 0°, 0.4 m; turning left the tangent is
        // +90°, bent away from the too-near boundary by 1.5·(0.8 − 0.4) = 0.6 rad: 90° + 0.6 rad
        // = 2.170796 rad, |d_sa| long.
        for method in [TrackMethod::Tangent, TrackMethod::Off] {
            let nav = with_sectors(method, d);
            let f = nav.track_direction(Side::Left, 0.0);
            assert_relative_eq!(f.x, 0.8 * (FRAC_PI_2 + 0.6).cos(), epsilon = 1e-6);
            assert_relative_eq!(f.y, 0.8 * (FRAC_PI_2 + 0.6).sin(), epsilon = 1e-6);
        }
    }

    #[test]
    fn track_method_names_round_trip() {
        for (m, name) in TrackMethod::ALL.into_iter().zip(TrackMethod::NAMES) {
            assert_eq!(m.name(), name);
            assert_eq!(name.parse::<TrackMethod>(), Ok(m));
            assert_eq!(m.to_string(), name);
        }
        assert!("bug2".parse::<TrackMethod>().unwrap_err().to_string().contains("bug2"));
    }

    #[test]
    fn crossing_by_hand() {
        // H (0, 0), G (4, 0); the path (1, −1) → (2, 1) crosses y = 0 at x = 1.5 (t = 0.375).
        let h = Point2::new(0.0, 0.0);
        let g = Point2::new(4.0, 0.0);
        let l = crossing_of_segment(Point2::new(1.0, -1.0), Point2::new(2.0, 1.0), h, g).unwrap();
        assert_relative_eq!(l.x, 1.5, epsilon = 1e-12);
        assert_relative_eq!(l.y, 0.0, epsilon = 1e-12);
        // Beyond G (x = 5): no leave point; not crossing: none.
        assert!(crossing_of_segment(Point2::new(5.0, -1.0), Point2::new(5.0, 1.0), h, g).is_none());
        assert!(crossing_of_segment(Point2::new(1.0, 1.0), Point2::new(2.0, 1.0), h, g).is_none());
    }
}
