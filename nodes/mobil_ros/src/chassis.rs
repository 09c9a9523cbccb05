//! The chassis geometry and limits of [`mobil_chassis`] as ROS parameters, declared once here
//! and nested by every node that models the chassis (`chassis_node`, `sim_node`,
//! `local_nav_node`, `planner_node`), so one `/**` section of a robot's params file configures
//! them all.
//!
//! ```
//! use mobil_chassis::ChassisConfig;
//! use mobil_ros::chassis::{chassis_params, declare_chassis};
//! use mobil_ros::config::{Config, Decl};
//!
//! #[derive(Debug, Clone, Default)]
//! struct PlannerConfig {
//!     chassis: ChassisConfig,
//!     lookahead: f64,
//! }
//!
//! impl Config for PlannerConfig {
//!     fn declare(d: &mut Decl<Self>) {
//!         d.nest(|c: &mut PlannerConfig| &mut c.chassis, declare_chassis);
//!         d.double("lookahead", 1.0, "lookahead distance [m]", |c, v| c.lookahead = v).above(0.0);
//!     }
//!
//!     fn validate(&self) -> Result<(), mobil_ros::ConfigError> {
//!         chassis_params(&self.chassis).map(|_| ())
//!     }
//! }
//!
//! let names: Vec<String> = Decl::<PlannerConfig>::of().specs().into_iter().map(|s| s.name).collect();
//! assert!(names.contains(&"v_max".to_string()) && names.contains(&"lookahead".to_string()));
//! ```

use crate::config::{ConfigError, Decl};
use mobil_chassis::model::{ChassisConfig, ChassisModel, ChassisParams};

/// Declares the chassis geometry and limits, each filling its field of [`ChassisConfig`];
/// defaults are MOBIL-II's (`omni_wheel_distance`: OMR-III's, so that switching `model` to
/// `omni` alone gives a valid chassis).
pub fn declare_chassis(d: &mut Decl<ChassisConfig>) {
    let m = ChassisConfig::mobil2();
    d.parsed("model", m.model.as_str(), "chassis model", |c, v: ChassisModel| {
        c.model = v
    })
    .choices(&["tricycle", "car_like", "omni"])
    .read_only();
    d.double(
        "wheelbase",
        m.wheelbase,
        "L, rear to front axle [m] (tricycle, car_like)",
        |c, v| c.wheelbase = v,
    )
    .min(0.0);
    d.double("track", m.track, "B, left to right wheel [m] (car_like)", |c, v| {
        c.track = v
    })
    .min(0.0);
    d.double("wheel_radius", m.wheel_radius, "r of the driven wheels [m]", |c, v| {
        c.wheel_radius = v
    })
    .above(0.0);
    d.double(
        "omni_wheel_distance",
        ChassisConfig::omr3().omni_wheel_distance,
        "R, centre to wheel [m] (omni)",
        |c, v| c.omni_wheel_distance = v,
    )
    .min(0.0);
    d.double(
        "max_steering",
        m.max_steering,
        "steering limit δ_max of the virtual centre (bicycle) wheel [rad]; on a car_like chassis the inner \
         Ackermann wheel steers further: for an inner-wheel limit δ_w set atan(L / (L / tan δ_w + B/2))",
        |c, v| c.max_steering = v,
    )
    .within(0.0, std::f64::consts::FRAC_PI_2);
    d.double(
        "min_turning_radius",
        m.min_turning_radius,
        "R_min at the kinematic origin [m]",
        |c, v| c.min_turning_radius = v,
    )
    .min(0.0);
    d.double("v_max", m.v_max, "speed limit [m/s]", |c, v| c.v_max = v)
        .above(0.0);
    d.double("omega_max", m.omega_max, "turn-rate limit [rad/s]", |c, v| {
        c.omega_max = v
    })
    .above(0.0);
    d.double(
        "max_wheel_speed",
        m.max_wheel_speed,
        "wheel speed limit [rad/s]",
        |c, v| c.max_wheel_speed = v,
    )
    .above(0.0);
    d.double(
        "reference_offset",
        m.reference_offset,
        "published reference point ahead of the kinematic origin [m] (moving it would make the pose jump)",
        |c, v| c.reference_offset = v,
    )
    .read_only();
}

/// Validated [`ChassisParams`] from the declared values (a node's `validate` calls it).
pub fn chassis_params(c: &ChassisConfig) -> Result<ChassisParams, ConfigError> {
    ChassisParams::new(*c).map_err(ConfigError::inconsistent)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::params::ParamValues;
    use ros2_client::ParameterValue;

    #[derive(Debug, Clone, Default)]
    struct Only(ChassisConfig);

    impl Config for Only {
        fn declare(d: &mut Decl<Self>) {
            d.nest(|c: &mut Only| &mut c.0, declare_chassis);
        }

        fn validate(&self) -> Result<(), ConfigError> {
            chassis_params(&self.0).map(|_| ())
        }
    }

    #[test]
    fn defaults_are_mobil2_and_bad_geometry_is_refused() {
        let mut values = ParamValues::defaults(&Decl::<Only>::of().specs());
        let mut expected = ChassisConfig::mobil2();
        expected.omni_wheel_distance = ChassisConfig::omr3().omni_wheel_distance;
        assert_eq!(crate::config::load::<Only>(&values).unwrap().0, expected);
        values.set("model", ParameterValue::String("omni".into()));
        // MOBIL-II's omni_wheel_distance default is OMR-III's, so switching the model is valid.
        assert_eq!(
            crate::config::load::<Only>(&values).unwrap().0.model,
            ChassisModel::Omni
        );
        values.set("wheel_radius", ParameterValue::Double(0.0));
        let e = crate::config::load::<Only>(&values).unwrap_err();
        assert!(matches!(e, ConfigError::Inconsistent(_)), "{e}");
    }
}
