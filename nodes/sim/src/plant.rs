//! The simulated chassis: wheel commands in, true motion and measured wheel feedback out.
//!
//! Each step, the actual joint values follow the commanded ones through a first-order lag
//! (time constant τ; 0 = ideal), the body twist follows from the chassis' forward kinematics,
//! and the pose is integrated exactly along the arc. The measured feedback is the actual wheel
//! speed times (1 + slip) plus Gaussian noise (relative), so odometry built on it drifts the way
//! real odometry does, deterministically for a seed. A pose that would collide with the world
//! is not entered (the robot stops at the obstacle, as on a bumper). Without a command for
//! `command_timeout` seconds the simulated motor drivers stop the wheels.

use mobil_chassis::kinematics::{
    forward, pose_at_origin, pose_at_reference, twist_at_reference, BodyTwist, JointKind, WheelState,
};
use mobil_chassis::model::ChassisParams;
use mobil_chassis::odometry::integrate_pose;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::world::World;

/// Settings of the simulated chassis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlantConfig {
    pub params: ChassisParams,
    /// First-order lag of wheel speeds and steering angles (s); 0 = they follow at once.
    pub motor_time_constant: f64,
    /// Relative standard deviation of the measured wheel speeds.
    pub wheel_speed_noise: f64,
    /// Relative bias of the measured wheel speeds (measured = true · (1 + slip)).
    pub wheel_slip: f64,
    /// The drivers stop the wheels after this long without a command (s); 0 = never.
    pub command_timeout: f64,
    /// Radius of the robot's footprint around the reference point, for collisions (m).
    pub robot_radius: f64,
}

/// Measured joint feedback, in the order of the model's joints.
#[derive(Debug, Clone, PartialEq)]
pub struct Feedback {
    pub names: Vec<String>,
    /// Steering angle, or accumulated wheel angle (rad).
    pub positions: Vec<f64>,
    /// Steering rate, or wheel speed (rad/s).
    pub velocities: Vec<f64>,
}

/// The simulated robot.
#[derive(Debug, Clone)]
pub struct Plant {
    config: PlantConfig,
    /// Pose of the kinematic origin in the world.
    pose: Vector3<f64>,
    actual: Vec<f64>,
    target: Vec<f64>,
    measured_positions: Vec<f64>,
    measured_velocities: Vec<f64>,
    twist: BodyTwist,
    time: f64,
    last_command: Option<f64>,
    collided: bool,
    rng: ChaCha8Rng,
}

impl Plant {
    /// A robot at rest with its reference point at `reference_pose` (x, y, yaw).
    pub fn new(config: PlantConfig, reference_pose: Vector3<f64>, seed: u64) -> Self {
        let zero = WheelState::zero(config.params.model()).values();
        Plant {
            pose: pose_at_origin(&reference_pose, config.params.reference_offset()),
            actual: zero.clone(),
            target: zero.clone(),
            measured_positions: zero.clone(),
            measured_velocities: zero,
            twist: BodyTwist::ZERO,
            time: 0.0,
            last_command: None,
            collided: false,
            rng: ChaCha8Rng::seed_from_u64(seed),
            config,
        }
    }

    /// New settings; ignored unless the chassis model stays the same (the pose is kept).
    pub fn reconfigure(&mut self, config: PlantConfig) {
        if config.params.model() == self.config.params.model() {
            self.config = config;
        }
    }

    /// Commands the wheels (from `wheel_commands`); a command for another model is ignored.
    pub fn command(&mut self, wheels: &WheelState) {
        if wheels.model() == self.config.params.model() {
            self.target = wheels.values();
            self.last_command = Some(self.time);
        }
    }

    /// Advances the simulation by `dt` seconds (non-positive or non-finite `dt` does nothing).
    pub fn step(&mut self, dt: f64, world: &World) {
        if !(dt.is_finite() && dt > 0.0) {
            return;
        }
        let joints = self.config.params.model().joints();
        let timed_out = self.config.command_timeout > 0.0
            && self
                .last_command
                .is_none_or(|t| self.time - t > self.config.command_timeout);
        if timed_out {
            for (target, joint) in self.target.iter_mut().zip(joints) {
                if joint.kind == JointKind::Wheel {
                    *target = 0.0;
                }
            }
        }
        let tau = self.config.motor_time_constant;
        let alpha = if tau > 0.0 { 1.0 - (-dt / tau).exp() } else { 1.0 };
        let before = self.actual.clone();
        for (actual, target) in self.actual.iter_mut().zip(&self.target) {
            *actual += alpha * (target - *actual);
        }
        self.time += dt;

        let wheels = WheelState::from_values(self.config.params.model(), &self.actual);
        let twist = wheels
            .and_then(|w| forward(&self.config.params, &w))
            .unwrap_or(BodyTwist::ZERO);
        let next = integrate_pose(&self.pose, twist, dt);
        let d = self.config.params.reference_offset();
        let reference = pose_at_reference(&next, d);
        let blocked = world.collides(
            nalgebra::Point2::new(reference.x, reference.y),
            self.config.robot_radius,
        );
        if blocked {
            self.collided = true;
            self.twist = BodyTwist::ZERO;
            // Stalled against the obstacle: the wheels stop too.
            for (actual, joint) in self.actual.iter_mut().zip(joints) {
                if joint.kind == JointKind::Wheel {
                    *actual = 0.0;
                }
            }
        } else {
            self.pose = next;
            self.twist = twist;
        }

        // What the encoders report.
        let noise = (self.config.wheel_speed_noise > 0.0)
            .then(|| Normal::new(0.0, self.config.wheel_speed_noise).ok())
            .flatten();
        for (i, joint) in joints.iter().enumerate() {
            match joint.kind {
                JointKind::Steering => {
                    self.measured_velocities[i] = (self.actual[i] - before[i]) / dt;
                    self.measured_positions[i] = self.actual[i];
                }
                JointKind::Wheel => {
                    let mut w = self.actual[i] * (1.0 + self.config.wheel_slip);
                    if let Some(n) = &noise {
                        w *= 1.0 + n.sample(&mut self.rng);
                    }
                    self.measured_velocities[i] = w;
                    self.measured_positions[i] += w * dt;
                }
            }
        }
    }

