//! Quadruped free-gait planning by best-first search (SPEC §7; Ondroušek & Březina, source 000).
//! ROS-free: no ROS types, no clock, no I/O (`tests/check_ros_free.sh` proves it). The start
//! state, the goal, the rule set and the evaluation are the input; a plan of states, each made
//! by one named rule, is the output, field for field `mobil_msgs/GaitPlan`. `gait_node` wires it
//! to topics and services.
//!
//! - [`model`]: the robot (body a × b, hips, annular-sector workspaces, the leg-angle
//!   reading), static stability, and the largest body rotation / translation that keeps every
//!   foot in its workspace along the whole motion.
//! - [`rules`]: the 27 production rules, each a named function.
//! - [`search`]: algorithm A, generic over the problem.
//! - [`planner`]: the gait problem (rules, evaluations (1)–(3), key, goal) and [`plan`].
//! - [`horizon`]: short-time plans, [`RecedingHorizon`].
//! - [`config`]: [`GaitConfig`], every default justified; `params/quadruped.yaml` holds them.

#![warn(missing_docs)]

pub mod config;
pub mod error;
pub mod horizon;
pub mod model;
pub mod planner;
pub mod rules;
pub mod search;

pub use config::{Evaluation, GaitConfig, RuleSet, Weights};
pub use error::GaitError;
pub use horizon::{Chunk, RecedingHorizon, Walk};
pub use model::{is_stable, is_supported, BodyPose, GaitState, LegAngleReading, QuadrupedModel, Workspace};
pub use planner::{plan, GaitProblem, Plan, PlanFailure, PlanStep};
pub use rules::{dev, vzd, Rule};
