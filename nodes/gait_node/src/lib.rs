//! The ROS side of [`mobil_gait`]: the `gait_node` executable (src/main.rs) and what its shell
//! does that can be checked without DDS — the configuration (every parameter declared once),
//! `gait/compute_plan` requests turned into searches and plans into `GaitPlan` replies, the
//! markers, and the reaction to UNEVEN ground.
//!
//! The method (rules, stability, the search, short-time plans and the walk that executes them,
//! [`mobil_gait::Walker`]) is in [`mobil_gait`]; nothing here plans.
//!
//! **Units.** The planner works in the paper's unit \[j\] (the body is 2 × 3 \[j\]). The service's
//! request and reply and `gait/plan` are in \[j\], as `mobil_msgs/GaitStep` says; `goal_pose`,
//! `gait/markers` and `gait/body` are in metres of the `frame` (`odom`), one \[j\] being
//! `unit_length` metres (default 1).
//!
//! What the node does with a bad request or message:
//! - a `gait/compute_plan` request with a rule set other than "A"/"B", an evaluation other than
//!   1/2/3, a non-finite number or a coordinate beyond ±[`MAX_COORDINATE`] \[j\] is answered at
//!   once with `success` false and the reason ([`query_from_request`]); `max_expansions` above
//!   `max_expansions_limit`, or above what `max_generated_states` allows, is capped to it (the
//!   reason says so if the limit is hit);
//! - a plan is sent whole by default; with `max_plan_states` set (not 0), a longer plan is sent
//!   truncated, with `success` false and the reason ([`reply_plan`]);
//! - a `goal_pose` in another frame, with NaN, beyond ±[`MAX_COORDINATE`] \[j\] or undecodable
//!   is refused and logged; the walk under way, if any, stops where it is (a quadruped
//!   standing on four feet is safe);
//! - a `terrain/assessment` with an unknown class is ignored (logged); the last known class
//!   stays.

#![warn(missing_docs)]

use mobil_gait::{
    BodyPose, Evaluation, GaitConfig, GaitState, LegAngleReading, Plan, PlanFailure, PlanStep, QuadrupedModel,
    RecedingHorizon, RuleSet, TieBreak,
};
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::{Point, Pose, Pose2D, PoseStamped};
use mobil_msgs::mobil_msgs::msg::{GaitPlan, GaitStep, TerrainAssessment};
use mobil_msgs::mobil_msgs::srv::PlanGaitRequest;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::visualization_msgs::msg::{Marker, MarkerArray};
use mobil_ros::config::{Config, ConfigError, Decl};
use mobil_ros::geometry::yaw_quaternion;
use mobil_ros::markers::{point, rgb, rgba, Markers};
use nalgebra::Point2;
use thiserror::Error;

/// Largest coordinate of a start or goal accepted, \[j\]: 333 body lengths, about 30 times the
/// paper's experiment (15 \[j\]). A search toward a goal this far ends at its expansion,
/// memory or time limit with a partial plan; a walk gets there plan by plan.
pub const MAX_COORDINATE: f64 = 1000.0;

/// A bound on the successors one expansion can generate with a rule set: two per rule. It is
/// conservative: rule 2 gives two (+ΔY and −ΔY), every other rule at most one.
pub fn max_successors(set: RuleSet) -> u32 {
    let rules = match set {
        RuleSet::A => 11,
        RuleSet::B => 27,
    };
    2 * rules
}

/// The reason a pre-empted `gait/compute_plan` caller gets.
pub const PREEMPTED: &str = "pre-empted";

