//! `sensor_msgs/JointState` ↔ [`WheelState`]: the wire layout of `wheel_commands` and
//! `joint_states`, checked once at the edge ("parse, don't validate").
//!
//! Joints are matched by name ([`ChassisModel::joints`]), in any order; other joints in the
//! message (an arm, a pan-tilt) are ignored. A steering joint carries its angle in `position`,
//! a wheel joint its speed in `velocity` (rad/s). `position` and `velocity` must each be empty
//! or as long as `name`, as the message definition requires.
//!
//! Feedback may carry wheel speeds (`velocity`) or only encoder angles (`position`, as many
//! drivers publish): [`FeedbackDecoder`] then differentiates the angles between samples, wrapped
//! or not.
//!
//! Commands (`wheel_commands`) list every joint of the model; steering joints get the angle in
//! `position` and 0 in `velocity`, wheel joints the speed in `velocity` and 0 in `position`.

use thiserror::Error;

use crate::angles::wrap;
use crate::kinematics::{JointKind, WheelState};
use crate::model::ChassisModel;

/// Why a JointState could not be read.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum JointStateError {
    /// `position` or `velocity` is neither empty nor as long as `name`.
    #[error("mismatched array lengths: {names} names, {positions} positions, {velocities} velocities")]
    MismatchedLengths {
        /// Length of `name`.
        names: usize,
        /// Length of `position`.
        positions: usize,
        /// Length of `velocity`.
        velocities: usize,
    },
    /// A joint of the model is not in the message.
    #[error("joint `{0}` is missing")]
    MissingJoint(&'static str),
    /// The field a joint needs is empty.
    #[error("joint `{joint}` needs `{field}`, which is empty")]
    MissingField {
        /// The joint.
        joint: &'static str,
        /// `position` or `velocity`.
        field: &'static str,
    },
    /// A needed value is NaN or infinite.
    #[error("joint `{joint}` has a non-finite value {value}")]
    NonFinite {
        /// The joint.
        joint: &'static str,
        /// The value.
        value: f64,
    },
}

/// Reads the model's joints from the arrays of a JointState.
pub fn wheel_state_from_joints(
    model: ChassisModel,
    names: &[String],
    positions: &[f64],
    velocities: &[f64],
) -> Result<WheelState, JointStateError> {
    let n = names.len();
    if (!positions.is_empty() && positions.len() != n) || (!velocities.is_empty() && velocities.len() != n) {
        return Err(JointStateError::MismatchedLengths {
            names: n,
            positions: positions.len(),
            velocities: velocities.len(),
        });
    }
    let mut values = Vec::with_capacity(model.joints().len());
    for joint in model.joints() {
        let index = names
            .iter()
            .position(|name| name == joint.name)
            .ok_or(JointStateError::MissingJoint(joint.name))?;
        let (field, array) = match joint.kind {
            JointKind::Steering => ("position", positions),
            JointKind::Wheel => ("velocity", velocities),
        };
        let value = *array.get(index).ok_or(JointStateError::MissingField {
            joint: joint.name,
            field,
        })?;
        if !value.is_finite() {
            return Err(JointStateError::NonFinite {
                joint: joint.name,
                value,
            });
        }
        values.push(value);
    }
    WheelState::from_values(model, &values).map_err(|_| JointStateError::MismatchedLengths {
        names: n,
        positions: positions.len(),
        velocities: velocities.len(),
    })
}

/// One decoded wheel-feedback sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FeedbackSample {
    /// Wheel speeds as measured at `stamp` (the message's `velocity`).
    Measured {
        /// Steering angles and wheel speeds.
        wheels: WheelState,
        /// Measurement time (s).
        stamp: f64,
    },
    /// Wheel speeds averaged over (`since`, `stamp`] from the change of the encoder angles: the
    /// distance they imply was really travelled, however long the interval (a dropout of the
    /// feedback does not lose it).
    Travelled {
        /// Steering angles at `stamp` and the mean wheel speeds over the interval.
        wheels: WheelState,
        /// Stamp (s) of the previous position sample.
        since: f64,
        /// Stamp (s) of this sample.
        stamp: f64,
        /// True if a wheel's angle difference was unwrapped to the shortest angle (its encoder
        /// reads wrapped angles): the difference is then only known modulo 2π, see
        /// [`FeedbackDecoder`].
        wrapped: bool,
    },
}

