//! The demo's third act (`plan_demo`): the route and the dock it gives `planner_node`, the record
//! of the run (pre-check answer, true path, docking status over time), the one-line summary and
//! the figure. Everything here works on recorded data; the binary only fills a [`PlanRun`].

use std::f64::consts::{FRAC_PI_2, PI};

use mobil_geom::wrap;
use mobil_world::World;

use crate::plot::{MapView, SeriesPanel, Stroke, Svg};
use crate::status::{GoalState, Status};

/// The demo's route (odom frame, metres): from where the second act ends, near its goal
/// (3, 4), west above the pillar at (1, 1.5), down the room's west side and back east. Legs of
/// 2.0–2.3 m, far beyond MOBIL-II's critical distance (0.16 m), its first waypoint 2 m from the
/// start, so that no start heading asks for a turn tighter than MOBIL-II's 0.73 m radius (a
/// point d from the start needs a radius of at least (d² − 0.3²)/(2d), 0.98 m at 2 m); the
/// pre-check passes it on every chassis (`tests/plan_route.rs`).
pub const DEMO_ROUTE: [(f64, f64); 5] = [(1.0, 3.6), (-1.2, 3.0), (-2.6, 1.4), (-1.6, -0.4), (0.4, -0.6)];

/// The demo's dock (x, y, yaw in odom): 1.3 m in front of the south wall (y = −2.5), facing it,
/// east of the triangle. The route ends heading east (its last leg points 0.1 rad south of
/// east; an omni robot keeps its heading from the second act, about east too), so the docking
/// must turn the robot a quarter turn as it brings it in.
pub const DEMO_DOCK: (f64, f64, f64) = (3.5, -1.2, -FRAC_PI_2);

/// One problem of the route pre-check, as `planner/check_route` answered it.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// Index (from 0) of the waypoint on whose leg it lies.
    pub index: i32,
    /// `collision`, `turn_radius` or `unreachable`.
    pub kind: String,
    /// The node's description, with its figures.
    pub detail: String,
    /// Where it is (odom): the collision's start, else the waypoint.
    pub at: (f64, f64),
}

/// How a goal of the planner ended, from `planner/status`.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// State SUCCEEDED.
    Succeeded,
    /// State FAILED, with the status' reason.
    Failed(String),
}

/// One `planner/status` sample during the docking.
#[derive(Debug, Clone, PartialEq)]
pub struct DockSample {
    /// Simulated time (s) since the dock was accepted.
    pub t: f64,
    /// The polar error e (m) to the dock.
    pub e: f64,
    /// Heading error wrap(ϑ − ϑ_G) (rad), from the status' α and Θ: ϑ − ϑ_G = Θ − α.
    pub heading: f64,
    /// V = ½(λe² + α² + hΘ²).
    pub lyapunov: f64,
    /// The planner's mode (`dock`, `rotate`, ...).
    pub mode: String,
}

impl DockSample {
    /// A sample from a status' t, e, α, Θ, V and mode.
    pub fn from_status(t: f64, e: f64, alpha: f64, theta: f64, lyapunov: f64, mode: &str) -> Self {
        DockSample {
            t,
            e,
            heading: wrap(theta - alpha),
            lyapunov,
            mode: mode.to_string(),
        }
    }
}

/// Everything the third act recorded.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanRun {
    /// The route sent (odom).
    pub waypoints: Vec<(f64, f64)>,
    /// The pre-check's verdict.
    pub feasible: bool,
    /// The pre-check's problems.
    pub problems: Vec<Problem>,
    /// The pre-check's predicted path (odom).
    pub predicted: Vec<(f64, f64)>,
    /// The pre-check's predicted path length (m).
    pub predicted_length: f64,
    /// The true path (`ground_truth`, world frame) over route and docking.
    pub path: Vec<(f64, f64)>,
    /// The odometry over the route (odom: the frame of the waypoints, as the planner judges).
    pub odom_path: Vec<(f64, f64)>,
    /// How the route ended.
    pub route_outcome: Outcome,
    /// Simulated seconds from the route's acceptance to its end.
    pub route_s: f64,
    /// The dock (x, y, yaw; odom).
    pub dock: (f64, f64, f64),
    /// The status during the docking.
    pub docking: Vec<DockSample>,
    /// How the docking ended.
    pub dock_outcome: Outcome,
    /// True pose (x, y, yaw) at the end of the docking (world frame).
    pub final_truth: Option<(f64, f64, f64)>,
}

/// Indices of the waypoints the odometry track never came within `tolerance` of (the
/// planner's Z_crit: a waypoint nearer than that counts as reached).
pub fn missed_waypoints(waypoints: &[(f64, f64)], track: &[(f64, f64)], tolerance: f64) -> Vec<usize> {
    waypoints
        .iter()
        .enumerate()
        .filter(|&(_, &w)| closest_approach(w, track) > tolerance)
        .map(|(i, _)| i)
        .collect()
}

