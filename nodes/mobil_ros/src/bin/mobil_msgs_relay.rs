//! `mobil_msgs_relay`: republishes the suite's own messages, to check that another ROS 2
//! implementation (rclpy, rclcpp) and this one agree on their layouts.
//!
//! `terrain/assessment_in` → `terrain/assessment_out`, `gait/plan_in` → `gait/plan_out`
//! (reliable, depth 10), every message unchanged.

use futures::StreamExt;
use mobil_msgs::mobil_msgs::msg::{GaitPlan, TerrainAssessment};
use mobil_ros::{qos, run_node, shutdown_signal, LogThrottle, NodeDecl, RosNode};
use std::process::ExitCode;

fn main() -> ExitCode {
    let decl = NodeDecl::new(
        "mobil_msgs_relay",
        "Republishes mobil_msgs messages unchanged (interoperability check)",
    );
    run_node(&decl, |node| Box::pin(relay(node)))
}

async fn relay(node: &mut RosNode) -> anyhow::Result<()> {
    let q = qos::default_qos();
    let terrain_in = node.subscription::<TerrainAssessment>("terrain/assessment_in", &q)?;
    let terrain_out = node.publisher::<TerrainAssessment>("terrain/assessment_out", &q)?;
    let plan_in = node.subscription::<GaitPlan>("gait/plan_in", &q)?;
    let plan_out = node.publisher::<GaitPlan>("gait/plan_out", &q)?;
    let mut throttle = LogThrottle::default();
    let terrain = terrain_in.async_stream();
    let plans = plan_in.async_stream();
    let shutdown = shutdown_signal();
    tokio::pin!(terrain, plans, shutdown);
    loop {
        tokio::select! {
            _ = &mut shutdown => return Ok(()),
            Some(m) = terrain.next() => match m {
                Ok((msg, _)) => { let _ = terrain_out.publish(msg); }
                Err(e) => mobil_ros::warn_throttled!(throttle, "terrain", "dropped an undecodable TerrainAssessment: {e:?}"),
            },
            Some(m) = plans.next() => match m {
                Ok((msg, _)) => { let _ = plan_out.publish(msg); }
                Err(e) => mobil_ros::warn_throttled!(throttle, "plan", "dropped an undecodable GaitPlan: {e:?}"),
            },
        }
    }
}
