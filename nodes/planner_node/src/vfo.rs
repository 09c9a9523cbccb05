//! The shell side of VFO waypoint following ([`mobil_planner::vfo`], SPEC §5): the parameters,
//! a route's waypoints as VFO waypoints, the gains held to the chassis, the hand-over of the
//! follower to the blocking pool and back, the segment's report for the status and what the
//! markers draw of the last optimisation. Nothing here decides where the robot goes.
//!
//! **While a segment is optimised the robot stops.** [`mobil_planner::vfo::VfoFollower::update`]
//! runs Algorithm 2 inside the tick (0.25–1 s at 20–30 obstacles), so every tick runs on the
//! blocking pool ([`VfoSlot`] lends the follower out and takes it back). An odometry tick that
//! finds the follower still out commands zero, and a command that comes back later than
//! [`VfoSlot::max_delay`] after its pose is replaced by zero: the virtual robots start from the
//! pose the optimisation began at, and a robot that drove on under the old Σ meanwhile would
//! leave that start (and could enter a zone whose σ the new Σ sets the other way). Holding the
//! last command instead would keep the robot on a path no optimisation has checked.

use std::str::FromStr;
use std::time::{Duration, Instant};

use mobil_chassis::{BodyTwist, ChassisParams};
use mobil_geom::Pose2;
use mobil_planner::vfo::{
    Obstacle, Optimisation, OptimiseConfig, PathIndices, QualityWeights, RobotEnd, ScanObstacleConfig, VfoFollower,
    VfoGains, VfoOutput, VfoWaypoint, DEFAULT_GUIDING,
};
use mobil_ros::config::Decl;
use nalgebra::Point2;

use crate::{GoalError, PlannerConfig, Route};

/// How `waypoints` and `follow_waypoints` are followed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum WaypointMethod {
    /// The goal approach after the route pre-check (SPEC §4).
    #[default]
    Approach,
    /// VFO with virtual-robot optimisation round obstacles seen by the LIDAR (SPEC §5).
    Vfo,
}

impl WaypointMethod {
    /// The parameter's spelling: `approach` or `vfo`.
    pub fn as_str(self) -> &'static str {
        match self {
            WaypointMethod::Approach => "approach",
            WaypointMethod::Vfo => "vfo",
        }
    }
}

impl FromStr for WaypointMethod {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "approach" => Ok(WaypointMethod::Approach),
            "vfo" => Ok(WaypointMethod::Vfo),
            other => Err(format!("waypoint_method `{other}`: give approach or vfo")),
        }
    }
}

/// The VFO settings, each filled by one `vfo.*` parameter (defaults: the library's).
#[derive(Debug, Clone, PartialEq)]
pub struct VfoSettings {
    /// The law's gains (U_2 and |ω| are further held to the chassis: [`vfo_gains`]).
    pub gains: VfoGains,
    /// Algorithm 2's settings (`time_step` = the node's control period).
    pub optimise: OptimiseConfig,
    /// Obstacle extraction and merge (`robot_radius` is the node's `robot_radius`).
    pub scan: ScanObstacleConfig,
    /// μ of every waypoint (eq. 11).
    pub guiding: f64,
    /// Echoes farther than this (m) are not turned into obstacles.
    pub scan_range: f64,
    /// A VFO goal fails STALE_INPUT when no valid scan arrived for this long (steady clock), s.
    pub scan_timeout_s: f64,
    /// The wall-clock budget of one segment's optimisation (s): when spent, the best Σ found
    /// so far is taken, with a warning (the robot stands meanwhile).
    pub optimise_budget_s: f64,
    /// A scan is placed with the odometry pose at its stamp, interpolated; one with no
    /// odometry pose within this (s) of its stamp is refused.
    pub scan_odom_max_gap_s: f64,
    /// The scan's frame when its header has none.
    pub laser_frame: String,
    /// The laser's pose in the base frame (x, y, yaw) for a frame `tf_static` does not give;
    /// empty: such scans are refused.
    pub laser_pose: Vec<f64>,
}

impl Default for VfoSettings {
    fn default() -> Self {
        VfoSettings {
            gains: VfoGains::default(),
            optimise: OptimiseConfig::default(),
            scan: ScanObstacleConfig::default(),
            guiding: DEFAULT_GUIDING,
            scan_range: 4.0,
            scan_timeout_s: 0.5,
            scan_odom_max_gap_s: DEFAULT_SCAN_ODOM_MAX_GAP_S,
            optimise_budget_s: DEFAULT_OPTIMISE_BUDGET_S,
            laser_frame: "laser".to_owned(),
            laser_pose: vec![0.0; 3],
        }
    }
}

/// The default `vfo.scan_odom_max_gap_s` (s): five periods of 50 Hz odometry. Between two
/// odometry poses a scan's pose is interpolated; beyond the last one it is held for at most
/// this, where a robot turning at 1.5 rad/s turns 0.15 rad (0.45 m at 3 m) — the worst
/// misplacement accepted.
pub const DEFAULT_SCAN_ODOM_MAX_GAP_S: f64 = 0.1;

/// The largest `vfo.optimise_budget_s` (s).
pub const MAX_OPTIMISE_BUDGET_S: f64 = 30.0;

