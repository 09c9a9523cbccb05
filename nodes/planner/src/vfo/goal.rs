//! VFO waypoint following as a goal law ([`mobil_motion::GoalLaw`]): the follower behind the
//! suite's one step interface, with the route's request indices, the point the law steers, what
//! the status and the markers show of the segment's optimisation, and the ends with their
//! reasons and Nav2's codes.
//!
//! A step may optimise a segment (Algorithm 2, 0.25–1 s at 20–30 obstacles), so a node runs it
//! off its event loop ([`mobil_motion::slot`]) and asks the step's [`VfoTick::interrupt`] to stop
//! or cut it short; the robot stops meanwhile.

use crate::vfo::{
    Interrupt, Obstacle, ObstacleMap, Optimisation, OptimiseConfig, PathIndices, RobotEnd, VfoEnd, VfoEvent,
    VfoFollower, VfoGains, VfoWaypoint, MAX_BUDGET_RETRIES,
};
use mobil_chassis::{BodyTwist, ChassisParams};
use mobil_geom::{downsample, Pose2};
use mobil_motion::{nav2, GoalLaw, Outcome, Step, StepInput};
use nalgebra::Point2;

/// The law's gains held to the chassis: U_2 ≤ v_max; |ω| ≤ the chassis' ω_max; on a steered
/// chassis (no turn in place) also |ω| ≤ U_2 / R_min, so a virtual robot at cruise speed turns
/// no tighter than the real one can. The law is a unicycle's: on a steered chassis the commands
/// are further held to the minimum radius at low speed, where the real robot then turns wider
/// than the virtual robots did.
pub fn vfo_gains(gains: &VfoGains, chassis: &ChassisParams) -> VfoGains {
    let speed = gains.speed.min(chassis.v_max());
    let mut omega_max = gains.omega_max.min(chassis.omega_max());
    if chassis.model().is_nonholonomic() {
        omega_max = omega_max.min(speed / chassis.min_turning_radius());
    }
    VfoGains {
        speed,
        omega_max,
        ..*gains
    }
}

/// The current segment's optimisation as the status reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentReport {
    /// Ψ_z of the chosen Σ (NaN when none).
    pub psi_z: f64,
    /// χ_D, χ_B, χ_E, χ_S of the chosen path (NaN when none).
    pub indices: [f64; 4],
    /// Virtual robots simulated.
    pub virtual_robots: usize,
    /// Candidates |D|.
    pub candidates: usize,
}

impl Default for SegmentReport {
    fn default() -> Self {
        SegmentReport {
            psi_z: f64::NAN,
            indices: [f64::NAN; 4],
            virtual_robots: 0,
            candidates: 0,
        }
    }
}

impl SegmentReport {
    /// The report of optimisation `o`.
    pub fn of(o: &Optimisation) -> Self {
        let best = o.best.and_then(|b| o.paths.get(b));
        SegmentReport {
            psi_z: o.score().unwrap_or(f64::NAN),
            indices: best.map_or([f64::NAN; 4], |p| PathIndices::as_array(&p.indices)),
            virtual_robots: o.robots.len(),
            candidates: o.candidates(),
        }
    }
}

/// Most virtual robots drawn (the first ones simulated; the count is in the status).
pub const MAX_DRAWN_ROBOTS: usize = 40;
/// Most points over all virtual robots drawn, and of the chosen path, in a [`VfoDrawing`].
pub const MAX_DRAWN_POINTS: usize = 1600;
/// Most obstacles drawn (the nearest to the robot first).
pub const MAX_DRAWN_OBSTACLES: usize = 25;

/// One virtual robot's path as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnRobot {
    /// Its points (odom), downsampled.
    pub points: Vec<Point2<f64>>,
    /// It ended in a collision or on the time cap (its path was dropped there).
    pub dropped: bool,
}

/// What the markers and the demo draw of an optimisation: every virtual robot's path, the
/// chosen path, the obstacles with r and R.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VfoDrawing {
    /// The virtual robots (at most [`MAX_DRAWN_ROBOTS`], [`MAX_DRAWN_POINTS`] points in all).
    pub robots: Vec<DrawnRobot>,
    /// The chosen path (at most [`MAX_DRAWN_POINTS`] points).
    pub chosen: Vec<Point2<f64>>,
    /// The obstacles known to the follower.
    pub obstacles: Vec<Obstacle>,
}

