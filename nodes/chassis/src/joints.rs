//! `sensor_msgs/JointState` ↔ [`WheelState`]: the wire layout of `wheel_commands` and
//! `joint_states`, checked once at the edge ("parse, don't validate").
//!
//! Joints are matched by name ([`ChassisModel::joints`]), in any order; other joints in the
//! message (an arm, a pan-tilt) are ignored. A steering joint carries its angle in `position`,
//! a wheel joint its speed in `velocity` (rad/s). `position` and `velocity` must each be empty
//! or as long as `name`, as the message definition requires.
//!
//! Feedback may carry wheel speeds (`velocity`) or only encoder angles (`position`, as many
//! drivers publish): [`FeedbackDecoder`] then differentiates the angles between samples.
//!
//! Commands (`wheel_commands`) list every joint of the model; steering joints get the angle in
//! `position` and 0 in `velocity`, wheel joints the speed in `velocity` and 0 in `position`.

use thiserror::Error;

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

/// Turns successive `joint_states` into [`WheelState`]s, from wheel speeds when the message has
/// them, else from the change of the wheel angles since the previous sample.
#[derive(Debug, Clone, Default)]
pub struct FeedbackDecoder {
    /// Stamp (s) and wheel-joint angles of the previous position-only sample.
    previous: Option<(f64, Vec<f64>)>,
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
    ) -> Result<Option<WheelState>, JointStateError> {
        if !velocities.is_empty() || positions.is_empty() {
            self.previous = None;
            return wheel_state_from_joints(model, names, positions, velocities).map(Some);
        }
        // Positions only: read every joint's angle, then differentiate the wheels'.
        let angles = wheel_state_from_joints(model, names, positions, positions)?.values();
        let wheel_angles: Vec<f64> = model
            .joints()
            .iter()
            .zip(&angles)
            .filter(|(j, _)| j.kind == JointKind::Wheel)
            .map(|(_, a)| *a)
            .collect();
        let previous = self.previous.replace((stamp, wheel_angles.clone()));
        let Some((t0, before)) = previous else { return Ok(None) };
        let dt = stamp - t0;
        if !(dt > 0.0 && dt.is_finite()) {
            return Ok(None);
        }
        let mut speeds = wheel_angles.iter().zip(&before).map(|(a, b)| (a - b) / dt);
        let values: Vec<f64> = model
            .joints()
            .iter()
            .zip(angles)
            .map(|(j, angle)| match j.kind {
                JointKind::Steering => angle,
                JointKind::Wheel => speeds.next().unwrap_or(0.0),
            })
            .collect();
        WheelState::from_values(model, &values)
            .map(Some)
            .map_err(|_| JointStateError::MismatchedLengths {
                names: names.len(),
                positions: positions.len(),
                velocities: velocities.len(),
            })
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
        let s = d.decode(m, &n, &[0.1, 0.08, 10.6, 20.7], &[], 5.1).unwrap().unwrap();
        match s {
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
        assert_eq!(v.values()[2], 1.0);
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
