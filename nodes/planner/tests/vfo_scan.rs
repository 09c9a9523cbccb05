//! Obstacles from a laser scan (SPEC §5: detected online): circles recovered from a synthetic
//! scan whose ranges are worked out here by ray–circle intersection, merged over time, placed
//! with the odometry pose at the scan's stamp, forgotten (seen through, decayed, capped), and
//! malformed scans refused.

use std::f64::consts::{FRAC_PI_2, PI};

use approx::assert_relative_eq;
use mobil_geom::{Pose2, Scan};
use mobil_planner::vfo::{
    Circle, KeptMap, MapChange, ObstacleMap, Placement, PoseHistory, ScanObstacleConfig, ScanSkipped,
};
use nalgebra::{Point2, Vector2};

/// Ranges of a scan from `odom_from_laser` with `beams` beams over `fov` (centred), seeing
/// `circles` (centre, radius) and nothing else: ray–circle intersections worked out here.
fn synthetic_scan(odom_from_laser: &Pose2, beams: usize, fov: f64, circles: &[(Point2<f64>, f64)]) -> Vec<f32> {
    let inc = fov / (beams - 1) as f64;
    (0..beams)
        .map(|i| {
            let a = odom_from_laser.yaw - fov / 2.0 + i as f64 * inc;
            let u = Vector2::new(a.cos(), a.sin());
            let p = odom_from_laser.position();
            let mut best = f64::INFINITY;
            for (c, rho) in circles {
                // |p + t·u − c|² = ρ²: t² + 2t·u·(p − c) + |p − c|² − ρ² = 0.
                let w = p - c;
                let b = u.dot(&w);
                let disc = b * b - (w.norm_squared() - rho * rho);
                if disc >= 0.0 {
                    let t = -b - disc.sqrt();
                    if t > 0.0 {
                        best = best.min(t);
                    }
                }
            }
            best as f32
        })
        .collect()
}

#[test]
fn obstacles_from_a_scan_recover_known_circles_and_merge_over_time() {
    let circles = [(Point2::new(4.0, 1.0), 0.3), (Point2::new(2.0, 3.0), 0.2)];
    let fov = 1.5 * PI;
    let beams = 1081;
    let inc = fov / (beams - 1) as f64;
    let config = ScanObstacleConfig::default();
    let mut map = ObstacleMap::new(config).expect("valid");
    let laser = Pose2::new(1.0, 0.5, 0.3);
    let mut ranges = synthetic_scan(&laser, beams, fov, &circles);
    ranges[0] = f32::NAN; // REP-117 no-measurements are not echoes
    ranges[1] = f32::NEG_INFINITY;
    let update = map
        .update_from_ranges(&ranges, -fov / 2.0, inc, 0.06, 10.0, &laser, 0.0)
        .expect("valid scan");
    assert_eq!(update.new, vec![0, 1]);
    let found = map.circles();
    // Order: beams sweep counter-clockwise from −135° about the laser's heading (0.3 rad):
    // (4, 1) lies at atan2(0.5, 3) − 0.3 = −0.135 rad, (2, 3) at atan2(2.5, 1) − 0.3 = 0.890.
    for (c, (centre, radius)) in found.iter().zip(circles) {
        assert!((c.centre - centre).norm() < 1e-3, "{c:?} vs {centre:?}");
        assert!((c.radius - radius).abs() < 1e-3, "{c:?} vs {radius}");
    }
    // The law's model: r = r_p + r_r, R = r + margin.
    let obstacles = map.obstacles();
    assert_relative_eq!(
        obstacles[0].forbidden_radius(),
        0.3 + config.robot_radius,
        epsilon = 1e-3
    );
    assert_relative_eq!(
        obstacles[0].influence_radius(),
        0.3 + config.robot_radius + config.influence_margin,
        epsilon = 1e-3
    );
    // A second scan from elsewhere sees the same two: nothing new, the indices kept.
    let laser2 = Pose2::new(2.5, -0.5, 1.0);
    let ranges2 = synthetic_scan(&laser2, beams, fov, &circles);
    let update = map
        .update_from_ranges(&ranges2, -fov / 2.0, inc, 0.06, 10.0, &laser2, 1.0)
        .expect("valid scan");
    assert_eq!((update.new.len(), update.seen), (0, 2));
    assert!((map.circles()[0].centre - circles[0].0).norm() < 1e-3);
    // A third circle appears: reported as new with the next index.
    let more = [circles[0], circles[1], (Point2::new(3.0, -2.0), 0.25)];
    let ranges3 = synthetic_scan(&laser2, beams, fov, &more);
    let update = map
        .update_from_ranges(&ranges3, -fov / 2.0, inc, 0.06, 10.0, &laser2, 1.0)
        .expect("valid scan");
    assert_eq!(update.new, vec![2]);
    assert!((map.circles()[2].centre - Point2::new(3.0, -2.0)).norm() < 1e-3);
    // Malformed scans change nothing.
    assert!(map.update_from_ranges(&[], 0.0, 0.01, 0.06, 10.0, &laser, 0.0).is_err());
    assert!(map
        .update_from_ranges(&ranges, 0.0, f64::NAN, 0.06, 10.0, &laser, 0.0)
        .is_err());
    assert!(map
        .update_from_ranges(&ranges, 0.0, inc, 1.0, 0.5, &laser, 0.0)
        .is_err());
    assert!(map
        .update_from_ranges(&ranges, 0.0, inc, 0.06, 10.0, &Pose2::new(f64::NAN, 0.0, 0.0), 0.0)
        .is_err());
    // Only NaN and inf: no obstacle.
    let nothing = vec![f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY];
    let update = map
        .update_from_ranges(&nothing, 0.0, 0.1, 0.06, 10.0, &laser, 1.0)
        .expect("valid");
    assert_eq!((update.new.len(), update.seen), (0, 0));
    assert_eq!(map.circles().len(), 3);
}

