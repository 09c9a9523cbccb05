//! A humanoid's forward step evolved by a genetic algorithm (SPEC §8; Chikishev and Sizikov,
//! source 003): a Nao's ten leg servos as piecewise-linear functions of time, five crossovers,
//! the source's mutation, roulette selection, best-N replacement and parallel, reproducible
//! evaluation. ROS-free: no ROS types, no clock (`tests/check_ros_free.sh` proves it); the
//! fitness comes from an [`Evaluator`] (a physics simulation, an external simulator) supplied by
//! the caller.
//!
//! - [`model`]: the servos in the SPEC's order with Table 1's limits and Webots' joint names,
//!   [`NaoModel`] (standing pose, step time T), [`Individual`] (10 × 21 knots) and its angles at
//!   any time, sampled every 40 ms.
//! - [`operators`]: [`blx`] (standard and the source's single draw), [`arithmetic`],
//!   [`one_point`], [`geometric`], [`linear_candidates`], [`mutate`].
//! - [`selection`]: [`roulette`], [`choose_operator`], [`replace_best`].
//! - [`evaluate`]: [`Evaluation`], [`Evaluator`], [`evaluate_all`] over the cores, and
//!   [`TestLandscape`], an analytic **test** evaluator (not physics) for tests and benchmarks.
//! - [`config`]: [`GaConfig`], [`FitnessConfig`], every default justified; `params/nao_step.yaml`
//!   holds the same values.
//!
//! Choices beyond the SPEC (its Decisions are implemented as written):
//! - **Standing pose and T** (SPEC: a documented choice): knees 0.8 rad, hip and ankle pitch
//!   −0.4 rad, rolls 0 (torso upright over flat feet, servos off their limits); T = 2.0 s, a
//!   whole number of 40 ms rows. See [`NaoModel`].
//! - **Distinct parents**: a crossover's second parent can be drawn by roulette among the others
//!   ([`roulette_excluding`]), so an individual is never crossed with itself.
//! - **All-zero fitness**: the roulette then chooses uniformly.
//! - **Bad fitness**: an evaluation with a negative or non-finite fitness counts as 0
//!   ([`Evaluation::sanitised`]).
//! - **Linear crossover**: of its three candidates the best two by fitness are kept
//!   ([`best_two_of_three`]). Extrapolated candidates are clamped into the limits.
//! - **Clamping and pinning**: every operator clamps knots into the servo limits and keeps the
//!   first and last knots at the standing pose (BLX-α and the linear crossover can leave the
//!   range; the others only by rounding). Mutation clamps each moved knot at once, so a knot
//!   picked twice moves from its clamped value. Its per-knot amount is (−1/6, 1/6], as the
//!   source's `(0.5 − u)/3`.
//! - **One-point cut**: over the 190 inner knots (the pinned ends are equal in both parents),
//!   uniform in 1 … 189, so each child has knots of both parents.
//! - **Fitness constants** (SPEC: e.g. f = t_fall/T_sim + w·max(0, Δx)): T_sim = T + 1 s,
//!   w = 2 /m, a fall is the torso below 0.20 m or tilted beyond 0.5 rad; a "forward step" is no
//!   fall and Δx ≥ 0.04 m. See [`FitnessConfig`].
//! - **Parallelism**: `std::thread::scope` with an atomic work counter, not rayon; results are
//!   stored by index, so they never depend on the thread count (see [`evaluate`]).

#![warn(missing_docs)]

pub mod config;
pub mod error;
pub mod evaluate;
pub mod model;
pub mod operators;
pub mod selection;

pub use config::{BlxVariant, Crossover, FitnessConfig, GaConfig};
pub use error::GaError;
pub use evaluate::{evaluate_all, resolve_threads, Evaluation, Evaluator, TestLandscape};
pub use model::{joint_names, Individual, NaoModel, Servo, INTERVALS, KNOTS, SERVO_COUNT};
pub use operators::{
    arithmetic, best_two_of_three, blx, blx_value, geometric, linear_candidates, mutate, one_point, one_point_at,
    MutationPick,
};
pub use selection::{choose_operator, replace_best, roulette, roulette_excluding, Operator, Scored};
