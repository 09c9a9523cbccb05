//! Body twist ↔ wheel state for each chassis model (SPEC §1; 004 §3.1–3.3).
//!
//! [`inverse`] maps a [`BodyTwist`] at the kinematic origin to wheel commands; [`forward`] maps
//! wheel feedback back to the twist. They are exact inverses of each other for feasible twists
//! (for the tricycle and the car-like chassis: `vy = 0`; `v = 0` only with `ω = 0`). Make a
//! request feasible first with [`crate::clamp_command`].
//!
//! # Joint layout
//!
//! | model | joints, in this order ([`ChassisModel::joints`]) |
//! |---|---|
//! | tricycle | `steering` (δ, rad), `traction` (front wheel, rad/s) |
//! | car-like | `front_left_steering`, `front_right_steering` (rad), `rear_left_wheel`, `rear_right_wheel` (rad/s) |
//! | omni | `wheel_1`, `wheel_2`, `wheel_3` (rad/s), rolling directions 0°, 120°, 240° |
//!
//! Steering joints carry a position (the angle, positive = turning left); wheel joints carry a
//! velocity (positive = driving the robot forward along the wheel's rolling direction).

use mobil_geom::Pose2;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::error::ChassisError;
use crate::model::{ChassisModel, ChassisParams};

/// Body-frame velocity at the kinematic origin: `vx` forward, `vy` left (m/s), `wz` yaw rate (rad/s).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct BodyTwist {
    /// Forward velocity v_u (m/s).
    pub vx: f64,
    /// Leftward velocity v_w (m/s); omni only, 0 for a feasible non-holonomic twist.
    pub vy: f64,
    /// Yaw rate ϑ̇ (rad/s), counter-clockwise positive.
    pub wz: f64,
}

impl BodyTwist {
    /// The zero twist (stop).
    pub const ZERO: Self = Self::new(0.0, 0.0, 0.0);

    /// A twist from its components.
    pub const fn new(vx: f64, vy: f64, wz: f64) -> Self {
        Self { vx, vy, wz }
    }

    /// True if all three components are finite.
    pub fn is_finite(&self) -> bool {
        self.vx.is_finite() && self.vy.is_finite() && self.wz.is_finite()
    }

    /// `[vx, vy, wz]` as a vector.
    pub fn as_vector(&self) -> Vector3<f64> {
        Vector3::new(self.vx, self.vy, self.wz)
    }

    /// A twist from `[vx, vy, wz]`.
    pub fn from_vector(v: &Vector3<f64>) -> Self {
        Self::new(v.x, v.y, v.z)
    }

    /// All three components multiplied by `k`.
    pub fn scaled(self, k: f64) -> Self {
        Self::new(k * self.vx, k * self.vy, k * self.wz)
    }
}

/// What a joint carries: a steering angle (position) or a wheel speed (velocity).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum JointKind {
    /// Steering angle δ (rad), JointState `position`.
    Steering,
    /// Wheel angular velocity (rad/s), JointState `velocity`.
    Wheel,
}

/// One joint of the chassis: default name and kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Joint {
    /// Default joint name.
    pub name: &'static str,
    /// Steering or wheel.
    pub kind: JointKind,
}

const fn joint(name: &'static str, kind: JointKind) -> Joint {
    Joint { name, kind }
}

/// Tricycle joints: steering δ of the front wheel, then the driven front wheel.
pub const TRICYCLE_JOINTS: [Joint; 2] = [
    joint("steering", JointKind::Steering),
    joint("traction", JointKind::Wheel),
];

/// Car-like (MOBIL-II) joints: two steered front wheels, then the two driven rear wheels.
pub const CAR_LIKE_JOINTS: [Joint; 4] = [
    joint("front_left_steering", JointKind::Steering),
    joint("front_right_steering", JointKind::Steering),
    joint("rear_left_wheel", JointKind::Wheel),
    joint("rear_right_wheel", JointKind::Wheel),
];

/// Omni (OMR-III) joints: wheels with rolling directions θ = 0°, 120°, 240°.
pub const OMNI_JOINTS: [Joint; 3] = [
    joint("wheel_1", JointKind::Wheel),
    joint("wheel_2", JointKind::Wheel),
    joint("wheel_3", JointKind::Wheel),
];

/// `(cos θ_i, sin θ_i)` of the omni rolling directions θ_i = 0°, 120°, 240° (SPEC §1).
pub const OMNI_ROLLING_DIRECTIONS: [(f64, f64); 3] = [(1.0, 0.0), (-0.5, SQRT_3_2), (-0.5, -SQRT_3_2)];

