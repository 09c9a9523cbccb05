//! A humanoid's forward step evolved by a genetic algorithm (SPEC §8; Chikishev and Sizikov,
//! source 003): a Nao's ten leg servos as piecewise-linear functions of time. ROS-free: no ROS
//! types, no clock (`tests/check_ros_free.sh` proves it).
//!
//! - [`model`]: the servos in the SPEC's order with Table 1's limits and Webots' joint names,
//!   [`NaoModel`] (standing pose, step time T), [`Individual`] (10 × 21 knots) and its angles at
//!   any time, sampled every 40 ms.
//! - [`config`]: [`GaConfig`], [`FitnessConfig`], every default justified; `params/nao_step.yaml`
//!   holds the same values.
//!
//! Choices beyond the SPEC (its Decisions are implemented as written):
//! - **Standing pose and T** (SPEC: a documented choice): knees 0.8 rad, hip and ankle pitch
//!   −0.4 rad, rolls 0 (torso upright over flat feet, servos off their limits); T = 2.0 s, a
//!   whole number of 40 ms rows. See [`NaoModel`].
//! - **Fitness constants** (SPEC: e.g. f = t_fall/T_sim + w·max(0, Δx)): T_sim = T + 1 s,
//!   w = 2 /m, a fall is the torso below 0.20 m or tilted beyond 0.5 rad; a "forward step" is no
//!   fall and Δx ≥ 0.04 m. See [`FitnessConfig`].

#![warn(missing_docs)]

pub mod config;
pub mod error;
pub mod model;

pub use config::{BlxVariant, Crossover, FitnessConfig, GaConfig};
pub use error::GaError;
pub use model::{joint_names, Individual, NaoModel, Servo, INTERVALS, KNOTS, SERVO_COUNT};
