//! Nav2's behaviors `BackUp`, `DriveOnHeading` and `Spin` (the behavior server's actions), and
//! the suite's `DriveDistance`, as one goal law. ROS-free: the pose, the goal's time and the
//! scan's echoes are inputs.
//!
//! - **Straight** (`BackUp`, `DriveOnHeading`, `DriveDistance`): [`DistanceDrive`], progress
//!   along the start heading.
//! - **Spin**: [`SpinTurn`], the yaw turned so far, unwrapped, toward a relative target; the
//!   turn rate ramps down as ω = min(`max_speed`, max(`min_speed`, √(2·`decel`·remaining))).
//! - **`time_allowance`** (Nav2's): the goal fails TIMEOUT once its time passes it; zero means
//!   no limit, as in Nav2.
//! - **Collision ahead** (Nav2's `simulate_ahead_time`): with a scan, the goal fails
//!   COLLISION_AHEAD when an echo lies in the area the round footprint (`robot_radius`) sweeps
//!   over the next `simulate_ahead_time` at the commanded speed (at most to the end of the
//!   motion), a capsule along the heading ([`echo_in_sweep`]). A spin sweeps nothing new with a
//!   round footprint, so it fails only when an echo is already inside the footprint. Without a
//!   scan the check is off.
//!
//! ```
//! use mobil_tools::behavior::{Behavior, Guard, SpinSettings};
//! use mobil_tools::drive::Pose2;
//! use mobil_motion::{nav2::behavior::SPIN, GoalLaw, Step, StepInput};
//! let guard = Guard { robot_radius: 0.25, simulate_ahead_time: 2.0 };
//! let mut spin = Behavior::spin(Pose2::new(0.0, 0.0, 3.0), 1.0, 0.0, SpinSettings::default(), guard).unwrap();
//! // Turned 0.5 rad through ±π: 0.5 rad left, ω = √(2·1.6·0.5) = 1.26, held to 1.0 rad/s.
//! let step = spin.step(&StepInput::new(0.5, 0.05, Pose2::new(0.0, 0.0, 3.5 - std::f64::consts::TAU)), &None);
//! let Step::Command { twist, feedback } = step else { panic!() };
//! assert!((feedback.travelled - 0.5).abs() < 1e-9 && twist.wz == 1.0);
//! ```

use crate::drive::{DistanceDrive, DriveSettings, Pose2};
use mobil_geom::segment::segment_distance;
use mobil_geom::wrap;
use mobil_motion::nav2::behavior::Codes;
use mobil_motion::{BodyTwist, GoalLaw, Outcome, Step, StepInput};
use nalgebra::Point2;

/// How a spin is carried out (Nav2's behavior server: `max_rotational_vel` 1.0,
/// `min_rotational_vel` 0.4, `rotational_acc_lim` 3.2; here a slower floor and half the
/// deceleration, so that the robot stops within `tolerance` rather than past the target).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpinSettings {
    /// Highest turn rate (rad/s).
    pub max_speed: f64,
    /// Slowest turn rate before arrival (rad/s).
    pub min_speed: f64,
    /// Deceleration of the ramp-down (rad/s²).
    pub decel: f64,
    /// Arrived within this of the target (rad).
    pub tolerance: f64,
}

impl Default for SpinSettings {
    fn default() -> Self {
        SpinSettings {
            max_speed: 1.0,
            min_speed: 0.1,
            decel: 1.6,
            tolerance: 0.01,
        }
    }
}

/// The collision check's footprint and horizon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Guard {
    /// The round footprint's radius, about the base frame's origin (m).
    pub robot_radius: f64,
    /// How far ahead in time the motion is checked (Nav2's `simulate_ahead_time`) (s).
    pub simulate_ahead_time: f64,
}

/// A spin toward a yaw relative to the start.
#[derive(Debug, Clone, PartialEq)]
pub struct SpinTurn {
    target: f64,
    turned: f64,
    last_yaw: f64,
    settings: SpinSettings,
}

impl SpinTurn {
    /// A spin of `target` (rad, signed: positive counter-clockwise) from heading `start_yaw`.
    pub fn new(start_yaw: f64, target: f64, settings: SpinSettings) -> Self {
        SpinTurn {
            target,
            turned: 0.0,
            last_yaw: start_yaw,
            settings,
        }
    }

