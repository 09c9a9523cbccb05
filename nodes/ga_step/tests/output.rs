//! The run's files: the Webots motion file's exact format and its round trip through our reader,
//! the JointTrajectory YAML and `fitness.csv`.

use mobil_ga_step::output::{generation_motion_name, motion_rows, motion_time, remove_temporaries, FITNESS_CSV_HEADER};
use mobil_ga_step::{
    read_motion, write_fitness_csv, write_joint_trajectory_yaml, write_motion, GenerationStats, Individual,
    MotionError, NaoModel,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn individual(seed: u64) -> (NaoModel, Individual) {
    let m = NaoModel::default();
    let ind = m.random_individual(&mut ChaCha8Rng::seed_from_u64(seed));
    (m, ind)
}

fn motion_text(m: &NaoModel, ind: &Individual) -> String {
    let mut out = Vec::new();
    write_motion(&mut out, m, ind).unwrap();
    String::from_utf8(out).unwrap()
}

#[test]
fn motion_times_are_minutes_seconds_milliseconds() {
    assert_eq!(motion_time(0), "00:00:000");
    assert_eq!(motion_time(40), "00:00:040");
    assert_eq!(motion_time(1960), "00:01:960");
    assert_eq!(motion_time(2000), "00:02:000");
    assert_eq!(motion_time(61_080), "01:01:080");
}

/// The format, line by line: the header with the ten Webots joint names in the SPEC's order;
/// 51 rows (0 … 2000 ms every 40 ms) labelled Pose1 … Pose51; ten values each with exactly 4
/// decimals; the first and last rows at the standing pose.
#[test]
fn the_motion_file_has_the_webots_format() {
    let (m, ind) = individual(1);
    let text = motion_text(&m, &ind);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0],
        "#WEBOTS_MOTION,V1.0,RHipPitch,RHipRoll,RKneePitch,RAnklePitch,RAnkleRoll,\
         LHipPitch,LHipRoll,LKneePitch,LAnklePitch,LAnkleRoll"
    );
    assert_eq!(lines.len(), 52);
    assert_eq!(motion_rows(&m), 51);
    for (k, line) in lines[1..].iter().enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 12, "{line}");
        let ms = 40 * k as u64;
        assert_eq!(
            f[0],
            format!("{:02}:{:02}:{:03}", ms / 60000, ms / 1000 % 60, ms % 1000)
        );
        assert_eq!(f[1], format!("Pose{}", k + 1));
        for v in &f[2..] {
            let (int, dec) = v.split_once('.').unwrap();
            assert_eq!(dec.len(), 4, "{v}");
            assert!(dec.bytes().all(|b| b.is_ascii_digit()));
            assert!(int.trim_start_matches('-').bytes().all(|b| b.is_ascii_digit()));
            assert_ne!(*v, "-0.0000");
        }
    }
    assert_eq!(
        lines[1],
        "00:00:000,Pose1,-0.4000,0.0000,0.8000,-0.4000,0.0000,-0.4000,0.0000,0.8000,-0.4000,0.0000"
    );
    assert_eq!(
        lines[51],
        "00:02:000,Pose51,-0.4000,0.0000,0.8000,-0.4000,0.0000,-0.4000,0.0000,0.8000,-0.4000,0.0000"
    );
    assert!(text.ends_with('\n'));
}

/// A row between knots, worked out by hand: at 160 ms (0.6 of the way from knot 1 at 100 ms to
/// knot 2 at 200 ms) the value is k1 + 0.6·(k2 − k1).
#[test]
fn a_row_interpolates_between_knots() {
    let m = NaoModel::default();
    let mut ind = m.standing();
    ind.knots[2][1] = 1.0; // RKneePitch at 100 ms
    ind.knots[2][2] = 2.0; // … at 200 ms
    let text = motion_text(&m, &ind);
    let row = text.lines().nth(1 + 160 / 40).unwrap();
    assert!(row.starts_with("00:00:160,Pose5,-0.4000,0.0000,1.6000,"), "{row}");
    // 40 ms: 0.4 of the way from 0.8 to 1.0, 0.88.
    let row = text.lines().nth(2).unwrap();
    assert!(row.starts_with("00:00:040,Pose2,-0.4000,0.0000,0.8800,"), "{row}");
}

