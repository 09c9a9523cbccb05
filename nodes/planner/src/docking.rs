//! Lyapunov docking: an Aicardi-type law that brings a unicycle onto a goal pose (SPEC §3;
//! 004 §3.4, §4.2.3).
//!
//! With e = |G − q|, Ω = atan2(y_G − y, x_G − x), Θ = wrap(Ω − ϑ_G), α = wrap(Ω − ϑ):
//! - V = ½(λe² + α² + hΘ²), eq. (3.41) — [`DockingGains::lyapunov`];
//! - v = γ·e·cos α, eq. (3.43); ω = k·α + γ·(cos α·sin α/α)·(α + h·Θ), eq. (3.46) without the
//!   printed stray factor e — [`DockingGains::law`];
//! - V̇ = −λγe²cos²α − kα² ≤ 0, eq. (3.48) — [`DockingGains::lyapunov_rate`].
//!
//! The law is a pure function of the state ([`DockingGains::law`]); [`DockingController`] adds
//! what the source leaves out: chassis limits by one common factor ([`VelocityLimits`]), the
//! docked test on position *and* heading, the final in-place rotation where the chassis can turn
//! in place, a time limit and a stall detector. Time is an input (seconds), never read.

use std::f64::consts::PI;

use mobil_chassis::{inverse, BodyTwist, ChassisParams};
use mobil_geom::{wrap, Pose2};

use crate::error::{positive_finite, PlannerError};

/// A unicycle command at the robot's reference point: forward speed v (m/s), turn rate ω (rad/s).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Velocity {
    /// Forward speed v (m/s); negative reverses.
    pub v: f64,
    /// Turn rate ω (rad/s), counter-clockwise positive.
    pub omega: f64,
}

impl Velocity {
    /// Standing still.
    pub const ZERO: Velocity = Velocity { v: 0.0, omega: 0.0 };

    /// A command from its components.
    pub const fn new(v: f64, omega: f64) -> Self {
        Velocity { v, omega }
    }

    /// Both components multiplied by `s` (the curvature ω/v is kept).
    pub fn scaled(self, s: f64) -> Self {
        Velocity::new(self.v * s, self.omega * s)
    }

    /// The command as a body twist (no sideways motion).
    pub fn to_twist(self) -> BodyTwist {
        BodyTwist::new(self.v, 0.0, self.omega)
    }
}

/// The docking error in the law's polar coordinates (SPEC §3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolarError {
    /// Distance e = |G − q| (m).
    pub e: f64,
    /// α = wrap(Ω − ϑ) ∈ [−π, π): the line of sight to G seen from the robot's heading.
    pub alpha: f64,
    /// Θ = wrap(Ω − ϑ_G): the line of sight seen from the goal heading.
    pub theta: f64,
}

/// Wraps to [−π, π): the SPEC §3 Decision for the α = ±π tie (a start facing exactly away from
/// G takes α = −π, as the paper's own unwrapped Ω − ϑ = −π/4 − 3π/4 gives).
pub fn wrap_alpha(a: f64) -> f64 {
    let w = wrap(a);
    if w == PI {
        -PI
    } else {
        w
    }
}

/// sin a / a, continuous at 0 (= 1); a Taylor series below 1e-4 rad, where it is exact to
/// rounding.
pub fn sinc(a: f64) -> f64 {
    if a.abs() < 1e-4 {
        1.0 - a * a / 6.0
    } else {
        a.sin() / a
    }
}

/// The polar error of `pose` against `goal`. At e = 0 the line of sight Ω is undefined; it is
/// taken as ϑ_G there, so Θ = 0 and α is the plain heading error (the law then only turns).
pub fn polar_error(pose: &Pose2, goal: &Pose2) -> PolarError {
    let (dx, dy) = (goal.x - pose.x, goal.y - pose.y);
    let e = dx.hypot(dy);
    let sight = if e > 0.0 { dy.atan2(dx) } else { goal.yaw };
    PolarError {
        e,
        alpha: wrap_alpha(sight - pose.yaw),
        theta: wrap(sight - goal.yaw),
    }
}

