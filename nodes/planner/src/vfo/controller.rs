//! The VFO control law for waypoint following with collision avoidance (eq. 5–13 of the VFO
//! paper), switching (Algorithm 1) and vortex escape (Algorithm 3), for a unicycle
//! q = [θ, x, y], u = [ω, v].
//!
//! For waypoint i (q*_ri, θ_ri, μ_i), at the robot's position q*:
//! - e* = q*_ri − q*, h* = k_p·e* + v*, v* = −k_p·μ_i·‖e*‖·[cos θ_ri, sin θ_ri] (ζ ≡ +1);
//! - S = Σ_k σ_k·V(d_k), h*_o = S·R_o·h*, R_o = [[0, 1], [−1, 0]]; H* = h* + h*_o;
//! - θ_a = Atan2c(H_y, H_x), continuous (kept unwrapped within a segment), e_a = θ_a − θ;
//! - θ̇_a = (Ḣ_y·H_x − Ḣ_x·H_y)/‖H*‖², with Ḣ* = (∂H*/∂q*)·q̇* worked out analytically
//!   (V'(d) from [`potential_derivative`]) and q̇* = v·[cos θ, sin θ];
//! - u = [k_a·e_a + θ̇_a, U_2·cos e_a] (13).
//!
//! With σ = +1 and the robot heading along h*, R_o·h* points to the robot's right, so a positive
//! S turns the field to the right of the straight way and the robot passes the obstacle with
//! the obstacle on its left: it goes round the right-hand side of it. That is the SPEC's
//! "σ = +1 passes on the right" (tested).
//!
//! Choices beyond the paper (its gains are not given):
//! - **Atan2c at a segment start**: θ_a is anchored on the branch within π of the robot's
//!   (unwrapped) heading, so |e_a| ≤ π when a new waypoint is taken; within the segment it is
//!   continued (each step adds wrap(atan2 − θ_a)), so e_a is continuous as the law needs. The
//!   robot's heading is unwrapped the same way from the poses given.
//! - **H* = 0** (at the waypoint itself): θ_a keeps its last value, θ̇_a = 0.
//! - **Limits**: ω is clamped to ±`omega_max`; |v| ≤ U_2 holds by the law. While ω is clamped
//!   e_a no longer decays as e_a(0)·exp(−k_a·t): it decays at least at ω_max − |θ̇_a| once the
//!   clamp exceeds |θ̇_a|, and may grow where |θ̇_a| > ω_max (deep in an influence zone, where
//!   V' is large). The default, 4 rad/s, binds only there.
//! - **The last waypoint**: the paper's constant profile v = U_2·cos e_a cannot stay at a
//!   point; at i = N the speed is v = min(U_2, ‖H*‖)·cos e_a, the original VFO stabiliser's
//!   ‖h*‖ scaling near the goal, so q converges (position and heading) and the end test
//!   ‖q_N − q‖ < ϵ (θ in rad, x, y in m, SPEC §5) is met, then u = 0.
//! - **Collision** (d_k ≤ r_k for some k): V = ∞, the law is undefined; the step says so and
//!   commands zero.

use mobil_geom::{wrap, Pose2};
use nalgebra::{Point2, Vector2};

use super::obstacles::{potential, potential_derivative, Obstacle, Sigma};
use crate::error::{check_coordinates, positive_finite, PlannerError};

/// Gains and tolerances of the VFO law; every default justified (the paper gives none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VfoGains {
    /// k_p (1/s), the position gain of h* (eq. 10). Default 1: it scales h* and h*_o alike, so
    /// it changes the path only through the last waypoint's speed min(U_2, ‖H*‖), which it
    /// makes slow down within U_2/k_p = 0.3 m.
    pub k_p: f64,
    /// k_a (1/s), the orienting gain (eq. 13): e_a falls as exp(−k_a·t). Default 5: e_a settles
    /// in about 1 s (5 time constants), well before the robot covers its 0.3 m per second.
    pub k_a: f64,
    /// U_2 (m/s), the constant speed profile (eq. 13). Default 0.3: the planner's cruise speed
    /// (60 % of MOBIL-II's and OMR-III's v_max).
    pub speed: f64,
    /// |ω| limit (rad/s). Default 4 (see the module docs for how it meets the law).
    pub omega_max: f64,
    /// ϵ_i (m), the switching accuracy of Algorithm 1 at an intermediate waypoint. Default 0.05,
    /// the paper's.
    pub switch_epsilon: f64,
    /// ϵ for the last waypoint: ‖q_N − q‖ < ϵ ends the route (θ in rad, x, y in m). Default
    /// 0.05, the paper's ϵ_i.
    pub final_epsilon: f64,
}

