//! In-process loop of the LOW-LEVEL: chassis controller → simulated plant → encoder feedback →
//! odometry, without DDS. The plant moves the body by its own wheel model (least squares over
//! the wheel constraints), not by the chassis' `forward`, so this comparison can catch a wrong
//! forward model: without noise the chassis odometry must stay within 0.1 % of the distance
//! driven from the truth at every feedback sample along the route, and a deliberately wrong
//! model fed the same feedback must not, even when the wheels are commanded by that model's own
//! inverse (so that its odometry agrees with the command); with encoder slip the odometry must
//! drift by the slip.
//!
//! The error is watched along the route, not only at its end: the test loop is closed, so a
//! model that scales every length by the same factor would end exactly where the truth does.

use mobil_chassis::controller::{ChassisController, ControllerConfig, InputAges};
use mobil_chassis::joints::wheel_state_from_joints;
use mobil_chassis::{
    forward, inverse, BodyTwist, ChassisConfig, ChassisModel, ChassisParams, Odometry, OdometryNoise, WheelState,
};
use mobil_sim::plant::{Plant, PlantConfig};
use mobil_world::World;

/// A forward model: the twist at the kinematic origin from measured wheels.
type ForwardModel = fn(&ChassisParams, &WheelState) -> BodyTwist;

/// An inverse model: the wheel commands for a twist at the kinematic origin.
type InverseModel = fn(&ChassisParams, BodyTwist) -> WheelState;

/// The result of one drive.
struct Run {
    /// Path length of the true reference point (m).
    distance: f64,
    /// Largest distance (m) along the route between the chassis controller's odometry and the
    /// truth, at the feedback samples.
    controller_error: f64,
    /// The same for the odometry of the model under test.
    model_error: f64,
    /// Final distance (m) between the chassis controller's odometry and the truth.
    controller_final_error: f64,
    /// Largest slip residual of the plant's wheels (m/s).
    max_slip: f64,
    /// Slip residual of the plant's wheels at the end, at rest (m/s).
    final_slip: f64,
    /// Largest distance (m) of the true reference point from its start, at the feedback samples.
    truth_farthest: f64,
    /// The same for the odometry of the model under test.
    model_farthest: f64,
}

/// The comparison every noise-free odometry is held to: never farther from the truth than
/// 0.1 % of the distance driven.
fn within_tolerance(error: f64, distance: f64) -> bool {
    error < 0.001 * distance
}

/// Drives `route` (v, ω, duration) with the chassis controller on a plant whose motors lag by
/// `tau` (s), and integrates a second odometry with `model` from the same feedback samples at
/// the same stamps.
fn drive(config: ChassisConfig, slip: f64, tau: f64, route: &[(f64, f64, f64)], model: ForwardModel) -> Run {
    drive_commanded(config, slip, tau, route, model, None)
}