/// The node's own parameters (the params file's `gait:` section), beside the planner's
/// [`GaitConfig`].
#[derive(Debug, Clone, PartialEq)]
pub struct NodeParams {
    /// Most expansions one `gait/compute_plan` request may ask for; larger requests are capped.
    pub max_expansions_limit: u32,
    /// Most states one search may generate (its memory): a search's expansions are capped to
    /// this over [`max_successors`] of its rule set.
    pub max_generated_states: u32,
    /// Most states of a plan sent (a reply or `gait/plan`); a longer plan is truncated. 0 (the
    /// default): no limit, every plan is sent whole.
    pub max_plan_states: u32,
    /// Wall time one search may take before it is stopped with its best partial plan \[s\].
    pub time_limit_s: f64,
    /// Metres per \[j\]: `goal_pose`, the markers and `gait/body` are in metres.
    pub unit_length: f64,
    /// The frame of `goal_pose`, the markers and `gait/body` (`gait/plan` is in \[j\] and sends
    /// an empty `frame_id`).
    pub frame: String,
    /// Rule set of the walk's short-time plans.
    pub walk_rule_set: RuleSet,
    /// Evaluation (1, 2 or 3) of the walk's short-time plans.
    pub walk_evaluation: u8,
    /// Expansion cap of each short-time plan of the walk.
    pub walk_chunk_expansions: u32,
    /// Moves executed from each short-time plan before replanning.
    pub walk_execute_moves: u32,
    /// Time per executed move of the simulated quadruped (its pace) \[s\].
    pub walk_move_period_s: f64,
    /// Short-time plans after which a walk that has not reached its goal gives up.
    pub walk_max_chunks: u32,
    /// Where the simulated quadruped stands at start-up, legs nominal: x, y \[j\], φ \[rad\].
    pub walk_start: [f64; 3],
    /// Stability margin of plans made while the ground is UNEVEN \[j\] (the larger of this and
    /// `stability_margin` applies).
    pub uneven_stability_margin: f64,
    /// Rule 2's ΔY of plans made while the ground is UNEVEN \[j\] (the smaller of this and
    /// `translation_step` applies).
    pub uneven_translation_step: f64,
}

impl Default for NodeParams {
    fn default() -> Self {
        NodeParams {
            max_expansions_limit: 1_000_000,
            max_generated_states: 2_000_000,
            max_plan_states: 0,
            time_limit_s: 2.0,
            unit_length: 1.0,
            frame: "odom".into(),
            walk_rule_set: RuleSet::A,
            walk_evaluation: 3,
            walk_chunk_expansions: 2000,
            walk_execute_moves: 4,
            walk_move_period_s: 0.25,
            walk_max_chunks: 200,
            walk_start: [0.0, 0.0, 0.0],
            uneven_stability_margin: 0.15,
            uneven_translation_step: 0.5,
        }
    }
}

/// Parses "A"/"B" for the parameter declaration.
#[derive(Debug, Clone, Copy)]
struct SetName(RuleSet);

impl std::str::FromStr for SetName {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        s.parse::<RuleSet>().map(SetName).map_err(|e| e.to_string())
    }
}

