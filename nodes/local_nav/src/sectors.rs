//! A checked scan reduced to N sectors around the robot (SPEC §2 Decision).
//!
//! Sector 0 is centred on a reference bearing (the goal's, or the locked one in L-mode); sector i
//! on `reference − i·2π/N`, i.e. the indices run **clockwise** as the source's sensors do (eq.
//! 3.51), while a LaserScan's angles run anticlockwise. d_i is the smallest valid range in the
//! sector measured from the robot centre (the base frame's origin), with REP-117's classes:
//! an echo counts at its distance, `+inf` (no echo) as free up to `range_max`, `−inf` (too close)
//! as 0, NaN and finite values outside the limits are ignored. A sector with no valid reading
//! (outside the field of view, or only NaN) is unknown: blocked (|f| = 0) or free by
//! [`UnseenSectors`].

use mobil_geom::{wrap, Beam, Scan};
use nalgebra::{Point2, Vector2};
use std::f64::consts::TAU;

/// What a sector without a valid reading counts as.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UnseenSectors {
    /// Blocked: |f_i| = 0 (the SPEC's default: what the robot cannot see it does not drive into).
    #[default]
    Blocked,
    /// Free: |f_i| = d_sa.
    Free,
}

/// One sector's reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sector {
    /// d_i (m): the smallest valid range in the sector from the robot centre; +∞ when unknown.
    pub distance: f64,
    /// Bearing (rad, base frame) of the nearest reading; the sector's centre when unknown.
    pub nearest_bearing: f64,
    /// Whether any valid reading fell into the sector.
    pub known: bool,
}

/// N sectors around a reference bearing, plus the obstacle points of the scan in the base frame
/// (for the corridor check of the motion). Buffers are reused from scan to scan.
#[derive(Debug, Clone)]
pub struct Sectors {
    reference_bearing: f64,
    unseen: UnseenSectors,
    sectors: Vec<Sector>,
    obstacles: Vec<Point2<f64>>,
}

impl Sectors {
    /// Empty sectors (all unknown) for `count` ≥ 1 sectors.
    pub fn new(count: usize, unseen: UnseenSectors) -> Self {
        let count = count.max(1);
        Sectors {
            reference_bearing: 0.0,
            unseen,
            sectors: vec![
                Sector {
                    distance: f64::INFINITY,
                    nearest_bearing: 0.0,
                    known: false,
                };
                count
            ],
            obstacles: Vec::new(),
        }
    }

    /// Builds the sectors from `scan` for a reference bearing (rad, base frame) of sector 0.
    pub fn compute(scan: &Scan, reference_bearing: f64, count: usize, unseen: UnseenSectors) -> Self {
        let mut s = Sectors::new(count, unseen);
        s.update(scan, reference_bearing);
        s
    }

    /// Number of sectors N.
    pub fn len(&self) -> usize {
        self.sectors.len()
    }

    /// Always false (at least one sector).
    pub fn is_empty(&self) -> bool {
        self.sectors.is_empty()
    }

    /// Angular width 2π/N of a sector (rad).
    pub fn width(&self) -> f64 {
        TAU / self.sectors.len() as f64
    }

    /// The reference bearing of sector 0 (rad, base frame).
    pub fn reference_bearing(&self) -> f64 {
        self.reference_bearing
    }

    /// Bearing (rad, base frame, wrapped) of sector i's centre: reference − i·2π/N (clockwise).
    pub fn bearing(&self, i: usize) -> f64 {
        wrap(self.reference_bearing - i as f64 * self.width())
    }

    /// The sector a base-frame bearing falls into.
    pub fn index_of(&self, bearing: f64) -> usize {
        let n = self.sectors.len() as i64;
        let k = (wrap(self.reference_bearing - bearing) / self.width()).round() as i64;
        k.rem_euclid(n) as usize
    }

    /// Sector i's reading (i taken modulo N).
    pub fn sector(&self, i: usize) -> Sector {
        self.sectors[i % self.sectors.len()]
    }

