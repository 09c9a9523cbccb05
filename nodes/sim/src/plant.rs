//! The simulated chassis: wheel commands in, true motion and measured wheel feedback out.
//!
//! The plant is the simulation's ground truth, so it does not reuse the odometry's model: it
//! describes every wheel by itself ([`WheelGeometry`]: contact point, rolling direction, radius,
//! driven or free, with or without sideways grip) from [`ChassisParams`], and moves the body with
//! the twist that best satisfies every wheel's constraints, by least squares
//! ([`WheelGeometry::body_twist`]). Wheels that disagree (a steering pair off Ackermann, driven
//! wheels at odds with the steering) cannot all roll without slipping; the least-squares residual
//! is that slip ([`Plant::slip_residual`]). The pose is integrated by classical Runge–Kutta
//! (RK4) in sub-steps of at most [`MAX_SUBSTEP`], the joints following their commands through an
//! exact first-order lag (time constant τ; 0 = ideal) inside each sub-step.
//!
//! Commands are held to the chassis' limits: wheel speeds to ±`max_wheel_speed`, steering angles
//! to the largest angle the virtual limit `max_steering` implies for a physical wheel
//! ([`ChassisParams::max_wheel_steering`]: the inner Ackermann wheel); a command with a NaN or infinite value stops the
//! wheels. So whatever arrives, the true pose stays finite and the robot moves no faster than
//! its wheels can drive it.
//!
//! The measured feedback is the actual wheel speed times (1 + slip) plus Gaussian noise
//! (relative), so odometry built on it drifts the way real odometry does, deterministically for a
//! seed. A pose that would collide with the world is not entered (the robot stops at the
//! obstacle, as on a bumper); the collision is checked after every sub-step, so the robot cannot
//! jump through a wall. The drivers' command timeout is the node's: it holds the commands with
//! their arrival time and calls [`Plant::stop`] when they go stale (the plant keeps no clock of
//! commands, so freshness is measured in one place).

use std::f64::consts::TAU;

use mobil_chassis::kinematics::{BodyTwist, JointKind, WheelState};
use mobil_chassis::model::{ChassisModel, ChassisParams};
use mobil_geom::{wrap, Pose2};
use nalgebra::{Matrix3, Point2, Vector2, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use mobil_world::World;

/// Longest integration sub-step (s): at the fastest wheel speed of the presets (about 1.2 m/s)
/// the robot moves 6 mm between collision checks, far less than any footprint.
pub const MAX_SUBSTEP: f64 = 0.005;

/// Longest step [`Plant::step`] accepts (s); a longer one is refused.
pub const MAX_STEP: f64 = 1.0;

/// Errors of the plant.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlantError {
    /// A command or joint vector for another chassis model.
    #[error("wheel command for a {got} chassis, but the plant is {expected}")]
    ModelMismatch {
        /// The plant's model.
        expected: ChassisModel,
        /// The command's model.
        got: ChassisModel,
    },
    /// A joint value is NaN or infinite.
    #[error("joint `{joint}` commanded to the non-finite value {value}; wheels stopped")]
    NonFinite {
        /// The joint.
        joint: &'static str,
        /// The value.
        value: f64,
    },
    /// A joint vector of the wrong length.
    #[error("{got} joint values for a {model} chassis, which has {expected}")]
    JointCount {
        /// The model.
        model: ChassisModel,
        /// Its number of joints.
        expected: usize,
        /// The number given.
        got: usize,
    },
}

/// Where a wheel's rolling direction comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Heading {
    /// A fixed rolling direction, at this angle (rad) from body x.
    Fixed(f64),
    /// Steered: the rolling direction is the angle (rad) of the steering joint with this index.
    Steered(usize),
}

/// One wheel as the plant sees it, in the body frame of the kinematic origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wheel {
    /// Contact point p (m) relative to the kinematic origin.
    pub position: Vector2<f64>,
    /// Rolling direction u (and with it the axle normal n = u rotated by +90°).
    pub heading: Heading,
    /// Index of the joint whose speed φ̇ (rad/s) drives it; `None` for a free-rolling wheel.
    pub drive: Option<usize>,
    /// Rolling radius r (m).
    pub radius: f64,
    /// A conventional wheel grips sideways (n·(v + ω × p) = 0); an omni wheel rolls freely along n.
    pub no_sideslip: bool,
}

/// Body twist from the wheels, and how far they disagree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwistSolution {
    /// Least-squares body twist of the kinematic origin.
    pub twist: BodyTwist,
    /// Euclidean norm (m/s) of the residual of every wheel constraint: 0 when all wheels roll
    /// without slipping.
    pub slip_residual: f64,
}

/// Most joints of any chassis (car-like: two steering angles, two wheel speeds).
const MAX_JOINTS: usize = 4;

/// Most constraint rows of any chassis (car-like: two rolling and four no-sideslip rows).
const MAX_ROWS: usize = 8;

/// The wheels of one chassis, built from its parameters independently of the odometry's model.
#[derive(Debug, Clone, PartialEq)]
pub struct WheelGeometry {
    model: ChassisModel,
    wheels: Vec<Wheel>,
}

