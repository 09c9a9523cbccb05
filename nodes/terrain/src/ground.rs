//! Height maps for the walking hexapod: flat, a plane sloped in any direction, seeded rough
//! ground, and a course of sections along world x (flat → ramp → rough for the demo).
//! Heights are z (m) in the world frame (z up) at world (x, y).

use crate::error::TerrainError;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Random rough ground: heights drawn uniformly from [−amplitude, amplitude] at the nodes of a
/// square grid, bilinear in between. Node (i, j)'s height depends only on the seed and (i, j)
/// (one ChaCha8 stream per node), so the ground is unbounded, deterministic and needs no memory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoughGround {
    amplitude: f64,
    cell: f64,
    seed: u64,
}

impl RoughGround {
    /// Rough ground with node heights in [−amplitude, amplitude] (m, ≥ 0) every `cell` m (> 0).
    pub fn new(amplitude: f64, cell: f64, seed: u64) -> Result<Self, TerrainError> {
        positive("rough amplitude", amplitude, true)?;
        positive("rough cell", cell, false)?;
        Ok(RoughGround { amplitude, cell, seed })
    }

    /// The largest |height| (m).
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// The grid's cell size (m).
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// Height of grid node (i, j) (m).
    pub fn node(&self, i: i64, j: i64) -> f64 {
        if self.amplitude == 0.0 {
            return 0.0;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        // Two 32-bit halves: every node of a ±2·10⁹-cell grid has its own stream.
        rng.set_stream(((i as u32 as u64) << 32) | (j as u32 as u64));
        rng.random_range(-self.amplitude..=self.amplitude)
    }

    /// Height at (x, y) (m): bilinear between the four surrounding nodes.
    pub fn height(&self, x: f64, y: f64) -> f64 {
        let (u, v) = (x / self.cell, y / self.cell);
        let (i, j) = (u.floor(), v.floor());
        let (fu, fv) = (u - i, v - j);
        let (i, j) = (i as i64, j as i64);
        let h00 = self.node(i, j);
        let h10 = self.node(i + 1, j);
        let h01 = self.node(i, j + 1);
        let h11 = self.node(i + 1, j + 1);
        h00 * (1.0 - fu) * (1.0 - fv) + h10 * fu * (1.0 - fv) + h01 * (1.0 - fu) * fv + h11 * fu * fv
    }
}

/// One section of a [`Course`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Section {
    /// Level ground.
    Flat,
    /// A plane rising along +x at this angle (rad; negative descends).
    Ramp(f64),
    /// Rough ground around the level the previous section ended at, its roughness tapered
    /// linearly from 0 to full over its first grid cell and back to 0 over its last (a last
    /// section runs on and has no end taper), so that the course has no step at its ends.
    Rough(RoughGround),
}

/// Sections one after another along world x from `start_x`, each continuing at the height the
/// previous one ended (a rough section ends at its base height). Before `start_x` the first
/// section's start height holds (0); the last section runs on for ever.
#[derive(Debug, Clone, PartialEq)]
pub struct Course {
    start_x: f64,
    sections: Vec<(f64, Section)>,
}

impl Course {
    /// A course of `(length m, section)` from `start_x`; needs at least one section, positive
    /// finite lengths and ramps steeper than −90° and less than 90°.
    pub fn new(start_x: f64, sections: Vec<(f64, Section)>) -> Result<Self, TerrainError> {
        finite("course start_x", start_x)?;
        if sections.is_empty() {
            return Err(TerrainError::InvalidConfig {
                name: "course",
                value: 0.0,
                reason: "needs at least one section",
            });
        }
        for (length, section) in &sections {
            positive("course section length", *length, false)?;
            if let Section::Ramp(angle) = section
                && !(angle.is_finite() && angle.abs() < std::f64::consts::FRAC_PI_2)
            {
                return Err(TerrainError::InvalidConfig {
                    name: "ramp angle",
                    value: *angle,
                    reason: "must be within (−π/2, π/2)",
                });
            }
        }
        Ok(Course { start_x, sections })
    }

    /// The section under world x and the x where it starts.
    pub fn section_at(&self, x: f64) -> (f64, Section) {
        let mut s = self.start_x;
        let last = self.sections.len() - 1;
        for (k, (length, section)) in self.sections.iter().enumerate() {
            if x < s + length || k == last {
                return (s, *section);
            }
            s += length;
        }
        (s, self.sections[last].1)
    }