/// A gain outside the paper's printed range: accepted (stability needs only positivity), but
/// worth a warning (SPEC §3 Decision).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GainWarning {
    /// The gain's name.
    pub name: &'static str,
    /// Its value.
    pub value: f64,
    /// The printed open range (lower, upper).
    pub range: (f64, f64),
}

impl std::fmt::Display for GainWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "gain {} = {} is outside the source's printed range ({}, {})",
            self.name, self.value, self.range.0, self.range.1
        )
    }
}

/// The gains γ, k, h, λ of the Lyapunov law, each finite and positive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DockingGains {
    gamma: f64,
    k: f64,
    h: f64,
    lambda: f64,
}

impl DockingGains {
    /// The paper's printed ranges in its printed order γ, λ, k, h: (0,1), (0,1), (0,6), (0,1).
    /// Which range belongs to which gain is garbled in the source; this is a chosen reading,
    /// the printed order. The paper's own run (γ 0.5, λ 0.55, k 0.3, h 0.5) lies inside all four
    /// ranges, but with every gain below 1 it would in most other assignments too: the run does
    /// not single this reading out.
    pub const PRINTED_RANGES: [(&'static str, (f64, f64)); 4] = [
        ("gamma", (0.0, 1.0)),
        ("lambda", (0.0, 1.0)),
        ("k", (0.0, 6.0)),
        ("h", (0.0, 1.0)),
    ];

    /// Gains γ (speed), k (turn), h (goal-heading weight), λ (distance weight in V); refused
    /// unless all are finite and positive.
    pub fn new(gamma: f64, k: f64, h: f64, lambda: f64) -> Result<Self, PlannerError> {
        for (name, value) in [("gamma", gamma), ("k", k), ("h", h), ("lambda", lambda)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(PlannerError::InvalidGain { name, value });
            }
        }
        Ok(DockingGains { gamma, k, h, lambda })
    }

    /// The paper's run (004 §4.3.2): γ = 0.5, k = 0.3, h = 0.5, λ = 0.55.
    pub const fn paper() -> Self {
        DockingGains {
            gamma: 0.5,
            k: 0.3,
            h: 0.5,
            lambda: 0.55,
        }
    }

    /// γ (1/s): v = γ·e·cos α.
    pub fn gamma(&self) -> f64 {
        self.gamma
    }

    /// k (1/s): the turn gain on α.
    pub fn k(&self) -> f64 {
        self.k
    }

    /// h: the weight of Θ.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// λ: the weight of e² in V (it does not enter v or ω).
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    /// The gains outside [`Self::PRINTED_RANGES`] (empty for the paper's gains).
    pub fn warnings(&self) -> Vec<GainWarning> {
        let value = |name| match name {
            "gamma" => self.gamma,
            "lambda" => self.lambda,
            "k" => self.k,
            _ => self.h,
        };
        Self::PRINTED_RANGES
            .iter()
            .filter(|(name, (lo, hi))| !(value(name) > *lo && value(name) < *hi))
            .map(|&(name, range)| GainWarning {
                name,
                value: value(name),
                range,
            })
            .collect()
    }

    /// The law: v = γe·cos α (3.43), ω = kα + γ·cos α·sinc(α)·(α + hΘ) (3.46, no stray e).
    pub fn law(&self, p: &PolarError) -> Velocity {
        let c = p.alpha.cos();
        Velocity::new(
            self.gamma * p.e * c,
            self.k * p.alpha + self.gamma * c * sinc(p.alpha) * (p.alpha + self.h * p.theta),
        )
    }

    /// Lyapunov function V = ½(λe² + α² + hΘ²), eq. (3.41).
    pub fn lyapunov(&self, p: &PolarError) -> f64 {
        0.5 * (self.lambda * p.e * p.e + p.alpha * p.alpha + self.h * p.theta * p.theta)
    }