impl WheelGeometry {
    /// The wheels of `params`' chassis (SPEC §1), with the kinematic origin at
    /// - tricycle: the rear-axle midpoint; the steered, driven front wheel at (L, 0); the two
    ///   free rear wheels share one no-sideslip constraint, so one wheel at the axle midpoint
    ///   stands for both;
    /// - car-like (MOBIL-II): the rear-axle midpoint; free steered front wheels at (L, ±B/2),
    ///   driven fixed rear wheels at (0, ±B/2);
    /// - omni (OMR-III): the centre; wheel i rolls along θ_i = 0°, 120°, 240° and touches the
    ///   ground at θ_i − 90°, a distance R from the centre.
    pub fn new(params: &ChassisParams) -> Self {
        let r = params.wheel_radius();
        let wheel = |x: f64, y: f64, heading: Heading, drive: Option<usize>, no_sideslip: bool| Wheel {
            position: Vector2::new(x, y),
            heading,
            drive,
            radius: r,
            no_sideslip,
        };
        let (l, half_b) = (params.wheelbase(), 0.5 * params.track());
        let wheels = match params.model() {
            ChassisModel::Tricycle => vec![
                wheel(l, 0.0, Heading::Steered(0), Some(1), true),
                wheel(0.0, 0.0, Heading::Fixed(0.0), None, true),
            ],
            ChassisModel::CarLike => vec![
                wheel(l, half_b, Heading::Steered(0), None, true),
                wheel(l, -half_b, Heading::Steered(1), None, true),
                wheel(0.0, half_b, Heading::Fixed(0.0), Some(2), true),
                wheel(0.0, -half_b, Heading::Fixed(0.0), Some(3), true),
            ],
            ChassisModel::Omni => {
                let big_r = params.omni_wheel_distance();
                (0..3)
                    .map(|i| {
                        let theta = i as f64 * TAU / 3.0;
                        let contact = theta - 0.25 * TAU;
                        wheel(
                            big_r * contact.cos(),
                            big_r * contact.sin(),
                            Heading::Fixed(theta),
                            Some(i),
                            false,
                        )
                    })
                    .collect()
            }
        };
        WheelGeometry {
            model: params.model(),
            wheels,
        }
    }

    /// The wheels.
    pub fn wheels(&self) -> &[Wheel] {
        &self.wheels
    }

    /// The body twist (v, ω) that best satisfies, in the least-squares sense, every wheel's
    /// rolling constraint u_i·(v + ω × p_i) = r·φ̇_i (driven wheels) and no-sideslip constraint
    /// n_i·(v + ω × p_i) = 0 (conventional wheels), for joint values in the order of the
    /// model's joints (steering angles in rad, wheel speeds in rad/s).
    pub fn body_twist(&self, joints: &[f64]) -> Result<TwistSolution, PlantError> {
        let expected = self.model.joints().len();
        if joints.len() != expected {
            return Err(PlantError::JointCount {
                model: self.model,
                expected,
                got: joints.len(),
            });
        }
        let mut rows = [(Vector3::zeros(), 0.0); MAX_ROWS];
        let mut count = 0;
        let mut push = |row: Vector3<f64>, rhs: f64| {
            if count < MAX_ROWS {
                rows[count] = (row, rhs);
                count += 1;
            }
        };
        for w in &self.wheels {
            let angle = match w.heading {
                Heading::Fixed(a) => a,
                Heading::Steered(j) => joints.get(j).copied().unwrap_or(0.0),
            };
            let (s, c) = angle.sin_cos();
            let (u, n) = (Vector2::new(c, s), Vector2::new(-s, c));
            let p = w.position;
            // u·(v + ω × p) = u_x·v_x + u_y·v_y + ω·(p_x·u_y − p_y·u_x).
            let row = |d: Vector2<f64>| Vector3::new(d.x, d.y, p.x * d.y - p.y * d.x);
            if let Some(j) = w.drive {
                push(row(u), w.radius * joints.get(j).copied().unwrap_or(0.0));
            }
            if w.no_sideslip {
                push(row(n), 0.0);
            }
        }
        let rows = &rows[..count];
        let mut normal = Matrix3::zeros();
        let mut rhs = Vector3::zeros();
        for (a, b) in rows {
            normal += a * a.transpose();
            rhs += a * *b;
        }
        let x = normal
            .cholesky()
            .map(|ch| ch.solve(&rhs))
            .unwrap_or_else(Vector3::zeros);
        let residual = rows.iter().map(|(a, b)| (a.dot(&x) - b).powi(2)).sum::<f64>().sqrt();
        Ok(TwistSolution {
            twist: BodyTwist::new(x.x, x.y, x.z),
            slip_residual: residual,
        })
    }
}

/// Settings of the simulated chassis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlantConfig {
    /// The chassis: geometry and limits.
    pub params: ChassisParams,
    /// First-order lag of wheel speeds and steering angles (s); 0 = they follow at once.
    pub motor_time_constant: f64,
    /// Relative standard deviation of the measured wheel speeds.
    pub wheel_speed_noise: f64,
    /// Relative bias of the measured wheel speeds (measured = true · (1 + slip)).
    pub wheel_slip: f64,
    /// Radius of the robot's footprint around the reference point, for collisions (m).
    pub robot_radius: f64,
}

