//! The LOW-LEVEL chassis controller, ROS-free: commands in, wheel commands out; wheel feedback
//! in, odometry out; timeouts on both streams. Time is always an input (the inputs' ages on the
//! node's steady clock, as its freshness holders measure them, for the timeouts; message stamps
//! for feedback), so tests and replays are deterministic.
//!
//! Command path: a body twist at the reference point (`cmd_vel` in `base_link`) → the twist at
//! the kinematic origin → [`clamp_command`] → [`inverse`] kinematics → the request. A
//! non-holonomic chassis takes `linear.x` and `angular.z`; the sideways velocity its reference
//! point has when turning (ω·d) is implied, and any *requested* `linear.y` is dropped (logged as
//! lateral).
//!
//! **One safety gate**: wheel commands come only out of [`ChassisController::gate`] (which
//! [`ChassisController::on_cmd_vel`] and [`ChassisController::stop`] also end in), as a
//! [`GatedCommand`] that nothing else can build. It passes the request only while a valid
//! `cmd_vel` arrived within `cmd_vel_timeout_s`, valid wheel feedback within
//! `feedback_timeout_s` (else the odometry is stale), the last `cmd_vel` was finite and the
//! wheel values are finite; otherwise it stops. A stop sets every driven wheel to zero and
//! **holds the steering angles last sent** (straight before any command): a safety stop starts
//! no new motion, and steering a standing car-like chassis only scrubs its tyres. A requested
//! zero twist is a command, not a stop: it straightens the wheels as the kinematics say.
//!
//! Feedback: a sample is refused if a wheel turns faster than the chassis physically can
//! (`max_feedback_wheel_speed_factor` × `max_wheel_speed`) or a steering angle is beyond ±90°;
//! the odometry itself refuses any update that would make it non-finite. Wheel speeds are
//! integrated over the interval since the previous sample; a gap longer than the feedback
//! timeout (a dropout, or a stamp far in the future) is not integrated across — the odometry
//! restarts its clock there and reports it; a stamp more than that far in the past is taken as
//! a clock reset (a restarted simulation) and handled the same way. A stamp slightly in the past
//! (an out-of-order sample) is refused. So one bad stamp costs one sample, never the odometry.
//! Encoder angles are different: their change over a gap is a distance really travelled, so it
//! is integrated however long the gap — unless the encoder wraps and the gap is long enough for
//! a wheel at the fastest believed speed to turn π (see [`crate::joints::FeedbackDecoder`]), when
//! the change is ambiguous. They are differenced from the last sample the controller accepted
//! ([`ChassisController::on_joint_state`]), so a refused or late sample neither loses distance nor
//! counts it twice.

use std::f64::consts::{FRAC_PI_2, PI};
use std::ops::Deref;

use crate::error::{ChassisError, OdometryError};
use crate::joints::{FeedbackDecoder, FeedbackSample, JointStateError};
use crate::kinematics::{
    forward, inverse, pre_steer, twist_at_origin, twist_at_reference, BodyTwist, JointKind, WheelState,
};
use crate::limits::{clamp_command, ClampReason, ClampReasons};
use crate::model::ChassisModel;
use crate::model::ChassisParams;
use crate::odometry::{Odometry, OdometryNoise};
use crate::watchdog::InputTimeout;

/// Default of [`ChassisController::feedback_speed_factor`]: feedback wheel speeds up to 3 ×
/// `max_wheel_speed` are believed (a wheel spinning free or pushed downhill can exceed the
/// command limit; an encoder glitch reads orders of magnitude more).
pub const DEFAULT_FEEDBACK_SPEED_FACTOR: f64 = 3.0;

/// Settings of the controller beyond the chassis geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControllerConfig {
    /// Geometry and limits.
    pub params: ChassisParams,
    /// Zero command after this long without a valid `cmd_vel` (s); 0 disables.
    pub cmd_vel_timeout_s: f64,
    /// Zero command after this long without valid wheel feedback (s); 0 disables.
    pub feedback_timeout_s: f64,
    /// Odometry covariance model.
    pub noise: OdometryNoise,
}

/// How long ago (s, steady clock) each input last arrived valid, as the node's freshness holders
/// measure it: what the gate's timeouts decide on. `None`: never, or not since the node forgot it
/// (a refused `cmd_vel` is not a valid one).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InputAges {
    /// Age of the last valid `cmd_vel`.
    pub cmd_vel_s: Option<f64>,
    /// Age of the last feedback sample the controller used.
    pub feedback_s: Option<f64>,
}

/// Wheel targets with the twist they give and what the limits changed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// Joint targets.
    pub wheels: WheelState,
    /// The feasible twist at the reference point.
    pub twist: BodyTwist,
    /// What the limits changed in the last request.
    pub reasons: ClampReasons,
}

impl Command {
    fn stop(params: &ChassisParams) -> Self {
        Command {
            wheels: WheelState::zero(params.model()),
            twist: BodyTwist::ZERO,
            reasons: ClampReasons::NONE,
        }
    }
}

/// A command that went through [`ChassisController::gate`], the only thing to send to the
/// wheels; it reads as a [`Command`] and says why it may be a stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GatedCommand {
    command: Command,
    safety: Safety,
}

impl GatedCommand {
    /// The watchdogs' state when the command was gated.
    pub fn safety(&self) -> Safety {
        self.safety
    }
}

impl Deref for GatedCommand {
    type Target = Command;

    fn deref(&self) -> &Command {
        &self.command
    }
}

/// The state of the watchdogs when a command was gated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Safety {
    /// No valid `cmd_vel` within the timeout (a non-finite one does not count as valid).
    pub cmd_vel_expired: bool,
    /// The last `cmd_vel` was non-finite: the chassis stopped for that, not for a timeout.
    pub cmd_vel_refused: bool,
    /// No valid wheel feedback within the timeout.
    pub feedback_stale: bool,
}

impl Safety {
    /// True if `cmd_vel` stopped arriving (the timeout, not a refused `cmd_vel`).
    pub fn cmd_vel_timed_out(&self) -> bool {
        self.cmd_vel_expired && !self.cmd_vel_refused
    }

    /// True if the gate stops the wheels for a watchdog or a refused `cmd_vel`.
    pub fn stops(&self) -> bool {
        self.cmd_vel_expired || self.cmd_vel_refused || self.feedback_stale
    }
}

