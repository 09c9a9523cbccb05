//! The VFO waypoint follower online: one control tick at a time on the real robot's pose,
//! Algorithm 2 at every segment start and whenever the obstacles change.
//!
//! Each [`VfoFollower::update`] takes the robot's pose (q = [θ, x, y], as odometry gives it)
//! and the time. When a segment starts (the first tick, a waypoint switch), when the caller
//! reports a new obstacle ([`VfoFollower::set_obstacles`] with `new_obstacles`,
//! [`VfoFollower::add_obstacle`]) or when the robot enters an influence zone whose σ the last
//! optimisation left undecided (it did not foresee that zone), the segment is re-optimised from
//! the real state ([`find_sigmas`](super::find_sigmas)) before the command is worked out. The tick then applies the
//! law with the segment's Σ: Algorithm 3, Algorithm 1 (the next waypoint in the same tick) or
//! the end test, u = [ω, v].
//!
//! **A segment that starts inside an influence zone starts from rest.** At a waypoint switch
//! the law's command jumps (the new waypoint may lie behind the robot), and the virtual robots
//! take the new command at once, while the real robot answers with its drives' lag and coasts
//! on. Outside every zone that costs a few centimetres of path; inside one — after Algorithm 3
//! passed a waypoint early, deep in a zone, where V grows steeply toward r — the real robot
//! coasts toward the obstacle from where the virtual robots turned away, and leaves their
//! paths: the next re-optimisation starts a few centimetres from r, where every Σ collides (no
//! safe Σ), or the robot collides on the old Σ. So when a segment starts with the robot inside
//! a zone, the follower commands zero until the robot is at rest (it moved less than
//! [`REST_SPEED`]·Δt and turned less than [`REST_TURN_RATE`]·Δt over each of
//! [`REST_INTERVALS`] consecutive intervals between poses, Δt timed by the poses' own stamps
//! — a pose republished with its old stamp is no interval, and one timed by its arrival would
//! read still — or [`MAX_SETTLE_S`] passed), and only then optimises the segment, from the pose where the robot
//! stands: a state the real robot is really in, from which it can start as the virtual robots
//! do. The same holds for a re-optimisation inside a zone (a new obstacle, an undecided zone
//! entered): the robot is brought to rest first. [`VfoFollower::is_settling`] tells the caller
//! why the robot stands.
//!
//! Safety: on a collision (d ≤ r, checked on every tick, holding or not), or when no safe Σ
//! exists for the segment, the command is zero and the route ends ([`VfoEnd`]); the caller
//! reports it. An optimisation whose wall-clock budget ran out before any candidate proved
//! nothing unsafe: the follower holds zero and retries on the next ticks, and only after
//! [`MAX_BUDGET_RETRIES`] such optimisations in a row ends the route with
//! [`VfoEnd::BudgetExhausted`]. Bad input (a non-finite pose,
//! time going backwards) is refused with a [`PlannerError`] and changes nothing; the caller
//! commands zero.

use mobil_geom::Pose2;

use super::controller::{ControlStep, StepOutcome, VfoController, VfoGains, VfoWaypoint};
use super::obstacles::{Obstacle, Sigma};
use super::optimise::{find_sigmas_until, Interrupt, Optimisation, OptimiseConfig, OptimiseWarning, Segment};
use super::scan::ObstacleMap;
use crate::error::PlannerError;

/// Below this speed (m/s) between two ticks the robot is at rest (module docs).
pub const REST_SPEED: f64 = 0.01;
/// Below this turn rate (rad/s) between two ticks the robot is at rest (module docs).
pub const REST_TURN_RATE: f64 = 0.05;
/// Consecutive still intervals between poses that make rest (module docs): one still interval
/// may be a repeated sample; three (60 ms of 50 Hz odometry) are not.
pub const REST_INTERVALS: u32 = 3;
/// The longest wait for the robot to come to rest before a segment started inside a zone is
/// optimised anyway (s): a robot that never reads still (odometry noise) must not wait forever.
pub const MAX_SETTLE_S: f64 = 2.0;
/// Optimisations in a row whose budget ran out before any candidate, after which the route
/// ends ([`VfoEnd::BudgetExhausted`]): three ticks of held zero (0.15 s at 20 Hz) ride out a
/// passing load on the machine, more means the budget is too small for the scene.
pub const MAX_BUDGET_RETRIES: u32 = 3;

