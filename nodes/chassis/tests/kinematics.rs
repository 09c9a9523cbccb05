//! Forward/inverse kinematics: golden values worked out by hand, and round-trip properties.

use std::f64::consts::PI;

use approx::{assert_relative_eq, relative_eq};
use mobil_chassis::kinematics::{pose_at_origin, pose_at_reference, twist_at_origin, twist_at_reference};
use mobil_chassis::{forward, inverse, pre_steer, BodyTwist, ChassisError, ChassisModel, ChassisParams, WheelState};
use nalgebra::{Isometry2, Translation2, Vector2, Vector3};
use proptest::prelude::*;

fn assert_values(state: &WheelState, expected: &[f64]) {
    let values = state.values();
    assert_eq!(values.len(), expected.len(), "{state:?}");
    for (v, e) in values.iter().zip(expected) {
        assert_relative_eq!(*v, *e, epsilon = 1e-12);
    }
}

#[test]
fn omni_pure_body_x_translation() {
    // v = 0.3, r = 0.05: Ω = (v/r)·[1, −½, −½] = 6·[1, −0.5, −0.5].
    let w = inverse(&ChassisParams::omr3(), BodyTwist::new(0.3, 0.0, 0.0));
    assert_values(&w, &[6.0, -3.0, -3.0]);
}

#[test]
fn omni_pure_body_y_translation() {
    // v_w = 0.3: r·ω_i = sin θ_i·0.3 → ω = 6·[0, √3/2, −√3/2].
    let w = inverse(&ChassisParams::omr3(), BodyTwist::new(0.0, 0.3, 0.0));
    assert_values(&w, &[0.0, 5.196_152_422_706_632, -5.196_152_422_706_632]);
}

#[test]
fn omni_pure_rotation_turns_all_wheels_equally() {
    // ω = 1 rad/s, R = 0.20, r = 0.05: every wheel R·ω / r = 4 rad/s.
    let p = ChassisParams::omr3();
    let w = inverse(&p, BodyTwist::new(0.0, 0.0, 1.0));
    assert_values(&w, &[4.0, 4.0, 4.0]);
    // And back: ϑ̇ = r·Σω / (3R) = 0.05·12 / 0.6 = 1.
    let t = forward(&p, &w).unwrap();
    assert_relative_eq!(t.as_vector(), Vector3::new(0.0, 0.0, 1.0), epsilon = 1e-12);
}

#[test]
fn car_like_ackermann_for_a_one_metre_left_turn() {
    // R = 1 m at the rear-axle midpoint, L = 0.6, B = 0.62, v = 0.5, ω = v/R = 0.5:
    // δ_l = atan(0.6 / 0.69) = 0.715744, δ_r = atan(0.6 / 1.31) = 0.429499,
    // rear wheels (v ∓ ω·B/2) / r = (0.5 ∓ 0.155) / 0.1 = 3.45, 6.55 rad/s.
    let w = inverse(&ChassisParams::mobil2(), BodyTwist::new(0.5, 0.0, 0.5));
    assert_values(&w, &[0.715_743_589_668_880_2, 0.429_499_397_925_036_44, 3.45, 6.55]);
}

#[test]
fn car_like_right_turn_mirrors_the_left_turn() {
    let w = inverse(&ChassisParams::mobil2(), BodyTwist::new(0.5, 0.0, -0.5));
    assert_values(&w, &[-0.429_499_397_925_036_44, -0.715_743_589_668_880_2, 6.55, 3.45]);
}

#[test]
fn car_like_straight_and_stopped() {
    let p = ChassisParams::mobil2();
    assert_values(&inverse(&p, BodyTwist::new(0.4, 0.0, 0.0)), &[0.0, 0.0, 4.0, 4.0]);
    // v = 0 with ω ≠ 0 is infeasible: inverse ignores ω (clamp first).
    assert_values(&inverse(&p, BodyTwist::new(0.0, 0.0, 0.3)), &[0.0; 4]);
}

