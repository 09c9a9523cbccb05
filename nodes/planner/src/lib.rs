//! HIGH-LEVEL planning of the mobil suite (SPEC §3–4; dissertation 004 §3.4, §4.2.1–4.2.3),
//! ROS-free: no ROS types, no clock, no I/O (`tests/check_ros_free.sh` proves it). Poses and
//! times are inputs; commands, phases and reports are outputs. `planner_node` wires it to topics.
//!
//! - [`docking`]: the Lyapunov docking law (eq. 3.41–3.48), its gains, V and V̇, chassis limits
//!   by one common factor, and [`DockingController`] (approach → in-place rotation → docked, or
//!   failed on a time limit, on V no longer falling, or with a heading residual on a chassis
//!   that cannot turn in place).
//! - [`sim`]: continuous-time integration of a docking (RK4 sub-steps on the closed loop).
//! - [`mod@approach`]: the goal approach without final heading for a steered chassis (δ within
//!   δ_eff, atan2, progress stop only within steering reach, Z_crit) and the shortest step.
//! - [`route`]: the route pre-check — a virtual robot drives the route on the chassis model
//!   against a [`mobil_sim::world::World`] and reports every collision, turn below the minimum
//!   radius and unreachable waypoint with its index.

#![warn(missing_docs)]

pub mod approach;
pub mod docking;
pub mod error;
pub mod route;
pub mod sim;

pub use approach::{
    approach, approach_step, approach_with, shortest_step, ApproachConfig, ApproachEnd, ApproachRun, ApproachStep,
    Motion, ShortestStep, Steering,
};

pub use docking::{
    polar_error, sinc, wrap_alpha, DockingConfig, DockingController, DockingFailure, DockingGains, DockingOutput,
    DockingPhase, Finish, GainWarning, PolarError, Velocity, VelocityLimits,
};
pub use error::PlannerError;
pub use route::{arc_radius, check_route, ProblemKind, RouteCheckConfig, RouteProblem, RouteReport, UnreachableCause};
pub use sim::{advance, rk4_step, simulate_docking, DockingRun, DockingSample, Kinematics};
