//! Obstacles from a laser scan (SPEC §5: detected online): circles recovered from a synthetic
//! scan whose ranges are worked out here by ray–circle intersection, merged over time, and
//! malformed scans refused.

use std::f64::consts::PI;

use approx::assert_relative_eq;
use mobil_geom::Pose2;
use mobil_planner::vfo::{ObstacleMap, ScanObstacleConfig};
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
        .update_from_ranges(&ranges, -fov / 2.0, inc, 0.06, 10.0, &laser)
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
        .update_from_ranges(&ranges2, -fov / 2.0, inc, 0.06, 10.0, &laser2)
        .expect("valid scan");
    assert_eq!((update.new.len(), update.seen), (0, 2));
    assert!((map.circles()[0].centre - circles[0].0).norm() < 1e-3);
    // A third circle appears: reported as new with the next index.
    let more = [circles[0], circles[1], (Point2::new(3.0, -2.0), 0.25)];
    let ranges3 = synthetic_scan(&laser2, beams, fov, &more);
    let update = map
        .update_from_ranges(&ranges3, -fov / 2.0, inc, 0.06, 10.0, &laser2)
        .expect("valid scan");
    assert_eq!(update.new, vec![2]);
    assert!((map.circles()[2].centre - Point2::new(3.0, -2.0)).norm() < 1e-3);
    // Malformed scans change nothing.
    assert!(map.update_from_ranges(&[], 0.0, 0.01, 0.06, 10.0, &laser).is_err());
    assert!(map
        .update_from_ranges(&ranges, 0.0, f64::NAN, 0.06, 10.0, &laser)
        .is_err());
    assert!(map.update_from_ranges(&ranges, 0.0, inc, 1.0, 0.5, &laser).is_err());
    assert!(map
        .update_from_ranges(&ranges, 0.0, inc, 0.06, 10.0, &Pose2::new(f64::NAN, 0.0, 0.0))
        .is_err());
    // Only NaN and inf: no obstacle.
    let nothing = vec![f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY];
    let update = map
        .update_from_ranges(&nothing, 0.0, 0.1, 0.06, 10.0, &laser)
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
        .update_from_ranges(&ranges, -fov / 2.0, inc, 0.06, 10.0, &laser)
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
