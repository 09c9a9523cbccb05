//! Odometry golden answers (straight line, pure rotation, exact arc) and refusals.

use std::f64::consts::{FRAC_PI_2, PI};

use approx::assert_relative_eq;
use mobil_chassis::odometry::integrate_pose;
use mobil_chassis::{BodyTwist, ChassisError, Odometry, OdometryError, OdometryNoise};
use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;

fn odom() -> Odometry {
    Odometry::new(0.0, OdometryNoise::default()).unwrap()
}

#[test]
fn straight_line() {
    // v = 0.5 m/s, ten steps of 0.1 s → x = 0.5, y = 0, ϑ = 0.
    let mut o = odom();
    for _ in 0..10 {
        o.update(BodyTwist::new(0.5, 0.0, 0.0), 0.1).unwrap();
    }
    assert_relative_eq!(o.pose(), Vector3::new(0.5, 0.0, 0.0), epsilon = 1e-12);
}

#[test]
fn pure_rotation() {
    // ω = 1 rad/s for π/2 s → ϑ = π/2, no translation; in one step and in 100.
    let mut one = odom();
    one.update(BodyTwist::new(0.0, 0.0, 1.0), FRAC_PI_2).unwrap();
    assert_relative_eq!(one.pose(), Vector3::new(0.0, 0.0, FRAC_PI_2), epsilon = 1e-12);
    let mut many = odom();
    for _ in 0..100 {
        many.update(BodyTwist::new(0.0, 0.0, 1.0), FRAC_PI_2 / 100.0).unwrap();
    }
    assert_relative_eq!(many.pose(), Vector3::new(0.0, 0.0, FRAC_PI_2), epsilon = 1e-12);
}

#[test]
fn exact_arc_in_one_step_and_in_many() {
    // v = 0.5, ω = 0.5 for 2 s: θ = 1, x = (v/ω)·sin 1 = 0.841471, y = (v/ω)·(1 − cos 1) = 0.459698.
    let expected = Vector3::new(0.841_470_984_807_896_5, 0.459_697_694_131_860_2, 1.0);
    let twist = BodyTwist::new(0.5, 0.0, 0.5);
    let mut one = odom();
    one.update(twist, 2.0).unwrap();
    assert_relative_eq!(one.pose(), expected, epsilon = 1e-9);
    let mut many = odom();
    for _ in 0..1000 {
        many.update(twist, 0.002).unwrap();
    }
    assert_relative_eq!(many.pose(), expected, epsilon = 1e-9);
}

#[test]
fn exact_arc_with_lateral_velocity() {
    // Omni drifting left at vy = 0.5 while turning at ω = 0.5 for 2 s: the same circle turned by
    // 90°: x = −(1 − cos 1) = −0.459698, y = sin 1 = 0.841471.
    let mut o = odom();
    o.update(BodyTwist::new(0.0, 0.5, 0.5), 2.0).unwrap();
    assert_relative_eq!(
        o.pose(),
        Vector3::new(-0.459_697_694_131_860_2, 0.841_470_984_807_896_5, 1.0),
        epsilon = 1e-9
    );
}

#[test]
fn full_circle_heading_wraps() {
    // ω = 1 for 3π/2 s → ϑ = 3π/2 wrapped to −π/2; v = 1 → back on the circle at (−1, 1).
    let mut o = odom();
    o.update(BodyTwist::new(1.0, 0.0, 1.0), 1.5 * PI).unwrap();
    assert_relative_eq!(o.pose(), Vector3::new(-1.0, 1.0, -FRAC_PI_2), epsilon = 1e-12);
}

