//! Odometry: exact arc integration of wheel feedback into the pose q = [x, y, ϑ] (SPEC §1; 004 §4.1).
//!
//! The state is the pose of the kinematic origin in the odom frame; the published pose and twist
//! are those of the reference point `d` ahead ([`Odometry::reference_pose`],
//! [`Odometry::odom_from_base`]), MOBIL-II's lesson (004 §4.3.4).
//!
//! # Noise model
//!
//! Each step integrates a constant body twist over `dt`, giving a body-frame displacement
//! (Δx_b, Δy_b) of path length s = |(vx, vy)|·dt and a rotation Δϑ = ω·dt. The pose covariance
//! is propagated as P' = F·P·Fᵀ + Q(s, Δϑ) with F = ∂q'/∂q = [[1, 0, −Δy], [0, 1, Δx], [0, 0, 1]]
//! (Δx, Δy the world-frame displacement) and
//! Q = G·diag(k_s·s, k_c·s, k_ϑ·|Δϑ| + k_ϑs·s)·Gᵀ, G = Rot(ψ) ⊕ 1, where ψ is the direction of the
//! chord of the step: independent along-track, cross-track and heading errors whose variances
//! grow linearly with the distance travelled and the angle turned (a random walk per metre and per
//! radian). The coefficients are [`OdometryNoise`]. The twist covariance is a constant diagonal
//! ([`OdometryNoise::twist_variance`]).
//!
//! # Finite state, whatever arrives
//!
//! Every update is worked out on a copy first: one that would make the pose, the covariance or
//! their values at the reference point non-finite (a finite but absurd twist, e.g. 1e306 m/s,
//! overflows the covariance) is refused with [`OdometryError::NonFiniteResult`] and the state is
//! left as it was. Plausibility (what a chassis can physically do) is the caller's check.

use nalgebra::{Isometry2, Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{ChassisError, OdometryError};
use crate::kinematics::{pose_at_reference, twist_at_reference, BodyTwist};
use mobil_geom::wrap;

/// Below this |ω·dt| the arc uses its Taylor series (truncation error below 1e-27 relative).
const SERIES_THRESHOLD: f64 = 1e-4;

/// Odometry noise coefficients (see the module doc); all must be finite and non-negative.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OdometryNoise {
    /// k_s: along-track position variance per metre travelled (m²/m).
    pub along_track_var_per_m: f64,
    /// k_c: cross-track position variance per metre travelled (m²/m).
    pub cross_track_var_per_m: f64,
    /// k_ϑ: heading variance per radian turned (rad²/rad).
    pub heading_var_per_rad: f64,
    /// k_ϑs: heading variance per metre travelled (rad²/m) (wheel slip, track uncertainty).
    pub heading_var_per_m: f64,
    /// Variances of the measured twist (vx (m²/s²), vy (m²/s²), ω (rad²/s²)).
    pub twist_variance: [f64; 3],
}

impl Default for OdometryNoise {
    /// k_s = 1e-4 m²/m (1 cm σ after 1 m), k_c = 1e-5 m²/m, k_ϑ = 1e-3 rad²/rad (4.5° σ after a
    /// full turn), k_ϑs = 1e-4 rad²/m (1.8° σ after 10 m), twist variances 1e-3 each.
    fn default() -> Self {
        Self {
            along_track_var_per_m: 1e-4,
            cross_track_var_per_m: 1e-5,
            heading_var_per_rad: 1e-3,
            heading_var_per_m: 1e-4,
            twist_variance: [1e-3; 3],
        }
    }
}

impl OdometryNoise {
    /// Refuses a non-finite or negative coefficient.
    pub fn validate(&self) -> Result<(), ChassisError> {
        let fields = [
            ("along_track_var_per_m", self.along_track_var_per_m),
            ("cross_track_var_per_m", self.cross_track_var_per_m),
            ("heading_var_per_rad", self.heading_var_per_rad),
            ("heading_var_per_m", self.heading_var_per_m),
            ("twist_variance[0]", self.twist_variance[0]),
            ("twist_variance[1]", self.twist_variance[1]),
            ("twist_variance[2]", self.twist_variance[2]),
        ];
        for (name, value) in fields {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ChassisError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and non-negative",
                });
            }
        }
        Ok(())
    }
}