impl VfoDrawing {
    /// The drawing of optimisation `o` over `obstacles`.
    pub fn of(o: &Optimisation, obstacles: &[Obstacle]) -> Self {
        let robots: Vec<_> = o.robots.iter().take(MAX_DRAWN_ROBOTS).collect();
        let per_robot = (MAX_DRAWN_POINTS / robots.len().max(1)).max(2);
        VfoDrawing {
            robots: robots
                .iter()
                .map(|r| DrawnRobot {
                    points: downsample(&r.path, per_robot),
                    dropped: matches!(r.end, RobotEnd::Collided { .. } | RobotEnd::TimeCap),
                })
                .collect(),
            chosen: downsample(&o.best_path(), MAX_DRAWN_POINTS),
            obstacles: obstacles.to_vec(),
        }
    }
}

/// A route's waypoints as VFO waypoints from `start` (the steered point's pose), μ = `guiding`
/// for every one. A waypoint's θ_r is its `heading` when given; one without takes the direction
/// from the waypoint before (the start for the first): the robot arrives moving along its leg;
/// one on the point before keeps the heading before it. A waypoint that cannot be one (not
/// finite) is refused by its index.
pub fn vfo_waypoints(
    points: &[Point2<f64>],
    headings: &[Option<f64>],
    start: &Pose2,
    guiding: f64,
) -> Result<Vec<VfoWaypoint>, usize> {
    let mut previous = start.position();
    let mut heading = start.yaw;
    let mut out = Vec::with_capacity(points.len());
    for (k, p) in points.iter().enumerate() {
        let leg = p - previous;
        heading = match headings.get(k).copied().flatten() {
            Some(h) => h,
            None if leg.norm() > 1e-9 => leg.y.atan2(leg.x),
            None => heading,
        };
        out.push(VfoWaypoint::new(p.x, p.y, heading, guiding).map_err(|_| k)?);
        previous = *p;
    }
    Ok(out)
}

/// What a VFO route is driven with: the law's gains, Algorithm 2's settings, the guiding μ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VfoSetup {
    /// The law's gains (held to the chassis by [`vfo_gains`]).
    pub gains: VfoGains,
    /// The optimisation's settings.
    pub optimise: OptimiseConfig,
    /// μ of every waypoint.
    pub guiding: f64,
}

/// What a VFO step senses besides the pose: the pose's stamp (s, on the odometry's clock; the
/// rest test times by it) and the interrupt an optimisation asks before every virtual
/// robot and as it runs: stop (the goal ended) or take the best so far (the budget is spent).
pub struct VfoTick {
    /// The pose's stamp (s).
    pub stamp: f64,
    /// Asked during an optimisation.
    pub interrupt: Box<dyn Fn() -> Option<Interrupt> + Send + Sync>,
}

impl VfoTick {
    /// A tick at `stamp` that never interrupts.
    pub fn uninterrupted(stamp: f64) -> Self {
        VfoTick {
            stamp,
            interrupt: Box::new(|| None),
        }
    }
}

/// What the status shows of a VFO route, kept by the node while the law is out on a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VfoView {
    /// The waypoint pursued (route index; the route's length once done).
    pub index: usize,
    /// The waypoint pursued (the request's index; the last once done).
    pub waypoint: usize,
    /// Its position.
    pub target: Option<Point2<f64>>,
    /// ‖e*‖ (m) to it at the last step.
    pub distance: f64,
    /// The segment's optimisation.
    pub report: SegmentReport,
}

/// One step of a VFO route.
#[derive(Debug, Clone, PartialEq)]
pub struct VfoStep {
    /// What happened (waypoint indices are the route's; [`VfoGoal::request`] maps them).
    pub events: Vec<VfoEvent>,
    /// The robot is held at zero inside an influence zone until it stands.
    pub settling: bool,
    /// This step optimised the segment: what to draw of it.
    pub drawing: Option<VfoDrawing>,
}

