//! Checkpoints: a resumed run equals the uninterrupted one; the file is written atomically and a
//! foreign, other-version or damaged file is a typed error.

use mobil_ga_step::checkpoint::from_json_tagged;
use mobil_ga_step::checkpoint::{from_json, temp_path, to_json};
use mobil_ga_step::{
    read_checkpoint, write_checkpoint, CheckpointError, Crossover, FitnessConfig, GaConfig, GaSetup, GaState, NaoModel,
    StopReason, TestLandscape,
};
use mobil_ga_step::{read_checkpoint_tagged, EvaluatorTag, MAX_CHECKPOINT_BYTES};
use std::ops::ControlFlow;

const TAG: EvaluatorTag = EvaluatorTag::Physics { physics_version: 7 };
use std::path::PathBuf;

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("mobil_ga_step_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn setup(crossover: Crossover) -> GaSetup {
    GaSetup {
        ga: GaConfig {
            crossover,
            stop_at_step: false,
            ..GaConfig::default()
        },
        ..GaSetup::default()
    }
}

fn landscape() -> TestLandscape {
    TestLandscape::new(NaoModel::default(), FitnessConfig::default())
}

/// A run to 12 generations writes a checkpoint after each; reading the one of generation 5 and
/// resuming to 12 (on another thread count) gives exactly the uninterrupted run's state, and so
/// does resuming from every other generation.
#[test]
fn resume_equals_uninterrupted() {
    let d = dir("resume");
    let e = landscape();
    for c in [Crossover::Blx, Crossover::Linear] {
        let path = d.join("checkpoint.json");
        let mut full = GaState::start(setup(c), 99, &e, 1).unwrap();
        let mut saved = vec![to_json(&full, &TAG)];
        full.run(&e, 1, 12, |s| {
            write_checkpoint(s, &TAG, &path).unwrap();
            saved.push(std::fs::read_to_string(&path).unwrap());
            ControlFlow::Continue(())
        });
        assert_eq!(full.generation, 12);
        assert_eq!(saved.len(), 13);
        // The last file on disk is the finished run.
        assert_eq!(read_checkpoint(&path).unwrap(), full);
        for (g, text) in saved.iter().enumerate() {
            let mut resumed = from_json(text).unwrap();
            assert_eq!(resumed.generation as usize, g);
            resumed.run(&e, 3, 12, |_| ControlFlow::Continue(()));
            assert_eq!(resumed, full, "{c}, resumed from generation {g}");
            assert_eq!(resumed.rng_word_pos(), full.rng_word_pos());
        }
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// An interrupt (the callback breaks after generation 4) stops the run there, with its
/// checkpoint written; resuming from that file finishes as the uninterrupted run does.
#[test]
fn an_interrupted_run_resumes_to_the_same_end() {
    let d = dir("interrupt");
    let e = landscape();
    let path = d.join("checkpoint.json");
    let mut full = GaState::start(setup(Crossover::Arithmetic), 4, &e, 2).unwrap();
    full.run(&e, 2, 10, |_| ControlFlow::Continue(()));
    let mut cut = GaState::start(setup(Crossover::Arithmetic), 4, &e, 2).unwrap();
    let reason = cut.run(&e, 2, 10, |s| {
        write_checkpoint(s, &TAG, &path).unwrap();
        if s.generation == 4 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    assert_eq!((reason, cut.generation), (StopReason::Interrupted, 4));
    let mut resumed = read_checkpoint(&path).unwrap();
    assert_eq!(resumed, cut);
    assert_eq!(
        resumed.run(&e, 1, 10, |_| ControlFlow::Continue(())),
        StopReason::MaxGenerations
    );
    assert_eq!(resumed, full);
    std::fs::remove_dir_all(&d).unwrap();
}

/// Every f64 of the state survives the round trip bit for bit (knots, fitness, history), and
/// so does the generator's position.
#[test]
fn a_checkpoint_round_trips_exactly() {
    let e = landscape();
    let mut s = GaState::start(setup(Crossover::Geometric), 5, &e, 2).unwrap();
    s.run(&e, 2, 3, |_| ControlFlow::Continue(()));
    let back = from_json(&to_json(&s, &TAG)).unwrap();
    for (a, b) in s.population.iter().zip(&back.population) {
        for (x, y) in a
            .individual
            .knots
            .iter()
            .flatten()
            .zip(b.individual.knots.iter().flatten())
        {
            assert_eq!(x.to_bits(), y.to_bits());
        }
        assert_eq!(a.fitness().to_bits(), b.fitness().to_bits());
    }
    assert_eq!(back, s);
    assert_eq!(back.rng_word_pos(), s.rng_word_pos());
}

/// The write goes through `<file>.tmp` and a rename: afterwards no temporary file is left, and
/// a directory that does not exist is an I/O error with no file written.
#[test]
fn the_write_is_atomic_and_failures_are_typed() {
    let d = dir("atomic");
    let e = landscape();
    let s = GaState::start(setup(Crossover::Blx), 1, &e, 1).unwrap();
    let path = d.join("state.json");
    write_checkpoint(&s, &TAG, &path).unwrap();
    assert_eq!(temp_path(&path), d.join("state.json.tmp"));
    assert!(!temp_path(&path).exists());
    let missing = d.join("no_such_dir").join("state.json");
    assert!(matches!(
        write_checkpoint(&s, &TAG, &missing),
        Err(CheckpointError::Io { .. })
    ));
    assert!(!missing.exists());
    assert!(matches!(
        read_checkpoint(&d.join("absent.json")),
        Err(CheckpointError::Io { .. })
    ));
    std::fs::remove_dir_all(&d).unwrap();
}

/// Foreign files (not JSON, JSON without the tag, another tag, binary), another version, and
/// damaged checkpoints (truncated, a knot beyond its limit, a population of the wrong size, a
/// bad generator position) are each refused with their own error.
#[test]
fn foreign_and_corrupt_files_are_refused() {
    let e = landscape();
    let mut s = GaState::start(setup(Crossover::Blx), 1, &e, 1).unwrap();
    s.run(&e, 1, 2, |_| ControlFlow::Continue(()));
    let good = to_json(&s, &TAG);

    for text in [
        "generation,max,mean,min\n0,1,1,1\n",
        "{\"generation\": 3}",
        "[1, 2]",
        "",
    ] {
        assert!(matches!(from_json(text), Err(CheckpointError::Foreign(_))), "{text}");
    }
    let other_tag = good.replacen("mobil_ga_step checkpoint", "something else", 1);
    assert!(matches!(from_json(&other_tag), Err(CheckpointError::Foreign(_))));
    let v5 = good.replacen("\"version\":4", "\"version\":5", 1);
    assert!(matches!(
        from_json(&v5),
        Err(CheckpointError::UnsupportedVersion { found: 5, expected: 4 })
    ));
    // Versions 1–3 record no evaluator: refused, not resumed under a measure they may not have
    // been scored by.
    for old in [1, 2, 3] {
        let text = good.replacen("\"version\":4", &format!("\"version\":{old}"), 1);
        assert!(matches!(
            from_json(&text),
            Err(CheckpointError::UnsupportedVersion { found, expected: 4 }) if found == old
        ));
    }

    let truncated = &good[..good.len() / 2];
    assert!(matches!(from_json(truncated), Err(CheckpointError::Corrupt(_))));

    let mut v: serde_json::Value = serde_json::from_str(&good).unwrap();
    v["population"][3]["individual"]["knots"][2][5] = serde_json::json!(3.0); // knee limit 2.2689
    assert!(matches!(from_json(&v.to_string()), Err(CheckpointError::Corrupt(m)) if m.contains("RKneePitch")));

    let mut v: serde_json::Value = serde_json::from_str(&good).unwrap();
    v["population"].as_array_mut().unwrap().pop();
    assert!(matches!(from_json(&v.to_string()), Err(CheckpointError::Corrupt(m)) if m.contains("99 individuals")));

    let mut v: serde_json::Value = serde_json::from_str(&good).unwrap();
    v["rng_word_pos"] = serde_json::json!("-5");
    assert!(matches!(from_json(&v.to_string()), Err(CheckpointError::Corrupt(_))));

    let mut v: serde_json::Value = serde_json::from_str(&good).unwrap();
    v["history"].as_array_mut().unwrap().pop();
    assert!(matches!(from_json(&v.to_string()), Err(CheckpointError::Corrupt(m)) if m.contains("history")));

    // Binary garbage on disk.
    let d = dir("foreign");
    let path = d.join("bin");
    std::fs::write(&path, [0xff, 0xfe, 0x00, 0x12]).unwrap();
    assert!(matches!(read_checkpoint(&path), Err(CheckpointError::Foreign(_))));
    std::fs::remove_dir_all(&d).unwrap();
}

/// The fitness shape is part of the recorded setup: a checkpoint of a run that counts a fall's
/// distance reads back with that shape and differs from the default setup, so a caller comparing
/// setups (the `ga_step` executable) refuses to resume it under the other shape.
#[test]
fn the_fitness_shape_is_recorded() {
    let mut with_fall = setup(Crossover::Arithmetic);
    with_fall.fitness.distance_on_fall = true;
    let e = TestLandscape::new(NaoModel::default(), with_fall.fitness.clone());
    let s = GaState::start(with_fall.clone(), 3, &e, 1).unwrap();
    let text = to_json(&s, &TAG);
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["setup"]["fitness"]["distance_on_fall"], serde_json::json!(true));
    let back = from_json(&text).unwrap();
    assert!(back.setup.fitness.distance_on_fall);
    assert_eq!(back.setup, with_fall);
    assert_ne!(back.setup, setup(Crossover::Arithmetic));

    // The backward allowance too: a run under b = 0.25 m reads back with it.
    let mut allowance = setup(Crossover::Arithmetic);
    allowance.fitness.backward_allowance = 0.25;
    let e = TestLandscape::new(NaoModel::default(), allowance.fitness.clone());
    let text = to_json(&GaState::start(allowance.clone(), 3, &e, 1).unwrap(), &TAG);
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["version"], serde_json::json!(4));
    assert_eq!(v["setup"]["fitness"]["backward_allowance"], serde_json::json!(0.25));
    let back = from_json(&text).unwrap();
    assert_eq!(back.setup, allowance);
    assert_ne!(back.setup, setup(Crossover::Arithmetic));
}

/// The robust score's switch is recorded; a checkpoint written before it existed (no key) was
/// scored without it and reads back with it off, though a missing key elsewhere takes its
/// default (on, for this one).
#[test]
fn the_robust_score_switch_is_recorded_and_off_where_a_checkpoint_predates_it() {
    let s = setup(Crossover::Blx);
    assert!(s.fitness.robust_check);
    let e = TestLandscape::new(NaoModel::default(), s.fitness.clone());
    let text = to_json(&GaState::start(s.clone(), 3, &e, 1).unwrap(), &TAG);
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["setup"]["fitness"]["robust_check"], serde_json::json!(true));
    assert!(from_json(&text).unwrap().setup.fitness.robust_check);
    v["setup"]["fitness"]["robust_check"] = serde_json::json!(false);
    assert!(!from_json(&v.to_string()).unwrap().setup.fitness.robust_check);
    v["setup"]["fitness"].as_object_mut().unwrap().remove("robust_check");
    let old = from_json(&v.to_string()).unwrap();
    assert!(!old.setup.fitness.robust_check);
    // Every other field as written.
    let mut want = s;
    want.fitness.robust_check = false;
    assert_eq!(old.setup, want);
}

/// The evaluator is recorded and read back; a document without it is corrupt.
#[test]
fn the_evaluator_is_recorded() {
    let e = landscape();
    let s = GaState::start(setup(Crossover::Blx), 5, &e, 1).unwrap();
    for tag in [EvaluatorTag::Ros, EvaluatorTag::Physics { physics_version: 3 }] {
        let text = to_json(&s, &tag);
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        match tag {
            EvaluatorTag::Ros => assert_eq!(v["evaluator"], serde_json::json!({"kind": "ros"})),
            EvaluatorTag::Physics { .. } => assert_eq!(
                v["evaluator"],
                serde_json::json!({"kind": "physics", "physics_version": 3})
            ),
        }
        let (back, back_tag) = from_json_tagged(&text).unwrap();
        assert_eq!(back, s);
        assert_eq!(back_tag, tag);
    }
    let mut v: serde_json::Value = serde_json::from_str(&to_json(&s, &TAG)).unwrap();
    v.as_object_mut().unwrap().remove("evaluator");
    assert!(matches!(from_json(&v.to_string()), Err(CheckpointError::Corrupt(m)) if m.contains("evaluator")));
}

/// A file beyond the size cap is refused after reading the cap, not read whole: `/dev/zero`
/// has no end.
#[test]
fn an_endless_file_is_refused_by_its_size() {
    let t = std::time::Instant::now();
    let r = read_checkpoint_tagged(std::path::Path::new("/dev/zero"));
    assert!(
        matches!(&r, Err(CheckpointError::TooLarge { limit, .. }) if *limit == MAX_CHECKPOINT_BYTES),
        "{r:?}"
    );
    assert!(t.elapsed() < std::time::Duration::from_secs(20));
    assert_eq!(MAX_CHECKPOINT_BYTES, 128 * 1024 * 1024);
}
