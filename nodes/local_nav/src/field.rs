//! The vector-distance function F = Σ f_i·w_i (eq. 3.50–3.57) and its weight sets.

use crate::config::ConfigError;
use crate::sectors::Sectors;
use nalgebra::Vector2;
use std::f64::consts::{PI, TAU};

/// Which way the asymmetric weights turn the robot (the side the large weights w'_1… pull to).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Left-turning set (eq. 3.56): w'_1, w'_2, … on the left sectors N−1, N−2, …; the obstacle
    /// stays on the robot's right.
    Left,
    /// Right-turning set (eq. 3.57): sector i carries w'_i; the obstacle stays on the left.
    Right,
}

/// The weights w'_0 … w'_{N−1} of the right-turning set, checked against eq. 3.53–3.55
/// generalised to N sectors (h = ⌊N/2⌋):
/// - 3.53: w'_0 > w'_i for every i ≠ 0;
/// - 3.54: w'_i ≥ w'_{N−i} for 0 < i < N − i, strictly for i = 1;
/// - 3.55: w'_1 > w'_2 ≥ w'_3 ≥ … ≥ w'_h.
#[derive(Debug, Clone, PartialEq)]
pub struct WeightProfile {
    weights: Vec<f64>,
}

impl WeightProfile {
    /// Checks a profile (finite, ≥ 0, eq. 3.53–3.55); at least 4 weights.
    pub fn new(weights: Vec<f64>) -> Result<Self, ConfigError> {
        let n = weights.len();
        if !(4..=360).contains(&n) {
            return Err(ConfigError::SectorCount(n));
        }
        for (index, &value) in weights.iter().enumerate() {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ConfigError::BadWeight { index, value });
            }
        }
        for i in 1..n {
            if weights[0] <= weights[i] {
                return Err(ConfigError::WeightOrder {
                    equation: "3.53",
                    detail: format!("w'0 = {} must exceed w'{i} = {}", weights[0], weights[i]),
                });
            }
        }
        for i in (1..n).take_while(|&i| i < n - i) {
            let (a, b) = (weights[i], weights[n - i]);
            if a < b || (i == 1 && a <= b) {
                return Err(ConfigError::WeightOrder {
                    equation: "3.54",
                    detail: format!(
                        "w'{i} = {a} must {} w'{} = {b}",
                        if i == 1 { "exceed" } else { "be ≥" },
                        n - i
                    ),
                });
            }
        }
        let h = n / 2;
        for i in 1..h {
            let (a, b) = (weights[i], weights[i + 1]);
            if a < b || (i == 1 && a <= b) {
                return Err(ConfigError::WeightOrder {
                    equation: "3.55",
                    detail: format!(
                        "w'{i} = {a} must {} w'{} = {b}",
                        if i == 1 { "exceed" } else { "be ≥" },
                        i + 1
                    ),
                });
            }
        }
        Ok(WeightProfile { weights })
    }

    /// The default profile for N sectors: w'_0 = 1; on the turning side w'_i = 0.1 + 0.9·(1 − a/π)
    /// at the sector's angle a = i·2π/N from the goal (falling linearly to 0.1 behind), and half
    /// that on the other side (w'_{N−i} = w'_i / 2). For N = 8: [1, 0.775, 0.55, 0.325, 0.1,
    /// 0.1625, 0.275, 0.3875]. Why: the goal direction dominates (3.53), pull falls off with the
    /// angle from the goal (3.55), and the 2 : 1 ratio between the sides leaves a wall square to
    /// the goal line a net sideways pull of half the turning side's (3.54: no stall).
    /// `n` is clamped to 4…360.
    pub fn linear(n: usize) -> Self {
        let n = n.clamp(4, 360);
        let mut weights = vec![0.0; n];
        weights[0] = 1.0;
        for i in 1..=n / 2 {
            let a = i as f64 * TAU / n as f64;
            let w = 0.1 + 0.9 * (1.0 - a / PI);
            weights[i] = w;
            if n - i != i {
                weights[n - i] = 0.5 * w;
            }
        }
        WeightProfile { weights }
    }

    /// Number of weights (= sectors).
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// Always false (at least 4 weights).
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// The profile w'_0 … w'_{N−1}.
    pub fn as_slice(&self) -> &[f64] {
        &self.weights
    }

    /// The weight sector i carries: w'_i (right-turning, 3.57), w'_{(N−i) mod N} (left-turning,
    /// 3.56), or the mean of the two (symmetric, used in R-mode, where no side has been chosen).
    pub fn weight(&self, side: Option<Side>, i: usize) -> f64 {
        let n = self.weights.len();
        let i = i % n;
        let mirror = (n - i) % n;
        match side {
            Some(Side::Right) => self.weights[i],
            Some(Side::Left) => self.weights[mirror],
            None => 0.5 * (self.weights[i] + self.weights[mirror]),
        }
    }
}