/// The distance from `waypoint` to the nearest point of `track` (infinite for an empty track).
pub fn closest_approach(waypoint: (f64, f64), track: &[(f64, f64)]) -> f64 {
    track
        .iter()
        .map(|p| (p.0 - waypoint.0).hypot(p.1 - waypoint.1))
        .fold(f64::INFINITY, f64::min)
}

/// The route's odometry track: the positions of the samples (stamp in ns, x, y) stamped from
/// the route's start to its end plus `slack` (ns), whatever order they were received in. The
/// planner ends the route on the first sample within Z_crit of the last waypoint, but its status
/// comes from another writer than the odometry and can be received first; and the status is
/// stamped by the planner's clock, which may lag the sample's stamp by a clock period.
pub fn route_track(samples: &[(i64, f64, f64)], start: i64, end: i64, slack: i64) -> Vec<(f64, f64)> {
    samples
        .iter()
        .filter(|&&(t, _, _)| t >= start && t <= end.saturating_add(slack))
        .map(|&(_, x, y)| (x, y))
        .collect()
}

/// Three significant digits, without exponent (1.43, 0.0523, 0.000123).
pub fn three_digits(v: f64) -> String {
    if !v.is_finite() || v == 0.0 {
        return format!("{v}");
    }
    let decimals = (2 - v.abs().log10().floor() as i32).clamp(0, 9) as usize;
    format!("{v:.decimals$}")
}

/// The figures of the summary line.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Waypoints in the route.
    pub waypoints: usize,
    /// Waypoints the odometry track did not come within the tolerance of.
    pub missed: Vec<usize>,
    /// How the route ended and in how many simulated seconds.
    pub route: (Outcome, f64),
    /// How the docking ended and in how many simulated seconds.
    pub dock: (Outcome, f64),
    /// The last docking sample's e (m) and heading error (rad), if any.
    pub residual: Option<(f64, f64)>,
    /// V at the first and the last docking sample.
    pub lyapunov: Option<(f64, f64)>,
}

impl Summary {
    /// The summary of `run`, waypoints judged reached within `tolerance` (m).
    pub fn of(run: &PlanRun, tolerance: f64) -> Summary {
        let dock_s = run.docking.last().map_or(0.0, |s| s.t);
        Summary {
            waypoints: run.waypoints.len(),
            missed: missed_waypoints(&run.waypoints, &run.odom_path, tolerance),
            route: (run.route_outcome.clone(), run.route_s),
            dock: (run.dock_outcome.clone(), dock_s),
            residual: run.docking.last().map(|s| (s.e, s.heading)),
            lyapunov: run
                .docking
                .first()
                .zip(run.docking.last())
                .map(|(a, b)| (a.lyapunov, b.lyapunov)),
        }
    }

    /// The demo's line for this act; `steered` (a car-like or tricycle chassis) adds why its
    /// docking ends with a residual.
    pub fn line(&self, plot: &str, steered: bool) -> String {
        let route = match &self.route.0 {
            Outcome::Succeeded => format!(
                "planner followed {} waypoints ({} missed) in {:.1} simulated s",
                self.waypoints,
                self.missed.len(),
                self.route.1
            ),
            Outcome::Failed(reason) => format!(
                "planner's route of {} waypoints failed after {:.1} simulated s ({reason})",
                self.waypoints, self.route.1
            ),
        };
        let (e, heading) = self.residual.unwrap_or((f64::NAN, f64::NAN));
        let heading = heading.abs();
        let dock = match &self.dock.0 {
            Outcome::Succeeded => format!(
                "docked in {:.1} s at e {e:.3} m, heading error {heading:.3} rad",
                self.dock.1
            ),
            Outcome::Failed(reason) => {
                // The status reason is "CODE: detail"; the detail repeats e and the heading.
                let code = reason.split(':').next().unwrap_or_default().trim();
                let why = if steered {
                    ": a steered chassis cannot turn in place, so the law cannot converge and leaves this residual"
                } else {
                    ""
                };
                format!(
                    "docking ended after {:.1} s at e {e:.3} m, heading error {heading:.3} rad ({code}{why})",
                    self.dock.1
                )
            }
        };
        let v = match self.lyapunov {
            Some((a, b)) if b < a => format!("; V fell from {} to {}", three_digits(a), three_digits(b)),
            Some((a, b)) => format!("; V went from {} to {}", three_digits(a), three_digits(b)),
            None => "; no docking status received".into(),
        };
        format!("demo: {route}, {dock}{v}; plot {plot}")
    }
}

