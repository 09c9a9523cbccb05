//! Goal approach without final heading (SPEC §4; 004 §4.2.1) and the shortest step (§4.2.2).
//!
//! Each step i of the approach, for a steered chassis (wheelbase L, effective limit δ_eff):
//! Z_i = |G − q_i|; Ω_i = atan2(y_G − y_i, x_G − x_i) (Decision: atan2, not the paper's quadrant
//! rule); δ_i = wrap(Ω_i − ϑ_i) held to ±δ_eff; ϑ_{i+1} = ϑ_i + v_i·tan δ_i / L; x, y advance
//! by v_i along ϑ_{i+1}; v_{i+1} = v_i if Z_i ≥ v_i, else Z_i / 2. Here v_i is a path length per
//! step. It stops when Z < Z_crit (reached), when the distance no longer falls by more than ε
//! *and* the goal is within steering reach (Decision: |wrap(Ω − ϑ)| < δ_eff; the paper's literal
//! rule stops after one step whenever the first step moves away from the goal), or after a
//! maximum number of steps.
//!
//! An omnidirectional chassis has no steering limit: it translates straight at the goal
//! holding its heading, with the same step lengths and stops.

use mobil_chassis::ChassisParams;
use mobil_geom::{wrap, Pose2};
use nalgebra::Point2;

use crate::error::{positive_finite, PlannerError};

/// The steering geometry of a car-like or tricycle chassis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steering {
    wheelbase: f64,
    limit: f64,
}

impl Steering {
    /// Wheelbase L (m) > 0 and steering limit δ_eff (rad) in (0, π/2).
    pub fn new(wheelbase: f64, limit: f64) -> Result<Self, PlannerError> {
        positive_finite("wheelbase", wheelbase)?;
        if !(limit > 0.0 && limit < std::f64::consts::FRAC_PI_2) {
            return Err(PlannerError::InvalidConfig {
                name: "steering_limit",
                value: limit,
                reason: "must lie in (0, π/2)",
            });
        }
        Ok(Steering { wheelbase, limit })
    }

    /// A chassis' L and δ_eff ([`ChassisParams::effective_steering_limit`]); `None` for the omni
    /// chassis, which does not steer.
    pub fn from_chassis(params: &ChassisParams) -> Option<Self> {
        params.model().is_nonholonomic().then_some(Steering {
            wheelbase: params.wheelbase(),
            limit: params.effective_steering_limit(),
        })
    }

    /// Wheelbase L (m).
    pub fn wheelbase(&self) -> f64 {
        self.wheelbase
    }

    /// δ_eff (rad).
    pub fn limit(&self) -> f64 {
        self.limit
    }

    /// The smallest turning radius L / tan δ_eff (m) (MOBIL-II: 0.73).
    pub fn min_radius(&self) -> f64 {
        self.wheelbase / self.limit.tan()
    }
}

/// How the virtual robot moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// Car-like or tricycle: steers toward the goal within δ_eff.
    Steered(Steering),
    /// Omni: translates straight at the goal, heading held.
    Holonomic,
}

impl Motion {
    /// The motion of a chassis model.
    pub fn from_chassis(params: &ChassisParams) -> Self {
        Steering::from_chassis(params).map_or(Motion::Holonomic, Motion::Steered)
    }

    /// The smallest turning radius (m); 0 for the holonomic chassis.
    pub fn min_radius(&self) -> f64 {
        match self {
            Motion::Steered(s) => s.min_radius(),
            Motion::Holonomic => 0.0,
        }
    }
}

/// Settings of the goal approach; every default justified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ApproachConfig {
    /// v_0 (m per step): the path length of a full step. Default 0.02: an eighth of Z_crit, so
    /// the capture circle cannot be stepped over, and under 3 % of MOBIL-II's 0.73 m radius, so
    /// each step is close to the continuous arc (in a node: speed × control period, e.g.
    /// 0.4 m/s at 20 Hz).
    pub step_length: f64,
    /// Z_crit (m): a goal nearer than this counts as reached (dropped, the next one taken).
    /// Default 0.16: the paper's figure for MOBIL-II (004 §4.3.1).
    pub critical_distance: f64,
    /// ε (m): within steering reach, a step that brings the goal no nearer than this ends the
    /// approach (closest approach passed). Default 1e-4: 0.5 % of a step, so only a step nearly
    /// abeam of the goal counts as no progress.
    pub progress_epsilon: f64,
    /// Most steps of one approach. Default 20 000 (400 m of full steps).
    pub max_steps: usize,
}

