//! Obstacles from a laser scan: returns clustered into circles, merged over time in the odom
//! frame (SPEC §5: obstacles are detected online).
//!
//! - **Clusters**: consecutive valid echoes (REP-117: NaN, ±inf and out-of-limits beams break
//!   a cluster) whose points lie within `cluster_gap` + `range · increment · 2` of each other
//!   (the gap grows with range, where neighbouring beams lie further apart). A cluster of fewer
//!   than `min_points` echoes is noise and dropped.
//! - **Circle fit**: the algebraic (Kåsa) least-squares circle as a start, then Gauss–Newton
//!   iterations of the geometric fit, which minimise Σ(‖p − c‖ − ρ)². A LIDAR sees less than
//!   half of a circle, and there the algebraic fit alone is biased under noise (it shrinks
//!   the radius); the geometric fit is unbiased and exact on noise-free points. The fit is
//!   taken when it converges, its radius is at most `max_radius`, and its centre lies beyond
//!   the arc as seen from the sensor (an obstacle's echoes face the sensor). Otherwise — a
//!   wall, a corner, a shape that is no circle — the cluster is covered by a chain of circles:
//!   pieces at most 2·`max_radius` long, each the circle round its points' centroid through
//!   its farthest point. So every echo lies inside some obstacle.
//! - **Merging**: a circle whose centre lies within `association_distance` of a known
//!   obstacle's centre, or that overlaps it by more than half the smaller radius, is the same
//!   obstacle: centre and radius become the running mean over its detections (at most the
//!   last `memory` detections weigh in). Any other circle is a new obstacle, appended (indices
//!   never change but for the removals below) and reported, so the caller re-optimises.
//! - **Forgetting** (each scan, after the merge; the removed obstacles' ids reported):
//!   1. *seen through*: a known circle a scan did not detect, whose centre lies inside the
//!      scan's field of view and range, is seen through when the beam nearest its bearing and
//!      both its neighbours see free space beyond its far side (an echo farther than d + ρ, or
//!      none within range_max); seen through on [`SEEN_THROUGH_SCANS`] consecutive scans it is
//!      removed: the obstacle moved away, or was a phantom. Only a scan placed by a pose
//!      between two odometry poses ([`Placement::Interpolated`]) judges this: a held pose
//!      may be a turn's worth off (0.06 rad at 1.5 rad/s over 0.04 s puts a pillar 3.5 m away
//!      0.21 m aside), and the real pillar would look seen through. A held scan neither counts
//!      nor breaks the run;
//!   2. *decay*: a circle not detected for `decay_s` is removed (out of view, it may be gone);
//!   3. *cap*: beyond `max_obstacles` circles, the least recently detected (then the oldest)
//!      are dropped, and the update says how many.
//!
//!   4. *clock reset*: a scan stamped before the last detection of any circle (time went
//!      backwards: a simulation restarted) empties the map first, its ids in
//!      [`MapUpdate::cleared`]; the circles' ages would mean nothing.
//!
//!   Every obstacle keeps an id ([`ObstacleMap::ids`]) for its whole life, so a caller holding
//!   decisions by index can carry them over a removal.
//! - **Obstacle model**: r = r_p + `robot_radius`, R = r + `influence_margin`.

use mobil_geom::{Beam, Pose2, Scan};
use mobil_motion::Notice;
use nalgebra::{Matrix3, Point2, Vector3};

use super::history::{Placement, PoseHistory};
use super::obstacles::Obstacle;
use crate::error::{positive_finite, PlannerError};

/// How many consecutive scans (placed by interpolation) must see through a circle before it is
/// removed: one scan may be off (a pose error, a beam through a gap), two in a row (25 ms apart
/// on a 40 Hz scanner) agree on free space.
pub const SEEN_THROUGH_SCANS: u8 = 2;