    /// V̇ under the law scaled by `scale` (V̇ is linear in v and ω): −s·(λγe²cos²α + kα²),
    /// eq. (3.48); never positive for s ≥ 0.
    pub fn lyapunov_rate(&self, p: &PolarError, scale: f64) -> f64 {
        let c = p.alpha.cos();
        -scale * (self.lambda * self.gamma * p.e * p.e * c * c + self.k * p.alpha * p.alpha)
    }
}

impl Default for DockingGains {
    /// The paper's.
    fn default() -> Self {
        DockingGains::paper()
    }
}

/// Speed limits applied by one common factor on v and ω (SPEC §3: never ω clipped alone).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VelocityLimits {
    v_max: f64,
    omega_max: f64,
    wheels: Option<ChassisParams>,
}

impl VelocityLimits {
    /// Limits |v| ≤ v_max (m/s), |ω| ≤ ω_max (rad/s); both finite and positive.
    pub fn new(v_max: f64, omega_max: f64) -> Result<Self, PlannerError> {
        Ok(VelocityLimits {
            v_max: positive_finite("v_max", v_max)?,
            omega_max: positive_finite("omega_max", omega_max)?,
            wheels: None,
        })
    }

    /// No limit at all (the paper's unlimited unicycle).
    pub const fn unlimited() -> Self {
        VelocityLimits {
            v_max: f64::INFINITY,
            omega_max: f64::INFINITY,
            wheels: None,
        }
    }

    /// A chassis' v_max, ω_max and its wheel-speed limit (wheel speeds are homogeneous of degree
    /// one in (v, ω), so that too is one common factor).
    pub fn from_chassis(params: &ChassisParams) -> Self {
        VelocityLimits {
            v_max: params.v_max(),
            omega_max: params.omega_max(),
            wheels: Some(*params),
        }
    }

    /// v_max (m/s).
    pub fn v_max(&self) -> f64 {
        self.v_max
    }

    /// ω_max (rad/s).
    pub fn omega_max(&self) -> f64 {
        self.omega_max
    }

    /// The factor s ∈ [0, 1] that brings `cmd` within every limit: min(1, v_max/|v|, ω_max/|ω|,
    /// max wheel speed / fastest wheel). A non-finite command gives 0 (stop).
    pub fn factor(&self, cmd: Velocity) -> f64 {
        if !(cmd.v.is_finite() && cmd.omega.is_finite()) {
            return 0.0;
        }
        let ratio = |limit: f64, value: f64| if value.abs() > limit { limit / value.abs() } else { 1.0 };
        let mut s = ratio(self.v_max, cmd.v).min(ratio(self.omega_max, cmd.omega));
        if let Some(params) = &self.wheels {
            let fastest = inverse(params, cmd.scaled(s).to_twist()).max_abs_wheel_speed();
            s *= ratio(params.max_wheel_speed(), fastest);
        }
        s
    }

    /// `cmd` scaled by [`Self::factor`], and the factor.
    pub fn apply(&self, cmd: Velocity) -> (Velocity, f64) {
        let s = self.factor(cmd);
        (cmd.scaled(s), s)
    }
}

/// How a docking ends once the position is reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Finish {
    /// The chassis turns in place (omni, unicycle): rotate onto ϑ_G once e < ε_e.
    RotateInPlace,
    /// The chassis cannot turn in place (car-like, tricycle): the heading left when e < ε_e is
    /// reported as the residual.
    ReportResidual,
}

impl Finish {
    /// The finish a chassis allows: in place for the omni chassis, residual otherwise.
    pub fn for_chassis(params: &ChassisParams) -> Self {
        if params.model().is_nonholonomic() {
            Finish::ReportResidual
        } else {
            Finish::RotateInPlace
        }
    }
}