/// As [`drive`], but with the wheels commanded by `command` instead of the chassis controller
/// (which still receives every `cmd_vel` and the feedback, and keeps its own odometry), when
/// given.
fn drive_commanded(
    config: ChassisConfig,
    slip: f64,
    tau: f64,
    route: &[(f64, f64, f64)],
    model: ForwardModel,
    command: Option<InverseModel>,
) -> Run {
    let params = ChassisParams::new(config).unwrap();
    let mut controller = ChassisController::new(ControllerConfig {
        params,
        cmd_vel_timeout_s: 0.5,
        feedback_timeout_s: 0.5,
        noise: OdometryNoise::default(),
    })
    .unwrap();
    let mut odometry = Odometry::new(params.reference_offset(), OdometryNoise::default()).unwrap();
    let plant_config = PlantConfig {
        params,
        motor_time_constant: tau,
        wheel_speed_noise: 0.0,
        wheel_slip: slip,
        robot_radius: 0.3,
    };
    let mut plant = Plant::new(plant_config, nalgebra::Vector3::zeros(), 1);
    let world = World::default();
    let dt = 0.005;
    let mut distance = 0.0;
    let mut last = plant.reference_pose();
    let mut step = 0u64;
    let (mut controller_error, mut model_error, mut max_slip) = (0.0f64, 0.0f64, 0.0f64);
    let (mut truth_farthest, mut model_farthest) = (0.0f64, 0.0f64);
    let start = plant.reference_pose();
    let error = |truth: nalgebra::Vector3<f64>, q: nalgebra::Vector3<f64>| (truth.x - q.x).hypot(truth.y - q.y);
    for &(v, w, duration) in route.iter().chain([(0.0, 0.0, 1.0)].iter()) {
        let steps = (duration / dt).round() as u64;
        for _ in 0..steps {
            let t = step as f64 * dt;
            if step.is_multiple_of(4) {
                // 50 Hz: joint_states, cmd_vel, wheel_commands. The feedback comes first, as
                // from a robot whose encoders report before anyone drives it: the controller
                // turns no wheel before its first feedback.
                let fb = plant.feedback();
                let wheels = wheel_state_from_joints(params.model(), &fb.names, &fb.positions, &fb.velocities).unwrap();
                controller.on_feedback(&wheels, t).unwrap();
                odometry.update_at(model(&params, &wheels), t).unwrap();
                let twist = BodyTwist::new(v, 0.0, w);
                // Both inputs arrived just now (age 0), as the node's holders would say.
                assert!(controller.on_cmd_vel(twist), "a finite cmd_vel is accepted");
                let cmd = controller.gate(InputAges {
                    cmd_vel_s: Some(0.0),
                    feedback_s: Some(0.0),
                });
                match command {
                    Some(inverse) => plant.command(&inverse(&params, twist)).unwrap(),
                    None => plant.command(&cmd.wheels).unwrap(),
                };
                let truth = plant.reference_pose();
                controller_error = controller_error.max(error(truth, controller.odometry().reference_pose()));
                model_error = model_error.max(error(truth, odometry.reference_pose()));
                truth_farthest = truth_farthest.max(error(truth, start));
                model_farthest = model_farthest.max(error(odometry.reference_pose(), start));
            }
            plant.step(dt, &world);
            max_slip = max_slip.max(plant.slip_residual());
            step += 1;
            let p = plant.reference_pose();
            distance += (p.x - last.x).hypot(p.y - last.y);
            last = p;
        }
    }
    Run {
        distance,
        controller_error,
        model_error,
        controller_final_error: error(plant.reference_pose(), controller.odometry().reference_pose()),
        max_slip,
        final_slip: plant.slip_residual(),
        truth_farthest,
        model_farthest,
    }
}

/// The chassis' own forward kinematics.
fn chassis_forward(params: &ChassisParams, wheels: &WheelState) -> BodyTwist {
    forward(params, wheels).unwrap()
}

/// OMR-III with the paper's matrix (3.28), which lacks the 2/3: translation 1.5× too fast.
fn omni_without_two_thirds(params: &ChassisParams, wheels: &WheelState) -> BodyTwist {
    let t = forward(params, wheels).unwrap();
    BodyTwist::new(1.5 * t.vx, 1.5 * t.vy, t.wz)
}

/// The inverse that matches [`omni_without_two_thirds`] exactly: the wheels turn for a translation
/// only ⅔ as fast as they should, so that model reads back exactly the commanded twist.
fn omni_inverse_without_two_thirds(params: &ChassisParams, twist: BodyTwist) -> WheelState {
    inverse(params, BodyTwist::new(twist.vx / 1.5, twist.vy / 1.5, twist.wz))
}

/// Any model whose translation reads 1 % fast while its heading stays right.
fn one_percent_fast(params: &ChassisParams, wheels: &WheelState) -> BodyTwist {
    let t = forward(params, wheels).unwrap();
    BodyTwist::new(1.01 * t.vx, 1.01 * t.vy, t.wz)
}

fn loop_route() -> Vec<(f64, f64, f64)> {
    let q = std::f64::consts::FRAC_PI_2 / 0.4;
    vec![
        (0.4, 0.0, 5.0),
        (0.4, 0.4, q),
        (0.4, 0.0, 2.5),
        (0.4, 0.4, q),
        (0.4, 0.0, 5.0),
        (0.4, 0.4, q),
        (0.4, 0.0, 2.5),
        (0.4, 0.4, q),
    ]
}

fn configs() -> [ChassisConfig; 3] {
    let mut mobil2 = ChassisConfig::mobil2();
    mobil2.reference_offset = 0.3;
    [mobil2, ChassisConfig::omr3(), ChassisConfig::tricycle()]
}