    /// All sectors, index 0 first.
    pub fn sectors(&self) -> &[Sector] {
        &self.sectors
    }

    /// The distance that enters the field: d_i when known, else 0 (blocked) or +∞ (free).
    pub fn effective_distance(&self, i: usize) -> f64 {
        let s = self.sector(i);
        if s.known {
            s.distance
        } else {
            match self.unseen {
                UnseenSectors::Blocked => 0.0,
                UnseenSectors::Free => f64::INFINITY,
            }
        }
    }

    /// Sector i clear beyond `threshold` (known and d_i > threshold, or unknown counted free).
    pub fn is_clear(&self, i: usize, threshold: f64) -> bool {
        self.effective_distance(i) > threshold
    }

    /// Echoes and too-close readings as points in the base frame.
    pub fn obstacles(&self) -> &[Point2<f64>] {
        &self.obstacles
    }

    /// The nearest known reading over all sectors: (distance, bearing), or None.
    pub fn nearest(&self) -> Option<(f64, f64)> {
        self.sectors
            .iter()
            .filter(|s| s.known && s.distance.is_finite())
            .min_by(|a, b| a.distance.total_cmp(&b.distance))
            .map(|s| (s.distance, s.nearest_bearing))
    }

    /// Free distance (m) along a base-frame bearing for a disc of radius `half_width` (the
    /// robot), counted from the centre like d_i: the distance the disc can travel before it
    /// touches an obstacle point ahead of the centre, plus the radius (so a point dead ahead at
    /// distance a gives a, and one grazing the corridor's edge gives its distance along the
    /// bearing plus the radius). +∞ when nothing is in the corridor.
    pub fn free_distance_along(&self, bearing: f64, half_width: f64) -> f64 {
        let (s, c) = bearing.sin_cos();
        let u = Vector2::new(c, s);
        let mut best = f64::INFINITY;
        for p in &self.obstacles {
            let along = p.x * u.x + p.y * u.y;
            let across = (p.y * u.x - p.x * u.y).abs();
            if along > 0.0 && across < half_width {
                let free = along - (half_width * half_width - across * across).sqrt() + half_width;
                best = best.min(free);
            }
        }
        best
    }

