//! The ROS side of [`mobil_chassis`]: the `chassis_node` executable (src/main.rs), and the
//! chassis geometry and limits as ROS parameters, shared by every node that models the chassis
//! (`chassis_node`, `sim_node`, and the planners), so one `/**` section of a robot's params file
//! configures them all.

use mobil_ros::params::ParamValues;
use mobil_ros::ParamSpec;

use mobil_chassis::model::{ChassisConfig, ChassisModel, ChassisParams};

/// Parameter declarations of [`ChassisConfig`]; defaults are MOBIL-II's.
pub fn chassis_param_specs() -> Vec<ParamSpec> {
    let m = ChassisConfig::mobil2();
    vec![
        ParamSpec::string("model", m.model.as_str(), "chassis model")
            .choices(&["tricycle", "car_like", "omni"])
            .read_only(),
        ParamSpec::double(
            "wheelbase",
            m.wheelbase,
            "L, rear to front axle [m] (tricycle, car_like)",
        )
        .min(0.0),
        ParamSpec::double("track", m.track, "B, left to right wheel [m] (car_like)").min(0.0),
        ParamSpec::double("wheel_radius", m.wheel_radius, "r of the driven wheels [m]").above(0.0),
        ParamSpec::double(
            "omni_wheel_distance",
            ChassisConfig::omr3().omni_wheel_distance,
            "R, centre to wheel [m] (omni)",
        )
        .min(0.0),
        ParamSpec::double(
            "max_steering",
            m.max_steering,
            "steering limit δ_max of the virtual centre (bicycle) wheel [rad]; on a car_like chassis the inner \
             Ackermann wheel steers further: for an inner-wheel limit δ_w set atan(L / (L / tan δ_w + B/2))",
        )
        .within(0.0, std::f64::consts::FRAC_PI_2),
        ParamSpec::double(
            "min_turning_radius",
            m.min_turning_radius,
            "R_min at the kinematic origin [m]",
        )
        .min(0.0),
        ParamSpec::double("v_max", m.v_max, "speed limit [m/s]").above(0.0),
        ParamSpec::double("omega_max", m.omega_max, "turn-rate limit [rad/s]").above(0.0),
        ParamSpec::double("max_wheel_speed", m.max_wheel_speed, "wheel speed limit [rad/s]").above(0.0),
        ParamSpec::double(
            "reference_offset",
            m.reference_offset,
            "published reference point ahead of the kinematic origin [m] (moving it would make the pose jump)",
        )
        .read_only(),
    ]
}

/// Builds validated [`ChassisParams`] from the parameters of [`chassis_param_specs`].
pub fn chassis_from_params(p: &ParamValues) -> Result<ChassisParams, String> {
    let model: ChassisModel = p.string("model")?.parse().map_err(|e| format!("{e}"))?;
    ChassisParams::new(ChassisConfig {
        model,
        wheelbase: p.f64("wheelbase")?,
        track: p.f64("track")?,
        wheel_radius: p.f64("wheel_radius")?,
        omni_wheel_distance: p.f64("omni_wheel_distance")?,
        max_steering: p.f64("max_steering")?,
        min_turning_radius: p.f64("min_turning_radius")?,
        v_max: p.f64("v_max")?,
        omega_max: p.f64("omega_max")?,
        max_wheel_speed: p.f64("max_wheel_speed")?,
        reference_offset: p.f64("reference_offset")?,
    })
    .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_mobil2_and_bad_geometry_is_refused() {
        let specs = chassis_param_specs();
        let mut values = ParamValues::defaults(&specs);
        let mut expected = ChassisConfig::mobil2();
        expected.omni_wheel_distance = ChassisConfig::omr3().omni_wheel_distance;
        assert_eq!(
            chassis_from_params(&values).unwrap(),
            ChassisParams::new(expected).unwrap()
        );
        values.set("model", ros2_client::ParameterValue::String("omni".into()));
        // MOBIL-II's omni_wheel_distance default is OMR-III's, so switching the model is valid.
        assert!(chassis_from_params(&values).is_ok());
        values.set("wheel_radius", ros2_client::ParameterValue::Double(0.0));
        assert!(chassis_from_params(&values).is_err());
    }
}