impl Default for ApproachConfig {
    fn default() -> Self {
        ApproachConfig {
            step_length: 0.02,
            critical_distance: 0.16,
            progress_epsilon: 1e-4,
            max_steps: 20_000,
        }
    }
}

impl ApproachConfig {
    /// Checks every field: lengths finite and positive, ε finite and ≥ 0, at least one step.
    pub fn validate(&self) -> Result<(), PlannerError> {
        positive_finite("step_length", self.step_length)?;
        positive_finite("critical_distance", self.critical_distance)?;
        if !(self.progress_epsilon.is_finite() && self.progress_epsilon >= 0.0) {
            return Err(PlannerError::InvalidConfig {
                name: "progress_epsilon",
                value: self.progress_epsilon,
                reason: "must be finite and non-negative",
            });
        }
        if self.max_steps == 0 {
            return Err(PlannerError::InvalidConfig {
                name: "max_steps",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        Ok(())
    }
}

/// One step of the approach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ApproachStep {
    /// Z_i (m), before the step.
    pub distance: f64,
    /// δ_i (rad), after the limit (0 for the holonomic chassis).
    pub steering: f64,
    /// The pose after the step.
    pub pose: Pose2,
    /// v_{i+1} (m per step) for the next step.
    pub next_step_length: f64,
}

/// Distance from `pose` to `goal` (m).
pub fn distance(pose: &Pose2, goal: &Point2<f64>) -> f64 {
    (goal.x - pose.x).hypot(goal.y - pose.y)
}

/// The bearing wrap(Ω − ϑ) of `goal` seen from `pose` (rad).
pub fn bearing(pose: &Pose2, goal: &Point2<f64>) -> f64 {
    wrap((goal.y - pose.y).atan2(goal.x - pose.x) - pose.yaw)
}

/// One step of path length `v` toward `goal` (SPEC §4, steps 2–12 of 004 §4.2.1).
pub fn approach_step(pose: &Pose2, goal: &Point2<f64>, v: f64, motion: &Motion) -> ApproachStep {
    let z = distance(pose, goal);
    let (steering, next) = match motion {
        Motion::Steered(s) => {
            let delta = bearing(pose, goal).clamp(-s.limit, s.limit);
            let yaw = pose.yaw + v * delta.tan() / s.wheelbase;
            (delta, Pose2::new(pose.x + v * yaw.cos(), pose.y + v * yaw.sin(), yaw))
        }
        Motion::Holonomic => {
            let sight = (goal.y - pose.y).atan2(goal.x - pose.x);
            (
                0.0,
                Pose2::new(pose.x + v * sight.cos(), pose.y + v * sight.sin(), pose.yaw),
            )
        }
    };
    ApproachStep {
        distance: z,
        steering,
        pose: next,
        next_step_length: if z >= v { v } else { z / 2.0 },
    }
}

/// Why an approach ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ApproachEnd {
    /// Z < Z_crit.
    Reached,
    /// Within steering reach, the distance stopped falling by more than ε: the closest approach
    /// has passed outside Z_crit.
    NoProgress,
    /// The step limit (or a caller's budget) ran out.
    StepLimit,
}

/// A whole approach.
#[derive(Debug, Clone, PartialEq)]
pub struct ApproachRun {
    /// Every pose, the start first.
    pub path: Vec<Pose2>,
    /// Why it ended.
    pub end: ApproachEnd,
    /// Distance to the goal at the end (m).
    pub final_distance: f64,
    /// Smallest distance to the goal on the way (m).
    pub closest: f64,
    /// Path length driven (m).
    pub travelled: f64,
}

/// How an approach ended, without its path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ApproachOutcome {
    /// Why it ended.
    pub end: ApproachEnd,
    /// The last pose.
    pub pose: Pose2,
    /// Smallest distance to the goal on the way (m).
    pub closest: f64,
    /// Path length driven (m).
    pub travelled: f64,
}