/// Colours of the figure.
const TRUE_PATH: &str = "#141414";
const PREDICTED: &str = "#005AB5";
const ROUTE: &str = "#E69F00";
const DOCK: &str = "#1A8C3A";
const PROBLEM: &str = "#DC3220";

/// Height (px) of the two series panels.
const PANEL_HEIGHT: f64 = 150.0;

/// The figure: the map (obstacles, the route with its waypoints numbered by index, the
/// pre-check's predicted path dashed, the true path, the dock as an arrow, each problem as a
/// red ✕) and below it V(t) and e(t) over the docking.
pub fn figure(world: &World, run: &PlanRun, title: &str) -> String {
    let shown = run
        .waypoints
        .iter()
        .chain(&run.path)
        .chain(&run.predicted)
        .copied()
        .chain(std::iter::once((run.dock.0, run.dock.1)));
    let top = 34.0;
    let map = MapView::fit(world, shown, 60.0, 0.5).at(0.0, top);
    let width = map.width().max(700.0);
    let panels_top = top + map.height() + 25.0;
    let height = panels_top + PANEL_HEIGHT + 95.0;
    let mut svg = Svg::new(width, height);
    svg.text(10.0, 22.0, 16.0, title);
    svg.world(&map, world);
    svg.metre_axes(&map);

    // The route: a thin line from the route's start (the first true point) through the waypoints.
    let mut route: Vec<(f64, f64)> = run.path.first().copied().into_iter().collect();
    route.extend(&run.waypoints);
    svg.path(&map, &route, Stroke::solid(ROUTE, 1.5));
    svg.path(&map, &run.predicted, Stroke::dashed(PREDICTED, 2.0));
    svg.path(&map, &run.path, Stroke::solid(TRUE_PATH, 2.0));
    for (i, &(x, y)) in run.waypoints.iter().enumerate() {
        let (px, py) = (map.x(x), map.y(y));
        svg.dot(px, py, 9.0, ROUTE, Some(&format!("waypoint {i} ({x}, {y})")));
        svg.text(px - 3.5, py + 4.0, 11.0, &i.to_string());
    }
    svg.arrow(&map, run.dock, 0.6, DOCK);
    for p in &run.problems {
        let (px, py) = (map.x(p.at.0), map.y(p.at.1));
        svg.cross(px, py, 7.0, PROBLEM, 3.0);
        svg.text(px + 9.0, py - 6.0, 11.0, &format!("{}: {}", p.index, p.kind));
    }

    // V(t) and e(t) over the docking, side by side.
    let half = 0.5 * (width - 120.0);
    let v: Vec<(f64, f64)> = run.docking.iter().map(|s| (s.t, s.lyapunov)).collect();
    let e: Vec<(f64, f64)> = run.docking.iter().map(|s| (s.t, s.e)).collect();
    let v_panel = SeriesPanel::fit(50.0, panels_top, half, PANEL_HEIGHT, &[&v]);
    let e_panel = SeriesPanel::fit(100.0 + half, panels_top, half, PANEL_HEIGHT, &[&e]);
    svg.series_axes(&v_panel, "t [s] since the dock was sent", "V = ½(λe² + α² + hΘ²)");
    svg.series_axes(&e_panel, "t [s] since the dock was sent", "e [m] to the dock");
    svg.series(&v_panel, &v, Stroke::solid(DOCK, 2.0));
    svg.series(&e_panel, &e, Stroke::solid(DOCK, 2.0));
    // Where the final in-place rotation began.
    if let Some(s) = run.docking.iter().find(|s| s.mode == "rotate") {
        for p in [&v_panel, &e_panel] {
            let (lo, hi) = p.v_range();
            svg.polyline(
                &[(p.px(s.t), p.py(lo)), (p.px(s.t), p.py(hi))],
                Stroke::dashed(PREDICTED, 1.0),
            );
        }
    }

    let base = panels_top + PANEL_HEIGHT + 50.0;
    svg.text(
        10.0,
        base,
        13.0,
        "orange: route, waypoints numbered by index; dashed blue: the pre-check's predicted path; black: true path",
    );
    let check = if run.feasible {
        "pre-check: feasible".to_string()
    } else {
        format!("pre-check: {} problem(s), red ✕", run.problems.len())
    };
    svg.text(
        10.0,
        base + 20.0,
        13.0,
        &format!("green arrow: the dock; {check}; dashed line in the panels: the final in-place rotation begins"),
    );
    if let Some((x, y, yaw)) = run.final_truth {
        let e = (x - run.dock.0).hypot(y - run.dock.1);
        let heading = wrap(yaw - run.dock.2);
        svg.text(
            10.0,
            base + 40.0,
            13.0,
            &format!(
                "true pose at the end: e {e:.3} m, heading {heading:.3} rad from the dock (the planner steers by odometry, which drifts)"
            ),
        );
    }
    svg.finish()
}