/// Thresholds and timers of [`DockingController`]; every default justified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DockingConfig {
    /// ε_e (m): docked needs e below it. Default 0.02: well inside a 0.05 m acceptance, with
    /// room for odometry error and one 20 Hz control period at the law's final speeds.
    pub position_tolerance: f64,
    /// ε_ϑ (rad): docked needs |wrap(ϑ − ϑ_G)| below it. Default 0.03 (1.7°): a third of a
    /// 0.1 rad acceptance; the in-place rotation settles well inside it.
    pub heading_tolerance: f64,
    /// Gain (1/s) of the final in-place rotation ω = k_rot·wrap(ϑ_G − ϑ). Default 1.5: a 0.67 s
    /// time constant; with OMR-III's ω_max = 1.5 rad/s it saturates only above 1 rad.
    pub rotate_gain: f64,
    /// The rotation hands back to the law if e grows above this multiple of ε_e (a real chassis
    /// drifts while turning). Default 2.
    pub rotate_exit_factor: f64,
    /// A docking not done after this long (s) fails. Default 120: from the paper's start the law
    /// and the final rotation dock in 14.55 s unlimited, 15.60 s within Nav2's limits
    /// (docs/experiments/docking.md).
    pub time_limit_s: f64,
    /// A docking whose progress measure (V while approaching, the heading error while rotating)
    /// has not fallen by `stall_fraction` for this long (s) fails as not converging. Default 5:
    /// the law's V falls by far more than 0.1 % in any 5 s away from the goal.
    pub stall_time_s: f64,
    /// Relative fall of the progress measure that counts as progress. Default 1e-3.
    pub stall_fraction: f64,
}

impl Default for DockingConfig {
    fn default() -> Self {
        DockingConfig {
            position_tolerance: 0.02,
            heading_tolerance: 0.03,
            rotate_gain: 1.5,
            rotate_exit_factor: 2.0,
            time_limit_s: 120.0,
            stall_time_s: 5.0,
            stall_fraction: 1e-3,
        }
    }
}

impl DockingConfig {
    /// Checks every field: positive and finite; the exit factor above 1; the fraction in (0, 1).
    pub fn validate(&self) -> Result<(), PlannerError> {
        positive_finite("position_tolerance", self.position_tolerance)?;
        positive_finite("heading_tolerance", self.heading_tolerance)?;
        positive_finite("rotate_gain", self.rotate_gain)?;
        positive_finite("time_limit_s", self.time_limit_s)?;
        positive_finite("stall_time_s", self.stall_time_s)?;
        if !(self.rotate_exit_factor.is_finite() && self.rotate_exit_factor > 1.0) {
            return Err(PlannerError::InvalidConfig {
                name: "rotate_exit_factor",
                value: self.rotate_exit_factor,
                reason: "must be finite and above 1",
            });
        }
        if !(self.stall_fraction > 0.0 && self.stall_fraction < 1.0) {
            return Err(PlannerError::InvalidConfig {
                name: "stall_fraction",
                value: self.stall_fraction,
                reason: "must lie in (0, 1)",
            });
        }
        Ok(())
    }
}

/// Why a docking failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DockingFailure {
    /// The time limit passed.
    TimeLimit,
    /// The progress measure stopped falling (the node's FAILED_TO_CONTROL).
    NotConverging,
    /// The position was reached but the chassis cannot turn in place onto ϑ_G: the heading
    /// residual stays.
    HeadingResidual,
}

impl DockingFailure {
    /// A short reason for logs and status messages.
    pub fn as_str(self) -> &'static str {
        match self {
            DockingFailure::TimeLimit => "time limit reached",
            DockingFailure::NotConverging => "Lyapunov function stopped falling",
            DockingFailure::HeadingResidual => "position reached, heading residual: chassis cannot turn in place",
        }
    }
}

/// Where a failed docking stood when it failed: what a node reports with the reason.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Residual {
    /// Distance e (m) to the goal position.
    pub e: f64,
    /// wrap(ϑ_G − ϑ) (rad): the heading still to turn.
    pub heading: f64,
}