    /// Rebuilds the sectors from `scan` for a new reference bearing, reusing the buffers.
    pub fn update(&mut self, scan: &Scan, reference_bearing: f64) {
        self.reference_bearing = if reference_bearing.is_finite() {
            wrap(reference_bearing)
        } else {
            0.0
        };
        let n = self.sectors.len();
        for (i, s) in self.sectors.iter_mut().enumerate() {
            *s = Sector {
                distance: f64::INFINITY,
                nearest_bearing: wrap(self.reference_bearing - i as f64 * TAU / n as f64),
                known: false,
            };
        }
        self.obstacles.clear();
        let base_from_laser = scan.base_from_laser();
        if !base_from_laser.is_finite() {
            return;
        }
        let (_, range_max) = scan.range_limits();
        let (range_min, _) = scan.range_limits();
        let origin = Vector2::new(base_from_laser.x, base_from_laser.y);
        let centred = origin.norm() < 1e-9;
        let first = scan.angle(0) + base_from_laser.yaw;
        let increment = scan.angle(1.min(scan.len() - 1)) - scan.angle(0);
        let (rs, rc) = increment.sin_cos();
        let mut dir = Vector2::new(first.cos(), first.sin());
        let per_radian = n as f64 / TAU;
        for i in 0..scan.len() {
            // The beam's direction in the base frame, rotated incrementally (exact every 64 beams).
            if i % 64 == 0 {
                let a = first + i as f64 * increment;
                dir = Vector2::new(a.cos(), a.sin());
            } else if i > 0 {
                dir = Vector2::new(dir.x * rc - dir.y * rs, dir.x * rs + dir.y * rc);
            }
            let (range, obstacle, distance_override) = match scan.beam(i) {
                Some(Beam::Hit(r)) => (r, true, None),
                Some(Beam::NoEcho) => (range_max, false, None),
                Some(Beam::TooClose) => (range_min, true, Some(0.0)),
                _ => continue,
            };
            let p = origin + dir * range;
            let (distance, bearing) = if centred {
                (range, first + i as f64 * increment)
            } else {
                (p.norm(), p.y.atan2(p.x))
            };
            let distance = distance_override.unwrap_or(distance);
            if obstacle {
                self.obstacles.push(Point2::from(p));
            }
            // Whole turns of the difference shift k by multiples of N: no wrapping needed.
            // Nearest integer by a cast (round() is a libm call, a sixth of the time here).
            let t = (self.reference_bearing - bearing) * per_radian + 0.5;
            let mut k = t as i64;
            if (k as f64) > t {
                k -= 1;
            }
            let s = &mut self.sectors[k.rem_euclid(n as i64) as usize];
            if !s.known || distance < s.distance {
                s.distance = distance;
                s.nearest_bearing = bearing;
                s.known = true;
            }
        }
        for s in &mut self.sectors {
            s.nearest_bearing = wrap(s.nearest_bearing);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use mobil_geom::Pose2;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

    /// 360 beams, one per degree from −180° (anticlockwise), all `free`, limits [0.05, 10].
    fn ring(set: &[(i32, f32)], free: f32, laser: Pose2) -> Scan {
        let mut ranges = vec![free; 360];
        for &(deg, r) in set {
            ranges[(deg + 180) as usize] = r;
        }
        Scan::new(-PI, PI - PI / 180.0, PI / 180.0, 0.05, 10.0, ranges, vec![], laser).unwrap()
    }

    #[test]
    fn sectors_run_clockwise_from_the_goal() {
        // Echoes: 1.0 m at +90° (left), 2.0 m at −90° (right), 3.0 m at +44°, 0.5 m at 180°.
        let scan = ring(
            &[(90, 1.0), (-90, 2.0), (44, 3.0), (180 - 360, 0.5)],
            f32::INFINITY,
            Pose2::identity(),
        );
        let s = Sectors::compute(&scan, 0.0, 8, UnseenSectors::Blocked);
        // Sector i is centred on −45°·i: 2 = −90° (right), 6 = +90° (left), 7 = +45°, 4 = 180°.
        assert_relative_eq!(s.sector(6).distance, 1.0, epsilon = 1e-6);
        assert_relative_eq!(s.sector(2).distance, 2.0, epsilon = 1e-6);
        assert_relative_eq!(s.sector(7).distance, 3.0, epsilon = 1e-6);
        assert_relative_eq!(s.sector(4).distance, 0.5, epsilon = 1e-6);
        // Sector 0 only sees +inf: free to range_max.
        assert_relative_eq!(s.sector(0).distance, 10.0);
        assert_relative_eq!(s.sector(6).nearest_bearing, FRAC_PI_2, epsilon = 1e-9);
        assert_eq!(s.index_of(-FRAC_PI_4), 1);
        assert_eq!(s.index_of(FRAC_PI_4), 7);
        // With the goal at +90°, the left echo is in sector 0 and the right one in sector 4.
        let s = Sectors::compute(&scan, FRAC_PI_2, 8, UnseenSectors::Blocked);
        assert_relative_eq!(s.sector(0).distance, 1.0, epsilon = 1e-6);
        assert_relative_eq!(s.sector(4).distance, 2.0, epsilon = 1e-6);
        // +44° is 46° clockwise of +90°: sector 1.
        assert_relative_eq!(s.sector(1).distance, 3.0, epsilon = 1e-6);
    }

    #[test]
    fn rep117_classes() {
        // In sector 0 (±22.5°): NaN at 0°, 0.01 (below range_min: ignored) at 5°, 12 (above
        // range_max: ignored) at 10°, a 4 m echo at −10°; −inf at +100° (too close → 0).
        let scan = ring(
            &[
                (0, f32::NAN),
                (5, 0.01),
                (10, 12.0),
                (-10, 4.0),
                (100, f32::NEG_INFINITY),
            ],
            f32::INFINITY,
            Pose2::identity(),
        );
        let s = Sectors::compute(&scan, 0.0, 8, UnseenSectors::Blocked);
        assert_relative_eq!(s.sector(0).distance, 4.0, epsilon = 1e-6);
        assert_eq!(s.sector(6).distance, 0.0);
        assert!(s.sector(6).known);
        // The too-close reading is an obstacle at range_min along +100°: it blocks a corridor
        // that way at 0.05 m, and (being behind the centre) not the corridor ahead.
        assert_relative_eq!(s.free_distance_along(100f64.to_radians(), 0.2), 0.05, epsilon = 1e-9);
        // Ahead: the 4 m echo at −10° is 4·sin 10° = 0.69 m off the axis: outside a 0.3 m
        // corridor, so nothing ahead.
        assert_eq!(s.free_distance_along(0.0, 0.3), f64::INFINITY);
        // With a 0.8 m radius: along 4·cos 10° = 3.93923, across 4·sin 10° = 0.69459; the disc
        // touches after 3.93923 − √(0.64 − 0.48246) = 3.93923 − 0.39691 = 3.54232 m, + 0.8.
        assert_relative_eq!(s.free_distance_along(0.0, 0.8), 4.34232, epsilon = 1e-4);
        // Dead ahead a point counts at its distance: the −10° echo along −10°.
        assert_relative_eq!(s.free_distance_along(-10f64.to_radians(), 0.3), 4.0, epsilon = 1e-5);
    }

    #[test]
    fn field_of_view_and_unseen_policy() {
        // A 270° scanner (−135°…+135°), 1° beams, everything at 5 m.
        let ranges = vec![5.0f32; 271];
        let fov = 135f64.to_radians();
        let scan = Scan::new(-fov, fov, PI / 180.0, 0.05, 10.0, ranges, vec![], Pose2::identity()).unwrap();
        let s = Sectors::compute(&scan, 0.0, 8, UnseenSectors::Blocked);
        // Sector 4 (180° ± 22.5°) is outside; sectors 3 and 5 (±135° ± 22.5°) are half seen.
        assert!(!s.sector(4).known);
        assert_eq!(s.effective_distance(4), 0.0);
        assert!(s.sector(3).known && s.sector(5).known);
        assert_relative_eq!(s.effective_distance(3), 5.0, epsilon = 1e-6);
        let s = Sectors::compute(&scan, 0.0, 8, UnseenSectors::Free);
        assert_eq!(s.effective_distance(4), f64::INFINITY);
    }

    #[test]
    fn distances_are_from_the_robot_centre() {
        // Laser 0.3 m ahead of the centre, turned +90° (looking left). A beam at −90° in the
        // laser looks along base +x: a 1.0 m echo there is at (1.3, 0): 1.3 m from the centre,
        // bearing 0 → sector 0.
        let laser = Pose2::new(0.3, 0.0, FRAC_PI_2);
        let scan = ring(&[(-90, 1.0)], f32::INFINITY, laser);
        let s = Sectors::compute(&scan, 0.0, 8, UnseenSectors::Blocked);
        assert_relative_eq!(s.sector(0).distance, 1.3, epsilon = 1e-6);
        assert_relative_eq!(s.sector(0).nearest_bearing, 0.0, epsilon = 1e-9);
        // +inf beams count from the centre too: the beam at +90° in the laser points along
        // base −x (90° + 90° = 180°) and reaches (0.3 − 10, 0): 9.7 m behind, the nearest
        // range_max point of sector 4.
        assert_relative_eq!(s.sector(4).distance, 9.7, epsilon = 1e-6);
    }
}
