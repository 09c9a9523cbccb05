//! Thresholds, body points and frame names of the assessment, and the hexapod's geometry.
//! Every default is justified on its field or on the docs page it cites; `params/hexapod.yaml`
//! holds the same values, and a test checks that the file's values classify a 10° slope, Table
//! 1's feet and ε_α as stated there.
//!
//! Both structs deserialize from a ROS 2 parameter section (flat names; nested maps for the
//! footholds): a missing key takes its default, keys of other structs are ignored.

use crate::error::{check_point, TerrainError};
use crate::leg::Leg;
use nalgebra::{Point2, Point3};
use serde::Deserialize;

/// 1° in radians.
const DEG: f64 = std::f64::consts::PI / 180.0;

/// What the assessment needs: thresholds of the classes and of the advice, the body points of
/// plane 3, and the body frame's name.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default)]
pub struct TerrainConfig {
    /// σ_flat (m), > 0 and ≤ `sigma_wave`: the largest σ of the feet that still counts as flat.
    /// FLAT needs all three angles within ε_α, the planes' offset within `plane_offset_max` *and*
    /// σ ≤ σ_flat. Default 0.010. Depends on the footholds: below their largest spread × tan ε_α it
    /// refuses coplanar stances within ε_α, which [`TerrainConfig::warnings`] reports (see
    /// docs/experiments/terrain-table1.md#the-thresholds).
    pub sigma_flat: f64,
    /// Largest offset (m), > 0, between the two foot planes, parallel within ε_α, that still
    /// counts as one plane ([`plane_offset`](crate::assess::plane_offset)); above it the stance is
    /// UNEVEN, a step between the tripods. Default 0.010 (see
    /// docs/experiments/terrain-table1.md#the-thresholds).
    pub plane_offset_max: f64,
    /// σ (m), from `sigma_flat` to `sigma_max`, between the ripple and the wave gait: SLOPE and
    /// UNEVEN get ripple up to it, wave above. Default 0.025, between a plain 10° slope's σ and
    /// Table 1's "large" feet (see docs/experiments/terrain-table1.md#the-thresholds).
    pub sigma_wave: f64,
    /// σ_max (m): above it the ground is BEYOND_LIMITS (reroute). Default 0.040: above Table 1's
    /// "large" feet (2.77 cm, UNEVEN) and a plain 10° slope in any direction (at most 2.37 cm
    /// with the default footholds: 0.1347 m × tan 10°); a 4 cm σ means feet about ±6 cm off
    /// their mean, 60 % of the default 0.10 m body height, where the legs near their reach.
    pub sigma_max: f64,
    /// ε_α (rad): angles within it count as zero ("≈" of SPEC §6). Default 3° (the most the SPEC
    /// allows): well above the angle noise of legs' kinematics (1 mm over the 0.30 m between
    /// front and rear feet is 0.2°), and below any slope worth reporting.
    pub epsilon_alpha: f64,
    /// tilt_max (rad): a foot plane inclined more than this to the body's xy-plane is
    /// BEYOND_LIMITS. Default 15°: a plain 10° slope stays SLOPE with 5° to spare, and 15° is
    /// about where a small hexapod's static stability on a tripod with ordinary friction
    /// (μ ≈ 0.5 gives 26°) leaves no margin for the swing leg's disturbance.
    pub tilt_max: f64,
    /// Body points 1, 2, 3 of plane 3 (m, body frame, finite, not collinear), as nine numbers
    /// x1 y1 z1 x2 y2 z2 x3 y3 z3 (a ROS double array). Default: a front point on the axis and two
    /// rear points at ±0.08 m, all in the body's xy-plane, so α13 and α23 are the foot planes'
    /// inclinations to the body (see docs/experiments/terrain-table1.md#the-thresholds).
    pub body_points: [f64; 9],
    /// Frame of the touchdowns and of the assessment (the body frame from leg kinematics, x
    /// forward, y left, z up). Default `base_link` (REP-105).
    pub body_frame: String,
}