#[test]
fn a_wall_is_covered_by_a_chain_of_circles_holding_every_echo() {
    // A straight wall x = 2 from y = −1.5 to 1.5, seen from the origin: no circle fits it
    // (the fit's radius is far beyond max_radius), so pieces at most 2·max_radius = 1 m long
    // are covered: at least three circles, every echo inside one of them.
    let beams = 181;
    let fov = PI / 2.0;
    let inc = fov / (beams - 1) as f64;
    let ranges: Vec<f32> = (0..beams)
        .map(|i| {
            let a = -fov / 2.0 + i as f64 * inc;
            let t = 2.0 / a.cos();
            if (t * a.sin()).abs() <= 1.5 {
                t as f32
            } else {
                f32::INFINITY
            }
        })
        .collect();
    let mut map = ObstacleMap::new(ScanObstacleConfig::default()).expect("valid");
    let laser = Pose2::identity();
    let update = map
        .update_from_ranges(&ranges, -fov / 2.0, inc, 0.06, 10.0, &laser, 0.0)
        .expect("valid scan");
    let circles = map.circles();
    assert!(circles.len() >= 3, "{circles:?}");
    assert_eq!(update.new.len(), circles.len());
    for (i, r) in ranges.iter().enumerate() {
        if r.is_finite() {
            let a = -fov / 2.0 + i as f64 * inc;
            let p = Point2::new(f64::from(*r) * a.cos(), f64::from(*r) * a.sin());
            assert!(
                circles.iter().any(|c| (p - c.centre).norm() <= c.radius + 1e-9),
                "echo {p:?} outside every circle"
            );
        }
    }
    for c in &circles {
        // The centroid of a piece at most 1 m long lies on the wall, within 1 m of its ends.
        assert!(c.radius <= 1.0 && (c.centre.x - 2.0).abs() < 1e-6, "{c:?}");
    }
}

