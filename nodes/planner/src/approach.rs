//! Goal approach without final heading (SPEC §4; 004 §4.2.1) and the shortest step (§4.2.2).
//!
//! Each step i of the approach, for a steered chassis (wheelbase L, effective limit δ_eff):
//! Z_i = |G − q_i|; Ω_i = atan2(y_G − y_i, x_G − x_i) (Decision: atan2, not the paper's quadrant
//! rule); δ_i = wrap(Ω_i − ϑ_i) held to ±δ_eff; ϑ_{i+1} = ϑ_i + v_i·tan δ_i / L; x, y advance
//! by v_i along ϑ_{i+1}; v_{i+1} = v_i if Z_i ≥ v_i, else Z_i / 2. Here v_i is a path length per
//! step. It stops when Z < Z_crit (reached), when the distance no longer falls by more than ε
//! once the goal has been within steering reach, or after a maximum number of steps.
//!
//! The progress stop (Decision: only within steering reach, |wrap(Ω − ϑ)| < δ_eff) is read as
//! *armed from then on*: it arms at the first pose where the goal lies within steering reach
//! and, from then on, ends the approach at the first step whose progress is ≤ ε. Read as "within
//! reach at the same step" it never fires: a goal being passed sits near ±90°, outside δ_eff,
//! exactly when the distance stops falling, and the car circles to the step limit. The
//! paper's literal rule (no reach condition) stops after one step whenever the first step moves
//! away from a goal behind the car; armed, a goal behind is first turned towards.
//!
//! Steering and the step are those of the model's origin (the rear axle); the distance Z (to
//! Z_crit, and for the progress stop) is that of the reference point `offset` ahead of it
//! ([`ChassisParams::reference_offset`], the point odometry reports): the reference point must
//! come within Z_crit. Steering the origin at the goal puts the reference point on the line of
//! sight.
//!
//! An omnidirectional chassis has no steering limit: it translates straight at the goal
//! holding its heading, with the same step lengths and stops.

use mobil_chassis::ChassisParams;
use mobil_geom::{wrap, Pose2};
use nalgebra::Point2;

use crate::error::{bounded_length, check_coordinates, PlannerError, COORDINATE_LIMIT};

/// Most steps one approach may take ([`ApproachConfig::max_steps`]): 20 000 km of 0.02 m steps
/// is far beyond any route; it bounds the run time (about 50 ms per 10⁶ steps).
pub const MAX_APPROACH_STEPS: usize = 1_000_000;

/// Most steering samples of [`shortest_step`]: a 0.001° grid over ±δ_eff < ±90° needs fewer.
pub const MAX_SHORTEST_STEP_SAMPLES: usize = 180_001;

/// The steering geometry of a car-like or tricycle chassis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steering {
    wheelbase: f64,
    limit: f64,
}