/// Why a feedback sample was not used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FeedbackError {
    /// The joint values do not fit the chassis.
    #[error(transparent)]
    Kinematics(#[from] ChassisError),
    /// The stamp or twist was refused by the odometry.
    #[error(transparent)]
    Odometry(#[from] OdometryError),
    /// The `joint_states` message could not be read, or its stamp was refused.
    #[error(transparent)]
    Joints(#[from] JointStateError),
    /// A joint value the chassis cannot physically reach.
    #[error("joint `{joint}` at {value} is beyond what the chassis can do (limit ±{limit})")]
    Implausible {
        /// The joint.
        joint: &'static str,
        /// Its value (rad/s for a wheel, rad for a steering angle).
        value: f64,
        /// The limit it exceeds.
        limit: f64,
    },
}

/// Command limits, watchdogs and odometry of one chassis.
#[derive(Debug, Clone)]
pub struct ChassisController {
    config: ControllerConfig,
    feedback_speed_factor: f64,
    cmd_timeout: InputTimeout,
    feedback_timeout: InputTimeout,
    odometry: Odometry,
    requested: Command,
    /// The last finite `cmd_vel` (at the reference point), re-clamped when the limits change;
    /// `None` before the first, after a non-finite one and after [`ChassisController::stop`].
    request: Option<BodyTwist>,
    /// The last `cmd_vel` was non-finite.
    refused: bool,
    /// The wheels last let through the gate (their steering angles are held by a stop).
    sent: WheelState,
    /// Turns `joint_states` into samples; its baseline moves only with an accepted sample.
    decoder: FeedbackDecoder,
}

/// What happened to a feedback sample that was used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FeedbackOutcome {
    /// Integrated over the interval since the previous sample.
    Integrated,
    /// The first sample, or one after a gap or clock jump of this many seconds (negative: the
    /// clock went back): its stamp starts a new interval, nothing was integrated.
    Restarted {
        /// The jump since the previous sample, `None` for the first sample.
        gap_s: Option<f64>,
    },
    /// Encoder angles spanning a gap longer than the feedback timeout: the distance they give
    /// was integrated across it.
    Bridged {
        /// The gap (s).
        gap_s: f64,
    },
    /// Wrapped encoder angles over a gap in which a wheel could turn π or more: the change is
    /// ambiguous (modulo 2π), so it was not integrated and the clock restarts here.
    Ambiguous {
        /// The gap (s).
        gap_s: f64,
    },
}

impl ChassisController {
    /// A controller at the odometry origin, stopped until the first command.
    pub fn new(config: ControllerConfig) -> Result<Self, ChassisError> {
        Ok(ChassisController {
            cmd_timeout: InputTimeout::new("cmd_vel_timeout_s", config.cmd_vel_timeout_s)?,
            feedback_timeout: InputTimeout::new("feedback_timeout_s", config.feedback_timeout_s)?,
            odometry: Odometry::new(config.params.reference_offset(), config.noise)?,
            requested: Command::stop(&config.params),
            request: None,
            refused: false,
            sent: WheelState::zero(config.params.model()),
            decoder: FeedbackDecoder::default(),
            feedback_speed_factor: DEFAULT_FEEDBACK_SPEED_FACTOR,
            config,
        })
    }

    /// Applies new settings (same model), keeping the odometry pose (the inputs' history is the
    /// node's).
    pub fn reconfigure(&mut self, config: ControllerConfig) -> Result<(), ChassisError> {
        if config.params.model() != self.config.params.model() {
            return Err(ChassisError::ModelMismatch {
                expected: self.config.params.model(),
                got: config.params.model(),
            });
        }
        let cmd = InputTimeout::new("cmd_vel_timeout_s", config.cmd_vel_timeout_s)?;
        let fb = InputTimeout::new("feedback_timeout_s", config.feedback_timeout_s)?;
        self.odometry.set_reference_offset(config.params.reference_offset())?;
        self.odometry.set_noise(config.noise)?;
        self.cmd_timeout = cmd;
        self.feedback_timeout = fb;
        self.config = config;
        // The running command was worked out under the old limits: work it out again.
        if let Some(request) = self.request {
            self.requested = self.command_for(request);
        }
        Ok(())
    }

    /// The settings in force.
    pub fn config(&self) -> &ControllerConfig {
        &self.config
    }

    /// Sets k: wheel feedback faster than k × `max_wheel_speed` is refused as impossible
    /// (default [`DEFAULT_FEEDBACK_SPEED_FACTOR`]); k must be finite and at least 1.
    pub fn set_feedback_speed_factor(&mut self, factor: f64) -> Result<(), ChassisError> {
        Self::check_feedback_speed_factor(factor)?;
        self.feedback_speed_factor = factor;
        Ok(())
    }

    /// The error [`ChassisController::set_feedback_speed_factor`] would give for `factor`, if any:
    /// to vet it before applying anything else.
    pub fn check_feedback_speed_factor(factor: f64) -> Result<(), ChassisError> {
        if !(factor.is_finite() && factor >= 1.0) {
            return Err(ChassisError::InvalidParameter {
                name: "max_feedback_wheel_speed_factor",
                value: factor,
                reason: "must be finite and at least 1",
            });
        }
        Ok(())
    }

    /// Takes position-only wheel feedback as wrapped angles (`true`) or a continuous count
    /// (`false`, the default). A change forgets the previous position sample.
    pub fn set_encoder_positions_wrap(&mut self, wraps: bool) {
        if wraps != self.decoder.wraps() {
            self.decoder = FeedbackDecoder::new(wraps);
        }
    }

    /// True if position-only wheel feedback is taken as wrapped angles.
    pub fn encoder_positions_wrap(&self) -> bool {
        self.decoder.wraps()
    }

    /// k of [`ChassisController::set_feedback_speed_factor`].
    pub fn feedback_speed_factor(&self) -> f64 {
        self.feedback_speed_factor
    }

    /// The fastest wheel feedback believed (rad/s): k × `max_wheel_speed`.
    pub fn max_feedback_wheel_speed(&self) -> f64 {
        self.feedback_speed_factor * self.config.params.max_wheel_speed()
    }

    /// A `cmd_vel` (twist of the reference point, body frame): becomes the request. Returns
    /// whether it is valid: `true`, the node records its arrival (its age is then 0); `false` (a
    /// non-finite request), the node forgets the last arrival (age `None`) and the next
    /// [`ChassisController::gate`] stops the chassis, reported as refused, not timed out.
    #[must_use = "the node records a valid cmd_vel and forgets the last one on a refused one"]
    pub fn on_cmd_vel(&mut self, requested_at_reference: BodyTwist) -> bool {
        self.requested = self.command_for(requested_at_reference);
        if self.requested.reasons.contains(ClampReason::NonFinite) {
            self.request = None;
            self.refused = true;
            false
        } else {
            self.request = Some(requested_at_reference);
            self.refused = false;
            true
        }
    }

    /// A `cmd_vel` that could not be decoded: the sender meant to command something the chassis
    /// cannot know, so it is refused like a non-finite one (always returns `false`).
    #[must_use = "the node forgets the last cmd_vel on a refused one"]
    pub fn on_unreadable_cmd_vel(&mut self) -> bool {
        self.on_cmd_vel(BodyTwist::new(f64::NAN, f64::NAN, f64::NAN))
    }

    /// The last `cmd_vel` after the limits, as requested (for logs); what reaches the wheels is
    /// [`ChassisController::gate`]'s.
    pub fn requested(&self) -> &Command {
        &self.requested
    }

    /// Forgets the request (at shutdown) and returns the stop the gate then gives (as if no
    /// `cmd_vel` had ever arrived; `ages.cmd_vel_s` is not used).
    pub fn stop(&mut self, ages: InputAges) -> GatedCommand {
        self.request = None;
        self.requested.twist = BodyTwist::ZERO;
        self.gate(InputAges {
            cmd_vel_s: None,
            ..ages
        })
    }

    /// The feasible command for a request (limits, then inverse kinematics).
    fn command_for(&self, requested_at_reference: BodyTwist) -> Command {
        let params = &self.config.params;
        let d = params.reference_offset();
        let mut lateral = false;
        let at_origin = if !requested_at_reference.is_finite() {
            requested_at_reference
        } else if params.model().is_nonholonomic() {
            lateral = requested_at_reference.vy.abs() > 1e-9;
            BodyTwist::new(requested_at_reference.vx, 0.0, requested_at_reference.wz)
        } else {
            twist_at_origin(requested_at_reference, d)
        };
        let clamped = clamp_command(params, at_origin);
        let mut reasons = clamped.reasons;
        if lateral {
            reasons.insert(ClampReason::Lateral);
        }
        let wheels = match clamped.pre_steer {
            Some(delta) => pre_steer(params, delta),
            None => inverse(params, clamped.twist),
        };
        let twist = if params.model().is_nonholonomic() {
            // Report what the user commands: speed and turn rate (the implied ω·d is not a request).
            BodyTwist::new(clamped.twist.vx, 0.0, clamped.twist.wz)
        } else {
            twist_at_reference(clamped.twist, d)
        };
        Command { wheels, twist, reasons }
    }

    /// The safety gate: the command to send now, for the inputs' ages now. The request, or a stop
    /// (driven wheels zero, steering held as last sent) when the cmd_vel timeout has expired, the
    /// feedback is
    /// stale, the last `cmd_vel` was non-finite, there is no request, or the request's wheel
    /// values are not finite. `reasons` keeps describing the last `cmd_vel`
    /// (`ChassisStatus.clamped`), e.g. a NaN.
    pub fn gate(&mut self, ages: InputAges) -> GatedCommand {
        let safety = Safety {
            cmd_vel_expired: self.cmd_timeout.expired(ages.cmd_vel_s),
            cmd_vel_refused: self.refused,
            feedback_stale: self.feedback_timeout.expired(ages.feedback_s),
        };
        let mut command = self.requested;
        if safety.stops() || self.request.is_none() || !command.wheels.is_finite() || !command.twist.is_finite() {
            if !(command.wheels.is_finite() && command.twist.is_finite()) {
                command.reasons.insert(ClampReason::NonFinite);
            }
            command.wheels = self.sent.stopped();
            command.twist = BodyTwist::ZERO;
        }
        self.sent = command.wheels;
        GatedCommand { command, safety }
    }

    /// Refuses joint values the chassis cannot physically reach: a wheel faster than
    /// [`ChassisController::max_feedback_wheel_speed`], a steering angle beyond ±90°.
    fn check_plausible(&self, wheels: &WheelState) -> Result<(), FeedbackError> {
        let max_speed = self.max_feedback_wheel_speed();
        let joints = self.config.params.model().joints();
        for (joint, value) in joints.iter().zip(wheels.values()) {
            let limit = match joint.kind {
                JointKind::Wheel => max_speed,
                JointKind::Steering => FRAC_PI_2,
            };
            if value.is_nan() || value.abs() > limit {
                return Err(FeedbackError::Implausible {
                    joint: joint.name,
                    value,
                    limit,
                });
            }
        }
        Ok(())
    }

    /// The longest gap (s) integrated across for wheel-speed feedback.
    fn max_gap(&self) -> f64 {
        if self.config.feedback_timeout_s > 0.0 {
            self.config.feedback_timeout_s
        } else {
            1.0
        }
    }

    /// Wheel speeds measured at `stamp` (s). Refused samples leave the odometry unchanged; on
    /// `Ok` the node records the arrival (the feedback's age for [`ChassisController::gate`]).
    pub fn on_feedback(&mut self, wheels: &WheelState, stamp: f64) -> Result<FeedbackOutcome, FeedbackError> {
        let twist = forward(&self.config.params, wheels)?;
        self.check_plausible(wheels)?;
        let max_gap = self.max_gap();
        let gap = self.odometry.last_stamp().map(|previous| stamp - previous);
        let restart = match gap {
            None => true,
            Some(dt) if !dt.is_finite() => false, // refused by update_at below
            Some(dt) => dt > max_gap || dt < -max_gap,
        };
        if restart {
            // On a copy: a refused sample must not restart the clock.
            let mut odometry = self.odometry.clone();
            odometry.restart_stamp();
            odometry.update_at(twist, stamp)?;
            self.odometry = odometry;
        } else {
            self.odometry.update_at(twist, stamp)?;
        }
        Ok(if restart {
            FeedbackOutcome::Restarted { gap_s: gap }
        } else {
            FeedbackOutcome::Integrated
        })
    }

    /// The arrays of a `joint_states` message stamped `stamp` (s), decoded (see
    /// [`FeedbackDecoder`]) and fed to [`ChassisController::on_feedback_sample`]. `Ok(None)`: a
    /// position-only sample that only set the baseline (not yet feedback: the node does not record
    /// it as an arrival). A refused sample leaves the odometry and the encoder baseline as they were,
    /// so the distance to the next good sample is not lost.
    pub fn on_joint_state(
        &mut self,
        names: &[String],
        positions: &[f64],
        velocities: &[f64],
        stamp: f64,
    ) -> Result<Option<FeedbackOutcome>, FeedbackError> {
        let model: ChassisModel = self.config.params.model();
        let decoded = self
            .decoder
            .decode(model, names, positions, velocities, stamp, self.max_gap())?;
        let outcome = match decoded.sample() {
            Some(sample) => Some(self.on_feedback_sample(sample)?),
            None => None,
        };
        self.decoder.commit(decoded);
        Ok(outcome)
    }

    /// A decoded feedback sample (see [`FeedbackSample`]). Refused samples leave the odometry
    /// unchanged; on `Ok` the node records the arrival.
    ///
    /// Measured speeds go through [`ChassisController::on_feedback`]. Travelled samples (encoder
    /// angles) are integrated over their own interval however long: the clock restarts at its
    /// start if needed (first sample, clock reset). One that starts before the odometry's last
    /// stamp, but less than the feedback timeout before it, overlaps what was integrated and is
    /// refused. A wrapped one whose interval is long enough for a wheel at the fastest believed
    /// speed ([`ChassisController::max_feedback_wheel_speed`]) to turn π is ambiguous and only
    /// restarts the clock, with a zero twist.
    pub fn on_feedback_sample(&mut self, sample: &FeedbackSample) -> Result<FeedbackOutcome, FeedbackError> {
        let (wheels, since, stamp, wrapped) = match *sample {
            FeedbackSample::Measured { ref wheels, stamp } => return self.on_feedback(wheels, stamp),
            FeedbackSample::Travelled {
                wheels,
                since,
                stamp,
                wrapped,
            } => (wheels, since, stamp, wrapped),
        };
        let twist = forward(&self.config.params, &wheels)?;
        self.check_plausible(&wheels)?;
        if let Some(last) = self.odometry.last_stamp()
            && since < last
            && since >= last - self.max_gap()
        {
            return Err(OdometryError::TimeNotIncreasing {
                previous: last,
                now: since,
            }
            .into());
        }
        let gap = stamp - since;
        let outcome = if wrapped && gap * self.max_feedback_wheel_speed() >= PI {
            // The mean speed over the gap is aliased: no twist is known.
            let mut odometry = self.odometry.clone();
            odometry.restart_stamp();
            odometry.update_at(BodyTwist::ZERO, stamp)?;
            self.odometry = odometry;
            FeedbackOutcome::Ambiguous { gap_s: gap }
        } else {
            self.odometry.update_over(twist, since, stamp)?;
            if gap > self.max_gap() {
                FeedbackOutcome::Bridged { gap_s: gap }
            } else {
                FeedbackOutcome::Integrated
            }
        };
        Ok(outcome)
    }

    /// The odometry (pose, twist and covariances; see [`Odometry::reference_pose`]).
    pub fn odometry(&self) -> &Odometry {
        &self.odometry
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{ChassisConfig, ChassisModel};
    use approx::assert_relative_eq;
    use mobil_geom::wrap;

    /// The controller as the node drives it: the rig records when each input last arrived valid
    /// (seconds, a stand-in for the node's steady-clock holders) and gates with those ages.
    struct Rig {
        c: ChassisController,
        cmd_at: Option<f64>,
        fb_at: Option<f64>,
    }

    impl Deref for Rig {
        type Target = ChassisController;
        fn deref(&self) -> &ChassisController {
            &self.c
        }
    }

    impl std::ops::DerefMut for Rig {
        fn deref_mut(&mut self) -> &mut ChassisController {
            &mut self.c
        }
    }

    impl Rig {
        fn ages(&self, now: f64) -> InputAges {
            InputAges {
                cmd_vel_s: self.cmd_at.map(|t| now - t),
                feedback_s: self.fb_at.map(|t| now - t),
            }
        }
        fn on_cmd_vel(&mut self, request: BodyTwist, now: f64) -> GatedCommand {
            self.cmd_at = self.c.on_cmd_vel(request).then_some(now);
            self.gate(now)
        }
        fn on_unreadable_cmd_vel(&mut self, now: f64) -> GatedCommand {
            self.cmd_at = self.c.on_unreadable_cmd_vel().then_some(now);
            self.gate(now)
        }
        fn gate(&mut self, now: f64) -> GatedCommand {
            let ages = self.ages(now);
            self.c.gate(ages)
        }
        fn stop(&mut self, now: f64) -> GatedCommand {
            self.cmd_at = None;
            let ages = self.ages(now);
            self.c.stop(ages)
        }
        fn on_feedback(&mut self, wheels: &WheelState, stamp: f64, now: f64) -> Result<FeedbackOutcome, FeedbackError> {
            let r = self.c.on_feedback(wheels, stamp);
            if r.is_ok() {
                self.fb_at = Some(now);
            }
            r
        }
        fn on_joint_state(
            &mut self,
            names: &[String],
            positions: &[f64],
            velocities: &[f64],
            stamp: f64,
            now: f64,
        ) -> Result<Option<FeedbackOutcome>, FeedbackError> {
            let r = self.c.on_joint_state(names, positions, velocities, stamp);
            if let Ok(Some(_)) = r {
                self.fb_at = Some(now);
            }
            r
        }
    }

    fn controller(config: ChassisConfig) -> Rig {
        let c = ChassisController::new(ControllerConfig {
            params: ChassisParams::new(config).unwrap(),
            cmd_vel_timeout_s: 0.5,
            feedback_timeout_s: 0.5,
            noise: OdometryNoise::default(),
        })
        .unwrap();
        Rig {
            c,
            cmd_at: None,
            fb_at: None,
        }
    }

    fn feed_feedback(c: &mut Rig, t: f64) {
        let zero = WheelState::zero(c.config().params.model());
        c.on_feedback(&zero, t, t).unwrap();
    }

    #[test]
    fn watchdog_zeroes_after_timeout_and_nan_stops_at_once() {
        let mut c = controller(ChassisConfig::omr3());
        feed_feedback(&mut c, 0.0);
        let cmd = c.on_cmd_vel(BodyTwist::new(0.3, 0.0, 0.0), 0.0);
        // Pure body-x translation at 0.3 m/s with r = 0.05: Ω = 6·[1, −½, −½] (SPEC §1).
        for (got, want) in cmd.wheels.values().iter().zip([6.0, -3.0, -3.0]) {
            assert_relative_eq!(*got, want, epsilon = 1e-12);
        }
        feed_feedback(&mut c, 0.4);
        assert_eq!(c.gate(0.4).wheels, cmd.wheels);
        feed_feedback(&mut c, 0.6);
        let stopped = c.gate(0.6);
        let safety = stopped.safety();
        assert!(safety.cmd_vel_expired && safety.cmd_vel_timed_out() && !safety.feedback_stale);
        assert_eq!(stopped.wheels, WheelState::Omni { wheels: [0.0; 3] });

        c.on_cmd_vel(BodyTwist::new(0.3, 0.0, 0.0), 0.7);
        let nan = c.on_cmd_vel(BodyTwist::new(f64::NAN, 0.0, 0.0), 0.71);
        assert_eq!(nan.wheels, WheelState::Omni { wheels: [0.0; 3] });
        assert!(nan.reasons.contains(ClampReason::NonFinite));
        let after = c.gate(0.72).safety();
        assert!(after.cmd_vel_expired, "a NaN does not keep the watchdog alive");
        assert!(
            after.cmd_vel_refused && !after.cmd_vel_timed_out(),
            "the stop is for the NaN, not a timeout"
        );
    }

    #[test]
    fn stale_feedback_stops_the_wheels() {
        let mut c = controller(ChassisConfig::omr3());
        feed_feedback(&mut c, 0.0);
        let cmd = c.on_cmd_vel(BodyTwist::new(0.3, 0.0, 0.0), 0.55);
        let safety = cmd.safety();
        assert!(safety.feedback_stale && !safety.cmd_vel_expired);
        assert_eq!(cmd.wheels, WheelState::Omni { wheels: [0.0; 3] });
    }

    #[test]
    fn car_like_drops_requested_lateral_but_not_the_implied_one() {
        let mut config = ChassisConfig::mobil2();
        config.reference_offset = 0.3;
        let mut c = controller(config);
        feed_feedback(&mut c, 0.0);
        // v = 0.4, ω = 0.2: radius 2 m ≥ 0.73 m, feasible; no lateral request.
        let cmd = c.on_cmd_vel(BodyTwist::new(0.4, 0.0, 0.2), 0.0);
        assert!(cmd.reasons.is_empty(), "{:?}", cmd.reasons);
        assert_relative_eq!(cmd.twist.wz, 0.2, epsilon = 1e-12);
        // Rear wheels: (v ∓ B·ω/2)/r = (0.4 ∓ 0.062)/0.1.
        match cmd.wheels {
            WheelState::CarLike {
                rear_left, rear_right, ..
            } => {
                assert_relative_eq!(rear_left, 3.38, epsilon = 1e-12);
                assert_relative_eq!(rear_right, 4.62, epsilon = 1e-12);
            }
            other => panic!("{other:?}"),
        }
        let lateral = c.on_cmd_vel(BodyTwist::new(0.4, 0.1, 0.0), 0.1);
        assert!(lateral.reasons.contains(ClampReason::Lateral));
        assert_eq!(lateral.twist.vy, 0.0);
    }

    #[test]
    fn omni_command_at_an_offset_reference_point() {
        let mut config = ChassisConfig::omr3();
        config.reference_offset = 0.1;
        let mut c = controller(config);
        feed_feedback(&mut c, 0.0);
        // Pure rotation about the reference point 0.1 m ahead: the centre moves sideways at
        // vy = −ω·d = −0.1 m/s, so each wheel gets r·ω_i = sin θ_i·(−0.1) + R·ω.
        let cmd = c.on_cmd_vel(BodyTwist::new(0.0, 0.0, 1.0), 0.0);
        let s = 3f64.sqrt() / 2.0;
        match cmd.wheels {
            WheelState::Omni { wheels } => {
                assert_relative_eq!(wheels[0], 0.2 / 0.05, epsilon = 1e-12);
                assert_relative_eq!(wheels[1], (-0.1 * s + 0.2) / 0.05, epsilon = 1e-12);
                assert_relative_eq!(wheels[2], (0.1 * s + 0.2) / 0.05, epsilon = 1e-12);
            }
            other => panic!("{other:?}"),
        }
        assert_relative_eq!(cmd.twist.vy, 0.0, epsilon = 1e-12);
    }

    #[test]
    fn a_future_stamp_or_a_clock_reset_costs_one_sample_not_the_odometry() {
        let mut c = controller(ChassisConfig::omr3());
        let forward = WheelState::Omni {
            wheels: [6.0, -3.0, -3.0],
        }; // 0.3 m/s along x
        c.on_feedback(&forward, 10.0, 10.0).unwrap();
        assert_eq!(
            c.on_feedback(&forward, 10.1, 10.1).unwrap(),
            FeedbackOutcome::Integrated
        );
        // A stamp 1e6 s ahead: not integrated across (it would be 300 km).
        let jump = c.on_feedback(&forward, 1e6, 10.2).unwrap();
        assert_eq!(
            jump,
            FeedbackOutcome::Restarted {
                gap_s: Some(1e6 - 10.1)
            }
        );
        assert_relative_eq!(c.odometry().reference_pose().x, 0.03, epsilon = 1e-12);
        // Back to the real clock: a jump back, restarted again, then normal integration.
        assert!(matches!(
            c.on_feedback(&forward, 10.3, 10.3).unwrap(),
            FeedbackOutcome::Restarted { .. }
        ));
        assert_eq!(
            c.on_feedback(&forward, 10.4, 10.4).unwrap(),
            FeedbackOutcome::Integrated
        );
        assert_relative_eq!(c.odometry().reference_pose().x, 0.06, epsilon = 1e-12);
        // A 0.6 s dropout (> the 0.5 s feedback timeout) is not integrated either.
        assert!(matches!(
            c.on_feedback(&forward, 11.0, 11.0).unwrap(),
            FeedbackOutcome::Restarted { .. }
        ));
        assert_relative_eq!(c.odometry().reference_pose().x, 0.06, epsilon = 1e-12);
        // A sample slightly out of order is refused.
        assert!(c.on_feedback(&forward, 10.95, 11.0).is_err());
    }

    #[test]
    fn a_new_limit_applies_to_the_command_already_running() {
        let mut c = controller(ChassisConfig::omr3());
        feed_feedback(&mut c, 0.0);
        c.on_cmd_vel(BodyTwist::new(0.5, 0.0, 0.0), 0.0);
        let mut config = *c.config();
        let mut slower = *config.params.config();
        slower.v_max = 0.1;
        config.params = ChassisParams::new(slower).unwrap();
        c.reconfigure(config).unwrap();
        // v_max 0.1 with r = 0.05: wheel 1 at 0.1/0.05 = 2 rad/s, not the 10 rad/s asked for before.
        let cmd = c.gate(0.1);
        assert_relative_eq!(cmd.wheels.values()[0], 2.0, epsilon = 1e-12);
        assert!(cmd.reasons.contains(ClampReason::Speed));
    }

    #[test]
    fn feedback_drives_odometry_and_refuses_time_going_backwards() {
        let mut c = controller(ChassisConfig::omr3());
        let forward = WheelState::Omni {
            wheels: [6.0, -3.0, -3.0],
        }; // 0.3 m/s along x
        c.on_feedback(&forward, 10.0, 10.0).unwrap();
        c.on_feedback(&forward, 10.5, 10.5).unwrap();
        // 0.3 m/s for 0.5 s.
        assert_relative_eq!(c.odometry().reference_pose().x, 0.15, epsilon = 1e-12);
        assert!(c.on_feedback(&forward, 10.25, 10.6).is_err());
        assert_relative_eq!(c.odometry().reference_pose().x, 0.15, epsilon = 1e-12);
        let bad = WheelState::Omni {
            wheels: [f64::NAN, 0.0, 0.0],
        };
        assert!(c.on_feedback(&bad, 10.7, 10.7).is_err());
    }

    fn is_zero_omni(cmd: &GatedCommand) -> bool {
        cmd.wheels == WheelState::Omni { wheels: [0.0; 3] }
    }

    #[test]
    fn without_any_feedback_no_command_reaches_the_wheels() {
        // OMR-III, cmd_vel 0.2 m/s at 10 Hz for 4 s, and the 50 Hz tick, with no joint_states at
        // all: the odometry would be blind, so every command is zero.
        let mut c = controller(ChassisConfig::omr3());
        for k in 0..200 {
            let t = 0.02 * f64::from(k);
            if k % 5 == 0 {
                let cmd = c.on_cmd_vel(BodyTwist::new(0.2, 0.0, 0.0), t);
                assert!(is_zero_omni(&cmd), "cmd_vel at {t} s sent {:?}", cmd.wheels);
                assert!(cmd.safety().feedback_stale && !cmd.safety().cmd_vel_expired);
            }
            assert!(is_zero_omni(&c.gate(t)), "tick at {t} s");
        }
        // The request itself stands: 0.2 m/s along x, Ω = (0.2/0.05)·[1, −½, −½] = [4, −2, −2].
        assert_eq!(
            c.requested().wheels,
            WheelState::Omni {
                wheels: [4.0, -2.0, -2.0]
            }
        );
    }

    #[test]
    fn feedback_stopping_mid_run_stops_the_wheels_after_its_timeout() {
        let mut c = controller(ChassisConfig::omr3());
        // Feedback at 50 Hz up to t = 1.0 s, cmd_vel at 10 Hz up to 3 s: wheels turn until the
        // feedback is 0.5 s old, i.e. through t = 1.5 s, and are zero after.
        for k in 0..=150 {
            let t = 0.02 * f64::from(k);
            if t <= 1.0 + 1e-9 {
                feed_feedback(&mut c, t);
            }
            let cmd = if k % 5 == 0 {
                c.on_cmd_vel(BodyTwist::new(0.2, 0.0, 0.0), t)
            } else {
                c.gate(t)
            };
            if t <= 1.5 - 1e-9 {
                assert_eq!(
                    cmd.wheels,
                    WheelState::Omni {
                        wheels: [4.0, -2.0, -2.0]
                    },
                    "at {t} s"
                );
            } else if t > 1.5 + 1e-9 {
                assert!(is_zero_omni(&cmd), "at {t} s: {:?}", cmd.wheels);
                assert!(cmd.safety().feedback_stale);
            }
        }
    }

    #[test]
    fn a_stop_holds_the_steering_angles_last_sent() {
        let mut c = controller(ChassisConfig::mobil2());
        // Before any command a stop is straight.
        assert_eq!(c.gate(0.0).wheels, WheelState::zero(ChassisModel::CarLike));
        feed_feedback(&mut c, 0.0);
        // v = 0.3, ω = 0.2: R = 1.5 m; δ_l = atan(0.6/(1.5 − 0.31)) = 0.467003,
        // δ_r = atan(0.6/(1.5 + 0.31)) = 0.320092; rear (0.3 ∓ 0.062)/0.1 = 2.38, 3.62 rad/s.
        let moving = c.on_cmd_vel(BodyTwist::new(0.3, 0.0, 0.2), 0.0);
        let WheelState::CarLike {
            front_left_steering: left,
            front_right_steering: right,
            rear_left,
            rear_right,
        } = moving.wheels
        else {
            panic!("{moving:?}")
        };
        assert_relative_eq!(left, 0.467_003_301, epsilon = 1e-9);
        assert_relative_eq!(right, 0.320_092_181, epsilon = 1e-9);
        assert_relative_eq!(rear_left, 2.38, epsilon = 1e-12);
        assert_relative_eq!(rear_right, 3.62, epsilon = 1e-12);
        // cmd_vel stops: at 0.6 s the watchdog has expired; the rear wheels stop, the steering
        // stays where it was.
        feed_feedback(&mut c, 0.6);
        let stopped = c.gate(0.6);
        assert!(stopped.safety().cmd_vel_timed_out());
        assert_eq!(
            stopped.wheels,
            WheelState::CarLike {
                front_left_steering: left,
                front_right_steering: right,
                rear_left: 0.0,
                rear_right: 0.0
            }
        );
        assert_eq!(stopped.twist, BodyTwist::ZERO);
        // A NaN holds it as well; an explicit zero twist is a command and straightens the wheels.
        assert_eq!(
            c.on_cmd_vel(BodyTwist::new(f64::NAN, 0.0, 0.0), 0.61).wheels,
            stopped.wheels
        );
        assert_eq!(
            c.on_cmd_vel(BodyTwist::ZERO, 0.62).wheels,
            WheelState::zero(ChassisModel::CarLike)
        );
    }

    #[test]
    fn an_unreadable_cmd_vel_stops_the_wheels_at_once_and_does_not_feed_the_watchdog() {
        let mut c = controller(ChassisConfig::omr3());
        feed_feedback(&mut c, 0.0);
        // 0.2 m/s along x with r = 0.05: Ω = 4·[1, −½, −½].
        let moving = c.on_cmd_vel(BodyTwist::new(0.2, 0.0, 0.0), 0.0);
        assert_eq!(
            moving.wheels,
            WheelState::Omni {
                wheels: [4.0, -2.0, -2.0]
            }
        );
        let refused = c.on_unreadable_cmd_vel(0.1);
        assert!(is_zero_omni(&refused));
        assert!(refused.safety().cmd_vel_refused);
        feed_feedback(&mut c, 0.2);
        assert!(is_zero_omni(&c.gate(0.2)), "the stop lasts until the next good cmd_vel");
        assert_eq!(
            c.on_cmd_vel(BodyTwist::new(0.2, 0.0, 0.0), 0.3).wheels,
            WheelState::Omni {
                wheels: [4.0, -2.0, -2.0]
            }
        );
    }

    #[test]
    fn the_shutdown_stop_goes_through_the_gate_even_with_both_watchdogs_off() {
        let mut c = Rig {
            c: ChassisController::new(ControllerConfig {
                params: ChassisParams::omr3(),
                cmd_vel_timeout_s: 0.0,
                feedback_timeout_s: 0.0,
                noise: OdometryNoise::default(),
            })
            .unwrap(),
            cmd_at: None,
            fb_at: None,
        };
        // Watchdogs off: the request passes, and only the gate's "no request" stops it.
        let moving = c.on_cmd_vel(BodyTwist::new(0.2, 0.0, 0.0), 0.0);
        assert_eq!(
            moving.wheels,
            WheelState::Omni {
                wheels: [4.0, -2.0, -2.0]
            }
        );
        assert!(!moving.safety().stops());
        assert!(is_zero_omni(&c.stop(100.0)));
        assert!(is_zero_omni(&c.gate(100.02)), "the stop lasts");
    }

    #[test]
    fn impossible_wheel_speeds_are_refused_and_leave_the_odometry_as_it_was() {
        let forward = WheelState::Omni {
            wheels: [6.0, -3.0, -3.0],
        };
        let mut c = controller(ChassisConfig::omr3());
        c.on_feedback(&forward, 1.0, 1.0).unwrap();
        c.on_feedback(&forward, 1.1, 1.1).unwrap();
        let before = c.odometry().clone();
        // OMR-III: max_wheel_speed 12 rad/s, so feedback is believed up to 3 × 12 = 36 rad/s.
        assert_relative_eq!(c.max_feedback_wheel_speed(), 36.0);
        let huge = WheelState::Omni {
            wheels: [1e308, -1e308, 0.0],
        };
        assert!(matches!(
            c.on_feedback(&huge, 1.2, 1.2),
            Err(FeedbackError::Implausible {
                joint: "wheel_1",
                limit: 36.0,
                ..
            })
        ));
        let just_over = WheelState::Omni {
            wheels: [0.0, 36.001, 0.0],
        };
        assert!(c.on_feedback(&just_over, 1.2, 1.2).is_err());
        assert_eq!(c.odometry(), &before);
        assert_relative_eq!(c.odometry().reference_pose().x, 0.03, epsilon = 1e-12);
        // At the limit it is believed.
        let at_limit = WheelState::Omni {
            wheels: [36.0, -18.0, -18.0],
        };
        assert_eq!(c.on_feedback(&at_limit, 1.2, 1.2).unwrap(), FeedbackOutcome::Integrated);

        // MOBIL-II: max_wheel_speed 7.5, limit 22.5 rad/s; the rear-left wheel at 1e308.
        let mut car = controller(ChassisConfig::mobil2());
        let rest = WheelState::zero(ChassisModel::CarLike);
        car.on_feedback(&rest, 1.0, 1.0).unwrap();
        let before = car.odometry().clone();
        let huge = WheelState::from_values(ChassisModel::CarLike, &[0.0, 0.0, 1e308, 0.0]).unwrap();
        assert!(matches!(
            car.on_feedback(&huge, 1.1, 1.1),
            Err(FeedbackError::Implausible {
                joint: "rear_left_wheel",
                ..
            })
        ));
        // A steering angle past 90° is not a real reading either.
        let bent = WheelState::from_values(ChassisModel::CarLike, &[1.6, 0.0, 1.0, 1.0]).unwrap();
        assert!(matches!(
            car.on_feedback(&bent, 1.1, 1.1),
            Err(FeedbackError::Implausible {
                joint: "front_left_steering",
                ..
            })
        ));
        assert_eq!(car.odometry(), &before);
        let cov = car.odometry().covariance();
        assert!(cov.iter().all(|v| v.is_finite()));
        // A lower factor applies at once: 2 × 7.5 = 15 rad/s.
        car.set_feedback_speed_factor(2.0).unwrap();
        let fast = WheelState::from_values(ChassisModel::CarLike, &[0.0, 0.0, 16.0, 16.0]).unwrap();
        assert!(car.on_feedback(&fast, 1.1, 1.1).is_err());
        assert!(car.set_feedback_speed_factor(0.5).is_err());
        assert!(car.set_feedback_speed_factor(f64::NAN).is_err());
        // The same verdicts before anything is applied (a parameter change vets it first).
        assert!(ChassisController::check_feedback_speed_factor(0.5).is_err());
        assert!(ChassisController::check_feedback_speed_factor(f64::INFINITY).is_err());
        assert!(ChassisController::check_feedback_speed_factor(1.0).is_ok());
        assert_relative_eq!(car.feedback_speed_factor(), 2.0);
    }

    /// Position-only samples of OMR-III (wheel angles) fed at their stamps.
    fn feed_angles(c: &mut Rig, t: f64, angles: [f64; 3]) -> Result<Option<FeedbackOutcome>, FeedbackError> {
        let names: Vec<String> = ["wheel_1", "wheel_2", "wheel_3"]
            .iter()
            .map(|s| (*s).to_owned())
            .collect();
        c.on_joint_state(&names, &angles, &[], t, t)
    }

    /// OMR-III driving along x at 0.3 m/s: wheel angles 6t, −3t, −3t (rad).
    fn driving(t: f64) -> [f64; 3] {
        [6.0 * t, -3.0 * t, -3.0 * t]
    }

    #[test]
    fn a_late_or_unstamped_encoder_sample_is_not_integrated_twice() {
        let mut c = controller(ChassisConfig::omr3());
        // Samples at 1.00 and 1.02, a late 1.01, a NaN stamp, then 1.04: wheel 1 turns 0.24 rad
        // in all, 0.04 s at 0.3 m/s = 12 mm (not 0.30 rad, 15 mm).
        assert_eq!(feed_angles(&mut c, 1.0, driving(1.0)).unwrap(), None);
        feed_angles(&mut c, 1.02, driving(1.02)).unwrap();
        assert!(feed_angles(&mut c, 1.01, driving(1.01)).is_err());
        assert!(feed_angles(&mut c, f64::NAN, driving(1.03)).is_err());
        assert_eq!(
            feed_angles(&mut c, 1.04, driving(1.04)).unwrap(),
            Some(FeedbackOutcome::Integrated)
        );
        assert_relative_eq!(c.odometry().reference_pose().x, 0.012, epsilon = 1e-12);
    }

    #[test]
    fn a_replayed_old_encoder_sample_does_not_repeat_the_distance() {
        let mut c = controller(ChassisConfig::omr3());
        // 50 Hz from 0 to 9.98 s: 0.3 m/s × 9.98 s = 2.994 m.
        for k in 0..500 {
            feed_angles(&mut c, 0.02 * f64::from(k), driving(0.02 * f64::from(k))).unwrap();
        }
        assert_relative_eq!(c.odometry().reference_pose().x, 2.994, epsilon = 1e-9);
        // A sample from t = 0 replayed, then the next real one at 10 s (angle 60): it continues
        // from 9.98 s, 6 mm, not the 60 rad (3 m) since t = 0 again.
        assert_eq!(feed_angles(&mut c, 0.0, driving(0.0)).unwrap(), None);
        assert_eq!(
            feed_angles(&mut c, 10.0, driving(10.0)).unwrap(),
            Some(FeedbackOutcome::Integrated)
        );
        assert_relative_eq!(c.odometry().reference_pose().x, 3.0, epsilon = 1e-9);
        // A real clock reset (a restarted simulation, its encoders back at 0) is followed: 20 ms
        // after it, 6 mm more.
        assert_eq!(feed_angles(&mut c, 0.0, driving(0.0)).unwrap(), None);
        feed_angles(&mut c, 0.02, driving(0.02)).unwrap();
        assert_relative_eq!(c.odometry().reference_pose().x, 3.006, epsilon = 1e-9);
    }

    #[test]
    fn a_refused_encoder_sample_loses_no_distance() {
        let mut c = controller(ChassisConfig::omr3());
        for k in 0..=50 {
            feed_angles(&mut c, 0.02 * f64::from(k), driving(0.02 * f64::from(k))).unwrap();
        }
        assert_relative_eq!(c.odometry().reference_pose().x, 0.3, epsilon = 1e-9);
        // A glitch of +100 rad on wheel 1 at 1.02 s (5006 rad/s): refused.
        let mut glitch = driving(1.02);
        glitch[0] += 100.0;
        assert!(matches!(
            feed_angles(&mut c, 1.02, glitch),
            Err(FeedbackError::Implausible { joint: "wheel_1", .. })
        ));
        // 1.04 spans (1.00, 1.04]: 12 mm more.
        assert_eq!(
            feed_angles(&mut c, 1.04, driving(1.04)).unwrap(),
            Some(FeedbackOutcome::Integrated)
        );
        assert_relative_eq!(c.odometry().reference_pose().x, 0.312, epsilon = 1e-9);
    }

    #[test]
    fn travelled_distance_overlapping_the_odometry_is_refused() {
        let mut c = controller(ChassisConfig::omr3());
        let forward = WheelState::Omni {
            wheels: [6.0, -3.0, -3.0],
        };
        c.on_feedback(&forward, 10.0, 10.0).unwrap();
        c.on_feedback(&forward, 10.5, 10.5).unwrap();
        let overlapping = FeedbackSample::Travelled {
            wheels: forward,
            since: 10.4,
            stamp: 10.6,
            wrapped: false,
        };
        assert!(matches!(
            c.on_feedback_sample(&overlapping),
            Err(FeedbackError::Odometry(OdometryError::TimeNotIncreasing { .. }))
        ));
        assert_relative_eq!(c.odometry().reference_pose().x, 0.15, epsilon = 1e-12);
        // Starting 5 s before it: a clock reset, integrated over its own 0.2 s (6 cm).
        let after_reset = FeedbackSample::Travelled {
            wheels: forward,
            since: 5.5,
            stamp: 5.7,
            wrapped: false,
        };
        assert_eq!(c.on_feedback_sample(&after_reset).unwrap(), FeedbackOutcome::Integrated);
        assert_relative_eq!(c.odometry().reference_pose().x, 0.21, epsilon = 1e-12);
    }

    #[test]
    fn encoder_angles_across_a_dropout_are_a_real_distance() {
        let mut c = controller(ChassisConfig::omr3());
        // At rest, 50 Hz, until t = 1 s.
        for k in 0..=50 {
            feed_angles(&mut c, 0.02 * f64::from(k), [0.0; 3]).unwrap();
        }
        // 2 s without feedback, in which the robot drives 1 m along x: wheel 1 (rolling along x)
        // turns 1/0.05 = 20 rad, wheels 2 and 3 −½ of that.
        let outcome = feed_angles(&mut c, 3.0, [20.0, -10.0, -10.0]).unwrap().unwrap();
        assert!(matches!(outcome, FeedbackOutcome::Bridged { gap_s } if (gap_s - 2.0).abs() < 1e-9));
        assert_relative_eq!(c.odometry().reference_pose().x, 1.0, epsilon = 1e-9);
        assert_relative_eq!(c.odometry().reference_pose().y, 0.0, epsilon = 1e-9);
        // And on from there at 50 Hz: 0.02 s at 0.3 m/s (6 rad/s on wheel 1) adds 6 mm.
        let next = feed_angles(&mut c, 3.02, [20.12, -10.06, -10.06]).unwrap().unwrap();
        assert_eq!(next, FeedbackOutcome::Integrated);
        assert_relative_eq!(c.odometry().reference_pose().x, 1.006, epsilon = 1e-9);
    }

    #[test]
    fn wrapped_encoder_angles_integrate_without_a_spike_and_refuse_an_ambiguous_gap() {
        let mut c = controller(ChassisConfig::omr3());
        c.set_encoder_positions_wrap(true);
        let wrapped = |t: f64| driving(t).map(wrap);
        // 0.3 m/s along x for 1 s at 50 Hz, wheel angles reported wrapped to (−π, π]: wheel 1
        // wraps at t = π/6 = 0.52 s. Odometry: x = 0.3 m, no spike.
        for k in 0..=50 {
            feed_angles(&mut c, 0.02 * f64::from(k), wrapped(0.02 * f64::from(k))).unwrap();
        }
        assert_relative_eq!(c.odometry().reference_pose().x, 0.3, epsilon = 1e-9);
        assert_relative_eq!(c.odometry().twist().vx, 0.3, epsilon = 1e-9);
        // A 0.1 s gap: feedback is believed up to 3 × 12 = 36 rad/s, at which a wheel turns
        // 3.6 rad > π in it, so the wrapped difference says nothing: not integrated, the clock
        // restarts, and no twist is claimed.
        let outcome = feed_angles(&mut c, 1.1, wrapped(1.1)).unwrap().unwrap();
        assert!(matches!(outcome, FeedbackOutcome::Ambiguous { gap_s } if (gap_s - 0.1).abs() < 1e-9));
        assert_relative_eq!(c.odometry().reference_pose().x, 0.3, epsilon = 1e-9);
        assert_eq!(c.odometry().twist(), BodyTwist::ZERO);
        // The next 20 ms integrate normally (6 mm); so does a gap of 0.08 s (2.88 rad < π at
        // 36 rad/s): 24 mm.
        feed_angles(&mut c, 1.12, wrapped(1.12)).unwrap().unwrap();
        assert_relative_eq!(c.odometry().reference_pose().x, 0.306, epsilon = 1e-9);
        assert_eq!(
            feed_angles(&mut c, 1.2, wrapped(1.2)).unwrap(),
            Some(FeedbackOutcome::Integrated)
        );
        assert_relative_eq!(c.odometry().reference_pose().x, 0.33, epsilon = 1e-9);
    }
}