    /// Takes the heading now: the yaw turned so far grows by the wrapped change.
    pub fn update(&mut self, yaw: f64) {
        self.turned += wrap(yaw - self.last_yaw);
        self.last_yaw = yaw;
    }

    /// Turned so far (rad, signed), and still to go (never negative).
    pub fn progress(&self) -> (f64, f64) {
        let remaining = (self.target.abs() - self.target.signum() * self.turned).max(0.0);
        (self.turned, remaining)
    }

    /// Whether the target is reached.
    pub fn arrived(&self) -> bool {
        self.progress().1 <= self.settings.tolerance
    }

    /// The turn rate to command (rad/s, signed; zero once arrived).
    pub fn command(&self) -> f64 {
        if self.arrived() {
            return 0.0;
        }
        let s = &self.settings;
        // max then min, not clamp: settings with min above max give max, never a panic.
        let w = (2.0 * s.decel * self.progress().1)
            .sqrt()
            .max(s.min_speed)
            .min(s.max_speed);
        w * self.target.signum()
    }
}

/// The motion of a behavior.
#[derive(Debug, Clone, PartialEq)]
pub enum Motion {
    /// Straight ahead or back.
    Straight(DistanceDrive),
    /// In place.
    Spin(SpinTurn),
}

/// Progress of a behavior: metres (straight, signed) or radians (spin, signed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BehaviorProgress {
    /// Travelled or turned so far.
    pub travelled: f64,
    /// Still to go, never negative.
    pub remaining: f64,
}

/// One behavior goal under way.
#[derive(Debug, Clone, PartialEq)]
pub struct Behavior {
    motion: Motion,
    /// Time allowed (s); `None`: no limit.
    allowance: Option<f64>,
    /// The action's codes, and the footprint, for the allowance and the collision check;
    /// `None` for `DriveDistance`, which has neither.
    checks: Option<(Codes, Guard)>,
}

fn invalid(codes: Codes, detail: String) -> Outcome {
    Outcome::failed("INVALID_INPUT", detail, codes.invalid_input)
}

/// A straight behavior's target moves along x only (Nav2: y or z is INVALID_INPUT).
fn x_only(codes: Codes, target: [f64; 3], what: &str) -> Result<(), Outcome> {
    if target[1] != 0.0 || target[2] != 0.0 {
        return Err(invalid(codes, format!("{what} in y and z is not supported")));
    }
    Ok(())
}

fn allowance(time_allowance: f64) -> Option<f64> {
    (time_allowance.is_finite() && time_allowance > 0.0).then_some(time_allowance)
}

impl Behavior {
    /// A `DriveDistance` goal: the drive alone.
    pub fn distance(drive: DistanceDrive) -> Self {
        Behavior {
            motion: Motion::Straight(drive),
            allowance: None,
            checks: None,
        }
    }

    /// A straight behavior, its goal checked by the caller's rule.
    fn straight(
        start: Pose2,
        (distance, speed): (f64, f64),
        settings: DriveSettings,
        time_allowance: f64,
        (codes, guard): (Codes, Guard),
    ) -> Result<Self, Outcome> {
        let drive = DistanceDrive::new(start, distance, speed, settings).map_err(|e| invalid(codes, e.to_string()))?;
        Ok(Behavior {
            motion: Motion::Straight(drive),
            allowance: allowance(time_allowance),
            checks: Some((codes, guard)),
        })
    }

    /// Nav2's `BackUp`: `target` (x, y, z) with only x, backed up by |x| at |speed|, as the
    /// behavior server silently makes both negative; y or z not zero is INVALID_INPUT.
    pub fn back_up(
        start: Pose2,
        target: [f64; 3],
        speed: f64,
        settings: DriveSettings,
        time_allowance: f64,
        guard: Guard,
    ) -> Result<Self, Outcome> {
        let codes = mobil_motion::nav2::behavior::BACK_UP;
        x_only(codes, target, "backing up")?;
        Self::straight(
            start,
            (-target[0].abs(), speed.abs()),
            settings,
            time_allowance,
            (codes, guard),
        )
    }

