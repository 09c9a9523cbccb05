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
            laser_frame: "laser".to_owned(),
            laser_pose: vec![0.0; 3],
        }
    }
}

impl VfoSettings {
    /// The laser's pose from `laser_pose` (`None` when empty or malformed).
    pub fn laser_pose(&self) -> Option<Pose2> {
        match self.laser_pose.as_slice() {
            [x, y, yaw] if x.is_finite() && y.is_finite() && yaw.is_finite() => Some(Pose2::new(*x, *y, *yaw)),
            _ => None,
        }
    }

    /// The scan timeout.
    pub fn scan_timeout(&self) -> Duration {
        crate::seconds(self.scan_timeout_s, crate::MAX_INPUT_TIMEOUT_S)
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
        "T_p, the virtual robots' step: the node's control period, one odom period [s]",
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

/// The route as VFO waypoints from `start`: θ_r is the pose's heading when it carries an
/// orientation (an identity or unset quaternion counts as none), else the direction from the
/// waypoint before (the start for the first) — the robot arrives moving along its leg. A
/// waypoint on the point before keeps the heading before it. μ = `guiding` for every one.
pub fn vfo_waypoints(route: &Route, start: &Pose2, guiding: f64) -> Result<Vec<VfoWaypoint>, GoalError> {
    let mut previous = start.position();
    let mut heading = start.yaw;
    let mut out = Vec::with_capacity(route.points.len());
    for (k, p) in route.points.iter().enumerate() {
        let pose = route.request_index.get(k).and_then(|&i| route.poses.get(i));
        let leg = p - previous;
        heading = match pose.filter(|s| oriented(&s.pose.orientation)) {
            Some(s) => mobil_ros::geometry::yaw_of(&s.pose.orientation),
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
pub const MAX_DRAWN_ROBOTS: usize = 80;
/// Most points over all virtual robots drawn, and of the chosen path (each 24 bytes: 48 KB in
/// all, so the marker array stays below the 80 KB a message to rclpy should stay below).
pub const MAX_DRAWN_POINTS: usize = 1600;
/// Most obstacles drawn (the nearest to the robot first), two markers each.
pub const MAX_DRAWN_OBSTACLES: usize = 40;

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
