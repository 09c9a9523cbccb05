//! The demo's VFO act (`vfo_demo`): `planner_node` in `waypoint_method: vfo` follows waypoints
//! through the built-in world's clutter. The record (the true path, one segment's optimisation
//! as `planner/markers` drew it), the one-line summary and the figure: the world, the obstacles
//! the planner saw with r and R, every virtual robot's path of that optimisation (grey; orange
//! where dropped), the chosen one (green), the executed path (blue) and the waypoints. The
//! act's course status by status is [`VfoAct`].

use crate::plot::{MapView, Stroke, Svg};
use crate::route::path_length;
use crate::status::{GoalState, Status};
use mobil_world::World;

/// The demo's route: past the pillar at (1, 1.5) (the first leg runs through it), beside the
/// box, back west and north past the pillar again (tests/test_planner_vfo.py drives it too).
pub const DEMO_ROUTE: [(f64, f64); 4] = [(2.0, 2.6), (3.2, 0.3), (1.0, -0.3), (0.0, 2.2)];

/// An obstacle as the planner saw it: centre, r, R (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeenObstacle {
    /// Centre (odom).
    pub centre: (f64, f64),
    /// Forbidden radius r.
    pub r: f64,
    /// Influence radius R.
    pub big_r: f64,
}

/// One segment's optimisation as the markers drew it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Optimisation {
    /// Each virtual robot's path and whether it was dropped (collision or time cap).
    pub robots: Vec<(Vec<(f64, f64)>, bool)>,
    /// The chosen path.
    pub chosen: Vec<(f64, f64)>,
    /// The obstacles drawn with it.
    pub obstacles: Vec<SeenObstacle>,
    /// The waypoint the segment led to (request index), from the status at that time.
    pub waypoint: i32,
}

/// Everything the act records.
#[derive(Debug, Clone, PartialEq)]
pub struct VfoRun {
    /// The waypoints sent.
    pub waypoints: Vec<(f64, f64)>,
    /// The true path (ground truth).
    pub path: Vec<(f64, f64)>,
    /// The optimisation with the most virtual robots seen.
    pub optimisation: Optimisation,
    /// The final status: SUCCEEDED or the reason.
    pub outcome: Result<(), String>,
    /// Simulated seconds from the route's start to its end.
    pub duration_s: f64,
    /// The robot's radius (m), for the clearance.
    pub robot_radius: f64,
}

impl VfoRun {
    /// Length of the true path (m).
    pub fn length(&self) -> f64 {
        path_length(&self.path)
    }

    /// The true path's closest approach to the world's surfaces (m).
    pub fn closest(&self, world: &World) -> f64 {
        self.path
            .iter()
            .map(|&(x, y)| world.distance_to(nalgebra::Point2::new(x, y)))
            .fold(f64::INFINITY, f64::min)
    }

    /// The printed line.
    pub fn summary(&self, world: &World, svg: &str) -> String {
        let outcome = match &self.outcome {
            Ok(()) => format!("followed {} waypoints", self.waypoints.len()),
            Err(reason) => format!("ended early ({reason})"),
        };
        format!(
            "demo: planner (vfo) {outcome} in {:.1} simulated s, {:.2} m driven, closest {:.2} m to an \
             obstacle (robot radius {:.2}); the segment to waypoint {}: {} virtual robots ({} dropped); plot {svg}",
            self.duration_s,
            self.length(),
            self.closest(world),
            self.robot_radius,
            self.optimisation.waypoint,
            self.optimisation.robots.len(),
            self.optimisation.robots.iter().filter(|(_, dropped)| *dropped).count(),
        )
    }
}

/// The sixth act's course: the route sent until the planner is active on it in mode `vfo`,
/// then the true path and the largest optimisation recorded until the route ends. The shell
/// sends the route while [`VfoAct::started`] is `None` and fills in what it receives.
#[derive(Debug, Clone, PartialEq)]
pub struct VfoAct {
    /// The record so far.
    pub run: VfoRun,
    /// When the route started (ns, the planner's stamp), once it has.
    pub started: Option<i64>,
    /// The waypoint the planner pursues (request index), from the last status.
    pub waypoint: i32,
}