/// Write → read: the names, the times and labels, and every value within the 4 decimals'
/// rounding (5e-5) of the individual's angle at that time.
#[test]
fn the_motion_file_round_trips_through_the_reader() {
    for seed in 0..20 {
        let (m, ind) = individual(seed);
        let motion = read_motion(motion_text(&m, &ind).as_bytes()).unwrap();
        assert_eq!(motion.joint_names, mobil_ga_step::joint_names().to_vec());
        assert_eq!(motion.rows.len(), 51);
        for (k, row) in motion.rows.iter().enumerate() {
            assert_eq!(row.time_ms, 40 * k as u64);
            assert_eq!(row.label, format!("Pose{}", k + 1));
            let angles = ind.angles_at(row.time_ms as f64 / 1000.0, 2.0);
            for (v, a) in row.values.iter().zip(angles) {
                assert!((v - a).abs() <= 5e-5 + 1e-12, "{v} vs {a}");
            }
        }
    }
}

#[test]
fn a_motion_file_gives_back_its_individual_within_the_files_rounding() {
    // 2 s steps: knots every 100 ms, rows every 40 ms, so the odd knots lie between rows and are
    // extrapolated from the first and last rows before them in their interval (a knot at 100 ms
    // from the rows at 0 and 80: r = 20/80, within 5e-5·1.5 of the file's rounding; at 300 ms
    // from 200 and 280). A 1.2 s step: knots every 60 ms, every other one on a row, the others
    // from two rows 40 ms apart 20 ms before them (r = ½: 1e-4). A 2.08 s step: knots every
    // 104 ms; knot 1 at 104 ms from the rows at 0 and 80 (r = 24/80), knot 2 at 208 from 120
    // and 200 (r = 8/80), and the worst, knot 3 at 312 ms from the only two rows in its
    // interval, 240 and 280 (r = 32/40 = 0.8: 5e-5·2.6 = 1.3e-4); every fifth knot on a row.
    // The ends at the standing pose.
    for (step_time, seeds, bound) in [(2.0, 0..10, 7.5e-5), (1.2, 10..15, 1e-4), (2.08, 15..20, 1.3e-4)] {
        let m = NaoModel {
            step_time,
            ..NaoModel::default()
        };
        for seed in seeds {
            let ind = m.random_individual(&mut ChaCha8Rng::seed_from_u64(seed));
            let back = read_motion(motion_text(&m, &ind).as_bytes())
                .unwrap()
                .to_individual(&m)
                .unwrap();
            for (s, (got, want)) in back.knots.iter().zip(&ind.knots).enumerate() {
                for (k, (g, w)) in got.iter().zip(want).enumerate() {
                    assert!(
                        (g - w).abs() <= bound + 1e-12,
                        "seed {seed} servo {s} knot {k}: {g} vs {w}"
                    );
                }
                assert_eq!((got[0], got[got.len() - 1]), (want[0], want[want.len() - 1]));
            }
        }
    }
    // Knots at the servos' limits (evolved individuals have many; the clamp must not move them
    // off), in a 60 s step (1500 rows, knots every 3 s).
    let long = NaoModel {
        step_time: 60.0,
        ..NaoModel::default()
    };
    let mut limits = long.random_individual(&mut ChaCha8Rng::seed_from_u64(21));
    for s in mobil_ga_step::Servo::ALL {
        let (lo, hi) = s.limits();
        for k in 1..mobil_ga_step::KNOTS - 1 {
            limits.knots[s.index()][k] = if k % 2 == 0 { lo } else { hi };
        }
    }
    let back = read_motion(motion_text(&long, &limits).as_bytes())
        .unwrap()
        .to_individual(&long)
        .unwrap();
    for (got, want) in back.knots.iter().zip(&limits.knots) {
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() <= 7.5e-5, "{g} vs {w}");
        }
    }
    // By hand: one interval's rows at 0 ms (the standing −0.4), 40 ms and 80 ms, set on a line
    // through −0.4 and −0.6 at 80 ms, put the 100 ms knot at −0.65; the rows written from
    // that individual are the same line, so the check passes.
    let m = NaoModel::default();
    let (_, ind) = individual(3);
    let mut motion = read_motion(motion_text(&m, &ind).as_bytes()).unwrap();
    motion.rows[1].values[0] = -0.5;
    motion.rows[2].values[0] = -0.6;
    // Rows 3 and 4 (120, 160 ms) lie on the line from the 100 ms knot to the 200 ms one.
    let k2 = motion.rows[5].values[0];
    motion.rows[3].values[0] = -0.65 + (k2 + 0.65) * 0.2;
    motion.rows[4].values[0] = -0.65 + (k2 + 0.65) * 0.6;
    let back = motion.to_individual(&m).unwrap();
    assert!((back.knots[0][1] - -0.65).abs() < 1e-12, "{}", back.knots[0][1]);
}