/// Settings of the extraction and the merge; every default justified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanObstacleConfig {
    /// r_r (m), the robot's radius, added to each obstacle's (no default that fits every robot:
    /// MOBIL-II's footprint is 0.53 m; here 0.3).
    pub robot_radius: f64,
    /// R − r (m). Default 0.4: at 0.3 m/s the law has more than a second in the zone to turn.
    pub influence_margin: f64,
    /// Largest gap (m) between neighbouring echoes of one cluster, plus two beam spacings at
    /// their range. Default 0.1: less than the narrowest gap the robot could pass.
    pub cluster_gap: f64,
    /// Fewest echoes in a cluster. Default 3, the fewest that define a circle.
    pub min_points: usize,
    /// Largest fitted radius (m); a larger fit is covered by a chain of circles. Default 0.5.
    pub max_radius: f64,
    /// Centres nearer than this (m) are one obstacle. Default 0.2.
    pub association_distance: f64,
    /// Detections the running mean remembers. Default 20 (half a second of a 40 Hz scanner).
    pub memory: usize,
    /// A circle not detected for this long (s) is forgotten. Default 30: 9 m of driving at
    /// 0.3 m/s, long enough to keep what the 270° scanner loses behind the robot while it goes
    /// round it, short enough that a long run does not carry a map of everything it passed.
    pub decay_s: f64,
    /// Most circles kept; beyond, the least recently detected are dropped. Default 200: a
    /// room's clutter and walls at 1 m per circle, and about a second of Algorithm 2 even if
    /// every one lay on the segment.
    pub max_obstacles: usize,
}

impl Default for ScanObstacleConfig {
    fn default() -> Self {
        ScanObstacleConfig {
            robot_radius: 0.3,
            influence_margin: 0.4,
            cluster_gap: 0.1,
            min_points: 3,
            max_radius: 0.5,
            association_distance: 0.2,
            memory: 20,
            decay_s: 30.0,
            max_obstacles: 200,
        }
    }
}

