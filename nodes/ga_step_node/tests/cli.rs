//! The `ga_step` executable as a user runs it: small populations for a few generations on the
//! physics evaluator (each run a few seconds), resume, Ctrl-C, and refused input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_ga_step");
const PARAMS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/nao_step.yaml");

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ga_step_cli_{}_{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn ga_step(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().unwrap()
}

/// `ga_step` with `--population`, `--generations`, `--seed` and `--crossover` given as text
/// (in that order), `--out` if given, then `extra`.
fn ga_step_opts([p, g, s, x]: [&str; 4], out: Option<&str>, extra: &[&str]) -> Output {
    let mut args = vec!["--population", p, "--generations", g, "--seed", s, "--crossover", x];
    if let Some(o) = out {
        args.extend(["--out", o]);
    }
    args.extend(extra);
    ga_step(&args)
}

fn run(out: &Path, population: u32, generations: u32, seed: u64, extra: &[&str]) -> Output {
    let (p, g, s) = (population.to_string(), generations.to_string(), seed.to_string());
    ga_step_opts([&p, &g, &s, "blx"], Some(out.to_str().unwrap()), extra)
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The generation number written in a checkpoint (0 while none is readable).
fn checkpoint_generation(dir: &Path) -> u64 {
    let Ok(text) = std::fs::read_to_string(dir.join("checkpoint.json")) else {
        return 0;
    };
    let Ok(v) = serde_json::from_str::<serde_json::Value>(&text) else {
        return 0;
    };
    v["generation"].as_u64().unwrap_or(0)
}

fn no_temporaries(dir: &Path) {
    for e in std::fs::read_dir(dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.ends_with(".tmp"), "{name} left in {}", dir.display());
    }
}

fn one_line_error(o: &Output, code: i32, contains: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(code), "stderr: {err}");
    assert_eq!(err.lines().count(), 1, "stderr: {err}");
    assert!(err.starts_with("ga_step: "), "stderr: {err}");
    assert!(err.contains(contains), "stderr: {err}");
    assert!(!err.contains("panicked"), "stderr: {err}");
}