fn circle_map(decay_s: f64, max_obstacles: usize) -> ObstacleMap {
    ObstacleMap::new(ScanObstacleConfig {
        decay_s,
        max_obstacles,
        ..ScanObstacleConfig::default()
    })
    .expect("valid")
}

fn circle(x: f64, y: f64, radius: f64) -> Circle {
    Circle {
        centre: Point2::new(x, y),
        radius,
    }
}

#[test]
fn the_pose_history_interpolates_and_refuses_a_time_without_odometry_near_it() {
    let mut h = PoseHistory::new(50);
    assert!(h.at(0.0, 0.1).is_none());
    h.push(0.0, Pose2::new(0.0, 0.0, 0.0));
    h.push(0.1, Pose2::new(0.1, 0.02, 0.3));
    // A quarter of the way: (0.025, 0.005, 0.075).
    let p = h.at(0.025, 0.05).expect("between two poses");
    assert_relative_eq!(p.x, 0.025, epsilon = 1e-12);
    assert_relative_eq!(p.y, 0.005, epsilon = 1e-12);
    assert_relative_eq!(p.yaw, 0.075, epsilon = 1e-12);
    // After the last pose: the last one while within the bound, none beyond (no extrapolation).
    assert_eq!(h.at(0.14, 0.05), Some(Pose2::new(0.1, 0.02, 0.3)));
    assert!(h.at(0.16, 0.05).is_none());
    // Between two poses or at one's stamp the pose is interpolated; after the last, held.
    assert_eq!(h.placed_at(0.025, 0.05).map(|(_, p)| p), Some(Placement::Interpolated));
    assert_eq!(h.placed_at(0.1, 0.05).map(|(_, p)| p), Some(Placement::Interpolated));
    assert_eq!(h.placed_at(0.14, 0.05).map(|(_, p)| p), Some(Placement::Held));
    assert!(h.at(-0.06, 0.05).is_none());
    assert!(h.at(f64::NAN, 0.05).is_none());
    // Across ±π the heading goes the short way: from 3.1 to −3.1 is +0.083 rad, so the
    // midpoint lies at 3.1 + 0.0416 = 3.1416.
    h.push(0.2, Pose2::new(0.0, 0.0, 3.1));
    h.push(0.3, Pose2::new(0.0, 0.0, -3.1));
    let p = h.at(0.25, 0.1).expect("between");
    assert_relative_eq!(p.yaw, 3.1 + 0.5 * (2.0 * PI - 6.2), epsilon = 1e-12);
    // A gap of one second in the odometry: a scan in its middle is refused.
    h.push(1.3, Pose2::new(1.0, 0.0, 0.0));
    assert!(h.at(0.8, 0.1).is_none());
    // Time going backwards (a clock reset) starts the history afresh; the capacity holds.
    h.push(0.05, Pose2::new(5.0, 5.0, 0.0));
    assert_eq!(h.len(), 1);
    for k in 0..60 {
        h.push(1.0 + f64::from(k) * 0.02, Pose2::identity());
    }
    assert_eq!(h.len(), 50);
}

