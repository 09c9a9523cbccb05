//! `params/quadruped.yaml` loads into the library's configuration and holds its defaults.

use mobil_gait::{GaitConfig, LegAngleReading};
use serde_norway::{Mapping, Value};

/// The `/**` section's parameters overlaid by the `gait` section's, as the node sees them.
fn parameters() -> Value {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/quadruped.yaml");
    let text = std::fs::read_to_string(path).unwrap();
    let doc: Value = serde_norway::from_str(&text).unwrap();
    let mut merged = Mapping::new();
    for section in ["/**", "gait"] {
        if let Some(params) = doc[section]["ros__parameters"].as_mapping() {
            merged.extend(params.clone());
        }
    }
    Value::Mapping(merged)
}

#[test]
fn the_file_holds_the_documented_defaults() {
    let config: GaitConfig = serde_norway::from_value(parameters()).unwrap();
    assert_eq!(config.validate(), Ok(()));
    assert_eq!(config, GaitConfig::default());
    assert_eq!(config.reading, LegAngleReading::Forward);
}

#[test]
fn every_key_of_the_config_is_in_the_file() {
    // A key missing from the file would silently take its default: list them all.
    let p = parameters();
    let keys = [
        "stability_margin",
        "translation_step",
        "key_quantum",
        "goal_tolerance",
        "max_expansions",
        "reading",
        "k1",
        "k2",
        "a3_k1",
        "a3_k2",
        "a3_k3",
        "b3_k1",
        "b3_k2",
        "b3_k3",
        "tie_break",
    ];
    for k in keys {
        assert!(p.get(k).is_some(), "params/quadruped.yaml lacks `{k}`");
    }
}
