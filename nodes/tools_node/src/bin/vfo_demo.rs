//! `vfo_demo`: the demo's VFO act. Sends a waypoint route on `waypoints` to `planner_node` in
//! `waypoint_method: vfo` and follows `planner/status` until the route ends; records the true
//! path (`ground_truth`) and, from `planner/markers`, the optimisation with the most virtual
//! robots; writes one SVG (world, obstacles seen with r and R, every virtual robot of that
//! segment, the chosen path, the executed path) and prints one line. The act's course, record,
//! summary and figure are `mobil_tools::vfo` (tested there).

use std::process::ExitCode;
use std::time::{Duration, Instant};

use futures::StreamExt;
use mobil_msgs::mobil_msgs::msg::NavStatus;
use mobil_msgs::nav_msgs::msg::{Odometry, Path};
use mobil_msgs::visualization_msgs::msg::{Marker, MarkerArray};
use mobil_ros::params::ParamValues;
use mobil_ros::{qos, run_node, shutdown_signal, NodeDecl, ParamSpec, RosNode};
use mobil_tools::plot::write_file;
use mobil_tools::route::{flat_waypoints, parse_waypoints};
use mobil_tools::vfo::{figure, Optimisation, SeenObstacle, VfoAct, VfoRun, DEMO_ROUTE};
use mobil_tools_node::{route_now, stamp_or, status_of};
use mobil_world::World;
use tracing::info;

fn decl() -> NodeDecl {
    let route = flat_waypoints(&DEMO_ROUTE);
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
    .check(|p: &ParamValues| parse_waypoints(&p.f64s("route")?).map(|_| ()))
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
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
    let route = parse_waypoints(&p.f64s("route").map_err(map_err)?).map_err(map_err)?;
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

    let mut act = VfoAct::new(VfoRun {
        waypoints: route.clone(),
        path: Vec::new(),
        optimisation: Optimisation::default(),
        outcome: Err("not started".into()),
        duration_s: 0.0,
        robot_radius,
    });
    loop {
        tokio::select! {
            _ = &mut shutdown => anyhow::bail!("interrupted"),
            _ = resend.tick() => {
                if Instant::now() > deadline {
                    anyhow::bail!("the planner did not finish within {timeout:?}");
                }
                // Repeated until the planner shows the route active: the first may be lost in
                // discovery.
                if act.started.is_none() {
                    let _ = route_pub.publish(route_now(node, &route));
                }
            }
            Some(Ok((m, _))) = truth.next() => act.truth((m.pose.pose.position.x, m.pose.pose.position.y)),
            Some(Ok((a, _))) = markers.next() => {
                if let Some(o) = optimisation(&a, act.waypoint) {
                    act.optimisation(o);
                }
            }
            Some(Ok((s, _))) = status.next() => {
                let was = act.started;
                if act.status(&status_of(&s), stamp_or(&s.header.stamp, node.now_nanos())) {
                    break;
                }
                if was.is_none() && act.started.is_some() {
                    info!("route accepted");
                }
            }
        }
    }
    let record = &act.run;
    let title = format!(
        "{}: VFO waypoint following, virtual robots of one segment",
        node.names().fully_qualified_node()
    );
    write_file(&out, &figure(&world, record, &title)).map_err(|e| anyhow::anyhow!("cannot write {out}: {e}"))?;
    println!("{}", record.summary(&world, &out));
    Ok(())
}