/// Body-frame displacement [Δx_b, Δy_b, Δϑ] of a constant twist held for `dt`, exact arc.
///
/// For ω ≠ 0: Δx_b = (vx·sin ωdt + vy·(cos ωdt − 1))/ω, Δy_b = (vx·(1 − cos ωdt) + vy·sin ωdt)/ω;
/// written as dt·(vx·S − vy·C), dt·(vx·C + vy·S) with S = sin a / a, C = (1 − cos a)/a, a = ω·dt,
/// and a Taylor series for small |a|, so ω → 0 is the straight line without division blow-up.
pub fn arc_displacement(twist: BodyTwist, dt: f64) -> Vector3<f64> {
    let a = twist.wz * dt;
    let (s, c) = if a.abs() < SERIES_THRESHOLD {
        let a2 = a * a;
        (
            1.0 - a2 / 6.0 * (1.0 - a2 / 20.0),
            a / 2.0 * (1.0 - a2 / 12.0 * (1.0 - a2 / 30.0)),
        )
    } else {
        let half = (0.5 * a).sin();
        (a.sin() / a, 2.0 * half * half / a)
    };
    Vector3::new(
        dt * (twist.vx * s - twist.vy * c),
        dt * (twist.vx * c + twist.vy * s),
        a,
    )
}

/// Pose `[x, y, ϑ]` after holding a body twist for `dt` from `pose` (exact arc, ϑ wrapped).
pub fn integrate_pose(pose: &Vector3<f64>, twist: BodyTwist, dt: f64) -> Vector3<f64> {
    let step = arc_displacement(twist, dt);
    let (sin, cos) = pose.z.sin_cos();
    Vector3::new(
        pose.x + cos * step.x - sin * step.y,
        pose.y + sin * step.x + cos * step.y,
        wrap(pose.z + step.z),
    )
}

/// Odometry integrator with pose and twist covariance; time is an input (`dt` or a stamp).
#[derive(Debug, Clone, PartialEq)]
pub struct Odometry {
    /// Pose [x, y, ϑ] of the kinematic origin in the odom frame.
    pose: Vector3<f64>,
    /// Covariance of `pose`.
    covariance: Matrix3<f64>,
    /// Last twist at the kinematic origin.
    twist: BodyTwist,
    /// Stamp of the last [`Odometry::update_at`].
    last_stamp: Option<f64>,
    reference_offset: f64,
    noise: OdometryNoise,
}

impl Odometry {
    /// Odometry with zero covariance whose published reference point (`base_link`) starts at
    /// the odom origin, as REP-105 expects (the kinematic origin then sits at (−d, 0));
    /// `reference_offset` is d (m) (finite).
    pub fn new(reference_offset: f64, noise: OdometryNoise) -> Result<Self, ChassisError> {
        check_offset(reference_offset)?;
        noise.validate()?;
        Ok(Self {
            pose: Vector3::new(-reference_offset, 0.0, 0.0),
            covariance: Matrix3::zeros(),
            twist: BodyTwist::ZERO,
            last_stamp: None,
            reference_offset,
            noise,
        })
    }

    /// Integrates a constant twist at the kinematic origin over `dt` (s).
    ///
    /// Refuses a non-finite or non-positive `dt` and a non-finite twist; the state is then
    /// unchanged. Does not touch the stamp used by [`Odometry::update_at`].
    pub fn update(&mut self, twist: BodyTwist, dt: f64) -> Result<(), OdometryError> {
        if !dt.is_finite() {
            return Err(OdometryError::NonFiniteDt(dt));
        }
        if dt <= 0.0 {
            return Err(OdometryError::NonPositiveDt(dt));
        }
        if !twist.is_finite() {
            return Err(OdometryError::NonFiniteTwist(twist));
        }
        self.integrate(twist, dt)
    }

    /// Integrates `twist`, measured at time `t` (s), over the interval since the previous stamp.
    ///
    /// The first call only records the stamp and the twist. Refuses a non-finite stamp, a stamp
    /// not after the previous one, and a non-finite twist; the state is then unchanged.
    pub fn update_at(&mut self, twist: BodyTwist, t: f64) -> Result<(), OdometryError> {
        if !t.is_finite() {
            return Err(OdometryError::NonFiniteTime(t));
        }
        if !twist.is_finite() {
            return Err(OdometryError::NonFiniteTwist(twist));
        }
        match self.last_stamp {
            None => self.twist = twist,
            Some(previous) if t <= previous => return Err(OdometryError::TimeNotIncreasing { previous, now: t }),
            Some(previous) => self.update(twist, t - previous)?,
        }
        self.last_stamp = Some(t);
        Ok(())
    }