impl ScanObstacleConfig {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlannerError> {
        positive_finite("robot_radius", self.robot_radius)?;
        positive_finite("influence_margin", self.influence_margin)?;
        positive_finite("cluster_gap", self.cluster_gap)?;
        positive_finite("max_radius", self.max_radius)?;
        positive_finite("association_distance", self.association_distance)?;
        positive_finite("decay_s", self.decay_s)?;
        if self.max_obstacles == 0 {
            return Err(PlannerError::InvalidConfig {
                name: "max_obstacles",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        if self.min_points < 3 || self.memory == 0 {
            return Err(PlannerError::InvalidConfig {
                name: "min_points/memory",
                value: self.min_points as f64,
                reason: "need at least 3 points per cluster and a memory of at least 1",
            });
        }
        Ok(())
    }
}

/// A circle (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    /// Its centre.
    pub centre: Point2<f64>,
    /// Its radius.
    pub radius: f64,
}

/// Circles from the echoes of `scan` (see the module docs), in the frame `frame_from_base`
/// maps the base frame to (the odom frame, with the robot's pose in it).
pub fn extract_circles(scan: &Scan, frame_from_base: &Pose2, config: &ScanObstacleConfig) -> Vec<Circle> {
    let frame_from_laser = *frame_from_base * scan.base_from_laser();
    let sensor = frame_from_laser.position();
    let spacing = 2.0 * scan_increment(scan);
    let mut circles = Vec::new();
    let mut cluster: Vec<Point2<f64>> = Vec::new();
    let mut previous: Option<(Point2<f64>, f64)> = None;
    for i in 0..scan.len() {
        let echo = scan
            .point_in_laser(i)
            .map(|p| (frame_from_laser.transform_point(p), p.coords.norm()));
        match (echo, previous) {
            (Some((p, range)), Some((q, _))) if (p - q).norm() <= config.cluster_gap + spacing * range => {
                cluster.push(p)
            }
            (Some((p, _)), _) => {
                flush(&mut cluster, sensor, config, &mut circles);
                cluster.push(p);
            }
            (None, _) => flush(&mut cluster, sensor, config, &mut circles),
        }
        previous = echo;
    }
    flush(&mut cluster, sensor, config, &mut circles);
    circles
}

fn scan_increment(scan: &Scan) -> f64 {
    if scan.len() > 1 {
        scan.angle(1) - scan.angle(0)
    } else {
        0.0
    }
}

fn flush(cluster: &mut Vec<Point2<f64>>, sensor: Point2<f64>, config: &ScanObstacleConfig, out: &mut Vec<Circle>) {
    if cluster.len() >= config.min_points {
        match fit_circle(cluster) {
            Some(c) if c.radius <= config.max_radius && faces(cluster, &c, sensor) => out.push(c),
            _ => cover(cluster, config.max_radius, out),
        }
    }
    cluster.clear();
}

/// Whether the arc faces the sensor: the centre lies further from the sensor than the points'
/// centroid.
fn faces(points: &[Point2<f64>], circle: &Circle, sensor: Point2<f64>) -> bool {
    let centroid = centroid(points);
    (circle.centre - sensor).norm() > (centroid - sensor).norm()
}

fn centroid(points: &[Point2<f64>]) -> Point2<f64> {
    let sum = points.iter().fold(nalgebra::Vector2::zeros(), |s, p| s + p.coords);
    Point2::from(sum / points.len().max(1) as f64)
}

/// Covers points by circles round the centroids of pieces at most 2·`max_radius` long.
fn cover(points: &[Point2<f64>], max_radius: f64, out: &mut Vec<Circle>) {
    let mut start = 0;
    while start < points.len() {
        let mut end = start + 1;
        while end < points.len() && (points[end] - points[start]).norm() <= 2.0 * max_radius {
            end += 1;
        }
        let piece = &points[start..end];
        let c = centroid(piece);
        let radius = piece.iter().map(|p| (p - c).norm()).fold(0.0, f64::max);
        out.push(Circle {
            centre: c,
            radius: radius.max(0.01),
        });
        start = end;
    }
}

/// The geometric least-squares circle through `points` (Kåsa start, Gauss–Newton); `None`
/// for fewer than three points, (nearly) collinear points or no convergence.
pub fn fit_circle(points: &[Point2<f64>]) -> Option<Circle> {
    if points.len() < 3 {
        return None;
    }
    // Work relative to the centroid, for conditioning.
    let c0 = centroid(points);
    // Kåsa: x² + y² + D·x + E·y + F = 0, linear least squares by the normal equations.
    let mut ata = Matrix3::zeros();
    let mut atb = Vector3::zeros();
    for p in points {
        let (x, y) = (p.x - c0.x, p.y - c0.y);
        let row = Vector3::new(x, y, 1.0);
        ata += row * row.transpose();
        atb += row * -(x * x + y * y);
    }
    let sol = ata.lu().solve(&atb)?;
    let (cx, cy) = (-sol.x / 2.0, -sol.y / 2.0);
    let rr = cx * cx + cy * cy - sol.z;
    if !(rr.is_finite() && rr > 0.0) {
        return None;
    }
    let (mut a, mut b, mut r) = (cx, cy, rr.sqrt());
    // Gauss–Newton on residuals ‖p − c‖ − ρ.
    for _ in 0..50 {
        let mut jtj = Matrix3::zeros();
        let mut jtr = Vector3::zeros();
        for p in points {
            let (dx, dy) = (p.x - c0.x - a, p.y - c0.y - b);
            let d = dx.hypot(dy);
            if d < 1e-12 {
                return None;
            }
            let j = Vector3::new(-dx / d, -dy / d, -1.0);
            let res = d - r;
            jtj += j * j.transpose();
            jtr += j * res;
        }
        let delta = jtj.lu().solve(&(-jtr))?;
        a += delta.x;
        b += delta.y;
        r += delta.z;
        if !(a.is_finite() && b.is_finite() && r.is_finite()) {
            return None;
        }
        if delta.norm() < 1e-12 * (1.0 + r.abs()) {
            break;
        }
    }
    (r > 0.0).then(|| Circle {
        centre: Point2::new(a + c0.x, b + c0.y),
        radius: r,
    })
}

/// One tracked obstacle: the running mean of its detections.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Tracked {
    circle: Circle,
    detections: usize,
    id: u64,
    /// When it was last detected (s).
    seen_at: f64,
    /// Consecutive interpolated scans that saw through it.
    through: u8,
}

/// What a scan changed.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MapUpdate {
    /// Indices (after the update) of the obstacles this scan added (the caller re-optimises
    /// when not empty).
    pub new: Vec<usize>,
    /// How many known obstacles it saw again.
    pub seen: usize,
    /// Ids of the obstacles the scan saw through (removed).
    pub seen_through: Vec<u64>,
    /// Ids of the obstacles forgotten for not being detected for `decay_s`.
    pub decayed: Vec<u64>,
    /// Ids of the obstacles dropped by the `max_obstacles` cap (the caller warns).
    pub capped: Vec<u64>,
    /// Ids of the obstacles dropped because the scan's time lay before their last detection
    /// (a clock reset: the caller warns).
    pub cleared: Vec<u64>,
}

