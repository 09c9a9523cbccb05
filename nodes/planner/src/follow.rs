//! Waypoint following online: the goal approach of [`mod@crate::approach`] run one control tick
//! at a time on the real robot's pose (SPEC §4), so the robot drives the very law the route
//! pre-check's virtual robot drove ([`crate::check_route`]).
//!
//! Each tick takes the reference point's pose (as odometry reports it), the time since the last
//! tick and the time itself, and gives a body twist at the reference point. Inside, the pose is
//! moved to the model's origin (`reference_offset` behind), [`approach_step`] takes one step of
//! path length `speed · dt` toward the current waypoint, and the twist is the one that drives
//! that step in `dt`: on a steered chassis v = step / dt = speed and ω = speed·tan δ / L at the
//! origin (so δ within δ_eff, exactly the step's turn, whatever the length of the tick), on the omni chassis the step's translation, heading
//! held. The twist is then moved to the reference point (vy += ω·d), where `cmd_vel` is
//! expressed. Holding it over the tick drives the step's arc rather than the step's
//! straight chord: the two differ by O(step²/R), under 0.3 mm for MOBIL-II's 0.73 m radius at
//! 0.02 m steps.
//!
//! The stops are the approach's, as the pre-check applies them, with the reference point's
//! distance Z:
//! - **reached**: Z < Z_crit; the next waypoint is taken (several in one tick if they lie
//!   within Z_crit too);
//! - **passed by** (the progress stop, armed once the waypoint has been within steering reach,
//!   SPEC §4 Decision): the distance is compared every `check_length` of path driven (the
//!   pre-check's step, so the same ε means the same thing); no fall by more than ε then → the
//!   waypoint is missed and the next one taken from where the robot is;
//! - **distance bound**: more path on one leg than `detour_factor` × its straight length plus one
//!   circle at the minimum radius (at most `max_leg_length`), as in the pre-check → missed;
//! - **stalled**: less than `check_length` of path in `stall_time_s` (the robot does not move:
//!   blocked, or its wheels do not answer) → the whole route ends ([`FollowEnd::Stalled`]).
//!
//! Speed: `speed`, and at the last waypoint min(speed, max(min_speed, speed · Z /
//! slow_down_distance)) inside `slow_down_distance`, so the robot arrives slowly rather than
//! stopping from full speed (0 disables). The path driven is measured from the poses given
//! (odometry), not from the commands.

use std::f64::consts::TAU;

use mobil_chassis::kinematics::twist_at_reference;
use mobil_chassis::{BodyTwist, ChassisParams};
use mobil_geom::Pose2;
use nalgebra::Point2;

use crate::approach::{approach_step, bearing, check_point, distance, Motion};
use crate::error::{bounded_length, positive_finite, PlannerError, COORDINATE_LIMIT};
use crate::route::UnreachableCause;

/// Settings of the online follower; every default justified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FollowConfig {
    /// Cruise speed (m/s). Default 0.3: 60 % of MOBIL-II's and OMR-III's v_max, so the chassis
    /// limits never bind on a straight.
    pub speed: f64,
    /// Slowest speed of the slow-down at the last waypoint (m/s). Default 0.05.
    pub min_speed: f64,
    /// The slow-down at the last waypoint starts this far from it (m); 0 disables. Default
    /// 0.6: two seconds of cruise.
    pub slow_down_distance: f64,
    /// Z_crit (m): a waypoint nearer than this is reached. Default 0.16, the pre-check's (the
    /// paper's figure for MOBIL-II).
    pub critical_distance: f64,
    /// ε (m): armed, a `check_length` of path that brings the waypoint no nearer than this
    /// misses it. Default 1e-4, the pre-check's.
    pub progress_epsilon: f64,
    /// Path length (m) between two progress checks. Default 0.02: the pre-check's step, so ε
    /// is judged over the same length of path.
    pub check_length: f64,
    /// A leg may be at most this many times its straight length plus one circle at the
    /// minimum radius. Default 2, the pre-check's.
    pub detour_factor: f64,
    /// No leg may be longer than this (m). Default 50, the pre-check's.
    pub max_leg_length: f64,
    /// The route ends [`FollowEnd::Stalled`] when less than `check_length` of path is driven in
    /// this long (s). Default 5.
    pub stall_time_s: f64,
}