    /// Height at (x, y) (m).
    pub fn height(&self, x: f64, y: f64) -> f64 {
        let mut s = self.start_x;
        let mut base = 0.0;
        let last = self.sections.len() - 1;
        for (k, (length, section)) in self.sections.iter().enumerate() {
            if x < s + length || k == last {
                let u = (x - s).max(0.0);
                return base
                    + match section {
                        Section::Flat => 0.0,
                        Section::Ramp(angle) => angle.tan() * u,
                        Section::Rough(r) => {
                            let from_start = u / r.cell();
                            let taper = if k == last {
                                from_start
                            } else {
                                from_start.min((length - u) / r.cell())
                            };
                            taper.clamp(0.0, 1.0) * r.height(x, y)
                        }
                    };
            }
            if let Section::Ramp(angle) = section {
                base += angle.tan() * length;
            }
            s += length;
        }
        base
    }
}

/// The ground the hexapod walks on.
#[derive(Debug, Clone, PartialEq)]
pub enum Ground {
    /// Level ground at this height (m).
    Flat(f64),
    /// A plane through the origin at height 0, inclined by `slope` (rad, in [0, π/2)) and
    /// rising toward the world direction `uphill` (rad).
    Plane {
        /// Inclination (rad).
        slope: f64,
        /// Direction in which the ground rises (rad, world frame).
        uphill: f64,
    },
    /// Seeded rough ground.
    Rough(RoughGround),
    /// Sections along world x.
    Course(Course),
}

impl Ground {
    /// A plane inclined by `slope` (rad) rising toward `uphill` (rad); refused unless
    /// 0 ≤ slope < π/2 and both are finite.
    pub fn plane(slope: f64, uphill: f64) -> Result<Self, TerrainError> {
        if !(slope.is_finite() && (0.0..std::f64::consts::FRAC_PI_2).contains(&slope)) {
            return Err(TerrainError::InvalidConfig {
                name: "slope",
                value: slope,
                reason: "must be within [0, π/2)",
            });
        }
        finite("uphill", uphill)?;
        Ok(Ground::Plane { slope, uphill })
    }

    /// Height at world (x, y) (m).
    pub fn height(&self, x: f64, y: f64) -> f64 {
        match self {
            Ground::Flat(h) => *h,
            Ground::Plane { slope, uphill } => slope.tan() * (x * uphill.cos() + y * uphill.sin()),
            Ground::Rough(r) => r.height(x, y),
            Ground::Course(c) => c.height(x, y),
        }
    }
}

fn finite(name: &'static str, value: f64) -> Result<f64, TerrainError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(TerrainError::InvalidConfig {
            name,
            value,
            reason: "must be finite",
        })
    }
}

