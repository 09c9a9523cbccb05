//! Whatever wheel feedback arrives, the controller's odometry stays finite, and impossible
//! feedback is refused before it reaches the odometry.

use mobil_chassis::controller::{ChassisController, ControllerConfig};
use mobil_chassis::{ChassisModel, ChassisParams, OdometryNoise, WheelState};
use proptest::prelude::*;

fn controller(params: ChassisParams) -> ChassisController {
    ChassisController::new(ControllerConfig {
        params,
        cmd_vel_timeout_s: 0.5,
        feedback_timeout_s: 0.5,
        noise: OdometryNoise::default(),
    })
    .unwrap()
}

fn finite(c: &ChassisController) -> bool {
    let o = c.odometry();
    [
        o.pose().as_slice(),
        o.reference_pose().as_slice(),
        o.covariance().as_slice(),
        o.reference_covariance().as_slice(),
    ]
    .iter()
    .all(|m| m.iter().all(|v| v.is_finite()))
        && o.twist().is_finite()
}

fn names(model: ChassisModel) -> Vec<String> {
    model.joints().iter().map(|j| j.name.to_owned()).collect()
}

#[test]
fn the_reported_huge_samples_are_refused_and_change_nothing() {
    // omr3 [1e308, −1e308, 0] and mobil2 [0, 0, 1e308, 0] as velocities, after a run at rest.
    for (params, huge) in [
        (ChassisParams::omr3(), vec![1e308, -1e308, 0.0]),
        (ChassisParams::mobil2(), vec![0.0, 0.0, 1e308, 0.0]),
    ] {
        let model = params.model();
        let n = names(model);
        let zeros = vec![0.0; n.len()];
        let mut c = controller(params);
        for k in 0..10 {
            let t = 0.02 * f64::from(k);
            c.on_joint_state(&n, &zeros, &zeros, t).unwrap().unwrap();
        }
        let before = c.odometry().clone();
        assert!(
            c.on_joint_state(&n, &zeros, &huge, 0.2).is_err(),
            "{model}: {huge:?} accepted"
        );
        assert_eq!(c.odometry(), &before, "{model}");
        assert!(finite(&c));
        // The next ordinary sample is integrated as usual.
        c.on_joint_state(&n, &zeros, &zeros, 0.22).unwrap().unwrap();
        assert_eq!(c.odometry().last_stamp(), Some(0.22));
    }
}

fn any_number() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -40.0..40.0f64,
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

fn any_params() -> impl Strategy<Value = ChassisParams> {
    prop::sample::select(vec![
        ChassisParams::mobil2(),
        ChassisParams::omr3(),
        ChassisParams::tricycle(),
    ])
}

proptest! {
    #[test]
    fn no_feedback_ever_makes_the_odometry_non_finite(
        params in any_params(),
        positions_only in any::<bool>(),
        wraps in any::<bool>(),
        samples in prop::collection::vec((prop::collection::vec(any_number(), 4), any_number()), 1..40),
    ) {
        let model = params.model();
        let n = names(model);
        let mut c = controller(params);
        c.set_encoder_positions_wrap(wraps);
        let mut t = 0.0;
        for (values, dt) in samples {
            // Stamps mostly moving on by ordinary steps, sometimes anything at all.
            t = if dt.is_finite() && dt.abs() < 1e3 { t + dt.abs() * 0.01 } else { dt };
            let values = &values[..n.len()];
            let _ = if positions_only {
                c.on_joint_state(&n, values, &[], t)
            } else {
                c.on_joint_state(&n, values, values, t)
            };
            let direct = WheelState::from_values(model, values);
            if let Ok(wheels) = direct {
                let _ = c.on_feedback(&wheels, t);
            }
            prop_assert!(finite(&c), "{:?}", c.odometry());
        }
    }
}