/// The loop's length at the reference point: straights of 0.4 m/s · (5 + 2.5 + 5 + 2.5) s =
/// 6 m, and four quarter turns of radius 0.4 / 0.4 = 1 m at the kinematic origin, a whole
/// circle; a reference point d ahead of it turns on sqrt(1 + d²) (MOBIL-II's base_link,
/// d = 0.3: 1.0440 m), so the turns add 2π·sqrt(1 + d²): 12.283 m, or 12.560 m for MOBIL-II.
/// The commands change on the 50 Hz ticks, so each turn lasts a whole number of 20 ms
/// (π/2 / 0.4 = 3.927 s becomes 3.92 or 3.94 s): the driven length is within 0.03 % of this.
fn loop_length(d: f64) -> f64 {
    6.0 + 2.0 * std::f64::consts::PI * (1.0 + d * d).sqrt()
}

#[test]
fn with_ideal_motors_odometry_follows_the_truth_for_every_model() {
    for config in configs() {
        let run = drive(config, 0.0, 0.0, &loop_route(), chassis_forward);
        let expected = loop_length(config.reference_offset);
        assert!(
            (run.distance - expected).abs() < 0.001 * expected,
            "{:?}: drove {} m, expected {expected} m",
            config.model,
            run.distance
        );
        assert!(
            within_tolerance(run.controller_error, run.distance),
            "{:?}: error {} m over {} m",
            config.model,
            run.controller_error,
            run.distance
        );
        // Wheels commanded by the inverse kinematics agree: nothing slips, and the two
        // independent models agree far inside the tolerance.
        assert!(run.max_slip < 1e-9, "{:?}: slip {}", config.model, run.max_slip);
        assert!(
            run.controller_error < 1e-9,
            "{:?}: {}",
            config.model,
            run.controller_error
        );
        // The second odometry, fed the same samples through the same model, agrees.
        assert!(within_tolerance(run.model_error, run.distance), "{:?}", config.model);
    }
}

#[test]
fn with_motor_lag_odometry_stays_close_and_steering_transients_slip() {
    for config in configs() {
        let run = drive(config, 0.0, 0.05, &loop_route(), chassis_forward);
        let expected = loop_length(config.reference_offset);
        assert!(
            (run.distance - expected).abs() < 0.001 * expected,
            "{:?}: drove {} m",
            config.model,
            run.distance
        );
        assert!(
            run.final_slip < 1e-9,
            "{:?}: slip at rest {}",
            config.model,
            run.final_slip
        );
        if config.model == ChassisModel::CarLike {
            // The two steering motors lag on their own, so while the wheels steer into and out
            // of a turn the pair is off Ackermann and disagrees with the rear wheels' speed
            // difference: the plant slips there, which no odometry can see. At δ_l = 41° half
            // way, tan(20.5°) = 0.374 against 0.5·tan 41° = 0.435: wheels disagree by ~14 % of
            // the turn rate, a slip residual of a few cm/s.
            assert!(run.max_slip > 0.01, "slip {}", run.max_slip);
            assert!(
                run.controller_error < 0.0015 * run.distance,
                "error {}",
                run.controller_error
            );
        } else {
            // One steered wheel, or none: nothing to disagree, so the motor lag costs only the
            // 50 Hz sampling of the feedback.
            assert!(run.max_slip < 1e-9, "{:?}: slip {}", config.model, run.max_slip);
            assert!(
                within_tolerance(run.controller_error, run.distance),
                "{:?}: error {} m over {} m",
                config.model,
                run.controller_error,
                run.distance
            );
        }
    }
}