    /// Nav2's `DriveOnHeading`: x metres at `speed`, both of one sign (negative: backwards);
    /// y or z not zero, or the signs differing, is INVALID_INPUT.
    pub fn drive_on_heading(
        start: Pose2,
        target: [f64; 3],
        speed: f64,
        settings: DriveSettings,
        time_allowance: f64,
        guard: Guard,
    ) -> Result<Self, Outcome> {
        let codes = mobil_motion::nav2::behavior::DRIVE_ON_HEADING;
        x_only(codes, target, "driving on heading")?;
        if (target[0] > 0.0) != (speed > 0.0) {
            return Err(invalid(
                codes,
                format!("the signs of target x {} and speed {speed} differ", target[0]),
            ));
        }
        Self::straight(
            start,
            (target[0], speed.abs()),
            settings,
            time_allowance,
            (codes, guard),
        )
    }

    /// Nav2's `Spin`: `target_yaw` (rad, relative, signed) from `start`; a non-finite target is
    /// refused (UNKNOWN: Spin defines no INVALID_INPUT).
    pub fn spin(
        start: Pose2,
        target_yaw: f64,
        time_allowance: f64,
        settings: SpinSettings,
        guard: Guard,
    ) -> Result<Self, Outcome> {
        let codes = mobil_motion::nav2::behavior::SPIN;
        if !target_yaw.is_finite() {
            return Err(Outcome::failed(
                "INVALID_INPUT",
                format!("target_yaw {target_yaw} is not finite"),
                codes.unknown,
            ));
        }
        if !start.yaw.is_finite() {
            return Err(Outcome::failed(
                "TF_ERROR",
                "the start heading is not finite",
                codes.tf_error,
            ));
        }
        Ok(Behavior {
            motion: Motion::Spin(SpinTurn::new(start.yaw, target_yaw, settings)),
            allowance: allowance(time_allowance),
            checks: Some((codes, guard)),
        })
    }

    /// The motion.
    pub fn motion(&self) -> &Motion {
        &self.motion
    }

    /// The progress at the last step.
    pub fn progress(&self) -> BehaviorProgress {
        match &self.motion {
            Motion::Straight(d) => {
                let p = d.progress();
                BehaviorProgress {
                    travelled: p.travelled,
                    remaining: p.remaining,
                }
            }
            Motion::Spin(s) => {
                let (travelled, remaining) = s.progress();
                BehaviorProgress { travelled, remaining }
            }
        }
    }

    /// The echo that blocks the motion now, if any (see the module docs).
    fn blocking(&self, echoes: &[Point2<f64>], guard: Guard) -> Option<Point2<f64>> {
        match &self.motion {
            Motion::Straight(d) => {
                let v = d.command();
                let reach = (v.abs() * guard.simulate_ahead_time).min(d.progress().remaining);
                echo_in_sweep(echoes, guard.robot_radius, reach.copysign(d.distance()))
            }
            Motion::Spin(_) => echo_in_sweep(echoes, guard.robot_radius, 0.0),
        }
    }
}

/// The first echo (base frame) inside the capsule a round footprint of `radius` sweeps moving
/// `reach` metres along x (negative: backwards) from the origin.
pub fn echo_in_sweep(echoes: &[Point2<f64>], radius: f64, reach: f64) -> Option<Point2<f64>> {
    let (start, end) = (Point2::origin(), Point2::new(reach, 0.0));
    echoes
        .iter()
        .copied()
        .find(|p| segment_distance(*p, start, end) < radius)
}

/// The behavior as a goal law: the command with the progress as feedback; the end at arrival
/// (SUCCEEDED), past the time allowance (TIMEOUT) or with an echo in the way (COLLISION_AHEAD);
/// a non-finite pose refused. `Sensors`: the latest scan's echoes in the base frame, when one is
/// fresh.
impl GoalLaw for Behavior {
    type Sensors = Option<Vec<Point2<f64>>>;
    type Feedback = BehaviorProgress;
    type Report = BehaviorProgress;

