//! `plan_demo`: the demo's third act. Asks `planner_node` to pre-check a waypoint route
//! (`planner/check_route`, from the robot's odometry pose) and prints the answer, sends the route
//! on `waypoints` and follows `planner/status` until it ends, then sends a dock on `dock_pose` and
//! follows the docking to its end; records the true path (`ground_truth`), the odometry track of
//! the route (the samples stamped within it: waypoints it never came within `reach_tolerance` of
//! count as missed) and the docking status (e, α, Θ, V, mode), writes one SVG (map: obstacles,
//! route, predicted and true paths, dock, problems; panels: V(t) and e(t)) and prints a one-line
//! summary. The record, summary and figure are `mobil_tools::plan` (tested there).

use std::process::ExitCode;
use std::time::{Duration, Instant};

use futures::StreamExt;
use mobil_msgs::geometry_msgs::msg::{Pose, PoseStamped};
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::mobil_msgs::srv::{CheckRoute, CheckRouteRequest, CheckRouteResponse};
use mobil_msgs::nav_msgs::msg::{Odometry, Path};
use mobil_msgs::RosService;
use mobil_ros::geometry::{yaw_of, yaw_quaternion};
use mobil_ros::params::ParamValues;
use mobil_ros::time::{nanos_from_stamp, stamp_from_nanos};
use mobil_ros::{qos, run_node, shutdown_signal, NodeDecl, ParamSpec, RosNode};
use mobil_tools::plan::{
    closest_approach, figure, route_track, DockSample, Outcome, PlanRun, Problem, Summary, DEMO_DOCK, DEMO_ROUTE,
};
use mobil_tools::plot::{world_to_draw, write_file};
use ros2_client::{Name, ServiceMapping};
use tracing::info;

fn decl() -> NodeDecl {
    let route: Vec<f64> = DEMO_ROUTE.iter().flat_map(|&(x, y)| [x, y]).collect();
    NodeDecl::new(
        "plan_demo",
        "Pre-checks a route with planner_node, follows it, docks, plots the run",
    )
    .param(ParamSpec::doubles(
        "route",
        &route,
        "waypoints [x0, y0, x1, y1, ...] in odom [m]",
    ))
    .param(ParamSpec::doubles(
        "dock",
        &[DEMO_DOCK.0, DEMO_DOCK.1, DEMO_DOCK.2],
        "dock x, y [m], yaw [rad] in odom",
    ))
    .param(ParamSpec::string(
        "output_svg",
        "demo_out/planner.svg",
        "where to write the plot",
    ))
    .param(ParamSpec::string(
        "world_file",
        "",
        "world to draw (empty: the built-in world)",
    ))
    .param(ParamSpec::string(
        "model",
        "",
        "chassis model (from the params file's /** section); a steered one (car_like, tricycle) explains the docking residual",
    ))
    .param(
        ParamSpec::double(
            "reach_tolerance",
            0.16,
            "a waypoint the odometry came this near counts as reached (the planner's Z_crit) [m]",
        )
        .above(0.0),
    )
    .param(ParamSpec::double("timeout_s", 90.0, "wall time allowed for the whole run [s]").above(0.0))
    .check(|p: &ParamValues| {
        let route = p.f64s("route")?;
        if route.is_empty() || route.len() % 2 != 0 || !route.iter().all(|v| v.is_finite()) {
            return Err("route must be a non-empty list of finite x, y pairs".into());
        }
        match p.f64s("dock")?.as_slice() {
            [x, y, yaw] if x.is_finite() && y.is_finite() && yaw.is_finite() => Ok(()),
            _ => Err("dock must be three finite numbers [x, y, yaw]".into()),
        }
    })
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

fn pose_stamped(node: &RosNode, x: f64, y: f64, yaw: f64) -> PoseStamped {
    let mut p = PoseStamped::default();
    p.header.frame_id = "odom".into();
    p.header.stamp = stamp_from_nanos(node.now_nanos());
    p.pose.position.x = x;
    p.pose.position.y = y;
    p.pose.orientation = yaw_quaternion(yaw);
    p
}

fn route_msg(node: &RosNode, route: &[(f64, f64)]) -> Path {
    let mut path = Path::default();
    path.header.frame_id = "odom".into();
    path.header.stamp = stamp_from_nanos(node.now_nanos());
    path.poses = route.iter().map(|&(x, y)| pose_stamped(node, x, y, 0.0)).collect();
    path
}

/// Seconds between two clock readings in nanoseconds.
fn secs(from: i64, to: i64) -> f64 {
    (to - from) as f64 * 1e-9
}

/// Asks `planner/check_route` for `route` from the robot's current odometry pose, re-sending
/// each 2 s (a request sent before discovery matched is lost) until `deadline`.
async fn check(node: &mut RosNode, route: &[(f64, f64)], deadline: Instant) -> anyhow::Result<CheckRouteResponse> {
    let name = node.names().resolve("planner/check_route")?;
    let name = Name::parse(&name).map_err(|e| anyhow::anyhow!("bad service name {name}: {e:?}"))?;
    let qos = qos::reliable(10);
    let client = node
        .inner()
        .create_client::<CheckRouteRequest, CheckRouteResponse>(
            ServiceMapping::Enhanced,
            &name,
            &CheckRoute::type_name(),
            qos.clone(),
            qos,
        )
        .map_err(|e| anyhow::anyhow!("cannot create a client of {name}: {e:?}"))?;
    let shutdown = shutdown_signal();
    tokio::pin!(shutdown);
    loop {
        if Instant::now() > deadline {
            anyhow::bail!("planner/check_route did not answer (is planner_node running on this ROS_DOMAIN_ID?)");
        }
        let request = CheckRouteRequest {
            route: route_msg(node, route),
            use_start: false,
            start: Pose::default(),
        };
        tokio::select! {
            _ = &mut shutdown => anyhow::bail!("interrupted"),
            answer = tokio::time::timeout(Duration::from_secs(2), client.async_call_service(request)) => {
                match answer {
                    Ok(Ok(reply)) => {
                        // Refused for want of fresh odometry at start-up: ask again.
                        if !reply.feasible && reply.problems.is_empty() && reply.reason.contains("odom") {
                            info!("pre-check refused ({}); asking again", reply.reason);
                            tokio::time::sleep(Duration::from_millis(500)).await;
                            continue;
                        }
                        return Ok(reply);
                    }
                    Ok(Err(e)) => info!("pre-check call failed ({e:?}); asking again"),
                    Err(_) => info!("no pre-check answer within 2 s; asking again"),
                }
            }
        }
    }
}

/// Where the act is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// The route was sent; waiting for the planner's ACTIVE.
    RouteSent,
    /// Following the route, accepted at this time (ns).
    Route(i64),
    /// The dock was sent at this time (ns); waiting for the planner's ACTIVE.
    DockSent(i64),
    /// Docking, sent at this time (ns).
    Dock(i64),
}

