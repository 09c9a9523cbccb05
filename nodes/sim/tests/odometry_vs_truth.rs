//! In-process loop of the LOW-LEVEL: chassis controller → simulated plant → encoder feedback →
//! odometry, without DDS. Without noise, odometry must follow the true motion closely; with
//! encoder slip it must drift by the slip.

use mobil_chassis::controller::{ChassisController, ControllerConfig};
use mobil_chassis::joints::wheel_state_from_joints;
use mobil_chassis::{BodyTwist, ChassisConfig, ChassisParams, OdometryNoise};
use mobil_sim::plant::{Plant, PlantConfig};
use mobil_sim::world::World;

/// Drives `route` (v, ω, duration) and returns (distance driven, final position error).
fn drive(config: ChassisConfig, slip: f64, route: &[(f64, f64, f64)]) -> (f64, f64) {
    let params = ChassisParams::new(config).unwrap();
    let mut controller = ChassisController::new(ControllerConfig {
        params,
        cmd_vel_timeout_s: 0.5,
        feedback_timeout_s: 0.5,
        noise: OdometryNoise::default(),
    })
    .unwrap();
    let plant_config = PlantConfig {
        params,
        motor_time_constant: 0.05,
        wheel_speed_noise: 0.0,
        wheel_slip: slip,
        command_timeout: 1.0,
        robot_radius: 0.3,
    };
    let mut plant = Plant::new(plant_config, nalgebra::Vector3::zeros(), 1);
    let world = World::default();
    let dt = 0.005;
    let mut distance = 0.0;
    let mut last = plant.reference_pose();
    let mut step = 0u64;
    for &(v, w, duration) in route.iter().chain([(0.0, 0.0, 1.0)].iter()) {
        let steps = (duration / dt).round() as u64;
        for _ in 0..steps {
            let t = step as f64 * dt;
            if step.is_multiple_of(4) {
                // 50 Hz: cmd_vel, wheel_commands, joint_states.
                let cmd = controller.on_cmd_vel(BodyTwist::new(v, 0.0, w), t);
                plant.command(&cmd.wheels);
                let fb = plant.feedback();
                let wheels = wheel_state_from_joints(params.model(), &fb.names, &fb.positions, &fb.velocities).unwrap();
                controller.on_feedback(&wheels, t, t).unwrap();
            }
            plant.step(dt, &world);
            step += 1;
            let p = plant.reference_pose();
            distance += (p.x - last.x).hypot(p.y - last.y);
            last = p;
        }
    }
    let truth = plant.reference_pose();
    let odom = controller.odometry().reference_pose();
    (distance, (truth.x - odom.x).hypot(truth.y - odom.y))
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

#[test]
fn noise_free_odometry_stays_within_a_tenth_of_a_percent_for_every_model() {
    for (config, d) in [
        (ChassisConfig::mobil2(), 0.3),
        (ChassisConfig::omr3(), 0.0),
        (ChassisConfig::tricycle(), 0.0),
    ] {
        let mut config = config;
        config.reference_offset = d;
        let (distance, error) = drive(config, 0.0, &loop_route());
        assert!(distance > 12.0, "{config:?}: drove {distance}");
        assert!(
            error < 0.001 * distance,
            "{:?}: error {error} m over {distance} m",
            config.model
        );
    }
}

#[test]
fn encoder_slip_shows_up_as_odometry_drift() {
    // Encoders reading 2 % fast on a straight 4 m: odometry overshoots by 2 % (8 cm), give or
    // take the motor lag at start and stop.
    let (distance, error) = drive(ChassisConfig::omr3(), 0.02, &[(0.4, 0.0, 10.0)]);
    assert!((distance - 4.0).abs() < 0.05, "{distance}");
    assert!((error - 0.02 * distance).abs() < 0.005, "error {error}");
}
