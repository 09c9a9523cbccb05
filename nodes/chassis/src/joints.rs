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

use crate::kinematics::{JointKind, WheelState};
use crate::model::ChassisModel;
use mobil_geom::wrap;

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
    /// The stamp is NaN or infinite.
    #[error("non-finite stamp {0}")]
    NonFiniteStamp(f64),
    /// The stamp is not after the previous sample's, but less than a clock reset behind it (out
    /// of order, or a duplicate).
    #[error("stamp {stamp} not after the previous sample's {previous}")]
    StampNotIncreasing {
        /// Stamp (s) of the previous sample.
        previous: f64,
        /// Stamp (s) of this one.
        stamp: f64,
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

/// The stamp and wheel-joint angles of a position-only sample, the baseline of the next one.
#[derive(Debug, Clone, PartialEq)]
struct Baseline {
    stamp: f64,
    angles: Vec<f64>,
}

/// A decoded sample, and the decoder's baseline once it is accepted: the baseline moves only when
/// [`FeedbackDecoder::commit`] is given this, so a sample the caller refuses costs no distance.
#[derive(Debug, Clone, PartialEq)]
pub struct Decoded {
    sample: Option<FeedbackSample>,
    previous: Option<Baseline>,
    before_reset: Option<Baseline>,
}

impl Decoded {
    /// The sample, `None` if the message only sets the baseline (the first position-only sample,
    /// or the first after a clock reset).
    pub fn sample(&self) -> Option<&FeedbackSample> {
        self.sample.as_ref()
    }
}

/// Turns successive `joint_states` into [`FeedbackSample`]s, from wheel speeds when the message
/// has them, else from the change of the wheel angles since the previous accepted sample.
///
/// Time: a stamp not after the baseline's but less than `max_gap` behind it (out of order, a
/// duplicate) is refused and the baseline kept, as is a non-finite stamp; one further behind is a
/// clock reset and becomes the new baseline. If the next sample then continues the old clock
/// (after the old baseline, within `max_gap`), the "reset" was one stray sample and the old
/// baseline is used; nothing is integrated twice.
///
/// Wrapped encoders (`wraps`, the node's `encoder_positions_wrap`): many drivers report a wheel
/// angle wrapped to (−π, π] (or [0, 2π)); the difference is then unwrapped to the shortest angle,
/// so a wrap from +π to −π is a small step forward, not a 2π spike. The shortest angle is the
/// true one only if the wheel turned less than π between the two samples, i.e. samples closer
/// than π / ω (at the fastest believed wheel speed ω = k × `max_wheel_speed`, k =
/// `max_feedback_wheel_speed_factor`, default 3: 0.14 s for MOBIL-II's 22.5 rad/s, 0.087 s for
/// OMR-III's 36 rad/s); such a sample is marked [`FeedbackSample::Travelled::wrapped`] so that the
/// controller can refuse to integrate a longer, ambiguous gap. Continuous encoders (the default)
/// are differentiated as they are, over any gap.
#[derive(Debug, Clone, Default)]
pub struct FeedbackDecoder {
    /// The encoders report wrapped angles.
    wraps: bool,
    /// The previous accepted position-only sample.
    previous: Option<Baseline>,
    /// The baseline before a clock reset, until the next sample confirms the reset.
    before_reset: Option<Baseline>,
}

impl FeedbackDecoder {
    /// A decoder for encoders that report wrapped angles (`wraps`) or count continuously.
    pub fn new(wraps: bool) -> Self {
        FeedbackDecoder {
            wraps,
            ..Self::default()
        }
    }

    /// True if the encoder angles are taken as wrapped.
    pub fn wraps(&self) -> bool {
        self.wraps
    }

    /// Decodes one sample stamped `stamp` (s), leaving the baseline as it is; pass the result to
    /// [`FeedbackDecoder::commit`] once the sample is accepted. `max_gap` (s): a stamp further than
    /// this behind the baseline is a clock reset, a nearer one is refused.
    pub fn decode(
        &self,
        model: ChassisModel,
        names: &[String],
        positions: &[f64],
        velocities: &[f64],
        stamp: f64,
        max_gap: f64,
    ) -> Result<Decoded, JointStateError> {
        if !stamp.is_finite() {
            return Err(JointStateError::NonFiniteStamp(stamp));
        }
        if !velocities.is_empty() || positions.is_empty() {
            let wheels = wheel_state_from_joints(model, names, positions, velocities)?;
            return Ok(Decoded {
                sample: Some(FeedbackSample::Measured { wheels, stamp }),
                previous: None,
                before_reset: None,
            });
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
        let current = Baseline {
            stamp,
            angles: wheel_joints.iter().map(|(_, a)| *a).collect(),
        };
        let base = match (&self.before_reset, &self.previous) {
            (Some(old), _) if stamp > old.stamp && stamp - old.stamp <= max_gap => Some(old),
            (_, previous) => previous.as_ref(),
        };
        let Some(base) = base.filter(|b| b.angles.len() == current.angles.len()) else {
            return Ok(Decoded {
                sample: None,
                previous: Some(current),
                before_reset: None,
            });
        };
        let dt = stamp - base.stamp;
        if dt <= 0.0 {
            if dt >= -max_gap {
                return Err(JointStateError::StampNotIncreasing {
                    previous: base.stamp,
                    stamp,
                });
            }
            // A clock reset: a new baseline, the old one kept until the next sample confirms it.
            return Ok(Decoded {
                sample: None,
                previous: Some(current),
                before_reset: Some(base.clone()),
            });
        }
        let mut speeds = Vec::with_capacity(wheel_joints.len());
        for ((name, angle), before) in wheel_joints.iter().zip(&base.angles) {
            let mut change = angle - before;
            if self.wraps {
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
        Ok(Decoded {
            sample: Some(FeedbackSample::Travelled {
                wheels,
                since: base.stamp,
                stamp,
                wrapped: self.wraps,
            }),
            previous: Some(current),
            before_reset: None,
        })
    }

    /// Takes the baseline `decoded` leaves: call it once its sample was accepted (or when it had
    /// none).
    pub fn commit(&mut self, decoded: Decoded) {
        self.previous = decoded.previous;
        self.before_reset = decoded.before_reset;
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

    /// Decodes with a 0.5 s clock-reset threshold and commits, as for an accepted sample.
    fn step(
        d: &mut FeedbackDecoder,
        m: ChassisModel,
        n: &[String],
        positions: &[f64],
        velocities: &[f64],
        t: f64,
    ) -> Result<Option<FeedbackSample>, JointStateError> {
        let decoded = d.decode(m, n, positions, velocities, t, 0.5)?;
        let sample = decoded.sample().copied();
        d.commit(decoded);
        Ok(sample)
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
        assert_eq!(step(&mut d, m, &n, &[0.1, 0.08, 10.0, 20.0], &[], 5.0).unwrap(), None);
        // Rear wheels turned 0.6 and 0.7 rad in 0.1 s: 6 and 7 rad/s; steering read as is.
        let sample = step(&mut d, m, &n, &[0.1, 0.08, 10.6, 20.7], &[], 5.1)
            .unwrap()
            .unwrap();
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
        // A stamp not after the previous one is refused.
        assert_eq!(
            step(&mut d, m, &n, &[0.1, 0.08, 10.6, 20.7], &[], 5.1),
            Err(JointStateError::StampNotIncreasing {
                previous: 5.1,
                stamp: 5.1
            })
        );
        // With velocities present they are used as they are.
        let v = step(&mut d, m, &n, &[0.0, 0.0, 0.0, 0.0], &[0.0, 0.0, 1.0, 1.0], 5.2)
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
        let mut d = FeedbackDecoder::new(true);
        assert_eq!(step(&mut d, m, &n, &[3.0, -3.0, 0.0], &[], 1.0).unwrap(), None);
        // In 0.1 s wheel 1 turns +0.4 rad across +π (3.0 → 3.4 − 2π = −2.883185), wheel 2 turns
        // −0.4 rad across −π (−3.0 → −3.4 + 2π = 2.883185), wheel 3 +0.4 rad: 4, −4, 4 rad/s, not
        // the ±58.8 rad/s of the raw differences.
        let spike_free = omni_speeds(step(&mut d, m, &n, &[-2.883_185_307, 2.883_185_307, 0.4], &[], 1.1).unwrap());
        for (got, want) in spike_free.iter().zip([4.0, -4.0, 4.0]) {
            assert!((got - want).abs() < 1e-6, "{spike_free:?}");
        }
    }

    #[test]
    fn continuous_encoder_is_taken_as_it_is() {
        let n = names(&["wheel_1", "wheel_2", "wheel_3"]);
        let m = ChassisModel::Omni;
        let mut d = FeedbackDecoder::default();
        assert_eq!(step(&mut d, m, &n, &[0.0, 0.0, 0.0], &[], 1.0).unwrap(), None);
        // A 2 s dropout, then wheel 1 is 20 rad further, wheels 2 and 3 −10 rad: OMR-III driving
        // 1 m along x (r = 0.05: 1/0.05 = 20 rad); mean speeds 10, −5, −5 rad/s, not wrapped.
        let sample = step(&mut d, m, &n, &[20.0, -10.0, -10.0], &[], 3.0).unwrap().unwrap();
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
        // Later differences of more than π are real too (0.1 s at 40 rad/s).
        let fast = omni_speeds(step(&mut d, m, &n, &[24.0, -14.0, -14.0], &[], 3.1).unwrap());
        for (got, want) in fast.iter().zip([40.0, -40.0, -40.0]) {
            assert!((got - want).abs() < 1e-9, "{fast:?}");
        }
    }

    #[test]
    fn a_continuous_encoder_is_not_unwrapped_before_it_has_turned_two_pi() {
        let n = names(&["wheel_1", "wheel_2", "wheel_3"]);
        let m = ChassisModel::Omni;
        let mut d = FeedbackDecoder::default();
        step(&mut d, m, &n, &[0.0, 0.0, 0.0], &[], 1.0).unwrap();
        // 4 rad in 0.2 s is 20 rad/s; unwrapped it would read (4 − 2π)/0.2 = −11.416 rad/s.
        let speeds = omni_speeds(step(&mut d, m, &n, &[4.0, -2.0, -2.0], &[], 1.2).unwrap());
        for (got, want) in speeds.iter().zip([20.0, -10.0, -10.0]) {
            assert!((got - want).abs() < 1e-9, "{speeds:?}");
        }
    }

    #[test]
    fn one_stray_reading_does_not_stop_a_wrapped_encoder_unwrapping() {
        let n = names(&["wheel_1", "wheel_2", "wheel_3"]);
        let m = ChassisModel::Omni;
        let mut d = FeedbackDecoder::new(true);
        // A glitch of 100 rad on wheel 1, then ordinary wrapped readings.
        step(&mut d, m, &n, &[100.0, 0.0, 0.0], &[], 1.0).unwrap();
        step(&mut d, m, &n, &[3.0, 0.0, 0.0], &[], 1.1).unwrap();
        // 3.0 → 3.4 − 2π = −2.883185 in 0.1 s: +0.4 rad, 4 rad/s (not the raw −58.83 rad/s).
        let speeds = omni_speeds(step(&mut d, m, &n, &[-2.883_185_307, 0.0, 0.0], &[], 1.2).unwrap());
        assert!((speeds[0] - 4.0).abs() < 1e-6, "{speeds:?}");
    }

    #[test]
    fn a_late_duplicate_or_unstamped_sample_keeps_the_baseline() {
        let n = names(&["wheel_1", "wheel_2", "wheel_3"]);
        let m = ChassisModel::Omni;
        let mut d = FeedbackDecoder::default();
        // Wheel 1 at angle 6t (6 rad/s).
        step(&mut d, m, &n, &[6.0, 0.0, 0.0], &[], 1.0).unwrap();
        step(&mut d, m, &n, &[6.12, 0.0, 0.0], &[], 1.02).unwrap();
        // Late (1.01), duplicate (1.02) and NaN stamps are refused and change nothing.
        assert!(matches!(
            step(&mut d, m, &n, &[6.06, 0.0, 0.0], &[], 1.01),
            Err(JointStateError::StampNotIncreasing { .. })
        ));
        assert!(step(&mut d, m, &n, &[6.12, 0.0, 0.0], &[], 1.02).is_err());
        assert!(matches!(
            step(&mut d, m, &n, &[6.18, 0.0, 0.0], &[], f64::NAN),
            Err(JointStateError::NonFiniteStamp(_))
        ));
        // 1.04 is measured from 1.02: (6.24 − 6.12)/0.02 = 6 rad/s over (1.02, 1.04].
        match step(&mut d, m, &n, &[6.24, 0.0, 0.0], &[], 1.04).unwrap() {
            Some(FeedbackSample::Travelled {
                wheels: WheelState::Omni { wheels },
                since,
                stamp,
                ..
            }) => {
                assert_eq!((since, stamp), (1.02, 1.04));
                assert!((wheels[0] - 6.0).abs() < 1e-9, "{wheels:?}");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn an_uncommitted_sample_leaves_the_baseline() {
        let n = names(&["wheel_1", "wheel_2", "wheel_3"]);
        let m = ChassisModel::Omni;
        let mut d = FeedbackDecoder::default();
        step(&mut d, m, &n, &[0.0, 0.0, 0.0], &[], 1.0).unwrap();
        // Decoded but not committed (the caller refused it).
        let refused = d.decode(m, &n, &[50.0, 0.0, 0.0], &[], 1.1, 0.5).unwrap();
        assert!(refused.sample().is_some());
        // The next one spans (1.0, 1.2]: 1.2 rad in 0.2 s = 6 rad/s.
        let speeds = omni_speeds(step(&mut d, m, &n, &[1.2, 0.0, 0.0], &[], 1.2).unwrap());
        assert!((speeds[0] - 6.0).abs() < 1e-9, "{speeds:?}");
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
