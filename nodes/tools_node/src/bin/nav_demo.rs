//! `nav_demo`: the demo's second act. Sends one goal to `local_nav_node` (`goal_pose`, in `odom`),
//! records the true path (`ground_truth`) and the navigator's modes (`local_nav/status`) until
//! the goal succeeds or fails, then writes an SVG of the world's obstacles, the path, the goal and
//! each point where the mode changed, coloured by mode (R blue, L orange, T red), and prints a
//! one-line summary. The record, summary and figure are `mobil_tools::nav` (tested there).

use futures::StreamExt;
use mobil_msgs::geometry_msgs::msg::PoseStamped;
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_ros::params::ParamValues;
use mobil_ros::{qos, run_node, shutdown_signal, NodeDecl, ParamSpec, RosNode};
use mobil_tools::nav::{figure, outcome_text, NavRun};
use mobil_tools::plot::{world_to_draw, write_file};
use mobil_tools_node::pose_now;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tracing::info;

fn decl() -> NodeDecl {
    NodeDecl::new(
        "nav_demo",
        "Sends a goal to local_nav_node, records the path and the modes, plots them",
    )
    .param(ParamSpec::doubles("goal", &[3.0, 4.0], "goal x, y in odom [m]"))
    .param(ParamSpec::string(
        "output_svg",
        "demo_out/local_nav.svg",
        "where to write the plot",
    ))
    .param(ParamSpec::string(
        "world_file",
        "",
        "world to draw (empty: the built-in world)",
    ))
    .param(ParamSpec::double("timeout_s", 60.0, "wall time allowed for the whole run [s]").above(0.0))
    .check(|p: &ParamValues| match p.f64s("goal")?.as_slice() {
        [x, y] if x.is_finite() && y.is_finite() => Ok(()),
        _ => Err("goal must be two finite numbers [x, y]".into()),
    })
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

async fn run(node: &mut RosNode) -> anyhow::Result<()> {
    let p = node.params();
    let map_err = anyhow::Error::msg;
    let goal = match p.f64s("goal").map_err(map_err)?.as_slice() {
        [x, y] => (*x, *y),
        _ => anyhow::bail!("goal must be [x, y]"),
    };
    let out = p.string("output_svg").map_err(map_err)?;
    let world_file = p.string("world_file").map_err(map_err)?;
    let timeout = Duration::from_secs_f64(p.f64("timeout_s").map_err(map_err)?);
    let world = world_to_draw(&world_file)?;

    let goal_pub = node.publisher::<PoseStamped>("goal_pose", &qos::default_qos())?;
    let truth_sub = node.subscription::<Odometry>("ground_truth", &qos::default_qos())?;
    let status_sub = node.subscription::<NavStatus>("local_nav/status", &qos::latched())?;
    let truth = truth_sub.async_stream();
    let status = status_sub.async_stream();
    let shutdown = shutdown_signal();
    let mut resend = tokio::time::interval(Duration::from_millis(500));
    tokio::pin!(truth, status, shutdown);

    let started = Instant::now();
    let mut record = NavRun::new(goal);
    let mut accepted_at: Option<i64> = None;
    let (final_state, reason) = loop {
        tokio::select! {
            _ = &mut shutdown => anyhow::bail!("interrupted"),
            _ = resend.tick() => {
                if started.elapsed() > timeout {
                    anyhow::bail!("local_nav did not finish within {timeout:?} (is local_nav_node running on this ROS_DOMAIN_ID?)");
                }
                // Repeated until the navigator shows it active: the first may be lost in discovery.
                if accepted_at.is_none() && !record.path.is_empty() {
                    let _ = goal_pub.publish(pose_now(node, (goal.0, goal.1, 0.0)));
                }
            }
            Some(Ok((m, _))) = truth.next() => {
                record.path.push((m.pose.pose.position.x, m.pose.pose.position.y));
            }
            Some(Ok((s, _))) = status.next() => {
                let ours = (s.goal.position.x - goal.0).hypot(s.goal.position.y - goal.1) < 1e-6;
                if s.state == NavStatus::ACTIVE && ours && accepted_at.is_none() {
                    info!("goal ({}, {}) accepted", goal.0, goal.1);
                    accepted_at = Some(node.now_nanos());
                }
                if accepted_at.is_none() {
                    continue;
                }
                if s.state == NavStatus::ACTIVE {
                    record.mode(&s.mode);
                } else if s.state == NavStatus::SUCCEEDED || s.state == NavStatus::FAILED {
                    break (s.state, s.reason);
                }
            }
        }
    };
    let sim_s = accepted_at.map_or(0.0, |t| (node.now_nanos() - t) as f64 * 1e-9);
    let outcome = outcome_text(final_state == NavStatus::SUCCEEDED, &reason);
    let title = record.title(&node.names().fully_qualified_node(), &outcome);
    write_file(&out, &figure(&world, &record, &title)).map_err(|e| anyhow::anyhow!("cannot write {out}: {e}"))?;
    println!("{}", record.summary(&outcome, sim_s, &out));
    Ok(())
}
