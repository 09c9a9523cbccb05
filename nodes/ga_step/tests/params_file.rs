//! `params/nao_step.yaml` loads into the library's model and configurations, equals their
//! documented defaults, and makes the statements its comments mark: (1) T is a whole number of
//! 40 ms rows; (2) hip + knee + ankle pitch = 0 on each leg; (3) the standing pose lies within
//! Table 1's limits; (4) with its fitness constants standing still scores 1 + w·b = 3 (b = 1.0 m),
//! a 10 cm non-falling step adds 0.2, and a fall scores its time alone (0.8 at 80 % of T_sim,
//! whatever its distance), below any upright individual. Read by `mobil_ga_step::params` (what
//! `ga_step --params` reads), it is the built-in setup, and a bad file is a one-line error.

// Table 1's values as printed (4 decimals): 0.7854 is the table's, not π/4.
#![allow(clippy::approx_constant)]

use mobil_ga_step::params::{read_setup, setup_from_yaml};
use mobil_ga_step::{FitnessConfig, GaConfig, GaSetup, NaoModel, Servo};
use serde_norway::Value;
use std::path::Path;

fn section() -> Value {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/nao_step.yaml");
    let text = std::fs::read_to_string(path).unwrap();
    let doc: Value = serde_norway::from_str(&text).unwrap();
    doc["ga_step"]["ros__parameters"].clone()
}

fn load() -> (NaoModel, FitnessConfig, GaConfig) {
    let p = section();
    (
        serde_norway::from_value(p.clone()).unwrap(),
        serde_norway::from_value(p.clone()).unwrap(),
        serde_norway::from_value(p).unwrap(),
    )
}

#[test]
fn the_file_holds_the_documented_defaults() {
    let (model, fitness, ga) = load();
    assert_eq!(model, NaoModel::default());
    assert_eq!(fitness, FitnessConfig::default());
    assert_eq!(ga, GaConfig::default());
    // Every key of the file is a field of one of the three (a misspelt key would be ignored).
    let known = [
        "step_time",
        "standing_pose",
        "settle_time",
        "forward_weight",
        "fall_height",
        "fall_tilt",
        "step_min_forward",
        "distance_on_fall",
        "backward_allowance",
        "robust_check",
        "physics",
        "blx_alpha",
        "blx_variant",
        "crossover_weight",
        "mutation_weight",
        "mutation_picks",
        "mutation_step",
        "level_window",
        "level_tolerance",
        "stop_at_step",
    ];
    let keys: Vec<String> = section()
        .as_mapping()
        .unwrap()
        .keys()
        .map(|k| k.as_str().unwrap().to_owned())
        .collect();
    assert_eq!(keys, known);
}

#[test]
fn statement_1_the_step_time_is_a_whole_number_of_rows() {
    let (model, _, _) = load();
    assert_eq!(model.validate(), Ok(()));
    assert_eq!(model.step_time_ms() % 40, 0);
    assert_eq!(model.step_time_ms(), 2000);
}

#[test]
fn statement_2_the_torso_is_upright_over_flat_feet() {
    let (model, _, _) = load();
    let p = |s: Servo| model.standing_pose[s.index()];
    assert_eq!(p(Servo::RHipPitch) + p(Servo::RKneePitch) + p(Servo::RAnklePitch), 0.0);
    assert_eq!(p(Servo::LHipPitch) + p(Servo::LKneePitch) + p(Servo::LAnklePitch), 0.0);
    for s in [Servo::RHipRoll, Servo::RAnkleRoll, Servo::LHipRoll, Servo::LAnkleRoll] {
        assert_eq!(p(s), 0.0);
    }
}

