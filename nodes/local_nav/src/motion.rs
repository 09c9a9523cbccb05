//! Motion along a direction (SPEC §2 Decision, "motion along F"): an omni chassis translates
//! along it holding its heading; a car-like one steers toward it within δ_eff; the speed is
//! scaled down by the free distance ahead and near the goal, and is zero below the hard stop
//! distance. The result is a body-frame velocity command, always finite and within the limits.
//!
//! "Ahead" is where the robot will actually go: along the direction for an omni chassis, along
//! the arc it is commanded to drive for a car-like one ([`arc_free_distance`]: the robot's
//! circle swept along the arc, checked against the scan points). A car turning away from a wall
//! has the wall close straight ahead while its arc curves clear of it; judged by the straight
//! line it would slow to a crawl exactly when it needs forward speed to turn.

use mobil_chassis::ChassisParams;
use mobil_geom::wrap;
use nalgebra::Point2;
use std::f64::consts::{FRAC_PI_2, TAU};

/// How the chassis can move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Drive {
    /// Holonomic: any (vx, vy), heading held.
    Omni,
    /// Car-like or tricycle: vy = 0 and |ω / vx| ≤ `max_curvature` = tan δ_eff / L.
    CarLike {
        /// Largest curvature (1/m).
        max_curvature: f64,
    },
}

/// The chassis limits the command respects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionLimits {
    /// Kind of drive.
    pub drive: Drive,
    /// Largest translational speed (m/s).
    pub v_max: f64,
    /// Largest yaw rate (rad/s).
    pub omega_max: f64,
}

impl MotionLimits {
    /// The limits of a chassis (its params file): δ_eff from SPEC §1 for a car-like chassis.
    pub fn from_chassis(params: &ChassisParams) -> Self {
        let drive = if params.model().is_nonholonomic() {
            Drive::CarLike {
                max_curvature: params.max_curvature(),
            }
        } else {
            Drive::Omni
        };
        MotionLimits {
            drive,
            v_max: params.v_max(),
            omega_max: params.omega_max(),
        }
    }

    /// Whether the limits are usable (finite, positive; a finite positive curvature limit).
    pub fn is_valid(&self) -> bool {
        let drive_ok = match self.drive {
            Drive::Omni => true,
            Drive::CarLike { max_curvature } => max_curvature.is_finite() && max_curvature > 0.0,
        };
        drive_ok && self.v_max.is_finite() && self.v_max > 0.0 && self.omega_max.is_finite() && self.omega_max > 0.0
    }
}

/// A body-frame velocity command at the reference point (cmd_vel's linear.x, linear.y,
/// angular.z).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct VelocityCommand {
    /// Forward speed (m/s).
    pub vx: f64,
    /// Leftward speed (m/s); 0 for a car-like chassis.
    pub vy: f64,
    /// Yaw rate (rad/s), anticlockwise.
    pub omega: f64,
}

impl VelocityCommand {
    /// The zero command.
    pub const ZERO: VelocityCommand = VelocityCommand {
        vx: 0.0,
        vy: 0.0,
        omega: 0.0,
    };

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        self.vx.is_finite() && self.vy.is_finite() && self.omega.is_finite()
    }

    /// Translational speed √(vx² + vy²).
    pub fn speed(&self) -> f64 {
        self.vx.hypot(self.vy)
    }

    /// The command held to the limits (speed scaled down, yaw rate clipped, vy dropped for a
    /// car-like chassis); anything non-finite gives the zero command.
    pub fn limited(self, limits: &MotionLimits) -> VelocityCommand {
        if !self.is_finite() || !limits.is_valid() {
            return VelocityCommand::ZERO;
        }
        let mut c = self;
        if matches!(limits.drive, Drive::CarLike { .. }) {
            c.vy = 0.0;
        }
        let speed = c.speed();
        if speed > limits.v_max {
            let k = limits.v_max / speed;
            c.vx *= k;
            c.vy *= k;
        }
        c.omega = c.omega.clamp(-limits.omega_max, limits.omega_max);
        c
    }

    /// The command as it goes to the chassis: [`VelocityCommand::limited`], and on a car-like
    /// chassis |ω| ≤ κ_max·|vx| (a turn no tighter than δ_eff allows: a standing car does not
    /// turn). Anything non-finite gives the zero command.
    pub fn for_chassis(self, limits: &MotionLimits) -> VelocityCommand {
        let mut c = self.limited(limits);
        if let Drive::CarLike { max_curvature } = limits.drive {
            let bound = max_curvature * c.vx.abs();
            c.omega = if bound.is_finite() {
                c.omega.clamp(-bound, bound)
            } else {
                0.0
            };
        }
        if c.is_finite() {
            c
        } else {
            VelocityCommand::ZERO
        }
    }
}