/// √3 / 2.
const SQRT_3_2: f64 = 0.866_025_403_784_438_6;

impl ChassisModel {
    /// The model's joints in [`WheelState::values`] order.
    pub fn joints(self) -> &'static [Joint] {
        match self {
            Self::Tricycle => &TRICYCLE_JOINTS,
            Self::CarLike => &CAR_LIKE_JOINTS,
            Self::Omni => &OMNI_JOINTS,
        }
    }
}

/// Wheel-level state of one chassis: commands from [`inverse`], or feedback for [`forward`].
///
/// Angles in rad (positive = steering left), wheel speeds in rad/s.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum WheelState {
    /// Tricycle: steered and driven front wheel.
    Tricycle {
        /// Steering angle δ (rad).
        steering: f64,
        /// Front (traction) wheel speed (rad/s); its ground speed is v / cos δ.
        traction: f64,
    },
    /// Car-like (MOBIL-II): Ackermann front steering, driven rear wheels.
    CarLike {
        /// Front-left steering angle δ_l (rad).
        front_left_steering: f64,
        /// Front-right steering angle δ_r (rad).
        front_right_steering: f64,
        /// Rear-left wheel speed (rad/s).
        rear_left: f64,
        /// Rear-right wheel speed (rad/s).
        rear_right: f64,
    },
    /// Omni (OMR-III): speeds ω_1..ω_3 (rad/s) of the wheels rolling at 0°, 120°, 240°.
    Omni {
        /// Wheel speeds (rad/s).
        wheels: [f64; 3],
    },
}

impl WheelState {
    /// All joints at rest and straight.
    pub fn zero(model: ChassisModel) -> Self {
        match model {
            ChassisModel::Tricycle => Self::Tricycle {
                steering: 0.0,
                traction: 0.0,
            },
            ChassisModel::CarLike => Self::CarLike {
                front_left_steering: 0.0,
                front_right_steering: 0.0,
                rear_left: 0.0,
                rear_right: 0.0,
            },
            ChassisModel::Omni => Self::Omni { wheels: [0.0; 3] },
        }
    }

    /// The same steering angles with every driven wheel at rest: a stop that starts no
    /// steering motion.
    pub fn stopped(&self) -> Self {
        match *self {
            Self::Tricycle { steering, .. } => Self::Tricycle {
                steering,
                traction: 0.0,
            },
            Self::CarLike {
                front_left_steering,
                front_right_steering,
                ..
            } => Self::CarLike {
                front_left_steering,
                front_right_steering,
                rear_left: 0.0,
                rear_right: 0.0,
            },
            Self::Omni { .. } => Self::Omni { wheels: [0.0; 3] },
        }
    }

    /// True if every joint value is finite.
    pub fn is_finite(&self) -> bool {
        let (array, len) = self.value_array();
        array[..len].iter().all(|v| v.is_finite())
    }

    /// The model this state belongs to.
    pub fn model(&self) -> ChassisModel {
        match self {
            Self::Tricycle { .. } => ChassisModel::Tricycle,
            Self::CarLike { .. } => ChassisModel::CarLike,
            Self::Omni { .. } => ChassisModel::Omni,
        }
    }

    /// Joint values in the order of [`ChassisModel::joints`].
    pub fn values(&self) -> Vec<f64> {
        let (array, len) = self.value_array();
        array[..len].to_vec()
    }

    /// Joint values in [`ChassisModel::joints`] order, padded to 4, and their count.
    fn value_array(&self) -> ([f64; 4], usize) {
        match *self {
            Self::Tricycle { steering, traction } => ([steering, traction, 0.0, 0.0], 2),
            Self::CarLike {
                front_left_steering,
                front_right_steering,
                rear_left,
                rear_right,
            } => ([front_left_steering, front_right_steering, rear_left, rear_right], 4),
            Self::Omni { wheels: [a, b, c] } => ([a, b, c, 0.0], 3),
        }
    }

    /// Parses joint values given in the order of [`ChassisModel::joints`]; refuses a wrong
    /// count or a non-finite value.
    pub fn from_values(model: ChassisModel, values: &[f64]) -> Result<Self, ChassisError> {
        let joints = model.joints();
        if values.len() != joints.len() {
            return Err(ChassisError::JointCount {
                model,
                expected: joints.len(),
                got: values.len(),
            });
        }
        for (joint, &value) in joints.iter().zip(values) {
            if !value.is_finite() {
                return Err(ChassisError::NonFiniteJoint {
                    joint: joint.name,
                    value,
                });
            }
        }
        // Indexing is in bounds: the length matched the model's joint count above.
        Ok(match model {
            ChassisModel::Tricycle => Self::Tricycle {
                steering: values[0],
                traction: values[1],
            },
            ChassisModel::CarLike => Self::CarLike {
                front_left_steering: values[0],
                front_right_steering: values[1],
                rear_left: values[2],
                rear_right: values[3],
            },
            ChassisModel::Omni => Self::Omni {
                wheels: [values[0], values[1], values[2]],
            },
        })
    }