/// The heading (rad) the route's end points the robot along: the chord of its last leg.
pub fn route_end_heading(route: &[(f64, f64)]) -> Option<f64> {
    match route {
        [.., a, b] => Some((b.1 - a.1).atan2(b.0 - a.0)),
        _ => None,
    }
}

/// True when the dock's heading differs from `heading` by more than 30°, so that the docking
/// must turn the robot as well as move it.
pub fn dock_needs_a_turn(dock: (f64, f64, f64), heading: f64) -> bool {
    wrap(dock.2 - heading).abs() > PI / 6.0
}

/// Where the act is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Phase {
    /// The route was sent; waiting for the planner's ACTIVE.
    RouteSent,
    /// Following the route, accepted at this time (ns).
    Route(i64),
    /// The dock was sent at this time (ns); waiting for the planner's ACTIVE.
    DockSent(i64),
    /// Docking, sent at this time (ns).
    Dock(i64),
}

/// What the act does after a status.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Next {
    /// Nothing: wait for the next status.
    Wait,
    /// The planner took the route.
    RouteAccepted,
    /// The route ended: send the dock.
    SendDock,
    /// The planner took the dock.
    DockAccepted,
    /// The docking ended: the act is over.
    Done,
}

/// One sample in the odometry's stream: its stamp (ns), x, y.
pub type OdomSample = (i64, f64, f64);

/// The third act's course, status by status: the route sent until the planner is active on it,
/// followed to its end, then the dock sent until the planner docks, and the docking followed to
/// its end, each status of the docking a [`DockSample`]. The shell sends what [`Next`] and the
/// [`Phase`] say and fills in the true path.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanAct {
    /// Where the act is.
    pub phase: Phase,
    /// The record so far.
    pub run: PlanRun,
    /// The route's start and end stamps (ns), once it has ended.
    pub route_window: Option<(i64, i64)>,
    /// The planner's reason when the route ended.
    pub route_reason: String,
}

/// One joint_states period (20 ms simulated) of slack at the route's end: the planner's clock
/// may lag the stamp of the sample it ended the route on.
pub const ROUTE_END_SLACK_NS: i64 = 20_000_000;

impl PlanAct {
    /// The act from its start, the route sent; `run` holds the route, the pre-check's answer
    /// and the dock.
    pub fn new(run: PlanRun) -> PlanAct {
        PlanAct {
            phase: Phase::RouteSent,
            run,
            route_window: None,
            route_reason: String::new(),
        }
    }

    /// Takes a status stamped `stamp` (ns; the planner's clock) and received at `now` (ns).
    /// Statuses of another phase (the route's last ones while the dock is sent, a docking
    /// mode's before the route ends) change nothing; a final docking status with the docking
    /// fields cleared adds no sample.
    pub fn status(&mut self, s: &Status, stamp: i64, now: i64) -> Next {
        let finished = s.state.finished();
        let outcome = || {
            if s.state == GoalState::Succeeded {
                Outcome::Succeeded
            } else {
                Outcome::Failed(s.reason.clone())
            }
        };
        let docking_mode = matches!(s.mode.as_str(), "dock" | "rotate");
        match self.phase {
            Phase::RouteSent if s.state == GoalState::Active && s.waypoint_index >= 0 => {
                self.phase = Phase::Route(stamp);
                Next::RouteAccepted
            }
            Phase::Route(t0) if finished => {
                self.run.route_outcome = outcome();
                self.run.route_s = secs(t0, stamp);
                self.route_window = Some((t0, stamp));
                self.route_reason = s.reason.clone();
                self.phase = Phase::DockSent(now);
                Next::SendDock
            }
            Phase::DockSent(t0) | Phase::Dock(t0) if docking_mode && (s.state == GoalState::Active || finished) => {
                let accepted = matches!(self.phase, Phase::DockSent(_));
                self.phase = Phase::Dock(t0);
                let (e, alpha, theta, lyapunov) = s.docking;
                let cleared = e == 0.0 && alpha == 0.0 && theta == 0.0 && lyapunov == 0.0;
                if !(finished && cleared) {
                    let t = secs(t0, stamp);
                    let sample = DockSample::from_status(t, e, alpha, theta, lyapunov, &s.mode);
                    self.run.docking.push(sample);
                }
                if finished {
                    self.run.dock_outcome = outcome();
                    Next::Done
                } else if accepted {
                    Next::DockAccepted
                } else {
                    Next::Wait
                }
            }
            Phase::Dock(_) if finished => {
                self.run.dock_outcome = outcome();
                Next::Done
            }
            _ => Next::Wait,
        }
    }