impl Default for VfoGains {
    fn default() -> Self {
        VfoGains {
            k_p: 1.0,
            k_a: 5.0,
            speed: 0.3,
            omega_max: 4.0,
            switch_epsilon: 0.05,
            final_epsilon: 0.05,
        }
    }
}

impl VfoGains {
    /// Checks every field: finite and positive.
    pub fn validate(&self) -> Result<(), PlannerError> {
        positive_finite("k_p", self.k_p)?;
        positive_finite("k_a", self.k_a)?;
        positive_finite("speed", self.speed)?;
        positive_finite("omega_max", self.omega_max)?;
        positive_finite("switch_epsilon", self.switch_epsilon)?;
        positive_finite("final_epsilon", self.final_epsilon)?;
        Ok(())
    }
}

/// A default guiding coefficient μ for waypoints that come without one (the paper gives
/// none): 0.5 makes the virtual velocity half of k_p·‖e*‖, so the approach bends toward θ_r
/// without the long swing-out a μ near 1 makes to line up (at μ = 1, h* vanishes on the
/// approach line itself, behind the waypoint).
pub const DEFAULT_GUIDING: f64 = 0.5;

/// A waypoint w_i = {q_ri, μ_i} (eq. 2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VfoWaypoint {
    /// q*_ri (m).
    pub position: Point2<f64>,
    /// θ_ri (rad): the direction the guiding effect lines the approach up with.
    pub heading: f64,
    /// μ_i ∈ (0, 1), the guiding coefficient (eq. 11).
    pub guiding: f64,
}

impl VfoWaypoint {
    /// A waypoint at (x, y) with heading θ_r and guiding coefficient μ, checked: finite, within
    /// the crate's coordinate limit, 0 < μ < 1.
    pub fn new(x: f64, y: f64, heading: f64, guiding: f64) -> Result<Self, PlannerError> {
        check_coordinates("waypoint", x, y, heading)?;
        if !(guiding > 0.0 && guiding < 1.0) {
            return Err(PlannerError::InvalidConfig {
                name: "guiding",
                value: guiding,
                reason: "the guiding coefficient μ must lie in (0, 1)",
            });
        }
        Ok(VfoWaypoint {
            position: Point2::new(x, y),
            heading,
            guiding,
        })
    }
}

/// The position field at one point (eq. 6, 7, 10, 11).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Field {
    /// e* = q*_ri − q*.
    pub error: Vector2<f64>,
    /// h* (eq. 10).
    pub h: Vector2<f64>,
    /// S = Σ σ_k·V(d_k), the signed sum that scales h*_o.
    pub signed_potential: f64,
    /// Σ V(d_k), unsigned: the danger χ_B takes the maximum of (eq. 15).
    pub danger: f64,
    /// h*_o (eq. 7).
    pub h_o: Vector2<f64>,
    /// H* = h* + h*_o.
    pub big_h: Vector2<f64>,
    /// The first obstacle whose forbidden zone holds the point (d ≤ r): h*_o is then 0 and the
    /// law undefined.
    pub collision: Option<usize>,
}

fn rot_o(v: Vector2<f64>) -> Vector2<f64> {
    // R_o = [[0, 1], [−1, 0]].
    Vector2::new(v.y, -v.x)
}

/// [cos θ_r, sin θ_r], the direction of a waypoint's guiding effect.
pub(crate) fn guide(wp: &VfoWaypoint) -> Vector2<f64> {
    let (sin, cos) = wp.heading.sin_cos();
    Vector2::new(cos, sin)
}

/// The obstacles a step evaluates: all of them, or a caller's subset (ascending indices) that
/// holds every obstacle whose influence zone the position can be in. The others contribute
/// exactly nothing (V = V' = 0 beyond R), so the result is the same either way.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Near<'a> {
    /// Every obstacle.
    All,
    /// Only these indices (ascending).
    Only(&'a [usize]),
}

impl Near<'_> {
    /// Calls `f` with each index, ascending.
    pub(crate) fn for_each(self, count: usize, mut f: impl FnMut(usize)) {
        match self {
            Near::All => (0..count).for_each(f),
            Near::Only(indices) => indices.iter().for_each(|&k| f(k)),
        }
    }
}

/// An obstacle whose influence zone holds a point (d ≤ R), with what the law needs of it there.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Nearby {
    /// Its index.
    pub(crate) k: usize,
    /// q* − p_k.
    pub(crate) away: Vector2<f64>,
    /// d_k = ‖q* − p_k‖.
    pub(crate) d: f64,
}

