//! The planner's parameters, every default justified; `params/quadruped.yaml` holds the same
//! values (a test checks it). Flat names, so the struct deserializes from a ROS 2 parameter
//! section: a missing key takes its default.

use crate::error::GaitError;
use crate::model::LegAngleReading;
use serde::{Deserialize, Serialize};

/// Rule set A (11 rules) or B (27 rules) of SPEC §7.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum RuleSet {
    /// Rules 1..=11: rotate, step ±ΔY, maximum translation, leg to max length and max angle, leg
    /// to nominal.
    A,
    /// Rules 1..=27: set A and the single-coordinate leg moves 12..=27.
    B,
}

impl RuleSet {
    /// The number of rules in the set (11 or 27).
    pub fn rule_count(self) -> u8 {
        match self {
            RuleSet::A => 11,
            RuleSet::B => 27,
        }
    }
}

impl std::str::FromStr for RuleSet {
    type Err = GaitError;
    fn from_str(s: &str) -> Result<Self, GaitError> {
        match s {
            "A" => Ok(RuleSet::A),
            "B" => Ok(RuleSet::B),
            other => Err(GaitError::UnknownRuleSet(other.to_string())),
        }
    }
}

impl std::fmt::Display for RuleSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            RuleSet::A => "A",
            RuleSet::B => "B",
        })
    }
}

/// Evaluation function (1), (2) or (3) of SPEC §7.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Evaluation {
    /// (1) h*(i) = k1·vzd(i) + k2·dev(i): greedy best-first.
    One,
    /// (2) h*(i) = k1·(vzd(i) − vzd(j)) + k2·(dev(i) − dev(j)) + h*(j): (1) plus a constant.
    Two,
    /// (3) as (2) plus k3·step(i): (1) plus k3 per leg move on the path.
    Three,
}

impl Evaluation {
    /// 1, 2 or 3.
    pub fn number(self) -> u8 {
        match self {
            Evaluation::One => 1,
            Evaluation::Two => 2,
            Evaluation::Three => 3,
        }
    }
}

impl TryFrom<u8> for Evaluation {
    type Error = GaitError;
    fn try_from(n: u8) -> Result<Self, GaitError> {
        match n {
            1 => Ok(Evaluation::One),
            2 => Ok(Evaluation::Two),
            3 => Ok(Evaluation::Three),
            other => Err(GaitError::UnknownEvaluation(other)),
        }
    }
}

/// The coefficients k1 (distance), k2 (deviation), k3 (per leg move) of an evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weights {
    /// k1, on vzd.
    pub k1: f64,
    /// k2, on dev.
    pub k2: f64,
    /// k3, per leg move (0 for (1) and (2)).
    pub k3: f64,
}

/// The planner's parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GaitConfig {
    /// Least distance \[j\], in [0, 1), of the centre of gravity inside the support triangle
    /// while a leg moves (and inside the four feet's hull while the body moves). Default 0.03,
    /// 1.5 % of the body width: a positive margin keeps a leg from lifting with the centre on the
    /// triangle's edge (see docs/experiments/gait-paper-table.md#the-stability-margin).
    pub stability_margin: f64,
    /// ΔY of rule 2 \[j\]. Default b/3 = 1 (the paper's, SPEC §7).
    pub translation_step: f64,
    /// Quantum of the duplicate key \[j and rad\]: states whose body pose and feet agree to it are
    /// one state. Default 1e-3: a thousandth of the body width, far below any move a rule
    /// makes, so distinct stances are never merged (the SPEC's check used it).
    pub key_quantum: f64,
    /// Goal: the body centre within this distance of the goal point \[j\] (the heading is free).
    /// Default 0.5, the SPEC check's: a quarter of a maximal leg length.
    pub goal_tolerance: f64,
    /// Expansion limit of one search (`gait/compute_plan`'s 0 means this). Default 200 000:
    /// five times the paper's largest count (39 826 for A,(3)); a few hundred ms at worst.
    pub max_expansions: u32,
    /// Which extreme of a sector "max angle" names. Default forward (SPEC §7 Decision).
    pub reading: LegAngleReading,
    /// k1 of evaluations (1) and (2). Default 1 (the paper's, both sets).
    pub k1: f64,
    /// k2 of evaluations (1) and (2). Default 5 (the paper's, both sets).
    pub k2: f64,
    /// k1 of evaluation (3) with set A. Default 1 (the paper's).
    pub a3_k1: f64,
    /// k2 of evaluation (3) with set A. Default 5 (the paper's).
    pub a3_k2: f64,
    /// k3 of evaluation (3) with set A. Default 0.4 (the paper's).
    pub a3_k3: f64,
    /// k1 of evaluation (3) with set B. Default 1 (the paper's).
    pub b3_k1: f64,
    /// k2 of evaluation (3) with set B. Default 50 (the paper's).
    pub b3_k2: f64,
    /// k3 of evaluation (3) with set B. Default 0.2 (the paper's).
    pub b3_k3: f64,
    /// Which of OPEN's states tied on f (and on being a goal) is expanded first. Default
    /// oldest (FIFO): the paper states no rule; docs/experiments/gait-paper-table.md sweeps both.
    pub tie_break: TieBreak,
}

