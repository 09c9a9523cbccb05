//! A planar laser scan, checked once at the edge (REP-117), with the laser's pose in the base
//! frame, so that navigation code gets beams it can trust and points in the base frame.
//!
//! REP-117 readings: `+inf` = nothing within range ([`Beam::NoEcho`]), `−inf` = too close
//! ([`Beam::TooClose`]), NaN = no valid measurement ([`Beam::Invalid`]); a finite value outside
//! `[range_min, range_max]` is no measurement either ([`Beam::OutOfLimits`], as drivers that
//! predate REP-117 encode "nothing" with such values).

use crate::pose::Pose2;
use nalgebra::Point2;
use thiserror::Error;

/// Why a scan is refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ScanError {
    /// No beams at all.
    #[error("empty scan (no ranges)")]
    Empty,
    /// The increment is zero, negative or not finite (beams must sweep counter-clockwise).
    #[error("angle_increment {0} must be finite and > 0")]
    BadIncrement(f64),
    /// `angle_min` or `angle_max` is not finite.
    #[error("angle_min {min} / angle_max {max} must be finite")]
    BadAngles {
        /// angle_min.
        min: f64,
        /// angle_max.
        max: f64,
    },
    /// `angle_max − angle_min` does not match the number of beams.
    #[error(
        "{beams} beams of {increment} rad from {min} rad end at {last} rad, but angle_max is {max} rad \
         (more than one increment off)"
    )]
    SpanMismatch {
        /// Number of ranges.
        beams: usize,
        /// angle_increment.
        increment: f64,
        /// angle_min.
        min: f64,
        /// angle_max.
        max: f64,
        /// The last beam's angle from angle_min, increment and count.
        last: f64,
    },
    /// Intensities are given, but not one per range.
    #[error("{intensities} intensities for {ranges} ranges (must be empty or one per range)")]
    IntensitiesLength {
        /// Number of ranges.
        ranges: usize,
        /// Number of intensities.
        intensities: usize,
    },
    /// range_min / range_max are not finite, range_min < 0, or range_max ≤ range_min.
    #[error("range limits [{min}, {max}] are invalid (need 0 ≤ range_min < range_max, finite)")]
    BadRangeLimits {
        /// range_min.
        min: f64,
        /// range_max.
        max: f64,
    },
}

/// What one beam says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Beam {
    /// An echo at this range (m), within [range_min, range_max].
    Hit(f64),
    /// `+inf`: nothing within range_max along the beam (free space up to range_max).
    NoEcho,
    /// `−inf`: something closer than range_min.
    TooClose,
    /// NaN: no valid measurement.
    Invalid,
    /// A finite value outside [range_min, range_max]: no measurement.
    OutOfLimits(f64),
}

/// A checked scan: angles consistent with the beams, limits valid, each beam classified.
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    angle_min: f64,
    angle_increment: f64,
    range_min: f64,
    range_max: f64,
    ranges: Vec<f32>,
    intensities: Vec<f32>,
    base_from_laser: Pose2,
}

