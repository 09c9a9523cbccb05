//! Parameter validation, presets and model names.

use approx::assert_relative_eq;
use mobil_chassis::{inverse, BodyTwist, ChassisConfig, ChassisError, ChassisModel, ChassisParams, WheelState};

#[test]
fn model_names_round_trip() {
    for (name, model) in [
        ("tricycle", ChassisModel::Tricycle),
        ("car_like", ChassisModel::CarLike),
        ("omni", ChassisModel::Omni),
    ] {
        assert_eq!(name.parse::<ChassisModel>(), Ok(model));
        assert_eq!(model.to_string(), name);
    }
    assert_eq!(
        "ackermann".parse::<ChassisModel>(),
        Err(ChassisError::UnknownModel("ackermann".into()))
    );
}

#[test]
fn presets_pass_validation() {
    for (config, params) in [
        (ChassisConfig::mobil2(), ChassisParams::mobil2()),
        (ChassisConfig::omr3(), ChassisParams::omr3()),
        (ChassisConfig::tricycle(), ChassisParams::tricycle()),
    ] {
        assert_eq!(ChassisParams::new(config), Ok(params));
    }
}

#[test]
fn mobil2_effective_steering_limit_is_39_4_degrees() {
    // SPEC §1 Decision: δ_eff = min(70°, atan(0.60 / 0.73)) = atan(0.8219…) = 39.417°.
    let p = ChassisParams::mobil2();
    assert_relative_eq!(p.effective_steering_limit(), 0.687_963_312_105_192_1, epsilon = 1e-12);
    assert_relative_eq!(
        p.effective_steering_limit().to_degrees(),
        39.417_394_243_468_93,
        epsilon = 1e-9
    );
    // Curvature limit tan δ_eff / L = 1 / R_min.
    assert_relative_eq!(p.max_curvature(), 1.0 / 0.73, epsilon = 1e-12);
}

#[test]
fn tricycle_preset_is_limited_by_the_mechanical_steering_angle() {
    // atan(0.50 / 0.25) = 63.4° > δ_max = 60°.
    let p = ChassisParams::tricycle();
    assert_relative_eq!(p.effective_steering_limit(), 60f64.to_radians(), epsilon = 1e-15);
}

#[test]
fn omni_has_no_curvature_limit() {
    let p = ChassisParams::omr3();
    assert_eq!(p.max_curvature(), f64::INFINITY);
    assert_eq!(p.effective_steering_limit(), std::f64::consts::FRAC_PI_2);
}

fn refused(config: ChassisConfig) -> &'static str {
    match ChassisParams::new(config) {
        Err(ChassisError::InvalidParameter { name, .. }) => name,
        other => panic!("expected a refusal, got {other:?}"),
    }
}

#[test]
fn bad_geometry_is_refused_with_the_parameter_name() {
    let base = ChassisConfig::mobil2();
    assert_eq!(
        refused(ChassisConfig {
            wheelbase: f64::NAN,
            ..base
        }),
        "wheelbase"
    );
    assert_eq!(
        refused(ChassisConfig {
            wheel_radius: -0.1,
            ..base
        }),
        "wheel_radius"
    );
    assert_eq!(refused(ChassisConfig { track: 0.0, ..base }), "track");
    assert_eq!(
        refused(ChassisConfig {
            v_max: f64::INFINITY,
            ..base
        }),
        "v_max"
    );
    assert_eq!(
        refused(ChassisConfig {
            max_steering: 2.0,
            ..base
        }),
        "max_steering"
    );
    assert_eq!(
        refused(ChassisConfig {
            reference_offset: f64::NAN,
            ..base
        }),
        "reference_offset"
    );
    // R_eff = L / tan δ_eff = 0.73 m: a 1.5 m track would put the inner wheel past 90°.
    assert_eq!(refused(ChassisConfig { track: 1.5, ..base }), "track");
    // Omni needs R > 0 but does not care about the wheelbase.
    let omni = ChassisConfig::omr3();
    assert_eq!(
        refused(ChassisConfig {
            omni_wheel_distance: 0.0,
            ..omni
        }),
        "omni_wheel_distance"
    );
    assert!(ChassisParams::new(ChassisConfig { wheelbase: 0.0, ..omni }).is_ok());
}

#[test]
fn refusal_message_names_the_reason() {
    let err = ChassisParams::new(ChassisConfig {
        wheel_radius: 0.0,
        ..ChassisConfig::omr3()
    })
    .unwrap_err();
    assert_eq!(
        err.to_string(),
        "parameter `wheel_radius` = 0 refused: must be positive"
    );
}

#[test]
fn the_physical_steering_limit_follows_from_the_virtual_one() {
    // MOBIL-II with δ_max = 30°: L / tan 30° = 0.6 / 0.577350 = 1.039230 m, inner wheel at
    // 1.039230 − 0.31 = 0.729230 m: atan(0.6 / 0.729230) = atan(0.822786) = 0.688481 rad (39.45°).
    let thirty = ChassisParams::new(ChassisConfig {
        max_steering: 30f64.to_radians(),
        ..ChassisConfig::mobil2()
    })
    .unwrap();
    assert_relative_eq!(thirty.max_wheel_steering(), 0.688_481, epsilon = 1e-6);
    // Second method: the inverse kinematics on the tightest left turn δ_max allows (ω/v =
    // tan 30° / L) steer the inner (left) wheel exactly there.
    let v = 0.2;
    let turn = BodyTwist::new(v, 0.0, v * 30f64.to_radians().tan() / 0.6);
    match inverse(&thirty, turn) {
        WheelState::CarLike {
            front_left_steering, ..
        } => assert_relative_eq!(front_left_steering, thirty.max_wheel_steering(), epsilon = 1e-12),
        other => panic!("{other:?}"),
    }
    // 70°: L / tan 70° = 0.218 m < B/2 = 0.31 m, the inner wheel would pass 90°.
    assert_relative_eq!(
        ChassisParams::mobil2().max_wheel_steering(),
        std::f64::consts::FRAC_PI_2
    );
    // The tricycle's single wheel is the virtual wheel; the omni chassis has no steering.
    assert_relative_eq!(ChassisParams::tricycle().max_wheel_steering(), 60f64.to_radians());
    assert_eq!(ChassisParams::omr3().max_wheel_steering(), 0.0);
}
