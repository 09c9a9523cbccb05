//! `scan_echo`: the floor of the end-to-end latency harness (`tests/bench_latency.py`). For every
//! `scan` (sensor_msgs/LaserScan, sensor-data QoS, as `local_nav_node` reads it) it publishes one
//! zero `cmd_vel` (geometry_msgs/Twist, default QoS, as `local_nav_node` writes it) at once,
//! doing nothing else, so a round trip through it is the DDS and message (de)serialisation cost
//! a navigator cannot beat. The scan's stamp is echoed in `angular.x` (seconds) and `angular.y`
//! (nanoseconds) so that the harness can pair replies with scans; a real chassis would ignore
//! them, but this node is not meant to drive one.

use futures::StreamExt;
use mobil_msgs::geometry_msgs::msg::Twist;
use mobil_msgs::sensor_msgs::msg::LaserScan;
use mobil_ros::input::{decoded, Input};
use mobil_ros::{qos, run_node, shutdown_signal, NodeDecl, RosNode};
use std::process::ExitCode;

fn main() -> ExitCode {
    run_node(
        &NodeDecl::new(
            "scan_echo",
            "Answers every scan with one cmd_vel at once (the latency floor of tests/bench_latency.py)",
        ),
        |node| Box::pin(echo(node)),
    )
}

async fn echo(node: &mut RosNode) -> anyhow::Result<()> {
    let scan_sub = node.subscription::<LaserScan>("scan", &qos::sensor_data())?;
    let cmd = node.publisher::<Twist>("cmd_vel", &qos::default_qos())?;
    let scans = decoded(scan_sub.async_stream(), "scan", "scan_decode", "no reply");
    let shutdown = shutdown_signal();
    tokio::pin!(scans, shutdown);
    loop {
        tokio::select! {
            _ = &mut shutdown => break,
            Some(input) = scans.next() => {
                if let Input::Message(scan) = input {
                    let mut twist = Twist::default();
                    twist.angular.x = f64::from(scan.header.stamp.sec);
                    twist.angular.y = f64::from(scan.header.stamp.nanosec);
                    // A lost reply shows in the harness' count; nothing to do about it here.
                    let _ = cmd.publish(twist);
                }
            }
        }
    }
    Ok(())
}
