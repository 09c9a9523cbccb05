//! `sim_node`: a simulated robot for demos and tests. Consumes `wheel_commands`, publishes wheel
//! feedback on `joint_states` (optional noise and slip), the true pose on `ground_truth`, and a
//! simulated LIDAR on `scan`, in a 2D world from a YAML file (or the built-in one).
//! Wheel commands are held to the chassis' limits; a malformed one, or one with NaN or infinity,
//! stops the wheels, and so does a pause in them longer than `command_timeout_s` (steady clock,
//! judged by the kit's [`Latest`] holder), as a real motor driver does. Deterministic for a given seed. Real time by default; with `publish_clock` it publishes
//! `/clock` and may run faster (`real_time_factor`) for nodes started with `use_sim_time:=true`.

use mobil_chassis::joints::wheel_state_from_joints;
use mobil_chassis::model::ChassisConfig;
use mobil_msgs::geometry_msgs::msg::{Point, Transform, TransformStamped, Vector3};
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_msgs::rosgraph_msgs::msg::Clock;
use mobil_msgs::sensor_msgs::msg::{JointState, LaserScan};
use mobil_msgs::std_msgs::msg::ColorRGBA;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::tf2_msgs::msg::TFMessage;
use mobil_msgs::visualization_msgs::msg::{Marker, MarkerArray};
use mobil_ros::chassis::{chassis_params, declare_chassis};
use mobil_ros::config::{Config, ConfigError, Decl};
use mobil_ros::diagnostics::DiagnosticsOut;
use mobil_ros::geometry::{planar_odometry, yaw_quaternion};
use mobil_ros::input::Inputs;
use mobil_ros::latest::{Freshness, Latest};
use mobil_ros::time::{stamp_from_nanos, stamp_from_secs};
use mobil_ros::{qos, run_node, shutdown_signal, warn_throttled, LogThrottle, NodeDecl, RosNode, Ticker};
use mobil_sim::health::{sim_health, SimReport};
use mobil_sim::lidar::{Lidar, LidarConfig};
use mobil_sim::plant::{CommandOutcome, Plant, PlantConfig};
use mobil_world::{Obstacle, World};
use nalgebra::Vector3 as V3;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tokio::time::MissedTickBehavior;
use tracing::{info, warn};

/// Everything the simulator is configured with, each field filled by one declared parameter.
#[derive(Debug, Clone, Default)]
struct SimConfig {
    chassis: ChassisConfig,
    robot_radius: f64,
    world_file: String,
    seed: u64,
    initial_pose: [f64; 3],
    physics_rate_hz: f64,
    joint_states_rate_hz: f64,
    wheel_speed_noise: f64,
    wheel_slip: f64,
    motor_time_constant: f64,
    command_timeout_s: f64,
    publish_clock: bool,
    real_time_factor: f64,
    clock_catch_up_s: f64,
    lidar_enabled: bool,
    lidar: LidarConfig,
    world_frame: String,
    base_frame: String,
    laser_frame: String,
}