/// A route by VFO round the obstacles seen (SPEC §5), the follower steering the point `offset`
/// behind the reference point (the rear axle of a steered chassis; 0 on the omni chassis).
///
/// Its report at the end is the waypoints not reached (request indices, from the one pursued
/// on): empty when done.
#[derive(Debug, Clone)]
pub struct VfoGoal {
    follower: VfoFollower,
    request_index: Vec<usize>,
    offset: f64,
    index: usize,
    distance: f64,
    report: SegmentReport,
    /// The map's ids of the obstacles the follower holds, by its index.
    held_ids: Vec<u64>,
}

impl VfoGoal {
    /// A route through `points` (their `headings` where given, the request's index of each
    /// alongside) from the reference point at `start` on `chassis`, round the obstacles of
    /// `map`, with `setup`'s gains held to the chassis; the law steers the point
    /// [`crate::goals::docking_offset`] behind the reference point. Refused `INVALID_GOAL` for a
    /// waypoint that cannot be one, `INVALID_INPUT` when the follower refuses its settings.
    pub fn for_route(
        (points, headings, request_index): (&[Point2<f64>], &[Option<f64>], &[usize]),
        start: &Pose2,
        setup: &VfoSetup,
        chassis: &ChassisParams,
        map: &ObstacleMap,
    ) -> Result<Self, Outcome> {
        let offset = crate::goals::docking_offset(chassis);
        let request = |i: usize| request_index.get(i).copied().unwrap_or(i);
        let waypoints = vfo_waypoints(points, headings, &start.ahead(-offset), setup.guiding).map_err(|k| {
            let code = nav2::follow_waypoints::UNKNOWN;
            Outcome::failed("INVALID_GOAL", format!("waypoint {} is not finite", request(k)), code)
        })?;
        let gains = vfo_gains(&setup.gains, chassis);
        let follower = VfoFollower::new(gains, setup.optimise, waypoints, map.obstacles()).map_err(|e| {
            let detail = format!("the planner refused its input: {e}; robot stopped");
            Outcome::failed("INVALID_INPUT", detail, nav2::follow_waypoints::TASK_EXECUTOR_FAILED)
        })?;
        Ok(VfoGoal::new(follower, request_index.to_vec(), offset, start, map.ids()))
    }

    /// A route for `follower`, which knows the obstacles of the map whose ids are `held_ids`;
    /// the request's index of each waypoint alongside (missing ones count as their own);
    /// starting with the reference point at `start`.
    pub fn new(
        follower: VfoFollower,
        request_index: Vec<usize>,
        offset: f64,
        start: &Pose2,
        held_ids: Vec<u64>,
    ) -> Self {
        let guide = start.ahead(-offset).position();
        let distance = follower
            .waypoints()
            .first()
            .map_or(f64::NAN, |w| (w.position - guide).norm());
        VfoGoal {
            follower,
            request_index,
            offset,
            index: 0,
            distance,
            report: SegmentReport::default(),
            held_ids,
        }
    }

    /// The request's index of route waypoint `i`.
    pub fn request(&self, i: usize) -> usize {
        self.request_index.get(i).copied().unwrap_or(i)
    }

    /// The follower.
    pub fn follower(&self) -> &VfoFollower {
        &self.follower
    }

    /// The waypoints not reached, request indices from the one pursued on.
    pub fn unreached(&self) -> Vec<usize> {
        (self.index..self.follower.waypoints().len())
            .map(|i| self.request(i))
            .collect()
    }

    /// What the status shows.
    pub fn view(&self) -> VfoView {
        let n = self.follower.waypoints().len();
        let i = self.index.min(n.saturating_sub(1));
        VfoView {
            index: self.index,
            waypoint: self.request(i),
            target: self.follower.waypoints().get(i).map(|w| w.position),
            distance: self.distance,
            report: self.report,
        }
    }

    /// The follower takes `map`'s obstacles, each decision carried over by the obstacle's id;
    /// with `new` obstacles (not seen before) the segment is re-optimised at the next step.
    pub fn follow_map(&mut self, map: &ObstacleMap, new: bool) {
        self.follower.follow_map(map, &mut self.held_ids, new);
    }

