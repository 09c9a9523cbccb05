//! Shared ROS 2 plumbing of the mobil node suite.
//!
//! Every executable (`chassis_node`, `sim_node`, …) is a thin shell around a ROS-free library;
//! this crate is the shell's common part:
//! - [`args`]: `--ros-args` with `--params-file`, `-p`, `-r` (incl. `__ns`, `__node`), `--log-level`;
//! - [`params`]: typed parameter declarations, ROS 2 YAML parameter files, validation;
//! - [`node`]: the node itself — DDS domain from `ROS_DOMAIN_ID`, the standard parameter
//!   services (list/get/set/describe) with validation, name resolution and remapping, clean
//!   shutdown on SIGINT/SIGTERM;
//! - [`qos`]: the QoS presets of the interface contract;
//! - [`log`]: `tracing` set-up and rate-limited warnings;
//! - [`time`]: message stamps; [`geometry`]: planar poses in messages;
//! - [`action`]: an action server with one active goal, for a node's main loop.

pub mod action;
pub mod args;
pub mod geometry;
pub mod log;
pub mod names;
pub mod node;
pub mod params;
pub mod qos;
pub mod time;

pub use args::RosArgs;
pub use log::LogThrottle;
pub use node::{run_node, shutdown_signal, NodeBody, NodeDecl, RosNode};
pub use params::{ParamSpec, ParamValues};
