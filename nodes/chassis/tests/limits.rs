//! Command limits: golden cases and feasibility/idempotence properties.

use approx::{assert_relative_eq, relative_eq};
use mobil_chassis::kinematics::ackermann_centre_tan;
use mobil_chassis::{
    clamp_at_reference, clamp_command, inverse, BodyTwist, ChassisConfig, ChassisParams, ClampReason, ClampReasons,
    WheelState,
};
use nalgebra::Vector3;
use proptest::prelude::*;

fn reasons(list: &[ClampReason]) -> ClampReasons {
    list.iter().copied().collect()
}

#[test]
fn turning_in_place_on_a_car_becomes_a_stop_with_pre_steer() {
    let p = ChassisParams::mobil2();
    let c = clamp_command(&p, BodyTwist::new(0.0, 0.0, 0.5));
    assert_eq!(c.twist, BodyTwist::ZERO);
    assert_eq!(c.reasons, reasons(&[ClampReason::MinRadius]));
    // δ = sign(ω)·δ_eff = atan(0.6 / 0.73).
    assert_relative_eq!(c.pre_steer.unwrap(), 0.687_963_312_105_192_1, epsilon = 1e-12);
    let c = clamp_command(&p, BodyTwist::new(0.0, 0.0, -0.5));
    assert_relative_eq!(c.pre_steer.unwrap(), -0.687_963_312_105_192_1, epsilon = 1e-12);
}

#[test]
fn lateral_velocity_is_dropped_on_non_holonomic_chassis() {
    for p in [ChassisParams::mobil2(), ChassisParams::tricycle()] {
        let c = clamp_command(&p, BodyTwist::new(0.3, 0.2, 0.0));
        assert_eq!(c.twist, BodyTwist::new(0.3, 0.0, 0.0));
        assert_eq!(c.reasons, reasons(&[ClampReason::Lateral]));
        assert_eq!(c.pre_steer, None);
    }
}

#[test]
fn omni_keeps_lateral_velocity() {
    let c = clamp_command(&ChassisParams::omr3(), BodyTwist::new(0.0, 0.3, 0.0));
    assert_eq!(c.twist, BodyTwist::new(0.0, 0.3, 0.0));
    assert!(c.reasons.is_empty());
}

#[test]
fn non_finite_request_becomes_zero() {
    for p in [
        ChassisParams::mobil2(),
        ChassisParams::omr3(),
        ChassisParams::tricycle(),
    ] {
        for bad in [
            BodyTwist::new(f64::NAN, 0.0, 0.0),
            BodyTwist::new(0.1, f64::INFINITY, 0.0),
            BodyTwist::new(0.1, 0.0, f64::NEG_INFINITY),
        ] {
            let c = clamp_command(&p, bad);
            assert_eq!(c.twist, BodyTwist::ZERO);
            assert_eq!(c.reasons.bits(), 1);
        }
    }
}

#[test]
fn speed_is_saturated_keeping_sign() {
    let p = ChassisParams::mobil2();
    let c = clamp_command(&p, BodyTwist::new(-1.0, 0.0, 0.0));
    assert_eq!(c.twist, BodyTwist::new(-0.5, 0.0, 0.0));
    assert_eq!(c.reasons, reasons(&[ClampReason::Speed]));
    // Omni: (0.6, 0.8) has speed 1 → scaled to 0.5 keeping the direction: (0.3, 0.4).
    let c = clamp_command(&ChassisParams::omr3(), BodyTwist::new(0.6, 0.8, 0.0));
    assert_relative_eq!(c.twist.as_vector(), Vector3::new(0.3, 0.4, 0.0), epsilon = 1e-15);
    assert_eq!(c.reasons, reasons(&[ClampReason::Speed]));
}