    /// What `event` says, by the request's waypoint indices: "waypoint 2 reached", "segment to
    /// waypoint 3 optimised (SegmentStart): Ψ_z 1.234, 17 virtual robots, 4 candidates".
    pub fn describe(&self, event: &VfoEvent) -> String {
        match event {
            VfoEvent::Reached { index, vortex } => format!(
                "waypoint {} reached{}",
                self.request(*index),
                if *vortex {
                    " (early: the robot was caught between obstacles, Algorithm 3)"
                } else {
                    ""
                }
            ),
            VfoEvent::Optimised {
                index, reason, score, ..
            } => format!(
                "segment to waypoint {} optimised ({reason:?}): Ψ_z {}, {} virtual robots, {} candidates",
                self.request(*index),
                score.map_or("none".to_owned(), |s| format!("{s:.3}")),
                self.report.virtual_robots,
                self.report.candidates
            ),
        }
    }

    fn fail(&self, code: &'static str, detail: String) -> Step<VfoStep, Vec<usize>> {
        Step::end(
            Outcome::failed(code, detail, nav2::follow_waypoints::TASK_EXECUTOR_FAILED),
            self.unreached(),
        )
    }
}

impl GoalLaw for VfoGoal {
    type Sensors = VfoTick;
    type Feedback = VfoStep;
    type Report = Vec<usize>;

    fn step(&mut self, input: &StepInput, tick: &VfoTick) -> Step<VfoStep, Vec<usize>> {
        let guide = input.pose.ahead(-self.offset);
        let o = match self
            .follower
            .update_stamped(&guide, input.t, tick.stamp, &*tick.interrupt)
        {
            Ok(o) => o,
            Err(e) => return Step::Refused(e.to_string()),
        };
        let optimised = o.events.iter().any(|e| matches!(e, VfoEvent::Optimised { .. }));
        let mut drawing = None;
        if let Some(last) = self.follower.last_optimisation().filter(|_| optimised) {
            self.report = SegmentReport::of(last);
            drawing = Some(VfoDrawing::of(last, self.follower.obstacles()));
        }
        self.index = o.index;
        self.distance = o.distance;
        let n = self.follower.waypoints().len();
        match o.end {
            None => Step::Command {
                twist: BodyTwist::new(o.v, 0.0, o.omega),
                feedback: VfoStep {
                    events: o.events,
                    settling: self.follower.is_settling(),
                    drawing,
                },
            },
            Some(VfoEnd::Done) => Step::end(Outcome::succeeded(crate::goals::route_done(n, &[])), Vec::new()),
            Some(VfoEnd::NoSafePath { index }) => {
                self.index = index;
                self.fail(
                    "NO_SAFE_PATH",
                    format!(
                        "no left/right decisions round the obstacles take the robot to waypoint {} without a \
                         collision ({} virtual robots simulated): robot stopped",
                        self.request(index),
                        self.report.virtual_robots
                    ),
                )
            }
            Some(VfoEnd::BudgetExhausted { index }) => {
                self.index = index;
                self.fail(
                    "OPTIMISATION_BUDGET",
                    format!(
                        "optimisation budget exhausted: {MAX_BUDGET_RETRIES} optimisations in a row ran out of \
                         vfo.optimise_budget_s before finding any path to waypoint {} (none was proven unsafe; the \
                         scene needs a larger budget or a faster machine): robot stopped",
                        self.request(index)
                    ),
                )
            }
            Some(VfoEnd::Collision { obstacle }) => {
                let detail = match self.follower.obstacles().get(obstacle) {
                    Some(ob) => format!(
                        "the robot is {:.2} m from the centre of the obstacle at ({:.2}, {:.2}), inside its \
                         forbidden radius r = {:.2} m (an obstacle seen too late or moving): robot stopped",
                        ob.distance(&guide.position()),
                        ob.centre().x,
                        ob.centre().y,
                        ob.forbidden_radius()
                    ),
                    None => "the robot is inside an obstacle's forbidden radius: robot stopped".to_owned(),
                };
                self.fail("COLLISION", detail)
            }
        }
    }
}
