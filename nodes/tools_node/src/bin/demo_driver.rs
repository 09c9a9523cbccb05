//! `demo_driver`: drives a scripted route through `cmd_vel`, records `odom` (the chassis node's
//! wheel odometry) and `ground_truth` (the simulator), then writes an SVG of both tracks over the
//! world's obstacles and prints a one-line summary: distance driven and final odometry error.

use futures::StreamExt;
use mobil_msgs::geometry_msgs::msg::Twist;
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_ros::geometry::yaw_of;
use mobil_ros::params::ParamValues;
use mobil_ros::{qos, run_node, shutdown_signal, NodeDecl, ParamSpec, RosNode};
use mobil_tools::plot::{world_to_draw, write_file};
use mobil_tools::route::{default_loop, figure, parse_route, twist_at, Drift};
use std::process::ExitCode;
use std::time::Duration;
use tracing::info;

fn decl() -> NodeDecl {
    NodeDecl::new(
        "demo_driver",
        "Drives a scripted route, compares odometry with ground truth, plots the run",
    )
    .param(ParamSpec::doubles(
        "route",
        &default_loop(),
        "segments [v, omega, duration, ...] (m/s, rad/s, s)",
    ))
    .param(ParamSpec::double("rate_hz", 20.0, "cmd_vel rate").within(1.0, 1000.0))
    .param(ParamSpec::string(
        "output_svg",
        "demo_out/run.svg",
        "where to write the plot",
    ))
    .param(ParamSpec::string(
        "world_file",
        "",
        "world to draw (empty: the built-in world)",
    ))
    .param(ParamSpec::double("start_timeout_s", 30.0, "wall time to wait for odom and ground_truth").above(0.0))
    .check(|p: &ParamValues| parse_route(&p.f64s("route")?).map(|_| ()))
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(drive(node)))
}

fn pose(m: &Odometry) -> (f64, f64, f64) {
    (
        m.pose.pose.position.x,
        m.pose.pose.position.y,
        yaw_of(&m.pose.pose.orientation),
    )
}

async fn drive(node: &mut RosNode) -> anyhow::Result<()> {
    let p = node.params();
    let map_err = anyhow::Error::msg;
    let route = parse_route(&p.f64s("route").map_err(map_err)?).map_err(map_err)?;
    let period = Duration::from_secs_f64(1.0 / p.f64("rate_hz").map_err(map_err)?);
    let svg = p.string("output_svg").map_err(map_err)?;
    let world_file = p.string("world_file").map_err(map_err)?;
    let start_timeout = Duration::from_secs_f64(p.f64("start_timeout_s").map_err(map_err)?);
    let world = world_to_draw(&world_file)?;

    let cmd = node.publisher::<Twist>("cmd_vel", &qos::default_qos())?;
    let odom_sub = node.subscription::<Odometry>("odom", &qos::default_qos())?;
    let truth_sub = node.subscription::<Odometry>("ground_truth", &qos::default_qos())?;
    let odom = odom_sub.async_stream();
    let truth = truth_sub.async_stream();
    let shutdown = shutdown_signal();
    let mut tick = tokio::time::interval(period);
    tokio::pin!(odom, truth, shutdown);

    let mut odom_track: Vec<(f64, f64, f64)> = Vec::new();
    let mut truth_track: Vec<(f64, f64, f64)> = Vec::new();
    let waiting_since = std::time::Instant::now();
    let mut started_at: Option<i64> = None;
    let mut finished_at: Option<i64> = None;
    info!("waiting for odom and ground_truth...");
    loop {
        tokio::select! {
            _ = &mut shutdown => {
                let _ = cmd.publish(Twist::default());
                anyhow::bail!("interrupted before the route was complete");
            }
            Some(Ok((m, _))) = odom.next() => odom_track.push(pose(&m)),
            Some(Ok((m, _))) = truth.next() => truth_track.push(pose(&m)),
            _ = tick.tick() => {
                let now = node.now_nanos();
                let Some(t0) = started_at else {
                    let _ = cmd.publish(Twist::default());
                    if !odom_track.is_empty() && !truth_track.is_empty() && now > 0 {
                        info!("driving the route: {} segments", route.len());
                        odom_track.clear();
                        truth_track.clear();
                        started_at = Some(now);
                    } else if waiting_since.elapsed() > start_timeout {
                        anyhow::bail!("no odom/ground_truth within {start_timeout:?}: are sim_node and chassis_node running on this ROS_DOMAIN_ID?");
                    }
                    continue;
                };
                let t = (now - t0) as f64 * 1e-9;
                let mut twist = Twist::default();
                match twist_at(&route, t) {
                    Some((v, omega)) => {
                        twist.linear.x = v;
                        twist.angular.z = omega;
                    }
                    None => {
                        // Route over: hold still for one second so both streams settle.
                        let end = *finished_at.get_or_insert(now);
                        if (now - end) as f64 * 1e-9 > 1.0 {
                            let _ = cmd.publish(twist);
                            break;
                        }
                    }
                }
                let _ = cmd.publish(twist);
            }
        }
    }

    let Some(drift) = Drift::of(&truth_track, &odom_track) else {
        anyhow::bail!("odom or ground_truth stopped arriving");
    };
    let xy = |v: &[(f64, f64, f64)]| v.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>();
    let title = format!("{}: odometry vs ground truth", node.names().fully_qualified_node());
    write_file(&svg, &figure(&world, &xy(&truth_track), &xy(&odom_track), &title))
        .map_err(|e| anyhow::anyhow!("cannot write {svg}: {e}"))?;
    println!("{}", drift.line(&svg));
    Ok(())
}