/// The default `vfo.optimise_budget_s` (s): twice the second Algorithm 2 takes at 30 obstacles
/// (the bench), so on a loaded machine an optimisation still finishes, while a robot standing
/// for it never stands longer than this.
pub const DEFAULT_OPTIMISE_BUDGET_S: f64 = 2.0;

impl VfoSettings {
    /// The optimisation's wall-clock budget.
    pub fn optimise_budget(&self) -> Duration {
        mobil_ros::time::seconds(self.optimise_budget_s, MAX_OPTIMISE_BUDGET_S)
    }

    /// The laser's pose from `laser_pose` (`None` when empty or malformed).
    pub fn laser_pose(&self) -> Option<Pose2> {
        match self.laser_pose.as_slice() {
            [x, y, yaw] if x.is_finite() && y.is_finite() && yaw.is_finite() => Some(Pose2::new(*x, *y, *yaw)),
            _ => None,
        }
    }

    /// The scan timeout.
    pub fn scan_timeout(&self) -> Duration {
        mobil_ros::time::seconds(self.scan_timeout_s, crate::MAX_INPUT_TIMEOUT_S)
    }

    /// The obstacle extraction with the robot's radius.
    pub fn scan_config(&self, robot_radius: f64) -> ScanObstacleConfig {
        ScanObstacleConfig {
            robot_radius,
            ..self.scan
        }
    }
}

