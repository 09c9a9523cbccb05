//! What the planner shows in RViz, as a ROS-free [`Sketch`]: the route, the virtual robot's
//! predicted path, the problems, the dock and a VFO segment's optimisation, within one budget
//! of points so the marker array stays small (`planner_node` turns it into markers).

use crate::goals::{Missed, MAX_LISTED_MISSED};
use crate::vfo::{VfoDrawing, MAX_DRAWN_OBSTACLES, MAX_DRAWN_ROBOTS};
use mobil_geom::sketch::{id, Rgba, Sketch};
use mobil_geom::{downsample, Pose2};
use nalgebra::Point2;

/// Most points of the predicted path drawn.
pub const MAX_DRAWN_PATH: usize = 300;

/// Most points over the whole sketch — the route's line and dots, the predicted path, the
/// virtual robots' paths and the chosen one — shared among them by [`MarkerView::sketch`]: 24
/// bytes each in a marker array's CDR, 24 KB. With the markers' own bytes (about 250 each, at
/// most 2 + 1 + 2·[`MAX_LISTED_MISSED`] + 1 + [`MAX_DRAWN_ROBOTS`] + 1 + 2·[`MAX_DRAWN_OBSTACLES`]
/// of them, plus the DELETEALL) the array stays below the 80 KB a message to rclpy should stay
/// below (tested on the worst case in `planner_node`).
pub const MAX_MARKER_POINTS: usize = 1000;

/// What the markers show between goals, owned: the last route, its prediction and problems,
/// the dock, a VFO route's last optimisation.
#[derive(Debug, Clone, Default)]
pub struct Drawing {
    /// The route's waypoints.
    pub route: Vec<Point2<f64>>,
    /// The virtual robot's predicted path.
    pub predicted: Vec<Pose2>,
    /// The problems.
    pub problems: Vec<Missed>,
    /// The dock pose.
    pub dock: Option<Pose2>,
    /// A VFO route's last optimisation.
    pub vfo: Option<VfoDrawing>,
}

impl Drawing {
    /// Its view with the robot at `robot`.
    pub fn view(&self, robot: Option<Point2<f64>>) -> MarkerView<'_> {
        MarkerView {
            route: &self.route,
            predicted: &self.predicted,
            problems: &self.problems,
            dock: self.dock,
            vfo: self.vfo.as_ref(),
            robot,
        }
    }
}

/// What the markers show.
#[derive(Debug, Clone, Default)]
pub struct MarkerView<'a> {
    /// The route's waypoints.
    pub route: &'a [Point2<f64>],
    /// The virtual robot's predicted path.
    pub predicted: &'a [Pose2],
    /// The problems (position and text).
    pub problems: &'a [Missed],
    /// The dock pose.
    pub dock: Option<Pose2>,
    /// A VFO route's last optimisation.
    pub vfo: Option<&'a VfoDrawing>,
    /// The robot's position: the obstacles nearest to it are drawn first.
    pub robot: Option<Point2<f64>>,
}

impl MarkerView<'_> {
    /// The sketch: the route as a line and dots of its waypoints, the predicted path as a line
    /// (at most [`MAX_DRAWN_PATH`] points), each problem (at most [`MAX_LISTED_MISSED`]) as a
    /// red sphere and a text at its place, the dock pose as an arrow, and a VFO optimisation
    /// (below). The points share one budget, [`MAX_MARKER_POINTS`]: the route takes up to half
    /// of it (its line and dots, a quarter each, downsampled beyond), the predicted path up to a
    /// quarter of the rest, the VFO paths what remains.
    pub fn sketch(&self) -> Sketch {
        let mut s = Sketch::default();
        let mut budget = MAX_MARKER_POINTS;
        if !self.route.is_empty() {
            let route = downsample(self.route, MAX_MARKER_POINTS / 4);
            budget -= 2 * route.len();
            let blue = Rgba::rgb(0.2, 0.6, 1.0);
            s.line("route", 0, route.clone(), 0.02, blue);
            s.dots("route", 1, route, 0.12, blue);
        }
        if !self.predicted.is_empty() {
            let path = downsample(self.predicted, MAX_DRAWN_PATH.min(budget / 4));
            budget -= path.len();
            let points = path.iter().map(|p| p.position()).collect();
            s.line("predicted", 0, points, 0.015, Rgba::rgb(0.0, 0.8, 0.0));
        }
        for (i, p) in self.problems.iter().take(MAX_LISTED_MISSED).enumerate() {
            s.sphere("problems", id(i), p.position, 0.2, Rgba::rgb(0.9, 0.0, 0.0));
            let white = Rgba::rgb(1.0, 1.0, 1.0);
            s.text("problem_text", id(i), (p.position, 0.3), 0.12, white, p.describe());
        }
        if let Some(d) = self.dock {
            s.arrow("dock", 0, d, (0.4, 0.06), Rgba::rgb(1.0, 0.5, 0.0));
        }
        if let Some(drawing) = self.vfo {
            vfo_sketch(&mut s, drawing, self.robot, budget);
        }
        s
    }
}