impl Steering {
    /// Wheelbase L (m) in [0.001, 1000] (any real vehicle; the bounds keep every step finite)
    /// and steering limit δ_eff (rad) in (0, π/2).
    pub fn new(wheelbase: f64, limit: f64) -> Result<Self, PlannerError> {
        bounded_length("wheelbase", wheelbase, 1000.0)?;
        if wheelbase < 1e-3 {
            return Err(PlannerError::InvalidConfig {
                name: "wheelbase",
                value: wheelbase,
                reason: "must be at least 0.001 m",
            });
        }
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
    /// Checks every field: lengths finite, positive and within [`COORDINATE_LIMIT`], ε finite
    /// and ≥ 0, between 1 and [`MAX_APPROACH_STEPS`] steps.
    pub fn validate(&self) -> Result<(), PlannerError> {
        bounded_length("step_length", self.step_length, COORDINATE_LIMIT)?;
        bounded_length("critical_distance", self.critical_distance, COORDINATE_LIMIT)?;
        if !(self.progress_epsilon.is_finite() && self.progress_epsilon >= 0.0) {
            return Err(PlannerError::InvalidConfig {
                name: "progress_epsilon",
                value: self.progress_epsilon,
                reason: "must be finite and non-negative",
            });
        }
        if self.max_steps == 0 || self.max_steps > MAX_APPROACH_STEPS {
            return Err(PlannerError::InvalidConfig {
                name: "max_steps",
                value: self.max_steps as f64,
                reason: "must lie in 1..=MAX_APPROACH_STEPS",
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

/// One step of path length `v` (finite, positive, at most [`COORDINATE_LIMIT`]) toward `goal`
/// (SPEC §4, steps 2–12 of 004 §4.2.1), `pose` being the model's origin. Refuses a non-finite or
/// out-of-range pose, goal or step.
pub fn approach_step(pose: &Pose2, goal: &Point2<f64>, v: f64, motion: &Motion) -> Result<ApproachStep, PlannerError> {
    check_coordinates("pose", pose.x, pose.y, pose.yaw)?;
    check_point("goal", goal)?;
    bounded_length("step_length", v, COORDINATE_LIMIT)?;
    let z = distance(pose, goal);
    let (steering, next) = step(pose, goal, v, motion);
    Ok(ApproachStep {
        distance: z,
        steering,
        pose: next,
        next_step_length: next_step_length(z, v),
    })
}

/// v_{i+1} = v_i if Z_i ≥ v_i, else Z_i / 2.
fn next_step_length(z: f64, v: f64) -> f64 {
    if z >= v {
        v
    } else {
        z / 2.0
    }
}

/// The steering angle and the pose after one step of `v` (inputs taken as checked).
fn step(pose: &Pose2, goal: &Point2<f64>, v: f64, motion: &Motion) -> (f64, Pose2) {
    match motion {
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
    }
}

/// Why an approach ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ApproachEnd {
    /// Z < Z_crit.
    Reached,
    /// After the goal had been within steering reach, the distance stopped falling by more than
    /// ε: the closest approach has passed outside Z_crit.
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

/// Drives the approach of the model's origin from `start` to `goal`, the distance being that
/// of the reference point `offset` ahead of the origin; calls `visit` with every new origin pose
/// and the path length so far; `visit` returns false to stop early (reported as
/// [`ApproachEnd::StepLimit`]). Inputs are taken as checked (by the public callers).
pub(crate) fn approach_with(
    start: &Pose2,
    goal: &Point2<f64>,
    motion: &Motion,
    offset: f64,
    config: &ApproachConfig,
    mut visit: impl FnMut(&Pose2, f64) -> bool,
) -> ApproachOutcome {
    let mut pose = *start;
    let mut v = config.step_length;
    let reference_distance = |p: &Pose2| distance(&p.ahead(offset), goal);
    let mut z = reference_distance(&pose);
    let mut closest = z;
    let mut travelled = 0.0;
    let reach = match motion {
        Motion::Steered(s) => s.limit,
        Motion::Holonomic => std::f64::consts::PI + 1.0,
    };
    let mut armed = bearing(&pose, goal).abs() < reach;
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
        pose = step(&pose, goal, v, motion).1;
        travelled += v;
        v = next_step_length(z, v);
        let z_next = reference_distance(&pose);
        closest = closest.min(z_next);
        let progress = z - z_next;
        z = z_next;
        if !visit(&pose, travelled) {
            return outcome(ApproachEnd::StepLimit, pose, closest, travelled);
        }
        if z < config.critical_distance {
            return outcome(ApproachEnd::Reached, pose, closest, travelled);
        }
        if armed && progress <= config.progress_epsilon {
            return outcome(ApproachEnd::NoProgress, pose, closest, travelled);
        }
        armed |= bearing(&pose, goal).abs() < reach;
    }
    outcome(ApproachEnd::StepLimit, pose, closest, travelled)
}

/// Drives the approach from `start` (the model's origin, whose distance counts) to `goal` and
/// records the path. Refuses an invalid configuration and a non-finite or out-of-range pose or
/// goal.
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
    let out = approach_with(start, goal, motion, 0.0, config, |p, _| {
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
/// (Decision: world frame). Ties go to the smallest |δ|, then to the left (δ > 0). Refuses a
/// non-finite or out-of-range pose or goal, a `ds` that is not finite and positive or exceeds
/// [`COORDINATE_LIMIT`], and more than [`MAX_SHORTEST_STEP_SAMPLES`] samples.
pub fn shortest_step(
    pose: &Pose2,
    goal: &Point2<f64>,
    ds: f64,
    steering: &Steering,
    samples: usize,
) -> Result<ShortestStep, PlannerError> {
    check_coordinates("pose", pose.x, pose.y, pose.yaw)?;
    check_point("goal", goal)?;
    bounded_length("ds", ds, COORDINATE_LIMIT)?;
    if samples > MAX_SHORTEST_STEP_SAMPLES {
        return Err(PlannerError::InvalidConfig {
            name: "samples",
            value: samples as f64,
            reason: "must be at most MAX_SHORTEST_STEP_SAMPLES",
        });
    }
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
    Ok(best)
}

pub(crate) fn check_point(what: &str, p: &Point2<f64>) -> Result<(), PlannerError> {
    check_coordinates(what, p.x, p.y, 0.0)
}