impl MapUpdate {
    /// What the node warns of, each with its log key: obstacles forgotten because the scan at
    /// `stamp` (s) is older than their last detection (`map-reset`), and obstacles dropped by the
    /// map's cap of `max_obstacles` (`map-cap`).
    pub fn warnings(&self, stamp: f64, max_obstacles: usize) -> Vec<(&'static str, String)> {
        let mut w = Vec::new();
        if !self.cleared.is_empty() {
            let n = self.cleared.len();
            let text = format!(
                "scan at {stamp:.3} s is older than obstacles already seen (clock reset?): the {n} obstacles forgotten"
            );
            w.push(("map-reset", text));
        }
        if !self.capped.is_empty() {
            let n = self.capped.len();
            let text =
                format!("obstacle map full (vfo.max_obstacles {max_obstacles}): the {n} least recently seen dropped");
            w.push(("map-cap", text));
        }
        w
    }

    /// Whether any obstacle was removed (the indices after it changed).
    pub fn removed_any(&self) -> bool {
        !(self.seen_through.is_empty() && self.decayed.is_empty() && self.capped.is_empty() && self.cleared.is_empty())
    }
}

/// The obstacles seen so far, in the odom frame, merged over time (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ObstacleMap {
    config: ScanObstacleConfig,
    tracked: Vec<Tracked>,
    next_id: u64,
}

/// Whether a frame's pose moved from `before` to `now` by more than 1 mm or 1 mrad: a
/// localiser's correction that moves the obstacle map for a law working in the goal's frame
/// ([`ObstacleMap::moved`]); smaller ones (rounding, a steady transform re-sent) do not.
pub fn frame_moved(before: &Pose2, now: &Pose2) -> bool {
    let d = before.inverse().compose(now);
    d.x.hypot(d.y) > 1e-3 || d.yaw.abs() > 1e-3 || !d.is_finite()
}

/// Why a scan did not go into the map ([`ObstacleMap::add_scan`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScanSkipped {
    /// No odometry pose at the scan's stamp.
    #[error(
        "scan at {stamp:.3} s ignored: no fresh odometry within {max_gap} s of its stamp (obstacles are placed by \
         the pose at the scan's time)"
    )]
    NoPose {
        /// The scan's stamp (s).
        stamp: f64,
        /// The largest gap to a pose taken (s).
        max_gap: f64,
    },
    /// The map refused the scan or its pose.
    #[error("scan refused: {0}")]
    Refused(PlannerError),
}

impl ObstacleMap {
    /// An empty map.
    pub fn new(config: ScanObstacleConfig) -> Result<Self, PlannerError> {
        config.validate()?;
        Ok(ObstacleMap {
            config,
            tracked: Vec::new(),
            next_id: 0,
        })
    }

    /// The settings.
    pub fn config(&self) -> &ScanObstacleConfig {
        &self.config
    }

    /// Each obstacle's id, by index: an id names one obstacle for its whole life.
    pub fn ids(&self) -> Vec<u64> {
        self.tracked.iter().map(|t| t.id).collect()
    }

    /// The number of obstacles.
    pub fn len(&self) -> usize {
        self.tracked.len()
    }

    /// Whether the map is empty.
    pub fn is_empty(&self) -> bool {
        self.tracked.is_empty()
    }