/// Something that happened during a tick.
#[derive(Debug, Clone, PartialEq)]
pub enum VfoEvent {
    /// Waypoint `index` was reached (Algorithm 1; `vortex`: with ϵ_i enlarged by Algorithm 3).
    Reached {
        /// The waypoint's index.
        index: usize,
        /// Algorithm 3 fired.
        vortex: bool,
    },
    /// Segment `index` was optimised (why: [`Reoptimised`]); the result is
    /// [`VfoFollower::last_optimisation`].
    Optimised {
        /// The segment's waypoint index.
        index: usize,
        /// Why.
        reason: Reoptimised,
        /// Ψ_z of the chosen Σ (`None`: no safe Σ).
        score: Option<f64>,
        /// Limits the optimisation hit.
        warnings: Vec<OptimiseWarning>,
    },
}

/// Why a segment was optimised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reoptimised {
    /// A segment started.
    SegmentStart,
    /// The caller reported a new obstacle.
    NewObstacle,
    /// The robot entered a zone whose σ was undecided.
    UndecidedZone,
}

/// How a route ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VfoEnd {
    /// The last waypoint was reached within ϵ.
    Done,
    /// The robot is inside the forbidden zone of obstacle `obstacle`.
    Collision {
        /// The obstacle's index.
        obstacle: usize,
    },
    /// No candidate path for segment `index`: no safe Σ exists (or none within the caps).
    NoSafePath {
        /// The waypoint index.
        index: usize,
    },
    /// The wall-clock budget ran out before any candidate for segment `index`, on
    /// [`MAX_BUDGET_RETRIES`] optimisations in a row: nothing was proven unsafe, but no Σ
    /// was found in time.
    BudgetExhausted {
        /// The waypoint index.
        index: usize,
    },
}

/// One tick's result.
#[derive(Debug, Clone, PartialEq)]
pub struct VfoOutput {
    /// Angular velocity ω (rad/s); 0 once ended.
    pub omega: f64,
    /// Linear velocity v (m/s); 0 once ended.
    pub v: f64,
    /// The waypoint pursued after this tick (`len()` once done).
    pub index: usize,
    /// ‖e*_i‖ (m) to the pursued waypoint (0 once ended).
    pub distance: f64,
    /// The law's step (`None` once ended).
    pub step: Option<ControlStep>,
    /// What happened, in order.
    pub events: Vec<VfoEvent>,
    /// Set once the route has ended.
    pub end: Option<VfoEnd>,
}

/// The VFO follower: waypoints, known obstacles, the segment's Σ and the last optimisation.
#[derive(Debug, Clone)]
pub struct VfoFollower {
    config: OptimiseConfig,
    controller: VfoController,
    waypoints: Vec<VfoWaypoint>,
    obstacles: Vec<Obstacle>,
    sigmas: Vec<Sigma>,
    index: usize,
    optimise: Option<Reoptimised>,
    last: Option<Optimisation>,
    last_t: Option<f64>,
    end: Option<VfoEnd>,
    /// Waiting for rest before optimising: since when, and the last tick's pose and time.
    settling: Option<Settling>,
    /// Optimisations in a row whose budget ran out before any candidate.
    budget_misses: u32,
}

#[derive(Debug, Clone, Copy)]
struct Settling {
    since: f64,
    /// The last pose and its stamp.
    last: Option<(Pose2, f64)>,
    /// Still intervals in a row.
    still: u32,
}

impl VfoFollower {
    /// A follower through `waypoints` (at least one) with the law's `gains` and Algorithm 2's
    /// `config`, knowing `obstacles` from the start.
    pub fn new(
        gains: VfoGains,
        config: OptimiseConfig,
        waypoints: Vec<VfoWaypoint>,
        obstacles: Vec<Obstacle>,
    ) -> Result<Self, PlannerError> {
        config.validate()?;
        if waypoints.is_empty() {
            return Err(PlannerError::EmptyRoute);
        }
        for (i, w) in waypoints.iter().enumerate() {
            VfoWaypoint::new(w.position.x, w.position.y, w.heading, w.guiding).map_err(|e| match e {
                PlannerError::NonFinite { x, y, yaw, .. } => PlannerError::NonFinite {
                    what: format!("waypoint {i}"),
                    x,
                    y,
                    yaw,
                },
                other => other,
            })?;
        }
        let n = obstacles.len();
        Ok(VfoFollower {
            config,
            controller: VfoController::new(gains)?,
            waypoints,
            obstacles,
            sigmas: vec![Sigma::Undecided; n],
            index: 0,
            optimise: Some(Reoptimised::SegmentStart),
            last: None,
            last_t: None,
            end: None,
            settling: None,
            budget_misses: 0,
        })
    }

