//! A simulated planar LIDAR (default: a Hokuyo UST-10LX — 270°, 1081 beams, 40 Hz).
//!
//! Beams follow `sensor_msgs/LaserScan` (REP-103): angles anticlockwise in the laser frame, beam
//! i at `angle_min + i·angle_increment`, `angle_min = −fov/2`. No return within `range_max` is
//! `+inf`, a surface closer than `range_min` is `−inf` (REP-117). Gaussian range noise, clamped
//! to [range_min, range_max], comes from a seeded ChaCha generator, so a run is reproducible.
#![warn(missing_docs)]

use mobil_geom::Pose2;
use nalgebra::Point2;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use thiserror::Error;

use mobil_world::World;

/// Settings of the simulated LIDAR.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LidarConfig {
    /// Field of view (rad), centred on the laser's x axis; in (0, 2π].
    pub fov: f64,
    /// Beams per scan, ≥ 2; the first and last lie on the edges of the field of view.
    pub beams: usize,
    /// Nearest measurable range (m).
    pub range_min: f64,
    /// Farthest measurable range (m).
    pub range_max: f64,
    /// Range noise standard deviation (m).
    pub noise_std: f64,
    /// Scans per second (for the node; a scan itself is instantaneous).
    pub rate_hz: f64,
    /// Pose of the laser in `base_link`: x, y (m), yaw (rad).
    pub mount: [f64; 3],
}

impl Default for LidarConfig {
    fn default() -> Self {
        LidarConfig {
            fov: 270f64.to_radians(),
            beams: 1081,
            range_min: 0.06,
            range_max: 10.0,
            noise_std: 0.0,
            rate_hz: 40.0,
            mount: [0.0; 3],
        }
    }
}

/// An invalid LIDAR setting, with the reason.
#[derive(Debug, Error, PartialEq)]
#[error("lidar: {0}")]
pub struct LidarError(String);

impl LidarConfig {
    /// Checks the settings: all finite, beams ≥ 2, fov in (0, 2π], 0 ≤ range_min < range_max,
    /// noise_std ≥ 0, rate_hz > 0.
    pub fn validate(&self) -> Result<(), LidarError> {
        let finite = [self.fov, self.range_min, self.range_max, self.noise_std, self.rate_hz]
            .iter()
            .chain(&self.mount)
            .all(|x| x.is_finite());
        if !finite {
            return Err(LidarError("every value must be finite".into()));
        }
        if self.beams < 2 {
            return Err(LidarError(format!("needs at least 2 beams, got {}", self.beams)));
        }
        if !(self.fov > 0.0 && self.fov <= std::f64::consts::TAU) {
            return Err(LidarError(format!("fov {} must be in (0, 2π]", self.fov)));
        }
        if !(0.0 <= self.range_min && self.range_min < self.range_max) {
            return Err(LidarError(format!(
                "needs 0 ≤ range_min < range_max, got range_min {} and range_max {}",
                self.range_min, self.range_max
            )));
        }
        if self.noise_std < 0.0 {
            return Err(LidarError(format!("noise_std {} must be ≥ 0", self.noise_std)));
        }
        if self.rate_hz <= 0.0 {
            return Err(LidarError(format!("rate_hz {} must be > 0", self.rate_hz)));
        }
        Ok(())
    }
}

/// One scan, in `sensor_msgs/LaserScan` terms (angles in the laser frame).
#[derive(Debug, Clone, PartialEq)]
pub struct ScanData {
    /// Angle of the first beam (rad), −fov/2.
    pub angle_min: f64,
    /// Angle of the last beam (rad), +fov/2.
    pub angle_max: f64,
    /// Angle between beams (rad), fov / (beams − 1).
    pub angle_increment: f64,
    /// Nearest measurable range (m).
    pub range_min: f64,
    /// Farthest measurable range (m).
    pub range_max: f64,
    /// Ranges (m): +inf for no return, −inf for a surface closer than `range_min`.
    pub ranges: Vec<f32>,
}

/// The simulated sensor.
#[derive(Debug, Clone)]
pub struct Lidar {
    config: LidarConfig,
    noise: Option<Normal<f64>>,
    rng: ChaCha8Rng,
}

impl Lidar {
    /// A LIDAR with its own random stream (ChaCha8 seeded with `seed`).
    ///
    /// The settings should have passed [`LidarConfig::validate`]; if not, scanning still does
    /// not panic (fewer than 2 beams give at most one beam at −fov/2, invalid noise none).
    pub fn new(config: LidarConfig, seed: u64) -> Self {
        let noise = (config.noise_std > 0.0)
            .then(|| Normal::new(0.0, config.noise_std).ok())
            .flatten();
        Lidar {
            config,
            noise,
            rng: ChaCha8Rng::seed_from_u64(seed),
        }
    }