    /// The map seen from another frame (`frame`: the map's frame's pose in it; a goal's frame
    /// that is not odometry's): every centre moved, the ids, radii and histories kept, so a law
    /// that follows the map by id ([`crate::vfo::VfoFollower::follow_map`]) follows this one.
    pub fn moved(&self, frame: &Pose2) -> ObstacleMap {
        let mut moved = self.clone();
        for t in &mut moved.tracked {
            t.circle.centre = frame.transform_point(t.circle.centre);
        }
        moved
    }

    /// The circles as detected (r_p, without the robot's radius), by index.
    pub fn circles(&self) -> Vec<Circle> {
        self.tracked.iter().map(|t| t.circle).collect()
    }

    /// The obstacles λ = {p, r_p + r_r, R} for the law, by index (the same as [`Self::circles`]).
    pub fn obstacles(&self) -> Vec<Obstacle> {
        self.tracked.iter().filter_map(|t| self.model(&t.circle)).collect()
    }

    fn model(&self, c: &Circle) -> Option<Obstacle> {
        let r = c.radius + self.config.robot_radius;
        Obstacle::new(c.centre, r, r + self.config.influence_margin).ok()
    }

    /// Adds the circles of a checked scan taken at `odom_from_base` at time `t` (s), the pose
    /// interpolated at the scan's time, then forgets what was seen through, what decayed and
    /// what exceeds the cap (module docs).
    pub fn update(&mut self, scan: &Scan, odom_from_base: &Pose2, t: f64) -> Result<MapUpdate, PlannerError> {
        self.update_placed(scan, odom_from_base, Placement::Interpolated, t)
    }

    /// Adds `scan`, taken at `stamp` (s, the odometry's clock), placed with the odometry pose
    /// `history` gives at that stamp ([`PoseHistory::placed_at`] within `max_gap`); `history`
    /// is `None` when the odometry is not fresh: obstacles are placed by the pose at the scan's
    /// time, or not at all.
    pub fn add_scan(
        &mut self,
        scan: &Scan,
        stamp: f64,
        history: Option<&PoseHistory>,
        max_gap: f64,
    ) -> Result<MapUpdate, ScanSkipped> {
        let (pose, placement) = history
            .and_then(|h| h.placed_at(stamp, max_gap))
            .ok_or(ScanSkipped::NoPose { stamp, max_gap })?;
        self.update_placed(scan, &pose, placement, stamp)
            .map_err(ScanSkipped::Refused)
    }

    /// As [`Self::update`], the pose found as `placement` says: a [`Placement::Held`] scan
    /// adds and confirms circles but judges none seen through.
    pub fn update_placed(
        &mut self,
        scan: &Scan,
        odom_from_base: &Pose2,
        placement: Placement,
        t: f64,
    ) -> Result<MapUpdate, PlannerError> {
        crate::docking::check_pose("odom_from_base", odom_from_base)?;
        if !t.is_finite() {
            return Err(PlannerError::InvalidConfig {
                name: "t",
                value: t,
                reason: "a scan's time must be finite",
            });
        }
        let cleared: Vec<u64> = if self.tracked.iter().any(|tr| tr.seen_at > t) {
            self.tracked.drain(..).map(|tr| tr.id).collect()
        } else {
            Vec::new()
        };
        let circles = extract_circles(scan, odom_from_base, &self.config);
        let mut update = self.merge_at(&circles, t);
        update.cleared = cleared;
        let frame_from_laser = *odom_from_base * scan.base_from_laser();
        let new_ids: Vec<u64> = update
            .new
            .iter()
            .filter_map(|&i| self.tracked.get(i))
            .map(|t| t.id)
            .collect();
        let config = self.config;
        let mut kept = Vec::with_capacity(self.tracked.len());
        for mut tr in self.tracked.drain(..) {
            if placement == Placement::Interpolated {
                let through = tr.seen_at < t && sees_through(scan, &frame_from_laser, &tr.circle);
                tr.through = if through { tr.through.saturating_add(1) } else { 0 };
            }
            if tr.through >= SEEN_THROUGH_SCANS {
                update.seen_through.push(tr.id);
            } else if t - tr.seen_at > config.decay_s {
                update.decayed.push(tr.id);
            } else {
                kept.push(tr);
            }
        }
        if kept.len() > config.max_obstacles {
            // Least recently detected first, then the oldest (smallest id).
            let mut order: Vec<usize> = (0..kept.len()).collect();
            order.sort_by(|&a, &b| {
                kept[a]
                    .seen_at
                    .total_cmp(&kept[b].seen_at)
                    .then(kept[a].id.cmp(&kept[b].id))
            });
            let drop: Vec<u64> = order[..kept.len() - config.max_obstacles]
                .iter()
                .map(|&i| kept[i].id)
                .collect();
            kept.retain(|tr| !drop.contains(&tr.id));
            update.capped = drop;
        }
        self.tracked = kept;
        update.new = self
            .tracked
            .iter()
            .enumerate()
            .filter(|(_, tr)| new_ids.contains(&tr.id))
            .map(|(i, _)| i)
            .collect();
        Ok(update)
    }