#[test]
fn tiny_omega_agrees_with_the_straight_line() {
    // ω = 1e-12: y = v·ω·t²/2 = 2.5e-13, i.e. the straight line to 1e-12.
    let mut o = odom();
    for _ in 0..10 {
        o.update(BodyTwist::new(0.5, 0.0, 1e-12), 0.1).unwrap();
    }
    let p = o.pose();
    assert_relative_eq!(p, Vector3::new(0.5, 0.0, 0.0), epsilon = 1e-12);
    assert!(p.y > 0.0 && p.y.is_finite());
    // Both sides of the series threshold (1e-4) and a large angle, against S = sin a / a and
    // C = (1 − cos a) / a summed to 50 digits: x = S, y = C for v = 1, dt = 1.
    for (a, s, c) in [
        (0.99e-4, 0.999_999_998_366_5, 4.949_999_995_957_088e-5),
        (1.01e-4, 0.999_999_998_299_833_3, 5.049_999_995_707_079e-5),
        (0.5, 0.958_851_077_208_406, 0.244_834_876_219_254_57),
    ] {
        let q = integrate_pose(&Vector3::zeros(), BodyTwist::new(1.0, 0.0, a), 1.0);
        assert_relative_eq!(q.x, s, max_relative = 1e-14);
        assert_relative_eq!(q.y, c, max_relative = 1e-14);
    }
}

#[test]
fn bad_dt_and_nan_are_refused_and_leave_the_state_unchanged() {
    let mut o = odom();
    o.update(BodyTwist::new(0.5, 0.0, 0.2), 0.1).unwrap();
    let before = o.clone();
    let t = BodyTwist::new(0.5, 0.0, 0.0);
    assert_eq!(o.update(t, 0.0), Err(OdometryError::NonPositiveDt(0.0)));
    assert_eq!(o.update(t, -0.1), Err(OdometryError::NonPositiveDt(-0.1)));
    assert!(matches!(o.update(t, f64::NAN), Err(OdometryError::NonFiniteDt(_))));
    assert!(matches!(
        o.update(BodyTwist::new(f64::NAN, 0.0, 0.0), 0.1),
        Err(OdometryError::NonFiniteTwist(_))
    ));
    assert_eq!(o, before);
}

#[test]
fn timestamped_updates_refuse_time_going_backwards() {
    let mut o = odom();
    let t = BodyTwist::new(0.5, 0.0, 0.0);
    o.update_at(t, 10.0).unwrap(); // first stamp: no motion yet
    assert_eq!(o.pose(), Vector3::zeros());
    o.update_at(t, 10.5).unwrap();
    assert_relative_eq!(o.pose().x, 0.25, epsilon = 1e-12);
    let before = o.clone();
    assert_eq!(
        o.update_at(t, 10.5),
        Err(OdometryError::TimeNotIncreasing {
            previous: 10.5,
            now: 10.5
        })
    );
    assert_eq!(
        o.update_at(t, 10.0),
        Err(OdometryError::TimeNotIncreasing {
            previous: 10.5,
            now: 10.0
        })
    );
    assert!(matches!(o.update_at(t, f64::NAN), Err(OdometryError::NonFiniteTime(_))));
    assert_eq!(o, before);
    o.update_at(t, 11.5).unwrap();
    assert_relative_eq!(o.pose().x, 0.75, epsilon = 1e-12);
}

#[test]
fn covariance_grows_with_distance_and_couples_heading_to_lateral() {
    // Default noise k_s = 1e-4, k_c = 1e-5, k_ϑs = 1e-4 per metre. Two straight steps of 0.5 m:
    // step 1: P1 = diag(5e-5, 5e-6, 5e-5);
    // step 2: F = [[1,0,0],[0,1,0.5],[0,0,1]] → F·P1·Fᵀ = [[5e-5,0,0],[0,5e-6+0.25·5e-5,2.5e-5],
    // [0,2.5e-5,5e-5]], plus Q again: xx 1e-4, yy 2.25e-5, yϑ 2.5e-5, ϑϑ 1e-4.
    let mut o = odom();
    o.update(BodyTwist::new(0.5, 0.0, 0.0), 1.0).unwrap();
    o.update(BodyTwist::new(0.5, 0.0, 0.0), 1.0).unwrap();
    let expected = Matrix3::new(1e-4, 0.0, 0.0, 0.0, 2.25e-5, 2.5e-5, 0.0, 2.5e-5, 1e-4);
    assert_relative_eq!(o.covariance(), expected, epsilon = 1e-15);
}

