//! Configuration of the navigator, validated once: sector count, weight profile (eq. 3.53–3.55),
//! distances, step counters and thresholds. Every default is justified on its field or on the
//! docs page it cites.

use crate::field::WeightProfile;
use crate::sectors::UnseenSectors;
use thiserror::Error;

/// Why a configuration is refused.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ConfigError {
    /// The sector count is outside 4…360.
    #[error("sector_count {0} must be within 4..=360")]
    SectorCount(usize),
    /// The weight profile does not have one weight per sector.
    #[error("{weights} weights for {sectors} sectors (need one per sector)")]
    WeightCount {
        /// Number of weights.
        weights: usize,
        /// Number of sectors.
        sectors: usize,
    },
    /// A weight is negative or not finite.
    #[error("weight w'{index} = {value} must be finite and ≥ 0")]
    BadWeight {
        /// Index of the weight.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The weights break one of the inequalities 3.53–3.55.
    #[error("weights break eq. {equation}: {detail}")]
    WeightOrder {
        /// The equation number broken (3.53, 3.54 or 3.55).
        equation: &'static str,
        /// Which weights, with their values.
        detail: String,
    },
    /// A `track_method` that names no method.
    #[error("track_method `{0}` is not one of tangent, vector_distance, off")]
    UnknownTrackMethod(String),
    /// A length or threshold is out of range or inconsistent with another.
    #[error("{name} = {value}: {reason}")]
    Value {
        /// The field's name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The rule it breaks.
        reason: &'static str,
    },
}

/// How T-mode (004 §4.2.4 step 4) chooses the direction along the obstacle's boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TrackMethod {
    /// The tangent of the nearest reading, bent toward or away from the boundary by
    /// `track_gain`·(d − d_sa): the boundary is kept at d_sa on the side opposite the chosen one.
    #[default]
    Tangent,
    /// The vector-distance function, eq. 3.50, as step 4 of §4.2.4 says: F with the asymmetric
    /// weights of the side L-mode chose, w'0 turned toward G at every step as in R-mode (the
    /// source neither locks nor re-aims the weights in T-mode; this reading uses nothing it
    /// does not define). `track_gain` plays no part.
    VectorDistance,
    /// No T-mode (rotate and lock only, the ablation of 004 §4.3.3): where T-mode would begin,
    /// L-mode goes on (with a new progress window when eq. 3.58 held, with the stalled command
    /// when the lock stalled). Without T-mode there is no no-path verdict either, so a goal
    /// with no way round runs until something else ends it: for experiments, not for robots.
    Off,
}

impl TrackMethod {
    /// Every method, in the order of their names in [`TrackMethod::NAMES`].
    pub const ALL: [TrackMethod; 3] = [TrackMethod::Tangent, TrackMethod::VectorDistance, TrackMethod::Off];
    /// The parameter values, one per method.
    pub const NAMES: [&'static str; 3] = ["tangent", "vector_distance", "off"];

    /// The parameter value: `tangent`, `vector_distance` or `off`.
    pub fn name(self) -> &'static str {
        match self {
            TrackMethod::Tangent => Self::NAMES[0],
            TrackMethod::VectorDistance => Self::NAMES[1],
            TrackMethod::Off => Self::NAMES[2],
        }
    }
}

impl std::fmt::Display for TrackMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for TrackMethod {
    type Err = ConfigError;
    fn from_str(s: &str) -> Result<Self, ConfigError> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| ConfigError::UnknownTrackMethod(s.to_string()))
    }
}

