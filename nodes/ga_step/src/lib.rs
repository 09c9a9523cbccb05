//! A humanoid's forward step evolved by a genetic algorithm (SPEC §8; Chikishev and Sizikov,
//! source 003): a Nao's ten leg servos as piecewise-linear functions of time, five crossovers,
//! the source's mutation, roulette selection, best-N replacement, stop rules, parallel and
//! reproducible evaluation, checkpoints, and the result as a Webots motion file. ROS-free: no
//! ROS types, no clock (`tests/check_ros_free.sh` proves it); the fitness comes from an
//! [`Evaluator`] (a physics simulation, an external simulator) supplied by the caller.
//!
//! - [`model`]: the servos in the SPEC's order with Table 1's limits and Webots' joint names,
//!   [`NaoModel`] (standing pose, step time T), [`Individual`] (10 × 21 knots) and its angles at
//!   any time, sampled every 40 ms.
//! - [`operators`]: [`blx`] (standard and the source's single draw), [`arithmetic`],
//!   [`one_point`], [`geometric`], [`linear_candidates`], [`mutate`].
//! - [`selection`]: [`roulette`], [`choose_operator`], [`replace_best`].
//! - [`evaluate`]: [`Evaluation`], [`Evaluator`], [`evaluate_all`] over the cores, and
//!   [`TestLandscape`], an analytic **test** evaluator (not physics) for tests and benchmarks.
//! - [`ga`]: [`GaState`], the generation loop, statistics, stop rules.
//! - [`checkpoint`]: the state as tagged, versioned JSON, written atomically.
//! - [`output`]: `fitness.csv`, Webots motion files (writer and reader), JointTrajectory YAML,
//!   the names of a run's files.
//! - [`resume`]: whether a checkpoint continues the run asked for ([`check_resume`]).
//! - [`summary`]: how a run ended, [`RunSummary`] and its line.
//! - [`external`]: the ROS-free half of an external simulator's evaluation (its answer's
//!   values, the void score).
//! - [`pool`]: the bookkeeping of a pool of external simulators: which one gets the next
//!   candidate, when a candidate is sent again or void, when the pool gives up.
//! - [`config`]: [`GaConfig`], [`FitnessConfig`], every default justified; `params/nao_step.yaml`
//!   holds the same values.
//! - [`params`]: a parameter file of `params/nao_step.yaml`'s form read into a [`GaSetup`].
//!
//! Choices beyond the SPEC (its Decisions are implemented as written):
//! - **Standing pose and T** (SPEC: a documented choice): knees 0.8 rad, hip and ankle pitch
//!   −0.4 rad, rolls 0 (torso upright over flat feet, servos off their limits); T = 2.0 s, a
//!   whole number of 40 ms rows. See [`NaoModel`].
//! - **Offspring per generation**: as many as the population (100), then the best 100 of the
//!   200. A crossover yields two children; when one slot is left only the first is kept (both
//!   are drawn, so the stream does not depend on it).
//! - **Distinct parents**: a crossover's second parent is drawn by roulette among the others
//!   ([`roulette_excluding`]), so an individual is never crossed with itself.
//! - **All-zero fitness**: the roulette then chooses uniformly.
//! - **Bad fitness**: an evaluation with a negative or non-finite fitness counts as 0 and is
//!   counted in [`GenerationStats::invalid_fitness`].
//! - **Linear crossover**: its three candidates are evaluated with the other offspring (in
//!   parallel) and the best two kept; it costs 3 evaluations per 2 children. Extrapolated
//!   candidates are clamped into the limits.
//! - **Clamping and pinning**: every operator clamps knots into the servo limits and keeps the
//!   first and last knots at the standing pose (BLX-α and the linear crossover can leave the
//!   range; the others only by rounding). Mutation clamps each moved knot at once, so a knot
//!   picked twice moves from its clamped value. Its per-knot amount is (−1/6, 1/6], as the
//!   source's `(0.5 − u)/3`.
//! - **One-point cut**: over the 190 inner knots (the pinned ends are equal in both parents),
//!   uniform in 1 … 189, so each child has knots of both parents.
//! - **Fitness** (SPEC: e.g. f = t_fall/T_sim + w·max(0, Δx); a better reading of that
//!   Decision): a fall scores its time alone, f = t_fall/T_sim (< 1), an upright individual its
//!   signed distance, f = 1 + w·max(0, Δx + b) (≥ 1, b = 1 m), so a fall < any upright
//!   individual ≤ standing still (3) < a forward step, and the best individual is a non-falling
//!   one whenever one exists. With b = 0 every upright individual that does not gain ground
//!   scores 1 (runs bred backward shufflers and stalled there); the SPEC's example shape, under
//!   which forward lunges that fall outscore short upright steps and take over the population,
//!   is the option `distance_on_fall` with b = 0. T_sim = T + 1 s, w = 2 /m, a fall is the torso below
//!   0.20 m or tilted beyond 0.5 rad; a "forward step" is no fall and Δx ≥ 0.04 m. See
//!   [`FitnessConfig`].
//! - **Stop rules**, tested after every generation in this order: the best individual makes a
//!   forward step (`stop_at_step`, default on); the mean fitness rose by less than 0.1 % over
//!   the last 20 generations (under best-N replacement it cannot fall); the requested number of
//!   generations; and the caller's interrupt, between generations. Generation 0 is the evaluated
//!   initial population, so a run to G generations has G + 1 rows of history.
//! - **Reproducibility**: one ChaCha8 generator per run seeded by `seed_from_u64`, drawn only by
//!   the main thread in the order [`ga`] documents; evaluations run on scoped threads and are
//!   stored by index. Same seed → same run with 1 or N threads; a checkpoint stores the
//!   generator's stream position, so a resumed run continues the same stream.
//! - **Parallelism**: `std::thread::scope` with an atomic work counter, not rayon (see
//!   [`evaluate`]).
//! - **Checkpoint**: one JSON document (readable, and with serde_json's exact float parsing
//!   every f64 comes back to the same bits), tagged `mobil_ga_step checkpoint`, version
//!   [`CHECKPOINT_VERSION`], written to `<file>.tmp`, synced and renamed. See [`checkpoint`].
//! - **Motion files** list only the ten evolved joints (Webots leaves the others where they are)
//!   and write `-0.0000` as `0.0000`. The JointTrajectory YAML gives the 21 knots, exact for a
//!   linearly interpolating follower.
//!
//! ```
//! use mobil_ga_step::{GaSetup, GaState, StopReason, TestLandscape};
//! use std::ops::ControlFlow;
//!
//! let setup = GaSetup::default();
//! // The analytic test landscape, not a physics simulation.
//! let evaluator = TestLandscape::new(setup.model.clone(), setup.fitness.clone());
//! let mut state = GaState::start(setup, 7, &evaluator, 1).unwrap();
//! let first_best = state.best().fitness();
//! let reason = state.run(&evaluator, 1, 5, |_| ControlFlow::Continue(()));
//! assert_eq!((reason, state.generation, state.history.len()), (StopReason::MaxGenerations, 5, 6));
//! // Best-N replacement never loses the best individual.
//! assert!(state.best().fitness() >= first_best);
//! ```