fn is_docking_mode(mode: &str) -> bool {
    matches!(mode, "dock" | "rotate")
}

async fn run(node: &mut RosNode) -> anyhow::Result<()> {
    let p = node.params();
    let map_err = anyhow::Error::msg;
    let route: Vec<(f64, f64)> = p
        .f64s("route")
        .map_err(map_err)?
        .chunks_exact(2)
        .map(|c| (c[0], c[1]))
        .collect();
    let dock = match p.f64s("dock").map_err(map_err)?.as_slice() {
        [x, y, yaw] => (*x, *y, *yaw),
        _ => anyhow::bail!("dock must be [x, y, yaw]"),
    };
    let out = p.string("output_svg").map_err(map_err)?;
    let world_file = p.string("world_file").map_err(map_err)?;
    let steered = matches!(p.string("model").map_err(map_err)?.as_str(), "car_like" | "tricycle");
    let tolerance = p.f64("reach_tolerance").map_err(map_err)?;
    let timeout = Duration::from_secs_f64(p.f64("timeout_s").map_err(map_err)?);
    let world = world_to_draw(&world_file)?;
    let deadline = Instant::now() + timeout;

    let route_pub = node.publisher::<Path>("waypoints", &qos::default_qos())?;
    let dock_pub = node.publisher::<PoseStamped>("dock_pose", &qos::default_qos())?;
    let truth_sub = node.subscription::<Odometry>("ground_truth", &qos::default_qos())?;
    // 500 samples: 10 simulated seconds at 50 Hz, so that a recorder seconds behind drops none.
    let odom_sub = node.subscription::<Odometry>("odom", &qos::reliable(500))?;
    let status_sub = node.subscription::<NavStatus>("planner/status", &qos::latched())?;

    info!("asking planner/check_route about {} waypoints...", route.len());
    let answer = check(node, &route, deadline).await?;
    let problems: Vec<Problem> = answer
        .problems
        .iter()
        .map(|p| Problem {
            index: p.index,
            kind: p.kind.clone(),
            detail: p.detail.clone(),
            at: (p.position.x, p.position.y),
        })
        .collect();
    if answer.feasible {
        println!(
            "  pre-check: route of {} waypoints feasible, predicted path {:.2} m",
            route.len(),
            answer.length
        );
    } else {
        println!(
            "  pre-check: route of {} waypoints not feasible, {} problem(s): {}",
            route.len(),
            problems.len(),
            answer.reason
        );
        for p in &problems {
            println!("    waypoint {}: {}: {}", p.index, p.kind, p.detail);
        }
    }

    let truth = truth_sub.async_stream();
    let odom = odom_sub.async_stream();
    let status = status_sub.async_stream();
    let shutdown = shutdown_signal();
    let mut resend = tokio::time::interval(Duration::from_millis(1000));
    tokio::pin!(truth, odom, status, shutdown);

    let mut record = PlanRun {
        waypoints: route.clone(),
        feasible: answer.feasible,
        problems,
        predicted: answer
            .simulated_path
            .poses
            .iter()
            .map(|p| (p.pose.position.x, p.pose.position.y))
            .collect(),
        predicted_length: answer.length,
        path: Vec::new(),
        odom_path: Vec::new(),
        route_outcome: Outcome::Failed("not started".into()),
        route_s: 0.0,
        dock,
        docking: Vec::new(),
        dock_outcome: Outcome::Failed("not started".into()),
        final_truth: None,
    };
    let mut phase = Phase::RouteSent;
    // Every odometry sample (stamp, x, y); the route's are chosen by stamp once it has ended.
    let mut odom_samples: Vec<(i64, f64, f64)> = Vec::new();
    let mut route_window: Option<(i64, i64)> = None;
    let mut route_reason = String::new();
    loop {
        tokio::select! {
            _ = &mut shutdown => anyhow::bail!("interrupted"),
            _ = resend.tick() => {
                if Instant::now() > deadline {
                    anyhow::bail!("the planner did not finish within {timeout:?} (phase {phase:?})");
                }
                // Repeated until the planner shows it active: the first may be lost in discovery.
                match phase {
                    Phase::RouteSent => {
                        let _ = route_pub.publish(route_msg(node, &route));
                    }
                    Phase::DockSent(_) => {
                        let _ = dock_pub.publish(pose_stamped(node, dock.0, dock.1, dock.2));
                    }
                    _ => {}
                }
            }
            Some(Ok((m, _))) = truth.next() => {
                let pose = &m.pose.pose;
                record.path.push((pose.position.x, pose.position.y));
                record.final_truth = Some((pose.position.x, pose.position.y, yaw_of(&pose.orientation)));
            }
            Some(Ok((m, _))) = odom.next() => {
                if let Some(t) = nanos_from_stamp(&m.header.stamp) {
                    odom_samples.push((t, m.pose.pose.position.x, m.pose.pose.position.y));
                }
            }
            Some(Ok((s, _))) = status.next() => {
                let now = node.now_nanos();
                let stamp = nanos_from_stamp(&s.header.stamp).filter(|&t| t > 0).unwrap_or(now);
                let finished = s.state == NavStatus::SUCCEEDED || s.state == NavStatus::FAILED;
                let outcome = || if s.state == NavStatus::SUCCEEDED { Outcome::Succeeded } else { Outcome::Failed(s.reason.clone()) };
                match phase {
                    Phase::RouteSent if s.state == NavStatus::ACTIVE && s.waypoint_index >= 0 => {
                        info!("route accepted");
                        phase = Phase::Route(stamp);
                    }
                    Phase::Route(t0) if finished => {
                        record.route_outcome = outcome();
                        record.route_s = secs(t0, stamp);
                        route_window = Some((t0, stamp));
                        route_reason = s.reason.clone();
                        info!("route ended: {:?}; sending the dock", record.route_outcome);
                        phase = Phase::DockSent(now);
                        let _ = dock_pub.publish(pose_stamped(node, dock.0, dock.1, dock.2));
                    }
                    Phase::DockSent(t0) | Phase::Dock(t0) if is_docking_mode(&s.mode) && (s.state == NavStatus::ACTIVE || finished) => {
                        if matches!(phase, Phase::DockSent(_)) {
                            info!("dock accepted");
                            phase = Phase::Dock(t0);
                        }
                        // A final status with the docking fields cleared adds no sample.
                        let cleared = s.e == 0.0 && s.alpha == 0.0 && s.theta == 0.0 && s.lyapunov == 0.0;
                        if !(finished && cleared) {
                            record.docking.push(DockSample::from_status(secs(t0, stamp), s.e, s.alpha, s.theta, s.lyapunov, &s.mode));
                        }
                        if finished {
                            record.dock_outcome = outcome();
                            break;
                        }
                    }
                    Phase::Dock(_) if finished => {
                        record.dock_outcome = outcome();
                        break;
                    }
                    _ => {}
                }
            }
        }
    }

    if let Some((start, end)) = route_window {
        // One joint_states period (20 ms simulated) of slack: the planner's clock may lag the
        // stamp of the sample it ended the route on.
        record.odom_path = route_track(&odom_samples, start, end, 20_000_000);
    }
    let summary = Summary::of(&record, tolerance);
    let title = format!(
        "{}: planner route and Lyapunov docking",
        node.names().fully_qualified_node()
    );
    write_file(&out, &figure(&world, &record, &title)).map_err(|e| anyhow::anyhow!("cannot write {out}: {e}"))?;
    println!("{}", summary.line(&out, steered));
    if !summary.missed.is_empty() {
        let closest: Vec<String> = summary
            .missed
            .iter()
            .map(|&i| {
                format!(
                    "{i} ({:.3} m)",
                    closest_approach(record.waypoints[i], &record.odom_path)
                )
            })
            .collect();
        println!(
            "  missed waypoints (the odometry's closest approach; reach within {tolerance} m): {}; the planner said: {}",
            closest.join(", "),
            if route_reason.is_empty() { "nothing" } else { &route_reason }
        );
    }
    Ok(())
}
