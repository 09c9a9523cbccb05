//! Chassis models and their validated parameters (SPEC §1; 004 §3.1–3.3, §4.1).
//!
//! [`ChassisConfig`] is the raw parameter set (as read from a parameter file); it becomes a
//! [`ChassisParams`] once, through [`ChassisParams::new`], which refuses anything the kinematics
//! cannot use. Only the fields a model uses are checked for positivity; the others must merely be
//! finite (the presets set them to 0).

use std::f64::consts::{FRAC_PI_2, PI};
use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::ChassisError;

/// The three chassis the suite drives (004 §3.1–3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChassisModel {
    /// Steered and driven front wheel, passive rear axle (004 §3.1).
    Tricycle,
    /// Four wheels, Ackermann-steered front pair, driven rear pair: MOBIL-II (004 §3.2).
    CarLike,
    /// Three omni wheels at 0°, 120°, 240°: OMR-III (004 §3.3).
    Omni,
}

impl ChassisModel {
    /// The parameter-file spelling: `tricycle`, `car_like` or `omni`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Tricycle => "tricycle",
            Self::CarLike => "car_like",
            Self::Omni => "omni",
        }
    }

    /// True for the models that cannot move sideways or turn in place (tricycle, car-like).
    pub fn is_nonholonomic(self) -> bool {
        !matches!(self, Self::Omni)
    }
}

impl fmt::Display for ChassisModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for ChassisModel {
    type Err = ChassisError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "tricycle" => Ok(Self::Tricycle),
            "car_like" => Ok(Self::CarLike),
            "omni" => Ok(Self::Omni),
            other => Err(ChassisError::UnknownModel(other.to_owned())),
        }
    }
}

/// Raw chassis parameters, SI units, angles in radians; validate with [`ChassisParams::new`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ChassisConfig {
    /// Chassis model.
    pub model: ChassisModel,
    /// Wheelbase L (m), rear axle to front axle (tricycle, car-like).
    pub wheelbase: f64,
    /// Track B (m), between the two front (and the two rear) wheels (car-like).
    pub track: f64,
    /// Wheel radius r (m) of the driven wheels (all models).
    pub wheel_radius: f64,
    /// Distance R (m) from the centre to each omni wheel (omni).
    pub omni_wheel_distance: f64,
    /// Steering limit δ_max (rad), in (0, π/2] (tricycle, car-like), of the model's one steering
    /// angle δ: the tricycle's wheel, the car-like chassis' virtual centre (bicycle) wheel. The
    /// inner Ackermann wheel steers further, atan(L / (L / tan δ − B/2)); a limit δ_w of the inner
    /// wheel is δ_max = atan(L / (L / tan δ_w + B/2)) (see docs/chassis_node.md).
    pub max_steering: f64,
    /// Minimum turning radius R_min (m) at the kinematic origin (tricycle, car-like).
    pub min_turning_radius: f64,
    /// Maximum speed v_max (m/s) of the kinematic origin (translation magnitude for omni).
    pub v_max: f64,
    /// Maximum turn rate ω_max (rad/s).
    pub omega_max: f64,
    /// Maximum wheel speed (rad/s) of any driven wheel.
    pub max_wheel_speed: f64,
    /// Offset d (m) of the published reference point ahead of the kinematic origin along body x
    /// (negative: behind).
    pub reference_offset: f64,
}

impl Default for ChassisConfig {
    /// MOBIL-II's.
    fn default() -> Self {
        ChassisConfig::mobil2()
    }
}

impl ChassisConfig {
    /// MOBIL-II figures (004 §4.1.1): car-like, L 0.60, B 0.62, δ_max 70°, R_min 0.73, v_max 0.5.
    ///
    /// Not in the source, chosen here: wheel radius r = 0.10 m (plausible for a 40 kg robot with
    /// 0.16 m ground clearance); ω_max = 1.0 rad/s (never binding: the curvature limit gives at
    /// most v_max·tan δ_eff / L = 0.685 rad/s); max wheel speed 7.5 rad/s, just above the outer
    /// rear wheel at v_max on the tightest turn, (0.5 + 0.685·0.31) / 0.10 = 7.12 rad/s, so that
    /// v_max stays reachable on every feasible curve; d = 0 (the paper's rear-axle reference;
    /// a parameter file should move it to the sensor centre, 004 §4.3.4).
    pub const fn mobil2() -> Self {
        Self {
            model: ChassisModel::CarLike,
            wheelbase: 0.60,
            track: 0.62,
            wheel_radius: 0.10,
            omni_wheel_distance: 0.0,
            max_steering: 70.0 * PI / 180.0,
            min_turning_radius: 0.73,
            v_max: 0.5,
            omega_max: 1.0,
            max_wheel_speed: 7.5,
            reference_offset: 0.0,
        }
    }