#[test]
fn a_scan_placed_with_the_pose_at_its_stamp_finds_the_obstacle_where_it_is() {
    // The robot turns on the spot at 1.5 rad/s: odometry at 50 Hz; a scan taken at t = 0.05 s
    // (heading 0.075 rad) of a pillar at (3, 0.5), r 0.3. Placed with the pose at its stamp
    // (interpolated between 0.04 and 0.06) the circle is found within 1 mm; placed with the
    // pose 0.1 s later (heading 0.225 rad, what a late scan met) it lands 0.15 rad round, about
    // 3.04 · 0.15 = 0.46 m off.
    let pillar = (Point2::new(3.0, 0.5), 0.3);
    let mut h = PoseHistory::new(50);
    for k in 0..10 {
        let t = f64::from(k) * 0.02;
        h.push(t, Pose2::new(0.0, 0.0, 1.5 * t));
    }
    let taken = Pose2::new(0.0, 0.0, 0.075);
    let fov = 1.5 * PI;
    let beams = 1081;
    let inc = fov / (beams - 1) as f64;
    let ranges = synthetic_scan(&taken, beams, fov, &[pillar]);
    let at_stamp = h.at(0.05, 0.05).expect("odometry near the stamp");
    assert_relative_eq!(at_stamp.yaw, 0.075, epsilon = 1e-12);
    let mut map = ObstacleMap::new(ScanObstacleConfig::default()).expect("valid");
    map.update_from_ranges(&ranges, -fov / 2.0, inc, 0.06, 10.0, &at_stamp, 0.05)
        .expect("valid");
    assert!(
        (map.circles()[0].centre - pillar.0).norm() < 1e-3,
        "{:?}",
        map.circles()
    );
    let mut late = ObstacleMap::new(ScanObstacleConfig::default()).expect("valid");
    late.update_from_ranges(&ranges, -fov / 2.0, inc, 0.06, 10.0, &Pose2::new(0.0, 0.0, 0.225), 0.05)
        .expect("valid");
    let off = (late.circles()[0].centre - pillar.0).norm();
    assert!((off - 0.46).abs() < 0.02, "{off}");
    // The same through add_scan, which finds the pose at the stamp itself; without fresh
    // odometry, or with none near the stamp, the scan is skipped and says why.
    let scan = Scan::new(
        -fov / 2.0,
        fov / 2.0,
        inc,
        0.06,
        10.0,
        ranges.clone(),
        Vec::new(),
        Pose2::identity(),
    )
    .expect("valid");
    let mut map = ObstacleMap::new(ScanObstacleConfig::default()).expect("valid");
    map.add_scan(&scan, 0.05, Some(&h), 0.05).expect("placed");
    assert!((map.circles()[0].centre - pillar.0).norm() < 1e-3);
    let skipped = map.add_scan(&scan, 0.05, None, 0.05).unwrap_err();
    assert_eq!(
        skipped.to_string(),
        "scan at 0.050 s ignored: no fresh odometry within 0.05 s of its stamp (obstacles are placed by the pose \
         at the scan's time)"
    );
    assert!(matches!(
        map.add_scan(&scan, 5.0, Some(&h), 0.05),
        Err(ScanSkipped::NoPose { .. })
    ));
}

#[test]
fn a_circle_seen_through_is_removed_and_one_hidden_or_out_of_view_is_kept() {
    // From the origin facing +x (270°, 10 m): a pillar at (3, 0) r 0.3 is seen at t = 0.
    let fov = 1.5 * PI;
    let beams = 1081;
    let inc = fov / (beams - 1) as f64;
    let laser = Pose2::identity();
    let pillar = (Point2::new(3.0, 0.0), 0.3);
    let mut map = circle_map(30.0, 200);
    let ranges = synthetic_scan(&laser, beams, fov, &[pillar]);
    map.update_from_ranges(&ranges, -fov / 2.0, inc, 0.06, 10.0, &laser, 0.0)
        .expect("valid");
    assert_eq!(map.ids(), vec![0]);
    // A box at (−2, −0.1), behind the laser's back (outside its 270°), is known too.
    map.merge_at(&[circle(-2.0, -0.1, 0.3)], 0.0);
    // Now a small pillar at (1.5, 0), r 0.2, hides it: kept (the echoes at 1.3 m stop short of
    // it); the small one is new (id 2).
    let occluder = (Point2::new(1.5, 0.0), 0.2);
    let hidden = synthetic_scan(&laser, beams, fov, &[occluder]);
    let u = map
        .update_from_ranges(&hidden, -fov / 2.0, inc, 0.06, 10.0, &laser, 1.0)
        .expect("valid");
    assert!(u.seen_through.is_empty(), "{u:?}");
    assert_eq!(map.ids(), vec![0, 1, 2]);
    // Nothing at all along the beams (both moved away): one scan is not enough, the second in a
    // row removes both, by id; the box behind the laser is not in view and stays, now at index 0.
    let empty = vec![f32::INFINITY; beams];
    let u = map
        .update_from_ranges(&empty, -fov / 2.0, inc, 0.06, 10.0, &laser, 2.0)
        .expect("valid");
    assert!(u.seen_through.is_empty(), "{u:?}");
    assert_eq!(map.ids(), vec![0, 1, 2]);
    let u = map
        .update_from_ranges(&empty, -fov / 2.0, inc, 0.06, 10.0, &laser, 2.025)
        .expect("valid");
    assert_eq!(u.seen_through, vec![0, 2]);
    assert!(u.removed_any());
    assert_eq!(map.ids(), vec![1]);
    assert_eq!(map.circles()[0].centre, Point2::new(-2.0, -0.1));
    // A circle beyond range_max (here 2.5 m) is not judged: kept.
    let mut map = circle_map(30.0, 200);
    map.merge_at(&[circle(3.0, 0.0, 0.3)], 0.0);
    for t in [1.0, 1.025] {
        let u = map
            .update_from_ranges(&empty, -fov / 2.0, inc, 0.06, 2.5, &laser, t)
            .expect("valid");
        assert!(u.seen_through.is_empty());
    }
    assert_eq!(map.len(), 1);
}