#[test]
fn a_run_writes_every_output_and_a_resumed_run_equals_an_uninterrupted_one() {
    let (whole, split) = (scratch("whole"), scratch("split"));
    // A user's temporary file in DIR is left alone; one of ours from a killed run is removed.
    std::fs::create_dir_all(&whole).unwrap();
    std::fs::write(whole.join("notes.tmp"), b"mine").unwrap();
    std::fs::write(whole.join("best_gen_0030.motion.tmp"), b"half").unwrap();
    // --eval-timeout is the external evaluator's: with the physics, even 0 is not looked at.
    let o = run(&whole, 4, 4, 11, &["--eval-timeout", "0"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let line = String::from_utf8_lossy(&o.stdout);
    assert!(
        line.starts_with("ga_step: stopped at generation 4 by the requested generations"),
        "{line}"
    );
    let csv = read(&whole.join("fitness.csv"));
    // Header and generations 0 … 4.
    assert_eq!(csv.lines().count(), 6, "{csv}");
    assert_eq!(csv.lines().next(), Some("generation,max,mean,min"));
    for name in [
        "fitness.svg",
        "best.motion",
        "best_gen_0000.motion",
        "best_trajectory.yaml",
        "checkpoint.json",
    ] {
        assert!(whole.join(name).is_file(), "{name}");
    }
    // T = 2 s at 40 ms: a header and 51 rows.
    assert_eq!(read(&whole.join("best.motion")).lines().count(), 52);
    assert_eq!(read(&whole.join("notes.tmp")), "mine");
    std::fs::remove_file(whole.join("notes.tmp")).unwrap();
    no_temporaries(&whole);

    let o = run(&split, 4, 2, 11, &[]);
    assert!(o.status.success());
    assert_eq!(checkpoint_generation(&split), 2);
    let o = run(&split, 4, 4, 11, &["--resume"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for name in [
        "checkpoint.json",
        "fitness.csv",
        "best.motion",
        "best_trajectory.yaml",
        "fitness.svg",
    ] {
        assert_eq!(read(&whole.join(name)), read(&split.join(name)), "{name}");
    }
    // Resuming a finished run changes nothing.
    let o = run(&split, 4, 4, 11, &["--resume"]);
    assert!(o.status.success());
    assert_eq!(
        read(&whole.join("checkpoint.json")),
        read(&split.join("checkpoint.json"))
    );
    let _ = std::fs::remove_dir_all(&whole);
    let _ = std::fs::remove_dir_all(&split);
}

#[test]
fn ctrl_c_loses_at_most_the_generation_in_flight_and_the_run_resumes_to_the_same_end() {
    let (reference, stopped) = (scratch("reference"), scratch("stopped"));
    let o = run(&reference, 4, 12, 23, &["--threads", "1"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let child = Command::new(BIN)
        .args([
            "--population",
            "4",
            "--generations",
            "12",
            "--seed",
            "23",
            "--crossover",
            "blx",
        ])
        .args(["--threads", "1", "--out", stopped.to_str().unwrap()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(60);
    while checkpoint_generation(&stopped) < 2 {
        assert!(Instant::now() < deadline, "no checkpoint of generation 2 within 60 s");
        std::thread::sleep(Duration::from_millis(10));
    }
    let seen = checkpoint_generation(&stopped);
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let o = child.wait_with_output().unwrap();
    // Interrupted: exit status 130, the checkpoint whole and at or after the generation seen
    // (the generation in flight is finished and kept, so none is lost).
    assert_eq!(o.status.code(), Some(130), "{}", String::from_utf8_lossy(&o.stderr));
    let at_stop = checkpoint_generation(&stopped);
    assert!(at_stop >= seen && at_stop < 12, "{seen} {at_stop}");
    assert!(String::from_utf8_lossy(&o.stdout).contains("by an interrupt"));
    no_temporaries(&stopped);

    let o = run(&stopped, 4, 12, 23, &["--threads", "1", "--resume"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for name in ["checkpoint.json", "fitness.csv", "best.motion"] {
        assert_eq!(read(&reference.join(name)), read(&stopped.join(name)), "{name}");
    }
    let _ = std::fs::remove_dir_all(&reference);
    let _ = std::fs::remove_dir_all(&stopped);
}

/// With `--evaluator ros` and no simulator, Ctrl-C stops the wait for one at once (not after
/// the 30 s timeout): status 130, nothing written.
#[test]
fn ctrl_c_reaches_the_ros_evaluator() {
    let dir = scratch("ctrl_c_ros");
    let domain = (200 + std::process::id() % 30).to_string();
    let child = Command::new(BIN)
        .args([
            "--population",
            "4",
            "--generations",
            "2",
            "--seed",
            "1",
            "--crossover",
            "blx",
        ])
        .args([
            "--out",
            dir.to_str().unwrap(),
            "--evaluator",
            "ros",
            "--eval-timeout",
            "30",
        ])
        .env("ROS_DOMAIN_ID", &domain)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let t = Instant::now();
    interrupt(&child);
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(t.elapsed() < Duration::from_secs(5), "{:?} {err}", t.elapsed());
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(
        err.contains("interrupted during generation 0; no output written"),
        "{err}"
    );
    assert!(!dir.join("checkpoint.json").exists());
    assert!(!dir.join("fitness.csv").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Sends SIGINT to a child process.
fn interrupt(child: &std::process::Child) {
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
}

/// Ctrl-C during generation 0 (a population of 200 takes the physics seconds): the generation
/// is finished and written whole. Ctrl-C twice while a write holds the write lock (the hidden
/// `--write-delay-ms` pauses each output's write between its temporary file and the rename):
/// the process ends at once after that write, with status 130, and every file in DIR is whole:
/// no `.tmp`, and the checkpoint reads back with the fitness table of the same generation.
#[test]
fn ctrl_c_during_generation_0_and_a_second_ctrl_c_leave_whole_files() {
    let spawn = |dir: &Path, population: &str, extra: &[&str]| {
        Command::new(BIN)
            .args(["--population", population, "--generations", "40", "--seed", "3"])
            .args(["--crossover", "blx", "--threads", "1", "--out", dir.to_str().unwrap()])
            .args(extra)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    // Once, during generation 0: generation 0 is kept.
    let once = scratch("ctrl_c_once");
    let child = spawn(&once, "200", &[]);
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(checkpoint_generation(&once), 0);
    assert!(
        !once.join("checkpoint.json").exists(),
        "generation 0 done too soon for this test"
    );
    interrupt(&child);
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_str(&read(&once.join("checkpoint.json"))).unwrap();
    assert_eq!(v["generation"], serde_json::json!(0));
    assert_eq!(read(&once.join("fitness.csv")).lines().count(), 2);
    no_temporaries(&once);

    // Twice, while generation 1's fitness.csv.tmp is written and not yet renamed (fitness.csv,
    // fitness.svg, best.motion and best_trajectory.yaml pause 400 ms each, the checkpoint
    // none): the second Ctrl-C waits for the write lock, so the process ends after the
    // checkpoint of generation 1, about 1.6 s later, with no `.tmp` left.
    let twice = scratch("ctrl_c_twice");
    let child = spawn(&twice, "4", &["--write-delay-ms", "400"]);
    let deadline = Instant::now() + Duration::from_secs(60);
    while !(checkpoint_generation(&twice) == 0
        && twice.join("checkpoint.json").exists()
        && twice.join("fitness.csv.tmp").exists())
    {
        assert!(Instant::now() < deadline, "no write of generation 1 seen within 60 s");
        std::thread::sleep(Duration::from_millis(2));
    }
    interrupt(&child);
    std::thread::sleep(Duration::from_millis(20));
    interrupt(&child);
    let t = Instant::now();
    let o = child.wait_with_output().unwrap();
    let waited = t.elapsed();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    // The rest of the write: at least the three pauses after fitness.csv's, 1.2 s.
    assert!(
        waited >= Duration::from_millis(1150) && waited < Duration::from_secs(10),
        "{waited:?} {err}"
    );
    no_temporaries(&twice);
    let state = mobil_ga_step::read_checkpoint(&twice.join("checkpoint.json")).unwrap();
    assert_eq!(state.generation, 1);
    let csv = read(&twice.join("fitness.csv"));
    assert_eq!(csv.lines().count(), 3, "{csv}");
    let _ = std::fs::remove_dir_all(&once);
    let _ = std::fs::remove_dir_all(&twice);
}

#[test]
fn bad_options_are_one_line_errors() {
    let dir = scratch("options");
    let d = dir.to_str().unwrap();
    let o = ga_step_opts(["4", "1", "1", "uniform"], Some(d), &[]);
    one_line_error(&o, 2, "--crossover");
    let o = ga_step_opts(["many", "1", "1", "blx"], Some(d), &[]);
    one_line_error(&o, 2, "--population");
    let o = ga_step_opts(["4", "1", "1", "blx"], None, &[]);
    one_line_error(&o, 2, "--out");
    let o = ga_step_opts(["1", "1", "1", "blx"], Some(d), &[]);
    one_line_error(&o, 2, "--population");
    let o = ga_step_opts(["4", "1", "-3", "blx"], Some(d), &[]);
    one_line_error(&o, 2, "");
    // Beyond the population cap (10 000).
    let o = ga_step_opts(["10001", "1", "1", "blx"], Some(d), &[]);
    one_line_error(&o, 2, "--population");
    // A timeout beyond a day (1e20 s once overflowed the clock), or not a positive number.
    for t in ["1e20", "86401", "0", "NaN", "inf"] {
        let o = ga_step_opts(
            ["4", "1", "1", "blx"],
            Some(d),
            &["--evaluator", "ros", "--eval-timeout", t],
        );
        one_line_error(&o, 1, "--eval-timeout must be a number of seconds within (0, 86400]");
    }
    // A parameter file with an unknown key, a bad value, or none at all.
    std::fs::create_dir_all(std::env::temp_dir()).unwrap();
    let bad = std::env::temp_dir().join(format!("ga_step_cli_{}_bad.yaml", std::process::id()));
    let shipped = read(Path::new(PARAMS));
    for (text, want) in [
        (
            shipped.replace("blx_alpha:", "blx_alfa:"),
            "unknown parameter `blx_alfa`",
        ),
        (shipped.replace("fall_height: 0.20", "fall_height: -1"), "fall_height"),
        (
            shipped.replace("blx_alpha: 0.7", "blx_alpha: 0.7\n    offspring: 50"),
            "`offspring` is set by the --population option",
        ),
        (
            shipped.replace("blx_alpha: 0.7", "blx_alpha: 0.7\n    crossover: linear"),
            "`crossover` is set by the --crossover option",
        ),
    ] {
        std::fs::write(&bad, text).unwrap();
        let o = ga_step_opts(["4", "1", "1", "blx"], Some(d), &["--params", bad.to_str().unwrap()]);
        one_line_error(&o, 1, want);
    }
    std::fs::remove_file(&bad).unwrap();
    let o = ga_step_opts(["4", "1", "1", "blx"], Some(d), &["--params", "/nonexistent/nao.yaml"]);
    one_line_error(&o, 1, "cannot read /nonexistent/nao.yaml");
    // A malformed ROS argument.
    let o = ga_step_opts(["4", "1", "1", "blx"], Some(d), &["--ros-args", "-r"]);
    one_line_error(&o, 2, "`-r` needs a value");
    assert!(!dir.exists(), "a refused command line created {d}");
    // --help documents every option.
    let o = ga_step(&["--help"]);
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout);
    for opt in [
        "--population <N>",
        "--generations <G>",
        "--seed <S>",
        "--crossover",
        "--out <DIR>",
        "--resume",
        "--level-window <N>",
    ] {
        assert!(help.contains(opt), "{opt} missing from --help");
    }
    for c in ["blx", "arithmetic", "one-point", "geometric", "linear"] {
        assert!(help.contains(c), "{c} missing from --help");
    }
}

#[test]
fn a_missing_foreign_or_other_runs_checkpoint_is_refused_and_left_alone() {
    let dir = scratch("checkpoints");
    // Nothing to resume: refused before anything is created.
    let o = run(&dir, 4, 2, 1, &["--resume"]);
    one_line_error(&o, 1, "cannot resume");
    assert!(!dir.exists(), "a refused resume created {}", dir.display());
    std::fs::create_dir_all(&dir).unwrap();
    // A foreign file.
    std::fs::write(dir.join("checkpoint.json"), "{\"hello\": 1}").unwrap();
    let o = run(&dir, 4, 2, 1, &["--resume"]);
    one_line_error(&o, 1, "not a ga_step checkpoint");
    assert_eq!(read(&dir.join("checkpoint.json")), "{\"hello\": 1}");
    // Not JSON at all.
    std::fs::write(dir.join("checkpoint.json"), [0xff, 0xfe, 0x00]).unwrap();
    let o = run(&dir, 4, 2, 1, &["--resume"]);
    one_line_error(&o, 1, "cannot resume");
    // Another run's checkpoint.
    std::fs::remove_file(dir.join("checkpoint.json")).unwrap();
    assert!(run(&dir, 4, 1, 1, &[]).status.success());
    let before = read(&dir.join("checkpoint.json"));
    let o = run(&dir, 4, 2, 2, &["--resume"]);
    one_line_error(&o, 1, "seed 1 (asked 2)");
    let o = run(&dir, 6, 2, 1, &["--resume"]);
    one_line_error(&o, 1, "population 4 (asked 6)");
    // The same run evolved under the other fitness shape (a fall's distance counted, so
    // without the robust score).
    let mut v: serde_json::Value = serde_json::from_str(&before).unwrap();
    v["setup"]["fitness"]["distance_on_fall"] = serde_json::json!(true);
    v["setup"]["fitness"]["robust_check"] = serde_json::json!(false);
    let other_shape = v.to_string();
    std::fs::write(dir.join("checkpoint.json"), &other_shape).unwrap();
    let o = run(&dir, 4, 2, 1, &["--resume"]);
    one_line_error(
        &o,
        1,
        "fitness distance counted on a fall, backward allowance 1 m (asked distance counted only without a fall, backward allowance 1 m)",
    );
    assert_eq!(read(&dir.join("checkpoint.json")), other_shape);
    // The same run evolved under the previous upright shape (no backward allowance).
    let mut v: serde_json::Value = serde_json::from_str(&before).unwrap();
    v["setup"]["fitness"]["backward_allowance"] = serde_json::json!(0.0);
    let other_shape = v.to_string();
    std::fs::write(dir.join("checkpoint.json"), &other_shape).unwrap();
    let o = run(&dir, 4, 2, 1, &["--resume"]);
    one_line_error(
        &o,
        1,
        "backward allowance 0 m (asked distance counted only without a fall, backward allowance 1 m)",
    );
    assert_eq!(read(&dir.join("checkpoint.json")), other_shape);
    std::fs::write(dir.join("checkpoint.json"), &before).unwrap();
    // The levelling rule is part of the run: a resume with another window is refused.
    let o = run(&dir, 4, 2, 1, &["--resume", "--level-window", "0"]);
    one_line_error(&o, 1, "level window 20 (asked 0)");
    assert_eq!(read(&dir.join("checkpoint.json")), before);
    // Another evaluator: the checkpoint records the physics at its version, this asks for ros.
    let v: serde_json::Value = serde_json::from_str(&before).unwrap();
    let version = mobil_ga_step_sim::PHYSICS_VERSION;
    assert_eq!(
        v["evaluator"],
        serde_json::json!({"kind": "physics", "physics_version": version})
    );
    let o = run(&dir, 4, 2, 1, &["--resume", "--evaluator", "ros"]);
    one_line_error(
        &o,
        1,
        &format!("evaluator physics (model version {version}) (asked ros (an external simulator))"),
    );
    // Another version of the physics model.
    let mut v: serde_json::Value = serde_json::from_str(&before).unwrap();
    v["evaluator"]["physics_version"] = serde_json::json!(version + 1);
    let other_physics = v.to_string();
    std::fs::write(dir.join("checkpoint.json"), &other_physics).unwrap();
    let o = run(&dir, 4, 2, 1, &["--resume"]);
    one_line_error(
        &o,
        1,
        &format!(
            "evaluator physics (model version {}) (asked physics (model version {version}))",
            version + 1
        ),
    );
    assert_eq!(read(&dir.join("checkpoint.json")), other_physics);
    // Another parameter file: refused as other parameters.
    std::fs::write(dir.join("checkpoint.json"), &before).unwrap();
    let params = dir.join("slow.yaml");
    let shipped = read(Path::new(PARAMS));
    std::fs::write(&params, shipped.replace("step_time: 2.0", "step_time: 2.4")).unwrap();
    let o = run(&dir, 4, 2, 1, &["--resume", "--params", params.to_str().unwrap()]);
    one_line_error(&o, 1, "other parameters");
    // A parameter file that switches the robust score off: named.
    std::fs::write(&params, shipped.replace("robust_check: true", "robust_check: false")).unwrap();
    let o = run(&dir, 4, 2, 1, &["--resume", "--params", params.to_str().unwrap()]);
    one_line_error(&o, 1, "robust_check true (asked false)");
    // A fall's distance counted with the robust score on: refused before any work.
    std::fs::write(
        &params,
        shipped.replace("distance_on_fall: false", "distance_on_fall: true"),
    )
    .unwrap();
    let fresh = scratch("distance_on_fall_robust");
    let o = run(&fresh, 4, 2, 1, &["--params", params.to_str().unwrap()]);
    one_line_error(&o, 1, "robust_check needs distance_on_fall false");
    assert!(!fresh.exists(), "a refused setup created {}", fresh.display());
    let _ = std::fs::remove_dir_all(&fresh);
    // A run scored under that combination (before it was refused) cannot be continued, with
    // the robust score or without.
    let mut v: serde_json::Value = serde_json::from_str(&before).unwrap();
    v["setup"]["fitness"]["distance_on_fall"] = serde_json::json!(true);
    let unoffered = v.to_string();
    std::fs::write(dir.join("checkpoint.json"), &unoffered).unwrap();
    let without = shipped
        .replace("distance_on_fall: false", "distance_on_fall: true")
        .replace("robust_check: true", "robust_check: false");
    std::fs::write(&params, without).unwrap();
    let o = run(&dir, 4, 2, 1, &["--resume", "--params", params.to_str().unwrap()]);
    one_line_error(&o, 1, "no longer offered");
    assert_eq!(read(&dir.join("checkpoint.json")), unoffered);
    std::fs::write(dir.join("checkpoint.json"), &before).unwrap();
    std::fs::remove_file(&params).unwrap();
    // A run of the external evaluator from before the robust score's switch (no key, read as
    // off): the switch is the built-in physics' alone, so the shipped parameters (on) resume it.
    let mut v: serde_json::Value = serde_json::from_str(&before).unwrap();
    v["evaluator"] = serde_json::json!({"kind": "ros"});
    v["setup"]["fitness"].as_object_mut().unwrap().remove("robust_check");
    std::fs::write(dir.join("checkpoint.json"), v.to_string()).unwrap();
    let o = run(
        &dir,
        4,
        1,
        1,
        &["--resume", "--evaluator", "ros", "--eval-timeout", "1"],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    std::fs::write(dir.join("checkpoint.json"), &before).unwrap();
    // A new run over an existing one.
    let o = run(&dir, 4, 2, 1, &[]);
    one_line_error(&o, 1, "already holds a run");
    assert_eq!(read(&dir.join("checkpoint.json")), before);
    no_temporaries(&dir);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_unwritable_output_directory_is_refused_before_any_work() {
    let dir = scratch("unwritable");
    std::fs::create_dir_all(&dir).unwrap();
    // A regular file where the directory should be (root may write anywhere, so permissions
    // would not stop this test's user).
    let file = dir.join("a_file");
    std::fs::write(&file, "x").unwrap();
    let t = Instant::now();
    let o = run(&file.join("out"), 4, 2, 1, &[]);
    one_line_error(&o, 1, "cannot create output directory");
    assert!(t.elapsed() < Duration::from_secs(5));
    let o = run(&file, 4, 2, 1, &[]);
    one_line_error(&o, 1, "output directory");
    assert_eq!(read(&file), "x");
    let _ = std::fs::remove_dir_all(&dir);
}