/// Declares the planner's parameters: one per [`GaitConfig`] field, with its name.
fn declare_gait(d: &mut Decl<GaitConfig>) {
    let c = GaitConfig::default();
    d.double(
        "stability_margin",
        c.stability_margin,
        "least distance of the centre of gravity inside the support triangle while a leg moves (and the feet's hull while the body moves) [j]",
        |c, v| c.stability_margin = v,
    )
    .within(0.0, 0.999);
    d.double("translation_step", c.translation_step, "ΔY of rule 2 [j]", |c, v| {
        c.translation_step = v
    })
    .above(0.0);
    d.double(
        "key_quantum",
        c.key_quantum,
        "quantum of the duplicate key: states agreeing to it are one [j and rad]",
        |c, v| c.key_quantum = v,
    )
    .within(1e-9, 0.1);
    d.double(
        "goal_tolerance",
        c.goal_tolerance,
        "goal: the body centre within this of the goal point [j]",
        |c, v| c.goal_tolerance = v,
    )
    .above(0.0);
    d.count(
        "max_expansions",
        c.max_expansions,
        "expansion limit of a search (a request's 0 means this)",
        |c, v| c.max_expansions = v,
    )
    .within(1.0, f64::from(u32::MAX));
    d.parsed::<LegAngleReading>(
        "reading",
        "forward",
        "which extreme of each leg's sector Tab. 1's \"max angle\" names: forward or rearward",
        |c, v| c.reading = v,
    )
    .choices(&["forward", "rearward"]);
    d.parsed::<TieBreak>(
        "tie_break",
        "oldest",
        "which of the states tied on f the search expands first: oldest (FIFO) or newest (LIFO)",
        |c, v| c.tie_break = v,
    )
    .choices(&["oldest", "newest"]);
    for (name, value, what, set) in [
        (
            "k1",
            c.k1,
            "k1 of evaluations (1) and (2)",
            (|c, v| c.k1 = v) as fn(&mut GaitConfig, f64),
        ),
        ("k2", c.k2, "k2 of evaluations (1) and (2)", |c, v| c.k2 = v),
        ("a3_k1", c.a3_k1, "k1 of evaluation (3) with set A", |c, v| c.a3_k1 = v),
        ("a3_k2", c.a3_k2, "k2 of evaluation (3) with set A", |c, v| c.a3_k2 = v),
        (
            "a3_k3",
            c.a3_k3,
            "k3 of evaluation (3) with set A (per leg move)",
            |c, v| c.a3_k3 = v,
        ),
        ("b3_k1", c.b3_k1, "k1 of evaluation (3) with set B", |c, v| c.b3_k1 = v),
        ("b3_k2", c.b3_k2, "k2 of evaluation (3) with set B", |c, v| c.b3_k2 = v),
        (
            "b3_k3",
            c.b3_k3,
            "k3 of evaluation (3) with set B (per leg move)",
            |c, v| c.b3_k3 = v,
        ),
    ] {
        d.double(name, value, what, set).within(0.0, 1000.0);
    }
}

/// Declares the node's own parameters.
fn declare_node(d: &mut Decl<NodeParams>) {
    let c = NodeParams::default();
    d.count(
        "max_expansions_limit",
        c.max_expansions_limit,
        "most expansions a gait/compute_plan request may ask for (larger requests are capped)",
        |c, v| c.max_expansions_limit = v,
    )
    .within(1.0, f64::from(u32::MAX));
    d.count(
        "max_generated_states",
        c.max_generated_states,
        "most states one search may generate, its memory: expansions are capped to this over 2 × the rule count",
        |c, v| c.max_generated_states = v,
    )
    .within(100.0, f64::from(u32::MAX));
    d.count(
        "max_plan_states",
        c.max_plan_states,
        "most states of a plan sent in a reply or on gait/plan, a longer plan truncated (success false); 0: no limit",
        |c, v| c.max_plan_states = v,
    )
    .within(0.0, f64::from(u32::MAX));
    d.double(
        "time_limit_s",
        c.time_limit_s,
        "wall time of one search before it stops with its best partial plan [s]",
        |c, v| c.time_limit_s = v,
    )
    .within(0.001, 3600.0);
    d.double(
        "unit_length",
        c.unit_length,
        "metres per [j]: goal_pose, gait/markers and gait/body are in metres [m]",
        |c, v| c.unit_length = v,
    )
    .within(1e-6, 1e3);
    d.string(
        "frame",
        &c.frame,
        "frame of goal_pose, gait/markers and gait/body (gait/plan is in [j], with an empty frame_id)",
        |c, v| c.frame = v,
    );
    d.parsed::<SetName>(
        "walk_rule_set",
        "A",
        "rule set of the walk's short-time plans: A or B",
        |c, v| c.walk_rule_set = v.0,
    )
    .choices(&["A", "B"]);
    d.count(
        "walk_evaluation",
        c.walk_evaluation,
        "evaluation function (1, 2 or 3) of the walk's short-time plans",
        |c, v| c.walk_evaluation = v,
    )
    .within(1.0, 3.0);
    d.count(
        "walk_chunk_expansions",
        c.walk_chunk_expansions,
        "expansion cap of each short-time plan of the walk",
        |c, v| c.walk_chunk_expansions = v,
    )
    .within(1.0, f64::from(u32::MAX));
    d.count(
        "walk_execute_moves",
        c.walk_execute_moves,
        "moves executed from each short-time plan before replanning",
        |c, v| c.walk_execute_moves = v,
    )
    .within(1.0, 1000.0);
    d.double(
        "walk_move_period_s",
        c.walk_move_period_s,
        "time per executed move of the simulated quadruped (its pace) [s]",
        |c, v| c.walk_move_period_s = v,
    )
    .within(0.001, 60.0);
    d.count(
        "walk_max_chunks",
        c.walk_max_chunks,
        "short-time plans after which a walk that has not reached its goal gives up",
        |c, v| c.walk_max_chunks = v,
    )
    .within(1.0, 1e6);
    d.doubles(
        "walk_start",
        c.walk_start,
        "where the simulated quadruped stands at start-up, legs nominal: x, y [j], φ [rad]",
        |c, v| c.walk_start = v,
    )
    .read_only();
    d.double(
        "uneven_stability_margin",
        c.uneven_stability_margin,
        "stability margin while terrain/assessment says UNEVEN (the larger of this and stability_margin) [j]",
        |c, v| c.uneven_stability_margin = v,
    )
    .within(0.0, 0.999);
    d.double(
        "uneven_translation_step",
        c.uneven_translation_step,
        "ΔY of rule 2 while terrain/assessment says UNEVEN (the smaller of this and translation_step) [j]",
        |c, v| c.uneven_translation_step = v,
    )
    .above(0.0);
}