#[test]
fn turn_rate_is_saturated() {
    // Omni ω_max = 1.5; wheels then turn at 1.5·0.2/0.05 = 6 rad/s < 12.
    let c = clamp_command(&ChassisParams::omr3(), BodyTwist::new(0.0, 0.0, -3.0));
    assert_eq!(c.twist, BodyTwist::new(0.0, 0.0, -1.5));
    assert_eq!(c.reasons, reasons(&[ClampReason::TurnRate]));
}

#[test]
fn curvature_is_clamped_at_fixed_speed() {
    // v = 0.5: |ω| ≤ 0.5 / R_min = 0.5 / 0.73 = 0.684932.
    let c = clamp_command(&ChassisParams::mobil2(), BodyTwist::new(0.5, 0.0, 1.0));
    assert_relative_eq!(
        c.twist.as_vector(),
        Vector3::new(0.5, 0.0, 0.684_931_506_849_315),
        epsilon = 1e-12
    );
    assert_eq!(c.reasons, reasons(&[ClampReason::MinRadius]));
    assert_eq!(c.pre_steer, None);
}

#[test]
fn a_binding_steering_limit_bounds_the_virtual_centre_wheel_not_the_inner_one() {
    // MOBIL-II geometry (L 0.60, B 0.62) with δ_max = 30°: atan(0.60/0.73) = 39.4° > 30°, so
    // δ_max binds. SPEC §1 reads δ as the model's one (bicycle) angle: δ = 70° on L = 0.60 gives
    // R = L / tan δ = 0.22 m. v = 0.3 with ω = 1.0 (R = 0.3 m) is clamped to the curvature
    // tan 30° / 0.6 = 0.962250: ω = 0.3·0.962250 = 0.288675; R = 0.6·√3 = 1.039230.
    let p = ChassisParams::new(ChassisConfig {
        max_steering: 30f64.to_radians(),
        ..ChassisConfig::mobil2()
    })
    .unwrap();
    assert_relative_eq!(p.effective_steering_limit(), 30f64.to_radians(), epsilon = 1e-15);
    let c = clamp_command(&p, BodyTwist::new(0.3, 0.0, 1.0));
    assert_relative_eq!(c.twist.wz, 0.288_675_134_594_812_9, epsilon = 1e-12);
    assert_eq!(c.reasons, reasons(&[ClampReason::MinRadius]));
    // Ackermann: inner (left) wheel atan(0.6 / (1.039230 − 0.31)) = 39.447°, outer
    // atan(0.6 / (1.039230 + 0.31)) = 23.975°: the centre wheel sits at δ_max, the inner one
    // 9.4° beyond it.
    match inverse(&p, c.twist) {
        WheelState::CarLike {
            front_left_steering,
            front_right_steering,
            ..
        } => {
            assert_relative_eq!(front_left_steering.to_degrees(), 39.447_04, epsilon = 1e-4);
            assert_relative_eq!(front_right_steering.to_degrees(), 23.974_62, epsilon = 1e-4);
            let centre = ackermann_centre_tan(0.6, 0.62, front_left_steering, front_right_steering);
            assert_relative_eq!(centre.atan().to_degrees(), 30.0, epsilon = 1e-9);
        }
        other => panic!("{other:?}"),
    }
    // The limit for a 30° inner wheel: atan(0.6 / (1.039230 + 0.31)) = 23.975°; with it the
    // inner wheel lands exactly on 30°.
    let inner_limited = ChassisParams::new(ChassisConfig {
        max_steering: (0.6 / (0.6 / 30f64.to_radians().tan() + 0.31)).atan(),
        ..ChassisConfig::mobil2()
    })
    .unwrap();
    let c = clamp_command(&inner_limited, BodyTwist::new(0.3, 0.0, 1.0));
    match inverse(&inner_limited, c.twist) {
        WheelState::CarLike {
            front_left_steering, ..
        } => assert_relative_eq!(front_left_steering.to_degrees(), 30.0, epsilon = 1e-9),
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_command_exactly_at_the_limit_is_not_reported() {
    let p = ChassisParams::mobil2();
    let at_limit = 0.5 * p.effective_steering_limit().tan() / p.wheelbase();
    let c = clamp_command(&p, BodyTwist::new(0.5, 0.0, at_limit));
    assert!(c.reasons.is_empty(), "{}", c.reasons);
    assert_relative_eq!(c.twist.wz, at_limit, epsilon = 1e-15);
}

#[test]
fn wheel_speed_scaling_keeps_the_ratio() {
    // MOBIL-II with max wheel speed 5 rad/s; v = ω = 0.5: outer rear wheel (0.5 + 0.155)/0.1 =
    // 6.55 rad/s → factor 5/6.55 = 0.763359, v = ω = 0.381679.
    let p = ChassisParams::new(ChassisConfig {
        max_wheel_speed: 5.0,
        ..ChassisConfig::mobil2()
    })
    .unwrap();
    let c = clamp_command(&p, BodyTwist::new(0.5, 0.0, 0.5));
    assert_relative_eq!(c.twist.vx, 0.381_679_389_312_977_1, epsilon = 1e-12);
    assert_relative_eq!(c.twist.wz, 0.381_679_389_312_977_1, epsilon = 1e-12);
    assert_eq!(c.reasons, reasons(&[ClampReason::WheelSpeed]));
    assert_relative_eq!(inverse(&p, c.twist).max_abs_wheel_speed(), 5.0, epsilon = 1e-12);

    // Omni: v = 0.5, ω = 1.5 → wheel 1 at (0.5 + 0.3)/0.05 = 16 > 12 → factor 0.75.
    let c = clamp_command(&ChassisParams::omr3(), BodyTwist::new(0.5, 0.0, 1.5));
    assert_relative_eq!(c.twist.as_vector(), Vector3::new(0.375, 0.0, 1.125), epsilon = 1e-12);
    assert_eq!(c.reasons, reasons(&[ClampReason::WheelSpeed]));
}

#[test]
fn several_reasons_are_reported_together() {
    let c = clamp_command(&ChassisParams::mobil2(), BodyTwist::new(0.0, 0.1, 0.5));
    assert_eq!(c.reasons.bits(), 8 | 16);
    assert_eq!(c.reasons.to_string(), "lateral, min_radius");
}

fn feasible(p: &ChassisParams, t: BodyTwist) -> bool {
    let tol = 1.0 + 1e-12;
    let speed_ok = t.vx.hypot(t.vy) <= p.v_max() * tol;
    let turn_ok = t.wz.abs() <= p.omega_max() * tol;
    let wheels_ok = inverse(p, t).max_abs_wheel_speed() <= p.max_wheel_speed() * tol;
    let shape_ok = !p.model().is_nonholonomic() || (t.vy == 0.0 && t.wz.abs() <= t.vx.abs() * p.max_curvature() * tol);
    speed_ok && turn_ok && wheels_ok && shape_ok
}

fn any_params() -> impl Strategy<Value = ChassisParams> {
    prop_oneof![
        Just(ChassisParams::mobil2()),
        Just(ChassisParams::omr3()),
        Just(ChassisParams::tricycle()),
    ]
}

proptest! {
    #[test]
    fn clamped_commands_are_feasible_and_clamping_is_idempotent(
        p in any_params(), vx in -3.0..3.0f64, vy in -3.0..3.0f64, wz in -6.0..6.0f64,
    ) {
        let c = clamp_command(&p, BodyTwist::new(vx, vy, wz));
        prop_assert!(feasible(&p, c.twist), "{c:?}");
        let again = clamp_command(&p, c.twist);
        prop_assert!(again.reasons.is_empty(), "{again:?}");
        prop_assert!(relative_eq!(again.twist.as_vector(), c.twist.as_vector(), epsilon = 1e-12));
    }

    #[test]
    fn feasible_requests_pass_unchanged(p in any_params(), v in -1.0..1.0f64, k in -1.0..1.0f64, vy in -1.0..1.0f64) {
        // Shrink a random shape until it sits well inside every limit.
        let omni = !p.model().is_nonholonomic();
        let wz = if omni { k } else { v * k * p.max_curvature() };
        let t = BodyTwist::new(v, if omni { vy } else { 0.0 }, wz).scaled(0.2);
        prop_assume!(feasible(&p, t));
        let c = clamp_command(&p, t);
        prop_assert_eq!(c.twist, t);
        prop_assert!(c.reasons.is_empty());
    }
}

#[test]
fn a_law_s_command_at_the_reference_point_is_held_to_the_chassis_limits() {
    // OMR-III: v_max 0.5. (0.6, 0.8) m/s is 1.0 m/s: scaled to (0.3, 0.4).
    let omr3 = ChassisParams::omr3();
    let t = clamp_at_reference(&omr3, BodyTwist::new(0.6, 0.8, 0.0));
    assert_relative_eq!(t.vx, 0.3, epsilon = 1e-12);
    assert_relative_eq!(t.vy, 0.4, epsilon = 1e-12);
    // MOBIL-II with its reference point 0.30 m ahead: at v = 0.3 the tightest turn is
    // ω = 0.3 / 0.73 = 0.410959 rad/s (linear.x and angular.z are the origin's). A request
    // for ω = 2 is held to that; a linear.y (the implied ω·d, or any) is never sent.
    let mobil2 = ChassisParams::new(ChassisConfig {
        reference_offset: 0.30,
        ..ChassisConfig::mobil2()
    })
    .expect("valid");
    let t = clamp_at_reference(&mobil2, BodyTwist::new(0.3, 2.0 * 0.3, 2.0));
    assert_relative_eq!(t.vx, 0.3, epsilon = 1e-12);
    assert_relative_eq!(t.wz, 0.3 / 0.73, epsilon = 1e-9);
    assert_eq!(t.vy, 0.0);
    // A feasible command passes unchanged.
    let t = clamp_at_reference(&mobil2, BodyTwist::new(0.2, 0.0, 0.1));
    assert_eq!((t.vx, t.vy, t.wz), (0.2, 0.0, 0.1));
    // A turn in place is a stop on a car (v = 0 allows no ω).
    let t = clamp_at_reference(&mobil2, BodyTwist::new(0.0, 0.0, 0.5));
    assert_eq!((t.vx, t.wz), (0.0, 0.0));
    // An omni with its reference point 0.2 m ahead: (0.5, 0, 0.25) at the reference point is
    // (0.5, −0.05, 0.25) at the origin, |v| = 0.502494 > 0.5: the translation is scaled by
    // s = 0.995037, ω (within 1.5) kept (the fastest wheel, at most (|v| + R·ω) / r =
    // (0.5 + 0.05) / 0.05 = 11 < 12 rad/s, does not bind); back at the reference point
    // vy = −0.05·s + 0.2·0.25 = 0.05·(1 − s) = 0.000248.
    let omni = ChassisParams::new(ChassisConfig {
        reference_offset: 0.2,
        ..ChassisConfig::omr3()
    })
    .expect("valid");
    let t = clamp_at_reference(&omni, BodyTwist::new(0.5, 0.0, 0.25));
    let s = 0.5 / 0.5f64.hypot(0.05);
    assert_relative_eq!(s, 0.995_037, epsilon = 1e-6);
    assert_relative_eq!(t.vx, 0.5 * s, epsilon = 1e-9);
    assert_relative_eq!(t.vy, 0.05 * (1.0 - s), epsilon = 1e-12);
    assert_relative_eq!(t.wz, 0.25, epsilon = 1e-12);
    // Non-finite → zero.
    let t = clamp_at_reference(&omr3, BodyTwist::new(f64::NAN, 0.0, 1.0));
    assert_eq!((t.vx, t.vy, t.wz), (0.0, 0.0, 0.0));
    let t = clamp_at_reference(&mobil2, BodyTwist::new(0.1, 0.0, f64::INFINITY));
    assert_eq!((t.vx, t.vy, t.wz), (0.0, 0.0, 0.0));
}