    /// At the act's end: the route's odometry track from every odometry sample received,
    /// chosen by stamp ([`route_track`], with [`ROUTE_END_SLACK_NS`]).
    pub fn finish(&mut self, odom: &[OdomSample]) {
        if let Some((start, end)) = self.route_window {
            self.run.odom_path = route_track(odom, start, end, ROUTE_END_SLACK_NS);
        }
    }
}

/// Seconds between two clock readings in nanoseconds.
fn secs(from: i64, to: i64) -> f64 {
    (to - from) as f64 * 1e-9
}

/// The lines printed once the pre-check answered (`reason`: its reason): the route feasible
/// with the predicted path's length, or not, with each problem on a line of its own.
pub fn precheck_lines(run: &PlanRun, reason: &str) -> Vec<String> {
    let n = run.waypoints.len();
    if run.feasible {
        return vec![format!(
            "  pre-check: route of {n} waypoints feasible, predicted path {:.2} m",
            run.predicted_length
        )];
    }
    let mut lines = vec![format!(
        "  pre-check: route of {n} waypoints not feasible, {} problem(s): {reason}",
        run.problems.len()
    )];
    lines.extend(
        run.problems
            .iter()
            .map(|p| format!("    waypoint {}: {}: {}", p.index, p.kind, p.detail)),
    );
    lines
}