#[test]
fn a_run_of_seen_through_scans_is_broken_by_a_detection() {
    // The pillar at (3, 0) r 0.3: seen, seen through, seen again, seen through: never two in a
    // row, kept; the next scan through it completes a run of two and removes it.
    let fov = 1.5 * PI;
    let beams = 1081;
    let inc = fov / (beams - 1) as f64;
    let laser = Pose2::identity();
    let seen = synthetic_scan(&laser, beams, fov, &[(Point2::new(3.0, 0.0), 0.3)]);
    let empty = vec![f32::INFINITY; beams];
    let mut map = circle_map(30.0, 200);
    for (k, ranges) in [&seen, &empty, &seen, &empty].into_iter().enumerate() {
        let u = map
            .update_from_ranges(ranges, -fov / 2.0, inc, 0.06, 10.0, &laser, k as f64 * 0.025)
            .expect("valid");
        assert!(u.seen_through.is_empty(), "scan {k}: {u:?}");
    }
    let u = map
        .update_from_ranges(&empty, -fov / 2.0, inc, 0.06, 10.0, &laser, 0.1)
        .expect("valid");
    assert_eq!(u.seen_through, vec![0]);
}

#[test]
fn a_scan_placed_with_a_held_pose_does_not_remove_the_pillar_it_misplaces() {
    // The robot turns on the spot at 1.5 rad/s; odometry up to 0.06 s (heading 0.09 rad). A
    // pillar at (3.5, 0), r 0.1, is known from a scan at 0.06 s. A scan stamped 0.1 s (true
    // heading 0.15 rad) is placed with the held pose at 0.06 s: 0.06 rad off, so the pillar
    // lands 3.5 · 0.06 = 0.21 m aside — beyond the 0.2 m association distance, and
    // 0.1 + 0.1 − 0.21 < 0 overlap: a new circle — and the beams at the known circle's bearing
    // (0.06 rad from the pillar, which spans ±0.1 / 3.5 = ±0.029 rad) see nothing.
    let pillar = (Point2::new(3.5, 0.0), 0.1);
    let mut h = PoseHistory::new(50);
    for k in 0..4 {
        let t = f64::from(k) * 0.02;
        h.push(t, Pose2::new(0.0, 0.0, 1.5 * t));
    }
    let fov = 1.5 * PI;
    let beams = 1081;
    let inc = fov / (beams - 1) as f64;
    let scan_at = |yaw: f64| {
        let ranges = synthetic_scan(&Pose2::new(0.0, 0.0, yaw), beams, fov, &[pillar]);
        Scan::new(
            -fov / 2.0,
            fov / 2.0,
            inc,
            0.06,
            10.0,
            ranges,
            Vec::new(),
            Pose2::identity(),
        )
        .expect("valid")
    };
    let mut map = ObstacleMap::new(ScanObstacleConfig::default()).expect("valid");
    let (first, how) = h.placed_at(0.06, 0.1).expect("odometry at the stamp");
    assert_eq!(how, Placement::Interpolated);
    map.update_placed(&scan_at(0.09), &first, how, 0.06).expect("valid");
    assert_eq!(map.ids(), vec![0]);
    assert!((map.circles()[0].centre - pillar.0).norm() < 1e-3);
    let (held, how) = h.placed_at(0.1, 0.1).expect("within max_gap of the newest odometry");
    assert_eq!(how, Placement::Held);
    assert_relative_eq!(held.yaw, 0.09, epsilon = 1e-12);
    // Twice (a second scan at the same true heading, as if the odometry stalled).
    for t in [0.1, 0.125] {
        let u = map.update_placed(&scan_at(0.15), &held, how, t).expect("valid");
        assert!(u.seen_through.is_empty(), "{u:?}");
    }
    // The misplaced pillar was added; the true one is kept.
    assert_eq!(map.ids(), vec![0, 1]);
    let off = (map.circles()[1].centre - pillar.0).norm();
    assert!((off - 0.21).abs() < 0.02, "{off}");
    assert!((map.circles()[0].centre - pillar.0).norm() < 1e-3);
}

