//! Driving a distance straight ahead or back, as Nav2's DriveOnHeading / BackUp behaviours do:
//! the progress of a `mobil_msgs/action/DriveDistance` goal from odometry, and the speed to
//! command. ROS-free: poses and settings are inputs.
//!
//! Progress is measured along the robot's heading at the start (the projection of the
//! displacement on it), so a sideways drift does not count as distance. The commanded speed
//! ramps down near the end, v = min(speed, max(min_speed, √(2·decel·remaining))), so the robot
//! arrives slowly enough to stop within `tolerance`.

pub use mobil_geom::Pose2;
use mobil_motion::{BodyTwist, GoalLaw, Outcome, Step, StepInput};
use thiserror::Error;

/// How a drive is carried out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveSettings {
    /// The highest speed a goal may ask for (m/s).
    pub max_speed: f64,
    /// The slowest speed commanded before arrival (m/s) (the ramp-down never stalls below it).
    pub min_speed: f64,
    /// Deceleration of the ramp-down (m/s²).
    pub decel: f64,
    /// Arrived when this close to the distance (m).
    pub tolerance: f64,
}

impl Default for DriveSettings {
    fn default() -> Self {
        DriveSettings {
            max_speed: 0.5,
            min_speed: 0.03,
            decel: 0.5,
            tolerance: 0.005,
        }
    }
}

/// Why a goal is refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DriveGoalError {
    /// NaN or infinite distance.
    #[error("distance {0} is not a finite number")]
    Distance(f64),
    /// Speed not in (0, max_speed].
    #[error("speed {0} is outside (0, {1}] m/s")]
    Speed(f64, f64),
}

/// Progress of a drive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Travelled along the start heading (m); negative when backwards.
    pub travelled: f64,
    /// Still to go (m), never negative.
    pub remaining: f64,
    /// Within `tolerance` of the distance (or beyond it).
    pub arrived: bool,
}

/// One DriveDistance goal under way.
#[derive(Debug, Clone, PartialEq)]
pub struct DistanceDrive {
    start: Pose2,
    distance: f64,
    speed: f64,
    settings: DriveSettings,
    travelled: f64,
}

impl DistanceDrive {
    /// Starts a drive of `distance` (m) (negative: backwards) at `speed` (m/s) from `start`, or
    /// says why the goal is refused.
    pub fn new(start: Pose2, distance: f64, speed: f64, settings: DriveSettings) -> Result<Self, DriveGoalError> {
        if !distance.is_finite() {
            return Err(DriveGoalError::Distance(distance));
        }
        if !(speed > 0.0 && speed <= settings.max_speed) {
            return Err(DriveGoalError::Speed(speed, settings.max_speed));
        }
        Ok(DistanceDrive {
            start,
            distance,
            speed,
            settings,
            travelled: 0.0,
        })
    }

    /// The distance asked for (m).
    pub fn distance(&self) -> f64 {
        self.distance
    }

    /// Takes the robot's current pose; returns the progress.
    pub fn update(&mut self, pose: Pose2) -> Progress {
        let (dx, dy) = (pose.x - self.start.x, pose.y - self.start.y);
        let along = dx * self.start.yaw.cos() + dy * self.start.yaw.sin();
        if along.is_finite() {
            self.travelled = along;
        }
        self.progress()
    }

    /// The progress at the last update.
    pub fn progress(&self) -> Progress {
        let direction = if self.distance < 0.0 { -1.0 } else { 1.0 };
        let remaining = (self.distance.abs() - direction * self.travelled).max(0.0);
        Progress {
            travelled: self.travelled,
            remaining,
            arrived: remaining <= self.settings.tolerance,
        }
    }

    /// The forward speed to command now (m/s) (signed; zero once arrived).
    pub fn command(&self) -> f64 {
        let p = self.progress();
        if p.arrived {
            return 0.0;
        }
        let s = &self.settings;
        let ramp = (2.0 * s.decel * p.remaining).sqrt().max(s.min_speed);
        let v = self.speed.min(ramp);
        if self.distance < 0.0 {
            -v
        } else {
            v
        }
    }
}