#[test]
fn a_motion_no_individual_of_the_model_gives_is_refused() {
    let (m, ind) = individual(4);
    let text = motion_text(&m, &ind);
    let not_a_step = |motion: &mobil_ga_step::Motion, model: &NaoModel| match motion.to_individual(model) {
        Err(MotionError::NotAStep(r)) => r,
        other => panic!("{other:?}"),
    };
    let motion = read_motion(text.as_bytes()).unwrap();
    let slower = NaoModel {
        step_time: 2.4,
        ..NaoModel::default()
    };
    assert_eq!(
        not_a_step(&motion, &slower),
        "the last row is at 2000 ms, the step lasts 2400 ms"
    );
    let renamed = read_motion(text.replacen("LAnkleRoll", "LAnkleRoll2", 1).as_bytes()).unwrap();
    assert_eq!(not_a_step(&renamed, &m), "no column LAnkleRoll");
    // A 0.4 s step: knots every 20 ms, the one at 20 ms with a single row (0 ms) before it.
    let short = NaoModel {
        step_time: 0.4,
        ..NaoModel::default()
    };
    let s = short.random_individual(&mut ChaCha8Rng::seed_from_u64(5));
    let r = not_a_step(&read_motion(motion_text(&short, &s).as_bytes()).unwrap(), &short);
    assert!(r.starts_with("knot 1 at 20 ms has fewer than two rows"), "{r}");
    // 0.88 s: knots every 44 ms; the one at 88 ms has the row at 80 ms alone in its interval.
    let odd = NaoModel {
        step_time: 0.88,
        ..NaoModel::default()
    };
    let s = odd.random_individual(&mut ChaCha8Rng::seed_from_u64(6));
    let r = not_a_step(&read_motion(motion_text(&odd, &s).as_bytes()).unwrap(), &odd);
    assert!(r.starts_with("knot 2 at 88 ms has fewer than two rows"), "{r}");
    // Another standing pose: the first row is not this model's.
    let crouched = NaoModel {
        standing_pose: m.standing_pose.map(|q| q * 1.1),
        ..NaoModel::default()
    };
    let r = not_a_step(&motion, &crouched);
    assert!(r.starts_with("RHipPitch at 0 ms is -0.4"), "{r}");
    // A row off the motion by 1e-3 rad (a hand edit, or not piecewise linear on this grid):
    // the one at 240 ms, between the rows (200 and 280 ms) that give the knot at 300 ms.
    let mut edited = motion.clone();
    edited.rows[6].values[2] += 1e-3;
    let r = not_a_step(&edited, &m);
    assert!(r.starts_with("RKneePitch at 240 ms"), "{r}");
    // A row without the value (rows built by hand; the reader never gives one).
    let mut short_row = motion.clone();
    short_row.rows[3].values.truncate(4);
    let r = not_a_step(&short_row, &m);
    assert_eq!(r, "the row at 120 ms has no RAnkleRoll");
}

/// The reader also takes the source's spaced form with its empty field after the version.
#[test]
fn the_reader_takes_the_sources_spaced_form() {
    let text = "#WEBOTS_MOTION,V1.0,, RHipPitch, RHipRoll\n00:00:000,Pose1, -0.4000, 0.0000\n00:00:040,Pose2, -0.3000, 0.1000\n";
    let m = read_motion(text.as_bytes()).unwrap();
    assert_eq!(m.joint_names, ["RHipPitch", "RHipRoll"]);
    assert_eq!(m.rows[1].values, [-0.3, 0.1]);
    assert_eq!(m.rows[1].time_ms, 40);
}

#[test]
fn bad_motion_files_are_refused_with_the_line() {
    let bad = |t: &str| read_motion(t.as_bytes()).unwrap_err();
    assert_eq!(bad(""), MotionError::BadHeader);
    assert_eq!(bad("#WEBOTS_MOTION,V2.0,A\n"), MotionError::BadHeader);
    assert_eq!(bad("#WEBOTS_MOTION,V1.0,\n"), MotionError::BadHeader);
    let h = "#WEBOTS_MOTION,V1.0,A,B\n";
    let cases = [
        (format!("{h}00:00:000,Pose1,1.0\n"), 2),
        (format!("{h}00:00:000,Pose1,1.0,x\n"), 2),
        (format!("{h}00:00:000,Pose1,1.0,NaN\n"), 2),
        (format!("{h}0:00:000,Pose1,1.0,2.0\n"), 2),
        (format!("{h}00:60:000,Pose1,1.0,2.0\n"), 2),
        (format!("{h}00:00:040,Pose1,1,2\n00:00:040,Pose2,1,2\n"), 3),
        (format!("{h}00:00:080,Pose1,1,2\n\n00:00:040,Pose2,1,2\n"), 4),
        (format!("{h}00:00:000,,1,2\n"), 2),
    ];
    for (text, line) in cases {
        match bad(&text) {
            MotionError::BadRow { line: l, .. } => assert_eq!(l, line, "{text}"),
            e => panic!("{text}: {e:?}"),
        }
    }
}