impl Default for TerrainConfig {
    fn default() -> Self {
        TerrainConfig {
            sigma_flat: 0.010,
            plane_offset_max: 0.010,
            sigma_wave: 0.025,
            sigma_max: 0.040,
            epsilon_alpha: 3.0 * DEG,
            tilt_max: 15.0 * DEG,
            body_points: [0.10, 0.0, 0.0, -0.10, 0.08, 0.0, -0.10, -0.08, 0.0],
            body_frame: "base_link".to_owned(),
        }
    }
}

fn check(name: &'static str, value: f64, ok: bool, reason: &'static str) -> Result<(), TerrainError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(TerrainError::InvalidConfig { name, value, reason })
    }
}

impl TerrainConfig {
    /// What in this configuration does not fit `geometry`, as sentences for a log (empty when
    /// all fits): σ_flat below the σ that a plane tilted by ε_α gives with these footholds
    /// (their [largest directional spread](HexapodGeometry::largest_spread) × tan ε_α), where a
    /// coplanar stance within ε_α would be refused as UNEVEN by σ alone. Not an error: the
    /// configuration still works, FLAT is only stricter than ε_α says.
    pub fn warnings(&self, geometry: &HexapodGeometry) -> Vec<String> {
        let mut out = Vec::new();
        let needed = geometry.largest_spread() * self.epsilon_alpha.tan();
        if self.sigma_flat < needed {
            out.push(format!(
                "sigma_flat = {} m is below the {:.4} m that a plane tilted by epsilon_alpha gives \
                 with these footholds (largest spread {:.4} m × tan epsilon_alpha): a coplanar \
                 stance within epsilon_alpha may be classed UNEVEN; raise sigma_flat to at least that",
                self.sigma_flat,
                needed,
                geometry.largest_spread()
            ));
        }
        out
    }

    /// The three body points.
    pub fn body_points(&self) -> [Point3<f64>; 3] {
        let p = &self.body_points;
        [
            Point3::new(p[0], p[1], p[2]),
            Point3::new(p[3], p[4], p[5]),
            Point3::new(p[6], p[7], p[8]),
        ]
    }

    /// Checks 0 < σ_flat ≤ σ_wave ≤ σ_max, plane_offset_max > 0, 0 < ε_α < tilt_max < 90°,
    /// finite body points and a non-empty frame name. Degenerate body points are refused by
    /// [`Assessor::new`](crate::Assessor::new), which builds plane 3.
    pub fn validate(&self) -> Result<(), TerrainError> {
        check("sigma_flat", self.sigma_flat, self.sigma_flat > 0.0, "must be > 0")?;
        check(
            "plane_offset_max",
            self.plane_offset_max,
            self.plane_offset_max > 0.0,
            "must be > 0",
        )?;
        check(
            "sigma_wave",
            self.sigma_wave,
            self.sigma_wave >= self.sigma_flat,
            "must be ≥ sigma_flat",
        )?;
        check(
            "sigma_max",
            self.sigma_max,
            self.sigma_max >= self.sigma_wave,
            "must be ≥ sigma_wave",
        )?;
        check(
            "epsilon_alpha",
            self.epsilon_alpha,
            self.epsilon_alpha > 0.0 && self.epsilon_alpha < self.tilt_max,
            "must be > 0 and below tilt_max",
        )?;
        check(
            "tilt_max",
            self.tilt_max,
            self.tilt_max > 0.0 && self.tilt_max < 90.0 * DEG,
            "must be within (0, π/2)",
        )?;
        for (i, p) in self.body_points().iter().enumerate() {
            check_point(|| format!("body point {}", i + 1), p.x, p.y, p.z)?;
        }
        if self.body_frame.is_empty() {
            return Err(TerrainError::InvalidConfig {
                name: "body_frame",
                value: f64::NAN,
                reason: "must not be empty",
            });
        }
        Ok(())
    }
}

/// Nominal footholds (x, y) of the six legs in the body frame (m), as the params file writes them
/// (`footholds: {KP: [x, y], …}`).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[allow(non_snake_case)]
pub struct Footholds {
    /// Left front.
    pub KP: [f64; 2],
    /// Left middle.
    pub KV: [f64; 2],
    /// Left rear.
    pub KG: [f64; 2],
    /// Right front.
    pub DP: [f64; 2],
    /// Right middle.
    pub DV: [f64; 2],
    /// Right rear.
    pub DG: [f64; 2],
}