impl FeedbackSample {
    /// Steering angles and wheel speeds.
    pub fn wheels(&self) -> &WheelState {
        match self {
            Self::Measured { wheels, .. } | Self::Travelled { wheels, .. } => wheels,
        }
    }

    /// Stamp (s) of the sample.
    pub fn stamp(&self) -> f64 {
        match *self {
            Self::Measured { stamp, .. } | Self::Travelled { stamp, .. } => stamp,
        }
    }
}

/// Readings of a wheel angle beyond ±2π prove that its encoder counts continuously.
const WRAPPED_RANGE: f64 = 2.0 * std::f64::consts::PI;

/// Turns successive `joint_states` into [`FeedbackSample`]s, from wheel speeds when the message
/// has them, else from the change of the wheel angles since the previous sample.
///
/// Wrapped encoders: many drivers report a wheel angle wrapped to (−π, π] (or [0, 2π)). While
/// every reading of a wheel has stayed within ±2π, its angle difference is unwrapped to the
/// shortest angle, so a wrap from +π to −π is a small step forward, not a 2π spike; once a
/// reading lies beyond ±2π the encoder is known to count continuously and differences are taken
/// as they are. The shortest angle is the true one only if the wheel turned less than π between
/// the two samples, i.e. samples closer than π / ω_max (at `max_wheel_speed` ω_max: 0.42 s for
/// MOBIL-II's 7.5 rad/s, 0.26 s for OMR-III's 12 rad/s); such a sample is marked
/// [`FeedbackSample::Travelled::wrapped`] so that the odometry can refuse to integrate a longer,
/// ambiguous gap.
#[derive(Debug, Clone, Default)]
pub struct FeedbackDecoder {
    /// Stamp (s) and wheel-joint angles of the previous position-only sample.
    previous: Option<(f64, Vec<f64>)>,
    /// Per wheel joint: a reading beyond ±2π was seen (the encoder does not wrap).
    continuous: Vec<bool>,
}

