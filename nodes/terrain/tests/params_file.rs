//! `params/hexapod.yaml` loads into the library's configuration, and its values make the three
//! statements its comments make: (1) a plain 10° slope is SLOPE, not BEYOND_LIMITS, in any
//! direction; (2) Table 1's "large" feet (σ 2.77 cm) are UNEVEN, not BEYOND_LIMITS; (3) ε_α is
//! at most 3°.

use mobil_terrain::{Assessor, HexapodGeometry, TerrainClass, TerrainConfig};
use nalgebra::Point3;
use serde_norway::{Mapping, Value};

/// The `/**` section's parameters overlaid by the `terrain` section's, as the node sees them.
fn parameters() -> Value {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/hexapod.yaml");
    let text = std::fs::read_to_string(path).unwrap();
    let doc: Value = serde_norway::from_str(&text).unwrap();
    let mut merged = Mapping::new();
    for section in ["/**", "terrain"] {
        let params = doc[section]["ros__parameters"].as_mapping().unwrap();
        merged.extend(params.clone());
    }
    Value::Mapping(merged)
}

fn load() -> (TerrainConfig, HexapodGeometry) {
    let p = parameters();
    (
        serde_norway::from_value(p.clone()).unwrap(),
        serde_norway::from_value(p).unwrap(),
    )
}

#[test]
fn the_file_holds_the_documented_defaults() {
    let (config, geometry) = load();
    assert_eq!(config.validate(), Ok(()));
    assert_eq!(geometry.validate(), Ok(()));
    // The file and the library's defaults agree to the file's 7 digits (the angles are written
    // in radians, 3° = 0.0523599 and 15° = 0.2617994).
    let d = TerrainConfig::default();
    assert!((config.epsilon_alpha - d.epsilon_alpha).abs() < 1e-7);
    assert!((config.tilt_max - d.tilt_max).abs() < 1e-7);
    assert_eq!(
        (
            config.sigma_flat,
            config.plane_offset_max,
            config.sigma_wave,
            config.sigma_max
        ),
        (d.sigma_flat, d.plane_offset_max, d.sigma_wave, d.sigma_max)
    );
    assert_eq!(
        (config.body_points, config.body_frame.as_str()),
        (d.body_points, "base_link")
    );
    assert_eq!(geometry, HexapodGeometry::default());
}

#[test]
fn epsilon_alpha_is_at_most_3_degrees() {
    let (config, _) = load();
    assert!(config.epsilon_alpha <= 3.0f64.to_radians() + 1e-7);
}

#[test]
fn a_plain_10_degree_slope_is_slope_in_every_direction() {
    let (config, geometry) = load();
    let assessor = Assessor::new(config).unwrap();
    let t = 10f64.to_radians().tan();
    for k in 0..24 {
        let phi = f64::from(k) * 15f64.to_radians();
        let feet = geometry.standing_feet().map(|p| {
            Point3::new(
                p.x,
                p.y,
                -geometry.body_height + t * (p.x * phi.cos() + p.y * phi.sin()),
            )
        });
        let a = assessor.assess(&feet).unwrap();
        assert_eq!(a.class, TerrainClass::Slope, "uphill {}°: {a:?}", k * 15);
    }
}

#[test]
fn table_1_large_feet_are_uneven() {
    let (config, geometry) = load();
    let assessor = Assessor::new(config).unwrap();
    let mut feet = geometry.standing_feet();
    for (f, z) in feet.iter_mut().zip([4.0, -3.0, 1.0, -4.0, 0.0, 2.0]) {
        f.z += z / 100.0;
    }
    let a = assessor.assess(&feet).unwrap();
    assert!((a.sigma - 0.027_689).abs() < 1e-6);
    assert_eq!(a.class, TerrainClass::Uneven);
}