/// Which of the states tied on f the search expands first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TieBreak {
    /// The one generated first (FIFO).
    #[default]
    Oldest,
    /// The one generated last (LIFO).
    Newest,
}

impl std::str::FromStr for TieBreak {
    type Err = GaitError;
    fn from_str(s: &str) -> Result<Self, GaitError> {
        match s {
            "oldest" => Ok(TieBreak::Oldest),
            "newest" => Ok(TieBreak::Newest),
            other => Err(GaitError::UnknownTieBreak(other.to_string())),
        }
    }
}

impl Default for GaitConfig {
    fn default() -> Self {
        GaitConfig {
            stability_margin: 0.03,
            translation_step: 1.0,
            key_quantum: 1e-3,
            goal_tolerance: 0.5,
            max_expansions: 200_000,
            reading: LegAngleReading::Forward,
            k1: 1.0,
            k2: 5.0,
            a3_k1: 1.0,
            a3_k2: 5.0,
            a3_k3: 0.4,
            b3_k1: 1.0,
            b3_k2: 50.0,
            b3_k3: 0.2,
            tie_break: TieBreak::Oldest,
        }
    }
}

impl GaitConfig {
    /// The coefficients of evaluation `eval` with rule set `set` (k3 = 0 for (1) and (2)).
    pub fn weights(&self, set: RuleSet, eval: Evaluation) -> Weights {
        match (eval, set) {
            (Evaluation::One | Evaluation::Two, _) => Weights {
                k1: self.k1,
                k2: self.k2,
                k3: 0.0,
            },
            (Evaluation::Three, RuleSet::A) => Weights {
                k1: self.a3_k1,
                k2: self.a3_k2,
                k3: self.a3_k3,
            },
            (Evaluation::Three, RuleSet::B) => Weights {
                k1: self.b3_k1,
                k2: self.b3_k2,
                k3: self.b3_k3,
            },
        }
    }

    /// Refuses values no search can use: a negative or non-finite margin or weight, a
    /// non-positive step, quantum or tolerance, a zero expansion limit.
    pub fn validate(&self) -> Result<(), GaitError> {
        let check = |name: &'static str, value: f64, ok: bool, reason: &'static str| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(GaitError::InvalidParameter { name, value, reason })
            }
        };
        check(
            "stability_margin",
            self.stability_margin,
            self.stability_margin >= 0.0 && self.stability_margin < 1.0,
            "must be in [0, 1) [j]",
        )?;
        check(
            "translation_step",
            self.translation_step,
            self.translation_step > 0.0,
            "must be > 0 [j]",
        )?;
        check(
            "key_quantum",
            self.key_quantum,
            self.key_quantum >= 1e-9 && self.key_quantum <= 0.1,
            "must be in [1e-9, 0.1]",
        )?;
        check(
            "goal_tolerance",
            self.goal_tolerance,
            self.goal_tolerance > 0.0,
            "must be > 0 [j]",
        )?;
        if self.max_expansions == 0 {
            return Err(GaitError::InvalidParameter {
                name: "max_expansions",
                value: 0.0,
                reason: "must be ≥ 1",
            });
        }
        for (name, v) in [
            ("k1", self.k1),
            ("k2", self.k2),
            ("a3_k1", self.a3_k1),
            ("a3_k2", self.a3_k2),
            ("a3_k3", self.a3_k3),
            ("b3_k1", self.b3_k1),
            ("b3_k2", self.b3_k2),
            ("b3_k3", self.b3_k3),
        ] {
            check(name, v, (0.0..=1000.0).contains(&v), "must be in [0, 1000]")?;
        }
        Ok(())
    }
}
