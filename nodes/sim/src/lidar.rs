//! A simulated planar LIDAR (default: a Hokuyo UST-10LX — 270°, 1081 beams, 40 Hz).
//!
//! Beams follow `sensor_msgs/LaserScan` (REP-103): angles anticlockwise in the laser frame, beam
//! i at `angle_min + i·angle_increment`, `angle_min = −fov/2`. No return within `range_max` is
//! `+inf` (REP-117). Gaussian range noise, clamped to [range_min, range_max], comes from a
//! seeded ChaCha generator, so a run is reproducible.

use nalgebra::Point2;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use thiserror::Error;

use crate::world::World;

/// Settings of the simulated LIDAR.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LidarConfig {
    /// Field of view [rad], centred on the laser's x axis.
    pub fov: f64,
    pub beams: usize,
    pub range_min: f64,
    pub range_max: f64,
    /// Range noise standard deviation [m].
    pub noise_std: f64,
    /// Scans per second.
    pub rate_hz: f64,
    /// Pose of the laser in `base_link`: x, y [m], yaw [rad].
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

/// An invalid LIDAR setting.
#[derive(Debug, Error, PartialEq)]
#[error("lidar: {0}")]
pub struct LidarError(String);

impl LidarConfig {
    /// Checks the settings.
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
            return Err(LidarError("needs 0 ≤ range_min < range_max".into()));
        }
        if self.noise_std < 0.0 || self.rate_hz <= 0.0 {
            return Err(LidarError("noise must be ≥ 0 and the rate > 0".into()));
        }
        Ok(())
    }
}

/// One scan, in LaserScan terms.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanData {
    pub angle_min: f64,
    pub angle_max: f64,
    pub angle_increment: f64,
    pub range_min: f64,
    pub range_max: f64,
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
    /// A LIDAR with its own random stream.
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

    /// The settings.
    pub fn config(&self) -> &LidarConfig {
        &self.config
    }

    /// Scans the world from a robot whose `base_link` is at `base_pose` = (x, y, yaw).
    pub fn scan(&mut self, world: &World, base_pose: (f64, f64, f64)) -> ScanData {
        let c = self.config;
        let (x, y, yaw) = base_pose;
        let (s, co) = yaw.sin_cos();
        let origin = Point2::new(
            x + co * c.mount[0] - s * c.mount[1],
            y + s * c.mount[0] + co * c.mount[1],
        );
        let heading = yaw + c.mount[2];
        let increment = c.fov / (c.beams - 1) as f64;
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
                    // Closer than range_min: the sensor cannot see it (REP-117: -inf is "too close").
                    Some(_) => f32::NEG_INFINITY,
                    None => f32::INFINITY,
                }
            })
            .collect();
        ScanData {
            angle_min,
            angle_max: angle_min + (c.beams - 1) as f64 * increment,
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

    fn wall_world() -> World {
        World::from_yaml_str(
            "obstacles:\n  - polygon: { points: [[3, -10], [4, -10], [4, 10], [3, 10]] }\n  - circle: { center: [-2, 0], radius: 0.5 }\n",
        )
        .unwrap()
    }

    fn beam_at(scan: &ScanData, angle: f64) -> f32 {
        let i = ((angle - scan.angle_min) / scan.angle_increment).round() as usize;
        scan.ranges[i]
    }

    #[test]
    fn hand_computed_ranges() {
        // 1081 beams over 270°: 0.25° apart, beam 540 straight ahead, beam 720 at +45°.
        let mut lidar = Lidar::new(LidarConfig::default(), 1);
        let scan = lidar.scan(&wall_world(), (0.0, 0.0, 0.0));
        assert_eq!(scan.ranges.len(), 1081);
        assert!((scan.angle_increment - 0.25f64.to_radians()).abs() < 1e-12);
        assert!((scan.angle_max - 135f64.to_radians()).abs() < 1e-12);
        assert!((scan.ranges[540] - 3.0).abs() < 1e-6);
        assert!((scan.ranges[720] as f64 - 3.0 * 2f64.sqrt()).abs() < 1e-5);
        // Straight behind is outside the 270° field of view; at +90° nothing is within 10 m.
        assert!(beam_at(&scan, std::f64::consts::FRAC_PI_2).is_infinite());
        // Facing −x, the circle at (−2, 0) of radius 0.5 is 1.5 m ahead.
        let scan = lidar.scan(&wall_world(), (0.0, 0.0, std::f64::consts::PI));
        assert!((scan.ranges[540] - 1.5).abs() < 1e-6);
    }

    #[test]
    fn mount_offset_and_empty_world() {
        let config = LidarConfig {
            mount: [0.5, 0.0, 0.0],
            ..LidarConfig::default()
        };
        let scan = Lidar::new(config, 1).scan(&wall_world(), (0.0, 0.0, 0.0));
        assert!((scan.ranges[540] - 2.5).abs() < 1e-6);
        let empty = Lidar::new(LidarConfig::default(), 1).scan(&World::default(), (0.0, 0.0, 0.0));
        assert!(empty.ranges.iter().all(|r| *r == f32::INFINITY));
    }

    #[test]
    fn noise_is_seeded() {
        let config = LidarConfig {
            noise_std: 0.05,
            ..LidarConfig::default()
        };
        let a = Lidar::new(config, 7).scan(&wall_world(), (0.0, 0.0, 0.0));
        let b = Lidar::new(config, 7).scan(&wall_world(), (0.0, 0.0, 0.0));
        let c = Lidar::new(config, 8).scan(&wall_world(), (0.0, 0.0, 0.0));
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert!((a.ranges[540] - 3.0).abs() < 0.3);
    }

    #[test]
    fn invalid_settings() {
        let ok = LidarConfig::default();
        assert!(ok.validate().is_ok());
        assert!(LidarConfig { beams: 1, ..ok }.validate().is_err());
        assert!(LidarConfig { fov: 7.0, ..ok }.validate().is_err());
        assert!(LidarConfig { range_min: 20.0, ..ok }.validate().is_err());
        assert!(LidarConfig {
            noise_std: f64::NAN,
            ..ok
        }
        .validate()
        .is_err());
    }
}
