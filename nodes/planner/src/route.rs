//! Route pre-check by a virtual robot (SPEC §4, MOBIL-II HIGH-LEVEL): before a route is sent to
//! the robot, a virtual robot drives it in simulation — the goal approach of
//! [`mod@crate::approach`] on the chosen chassis model, waypoint after waypoint — against a known
//! map (a [`mobil_world::World`], the sim's world format and geometry) and every problem is
//! reported with the index of its waypoint:
//!
//! Poses are those of the chassis' reference point, `reference_offset` ahead of the kinematic
//! origin ([`ChassisParams::reference_offset`]): the point odometry reports, the centre of the
//! sim's collision disc, and the point a route's waypoints are meant for. The start is converted
//! to the model's origin, the model is driven there (the goal approach steers the origin), and
//! clearance is tested at the reference point; a waypoint counts as reached when the
//! **reference point** comes within Z_crit of it.
//!
//! - [`ProblemKind::Collision`]: the robot's footprint (a disc of `robot_radius` around the
//!   reference point) overlaps an obstacle on the leg into waypoint i. Each stretch of overlap
//!   is one problem, at the point where it begins. The virtual robot drives on through it (a
//!   ghost), so one collision does not hide the problems behind it.
//! - [`ProblemKind::TurnRadius`]: the arc the origin must drive from where the leg began
//!   (tangent to the heading there) so that the reference point passes through waypoint i
//!   ([`arc_radius`]) is tighter than the chassis' minimum L / tan δ_eff — reported whether or
//!   not the virtual robot came within Z_crit of the waypoint.
//! - [`ProblemKind::Unreachable`]: waypoint i was not reached for another cause: its own
//!   footprint overlaps an obstacle (blocked), the closest approach passed outside Z_crit, or
//!   the leg's distance bound ran out.
//!
//! After a waypoint that was not reached the virtual robot is set down with its reference point
//! on it, heading along the leg's chord, so later legs are checked as if it had been reached. The check is deterministic:
//! no clock, no randomness; the leg bound is a path length.

use std::f64::consts::TAU;

use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_world::World;
use nalgebra::Point2;

use crate::approach::{approach_with, check_point, distance, ApproachConfig, ApproachEnd, Motion};
use crate::error::{positive_finite, PlannerError};

/// Settings of the route pre-check; every default justified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RouteCheckConfig {
    /// The virtual robot's goal approach (step length, Z_crit, ε, step limit).
    pub approach: ApproachConfig,
    /// Radius (m) of the footprint disc around the reference point: the params file's
    /// `robot_radius` of the chassis (MOBIL-II 0.53, the tricycle 0.40, OMR-III 0.25). No
    /// default: [`RouteCheckConfig::new`] takes it.
    pub robot_radius: f64,
    /// A leg may be at most this many times its straight length, plus one full circle at the
    /// minimum turning radius (a car-like chassis may need one loop to line up). Default 2.
    pub detour_factor: f64,
    /// No leg may be longer than this (m), whatever its straight length. Default 50: beyond the
    /// size of the maps the suite drives; a waypoint further away is a typing error.
    pub max_leg_length: f64,
}

impl RouteCheckConfig {
    /// The defaults for a robot whose footprint disc has radius `robot_radius` (m).
    pub fn new(robot_radius: f64) -> Self {
        RouteCheckConfig {
            approach: ApproachConfig::default(),
            robot_radius,
            detour_factor: 2.0,
            max_leg_length: 50.0,
        }
    }

    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlannerError> {
        self.approach.validate()?;
        positive_finite("robot_radius", self.robot_radius)?;
        positive_finite("max_leg_length", self.max_leg_length)?;
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

/// Why a waypoint cannot be reached (other than a turn too tight).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum UnreachableCause {
    /// The robot cannot stand there: its footprint at the waypoint overlaps an obstacle.
    Blocked {
        /// Distance (m) from the waypoint to the nearest surface minus the robot radius (< 0).
        clearance: f64,
    },
    /// The virtual robot passed its closest approach outside Z_crit.
    PassedBy {
        /// The closest approach (m).
        closest: f64,
    },
    /// The leg's distance bound (or step limit) ran out.
    DistanceBound {
        /// Path driven on the leg (m).
        travelled: f64,
        /// Distance to the waypoint at the end (m).
        remaining: f64,
    },
}

/// What is wrong at a waypoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProblemKind {
    /// The footprint overlaps an obstacle on the way into the waypoint.
    Collision {
        /// Where the overlap begins (the reference point).
        at: Point2<f64>,
        /// Distance (m) from there to the nearest surface minus the robot radius (< 0).
        clearance: f64,
    },
    /// The waypoint needs a tighter turn than the chassis can make.
    TurnRadius {
        /// The radius (m) of the origin's arc from the leg's start pose on which the reference
        /// point passes through the waypoint ([`arc_radius`]).
        required: f64,
        /// The chassis' minimum L / tan δ_eff (m).
        minimum: f64,
    },
    /// The waypoint cannot be reached.
    Unreachable(UnreachableCause),
}