/// A VFO optimisation: each virtual robot's path a thin line (`vfo_robots`, grey; orange where
/// the path was dropped on a collision or the time cap), the chosen path a thick green one
/// (`vfo_chosen`), each obstacle (at most [`MAX_DRAWN_OBSTACLES`], the nearest to `robot`
/// first) a red disc of radius r (`vfo_forbidden`) inside a pale yellow one of radius R
/// (`vfo_influence`). The paths share `budget` points: the chosen one up to a third, the
/// virtual robots the rest, evenly (at least two points each, so the first `budget / 2` robots
/// at most).
fn vfo_sketch(s: &mut Sketch, drawing: &VfoDrawing, robot: Option<Point2<f64>>, budget: usize) {
    let chosen = downsample(&drawing.chosen, budget / 3);
    let rest = budget - chosen.len();
    let robots = &drawing.robots[..drawing.robots.len().min(rest / 2).min(MAX_DRAWN_ROBOTS)];
    let per_robot = (rest / robots.len().max(1)).max(2);
    for (i, r) in robots.iter().enumerate() {
        let c = if r.dropped {
            Rgba::rgb(1.0, 0.5, 0.0)
        } else {
            Rgba::rgb(0.6, 0.6, 0.6)
        };
        s.line("vfo_robots", id(i), downsample(&r.points, per_robot), 0.01, c);
    }
    if !chosen.is_empty() {
        s.line("vfo_chosen", 0, chosen, 0.04, Rgba::rgb(0.0, 0.9, 0.2));
    }
    let mut order: Vec<usize> = (0..drawing.obstacles.len()).collect();
    if let Some(at) = robot {
        order.sort_by(|&a, &b| {
            drawing.obstacles[a]
                .distance(&at)
                .total_cmp(&drawing.obstacles[b].distance(&at))
        });
    }
    for (k, &i) in order.iter().take(MAX_DRAWN_OBSTACLES).enumerate() {
        let o = &drawing.obstacles[i];
        let zone = (o.influence_radius(), 0.02);
        s.disc("vfo_influence", id(k), o.centre(), zone, Rgba::new(1.0, 0.9, 0.2, 0.25));
        let forbidden = (o.forbidden_radius(), 0.05);
        s.disc(
            "vfo_forbidden",
            id(k),
            o.centre(),
            forbidden,
            Rgba::new(0.9, 0.1, 0.1, 0.6),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vfo::DrawnRobot;
    use mobil_geom::sketch::Shape;

    #[test]
    fn the_budget_goes_to_the_route_the_prediction_then_the_virtual_robots() {
        // 600 waypoints: each of line and dots downsampled to a quarter (250), 500 left; the
        // prediction takes a quarter of that (125), 375 left; the chosen path a third (125),
        // the 10 robots 250 / 10 = 25 points each.
        let route: Vec<_> = (0..600).map(|i| Point2::new(f64::from(i), 0.0)).collect();
        let predicted: Vec<_> = (0..5000).map(|i| Pose2::new(f64::from(i) * 0.1, 0.0, 0.0)).collect();
        let robot = DrawnRobot {
            points: (0..400).map(|i| Point2::new(f64::from(i), 1.0)).collect(),
            dropped: false,
        };
        let drawing = VfoDrawing {
            robots: vec![robot; 10],
            chosen: (0..900).map(|i| Point2::new(f64::from(i), 2.0)).collect(),
            obstacles: Vec::new(),
        };
        let view = MarkerView {
            route: &route,
            predicted: &predicted,
            vfo: Some(&drawing),
            ..MarkerView::default()
        };
        let s = view.sketch();
        let points = |ns: &str| -> Vec<usize> {
            s.items
                .iter()
                .filter(|i| i.ns == ns)
                .map(|i| match &i.shape {
                    Shape::Line { points, .. } | Shape::Dots { points, .. } => points.len(),
                    _ => 0,
                })
                .collect()
        };
        assert_eq!(points("route"), [250, 250]);
        assert_eq!(points("predicted"), [125]);
        assert_eq!(points("vfo_chosen"), [125]);
        assert_eq!(points("vfo_robots"), [25; 10]);
        assert_eq!(s.points(), 1000);
    }
}