/// Everything the navigator needs besides the chassis limits.
#[derive(Debug, Clone, PartialEq)]
pub struct NavConfig {
    /// Number of sectors N. Default 8 (× 45°): the eight sensors of the source (eq. 3.50).
    pub sector_count: usize,
    /// Weights w'_0 … w'_{N−1} of the right-turning set (eq. 3.57); the left-turning set is its
    /// mirror (eq. 3.56). Default [`WeightProfile::linear`].
    pub weights: WeightProfile,
    /// Sectors without a valid reading (outside the field of view): blocked (|f| = 0), the SPEC's
    /// default, or free.
    pub unseen: UnseenSectors,
    /// Radius (m) of the circle around the robot's body, centred on the reference point.
    /// Default 0.25: OMR-III (`params/omr3.yaml`); MOBIL-II sets 0.53.
    pub robot_radius: f64,
    /// Hard stop distance (m) from the centre: nothing in the corridor ahead nearer than this, or
    /// forward motion is zero (the LOW-LEVEL emergency state). Default 0.35 = robot radius + 0.10 m,
    /// the braking distance from a creeping speed with margin for a scan's age at 40 Hz.
    pub stop_distance: f64,
    /// Safe distance d_sa (m), eq. 3.52; must exceed the stop distance. Default 0.80: the robot
    /// radius plus 0.55 m, which at v_max = 0.5 m/s leaves over a second to turn away before the
    /// hard stop, and is the distance the boundary is tracked at in T-mode.
    pub safe_distance: f64,
    /// Hysteresis (m) added to d_sa before a blocked sector counts as clear again (L → R, and the
    /// T-mode goal-sector leave). Default 0.20: four times ds and above the tracking error at
    /// d_sa, so a robot hugging a wall at d_sa does not flicker between modes.
    pub release_hysteresis: f64,
    /// Path increment ds (m) that makes one step (SPEC Decision). Default 0.05: 2.5 cycles of a
    /// 20 Hz loop at 0.5 m/s, and well below d_sa so the counters resolve the obstacle's scale.
    pub step_length: f64,
    /// n: steps of L-mode over which the progress must reach c1 (eq. 3.58). Default 40 (2 m of
    /// path): long enough to go round a convex obstacle's near side before judging the side.
    pub lock_steps: u32,
    /// c1 (m): least progress toward G over n steps in L-mode; less makes the hit point H
    /// (eq. 3.58). Default 0.30: sliding along a wall square to the goal line gains ~0 m in 2 m,
    /// going round a convex obstacle gains well over 0.3 m.
    pub lock_min_progress: f64,
    /// m: steps of T-mode over which the progress must reach c2 (eq. 3.60). Default 600 (30 m of
    /// path): going round an obstacle takes the robot away from G for a long time, so m must be
    /// large (SPEC); the return to H is the main no-path test.
    pub track_steps: u32,
    /// Speed (m/s) below which an L-mode command counts as a stall: the lock cannot make progress
    /// where it stands, so that point is the hit point H at once (a stalled robot makes no path,
    /// so the n-step test of eq. 3.58 alone would never fire). Default 0.02: at that speed the n
    /// steps (2 m) would take 100 s.
    pub stall_speed: f64,
    /// Car-like chassis: the least speed (m/s), ≥ 0, of a turn whose arc (the robot's circle swept
    /// along it) is clear of the scan points; the turn's own slow-downs never go below it, only the
    /// arc's clearance and the goal can. 0: no floor. Default 0.10, twice the average speed Nav2's
    /// progress checker asks for (see docs/local_nav_node.md, "Parameters").
    pub min_turn_speed: f64,
    /// c2 (m): least progress toward G over m steps of T-mode (eq. 3.60). Default 0.50.
    pub track_min_progress: f64,
    /// Radius (m) around H that counts as a return to it (NO_PATH) once the robot has been
    /// twice as far. Default 0.40: above the tracking error, and over 4 × ds so no step jumps it.
    pub hit_radius: f64,
    /// Distance (m) to G below which the goal is reached. Default 0.10 (Nav2's
    /// `xy_goal_tolerance` is 0.25; the chassis can do better).
    pub goal_tolerance: f64,
    /// Distance (m) to G inside which the speed falls linearly toward zero. Default 0.60.
    pub slow_down_radius: f64,
    /// Gain (rad/m), ≥ 0, of T-mode's bend b = gain·(d − d_sa) of the tracking direction toward
    /// (d > d_sa) or away from (d < d_sa) the boundary, b clamped to ±π/3. Default 1.5: the bend
    /// reaches ±π/3 at a 0.70 m error.
    pub track_gain: f64,
    /// T-mode's direction: the tangent follower (default) or eq. 3.50; `Off` disables T-mode.
    /// The default is the one the five scenarios with the 270° scanner favour
    /// (docs/experiments/local-nav.md).
    pub track_method: TrackMethod,
    /// Gain (1/s), > 0, of an omni chassis' turns: in place toward a direction outside the field
    /// of view, and in T-mode to face its direction of motion. Default 1.5.
    pub heading_gain: f64,
}