fn positive(name: &'static str, value: f64, zero_ok: bool) -> Result<f64, TerrainError> {
    if value.is_finite() && (value > 0.0 || (zero_ok && value == 0.0)) {
        Ok(value)
    } else {
        Err(TerrainError::InvalidConfig {
            name,
            value,
            reason: if zero_ok {
                "must be finite and ≥ 0"
            } else {
                "must be finite and > 0"
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rough_ground_is_seeded_bounded_and_bilinear() {
        let r = RoughGround::new(0.04, 0.1, 7).unwrap();
        let again = RoughGround::new(0.04, 0.1, 7).unwrap();
        let other = RoughGround::new(0.04, 0.1, 8).unwrap();
        assert_eq!(r.node(3, -2), again.node(3, -2));
        assert_ne!(r.node(3, -2), other.node(3, -2));
        // At a node the height is the node's; halfway between two nodes, their mean.
        // (0.3 / 0.1 is 2.9999999999999996 in floating point: node 3 is reached from cell 2.)
        assert!((r.height(0.3, -0.2) - r.node(3, -2)).abs() < 1e-12);
        let mid = r.height(0.35, -0.2);
        assert!((mid - 0.5 * (r.node(3, -2) + r.node(4, -2))).abs() < 1e-12);
        // 1000 nodes: all within ±amplitude; their mean near 0 and their standard deviation
        // near a/√3 = 0.0231 (uniform), within 3 standard errors.
        let h: Vec<f64> = (0..1000).map(|k| r.node(k % 40 - 20, k / 40 - 12)).collect();
        assert!(h.iter().all(|z| z.abs() <= 0.04));
        let mean = h.iter().sum::<f64>() / 1000.0;
        let sd = (h.iter().map(|z| (z - mean).powi(2)).sum::<f64>() / 1000.0).sqrt();
        assert!(mean.abs() < 3.0 * 0.0231 / 1000f64.sqrt(), "mean {mean}");
        assert!((sd - 0.0231).abs() < 0.0015, "sd {sd}");
    }

    /// Flat 1 m from x = 0, a 10° ramp 2 m long, then flat: heights 0, tan 10° · 1 = 0.1763 at
    /// x = 2, and 2 · tan 10° = 0.3527 from x = 3 on; 0 before the start.
    #[test]
    fn course_heights_are_continuous() {
        let c = Course::new(
            0.0,
            vec![
                (1.0, Section::Flat),
                (2.0, Section::Ramp(10f64.to_radians())),
                (1.0, Section::Flat),
            ],
        )
        .unwrap();
        let t = 10f64.to_radians().tan();
        assert_eq!(c.height(-5.0, 0.0), 0.0);
        assert_eq!(c.height(0.5, 1.0), 0.0);
        assert!((c.height(2.0, 0.0) - t).abs() < 1e-12);
        assert!((c.height(3.0, 0.0) - 2.0 * t).abs() < 1e-12);
        assert!((c.height(9.0, -3.0) - 2.0 * t).abs() < 1e-12);
        assert!(matches!(c.section_at(2.5), (s, Section::Ramp(_)) if s == 1.0));
    }

    /// Flat to x = 1, rough (±5 cm, 0.10 m cells) from 1 to 2, flat after. Untapered, the
    /// height would jump from 0 to the rough ground's (up to 5 cm) at x = 1 and back at x = 2.
    /// Tapered over one cell, within δ of either end it is at most 0.05 · δ / 0.10 (δ = 1 µm:
    /// 5e-7 m) from the base 0; halfway into the first cell (x = 1.05) half the rough height;
    /// from one cell in (x = 1.1 … 1.9) the rough height itself.
    #[test]
    fn a_rough_section_is_tapered_to_its_neighbours() {
        let r = RoughGround::new(0.05, 0.10, 11).unwrap();
        let c = Course::new(
            0.0,
            vec![(1.0, Section::Flat), (1.0, Section::Rough(r)), (1.0, Section::Flat)],
        )
        .unwrap();
        let ys = [-0.33, -0.1, 0.0, 0.17, 0.42];
        // The step the taper removes: the rough ground at the ends is not near 0 everywhere.
        assert!(ys
            .iter()
            .any(|&y| r.height(1.0, y).abs() > 1e-3 && r.height(2.0, y).abs() > 1e-3));
        let d = 1e-6;
        for y in ys {
            for x in [1.0 - d, 1.0, 1.0 + d, 2.0 - d, 2.0, 2.0 + d] {
                assert!(c.height(x, y).abs() <= 5e-7 + 1e-15, "x {x}, y {y}: {}", c.height(x, y));
            }
            assert!((c.height(1.05, y) - 0.5 * r.height(1.05, y)).abs() < 1e-12);
            assert!((c.height(1.95, y) - 0.5 * r.height(1.95, y)).abs() < 1e-12);
            for x in [1.1, 1.5, 1.9] {
                assert!((c.height(x, y) - r.height(x, y)).abs() < 1e-12, "x {x}");
            }
        }
        // A rough last section tapers in only: full height from one cell in, for ever.
        let c = Course::new(0.0, vec![(1.0, Section::Flat), (0.5, Section::Rough(r))]).unwrap();
        assert!(c.height(1.0 + d, 0.17).abs() <= 5e-7 + 1e-15);
        assert!((c.height(7.3, 0.17) - r.height(7.3, 0.17)).abs() < 1e-12);
    }

    /// A 10° plane rising toward 90° (world +y): z = tan 10° · y.
    #[test]
    fn plane_rises_toward_uphill() {
        let g = Ground::plane(10f64.to_radians(), std::f64::consts::FRAC_PI_2).unwrap();
        assert!((g.height(5.0, 1.0) - 0.176_327).abs() < 1e-6);
        assert!(g.height(5.0, 0.0).abs() < 1e-12);
        assert!(Ground::plane(f64::NAN, 0.0).is_err());
        assert!(RoughGround::new(-0.1, 0.1, 0).is_err());
        assert!(Course::new(0.0, vec![]).is_err());
    }
}