    /// Largest |wheel speed| (rad/s) over the driven wheels.
    pub fn max_abs_wheel_speed(&self) -> f64 {
        match *self {
            Self::Tricycle { traction, .. } => traction.abs(),
            Self::CarLike {
                rear_left, rear_right, ..
            } => rear_left.abs().max(rear_right.abs()),
            Self::Omni { wheels } => wheels.iter().fold(0.0, |m, w| m.max(w.abs())),
        }
    }

    fn check_finite(&self) -> Result<(), ChassisError> {
        let (array, len) = self.value_array();
        for (joint, &value) in self.model().joints().iter().zip(&array[..len]) {
            if !value.is_finite() {
                return Err(ChassisError::NonFiniteJoint {
                    joint: joint.name,
                    value,
                });
            }
        }
        Ok(())
    }
}

/// Ackermann angles (δ_l, δ_r) for a virtual centre steering angle with tan δ_c = `tan_delta_c`:
/// tan δ_l = L/(R − B/2), tan δ_r = L/(R + B/2) with R = L / tan δ_c (004 §3.2).
///
/// Written in tan δ_c so that straight ahead (tan δ_c = 0) has no singularity.
pub fn ackermann_angles(wheelbase: f64, track: f64, tan_delta_c: f64) -> (f64, f64) {
    let k = 0.5 * track / wheelbase;
    (
        tan_delta_c.atan2(1.0 - k * tan_delta_c),
        tan_delta_c.atan2(1.0 + k * tan_delta_c),
    )
}

/// tan δ_c recovered from both Ackermann angles: the mean of the two single-wheel estimates
/// tan δ_l / (1 + k·tan δ_l) and tan δ_r / (1 − k·tan δ_r), k = B/(2L); exact for a consistent pair.
pub fn ackermann_centre_tan(wheelbase: f64, track: f64, delta_left: f64, delta_right: f64) -> f64 {
    let k = 0.5 * track / wheelbase;
    let tl = delta_left.tan();
    let tr = delta_right.tan();
    0.5 * (tl / (1.0 + k * tl) + tr / (1.0 - k * tr))
}

/// Inverse kinematics: wheel commands for a twist at the kinematic origin.
///
/// - Tricycle, eq. (3.4) of 004 §3.1 in the SPEC's form: δ = atan(L·ω / v), traction
///   ground speed v / cos δ (sign of v).
/// - Car-like, 004 §3.2: Ackermann steering for tan δ_c = L·ω / v, rear wheels (v ∓ ω·B/2) / r.
/// - Omni, SPEC §1 Decision: r·ω_i = cos θ_i·v_u + sin θ_i·v_w + R·ϑ̇.
///
/// For the tricycle and the car-like chassis `vy` is ignored, and `v = 0` gives straight,
/// stopped wheels whatever ω (turning in place is infeasible; see [`pre_steer`]).
pub fn inverse(params: &ChassisParams, twist: BodyTwist) -> WheelState {
    let r = params.wheel_radius();
    let BodyTwist { vx: v, vy, wz: w } = twist;
    match params.model() {
        ChassisModel::Tricycle => {
            if v == 0.0 {
                return WheelState::zero(ChassisModel::Tricycle);
            }
            let lw = params.wheelbase() * w;
            WheelState::Tricycle {
                steering: (lw / v).atan(),
                traction: v.signum() * v.hypot(lw) / r,
            }
        }
        ChassisModel::CarLike => {
            if v == 0.0 {
                return WheelState::zero(ChassisModel::CarLike);
            }
            let (l, b) = (params.wheelbase(), params.track());
            let (front_left_steering, front_right_steering) = ackermann_angles(l, b, l * w / v);
            WheelState::CarLike {
                front_left_steering,
                front_right_steering,
                rear_left: (v - 0.5 * b * w) / r,
                rear_right: (v + 0.5 * b * w) / r,
            }
        }
        ChassisModel::Omni => {
            let rw = params.omni_wheel_distance() * w;
            let wheel = |(c, s): (f64, f64)| (c * v + s * vy + rw) / r;
            WheelState::Omni {
                wheels: OMNI_ROLLING_DIRECTIONS.map(wheel),
            }
        }
    }
}

