//! The production rules of SPEC §7: set A (1..=11) and set B (1..=27). Each is a named function
//! returning the successor, or nothing when the state would not change, a foot would leave its
//! workspace (along the whole motion for a body move) or the robot would lose static stability.

use crate::config::{GaitConfig, RuleSet};
use crate::error::GaitError;
use crate::model::{
    is_stable, is_supported, max_rotation, max_translation, rotate, wrap, GaitState, QuadrupedModel, TOLERANCE,
};
use nalgebra::{Point2, Vector2};
use std::f64::consts::PI;

/// A production rule, 1..=27 (SPEC §7's numbering).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Rule(u8);

const NAMES: [&str; 27] = [
    "rotate_toward_goal",
    "translate_step",
    "translate_max_toward_goal",
    "leg0_max_length_max_angle",
    "leg1_max_length_max_angle",
    "leg2_max_length_max_angle",
    "leg3_max_length_max_angle",
    "leg0_nominal",
    "leg1_nominal",
    "leg2_nominal",
    "leg3_nominal",
    "leg0_max_length",
    "leg1_max_length",
    "leg2_max_length",
    "leg3_max_length",
    "leg0_min_length",
    "leg1_min_length",
    "leg2_min_length",
    "leg3_min_length",
    "leg0_max_angle",
    "leg1_max_angle",
    "leg2_max_angle",
    "leg3_max_angle",
    "leg0_min_angle",
    "leg1_min_angle",
    "leg2_min_angle",
    "leg3_min_angle",
];

impl Rule {
    /// Rule `n` (1..=27).
    pub fn new(n: u8) -> Result<Rule, GaitError> {
        if (1..=27).contains(&n) {
            Ok(Rule(n))
        } else {
            Err(GaitError::UnknownRule(n))
        }
    }

    /// The rules of a set, in order (the order successors are generated in).
    pub fn all(set: RuleSet) -> impl Iterator<Item = Rule> {
        (1..=set.rule_count()).map(Rule)
    }

    /// The rule's number, 1..=27.
    pub fn number(self) -> u8 {
        self.0
    }

    /// The rule's name (`rotate_toward_goal`, `leg2_min_angle`, …).
    pub fn name(self) -> &'static str {
        NAMES[usize::from(self.0 - 1)]
    }

    /// The leg the rule moves, or `None` for a body move (rules 1..=3).
    pub fn moving_leg(self) -> Option<usize> {
        match self.0 {
            1..=3 => None,
            n => Some(usize::from(n - 4) % 4),
        }
    }

    /// Applies the rule: up to two successors (rule 2 gives one for +ΔY and one for −ΔY, in
    /// that order; every other rule at most one).
    pub fn apply(
        self,
        model: &QuadrupedModel,
        cfg: &GaitConfig,
        state: &GaitState,
        goal: Point2<f64>,
    ) -> [Option<GaitState>; 2] {
        let m = cfg.stability_margin;
        let one = |s| [s, None];
        match self.0 {
            1 => one(rotate_toward_goal(model, state, goal)),
            2 => [
                translate_step(model, m, state, cfg.translation_step),
                translate_step(model, m, state, -cfg.translation_step),
            ],
            3 => one(translate_max_toward_goal(model, m, state, goal)),
            n => {
                let leg = usize::from(n - 4) % 4;
                one(match (n - 4) / 4 {
                    0 => leg_max_length_max_angle(model, m, state, leg),
                    1 => leg_nominal(model, m, state, leg),
                    2 => leg_max_length(model, m, state, leg),
                    3 => leg_min_length(model, m, state, leg),
                    4 => leg_max_angle(model, m, state, leg),
                    _ => leg_min_angle(model, m, state, leg),
                })
            }
        }
    }
}

impl std::fmt::Display for Rule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {}", self.0, self.name())
    }
}

/// vzd: the distance of the body centre to the goal.
pub fn vzd(state: &GaitState, goal: Point2<f64>) -> f64 {
    (goal - state.body.centre()).norm()
}

/// The signed angle from y_r to the goal direction, in (−π, π]; 0 at the goal itself.
pub fn signed_dev(state: &GaitState, goal: Point2<f64>) -> f64 {
    let d = goal - state.body.centre();
    if d.norm_squared() == 0.0 {
        return 0.0;
    }
    wrap(d.y.atan2(d.x) - (state.body.phi + PI / 2.0))
}

/// dev = |wrap(atan2(goal − centre) − (φ + π/2))| ∈ [0, π].
pub fn dev(state: &GaitState, goal: Point2<f64>) -> f64 {
    signed_dev(state, goal).abs()
}

/// Rule 1: rotates the body about its centre toward the goal direction by min(dev, the largest
/// angle the workspaces allow along the rotation). The feet and the centre stay where they are,
/// so static stability does not change.
pub fn rotate_toward_goal(model: &QuadrupedModel, state: &GaitState, goal: Point2<f64>) -> Option<GaitState> {
    let sd = signed_dev(state, goal);
    let sign = if sd >= 0.0 { 1.0 } else { -1.0 };
    let angle = max_rotation(model, state, sign, sd.abs());
    if angle <= TOLERANCE {
        return None;
    }
    let mut next = *state;
    next.body.phi = wrap(state.body.phi + sign * angle);
    Some(next)
}