/// `gait_node`'s configuration: the planner's parameters and the node's own.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GaitNodeConfig {
    /// The planner's parameters (names as the fields of [`GaitConfig`]).
    pub gait: GaitConfig,
    /// The node's own parameters.
    pub node: NodeParams,
}

impl Config for GaitNodeConfig {
    fn declare(d: &mut Decl<Self>) {
        d.nest(|c: &mut GaitNodeConfig| &mut c.gait, declare_gait);
        d.nest(|c: &mut GaitNodeConfig| &mut c.node, declare_node);
    }

    fn validate(&self) -> Result<(), ConfigError> {
        self.gait.validate().map_err(ConfigError::inconsistent)?;
        self.walk_evaluation().map_err(ConfigError::inconsistent)?;
        if !self
            .node
            .walk_start
            .iter()
            .all(|v| v.is_finite() && v.abs() <= MAX_COORDINATE)
        {
            return Err(ConfigError::inconsistent(format!(
                "walk_start {:?} must be finite and within ±{MAX_COORDINATE}",
                self.node.walk_start
            )));
        }
        // The UNEVEN configuration must be one the planner takes too.
        self.gait_for(Ground::Uneven)
            .validate()
            .map_err(|e| ConfigError::inconsistent(format!("on UNEVEN ground: {e}")))?;
        let start = self.walk_start_state();
        mobil_gait::planner::check_start(&self.model(), &self.gait, &start)
            .map_err(|e| ConfigError::inconsistent(format!("walk_start: {e}")))
    }
}

/// What the latest `terrain/assessment` said, as far as the planner cares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Ground {
    /// No assessment yet, or a class other than UNEVEN.
    #[default]
    Even,
    /// The latest assessment's class is UNEVEN.
    Uneven,
}

impl GaitNodeConfig {
    /// The robot (the paper's, under the configured reading).
    pub fn model(&self) -> QuadrupedModel {
        QuadrupedModel::paper(self.gait.reading)
    }

    /// The walk's evaluation function.
    pub fn walk_evaluation(&self) -> Result<Evaluation, mobil_gait::GaitError> {
        Evaluation::try_from(self.node.walk_evaluation)
    }

    /// The planner's configuration on this ground: on UNEVEN ground the larger stability margin
    /// and the shorter translation step of the reaction.
    pub fn gait_for(&self, ground: Ground) -> GaitConfig {
        let mut g = self.gait.clone();
        if ground == Ground::Uneven {
            g.stability_margin = g.stability_margin.max(self.node.uneven_stability_margin);
            g.translation_step = g.translation_step.min(self.node.uneven_translation_step);
        }
        g
    }

    /// The simulated quadruped's start-up state: `walk_start`, legs nominal.
    pub fn walk_start_state(&self) -> GaitState {
        let [x, y, phi] = self.node.walk_start;
        GaitState::nominal(&self.model(), BodyPose { x, y, phi })
    }

