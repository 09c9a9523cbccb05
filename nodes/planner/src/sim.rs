//! Continuous-time integration of a docking: the controller gives (v, ω) for a state, this
//! module moves the robot (SPEC §3 Decision: the law is continuous-time; the paper's time step
//! of 1 raises V, small sub-steps do not).
//!
//! Between control decisions the approach phase is integrated by classical Runge–Kutta (RK4) on
//! the closed loop q̇ = f(q), the law re-evaluated at every stage, so the simulation follows the
//! continuous-time system the Lyapunov proof is about. [`advance`] is the exact motion under a
//! constant body twist (an arc), used for the in-place rotation and by callers that hold a
//! command for a control period.

use mobil_chassis::{clamp_command, BodyTwist, ChassisParams};
use mobil_geom::Pose2;

use crate::docking::{DockingController, DockingOutput, DockingPhase, Velocity};
use crate::error::{positive_finite, PlannerError};

/// What executes a command: an ideal unicycle (the paper's model) or a chassis whose LOW-LEVEL
/// makes every twist feasible ([`mobil_chassis::clamp_command`]: on a car-like chassis that
/// clamps the curvature, so the law is no longer followed there).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kinematics {
    /// ẋ = v cos ϑ, ẏ = v sin ϑ, ϑ̇ = ω, no limits.
    Unicycle,
    /// The chassis' own command limits, then rigid-body motion with the resulting twist.
    Chassis(ChassisParams),
}

impl Kinematics {
    /// The body twist the robot actually moves with for a commanded (v, ω).
    pub fn execute(&self, cmd: Velocity) -> BodyTwist {
        match self {
            Kinematics::Unicycle => cmd.to_twist(),
            Kinematics::Chassis(params) => clamp_command(params, cmd.to_twist()).twist,
        }
    }
}

/// World-frame pose rate of a body moving with `t` at heading `yaw`.
fn pose_rate(yaw: f64, t: &BodyTwist) -> [f64; 3] {
    let (s, c) = yaw.sin_cos();
    [c * t.vx - s * t.vy, s * t.vx + c * t.vy, t.wz]
}

/// The pose after `dt` seconds under the constant body twist `t` (exact: an arc, or a line when
/// ω·dt is below 1e-9 rad).
pub fn advance(pose: &Pose2, t: &BodyTwist, dt: f64) -> Pose2 {
    let turn = t.wz * dt;
    let (dx, dy) = if turn.abs() < 1e-9 {
        (t.vx * dt, t.vy * dt)
    } else {
        let (s, c) = turn.sin_cos();
        (
            (t.vx * s - t.vy * (1.0 - c)) / t.wz,
            (t.vx * (1.0 - c) + t.vy * s) / t.wz,
        )
    };
    pose.compose(&Pose2::new(dx, dy, turn))
}

/// One RK4 step of length `h` of q̇ = f(q), f giving the body twist at a pose.
pub fn rk4_step(pose: &Pose2, h: f64, f: impl Fn(&Pose2) -> BodyTwist) -> Pose2 {
    let at = |k: &[f64; 3], s: f64| Pose2 {
        x: pose.x + s * k[0],
        y: pose.y + s * k[1],
        yaw: pose.yaw + s * k[2],
    };
    let rate = |p: &Pose2| pose_rate(p.yaw, &f(p));
    let k1 = rate(pose);
    let k2 = rate(&at(&k1, 0.5 * h));
    let k3 = rate(&at(&k2, 0.5 * h));
    let k4 = rate(&at(&k3, h));
    let d = |i: usize| h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    Pose2::new(pose.x + d(0), pose.y + d(1), pose.yaw + d(2))
}

/// One recorded instant of a simulated docking.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DockingSample {
    /// Time since the start (s).
    pub t: f64,
    /// The pose at `t`.
    pub pose: Pose2,
    /// The controller's output at that pose.
    pub output: DockingOutput,
}

/// A whole simulated docking.
#[derive(Debug, Clone, PartialEq)]
pub struct DockingRun {
    /// One sample per sub-step, the first at t = 0, the last at the end.
    pub samples: Vec<DockingSample>,
    /// The phase at the end ([`DockingPhase::Approach`] or [`DockingPhase::Rotate`] if
    /// `max_time` ran out first).
    pub end: DockingPhase,
    /// The pose at the end.
    pub final_pose: Pose2,
    /// Time at the end (s).
    pub time: f64,
    /// Length of the path driven by the reference point (m).
    pub path_length: f64,
}

/// Most sub-steps of one [`simulate_docking`] (`max_time / h`): 10⁴ s at 10 ms; the recorded
/// run then holds about 100 MB.
pub const MAX_SIMULATION_STEPS: f64 = 1e6;

/// Drives `controller` from `start` with sub-steps of `h` seconds until the docking ends or
/// `max_time` passes. Every sub-step is a control decision (`update`), then the motion: RK4 on
/// the closed loop while approaching, the exact arc of the held command otherwise. Refuses h or
/// `max_time` not finite and positive, `max_time / h` above [`MAX_SIMULATION_STEPS`], and a
/// non-finite or out-of-range start.
pub fn simulate_docking(
    controller: &mut DockingController,
    kinematics: Kinematics,
    start: Pose2,
    h: f64,
    max_time: f64,
) -> Result<DockingRun, PlannerError> {
    positive_finite("h", h)?;
    positive_finite("max_time", max_time)?;
    if max_time / h > MAX_SIMULATION_STEPS {
        return Err(PlannerError::InvalidConfig {
            name: "max_time",
            value: max_time,
            reason: "more than MAX_SIMULATION_STEPS sub-steps of h",
        });
    }
    crate::docking::check_pose("start", &start)?;
    let mut pose = start;
    let mut samples = Vec::new();
    let mut path_length = 0.0;
    let mut step = 0u64;
    loop {
        let t = step as f64 * h;
        let output = controller.update(&pose, t)?;
        samples.push(DockingSample { t, pose, output });
        if output.phase.is_terminal() || t >= max_time {
            return Ok(DockingRun {
                end: output.phase,
                final_pose: pose,
                time: t,
                path_length,
                samples,
            });
        }
        let next = match output.phase {
            DockingPhase::Approach => rk4_step(&pose, h, |q| kinematics.execute(controller.approach_command(q).0)),
            _ => advance(&pose, &kinematics.execute(output.command), h),
        };
        path_length += (next.x - pose.x).hypot(next.y - pose.y);
        pose = next;
        step += 1;
    }
}