impl Summary {
    /// The line after the summary when waypoints were missed: each one's closest approach of
    /// the odometry in `run`, the tolerance and what the planner said when the route ended
    /// (`planner_said`); `None` when none was missed.
    pub fn missed_line(&self, run: &PlanRun, tolerance: f64, planner_said: &str) -> Option<String> {
        if self.missed.is_empty() {
            return None;
        }
        let closest: Vec<String> = self
            .missed
            .iter()
            .map(|&i| format!("{i} ({:.3} m)", closest_approach(run.waypoints[i], &run.odom_path)))
            .collect();
        Some(format!(
            "  missed waypoints (the odometry's closest approach; reach within {tolerance} m): {}; the planner said: {}",
            closest.join(", "),
            if planner_said.is_empty() { "nothing" } else { planner_said }
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mobil_world::Obstacle;

    /// A recorded run, small enough to work out by hand.
    fn recorded(route: Outcome, dock: Outcome) -> PlanRun {
        PlanRun {
            waypoints: vec![(0.0, 0.0), (2.0, 0.0), (2.0, 2.0)],
            feasible: false,
            problems: vec![Problem {
                index: 2,
                kind: "turn_radius".into(),
                detail: "turn radius 0.50 m below the chassis minimum 0.73 m".into(),
                at: (2.0, 2.0),
            }],
            predicted: vec![(0.0, 0.0), (1.0, 0.1), (2.0, 0.0), (2.0, 2.0)],
            predicted_length: 4.0,
            path: vec![(0.0, 0.0), (1.0, 0.0), (2.0, 0.1), (2.0, 1.8), (3.0, 1.0)],
            // Within 0.1, 0.15 and 0.3 m of the three waypoints.
            odom_path: vec![(0.0, 0.1), (1.0, 0.0), (2.0, 0.15), (2.0, 1.0), (2.0, 1.7)],
            route_outcome: route,
            route_s: 21.34,
            dock: (3.0, 1.0, FRAC_PI_2),
            docking: vec![
                DockSample::from_status(0.0, 1.0, 0.2, 0.5, 1.43, "dock"),
                DockSample::from_status(4.0, 0.03, 0.05, 0.2, 0.02, "dock"),
                DockSample::from_status(5.5, 0.018, 0.01, 0.03, 0.0001, "rotate"),
            ],
            dock_outcome: dock,
            final_truth: Some((3.03, 1.04, FRAC_PI_2 + 0.05)),
        }
    }

    #[test]
    fn route_track_is_the_samples_stamped_within_the_route() {
        // Received out of order: the sample the route ended on (t = 100) after later ones.
        let samples = [
            (5, 0.0, 0.0),
            (10, 1.0, 0.0),
            (130, 3.0, 0.0),
            (100, 2.0, 0.0),
            (121, 4.0, 0.0),
        ];
        assert_eq!(route_track(&samples, 10, 100, 0), vec![(1.0, 0.0), (2.0, 0.0)]);
        // A status stamped a clock period behind its sample: the slack takes the sample in.
        assert_eq!(route_track(&samples, 10, 90, 20), vec![(1.0, 0.0), (2.0, 0.0)]);
        assert_eq!(
            route_track(&samples, 10, 100, 21),
            vec![(1.0, 0.0), (2.0, 0.0), (4.0, 0.0)]
        );
        // Before the start: nothing; an end at the extreme does not overflow.
        assert!(route_track(&samples, 200, i64::MAX, 20).is_empty());
        assert_eq!(route_track(&samples, 0, i64::MAX, 1).len(), 5);
    }

    #[test]
    fn missed_waypoints_by_closest_approach() {
        let run = recorded(Outcome::Succeeded, Outcome::Succeeded);
        assert_eq!(missed_waypoints(&run.waypoints, &run.odom_path, 0.16), vec![2]);
        assert_eq!(
            missed_waypoints(&run.waypoints, &run.odom_path, 0.31),
            Vec::<usize>::new()
        );
        assert_eq!(missed_waypoints(&run.waypoints, &run.odom_path, 0.12), vec![1, 2]);
        assert_eq!(missed_waypoints(&run.waypoints, &[], 1.0), vec![0, 1, 2]);
        // The track's nearest points: (0, 0.1), (2, 0.15), (2, 1.7) at 0.1, 0.15 and 0.3 m.
        let closest: Vec<f64> = run
            .waypoints
            .iter()
            .map(|&w| closest_approach(w, &run.odom_path))
            .collect();
        for (c, want) in closest.iter().zip([0.1, 0.15, 0.3]) {
            assert!((c - want).abs() < 1e-12, "{c} vs {want}");
        }
        assert_eq!(closest_approach((0.0, 0.0), &[]), f64::INFINITY);
    }

    #[test]
    fn heading_error_from_alpha_and_theta() {
        // α = Ω − ϑ, Θ = Ω − ϑ_G, so ϑ − ϑ_G = Θ − α: 0.03 − 0.01.
        let s = DockSample::from_status(0.0, 0.1, 0.01, 0.03, 0.0, "dock");
        assert!((s.heading - 0.02).abs() < 1e-15);
        // Wrapped: Θ = 3, α = −3 is 6 rad, i.e. 6 − 2π.
        let s = DockSample::from_status(0.0, 0.1, -3.0, 3.0, 0.0, "dock");
        assert!((s.heading - (6.0 - std::f64::consts::TAU)).abs() < 1e-12);
    }

    #[test]
    fn three_significant_digits() {
        assert_eq!(three_digits(1.4321), "1.43");
        assert_eq!(three_digits(0.052349), "0.0523");
        assert_eq!(three_digits(0.0001), "0.000100");
        assert_eq!(three_digits(12.34), "12.3");
        assert_eq!(three_digits(1234.5), "1234");
        assert_eq!(three_digits(0.0), "0");
    }

    #[test]
    fn summary_line_of_a_docked_run() {
        let run = recorded(Outcome::Succeeded, Outcome::Succeeded);
        let s = Summary::of(&run, 0.16);
        assert_eq!(s.missed, vec![2]);
        assert_eq!(s.residual, Some((0.018, 0.03 - 0.01)));
        assert_eq!(s.lyapunov, Some((1.43, 0.0001)));
        assert_eq!(
            s.line("demo_out/omr3_planner.svg", false),
            "demo: planner followed 3 waypoints (1 missed) in 21.3 simulated s, docked in 5.5 s at e 0.018 m, \
             heading error 0.020 rad; V fell from 1.43 to 0.000100; plot demo_out/omr3_planner.svg"
        );
    }

    #[test]
    fn summary_line_of_a_car_that_stops_with_a_residual() {
        let mut run = recorded(
            Outcome::Failed("ROUTE: waypoint 2 unreachable".into()),
            Outcome::Failed("RESIDUAL: V stopped falling: e = 0.030 m, heading error 0.150 rad".into()),
        );
        run.docking.truncate(2);
        // The heading error is printed unsigned: Θ − α = 0.2 − 0.05 here; −0.15 reads the same.
        run.docking[1].heading = -run.docking[1].heading;
        let line = Summary::of(&run, 0.16).line("p.svg", true);
        assert_eq!(
            line,
            "demo: planner's route of 3 waypoints failed after 21.3 simulated s (ROUTE: waypoint 2 unreachable), \
             docking ended after 4.0 s at e 0.030 m, heading error 0.150 rad (RESIDUAL: a steered chassis cannot \
             turn in place, so the law cannot converge and leaves this residual); V fell from 1.43 to 0.0200; plot p.svg"
        );
        // No docking status at all, and V rising, are said as such.
        run.docking.clear();
        assert!(Summary::of(&run, 0.16)
            .line("p.svg", false)
            .contains("e NaN m, heading error NaN rad"));
        assert!(Summary::of(&run, 0.16)
            .line("p.svg", false)
            .contains("; no docking status received;"));
        run.docking = vec![
            DockSample::from_status(0.0, 1.0, 0.0, 0.0, 0.5, "dock"),
            DockSample::from_status(1.0, 1.0, 0.0, 0.0, 0.7, "dock"),
        ];
        assert!(Summary::of(&run, 0.16)
            .line("p.svg", false)
            .contains("; V went from 0.500 to 0.700;"));
    }

    #[test]
    fn figure_places_route_paths_dock_problems_and_panels_by_hand() {
        // A disc r 0.5 at (1, 3): with the run the map spans x [0, 3], y [0, 3.5]; at 60 px/m
        // with a 0.5 m margin x = 0 is at 30 px, and y = 0 at 34 + (3.5 + 0.5)·60 = 274 px.
        let world = World {
            obstacles: vec![Obstacle::Circle {
                center: [1.0, 3.0],
                radius: 0.5,
            }],
        };
        let run = recorded(Outcome::Succeeded, Outcome::Succeeded);
        let svg = figure(&world, &run, "t <&>");
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        // Width: the map is (3 + 1)·60 = 240 px, widened to 700 for the panels; height 34 +
        // (3.5 + 1)·60 + 25 + 150 + 95 = 574.
        assert!(svg.contains(r#"width="700" height="574""#), "{svg}");
        assert!(
            svg.contains(r##"<circle cx="90.0" cy="94.0" r="30.0" fill="#969696"/>"##),
            "{svg}"
        );
        // The route from the first true point (0, 0) through the waypoints, thin orange.
        assert!(
            svg.contains(r##"points="30.0,274.0 30.0,274.0 150.0,274.0 150.0,154.0" fill="none" stroke="#E69F00""##),
            "{svg}"
        );
        // The prediction dashed blue; the true path solid black.
        assert!(svg.contains(r##"points="30.0,274.0 90.0,268.0 150.0,274.0 150.0,154.0" fill="none" stroke="#005AB5" stroke-width="2" stroke-dasharray="8 5""##), "{svg}");
        assert!(
            svg.contains(
                r##"points="30.0,274.0 90.0,274.0 150.0,268.0 150.0,166.0 210.0,214.0" fill="none" stroke="#141414""##
            ),
            "{svg}"
        );
        // Waypoints numbered 0, 1, 2; the dock an arrow from (3, 1) (210, 214) 0.6 m up to (210, 178).
        for (i, (x, y)) in [(0, (30.0, 274.0)), (1, (150.0, 274.0)), (2, (150.0, 154.0))] {
            assert!(
                svg.contains(&format!(
                    r#"<text x="{:.1}" y="{:.1}" font-size="11">{i}</text>"#,
                    x - 3.5,
                    y + 4.0
                )),
                "{i}: {svg}"
            );
        }
        assert!(svg.contains("M 210.0 214.0 L 210.0 178.0"), "{svg}");
        // The problem: a red cross at waypoint 2 and its label.
        assert!(
            svg.contains(r##"M 143.0 147.0 L 157.0 161.0"##) && svg.contains("2: turn_radius"),
            "{svg}"
        );
        // The panels start 25 px below the map (34 + 270 + 25 = 329 px), 150 px high; the left
        // one spans x 50..340 ((700 − 120) / 2 = 290 px wide). V(t) starts at its top (1.43 at
        // t = 0) and ends at t = 5.5, the right edge, at 0.0001 / 1.43 · 150 = 0.01 px above
        // the bottom (479 px).
        assert!(svg.contains(r##"<polyline points="50.0,329.0 "##), "{svg}");
        assert!(svg.contains(r##" 340.0,479.0" fill="none" stroke="#1A8C3A""##), "{svg}");
        // The final rotation begins at t = 5.5: a dashed line at the panel's right edge.
        assert!(
            svg.contains(
                r##"points="340.0,479.0 340.0,329.0" fill="none" stroke="#005AB5" stroke-width="1" stroke-dasharray"##
            ),
            "{svg}"
        );
        // The true end: e = |(0.03, 0.04)| = 0.05 m, heading 0.05 rad.
        assert!(svg.contains("e 0.050 m, heading 0.050 rad"), "{svg}");
        assert!(svg.contains("t &lt;&amp;&gt;"));
        assert!(svg.contains("1 problem(s), red ✕"));
    }

    fn status(state: GoalState, index: i32, mode: &str, docking: (f64, f64, f64, f64)) -> Status {
        Status {
            state,
            waypoint_index: index,
            mode: mode.into(),
            reason: if state == GoalState::Failed {
                "RESIDUAL: e = 0.1 m".into()
            } else {
                String::new()
            },
            docking,
        }
    }

    #[test]
    fn the_act_follows_the_route_then_the_docking() {
        use GoalState::*;
        let mut run = recorded(
            Outcome::Failed("not started".into()),
            Outcome::Failed("not started".into()),
        );
        run.docking.clear();
        let mut act = PlanAct::new(run);
        let none = (0.0, 0.0, 0.0, 0.0);
        let s = 1_000_000_000;
        // Idle, then a status of no route: still sent.
        assert_eq!(act.status(&status(Idle, -1, "idle", none), 0, 0), Next::Wait);
        assert_eq!(act.status(&status(Active, -1, "pre_check", none), s, s), Next::Wait);
        assert_eq!(
            act.status(&status(Active, 0, "approach", none), 2 * s, 2 * s),
            Next::RouteAccepted
        );
        assert_eq!(act.phase, Phase::Route(2 * s));
        assert_eq!(
            act.status(&status(Active, 2, "approach", none), 9 * s, 9 * s),
            Next::Wait
        );
        // Ends at 23.5 s by its stamp, received at 24 s: the dock is sent then.
        assert_eq!(
            act.status(&status(Succeeded, 2, "approach", none), 23_500_000_000, 24 * s),
            Next::SendDock
        );
        assert_eq!(act.phase, Phase::DockSent(24 * s));
        assert_eq!(
            (act.run.route_outcome.clone(), act.run.route_s),
            (Outcome::Succeeded, 21.5)
        );
        assert_eq!(act.route_window, Some((2 * s, 23_500_000_000)));
        // The route's last status again: nothing; then the docking, sample by sample.
        assert_eq!(
            act.status(&status(Succeeded, 2, "approach", none), 23_500_000_000, 25 * s),
            Next::Wait
        );
        let d = (1.0, 0.2, 0.5, 1.43);
        assert_eq!(
            act.status(&status(Active, -1, "dock", d), 25 * s, 25 * s),
            Next::DockAccepted
        );
        assert_eq!(act.status(&status(Active, -1, "rotate", d), 26 * s, 26 * s), Next::Wait);
        // A final status with the docking fields cleared ends it without a sample.
        assert_eq!(
            act.status(&status(Failed, -1, "rotate", none), 27 * s, 27 * s),
            Next::Done
        );
        assert_eq!(act.run.dock_outcome, Outcome::Failed("RESIDUAL: e = 0.1 m".into()));
        let t: Vec<f64> = act.run.docking.iter().map(|d| d.t).collect();
        assert_eq!(t, [1.0, 2.0]);
        // The route's odometry: the samples stamped within it and the slack.
        act.finish(&[
            (s, 9.0, 9.0),
            (3 * s, 1.0, 0.0),
            (23_510_000_000, 2.0, 0.0),
            (24 * s, 3.0, 0.0),
        ]);
        assert_eq!(act.run.odom_path, [(1.0, 0.0), (2.0, 0.0)]);
    }

    #[test]
    fn a_final_docking_status_with_its_figures_is_a_sample() {
        use GoalState::*;
        let mut act = PlanAct::new(recorded(Outcome::Succeeded, Outcome::Succeeded));
        act.run.docking.clear();
        act.phase = Phase::DockSent(0);
        let d = (0.018, 0.01, 0.03, 0.0001);
        // A docking that ends on the status that first shows it.
        assert_eq!(
            act.status(&status(Succeeded, -1, "rotate", d), 500_000_000, 1),
            Next::Done
        );
        assert_eq!(act.run.docking.len(), 1);
        assert_eq!(act.run.dock_outcome, Outcome::Succeeded);
        // A docking that ends in another mode: no sample, the outcome taken.
        act.phase = Phase::Dock(0);
        assert_eq!(
            act.status(&status(Failed, -1, "idle", (0.0, 0.0, 0.0, 0.0)), 1, 1),
            Next::Done
        );
        assert_eq!(act.run.docking.len(), 1);
    }

    #[test]
    fn the_pre_check_and_missed_waypoint_lines() {
        let run = recorded(Outcome::Succeeded, Outcome::Succeeded);
        assert_eq!(
            precheck_lines(&run, "turn too tight"),
            [
                "  pre-check: route of 3 waypoints not feasible, 1 problem(s): turn too tight",
                "    waypoint 2: turn_radius: turn radius 0.50 m below the chassis minimum 0.73 m",
            ]
        );
        let feasible = PlanRun {
            feasible: true,
            ..run.clone()
        };
        assert_eq!(
            precheck_lines(&feasible, ""),
            ["  pre-check: route of 3 waypoints feasible, predicted path 4.00 m"]
        );
        let summary = Summary::of(&run, 0.16);
        assert_eq!(
            summary.missed_line(&run, 0.16, "").as_deref(),
            Some(
                "  missed waypoints (the odometry's closest approach; reach within 0.16 m): 2 (0.300 m); the planner said: nothing"
            )
        );
        assert_eq!(Summary::of(&run, 0.31).missed_line(&run, 0.31, "x"), None);
    }
}