    /// Integrates `twist`, held over (`from`, `to`] (s), whatever the previous stamp: the clock
    /// restarts at `from`. For a displacement known to cover that interval however long it is,
    /// e.g. the change of encoder angles between two samples.
    ///
    /// Refuses non-finite stamps, `to` not after `from` and a non-finite twist; the state is then
    /// unchanged. Afterwards the stamp is `to`.
    pub fn update_over(&mut self, twist: BodyTwist, from: f64, to: f64) -> Result<(), OdometryError> {
        for t in [from, to] {
            if !t.is_finite() {
                return Err(OdometryError::NonFiniteTime(t));
            }
        }
        if to <= from {
            return Err(OdometryError::TimeNotIncreasing {
                previous: from,
                now: to,
            });
        }
        self.update(twist, to - from)?;
        self.last_stamp = Some(to);
        Ok(())
    }

    fn integrate(&mut self, twist: BodyTwist, dt: f64) -> Result<(), OdometryError> {
        let step = arc_displacement(twist, dt);
        let (sin, cos) = self.pose.z.sin_cos();
        let dx = cos * step.x - sin * step.y;
        let dy = sin * step.x + cos * step.y;

        let f = Matrix3::new(1.0, 0.0, -dy, 0.0, 1.0, dx, 0.0, 0.0, 1.0);
        let distance = twist.vx.hypot(twist.vy) * dt;
        let chord = if step.x == 0.0 && step.y == 0.0 {
            self.pose.z
        } else {
            self.pose.z + step.y.atan2(step.x)
        };
        let (sp, cp) = chord.sin_cos();
        let g = Matrix3::new(cp, -sp, 0.0, sp, cp, 0.0, 0.0, 0.0, 1.0);
        let n = &self.noise;
        let q_step = Matrix3::from_diagonal(&Vector3::new(
            n.along_track_var_per_m * distance,
            n.cross_track_var_per_m * distance,
            n.heading_var_per_rad * step.z.abs() + n.heading_var_per_m * distance,
        ));
        let p = f * self.covariance * f.transpose() + g * q_step * g.transpose();
        let covariance = 0.5 * (p + p.transpose());
        let pose = Vector3::new(self.pose.x + dx, self.pose.y + dy, wrap(self.pose.z + step.z));
        if !state_is_finite(&pose, &covariance, self.reference_offset) {
            return Err(OdometryError::NonFiniteResult { twist, dt });
        }
        self.covariance = covariance;
        self.pose = pose;
        self.twist = twist;
        Ok(())
    }

    /// Forgets the previous stamp, keeping pose and covariance: the next [`Odometry::update_at`]
    /// only records its stamp. For a gap in the feedback, or a clock that jumped.
    pub fn restart_stamp(&mut self) {
        self.last_stamp = None;
    }

    /// Back to the start: reference point at the odom origin, zero covariance, zero twist, no stamp.
    pub fn reset(&mut self) {
        self.pose = Vector3::new(-self.reference_offset, 0.0, 0.0);
        self.covariance = Matrix3::zeros();
        self.twist = BodyTwist::ZERO;
        self.last_stamp = None;
    }

    /// Restarts at `pose_of_origin` [x, y, ϑ] (ϑ wrapped) with zero covariance, zero twist, no
    /// stamp; refuses a non-finite pose, leaving the state unchanged.
    pub fn reset_to(&mut self, pose_of_origin: Vector3<f64>) -> Result<(), OdometryError> {
        if !state_is_finite(&pose_of_origin, &Matrix3::zeros(), self.reference_offset) {
            return Err(OdometryError::NonFinitePose([
                pose_of_origin.x,
                pose_of_origin.y,
                pose_of_origin.z,
            ]));
        }
        self.pose = Vector3::new(pose_of_origin.x, pose_of_origin.y, wrap(pose_of_origin.z));
        self.covariance = Matrix3::zeros();
        self.twist = BodyTwist::ZERO;
        self.last_stamp = None;
        Ok(())
    }