    /// Like [`Lidar::new`], refusing invalid settings.
    pub fn try_new(config: LidarConfig, seed: u64) -> Result<Self, LidarError> {
        config.validate()?;
        Ok(Self::new(config, seed))
    }

    /// The settings.
    pub fn config(&self) -> &LidarConfig {
        &self.config
    }

    /// Scans the world from a robot whose `base_link` is at `base_pose` = (x, y, yaw) in the
    /// world; the laser sits at `config.mount` in `base_link`.
    pub fn scan(&mut self, world: &World, base_pose: (f64, f64, f64)) -> ScanData {
        let c = self.config;
        let (x, y, yaw) = base_pose;
        let world_from_base = Pose2 { x, y, yaw };
        let origin = world_from_base.transform_point(Point2::new(c.mount[0], c.mount[1]));
        let heading = yaw + c.mount[2];
        // A full circle must not measure ±π twice: N beams then split 2π into N gaps.
        let full_circle = (c.fov - std::f64::consts::TAU).abs() < 1e-9;
        let increment = if full_circle {
            c.fov / c.beams.max(1) as f64
        } else if c.beams >= 2 {
            c.fov / (c.beams - 1) as f64
        } else {
            0.0
        };
        let angle_min = -0.5 * c.fov;
        let ranges = (0..c.beams)
            .map(|i| {
                let angle = angle_min + i as f64 * increment;
                match world.ray_distance(origin, heading + angle, c.range_max) {
                    Some(r) if r >= c.range_min => {
                        let noisy = match &self.noise {
                            Some(n) => (r + n.sample(&mut self.rng)).clamp(c.range_min, c.range_max),
                            None => r,
                        };
                        noisy as f32
                    }
                    Some(_) => f32::NEG_INFINITY,
                    None => f32::INFINITY,
                }
            })
            .collect();
        ScanData {
            angle_min,
            angle_max: angle_min + c.beams.saturating_sub(1) as f64 * increment,
            angle_increment: increment,
            range_min: c.range_min,
            range_max: c.range_max,
            ranges,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// A wall 1 m thick whose near face is the line x = 3, from y = −10 to 10.
    fn wall() -> World {
        World::from_yaml_str("obstacles:\n  - polygon: { points: [[3, -10], [4, -10], [4, 10], [3, 10]] }\n").unwrap()
    }

    fn beam_at(scan: &ScanData, angle: f64) -> f32 {
        let i = ((angle - scan.angle_min) / scan.angle_increment).round() as usize;
        scan.ranges[i]
    }

    #[test]
    fn angles_follow_laser_scan_conventions() {
        let scan = Lidar::new(LidarConfig::default(), 1).scan(&World::default(), (0.0, 0.0, 0.0));
        // 1081 beams over 270°: 0.25° apart, beam 540 straight ahead, beam 720 at +45°.
        assert_eq!(scan.ranges.len(), 1081);
        assert!((scan.angle_min + 135f64.to_radians()).abs() < 1e-12);
        assert!((scan.angle_max - 135f64.to_radians()).abs() < 1e-12);
        assert!((scan.angle_increment - 0.25f64.to_radians()).abs() < 1e-12);
        assert_eq!((scan.range_min, scan.range_max), (0.06, 10.0));
        // An empty world returns nothing: every beam is +inf.
        assert!(scan.ranges.iter().all(|r| *r == f32::INFINITY));
        // 3 beams over 90°: −45°, 0°, +45°.
        let config = LidarConfig {
            fov: FRAC_PI_2,
            beams: 3,
            ..LidarConfig::default()
        };
        let scan = Lidar::new(config, 1).scan(&wall(), (0.0, 0.0, 0.0));
        assert!((scan.angle_increment - PI / 4.0).abs() < 1e-15);
        assert_eq!(scan.ranges.len(), 3);
        assert_eq!(scan.ranges[1], 3.0);
        assert!((f64::from(scan.ranges[0]) - 3.0 * 2f64.sqrt()).abs() < 1e-6);
        assert!((f64::from(scan.ranges[2]) - 3.0 * 2f64.sqrt()).abs() < 1e-6);
    }

    #[test]
    fn wall_ahead_by_hand() {
        let scan = Lidar::new(LidarConfig::default(), 1).scan(&wall(), (0.0, 0.0, 0.0));
        assert_eq!(scan.ranges[540], 3.0);
        // +45°: 3 / cos 45° = 4.2426…
        assert!((f64::from(scan.ranges[720]) - 3.0 * 2f64.sqrt()).abs() < 1e-6);
        assert!((f64::from(scan.ranges[720]) - 4.242_640_687).abs() < 1e-6);
        // −60°: 3 / cos 60° = 6.
        assert!((beam_at(&scan, -PI / 3.0) - 6.0).abs() < 1e-5);
        // Past ±72.54° the wall is farther than 10 m (3 / cos θ > 10): +inf.
        assert!(beam_at(&scan, 72.0f64.to_radians()).is_finite());
        assert_eq!(beam_at(&scan, 73.0f64.to_radians()), f32::INFINITY);
        assert_eq!(beam_at(&scan, FRAC_PI_2), f32::INFINITY);
    }

    #[test]
    fn circle_ahead_by_hand() {
        let world = World::from_yaml_str("obstacles:\n  - circle: { center: [2, 0], radius: 0.5 }\n").unwrap();
        let scan = Lidar::new(LidarConfig::default(), 1).scan(&world, (0.0, 0.0, 0.0));
        assert_eq!(scan.ranges[540], 1.5);
        // The disc subtends ±asin(0.5 / 2) = ±14.48°: beams at ±14° hit, ±15° miss.
        assert!(beam_at(&scan, 14f64.to_radians()).is_finite());
        assert_eq!(beam_at(&scan, 15f64.to_radians()), f32::INFINITY);
        // At 10°: nearer root of t² − 4t cos 10° + 3.75 = 0.
        let c = 10f64.to_radians().cos();
        let t = 2.0 * c - (4.0 * c * c - 3.75).sqrt();
        assert!((f64::from(beam_at(&scan, 10f64.to_radians())) - t).abs() < 1e-6);
    }

    #[test]
    fn left_is_positive_angles() {
        // A wall along y = 2 (left of a robot facing +x): seen by +90° beams only.
        let world =
            World::from_yaml_str("obstacles:\n  - polygon: { points: [[-10, 2], [10, 2], [10, 3], [-10, 3]] }\n")
                .unwrap();
        let scan = Lidar::new(LidarConfig::default(), 1).scan(&world, (0.0, 0.0, 0.0));
        assert_eq!(scan.ranges[900], 2.0);
        assert_eq!(scan.ranges[180], f32::INFINITY);
        // Robot turned to face −y: the wall is now behind, in the blind 90° sector.
        let scan = Lidar::new(LidarConfig::default(), 1).scan(&world, (0.0, 0.0, -FRAC_PI_2));
        assert!(
            scan.ranges[0] > 2.8 && scan.ranges[1080] > 2.8,
            "edges see the wall at 2/cos 45°"
        );
        assert_eq!(scan.ranges[540], f32::INFINITY);
    }

    #[test]
    fn mount_offset_is_respected() {
        // Laser 0.5 m ahead of base_link: the wall is 2.5 m away.
        let forward = LidarConfig {
            mount: [0.5, 0.0, 0.0],
            ..LidarConfig::default()
        };
        let scan = Lidar::new(forward, 1).scan(&wall(), (0.0, 0.0, 0.0));
        assert_eq!(scan.ranges[540], 2.5);
        // Laser at (0.5, 0.2) yawed +90° on a robot at (1, −1) facing +y: the laser sits at
        // (0.8, −0.5) facing −x, straight at the circle at (−2, −0.5) of radius 0.5:
        // 2.8 − 0.5 = 2.3 m.
        let world = World::from_yaml_str("obstacles:\n  - circle: { center: [-2, -0.5], radius: 0.5 }\n").unwrap();
        let mounted = LidarConfig {
            mount: [0.5, 0.2, FRAC_PI_2],
            ..LidarConfig::default()
        };
        let scan = Lidar::new(mounted, 1).scan(&world, (1.0, -1.0, FRAC_PI_2));
        assert!((scan.ranges[540] - 2.3).abs() < 1e-6, "{}", scan.ranges[540]);
        // The same laser without the mount yaw faces +y and does not see the circle ahead.
        let unyawed = LidarConfig {
            mount: [0.5, 0.2, 0.0],
            ..LidarConfig::default()
        };
        let scan = Lidar::new(unyawed, 1).scan(&world, (1.0, -1.0, FRAC_PI_2));
        assert_eq!(scan.ranges[540], f32::INFINITY);
        assert!((scan.ranges[900] - 2.3).abs() < 1e-6, "now at +90°");
    }

    #[test]
    fn surfaces_nearer_than_range_min_read_minus_inf() {
        let config = LidarConfig {
            range_min: 0.5,
            ..LidarConfig::default()
        };
        let scan = Lidar::new(config, 1).scan(&wall(), (2.8, 0.0, 0.0));
        assert_eq!(scan.ranges[540], f32::NEG_INFINITY);
        // 0.2 / cos 70° = 0.585 ≥ 0.5: a valid return.
        assert!((f64::from(beam_at(&scan, 70f64.to_radians())) - 0.2 / 70f64.to_radians().cos()).abs() < 1e-5);
    }

    #[test]
    fn noise_is_seeded_gaussian_and_clamped() {
        let config = LidarConfig {
            noise_std: 0.05,
            ..LidarConfig::default()
        };
        // Facing the wall from 3 m, beams within ±30° (241 of them) all hit.
        let a = Lidar::new(config, 7).scan(&wall(), (0.0, 0.0, 0.0));
        let b = Lidar::new(config, 7).scan(&wall(), (0.0, 0.0, 0.0));
        let c = Lidar::new(config, 8).scan(&wall(), (0.0, 0.0, 0.0));
        assert_eq!(a, b);
        assert_ne!(a, c);
        // A second scan continues the stream: it differs from the first.
        let mut lidar = Lidar::new(config, 7);
        let first = lidar.scan(&wall(), (0.0, 0.0, 0.0));
        assert_ne!(first.ranges, lidar.scan(&wall(), (0.0, 0.0, 0.0)).ranges);
        let errors: Vec<f64> = (420..=660)
            .map(|i| {
                let angle = a.angle_min + i as f64 * a.angle_increment;
                f64::from(a.ranges[i]) - 3.0 / angle.cos()
            })
            .collect();
        let n = errors.len() as f64;
        let mean = errors.iter().sum::<f64>() / n;
        let std = (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        // Standard error of the mean 0.05/√241 = 0.0032; of the std about 0.0023.
        assert!(mean.abs() < 0.012, "mean {mean}");
        assert!((std - 0.05).abs() < 0.01, "std {std}");
        // Where there is no return, noise does not invent one.
        assert_eq!(beam_at(&a, FRAC_PI_2), f32::INFINITY);
        // Huge noise is clamped into [range_min, range_max].
        let wild = LidarConfig {
            noise_std: 100.0,
            ..LidarConfig::default()
        };
        let scan = Lidar::new(wild, 3).scan(&wall(), (0.0, 0.0, 0.0));
        let hits: Vec<f32> = scan.ranges.iter().copied().filter(|r| r.is_finite()).collect();
        assert!(hits.len() > 200);
        assert!(hits.iter().all(|r| (0.06..=10.0).contains(r)));
        assert!(hits.contains(&0.06) && hits.contains(&10.0));
    }

    #[test]
    fn invalid_settings_are_refused_with_a_reason() {
        let ok = LidarConfig::default();
        assert_eq!(ok.validate(), Ok(()));
        let reason = |c: LidarConfig| c.validate().unwrap_err().to_string();
        assert!(reason(LidarConfig { beams: 1, ..ok }).contains("at least 2 beams, got 1"));
        assert!(reason(LidarConfig { fov: 7.0, ..ok }).contains("fov 7"));
        assert!(reason(LidarConfig { fov: 0.0, ..ok }).contains("fov 0"));
        assert!(LidarConfig {
            fov: std::f64::consts::TAU,
            ..ok
        }
        .validate()
        .is_ok());
        assert!(reason(LidarConfig { range_min: 20.0, ..ok }).contains("range_min < range_max"));
        assert!(reason(LidarConfig { range_min: -0.1, ..ok }).contains("range_min"));
        assert!(reason(LidarConfig { noise_std: -0.1, ..ok }).contains("noise_std"));
        assert!(reason(LidarConfig { rate_hz: 0.0, ..ok }).contains("rate_hz"));
        assert!(reason(LidarConfig {
            noise_std: f64::NAN,
            ..ok
        })
        .contains("finite"));
        assert!(reason(LidarConfig {
            mount: [0.0, f64::INFINITY, 0.0],
            ..ok
        })
        .contains("finite"));
        assert!(Lidar::try_new(LidarConfig { beams: 0, ..ok }, 1).is_err());
        assert!(Lidar::try_new(ok, 1).is_ok());
    }

    #[test]
    fn smoke_unvalidated_settings_do_not_panic() {
        for beams in [0, 1] {
            let scan = Lidar::new(
                LidarConfig {
                    beams,
                    ..LidarConfig::default()
                },
                1,
            )
            .scan(&wall(), (0.0, 0.0, 0.0));
            assert_eq!(scan.ranges.len(), beams);
        }
    }
}