impl Scan {
    /// Checks a scan given as LaserScan fields; `base_from_laser` is the laser's pose in the
    /// robot's base frame. `angle_max` must be the last beam's angle within one increment
    /// (drivers differ on whether it is the last beam or one past it).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        angle_min: f64,
        angle_max: f64,
        angle_increment: f64,
        range_min: f64,
        range_max: f64,
        ranges: Vec<f32>,
        intensities: Vec<f32>,
        base_from_laser: Pose2,
    ) -> Result<Scan, ScanError> {
        if ranges.is_empty() {
            return Err(ScanError::Empty);
        }
        if !(angle_increment.is_finite() && angle_increment > 0.0) {
            return Err(ScanError::BadIncrement(angle_increment));
        }
        if !(angle_min.is_finite() && angle_max.is_finite()) {
            return Err(ScanError::BadAngles {
                min: angle_min,
                max: angle_max,
            });
        }
        let last = angle_min + (ranges.len() - 1) as f64 * angle_increment;
        // One increment, plus the rounding of angles sent as f32.
        let tolerance = angle_increment + 1e-6 * (1.0 + angle_max.abs());
        if (last - angle_max).abs() > tolerance {
            return Err(ScanError::SpanMismatch {
                beams: ranges.len(),
                increment: angle_increment,
                min: angle_min,
                max: angle_max,
                last,
            });
        }
        if !intensities.is_empty() && intensities.len() != ranges.len() {
            return Err(ScanError::IntensitiesLength {
                ranges: ranges.len(),
                intensities: intensities.len(),
            });
        }
        if !(range_min.is_finite() && range_max.is_finite() && range_min >= 0.0 && range_max > range_min) {
            return Err(ScanError::BadRangeLimits {
                min: range_min,
                max: range_max,
            });
        }
        Ok(Scan {
            angle_min,
            angle_increment,
            range_min,
            range_max,
            ranges,
            intensities,
            base_from_laser,
        })
    }

    /// Number of beams (never 0).
    pub fn len(&self) -> usize {
        self.ranges.len()
    }

    /// Always false: an empty scan is refused.
    pub fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }

    /// The angle of beam `i` in the laser frame (rad).
    pub fn angle(&self, i: usize) -> f64 {
        self.angle_min + i as f64 * self.angle_increment
    }

    /// What beam `i` says (`None` past the last beam).
    pub fn beam(&self, i: usize) -> Option<Beam> {
        let r = f64::from(*self.ranges.get(i)?);
        Some(if r.is_nan() {
            Beam::Invalid
        } else if r == f64::INFINITY {
            Beam::NoEcho
        } else if r == f64::NEG_INFINITY {
            Beam::TooClose
        } else if r < self.range_min || r > self.range_max {
            Beam::OutOfLimits(r)
        } else {
            Beam::Hit(r)
        })
    }

    /// Every beam with its angle in the laser frame.
    pub fn beams(&self) -> impl Iterator<Item = (f64, Beam)> + '_ {
        (0..self.len()).filter_map(|i| Some((self.angle(i), self.beam(i)?)))
    }

    /// The intensities (empty, or one per beam).
    pub fn intensities(&self) -> &[f32] {
        &self.intensities
    }

    /// The valid range limits (m).
    pub fn range_limits(&self) -> (f64, f64) {
        (self.range_min, self.range_max)
    }

    /// The laser's pose in the base frame.
    pub fn base_from_laser(&self) -> Pose2 {
        self.base_from_laser
    }

    /// The echo of beam `i` as a point in the laser frame (`None` unless a [`Beam::Hit`]).
    pub fn point_in_laser(&self, i: usize) -> Option<Point2<f64>> {
        match self.beam(i)? {
            Beam::Hit(r) => {
                let (s, c) = self.angle(i).sin_cos();
                Some(Point2::new(r * c, r * s))
            }
            _ => None,
        }
    }

    /// Every echo as a point in the base frame.
    pub fn points_in_base(&self) -> impl Iterator<Item = Point2<f64>> + '_ {
        (0..self.len()).filter_map(|i| Some(self.base_from_laser.transform_point(self.point_in_laser(i)?)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::FRAC_PI_2;

    /// Five beams from −90° to +90° every 45°, limits [0.1, 10].
    fn five(ranges: [f32; 5]) -> Result<Scan, ScanError> {
        Scan::new(
            -FRAC_PI_2,
            FRAC_PI_2,
            FRAC_PI_2 / 2.0,
            0.1,
            10.0,
            ranges.to_vec(),
            Vec::new(),
            Pose2::new(0.3, 0.0, 0.0),
        )
    }

    #[test]
    fn beams_are_classified_by_rep_117() {
        let s = five([2.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 0.05]).unwrap();
        assert_eq!(s.beam(0), Some(Beam::Hit(2.0)));
        assert_eq!(s.beam(1), Some(Beam::NoEcho));
        assert_eq!(s.beam(2), Some(Beam::TooClose));
        assert_eq!(s.beam(3), Some(Beam::Invalid));
        assert_eq!(s.beam(4), Some(Beam::OutOfLimits(f64::from(0.05f32))));
        assert_eq!(s.beam(5), None);
        assert_eq!(
            five([12.0, 10.0, 0.1, 1.0, 1.0]).unwrap().beam(0),
            Some(Beam::OutOfLimits(12.0))
        );
        assert_eq!(
            five([12.0, 10.0, 0.1, 1.0, 1.0]).unwrap().beam(1),
            Some(Beam::Hit(10.0))
        );
        assert_relative_eq!(s.angle(3), FRAC_PI_2 / 2.0, epsilon = 1e-12);
    }

    #[test]
    fn points_land_in_the_base_frame() {
        // Laser 0.3 m ahead of base: the −90° echo at 2 m is at (0.3, −2) in base, the +45°
        // echo at √2 m at (0.3 + 1, 1).
        let s = five([2.0, f32::NAN, f32::INFINITY, 2f32.sqrt(), 0.0]).unwrap();
        let points: Vec<Point2<f64>> = s.points_in_base().collect();
        assert_eq!(points.len(), 2, "only hits become points");
        assert_relative_eq!(points[0].x, 0.3, epsilon = 1e-6);
        assert_relative_eq!(points[0].y, -2.0, epsilon = 1e-6);
        assert_relative_eq!(points[1].x, 1.3, epsilon = 1e-6);
        assert_relative_eq!(points[1].y, 1.0, epsilon = 1e-6);
    }

    #[test]
    fn malformed_scans_are_refused_with_the_reason() {
        let pose = Pose2::identity();
        let new = |min: f64, max: f64, inc: f64, rmin: f64, rmax: f64, n: usize, ni: usize| {
            Scan::new(min, max, inc, rmin, rmax, vec![1.0; n], vec![1.0; ni], pose)
        };
        assert_eq!(new(0.0, 0.0, 0.1, 0.1, 10.0, 0, 0), Err(ScanError::Empty));
        assert_eq!(new(0.0, 0.4, 0.0, 0.1, 10.0, 5, 0), Err(ScanError::BadIncrement(0.0)));
        assert_eq!(new(0.4, 0.0, -0.1, 0.1, 10.0, 5, 0), Err(ScanError::BadIncrement(-0.1)));
        assert!(matches!(
            new(0.0, 0.4, f64::NAN, 0.1, 10.0, 5, 0),
            Err(ScanError::BadIncrement(_))
        ));
        assert!(matches!(
            new(f64::NAN, 0.4, 0.1, 0.1, 10.0, 5, 0),
            Err(ScanError::BadAngles { .. })
        ));
        // 5 beams of 0.1 rad from 0 end at 0.4; angle_max 0.5 (one past) is accepted, 0.7 not.
        assert!(new(0.0, 0.4, 0.1, 0.1, 10.0, 5, 0).is_ok());
        assert!(new(0.0, 0.5, 0.1, 0.1, 10.0, 5, 0).is_ok());
        match new(0.0, 0.7, 0.1, 0.1, 10.0, 5, 0) {
            Err(ScanError::SpanMismatch { beams: 5, last, .. }) => assert_relative_eq!(last, 0.4, epsilon = 1e-12),
            other => panic!("{other:?}"),
        }
        assert_eq!(
            new(0.0, 0.4, 0.1, 0.1, 10.0, 5, 3),
            Err(ScanError::IntensitiesLength {
                ranges: 5,
                intensities: 3
            })
        );
        assert!(new(0.0, 0.4, 0.1, 0.1, 10.0, 5, 5).is_ok());
        for (rmin, rmax) in [
            (-0.1, 10.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (0.0, f64::INFINITY),
            (f64::NAN, 1.0),
        ] {
            assert!(
                matches!(
                    new(0.0, 0.4, 0.1, rmin, rmax, 5, 0),
                    Err(ScanError::BadRangeLimits { .. })
                ),
                "[{rmin}, {rmax}]"
            );
        }
    }
}