/// Declares `waypoint_method` and the `vfo.*` parameters.
pub fn declare_vfo(d: &mut Decl<PlannerConfig>) {
    let g = VfoGains::default();
    let o = OptimiseConfig::default();
    let w = QualityWeights::default();
    let s = ScanObstacleConfig::default();
    let v = VfoSettings::default();
    d.parsed::<WaypointMethod>(
        "waypoint_method",
        "approach",
        "how waypoints and follow_waypoints are followed: approach (the goal approach after the route \
         pre-check) or vfo (VFO round the obstacles the LIDAR sees, left/right decisions optimised by \
         virtual robots); applies from the next goal",
        |c, m| c.waypoint_method = m,
    )
    .choices(&["approach", "vfo"]);
    d.double(
        "vfo.k_p",
        g.k_p,
        "k_p, the position gain of h* (eq. 10) [1/s]",
        |c, x| c.vfo.gains.k_p = x,
    )
    .above(0.0);
    d.double("vfo.k_a", g.k_a, "k_a, the orienting gain (eq. 13) [1/s]", |c, x| {
        c.vfo.gains.k_a = x
    })
    .above(0.0);
    d.double(
        "vfo.speed",
        g.speed,
        "U_2, the speed profile (eq. 13), held to v_max [m/s]",
        |c, x| c.vfo.gains.speed = x,
    )
    .above(0.0);
    d.double(
        "vfo.omega_max",
        g.omega_max,
        "|ω| limit of the law, held to the chassis' omega_max (and on a steered chassis to speed / R_min) [rad/s]",
        |c, x| c.vfo.gains.omega_max = x,
    )
    .above(0.0);
    d.double(
        "vfo.switch_epsilon",
        g.switch_epsilon,
        "ϵ_i: an intermediate waypoint is passed within this (Algorithm 1) [m]",
        |c, x| c.vfo.gains.switch_epsilon = x,
    )
    .above(0.0);
    d.double(
        "vfo.final_epsilon",
        g.final_epsilon,
        "ϵ: the route ends when ‖q_N − q‖ (heading included) is below this",
        |c, x| c.vfo.gains.final_epsilon = x,
    )
    .above(0.0);
    d.double(
        "vfo.guiding",
        v.guiding,
        "μ, the guiding coefficient of every waypoint (eq. 11), in (0, 1)",
        |c, x| c.vfo.guiding = x,
    )
    .above(0.0)
    .max(0.999);
    d.double(
        "vfo.k_d",
        w.length,
        "K_D, the weight of path length in Ψ_z (eq. 22)",
        |c, x| c.vfo.optimise.weights.length = x,
    )
    .min(0.0);
    d.double(
        "vfo.k_b",
        w.danger,
        "K_B, the weight of danger in Ψ_z (eq. 22)",
        |c, x| c.vfo.optimise.weights.danger = x,
    )
    .min(0.0);
    d.double(
        "vfo.k_e",
        w.control,
        "K_E, the weight of control cost in Ψ_z (eq. 22)",
        |c, x| c.vfo.optimise.weights.control = x,
    )
    .min(0.0);
    d.double(
        "vfo.k_s",
        w.smoothness,
        "K_S, the weight of smoothness in Ψ_z (eq. 22)",
        |c, x| c.vfo.optimise.weights.smoothness = x,
    )
    .min(0.0);
    d.double(
        "vfo.time_step",
        o.time_step,
        "T_p, the virtual robots' integration step; set it to the odometry period the node steps on [s]",
        |c, x| c.vfo.optimise.time_step = x,
    )
    .above(0.0)
    .max(0.1);
    d.integer(
        "vfo.max_virtual_robots",
        o.max_virtual_robots as i64,
        "most virtual robots per optimisation (then the best so far, with a warning)",
        |c, x| c.vfo.optimise.max_virtual_robots = usize::try_from(x).unwrap_or(0),
    )
    .min(1.0);
    d.double(
        "vfo.max_path_time_s",
        o.max_path_time_s,
        "a virtual robot's path longer than this in simulated time is dropped [s]",
        |c, x| c.vfo.optimise.max_path_time_s = x,
    )
    .above(0.0);
    d.double(
        "vfo.max_total_time_s",
        o.max_total_time_s,
        "most simulated time over all virtual robots of one optimisation [s]",
        |c, x| c.vfo.optimise.max_total_time_s = x,
    )
    .above(0.0);
    d.integer(
        "vfo.threads",
        o.threads as i64,
        "threads for a batch of virtual robots (0: every core)",
        |c, x| c.vfo.optimise.threads = usize::try_from(x).unwrap_or(0),
    )
    .min(0.0);
    d.double(
        "vfo.influence_margin",
        s.influence_margin,
        "R − r of every obstacle seen [m]",
        |c, x| c.vfo.scan.influence_margin = x,
    )
    .above(0.0);
    d.double(
        "vfo.cluster_gap",
        s.cluster_gap,
        "largest gap between the echoes of one obstacle (plus two beam spacings) [m]",
        |c, x| c.vfo.scan.cluster_gap = x,
    )
    .above(0.0);
    d.integer(
        "vfo.min_points",
        s.min_points as i64,
        "fewest echoes of one obstacle",
        |c, x| c.vfo.scan.min_points = usize::try_from(x).unwrap_or(0),
    )
    .min(3.0);
    d.double(
        "vfo.max_radius",
        s.max_radius,
        "largest circle fitted to one cluster; larger shapes become chains of circles [m]",
        |c, x| c.vfo.scan.max_radius = x,
    )
    .above(0.0);
    d.double(
        "vfo.association_distance",
        s.association_distance,
        "circles whose centres lie nearer than this are one obstacle [m]",
        |c, x| c.vfo.scan.association_distance = x,
    )
    .above(0.0);
    d.integer(
        "vfo.memory",
        s.memory as i64,
        "detections an obstacle's running mean remembers",
        |c, x| c.vfo.scan.memory = usize::try_from(x).unwrap_or(0),
    )
    .min(1.0);
    d.double(
        "vfo.optimise_budget_s",
        v.optimise_budget_s,
        "wall-clock budget of one optimisation: then the best Σ so far, with a warning (the robot stands meanwhile) [s]",
        |c, x| c.vfo.optimise_budget_s = x,
    )
    .above(0.0)
    .max(MAX_OPTIMISE_BUDGET_S);
    d.double(
        "vfo.decay_s",
        s.decay_s,
        "an obstacle not seen again for this long is forgotten [s]",
        |c, x| c.vfo.scan.decay_s = x,
    )
    .above(0.0);
    d.integer(
        "vfo.max_obstacles",
        s.max_obstacles as i64,
        "most obstacles in the map; beyond, the least recently seen are dropped (with a warning)",
        |c, x| c.vfo.scan.max_obstacles = usize::try_from(x).unwrap_or(0),
    )
    .min(1.0);
    d.double(
        "vfo.scan_odom_max_gap_s",
        v.scan_odom_max_gap_s,
        "a scan is placed with the odometry pose at its stamp; refused when no odometry lies within this of it [s]",
        |c, x| c.vfo.scan_odom_max_gap_s = x,
    )
    .above(0.0)
    .max(1.0);
    d.double(
        "vfo.scan_range",
        v.scan_range,
        "echoes farther than this are not turned into obstacles [m]",
        |c, x| c.vfo.scan_range = x,
    )
    .above(0.0);
    d.double(
        "vfo.scan_timeout_s",
        v.scan_timeout_s,
        "a vfo goal fails STALE_INPUT when no valid scan arrived for this long (steady clock) [s]",
        |c, x| c.vfo.scan_timeout_s = x,
    )
    .above(0.0)
    .max(crate::MAX_INPUT_TIMEOUT_S);
    d.string(
        "vfo.laser_frame",
        &v.laser_frame,
        "the scan's frame when its header has none; its pose comes from tf_static",
        |c, x| c.vfo.laser_frame = x,
    )
    .read_only();
    d.double_list(
        "vfo.laser_pose",
        &v.laser_pose,
        "x, y, yaw of the laser in base_link for a scan frame tf_static does not give; [] = none",
        |c, x| c.vfo.laser_pose = x,
    );
}

/// The law's gains held to the chassis: U_2 ≤ v_max; |ω| ≤ the chassis' ω_max; on a steered
/// chassis (no turn in place) also |ω| ≤ U_2 / R_min, so a virtual robot at cruise speed turns
/// no tighter than the real one can. The law is a unicycle's: on a steered chassis the commands
/// are further held to the minimum radius at low speed ([`crate::clamp_twist`]), where the real
/// robot then turns wider than the virtual robots did.
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

/// Whether a quaternion carries an orientation: not all-zero (never set) and not within 1e-6 of
/// ±identity.
pub(crate) fn oriented(q: &mobil_msgs::geometry_msgs::msg::Quaternion) -> bool {
    let unset = q.x == 0.0 && q.y == 0.0 && q.z == 0.0 && q.w == 0.0;
    let identity = q.x.abs() < 1e-6 && q.y.abs() < 1e-6 && q.z.abs() < 1e-6 && (q.w.abs() - 1.0).abs() < 1e-6;
    !(unset || identity)
}