    /// The encoder feedback after the last step.
    pub fn feedback(&self) -> Feedback {
        Feedback {
            names: self
                .config
                .params
                .model()
                .joints()
                .iter()
                .map(|j| j.name.to_owned())
                .collect(),
            positions: self.measured_positions.clone(),
            velocities: self.measured_velocities.clone(),
        }
    }

    /// True pose (x, y, yaw) of the reference point.
    pub fn reference_pose(&self) -> Vector3<f64> {
        pose_at_reference(&self.pose, self.config.params.reference_offset())
    }

    /// True body twist of the reference point.
    pub fn reference_twist(&self) -> BodyTwist {
        twist_at_reference(self.twist, self.config.params.reference_offset())
    }

    /// Simulated time since start (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Whether the robot has run into an obstacle.
    pub fn collided(&self) -> bool {
        self.collided
    }

    /// The settings.
    pub fn config(&self) -> &PlantConfig {
        &self.config
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mobil_chassis::kinematics::inverse;
    use mobil_chassis::model::ChassisConfig;

    fn plant(config: ChassisConfig, tau: f64, slip: f64) -> Plant {
        Plant::new(
            PlantConfig {
                params: ChassisParams::new(config).unwrap(),
                motor_time_constant: tau,
                wheel_speed_noise: 0.0,
                wheel_slip: slip,
                command_timeout: 1.0,
                robot_radius: 0.3,
            },
            Vector3::zeros(),
            1,
        )
    }

    #[test]
    fn ideal_car_like_drives_an_exact_arc() {
        let mut p = plant(ChassisConfig::mobil2(), 0.0, 0.0);
        let params = p.config().params;
        let world = World { obstacles: vec![] };
        // v = 0.4 m/s on a 1 m radius for π/2 / 0.4 s: a quarter circle to (1, 1), facing +y.
        p.command(&inverse(&params, BodyTwist::new(0.4, 0.0, 0.4)));
        let steps = 1000;
        let t = std::f64::consts::FRAC_PI_2 / 0.4;
        for _ in 0..steps {
            p.step(t / steps as f64, &world);
            p.command(&inverse(&params, BodyTwist::new(0.4, 0.0, 0.4)));
        }
        let q = p.reference_pose();
        assert!((q.x - 1.0).abs() < 1e-9 && (q.y - 1.0).abs() < 1e-9, "{q:?}");
        assert!((q.z - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
    }

    #[test]
    fn lag_slip_timeout_and_collision() {
        let mut p = plant(ChassisConfig::omr3(), 0.1, 0.02);
        let params = p.config().params;
        let world = World::builtin();
        p.command(&inverse(&params, BodyTwist::new(0.3, 0.0, 0.0)));
        p.step(0.1, &world);
        // First-order lag: after one time constant, 1 − e⁻¹ of the command (6 rad/s on wheel 1).
        let fb = p.feedback();
        let expected = 6.0 * (1.0 - (-1.0f64).exp()) * 1.02;
        assert!((fb.velocities[0] - expected).abs() < 1e-12, "{fb:?}");
        // No command for more than 1 s: the drivers stop the wheels.
        for _ in 0..300 {
            p.step(0.01, &world);
        }
        assert!(p.feedback().velocities.iter().all(|w| w.abs() < 1e-3));
        // Drive into a wall: the robot stops at it and never enters it.
        let mut p = plant(ChassisConfig::omr3(), 0.0, 0.0);
        for _ in 0..10_000 {
            p.command(&inverse(&params, BodyTwist::new(0.5, 0.0, 0.0)));
            p.step(0.01, &world);
        }
        assert!(p.collided());
        assert!(!world.collides(nalgebra::Point2::new(p.reference_pose().x, p.reference_pose().y), 0.3));
    }
}