/// The JointTrajectory YAML parses as YAML into the message's shape: ten joint names, 21 points
/// at i·0.1 s as (sec, nanosec), positions equal to the knots exactly.
#[test]
fn the_joint_trajectory_yaml_has_the_message_shape() {
    let (m, ind) = individual(3);
    let mut out = Vec::new();
    write_joint_trajectory_yaml(&mut out, &m, &ind).unwrap();
    let y: serde_norway::Value = serde_norway::from_slice(&out).unwrap();
    let names: Vec<&str> = y["joint_names"]
        .as_sequence()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(names, mobil_ga_step::joint_names());
    let points = y["points"].as_sequence().unwrap();
    assert_eq!(points.len(), 21);
    for (i, p) in points.iter().enumerate() {
        let t = &p["time_from_start"];
        let ns = i as u64 * 100_000_000;
        assert_eq!(t["sec"].as_u64(), Some(ns / 1_000_000_000));
        assert_eq!(t["nanosec"].as_u64(), Some(ns % 1_000_000_000));
        let pos: Vec<f64> = p["positions"]
            .as_sequence()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let knots: Vec<f64> = ind.knots.iter().map(|k| k[i]).collect();
        assert_eq!(pos, knots);
    }
    assert_eq!(points[20]["time_from_start"]["sec"].as_u64(), Some(2));
    // No exponent form (PyYAML reads `1e-7` as a string), and a point in every number.
    let mut tiny = m.standing();
    tiny.knots[1][5] = 1e-7;
    let mut out = Vec::new();
    write_joint_trajectory_yaml(&mut out, &m, &tiny).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains("[-0.4, 0.0000001, 0.8,"), "{text}");
    assert!(!text.contains("e-"));
}

#[test]
fn fitness_csv_has_a_header_and_one_row_per_generation() {
    let row = |g: u32, max: f64, mean: f64, min: f64| GenerationStats {
        generation: g,
        max,
        mean,
        min,
        best_fell: true,
        best_forward: 0.0,
        invalid_fitness: 0,
        evaluations: 100,
    };
    let mut out = Vec::new();
    write_fitness_csv(&mut out, &[row(0, 0.9, 0.25, 0.0), row(1, 1.125, 0.5, 0.1)]).unwrap();
    assert_eq!(
        String::from_utf8(out).unwrap(),
        format!("{FITNESS_CSV_HEADER}\n0,0.9,0.25,0\n1,1.125,0.5,0.1\n")
    );
    assert_eq!(FITNESS_CSV_HEADER, "generation,max,mean,min");
}

#[test]
fn only_a_runs_temporaries_are_removed() {
    let dir = std::env::temp_dir().join(format!("ga_step_temporaries_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let ours = [
        "fitness.csv.tmp",
        "fitness.svg.tmp",
        "best.motion.tmp",
        "best_trajectory.yaml.tmp",
        "checkpoint.json.tmp",
        "best_gen_0010.motion.tmp",
        "best_gen_12340.motion.tmp",
    ];
    let theirs = [
        "notes.tmp",
        "fitness.csv",
        "best_gen_12.motion.tmp",
        "best_gen_00x0.motion.tmp",
        "my_fitness.csv.tmp",
        "checkpoint.json.tmp.tmp",
    ];
    for name in ours.iter().chain(&theirs) {
        std::fs::write(dir.join(name), b"x").unwrap();
    }
    remove_temporaries(&dir);
    let mut left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    left.sort();
    let mut want: Vec<String> = theirs.iter().map(|s| s.to_string()).collect();
    want.sort();
    assert_eq!(left, want);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn motion_files_are_numbered_with_four_digits() {
    assert_eq!(generation_motion_name(0), "best_gen_0000.motion");
    assert_eq!(generation_motion_name(140), "best_gen_0140.motion");
}