impl VfoAct {
    /// The act from its start; `run` holds the route and the robot's radius.
    pub fn new(run: VfoRun) -> VfoAct {
        VfoAct {
            run,
            started: None,
            waypoint: 0,
        }
    }

    /// A true position: part of the path once the route has started.
    pub fn truth(&mut self, p: (f64, f64)) {
        if self.started.is_some() {
            self.run.path.push(p);
        }
    }

    /// An optimisation the markers drew: kept when it has more virtual robots than the one
    /// kept so far.
    pub fn optimisation(&mut self, o: Optimisation) {
        if o.robots.len() > self.run.optimisation.robots.len() {
            self.run.optimisation = o;
        }
    }

    /// Takes a status stamped `stamp` (ns); true when the route has ended (succeeded or
    /// failed after it started), with its outcome and duration recorded.
    pub fn status(&mut self, s: &Status, stamp: i64) -> bool {
        self.waypoint = s.waypoint_index;
        match self.started {
            None if s.state == GoalState::Active && s.mode == "vfo" => {
                self.started = Some(stamp);
                false
            }
            Some(t0) if s.state.finished() => {
                self.run.outcome = if s.state == GoalState::Succeeded {
                    Ok(())
                } else {
                    Err(s.reason.clone())
                };
                self.run.duration_s = (stamp - t0) as f64 * 1e-9;
                true
            }
            _ => false,
        }
    }
}