#[test]
fn covariance_of_a_rotation_in_place() {
    // ω = 1 for π/2 s: only heading noise, k_ϑ·π/2 = 1e-3·1.570796 = 1.570796e-3.
    let mut o = odom();
    o.update(BodyTwist::new(0.0, 0.0, 1.0), FRAC_PI_2).unwrap();
    let expected = Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.570_796_326_794_896_6e-3);
    assert_relative_eq!(o.covariance(), expected, epsilon = 1e-15);
}

#[test]
fn reference_point_pose_twist_and_covariance() {
    // d = 0.3; the reference point starts at the odom origin, so the kinematic origin starts at
    // (−0.3, 0). Drive 0.5 m straight then turn in place by π/2: origin (0.2, 0, π/2),
    // reference (0.2, 0.3, π/2).
    let mut o = Odometry::new(0.3, OdometryNoise::default()).unwrap();
    o.update(BodyTwist::new(0.5, 0.0, 0.0), 1.0).unwrap();
    o.update(BodyTwist::new(0.0, 0.0, 1.0), FRAC_PI_2).unwrap();
    assert_relative_eq!(o.pose(), Vector3::new(0.2, 0.0, FRAC_PI_2), epsilon = 1e-12);
    assert_relative_eq!(o.reference_pose(), Vector3::new(0.2, 0.3, FRAC_PI_2), epsilon = 1e-12);
    let iso = o.odom_from_base();
    assert_relative_eq!(iso.translation.vector.x, 0.2, epsilon = 1e-12);
    assert_relative_eq!(iso.translation.vector.y, 0.3, epsilon = 1e-12);
    assert_relative_eq!(iso.rotation.angle(), FRAC_PI_2, epsilon = 1e-12);
    // Twist at the reference: vy = ω·d = 0.3.
    assert_relative_eq!(
        o.reference_twist().as_vector(),
        Vector3::new(0.0, 0.3, 1.0),
        epsilon = 1e-15
    );
    // At ϑ = π/2, J = [[1,0,−0.3],[0,1,0],[0,0,1]]: xx_ref = xx − 2·0.3·xϑ + 0.09·ϑϑ.
    let p = o.covariance();
    let r = o.reference_covariance();
    assert_relative_eq!(
        r[(0, 0)],
        p[(0, 0)] - 0.6 * p[(0, 2)] + 0.09 * p[(2, 2)],
        epsilon = 1e-15
    );
    assert_relative_eq!(r[(1, 1)], p[(1, 1)], epsilon = 1e-15);
    // Twist covariance at the reference: var(vy + d·ω) = 1e-3 + 0.09·1e-3.
    assert_relative_eq!(o.reference_twist_covariance()[(1, 1)], 1.09e-3, epsilon = 1e-15);
}

#[test]
fn reset_returns_to_the_origin() {
    let mut o = odom();
    o.update_at(BodyTwist::new(0.5, 0.0, 0.3), 1.0).unwrap();
    o.update_at(BodyTwist::new(0.5, 0.0, 0.3), 2.0).unwrap();
    o.reset();
    assert_eq!(o, odom());
    o.reset_to(Vector3::new(1.0, 2.0, 4.0)).unwrap();
    assert_relative_eq!(o.pose(), Vector3::new(1.0, 2.0, 4.0 - 2.0 * PI), epsilon = 1e-15);
    let before = o.clone();
    assert!(o.reset_to(Vector3::new(f64::NAN, 0.0, 0.0)).is_err());
    assert!(o.reset_to(Vector3::new(0.0, f64::INFINITY, 0.0)).is_err());
    assert_eq!(o, before);
}

#[test]
fn bad_noise_or_offset_is_refused() {
    let noise = OdometryNoise {
        heading_var_per_rad: -1.0,
        ..OdometryNoise::default()
    };
    assert!(matches!(
        Odometry::new(0.0, noise),
        Err(ChassisError::InvalidParameter {
            name: "heading_var_per_rad",
            ..
        })
    ));
    assert!(Odometry::new(f64::NAN, OdometryNoise::default()).is_err());
}

