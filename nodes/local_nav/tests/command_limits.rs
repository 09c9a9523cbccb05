//! Property: whatever the pose, goal and scan (finite or not), every command is finite and
//! within the chassis limits, on the omni and the car-like chassis.

use mobil_chassis::ChassisParams;
use mobil_geom::{Pose2, Scan};
use mobil_local_nav::{Drive, MotionLimits, NavConfig, Navigator, VelocityCommand};
use nalgebra::Point2;
use proptest::prelude::*;

fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -50.0..50.0f64,
        1 => prop::num::f64::ANY,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
    ]
}

fn any_range() -> impl Strategy<Value = f32> {
    prop_oneof![
        6 => 0.0..12.0f32,
        1 => prop::num::f32::ANY,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::NEG_INFINITY),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn commands_are_finite_and_within_limits(
        car in any::<bool>(),
        goal in (-20.0..20.0f64, -20.0..20.0f64),
        poses in prop::collection::vec((any_f64(), any_f64(), any_f64()), 1..12),
        ranges in prop::collection::vec(any_range(), 2..200),
        laser in (-0.5..0.5f64, -0.5..0.5f64, -4.0..4.0f64),
        fov in 0.5..3.1f64,
    ) {
        let chassis = if car { ChassisParams::mobil2() } else { ChassisParams::omr3() };
        let limits = MotionLimits::from_chassis(&chassis);
        let mut nav = Navigator::new(NavConfig::default(), limits).unwrap();
        nav.set_goal(Point2::new(goal.0, goal.1)).unwrap();
        let n = ranges.len();
        let inc = 2.0 * fov / (n - 1) as f64;
        let scan = Scan::new(-fov, fov, inc, 0.05, 10.0, ranges, vec![], Pose2::new(laser.0, laser.1, laser.2)).unwrap();
        for (x, y, yaw) in poses {
            let c = nav.step(Pose2::new(x, y, yaw), &scan).command;
            prop_assert!(c.is_finite(), "{c:?}");
            prop_assert!(c.speed() <= limits.v_max + 1e-12, "{c:?}");
            prop_assert!(c.omega.abs() <= limits.omega_max + 1e-12, "{c:?}");
            if let Drive::CarLike { max_curvature } = limits.drive {
                prop_assert_eq!(c.vy, 0.0);
                prop_assert!(c.omega.abs() <= max_curvature * c.vx.abs() + 1e-12, "{c:?}");
            }
        }
    }
}

#[test]
fn commands_go_to_the_chassis_held_to_its_limits() {
    // OMR-III: v_max 0.5, ω_max 1.5. (0.6, 0.8) is 1.0 m/s: scaled by 0.5 to (0.3, 0.4).
    let omni = MotionLimits::from_chassis(&ChassisParams::omr3());
    let t = VelocityCommand {
        vx: 0.6,
        vy: 0.8,
        omega: -3.0,
    }
    .for_chassis(&omni);
    assert!((t.vx - 0.3).abs() < 1e-12 && (t.vy - 0.4).abs() < 1e-12);
    assert_eq!(t.omega, -1.5);
    // MOBIL-II: δ_eff = atan(0.60 / 0.73), κ_max = tan δ_eff / L = 1 / 0.73 = 1.36986 1/m.
    // At vx 0.2 the turn rate is held to 0.2 / 0.73 = 0.273973 rad/s; vy dropped.
    let car = MotionLimits::from_chassis(&ChassisParams::mobil2());
    let t = VelocityCommand {
        vx: 0.2,
        vy: 0.3,
        omega: 0.9,
    }
    .for_chassis(&car);
    assert_eq!((t.vx, t.vy), (0.2, 0.0));
    assert!((t.omega - 0.2 / 0.73).abs() < 1e-9, "{}", t.omega);
    // A standing car cannot turn; NaN anywhere gives the zero command.
    let t = VelocityCommand {
        vx: 0.0,
        vy: 0.0,
        omega: 0.5,
    }
    .for_chassis(&car);
    assert_eq!(t.omega, 0.0);
    let t = VelocityCommand {
        vx: f64::NAN,
        vy: 0.0,
        omega: 0.1,
    }
    .for_chassis(&omni);
    assert_eq!((t.vx, t.vy, t.omega), (0.0, 0.0, 0.0));
}