/// Measured joint feedback, in the order of the model's joints.
#[derive(Debug, Clone, PartialEq)]
pub struct Feedback {
    /// Joint names.
    pub names: Vec<String>,
    /// Steering angle, or accumulated wheel angle (rad).
    pub positions: Vec<f64>,
    /// Steering rate, or wheel speed (rad/s).
    pub velocities: Vec<f64>,
}

/// What became of an accepted command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandOutcome {
    /// Every value within the chassis' limits, taken as is.
    Accepted,
    /// At least one value was beyond a limit and was held to it.
    Limited,
}

/// Pose `[x, y, ϑ]` of a point `d` ahead of `pose` along its body x.
fn ahead(pose: &Vector3<f64>, d: f64) -> Vector3<f64> {
    Pose2 {
        x: pose.x,
        y: pose.y,
        yaw: pose.z,
    }
    .ahead(d)
    .to_vector()
}

/// World-frame pose rate of a body moving with `twist` at heading `yaw`.
fn pose_rate(yaw: f64, twist: &BodyTwist) -> Vector3<f64> {
    let (s, c) = yaw.sin_cos();
    Vector3::new(c * twist.vx - s * twist.vy, s * twist.vx + c * twist.vy, twist.wz)
}

/// The simulated robot.
#[derive(Debug, Clone)]
pub struct Plant {
    config: PlantConfig,
    geometry: WheelGeometry,
    /// Pose of the kinematic origin in the world.
    pose: Vector3<f64>,
    actual: Vec<f64>,
    target: Vec<f64>,
    measured_positions: Vec<f64>,
    measured_velocities: Vec<f64>,
    /// True twist of the kinematic origin.
    twist: BodyTwist,
    /// The joint values `twist` was solved for (a sub-step starts where the last one ended).
    twist_joints: Vec<f64>,
    slip_residual: f64,
    time: f64,
    collided: bool,
    rng: ChaCha8Rng,
}

impl Plant {
    /// A robot at rest with its reference point at `reference_pose` (x, y, yaw); a non-finite
    /// pose puts it at the origin.
    pub fn new(config: PlantConfig, reference_pose: Vector3<f64>, seed: u64) -> Self {
        let zero = WheelState::zero(config.params.model()).values();
        let start = if reference_pose.iter().all(|v| v.is_finite()) {
            reference_pose
        } else {
            Vector3::zeros()
        };
        Plant {
            pose: ahead(&start, -config.params.reference_offset()),
            geometry: WheelGeometry::new(&config.params),
            actual: zero.clone(),
            target: zero.clone(),
            measured_positions: zero.clone(),
            measured_velocities: zero.clone(),
            twist: BodyTwist::ZERO,
            twist_joints: zero,
            slip_residual: 0.0,
            time: 0.0,
            collided: false,
            rng: ChaCha8Rng::seed_from_u64(seed),
            config,
        }
    }

    /// New settings; ignored unless the chassis model stays the same (the pose is kept). The
    /// current command is held to the new limits.
    pub fn reconfigure(&mut self, config: PlantConfig) {
        if config.params.model() == self.config.params.model() {
            self.config = config;
            self.geometry = WheelGeometry::new(&config.params);
            self.limit_targets();
            // New geometry: the twist of the current joints is solved afresh.
            self.twist_joints.clear();
        }
    }

    /// Commands the wheels (from `wheel_commands`), each value held to the chassis' limits.
    ///
    /// A command for another model is refused and changes nothing; one with a NaN or infinite
    /// value is refused and stops the wheels (steering angles are held).
    pub fn command(&mut self, wheels: &WheelState) -> Result<CommandOutcome, PlantError> {
        let model = self.config.params.model();
        if wheels.model() != model {
            return Err(PlantError::ModelMismatch {
                expected: model,
                got: wheels.model(),
            });
        }
        let values = wheels.values();
        if let Some((joint, &value)) = model.joints().iter().zip(&values).find(|(_, v)| !v.is_finite()) {
            self.stop();
            return Err(PlantError::NonFinite {
                joint: joint.name,
                value,
            });
        }
        self.target = values;
        Ok(if self.limit_targets() {
            CommandOutcome::Limited
        } else {
            CommandOutcome::Accepted
        })
    }

    /// Stops the wheels (their commanded speeds become 0; steering angles are held), as the
    /// drivers do on a bad command.
    pub fn stop(&mut self) {
        for (target, joint) in self.target.iter_mut().zip(self.config.params.model().joints()) {
            if joint.kind == JointKind::Wheel {
                *target = 0.0;
            }
        }
    }

    /// Holds every commanded value to its limit; true if one was beyond it.
    fn limit_targets(&mut self) -> bool {
        let params = &self.config.params;
        let mut limited = false;
        for (target, joint) in self.target.iter_mut().zip(params.model().joints()) {
            let limit = match joint.kind {
                JointKind::Steering => params.max_wheel_steering(),
                JointKind::Wheel => params.max_wheel_speed(),
            };
            let held = target.clamp(-limit, limit);
            limited |= held != *target;
            *target = held;
        }
        limited
    }