    /// The walk's receding-horizon planner on this ground.
    pub fn horizon(&self, ground: Ground) -> Result<RecedingHorizon, mobil_gait::GaitError> {
        let mut h = RecedingHorizon::new(self.gait_for(ground), self.node.walk_rule_set, self.walk_evaluation()?);
        h.chunk_expansions = self.node.walk_chunk_expansions;
        h.execute_steps = usize::try_from(self.node.walk_execute_moves).unwrap_or(usize::MAX);
        Ok(h)
    }
}

/// The ground a `terrain/assessment` reports, or why it is ignored.
pub fn ground_from_assessment(a: &TerrainAssessment) -> Result<Ground, String> {
    match a.terrain_class {
        TerrainAssessment::UNEVEN => Ok(Ground::Uneven),
        TerrainAssessment::FLAT | TerrainAssessment::SLOPE | TerrainAssessment::BEYOND_LIMITS => Ok(Ground::Even),
        other => Err(format!("terrain/assessment with unknown class {other} ignored")),
    }
}

/// Why a `gait/compute_plan` request was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RequestRefusal {
    /// rule_set is not "A" or "B".
    #[error("INVALID_REQUEST: rule_set `{0}` (expected \"A\" or \"B\")")]
    RuleSet(String),
    /// evaluation is not 1, 2 or 3.
    #[error("INVALID_REQUEST: evaluation {0} (expected 1, 2 or 3)")]
    Evaluation(u8),
    /// A number is NaN or infinite.
    #[error("INVALID_REQUEST: {0} is not finite")]
    NotFinite(&'static str),
    /// A coordinate beyond ±[`MAX_COORDINATE`].
    #[error("INVALID_REQUEST: {what} {value} is beyond ±{MAX_COORDINATE} [j]")]
    TooFar {
        /// Which coordinate.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// The start stance is not one the robot can stand in.
    #[error("INVALID_REQUEST: {0}")]
    Start(String),
}

/// A checked `gait/compute_plan` request.
#[derive(Debug, Clone, PartialEq)]
pub struct GaitQuery {
    /// The start state: the request's body pose, legs nominal.
    pub start: GaitState,
    /// The goal of the body centre \[j\].
    pub goal: Point2<f64>,
    /// The rule set.
    pub set: RuleSet,
    /// The evaluation.
    pub evaluation: Evaluation,
    /// The expansion limit of the search.
    pub max_expansions: u32,
    /// The request's own limit when it was capped (to `max_expansions_limit` or by
    /// `max_generated_states`).
    pub capped_from: Option<u32>,
    /// What capped it.
    pub capped_by: Cap,
}

/// Which node limit capped a request's expansions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cap {
    /// Not capped.
    None,
    /// `max_expansions_limit`.
    ExpansionsLimit,
    /// `max_generated_states` over the rule set's [`max_successors`].
    GeneratedStates {
        /// The parameter's value.
        max_generated: u32,
        /// Successors per expansion at most.
        per_expansion: u32,
    },
}

