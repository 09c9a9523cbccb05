//! Quadruped free-gait planning by best-first search (SPEC §7; Ondroušek & Březina, source 000).
//! ROS-free: no ROS types, no clock, no I/O (`tests/check_ros_free.sh` proves it). The start
//! state, the goal, the rule set and the evaluation are the input; a plan of states, each made
//! by one named rule, is the output, field for field `mobil_msgs/GaitPlan` (rule 1..=27 or 0 for
//! the start, its name, the body pose, the four feet, the moving leg or −1, the evaluation;
//! expanded and generated counts; success and the reason). `gait_node` wires it to topics.
//!
//! - [`model`]: the robot (body a × b, hips, annular-sector workspaces, the leg-angle
//!   reading), static stability, and the largest body rotation / translation that keeps every
//!   foot in its workspace along the whole motion.
//! - [`rules`]: the 27 production rules, each a named function.
//! - [`search`]: algorithm A, generic over the problem (a trait); knows nothing of legs.
//! - [`planner`]: the gait problem (rules, evaluations (1)–(3), key, goal) and [`plan`].
//! - [`horizon`]: short-time plans, [`RecedingHorizon`].
//! - [`config`]: [`GaitConfig`], every default justified; `params/quadruped.yaml` holds them.
//!
//! Choices beyond the SPEC:
//! - **Body moves need the centre inside the four feet's hull** by the stability margin (the
//!   SPEC states stability for leg moves only). A rotation about the centre moves neither the
//!   centre nor the feet, so it never changes stability; a translation is limited by it (the
//!   hull's margin is concave along the line, so the end point decides; its end is bisected to
//!   1e-12). With Tab. 1's sectors the front feet always lie ≥ 0.086 ahead of the centre, so
//!   with the default margin this never binds before a workspace does.
//! - **Workspaces along the whole motion, in closed form**: every boundary (L = L_min, L_max and
//!   the two sector edges) is a sinusoid A cos t + B sin t + C of the rotation angle, or a
//!   quadratic of the translation distance; [`model::max_rotation`] and
//!   [`model::max_translation`] solve for the first exit. No sampling: exact to rounding (a dip
//!   of 1e-12 is ignored). A state is valid within 1e-9 ([`model::TOLERANCE`]); a foot already on
//!   a boundary may move along or inward, never further out.
//! - **Rule 1** turns toward the goal by the sign of wrap(goal direction − (φ + π/2))
//!   (counter-clockwise at exactly π); **rule 2** gives +ΔY then −ΔY; **rule 3** moves toward the
//!   goal's side of y_r, capped at its projection. Rules 12–27 keep the other polar coordinate as
//!   measured. A move shorter than 1e-9 is "unchanged": no successor.
//! - **Duplicates**: the key is the body pose and the feet, each rounded to `key_quantum` (φ
//!   modulo 2π). A later duplicate is judged on the state stored under its key, so under (1),
//!   where f does not depend on the path, no state is re-parented. **Plans are exact**: every
//!   step's state is the one its rule makes from the previous step's state, so an executed
//!   plan never moves a planted foot. Re-parenting stores the state the rule makes
//!   from the new parent (and re-opens it), and a link made from a parent's older state is made
//!   again when the plan is taken ([`search`]'s documentation). Chosen over replaying the rules
//!   from the start at the end: a replay can fail on any step (ΔY no longer fits by 1e-4, a
//!   lift on the margin's edge) and returns states the search never ranked. The paper's six
//!   rows (forward reading) plan as before, with the same counts; under (3) with a coarse key (0.1) the first
//!   state stored under a key was up to 0.025 off the rule's.
//! - **f is compared on a 1e-7 grid** ([`search::VALUE_QUANTUM`]): (2) and (3) accumulate f
//!   along the path, and rounding noise (1e-15..1e-12) must not break the exact ties (1) has,
//!   so (2) expands the same states in the same order as (1) (tested).
//! - **Counts**: expanded = states moved to CLOSED (a reopened state counts again); generated =
//!   successors the rules produced, duplicates included.
//! - **Best partial plan** on a limit: start to the generated state nearest the goal (least
//!   vzd; ties: the first generated). The stop callback is asked every 256 expansions.
//! - [`plan`] uses `cfg.reading`, overriding the model's.
//! - **Receding horizon**: 2000 expansions per plan, 4 moves executed (each leg once in a
//!   cycle); a plan that finds no state nearer the goal is made again with twice the cap, up to
//!   `max_expansions` (B with (1) meets plateaus of tied leg configurations).
//!
//! ```
//! use mobil_gait::{plan, BodyPose, Evaluation, GaitConfig, GaitState, QuadrupedModel, RuleSet};
//! use nalgebra::Point2;
//!
//! let (model, cfg) = (QuadrupedModel::default(), GaitConfig::default());
//! let start = GaitState::nominal(&model, BodyPose { x: 0.0, y: 0.0, phi: 0.0 });
//! // A goal 4 ahead: shift the body, bring the legs forward, shift again.
//! let p = plan(&model, &cfg, &start, Point2::new(0.0, 4.0), RuleSet::A, Evaluation::Three, 0, &mut || false);
//! assert!(p.success);
//! assert!((p.steps.last().unwrap().state.body.y - 4.0).abs() <= cfg.goal_tolerance);
//! assert_eq!(p.steps[1].rule.map(|r| r.name()), Some("translate_max_toward_goal"));
//! ```

#![warn(missing_docs)]

pub mod config;
pub mod error;
pub mod horizon;
pub mod model;
pub mod planner;
pub mod rules;
pub mod search;
pub mod walker;

pub use config::{Evaluation, GaitConfig, RuleSet, TieBreak, Weights};
pub use error::GaitError;
pub use horizon::{Chunk, RecedingHorizon, Walk};
pub use model::{is_stable, is_supported, BodyPose, GaitState, LegAngleReading, QuadrupedModel, Workspace};
pub use planner::{plan, plan_paper_run, GaitProblem, Plan, PlanFailure, PlanStep, PAPER_GOAL};
pub use rules::{dev, vzd, Rule};
pub use walker::{WalkNext, Walker};