#[test]
fn car_like_forward_from_a_parallel_not_ackermann_steering_pair() {
    // Both front wheels at 0.3 rad (a worn linkage: not an Ackermann pair). Each wheel alone
    // implies tan δ_c: from the left tan δ / (1 + k·tan δ), from the right tan δ / (1 − k·tan δ),
    // k = B/(2L) = 0.62/1.2; their mean is 0.317444944008083 (worked out separately).
    // Rear wheels 4 and 5 rad/s with r = 0.1: v = 0.45 m/s, ω = v·tan δ_c / L = 0.238083708006063.
    let params = ChassisParams::mobil2();
    let wheels = WheelState::CarLike {
        front_left_steering: 0.3,
        front_right_steering: 0.3,
        rear_left: 4.0,
        rear_right: 5.0,
    };
    let t = forward(&params, &wheels).unwrap();
    assert_relative_eq!(t.vx, 0.45, epsilon = 1e-12);
    assert_relative_eq!(t.wz, 0.238_083_708_006_062_57, epsilon = 1e-12);
    assert_eq!(t.vy, 0.0);
}

#[test]
fn tricycle_golden() {
    // L = 0.5, v = 0.4, ω = 0.4: δ = atan(0.5·0.4/0.4) = atan(0.5) = 0.463648;
    // front ground speed v / cos δ = hypot(0.4, 0.2) = 0.447214 → 4.472136 rad/s (r = 0.1).
    let p = ChassisParams::tricycle();
    let w = inverse(&p, BodyTwist::new(0.4, 0.0, 0.4));
    assert_values(&w, &[0.463_647_609_000_806_1, 4.472_135_954_999_58]);
    // Reversing on the same circle: steering the same way, wheel backwards, ω negative.
    let w = inverse(&p, BodyTwist::new(-0.4, 0.0, -0.4));
    assert_values(&w, &[0.463_647_609_000_806_1, -4.472_135_954_999_58]);
}

#[test]
fn pre_steer_gives_ackermann_angles_at_rest() {
    let p = ChassisParams::mobil2();
    // δ_c = δ_eff: R = 0.73 → δ_l = atan(0.6 / 0.42), δ_r = atan(0.6 / 1.04).
    let w = pre_steer(&p, p.effective_steering_limit());
    assert_values(&w, &[0.960_070_362_405_688, 0.523_278_322_131_975_4, 0.0, 0.0]);
    assert_values(&pre_steer(&ChassisParams::tricycle(), 0.3), &[0.3, 0.0]);
}

#[test]
fn forward_refuses_other_models_and_nan() {
    let p = ChassisParams::mobil2();
    assert_eq!(
        forward(&p, &WheelState::zero(ChassisModel::Omni)),
        Err(ChassisError::ModelMismatch {
            expected: ChassisModel::CarLike,
            got: ChassisModel::Omni
        })
    );
    let bad = WheelState::CarLike {
        front_left_steering: 0.0,
        front_right_steering: f64::NAN,
        rear_left: 1.0,
        rear_right: 1.0,
    };
    assert!(matches!(
        forward(&p, &bad),
        Err(ChassisError::NonFiniteJoint {
            joint: "front_right_steering",
            ..
        })
    ));
}

#[test]
fn joint_values_parse_by_layout() {
    let names: Vec<_> = ChassisModel::CarLike.joints().iter().map(|j| j.name).collect();
    assert_eq!(
        names,
        [
            "front_left_steering",
            "front_right_steering",
            "rear_left_wheel",
            "rear_right_wheel"
        ]
    );
    assert_eq!(
        WheelState::from_values(ChassisModel::Tricycle, &[0.1, 2.0]),
        Ok(WheelState::Tricycle {
            steering: 0.1,
            traction: 2.0
        })
    );
    assert_eq!(
        WheelState::from_values(ChassisModel::Omni, &[1.0, 2.0]),
        Err(ChassisError::JointCount {
            model: ChassisModel::Omni,
            expected: 3,
            got: 2
        })
    );
    assert!(matches!(
        WheelState::from_values(ChassisModel::Omni, &[1.0, f64::INFINITY, 2.0]),
        Err(ChassisError::NonFiniteJoint { joint: "wheel_2", .. })
    ));
}