#[test]
fn the_comparison_catches_a_wrong_forward_model() {
    // The loop at the kinematic origin: 2 m ahead, a quarter turn of radius 1 about (2, 1),
    // 1 m up, a quarter turn about (2, 2), 2 m back, one about (0, 2), 1 m down, one about
    // (0, 1) home; a 4 m × 3 m loop whose farthest point from the start is on the turn about
    // (2, 2), |(2, 2)| + 1 = 2.8284 + 1 = 3.8284 m away.
    //
    // Without the 2/3 every translation reads 1.5× too long while the heading stays right: the
    // odometry's loop is the true one scaled by 1.5 about the start, so it is off by 0.5·3.8284
    // = 1.914 m at that point, not 0.1 %.
    for tau in [0.0, 0.05] {
        let wrong = drive(ChassisConfig::omr3(), 0.0, tau, &loop_route(), omni_without_two_thirds);
        assert!(
            !within_tolerance(wrong.model_error, wrong.distance),
            "{}",
            wrong.model_error
        );
        assert!(
            wrong.model_error > 1.90 && wrong.model_error < 1.92,
            "{}",
            wrong.model_error
        );
    }
    // A translation 1 % fast is caught too, on every chassis: 1 % of 3.8284 m is 3.83 cm,
    // against a tolerance of 0.1 % of the 12.3 m (12.6 m) driven, 1.2 cm (1.3 cm); the right
    // model in the same loop passes. (The loop is driven at the kinematic origin on every
    // chassis, and with the heading right the reference point is off by as much as the origin.)
    for config in configs() {
        let run = drive(config, 0.0, 0.0, &loop_route(), one_percent_fast);
        assert!(
            !within_tolerance(run.model_error, run.distance),
            "{:?}: {}",
            config.model,
            run.model_error
        );
        assert!(
            run.model_error > 0.0375 && run.model_error < 0.0390,
            "{:?}: {}",
            config.model,
            run.model_error
        );
        assert!(
            within_tolerance(run.controller_error, run.distance),
            "{:?}",
            config.model
        );
    }
}

#[test]
fn the_truth_does_not_follow_a_wrong_but_self_consistent_chassis() {
    // A chassis whose forward model lacks the 2/3 and whose inverse is its exact inverse: the
    // wheels turn for a translation ⅔ as fast as they must, and the odometry, reading them with
    // the matching wrong forward model, sees exactly the commanded loop. A plant that moved the
    // body by the chassis' own kinematics would agree with it; the plant's wheel model does not.
    //
    // By hand: the body translates at ⅔·0.4 = 0.2667 m/s and turns at the commanded 0.4 rad/s
    // (the omni wheels' rotation term R·ω is right), so it drives the commanded loop scaled by
    // ⅔ about the start: straights of 4/3 and 2/3 m, turns of radius 2/3 m, a length of
    // ⅔·(6 + 2π) = 4 + 4.1888 = 8.1888 m, its farthest point ⅔·3.8284 = 2.5523 m from the
    // start. The odometry's loop is the commanded one, its farthest point 3.8284 m out, and the
    // two are off by ⅓·3.8284 = 1.2761 m there.
    for tau in [0.0, 0.05] {
        let run = drive_commanded(
            ChassisConfig::omr3(),
            0.0,
            tau,
            &loop_route(),
            omni_without_two_thirds,
            Some(omni_inverse_without_two_thirds),
        );
        assert!(
            (run.model_farthest - 3.8284).abs() < 0.01,
            "{tau}: {}",
            run.model_farthest
        );
        assert!(
            (run.truth_farthest - 2.5523).abs() < 0.01,
            "{tau}: {}",
            run.truth_farthest
        );
        assert!((run.distance - 8.1888).abs() < 0.01, "{tau}: {}", run.distance);
        assert!(
            run.model_error > 1.26 && run.model_error < 1.29,
            "{tau}: {}",
            run.model_error
        );
        assert!(!within_tolerance(run.model_error, run.distance));
        // The right model, fed the same wheels, follows the truth.
        assert!(
            within_tolerance(run.controller_error, run.distance),
            "{tau}: {}",
            run.controller_error
        );
    }
}

#[test]
fn encoder_slip_shows_up_as_odometry_drift() {
    // Encoders reading 2 % fast on a straight 4 m: odometry overshoots by 2 % (8 cm), give or
    // take the motor lag at start and stop.
    let run = drive(ChassisConfig::omr3(), 0.02, 0.05, &[(0.4, 0.0, 10.0)], chassis_forward);
    assert!((run.distance - 4.0).abs() < 0.05, "{}", run.distance);
    assert!(
        (run.controller_final_error - 0.02 * run.distance).abs() < 0.005,
        "error {}",
        run.controller_final_error
    );
}