/// Drives the approach from `start` to `goal`, calling `visit` with every new pose and the
/// path length so far; `visit` returns false to stop early (reported as
/// [`ApproachEnd::StepLimit`]). The configuration is taken as valid
/// ([`ApproachConfig::validate`]).
pub fn approach_with(
    start: &Pose2,
    goal: &Point2<f64>,
    motion: &Motion,
    config: &ApproachConfig,
    mut visit: impl FnMut(&Pose2, f64) -> bool,
) -> ApproachOutcome {
    let mut pose = *start;
    let mut v = config.step_length;
    let mut z = distance(&pose, goal);
    let mut closest = z;
    let mut travelled = 0.0;
    let reach = match motion {
        Motion::Steered(s) => s.limit,
        Motion::Holonomic => std::f64::consts::PI + 1.0,
    };
    let outcome = |end, pose, closest, travelled| ApproachOutcome {
        end,
        pose,
        closest,
        travelled,
    };
    for _ in 0..config.max_steps {
        if z < config.critical_distance {
            return outcome(ApproachEnd::Reached, pose, closest, travelled);
        }
        let step = approach_step(&pose, goal, v, motion);
        travelled += v;
        pose = step.pose;
        v = step.next_step_length;
        let z_next = distance(&pose, goal);
        closest = closest.min(z_next);
        let progress = z - z_next;
        z = z_next;
        if !visit(&pose, travelled) {
            return outcome(ApproachEnd::StepLimit, pose, closest, travelled);
        }
        if z < config.critical_distance {
            return outcome(ApproachEnd::Reached, pose, closest, travelled);
        }
        if bearing(&pose, goal).abs() < reach && progress <= config.progress_epsilon {
            return outcome(ApproachEnd::NoProgress, pose, closest, travelled);
        }
    }
    outcome(ApproachEnd::StepLimit, pose, closest, travelled)
}

/// Drives the approach from `start` to `goal` and records the path.
pub fn approach(
    start: &Pose2,
    goal: &Point2<f64>,
    motion: &Motion,
    config: &ApproachConfig,
) -> Result<ApproachRun, PlannerError> {
    config.validate()?;
    crate::docking::check_pose("start", start)?;
    check_point("goal", goal)?;
    let mut path = vec![*start];
    let out = approach_with(start, goal, motion, config, |p, _| {
        path.push(*p);
        true
    });
    Ok(ApproachRun {
        path,
        end: out.end,
        final_distance: distance(&out.pose, goal),
        closest: out.closest,
        travelled: out.travelled,
    })
}

/// The shortest step's choice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShortestStep {
    /// The chosen δ (rad).
    pub steering: f64,
    /// The pose after the step.
    pub pose: Pose2,
    /// Its distance to the goal (m).
    pub distance: f64,
}

/// Shortest step (SPEC §4; 004 §4.2.2): of `samples` steering angles evenly spread over
/// [−δ_eff, δ_eff] (at least 3, made odd so δ = 0 is one), the one whose step of path length
/// `ds` ends nearest `goal`: dϑ = ds·tan δ / L, dx = ds·cos(ϑ + dϑ), dy = ds·sin(ϑ + dϑ)
/// (Decision: world frame). Ties go to the smallest |δ|, then to the left (δ > 0).
pub fn shortest_step(pose: &Pose2, goal: &Point2<f64>, ds: f64, steering: &Steering, samples: usize) -> ShortestStep {
    let half = (samples.max(3) - 1).div_ceil(2);
    let candidate = |delta: f64| {
        let yaw = pose.yaw + ds * delta.tan() / steering.wheelbase;
        let next = Pose2::new(pose.x + ds * yaw.cos(), pose.y + ds * yaw.sin(), yaw);
        ShortestStep {
            steering: delta,
            pose: next,
            distance: distance(&next, goal),
        }
    };
    let mut best = candidate(0.0);
    for j in 1..=half {
        let delta = steering.limit * j as f64 / half as f64;
        for d in [delta, -delta] {
            let c = candidate(d);
            if c.distance < best.distance {
                best = c;
            }
        }
    }
    best
}

pub(crate) fn check_point(what: &str, p: &Point2<f64>) -> Result<(), PlannerError> {
    if p.x.is_finite() && p.y.is_finite() {
        Ok(())
    } else {
        Err(PlannerError::NonFinite {
            what: what.to_owned(),
            x: p.x,
            y: p.y,
            yaw: 0.0,
        })
    }
}