impl Footholds {
    /// The foothold of one leg.
    pub fn get(&self, leg: Leg) -> Point2<f64> {
        let [x, y] = match leg {
            Leg::KP => self.KP,
            Leg::KV => self.KV,
            Leg::KG => self.KG,
            Leg::DP => self.DP,
            Leg::DV => self.DV,
            Leg::DG => self.DG,
        };
        Point2::new(x, y)
    }
}

/// The hexapod's body geometry shared by the assessment's users and the walking simulator.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(default)]
pub struct HexapodGeometry {
    /// Nominal footholds (m, body frame). Default: front and rear feet at x = ±0.15 m,
    /// y = ±0.12 m, middle feet at x = 0, y = ±0.16 m (see
    /// docs/experiments/terrain-table1.md#the-thresholds).
    pub footholds: Footholds,
    /// Height (m) of the body's origin above the local ground (the mean ground height under the
    /// six nominal footholds). Default 0.10.
    pub body_height: f64,
}

impl Default for HexapodGeometry {
    fn default() -> Self {
        HexapodGeometry {
            footholds: Footholds {
                KP: [0.15, 0.12],
                KV: [0.0, 0.16],
                KG: [-0.15, 0.12],
                DP: [0.15, -0.12],
                DV: [0.0, -0.16],
                DG: [-0.15, -0.12],
            },
            body_height: 0.10,
        }
    }
}

impl HexapodGeometry {
    /// Checks finite footholds (left legs at y > 0, right legs at y < 0, within 1 km) and a
    /// finite positive body height.
    pub fn validate(&self) -> Result<(), TerrainError> {
        for leg in Leg::ALL {
            let p = self.footholds.get(leg);
            check_point(|| format!("foothold {leg}"), p.x, p.y, 0.0)?;
            let side_ok = if leg.is_left() { p.y > 0.0 } else { p.y < 0.0 };
            check(
                "footholds",
                p.y,
                side_ok,
                "left legs (K…) need y > 0, right legs (D…) y < 0",
            )?;
        }
        check("body_height", self.body_height, self.body_height > 0.0, "must be > 0")
    }

    /// Largest directional standard deviation (m) of the six footholds: the square root of the
    /// larger eigenvalue of their 2 × 2 covariance (population). A plane of slope tan θ under
    /// the feet, rising in the worst direction, gives σ = this × tan θ. Default footholds:
    /// √0.018133 = 0.1347 m (along y).
    pub fn largest_spread(&self) -> f64 {
        let p = Leg::ALL.map(|leg| self.footholds.get(leg));
        let (mx, my) = (
            p.iter().map(|q| q.x).sum::<f64>() / 6.0,
            p.iter().map(|q| q.y).sum::<f64>() / 6.0,
        );
        let (mut vx, mut vy, mut cxy) = (0.0, 0.0, 0.0);
        for q in &p {
            let (dx, dy) = (q.x - mx, q.y - my);
            vx += dx * dx / 6.0;
            vy += dy * dy / 6.0;
            cxy += dx * dy / 6.0;
        }
        let half_diff = (vx - vy) / 2.0;
        ((vx + vy) / 2.0 + (half_diff * half_diff + cxy * cxy).sqrt()).sqrt()
    }