#[test]
fn reference_point_twist_and_pose() {
    // ω = 0.5, d = 0.3: the point ahead moves sideways at 0.15 m/s (cf. 004 eq. 3.12).
    let t = twist_at_reference(BodyTwist::new(0.4, 0.0, 0.5), 0.3);
    assert_relative_eq!(t.as_vector(), Vector3::new(0.4, 0.15, 0.5), epsilon = 1e-15);
    // Heading 90°: the point 0.3 ahead of (1, 2) is (1, 2.3).
    let p = pose_at_reference(&Vector3::new(1.0, 2.0, std::f64::consts::FRAC_PI_2), 0.3);
    assert_relative_eq!(p, Vector3::new(1.0, 2.3, std::f64::consts::FRAC_PI_2), epsilon = 1e-15);
}

fn nonholonomic_twist(p: ChassisParams) -> impl Strategy<Value = BodyTwist> {
    let (v_max, k_max) = (p.v_max(), p.max_curvature());
    (-v_max..=v_max, -k_max..=k_max).prop_map(|(v, k)| BodyTwist::new(v, 0.0, v * k))
}

fn round_trips(p: &ChassisParams, t: BodyTwist) -> bool {
    let back = forward(p, &inverse(p, t)).unwrap();
    relative_eq!(back.as_vector(), t.as_vector(), epsilon = 1e-9)
}

proptest! {
    #[test]
    fn car_like_forward_inverse_is_identity(t in nonholonomic_twist(ChassisParams::mobil2())) {
        prop_assert!(round_trips(&ChassisParams::mobil2(), t), "{t:?}");
    }

    #[test]
    fn tricycle_forward_inverse_is_identity(t in nonholonomic_twist(ChassisParams::tricycle())) {
        prop_assert!(round_trips(&ChassisParams::tricycle(), t), "{t:?}");
    }

    #[test]
    fn omni_forward_inverse_is_identity(vx in -2.0..2.0f64, vy in -2.0..2.0f64, wz in -5.0..5.0f64) {
        prop_assert!(round_trips(&ChassisParams::omr3(), BodyTwist::new(vx, vy, wz)));
    }

    #[test]
    fn omni_inverse_forward_is_identity(w in prop::array::uniform3(-20.0..20.0f64)) {
        let p = ChassisParams::omr3();
        let wheels = WheelState::Omni { wheels: w };
        let back = inverse(&p, forward(&p, &wheels).unwrap());
        prop_assert!(relative_eq!(
            Vector3::from(back.values().as_slice().try_into().unwrap_or([f64::NAN; 3])),
            Vector3::from(w),
            epsilon = 1e-9
        ));
    }

    #[test]
    fn car_like_steering_stays_within_ninety_degrees(t in nonholonomic_twist(ChassisParams::mobil2())) {
        let values = inverse(&ChassisParams::mobil2(), t).values();
        // Inner wheel at R_eff = 0.73: atan(0.6 / 0.42) = 0.96 rad.
        prop_assert!(values[0].abs() <= 0.960_070_362_405_689 && values[1].abs() <= 0.960_070_362_405_689);
    }

    #[test]
    fn reference_shift_round_trips(
        x in -10.0..10.0f64, y in -10.0..10.0f64, th in -PI..PI,
        vx in -1.0..1.0f64, vy in -1.0..1.0f64, wz in -2.0..2.0f64, d in -1.0..1.0f64,
    ) {
        let pose = Vector3::new(x, y, th);
        prop_assert!(relative_eq!(pose_at_origin(&pose_at_reference(&pose, d), d), pose, epsilon = 1e-9));
        let t = BodyTwist::new(vx, vy, wz);
        prop_assert!(relative_eq!(
            twist_at_origin(twist_at_reference(t, d), d).as_vector(), t.as_vector(), epsilon = 1e-9
        ));
        // Frame composition: odom_from_reference = odom_from_origin · origin_from_reference.
        let odom_from_origin = Isometry2::new(Vector2::new(x, y), th);
        let composed = odom_from_origin * Translation2::new(d, 0.0);
        let r = pose_at_reference(&pose, d);
        prop_assert!(relative_eq!(composed.translation.vector, Vector2::new(r.x, r.y), epsilon = 1e-9));
    }
}
