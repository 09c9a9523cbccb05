//! `plan_demo`: the demo's third act. Asks `planner_node` to pre-check a waypoint route
//! (`planner/check_route`, from the robot's odometry pose) and prints the answer, sends the route
//! on `waypoints` and follows `planner/status` until it ends, then sends a dock on `dock_pose` and
//! follows the docking to its end; records the true path (`ground_truth`), the odometry track of
//! the route (the samples stamped within it: waypoints it never came within `reach_tolerance` of
//! count as missed) and the docking status (e, α, Θ, V, mode), writes one SVG (map: obstacles,
//! route, predicted and true paths, dock, problems; panels: V(t) and e(t)) and prints a one-line
//! summary. The act's course, record, summary and figure are `mobil_tools::plan` (tested there).

use std::process::ExitCode;
use std::time::{Duration, Instant};

use futures::StreamExt;
use mobil_msgs::geometry_msgs::msg::{Pose, PoseStamped};
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::mobil_msgs::srv::{CheckRoute, CheckRouteRequest, CheckRouteResponse};
use mobil_msgs::nav_msgs::msg::{Odometry, Path};
use mobil_ros::geometry::yaw_of;
use mobil_ros::params::ParamValues;
use mobil_ros::time::nanos_from_stamp;
use mobil_ros::{qos, run_node, shutdown_signal, NodeDecl, ParamSpec, RosNode};
use mobil_tools::plan::{
    figure, precheck_lines, Next, OdomSample, Outcome, Phase, PlanAct, PlanRun, Problem, Summary, DEMO_DOCK, DEMO_ROUTE,
};
use mobil_tools::plot::{world_to_draw, write_file};
use mobil_tools::route::{flat_waypoints, parse_waypoints};
use mobil_tools_node::{pose_now, route_now, service_client, stamp_or, status_of};
use tracing::info;

fn decl() -> NodeDecl {
    let route = flat_waypoints(&DEMO_ROUTE);
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
        parse_waypoints(&p.f64s("route")?)?;
        match p.f64s("dock")?.as_slice() {
            [x, y, yaw] if x.is_finite() && y.is_finite() && yaw.is_finite() => Ok(()),
            _ => Err("dock must be three finite numbers [x, y, yaw]".into()),
        }
    })
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

/// Asks `planner/check_route` for `route` from the robot's current odometry pose, re-sending
/// each 2 s (a request sent before discovery matched is lost) until `deadline`.
async fn check(node: &mut RosNode, route: &[(f64, f64)], deadline: Instant) -> anyhow::Result<CheckRouteResponse> {
    let client = service_client::<CheckRoute>(node, "planner/check_route")?;
    let shutdown = shutdown_signal();
    tokio::pin!(shutdown);
    loop {
        if Instant::now() > deadline {
            anyhow::bail!("planner/check_route did not answer (is planner_node running on this ROS_DOMAIN_ID?)");
        }
        let request = CheckRouteRequest {
            route: route_now(node, route),
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

async fn run(node: &mut RosNode) -> anyhow::Result<()> {
    let p = node.params();
    let map_err = anyhow::Error::msg;
    let route = parse_waypoints(&p.f64s("route").map_err(map_err)?).map_err(map_err)?;
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
    let truth = truth_sub.async_stream();
    let odom = odom_sub.async_stream();
    let status = status_sub.async_stream();
    let shutdown = shutdown_signal();
    let mut resend = tokio::time::interval(Duration::from_millis(1000));
    tokio::pin!(truth, odom, status, shutdown);

    let mut act = PlanAct::new(PlanRun {
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
    });
    for line in precheck_lines(&act.run, &answer.reason) {
        println!("{line}");
    }
    // Every odometry sample (stamp, x, y); the route's are chosen by stamp once it has ended.
    let mut odom_samples: Vec<OdomSample> = Vec::new();
    loop {
        tokio::select! {
            _ = &mut shutdown => anyhow::bail!("interrupted"),
            _ = resend.tick() => {
                if Instant::now() > deadline {
                    anyhow::bail!("the planner did not finish within {timeout:?} (phase {:?})", act.phase);
                }
                // Repeated until the planner shows it active: the first may be lost in discovery.
                match act.phase {
                    Phase::RouteSent => {
                        let _ = route_pub.publish(route_now(node, &route));
                    }
                    Phase::DockSent(_) => {
                        let _ = dock_pub.publish(pose_now(node, dock));
                    }
                    _ => {}
                }
            }
            Some(Ok((m, _))) = truth.next() => {
                let pose = &m.pose.pose;
                act.run.path.push((pose.position.x, pose.position.y));
                act.run.final_truth = Some((pose.position.x, pose.position.y, yaw_of(&pose.orientation)));
            }
            Some(Ok((m, _))) = odom.next() => {
                if let Some(t) = nanos_from_stamp(&m.header.stamp) {
                    odom_samples.push((t, m.pose.pose.position.x, m.pose.pose.position.y));
                }
            }
            Some(Ok((s, _))) = status.next() => {
                let now = node.now_nanos();
                match act.status(&status_of(&s), stamp_or(&s.header.stamp, now), now) {
                    Next::RouteAccepted => info!("route accepted"),
                    Next::SendDock => {
                        info!("route ended: {:?}; sending the dock", act.run.route_outcome);
                        let _ = dock_pub.publish(pose_now(node, dock));
                    }
                    Next::DockAccepted => info!("dock accepted"),
                    Next::Done => break,
                    Next::Wait => {}
                }
            }
        }
    }

    act.finish(&odom_samples);
    let record = &act.run;
    let summary = Summary::of(record, tolerance);
    let title = format!(
        "{}: planner route and Lyapunov docking",
        node.names().fully_qualified_node()
    );
    write_file(&out, &figure(&world, record, &title)).map_err(|e| anyhow::anyhow!("cannot write {out}: {e}"))?;
    println!("{}", summary.line(&out, steered));
    if let Some(line) = summary.missed_line(record, tolerance, &act.route_reason) {
        println!("{line}");
    }
    Ok(())
}