/// The obstacles among `candidates` whose influence zone holds `position`, ascending, into
/// `out` (cleared first): one distance per candidate, which the zone test, H*, Ḣ* and the
/// danger then share.
pub(crate) fn measure(obstacles: &[Obstacle], candidates: Near<'_>, position: &Point2<f64>, out: &mut Vec<Nearby>) {
    out.clear();
    candidates.for_each(obstacles.len(), |k| {
        let Some(o) = obstacles.get(k) else {
            return;
        };
        let away = position - o.centre();
        let d = away.norm();
        if d <= o.influence_radius() {
            out.push(Nearby { k, away, d });
        }
    });
}

/// The convergence field H* at `position` for waypoint `wp` (eq. 6, 7, 10–12; ζ ≡ +1).
/// `sigmas[k]` is σ of `obstacles[k]` (missing entries count as undecided).
pub fn convergence_field(
    position: &Point2<f64>,
    wp: &VfoWaypoint,
    k_p: f64,
    obstacles: &[Obstacle],
    sigmas: &[Sigma],
) -> Field {
    let mut nearby = Vec::new();
    measure(obstacles, Near::All, position, &mut nearby);
    field_among(position, wp, &guide(wp), k_p, obstacles, sigmas, &nearby)
}

/// [`convergence_field`] from the obstacles [`measure`]d at `position`, with the guide
/// [cos θ_r, sin θ_r] given.
fn field_among(
    position: &Point2<f64>,
    wp: &VfoWaypoint,
    guide: &Vector2<f64>,
    k_p: f64,
    obstacles: &[Obstacle],
    sigmas: &[Sigma],
    nearby: &[Nearby],
) -> Field {
    let error = wp.position - position;
    let h = k_p * error - k_p * wp.guiding * error.norm() * guide;
    let mut signed = 0.0;
    let mut danger = 0.0;
    let mut collision = None;
    for &Nearby { k, d, .. } in nearby {
        let Some(o) = obstacles.get(k) else {
            continue;
        };
        if d <= o.forbidden_radius() {
            collision.get_or_insert(k);
            continue;
        }
        let v = potential(d, o.forbidden_radius(), o.influence_radius());
        danger += v;
        signed += sigmas.get(k).copied().unwrap_or_default().value() * v;
    }
    if collision.is_some() {
        return Field {
            error,
            h,
            signed_potential: f64::INFINITY,
            danger: f64::INFINITY,
            h_o: Vector2::zeros(),
            big_h: h,
            collision,
        };
    }
    let h_o = signed * rot_o(h);
    Field {
        error,
        h,
        signed_potential: signed,
        danger,
        h_o,
        big_h: h + h_o,
        collision: None,
    }
}

/// Ḣ* = (∂H*/∂q*)·q̇* at `position` moving with `velocity` (analytic, V'(d) of eq. 16):
/// ḣ* = −k_p·q̇* + k_p·μ·(e*·q̇*/‖e*‖)·[cos θ_r, sin θ_r], Ṡ = Σ σ_k·V'(d_k)·(q* − p_k)·q̇*/d_k,
/// ḣ*_o = Ṡ·R_o·h* + S·R_o·ḣ*. `field` is [`convergence_field`] at the same point.
pub fn field_rate(
    field: &Field,
    position: &Point2<f64>,
    velocity: &Vector2<f64>,
    wp: &VfoWaypoint,
    k_p: f64,
    obstacles: &[Obstacle],
    sigmas: &[Sigma],
) -> Vector2<f64> {
    let mut nearby = Vec::new();
    measure(obstacles, Near::All, position, &mut nearby);
    rate_among(field, velocity, wp, &guide(wp), k_p, obstacles, sigmas, &nearby)
}

/// [`field_rate`] from the obstacles [`measure`]d at the field's point, with the guide given.
#[allow(clippy::too_many_arguments)] // the law's inputs, private
fn rate_among(
    field: &Field,
    velocity: &Vector2<f64>,
    wp: &VfoWaypoint,
    guide: &Vector2<f64>,
    k_p: f64,
    obstacles: &[Obstacle],
    sigmas: &[Sigma],
    nearby: &[Nearby],
) -> Vector2<f64> {
    let norm = field.error.norm();
    let mut h_dot = -k_p * velocity;
    if norm > 0.0 {
        h_dot += k_p * wp.guiding * field.error.dot(velocity) / norm * guide;
    }
    if field.collision.is_some() {
        return h_dot;
    }
    let mut s_dot = 0.0;
    for &Nearby { k, away, d } in nearby {
        let Some(o) = obstacles.get(k) else {
            continue;
        };
        if d <= o.forbidden_radius() {
            continue;
        }
        let dv = potential_derivative(d, o.forbidden_radius(), o.influence_radius());
        s_dot += sigmas.get(k).copied().unwrap_or_default().value() * dv * away.dot(velocity) / d;
    }
    h_dot + s_dot * rot_o(field.h) + field.signed_potential * rot_o(h_dot)
}