/// Checks a request and makes it a query for a search on `ground`: `max_expansions` 0 becomes
/// `cfg.gait.max_expansions`, anything above `max_expansions_limit` is capped to it, and
/// anything above `max_generated_states` / [`max_successors`] to that (so the search never
/// holds more states). The start is checked under the configuration the search will run with.
pub fn query_from_request(
    req: &PlanGaitRequest,
    cfg: &GaitNodeConfig,
    ground: Ground,
) -> Result<GaitQuery, RequestRefusal> {
    let set: RuleSet = req
        .rule_set
        .parse()
        .map_err(|_| RequestRefusal::RuleSet(req.rule_set.clone()))?;
    let evaluation = Evaluation::try_from(req.evaluation).map_err(|_| RequestRefusal::Evaluation(req.evaluation))?;
    for (what, v) in [
        ("start.x", req.start.x),
        ("start.y", req.start.y),
        ("start.theta", req.start.theta),
        ("goal.x", req.goal.x),
        ("goal.y", req.goal.y),
    ] {
        if !v.is_finite() {
            return Err(RequestRefusal::NotFinite(what));
        }
        if v.abs() > MAX_COORDINATE {
            return Err(RequestRefusal::TooFar { what, value: v });
        }
    }
    let model = cfg.model();
    let start = GaitState::nominal(
        &model,
        BodyPose {
            x: req.start.x,
            y: req.start.y,
            phi: req.start.theta,
        },
    );
    mobil_gait::planner::check_start(&model, &cfg.gait_for(ground), &start).map_err(RequestRefusal::Start)?;
    let asked = if req.max_expansions == 0 {
        cfg.gait.max_expansions
    } else {
        req.max_expansions
    };
    let per_expansion = max_successors(set);
    let by_memory = (cfg.node.max_generated_states / per_expansion).max(1);
    let (max_expansions, capped_by) = if asked <= cfg.node.max_expansions_limit.min(by_memory) {
        (asked, Cap::None)
    } else if cfg.node.max_expansions_limit <= by_memory {
        (cfg.node.max_expansions_limit, Cap::ExpansionsLimit)
    } else {
        (
            by_memory,
            Cap::GeneratedStates {
                max_generated: cfg.node.max_generated_states,
                per_expansion,
            },
        )
    };
    Ok(GaitQuery {
        start,
        goal: Point2::new(req.goal.x, req.goal.y),
        set,
        evaluation,
        max_expansions,
        capped_from: (capped_by != Cap::None).then_some(asked),
        capped_by,
    })
}

/// Why a search ended without its plan being the caller's to use as it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopCause {
    /// Not stopped (a goal, the expansion limit, or no successor).
    None,
    /// The node's `time_limit_s` ran out.
    TimeLimit,
    /// A newer request pre-empted it.
    Preempted,
}

/// Runs a query's search with the node's limits: stopped when `cancelled()` says so (a newer
/// request) or when `time_out()` does (the node's time limit), and tells which.
pub fn run_query(
    query: &GaitQuery,
    cfg: &GaitConfig,
    cancelled: &dyn Fn() -> bool,
    time_out: &mut dyn FnMut() -> bool,
) -> (Plan, StopCause) {
    let model = QuadrupedModel::paper(cfg.reading);
    let mut cause = StopCause::None;
    let plan = {
        let mut stop = || {
            if cancelled() {
                cause = StopCause::Preempted;
                true
            } else if time_out() {
                cause = StopCause::TimeLimit;
                true
            } else {
                false
            }
        };
        mobil_gait::plan(
            &model,
            cfg,
            &query.start,
            query.goal,
            query.set,
            query.evaluation,
            query.max_expansions,
            &mut stop,
        )
    };
    if plan.failure != Some(PlanFailure::Stopped) {
        cause = StopCause::None;
    }
    (plan, cause)
}

/// The reply's reason for a plan: empty on success, else the failure, with the node's limits
/// named (the time limit, a capped request).
pub fn plan_reason(plan: &Plan, cause: StopCause, query: &GaitQuery, time_limit_s: f64) -> String {
    match cause {
        StopCause::Preempted => return PREEMPTED.into(),
        StopCause::TimeLimit => {
            return format!(
                "TIME_LIMIT: no goal within the time limit of {time_limit_s} s ({} states expanded); the plan is the best partial one",
                plan.expanded
            );
        }
        StopCause::None => {}
    }
    match (&plan.failure, query.capped_from, query.capped_by) {
        (None, _, _) => String::new(),
        (
            Some(f @ PlanFailure::ExpansionLimit(_)),
            Some(asked),
            Cap::GeneratedStates {
                max_generated,
                per_expansion,
            },
        ) => format!(
            "{f} (the request's {asked} was capped so that the search generates at most max_generated_states \
             {max_generated} states, {per_expansion} per expansion at most)"
        ),
        (Some(f @ PlanFailure::ExpansionLimit(_)), Some(asked), _) => {
            format!("{f} (the request's {asked} was capped to max_expansions_limit)")
        }
        (Some(f), _, _) => f.to_string(),
    }
}

