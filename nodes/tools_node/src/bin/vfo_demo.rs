//! `vfo_demo`: the demo's VFO act. Sends a waypoint route on `waypoints` to `planner_node` in
//! `waypoint_method: vfo` and follows `planner/status` until the route ends; records the true
//! path (`ground_truth`) and, from `planner/markers`, the optimisation with the most virtual
//! robots; writes one SVG (world, obstacles seen with r and R, every virtual robot of that
//! segment, the chosen path, the executed path) and prints one line. The record, summary and
//! figure are `mobil_tools::vfo` (tested there).

use std::process::ExitCode;
use std::time::{Duration, Instant};

use futures::StreamExt;
use mobil_msgs::geometry_msgs::msg::PoseStamped;
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::nav_msgs::msg::{Odometry, Path};
use mobil_msgs::visualization_msgs::msg::{Marker, MarkerArray};
use mobil_ros::geometry::yaw_quaternion;
use mobil_ros::params::ParamValues;
use mobil_ros::time::{nanos_from_stamp, stamp_from_nanos};
use mobil_ros::{qos, run_node, shutdown_signal, NodeDecl, ParamSpec, RosNode};
use mobil_tools::plot::write_file;
use mobil_tools::vfo::{figure, Optimisation, SeenObstacle, VfoRun, DEMO_ROUTE};
use mobil_world::World;
use tracing::info;

fn decl() -> NodeDecl {
    let route: Vec<f64> = DEMO_ROUTE.iter().flat_map(|&(x, y)| [x, y]).collect();
    NodeDecl::new(
        "vfo_demo",
        "Sends a route to planner_node in vfo mode, plots one segment's virtual robots and the run",
    )
    .param(ParamSpec::doubles(
        "route",
        &route,
        "waypoints [x0, y0, x1, y1, ...] in odom [m]",
    ))
    .param(ParamSpec::string(
        "output_svg",
        "demo_out/vfo.svg",
        "where to write the plot",
    ))
    .param(ParamSpec::double("robot_radius", 0.25, "the robot's radius, for the clearance [m]").above(0.0))
    .param(ParamSpec::double("timeout_s", 90.0, "wall time allowed for the whole run [s]").above(0.0))
    .check(|p: &ParamValues| {
        let route = p.f64s("route")?;
        if route.is_empty() || route.len() % 2 != 0 || !route.iter().all(|v| v.is_finite()) {
            return Err("route must be a non-empty list of finite x, y pairs".into());
        }
        Ok(())
    })
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

fn route_msg(node: &RosNode, route: &[(f64, f64)]) -> Path {
    let mut path = Path::default();
    path.header.frame_id = "odom".into();
    path.header.stamp = stamp_from_nanos(node.now_nanos());
    path.poses = route
        .iter()
        .map(|&(x, y)| {
            let mut p = PoseStamped {
                header: path.header.clone(),
                ..Default::default()
            };
            p.pose.position.x = x;
            p.pose.position.y = y;
            p.pose.orientation = yaw_quaternion(0.0);
            p
        })
        .collect();
    path
}

/// The optimisation drawn in `a`, if it has one.
fn optimisation(a: &MarkerArray, waypoint: i32) -> Option<Optimisation> {
    let robots: Vec<(Vec<(f64, f64)>, bool)> = a
        .markers
        .iter()
        .filter(|m| m.ns == "vfo_robots")
        .map(|m| (m.points.iter().map(|p| (p.x, p.y)).collect(), m.color.g < 0.55))
        .collect();
    if robots.is_empty() {
        return None;
    }
    let chosen = a
        .markers
        .iter()
        .find(|m| m.ns == "vfo_chosen")
        .map(|m| m.points.iter().map(|p| (p.x, p.y)).collect())
        .unwrap_or_default();
    let disc = |ns: &str, id: i32| -> Option<&Marker> { a.markers.iter().find(|m| m.ns == ns && m.id == id) };
    let obstacles = a
        .markers
        .iter()
        .filter(|m| m.ns == "vfo_forbidden")
        .filter_map(|r| {
            disc("vfo_influence", r.id).map(|big| SeenObstacle {
                centre: (r.pose.position.x, r.pose.position.y),
                r: r.scale.x / 2.0,
                big_r: big.scale.x / 2.0,
            })
        })
        .collect();
    Some(Optimisation {
        robots,
        chosen,
        obstacles,
        waypoint,
    })
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
    let out = p.string("output_svg").map_err(map_err)?;
    let robot_radius = p.f64("robot_radius").map_err(map_err)?;
    let timeout = Duration::from_secs_f64(p.f64("timeout_s").map_err(map_err)?);
    let deadline = Instant::now() + timeout;
    let world = World::builtin();

    let route_pub = node.publisher::<Path>("waypoints", &qos::default_qos())?;
    let truth_sub = node.subscription::<Odometry>("ground_truth", &qos::default_qos())?;
    let status_sub = node.subscription::<NavStatus>("planner/status", &qos::latched())?;
    let markers_sub = node.subscription::<MarkerArray>("planner/markers", &qos::default_qos())?;
    let truth = truth_sub.async_stream();
    let status = status_sub.async_stream();
    let markers = markers_sub.async_stream();
    let shutdown = shutdown_signal();
    let mut resend = tokio::time::interval(Duration::from_millis(1000));
    tokio::pin!(truth, status, markers, shutdown);

    let mut record = VfoRun {
        waypoints: route.clone(),
        path: Vec::new(),
        optimisation: Optimisation::default(),
        outcome: Err("not started".into()),
        duration_s: 0.0,
        robot_radius,
    };
    let mut started: Option<i64> = None;
    let mut waypoint = 0;
    loop {
        tokio::select! {
            _ = &mut shutdown => anyhow::bail!("interrupted"),
            _ = resend.tick() => {
                if Instant::now() > deadline {
                    anyhow::bail!("the planner did not finish within {timeout:?}");
                }
                // Repeated until the planner shows the route active: the first may be lost in
                // discovery.
                if started.is_none() {
                    let _ = route_pub.publish(route_msg(node, &route));
                }
            }
            Some(Ok((m, _))) = truth.next() => {
                if started.is_some() {
                    record.path.push((m.pose.pose.position.x, m.pose.pose.position.y));
                }
            }
            Some(Ok((a, _))) = markers.next() => {
                if let Some(o) = optimisation(&a, waypoint)
                    && o.robots.len() > record.optimisation.robots.len()
                {
                    record.optimisation = o;
                }
            }
            Some(Ok((s, _))) = status.next() => {
                let stamp = nanos_from_stamp(&s.header.stamp).filter(|&t| t > 0).unwrap_or_else(|| node.now_nanos());
                waypoint = s.waypoint_index;
                match started {
                    None if s.state == NavStatus::ACTIVE && s.mode == "vfo" => {
                        info!("route accepted");
                        started = Some(stamp);
                    }
                    Some(t0) if s.state == NavStatus::SUCCEEDED || s.state == NavStatus::FAILED => {
                        record.outcome = if s.state == NavStatus::SUCCEEDED { Ok(()) } else { Err(s.reason.clone()) };
                        record.duration_s = (stamp - t0) as f64 * 1e-9;
                        break;
                    }
                    _ => {}
                }
            }
        }
    }
    let title = format!(
        "{}: VFO waypoint following, virtual robots of one segment",
        node.names().fully_qualified_node()
    );
    write_file(&out, &figure(&world, &record, &title)).map_err(|e| anyhow::anyhow!("cannot write {out}: {e}"))?;
    println!("{}", record.summary(&world, &out));
    Ok(())
}