impl FeedbackDecoder {
    /// Decodes one sample stamped `stamp` (s). `Ok(None)`: a position-only sample that only sets
    /// the baseline (the first one, or one not after the previous stamp).
    pub fn decode(
        &mut self,
        model: ChassisModel,
        names: &[String],
        positions: &[f64],
        velocities: &[f64],
        stamp: f64,
    ) -> Result<Option<FeedbackSample>, JointStateError> {
        if !velocities.is_empty() || positions.is_empty() {
            self.previous = None;
            let wheels = wheel_state_from_joints(model, names, positions, velocities)?;
            return Ok(Some(FeedbackSample::Measured { wheels, stamp }));
        }
        // Positions only: read every joint's angle, then differentiate the wheels'.
        let angles = wheel_state_from_joints(model, names, positions, positions)?.values();
        let wheel_joints: Vec<(&'static str, f64)> = model
            .joints()
            .iter()
            .zip(&angles)
            .filter(|(j, _)| j.kind == JointKind::Wheel)
            .map(|(j, a)| (j.name, *a))
            .collect();
        if self.continuous.len() != wheel_joints.len() {
            self.continuous = vec![false; wheel_joints.len()];
        }
        for (continuous, (_, angle)) in self.continuous.iter_mut().zip(&wheel_joints) {
            *continuous |= angle.abs() > WRAPPED_RANGE;
        }
        let wheel_angles: Vec<f64> = wheel_joints.iter().map(|(_, a)| *a).collect();
        let previous = self.previous.replace((stamp, wheel_angles));
        let Some((since, before)) = previous else {
            return Ok(None);
        };
        let dt = stamp - since;
        if !(dt > 0.0 && dt.is_finite()) {
            return Ok(None);
        }
        let mut wrapped = false;
        let mut speeds = Vec::with_capacity(wheel_joints.len());
        for (((name, angle), before), continuous) in wheel_joints.iter().zip(&before).zip(&self.continuous) {
            let mut change = angle - before;
            if !continuous {
                wrapped = true;
                change = wrap(change);
            }
            let speed = change / dt;
            if !speed.is_finite() {
                return Err(JointStateError::NonFinite {
                    joint: name,
                    value: speed,
                });
            }
            speeds.push(speed);
        }
        let mut speeds = speeds.into_iter();
        let values: Vec<f64> = model
            .joints()
            .iter()
            .zip(angles)
            .map(|(j, angle)| match j.kind {
                JointKind::Steering => angle,
                JointKind::Wheel => speeds.next().unwrap_or(0.0),
            })
            .collect();
        let wheels = WheelState::from_values(model, &values).map_err(|_| JointStateError::MismatchedLengths {
            names: names.len(),
            positions: positions.len(),
            velocities: velocities.len(),
        })?;
        Ok(Some(FeedbackSample::Travelled {
            wheels,
            since,
            stamp,
            wrapped,
        }))
    }
}

/// The `(name, position, velocity)` arrays of a `wheel_commands` message.
pub fn joints_from_wheel_state(state: &WheelState) -> (Vec<String>, Vec<f64>, Vec<f64>) {
    let joints = state.model().joints();
    let values = state.values();
    let mut names = Vec::with_capacity(joints.len());
    let mut positions = Vec::with_capacity(joints.len());
    let mut velocities = Vec::with_capacity(joints.len());
    for (joint, value) in joints.iter().zip(values) {
        names.push(joint.name.to_owned());
        match joint.kind {
            JointKind::Steering => {
                positions.push(value);
                velocities.push(0.0);
            }
            JointKind::Wheel => {
                positions.push(0.0);
                velocities.push(value);
            }
        }
    }
    (names, positions, velocities)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| (*s).to_owned()).collect()
    }

    #[test]
    fn reads_joints_by_name_in_any_order_ignoring_others() {
        let n = names(&[
            "arm",
            "rear_right_wheel",
            "front_right_steering",
            "rear_left_wheel",
            "front_left_steering",
        ]);
        let s = wheel_state_from_joints(
            ChassisModel::CarLike,
            &n,
            &[9.0, 0.0, 0.2, 0.0, 0.3],
            &[9.0, 5.0, 0.0, 4.0, 0.0],
        )
        .unwrap();
        assert_eq!(
            s,
            WheelState::CarLike {
                front_left_steering: 0.3,
                front_right_steering: 0.2,
                rear_left: 4.0,
                rear_right: 5.0
            }
        );
    }

    #[test]
    fn omni_needs_only_velocities() {
        let n = names(&["wheel_1", "wheel_2", "wheel_3"]);
        let s = wheel_state_from_joints(ChassisModel::Omni, &n, &[], &[1.0, 2.0, 3.0]).unwrap();
        assert_eq!(
            s,
            WheelState::Omni {
                wheels: [1.0, 2.0, 3.0]
            }
        );
    }

    #[test]
    fn refuses_bad_messages() {
        let n = names(&["steering", "traction"]);
        let m = ChassisModel::Tricycle;
        assert!(matches!(
            wheel_state_from_joints(m, &n, &[0.1], &[1.0, 2.0]),
            Err(JointStateError::MismatchedLengths {
                names: 2,
                positions: 1,
                velocities: 2
            })
        ));
        assert_eq!(
            wheel_state_from_joints(m, &names(&["steering"]), &[0.1], &[1.0]),
            Err(JointStateError::MissingJoint("traction"))
        );
        assert_eq!(
            wheel_state_from_joints(m, &n, &[], &[1.0, 2.0]),
            Err(JointStateError::MissingField {
                joint: "steering",
                field: "position"
            })
        );
        assert!(matches!(
            wheel_state_from_joints(m, &n, &[f64::NAN, 0.0], &[0.0, 1.0]),
            Err(JointStateError::NonFinite { joint: "steering", .. })
        ));
        assert!(
            wheel_state_from_joints(m, &n, &[0.0, f64::NAN], &[0.0, 1.0]).is_ok(),
            "unused fields may be NaN"
        );
    }

    #[test]
    fn position_only_feedback_is_differentiated() {
        let n = names(&[
            "front_left_steering",
            "front_right_steering",
            "rear_left_wheel",
            "rear_right_wheel",
        ]);
        let mut d = FeedbackDecoder::default();
        let m = ChassisModel::CarLike;
        assert_eq!(d.decode(m, &n, &[0.1, 0.08, 10.0, 20.0], &[], 5.0).unwrap(), None);
        // Rear wheels turned 0.6 and 0.7 rad in 0.1 s: 6 and 7 rad/s; steering read as is.
        let sample = d.decode(m, &n, &[0.1, 0.08, 10.6, 20.7], &[], 5.1).unwrap().unwrap();
        assert!(matches!(
            sample,
            FeedbackSample::Travelled {
                since: 5.0,
                stamp: 5.1,
                wrapped: false,
                ..
            }
        ));
        match *sample.wheels() {
            WheelState::CarLike {
                front_left_steering,
                front_right_steering,
                rear_left,
                rear_right,
            } => {
                assert_eq!((front_left_steering, front_right_steering), (0.1, 0.08));
                assert!((rear_left - 6.0).abs() < 1e-9 && (rear_right - 7.0).abs() < 1e-9);
            }
            other => panic!("{other:?}"),
        }
        // A stamp not after the previous one only resets the baseline.
        assert_eq!(d.decode(m, &n, &[0.1, 0.08, 10.6, 20.7], &[], 5.1).unwrap(), None);
        // With velocities present they are used as they are.
        let v = d
            .decode(m, &n, &[0.0, 0.0, 0.0, 0.0], &[0.0, 0.0, 1.0, 1.0], 5.2)
            .unwrap()
            .unwrap();
        assert_eq!(v.wheels().values()[2], 1.0);
        assert!(matches!(v, FeedbackSample::Measured { stamp: 5.2, .. }));
    }

    fn omni_speeds(sample: Option<FeedbackSample>) -> [f64; 3] {
        match sample {
            Some(FeedbackSample::Travelled {
                wheels: WheelState::Omni { wheels },
                ..
            }) => wheels,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn wrapped_encoder_angles_make_no_two_pi_spike() {
        let n = names(&["wheel_1", "wheel_2", "wheel_3"]);
        let m = ChassisModel::Omni;
        let mut d = FeedbackDecoder::default();
        assert_eq!(d.decode(m, &n, &[3.0, -3.0, 0.0], &[], 1.0).unwrap(), None);
        // In 0.1 s wheel 1 turns +0.4 rad across +π (3.0 → 3.4 − 2π = −2.883185), wheel 2 turns
        // −0.4 rad across −π (−3.0 → −3.4 + 2π = 2.883185), wheel 3 +0.4 rad: 4, −4, 4 rad/s, not
        // the ±58.8 rad/s of the raw differences.
        let spike_free = omni_speeds(
            d.decode(m, &n, &[-2.883_185_307, 2.883_185_307, 0.4], &[], 1.1)
                .unwrap(),
        );
        for (got, want) in spike_free.iter().zip([4.0, -4.0, 4.0]) {
            assert!((got - want).abs() < 1e-6, "{spike_free:?}");
        }
    }

    #[test]
    fn continuous_encoder_is_taken_as_it_is() {
        let n = names(&["wheel_1", "wheel_2", "wheel_3"]);
        let m = ChassisModel::Omni;
        let mut d = FeedbackDecoder::default();
        assert_eq!(d.decode(m, &n, &[0.0, 0.0, 0.0], &[], 1.0).unwrap(), None);
        // A 2 s dropout, then wheel 1 is 20 rad further (beyond ±2π: a continuous count), wheels
        // 2 and 3 −10 rad: OMR-III driving 1 m along x (r = 0.05: 1/0.05 = 20 rad); mean speeds
        // 10, −5, −5 rad/s, not wrapped.
        let sample = d.decode(m, &n, &[20.0, -10.0, -10.0], &[], 3.0).unwrap().unwrap();
        assert_eq!(
            sample,
            FeedbackSample::Travelled {
                wheels: WheelState::Omni {
                    wheels: [10.0, -5.0, -5.0]
                },
                since: 1.0,
                stamp: 3.0,
                wrapped: false,
            }
        );
        // Later differences of more than π on those wheels are real too (0.1 s at 40 rad/s).
        let fast = omni_speeds(d.decode(m, &n, &[24.0, -14.0, -14.0], &[], 3.1).unwrap());
        for (got, want) in fast.iter().zip([40.0, -40.0, -40.0]) {
            assert!((got - want).abs() < 1e-9, "{fast:?}");
        }
    }

    #[test]
    fn commands_round_trip() {
        let s = WheelState::Tricycle {
            steering: -0.4,
            traction: 3.0,
        };
        let (n, p, v) = joints_from_wheel_state(&s);
        assert_eq!(n, ["steering", "traction"]);
        assert_eq!(p, [-0.4, 0.0]);
        assert_eq!(v, [0.0, 3.0]);
        assert_eq!(wheel_state_from_joints(ChassisModel::Tricycle, &n, &p, &v).unwrap(), s);
    }
}