impl ProblemKind {
    /// A short machine-readable name: `collision`, `turn_radius`, `unreachable`.
    pub fn as_str(&self) -> &'static str {
        match self {
            ProblemKind::Collision { .. } => "collision",
            ProblemKind::TurnRadius { .. } => "turn_radius",
            ProblemKind::Unreachable(_) => "unreachable",
        }
    }
}

impl std::fmt::Display for ProblemKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ProblemKind::Collision { at, clearance } => write!(
                f,
                "collision at ({:.2}, {:.2}): footprint {:.2} m into an obstacle",
                at.x, at.y, -clearance
            ),
            ProblemKind::TurnRadius { required, minimum } => {
                write!(
                    f,
                    "turn radius {required:.2} m below the chassis minimum {minimum:.2} m"
                )
            }
            ProblemKind::Unreachable(UnreachableCause::Blocked { clearance }) => {
                write!(
                    f,
                    "unreachable: the waypoint lies {:.2} m inside an obstacle's clearance",
                    -clearance
                )
            }
            ProblemKind::Unreachable(UnreachableCause::PassedBy { closest }) => {
                write!(f, "unreachable: closest approach {closest:.2} m")
            }
            ProblemKind::Unreachable(UnreachableCause::DistanceBound { travelled, remaining }) => write!(
                f,
                "unreachable: {remaining:.2} m short after {travelled:.2} m of driving"
            ),
        }
    }
}

/// One problem, with the index (from 0) of the waypoint whose leg it lies on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RouteProblem {
    /// Index of the waypoint.
    pub index: usize,
    /// What is wrong.
    pub kind: ProblemKind,
}

/// The result of a pre-check.
#[derive(Debug, Clone, PartialEq)]
pub struct RouteReport {
    /// Every problem, in route order (by index, then as met).
    pub problems: Vec<RouteProblem>,
    /// The virtual robot's predicted path, the start first (a jump where it was set down on a
    /// waypoint it did not reach).
    pub path: Vec<Pose2>,
    /// For each waypoint, whether the virtual robot reached it (within Z_crit).
    pub reached: Vec<bool>,
}

impl RouteReport {
    /// True when the route has no problem.
    pub fn is_ok(&self) -> bool {
        self.problems.is_empty()
    }

    /// The length (m) of the predicted path, without the jumps where the virtual robot was set
    /// down on a waypoint it missed (any move longer than 2 `step`s, the check's step length).
    pub fn driven_length(&self, step: f64) -> f64 {
        self.path
            .windows(2)
            .map(|w| (w[1].position() - w[0].position()).norm())
            .filter(|d| *d <= 2.0 * step)
            .sum()
    }
}

/// Radius (m) of the arc that the origin drives from `origin` (tangent to its heading) so that
/// the reference point `offset` ahead passes through `p`. With p at (x_b, y_b) in the origin's
/// body frame: the origin circles the centre (0, R) and the reference point then the same centre
/// at radius √(R² + d²), so |p − (0, R)|² = R² + d² gives R = |x_b² + y_b² − d²| / (2|y_b|)
/// (d = 0: the arc through p itself). Infinite on the centre line.
pub fn arc_radius(origin: &Pose2, p: &Point2<f64>, offset: f64) -> f64 {
    let body = origin.inverse().transform_point(*p);
    let y = body.y.abs();
    if y == 0.0 {
        f64::INFINITY
    } else {
        (body.x * body.x + body.y * body.y - offset * offset).abs() / (2.0 * y)
    }
}