/// The route as VFO waypoints from `start`, μ = `guiding` for every one. θ_r, by one rule for
/// the whole route (a ROS pose's orientation defaults to the identity, so a single identity
/// cannot tell "heading 0" from "no heading"):
/// - a route in which some pose carries an orientation other than the identity is an
///   **oriented route**: every waypoint's θ_r is its pose's yaw, the identity's 0 rad included
///   (only an all-zero quaternion, never set, counts as none there);
/// - in any other route (every orientation the identity or unset) no waypoint carries one.
///
/// A waypoint without a heading takes the direction from the waypoint before (the start for
/// the first): the robot arrives moving along its leg; one on the point before keeps the
/// heading before it.
pub fn vfo_waypoints(route: &Route, start: &Pose2, guiding: f64) -> Result<Vec<VfoWaypoint>, GoalError> {
    let oriented_route = route.first_oriented().is_some();
    let mut previous = start.position();
    let mut heading = start.yaw;
    let mut out = Vec::with_capacity(route.points.len());
    for (k, p) in route.points.iter().enumerate() {
        let pose = route.request_index.get(k).and_then(|&i| route.poses.get(i));
        let leg = p - previous;
        let q = pose.map(|s| &s.pose.orientation);
        let given = q.filter(|q| oriented_route && !(q.x == 0.0 && q.y == 0.0 && q.z == 0.0 && q.w == 0.0));
        heading = match given {
            Some(q) => mobil_ros::geometry::yaw_of(q),
            None if leg.norm() > 1e-9 => leg.y.atan2(leg.x),
            None => heading,
        };
        let w = VfoWaypoint::new(p.x, p.y, heading, guiding).map_err(|_| GoalError::NotFinite {
            what: format!("waypoint {}", route.request_index.get(k).copied().unwrap_or(k)),
        })?;
        out.push(w);
        previous = *p;
    }
    Ok(out)
}

/// The follower between ticks: at home, ready for the next tick, or lent out to the blocking
/// pool for one. See the module docs for why the robot stops while it is out.
#[derive(Debug)]
pub struct VfoSlot {
    home: Option<Box<VfoFollower>>,
    lent: Option<Instant>,
    max_delay: Duration,
}

/// The mean period of a stream's arrivals (steady clock): an exponential mean giving each new
/// interval a weight of 0.1; an interval over [`ArrivalPeriod::PAUSE`] (the stream paused)
/// is not counted.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ArrivalPeriod {
    last: Option<Instant>,
    mean: Option<f64>,
}

impl ArrivalPeriod {
    /// Intervals longer than this are a pause, not the period.
    pub const PAUSE: Duration = Duration::from_secs(1);

    /// One arrival at `at`.
    pub fn arrived(&mut self, at: Instant) {
        if let Some(last) = self.last {
            let gap = at.saturating_duration_since(last);
            if gap <= Self::PAUSE && !gap.is_zero() {
                let gap = gap.as_secs_f64();
                self.mean = Some(self.mean.map_or(gap, |m| m + 0.1 * (gap - m)));
            }
        }
        self.last = Some(at);
    }

    /// The mean period, once two arrivals were seen.
    pub fn period(&self) -> Option<Duration> {
        self.mean.map(Duration::from_secs_f64)
    }
}

/// The longest delay of a VFO tick's command after its pose: two odometry periods (by then a
/// newer pose has come, and the command was worked out for a place the robot has left), at
/// least [`MIN_MAX_DELAY`] (a scheduler's jitter); the control step `time_step` (s) until a
/// period was measured. Under a simulated clock the period is the wall-clock one, as the delay.
pub fn vfo_max_delay(period: Option<Duration>, time_step: f64) -> Duration {
    period
        .map_or_else(|| Duration::from_secs_f64(time_step.max(0.0)), |p| 2 * p)
        .max(MIN_MAX_DELAY)
}

/// The shortest [`vfo_max_delay`].
pub const MIN_MAX_DELAY: Duration = Duration::from_millis(10);

/// What to do with a tick's output that came back.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Handback {
    /// Send the command: it came back within `max_delay` of its pose.
    Fresh,
    /// Send zero instead: it is older than `max_delay` (an optimisation ran).
    Late,
}

impl VfoSlot {
    /// A slot holding `follower`; a command older than `max_delay` is [`Handback::Late`].
    pub fn new(follower: VfoFollower, max_delay: Duration) -> Self {
        VfoSlot {
            home: Some(Box::new(follower)),
            lent: None,
            max_delay,
        }
    }

    /// The follower for a tick at `now`, or `None` while it is out on a tick (the caller then
    /// commands zero).
    pub fn lend(&mut self, now: Instant) -> Option<Box<VfoFollower>> {
        let f = self.home.take()?;
        self.lent = Some(now);
        Some(f)
    }

    /// The follower back from the tick lent at [`VfoSlot::lend`], at `now`.
    pub fn give_back(&mut self, follower: Box<VfoFollower>, now: Instant) -> Handback {
        let since = self.lent.take().unwrap_or(now);
        self.home = Some(follower);
        if now.saturating_duration_since(since) > self.max_delay {
            Handback::Late
        } else {
            Handback::Fresh
        }
    }