impl Default for FollowConfig {
    fn default() -> Self {
        FollowConfig {
            speed: 0.3,
            min_speed: 0.05,
            slow_down_distance: 0.6,
            critical_distance: 0.16,
            progress_epsilon: 1e-4,
            check_length: 0.02,
            detour_factor: 2.0,
            max_leg_length: 50.0,
            stall_time_s: 5.0,
        }
    }
}

impl FollowConfig {
    /// Checks every field: speeds, lengths and the stall time finite and positive (the
    /// slow-down distance may be 0), `min_speed` ≤ `speed`, ε finite and ≥ 0, the detour
    /// factor finite and ≥ 1.
    pub fn validate(&self) -> Result<(), PlannerError> {
        bounded_length("speed", self.speed, COORDINATE_LIMIT)?;
        bounded_length("min_speed", self.min_speed, COORDINATE_LIMIT)?;
        bounded_length("critical_distance", self.critical_distance, COORDINATE_LIMIT)?;
        bounded_length("check_length", self.check_length, COORDINATE_LIMIT)?;
        positive_finite("max_leg_length", self.max_leg_length)?;
        positive_finite("stall_time_s", self.stall_time_s)?;
        if self.min_speed > self.speed {
            return Err(PlannerError::InvalidConfig {
                name: "min_speed",
                value: self.min_speed,
                reason: "must not exceed speed",
            });
        }
        if !(self.slow_down_distance.is_finite() && self.slow_down_distance >= 0.0) {
            return Err(PlannerError::InvalidConfig {
                name: "slow_down_distance",
                value: self.slow_down_distance,
                reason: "must be finite and non-negative",
            });
        }
        if !(self.progress_epsilon.is_finite() && self.progress_epsilon >= 0.0) {
            return Err(PlannerError::InvalidConfig {
                name: "progress_epsilon",
                value: self.progress_epsilon,
                reason: "must be finite and non-negative",
            });
        }
        if !(self.detour_factor.is_finite() && self.detour_factor >= 1.0) {
            return Err(PlannerError::InvalidConfig {
                name: "detour_factor",
                value: self.detour_factor,
                reason: "must be finite and at least 1",
            });
        }
        Ok(())
    }
}

/// Something that happened to a waypoint during a tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FollowEvent {
    /// The reference point came within Z_crit of waypoint `index`.
    Reached {
        /// The waypoint's index.
        index: usize,
    },
    /// Waypoint `index` was given up (the next one is taken from where the robot is).
    Missed {
        /// The waypoint's index.
        index: usize,
        /// Why: passed by (closest approach) or the leg's distance bound.
        cause: UnreachableCause,
    },
}

/// How a route ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FollowEnd {
    /// Every waypoint was taken in turn (reached or missed; see [`WaypointFollower::missed`]).
    Done,
    /// The robot drove less than `check_length` in `stall_time_s`.
    Stalled,
}

/// One tick's result.
#[derive(Debug, Clone, PartialEq)]
pub struct FollowOutput {
    /// The command: a body twist at the reference point (zero once the route has ended).
    pub twist: BodyTwist,
    /// The waypoint pursued after this tick (`len()` once every one was taken).
    pub index: usize,
    /// Distance Z (m) of the reference point to the pursued waypoint (0 once ended).
    pub distance: f64,
    /// δ (rad) of this tick's step (0 on the omni chassis).
    pub steering: f64,
    /// Waypoints reached or missed in this tick, in order.
    pub events: Vec<FollowEvent>,
    /// Set once the route has ended (this tick or before).
    pub end: Option<FollowEnd>,
}

/// The goal approach through a list of waypoints, one control tick at a time (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct WaypointFollower {
    config: FollowConfig,
    motion: Motion,
    offset: f64,
    waypoints: Vec<Point2<f64>>,
    index: usize,
    missed: Vec<(usize, UnreachableCause)>,
    end: Option<FollowEnd>,
    leg: Option<Leg>,
    last_position: Option<Point2<f64>>,
}