    /// OMR-III (004 §4.1.2): omni, three wheels at 120°. The source gives no dimensions.
    ///
    /// Chosen here: r = 0.05 m, the common 100 mm omni wheel; R = 0.20 m, a platform about
    /// 0.45 m across, the size class of MOBIL-II (0.68 m wide) for a three-wheel indoor base;
    /// v_max = 0.5 m/s as MOBIL-II; ω_max = 1.5 rad/s; max wheel speed 12 rad/s (≈ 115 rpm),
    /// above v_max / r = 10 rad/s so any translation at v_max is reachable.
    pub const fn omr3() -> Self {
        Self {
            model: ChassisModel::Omni,
            wheelbase: 0.0,
            track: 0.0,
            wheel_radius: 0.05,
            omni_wheel_distance: 0.20,
            max_steering: 0.0,
            min_turning_radius: 0.0,
            v_max: 0.5,
            omega_max: 1.5,
            max_wheel_speed: 12.0,
            reference_offset: 0.0,
        }
    }

    /// A generic small tricycle (not from the source): L 0.50, r 0.10, δ_max 60°, R_min 0.25.
    ///
    /// Here the mechanical limit binds (atan(0.50/0.25) = 63.4° > 60°), unlike MOBIL-II.
    /// v_max 0.5 m/s, ω_max 1.0 rad/s, max wheel speed 10 rad/s (front wheel ground speed
    /// v / cos δ = 1.0 m/s at v_max and δ = 60°).
    pub const fn tricycle() -> Self {
        Self {
            model: ChassisModel::Tricycle,
            wheelbase: 0.50,
            track: 0.0,
            wheel_radius: 0.10,
            omni_wheel_distance: 0.0,
            max_steering: 60.0 * PI / 180.0,
            min_turning_radius: 0.25,
            v_max: 0.5,
            omega_max: 1.0,
            max_wheel_speed: 10.0,
            reference_offset: 0.0,
        }
    }
}

/// Validated chassis parameters; build with [`ChassisParams::new`] or a preset.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ChassisConfig", into = "ChassisConfig")]
pub struct ChassisParams {
    config: ChassisConfig,
}

fn invalid(name: &'static str, value: f64, reason: &'static str) -> ChassisError {
    ChassisError::InvalidParameter { name, value, reason }
}

fn positive(name: &'static str, value: f64) -> Result<(), ChassisError> {
    if value > 0.0 {
        Ok(())
    } else {
        Err(invalid(name, value, "must be positive"))
    }
}

impl ChassisParams {
    /// Validates a [`ChassisConfig`]: every field finite, the model's geometry and all limits
    /// positive, δ_max ≤ π/2, and for the car-like chassis an effective minimum radius larger
    /// than B/2 (else the inner front wheel would have to steer past 90°).
    pub fn new(config: ChassisConfig) -> Result<Self, ChassisError> {
        let c = &config;
        let fields = [
            ("wheelbase", c.wheelbase),
            ("track", c.track),
            ("wheel_radius", c.wheel_radius),
            ("omni_wheel_distance", c.omni_wheel_distance),
            ("max_steering", c.max_steering),
            ("min_turning_radius", c.min_turning_radius),
            ("v_max", c.v_max),
            ("omega_max", c.omega_max),
            ("max_wheel_speed", c.max_wheel_speed),
            ("reference_offset", c.reference_offset),
        ];
        for (name, value) in fields {
            if !value.is_finite() {
                return Err(invalid(name, value, "must be finite"));
            }
        }
        positive("wheel_radius", c.wheel_radius)?;
        positive("v_max", c.v_max)?;
        positive("omega_max", c.omega_max)?;
        positive("max_wheel_speed", c.max_wheel_speed)?;
        match c.model {
            ChassisModel::Omni => positive("omni_wheel_distance", c.omni_wheel_distance)?,
            ChassisModel::Tricycle | ChassisModel::CarLike => {
                positive("wheelbase", c.wheelbase)?;
                positive("max_steering", c.max_steering)?;
                positive("min_turning_radius", c.min_turning_radius)?;
                if c.max_steering > FRAC_PI_2 {
                    return Err(invalid("max_steering", c.max_steering, "must be at most π/2"));
                }
            }
        }
        let params = Self { config };
        if c.model == ChassisModel::CarLike {
            positive("track", c.track)?;
            let radius = c.wheelbase / params.effective_steering_limit().tan();
            if radius <= 0.5 * c.track {
                return Err(invalid(
                    "track",
                    c.track,
                    "half the track must be smaller than the effective minimum radius \
                     L / tan(δ_eff), else the inner front wheel steers past 90°",
                ));
            }
        }
        Ok(params)
    }

