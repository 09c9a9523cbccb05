//! The settings of VFO waypoint following as a node configures it: the law's gains,
//! Algorithm 2's, the obstacle extraction, and the shell's timing (scan timeout, optimisation
//! budget, scan placement), each a plain field with the library's default.

use std::str::FromStr;
use std::time::Duration;

use mobil_geom::Pose2;
use mobil_motion::{seconds, MAX_INPUT_TIMEOUT_S};

use super::{OptimiseConfig, ScanObstacleConfig, VfoGains, VfoSetup, DEFAULT_GUIDING};

/// How `waypoints` and `follow_waypoints` are followed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum WaypointMethod {
    /// The goal approach after the route pre-check (SPEC §4).
    #[default]
    Approach,
    /// VFO with virtual-robot optimisation round obstacles seen by the LIDAR (SPEC §5).
    Vfo,
}

impl WaypointMethod {
    /// The parameter's spelling: `approach` or `vfo`.
    pub fn as_str(self) -> &'static str {
        match self {
            WaypointMethod::Approach => "approach",
            WaypointMethod::Vfo => "vfo",
        }
    }
}

impl FromStr for WaypointMethod {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "approach" => Ok(WaypointMethod::Approach),
            "vfo" => Ok(WaypointMethod::Vfo),
            other => Err(format!("waypoint_method `{other}`: give approach or vfo")),
        }
    }
}

/// The VFO settings, each filled by one `vfo.*` parameter (defaults: the library's).
#[derive(Debug, Clone, PartialEq)]
pub struct VfoSettings {
    /// The law's gains (U_2 and |ω| are further held to the chassis: [`super::vfo_gains`]).
    pub gains: VfoGains,
    /// Algorithm 2's settings (`time_step` = the node's control period).
    pub optimise: OptimiseConfig,
    /// Obstacle extraction and merge (`robot_radius` is the node's `robot_radius`).
    pub scan: ScanObstacleConfig,
    /// μ of every waypoint (eq. 11).
    pub guiding: f64,
    /// Echoes farther than this (m) are not turned into obstacles.
    pub scan_range: f64,
    /// A VFO goal fails STALE_INPUT when no valid scan arrived for this long (steady clock), s.
    pub scan_timeout_s: f64,
    /// The wall-clock budget of one segment's optimisation (s): when spent, the best Σ found
    /// so far is taken, with a warning (the robot stands meanwhile).
    pub optimise_budget_s: f64,
    /// A scan is placed with the odometry pose at its stamp, interpolated; one with no
    /// odometry pose within this (s) of its stamp is refused.
    pub scan_odom_max_gap_s: f64,
    /// The scan's frame when its header has none.
    pub laser_frame: String,
    /// The laser's pose in the base frame (x, y, yaw) for a frame `tf_static` does not give;
    /// empty: such scans are refused.
    pub laser_pose: Vec<f64>,
}

impl Default for VfoSettings {
    fn default() -> Self {
        VfoSettings {
            gains: VfoGains::default(),
            optimise: OptimiseConfig::default(),
            scan: ScanObstacleConfig::default(),
            guiding: DEFAULT_GUIDING,
            scan_range: 4.0,
            scan_timeout_s: 0.5,
            scan_odom_max_gap_s: DEFAULT_SCAN_ODOM_MAX_GAP_S,
            optimise_budget_s: DEFAULT_OPTIMISE_BUDGET_S,
            laser_frame: "laser".to_owned(),
            laser_pose: vec![0.0; 3],
        }
    }
}

/// The default `vfo.scan_odom_max_gap_s` (s): five periods of 50 Hz odometry. Between two
/// odometry poses a scan's pose is interpolated; beyond the last one it is held for at most
/// this, where a robot turning at 1.5 rad/s turns 0.15 rad (0.45 m at 3 m) — the worst
/// misplacement accepted.
pub const DEFAULT_SCAN_ODOM_MAX_GAP_S: f64 = 0.1;

/// The largest `vfo.optimise_budget_s` (s).
pub const MAX_OPTIMISE_BUDGET_S: f64 = 30.0;

/// The default `vfo.optimise_budget_s` (s): twice the second Algorithm 2 takes at 30 obstacles
/// (the bench), so on a loaded machine an optimisation still finishes, while a robot standing
/// for it never stands longer than this.
pub const DEFAULT_OPTIMISE_BUDGET_S: f64 = 2.0;

impl VfoSettings {
    /// What a VFO route is driven with.
    pub fn setup(&self) -> VfoSetup {
        VfoSetup {
            gains: self.gains,
            optimise: self.optimise,
            guiding: self.guiding,
        }
    }

    /// The optimisation's wall-clock budget.
    pub fn optimise_budget(&self) -> Duration {
        seconds(self.optimise_budget_s, MAX_OPTIMISE_BUDGET_S)
    }

    /// The laser's pose from `laser_pose` (`None` when empty or malformed).
    pub fn laser_pose(&self) -> Option<Pose2> {
        Pose2::from_values(&self.laser_pose)
    }

    /// The scan timeout.
    pub fn scan_timeout(&self) -> Duration {
        seconds(self.scan_timeout_s, MAX_INPUT_TIMEOUT_S)
    }

    /// The obstacle extraction with the robot's radius.
    pub fn scan_config(&self, robot_radius: f64) -> ScanObstacleConfig {
        ScanObstacleConfig {
            robot_radius,
            ..self.scan
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn waypoint_method_parses_its_two_names_only() {
        assert_eq!("vfo".parse::<WaypointMethod>(), Ok(WaypointMethod::Vfo));
        assert_eq!("approach".parse::<WaypointMethod>(), Ok(WaypointMethod::Approach));
        assert!("VFO".parse::<WaypointMethod>().is_err());
        assert_eq!(WaypointMethod::Vfo.as_str(), "vfo");
    }

    #[test]
    fn timeouts_are_held_to_their_caps() {
        let s = VfoSettings {
            optimise_budget_s: 1e9,
            scan_timeout_s: f64::NAN,
            ..VfoSettings::default()
        };
        assert_eq!(s.optimise_budget(), Duration::from_secs(30));
        assert_eq!(s.scan_timeout(), Duration::from_secs(60));
        assert_eq!(VfoSettings::default().scan_timeout(), Duration::from_millis(500));
        assert_eq!(
            VfoSettings {
                laser_pose: vec![0.1],
                ..VfoSettings::default()
            }
            .laser_pose(),
            None
        );
    }
}