#![warn(missing_docs)]

pub mod checkpoint;
pub mod config;
pub mod error;
pub mod evaluate;
pub mod external;
pub mod ga;
pub mod model;
pub mod operators;
pub mod output;
pub mod params;
pub mod pool;
pub mod resume;
pub mod selection;
pub mod summary;

pub use checkpoint::{
    read_checkpoint, read_checkpoint_tagged, write_checkpoint, EvaluatorTag, CHECKPOINT_FORMAT, CHECKPOINT_VERSION,
    MAX_CHECKPOINT_BYTES,
};
pub use config::{BlxVariant, Crossover, FitnessConfig, GaConfig, PhysicsModel, MAX_POPULATION};
pub use error::{CheckpointError, GaError, MotionError, ParamsError};
pub use evaluate::{evaluate_all, resolve_threads, Evaluation, Evaluator, TestLandscape};
pub use ga::{GaRng, GaSetup, GaState, GenerationStats, StopReason};
pub use model::{joint_names, Individual, NaoModel, Servo, INTERVALS, KNOTS, SERVO_COUNT};
pub use operators::{
    arithmetic, best_two_of_three, blx, blx_value, geometric, linear_candidates, mutate, one_point, one_point_at,
    MutationPick,
};
pub use output::{read_motion, write_fitness_csv, write_joint_trajectory_yaml, write_motion, Motion, MotionRow};
pub use resume::{check_resume, ResumeRefusal};
pub use selection::{choose_operator, replace_best, roulette, roulette_excluding, Operator, Scored};
pub use summary::RunSummary;
