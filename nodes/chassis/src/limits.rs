//! Command limits: any requested twist becomes one the chassis can execute (SPEC §1).
//!
//! Policy of [`clamp_command`], in this order, for a twist at the kinematic origin:
//!
//! 1. **Non-finite** input (any NaN/∞ component) → zero twist ([`ClampReason::NonFinite`]); the
//!    robot is made safe rather than left on stale data.
//! 2. **Lateral** (tricycle, car-like): `vy` is dropped ([`ClampReason::Lateral`]).
//! 3. **Speed**: |v| ≤ v_max, keeping the sign; for the omni chassis the translation (vx, vy) is
//!    scaled as a vector, keeping its direction ([`ClampReason::Speed`]).
//! 4. **Turn rate**: |ω| ≤ ω_max, keeping the sign ([`ClampReason::TurnRate`]).
//! 5. **Minimum radius** (tricycle, car-like) — *keep speed, clamp curvature*: at the speed
//!    reached so far, |ω| ≤ |v|·tan δ_eff / L ([`ClampReason::MinRadius`]). So v = 0 with ω ≠ 0
//!    becomes a stop; [`Clamped::pre_steer`] then gives δ = sign(ω)·δ_eff so the wheels can
//!    still turn toward the request (see [`crate::pre_steer`]).
//! 6. **Wheel speed**: if a driven wheel would exceed `max_wheel_speed`, the whole twist is
//!    scaled by one common factor (curvature and direction kept; wheel speeds are homogeneous of
//!    degree one in the twist, so the fastest wheel lands exactly on the limit)
//!    ([`ClampReason::WheelSpeed`]).
//!
//! The output always satisfies the limits. A reason is reported only when the request exceeded a
//! limit by more than a relative 1e-9, so a command computed right at a limit by another
//! formula is not logged as clamped.

use std::fmt;

use crate::kinematics::{inverse, twist_at_origin, twist_at_reference, BodyTwist};
use crate::model::ChassisParams;

/// Relative excess over a limit below which a clamp is applied silently.
const REPORT_TOLERANCE: f64 = 1e-9;

fn exceeds(magnitude: f64, limit: f64) -> bool {
    magnitude > limit * (1.0 + REPORT_TOLERANCE)
}

/// Why a command was changed; the values are the `CLAMP_*` bits of `mobil_msgs/ChassisStatus`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum ClampReason {
    /// A component was NaN or infinite: the command became zero.
    NonFinite = 1,
    /// |v| (omni: |(vx, vy)|) was above v_max.
    Speed = 2,
    /// |ω| was above ω_max.
    TurnRate = 4,
    /// A sideways velocity was asked of a non-holonomic chassis.
    Lateral = 8,
    /// The turn was tighter than the effective minimum radius (incl. turning in place).
    MinRadius = 16,
    /// A wheel would have exceeded its maximum speed.
    WheelSpeed = 32,
}

impl ClampReason {
    /// All reasons, in bit order.
    pub const ALL: [Self; 6] = [
        Self::NonFinite,
        Self::Speed,
        Self::TurnRate,
        Self::Lateral,
        Self::MinRadius,
        Self::WheelSpeed,
    ];

    /// The reason's bit (`ChassisStatus.CLAMP_*`).
    pub fn bit(self) -> u32 {
        self as u32
    }

    /// Short snake_case name for logs.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::NonFinite => "non_finite",
            Self::Speed => "speed",
            Self::TurnRate => "turn_rate",
            Self::Lateral => "lateral",
            Self::MinRadius => "min_radius",
            Self::WheelSpeed => "wheel_speed",
        }
    }
}

impl fmt::Display for ClampReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A set of [`ClampReason`]s, stored as the `ChassisStatus.clamped` bit mask.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct ClampReasons(u32);

impl ClampReasons {
    /// The empty set.
    pub const NONE: Self = Self(0);

    /// Adds a reason.
    pub fn insert(&mut self, reason: ClampReason) {
        self.0 |= reason.bit();
    }

    /// True if the set holds `reason`.
    pub fn contains(self, reason: ClampReason) -> bool {
        self.0 & reason.bit() != 0
    }

    /// True if nothing was clamped.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The bit mask (`ChassisStatus.clamped`).
    pub fn bits(self) -> u32 {
        self.0
    }

