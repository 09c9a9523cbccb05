//! Error types: [`ChassisError`] for parameters and wheel data, [`OdometryError`] for updates.

use crate::kinematics::BodyTwist;
use crate::model::ChassisModel;

/// A refused parameter, model name or wheel-state value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ChassisError {
    /// The model name is not one of `tricycle`, `car_like`, `omni`.
    #[error("unknown chassis model {0:?}: expected \"tricycle\", \"car_like\" or \"omni\"")]
    UnknownModel(String),
    /// A parameter value is out of its domain.
    #[error("parameter `{name}` = {value} refused: {reason}")]
    InvalidParameter {
        /// Parameter name as in [`crate::ChassisConfig`] / [`crate::OdometryNoise`].
        name: &'static str,
        /// The refused value.
        value: f64,
        /// Why it was refused.
        reason: &'static str,
    },
    /// A joint vector has the wrong length for the model.
    #[error("{model} chassis has {expected} joints, got {got} values")]
    JointCount {
        /// The chassis model.
        model: ChassisModel,
        /// Joints the model has.
        expected: usize,
        /// Values received.
        got: usize,
    },
    /// A joint value is NaN or infinite.
    #[error("joint `{joint}` value {value} is not finite")]
    NonFiniteJoint {
        /// Joint name (see [`crate::ChassisModel::joints`]).
        joint: &'static str,
        /// The refused value.
        value: f64,
    },
    /// A wheel state of one model was given to parameters of another.
    #[error("wheel state is for a {got} chassis, the parameters are for {expected}")]
    ModelMismatch {
        /// Model of the parameters.
        expected: ChassisModel,
        /// Model of the wheel state.
        got: ChassisModel,
    },
}

/// A refused odometry update; the odometry state is unchanged.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OdometryError {
    /// `dt` is NaN or infinite.
    #[error("dt = {0} s is not finite")]
    NonFiniteDt(f64),
    /// `dt` is zero or negative.
    #[error("dt = {0} s is not positive")]
    NonPositiveDt(f64),
    /// A twist component is NaN or infinite.
    #[error("twist {0:?} is not finite")]
    NonFiniteTwist(BodyTwist),
    /// A timestamp is NaN or infinite.
    #[error("timestamp {0} s is not finite")]
    NonFiniteTime(f64),
    /// The update would make the pose or its covariance non-finite (an absurd, if finite, twist).
    #[error("twist {twist:?} over {dt} s would make the pose or its covariance non-finite")]
    NonFiniteResult {
        /// The refused twist.
        twist: BodyTwist,
        /// Over this interval (s).
        dt: f64,
    },
    /// A pose to restart from is not finite.
    #[error("pose {0:?} is not finite")]
    NonFinitePose([f64; 3]),
    /// A timestamp is not after the previous one (time went backwards or repeated).
    #[error("timestamp {now} s is not after the previous {previous} s")]
    TimeNotIncreasing {
        /// The previous accepted timestamp.
        previous: f64,
        /// The refused timestamp.
        now: f64,
    },
}