/// The state of the leg into the current waypoint.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Leg {
    armed: bool,
    budget: f64,
    travelled: f64,
    closest: f64,
    /// Z and the path length at the last progress check.
    checked_distance: f64,
    checked_at: f64,
    /// The time of the last progress check (or of the leg's start).
    checked_t: f64,
}

impl WaypointFollower {
    /// A follower for `chassis` (its motion and `reference_offset`) through `waypoints` (at
    /// least one, each finite and within [`COORDINATE_LIMIT`]).
    pub fn new(
        config: FollowConfig,
        chassis: &ChassisParams,
        waypoints: Vec<Point2<f64>>,
    ) -> Result<Self, PlannerError> {
        Self::with_motion(
            config,
            Motion::from_chassis(chassis),
            chassis.reference_offset(),
            waypoints,
        )
    }

    /// A follower for a given motion model and reference offset `offset` (m, finite).
    pub fn with_motion(
        config: FollowConfig,
        motion: Motion,
        offset: f64,
        waypoints: Vec<Point2<f64>>,
    ) -> Result<Self, PlannerError> {
        config.validate()?;
        if !offset.is_finite() || offset.abs() > COORDINATE_LIMIT {
            return Err(PlannerError::InvalidConfig {
                name: "reference_offset",
                value: offset,
                reason: "must be finite",
            });
        }
        if waypoints.is_empty() {
            return Err(PlannerError::EmptyRoute);
        }
        for (i, w) in waypoints.iter().enumerate() {
            check_point(&format!("waypoint {i}"), w)?;
        }
        Ok(WaypointFollower {
            config,
            motion,
            offset,
            waypoints,
            index: 0,
            missed: Vec::new(),
            end: None,
            leg: None,
            last_position: None,
        })
    }

    /// The waypoints.
    pub fn waypoints(&self) -> &[Point2<f64>] {
        &self.waypoints
    }

    /// The waypoint pursued (`waypoints().len()` once all were taken).
    pub fn index(&self) -> usize {
        self.index
    }

    /// The waypoints missed so far, with their causes, in order.
    pub fn missed(&self) -> &[(usize, UnreachableCause)] {
        &self.missed
    }

    /// How the route ended, once it has.
    pub fn end(&self) -> Option<FollowEnd> {
        self.end
    }

    /// The settings.
    pub fn config(&self) -> &FollowConfig {
        &self.config
    }

    /// One control tick at `pose` (the reference point's, as odometry gives it), `dt` seconds
    /// (finite, > 0) after the last tick, at time `t` (s, any origin, non-decreasing). Refuses
    /// a non-finite or out-of-range pose and a bad `dt` (the caller stops the robot).
    pub fn update(&mut self, pose: &Pose2, dt: f64, t: f64) -> Result<FollowOutput, PlannerError> {
        crate::docking::check_pose("pose", pose)?;
        if !(dt.is_finite() && dt > 0.0 && dt <= COORDINATE_LIMIT) {
            return Err(PlannerError::InvalidConfig {
                name: "dt",
                value: dt,
                reason: "must be finite and positive",
            });
        }
        if !t.is_finite() {
            return Err(PlannerError::NonFinite {
                what: "time".into(),
                x: t,
                y: 0.0,
                yaw: 0.0,
            });
        }
        let moved = self.last_position.map_or(0.0, |p| (pose.position() - p).norm());
        self.last_position = Some(pose.position());
        let mut events = Vec::new();
        if self.end.is_none() {
            self.advance(pose, moved, t, &mut events);
        }
        let Some(goal) = self.waypoints.get(self.index).copied().filter(|_| self.end.is_none()) else {
            return Ok(FollowOutput {
                twist: BodyTwist::new(0.0, 0.0, 0.0),
                index: self.index,
                distance: 0.0,
                steering: 0.0,
                events,
                end: self.end,
            });
        };
        let z = distance(pose, &goal);
        let speed = self.speed_at(z);
        let origin = pose.ahead(-self.offset);
        let step = approach_step(&origin, &goal, speed * dt, &self.motion)?;
        let twist = match self.motion {
            Motion::Steered(steering) => {
                // The step's turn rate, not its heading change over dt: the same for any dt,
                // where wrap(Δϑ)/dt would fold a turn beyond π in a long tick.
                let omega = speed * step.steering.tan() / steering.wheelbase();
                twist_at_reference(BodyTwist::new(speed, 0.0, omega), self.offset)
            }
            Motion::Holonomic => {
                let world = step.pose.position() - origin.position();
                let (s, c) = origin.yaw.sin_cos();
                BodyTwist::new((c * world.x + s * world.y) / dt, (-s * world.x + c * world.y) / dt, 0.0)
            }
        };
        Ok(FollowOutput {
            twist,
            index: self.index,
            distance: z,
            steering: step.steering,
            events,
            end: None,
        })
    }

