//! `sim_node`: a simulated robot for demos and tests. Consumes `wheel_commands`, publishes wheel
//! feedback on `joint_states` (optional noise and slip), the true pose on `ground_truth`, and a
//! simulated LIDAR on `scan`, in a 2D world from a YAML file (or the built-in one).
//! Wheel commands are held to the chassis' limits; a malformed one, or one with NaN or infinity,
//! stops the wheels. Deterministic for a given seed. Real time by default; with `publish_clock` it publishes
//! `/clock` and may run faster (`real_time_factor`) for nodes started with `use_sim_time:=true`.

use futures::StreamExt;
use mobil_chassis::joints::wheel_state_from_joints;
use mobil_chassis_node::{chassis_from_params, chassis_param_specs};
use mobil_msgs::geometry_msgs::msg::{Point, Transform, TransformStamped, Vector3};
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_msgs::rosgraph_msgs::msg::Clock;
use mobil_msgs::sensor_msgs::msg::{JointState, LaserScan};
use mobil_msgs::std_msgs::msg::ColorRGBA;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::tf2_msgs::msg::TFMessage;
use mobil_msgs::visualization_msgs::msg::{Marker, MarkerArray};
use mobil_ros::geometry::{planar_odometry, yaw_quaternion};
use mobil_ros::params::ParamValues;
use mobil_ros::time::{stamp_from_nanos, stamp_from_secs};
use mobil_ros::{qos, run_node, shutdown_signal, warn_throttled, LogThrottle, NodeDecl, ParamSpec, RosNode};
use mobil_sim::lidar::{Lidar, LidarConfig};
use mobil_sim::plant::{CommandOutcome, Plant, PlantConfig};
use mobil_sim::world::{Obstacle, World};
use nalgebra::Vector3 as V3;
use std::process::ExitCode;
use std::time::Duration;
use tracing::{info, warn};

#[derive(Debug, Clone)]
struct SimConfig {
    plant: PlantConfig,
    seed: u64,
    initial_pose: V3<f64>,
    physics_rate_hz: f64,
    joint_states_rate_hz: f64,
    publish_clock: bool,
    real_time_factor: f64,
    lidar: Option<LidarConfig>,
    world_frame: String,
    base_frame: String,
    laser_frame: String,
}

fn decl() -> NodeDecl {
    let lidar = LidarConfig::default();
    NodeDecl::new("sim", "Simulated chassis, 2D world and LIDAR")
        .params(chassis_param_specs())
        .param(ParamSpec::double("robot_radius", 0.3, "footprint radius around the reference point [m]").above(0.0))
        .param(ParamSpec::string("world_file", "", "world YAML (empty: the built-in world)").read_only())
        .param(
            ParamSpec::integer("seed", 1, "random seed (noise)")
                .min(0.0)
                .read_only(),
        )
        .param(
            ParamSpec::doubles("initial_pose", &[0.0, 0.0, 0.0], "x, y, yaw of the reference point")
                .length(3)
                .read_only(),
        )
        .param(
            ParamSpec::double("physics_rate_hz", 200.0, "simulation steps per simulated second")
                .within(10.0, 10_000.0)
                .read_only(),
        )
        .param(
            ParamSpec::double("joint_states_rate_hz", 50.0, "wheel feedback and ground_truth rate").within(1.0, 1000.0),
        )
        .param(ParamSpec::double("wheel_speed_noise", 0.0, "relative std of measured wheel speeds").min(0.0))
        .param(ParamSpec::double("wheel_slip", 0.0, "relative bias of measured wheel speeds").within(-0.5, 0.5))
        .param(ParamSpec::double("motor_time_constant", 0.05, "first-order lag of the wheels [s]").min(0.0))
        .param(
            ParamSpec::double(
                "command_timeout_s",
                1.0,
                "drivers stop without wheel_commands [s] (0: never)",
            )
            .min(0.0),
        )
        .param(ParamSpec::boolean("publish_clock", false, "publish /clock (simulated time from 0)").read_only())
        .param(ParamSpec::double("real_time_factor", 1.0, "simulated seconds per wall second").within(0.01, 100.0))
        .param(ParamSpec::boolean("lidar.enabled", true, "publish scan"))
        .param(ParamSpec::double("lidar.fov", lidar.fov, "field of view [rad]").within(0.01, std::f64::consts::TAU))
        .param(ParamSpec::integer("lidar.beams", lidar.beams as i64, "beams per scan").within(2.0, 100_000.0))
        .param(ParamSpec::double("lidar.range_min", lidar.range_min, "[m]").min(0.0))
        .param(ParamSpec::double("lidar.range_max", lidar.range_max, "[m]").above(0.0))
        .param(ParamSpec::double("lidar.noise_std", lidar.noise_std, "range noise std [m]").min(0.0))
        .param(ParamSpec::double("lidar.rate_hz", lidar.rate_hz, "scans per simulated second").within(0.1, 1000.0))
        .param(ParamSpec::doubles("lidar.mount", &lidar.mount, "x, y, yaw of the laser in base_link").length(3))
        .param(ParamSpec::string("world_frame", "odom", "frame of ground_truth"))
        .param(ParamSpec::string(
            "base_frame",
            "base_link",
            "robot frame (reference point)",
        ))
        .param(ParamSpec::string("laser_frame", "laser", "frame of scan"))
        .check(|p| sim_config(p).map(|_| ()))
}