    /// Joint values `s` seconds after `start` on their way to the targets (exact first-order lag).
    fn joints_after(&self, start: &[f64], s: f64, out: &mut [f64]) {
        let tau = self.config.motor_time_constant;
        let keep = if tau > 0.0 { (-s / tau).exp() } else { 0.0 };
        for ((o, a), t) in out.iter_mut().zip(start).zip(&self.target) {
            *o = t + (a - t) * keep;
        }
    }

    /// The least-squares twist for joint values (zero if they do not fit the model).
    fn solve(&self, joints: &[f64]) -> TwistSolution {
        self.geometry.body_twist(joints).unwrap_or(TwistSolution {
            twist: BodyTwist::ZERO,
            slip_residual: 0.0,
        })
    }

    /// Advances the simulation by `dt` seconds, in sub-steps of at most [`MAX_SUBSTEP`].
    /// A non-finite or non-positive `dt`, or one longer than [`MAX_STEP`], does nothing.
    pub fn step(&mut self, dt: f64, world: &World) {
        if !(dt.is_finite() && dt > 0.0 && dt <= MAX_STEP) {
            return;
        }
        let joints = self.config.params.model().joints();
        // At most four joints (car-like): scratch space on the stack, no allocation per step.
        let n = self.actual.len().min(MAX_JOINTS);
        let mut before = [0.0; MAX_JOINTS];
        before[..n].copy_from_slice(&self.actual[..n]);
        if self.config.motor_time_constant <= 0.0 {
            // Ideal motors: the joints are at their commands from the start of the step.
            self.actual.clone_from(&self.target);
        }
        let substeps = (dt / MAX_SUBSTEP).ceil().max(1.0) as usize;
        let h = dt / substeps as f64;
        let d = self.config.params.reference_offset();
        let (mut mid_buffer, mut end_buffer) = ([0.0; MAX_JOINTS], [0.0; MAX_JOINTS]);
        let (mid, end) = (&mut mid_buffer[..n], &mut end_buffer[..n]);
        for done in 0..substeps {
            self.joints_after(&self.actual, 0.5 * h, mid);
            self.joints_after(&self.actual, h, end);
            let t0 = if self.twist_joints == self.actual {
                self.twist
            } else {
                self.solve(&self.actual).twist
            };
            let t_mid = self.solve(mid).twist;
            let solution = self.solve(end);
            // Classical RK4 on the pose; the twist depends on time only (through the joints).
            let p = self.pose;
            let k1 = pose_rate(p.z, &t0);
            let k2 = pose_rate(p.z + 0.5 * h * k1.z, &t_mid);
            let k3 = pose_rate(p.z + 0.5 * h * k2.z, &t_mid);
            let k4 = pose_rate(p.z + h * k3.z, &solution.twist);
            let mut next = p + (k1 + 2.0 * k2 + 2.0 * k3 + k4) * (h / 6.0);
            next.z = wrap(next.z);
            self.actual[..n].copy_from_slice(end);
            let reference = ahead(&next, d);
            let finite = next.iter().all(|v| v.is_finite());
            if !finite || world.collides(Point2::new(reference.x, reference.y), self.config.robot_radius) {
                self.collided |= finite;
                self.slip_residual = 0.0;
                // The pose stays where it is for the rest of the step, but the motors keep
                // moving toward their commands over the sub-steps left (the lag is exact, so one
                // jump covers them all): a steering motor still settles against a wall.
                let remaining = (substeps - done - 1) as f64 * h;
                if remaining > 0.0 {
                    end.copy_from_slice(&self.actual[..n]);
                    self.joints_after(end, remaining, mid);
                    self.actual[..n].copy_from_slice(mid);
                }
                // Stalled against the obstacle: the wheels stop too.
                for (actual, joint) in self.actual.iter_mut().zip(joints) {
                    if joint.kind == JointKind::Wheel {
                        *actual = 0.0;
                    }
                }
                // Stopped wheels drive nothing: the twist is zero whatever the steering.
                self.twist = BodyTwist::ZERO;
                self.twist_joints.clone_from(&self.actual);
                break;
            }
            self.pose = next;
            self.twist = solution.twist;
            self.twist_joints.clone_from(&self.actual);
            self.slip_residual = solution.slip_residual;
        }
        self.time += dt;

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

    /// True pose (x, y, yaw) of the reference point: the kinematic origin moved `d` along body x.
    pub fn reference_pose(&self) -> Vector3<f64> {
        ahead(&self.pose, self.config.params.reference_offset())
    }

    /// True body twist of the reference point: v + ω × (d, 0) = (v_x, v_y + ω·d), ω.
    pub fn reference_twist(&self) -> BodyTwist {
        let d = self.config.params.reference_offset();
        BodyTwist::new(self.twist.vx, self.twist.vy + self.twist.wz * d, self.twist.wz)
    }

    /// How far the wheels disagreed in the last step: the norm (m/s) of the least-squares
    /// residual of their constraints ([`WheelGeometry::body_twist`]); 0 when they all roll
    /// without slipping.
    pub fn slip_residual(&self) -> f64 {
        self.slip_residual
    }

    /// The commanded joint values after limiting, in the order of the model's joints.
    pub fn commanded(&self) -> &[f64] {
        &self.target
    }

    /// The plant's wheel geometry.
    pub fn geometry(&self) -> &WheelGeometry {
        &self.geometry
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
    use approx::assert_relative_eq;
    use mobil_chassis::kinematics::inverse;
    use mobil_chassis::model::ChassisConfig;
    use mobil_world::Obstacle;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn plant_with(params: ChassisParams, tau: f64, slip: f64, radius: f64) -> Plant {
        Plant::new(
            PlantConfig {
                params,
                motor_time_constant: tau,
                wheel_speed_noise: 0.0,
                wheel_slip: slip,
                robot_radius: radius,
            },
            Vector3::zeros(),
            1,
        )
    }

    fn plant(config: ChassisConfig, tau: f64, slip: f64) -> Plant {
        plant_with(ChassisParams::new(config).unwrap(), tau, slip, 0.3)
    }

    fn empty() -> World {
        World { obstacles: vec![] }
    }

    fn twist_of(params: &ChassisParams, joints: &[f64]) -> TwistSolution {
        WheelGeometry::new(params).body_twist(joints).unwrap()
    }

    fn assert_twist(t: BodyTwist, vx: f64, vy: f64, wz: f64) {
        assert_relative_eq!(t.vx, vx, epsilon = 1e-12);
        assert_relative_eq!(t.vy, vy, epsilon = 1e-12);
        assert_relative_eq!(t.wz, wz, epsilon = 1e-12);
    }

    #[test]
    fn omni_wheels_by_hand() {
        let params = ChassisParams::omr3();
        // SPEC §1: a body-x translation at v turns the wheels at (v/r)·[1, −½, −½];
        // r = 0.05, so [6, −3, −3] rad/s is v = 6 · 0.05 = 0.3 m/s.
        let s = twist_of(&params, &[6.0, -3.0, -3.0]);
        assert_twist(s.twist, 0.3, 0.0, 0.0);
        assert!(s.slip_residual < 1e-12);
        // Equal wheels: pure rotation, ϑ̇ = r·Σω / (3R) = 0.05 · 3 / 0.6 = 0.25 rad/s.
        assert_twist(twist_of(&params, &[1.0, 1.0, 1.0]).twist, 0.0, 0.0, 0.25);
        // Sideways at v: wheel i turns at v·sin θ_i / r = (0, √3/2, −√3/2)·v/r; v = 0.2 m/s.
        let k = 0.75f64.sqrt() * 0.2 / 0.05;
        assert_twist(twist_of(&params, &[0.0, k, -k]).twist, 0.0, 0.2, 0.0);
    }

    #[test]
    fn tricycle_wheel_by_hand() {
        // Front wheel at 30°, ground speed 4 · 0.1 = 0.4 m/s on L = 0.5:
        // v = 0.4·cos 30° = 0.34641, ω = 0.4·sin 30° / 0.5 = 0.4 rad/s.
        let s = twist_of(&ChassisParams::tricycle(), &[PI / 6.0, 4.0]);
        assert_twist(s.twist, 0.2 * 3f64.sqrt(), 0.0, 0.4);
        assert!(s.slip_residual < 1e-12);
    }

    /// MOBIL-II on a 1 m radius at the rear-axle centre, ω = 0.4 rad/s (L = 0.60, B = 0.62,
    /// r = 0.10): δ_l = atan(0.60 / 0.69) = 41.0°, δ_r = atan(0.60 / 1.31) = 24.6°, rear wheels
    /// (1 ∓ 0.31)·0.4 / 0.1 = 2.76 and 5.24 rad/s.
    fn mobil2_turn() -> [f64; 4] {
        [(0.60f64 / 0.69).atan(), (0.60f64 / 1.31).atan(), 2.76, 5.24]
    }

    #[test]
    fn car_like_ackermann_turn_by_hand() {
        let turn = mobil2_turn();
        assert_relative_eq!(turn[0].to_degrees(), 41.0, epsilon = 0.05);
        assert_relative_eq!(turn[1].to_degrees(), 24.6, epsilon = 0.05);
        let s = twist_of(&ChassisParams::mobil2(), &turn);
        assert_twist(s.twist, 0.4, 0.0, 0.4);
        assert!(s.slip_residual < 1e-12, "{}", s.slip_residual);

        // Driven for a whole circle with base_link 0.30 m ahead: the rear-axle centre keeps
        // 1 m from the centre of the turn, (−0.3, 1), and base_link sqrt(1² + 0.3²) = 1.04403 m.
        let mut config = ChassisConfig::mobil2();
        config.reference_offset = 0.3;
        let mut p = plant(config, 0.0, 0.0);
        let steps = 2000;
        let dt = TAU / 0.4 / steps as f64;
        let centre = Vector2::new(-0.3, 1.0);
        for i in 0..steps {
            p.command(&WheelState::from_values(ChassisModel::CarLike, &turn).unwrap())
                .unwrap();
            p.step(dt, &empty());
            let q = p.reference_pose();
            let axle = ahead(&q, -0.3);
            assert_relative_eq!((axle.xy() - centre).norm(), 1.0, epsilon = 1e-9);
            assert_relative_eq!((q.xy() - centre).norm(), 1.09f64.sqrt(), epsilon = 1e-9);
            if i == steps / 4 - 1 {
                // A quarter turn: the axle at (0.7, 1) facing +y, base_link 0.3 further on.
                assert_relative_eq!(q, Vector3::new(0.7, 1.3, FRAC_PI_2), epsilon = 1e-9);
            }
        }
        // base_link's twist: v = 0.4 ahead and ω·d = 0.12 m/s sideways (its speed ω·1.04403).
        assert_twist(p.reference_twist(), 0.4, 0.12, 0.4);
    }

    #[test]
    fn ackermann_commands_do_not_slip_and_an_inconsistent_pair_does() {
        let params = ChassisParams::mobil2();
        for (v, w) in [(0.4, 0.4), (0.5, -0.3), (-0.2, 0.25), (0.1, 0.0)] {
            let cmd = inverse(&params, BodyTwist::new(v, 0.0, w)).values();
            let s = twist_of(&params, &cmd);
            assert!(s.slip_residual < 1e-12, "{v} {w}: {}", s.slip_residual);
            assert_twist(s.twist, v, 0.0, w);
        }
        // Toe-out: δ_l = +10°, δ_r = −10°, both rear wheels at 0.4 m/s. By symmetry vy = ω = 0;
        // least squares over 2·(vx − 0.4)² + 2·(sin 10°·vx)² gives vx = 0.4 / (1 + s²), and the
        // residual is 0.4·s·sqrt(2 / (1 + s²)), s = sin 10° = 0.173648:
        // s² = 0.030153690, vx = 0.4 / 1.030153690 = 0.388291576 m/s,
        // residual = 0.4 · 0.173648178 · sqrt(2 / 1.030153690) = 0.069459271 · 1.393362
        // = 0.096781914 m/s.
        let toe_out = [10f64.to_radians(), -10f64.to_radians(), 4.0, 4.0];
        let s = twist_of(&params, &toe_out);
        assert_relative_eq!(s.twist.vx, 0.388_291_576, epsilon = 1e-9);
        assert!(s.twist.vy.abs() < 1e-12 && s.twist.wz.abs() < 1e-12, "{:?}", s.twist);
        assert_relative_eq!(s.slip_residual, 0.096_781_914, epsilon = 1e-9);
        // The plant reports the same slip while it drives on them.
        let mut p = plant_with(params, 0.0, 0.0, 0.3);
        p.command(&WheelState::from_values(ChassisModel::CarLike, &toe_out).unwrap())
            .unwrap();
        p.step(0.01, &empty());
        assert_relative_eq!(p.slip_residual(), 0.096_781_914, epsilon = 1e-9);
        assert_relative_eq!(p.reference_pose().x, 0.003_882_916, epsilon = 1e-9);
    }

    #[test]
    fn lag_slip_stop_and_collision() {
        let mut p = plant(ChassisConfig::omr3(), 0.1, 0.02);
        let world = World::builtin();
        p.command(&WheelState::Omni {
            wheels: [6.0, -3.0, -3.0],
        })
        .unwrap();
        p.step(0.1, &world);
        // First-order lag: after one time constant, 1 − e⁻¹ of the command (6 rad/s on wheel 1).
        let fb = p.feedback();
        let expected = 6.0 * (1.0 - (-1.0f64).exp()) * 1.02;
        assert!((fb.velocities[0] - expected).abs() < 1e-12, "{fb:?}");
        // ... and the body has moved ∫ 0.3·(1 − e^(−t/τ)) dt over 0.1 s = 0.3·τ·e⁻¹ = 0.011036 m.
        assert_relative_eq!(p.reference_pose().x, 0.3 * 0.1 * (-1.0f64).exp(), epsilon = 1e-9);
        // The drivers stop (the node's command timeout): the wheels coast down, e^(−3 s / 0.1 s).
        p.stop();
        for _ in 0..300 {
            p.step(0.01, &world);
        }
        assert!(p.feedback().velocities.iter().all(|w| w.abs() < 1e-3));
        // Drive into a wall: the robot stops at it and never enters it.
        let mut p = plant(ChassisConfig::omr3(), 0.0, 0.0);
        for _ in 0..10_000 {
            p.command(&WheelState::Omni {
                wheels: [10.0, -5.0, -5.0],
            })
            .unwrap();
            p.step(0.01, &world);
        }
        assert!(p.collided());
        let q = p.reference_pose();
        assert!(!world.collides(Point2::new(q.x, q.y), 0.3));
    }

    #[test]
    fn one_omni_wheel_at_1e308_turns_at_the_wheel_limit() {
        // Held to 12 rad/s: r·12 = 0.6 m/s on wheel 1 alone is v_u = ⅔·0.6 = 0.4 m/s and
        // ϑ̇ = 0.6 / (3·0.2) = 1 rad/s (check: 0.4 + 0.2·1 = 0.6, and −½·0.4 + 0.2 = 0 on the
        // others): a circle of radius 0.4 m, half of it after π s, at (0, 0.8) facing −x.
        let mut p = plant(ChassisConfig::omr3(), 0.0, 0.0);
        let outcome = p.command(&WheelState::Omni {
            wheels: [1e308, 0.0, 0.0],
        });
        assert_eq!(outcome, Ok(CommandOutcome::Limited));
        assert_eq!(p.commanded(), &[12.0, 0.0, 0.0]);
        for _ in 0..1000 {
            p.command(&WheelState::Omni {
                wheels: [1e308, 0.0, 0.0],
            })
            .unwrap();
            p.step(PI / 1000.0, &empty());
        }
        // The heading may land a few ulp either side of π, where the wrap flips to −π + ε:
        // compare it as an angle.
        let q = p.reference_pose();
        assert_relative_eq!(q.xy(), Vector2::new(0.0, 0.8), epsilon = 1e-9);
        assert!(wrap(q.z - PI).abs() < 1e-9, "{q:?}");
        assert_relative_eq!(p.feedback().velocities[0], 12.0);
    }

    #[test]
    fn one_rear_wheel_at_1e308_is_held_to_the_limit_and_stays_in_the_room() {
        // Rear-left held to 7.5 rad/s (0.75 m/s), rear-right 0, front straight. Least squares
        // by hand (b = 0.31, L = 0.60): vx = 0.75 / 2 = 0.375; the straight front wheels and
        // the rear axle share the sideslip, vy = −L·ω / 2; and ω minimises
        // 2·(b·ω + 0.375)² + L²·ω², so ω = −4·b·0.375 / (4b² + 2L²) = −0.465 / 1.1044.
        let params = ChassisParams::mobil2();
        let cmd = [0.0, 0.0, 1e308, 0.0];
        let w = -0.465 / 1.1044;
        let mut p = plant_with(params, 0.05, 0.0, 0.53);
        assert_eq!(
            p.command(&WheelState::from_values(ChassisModel::CarLike, &cmd).unwrap()),
            Ok(CommandOutcome::Limited)
        );
        let world = World::builtin();
        let mut last = p.reference_pose();
        for _ in 0..12_000 {
            p.command(&WheelState::from_values(ChassisModel::CarLike, &cmd).unwrap())
                .unwrap();
            p.step(0.005, &world);
            let q = p.reference_pose();
            assert!(q.iter().all(|v| v.is_finite()));
            // base_link's speed is at most |v| + |ω|·(d + |vy/ω|): bounded by 0.375 + 0.127.
            assert!((q.xy() - last.xy()).norm() <= 0.51 * 0.005, "{q:?} from {last:?}");
            assert!(!world.collides(Point2::new(q.x, q.y), 0.53));
            last = q;
        }
        assert_twist(p.reference_twist(), 0.375, -0.6 * w / 2.0, w);
    }

    #[test]
    fn nan_and_inf_commands_stop_the_wheels_and_the_pose_stays_finite() {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let mut p = plant(ChassisConfig::omr3(), 0.0, 0.0);
            p.command(&WheelState::Omni {
                wheels: [6.0, -3.0, -3.0],
            })
            .unwrap();
            p.step(1.0, &empty());
            let before = p.reference_pose();
            assert_relative_eq!(before, Vector3::new(0.3, 0.0, 0.0), epsilon = 1e-12);
            let err = p.command(&WheelState::Omni {
                wheels: [6.0, bad, -3.0],
            });
            assert!(
                matches!(err, Err(PlantError::NonFinite { joint: "wheel_2", .. })),
                "{err:?}"
            );
            for _ in 0..10 {
                let _ = p.command(&WheelState::Omni { wheels: [bad; 3] });
                p.step(0.1, &empty());
            }
            // Stopped at once (τ = 0): not moved since, finite, at rest.
            assert_eq!(p.reference_pose(), before);
            assert_eq!(p.feedback().velocities, vec![0.0; 3]);
        }
        // A car-like chassis at 1e308 everywhere: steering held to ±90° (the inner wheel at
        // δ_max = 70°: L / tan 70° = 0.218 m < B/2 = 0.31 m), wheels to 7.5 rad/s.
        let mut p = plant(ChassisConfig::mobil2(), 0.05, 0.0);
        let huge = WheelState::from_values(ChassisModel::CarLike, &[1e308, -1e308, 1e308, 1e308]).unwrap();
        assert_eq!(p.command(&huge), Ok(CommandOutcome::Limited));
        let max = std::f64::consts::FRAC_PI_2;
        assert_eq!(p.commanded(), &[max, -max, 7.5, 7.5]);
        for _ in 0..1000 {
            p.step(0.005, &empty());
            assert!(p.reference_pose().iter().all(|v| v.is_finite()));
            assert!(p.reference_twist().vx.abs() <= 0.75 + 1e-12);
        }
    }

    #[test]
    fn a_long_step_cannot_jump_through_a_thin_wall() {
        // A 1 cm wall at x = 1; the omni robot (radius 0.1) at 0.6 m/s would cross it in one
        // 1 s step (0.6 → 1.2), but the collision is checked every 5 ms.
        let world = World {
            obstacles: vec![Obstacle::Polygon {
                points: vec![[1.0, -5.0], [1.01, -5.0], [1.01, 5.0], [1.0, 5.0]],
            }],
        };
        let mut p = plant_with(ChassisParams::omr3(), 0.0, 0.0, 0.1);
        for _ in 0..5 {
            p.command(&WheelState::Omni {
                wheels: [12.0, -6.0, -6.0],
            })
            .unwrap();
            p.step(1.0, &world);
        }
        let x = p.reference_pose().x;
        assert!(p.collided());
        assert!(x > 0.89 && x <= 0.9, "{x}");
        // Steps that are not finite, not positive or too long do nothing.
        for dt in [f64::NAN, f64::INFINITY, -1.0, 0.0, 1e308] {
            p.step(dt, &world);
            assert_eq!(p.reference_pose().x, x);
        }
    }

    #[test]
    fn steering_keeps_settling_while_the_robot_stands_at_a_wall() {
        // The tricycle (radius 0.3) starts 10 µm short of a wall at x = 0.30001 and is told to
        // steer to 30° and drive at 5 rad/s, with τ = 0.1 s. Its first 5 ms sub-step already
        // moves it about 6·10⁻⁵ m ahead, into the wall, so it stays at the origin; the steering
        // motor keeps turning for the whole step all the same: after one 0.1 s step it is at
        // 30°·(1 − e⁻¹) = 18.9636° (0.3309776 rad), not at the 30°·(1 − e^(−0.05)) = 1.46° of
        // the first sub-step; after a second step, 30°·(1 − e⁻²) = 25.9399° (0.4527374 rad).
        let world = World {
            obstacles: vec![Obstacle::Polygon {
                points: vec![[0.30001, -5.0], [0.4, -5.0], [0.4, 5.0], [0.30001, 5.0]],
            }],
        };
        let mut p = plant_with(ChassisParams::tricycle(), 0.1, 0.0, 0.3);
        let command = WheelState::from_values(ChassisModel::Tricycle, &[30f64.to_radians(), 5.0]).unwrap();
        p.command(&command).unwrap();
        p.step(0.1, &world);
        assert!(p.collided());
        assert_eq!(p.reference_pose(), Vector3::zeros());
        assert_relative_eq!(p.feedback().positions[0], 0.330_977_551, epsilon = 1e-9);
        // Stalled: the wheel stands, and the body with it.
        assert_eq!(p.feedback().velocities[1], 0.0);
        assert_eq!(p.reference_twist(), BodyTwist::ZERO);
        p.command(&command).unwrap();
        p.step(0.1, &world);
        assert_eq!(p.reference_pose(), Vector3::zeros());
        assert_relative_eq!(p.feedback().positions[0], 0.452_737_387, epsilon = 1e-9);
    }

    proptest::proptest! {
        /// Two independently written models agree: the plant's least squares, fed the wheels
        /// the chassis' inverse kinematics commands for a feasible twist, returns that twist
        /// with no slip (omni: any twist; car-like and tricycle: v ≠ 0, no sideways part).
        #[test]
        fn plant_recovers_every_twist_the_chassis_commands(
            v in -0.5f64..0.5, vy in -0.5f64..0.5, w in -1.0f64..1.0, k in -1.0f64..1.0
        ) {
            let omni = ChassisParams::omr3();
            let s = twist_of(&omni, &inverse(&omni, BodyTwist::new(v, vy, w)).values());
            proptest::prop_assert!((s.twist.vx - v).abs() < 1e-9 && (s.twist.vy - vy).abs() < 1e-9);
            proptest::prop_assert!((s.twist.wz - w).abs() < 1e-9 && s.slip_residual < 1e-9);
            proptest::prop_assume!(v.abs() > 0.01);
            for params in [ChassisParams::mobil2(), ChassisParams::tricycle()] {
                // A curvature within the chassis' limit: ω = k·v·κ_max.
                let w = k * v * params.max_curvature();
                let s = twist_of(&params, &inverse(&params, BodyTwist::new(v, 0.0, w)).values());
                proptest::prop_assert!((s.twist.vx - v).abs() < 1e-9, "{:?} {:?}", params.model(), s);
                proptest::prop_assert!(s.twist.vy.abs() < 1e-9 && (s.twist.wz - w).abs() < 1e-9);
                proptest::prop_assert!(s.slip_residual < 1e-9);
            }
        }
    }

    #[test]
    fn a_command_for_another_model_changes_nothing() {
        let mut p = plant(ChassisConfig::omr3(), 0.0, 0.0);
        p.command(&WheelState::Omni {
            wheels: [6.0, -3.0, -3.0],
        })
        .unwrap();
        let err = p.command(&WheelState::zero(ChassisModel::CarLike));
        assert!(matches!(err, Err(PlantError::ModelMismatch { .. })));
        assert_eq!(p.commanded(), &[6.0, -3.0, -3.0]);
        assert!(WheelGeometry::new(&ChassisParams::omr3()).body_twist(&[1.0]).is_err());
    }
}