/// Moves a unicycle at `pose` along the exact arc of (v, ω) held for `dt` seconds. The
/// heading is not wrapped (the law keeps it continuous).
pub fn integrate_unicycle(pose: &Pose2, v: f64, omega: f64, dt: f64) -> Pose2 {
    integrate_from(pose, pose.yaw.sin_cos(), v, omega, dt).0
}

/// [`integrate_unicycle`] with (sin, cos) of the pose's yaw given; also returns the new pose's
/// (of its yaw as [`Pose2`] keeps it, wrapped, so that a simulation started from that pose
/// computes the same values).
pub(crate) fn integrate_from(pose: &Pose2, (sin, cos): (f64, f64), v: f64, omega: f64, dt: f64) -> (Pose2, (f64, f64)) {
    let turn = omega * dt;
    let yaw = wrap(pose.yaw + turn);
    let next = yaw.sin_cos();
    if turn.abs() < 1e-9 {
        let (mid_sin, mid_cos) = (pose.yaw + 0.5 * turn).sin_cos();
        (
            Pose2::new(pose.x + v * dt * mid_cos, pose.y + v * dt * mid_sin, yaw),
            next,
        )
    } else {
        let r = v / omega;
        (
            Pose2::new(pose.x + r * (next.0 - sin), pose.y - r * (next.1 - cos), yaw),
            next,
        )
    }
}

/// What one control step decided.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepOutcome {
    /// Keep driving with `omega`, `v`.
    Drive,
    /// The waypoint is done (Algorithm 1, or the end test at i = N): command zero and take
    /// the next one. `vortex` says Algorithm 3 enlarged ϵ_i to 2‖e*_i‖ in this step.
    Reached {
        /// Algorithm 3 fired in this step.
        vortex: bool,
    },
    /// The robot is inside the forbidden zone of obstacle `obstacle`: command zero.
    Collision {
        /// The obstacle's index.
        obstacle: usize,
    },
}

/// One step of the law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlStep {
    /// ω (rad/s), after the clamp (0 unless [`StepOutcome::Drive`]).
    pub omega: f64,
    /// v (m/s) (0 unless [`StepOutcome::Drive`]).
    pub v: f64,
    /// e_a = θ_a − θ (rad), continuous.
    pub e_a: f64,
    /// θ_a (rad), unwrapped.
    pub theta_a: f64,
    /// θ̇_a (rad/s).
    pub theta_a_rate: f64,
    /// The field at the step's position.
    pub field: Field,
    /// ϵ_i in force after this step (m).
    pub epsilon: f64,
    /// What the step decided.
    pub outcome: StepOutcome,
}

/// The waypoint a step aims at, with what a virtual robot computes once per segment.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Aim<'a> {
    /// The waypoint.
    pub(crate) waypoint: &'a VfoWaypoint,
    /// [cos θ_r, sin θ_r].
    pub(crate) guide: Vector2<f64>,
    /// Whether it is the last waypoint.
    pub(crate) last: bool,
}

/// The VFO law's state over a segment: the unwrapped heading and θ_a (Atan2c) and ϵ_i.
/// Virtual robots clone it, so they continue exactly where the real robot's law stands.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VfoController {
    gains: VfoGains,
    theta: Option<f64>,
    theta_a: Option<f64>,
    epsilon: f64,
}

impl VfoController {
    /// A controller with checked gains.
    pub fn new(gains: VfoGains) -> Result<Self, PlannerError> {
        gains.validate()?;
        Ok(VfoController {
            gains,
            theta: None,
            theta_a: None,
            epsilon: gains.switch_epsilon,
        })
    }

    /// The gains.
    pub fn gains(&self) -> &VfoGains {
        &self.gains
    }

    /// ϵ_i in force (m).
    pub fn epsilon(&self) -> f64 {
        self.epsilon
    }

    /// Starts a new segment: ϵ_i back to its default, θ_a anchored anew at the next step.
    pub fn start_segment(&mut self) {
        self.theta_a = None;
        self.epsilon = self.gains.switch_epsilon;
    }