/// The world named by `world_file` (read-only, so read once at start-up).
fn load_world(p: &ParamValues) -> Result<World, String> {
    let world_file = p.string("world_file")?;
    if world_file.is_empty() {
        Ok(World::builtin())
    } else {
        World::load(&world_file).map_err(|e| e.to_string())
    }
}

/// Everything but the world, so that vetting a parameter change does no file I/O.
fn sim_config(p: &ParamValues) -> Result<SimConfig, String> {
    let pose = p.f64s("initial_pose")?;
    let mount = p.f64s("lidar.mount")?;
    let lidar = LidarConfig {
        fov: p.f64("lidar.fov")?,
        beams: usize::try_from(p.i64("lidar.beams")?).map_err(|e| e.to_string())?,
        range_min: p.f64("lidar.range_min")?,
        range_max: p.f64("lidar.range_max")?,
        noise_std: p.f64("lidar.noise_std")?,
        rate_hz: p.f64("lidar.rate_hz")?,
        mount: [mount[0], mount[1], mount[2]],
    };
    lidar.validate().map_err(|e| e.to_string())?;
    let plant = PlantConfig {
        params: chassis_from_params(p)?,
        motor_time_constant: p.f64("motor_time_constant")?,
        wheel_speed_noise: p.f64("wheel_speed_noise")?,
        wheel_slip: p.f64("wheel_slip")?,
        command_timeout: p.f64("command_timeout_s")?,
        robot_radius: p.f64("robot_radius")?,
    };
    let initial_pose = V3::new(pose[0], pose[1], pose[2]);
    if !initial_pose.iter().all(|v| v.is_finite()) {
        return Err(format!("initial_pose must be finite, got {pose:?}"));
    }
    Ok(SimConfig {
        plant,
        seed: u64::try_from(p.i64("seed")?).map_err(|e| e.to_string())?,
        initial_pose,
        physics_rate_hz: p.f64("physics_rate_hz")?,
        joint_states_rate_hz: p.f64("joint_states_rate_hz")?,
        publish_clock: p.bool("publish_clock")?,
        real_time_factor: p.f64("real_time_factor")?,
        lidar: p.bool("lidar.enabled")?.then_some(lidar),
        world_frame: p.string("world_frame")?,
        base_frame: p.string("base_frame")?,
        laser_frame: p.string("laser_frame")?,
    })
}

/// The stamp of simulated t = 0.
fn stamp_at_start(config: &SimConfig, node: &RosNode) -> mobil_msgs::builtin_interfaces::msg::Time {
    if config.publish_clock {
        stamp_from_secs(0.0)
    } else {
        node.stamp()
    }
}