    /// The waypoints.
    pub fn waypoints(&self) -> &[VfoWaypoint] {
        &self.waypoints
    }

    /// The waypoint pursued (`waypoints().len()` once done).
    pub fn index(&self) -> usize {
        self.index
    }

    /// The known obstacles (σ indices follow them).
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.obstacles
    }

    /// The current segment's Σ.
    pub fn sigmas(&self) -> &[Sigma] {
        &self.sigmas
    }

    /// The last optimisation: every virtual robot's path with its Σ, every path's fate, Ψ_z
    /// and the χ's.
    pub fn last_optimisation(&self) -> Option<&Optimisation> {
        self.last.as_ref()
    }

    /// Whether the follower is bringing the robot to rest before it optimises a segment that
    /// started inside an influence zone (module docs).
    pub fn is_settling(&self) -> bool {
        self.settling.is_some()
    }

    /// How the route ended, once it has.
    pub fn end(&self) -> Option<VfoEnd> {
        self.end
    }

    /// Adds one obstacle; the segment is re-optimised at the next tick.
    pub fn add_obstacle(&mut self, obstacle: Obstacle) {
        self.obstacles.push(obstacle);
        self.sigmas.push(Sigma::Undecided);
        self.optimise.get_or_insert(Reoptimised::NewObstacle);
    }

    /// Replaces the obstacles by a list that only grew: the same indices for the same
    /// obstacles, new ones appended (an [`ObstacleMap`] removes and re-indexes: follow one with
    /// [`Self::follow_map`]). With `new_obstacles` the segment is re-optimised at the next tick;
    /// without, Σ is kept (new entries undecided).
    pub fn set_obstacles(&mut self, obstacles: Vec<Obstacle>, new_obstacles: bool) {
        self.sigmas.resize(obstacles.len(), Sigma::Undecided);
        self.obstacles = obstacles;
        if new_obstacles {
            self.optimise.get_or_insert(Reoptimised::NewObstacle);
        }
    }

    /// Replaces the obstacles by a map in which some were removed or reordered: `previous[k]`
    /// is the index, among the obstacles before, of obstacle `k` (`None`: a new one). Each kept
    /// obstacle keeps its σ; new ones are undecided. With `new_obstacles` the segment is
    /// re-optimised at the next tick. Removing an obstacle never re-optimises by itself: the
    /// decisions left stay those of a path that was safe with more obstacles.
    pub fn set_obstacles_mapped(&mut self, obstacles: Vec<Obstacle>, previous: &[Option<usize>], new_obstacles: bool) {
        self.sigmas = (0..obstacles.len())
            .map(|k| {
                previous
                    .get(k)
                    .copied()
                    .flatten()
                    .and_then(|i| self.sigmas.get(i).copied())
                    .unwrap_or(Sigma::Undecided)
            })
            .collect();
        self.obstacles = obstacles;
        if new_obstacles {
            self.optimise.get_or_insert(Reoptimised::NewObstacle);
        }
    }

    /// Takes the obstacles of `map`, carrying each decision over by the obstacle's id:
    /// `held_ids` are the ids of the obstacles the follower holds (by index), updated here.
    /// With `new_obstacles` the segment is re-optimised at the next tick
    /// ([`Self::set_obstacles_mapped`]).
    pub fn follow_map(&mut self, map: &ObstacleMap, held_ids: &mut Vec<u64>, new_obstacles: bool) {
        let now = map.ids();
        let previous: Vec<Option<usize>> = now
            .iter()
            .map(|id| held_ids.iter().position(|held| held == id))
            .collect();
        self.set_obstacles_mapped(map.obstacles(), &previous, new_obstacles);
        *held_ids = now;
    }

    fn optimise(
        &mut self,
        pose: &Pose2,
        reason: Reoptimised,
        events: &mut Vec<VfoEvent>,
        interrupt: &(dyn Fn() -> Option<Interrupt> + Sync),
    ) -> Result<bool, PlannerError> {
        let Some(waypoint) = self.waypoints.get(self.index).copied() else {
            return Ok(true);
        };
        let segment = Segment {
            waypoint,
            last: self.index + 1 == self.waypoints.len(),
            obstacles: &self.obstacles,
        };
        let result = find_sigmas_until(pose, &self.controller, &segment, &self.config, interrupt)?;
        events.push(VfoEvent::Optimised {
            index: self.index,
            reason,
            score: result.score(),
            warnings: result.warnings.clone(),
        });
        let starved = result.best.is_none()
            && result
                .warnings
                .iter()
                .any(|w| matches!(w, OptimiseWarning::WallTimeBudget { .. }));
        if starved {
            // Nothing proven unsafe: keep the old Σ, hold, retry (module docs).
            self.budget_misses += 1;
            if self.budget_misses >= MAX_BUDGET_RETRIES {
                self.end = Some(VfoEnd::BudgetExhausted { index: self.index });
            }
        } else {
            self.budget_misses = 0;
            self.sigmas = result.sigmas.clone();
            if result.best.is_none() {
                self.end = Some(VfoEnd::NoSafePath { index: self.index });
            }
        }
        self.last = Some(result);
        Ok(!starved)
    }

    /// Whether `pose` lies inside some obstacle's influence zone.
    fn in_zone(&self, pose: &Pose2) -> bool {
        let position = pose.position();
        self.obstacles
            .iter()
            .any(|o| o.distance(&position) <= o.influence_radius())
    }

    /// The obstacle whose forbidden zone (d ≤ r) holds `pose`, if any.
    fn collision(&self, pose: &Pose2) -> Option<usize> {
        let position = pose.position();
        self.obstacles
            .iter()
            .position(|o| o.distance(&position) <= o.forbidden_radius())
    }

    fn hold(&self, pose: &Pose2, events: Vec<VfoEvent>) -> VfoOutput {
        VfoOutput {
            omega: 0.0,
            v: 0.0,
            index: self.index,
            distance: self
                .waypoints
                .get(self.index)
                .map_or(0.0, |w| (w.position - pose.position()).norm()),
            step: None,
            events,
            end: None,
        }
    }

    /// One control tick at `pose` (θ, x, y of the robot's guide point) at time `t` (s,
    /// non-decreasing). Refuses a non-finite or out-of-range pose or time.
    pub fn update(&mut self, pose: &Pose2, t: f64) -> Result<VfoOutput, PlannerError> {
        self.update_until(pose, t, &|| None)
    }

    /// [`VfoFollower::update`] whose optimisation asks `interrupt` whether to stop
    /// ([`find_sigmas_until`]): on [`Interrupt::Cancel`] the tick returns
    /// [`PlannerError::Stopped`] and the segment stays due for optimisation; on
    /// [`Interrupt::Budget`] the best Σ found so far is taken, with the warning in the
    /// [`VfoEvent::Optimised`] event.
    pub fn update_until(
        &mut self,
        pose: &Pose2,
        t: f64,
        interrupt: &(dyn Fn() -> Option<Interrupt> + Sync),
    ) -> Result<VfoOutput, PlannerError> {
        self.update_stamped(pose, t, t, interrupt)
    }

    /// [`VfoFollower::update_until`] with `pose_stamp` (s), the time the pose was measured
    /// (the odometry's stamp, on its own clock): the rest test times the pose changes by it
    /// (module docs). A non-finite stamp is no interval.
    pub fn update_stamped(
        &mut self,
        pose: &Pose2,
        t: f64,
        pose_stamp: f64,
        interrupt: &(dyn Fn() -> Option<Interrupt> + Sync),
    ) -> Result<VfoOutput, PlannerError> {
        crate::docking::check_pose("pose", pose)?;
        if !t.is_finite() || self.last_t.is_some_and(|last| t < last) {
            return Err(PlannerError::InvalidConfig {
                name: "t",
                value: t,
                reason: "time must be finite and must not go backwards",
            });
        }
        self.last_t = Some(t);
        let mut events = Vec::new();
        // Whether the robot came to rest in this tick (it then optimises without a new wait).
        let mut settled = false;
        if self.end.is_none()
            && let Some(obstacle) = self.collision(pose)
        {
            self.end = Some(VfoEnd::Collision { obstacle });
        }
        loop {
            if self.end.is_some() {
                return Ok(self.stopped(events));
            }
            let Some(waypoint) = self.waypoints.get(self.index).copied() else {
                self.end = Some(VfoEnd::Done);
                continue;
            };
            if let Some(settling) = self.settling.as_mut() {
                match settling.last {
                    // The same sample again (or no usable stamp): no interval.
                    Some((_, s0)) if !(pose_stamp.is_finite() && pose_stamp != s0) => {}
                    Some((p, s0)) => {
                        let dt = pose_stamp - s0;
                        let still = dt > 0.0
                            && (p.position() - pose.position()).norm() < REST_SPEED * dt
                            && mobil_geom::wrap(pose.yaw - p.yaw).abs() < REST_TURN_RATE * dt;
                        settling.still = if still { settling.still + 1 } else { 0 };
                        settling.last = Some((*pose, pose_stamp));
                    }
                    None => {
                        if pose_stamp.is_finite() {
                            settling.last = Some((*pose, pose_stamp));
                        }
                    }
                }
                if settling.still >= REST_INTERVALS || t - settling.since >= MAX_SETTLE_S {
                    self.settling = None;
                    settled = true;
                } else {
                    return Ok(self.hold(pose, events));
                }
            }
            if let Some(reason) = self.optimise {
                // A re-optimisation inside a zone starts from rest too (module docs).
                if reason != Reoptimised::SegmentStart && !settled && self.in_zone(pose) {
                    self.settling = Some(Settling {
                        since: t,
                        last: Some((*pose, pose_stamp)).filter(|_| pose_stamp.is_finite()),
                        still: 0,
                    });
                    return Ok(self.hold(pose, events));
                }
            }
            if let Some(reason) = self.optimise.take() {
                match self.optimise(pose, reason, &mut events, interrupt) {
                    Ok(true) => {}
                    Ok(false) => {
                        // Starved by the budget: due again on the next tick, zero meanwhile.
                        if self.end.is_none() {
                            self.optimise = Some(reason);
                            return Ok(self.hold(pose, events));
                        }
                    }
                    Err(e) => {
                        self.optimise = Some(reason);
                        return Err(e);
                    }
                }
                continue;
            }
            // A zone the optimisation did not foresee: decide it now.
            let position = pose.position();
            let undecided = self
                .obstacles
                .iter()
                .zip(&self.sigmas)
                .any(|(o, s)| *s == Sigma::Undecided && o.distance(&position) <= o.influence_radius());
            if undecided && !matches!(events.last(), Some(VfoEvent::Optimised { .. })) {
                self.optimise = Some(Reoptimised::UndecidedZone);
                continue;
            }
            let last = self.index + 1 == self.waypoints.len();
            let step = self
                .controller
                .step(pose, &waypoint, last, &self.obstacles, &self.sigmas);
            match step.outcome {
                StepOutcome::Drive => {
                    return Ok(VfoOutput {
                        omega: step.omega,
                        v: step.v,
                        index: self.index,
                        distance: step.field.error.norm(),
                        step: Some(step),
                        events,
                        end: None,
                    });
                }
                StepOutcome::Reached { vortex } => {
                    events.push(VfoEvent::Reached {
                        index: self.index,
                        vortex,
                    });
                    self.index += 1;
                    self.controller.start_segment();
                    if self.index < self.waypoints.len() {
                        self.optimise = Some(Reoptimised::SegmentStart);
                        if self.in_zone(pose) {
                            self.settling = Some(Settling {
                                since: t,
                                last: Some((*pose, pose_stamp)).filter(|_| pose_stamp.is_finite()),
                                still: 0,
                            });
                        }
                    }
                }
                StepOutcome::Collision { obstacle } => {
                    self.end = Some(VfoEnd::Collision { obstacle });
                }
            }
        }
    }

    fn stopped(&self, events: Vec<VfoEvent>) -> VfoOutput {
        VfoOutput {
            omega: 0.0,
            v: 0.0,
            index: self.index,
            distance: 0.0,
            step: None,
            events,
            end: self.end,
        }
    }
}