/// A drive as a goal law: the forward speed of [`DistanceDrive::command`] as the body twist, the
/// progress as the feedback, and the progress at the end as the report. A non-finite pose is
/// refused (the robot stops for that step).
impl GoalLaw for DistanceDrive {
    type Sensors = ();
    type Feedback = Progress;
    type Report = Progress;

    fn step(&mut self, input: &StepInput, _: &()) -> Step<Progress, Progress> {
        if !input.pose.is_finite() {
            return Step::Refused("non-finite pose".to_owned());
        }
        let progress = self.update(input.pose);
        if progress.arrived {
            let detail = format!("travelled {:.3} m of {} m", progress.travelled, self.distance);
            return Step::end(Outcome::succeeded(detail), progress);
        }
        Step::Command {
            twist: BodyTwist::new(self.command(), 0.0, 0.0),
            feedback: progress,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    const SETTINGS: DriveSettings = DriveSettings {
        max_speed: 0.5,
        min_speed: 0.03,
        decel: 0.5,
        tolerance: 0.005,
    };

    fn pose(x: f64, y: f64, yaw: f64) -> Pose2 {
        Pose2 { x, y, yaw }
    }

    #[test]
    fn progress_is_measured_along_the_start_heading() {
        // Start at (1, 2) heading 90°: "ahead" is +y. Moving to (1.3, 2.4): 0.4 m ahead (the
        // 0.3 m sideways drift does not count), 0.6 m of 1.0 left.
        let mut d = DistanceDrive::new(pose(1.0, 2.0, std::f64::consts::FRAC_PI_2), 1.0, 0.2, SETTINGS).unwrap();
        let p = d.update(pose(1.3, 2.4, 0.0));
        assert_relative_eq!(p.travelled, 0.4, epsilon = 1e-12);
        assert_relative_eq!(p.remaining, 0.6, epsilon = 1e-12);
        assert!(!p.arrived);
        // Heading 30°, 0.5 m ahead: (0.5 cos 30°, 0.5 sin 30°) = (0.4330127, 0.25).
        let mut d = DistanceDrive::new(pose(0.0, 0.0, 30f64.to_radians()), 2.0, 0.2, SETTINGS).unwrap();
        assert_relative_eq!(
            d.update(pose(0.4330127018922193, 0.25, 0.0)).travelled,
            0.5,
            epsilon = 1e-12
        );
    }

    #[test]
    fn backwards_goals_count_negative_travel() {
        let mut d = DistanceDrive::new(pose(0.0, 0.0, 0.0), -0.5, 0.2, SETTINGS).unwrap();
        let p = d.update(pose(-0.2, 0.0, 0.0));
        assert_relative_eq!(p.travelled, -0.2, epsilon = 1e-12);
        assert_relative_eq!(p.remaining, 0.3, epsilon = 1e-12);
        assert_eq!(d.command(), -0.2);
        // Driving the wrong way adds to what is left.
        let p = d.update(pose(0.1, 0.0, 0.0));
        assert_relative_eq!(p.remaining, 0.6, epsilon = 1e-12);
    }

    #[test]
    fn arrival_within_tolerance_and_beyond() {
        let mut d = DistanceDrive::new(pose(0.0, 0.0, 0.0), 1.0, 0.2, SETTINGS).unwrap();
        assert!(!d.update(pose(0.994, 0.0, 0.0)).arrived); // 6 mm short
        assert!(d.update(pose(0.996, 0.0, 0.0)).arrived); // 4 mm short
        assert_eq!(d.command(), 0.0);
        let p = d.update(pose(1.2, 0.0, 0.0)); // overshoot: nothing left, arrived
        assert_eq!(p.remaining, 0.0);
        assert!(p.arrived);
        // A zero distance has arrived at once.
        let d = DistanceDrive::new(pose(0.0, 0.0, 0.0), 0.0, 0.2, SETTINGS).unwrap();
        assert!(d.progress().arrived);
    }

    #[test]
    fn speed_ramps_down_to_the_minimum_near_the_end() {
        let mut d = DistanceDrive::new(pose(0.0, 0.0, 0.0), 1.0, 0.3, SETTINGS).unwrap();
        assert_eq!(d.command(), 0.3); // √(2·0.5·1) = 1 > 0.3
        d.update(pose(0.96, 0.0, 0.0)); // 0.04 m left: √(2·0.5·0.04) = 0.2
        assert_relative_eq!(d.command(), 0.2, epsilon = 1e-12);
        // 6 mm left: √(2·0.5·0.006) = √0.006 = 0.0775.
        d.update(pose(0.994, 0.0, 0.0));
        assert_relative_eq!(d.command(), 0.006f64.sqrt(), epsilon = 1e-12);
        // The floor: with decel 0.0001, √(2·0.0001·0.5) = 0.01 < 0.03, so 0.03.
        let slow = DriveSettings {
            decel: 0.0001,
            ..SETTINGS
        };
        let d = DistanceDrive::new(pose(0.0, 0.0, 0.0), 0.5, 0.3, slow).unwrap();
        assert_eq!(d.command(), 0.03);
    }

    #[test]
    fn goals_are_checked() {
        let start = pose(0.0, 0.0, 0.0);
        assert_eq!(
            DistanceDrive::new(start, f64::NAN, 0.2, SETTINGS)
                .unwrap_err()
                .to_string(),
            "distance NaN is not a finite number"
        );
        assert!(matches!(
            DistanceDrive::new(start, 1.0, 0.0, SETTINGS),
            Err(DriveGoalError::Speed(..))
        ));
        assert!(DistanceDrive::new(start, 1.0, -0.1, SETTINGS).is_err());
        assert!(DistanceDrive::new(start, 1.0, 0.51, SETTINGS).is_err());
        assert!(DistanceDrive::new(start, 1.0, f64::NAN, SETTINGS).is_err());
        assert!(DistanceDrive::new(start, 1.0, 0.5, SETTINGS).is_ok());
    }

    #[test]
    fn a_non_finite_pose_keeps_the_last_progress() {
        let mut d = DistanceDrive::new(pose(0.0, 0.0, 0.0), 1.0, 0.2, SETTINGS).unwrap();
        d.update(pose(0.3, 0.0, 0.0));
        let p = d.update(pose(f64::NAN, 0.0, 0.0));
        assert_relative_eq!(p.travelled, 0.3, epsilon = 1e-12);
    }

    #[test]
    fn as_a_goal_law_it_commands_the_ramp_and_ends_within_tolerance() {
        use mobil_motion::{GoalLaw, Step, StepInput};
        // 1 m ahead at 0.3 m/s, the default settings: decel 0.5, min 0.03, tolerance 0.005.
        let mut d = DistanceDrive::new(Pose2::new(0.0, 0.0, 0.0), 1.0, 0.3, DriveSettings::default()).unwrap();
        let at = |x: f64| StepInput::new(0.0, 0.05, Pose2::new(x, 0.0, 0.0));
        // 0.5 m left: √(2·0.5·0.5) = 0.707 > 0.3, so the goal's speed.
        match d.step(&at(0.5), &()) {
            Step::Command { twist, feedback } => {
                assert_eq!((twist.vx, twist.vy, twist.wz), (0.3, 0.0, 0.0));
                assert!((feedback.remaining - 0.5).abs() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
        // 0.01 m left: √(2·0.5·0.01) = 0.1.
        match d.step(&at(0.99), &()) {
            Step::Command { twist, .. } => assert!((twist.vx - 0.1).abs() < 1e-9, "{}", twist.vx),
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            d.step(&StepInput::new(0.0, 0.05, Pose2::new(f64::NAN, 0.0, 0.0)), &()),
            Step::Refused(_)
        ));
        // 0.002 m left, within 0.005: the end, reporting what was travelled.
        match d.step(&at(0.998), &()) {
            Step::End(end) => {
                assert!(end.outcome.is_success());
                assert!((end.report.travelled - 0.998).abs() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
    }
}