/// The world's obstacles for RViz: circles as 0.5 m high cylinders, polygons as closed outlines.
fn world_markers(world: &World, frame: &str, stamp: mobil_msgs::builtin_interfaces::msg::Time) -> MarkerArray {
    let grey = ColorRGBA {
        r: 0.6,
        g: 0.6,
        b: 0.6,
        a: 1.0,
    };
    let markers = world
        .obstacles
        .iter()
        .enumerate()
        .map(|(i, o)| {
            let mut m = Marker {
                header: Header {
                    stamp: stamp.clone(),
                    frame_id: frame.to_owned(),
                },
                ns: "world".into(),
                id: i32::try_from(i).unwrap_or(i32::MAX),
                action: Marker::ADD,
                color: grey.clone(),
                ..Default::default()
            };
            match o {
                Obstacle::Circle { center, radius } => {
                    m.r#type = Marker::CYLINDER;
                    m.pose.position = Point {
                        x: center[0],
                        y: center[1],
                        z: 0.25,
                    };
                    m.scale = Vector3 {
                        x: 2.0 * radius,
                        y: 2.0 * radius,
                        z: 0.5,
                    };
                }
                Obstacle::Polygon { points } => {
                    m.r#type = Marker::LINE_STRIP;
                    m.scale.x = 0.03;
                    m.points = points
                        .iter()
                        .chain(points.first())
                        .map(|p| Point {
                            x: p[0],
                            y: p[1],
                            z: 0.0,
                        })
                        .collect();
                }
            }
            m
        })
        .collect();
    MarkerArray { markers }
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

async fn run(node: &mut RosNode) -> anyhow::Result<()> {
    let mut config = sim_config(&node.params()).map_err(anyhow::Error::msg)?;
    let world = load_world(&node.params()).map_err(anyhow::Error::msg)?;
    let start = config.initial_pose;
    if world.collides(nalgebra::Point2::new(start.x, start.y), config.plant.robot_radius) {
        anyhow::bail!("initial_pose {start:?} collides with the world");
    }
    let mut plant = Plant::new(config.plant, config.initial_pose, config.seed);
    let mut lidar = config.lidar.map(|c| Lidar::new(c, config.seed.wrapping_add(1)));
    info!(
        "simulating a {} chassis in a world of {} obstacles; lidar {}",
        config.plant.params.model().as_str(),
        world.obstacles.len(),
        match &config.lidar {
            Some(l) => format!("{} beams over {:.0}° at {} Hz", l.beams, l.fov.to_degrees(), l.rate_hz),
            None => "off".into(),
        }
    );

    let q = qos::default_qos();
    let commands_sub = node.subscription::<JointState>("wheel_commands", &q)?;
    let joints_pub = node.publisher::<JointState>("joint_states", &q)?;
    let truth_pub = node.publisher::<Odometry>("ground_truth", &q)?;
    let scan_pub = node.publisher::<LaserScan>("scan", &qos::sensor_data())?;
    let static_pub = node.publisher::<TFMessage>("tf_static", &qos::latched())?;
    let markers_pub = node.publisher::<MarkerArray>("~/markers", &qos::latched())?;
    let _ = markers_pub.publish(world_markers(
        &world,
        &config.world_frame,
        stamp_at_start(&config, node),
    ));
    let clock_pub = if config.publish_clock {
        Some(node.publisher::<Clock>("/clock", &qos::reliable(1))?)
    } else {
        None
    };

    // Wall time of simulated t = 0, for stamps when there is no simulated clock.
    let epoch_nanos = node.now_nanos();
    let stamp_at = |t: f64, publish_clock: bool| {
        if publish_clock {
            stamp_from_secs(t)
        } else {
            stamp_from_nanos(epoch_nanos + (t * 1e9) as i64)
        }
    };
    if let Some(l) = &config.lidar {
        let mount = TransformStamped {
            header: Header {
                stamp: stamp_at(0.0, config.publish_clock),
                frame_id: config.base_frame.clone(),
            },
            child_frame_id: config.laser_frame.clone(),
            transform: Transform {
                translation: Vector3 {
                    x: l.mount[0],
                    y: l.mount[1],
                    z: 0.0,
                },
                rotation: yaw_quaternion(l.mount[2]),
            },
        };
        let _ = static_pub.publish(TFMessage {
            transforms: vec![mount],
        });
    }

    let commands = commands_sub.async_stream();
    let shutdown = shutdown_signal();
    let period = |c: &SimConfig| Duration::from_secs_f64(1.0 / (c.physics_rate_hz * c.real_time_factor));
    let mut tick = tokio::time::interval(period(&config));
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Burst);
    tokio::pin!(commands, shutdown);
    let mut throttle = LogThrottle::default();
    let dt = 1.0 / config.physics_rate_hz;
    let (mut next_joints, mut next_scan) = (0.0f64, 0.0f64);
    let mut reported_collision = false;

    loop {
        tokio::select! {
            _ = &mut shutdown => break,
            Some(changed) = node.param_changed() => match sim_config(&changed) {
                Ok(new) => {
                    if new.real_time_factor != config.real_time_factor {
                        tick = tokio::time::interval(period(&new));
                    }
                    lidar = match (new.lidar, lidar.take()) {
                        (Some(c), Some(l)) if Some(c) == config.lidar => Some(l),
                        (Some(c), _) => Some(Lidar::new(c, config.seed.wrapping_add(1))),
                        (None, _) => None,
                    };
                    plant.reconfigure(new.plant);
                    config = new;
                }
                Err(e) => warn!("parameter change not applied: {e}"),
            },
            Some(msg) = commands.next() => match msg {
                // A bad command stops the wheels, as real motor drivers do: the previous
                // command must not keep them turning until the driver timeout.
                Ok((js, _)) => match wheel_state_from_joints(config.plant.params.model(), &js.name, &js.position, &js.velocity) {
                    Ok(wheels) => match plant.command(&wheels) {
                        Ok(CommandOutcome::Accepted) => {}
                        Ok(CommandOutcome::Limited) => warn_throttled!(
                            throttle,
                            "limit",
                            "wheel_commands beyond the chassis limits (max_wheel_speed, max_steering) held to them: {:?}",
                            plant.commanded()
                        ),
                        Err(e) => warn_throttled!(throttle, "cmd", "wheel_commands refused: {e}"),
                    },
                    Err(e) => {
                        plant.stop();
                        warn_throttled!(throttle, "cmd", "wheel_commands dropped, wheels stopped: {e}");
                    }
                },
                Err(e) => {
                    plant.stop();
                    warn_throttled!(throttle, "decode", "undecodable wheel_commands dropped, wheels stopped: {e:?}");
                }
            },
            _ = tick.tick() => {
                plant.step(dt, &world);
                let t = plant.time();
                if plant.collided() && !reported_collision {
                    warn!("the robot hit an obstacle at {:?}", plant.reference_pose());
                    reported_collision = true;
                }
                if let Some(clock) = &clock_pub {
                    let _ = clock.publish(Clock { clock: stamp_from_secs(t) });
                }
                if t + 1e-9 >= next_joints {
                    next_joints += 1.0 / config.joint_states_rate_hz;
                    let stamp = stamp_at(t, config.publish_clock);
                    let fb = plant.feedback();
                    let _ = joints_pub.publish(JointState {
                        header: Header { stamp: stamp.clone(), frame_id: String::new() },
                        name: fb.names,
                        position: fb.positions,
                        velocity: fb.velocities,
                        effort: Vec::new(),
                    });
                    let pose = plant.reference_pose();
                    let twist = plant.reference_twist();
                    let truth = planar_odometry(
                        Header { stamp, frame_id: config.world_frame.clone() },
                        &config.base_frame,
                        pose.into(),
                        [twist.vx, twist.vy, twist.wz],
                    );
                    let _ = truth_pub.publish(truth);
                }
                if let (Some(l), Some(cfg)) = (lidar.as_mut(), config.lidar.as_ref()) {
                    if t + 1e-9 >= next_scan {
                        next_scan += 1.0 / cfg.rate_hz;
                        let pose = plant.reference_pose();
                        let scan = l.scan(&world, (pose.x, pose.y, pose.z));
                        let _ = scan_pub.publish(LaserScan {
                            header: Header { stamp: stamp_at(t, config.publish_clock), frame_id: config.laser_frame.clone() },
                            angle_min: scan.angle_min as f32,
                            angle_max: scan.angle_max as f32,
                            angle_increment: scan.angle_increment as f32,
                            time_increment: 0.0,
                            scan_time: (1.0 / cfg.rate_hz) as f32,
                            range_min: scan.range_min as f32,
                            range_max: scan.range_max as f32,
                            ranges: scan.ranges,
                            intensities: Vec::new(),
                        });
                    }
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_obstacle_becomes_one_marker() {
        let world = World::from_yaml_str(
            "obstacles:\n  - circle: { center: [2.0, 1.0], radius: 0.3 }\n  - polygon: { points: [[0, 0], [1, 0], [1, 1]] }\n",
        )
        .unwrap();
        let m = world_markers(&world, "odom", Default::default()).markers;
        assert_eq!(m.len(), 2);
        assert_eq!(
            (m[0].r#type, m[0].scale.x, m[0].pose.position.x),
            (Marker::CYLINDER, 0.6, 2.0)
        );
        assert_eq!(m[1].r#type, Marker::LINE_STRIP);
        assert_eq!(m[1].points.len(), 4, "closed: the first point repeated");
        assert_eq!((m[1].points[3].x, m[1].points[3].y), (0.0, 0.0));
        assert_eq!(m[0].pose.orientation.w, 1.0);
    }
}