#[test]
fn a_full_turn_scanner_judges_an_obstacle_at_a_negative_bearing() {
    // Beams from 0 every 0.5° over the full turn; a circle at bearing −0.5 rad, 3 m away: beam
    // (2π − 0.5) / 0.5° ≈ 658 looks at it. Two empty scans remove it.
    let beams = 720;
    let inc = 2.0 * PI / beams as f64;
    let empty = vec![f32::INFINITY; beams];
    let mut map = circle_map(30.0, 200);
    map.merge_at(&[circle(3.0 * (-0.5f64).cos(), 3.0 * (-0.5f64).sin(), 0.3)], 0.0);
    let laser = Pose2::identity();
    map.update_from_ranges(&empty, 0.0, inc, 0.06, 10.0, &laser, 0.5)
        .expect("valid");
    let u = map
        .update_from_ranges(&empty, 0.0, inc, 0.06, 10.0, &laser, 0.525)
        .expect("valid");
    assert_eq!(u.seen_through, vec![0]);
}

#[test]
fn a_scan_older_than_the_map_empties_it() {
    // Circles seen at 100 s; the clock restarts and a scan stamped 1 s arrives (looking away
    // from both, so nothing is seen through): the map is emptied and says which ids went; a
    // circle then seen at 1 s decays 30 s later, on the new clock.
    let mut map = circle_map(30.0, 200);
    map.merge_at(&[circle(3.0, 0.0, 0.3), circle(0.0, 3.0, 0.3)], 100.0);
    let away = Pose2::new(0.0, 0.0, -FRAC_PI_2);
    let ranges = vec![f32::INFINITY; 21];
    let u = map
        .update_from_ranges(&ranges, -0.1, 0.01, 0.06, 10.0, &away, 99.0)
        .expect("valid");
    assert_eq!(u.cleared, vec![0, 1]);
    assert!(u.removed_any());
    assert!(map.is_empty());
    let reset = "scan at 99.000 s is older than obstacles already seen (clock reset?): the 2 obstacles forgotten";
    assert_eq!(u.warnings(99.0, 200), vec![("map-reset", reset.to_owned())]);
    map.merge_at(&[circle(3.0, 0.0, 0.3)], 99.5);
    let u = map
        .update_from_ranges(&ranges, -0.1, 0.01, 0.06, 10.0, &away, 129.6)
        .expect("valid");
    assert_eq!(u.decayed, vec![2]);
    // A scan at the same time as the last detection is no reset.
    map.merge_at(&[circle(3.0, 0.0, 0.3)], 130.0);
    let u = map
        .update_from_ranges(&ranges, -0.1, 0.01, 0.06, 10.0, &away, 130.0)
        .expect("valid");
    assert!(u.cleared.is_empty() && u.warnings(130.0, 200).is_empty());
    assert_eq!(map.len(), 1);
}

