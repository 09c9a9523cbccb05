//! VFO waypoint following in closed loop without DDS: the node's route conversion and gains,
//! the simulated LIDAR (mobil_sim) in the built-in world, the obstacle map and the follower at
//! the node's control period (one step per 50 Hz odometry message, a scan every other step as
//! at 40 Hz), the unicycle moved by the exact arc. The same route as tests/test_planner_vfo.py;
//! the clearance is the world geometry's (mobil_sim's signed distance), not the follower's.

use mobil_chassis::ChassisParams;
use mobil_geom::Pose2;
use mobil_msgs::geometry_msgs::msg::PoseStamped;
use mobil_planner::vfo::{integrate_unicycle, ObstacleMap, OptimiseConfig, VfoEnd, VfoEvent, VfoFollower, VfoGains};
use mobil_planner_node::route_from_poses;
use mobil_planner_node::vfo::{vfo_gains, vfo_waypoints, VfoSettings};
use mobil_sim::lidar::{Lidar, LidarConfig};
use mobil_sim::world::World;
use nalgebra::Point2;

const ROUTE: [(f64, f64); 4] = [(2.0, 2.6), (3.2, 0.3), (1.0, -0.3), (0.0, 2.2)];
const ROBOT_RADIUS: f64 = 0.25;
const DT: f64 = 0.02;

#[test]
fn omr3_follows_four_waypoints_through_the_builtin_world_without_collision() {
    let world = World::builtin();
    let poses: Vec<PoseStamped> = ROUTE
        .iter()
        .map(|&(x, y)| {
            let mut p = PoseStamped::default();
            p.header.frame_id = "odom".into();
            p.pose.position.x = x;
            p.pose.position.y = y;
            p.pose.orientation.w = 1.0;
            p
        })
        .collect();
    let route = route_from_poses(&poses, "odom", "odom", 0, 0, None, 1e-3).expect("valid route");
    let settings = VfoSettings {
        scan_range: 4.0,
        ..VfoSettings::default()
    };
    let start = Pose2::identity();
    let waypoints = vfo_waypoints(&route, &start, settings.guiding).expect("valid");
    let gains = vfo_gains(&VfoGains::default(), &ChassisParams::omr3());
    assert_eq!(gains.omega_max, 1.5);
    let config = OptimiseConfig {
        time_step: DT,
        ..OptimiseConfig::default()
    };
    let mut follower = VfoFollower::new(gains, config, waypoints, Vec::new()).expect("valid");
    let mut map = ObstacleMap::new(settings.scan_config(ROBOT_RADIUS)).expect("valid");
    let mut lidar = Lidar::new(
        LidarConfig {
            range_max: settings.scan_range,
            ..LidarConfig::default()
        },
        1,
    );
    let mut pose = start;
    let mut reached = Vec::new();
    let mut optimisations = 0;
    let mut closest = f64::INFINITY;
    let mut end = None;
    for k in 0..(120.0 / DT) as usize {
        if k % 2 == 0 {
            let s = lidar.scan(&world, (pose.x, pose.y, pose.yaw));
            let update = map
                .update_from_ranges(
                    &s.ranges,
                    s.angle_min,
                    s.angle_increment,
                    s.range_min,
                    s.range_max,
                    &pose,
                )
                .expect("valid scan");
            follower.set_obstacles(map.obstacles(), !update.new.is_empty());
        }
        let o = follower.update(&pose, k as f64 * DT).expect("valid pose");
        for e in &o.events {
            match e {
                VfoEvent::Reached { index, .. } => reached.push(*index),
                VfoEvent::Optimised { score, .. } => {
                    optimisations += 1;
                    assert!(score.is_some(), "a segment without a safe Σ");
                }
            }
        }
        if o.end.is_some() {
            end = o.end;
            break;
        }
        pose = integrate_unicycle(&pose, o.v, o.omega, DT);
        closest = closest.min(world.distance_to(pose.position()));
    }
    assert_eq!(end, Some(VfoEnd::Done));
    assert_eq!(reached, vec![0, 1, 2, 3]);
    // The pillar, the box and the walls seen on the way re-optimise segments as they appear.
    assert!(optimisations > 4, "{optimisations} optimisations");
    assert!(closest > ROBOT_RADIUS, "{closest:.3} m from an obstacle");
    let last = Point2::new(0.0, 2.2);
    assert!((pose.position() - last).norm() < 0.05, "ends at {pose:?}");
}
