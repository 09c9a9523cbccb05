//! The `waypoint_method` and `vfo.*` parameters of VFO waypoint following
//! ([`mobil_planner::vfo`], SPEC §5), each bound to a field of
//! [`mobil_planner::vfo::VfoSettings`]. The law is [`mobil_planner::vfo::VfoGoal`]; the node
//! runs its steps off the event loop ([`mobil_motion::slot`]) and the robot stops while a
//! segment is optimised. Nothing here decides where the robot goes.

use mobil_planner::vfo::{
    OptimiseConfig, QualityWeights, ScanObstacleConfig, VfoGains, VfoSettings, MAX_OPTIMISE_BUDGET_S,
};
use mobil_ros::config::Decl;

use crate::PlannerConfig;

/// Declares `waypoint_method` and the `vfo.*` parameters.
pub fn declare_vfo(d: &mut Decl<PlannerConfig>) {
    let g = VfoGains::default();
    let o = OptimiseConfig::default();
    let w = QualityWeights::default();
    let s = ScanObstacleConfig::default();
    let v = VfoSettings::default();
    mobil_ros::params! { d;
        parsed "waypoint_method" = "approach" => waypoint_method, choices(&["approach", "vfo"]);
            "how waypoints and follow_waypoints are followed: approach (the goal approach after the route \
             pre-check) or vfo (VFO round the obstacles the LIDAR sees, left/right decisions optimised by \
             virtual robots), and follow_path when its controller_id is empty or FollowPath; applies from the next goal";
        double "vfo.k_p" = g.k_p => vfo.gains.k_p, above(0.0); "k_p, the position gain of h* (eq. 10) [1/s]";
        double "vfo.k_a" = g.k_a => vfo.gains.k_a, above(0.0); "k_a, the orienting gain (eq. 13) [1/s]";
        double "vfo.speed" = g.speed => vfo.gains.speed, above(0.0);
            "U_2, the speed profile (eq. 13), held to v_max [m/s]";
        double "vfo.omega_max" = g.omega_max => vfo.gains.omega_max, above(0.0);
            "|ω| limit of the law, held to the chassis' omega_max (and on a steered chassis to speed / R_min) [rad/s]";
        double "vfo.switch_epsilon" = g.switch_epsilon => vfo.gains.switch_epsilon, above(0.0);
            "ϵ_i: an intermediate waypoint is passed within this (Algorithm 1) [m]";
        double "vfo.final_epsilon" = g.final_epsilon => vfo.gains.final_epsilon, above(0.0);
            "ϵ: the route ends when ‖q_N − q‖ (heading included) is below this";
        double "vfo.guiding" = v.guiding => vfo.guiding, above(0.0), max(0.999);
            "μ, the guiding coefficient of every waypoint (eq. 11), in (0, 1)";
        double "vfo.k_d" = w.length => vfo.optimise.weights.length, min(0.0);
            "K_D, the weight of path length in Ψ_z (eq. 22)";
        double "vfo.k_b" = w.danger => vfo.optimise.weights.danger, min(0.0);
            "K_B, the weight of danger in Ψ_z (eq. 22)";
        double "vfo.k_e" = w.control => vfo.optimise.weights.control, min(0.0);
            "K_E, the weight of control cost in Ψ_z (eq. 22)";
        double "vfo.k_s" = w.smoothness => vfo.optimise.weights.smoothness, min(0.0);
            "K_S, the weight of smoothness in Ψ_z (eq. 22)";
        double "vfo.time_step" = o.time_step => vfo.optimise.time_step, above(0.0), max(0.1);
            "T_p, the virtual robots' integration step; set it to the odometry period the node steps on [s]";
        count "vfo.max_virtual_robots" = o.max_virtual_robots => vfo.optimise.max_virtual_robots, min(1.0);
            "most virtual robots per optimisation (then the best so far, with a warning)";
        double "vfo.max_path_time_s" = o.max_path_time_s => vfo.optimise.max_path_time_s, above(0.0);
            "a virtual robot's path longer than this in simulated time is dropped [s]";
        double "vfo.max_total_time_s" = o.max_total_time_s => vfo.optimise.max_total_time_s, above(0.0);
            "most simulated time over all virtual robots of one optimisation [s]";
        count "vfo.threads" = o.threads => vfo.optimise.threads, min(0.0);
            "threads that simulate virtual robots (0, or more than the cores: every core; the result is the same)";
        double "vfo.influence_margin" = s.influence_margin => vfo.scan.influence_margin, above(0.0);
            "R − r of every obstacle seen [m]";
        double "vfo.cluster_gap" = s.cluster_gap => vfo.scan.cluster_gap, above(0.0);
            "largest gap between the echoes of one obstacle (plus two beam spacings) [m]";
        count "vfo.min_points" = s.min_points => vfo.scan.min_points, min(3.0);
            "fewest echoes of one obstacle";
        double "vfo.max_radius" = s.max_radius => vfo.scan.max_radius, above(0.0);
            "largest circle fitted to one cluster; larger shapes become chains of circles [m]";
        double "vfo.association_distance" = s.association_distance => vfo.scan.association_distance, above(0.0);
            "circles whose centres lie nearer than this are one obstacle [m]";
        count "vfo.memory" = s.memory => vfo.scan.memory, min(1.0);
            "detections an obstacle's running mean remembers";
        double "vfo.optimise_budget_s" = v.optimise_budget_s => vfo.optimise_budget_s, above(0.0),
            max(MAX_OPTIMISE_BUDGET_S);
            "wall-clock budget of one optimisation: then the best Σ so far, with a warning (the robot stands \
             meanwhile) [s]";
        double "vfo.decay_s" = s.decay_s => vfo.scan.decay_s, above(0.0);
            "an obstacle not seen again for this long is forgotten [s]";
        count "vfo.max_obstacles" = s.max_obstacles => vfo.scan.max_obstacles, min(1.0);
            "most obstacles in the map; beyond, the least recently seen are dropped (with a warning)";
        double "vfo.scan_odom_max_gap_s" = v.scan_odom_max_gap_s => vfo.scan_odom_max_gap_s, above(0.0), max(1.0);
            "a scan is placed with the odometry pose at its stamp; refused when no odometry lies within this of it \
             [s]";
        double "vfo.scan_range" = v.scan_range => vfo.scan_range, above(0.0);
            "echoes farther than this are not turned into obstacles [m]";
        double "vfo.scan_timeout_s" = v.scan_timeout_s => vfo.scan_timeout_s, above(0.0),
            max(mobil_ros::groups::MAX_INPUT_TIMEOUT_S);
            "a vfo goal fails STALE_INPUT when no valid scan arrived for this long (steady clock) [s]";
        string "vfo.laser_frame" = &v.laser_frame => vfo.laser_frame, read_only();
            "the scan's frame when its header has none; its pose comes from tf_static";
        double_list "vfo.laser_pose" = &v.laser_pose => vfo.laser_pose;
            "x, y, yaw of the laser in base_link for a scan frame tf_static does not give; [] = none";
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{follow_result, markers, MarkerView};
    use mobil_geom::Pose2;
    use mobil_msgs::builtin_interfaces::msg::Time;
    use mobil_msgs::geometry_msgs::msg::PoseStamped;
    use mobil_msgs::nav2_msgs::action::FollowWaypointsResult;
    use mobil_msgs::visualization_msgs::msg::Marker;
    use mobil_planner::goals::MISSED_BY_THE_RUN;
    use mobil_planner::vfo::WaypointMethod;
    use mobil_planner::vfo::{DrawnRobot, Obstacle, VfoDrawing, MAX_DRAWN_OBSTACLES};
    use mobil_ros::config::{load, Decl};
    use mobil_ros::geometry::{header_in, pose_stamped};
    use mobil_ros::motion::EndCause;
    use mobil_ros::params::ParamValues;
    use nalgebra::Point2;
    use ros2_client::ParameterValue;

    fn pose(x: f64, y: f64, yaw: Option<f64>) -> PoseStamped {
        pose_stamped(header_in("odom"), &Pose2::new(x, y, yaw.unwrap_or(0.0)))
    }

    #[test]
    fn vfo_parameters_default_to_the_library_s_and_bad_ones_are_refused() {
        let specs = Decl::<PlannerConfig>::of().specs();
        let values = ParamValues::defaults(&specs);
        let c: PlannerConfig = load(&values).expect("defaults valid");
        assert_eq!(c.waypoint_method, WaypointMethod::Approach);
        assert_eq!(c.vfo, VfoSettings::default());
        assert_eq!(c.vfo.gains, VfoGains::default());
        assert_eq!(c.vfo.optimise, OptimiseConfig::default());
        // The library's figures, from its docs: k_p 1, k_a 5, U_2 0.3, |ω| ≤ 4, T_p 0.01,
        // 16 384 virtual robots, 80 000 s of simulated time, weights {K_D 1, K_B 2, K_E 1, K_S 1}.
        assert_eq!((c.vfo.gains.k_p, c.vfo.gains.k_a, c.vfo.gains.speed), (1.0, 5.0, 0.3));
        assert_eq!(
            (
                c.vfo.optimise.time_step,
                c.vfo.optimise.max_virtual_robots,
                c.vfo.optimise.max_total_time_s
            ),
            (0.01, 16_384, 80_000.0)
        );
        let w = c.vfo.optimise.weights;
        assert_eq!((w.length, w.danger, w.control, w.smoothness), (1.0, 2.0, 1.0, 1.0));
        // The scan's obstacles carry the node's robot radius (0.53 by default).
        assert_eq!(c.vfo.scan_config(c.robot_radius).robot_radius, 0.53);
        assert_eq!(c.vfo.laser_pose(), Some(Pose2::new(0.0, 0.0, 0.0)));

        let mut set = values.clone();
        set.set("waypoint_method", ParameterValue::String("vfo".into()));
        set.set("vfo.k_b", ParameterValue::Double(3.0));
        set.set("vfo.time_step", ParameterValue::Double(0.02));
        let c: PlannerConfig = load(&set).expect("valid");
        assert_eq!(c.waypoint_method, WaypointMethod::Vfo);
        assert_eq!(c.vfo.optimise.weights.danger, 3.0);
        assert_eq!(c.vfo.optimise.time_step, 0.02);
        for (name, value) in [
            ("waypoint_method", ParameterValue::String("dwa".into())),
            ("vfo.guiding", ParameterValue::Double(1.0)),
            ("vfo.k_a", ParameterValue::Double(0.0)),
            ("vfo.time_step", ParameterValue::Double(0.5)),
            ("vfo.max_virtual_robots", ParameterValue::Integer(0)),
            ("vfo.laser_pose", ParameterValue::DoubleArray(vec![0.1, 0.2])),
        ] {
            // Refused by the declaration's range (as -p and set_parameters are) or by the
            // configuration's own checks.
            let spec = specs.iter().find(|s| s.name == name).expect("declared");
            let mut bad = values.clone();
            bad.set(name, value.clone());
            assert!(
                spec.check(&value).is_err() || load::<PlannerConfig>(&bad).is_err(),
                "{name} accepted"
            );
        }
    }

    #[test]
    fn markers_draw_robots_the_chosen_path_and_r_and_r_big() {
        let near = Obstacle::new(Point2::new(1.0, 0.0), 0.4, 0.8).expect("valid");
        let far = Obstacle::new(Point2::new(5.0, 0.0), 0.3, 0.7).expect("valid");
        let drawing = VfoDrawing {
            robots: vec![
                DrawnRobot {
                    points: vec![Point2::new(0.0, 0.0), Point2::new(0.5, 0.2)],
                    dropped: false,
                },
                DrawnRobot {
                    points: vec![Point2::new(0.5, 0.2), Point2::new(0.9, 0.1)],
                    dropped: true,
                },
            ],
            chosen: vec![Point2::new(0.0, 0.0), Point2::new(0.5, 0.2), Point2::new(2.0, 0.6)],
            obstacles: vec![far, near],
        };
        let view = MarkerView {
            vfo: Some(&drawing),
            robot: Some(Point2::new(0.0, 0.0)),
            ..MarkerView::default()
        };
        let a = markers(&view, Time::default(), "odom");
        let of = |ns: &str| a.markers.iter().filter(|m| m.ns == ns).collect::<Vec<_>>();
        let robots = of("vfo_robots");
        assert_eq!(robots.len(), 2);
        assert_eq!((robots[0].color.r, robots[0].color.g), (0.6, 0.6));
        assert_eq!((robots[1].color.r, robots[1].color.g), (1.0, 0.5));
        assert_eq!(of("vfo_chosen")[0].points.len(), 3);
        // The nearest obstacle (at 1 m) first: discs of diameter 2r = 0.8 and 2R = 1.6.
        let (r, big) = (of("vfo_forbidden"), of("vfo_influence"));
        assert_eq!((r.len(), big.len()), (2, 2));
        assert_eq!(r[0].r#type, Marker::CYLINDER);
        assert_eq!((r[0].pose.position.x, r[0].scale.x, big[0].scale.x), (1.0, 0.8, 1.6));
        assert_eq!((r[1].pose.position.x, r[1].scale.x, big[1].scale.x), (5.0, 0.6, 1.4));
    }

    #[test]
    fn an_early_end_lists_the_waypoints_not_reached_with_the_law_s_reason() {
        let poses: Vec<PoseStamped> = (0..4).map(|i| pose(i as f64, 1.0, None)).collect();
        // The law's failure (its reason and code, as mobil_planner's VfoGoal gives them) with
        // the waypoints not reached as the task lists them (mobil_planner's task tests).
        let law = EndCause::Outcome(mobil_motion::Outcome::failed("NO_SAFE_PATH", "no way", 601));
        let r = follow_result(&law, &poses, &[(2, MISSED_BY_THE_RUN), (3, MISSED_BY_THE_RUN)]);
        assert_eq!(r.error_code, FollowWaypointsResult::TASK_EXECUTOR_FAILED);
        assert_eq!(r.error_msg, "NO_SAFE_PATH: no way");
        let listed: Vec<(u32, u16, f64)> = r
            .missed_waypoints
            .iter()
            .map(|m| (m.index, m.error_code, m.goal.pose.position.x))
            .collect();
        assert_eq!(listed, vec![(2, 105, 2.0), (3, 105, 3.0)]);
    }

    #[test]
    fn the_worst_marker_array_stays_below_80_kb_in_cdr() {
        // Everything at once, each at its cap: a route of 1000 waypoints, a predicted path of
        // 5000 poses, 60 problems with their texts, a dock, 200 virtual robots of 500 points,
        // a chosen path of 5000 points, 300 obstacles.
        let route: Vec<Point2<f64>> = (0..1000).map(|i| Point2::new(f64::from(i) * 0.1, 1.0)).collect();
        let predicted: Vec<Pose2> = (0..5000).map(|i| Pose2::new(f64::from(i) * 0.01, 0.0, 0.1)).collect();
        let problems: Vec<crate::Missed> = (0..60)
            .map(|i| crate::Missed {
                index: i,
                position: Point2::new(i as f64, 2.0),
                kind: mobil_planner::ProblemKind::TurnRadius {
                    required: 0.123456,
                    minimum: 0.734567,
                },
                pre_check: true,
            })
            .collect();
        let path: Vec<Point2<f64>> = (0..500).map(|i| Point2::new(f64::from(i) * 0.01, 0.5)).collect();
        let drawing = VfoDrawing {
            robots: (0..200)
                .map(|i| DrawnRobot {
                    points: path.clone(),
                    dropped: i % 2 == 0,
                })
                .collect(),
            chosen: (0..5000).map(|i| Point2::new(f64::from(i) * 0.01, 0.0)).collect(),
            obstacles: (0..300)
                .map(|i| Obstacle::new(Point2::new(f64::from(i), 3.0), 0.4, 0.8).expect("valid"))
                .collect(),
        };
        let view = MarkerView {
            route: &route,
            predicted: &predicted,
            problems: &problems,
            dock: Some(Pose2::new(1.0, 2.0, 0.5)),
            vfo: Some(&drawing),
            robot: Some(Point2::new(0.0, 0.0)),
        };
        let a = markers(&view, Time::default(), "odom");
        let bytes = cdr_encoding::to_vec::<_, byteorder::LittleEndian>(&a).expect("serialisable");
        let points: usize = a.markers.iter().map(|m| m.points.len()).sum();
        assert!(points <= crate::MAX_MARKER_POINTS, "{points} points");
        assert!(
            bytes.len() < 80_000,
            "{} bytes, {} markers, {points} points",
            bytes.len(),
            a.markers.len()
        );
        // Each part is still drawn.
        let of = |ns: &str| a.markers.iter().filter(|m| m.ns == ns).count();
        assert!(of("vfo_robots") >= 20 && of("vfo_chosen") == 1 && of("route") == 2);
        assert_eq!(of("vfo_forbidden"), MAX_DRAWN_OBSTACLES);
        println!("{} bytes, {} markers, {points} points", bytes.len(), a.markers.len());
    }
}