/// Where a docking stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DockingPhase {
    /// Driving by the Lyapunov law.
    Approach,
    /// Turning in place onto ϑ_G (e < ε_e).
    Rotate,
    /// e < ε_e and the heading within ε_ϑ: done, stopped.
    Docked,
    /// Ended without docking, stopped.
    Failed(DockingFailure),
}

impl DockingPhase {
    /// True once the docking has ended (docked or failed): the command is zero from then on.
    pub fn is_terminal(self) -> bool {
        matches!(self, DockingPhase::Docked | DockingPhase::Failed(_))
    }
}

/// One control step's result: the command and everything a node reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DockingOutput {
    /// The phase after this step.
    pub phase: DockingPhase,
    /// The command, within the limits (zero in a terminal phase).
    pub command: Velocity,
    /// The common factor s applied to the command (the law's while approaching, the in-place
    /// rotation's while rotating; 1 when within the limits, 0 once ended).
    pub scale: f64,
    /// The polar error at this pose.
    pub polar: PolarError,
    /// V at this pose, eq. (3.41).
    pub lyapunov: f64,
    /// V̇ under this command, eq. (3.48) times s; 0 outside the approach phase.
    pub lyapunov_rate: f64,
    /// wrap(ϑ_G − ϑ) (rad): the heading still to turn.
    pub heading_error: f64,
    /// After a failure: e and the heading error at the step it failed (kept from then on).
    pub residual: Option<Residual>,
}

/// The docking state machine around the law: approach, rotate, docked or failed.
#[derive(Debug, Clone, PartialEq)]
pub struct DockingController {
    gains: DockingGains,
    config: DockingConfig,
    limits: VelocityLimits,
    finish: Finish,
    goal: Pose2,
    phase: DockingPhase,
    start_t: Option<f64>,
    best: f64,
    best_t: f64,
    residual: Option<Residual>,
}

impl DockingController {
    /// A controller for `goal` (finite) with validated settings.
    pub fn new(
        gains: DockingGains,
        config: DockingConfig,
        limits: VelocityLimits,
        finish: Finish,
        goal: Pose2,
    ) -> Result<Self, PlannerError> {
        config.validate()?;
        check_pose("goal", &goal)?;
        Ok(DockingController {
            gains,
            config,
            limits,
            finish,
            goal,
            phase: DockingPhase::Approach,
            start_t: None,
            best: f64::INFINITY,
            best_t: 0.0,
            residual: None,
        })
    }

    /// A new goal (finite): the docking starts again from the approach phase.
    pub fn set_goal(&mut self, goal: Pose2) -> Result<(), PlannerError> {
        check_pose("goal", &goal)?;
        self.goal = goal;
        self.phase = DockingPhase::Approach;
        self.start_t = None;
        self.best = f64::INFINITY;
        self.residual = None;
        Ok(())
    }

    /// How the docking ends once the position is reached.
    pub fn finish(&self) -> Finish {
        self.finish
    }

    /// The goal pose.
    pub fn goal(&self) -> Pose2 {
        self.goal
    }

    /// The gains.
    pub fn gains(&self) -> &DockingGains {
        &self.gains
    }

    /// The settings.
    pub fn config(&self) -> &DockingConfig {
        &self.config
    }

    /// The limits.
    pub fn limits(&self) -> &VelocityLimits {
        &self.limits
    }

    /// The current phase.
    pub fn phase(&self) -> DockingPhase {
        self.phase
    }

    /// The law's command at `pose`, limited by one common factor, and the factor: a pure
    /// function of the state (what an integrator evaluates between control steps).
    pub fn approach_command(&self, pose: &Pose2) -> (Velocity, f64) {
        self.limits.apply(self.gains.law(&polar_error(pose, &self.goal)))
    }