    /// The speed toward a waypoint at distance `z`: the slow-down applies at the last one.
    fn speed_at(&self, z: f64) -> f64 {
        let c = &self.config;
        if self.index + 1 == self.waypoints.len() && z < c.slow_down_distance {
            (c.speed * z / c.slow_down_distance).clamp(c.min_speed, c.speed)
        } else {
            c.speed
        }
    }

    /// Reach-range of the progress stop's arming: δ_eff, or everywhere for the omni chassis.
    fn reach(&self) -> f64 {
        match self.motion {
            Motion::Steered(s) => s.limit(),
            Motion::Holonomic => std::f64::consts::PI + 1.0,
        }
    }

    fn start_leg(&mut self, pose: &Pose2, t: f64) -> Option<Leg> {
        let goal = *self.waypoints.get(self.index)?;
        let origin = pose.ahead(-self.offset);
        let z = distance(pose, &goal);
        let budget = (self.config.detour_factor * z + TAU * self.motion.min_radius()).min(self.config.max_leg_length);
        Some(Leg {
            armed: bearing(&origin, &goal).abs() < self.reach(),
            budget,
            travelled: 0.0,
            closest: z,
            checked_distance: z,
            checked_at: 0.0,
            checked_t: t,
        })
    }

    /// The stops, for the pose reached after `moved` metres of path.
    fn advance(&mut self, pose: &Pose2, moved: f64, t: f64, events: &mut Vec<FollowEvent>) {
        let cfg = self.config;
        if let Some(leg) = &mut self.leg {
            leg.travelled += moved;
        }
        loop {
            let Some(goal) = self.waypoints.get(self.index).copied() else {
                self.end = Some(FollowEnd::Done);
                self.leg = None;
                return;
            };
            let mut leg = match self.leg {
                Some(l) => l,
                None => match self.start_leg(pose, t) {
                    Some(l) => l,
                    None => return,
                },
            };
            let z = distance(pose, &goal);
            leg.closest = leg.closest.min(z);
            let outcome = if z < cfg.critical_distance {
                Some(FollowEvent::Reached { index: self.index })
            } else if leg.travelled >= leg.budget {
                Some(FollowEvent::Missed {
                    index: self.index,
                    cause: UnreachableCause::DistanceBound {
                        travelled: leg.travelled,
                        remaining: z,
                    },
                })
            } else if leg.travelled - leg.checked_at >= cfg.check_length * (1.0 - 1e-9) {
                let progress = leg.checked_distance - z;
                leg.checked_distance = z;
                leg.checked_at = leg.travelled;
                leg.checked_t = t;
                if leg.armed && progress <= cfg.progress_epsilon {
                    Some(FollowEvent::Missed {
                        index: self.index,
                        cause: UnreachableCause::PassedBy { closest: leg.closest },
                    })
                } else {
                    None
                }
            } else {
                None
            };
            match outcome {
                Some(event) => {
                    if let FollowEvent::Missed { index, cause } = event {
                        self.missed.push((index, cause));
                    }
                    events.push(event);
                    self.index += 1;
                    self.leg = None;
                }
                None => {
                    if t - leg.checked_t > cfg.stall_time_s {
                        self.end = Some(FollowEnd::Stalled);
                        self.leg = None;
                        return;
                    }
                    leg.armed |= bearing(&pose.ahead(-self.offset), &goal).abs() < self.reach();
                    self.leg = Some(leg);
                    return;
                }
            }
        }
    }
}