impl Config for SimConfig {
    fn declare(d: &mut Decl<Self>) {
        let lidar = LidarConfig::default();
        d.nest(|c: &mut SimConfig| &mut c.chassis, declare_chassis);
        d.double(
            "robot_radius",
            0.3,
            "footprint radius around the reference point [m]",
            |c, v| c.robot_radius = v,
        )
        .above(0.0);
        d.string("world_file", "", "world YAML (empty: the built-in world)", |c, v| {
            c.world_file = v
        })
        .read_only();
        d.count("seed", 1u64, "random seed (noise)", |c, v| c.seed = v)
            .min(0.0)
            .read_only();
        d.doubles(
            "initial_pose",
            [0.0, 0.0, 0.0],
            "x, y, yaw of the reference point",
            |c, v| c.initial_pose = v,
        )
        .read_only();
        d.double(
            "physics_rate_hz",
            200.0,
            "simulation steps per simulated second",
            |c, v| c.physics_rate_hz = v,
        )
        .within(10.0, 10_000.0)
        .read_only();
        d.double(
            "joint_states_rate_hz",
            50.0,
            "wheel feedback and ground_truth rate",
            |c, v| c.joint_states_rate_hz = v,
        )
        .within(1.0, 1000.0);
        d.double(
            "wheel_speed_noise",
            0.0,
            "relative std of measured wheel speeds",
            |c, v| c.wheel_speed_noise = v,
        )
        .min(0.0);
        d.double("wheel_slip", 0.0, "relative bias of measured wheel speeds", |c, v| {
            c.wheel_slip = v
        })
        .within(-0.5, 0.5);
        d.double(
            "motor_time_constant",
            0.05,
            "first-order lag of the wheel speeds and steering angles (0: none) [s]",
            |c, v| c.motor_time_constant = v,
        )
        .min(0.0);
        // 1 s: chassis_node sends wheel_commands every control period (20 ms at its default
        // 50 Hz, 1 s at its slowest 1 Hz) and stops the wheels itself 0.5 s after the last
        // cmd_vel, logging why; this is the drivers' backstop for a chassis_node that died.
        d.double(
            "command_timeout_s",
            1.0,
            "drivers stop without wheel_commands [s] (0: never)",
            |c, v| c.command_timeout_s = v,
        )
        .min(0.0);
        d.boolean(
            "publish_clock",
            false,
            "publish /clock (simulated time from 0)",
            |c, v| c.publish_clock = v,
        )
        .read_only();
        d.double("real_time_factor", 1.0, "simulated seconds per wall second", |c, v| {
            c.real_time_factor = v
        })
        .within(0.01, 100.0);
        // The simulated clock's backlog bound: see the tick arm of the loop.
        d.double(
            "clock_catch_up_s",
            0.01,
            "with publish_clock: a stall longer than this [wall s] slows simulated time instead of being caught up",
            |c, v| c.clock_catch_up_s = v,
        )
        // At least a few physics ticks: ticks always come a little late, and a bound below that
        // would drop every tick's backlog and hold simulated time below the factor throughout.
        .within(0.002, 1.0);
        d.boolean("lidar.enabled", true, "publish scan", |c, v| c.lidar_enabled = v);
        d.double("lidar.fov", lidar.fov, "field of view [rad]", |c, v| c.lidar.fov = v)
            .within(0.01, std::f64::consts::TAU);
        d.count("lidar.beams", lidar.beams, "beams per scan", |c, v| c.lidar.beams = v)
            .within(2.0, 100_000.0);
        d.double("lidar.range_min", lidar.range_min, "[m]", |c, v| c.lidar.range_min = v)
            .min(0.0);
        d.double("lidar.range_max", lidar.range_max, "[m]", |c, v| c.lidar.range_max = v)
            .above(0.0);
        d.double("lidar.noise_std", lidar.noise_std, "range noise std [m]", |c, v| {
            c.lidar.noise_std = v
        })
        .min(0.0);
        d.double("lidar.rate_hz", lidar.rate_hz, "scans per simulated second", |c, v| {
            c.lidar.rate_hz = v
        })
        .within(0.1, 1000.0);
        d.doubles(
            "lidar.mount",
            lidar.mount,
            "x, y, yaw of the laser in base_link",
            |c, v| c.lidar.mount = v,
        );
        d.string("world_frame", "odom", "frame of ground_truth", |c, v| c.world_frame = v);
        d.string("base_frame", "base_link", "robot frame (reference point)", |c, v| {
            c.base_frame = v
        });
        d.string("laser_frame", "laser", "frame of scan", |c, v| c.laser_frame = v);
    }

    fn validate(&self) -> Result<(), ConfigError> {
        self.lidar.validate().map_err(ConfigError::inconsistent)?;
        self.plant().map(|_| ())
    }
}

impl SimConfig {
    /// The plant's settings, with the validated chassis.
    fn plant(&self) -> Result<PlantConfig, ConfigError> {
        Ok(PlantConfig {
            params: chassis_params(&self.chassis)?,
            motor_time_constant: self.motor_time_constant,
            wheel_speed_noise: self.wheel_speed_noise,
            wheel_slip: self.wheel_slip,
            robot_radius: self.robot_radius,
        })
    }

    /// The LIDAR's settings, if it is enabled.
    fn lidar(&self) -> Option<LidarConfig> {
        self.lidar_enabled.then_some(self.lidar)
    }

    /// Physics steps per wall second.
    fn tick_rate_hz(&self) -> f64 {
        self.physics_rate_hz * self.real_time_factor
    }
}

fn decl() -> NodeDecl {
    NodeDecl::for_config::<SimConfig>("sim", "Simulated chassis, 2D world and LIDAR")
}