#[test]
fn a_circle_not_seen_for_the_decay_time_is_forgotten() {
    // decay 5 s; the laser looks along −x with a 0.2 rad field of view: it never sees the
    // circle at (3, 0), nor through it.
    let mut map = circle_map(5.0, 200);
    map.merge_at(&[circle(3.0, 0.0, 0.3)], 0.0);
    map.merge_at(&[circle(0.0, 3.0, 0.3)], 2.0);
    let away = Pose2::new(0.0, 0.0, PI);
    let ranges = vec![f32::INFINITY; 21];
    let u = map
        .update_from_ranges(&ranges, -0.1, 0.01, 0.06, 10.0, &away, 5.0)
        .expect("valid");
    assert!(u.decayed.is_empty());
    assert_eq!(map.len(), 2);
    // At 5.1 s the first (seen at 0) is 5.1 s old: forgotten; the second (seen at 2) stays.
    let u = map
        .update_from_ranges(&ranges, -0.1, 0.01, 0.06, 10.0, &away, 5.1)
        .expect("valid");
    assert_eq!(u.decayed, vec![0]);
    assert_eq!(map.ids(), vec![1]);
    // Seen again, a circle's clock restarts.
    map.merge_at(&[circle(0.0, 3.0, 0.3)], 6.0);
    let u = map
        .update_from_ranges(&ranges, -0.1, 0.01, 0.06, 10.0, &away, 10.5)
        .expect("valid");
    assert!(u.decayed.is_empty());
    assert_eq!(map.ids(), vec![1]);
}

#[test]
fn beyond_the_cap_the_least_recently_seen_circles_are_dropped() {
    // Cap 2; A seen at 0, B at 1, C at 2, then A again at 3: B is the least recently seen.
    let mut map = circle_map(30.0, 2);
    map.merge_at(&[circle(3.0, 0.0, 0.3)], 0.0);
    map.merge_at(&[circle(0.0, 3.0, 0.3)], 1.0);
    map.merge_at(&[circle(-3.0, 0.0, 0.3)], 2.0);
    map.merge_at(&[circle(3.0, 0.0, 0.3)], 3.0);
    assert_eq!(map.ids(), vec![0, 1, 2]);
    let away = Pose2::new(0.0, 0.0, -FRAC_PI_2);
    let ranges = vec![f32::INFINITY; 21];
    let u = map
        .update_from_ranges(&ranges, -0.1, 0.01, 0.06, 10.0, &away, 3.5)
        .expect("valid");
    assert_eq!(u.capped, vec![1]);
    assert_eq!(map.ids(), vec![0, 2]);
    let full = "obstacle map full (vfo.max_obstacles 2): the 1 least recently seen dropped";
    assert_eq!(u.warnings(3.5, 2), vec![("map-cap", full.to_owned())]);
    assert_eq!(map.circles()[1].centre, Point2::new(-3.0, 0.0));
    // Equal ages: the oldest (smallest id) goes first.
    let mut map = circle_map(30.0, 1);
    map.merge_at(&[circle(3.0, 0.0, 0.3), circle(0.0, 3.0, 0.3)], 0.0);
    let u = map
        .update_from_ranges(&ranges, -0.1, 0.01, 0.06, 10.0, &away, 0.5)
        .expect("valid");
    assert_eq!((u.capped, map.ids()), (vec![0], vec![1]));
    // Refused settings.
    assert!(ObstacleMap::new(ScanObstacleConfig {
        max_obstacles: 0,
        ..ScanObstacleConfig::default()
    })
    .is_err());
    assert!(ObstacleMap::new(ScanObstacleConfig {
        decay_s: f64::NAN,
        ..ScanObstacleConfig::default()
    })
    .is_err());
}