    /// The in-place rotation command at `pose`: ω = k_rot·wrap(ϑ_G − ϑ), limited, and the
    /// factor applied.
    pub fn rotate_command(&self, pose: &Pose2) -> (Velocity, f64) {
        let cmd = Velocity::new(0.0, self.config.rotate_gain * wrap(self.goal.yaw - pose.yaw));
        self.limits.apply(cmd)
    }

    fn restart_progress(&mut self, measure: f64, t: f64) {
        self.best = measure;
        self.best_t = t;
    }

    /// One control step at `pose` and time `t` (s, any origin, non-decreasing): the phase
    /// logic, then the command. A non-finite pose is refused (the caller stops the robot).
    pub fn update(&mut self, pose: &Pose2, t: f64) -> Result<DockingOutput, PlannerError> {
        check_pose("pose", pose)?;
        if !t.is_finite() {
            return Err(PlannerError::NonFinite {
                what: "time".into(),
                x: t,
                y: 0.0,
                yaw: 0.0,
            });
        }
        let polar = polar_error(pose, &self.goal);
        let heading_error = wrap(self.goal.yaw - pose.yaw);
        let lyapunov = self.gains.lyapunov(&polar);
        let start = *self.start_t.get_or_insert(t);
        let cfg = self.config;
        if !self.phase.is_terminal() {
            if polar.e < cfg.position_tolerance && heading_error.abs() < cfg.heading_tolerance {
                self.phase = DockingPhase::Docked;
            } else if t - start > cfg.time_limit_s {
                self.phase = DockingPhase::Failed(DockingFailure::TimeLimit);
            }
        }
        match self.phase {
            DockingPhase::Approach if polar.e < cfg.position_tolerance => match self.finish {
                Finish::RotateInPlace => {
                    self.phase = DockingPhase::Rotate;
                    self.restart_progress(heading_error.abs(), t);
                }
                Finish::ReportResidual => {
                    self.phase = DockingPhase::Failed(DockingFailure::HeadingResidual);
                }
            },
            // Back to the law when the position drifted too far, or when it drifted out of ε_e
            // with the heading already within ε_ϑ: the rotation would command ω ≈ 0 there and
            // never bring e back.
            DockingPhase::Rotate
                if polar.e > cfg.rotate_exit_factor * cfg.position_tolerance
                    || (polar.e >= cfg.position_tolerance && heading_error.abs() < cfg.heading_tolerance) =>
            {
                self.phase = DockingPhase::Approach;
                self.restart_progress(lyapunov, t);
            }
            _ => {}
        }
        let (command, scale, rate, measure) = match self.phase {
            DockingPhase::Approach => {
                let (cmd, s) = self.limits.apply(self.gains.law(&polar));
                (cmd, s, self.gains.lyapunov_rate(&polar, s), lyapunov)
            }
            DockingPhase::Rotate => {
                let (cmd, s) = self.rotate_command(pose);
                (cmd, s, 0.0, heading_error.abs())
            }
            DockingPhase::Docked | DockingPhase::Failed(_) => (Velocity::ZERO, 0.0, 0.0, 0.0),
        };
        if !self.phase.is_terminal() {
            if measure < self.best * (1.0 - cfg.stall_fraction) || !self.best.is_finite() {
                self.restart_progress(measure, t);
            } else if t - self.best_t > cfg.stall_time_s {
                self.phase = DockingPhase::Failed(DockingFailure::NotConverging);
            }
        }
        let command = if self.phase.is_terminal() {
            Velocity::ZERO
        } else {
            command
        };
        if matches!(self.phase, DockingPhase::Failed(_)) && self.residual.is_none() {
            self.residual = Some(Residual {
                e: polar.e,
                heading: heading_error,
            });
        }
        Ok(DockingOutput {
            phase: self.phase,
            command,
            scale,
            polar,
            lyapunov,
            lyapunov_rate: rate,
            heading_error,
            residual: self.residual,
        })
    }
}

pub(crate) fn check_pose(what: &str, p: &Pose2) -> Result<(), PlannerError> {
    crate::error::check_coordinates(what, p.x, p.y, p.yaw)
}