    /// One step toward `wp` (the last waypoint if `last`) at `pose` (its yaw wrapped or not):
    /// Algorithm 3, Algorithm 1 (or the end test), then u of eq. (13), ω clamped.
    pub fn step(
        &mut self,
        pose: &Pose2,
        wp: &VfoWaypoint,
        last: bool,
        obstacles: &[Obstacle],
        sigmas: &[Sigma],
    ) -> ControlStep {
        let aim = Aim {
            waypoint: wp,
            guide: guide(wp),
            last,
        };
        let mut nearby = Vec::new();
        measure(obstacles, Near::All, &pose.position(), &mut nearby);
        self.step_among(pose, pose.yaw.sin_cos(), &aim, obstacles, sigmas, &nearby)
    }

    /// [`VfoController::step`] from the obstacles [`measure`]d at the pose's position, with
    /// (sin, cos) of its yaw and the waypoint's guide given (a virtual robot keeps them from its
    /// integration and its segment).
    pub(crate) fn step_among(
        &mut self,
        pose: &Pose2,
        (sin_yaw, cos_yaw): (f64, f64),
        aim: &Aim<'_>,
        obstacles: &[Obstacle],
        sigmas: &[Sigma],
        nearby: &[Nearby],
    ) -> ControlStep {
        let (wp, last) = (aim.waypoint, aim.last);
        let g = self.gains;
        let theta = match self.theta {
            Some(prev) => prev + wrap(pose.yaw - prev),
            None => pose.yaw,
        };
        self.theta = Some(theta);
        let position = pose.position();
        let field = field_among(&position, wp, &aim.guide, g.k_p, obstacles, sigmas, nearby);
        let stop = |outcome, field: Field, epsilon, theta_a: f64| ControlStep {
            omega: 0.0,
            v: 0.0,
            e_a: theta_a - theta,
            theta_a,
            theta_a_rate: 0.0,
            field,
            epsilon,
            outcome,
        };
        let theta_a_prev = self.theta_a.unwrap_or(theta);
        if let Some(obstacle) = field.collision {
            return stop(StepOutcome::Collision { obstacle }, field, self.epsilon, theta_a_prev);
        }
        let e_norm = field.error.norm();
        if last {
            let heading_error = wrap(wp.heading - theta);
            if (heading_error * heading_error + e_norm * e_norm).sqrt() < g.final_epsilon {
                return stop(
                    StepOutcome::Reached { vortex: false },
                    field,
                    self.epsilon,
                    theta_a_prev,
                );
            }
        } else {
            // Algorithm 3: the repelling part dominates and the waypoint lies in some zone.
            let mut vortex = false;
            if field.h.norm_squared() < 0.01 * field.big_h.norm_squared()
                && obstacles
                    .iter()
                    .any(|o| o.distance(&wp.position) < o.influence_radius())
            {
                self.epsilon = 2.0 * e_norm;
                vortex = true;
            }
            // Algorithm 1.
            if e_norm < self.epsilon {
                return stop(StepOutcome::Reached { vortex }, field, self.epsilon, theta_a_prev);
            }
        }
        let hh = field.big_h.norm_squared();
        let norm_h = hh.sqrt();
        let theta_a = if hh > 0.0 {
            let raw = field.big_h.y.atan2(field.big_h.x);
            theta_a_prev + wrap(raw - theta_a_prev)
        } else {
            theta_a_prev
        };
        self.theta_a = Some(theta_a);
        let e_a = theta_a - theta;
        let speed = if last { g.speed.min(norm_h) } else { g.speed };
        // cos e_a = H*·[cos θ, sin θ]/‖H*‖ (θ_a is H*'s direction); θ and the pose's yaw differ
        // by whole turns only.
        let cos_e_a = if hh > 0.0 {
            (field.big_h.x * cos_yaw + field.big_h.y * sin_yaw) / norm_h
        } else {
            e_a.cos()
        };
        let v = speed * cos_e_a;
        let velocity = v * Vector2::new(cos_yaw, sin_yaw);
        let theta_a_rate = if hh > 0.0 {
            let h_dot = rate_among(&field, &velocity, wp, &aim.guide, g.k_p, obstacles, sigmas, nearby);
            (h_dot.y * field.big_h.x - h_dot.x * field.big_h.y) / hh
        } else {
            0.0
        };
        let omega = (g.k_a * e_a + theta_a_rate).clamp(-g.omega_max, g.omega_max);
        ControlStep {
            omega,
            v,
            e_a,
            theta_a,
            theta_a_rate,
            field,
            epsilon: self.epsilon,
            outcome: StepOutcome::Drive,
        }
    }
}