/// What the motion law needs to know about the moment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionInput<'a> {
    /// Desired direction of motion, bearing in the base frame (rad).
    pub bearing: f64,
    /// Whether that direction lies in the field of view (else an omni chassis turns toward it
    /// in place instead of driving blind).
    pub bearing_seen: bool,
    /// Omni: free distance (m) from the centre along the desired direction (a car-like chassis
    /// checks its arcs against `obstacles` instead).
    pub free_ahead: f64,
    /// Obstacle points in the base frame (the scan's echoes), for a car-like chassis' arcs.
    pub obstacles: &'a [Point2<f64>],
    /// Distance to the goal (m).
    pub goal_distance: f64,
    /// Factor in [0, 1] on the speed from the direction itself (the sliding rule's reduction
    /// of the motion toward an obstacle; 1 = none).
    pub speed_scale: f64,
}

/// Distances that scale the speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedProfile {
    /// Below this free distance (m) ahead, the forward speed is zero.
    pub stop_distance: f64,
    /// At or above this free distance (m), full speed (d_sa).
    pub safe_distance: f64,
    /// Inside this distance (m) to the goal, the speed falls linearly toward zero.
    pub slow_down_radius: f64,
    /// Gain (1/s) of an omni chassis' turn toward a direction outside the field of view (the
    /// navigator also turns an omni in T-mode toward its direction of motion with it).
    pub heading_gain: f64,
    /// Radius (m) of the circle swept along a car-like chassis' arcs: the robot's, or more for
    /// a margin to the side as well as ahead (the navigator sweeps the robot radius plus half
    /// the margin to the stop distance).
    pub robot_radius: f64,
    /// Car-like: the least speed (m/s) of a turn whose arc is clear; the turn's own slow-downs
    /// (with the angle to the direction, and the sliding rule's) never go below it. Only the
    /// arc's clearance, the goal and the chassis' v_max can.
    pub min_turn_speed: f64,
}

impl SpeedProfile {
    /// Fraction in [0, 1] of the speed a free distance ahead allows: 0 at or below the stop
    /// distance, 1 at or beyond the safe distance, linear between.
    pub fn clearance(&self, free_ahead: f64) -> f64 {
        let span = (self.safe_distance - self.stop_distance).max(1e-9);
        let c = ((free_ahead - self.stop_distance) / span).clamp(0.0, 1.0);
        if c.is_nan() {
            0.0
        } else {
            c
        }
    }

    /// Fraction in [0, 1] of the speed left near the goal (linear inside `slow_down_radius`).
    pub fn near_goal(&self, goal_distance: f64) -> f64 {
        let g = (goal_distance / self.slow_down_radius.max(1e-9)).clamp(0.0, 1.0);
        if g.is_nan() {
            0.0
        } else {
            g
        }
    }

    /// Speed (m/s) for a free distance ahead and a distance to the goal, ≤ v_max.
    pub fn speed(&self, v_max: f64, free_ahead: f64, goal_distance: f64) -> f64 {
        let s = v_max * self.clearance(free_ahead) * self.near_goal(goal_distance);
        if s.is_finite() {
            s
        } else {
            0.0
        }
    }
}