    /// Changes d (m) (finite); the state, kept at the origin, is unaffected.
    pub fn set_reference_offset(&mut self, reference_offset: f64) -> Result<(), ChassisError> {
        check_offset(reference_offset)?;
        self.reference_offset = reference_offset;
        Ok(())
    }

    /// Changes the noise coefficients for later steps.
    pub fn set_noise(&mut self, noise: OdometryNoise) -> Result<(), ChassisError> {
        noise.validate()?;
        self.noise = noise;
        Ok(())
    }

    /// Reference offset d (m).
    pub fn reference_offset(&self) -> f64 {
        self.reference_offset
    }

    /// Noise coefficients.
    pub fn noise(&self) -> &OdometryNoise {
        &self.noise
    }

    /// Stamp of the last accepted [`Odometry::update_at`].
    pub fn last_stamp(&self) -> Option<f64> {
        self.last_stamp
    }

    /// Pose [x, y, ϑ] of the kinematic origin, ϑ in (−π, π].
    pub fn pose(&self) -> Vector3<f64> {
        self.pose
    }

    /// Covariance of [`Odometry::pose`] (order x, y, ϑ).
    pub fn covariance(&self) -> Matrix3<f64> {
        self.covariance
    }

    /// Last twist at the kinematic origin.
    pub fn twist(&self) -> BodyTwist {
        self.twist
    }

    /// Covariance of the twist (order vx, vy, ω) at the kinematic origin.
    pub fn twist_covariance(&self) -> Matrix3<f64> {
        Matrix3::from_diagonal(&Vector3::from(self.noise.twist_variance))
    }

    /// Pose [x, y, ϑ] of the reference point: origin pose moved by Rot(ϑ)·[d, 0].
    pub fn reference_pose(&self) -> Vector3<f64> {
        pose_at_reference(&self.pose, self.reference_offset)
    }

    /// Covariance of [`Odometry::reference_pose`]: J·P·Jᵀ, J = ∂(reference pose)/∂(origin pose).
    pub fn reference_covariance(&self) -> Matrix3<f64> {
        let d = self.reference_offset;
        let (sin, cos) = self.pose.z.sin_cos();
        let j = Matrix3::new(1.0, 0.0, -d * sin, 0.0, 1.0, d * cos, 0.0, 0.0, 1.0);
        j * self.covariance * j.transpose()
    }

    /// Twist of the reference point (body frame): vy += ω·d.
    pub fn reference_twist(&self) -> BodyTwist {
        twist_at_reference(self.twist, self.reference_offset)
    }

    /// Covariance of [`Odometry::reference_twist`].
    pub fn reference_twist_covariance(&self) -> Matrix3<f64> {
        let j = Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, self.reference_offset, 0.0, 0.0, 1.0);
        j * self.twist_covariance() * j.transpose()
    }

    /// `odom_from_base`: the reference point (published `base_link`) in the odom frame.
    pub fn odom_from_base(&self) -> Isometry2<f64> {
        let p = self.reference_pose();
        Isometry2::new(Vector2::new(p.x, p.y), p.z)
    }

    /// `odom_from_origin`: the kinematic origin in the odom frame.
    pub fn odom_from_origin(&self) -> Isometry2<f64> {
        Isometry2::new(Vector2::new(self.pose.x, self.pose.y), self.pose.z)
    }
}

/// True if the pose, its covariance and both at the reference point `d` ahead are all finite.
fn state_is_finite(pose: &Vector3<f64>, covariance: &Matrix3<f64>, d: f64) -> bool {
    if !(pose.iter().all(|v| v.is_finite()) && covariance.iter().all(|v| v.is_finite())) {
        return false;
    }
    // As reference_pose and reference_covariance work them out.
    let (sin, cos) = pose.z.sin_cos();
    let reference = [pose.x + d * cos, pose.y + d * sin];
    let j = Matrix3::new(1.0, 0.0, -d * sin, 0.0, 1.0, d * cos, 0.0, 0.0, 1.0);
    let reference_covariance = j * covariance * j.transpose();
    reference
        .iter()
        .chain(reference_covariance.iter())
        .all(|v| v.is_finite())
}

fn check_offset(reference_offset: f64) -> Result<(), ChassisError> {
    if reference_offset.is_finite() {
        Ok(())
    } else {
        Err(ChassisError::InvalidParameter {
            name: "reference_offset",
            value: reference_offset,
            reason: "must be finite",
        })
    }
}