/// The reason of a walk's short-time plan: empty when it reaches the goal, `TIME_LIMIT` when
/// the node's time limit stopped it, else the plan's failure.
pub fn chunk_reason(plan: &Plan, cause: StopCause, time_limit_s: f64) -> String {
    match (cause, &plan.failure) {
        (_, None) => String::new(),
        (StopCause::TimeLimit, Some(PlanFailure::Stopped)) => format!(
            "TIME_LIMIT: no goal within the time limit of {time_limit_s} s ({} states expanded); the plan is the best partial one",
            plan.expanded
        ),
        (_, Some(f)) => f.to_string(),
    }
}

/// A plan as the message sent (a reply or `gait/plan`, header left default for the caller to
/// stamp): the whole plan when `max_plan_states` is 0, else at most that many states. A longer
/// plan is truncated to its first `max_plan_states` states, `success` false, and the reason says
/// so and what the whole plan was (the prefix is a valid walk, and a new request from its end
/// continues it).
pub fn reply_plan(plan: &Plan, set: RuleSet, evaluation: Evaluation, reason: String, max_plan_states: u32) -> GaitPlan {
    let keep = match max_plan_states {
        0 => usize::MAX,
        n => usize::try_from(n).unwrap_or(usize::MAX),
    };
    let mut msg = GaitPlan {
        header: Header::default(),
        rule_set: set.to_string(),
        evaluation: evaluation.number(),
        success: plan.success,
        reason,
        states_expanded: plan.expanded,
        states_generated: plan.generated,
        steps: plan.steps.iter().take(keep).map(step_message).collect(),
    };
    if plan.steps.len() > keep {
        let whole = if plan.success {
            "the whole plan reaches the goal".to_owned()
        } else {
            msg.reason.clone()
        };
        msg.success = false;
        msg.reason = format!(
            "TRUNCATED: the plan has {} states, only the first {keep} are sent (max_plan_states); {whole}",
            plan.steps.len()
        );
    }
    msg
}

/// A plan state as a message step (\[j\]): rule 0 and "start" for the start, `moving_leg` −1
/// for a body move (and for the start).
pub fn step_message(step: &PlanStep) -> GaitStep {
    let s = &step.state;
    GaitStep {
        rule: step.rule.map_or(0, |r| r.number()),
        rule_name: step.rule.map_or("start", |r| r.name()).to_owned(),
        body: Pose2D {
            x: s.body.x,
            y: s.body.y,
            theta: s.body.phi,
        },
        feet: s.feet.map(|f| Point { x: f.x, y: f.y, z: 0.0 }),
        moving_leg: step
            .rule
            .and_then(|r| r.moving_leg())
            .and_then(|l| i8::try_from(l).ok())
            .unwrap_or(-1),
        evaluation: step.evaluation,
    }
}

/// A plan with no steps, `success` false and the reason: a refused or pre-empted request (its
/// rule set and evaluation as they were asked).
pub fn refused_plan(req: &PlanGaitRequest, header: Header, reason: String) -> GaitPlan {
    GaitPlan {
        header,
        rule_set: req.rule_set.clone(),
        evaluation: req.evaluation,
        success: false,
        reason,
        ..GaitPlan::default()
    }
}

/// Why a `goal_pose` was refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GoalRefusal {
    /// Not in the configured frame.
    #[error("goal_pose in frame `{got}`, expected `{expected}` (the node has no transforms)")]
    Frame {
        /// The message's frame.
        got: String,
        /// The configured frame.
        expected: String,
    },
    /// NaN or beyond the coordinate bound.
    #[error("goal_pose ({x}, {y}) m is not finite or beyond ±{MAX_COORDINATE} [j]")]
    Invalid {
        /// x \[m\].
        x: f64,
        /// y \[m\].
        y: f64,
    },
}