/// Free distance (m) along the arc of curvature `curvature` (1/m, positive to the left) that the
/// reference point drives from the origin, heading +x, before a circle of `radius` around it
/// touches one of `points` (base frame), counted from the centre like d_i: the arc length
/// travelled plus the radius (so for `curvature` 0 a point dead ahead at distance a gives a).
/// 0 when a point is already inside the circle; +∞ when the circle swept over a whole turn
/// (or along the whole straight line) touches none.
///
/// On the arc, the centre of the turn is C = (0, 1/κ) and the reference point is at angle θ
/// (travelled) on the circle of radius R = 1/|κ| around it; a point at distance ρ from C is
/// touched where the law of cosines gives r² = R² + ρ² − 2Rρ·cos Δ, i.e. at θ = θ_p − Δ, θ_p
/// being the point's angle around C measured from the start in the direction of travel.
pub fn arc_free_distance(points: &[Point2<f64>], curvature: f64, radius: f64) -> f64 {
    if !curvature.is_finite() || !radius.is_finite() || radius < 0.0 {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    if curvature.abs() < 1e-6 {
        for p in points {
            if p.x.hypot(p.y) < radius {
                return 0.0;
            }
            let across = p.y.abs();
            if p.x > 0.0 && across < radius {
                best = best.min(p.x - (radius * radius - across * across).sqrt());
            }
        }
        return best + radius;
    }
    let big_r = 1.0 / curvature.abs();
    // Mirror a right turn into a left one: C = (0, R), travel anticlockwise from angle −π/2.
    let mirror = if curvature < 0.0 { -1.0 } else { 1.0 };
    for p in points {
        let (x, y) = (p.x, p.y * mirror);
        if x.hypot(y) < radius {
            return 0.0;
        }
        let (vx, vy) = (x, y - big_r);
        let rho = vx.hypot(vy);
        if !rho.is_finite() || rho < big_r - radius || rho > big_r + radius {
            continue;
        }
        let theta_p = (vy.atan2(vx) + FRAC_PI_2).rem_euclid(TAU);
        let cos_delta = ((big_r * big_r + rho * rho - radius * radius) / (2.0 * big_r * rho)).clamp(-1.0, 1.0);
        let contact = (theta_p - cos_delta.acos()).max(0.0);
        best = best.min(big_r * contact);
    }
    best + radius
}

/// The command that moves the robot along `input.bearing` (see the module doc).
///
/// Omni: translation along the bearing at the speed the free distance along it allows, or a
/// turn in place toward a bearing outside the field of view.
///
/// Car-like: the curvature is the pure-pursuit one toward a point at the safe distance along
/// the bearing, 2·sin α / d_sa, clipped to the chassis' limit (full lock for a bearing abeam or
/// behind). The speed is limited by the clearance of the arc the car will drive
/// ([`arc_free_distance`] with the robot radius), not of the straight line ahead: when that arc
/// is blocked before d_sa and the arc at the steering limit toward the bearing is freer, the car
/// turns at the limit instead. The speed falls with cos α (to a quarter for a bearing abeam or
/// behind: the car must turn before it goes) and with `speed_scale`, but these never take it
/// below `min_turn_speed` (nor the arc's clearance allows less); with no arc free beyond the
/// stop distance the command is zero (the method has no reversing).
pub fn command_along(input: &MotionInput, profile: &SpeedProfile, limits: &MotionLimits) -> VelocityCommand {
    if !input.bearing.is_finite() || !limits.is_valid() {
        return VelocityCommand::ZERO;
    }
    let alpha = wrap(input.bearing);
    let scale = if input.speed_scale.is_finite() {
        input.speed_scale.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let command = match limits.drive {
        Drive::Omni => {
            let speed = profile.speed(limits.v_max, input.free_ahead, input.goal_distance);
            if input.bearing_seen {
                let (s, c) = alpha.sin_cos();
                VelocityCommand {
                    vx: speed * c * scale,
                    vy: speed * s * scale,
                    omega: 0.0,
                }
            } else {
                let omega = (profile.heading_gain * alpha).clamp(-limits.omega_max, limits.omega_max);
                VelocityCommand {
                    vx: 0.0,
                    vy: 0.0,
                    omega: omega * scale,
                }
            }
        }
        Drive::CarLike { max_curvature } => car_command(input, alpha, scale, max_curvature, profile, limits),
    };
    command.limited(limits)
}

/// The arc a car-like chassis drives toward a bearing (see [`car_arc`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CarArc {
    /// Curvature (1/m, positive to the left).
    pub curvature: f64,
    /// Free distance (m) along it, from the centre ([`arc_free_distance`]).
    pub free: f64,
    /// Whether it turns at the steering limit to the side opposite the bearing, because the arcs
    /// toward the bearing are blocked before d_sa: the car cannot follow the direction here.
    pub against: bool,
}

/// The arc a car-like chassis drives toward `bearing` (base frame): the pure-pursuit one toward
/// a point at the safe distance along the bearing, 2·sin α / d_sa, clipped to `max_curvature`
/// (full lock for a bearing abeam or behind); when its free distance is below d_sa, the freer of
/// the two arcs at the steering limit instead (the one toward the bearing first).
pub fn car_arc(obstacles: &[Point2<f64>], bearing: f64, max_curvature: f64, profile: &SpeedProfile) -> CarArc {
    let alpha = wrap(bearing);
    let lookahead = profile.safe_distance.max(1e-3);
    let pursuit = if alpha.abs() >= FRAC_PI_2 {
        max_curvature.copysign(alpha)
    } else {
        (2.0 * alpha.sin() / lookahead).clamp(-max_curvature, max_curvature)
    };
    let radius = profile.robot_radius.max(0.0);
    let mut arc = CarArc {
        curvature: pursuit,
        free: arc_free_distance(obstacles, pursuit, radius),
        against: false,
    };
    if arc.free < profile.safe_distance {
        let toward = max_curvature.copysign(if alpha == 0.0 { 1.0 } else { alpha });
        for (limit, against) in [(toward, false), (-toward, alpha != 0.0)] {
            let free = arc_free_distance(obstacles, limit, radius);
            if free > arc.free {
                arc = CarArc {
                    curvature: limit,
                    free,
                    against,
                };
            }
        }
    }
    arc
}

/// The car-like branch of [`command_along`].
fn car_command(
    input: &MotionInput,
    alpha: f64,
    scale: f64,
    max_curvature: f64,
    profile: &SpeedProfile,
    limits: &MotionLimits,
) -> VelocityCommand {
    let CarArc {
        curvature: kappa, free, ..
    } = car_arc(input.obstacles, alpha, max_curvature, profile);
    let clear = limits.v_max * profile.clearance(free);
    if clear <= 0.0 {
        return VelocityCommand::ZERO;
    }
    let turning = clear * alpha.cos().clamp(0.25, 1.0) * scale;
    let floor = clear.min(profile.min_turn_speed.max(0.0));
    let mut v = turning.max(floor) * profile.near_goal(input.goal_distance);
    if (v * kappa).abs() > limits.omega_max {
        v = limits.omega_max / kappa.abs();
    }
    VelocityCommand {
        vx: v,
        vy: 0.0,
        omega: v * kappa,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::FRAC_PI_4;

    const PROFILE: SpeedProfile = SpeedProfile {
        stop_distance: 0.35,
        safe_distance: 0.8,
        slow_down_radius: 0.6,
        heading_gain: 1.5,
        robot_radius: 0.25,
        min_turn_speed: 0.1,
    };

    fn omni() -> MotionLimits {
        MotionLimits::from_chassis(&ChassisParams::omr3())
    }

    fn car() -> MotionLimits {
        MotionLimits::from_chassis(&ChassisParams::mobil2())
    }

    #[test]
    fn limits_from_the_params() {
        // MOBIL-II: δ_eff = atan(0.60 / 0.73) → tan δ_eff / L = (0.60/0.73)/0.60 = 1/0.73.
        match car().drive {
            Drive::CarLike { max_curvature } => assert_relative_eq!(max_curvature, 1.0 / 0.73, epsilon = 1e-12),
            Drive::Omni => panic!("MOBIL-II is car-like"),
        }
        assert_eq!(omni().drive, Drive::Omni);
        assert_eq!(omni().v_max, 0.5);
    }

    #[test]
    fn speed_scales_with_clearance_and_goal_distance() {
        // Free 0.575 m: (0.575 − 0.35)/(0.8 − 0.35) = 0.5 → 0.25 m/s; 0.3 m from G: ×0.5.
        assert_relative_eq!(PROFILE.speed(0.5, 0.575, 10.0), 0.25, epsilon = 1e-12);
        assert_relative_eq!(PROFILE.speed(0.5, 5.0, 0.3), 0.25, epsilon = 1e-12);
        assert_relative_eq!(PROFILE.speed(0.5, 0.575, 0.3), 0.125, epsilon = 1e-12);
        // Hard stop.
        assert_eq!(PROFILE.speed(0.5, 0.34, 10.0), 0.0);
        assert_eq!(PROFILE.speed(0.5, f64::INFINITY, 10.0), 0.5);
    }

    #[test]
    fn omni_translates_along_the_direction_holding_heading() {
        let input = MotionInput {
            bearing: 3.0 * FRAC_PI_4,
            bearing_seen: true,
            free_ahead: 5.0,
            obstacles: &[],
            goal_distance: 5.0,
            speed_scale: 1.0,
        };
        let c = command_along(&input, &PROFILE, &omni());
        // 0.5 m/s at 135°: (−0.35355, 0.35355), no rotation.
        assert_relative_eq!(c.vx, -0.5 * FRAC_PI_4.cos(), epsilon = 1e-12);
        assert_relative_eq!(c.vy, 0.5 * FRAC_PI_4.sin(), epsilon = 1e-12);
        assert_eq!(c.omega, 0.0);
        // Outside the field of view: turn toward it in place, 1.5 × 3π/4 = 3.53 → ω_max 1.5.
        let c = command_along(
            &MotionInput {
                bearing_seen: false,
                ..input
            },
            &PROFILE,
            &omni(),
        );
        assert_eq!((c.vx, c.vy, c.omega), (0.0, 0.0, 1.5));
    }

    #[test]
    fn car_steers_within_delta_eff() {
        // 20° left at full clearance: κ = 2 sin 20° / 0.8 = 0.85505 (< 1/0.73 = 1.3699);
        // v = 0.5·cos 20° = 0.46985; ω = v·κ = 0.40174 (< ω_max 1.0).
        let input = MotionInput {
            bearing: 20f64.to_radians(),
            bearing_seen: true,
            free_ahead: 5.0,
            obstacles: &[],
            goal_distance: 5.0,
            speed_scale: 1.0,
        };
        let c = command_along(&input, &PROFILE, &car());
        assert_relative_eq!(c.vx, 0.469_846, epsilon = 1e-6);
        assert_eq!(c.vy, 0.0);
        assert_relative_eq!(c.omega, 0.401_742, epsilon = 1e-6);
        // 60° right: κ would be 2 sin 60°/0.8 = 2.165 → clipped to −1/0.73; v = 0.5·cos 60° = 0.25.
        let c = command_along(
            &MotionInput {
                bearing: -60f64.to_radians(),
                ..input
            },
            &PROFILE,
            &car(),
        );
        assert_relative_eq!(c.vx, 0.25, epsilon = 1e-12);
        assert_relative_eq!(c.omega / c.vx, -1.0 / 0.73, epsilon = 1e-9);
        // Behind: full lock toward it at a quarter speed.
        let c = command_along(&MotionInput { bearing: 3.0, ..input }, &PROFILE, &car());
        assert_relative_eq!(c.vx, 0.125, epsilon = 1e-12);
        assert_relative_eq!(c.omega, 0.125 / 0.73, epsilon = 1e-9);
        // Hard stop: a point dead ahead at 0.3 m is touched by the 0.25 m circle after 0.05 m
        // on any arc (free ≈ 0.30 < 0.35), so nothing moves, whatever the turn.
        let c = command_along(
            &MotionInput {
                obstacles: &[Point2::new(0.3, 0.0)],
                ..input
            },
            &PROFILE,
            &car(),
        );
        assert_eq!(c, VelocityCommand::ZERO);
    }

    #[test]
    fn arc_free_distance_by_hand() {
        // Straight, radius 0.5: a point at (1, 0.3) is touched after 1 − √(0.25 − 0.09) = 0.6 m;
        // counted from the centre, 1.1.
        assert_relative_eq!(
            arc_free_distance(&[Point2::new(1.0, 0.3)], 0.0, 0.5),
            1.1,
            epsilon = 1e-12
        );
        // κ = 1 (R = 1, centre of the turn C = (0, 1)), radius 0.5. The point (1, 0) is
        // ρ = √2 from C at θ_p = π/4 from the start; cos Δ = (1 + 2 − 0.25)/(2√2) → Δ = 0.236052,
        // so contact after θ = 0.549359 rad = 0.549359 m. Check: the reference point is then at
        // (sin θ, 1 − cos θ) = (0.52205, 0.14717), and its distance to (1, 0) is 0.500000.
        assert_relative_eq!(
            arc_free_distance(&[Point2::new(1.0, 0.0)], 1.0, 0.5),
            0.549_359 + 0.5,
            epsilon = 1e-6
        );
        // The point (1.5, 1) lies on the outer edge of the swept ring (ρ = R + r): touched at
        // the quarter turn, π/2 m; mirrored, the same for the right turn and (1.5, −1).
        assert_relative_eq!(
            arc_free_distance(&[Point2::new(1.5, 1.0)], 1.0, 0.5),
            FRAC_PI_2 + 0.5,
            epsilon = 1e-9
        );
        assert_relative_eq!(
            arc_free_distance(&[Point2::new(1.5, -1.0)], -1.0, 0.5),
            FRAC_PI_2 + 0.5,
            epsilon = 1e-9
        );
        // (1.5, 1) for the right turn, and (0, 3) for the left one (ρ = 2 > 1.5), are never
        // touched; a point inside the circle already is.
        assert_eq!(arc_free_distance(&[Point2::new(1.5, 1.0)], -1.0, 0.5), f64::INFINITY);
        assert_eq!(arc_free_distance(&[Point2::new(0.0, 3.0)], 1.0, 0.5), f64::INFINITY);
        assert_eq!(arc_free_distance(&[Point2::new(0.3, 0.2)], 1.0, 0.5), 0.0);
    }

    /// A wall square ahead at x = d, y from −3 to 3, as scan points every centimetre.
    fn wall_at(d: f64) -> Vec<Point2<f64>> {
        (0..=600).map(|i| Point2::new(d, -3.0 + 0.01 * f64::from(i))).collect()
    }

    const MOBIL2: SpeedProfile = SpeedProfile {
        stop_distance: 0.65,
        safe_distance: 1.5,
        slow_down_radius: 0.6,
        heading_gain: 1.5,
        robot_radius: 0.53,
        min_turn_speed: 0.1,
    };

    #[test]
    fn the_arc_at_delta_eff_clears_a_wall_or_not() {
        // MOBIL-II at full lock: R = 0.73 around C = (0, 0.73); the reference point reaches
        // x = R sin θ ≤ 0.73, its 0.53 m circle x ≤ 1.26. A wall at 1.30 is never touched.
        let k = 1.0 / 0.73;
        assert_eq!(arc_free_distance(&wall_at(1.30), k, 0.53), f64::INFINITY);
        // A wall at 1.00: touched where R sin θ = 1.00 − 0.53 = 0.47, θ = asin(0.47/0.73) =
        // 0.699501 rad, after 0.73 θ = 0.510635 m; from the centre 1.040635. (The nearest point
        // of the grid, y = 0.17, is 0.0015 m off the contact point (1, 0.1715): 2e-6 m later.)
        assert_relative_eq!(arc_free_distance(&wall_at(1.00), k, 0.53), 1.040_635, epsilon = 1e-5);
        // At 0.64 the arc touches after 0.73·asin(0.11/0.73) = 0.110421 m: 0.640421 from the
        // centre, inside the 0.65 hard stop. Straight ahead, the wall is at d itself.
        assert_relative_eq!(arc_free_distance(&wall_at(0.64), -k, 0.53), 0.640_421, epsilon = 1e-5);
        assert_relative_eq!(arc_free_distance(&wall_at(1.00), 0.0, 0.53), 1.0, epsilon = 1e-12);
    }

    #[test]
    fn car_turns_away_from_a_wall_at_a_useful_speed() {
        let wall = wall_at(1.30);
        let input = MotionInput {
            bearing: FRAC_PI_2,
            bearing_seen: true,
            free_ahead: f64::INFINITY,
            obstacles: &wall,
            goal_distance: 5.0,
            speed_scale: 0.4,
        };
        // Along the wall (90° left), the sliding rule keeping 0.4 of the direction: full lock.
        // Its arc is free, so the clearance allows 0.5 m/s; the turn's slow-downs would give
        // 0.5·0.25·0.4 = 0.05 m/s, under the 0.1 floor: 0.1 m/s, ω = 0.1/0.73 = 0.136986.
        // (Judged by the straight line, 1.30 m: 0.5·(1.30 − 0.65)/0.85·0.25·0.4 = 0.038 m/s.)
        let c = command_along(&input, &MOBIL2, &car());
        assert_relative_eq!(c.vx, 0.1, epsilon = 1e-12);
        assert_relative_eq!(c.omega, 0.1 / 0.73, epsilon = 1e-12);
        // A wall at 1.00: the arc is free for 1.040635 from the centre, a clearance of
        // (1.040635 − 0.65)/0.85 = 0.459571 → 0.229786 m/s; the floor 0.1 binds again.
        let wall = wall_at(1.00);
        let c = command_along(
            &MotionInput {
                obstacles: &wall,
                ..input
            },
            &MOBIL2,
            &car(),
        );
        assert_relative_eq!(c.vx, 0.1, epsilon = 1e-12);
        // At 0.70 the arc is free for 0.73·asin(0.17/0.73) + 0.53 = 0.701575: the clearance
        // allows only 0.5·0.051575/0.85 = 0.030338 m/s, and that, not the floor, is the speed.
        let wall = wall_at(0.70);
        let c = command_along(
            &MotionInput {
                obstacles: &wall,
                ..input
            },
            &MOBIL2,
            &car(),
        );
        assert_relative_eq!(c.vx, 0.030_338, epsilon = 1e-5);
        // At 0.64 no arc is free beyond the hard stop: stopped (no reversing).
        let wall = wall_at(0.64);
        let c = command_along(
            &MotionInput {
                obstacles: &wall,
                ..input
            },
            &MOBIL2,
            &car(),
        );
        assert_eq!(c, VelocityCommand::ZERO);
    }

    #[test]
    fn car_turns_against_the_direction_only_when_every_arc_toward_it_is_blocked() {
        // 30° left toward a wall at x = 1.00 that runs from y = −0.1 to the left: the pursuit
        // arc (1.008052) and the left limit (1.040635) touch it as above. The right limit
        // (R = 0.73, C = (0, −0.73)) passes the wall's foot (1, −0.1715), which is not there, and
        // first touches its end (1, −0.1): mirrored, (1, 0.1) is ρ = √(1 + 0.63²) = 1.181905 from
        // C at θ_p = 1.008610; cos Δ = (0.73² + ρ² − 0.53²)/(2·0.73·ρ) → Δ = 0.299236; after
        // 0.73·0.709373 = 0.517842 m, 1.047842 from the centre: the freest, against the bearing.
        // (A brute-force sweep in 10 µm steps finds the contact at 0.51785 m.)
        let wall: Vec<_> = (0..=310)
            .map(|i| Point2::new(1.0, -0.1 + 0.01 * f64::from(i)))
            .collect();
        let arc = car_arc(&wall, 30f64.to_radians(), 1.0 / 0.73, &MOBIL2);
        assert!(arc.against);
        assert_relative_eq!(arc.curvature, -1.0 / 0.73, epsilon = 1e-12);
        assert_relative_eq!(arc.free, 1.047_842, epsilon = 1e-5);
        // The whole wall (y from −3): the left limit is the freest, toward the bearing.
        let arc = car_arc(&wall_at(1.00), 30f64.to_radians(), 1.0 / 0.73, &MOBIL2);
        assert!(!arc.against);
        assert_relative_eq!(arc.curvature, 1.0 / 0.73, epsilon = 1e-12);
        // Nothing in the way: the pursuit arc, 2 sin 30°/1.5.
        let arc = car_arc(&[], 30f64.to_radians(), 1.0 / 0.73, &MOBIL2);
        assert!(!arc.against);
        assert_relative_eq!(arc.curvature, 1.0 / 1.5, epsilon = 1e-12);
        assert_eq!(arc.free, f64::INFINITY);
    }

    #[test]
    fn car_takes_the_freer_arc_at_the_limit() {
        // 30° left toward a wall at 1.00: pure pursuit κ = 2 sin 30°/1.5 = 1/1.5, whose arc
        // touches at 1.5·asin(0.47/1.5) + 0.53 = 1.008052; the arc at the limit (R = 0.73) at
        // 1.040635, freer: the car turns at the limit, 0.5·0.459571·cos 30° = 0.199000 m/s,
        // ω = 0.199000/0.73 = 0.272603.
        let wall = wall_at(1.00);
        let input = MotionInput {
            bearing: 30f64.to_radians(),
            bearing_seen: true,
            free_ahead: f64::INFINITY,
            obstacles: &wall,
            goal_distance: 5.0,
            speed_scale: 1.0,
        };
        let c = command_along(&input, &MOBIL2, &car());
        assert_relative_eq!(c.vx, 0.199_000, epsilon = 1e-5);
        assert_relative_eq!(c.omega, 0.272_603, epsilon = 1e-5);
    }

    #[test]
    fn non_finite_gives_zero() {
        let c = VelocityCommand {
            vx: f64::NAN,
            vy: 0.0,
            omega: 0.0,
        };
        assert_eq!(c.limited(&omni()), VelocityCommand::ZERO);
        let input = MotionInput {
            bearing: f64::INFINITY,
            bearing_seen: true,
            free_ahead: 5.0,
            obstacles: &[],
            goal_distance: 5.0,
            speed_scale: 1.0,
        };
        assert_eq!(command_along(&input, &PROFILE, &omni()), VelocityCommand::ZERO);
    }
}