#[test]
fn new_extraction_parameters_wait_for_the_running_goal_to_end() {
    let base = ScanObstacleConfig::default();
    let mut kept = KeptMap::new(base).expect("valid");
    kept.map_mut().merge_at(&[circle(2.0, 0.0, 0.3)], 0.0);
    let wider = ScanObstacleConfig {
        influence_margin: base.influence_margin + 0.2,
        ..base
    };
    // During a goal: the map keeps its obstacle and its parameters until the goal ends.
    assert_eq!(kept.reconfigure(wider, true), Ok(MapChange::AfterGoal));
    assert_eq!(
        kept.reconfigure(wider, true),
        Ok(MapChange::Unchanged),
        "already waiting"
    );
    assert_eq!((kept.map().len(), *kept.map().config()), (1, base));
    // Invalid parameters are refused and leave the change waiting as it was.
    let bad = ScanObstacleConfig { memory: 0, ..base };
    assert!(kept.reconfigure(bad, true).is_err());
    assert!(kept.goal_ended());
    assert_eq!((kept.map().len(), *kept.map().config()), (0, wider));
    assert!(!kept.goal_ended(), "nothing waits any more");
    // Back to the map's own parameters during a goal: nothing waits, the map is kept.
    kept.map_mut().merge_at(&[circle(2.0, 0.0, 0.3)], 1.0);
    assert_eq!(kept.reconfigure(base, true), Ok(MapChange::AfterGoal));
    assert_eq!(kept.reconfigure(wider, true), Ok(MapChange::Unchanged));
    assert!(!kept.goal_ended());
    assert_eq!(kept.map().len(), 1);
    // With no goal running the map starts afresh at once.
    assert_eq!(kept.reconfigure(base, false), Ok(MapChange::Restarted));
    assert_eq!((kept.map().len(), *kept.map().config()), (0, base));
    // What the node tells of each.
    let told = |c: MapChange| match c.notice() {
        Some(mobil_motion::Notice::Info(line)) => line,
        other => format!("{other:?}"),
    };
    assert_eq!(
        told(MapChange::Restarted),
        "vfo obstacle extraction changed: the obstacle map starts afresh"
    );
    assert_eq!(
        told(MapChange::AfterGoal),
        "vfo obstacle extraction changed: the obstacle map starts afresh once the goal ends"
    );
    assert_eq!(MapChange::Unchanged.notice(), None);
}

/// The map seen from a goal's frame in which odom sits at (2, 3) turned by π/2: a circle at
/// (1, 0) in odom is at (2 − 0, 3 + 1) = (2, 4), its radius and id kept, the map itself
/// unchanged. A correction moves the frame when it passes 1 mm or 1 mrad.
#[test]
fn the_map_seen_from_a_goal_s_frame() {
    use mobil_planner::vfo::{frame_moved, Circle};
    let mut map = ObstacleMap::new(ScanObstacleConfig::default()).unwrap();
    map.merge_at(
        &[Circle {
            centre: Point2::new(1.0, 0.0),
            radius: 0.2,
        }],
        0.0,
    );
    let moved = map.moved(&Pose2::new(2.0, 3.0, std::f64::consts::FRAC_PI_2));
    assert_eq!(moved.ids(), map.ids());
    let c = moved.circles()[0];
    assert!(
        (c.centre - Point2::new(2.0, 4.0)).norm() < 1e-12 && c.radius == 0.2,
        "{c:?}"
    );
    assert_eq!(map.circles()[0].centre, Point2::new(1.0, 0.0));
    let at = Pose2::new(0.5, -1.0, 1.0);
    assert!(!frame_moved(&at, &Pose2::new(0.5009, -1.0, 1.0)));
    assert!(frame_moved(&at, &Pose2::new(0.5, -1.0011, 1.0)));
    assert!(frame_moved(&at, &Pose2::new(0.5, -1.0, 1.0011)));
    assert!(frame_moved(&at, &Pose2::new(f64::NAN, -1.0, 1.0)));
}