/// A `goal_pose` as the walk's goal \[j\]; the orientation is ignored (the goal is a position).
pub fn goal_from_pose(m: &PoseStamped, frame: &str, unit_length: f64) -> Result<Point2<f64>, GoalRefusal> {
    if m.header.frame_id.trim_start_matches('/') != frame.trim_start_matches('/') {
        return Err(GoalRefusal::Frame {
            got: m.header.frame_id.clone(),
            expected: frame.to_owned(),
        });
    }
    let (x, y) = (m.pose.position.x, m.pose.position.y);
    let goal = Point2::new(x / unit_length, y / unit_length);
    if !(goal.x.is_finite() && goal.y.is_finite()) || goal.x.abs() > MAX_COORDINATE || goal.y.abs() > MAX_COORDINATE {
        return Err(GoalRefusal::Invalid { x, y });
    }
    Ok(goal)
}

/// The namespace of every gait marker.
const NS: &str = "gait";

/// The body's outline: its four corners (the hips) and the first again, in the world \[j\].
pub fn body_outline(model: &QuadrupedModel, body: &BodyPose) -> [Point2<f64>; 5] {
    let corner = |k: usize| body.centre() + body.to_world(model.hips[k]);
    // Hips 0 front left, 2 front right, 3 rear right, 1 rear left: round the rectangle.
    [corner(0), corner(2), corner(3), corner(1), corner(0)]
}

/// The support triangle while leg `leg` moves: the other three feet, the first again.
pub fn support_triangle(state: &GaitState, leg: usize) -> Vec<Point2<f64>> {
    let mut t: Vec<Point2<f64>> = (0..4).filter(|&k| k != leg).map(|k| state.feet[k]).collect();
    if let Some(&first) = t.first() {
        t.push(first);
    }
    t
}

/// Markers of the walk in `header`'s frame (metres, `unit` m per \[j\]), all in the namespace
/// `gait`: a DELETEALL of it, then the body outline (0), the feet (1), the support triangle of
/// the move just made if it moved a leg (2), the planned body path (3) and the goal (4).
pub fn markers(
    model: &QuadrupedModel,
    state: &GaitState,
    current: Option<&PlanStep>,
    plan: &[PlanStep],
    goal: Option<Point2<f64>>,
    header: &Header,
    unit: f64,
) -> MarkerArray {
    let line = 0.02 * unit;
    let metres = |p: Point2<f64>| p * unit;
    let mut m = Markers::new(header.stamp.clone(), &header.frame_id);
    // A DELETEALL of this namespace only (RViz 2 scopes a DELETEALL that names one).
    m.add(NS, 0, Marker::ARROW, [0.0; 3], rgba(0.0, 0.0, 0.0, 0.0)).action = Marker::DELETEALL;
    let outline = body_outline(model, &state.body).map(metres);
    m.line_strip(NS, 0, outline, line * 2.0, rgb(0.2, 0.2, 0.2));
    m.dots(NS, 1, state.feet.map(metres), 0.15 * unit, rgb(0.0, 0.35, 0.71));
    if let Some(leg) = current.and_then(|s| s.rule).and_then(|r| r.moving_leg()) {
        let triangle = support_triangle(state, leg).into_iter().map(metres);
        m.line_strip(NS, 2, triangle, line * 1.5, rgb(0.9, 0.62, 0.0));
    }
    if plan.len() >= 2 {
        let path = plan.iter().map(|s| metres(s.state.body.centre()));
        m.line_strip(NS, 3, path, line, rgb(0.0, 0.6, 0.3));
    }
    if let Some(g) = goal {
        m.sphere(NS, 4, metres(g), 0.3 * unit, rgb(0.8, 0.1, 0.1));
    }
    m.array()
}

/// The simulated body as a pose in `header`'s frame (metres; orientation: the body's φ).
pub fn body_pose(body: &BodyPose, header: Header, unit: f64) -> PoseStamped {
    PoseStamped {
        header,
        pose: Pose {
            position: point(body.centre() * unit),
            orientation: yaw_quaternion(body.phi),
        },
    }
}

/// A stamp and frame as a header.
pub fn header(stamp: Time, frame: &str) -> Header {
    Header {
        stamp,
        frame_id: frame.to_owned(),
    }
}