/// The body moved by `distance` along y_r (negative: back), feet planted, if every foot stays in
/// its workspace along the motion and the centre inside the feet's hull by `margin`.
fn translated(model: &QuadrupedModel, margin: f64, state: &GaitState, distance: f64) -> Option<GaitState> {
    let mut next = *state;
    let c = state.body.centre() + distance * state.body.forward();
    next.body.x = c.x;
    next.body.y = c.y;
    (next.in_workspaces(model) && is_supported(margin, &next)).then_some(next)
}

/// Rule 2: translates the body along y_r by `step` (the paper's ΔY = b/3; negative: back), if
/// the whole motion is allowed.
pub fn translate_step(model: &QuadrupedModel, margin: f64, state: &GaitState, step: f64) -> Option<GaitState> {
    if step.abs() <= TOLERANCE {
        return None;
    }
    let sign = step.signum();
    let reach = max_translation(model, margin, state, sign, step.abs());
    if reach < step.abs() - TOLERANCE {
        return None;
    }
    translated(model, margin, state, step)
}

/// Rule 3: the largest translation along y_r toward the goal that the workspaces and stability
/// allow, capped at the goal's projection on y_r.
pub fn translate_max_toward_goal(
    model: &QuadrupedModel,
    margin: f64,
    state: &GaitState,
    goal: Point2<f64>,
) -> Option<GaitState> {
    let along = (goal - state.body.centre()).dot(&state.body.forward());
    let sign = if along >= 0.0 { 1.0 } else { -1.0 };
    let reach = max_translation(model, margin, state, sign, along.abs());
    if reach <= TOLERANCE {
        return None;
    }
    translated(model, margin, state, sign * reach)
}

/// Places leg `leg`'s foot at polar (length, angle) from its hip: the leg lifts, so the other
/// three feet must hold the centre by `margin`. Nothing when the foot would not move.
pub fn place_leg(
    model: &QuadrupedModel,
    margin: f64,
    state: &GaitState,
    leg: usize,
    length: f64,
    angle: f64,
) -> Option<GaitState> {
    let in_body: Vector2<f64> = model.foot_in_body(leg, length, angle);
    let foot = state.body.centre() + rotate(in_body, state.body.phi);
    if (foot - state.feet[leg]).norm() <= TOLERANCE {
        return None;
    }
    if !model.workspaces[leg].contains(in_body - model.hips[leg]) || !is_stable(model, margin, state, leg) {
        return None;
    }
    let mut next = *state;
    next.feet[leg] = foot;
    Some(next)
}

/// Rules 4..=7: leg `leg` to max length and max angle.
pub fn leg_max_length_max_angle(
    model: &QuadrupedModel,
    margin: f64,
    state: &GaitState,
    leg: usize,
) -> Option<GaitState> {
    let w = &model.workspaces[leg];
    place_leg(model, margin, state, leg, w.l_max(), model.max_angle(leg))
}

/// Rules 8..=11: leg `leg` to middle length and nominal angle.
pub fn leg_nominal(model: &QuadrupedModel, margin: f64, state: &GaitState, leg: usize) -> Option<GaitState> {
    let w = &model.workspaces[leg];
    place_leg(model, margin, state, leg, w.nominal_length(), w.nominal_angle())
}

/// Rules 12..=15: leg `leg` to max length, keeping its angle.
pub fn leg_max_length(model: &QuadrupedModel, margin: f64, state: &GaitState, leg: usize) -> Option<GaitState> {
    let (_, beta) = state.polar(model, leg);
    place_leg(model, margin, state, leg, model.workspaces[leg].l_max(), beta)
}

/// Rules 16..=19: leg `leg` to min length, keeping its angle.
pub fn leg_min_length(model: &QuadrupedModel, margin: f64, state: &GaitState, leg: usize) -> Option<GaitState> {
    let (_, beta) = state.polar(model, leg);
    place_leg(model, margin, state, leg, model.workspaces[leg].l_min(), beta)
}

/// Rules 20..=23: leg `leg` to max angle, keeping its length.
pub fn leg_max_angle(model: &QuadrupedModel, margin: f64, state: &GaitState, leg: usize) -> Option<GaitState> {
    let (l, _) = state.polar(model, leg);
    place_leg(model, margin, state, leg, l, model.max_angle(leg))
}

/// Rules 24..=27: leg `leg` to min angle, keeping its length.
pub fn leg_min_angle(model: &QuadrupedModel, margin: f64, state: &GaitState, leg: usize) -> Option<GaitState> {
    let (l, _) = state.polar(model, leg);
    place_leg(model, margin, state, leg, l, model.min_angle(leg))
}