/// F = Σ f_i·w_i in the base frame (eq. 3.50), f_i along sector i's centre with
/// |f_i| = min(d_i, d_sa) (3.52); `side` picks the weight set (None: symmetric).
/// The sectors and the profile must have the same length (the navigator's config ensures it);
/// extra sectors or weights are ignored.
pub fn vector_distance(
    sectors: &Sectors,
    weights: &WeightProfile,
    side: Option<Side>,
    safe_distance: f64,
) -> Vector2<f64> {
    let n = sectors.len().min(weights.len());
    let mut f = Vector2::zeros();
    for i in 0..n {
        let magnitude = sectors.effective_distance(i).min(safe_distance);
        let (s, c) = sectors.bearing(i).sin_cos();
        f += Vector2::new(c, s) * (magnitude * weights.weight(side, i));
    }
    f
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::sectors::UnseenSectors;
    use approx::assert_relative_eq;
    use mobil_geom::{Pose2, Scan};

    /// Eight beams exactly on the sector centres (sector i at −45°·i), ranges given per sector.
    pub(crate) fn eight(d: [f32; 8]) -> Sectors {
        // Beam k looks at −180° + 45°·k.
        let mut ranges = vec![0.0f32; 8];
        for (i, &r) in d.iter().enumerate() {
            let deg = -45 * i as i32;
            let k = ((deg + 180).rem_euclid(360) / 45) as usize;
            ranges[k] = r;
        }
        let scan = Scan::new(-PI, 0.75 * PI, PI / 4.0, 0.05, 10.0, ranges, vec![], Pose2::identity()).unwrap();
        Sectors::compute(&scan, 0.0, 8, UnseenSectors::Blocked)
    }

    #[test]
    fn default_profile_satisfies_the_inequalities() {
        let w = WeightProfile::linear(8);
        let expect = [1.0, 0.775, 0.55, 0.325, 0.1, 0.1625, 0.275, 0.3875];
        for (a, b) in w.as_slice().iter().zip(expect) {
            assert_relative_eq!(*a, b, epsilon = 1e-12);
        }
        assert!(WeightProfile::new(w.as_slice().to_vec()).is_ok());
        for n in [4, 5, 12, 16, 36, 360] {
            assert!(
                WeightProfile::new(WeightProfile::linear(n).as_slice().to_vec()).is_ok(),
                "n = {n}"
            );
        }
    }

    #[test]
    fn weights_breaking_3_53_to_3_55_are_refused() {
        let bad = |w: [f64; 8]| match WeightProfile::new(w.to_vec()) {
            Err(ConfigError::WeightOrder { equation, .. }) => equation,
            other => panic!("{other:?}"),
        };
        // w'1 = w'0.
        assert_eq!(bad([1.0, 1.0, 0.5, 0.3, 0.1, 0.1, 0.2, 0.4]), "3.53");
        // Symmetric: w'1 = w'7.
        assert_eq!(bad([1.0, 0.8, 0.5, 0.3, 0.1, 0.3, 0.5, 0.8]), "3.54");
        // w'2 < w'6.
        assert_eq!(bad([1.0, 0.8, 0.5, 0.3, 0.1, 0.1, 0.6, 0.4]), "3.54");
        // w'2 = w'1.
        assert_eq!(bad([1.0, 0.8, 0.8, 0.3, 0.1, 0.1, 0.2, 0.4]), "3.55");
        // w'4 > w'3.
        assert_eq!(bad([1.0, 0.8, 0.5, 0.3, 0.4, 0.1, 0.2, 0.4]), "3.55");
        assert!(matches!(
            WeightProfile::new(vec![1.0, 0.8, f64::NAN, 0.3, 0.1, 0.1, 0.2, 0.4]),
            Err(ConfigError::BadWeight { index: 2, .. })
        ));
        // Equalities allowed by ≥ pass: w'2 = w'3 = w'4, w'3 = w'5, w'2 = w'6.
        assert!(WeightProfile::new(vec![1.0, 0.8, 0.3, 0.3, 0.3, 0.3, 0.3, 0.4]).is_ok());
    }

    #[test]
    fn left_set_mirrors_the_right_set() {
        let w = WeightProfile::linear(8);
        // Eq. 3.56: sensor 7 carries w'1, sensor 6 w'2, sensor 1 w'7, sensor 0 w'0.
        assert_eq!(w.weight(Some(Side::Left), 7), w.as_slice()[1]);
        assert_eq!(w.weight(Some(Side::Left), 6), w.as_slice()[2]);
        assert_eq!(w.weight(Some(Side::Left), 1), w.as_slice()[7]);
        assert_eq!(w.weight(Some(Side::Left), 0), 1.0);
        assert_eq!(w.weight(Some(Side::Right), 1), w.as_slice()[1]);
        assert_relative_eq!(w.weight(None, 1), 0.5 * (0.775 + 0.3875));
    }

    #[test]
    fn field_by_hand() {
        // d = [0.4, 0.8, 2, 2, 2, 2, 2, 0.2], d_sa = 0.8 → |f| = [0.4, 0.8, 0.8, 0.8, 0.8, 0.8,
        // 0.8, 0.2]. Right-turning weights [1, .775, .55, .325, .1, .1625, .275, .3875]:
        // |f|·w = [0.4, 0.62, 0.44, 0.26, 0.08, 0.13, 0.22, 0.0775] at 0°, −45°, −90°, −135°,
        // 180°, 135°, 90°, 45°. With c = cos 45° = 0.70710678:
        // x = 0.4 − 0.08 + c·(0.62 − 0.26 − 0.13 + 0.0775) = 0.32 + 0.3075c = 0.537435
        // y = −0.44 + 0.22 + c·(−0.62 − 0.26 + 0.13 + 0.0775) = −0.22 − 0.6725c = −0.695529
        let s = eight([0.4, 0.8, 2.0, 2.0, 2.0, 2.0, 2.0, 0.2]);
        let w = WeightProfile::linear(8);
        let f = vector_distance(&s, &w, Some(Side::Right), 0.8);
        assert_relative_eq!(f.x, 0.537_435, epsilon = 1e-6);
        assert_relative_eq!(f.y, -0.695_529, epsilon = 1e-6);
        // Left-turning: sector i carries w'_{8−i}: weights [1, .3875, .275, .1625, .1, .325, .55,
        // .775] → |f|·w = [0.4, 0.31, 0.22, 0.13, 0.08, 0.26, 0.44, 0.155]:
        // x = 0.32 + c·(0.31 − 0.13 − 0.26 + 0.155) = 0.32 + 0.075c = 0.373033
        // y = −0.22 + 0.44 + c·(−0.31 − 0.13 + 0.26 + 0.155) = 0.22 − 0.025c = 0.202322
        let f = vector_distance(&s, &w, Some(Side::Left), 0.8);
        assert_relative_eq!(f.x, 0.373_033, epsilon = 1e-6);
        assert_relative_eq!(f.y, 0.202_322, epsilon = 1e-6);
    }

    #[test]
    fn wide_wall_stalls_symmetric_weights_but_not_asymmetric_ones() {
        // A wall square to the goal line: sector 0 at 0.3, sectors 1 and 7 at 0.3·√2 = 0.424,
        // the rest free. Symmetric weights: y cancels exactly.
        let s = eight([0.3, 0.424, 2.0, 2.0, 2.0, 2.0, 2.0, 0.424]);
        let w = WeightProfile::linear(8);
        let f = vector_distance(&s, &w, None, 0.8);
        assert!(f.y.abs() < 1e-12, "{f}");
        // Left-turning: y = 0.8·(w'2 − w'6) + c·(0.424·(w'1 − w'7) + 0.8·(w'3 − w'5))
        //   = 0.8·0.275 + c·(0.424·0.3875 + 0.8·0.1625) = 0.22 + c·0.2943 = 0.428102.
        let f = vector_distance(&s, &w, Some(Side::Left), 0.8);
        assert_relative_eq!(f.y, 0.428_102, epsilon = 1e-5);
        let f = vector_distance(&s, &w, Some(Side::Right), 0.8);
        assert_relative_eq!(f.y, -0.428_102, epsilon = 1e-5);
    }
}