/// Forward kinematics: the twist at the kinematic origin from wheel feedback.
///
/// - Tricycle, 004 §3.1: front ground speed u = r·ω_t, v = u·cos δ, ϑ̇ = u·sin δ / L.
/// - Car-like, 004 §3.2: v = mean rear ground speed, ϑ̇ = v·tan δ_c / L with δ_c from both
///   steering angles ([`ackermann_centre_tan`]).
/// - Omni, exact inverse of the SPEC §1 Decision: v_u = ⅔·r·Σ cos θ_i·ω_i,
///   v_w = ⅔·r·Σ sin θ_i·ω_i, ϑ̇ = r·Σω_i / (3R).
///
/// Refuses a wheel state of another model or with a non-finite value.
pub fn forward(params: &ChassisParams, wheels: &WheelState) -> Result<BodyTwist, ChassisError> {
    if wheels.model() != params.model() {
        return Err(ChassisError::ModelMismatch {
            expected: params.model(),
            got: wheels.model(),
        });
    }
    wheels.check_finite()?;
    let r = params.wheel_radius();
    Ok(match *wheels {
        WheelState::Tricycle { steering, traction } => {
            let u = r * traction;
            BodyTwist::new(u * steering.cos(), 0.0, u * steering.sin() / params.wheelbase())
        }
        WheelState::CarLike {
            front_left_steering,
            front_right_steering,
            rear_left,
            rear_right,
        } => {
            let l = params.wheelbase();
            let v = 0.5 * r * (rear_left + rear_right);
            let t = ackermann_centre_tan(l, params.track(), front_left_steering, front_right_steering);
            BodyTwist::new(v, 0.0, v * t / l)
        }
        WheelState::Omni { wheels } => {
            let (mut su, mut sw, mut sum) = (0.0, 0.0, 0.0);
            for ((c, s), w) in OMNI_ROLLING_DIRECTIONS.into_iter().zip(wheels) {
                su += c * w;
                sw += s * w;
                sum += w;
            }
            BodyTwist::new(
                2.0 * r * su / 3.0,
                2.0 * r * sw / 3.0,
                r * sum / (3.0 * params.omni_wheel_distance()),
            )
        }
    })
}

/// Stopped wheels steered to the virtual centre angle `delta_c` (Ackermann for the car-like
/// chassis): turns the wheels toward a request that was infeasible at v = 0. Omni: all zero.
pub fn pre_steer(params: &ChassisParams, delta_c: f64) -> WheelState {
    match params.model() {
        ChassisModel::Tricycle => WheelState::Tricycle {
            steering: delta_c,
            traction: 0.0,
        },
        ChassisModel::CarLike => {
            let (front_left_steering, front_right_steering) =
                ackermann_angles(params.wheelbase(), params.track(), delta_c.tan());
            WheelState::CarLike {
                front_left_steering,
                front_right_steering,
                rear_left: 0.0,
                rear_right: 0.0,
            }
        }
        ChassisModel::Omni => WheelState::zero(ChassisModel::Omni),
    }
}

/// Twist of the reference point `d` ahead, from the twist at the origin: vy += ω·d (cf. eq. 3.12).
pub fn twist_at_reference(twist_at_origin: BodyTwist, d: f64) -> BodyTwist {
    BodyTwist::new(
        twist_at_origin.vx,
        twist_at_origin.vy + twist_at_origin.wz * d,
        twist_at_origin.wz,
    )
}

/// Twist at the origin from the twist of the reference point `d` ahead: vy −= ω·d.
pub fn twist_at_origin(twist_at_reference: BodyTwist, d: f64) -> BodyTwist {
    BodyTwist::new(
        twist_at_reference.vx,
        twist_at_reference.vy - twist_at_reference.wz * d,
        twist_at_reference.wz,
    )
}

/// Pose `[x, y, ϑ]` of the reference point: the origin pose moved by Rot(ϑ)·[d, 0] (SPEC §1).
pub fn pose_at_reference(pose_of_origin: &Vector3<f64>, d: f64) -> Vector3<f64> {
    Pose2 {
        x: pose_of_origin.x,
        y: pose_of_origin.y,
        yaw: pose_of_origin.z,
    }
    .ahead(d)
    .to_vector()
}

/// Pose `[x, y, ϑ]` of the origin from the pose of the reference point `d` ahead.
pub fn pose_at_origin(pose_of_reference: &Vector3<f64>, d: f64) -> Vector3<f64> {
    pose_at_reference(pose_of_reference, -d)
}