    /// The nominal feet on flat ground: the footholds at z = −body_height, in [`Leg::ALL`] order.
    pub fn standing_feet(&self) -> [Point3<f64>; 6] {
        Leg::ALL.map(|leg| {
            let p = self.footholds.get(leg);
            Point3::new(p.x, p.y, -self.body_height)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid() {
        assert_eq!(TerrainConfig::default().validate(), Ok(()));
        assert_eq!(HexapodGeometry::default().validate(), Ok(()));
    }

    #[test]
    fn inconsistent_thresholds_are_refused() {
        let c = TerrainConfig {
            sigma_max: 0.015,
            ..TerrainConfig::default()
        };
        assert!(matches!(
            c.validate(),
            Err(TerrainError::InvalidConfig { name: "sigma_max", .. })
        ));
        let c = TerrainConfig {
            epsilon_alpha: f64::NAN,
            ..TerrainConfig::default()
        };
        assert!(matches!(
            c.validate(),
            Err(TerrainError::InvalidConfig {
                name: "epsilon_alpha",
                ..
            })
        ));
        let mut c = TerrainConfig::default();
        c.body_points[4] = f64::INFINITY;
        assert!(matches!(c.validate(), Err(TerrainError::NonFinite { .. })));
        let mut g = HexapodGeometry::default();
        g.footholds.KV = [0.0, -0.1];
        assert!(matches!(
            g.validate(),
            Err(TerrainError::InvalidConfig { name: "footholds", .. })
        ));
    }

    /// The footholds' spread that the σ defaults quote: var(x) = 4 · 0.15² / 6 = 0.015,
    /// var(y) = (4 · 0.12² + 2 · 0.16²) / 6 = 0.018133, covariance 0 (symmetric stance); the
    /// largest directional standard deviation is √0.018133 = 0.13466 m.
    #[test]
    fn foothold_spread_matches_the_documented_figures() {
        let feet = HexapodGeometry::default().standing_feet();
        let mean = |f: &dyn Fn(&Point3<f64>) -> f64| feet.iter().map(f).sum::<f64>() / 6.0;
        let (mx, my) = (mean(&|p| p.x), mean(&|p| p.y));
        let vx = mean(&|p| (p.x - mx).powi(2));
        let vy = mean(&|p| (p.y - my).powi(2));
        assert!((vx - 0.015).abs() < 1e-12);
        assert!((vy - 0.018_133_333_333).abs() < 1e-9);
        assert!((vy.sqrt() - 0.134_66).abs() < 1e-5);
        assert!((HexapodGeometry::default().largest_spread() - 0.134_66).abs() < 1e-5);
    }

    /// Footholds sheared along x by y (x' = x + y): var(x') = var x + var y + 2 cov = 0.015 +
    /// 0.018133 = 0.033133, var(y) = 0.018133, cov(x', y) = var y = 0.018133. Larger eigenvalue
    /// (0.033133 + 0.018133)/2 + √(0.0075² + 0.018133²) = 0.025633 + 0.019623 = 0.045257:
    /// spread √0.045257 = 0.21274 m, above both axis spreads (0.1820, 0.1347), so the
    /// covariance counts.
    #[test]
    fn largest_spread_sees_the_covariance() {
        let mut g = HexapodGeometry::default();
        for leg in Leg::ALL {
            let [x, y] = match leg {
                Leg::KP => &mut g.footholds.KP,
                Leg::KV => &mut g.footholds.KV,
                Leg::KG => &mut g.footholds.KG,
                Leg::DP => &mut g.footholds.DP,
                Leg::DV => &mut g.footholds.DV,
                Leg::DG => &mut g.footholds.DG,
            };
            *x += *y;
        }
        assert!((g.largest_spread() - 0.212_74).abs() < 1e-5, "{}", g.largest_spread());
    }

    /// σ_flat (1 cm) against the footholds: the default spread 0.1347 m × tan 3° = 0.706 cm
    /// fits; footholds 1.5 times wider spread 0.2020 m, × tan 3° = 1.059 cm > 1 cm: a warning
    /// naming sigma_flat. σ_flat = 1.1 cm fits them again.
    #[test]
    fn sigma_flat_is_checked_against_the_footholds() {
        let c = TerrainConfig::default();
        assert!(c.warnings(&HexapodGeometry::default()).is_empty());
        let mut wide = HexapodGeometry::default();
        for f in [
            &mut wide.footholds.KP,
            &mut wide.footholds.KV,
            &mut wide.footholds.KG,
            &mut wide.footholds.DP,
            &mut wide.footholds.DV,
            &mut wide.footholds.DG,
        ] {
            *f = f.map(|v| v * 1.5);
        }
        let w = c.warnings(&wide);
        assert_eq!(w.len(), 1);
        assert!(
            w[0].starts_with("sigma_flat = 0.01 m is below the 0.0106 m"),
            "{}",
            w[0]
        );
        let c = TerrainConfig {
            sigma_flat: 0.011,
            ..TerrainConfig::default()
        };
        assert!(c.warnings(&wide).is_empty());
    }
}