#[test]
fn statement_3_the_standing_pose_is_within_the_limits() {
    let (model, _, _) = load();
    // Table 1, in genome order (min, max).
    let table = [
        (-1.7453, 0.4363),
        (-0.7854, 0.4363),
        (0.0, 2.2689),
        (-1.309, 0.7854),
        (-0.4363, 0.7854),
        (-1.7453, 0.4363),
        (-0.4363, 0.7854),
        (0.0, 2.2689),
        (-1.309, 0.7854),
        (-0.7854, 0.4363),
    ];
    for (i, (lo, hi)) in table.into_iter().enumerate() {
        let v = model.standing_pose[i];
        assert!(lo < v && v < hi, "servo {i}: {v} not inside ({lo}, {hi})");
        assert_eq!(Servo::ALL[i].limits(), (lo, hi));
    }
}

#[test]
fn statement_4_staying_up_comes_before_distance() {
    let (model, fitness, _) = load();
    let t = model.step_time;
    let t_sim = 3.0; // T + settle time = 2 + 1
    assert_eq!(fitness.sim_time(t), t_sim);
    let standing = fitness.fitness(t, None, 0.0);
    // Standing still, upright: 1 + 2 · (0 + 1) = 3.
    assert_eq!(standing, 3.0);
    // 10 cm without a fall: 1 + 2 · 1.1 = 3.2; 0.5 m backward without one: 1 + 2 · 0.5 = 2.
    assert!((fitness.fitness(t, None, 0.10) - 3.2).abs() < 1e-12);
    assert!((fitness.fitness(t, None, -0.5) - 2.0).abs() < 1e-12);
    // Any upright individual, however far back, scores at least 1, above every fall.
    assert_eq!(fitness.fitness(t, None, -3.0), 1.0);
    // A fall scores its time alone: at 80 % of T_sim (2.4 s) with 10 cm, 0.8; a lunge of 1 m
    // falling 0.1 s before the end, 2.9/3 < 1.
    assert!((fitness.fitness(t, Some(0.8 * t_sim), 0.10) - 0.8).abs() < 1e-12);
    assert!((fitness.fitness(t, Some(2.9), 1.0) - 2.9 / 3.0).abs() < 1e-12);
    assert!(fitness.fitness(t, Some(2.9), 1.0) < standing);
}

/// `--params FILE`'s reading (`mobil_ga_step::params`), on the shipped file.
const FILE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/nao_step.yaml");

#[test]
fn the_shipped_file_is_the_built_in_defaults() {
    let setup = read_setup(Path::new(FILE)).unwrap();
    assert_eq!(setup, GaSetup::default());
    // A value of the file is read, not just defaulted: the step time is 2.0 s there.
    let text = std::fs::read_to_string(FILE)
        .unwrap()
        .replace("step_time: 2.0", "step_time: 2.4");
    let changed = setup_from_yaml(&text, "f").unwrap();
    assert_eq!(changed.model.step_time, 2.4);
    assert_ne!(changed, GaSetup::default());
}

#[test]
fn unknown_keys_and_bad_values_are_one_line_errors() {
    let text = std::fs::read_to_string(FILE).unwrap();
    let cases = [
        (text.replace("blx_alpha:", "blx_alpa:"), "unknown parameter `blx_alpa`"),
        (text.replace("fall_tilt: 0.5", "fall_tilt: 2.0"), "fall_tilt"),
        (text.replace("mutation_picks: 10", "mutation_picks: ten"), "algorithm"),
        (
            text.replace("blx_alpha: 0.7", "blx_alpha: 0.7\n    population: 5"),
            "`population` is set by the --population option",
        ),
        (
            text.replace("blx_alpha: 0.7", "blx_alpha: 0.7\n    offspring: 100"),
            "`offspring` is set by the --population option",
        ),
        (
            text.replace("blx_alpha: 0.7", "blx_alpha: 0.7\n    crossover: arithmetic"),
            "`crossover` is set by the --crossover option",
        ),
        ("ga_step: 3".to_owned(), "no `ga_step: ros__parameters:`"),
    ];
    for (t, want) in cases {
        let e = setup_from_yaml(&t, "f").unwrap_err().to_string();
        assert!(e.contains(want), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
}
