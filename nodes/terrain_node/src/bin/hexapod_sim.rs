//! `hexapod_sim`: a tripod-gait hexapod walking straight ahead (world +x) over flat ground, a
//! slope, seeded rough ground or the course flat → ramp → rough ([`mobil_terrain::Walker`]).
//! It publishes what a real hexapod's control would: each touchdown on `terrain/touchdown`
//! (stamped with the touchdown's instant, in the body frame, the foot as leg kinematics measure
//! it) and the body's pose as `odom` (nav_msgs/Odometry, `odom` → `base_link`) and on `tf` —
//! the pair every ROS tool (RViz, Nav2, tf2) reads a mobile base's pose from.
//!
//! Time as in `sim_node`: real time by default, stamps from the system clock; with
//! `publish_clock` it publishes `/clock` (simulated time from 0) and may run faster
//! (`real_time_factor`) for nodes started with `use_sim_time:=true`. Simulated time advances by
//! the wall time between steps times the factor, so a late step catches up; each touchdown is
//! sent once, with its own time, whatever the step. With `wait_for_subscriber` the walk (t = 0)
//! starts once `terrain/touchdown` has a subscriber. That narrows what discovery can lose but
//! does not close it: this writer can see the reader before the reader has matched the writer,
//! and a volatile reader gets nothing written before that; the walk's first touchdowns may be
//! lost, and a tripod later every foot is known again.
//! Stops on SIGINT/SIGTERM.

use mobil_msgs::geometry_msgs::msg::{Transform, TransformStamped, Vector3};
use mobil_msgs::mobil_msgs::msg::FootTouchdown;
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_msgs::rosgraph_msgs::msg::Clock;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::tf2_msgs::msg::TFMessage;
use mobil_ros::geometry::{planar_odometry, yaw_quaternion};
use mobil_ros::time::{stamp_from_nanos, stamp_from_secs};
use mobil_ros::{qos, run_node, shutdown_signal, warn_throttled, LogThrottle, NodeDecl, RosNode, Ticker};
use mobil_terrain_node::hexapod_sim::{touchdown_message, HexapodSimConfig};
use std::process::ExitCode;
use std::time::Instant;
use tokio::time::MissedTickBehavior;
use tracing::info;

fn decl() -> NodeDecl {
    NodeDecl::for_config::<HexapodSimConfig>(
        "hexapod_sim",
        "A tripod-gait hexapod walking over flat, sloped, rough or mixed ground: terrain/touchdown, odom and tf out",
    )
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

async fn run(node: &mut RosNode) -> anyhow::Result<()> {
    let mut config: HexapodSimConfig = node.config()?;
    let walker = config.walker()?;
    let touch_pub = node.publisher::<FootTouchdown>("terrain/touchdown", &qos::reliable(10))?;
    let odom_pub = node.publisher::<Odometry>("odom", &qos::default_qos())?;
    let tf_pub = node.publisher::<TFMessage>("tf", &qos::default_qos())?;
    let clock_pub = if config.publish_clock {
        Some(node.publisher::<Clock>("/clock", &qos::reliable(1))?)
    } else {
        None
    };
    info!(
        "walking at {} m/s (gait period {} s) on {:?} ground, {}× real time{}",
        config.speed,
        config.gait_period,
        config.ground,
        config.real_time_factor,
        if config.publish_clock {
            ", publishing /clock"
        } else {
            ""
        }
    );
    let shutdown = shutdown_signal();
    tokio::pin!(shutdown);
    let mut tick = Ticker::with_missed_tick_behavior(config.tick_rate_hz, MissedTickBehavior::Delay)?;
    let mut throttle = LogThrottle::default();
    // Before the first step, t = −1 ns: the standing feet's touchdowns at t = 0 are in the first.
    let mut t = -1e-9;
    if config.wait_for_subscriber {
        info!("waiting for a subscriber of terrain/touchdown before the walk starts");
        let matched = touch_pub.wait_for_subscription(node.inner());
        tokio::select! {
            _ = &mut shutdown => return Ok(()),
            _ = matched => info!("terrain/touchdown has a subscriber: walking"),
        }
    }
    // Wall time of simulated t = 0, for stamps when there is no simulated clock: read when the
    // walk starts (after any wait for a subscriber), so the stamps keep pace with the wall clock.
    let epoch_nanos = node.now_nanos();
    let stamp_at = |t: f64, publish_clock: bool| {
        if publish_clock {
            stamp_from_secs(t)
        } else {
            stamp_from_nanos(epoch_nanos + (t * 1e9) as i64)
        }
    };
    let mut last_wall = Instant::now();
    enum Event {
        Shutdown,
        /// The new real_time_factor: the only parameter that may change (the rest is read-only).
        Factor(Result<f64, mobil_ros::ConfigError>),
        Tick,
    }
    loop {
        let event = tokio::select! {
            _ = &mut shutdown => Event::Shutdown,
            Some(changed) = node.config_changed::<HexapodSimConfig>() => {
                Event::Factor(changed.map(|c| c.real_time_factor))
            }
            _ = tick.tick() => Event::Tick,
        };
        match event {
            Event::Shutdown => return Ok(()),
            Event::Factor(Ok(factor)) => config.real_time_factor = factor,
            Event::Factor(Err(e)) => tracing::warn!("parameter change not applied: {e}"),
            Event::Tick => {
                let now = Instant::now();
                let t1 = (t + now.duration_since(last_wall).as_secs_f64() * config.real_time_factor).max(0.0);
                last_wall = now;
                if let Some(clock) = &clock_pub {
                    let _ = clock.publish(Clock {
                        clock: stamp_from_secs(t1),
                    });
                }
                for td in walker.touchdowns_in(t, t1) {
                    let msg = touchdown_message(&td, stamp_at(td.t, config.publish_clock), &config.body_frame);
                    if let Err(e) = touch_pub.publish(msg) {
                        warn_throttled!(throttle, "touchdown", "cannot publish terrain/touchdown: {e:?}");
                    }
                }
                t = t1;
                let pose = walker.body_pose(t);
                let stamp = stamp_at(t, config.publish_clock);
                let header = Header {
                    stamp,
                    frame_id: config.world_frame.clone(),
                };
                let mut odom = planar_odometry(
                    header.clone(),
                    &config.body_frame,
                    [pose.position.x, pose.position.y, pose.yaw],
                    [config.speed, 0.0, 0.0],
                );
                odom.pose.pose.position.z = pose.position.z;
                let _ = odom_pub.publish(odom);
                let tf = TransformStamped {
                    header,
                    child_frame_id: config.body_frame.clone(),
                    transform: Transform {
                        translation: Vector3 {
                            x: pose.position.x,
                            y: pose.position.y,
                            z: pose.position.z,
                        },
                        rotation: yaw_quaternion(pose.yaw),
                    },
                };
                let _ = tf_pub.publish(TFMessage { transforms: vec![tf] });
            }
        }
    }
}