    /// Adds the circles of a scan given as plain LaserScan fields: `ranges` from `angle_min`
    /// every `angle_increment`, valid within [`range_min`, `range_max`], the laser at
    /// `odom_from_laser`, at time `t` (s; see [`Self::update`]). A malformed scan (empty, bad
    /// angles or limits, non-finite pose) is
    /// refused and changes nothing; NaN and ±inf ranges are no echoes (REP-117).
    #[allow(clippy::too_many_arguments)]
    pub fn update_from_ranges(
        &mut self,
        ranges: &[f32],
        angle_min: f64,
        angle_increment: f64,
        range_min: f64,
        range_max: f64,
        odom_from_laser: &Pose2,
        t: f64,
    ) -> Result<MapUpdate, PlannerError> {
        let angle_max = angle_min + ranges.len().saturating_sub(1) as f64 * angle_increment;
        let scan = Scan::new(
            angle_min,
            angle_max,
            angle_increment,
            range_min,
            range_max,
            ranges.to_vec(),
            Vec::new(),
            Pose2::identity(),
        )?;
        self.update(&scan, odom_from_laser, t)
    }

    /// Merges detected circles (odom frame) into the map, detected at time `now` (s); nothing is
    /// forgotten here.
    pub fn merge_at(&mut self, circles: &[Circle], now: f64) -> MapUpdate {
        let mut update = MapUpdate::default();
        // Only obstacles known before this scan: the circles of one scan are distinct (a
        // wall's chain overlaps by design).
        let known = self.tracked.len();
        for c in circles {
            let near = self.tracked[..known]
                .iter()
                .enumerate()
                .map(|(i, t)| (i, (t.circle.centre - c.centre).norm(), t.circle.radius))
                // Near centres, or an overlap r1 + r2 − d of more than half the smaller radius.
                .filter(|&(_, d, r)| d <= self.config.association_distance || r + c.radius - d > 0.5 * r.min(c.radius))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            match near {
                Some((i, _, _)) => {
                    let t = &mut self.tracked[i];
                    t.detections = (t.detections + 1).min(self.config.memory);
                    let w = 1.0 / t.detections as f64;
                    t.circle.centre += (c.centre - t.circle.centre) * w;
                    t.circle.radius += (c.radius - t.circle.radius) * w;
                    t.seen_at = t.seen_at.max(now);
                    t.through = 0;
                    update.seen += 1;
                }
                // A circle the law cannot take (beyond the coordinate limit) is not kept, so
                // `obstacles()` has an entry for every circle and the indices agree.
                None if self.model(c).is_none() => {}
                None => {
                    update.new.push(self.tracked.len());
                    self.tracked.push(Tracked {
                        circle: *c,
                        detections: 1,
                        id: self.next_id,
                        seen_at: now,
                        through: 0,
                    });
                    self.next_id += 1;
                }
            }
        }
        update
    }
}