/// The SVG figure of a run.
pub fn figure(world: &World, run: &VfoRun, title: &str) -> String {
    let points = run
        .path
        .iter()
        .chain(&run.waypoints)
        .copied()
        .chain(run.optimisation.robots.iter().flat_map(|(p, _)| p.iter().copied()));
    let view = MapView::fit(world, points, 60.0, 0.5).at(20.0, 50.0);
    let mut svg = Svg::new(view.width() + 40.0, view.height() + 110.0);
    svg.text(20.0, 30.0, 16.0, title);
    svg.world(&view, world);
    svg.metre_axes(&view);
    for o in &run.optimisation.obstacles {
        svg.circle(
            &view,
            o.centre,
            o.big_r,
            Stroke::dashed("#d4b000", 1.0),
            "#ffe680",
            0.25,
        );
        svg.circle(&view, o.centre, o.r, Stroke::solid("#c01818", 1.0), "#e04040", 0.35);
    }
    for (p, dropped) in &run.optimisation.robots {
        let stroke = if *dropped {
            Stroke::solid("#ff8000", 1.0)
        } else {
            Stroke::solid("#909090", 1.0)
        };
        svg.path(&view, p, stroke);
    }
    svg.path(&view, &run.optimisation.chosen, Stroke::solid("#00a030", 3.0));
    svg.path(&view, &run.path, Stroke::solid("#1f5fd0", 2.0));
    for (i, &(x, y)) in run.waypoints.iter().enumerate() {
        svg.dot(view.x(x), view.y(y), 5.0, "#1f5fd0", None);
        svg.text(view.x(x) + 7.0, view.y(y) - 7.0, 12.0, &i.to_string());
    }
    let legend = format!(
        "blue: executed path; grey: the {} virtual robots of the segment to waypoint {} (orange: dropped); \
         green: the chosen path; red: r, yellow: R of the obstacles seen",
        run.optimisation.robots.len(),
        run.optimisation.waypoint
    );
    svg.text(20.0, view.height() + 80.0, 12.0, &legend);
    svg.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run() -> VfoRun {
        VfoRun {
            waypoints: vec![(1.0, 0.0), (1.0, 1.0)],
            // 1 m east, then 0.5 m north: 1.5 m.
            path: vec![(0.0, 0.0), (1.0, 0.0), (1.0, 0.5)],
            optimisation: Optimisation {
                robots: vec![
                    (vec![(0.0, 0.0), (0.5, 0.1)], false),
                    (vec![(0.5, 0.1), (0.6, 0.3)], true),
                ],
                chosen: vec![(0.0, 0.0), (0.5, 0.1), (1.0, 0.0)],
                obstacles: vec![SeenObstacle {
                    centre: (0.5, 1.0),
                    r: 0.4,
                    big_r: 0.8,
                }],
                waypoint: 1,
            },
            outcome: Ok(()),
            duration_s: 12.34,
            robot_radius: 0.25,
        }
    }

    #[test]
    fn summary_gives_length_clearance_and_the_segment_s_robots() {
        // A world of one pillar of radius 0.5 at (3, 0): the path's closest point (1, 0) is
        // 2 − 0.5 = 1.5 m from its surface.
        let world =
            World::from_yaml_str("obstacles:\n  - circle: { center: [3.0, 0.0], radius: 0.5 }\n").expect("valid");
        let r = run();
        assert!((r.length() - 1.5).abs() < 1e-12);
        assert!((r.closest(&world) - 1.5).abs() < 1e-12);
        assert_eq!(
            r.summary(&world, "x.svg"),
            "demo: planner (vfo) followed 2 waypoints in 12.3 simulated s, 1.50 m driven, closest 1.50 m to an \
             obstacle (robot radius 0.25); the segment to waypoint 1: 2 virtual robots (1 dropped); plot x.svg"
        );
    }

    #[test]
    fn figure_draws_every_robot_the_chosen_path_and_both_radii() {
        let world = World::builtin();
        let svg = figure(&world, &run(), "t");
        // Two robots, the chosen path, the executed path: four polylines.
        assert_eq!(svg.matches("<polyline").count(), 4);
        assert_eq!(svg.matches("#ff8000").count(), 1);
        // r and R of the one obstacle at 60 px/m: radii 24 and 48 px.
        assert!(svg.contains(r#"r="24.0""#) && svg.contains(r#"r="48.0""#));
    }

    #[test]
    fn the_act_records_from_the_start_of_the_vfo_route_to_its_end() {
        let status = |state, index, mode: &str| Status {
            state,
            waypoint_index: index,
            mode: mode.into(),
            reason: "STALE_INPUT: odom stale".into(),
            docking: (0.0, 0.0, 0.0, 0.0),
        };
        let mut act = VfoAct::new(VfoRun {
            path: Vec::new(),
            optimisation: Optimisation::default(),
            outcome: Err("not started".into()),
            duration_s: 0.0,
            ..run()
        });
        act.truth((9.0, 9.0));
        assert!(!act.status(&status(GoalState::Active, 0, "approach"), 1));
        assert!(!act.status(&status(GoalState::Failed, 0, "approach"), 1));
        assert_eq!(act.started, None);
        assert!(!act.status(&status(GoalState::Active, 0, "vfo"), 2_000_000_000));
        act.truth((0.0, 0.0));
        let robots = |n| Optimisation {
            robots: vec![(Vec::new(), false); n],
            waypoint: n as i32,
            ..Optimisation::default()
        };
        act.optimisation(robots(3));
        act.optimisation(robots(2));
        assert!(!act.status(&status(GoalState::Active, 1, "vfo"), 3_000_000_000));
        assert_eq!(act.waypoint, 1);
        assert!(act.status(&status(GoalState::Failed, 1, "vfo"), 14_500_000_000));
        assert_eq!(act.run.path, [(0.0, 0.0)]);
        assert_eq!(act.run.optimisation.robots.len(), 3);
        assert_eq!(act.run.outcome, Err("STALE_INPUT: odom stale".into()));
        assert!((act.run.duration_s - 12.5).abs() < 1e-12);
    }
}