    fn step(&mut self, input: &StepInput, echoes: &Self::Sensors) -> Step<BehaviorProgress, BehaviorProgress> {
        if !input.pose.is_finite() {
            return Step::Refused("non-finite pose".to_owned());
        }
        let (arrived, twist) = match &mut self.motion {
            Motion::Straight(d) => {
                let arrived = d.update(input.pose).arrived;
                (arrived, BodyTwist::new(d.command(), 0.0, 0.0))
            }
            Motion::Spin(s) => {
                s.update(input.pose.yaw);
                (s.arrived(), BodyTwist::new(0.0, 0.0, s.command()))
            }
        };
        let progress = self.progress();
        if arrived {
            let detail = match &self.motion {
                Motion::Straight(d) => format!("travelled {:.3} m of {} m", progress.travelled, d.distance()),
                Motion::Spin(_) => format!("turned {:.3} rad", progress.travelled),
            };
            return Step::end(Outcome::succeeded(detail), progress);
        }
        if let Some((codes, guard)) = self.checks {
            if let Some(limit) = self.allowance
                && input.t > limit
            {
                let detail = format!("time allowance {limit} s exceeded");
                return Step::end(Outcome::failed("TIMEOUT", detail, codes.timeout), progress);
            }
            if let Some(p) = echoes.as_deref().and_then(|e| self.blocking(e, guard)) {
                let detail = format!("obstacle at ({:.2}, {:.2}) m in the robot's way", p.x, p.y);
                return Step::end(
                    Outcome::failed("COLLISION_AHEAD", detail, codes.collision_ahead),
                    progress,
                );
            }
        }
        Step::Command {
            twist,
            feedback: progress,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mobil_motion::nav2::behavior::{BACK_UP, DRIVE_ON_HEADING, SPIN};

    const GUARD: Guard = Guard {
        robot_radius: 0.25,
        simulate_ahead_time: 2.0,
    };

    fn at(x: f64, yaw: f64) -> Pose2 {
        Pose2::new(x, 0.0, yaw)
    }

    fn ended(step: Step<BehaviorProgress, BehaviorProgress>) -> Outcome {
        match step {
            Step::End(end) => end.outcome,
            other => panic!("not an end: {other:?}"),
        }
    }

    /// Nav2's goal rules: BackUp goes back whatever the signs; DriveOnHeading needs one sign;
    /// y or z refused; each with its own code.
    #[test]
    fn goals_follow_nav2s_rules_and_codes() {
        let s = DriveSettings::default();
        let back = Behavior::back_up(at(0.0, 0.0), [0.3, 0.0, 0.0], -0.1, s, 0.0, GUARD).unwrap();
        let Motion::Straight(d) = back.motion() else { panic!() };
        assert_eq!(d.distance(), -0.3);
        assert_eq!(d.command(), -0.1);
        let e = Behavior::back_up(at(0.0, 0.0), [0.3, 0.1, 0.0], 0.1, s, 0.0, GUARD).unwrap_err();
        assert_eq!(e.nav2_error(), BACK_UP.invalid_input);
        let e = Behavior::drive_on_heading(at(0.0, 0.0), [0.5, 0.0, 0.0], -0.1, s, 0.0, GUARD).unwrap_err();
        assert_eq!((e.nav2_error(), e.reason().starts_with("INVALID_INPUT")), (724, true));
        let e = Behavior::drive_on_heading(at(0.0, 0.0), [0.5, 0.0, 0.0], 0.9, s, 0.0, GUARD).unwrap_err();
        assert_eq!(e.nav2_error(), 724, "above max_speed 0.5");
        assert!(Behavior::drive_on_heading(at(0.0, 0.0), [-0.5, 0.0, 0.0], -0.1, s, 0.0, GUARD).is_ok());
        let e = Behavior::spin(at(0.0, 0.0), f64::NAN, 0.0, SpinSettings::default(), GUARD).unwrap_err();
        assert_eq!(e.nav2_error(), SPIN.unknown);
    }

    /// The spin's ramp by hand: 1.0 rad left, √(2·1.6·1.0) = 1.79 → 1.0 (the cap); 0.1 left,
    /// √0.32 = 0.566; within 0.01: arrived. With a 0.001 tolerance, 0.002 left gives
    /// √0.0064 = 0.08 → 0.1 (the floor). Negative targets turn clockwise; the yaw is unwrapped
    /// through ±π.
    #[test]
    fn spin_ramps_down_and_unwraps() {
        let mut s = SpinTurn::new(0.0, 1.5, SpinSettings::default());
        s.update(0.5);
        assert_eq!(s.command(), 1.0);
        s.update(1.4);
        assert!((s.command() - 0.32f64.sqrt()).abs() < 1e-12);
        s.update(1.495);
        assert!(s.arrived() && s.command() == 0.0);
        let fine = SpinSettings {
            tolerance: 0.001,
            ..SpinSettings::default()
        };
        let mut s = SpinTurn::new(0.0, 1.5, fine);
        s.update(1.498);
        assert!((s.command() - 0.1).abs() < 1e-12);
        let mut cw = SpinTurn::new(3.0, -7.0, SpinSettings::default());
        for k in 1..=10 {
            cw.update(wrap(3.0 - 0.6 * k as f64));
        }
        let (turned, remaining) = cw.progress();
        assert!((turned + 6.0).abs() < 1e-9 && (remaining - 1.0).abs() < 1e-9);
        assert_eq!(cw.command(), -1.0);
    }

    /// The capsule: backing up 0.4 m with a 0.25 m footprint, an echo at (−0.6, 0.1) is 0.22
    /// from (−0.4, 0) (inside); (−0.7, 0) is 0.3 away (outside); one ahead at (0.2, 0) is inside
    /// the footprint now; (0.3, 0.3) is not.
    #[test]
    fn the_sweep_is_a_capsule_along_the_heading() {
        assert_eq!(
            echo_in_sweep(&[Point2::new(-0.6, 0.1)], 0.25, -0.4),
            Some(Point2::new(-0.6, 0.1))
        );
        assert_eq!(echo_in_sweep(&[Point2::new(-0.7, 0.0)], 0.25, -0.4), None);
        assert!(echo_in_sweep(&[Point2::new(0.2, 0.0)], 0.25, -0.4).is_some());
        assert_eq!(echo_in_sweep(&[Point2::new(0.3, 0.3)], 0.25, -0.4), None);
        assert_eq!(
            echo_in_sweep(&[Point2::new(1.0, 0.0)], 0.25, 0.8),
            Some(Point2::new(1.0, 0.0))
        );
    }

    /// A back-up toward a wall 0.5 m behind: at 0.1 m/s the 2 s horizon reaches 0.2 m, the
    /// capsule ends at −0.2 − 0.25 = −0.45 (free); at 0.2 m/s it reaches −0.65: COLLISION_AHEAD.
    /// Without a scan the check is off. Past the allowance: TIMEOUT.
    #[test]
    fn collision_ahead_timeout_and_success() {
        let s = DriveSettings::default();
        let wall: Option<Vec<Point2<f64>>> = Some((-5..=5).map(|k| Point2::new(-0.5, 0.1 * k as f64)).collect());
        let input = |t: f64, x: f64| StepInput::new(t, 0.05, at(x, 0.0));
        let mut slow = Behavior::back_up(at(0.0, 0.0), [0.3, 0.0, 0.0], 0.1, s, 0.0, GUARD).unwrap();
        assert!(matches!(slow.step(&input(0.0, 0.0), &wall), Step::Command { .. }));
        let mut fast = Behavior::back_up(at(0.0, 0.0), [0.3, 0.0, 0.0], 0.2, s, 0.0, GUARD).unwrap();
        assert_eq!(
            ended(fast.step(&input(0.0, 0.0), &wall)).nav2_error(),
            BACK_UP.collision_ahead
        );
        assert!(matches!(fast.step(&input(0.0, 0.0), &None), Step::Command { .. }));
        let mut timed = Behavior::drive_on_heading(at(0.0, 0.0), [1.0, 0.0, 0.0], 0.2, s, 0.5, GUARD).unwrap();
        assert!(matches!(timed.step(&input(0.5, 0.1), &None), Step::Command { .. }));
        assert_eq!(
            ended(timed.step(&input(0.55, 0.11), &None)).nav2_error(),
            DRIVE_ON_HEADING.timeout
        );
        let mut done = Behavior::back_up(at(0.0, 0.0), [0.3, 0.0, 0.0], 0.1, s, 0.0, GUARD).unwrap();
        assert!(ended(done.step(&input(3.0, -0.298), &wall)).is_success());
        let spin_in_the_footprint: Option<Vec<Point2<f64>>> = Some(vec![Point2::new(0.1, 0.1)]);
        let mut spin = Behavior::spin(at(0.0, 0.0), 1.0, 0.0, SpinSettings::default(), GUARD).unwrap();
        assert_eq!(
            ended(spin.step(&input(0.0, 0.0), &spin_in_the_footprint)).nav2_error(),
            SPIN.collision_ahead
        );
    }
}