    /// MOBIL-II preset, see [`ChassisConfig::mobil2`].
    pub const fn mobil2() -> Self {
        Self {
            config: ChassisConfig::mobil2(),
        }
    }

    /// OMR-III preset, see [`ChassisConfig::omr3`].
    pub const fn omr3() -> Self {
        Self {
            config: ChassisConfig::omr3(),
        }
    }

    /// Tricycle preset, see [`ChassisConfig::tricycle`].
    pub const fn tricycle() -> Self {
        Self {
            config: ChassisConfig::tricycle(),
        }
    }

    /// The validated raw values.
    pub fn config(&self) -> &ChassisConfig {
        &self.config
    }

    /// Chassis model.
    pub fn model(&self) -> ChassisModel {
        self.config.model
    }

    /// Wheelbase L (m).
    pub fn wheelbase(&self) -> f64 {
        self.config.wheelbase
    }

    /// Track B (m).
    pub fn track(&self) -> f64 {
        self.config.track
    }

    /// Wheel radius r (m).
    pub fn wheel_radius(&self) -> f64 {
        self.config.wheel_radius
    }

    /// Omni wheel distance R (m) from the centre.
    pub fn omni_wheel_distance(&self) -> f64 {
        self.config.omni_wheel_distance
    }

    /// Steering limit δ_max (rad) of the model's steering angle (car-like: the virtual centre wheel).
    pub fn max_steering(&self) -> f64 {
        self.config.max_steering
    }

    /// The largest angle (rad) of any physical steering joint that the virtual limit δ_max
    /// implies: the tricycle's one wheel is the virtual wheel (δ_max); the car-like chassis' inner
    /// Ackermann wheel steers to atan(L / (L / tan δ_max − B/2)), π/2 when the turning centre of
    /// δ_max lies within the track (MOBIL-II: L / tan 70° = 0.218 m < B/2 = 0.31 m). The limit to
    /// hold each steering joint to; 0 for the omni chassis, which has none.
    pub fn max_wheel_steering(&self) -> f64 {
        let c = &self.config;
        match c.model {
            ChassisModel::Omni => 0.0,
            ChassisModel::Tricycle => c.max_steering,
            ChassisModel::CarLike => {
                let inner_radius = c.wheelbase / c.max_steering.tan() - c.track / 2.0;
                if inner_radius > 0.0 {
                    (c.wheelbase / inner_radius).atan()
                } else {
                    FRAC_PI_2
                }
            }
        }
    }

    /// Minimum turning radius R_min (m) at the kinematic origin.
    pub fn min_turning_radius(&self) -> f64 {
        self.config.min_turning_radius
    }

    /// Maximum speed v_max (m/s).
    pub fn v_max(&self) -> f64 {
        self.config.v_max
    }

    /// Maximum turn rate ω_max (rad/s).
    pub fn omega_max(&self) -> f64 {
        self.config.omega_max
    }

    /// Maximum wheel speed (rad/s).
    pub fn max_wheel_speed(&self) -> f64 {
        self.config.max_wheel_speed
    }

    /// Reference-point offset d (m) ahead of the kinematic origin.
    pub fn reference_offset(&self) -> f64 {
        self.config.reference_offset
    }

    /// Effective steering limit δ_eff = min(δ_max, atan(L / R_min)), SPEC §1 Decision
    /// (39.4° for MOBIL-II); π/2 for the omni chassis, which has no steering limit.
    pub fn effective_steering_limit(&self) -> f64 {
        match self.config.model {
            ChassisModel::Omni => FRAC_PI_2,
            ChassisModel::Tricycle | ChassisModel::CarLike => self
                .config
                .max_steering
                .min((self.config.wheelbase / self.config.min_turning_radius).atan()),
        }
    }

    /// Largest curvature |ω / v| = tan δ_eff / L (1/m); infinite for the omni chassis.
    pub fn max_curvature(&self) -> f64 {
        match self.config.model {
            ChassisModel::Omni => f64::INFINITY,
            ChassisModel::Tricycle | ChassisModel::CarLike => {
                self.effective_steering_limit().tan() / self.config.wheelbase
            }
        }
    }
}

impl TryFrom<ChassisConfig> for ChassisParams {
    type Error = ChassisError;

    fn try_from(config: ChassisConfig) -> Result<Self, Self::Error> {
        Self::new(config)
    }
}

impl From<ChassisParams> for ChassisConfig {
    fn from(params: ChassisParams) -> Self {
        params.config
    }
}
