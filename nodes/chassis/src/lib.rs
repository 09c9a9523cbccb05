//! LOW-LEVEL chassis method of the mobil suite (SPEC §1; dissertation 004 §3.1–3.3, §4.1).
//!
//! Pure algorithm core: no ROS types, no clock, no I/O, and no ROS dependency at all
//! (`tests/check_ros_free.sh` proves it). Time is always an input (`dt` or a timestamp in
//! seconds), so tests and replays are deterministic. Angles wrap with [`mobil_geom::wrap`].
//! `chassis_node` (crate `mobil_chassis_node`) wires this library to topics.
//!
//! - [`model`]: [`ChassisModel`] (tricycle, car-like MOBIL-II, omni OMR-III) and validated
//!   [`ChassisParams`], with presets and the effective steering limit δ_eff.
//! - [`kinematics`]: [`BodyTwist`] ↔ [`WheelState`] (inverse / forward) per model, the joint
//!   layout, and the reference-point shift (pose and twist at the point `d` ahead).
//! - [`limits`]: [`clamp_command`] makes any requested twist feasible and says why it changed it.
//! - [`odometry`]: [`Odometry`], exact arc integration with pose and twist covariance.
//! - [`watchdog`]: [`InputTimeout`], the timeout the safety gate applies to an input's age.
//! - [`joints`]: the `sensor_msgs/JointState` layout of wheel commands and feedback, parsed once.
//! - [`controller`]: [`ChassisController`], the LOW-LEVEL loop (limits, watchdogs, odometry)
//!   that `chassis_node` wraps, with the one safety gate every wheel command comes out of.
//!
//! Frames: the *kinematic origin* is the rear-axle midpoint for the tricycle and the car-like
//! chassis, and the centre for the omni chassis. The *reference point* (published as `base_link`)
//! sits `reference_offset` (d) ahead of the origin along body x.
//!
//! ```
//! use mobil_chassis::{clamp_command, inverse, BodyTwist, ChassisParams, Odometry, OdometryNoise};
//!
//! let params = ChassisParams::mobil2();
//! // Turning in place is infeasible for a car: the command is clamped and logged.
//! let clamped = clamp_command(&params, BodyTwist::new(0.0, 0.0, 0.5));
//! assert_eq!(clamped.twist, BodyTwist::default());
//! let wheels = inverse(&params, BodyTwist::new(0.4, 0.0, 0.2));
//! assert_eq!(wheels.values().len(), 4);
//!
//! let mut odom = Odometry::new(params.reference_offset(), OdometryNoise::default()).unwrap();
//! odom.update(BodyTwist::new(0.5, 0.0, 0.0), 1.0).unwrap();
//! assert!((odom.pose().x - 0.5).abs() < 1e-12);
//! ```

#![warn(missing_docs)]

pub mod controller;
pub mod error;
pub mod health;
pub mod joints;
pub mod kinematics;
pub mod limits;
pub mod model;
pub mod odometry;
pub mod watchdog;

pub use controller::{ChassisController, Command, ControllerConfig, FeedbackOutcome, GatedCommand, Safety};
pub use error::{ChassisError, OdometryError};
pub use joints::{FeedbackDecoder, FeedbackSample};
pub use kinematics::{forward, inverse, pre_steer, BodyTwist, Joint, JointKind, WheelState};
pub use limits::{clamp_at_reference, clamp_command, ClampReason, ClampReasons, Clamped};
pub use model::{ChassisConfig, ChassisModel, ChassisParams};
pub use odometry::{Odometry, OdometryNoise};
pub use watchdog::InputTimeout;