impl Default for NavConfig {
    fn default() -> Self {
        NavConfig {
            sector_count: 8,
            weights: WeightProfile::linear(8),
            unseen: UnseenSectors::Blocked,
            robot_radius: 0.25,
            stop_distance: 0.35,
            safe_distance: 0.80,
            release_hysteresis: 0.20,
            step_length: 0.05,
            lock_steps: 40,
            lock_min_progress: 0.30,
            track_steps: 600,
            track_min_progress: 0.50,
            stall_speed: 0.02,
            min_turn_speed: 0.10,
            hit_radius: 0.40,
            goal_tolerance: 0.10,
            slow_down_radius: 0.60,
            track_gain: 1.5,
            track_method: TrackMethod::Tangent,
            heading_gain: 1.5,
        }
    }
}

fn check(name: &'static str, value: f64, ok: bool, reason: &'static str) -> Result<(), ConfigError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ConfigError::Value { name, value, reason })
    }
}

impl NavConfig {
    /// Checks every rule: sector count, weights (count and eq. 3.53–3.55), and
    /// 0 ≤ robot_radius < stop_distance < safe_distance, positive step, counters and tolerances.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !(4..=360).contains(&self.sector_count) {
            return Err(ConfigError::SectorCount(self.sector_count));
        }
        if self.weights.len() != self.sector_count {
            return Err(ConfigError::WeightCount {
                weights: self.weights.len(),
                sectors: self.sector_count,
            });
        }
        check(
            "robot_radius",
            self.robot_radius,
            self.robot_radius >= 0.0,
            "must be ≥ 0",
        )?;
        check(
            "stop_distance",
            self.stop_distance,
            self.stop_distance > self.robot_radius,
            "must exceed robot_radius",
        )?;
        check(
            "safe_distance",
            self.safe_distance,
            self.safe_distance > self.stop_distance,
            "must exceed stop_distance",
        )?;
        check(
            "release_hysteresis",
            self.release_hysteresis,
            self.release_hysteresis >= 0.0,
            "must be ≥ 0",
        )?;
        check("step_length", self.step_length, self.step_length > 0.0, "must be > 0")?;
        check(
            "lock_steps",
            f64::from(self.lock_steps),
            self.lock_steps >= 1,
            "must be ≥ 1",
        )?;
        check(
            "track_steps",
            f64::from(self.track_steps),
            self.track_steps >= 1,
            "must be ≥ 1",
        )?;
        check("lock_min_progress", self.lock_min_progress, true, "must be finite")?;
        check("track_min_progress", self.track_min_progress, true, "must be finite")?;
        check("stall_speed", self.stall_speed, self.stall_speed >= 0.0, "must be ≥ 0")?;
        check(
            "min_turn_speed",
            self.min_turn_speed,
            self.min_turn_speed >= 0.0,
            "must be ≥ 0",
        )?;
        check(
            "hit_radius",
            self.hit_radius,
            self.hit_radius > self.step_length,
            "must exceed step_length",
        )?;
        check(
            "goal_tolerance",
            self.goal_tolerance,
            self.goal_tolerance > 0.0,
            "must be > 0",
        )?;
        check(
            "slow_down_radius",
            self.slow_down_radius,
            self.slow_down_radius > 0.0,
            "must be > 0",
        )?;
        check("track_gain", self.track_gain, self.track_gain >= 0.0, "must be ≥ 0")?;
        check(
            "heading_gain",
            self.heading_gain,
            self.heading_gain > 0.0,
            "must be > 0",
        )?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_valid() {
        assert_eq!(NavConfig::default().validate(), Ok(()));
    }

    #[test]
    fn inconsistent_distances_are_refused() {
        let c = NavConfig {
            safe_distance: 0.3,
            ..NavConfig::default()
        };
        assert!(matches!(
            c.validate(),
            Err(ConfigError::Value {
                name: "safe_distance",
                ..
            })
        ));
        let c = NavConfig {
            sector_count: 12,
            ..NavConfig::default()
        };
        assert_eq!(
            c.validate(),
            Err(ConfigError::WeightCount {
                weights: 8,
                sectors: 12
            })
        );
        let c = NavConfig {
            step_length: f64::NAN,
            ..NavConfig::default()
        };
        assert!(c.validate().is_err());
    }
}