    /// The reasons in the set, in bit order.
    pub fn iter(self) -> impl Iterator<Item = ClampReason> {
        ClampReason::ALL.into_iter().filter(move |r| self.contains(*r))
    }
}

impl FromIterator<ClampReason> for ClampReasons {
    fn from_iter<I: IntoIterator<Item = ClampReason>>(iter: I) -> Self {
        let mut set = Self::NONE;
        for r in iter {
            set.insert(r);
        }
        set
    }
}

impl fmt::Display for ClampReasons {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, r) in self.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str(r.as_str())?;
        }
        Ok(())
    }
}

/// A feasible command and what was changed to get it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clamped {
    /// The feasible twist at the kinematic origin.
    pub twist: BodyTwist,
    /// Why the request was changed (empty: passed unchanged, up to rounding).
    pub reasons: ClampReasons,
    /// Virtual centre steering angle to hold while stopped: `Some(sign(ω)·δ_eff)` when a
    /// non-holonomic chassis was asked to turn at v = 0.
    pub pre_steer: Option<f64>,
}

/// Makes `requested` feasible for the chassis (policy in the module doc).
pub fn clamp_command(params: &ChassisParams, requested: BodyTwist) -> Clamped {
    let mut reasons = ClampReasons::NONE;
    if !requested.is_finite() {
        reasons.insert(ClampReason::NonFinite);
        return Clamped {
            twist: BodyTwist::ZERO,
            reasons,
            pre_steer: None,
        };
    }
    let nonholonomic = params.model().is_nonholonomic();
    let mut t = requested;
    let mut pre_steer = None;

    if nonholonomic && t.vy != 0.0 {
        t.vy = 0.0;
        reasons.insert(ClampReason::Lateral);
    }

    let v_max = params.v_max();
    let speed = t.vx.hypot(t.vy);
    if speed > v_max {
        if exceeds(speed, v_max) {
            reasons.insert(ClampReason::Speed);
        }
        let k = v_max / speed;
        t.vx *= k;
        t.vy *= k;
    }

    let omega_max = params.omega_max();
    if t.wz.abs() > omega_max {
        if exceeds(t.wz.abs(), omega_max) {
            reasons.insert(ClampReason::TurnRate);
        }
        t.wz = omega_max.copysign(t.wz);
    }

    if nonholonomic {
        let limit = t.vx.abs() * params.max_curvature();
        if t.wz.abs() > limit {
            if exceeds(t.wz.abs(), limit) {
                reasons.insert(ClampReason::MinRadius);
            }
            if t.vx == 0.0 {
                pre_steer = Some(params.effective_steering_limit().copysign(t.wz));
            }
            t.wz = if limit == 0.0 { 0.0 } else { limit.copysign(t.wz) };
        }
    }

    let max_wheel_speed = params.max_wheel_speed();
    let fastest = inverse(params, t).max_abs_wheel_speed();
    if fastest > max_wheel_speed {
        if exceeds(fastest, max_wheel_speed) {
            reasons.insert(ClampReason::WheelSpeed);
        }
        t = t.scaled(max_wheel_speed / fastest);
    }

    Clamped {
        twist: t,
        reasons,
        pre_steer,
    }
}

/// A command given at the reference point (a law's), held to the chassis limits as a command
/// to the chassis is held: on a steered chassis `vx` and `wz` are taken as the kinematic
/// origin's (the reference point's sideways speed ω·d is implied, and dropped), on the omni
/// chassis the twist is moved to the origin and back; in between [`clamp_command`] (speed,
/// turn rate, minimum radius, wheel speeds). Anything non-finite gives zero.
pub fn clamp_at_reference(params: &ChassisParams, twist: BodyTwist) -> BodyTwist {
    let d = params.reference_offset();
    let steered = params.model().is_nonholonomic();
    let origin = if steered {
        BodyTwist::new(twist.vx, 0.0, twist.wz)
    } else {
        twist_at_origin(twist, d)
    };
    let clamped = clamp_command(params, origin).twist;
    let out = if steered {
        BodyTwist::new(clamped.vx, 0.0, clamped.wz)
    } else {
        twist_at_reference(clamped, d)
    };
    if out.is_finite() {
        out
    } else {
        BodyTwist::ZERO
    }
}