#[test]
fn an_absurd_but_finite_twist_cannot_poison_the_state() {
    // After 0.5 m straight the heading variance is k_ϑs·0.5 = 5e-5 rad². Then 1e306 m/s for 1 s:
    // F·P·Fᵀ gets Δx²·5e-5 = 1e612·5e-5, which overflows: refused, nothing changes.
    let mut o = odom();
    o.update(BodyTwist::new(0.5, 0.0, 0.0), 1.0).unwrap();
    assert_relative_eq!(o.covariance()[(2, 2)], 5e-5, epsilon = 1e-18);
    let before = o.clone();
    let absurd = BodyTwist::new(1e306, 0.0, 0.0);
    assert!(matches!(
        o.update(absurd, 1.0),
        Err(OdometryError::NonFiniteResult { .. })
    ));
    assert_eq!(o, before);
    // From a fresh start (zero covariance) the same step is representable (x = 1e306 m, variances
    // k·1e306): the odometry promises finiteness, plausibility is the controller's check. The
    // next one overflows and is refused.
    let mut fresh = odom();
    fresh.update(absurd, 1.0).unwrap();
    assert_eq!(fresh.pose().x, 1e306);
    let kept = fresh.clone();
    assert!(fresh.update(absurd, 1.0).is_err());
    assert_eq!(fresh, kept);
    // 1e308 m/s over 10 s overflows the step itself.
    assert!(matches!(
        o.update(BodyTwist::new(1e308, 1e308, 0.0), 10.0),
        Err(OdometryError::NonFiniteResult { .. })
    ));
    assert_eq!(o, before);
}

#[test]
fn update_over_integrates_an_interval_whatever_the_previous_stamp() {
    let mut o = odom();
    o.update_at(BodyTwist::ZERO, 1.0).unwrap();
    // 0.5 m/s over (1.0, 3.0]: 1 m, then the stamp is 3.0.
    o.update_over(BodyTwist::new(0.5, 0.0, 0.0), 1.0, 3.0).unwrap();
    assert_relative_eq!(o.pose(), Vector3::new(1.0, 0.0, 0.0), epsilon = 1e-12);
    assert_eq!(o.last_stamp(), Some(3.0));
    // A clock reset: an interval before the last stamp is still a real distance.
    o.update_over(BodyTwist::new(0.5, 0.0, 0.0), 0.0, 0.2).unwrap();
    assert_relative_eq!(o.pose(), Vector3::new(1.1, 0.0, 0.0), epsilon = 1e-12);
    let before = o.clone();
    assert!(o.update_over(BodyTwist::new(0.5, 0.0, 0.0), 0.2, 0.2).is_err());
    assert!(o.update_over(BodyTwist::new(0.5, 0.0, 0.0), f64::NAN, 0.3).is_err());
    assert!(o.update_over(BodyTwist::new(f64::NAN, 0.0, 0.0), 0.2, 0.3).is_err());
    assert_eq!(o, before);
}

/// Any f64: mostly ordinary values, but also huge, tiny, infinite and NaN.
fn any_number() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -10.0..10.0f64,
        2 => prop::num::f64::ANY,
        1 => prop::sample::select(vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
            1e308,
            -1e308,
            1e-308,
            0.0
        ]),
    ]
}

proptest! {
    #[test]
    fn no_update_ever_makes_the_odometry_non_finite(
        d in -1.0..1.0f64,
        steps in prop::collection::vec((any_number(), any_number(), any_number(), any_number()), 1..30),
    ) {
        let mut o = Odometry::new(d, OdometryNoise::default()).unwrap();
        for (vx, vy, wz, dt) in steps {
            let _ = o.update(BodyTwist::new(vx, vy, wz), dt);
            let _ = o.update_at(BodyTwist::new(vx, vy, wz), dt);
            let finite = |m: &[f64]| m.iter().all(|v| v.is_finite());
            prop_assert!(finite(o.pose().as_slice()) && finite(o.reference_pose().as_slice()));
            prop_assert!(finite(o.covariance().as_slice()) && finite(o.reference_covariance().as_slice()));
        }
    }
}
