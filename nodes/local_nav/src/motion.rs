//! Motion along a direction (SPEC §2 Decision, "motion along F"): an omni chassis translates
//! along it holding its heading; a car-like one steers toward it within δ_eff; the speed is
//! scaled down by the free distance ahead and near the goal, and is zero below the hard stop
//! distance. The result is a body-frame velocity command, always finite and within the limits.

use mobil_chassis::ChassisParams;
use mobil_geom::wrap;
use std::f64::consts::FRAC_PI_2;

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
}

/// What the motion law needs to know about the moment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionInput {
    /// Desired direction of motion, bearing in the base frame (rad).
    pub bearing: f64,
    /// Whether that direction lies in the field of view (else an omni chassis turns toward it
    /// in place instead of driving blind).
    pub bearing_seen: bool,
    /// Free distance (m) from the centre along the direction the robot will move in (the
    /// desired direction for omni, straight ahead for car-like).
    pub free_ahead: f64,
    /// Distance to the goal (m).
    pub goal_distance: f64,
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
    /// Gain (1/s) of an omni chassis' turn toward a direction outside the field of view.
    pub heading_gain: f64,
}

impl SpeedProfile {
    /// Speed (m/s) for a free distance ahead and a distance to the goal, ≤ v_max.
    pub fn speed(&self, v_max: f64, free_ahead: f64, goal_distance: f64) -> f64 {
        let span = (self.safe_distance - self.stop_distance).max(1e-9);
        let clearance = ((free_ahead - self.stop_distance) / span).clamp(0.0, 1.0);
        let near_goal = (goal_distance / self.slow_down_radius.max(1e-9)).clamp(0.0, 1.0);
        let s = v_max * clearance * near_goal;
        if s.is_finite() {
            s
        } else {
            0.0
        }
    }
}

/// The command that moves the robot along `input.bearing` (see the module doc). For a car-like
/// chassis the curvature is the pure-pursuit one toward a point at the safe distance along the
/// bearing, 2·sin α / d_sa, clipped to the chassis' limit; the speed falls with cos α (to a
/// quarter for a direction abeam or behind), as the car must turn before it goes.
pub fn command_along(input: &MotionInput, profile: &SpeedProfile, limits: &MotionLimits) -> VelocityCommand {
    if !input.bearing.is_finite() || !limits.is_valid() {
        return VelocityCommand::ZERO;
    }
    let alpha = wrap(input.bearing);
    let speed = profile.speed(limits.v_max, input.free_ahead, input.goal_distance);
    let command = match limits.drive {
        Drive::Omni => {
            if input.bearing_seen {
                let (s, c) = alpha.sin_cos();
                VelocityCommand {
                    vx: speed * c,
                    vy: speed * s,
                    omega: 0.0,
                }
            } else {
                VelocityCommand {
                    vx: 0.0,
                    vy: 0.0,
                    omega: profile.heading_gain * alpha,
                }
            }
        }
        Drive::CarLike { max_curvature } => {
            let lookahead = profile.safe_distance.max(1e-3);
            let kappa = if alpha.abs() >= FRAC_PI_2 {
                max_curvature.copysign(alpha)
            } else {
                (2.0 * alpha.sin() / lookahead).clamp(-max_curvature, max_curvature)
            };
            let mut v = speed * alpha.cos().clamp(0.25, 1.0);
            if (v * kappa).abs() > limits.omega_max {
                v = limits.omega_max / kappa.abs();
            }
            VelocityCommand {
                vx: v,
                vy: 0.0,
                omega: v * kappa,
            }
        }
    };
    command.limited(limits)
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
            goal_distance: 5.0,
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
            goal_distance: 5.0,
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
        // Hard stop: nothing moves.
        let c = command_along(
            &MotionInput {
                free_ahead: 0.3,
                ..input
            },
            &PROFILE,
            &car(),
        );
        assert_eq!(c, VelocityCommand::ZERO);
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
            goal_distance: 5.0,
        };
        assert_eq!(command_along(&input, &PROFILE, &omni()), VelocityCommand::ZERO);
    }
}