/// Pre-checks `waypoints` driven in order from `start` (the reference point's pose, as odometry
/// reports it) by the virtual robot of `chassis` in `world` (module documentation). Refuses an
/// empty route, an invalid configuration and non-finite or out-of-range input.
pub fn check_route(
    start: &Pose2,
    waypoints: &[Point2<f64>],
    chassis: &ChassisParams,
    world: &World,
    config: &RouteCheckConfig,
) -> Result<RouteReport, PlannerError> {
    check_route_until(start, waypoints, chassis, world, config, || false)
}

/// [`check_route`] that asks `stop` at every virtual step (0.02 m of path, well under a
/// microsecond of work) and between legs whether its caller still wants the answer; when `stop`
/// says true the check ends at once with [`PlannerError::Stopped`]. A superseded check so
/// frees its thread within a step instead of running its up to 0.6 s to the end.
pub fn check_route_until(
    start: &Pose2,
    waypoints: &[Point2<f64>],
    chassis: &ChassisParams,
    world: &World,
    config: &RouteCheckConfig,
    mut stop: impl FnMut() -> bool,
) -> Result<RouteReport, PlannerError> {
    config.validate()?;
    crate::docking::check_pose("start", start)?;
    if waypoints.is_empty() {
        return Err(PlannerError::EmptyRoute);
    }
    for (i, w) in waypoints.iter().enumerate() {
        check_point(&format!("waypoint {i}"), w)?;
    }
    let motion = Motion::from_chassis(chassis);
    let min_radius = motion.min_radius();
    let d = chassis.reference_offset();
    let radius = config.robot_radius;
    let clearance = |p: &Point2<f64>| world.distance_to(*p) - radius;

    let mut problems = Vec::new();
    let mut path = vec![*start];
    let mut reached = Vec::with_capacity(waypoints.len());
    // The model's origin, d behind the reference point.
    let mut origin = start.ahead(-d);
    let mut in_collision = clearance(&start.position()) < 0.0;
    if in_collision {
        problems.push(RouteProblem {
            index: 0,
            kind: ProblemKind::Collision {
                at: start.position(),
                clearance: clearance(&start.position()),
            },
        });
    }
    let mut stopped = false;
    for (index, goal) in waypoints.iter().enumerate() {
        if stop() {
            return Err(PlannerError::Stopped);
        }
        let leg_start = origin;
        let leg_start_reference = leg_start.ahead(d);
        let straight = distance(&leg_start_reference, goal);
        let budget = (config.detour_factor * straight + TAU * min_radius).min(config.max_leg_length);
        let out = approach_with(&leg_start, goal, &motion, d, &config.approach, |o, s| {
            let p = o.ahead(d);
            path.push(p);
            let c = clearance(&p.position());
            if c < 0.0 && !in_collision {
                problems.push(RouteProblem {
                    index,
                    kind: ProblemKind::Collision {
                        at: p.position(),
                        clearance: c,
                    },
                });
            }
            in_collision = c < 0.0;
            stopped = stop();
            s < budget && !stopped
        });
        if stopped {
            return Err(PlannerError::Stopped);
        }
        let blocked = clearance(goal);
        let required = arc_radius(&leg_start, goal, d);
        let ok = out.end == ApproachEnd::Reached && blocked >= 0.0;
        reached.push(ok);
        let kind = if blocked < 0.0 {
            Some(ProblemKind::Unreachable(UnreachableCause::Blocked {
                clearance: blocked,
            }))
        } else if required < min_radius {
            Some(ProblemKind::TurnRadius {
                required,
                minimum: min_radius,
            })
        } else if ok {
            None
        } else if out.end == ApproachEnd::NoProgress {
            Some(ProblemKind::Unreachable(UnreachableCause::PassedBy {
                closest: out.closest,
            }))
        } else {
            Some(ProblemKind::Unreachable(UnreachableCause::DistanceBound {
                travelled: out.travelled,
                remaining: distance(&out.pose.ahead(d), goal),
            }))
        };
        if let Some(kind) = kind {
            problems.push(RouteProblem { index, kind });
        }
        if ok {
            origin = out.pose;
            continue;
        }
        // Set the reference point down on the waypoint, heading along the leg's chord, and go
        // on from there.
        let chord = (goal.y - leg_start_reference.y).atan2(goal.x - leg_start_reference.x);
        let yaw = if straight > 0.0 { chord } else { leg_start.yaw };
        let set_down = Pose2::new(goal.x, goal.y, yaw);
        origin = set_down.ahead(-d);
        path.push(set_down);
        in_collision = blocked < 0.0;
    }
    Ok(RouteReport {
        problems,
        path,
        reached,
    })
}