    /// Whether the follower is out on a tick.
    pub fn is_lent(&self) -> bool {
        self.home.is_none()
    }

    /// The follower when at home.
    pub fn follower(&self) -> Option<&VfoFollower> {
        self.home.as_deref()
    }

    /// The longest delay of a command that is still sent.
    pub fn max_delay(&self) -> Duration {
        self.max_delay
    }
}

/// The command of a tick's output: u = [ω, v] as a body twist (v along the heading, no sideways
/// speed); zero once the route ended or when [`Handback::Late`].
pub fn vfo_command(output: &VfoOutput, handback: Handback) -> BodyTwist {
    if output.end.is_some() || handback == Handback::Late {
        BodyTwist::new(0.0, 0.0, 0.0)
    } else {
        BodyTwist::new(output.v, 0.0, output.omega)
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

/// The report of an optimisation.
pub fn segment_report(o: &Optimisation) -> SegmentReport {
    let best = o.best.and_then(|b| o.paths.get(b));
    SegmentReport {
        psi_z: o.score().unwrap_or(f64::NAN),
        indices: best.map_or([f64::NAN; 4], |p| PathIndices::as_array(&p.indices)),
        virtual_robots: o.robots.len(),
        candidates: o.candidates(),
    }
}

/// Most virtual robots drawn (the first ones simulated; the count is in the status).
pub const MAX_DRAWN_ROBOTS: usize = 40;
/// Most points over all virtual robots drawn, and of the chosen path, in a [`VfoDrawing`] (the
/// demo's SVG); the markers draw fewer, within [`crate::MAX_MARKER_POINTS`] shared with the
/// route.
pub const MAX_DRAWN_POINTS: usize = 1600;
/// Most obstacles drawn (the nearest to the robot first), two markers each.
pub const MAX_DRAWN_OBSTACLES: usize = 25;

/// One virtual robot's path as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnRobot {
    /// Its points (odom), downsampled.
    pub points: Vec<Point2<f64>>,
    /// It ended in a collision or on the time cap (its path was dropped there).
    pub dropped: bool,
}

/// What the markers and the demo draw of the last optimisation: every virtual robot's path,
/// the chosen path, the obstacles with r and R.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VfoDrawing {
    /// The virtual robots (at most [`MAX_DRAWN_ROBOTS`], [`MAX_DRAWN_POINTS`] points in all).
    pub robots: Vec<DrawnRobot>,
    /// The chosen path (at most [`MAX_DRAWN_POINTS`] points).
    pub chosen: Vec<Point2<f64>>,
    /// The obstacles known to the follower.
    pub obstacles: Vec<Obstacle>,
}