/// The world named by `world_file` (read-only, so read once at start-up).
fn load_world(config: &SimConfig) -> anyhow::Result<World> {
    if config.world_file.is_empty() {
        Ok(World::builtin())
    } else {
        Ok(World::load(&config.world_file)?)
    }
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

/// A `wheel_commands` sample.
enum Command {
    Joints(JointState),
    /// Could not be decoded (logged): the wheels stop.
    Undecodable,
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

async fn run(node: &mut RosNode) -> anyhow::Result<()> {
    let mut config: SimConfig = node.config()?;
    let mut plant_config = config.plant()?;
    let world = load_world(&config)?;
    let start = config.initial_pose;
    if world.collides(nalgebra::Point2::new(start[0], start[1]), config.robot_radius) {
        anyhow::bail!("initial_pose {start:?} collides with the world");
    }
    let mut plant = Plant::new(plant_config, V3::from(config.initial_pose), config.seed);
    let mut lidar = config.lidar().map(|c| Lidar::new(c, config.seed.wrapping_add(1)));
    info!(
        "simulating a {} chassis in a world of {} obstacles; lidar {}",
        plant_config.params.model().as_str(),
        world.obstacles.len(),
        match &config.lidar() {
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
    if let Some(l) = &config.lidar() {
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

    // A bad command stops the wheels, as real motor drivers do: the previous command must not
    // keep them turning until the driver timeout.
    let mut inputs = Inputs::new();
    inputs.add_guarded(
        commands_sub.async_stream(),
        "wheel_commands",
        "wheels stopped",
        Command::Joints,
        || Some(Command::Undecodable),
    );
    let shutdown = shutdown_signal();
    // Burst: a late physics step is caught up, so simulated time keeps its rate.
    let mut tick = Ticker::with_missed_tick_behavior(config.tick_rate_hz(), MissedTickBehavior::Burst)?;
    tokio::pin!(shutdown);
    let mut throttle = LogThrottle::default();
    let dt = 1.0 / config.physics_rate_hz;
    let (mut next_joints, mut next_scan) = (0.0f64, 0.0f64);
    let mut reported_collision = false;
    let mut watch = CommandWatch::default();
    let mut diagnostics = SimDiagnostics {
        out: DiagnosticsOut::create(node)?,
        since: None,
        refused: 0,
        collision: None,
    };

    loop {
        tokio::select! {
            _ = &mut shutdown => break,
            Some(changed) = node.config_changed::<SimConfig>() => match changed.and_then(|new| Ok((new.plant()?, new))) {
                Ok((new_plant, new)) => {
                    // The declared ranges keep the rate valid; a refusal would keep the old one.
                    if let Err(e) = tick.set_rate(new.tick_rate_hz()) {
                        warn!("real_time_factor not applied: {e}");
                    }
                    lidar = match (new.lidar(), lidar.take()) {
                        (Some(c), Some(l)) if Some(c) == config.lidar() => Some(l),
                        (Some(c), _) => Some(Lidar::new(c, config.seed.wrapping_add(1))),
                        (None, _) => None,
                    };
                    if new.real_time_factor != config.real_time_factor {
                        // The next measurement starts at the new rate, not blended with the old.
                        diagnostics.since = None;
                    }
                    plant.reconfigure(new_plant);
                    plant_config = new_plant;
                    config = new;
                }
                Err(e) => warn!("parameter change not applied: {e}"),
            },
            command = inputs.next() => match command? {
                Command::Joints(js) => match wheel_state_from_joints(plant_config.params.model(), &js.name, &js.position, &js.velocity) {
                    Ok(wheels) => match plant.command(&wheels) {
                        Ok(CommandOutcome::Accepted) => watch.commanded(js.header.stamp.clone(), Instant::now()),
                        Ok(CommandOutcome::Limited) => {
                            watch.commanded(js.header.stamp.clone(), Instant::now());
                            warn_throttled!(
                            throttle,
                            "limit",
                            "wheel_commands beyond the chassis limits (max_wheel_speed, max_steering) held to them: {:?}",
                            plant.commanded()
                            )
                        }
                        Err(e) => {
                            diagnostics.refused += 1;
                            warn_throttled!(throttle, "cmd", "wheel_commands refused: {e}")
                        }
                    },
                    Err(e) => {
                        diagnostics.refused += 1;
                        plant.stop();
                        warn_throttled!(throttle, "cmd", "wheel_commands dropped, wheels stopped: {e}");
                    }
                },
                // Logged (rate-limited) by the inputs.
                Command::Undecodable => {
                    diagnostics.refused += 1;
                    plant.stop()
                }
            },
            scheduled = tick.tick() => {
                // With its own clock the simulation never runs ahead of the nodes it drives by
                // more than clock_catch_up_s of wall time: after a longer stall (this process,
                // or a machine short of CPU) it goes on from where it stood, rather than
                // stepping through the backlog at once while they still act on old samples.
                // Without it the stamps are wall time, which the catch-up keeps.
                if config.publish_clock {
                    let _ = tick.drop_backlog(
                        scheduled,
                        tokio::time::Instant::now(),
                        Duration::from_secs_f64(config.clock_catch_up_s),
                    );
                }
                if watch.check(config.command_timeout_s, Instant::now()) {
                    if watch.newly_stale() {
                        warn_throttled!(throttle, "cmd_timeout", "no wheel_commands for {} s: wheels stopped", config.command_timeout_s);
                    }
                    plant.stop();
                }
                plant.step(dt, &world);
                let t = plant.time();
                if plant.collided() && !reported_collision {
                    let at = plant.reference_pose();
                    warn!("the robot hit an obstacle at {at:?}");
                    diagnostics.collision = Some((at.x, at.y));
                    reported_collision = true;
                }
                let now = Instant::now();
                if diagnostics.out.due(now) {
                    let report = diagnostics.report(&config, t, watch.last.age_at(now), now);
                    let health = sim_health(&report);
                    let model = plant_config.params.model().as_str();
                    diagnostics.out.send(&[("simulation", model, health)], stamp_at(t, config.publish_clock), now, &mut throttle);
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
                if let (Some(l), Some(cfg)) = (lidar.as_mut(), config.lidar())
                    && t + 1e-9 >= next_scan
                {
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
    Ok(())
}

/// `/diagnostics` once a second, and what it gathers between reports.
struct SimDiagnostics {
    out: DiagnosticsOut,
    /// Simulated time and the wall instant at the last report.
    since: Option<(f64, Instant)>,
    /// `wheel_commands` refused or dropped since the last report.
    refused: u64,
    /// Where the robot first hit an obstacle.
    collision: Option<(f64, f64)>,
}

impl SimDiagnostics {
    /// The report at simulated time `t` and wall instant `now` (the factor measured since the
    /// last one; the refusals counted anew from here).
    fn report(&mut self, config: &SimConfig, t: f64, command_age: Option<Duration>, now: Instant) -> SimReport {
        let factor_measured = self.since.and_then(|(t0, wall0)| {
            let wall = now.duration_since(wall0).as_secs_f64();
            (wall > 0.0).then(|| (t - t0) / wall)
        });
        self.since = Some((t, now));
        SimReport {
            factor_asked: config.real_time_factor,
            factor_measured,
            command_age_s: command_age.map(|a| a.as_secs_f64()),
            command_timeout_s: config.command_timeout_s,
            commands_refused: std::mem::take(&mut self.refused),
            collision: self.collision,
        }
    }
}

/// The simulated drivers' command timeout: the last valid `wheel_commands` in a [`Latest`]
/// (steady receive instant), judged on every physics step.
#[derive(Default)]
struct CommandWatch {
    last: Latest<()>,
    /// The last check found the commands stale (after having had fresh ones).
    stale: bool,
    /// `stale` turned true at the last check.
    newly: bool,
}

impl CommandWatch {
    /// A valid command arrived at `now`.
    fn commanded(&mut self, stamp: mobil_msgs::builtin_interfaces::msg::Time, now: Instant) {
        self.last.set_at((), stamp, now);
    }

    /// True if the drivers must hold the wheels stopped at `now`: the last command is older
    /// than `timeout_s` (0: never), or there never was one (the wheels are at rest then; the
    /// stop changes nothing and is not reported).
    fn check(&mut self, timeout_s: f64, now: Instant) -> bool {
        if timeout_s <= 0.0 {
            self.stale = false;
            self.newly = false;
            return false;
        }
        let max_age = Duration::try_from_secs_f64(timeout_s).unwrap_or(Duration::MAX);
        let (stop, stale) = match self.last.status_at(max_age, now) {
            Freshness::Fresh => (false, false),
            Freshness::Stale { .. } => (true, true),
            Freshness::Never => (true, false),
        };
        self.newly = stale && !self.stale;
        self.stale = stale;
        stop
    }

    /// The commands went stale at the last check (to log once, not on every step).
    fn newly_stale(&self) -> bool {
        self.newly
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_drivers_stop_once_the_last_command_is_older_than_the_timeout() {
        let ms = Duration::from_millis;
        let t0 = Instant::now();
        let mut w = CommandWatch::default();
        assert!(w.check(1.0, t0), "no command yet: at rest");
        assert!(!w.newly_stale(), "nothing to report before the first command");
        w.commanded(Default::default(), t0);
        assert!(!w.check(1.0, t0 + ms(1000)), "exactly the timeout: still driving");
        assert!(w.check(1.0, t0 + ms(1001)));
        assert!(w.newly_stale(), "reported once...");
        assert!(w.check(1.0, t0 + ms(1020)));
        assert!(!w.newly_stale(), "...not on every step");
        // A new command drives again; 0 turns the timeout off.
        w.commanded(Default::default(), t0 + ms(1100));
        assert!(!w.check(1.0, t0 + ms(1200)));
        assert!(!w.check(0.0, t0 + ms(60_000)));
        assert!(
            w.check(0.5, t0 + ms(1601)) && w.newly_stale(),
            "a shorter timeout applies at once"
        );
    }

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