/// Whether `scan` (its laser at `frame_from_laser`) sees free space through `circle`: its centre
/// lies inside the field of view and within (range_min, range_max), and the beam nearest its
/// bearing and both neighbours reach beyond d + ρ (an echo farther, or none within range_max).
fn sees_through(scan: &Scan, frame_from_laser: &Pose2, circle: &Circle) -> bool {
    let centre = frame_from_laser.inverse().transform_point(circle.centre);
    let d = centre.coords.norm();
    let (range_min, range_max) = scan.range_limits();
    if !(d > range_min && d < range_max) || scan.len() < 3 {
        return false;
    }
    let increment = scan_increment(scan);
    if increment <= 0.0 {
        return false;
    }
    // Relative to the first beam, in [0, 2π): a scanner sweeping 0…2π sees obstacles at
    // negative bearings too.
    let from_first = (centre.y.atan2(centre.x) - scan.angle(0)).rem_euclid(std::f64::consts::TAU);
    let k = (from_first / increment).round();
    if !(k >= 1.0 && k <= (scan.len() - 2) as f64) {
        return false;
    }
    let k = k as usize;
    let beyond = d + circle.radius;
    (k - 1..=k + 1).all(|i| match scan.beam(i) {
        Some(Beam::Hit(r)) => r > beyond,
        Some(Beam::NoEcho) => true,
        Some(Beam::OutOfLimits(r)) => r > range_max,
        _ => false,
    })
}

/// The obstacle map a node keeps between goals, and a change of its extraction parameters:
/// applied at once while no goal runs; while one runs, once it ends (the goal keeps the map
/// its parameters built, so its obstacles and σ stay valid).
#[derive(Debug, Clone, PartialEq)]
pub struct KeptMap {
    map: ObstacleMap,
    next: Option<ScanObstacleConfig>,
}

/// What a change of the extraction parameters did to a [`KeptMap`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MapChange {
    /// The parameters are the map's own (a change waiting, if any, is dropped), or those
    /// already waiting.
    Unchanged,
    /// The map starts afresh with them.
    Restarted,
    /// The map starts afresh with them once the running goal ends.
    AfterGoal,
}

impl MapChange {
    /// What the node tells of it: nothing when unchanged.
    pub fn notice(self) -> Option<Notice> {
        let when = match self {
            MapChange::Unchanged => return None,
            MapChange::Restarted => "",
            MapChange::AfterGoal => " once the goal ends",
        };
        Some(Notice::Info(format!(
            "vfo obstacle extraction changed: the obstacle map starts afresh{when}"
        )))
    }
}

impl KeptMap {
    /// An empty map with `config`.
    pub fn new(config: ScanObstacleConfig) -> Result<Self, PlannerError> {
        Ok(KeptMap {
            map: ObstacleMap::new(config)?,
            next: None,
        })
    }

    /// The map.
    pub fn map(&self) -> &ObstacleMap {
        &self.map
    }

    /// The map, to add scans to.
    pub fn map_mut(&mut self) -> &mut ObstacleMap {
        &mut self.map
    }

    /// New extraction parameters, while a goal runs (`goal_running`) or not. Invalid ones are
    /// refused, the map and any change waiting left as they were.
    pub fn reconfigure(&mut self, config: ScanObstacleConfig, goal_running: bool) -> Result<MapChange, PlannerError> {
        config.validate()?;
        if config == self.map.config {
            self.next = None;
            return Ok(MapChange::Unchanged);
        }
        if goal_running {
            if self.next == Some(config) {
                return Ok(MapChange::Unchanged);
            }
            self.next = Some(config);
            return Ok(MapChange::AfterGoal);
        }
        self.map = ObstacleMap::new(config)?;
        self.next = None;
        Ok(MapChange::Restarted)
    }

    /// The goal ended (none runs now): whether a change waiting made the map start afresh.
    pub fn goal_ended(&mut self) -> bool {
        match self.next.take().map(ObstacleMap::new) {
            Some(Ok(map)) => {
                self.map = map;
                true
            }
            // Validated when it was given; or none waiting.
            Some(Err(_)) | None => false,
        }
    }
}