/// The drawing of optimisation `o` over `obstacles`.
pub fn vfo_drawing(o: &Optimisation, obstacles: &[Obstacle]) -> VfoDrawing {
    let robots: Vec<_> = o.robots.iter().take(MAX_DRAWN_ROBOTS).collect();
    let per_robot = (MAX_DRAWN_POINTS / robots.len().max(1)).max(2);
    VfoDrawing {
        robots: robots
            .iter()
            .map(|r| DrawnRobot {
                points: crate::downsample(&r.path, per_robot),
                dropped: matches!(r.end, RobotEnd::Collided { .. } | RobotEnd::TimeCap),
            })
            .collect(),
        chosen: crate::downsample(&o.best_path(), MAX_DRAWN_POINTS),
        obstacles: obstacles.to_vec(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{markers, route_from_poses, status_message, MarkerView, Mode, Outcome, StatusView, MISSED_BY_THE_RUN};
    use approx::assert_relative_eq;
    use mobil_chassis::model::ChassisConfig;
    use mobil_msgs::builtin_interfaces::msg::Time;
    use mobil_msgs::geometry_msgs::msg::PoseStamped;
    use mobil_msgs::mobil_msgs::msg::NavStatus;
    use mobil_msgs::nav2_msgs::action::FollowWaypointsResult;
    use mobil_msgs::visualization_msgs::msg::Marker;
    use mobil_planner::vfo::{find_sigmas, Segment, VfoController, VfoEnd};
    use mobil_ros::config::{load, Decl};
    use mobil_ros::geometry::yaw_quaternion;
    use mobil_ros::params::ParamValues;
    use mobil_ros::OffLoop;
    use ros2_client::ParameterValue;
    use std::f64::consts::PI;

    fn pose(x: f64, y: f64, yaw: Option<f64>) -> PoseStamped {
        let mut p = PoseStamped::default();
        p.header.frame_id = "odom".into();
        p.pose.position.x = x;
        p.pose.position.y = y;
        p.pose.orientation = yaw.map_or_else(|| yaw_quaternion(0.0), yaw_quaternion);
        p
    }

    #[test]
    fn waypoint_method_parses_its_two_names_only() {
        assert_eq!("vfo".parse::<WaypointMethod>(), Ok(WaypointMethod::Vfo));
        assert_eq!("approach".parse::<WaypointMethod>(), Ok(WaypointMethod::Approach));
        assert!("VFO".parse::<WaypointMethod>().is_err());
        assert_eq!(WaypointMethod::Vfo.as_str(), "vfo");
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
        // 4096 virtual robots, weights {K_D 1, K_B 2, K_E 1, K_S 1}.
        assert_eq!((c.vfo.gains.k_p, c.vfo.gains.k_a, c.vfo.gains.speed), (1.0, 5.0, 0.3));
        assert_eq!(
            (c.vfo.optimise.time_step, c.vfo.optimise.max_virtual_robots),
            (0.01, 4096)
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
    fn gains_are_held_to_the_chassis() {
        // OMR-III: v_max 0.5, ω_max 1.5; U_2 0.3 stays, |ω| ≤ 4 becomes 1.5.
        let g = vfo_gains(&VfoGains::default(), &ChassisParams::omr3());
        assert_eq!((g.speed, g.omega_max, g.k_a), (0.3, 1.5, 5.0));
        // A U_2 above v_max is held to it.
        let fast = VfoGains {
            speed: 0.8,
            ..VfoGains::default()
        };
        assert_eq!(vfo_gains(&fast, &ChassisParams::omr3()).speed, 0.5);
        // MOBIL-II turns no tighter than R_min = 0.73 m: |ω| ≤ 0.3 / 0.73 = 0.411 rad/s.
        let mobil2 = ChassisParams::new(ChassisConfig::mobil2()).expect("valid");
        assert_relative_eq!(mobil2.min_turning_radius(), 0.73, epsilon = 0.005);
        let g = vfo_gains(&VfoGains::default(), &mobil2);
        assert_relative_eq!(g.omega_max, 0.3 / mobil2.min_turning_radius(), epsilon = 1e-12);
        assert_relative_eq!(g.omega_max, 0.411, epsilon = 0.003);
    }

    #[test]
    fn waypoint_headings_follow_the_legs_unless_the_route_carries_orientations() {
        // No orientation in the route (all identity): from (0, 0) facing 0.3 rad, (1, 0) along
        // +x (0); (1, 0) again keeps 0; (1, 2) along +y (π/2); (0, 2) along −x (π).
        let plain = vec![
            pose(1.0, 0.0, None),
            pose(1.0, 0.0, None),
            pose(1.0, 2.0, None),
            pose(0.0, 2.0, None),
        ];
        let route = route_from_poses(&plain, "odom", "odom", 0, 0, None, 0.01).expect("valid");
        let w = vfo_waypoints(&route, &Pose2::new(0.0, 0.0, 0.3), 0.4).expect("valid");
        let headings: Vec<f64> = w.iter().map(|w| w.heading).collect();
        assert_relative_eq!(headings[0], 0.0, epsilon = 1e-12);
        assert_relative_eq!(headings[1], 0.0, epsilon = 1e-12);
        assert_relative_eq!(headings[2], PI / 2.0, epsilon = 1e-12);
        assert_relative_eq!(headings[3], PI, epsilon = 1e-12);
        assert!(w.iter().all(|w| w.guiding == 0.4));
        assert_eq!(w[2].position, Point2::new(1.0, 2.0));
        // An oriented route: (1, 2) carries 0.5 rad, so the identity of (0, 2) is a real
        // heading of 0 rad (not the leg's π), and an unset (all-zero) one is none: the leg's.
        let mut unset = pose(0.0, 3.0, None);
        unset.pose.orientation.w = 0.0;
        let oriented = vec![
            pose(1.0, 0.0, None),
            pose(1.0, 2.0, Some(0.5)),
            pose(0.0, 2.0, None),
            unset,
        ];
        let route = route_from_poses(&oriented, "odom", "odom", 0, 0, None, 0.01).expect("valid");
        let w = vfo_waypoints(&route, &Pose2::new(0.0, 0.0, 0.3), 0.4).expect("valid");
        let headings: Vec<f64> = w.iter().map(|w| w.heading).collect();
        assert_relative_eq!(headings[0], 0.0, epsilon = 1e-12);
        assert_relative_eq!(headings[1], 0.5, epsilon = 1e-9);
        assert_relative_eq!(headings[2], 0.0, epsilon = 1e-12);
        assert_relative_eq!(headings[3], PI / 2.0, epsilon = 1e-12);
        // A waypoint on the start keeps the start's heading.
        let route = route_from_poses(
            &[pose(0.0, 0.0, None), pose(1.0, 1.0, None)],
            "odom",
            "odom",
            0,
            0,
            None,
            0.01,
        )
        .expect("valid");
        let w = vfo_waypoints(&route, &Pose2::new(0.0, 0.0, 0.3), 0.5).expect("valid");
        assert_relative_eq!(w[0].heading, 0.3, epsilon = 1e-12);
        assert_relative_eq!(w[1].heading, PI / 4.0, epsilon = 1e-12);
    }

    fn follower(obstacles: Vec<Obstacle>) -> VfoFollower {
        let w = VfoWaypoint::new(4.0, 0.0, 0.0, 0.5).expect("valid");
        VfoFollower::new(VfoGains::default(), OptimiseConfig::default(), vec![w], obstacles).expect("valid")
    }

    #[test]
    fn the_slot_lends_once_and_a_late_command_becomes_zero() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let mut slot = VfoSlot::new(follower(Vec::new()), ms(20));
        let f = slot.lend(t0).expect("at home");
        assert!(slot.is_lent());
        // Out on a tick: the next tick gets nothing (the node commands zero).
        assert!(slot.lend(t0 + ms(10)).is_none());
        assert!(slot.follower().is_none());
        assert_eq!(slot.give_back(f, t0 + ms(20)), Handback::Fresh);
        let f = slot.lend(t0 + ms(30)).expect("home again");
        assert_eq!(slot.give_back(f, t0 + ms(51)), Handback::Late);
        assert!(!slot.is_lent());

        let output = VfoOutput {
            omega: 0.7,
            v: 0.25,
            index: 0,
            distance: 1.0,
            step: None,
            events: Vec::new(),
            end: None,
        };
        let c = vfo_command(&output, Handback::Fresh);
        assert_eq!((c.vx, c.vy, c.wz), (0.25, 0.0, 0.7));
        let c = vfo_command(&output, Handback::Late);
        assert_eq!((c.vx, c.vy, c.wz), (0.0, 0.0, 0.0));
        let ended = VfoOutput {
            end: Some(VfoEnd::NoSafePath { index: 0 }),
            ..output
        };
        let c = vfo_command(&ended, Handback::Fresh);
        assert_eq!((c.vx, c.vy, c.wz), (0.0, 0.0, 0.0));
    }

    /// The hand-over through the kit's OffLoop on a single-threaded runtime: the follower goes to
    /// the blocking pool, the loop meanwhile finds it out (zero command), and it comes back with
    /// the tick's output, which optimised the segment (one obstacle on the way: two ways round,
    /// three virtual robots — the first to the zone's edge, then one each way).
    #[tokio::test(flavor = "current_thread")]
    async fn a_tick_runs_off_the_loop_and_the_follower_comes_back() {
        let obstacle = Obstacle::new(Point2::new(2.0, 0.0), 0.5, 1.0).expect("valid");
        let mut slot = VfoSlot::new(follower(vec![obstacle]), Duration::from_secs(5));
        let mut jobs: OffLoop<(Box<VfoFollower>, VfoOutput)> = OffLoop::new();
        let mut f = slot.lend(Instant::now()).expect("at home");
        jobs.start(move |_| {
            let o = f.update(&Pose2::identity(), 0.0).expect("valid pose");
            (f, o)
        });
        assert!(slot.lend(Instant::now()).is_none());
        let (f, o) = jobs.result().await;
        assert_eq!(slot.give_back(f, Instant::now()), Handback::Fresh);
        assert!(o
            .events
            .iter()
            .any(|e| matches!(e, mobil_planner::vfo::VfoEvent::Optimised { .. })));
        let follower = slot.follower().expect("home");
        let report = segment_report(follower.last_optimisation().expect("optimised"));
        assert_eq!((report.virtual_robots, report.candidates), (3, 2));
        assert!(report.psi_z.is_finite());
        assert!(report.indices.iter().all(|x| x.is_finite()));
        // At the start d = 2 > R = 1: no avoidance yet, H* = k_p·e* + v* = (4, 0) − 0.5·4·(1, 0)
        // = (2, 0) points at the waypoint straight ahead, e_a = 0: ω = 0 and, the waypoint
        // being the last, v = min(U_2, ‖H*‖)·cos 0 = 0.3.
        assert_relative_eq!(o.omega, 0.0, epsilon = 1e-12);
        assert_relative_eq!(o.v, 0.3, epsilon = 1e-12);
    }

    #[test]
    fn the_report_and_the_drawing_of_an_optimisation() {
        let obstacles = [Obstacle::new(Point2::new(2.0, 0.0), 0.5, 1.0).expect("valid")];
        let segment = Segment {
            waypoint: VfoWaypoint::new(4.0, 0.0, 0.0, 0.5).expect("valid"),
            last: true,
            obstacles: &obstacles,
        };
        let controller = VfoController::new(VfoGains::default()).expect("valid");
        let o = find_sigmas(&Pose2::identity(), &controller, &segment, &OptimiseConfig::default()).expect("valid");
        let d = vfo_drawing(&o, &obstacles);
        assert_eq!(d.robots.len(), 3);
        assert!(d.robots.iter().all(|r| !r.dropped && r.points.len() >= 2));
        // The chosen path runs from the start to within ϵ of the waypoint.
        let (first, last) = (d.chosen[0], d.chosen[d.chosen.len() - 1]);
        assert!((first - Point2::origin()).norm() < 1e-9);
        assert!((last - Point2::new(4.0, 0.0)).norm() < 0.1);
        // It passes the obstacle outside r = 0.5.
        assert!(d.chosen.iter().all(|p| (p - Point2::new(2.0, 0.0)).norm() > 0.5));
        let r = SegmentReport::default();
        assert!(r.psi_z.is_nan() && r.virtual_robots == 0);
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
    fn status_carries_the_segment_s_psi_z_and_indices() {
        let view = StatusView {
            state: NavStatus::ACTIVE,
            mode: Mode::Vfo,
            goal: None,
            distance_to_goal: 1.0,
            reason: String::new(),
            waypoint_index: 2,
            docking: None,
            vfo: Some(SegmentReport {
                psi_z: 3.25,
                indices: [4.5, 0.75, 1.5, 0.5],
                virtual_robots: 9,
                candidates: 5,
            }),
        };
        let m = status_message(&view, Time::default(), "odom");
        assert_eq!(m.mode, "vfo");
        assert_eq!(
            (m.psi_z, m.chi_length, m.chi_danger, m.chi_control, m.chi_smoothness),
            (3.25, 4.5, 0.75, 1.5, 0.5)
        );
        assert_eq!((m.virtual_robots, m.candidates, m.waypoint_index), (9, 5, 2));
        let m = status_message(&StatusView { vfo: None, ..view }, Time::default(), "odom");
        assert!(m.psi_z.is_nan() && m.chi_length.is_nan() && m.virtual_robots == 0);
    }

    #[test]
    fn an_early_end_lists_the_waypoints_not_reached() {
        let poses: Vec<PoseStamped> = (0..4).map(|i| pose(i as f64, 1.0, None)).collect();
        let outcome = Outcome::NoSafePath {
            index: 2,
            virtual_robots: 17,
            unreached: vec![2, 3],
        };
        let r = outcome.follow_result(&poses, &[]);
        assert_eq!(r.error_code, FollowWaypointsResult::TASK_EXECUTOR_FAILED);
        let listed: Vec<(u32, u16)> = r.missed_waypoints.iter().map(|m| (m.index, m.error_code)).collect();
        assert_eq!(listed, vec![(2, MISSED_BY_THE_RUN), (3, MISSED_BY_THE_RUN)]);
        assert_eq!(r.missed_waypoints[1].goal.pose.position.x, 3.0);
        assert!(r.error_msg.starts_with("NO_SAFE_PATH: "), "{}", r.error_msg);
        assert!(r.error_msg.contains("waypoint 2") && r.error_msg.contains("17 virtual robots"));
        let outcome = Outcome::Collision {
            centre: Point2::new(2.0, -1.0),
            radius: 0.6,
            distance: 0.55,
            unreached: vec![3],
        };
        assert_eq!(outcome.state(), NavStatus::FAILED);
        let r = outcome.follow_result(&poses, &[]);
        assert_eq!(r.missed_waypoints.len(), 1);
        assert!(r
            .error_msg
            .starts_with("COLLISION: the robot is 0.55 m from the centre of the obstacle at (2.00, -1.00)"));
        assert_eq!(Outcome::ScanStale.code(), "STALE_INPUT");
        // A starved optimisation is its own failure, never NO_SAFE_PATH.
        let outcome = Outcome::OptimisationBudget {
            index: 1,
            tries: 3,
            unreached: vec![1, 2, 3],
        };
        assert_eq!(outcome.state(), NavStatus::FAILED);
        let r = outcome.vfo_follow_result(&poses, &[0, 1, 2, 3]);
        assert_eq!(r.error_code, FollowWaypointsResult::TASK_EXECUTOR_FAILED);
        let listed: Vec<u32> = r.missed_waypoints.iter().map(|m| m.index).collect();
        assert_eq!(listed, vec![1, 2, 3]);
        assert!(
            r.error_msg
                .starts_with("OPTIMISATION_BUDGET: optimisation budget exhausted: 3 optimisations in a row"),
            "{}",
            r.error_msg
        );
        assert!(r.error_msg.contains("waypoint 1") && !r.error_msg.contains("NO_SAFE_PATH"));
        assert!(!r.error_msg.contains("  "), "one space between words: {}", r.error_msg);
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

    #[test]
    fn the_late_command_bound_is_two_measured_odometry_periods() {
        let t0 = Instant::now();
        let ms = Duration::from_millis;
        let mut p = ArrivalPeriod::default();
        assert_eq!(p.period(), None);
        // Before a period is measured: the control step (20 ms), floored at 10 ms.
        assert_eq!(vfo_max_delay(p.period(), 0.02), ms(20));
        assert_eq!(vfo_max_delay(p.period(), 0.001), MIN_MAX_DELAY);
        // Odometry every 20 ms: the mean is 20 ms, the bound 40 ms.
        for k in 0..10 {
            p.arrived(t0 + ms(20 * k));
        }
        let period = p.period().expect("measured");
        assert!((period.as_secs_f64() - 0.020).abs() < 1e-9, "{period:?}");
        assert_eq!(vfo_max_delay(p.period(), 0.5), 2 * period);
        // A 3 s pause is not a period; one 30 ms interval moves the mean by a tenth: 21 ms.
        p.arrived(t0 + ms(180 + 3000));
        assert!((p.period().expect("kept").as_secs_f64() - 0.020).abs() < 1e-9);
        p.arrived(t0 + ms(180 + 3000 + 30));
        assert!((p.period().expect("kept").as_secs_f64() - 0.021).abs() < 1e-9);
        // At 5× simulated time odometry comes every 4 ms of wall time: the floor, 10 ms.
        let mut fast = ArrivalPeriod::default();
        for k in 0..10 {
            fast.arrived(t0 + ms(4 * k));
        }
        assert_eq!(vfo_max_delay(fast.period(), 0.02), MIN_MAX_DELAY);
    }
}
