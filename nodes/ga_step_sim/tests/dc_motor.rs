//! The earlier physics model, `physics: dc-motor` ([`BodyParams::dc_motor`]), against what a
//! body of Nao's figures must do, and against the runs made under it: it scores as it did. Each
//! test simulates at most T_sim = 3 s.

use mobil_ga_step::{
    evaluate_all, Evaluation, Evaluator, FitnessConfig, Individual, NaoModel, PhysicsModel, Servo, KNOTS, SERVO_COUNT,
};
use mobil_ga_step_sim::{
    motions, BodyParams, FallCause, PhysicsEvaluator, SimError, SimOutcome, SolverSetting, CHECK_SETTING,
    PHYSICS_VERSION,
};
use rand::{Rng, SeedableRng};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

/// The default fitness with the DC-motor model.
fn dc_fitness() -> FitnessConfig {
    FitnessConfig {
        physics: PhysicsModel::DcMotor,
        ..FitnessConfig::default()
    }
}

fn evaluator() -> PhysicsEvaluator {
    PhysicsEvaluator::new(NaoModel::default(), dc_fitness()).unwrap()
}

/// An evaluator of one setting alone (no robust score): the default body at `setting`.
fn single(setting: SolverSetting) -> PhysicsEvaluator {
    let fitness = FitnessConfig {
        robust_check: false,
        ..dc_fitness()
    };
    PhysicsEvaluator::with_body(NaoModel::default(), fitness, setting.apply(&BodyParams::dc_motor())).unwrap()
}

/// The default solver setting, 5 ms, 4 iterations of 2 passes.
const DEFAULT: SolverSetting = SolverSetting {
    dt: 0.005,
    solver_iterations: 4,
    pgs_iterations: 2,
};

/// Every inner knot of `servos` at `value`.
fn hold(model: &NaoModel, servos: &[(Servo, f64)]) -> Individual {
    let mut ind = model.standing();
    for &(s, v) in servos {
        for k in 1..KNOTS - 1 {
            ind.knots[s.index()][k] = v;
        }
    }
    ind
}

/// The mirror image in the sagittal plane: left and right swapped, rolls negated (Table 1's
/// roll limits mirror, so the image is within the limits).
fn mirrored(ind: &Individual) -> Individual {
    let pairs = [
        (Servo::RHipPitch, Servo::LHipPitch, 1.0),
        (Servo::RHipRoll, Servo::LHipRoll, -1.0),
        (Servo::RKneePitch, Servo::LKneePitch, 1.0),
        (Servo::RAnklePitch, Servo::LAnklePitch, 1.0),
        (Servo::RAnkleRoll, Servo::LAnkleRoll, -1.0),
    ];
    let mut m = ind.clone();
    for (r, l, sign) in pairs {
        for k in 0..KNOTS {
            m.knots[r.index()][k] = sign * ind.knots[l.index()][k];
            m.knots[l.index()][k] = sign * ind.knots[r.index()][k];
        }
    }
    m
}

#[test]
fn knees_fully_bent_at_once_make_the_robot_fall() {
    let ev = evaluator();
    let model = NaoModel::default();
    let bent = hold(&model, &[(Servo::RKneePitch, 2.2689), (Servo::LKneePitch, 2.2689)]);
    let o = ev.simulate(&bent);
    // The knees reach 2.27 rad at 6.4 rad/s within 0.25 s, folding the legs under a torso
    // 0.32 m up: a free fall from there takes √(2·0.12/9.81) ≈ 0.16 s to pass 0.20 m, so the
    // fall (height or tilt) comes well before 0.5 s.
    assert!(o.fell, "{o:?}");
    assert!(o.t_end > 0.0 && o.t_end < 0.5, "{o:?}");
    let e = ev.evaluate(&bent);
    assert!(e.fell);
    // A fall scores its time alone: f = t_fall/3 s < 0.5/3, whatever Δx.
    assert!(e.fitness < 0.5 / 3.0, "{e:?}");
    assert!((e.fitness - e.t_fall / 3.0).abs() < 1e-12, "{e:?}");
}

#[test]
fn standing_still_for_the_whole_step_does_not_fall_and_stays_put() {
    let ev = evaluator();
    let model = NaoModel::default();
    let o = ev.simulate(&model.standing());
    assert!(!o.fell && o.cause.is_none(), "{o:?}");
    assert_eq!(o.t_end, 3.0);
    assert_eq!(o.steps, 600);
    // Torso frame height by hand: foot 45.19 mm + (thigh 100 + tibia 102.9 mm)·cos 0.4 +
    // hip offset 85 mm = 0.04519 + 0.2029·0.921061 + 0.085 = 0.317073 m (f32 placement).
    assert!((o.start_height - 0.317073).abs() < 1e-4, "{o:?}");
    // Held servos sag by a few millimetres under the load (1 N·m at 156 N·m/rad is 6 mrad),
    // which moves the torso down, not along: nothing pushes it forward or sideways, so it stays
    // within 2 mm of where it stood (a twentieth of the 4 cm that counts as a step).
    assert!(o.forward_distance.abs() < 0.002, "{o:?}");
    assert!(o.lateral_distance.abs() < 0.002, "{o:?}");
    assert!((o.end_height - o.start_height).abs() < 0.005, "{o:?}");
    assert!(o.max_tilt < 0.05, "{o:?}");
    let e = ev.evaluate(&model.standing());
    // No fall: t_fall = T_sim, f = 1 + 2·max(0, Δx + 1 m) with |Δx| < 1 cm: 3 ± 0.02.
    assert!(!e.fell && e.t_fall == 3.0);
    assert!((e.fitness - 3.0).abs() < 0.02, "{e:?}");
}

#[test]
fn a_mirrored_individual_moves_the_torso_the_mirrored_way() {
    let ev = evaluator();
    let model = NaoModel::default();
    // Both hip rolls +0.3 rad: the left leg spreads out, the right one swings in, so the torso
    // is pushed to the right (−y) and topples that way; the mirror image pushes it left.
    let ind = hold(&model, &[(Servo::RHipRoll, 0.3), (Servo::LHipRoll, 0.3)]);
    let image = mirrored(&ind);
    assert_eq!(image.validate(&model), Ok(()));
    let (a, b) = (ev.simulate(&ind), ev.simulate(&image));
    assert!(a.fell && b.fell, "{a:?} {b:?}");
    assert!(a.lateral_distance < -0.1, "{a:?}");
    assert!(b.lateral_distance > 0.1, "{b:?}");
    // Mirror images: lateral motions equal and opposite within 10 %, falls within 0.1 s, the
    // same forward motion within 2 cm (the solver treats the legs in a fixed order, so the
    // image is not exact).
    assert!(
        (a.lateral_distance + b.lateral_distance).abs() < 0.1 * a.lateral_distance.abs(),
        "{a:?} {b:?}"
    );
    assert!((a.t_end - b.t_end).abs() < 0.1, "{a:?} {b:?}");
    assert!((a.forward_distance - b.forward_distance).abs() < 0.02, "{a:?} {b:?}");
}

#[test]
fn the_same_individual_gives_the_same_evaluation_bit_for_bit_on_any_thread() {
    // The robust score (the default and the check setting), as ga_step uses it.
    let ev = evaluator();
    assert_eq!(ev.check_bodies().len(), 1);
    let model = NaoModel::default();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    // Gentle random motions (a quarter of each range around the standing pose) that stay up
    // for a while, so the comparison covers many steps.
    let batch: Vec<Individual> = (0..4)
        .map(|_| motions::gentle(&model, 0.125, &mut || rng.random::<f64>()))
        .collect();
    let one = evaluate_all(&ev, &batch, 1);
    let two = evaluate_all(&ev, &batch, 2);
    let again: Vec<_> = batch.iter().rev().map(|i| ev.evaluate(i)).collect();
    for (i, ((a, b), c)) in one.iter().zip(&two).zip(again.iter().rev()).enumerate() {
        for (x, y) in [(a, b), (a, c)] {
            assert_eq!(x.fitness.to_bits(), y.fitness.to_bits(), "individual {i}");
            assert_eq!(x.t_fall.to_bits(), y.t_fall.to_bits(), "individual {i}");
            assert_eq!(
                x.forward_distance.to_bits(),
                y.forward_distance.to_bits(),
                "individual {i}"
            );
            assert_eq!(x.fell, y.fell, "individual {i}");
        }
    }
}

#[test]
fn the_motor_figures_are_the_re_max_24_through_naos_reductions() {
    let b = BodyParams::dc_motor();
    // Continuous torques: the RE-Max 24's nominal 12.3 mN·m × 130.85 = 1.609 N·m (the
    // documentation prints 1.61) and × 201.3 = 2.476 N·m (the documentation prints 2.47, which
    // the body keeps: its runs were scored with it). Stall torques: 59.5 mN·m × 130.85 = 7.786
    // N·m (7.78) and × 201.3 = 11.977 N·m (11.97). No-load speeds: 8000 rpm ÷ 130.85 =
    // 366.83 °/s = 6.4024 rad/s and ÷ 201.3 = 238.45 °/s = 4.1618 rad/s.
    assert!((b.max_torque(Servo::LKneePitch) - 0.0123 * 130.85).abs() < 0.01);
    assert!((b.max_torque(Servo::RAnkleRoll) - 0.0123 * 201.3).abs() < 0.01);
    assert!((b.stall_torque(Servo::LKneePitch) - 0.0595 * 130.85).abs() < 0.01);
    assert!((b.stall_torque(Servo::RAnkleRoll) - 0.0595 * 201.3).abs() < 0.01);
    assert!((b.max_speed(Servo::LKneePitch) - 8000.0 / 60.0 * 2.0 * std::f64::consts::PI / 130.85).abs() < 0.001);
    assert!((b.max_speed(Servo::RHipRoll) - 8000.0 / 60.0 * 2.0 * std::f64::consts::PI / 201.3).abs() < 0.001);
}

#[test]
fn bad_body_figures_are_refused() {
    let body = BodyParams {
        dt: 0.0,
        ..BodyParams::dc_motor()
    };
    let r = PhysicsEvaluator::with_body(NaoModel::default(), dc_fitness(), body);
    assert_eq!(r.err(), Some(SimError::BadBody { name: "dt", value: 0.0 }));
    // The time step within 10 µs … 50 ms, both ends accepted.
    for (dt, ok) in [
        (1e-5, true),
        (0.05, true),
        (0.9e-5, false),
        (0.051, false),
        (1.0, false),
    ] {
        let body = BodyParams {
            dt,
            ..BodyParams::dc_motor()
        };
        let r = PhysicsEvaluator::with_body(NaoModel::default(), dc_fitness(), body);
        if ok {
            assert!(r.is_ok(), "dt {dt}");
        } else {
            assert_eq!(r.err(), Some(SimError::BadTimeStep { value: dt }));
        }
    }
    // A check setting's time step is checked too.
    let fine = SolverSetting {
        dt: 1e-6,
        ..CHECK_SETTING
    };
    let fitness = dc_fitness();
    let r = PhysicsEvaluator::with_checks(NaoModel::default(), fitness, BodyParams::dc_motor(), &[fine]);
    assert_eq!(r.err(), Some(SimError::BadTimeStep { value: 1e-6 }));
    let body = BodyParams {
        friction: f64::NAN,
        ..BodyParams::dc_motor()
    };
    assert!(matches!(
        PhysicsEvaluator::with_body(NaoModel::default(), dc_fitness(), body),
        Err(SimError::BadBody { name: "friction", .. })
    ));
    // Solver counts within 1 … 256 (usize::MAX would never finish a step).
    for (it, pgs, name, value) in [
        (0, 2, "solver_iterations", 0),
        (usize::MAX, 2, "solver_iterations", usize::MAX),
        (4, 257, "pgs_iterations", 257),
        (4, 0, "pgs_iterations", 0),
    ] {
        let body = BodyParams {
            solver_iterations: it,
            pgs_iterations: pgs,
            ..BodyParams::dc_motor()
        };
        let r = PhysicsEvaluator::with_body(NaoModel::default(), dc_fitness(), body);
        assert_eq!(r.err(), Some(SimError::BadSolverCount { name, value }));
    }
    let body = BodyParams {
        solver_iterations: 256,
        pgs_iterations: 1,
        ..BodyParams::dc_motor()
    };
    assert!(PhysicsEvaluator::with_body(NaoModel::default(), dc_fitness(), body).is_ok());
    // A stall torque below the continuous one would cut the torque at rest.
    let body = BodyParams {
        roll_stall_torque: 2.0,
        ..BodyParams::dc_motor()
    };
    assert_eq!(
        PhysicsEvaluator::with_body(NaoModel::default(), dc_fitness(), body).err(),
        Some(SimError::StallBelowContinuous {
            joints: "roll",
            stall: 2.0,
            continuous: 2.47
        })
    );
}

/// The individuals of `fixtures/blx1_gen56.txt` with the evaluation a `ga_step` run stored for
/// each, every figure as the bits of its double.
fn stored_individuals() -> Vec<(Individual, Evaluation)> {
    parse_fixture(include_str!("fixtures/blx1_gen56.txt"))
}

/// Individuals and stored evaluations from a fixture's text (see its header).
fn parse_fixture(text: &str) -> Vec<(Individual, Evaluation)> {
    let bits = |t: &str| f64::from_bits(u64::from_str_radix(t, 16).expect("fixture: hexadecimal bits"));
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let t: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(t.len(), 4 + SERVO_COUNT * KNOTS, "fixture line");
            let mut ind = NaoModel::default().standing();
            for s in 0..SERVO_COUNT {
                for k in 0..KNOTS {
                    ind.knots[s][k] = bits(t[4 + s * KNOTS + k]);
                }
            }
            let e = Evaluation {
                fell: t[0] == "1",
                fitness: bits(t[1]),
                t_fall: bits(t[2]),
                forward_distance: bits(t[3]),
            };
            (ind, e)
        })
        .collect()
}

#[test]
fn the_single_setting_scores_individuals_of_a_physics_2_run_exactly_as_the_run_did() {
    // Without the robust score, the evaluator is physics version 2's and must score every
    // individual as the runs made under it did, to the bit: five of a BLX-α run's population
    // (generation 56; ranks 0, 7, 28, 63 and 99), their fitness, fall time and Δx as its
    // checkpoint holds them.
    let ev = single(DEFAULT);
    assert!(ev.check_bodies().is_empty());
    let model = NaoModel::default();
    let stored = stored_individuals();
    assert_eq!(stored.len(), 5);
    for (i, (ind, want)) in stored.iter().enumerate() {
        assert_eq!(ind.validate(&model), Ok(()), "individual {i}");
        let got = ev.evaluate(ind);
        assert_eq!(got.fell, want.fell, "individual {i}");
        assert_eq!(
            got.fitness.to_bits(),
            want.fitness.to_bits(),
            "individual {i}: {got:?} {want:?}"
        );
        assert_eq!(
            got.t_fall.to_bits(),
            want.t_fall.to_bits(),
            "individual {i}: {got:?} {want:?}"
        );
        assert_eq!(
            got.forward_distance.to_bits(),
            want.forward_distance.to_bits(),
            "individual {i}: {got:?} {want:?}"
        );
        // The feet's report watches the same simulation: the same outcome, bit for bit.
        let (o, _) = ev.simulate_feet_report(ind, 3.0);
        assert_eq!(o, ev.simulate(ind), "individual {i}");
    }
}

#[test]
fn an_invalid_individual_is_a_fall_at_once_without_a_simulation() {
    let ev = evaluator();
    let model = NaoModel::default();
    // A NaN knot would become a NaN motor target.
    let mut nan = model.standing();
    nan.knots[Servo::LKneePitch.index()][7] = f64::NAN;
    // RHipRoll's limits are [−0.7854, 0.4363] (Table 1): 0.5 is outside.
    let mut wide = model.standing();
    wide.knots[Servo::RHipRoll.index()][3] = 0.5;
    // The last knot must be the standing pose (−0.4 for the ankle pitch).
    let mut end = model.standing();
    end.knots[Servo::RAnklePitch.index()][KNOTS - 1] = -0.3;
    for (ind, servo, knot) in [
        (&nan, Servo::LKneePitch, 7),
        (&wide, Servo::RHipRoll, 3),
        (&end, Servo::RAnklePitch, KNOTS - 1),
    ] {
        assert!(ind.validate(&model).is_err());
        let o = ev.simulate(ind);
        assert!(o.fell && o.t_end == 0.0 && o.steps == 0, "{o:?}");
        assert_eq!(o.cause, Some(FallCause::Invalid { servo, knot }));
        // A fall at 0 s scores 0/3 s = 0.
        let e = ev.evaluate(ind);
        assert!(e.fell && e.t_fall == 0.0 && e.fitness == 0.0, "{e:?}");
    }
}

#[test]
fn standing_lifts_no_foot_and_never_flies() {
    // Standing still, both soles stay flat on the floor (lowest corner at 0 m; the servos'
    // sag tips them by milliradians, a corner by well under a millimetre), each carries half
    // the weight (24.5 N > 5 N) throughout, and neither moves.
    let ev = evaluator();
    let model = NaoModel::default();
    let (o, r) = ev.simulate_feet_report(&model.standing(), 3.0);
    assert!(!o.fell, "{o:?}");
    assert_eq!(r.longest_flight, 0.0, "{r:?}");
    assert_eq!(r.flight_time, 0.0, "{r:?}");
    for f in r.feet {
        assert!(f.peak_height.abs() < 0.001, "{r:?}");
        assert!(f.forward.abs() < 0.002, "{r:?}");
        assert!(f.slip_loaded < 0.001, "{r:?}");
        assert!(f.loaded_time > 2.95, "{r:?}");
    }
}

#[test]
fn servos_weaker_than_the_standing_load_let_the_robot_collapse() {
    // The knees carry the body above them: each about half of the torso and both hips and
    // thighs, (2.750 + 2·(0.135 + 0.394))/2 = 1.90 kg, about 0.039 m behind the knee
    // (thigh 0.1 m · sin 0.4, the torso's mass above the hips): 1.90·9.81·0.039 = 0.73 N·m.
    // A pitch torque limit 30 % below that cannot hold the pose; 35 % above it can.
    let model = NaoModel::default();
    let with = |tau: f64| {
        let body = BodyParams {
            pitch_max_torque: tau,
            ..BodyParams::dc_motor()
        };
        PhysicsEvaluator::with_body(model.clone(), dc_fitness(), body)
            .unwrap()
            .simulate(&model.standing())
    };
    let weak = with(0.5);
    assert!(weak.fell && weak.t_end < 1.5, "{weak:?}");
    let strong = with(1.0);
    assert!(!strong.fell, "{strong:?}");
}

#[test]
fn an_observer_sees_every_step_and_the_same_end() {
    let ev = evaluator();
    let model = NaoModel::default();
    let mut seen = Vec::new();
    let o = ev.simulate_observed(&model.standing(), 0.5, &mut |s| seen.push(*s));
    // 0.5 s at 5 ms: 100 steps, the last at 0.5 s where the outcome ends.
    assert_eq!(seen.len(), 100);
    assert!((seen[99].t - 0.5).abs() < 1e-12);
    assert_eq!(seen[99].z, o.end_height);
}

#[test]
fn the_motor_gives_its_continuous_torque_up_to_the_nominal_speed_then_follows_its_line() {
    let b = BodyParams::dc_motor();
    let k = Servo::RKneePitch;
    // At rest and at 3 rad/s the line τ_stall·(1 − ω/ω₀) = 7.78·(1 − 3/6.402) = 4.14 N·m lies
    // above the continuous 1.61 N·m, which caps it.
    assert_eq!(b.torque_limit(k, 0.0, true), 1.61);
    assert_eq!(b.torque_limit(k, -3.0, true), 1.61);
    // At Aldebaran's nominal speed 290.25 °/s = 5.0658 rad/s the line gives
    // 7.78·(1 − 290.25/366.83) = 7.78·0.208762 = 1.624 N·m: the nominal point (1.61 N·m) lies
    // on the line within 0.02 N·m. The line itself, from the body's figures (`torque_limit`
    // caps it at 1.61, so it cannot show this): stall·(1 − ω/ω₀).
    let omega = 290.25_f64.to_radians();
    let line = b.pitch_stall_torque * (1.0 - omega / b.pitch_max_speed);
    assert!((line - 1.624).abs() < 0.001, "{line}");
    assert!((line - b.pitch_max_torque).abs() < 0.02, "{line}");
    // The roll joints' nominal point, 2.47 N·m at 188.67 °/s: 11.97·(1 − 188.67/238.45)
    // = 11.97·0.208765 = 2.499 N·m, within 0.03 N·m.
    let line = b.roll_stall_torque * (1.0 - 188.67_f64.to_radians() / b.roll_max_speed);
    assert!((line - 2.499).abs() < 0.001, "{line}");
    assert!((line - b.roll_max_torque).abs() < 0.03, "{line}");
    // Faster, the line: at 6 rad/s 7.78·(1 − 6/6.4024) = 0.489 N·m; at the no-load speed 0.
    assert!((b.torque_limit(k, 6.0, true) - 0.489).abs() < 0.002);
    assert_eq!(b.torque_limit(k, 7.0, true), 0.0);
    // Braking, the continuous torque at any speed.
    assert_eq!(b.torque_limit(k, 6.0, false), 1.61);
    // Roll joints: 2.47 N·m at rest; at 4 rad/s 11.97·(1 − 4/4.1618) = 0.465 N·m.
    assert_eq!(b.torque_limit(Servo::LAnkleRoll, 0.0, true), 2.47);
    assert!((b.torque_limit(Servo::LAnkleRoll, 4.0, true) - 0.465).abs() < 0.002);
}

/// Nao's joint convention (Aldebaran, "H25 – Joints": at the zero pose every joint frame is the
/// torso's; roll turns about x, pitch about y, positively by the right-hand rule), checked on
/// the simulated body with its torso held in the air: each figure worked out by hand from the
/// link lengths (hips 50 mm either side and 85 mm below the torso frame, thigh 100 mm, tibia
/// 102.9 mm, foot height 45.19 mm). A sign flipped in the placement of the links or in a joint's
/// axis moves a point by centimetres.
#[test]
fn joints_turn_as_naos_do_in_an_asymmetric_pose() {
    let ev = evaluator();
    let close = |got: [f64; 3], want: [f64; 3], what: &str| {
        let d = ((got[0] - want[0]).powi(2) + (got[1] - want[1]).powi(2) + (got[2] - want[2]).powi(2)).sqrt();
        assert!(d < 0.004, "{what}: {got:?}, by hand {want:?}");
    };
    // Every joint at 0 but RHipPitch −0.5 rad: the straight right leg (0.2029 m to the ankle)
    // swings forward: ankle at (0.2029·sin 0.5, −0.05, −0.085 − 0.2029·cos 0.5) =
    // (0.09728, −0.05, −0.26306); knee at (0.1·sin 0.5, −0.05, −0.085 − 0.1·cos 0.5) =
    // (0.04794, −0.05, −0.17276). The left leg hangs straight: ankle (0, 0.05, −0.2879).
    let mut pose = [0.0; 10];
    pose[Servo::RHipPitch.index()] = -0.5;
    let p = ev.reach(&pose, 1.0);
    close(p.ankles[0], [0.09728, -0.05, -0.26306], "right ankle, RHipPitch −0.5");
    close(p.knees[0], [0.04794, -0.05, -0.17276], "right knee, RHipPitch −0.5");
    close(p.ankles[1], [0.0, 0.05, -0.2879], "left ankle, straight");
    // LKneePitch +1.0 rad: the left shank swings back: ankle at the knee (0, 0.05, −0.185) plus
    // 0.1029·(−sin 1, 0, −cos 1) = (−0.08659, 0.05, −0.24060).
    let mut pose = [0.0; 10];
    pose[Servo::LKneePitch.index()] = 1.0;
    let p = ev.reach(&pose, 1.0);
    close(p.ankles[1], [-0.08659, 0.05, -0.24060], "left ankle, LKneePitch +1");
    close(p.ankles[0], [0.0, -0.05, -0.2879], "right ankle, straight");
    // LHipRoll +0.3 rad spreads the left leg outwards (+y): ankle at
    // (0, 0.05 + 0.2029·sin 0.3, −0.085 − 0.2029·cos 0.3) = (0, 0.10996, −0.27884).
    // RAnkleRoll +0.3 rad turns the right sole about x: its normal (0, 0, −1) becomes
    // (0, sin 0.3, −cos 0.3) = (0, 0.29552, −0.95534), the foot's left (inner) edge up.
    let mut pose = [0.0; 10];
    pose[Servo::LHipRoll.index()] = 0.3;
    pose[Servo::RAnkleRoll.index()] = 0.3;
    let p = ev.reach(&pose, 1.0);
    close(p.ankles[1], [0.0, 0.10996, -0.27884], "left ankle, LHipRoll +0.3");
    close(
        p.sole_normals[0],
        [0.0, 0.29552, -0.95534],
        "right sole normal, RAnkleRoll +0.3",
    );
    // The right sole's centre (20 mm ahead of the ankle, 45.19 mm below it) turns with it:
    // (0.02, −0.05 + 0.04519·sin 0.3, −0.2879 − 0.04519·cos 0.3) = (0.02, −0.03665, −0.33107).
    close(
        p.soles[0],
        [0.02, -0.03665, -0.33107],
        "right sole centre, RAnkleRoll +0.3",
    );
    // RAnklePitch +0.3 alone: the right foot turns about y, its toes down. The sole normal
    // (0, 0, −1) becomes (−sin 0.3, 0, −cos 0.3) = (−0.29552, 0, −0.95534); the sole centre,
    // (0.02, 0, −0.04519) from the ankle, becomes (0.02·cos 0.3 − 0.04519·sin 0.3, 0,
    // −0.02·sin 0.3 − 0.04519·cos 0.3) = (0.00575, 0, −0.04908), below the straight leg's ankle
    // (0, −0.05, −0.2879): (0.00575, −0.05, −0.33698).
    let mut pose = [0.0; 10];
    pose[Servo::RAnklePitch.index()] = 0.3;
    let p = ev.reach(&pose, 1.0);
    close(
        p.sole_normals[0],
        [-0.29552, 0.0, -0.95534],
        "right sole normal, RAnklePitch +0.3",
    );
    close(
        p.soles[0],
        [0.00575, -0.05, -0.33698],
        "right sole centre, RAnklePitch +0.3",
    );
    close(p.ankles[0], [0.0, -0.05, -0.2879], "right ankle, RAnklePitch +0.3");
    // LHipRoll +0.3 and LHipPitch −0.5 together: the roll comes first in the chain, so the
    // straight leg's direction is R_x(0.3)·R_y(−0.5)·(0, 0, −1). R_y(−0.5) gives
    // (sin 0.5, 0, −cos 0.5) = (0.479426, 0, −0.877583); R_x(0.3) turns (x, y, z) into
    // (x, y·cos 0.3 − z·sin 0.3, y·sin 0.3 + z·cos 0.3) = (0.479426, 0.259343, −0.838387).
    // From the hip (0, 0.05, −0.085): knee at 0.1 m (0.04794, 0.07593, −0.16884), ankle at
    // 0.2029 m (0.09728, 0.10262, −0.25511); the flat-jointed foot's sole normal is the same
    // direction. (The other order, pitch before roll, puts the ankle 7 mm further out.)
    let mut pose = [0.0; 10];
    pose[Servo::LHipRoll.index()] = 0.3;
    pose[Servo::LHipPitch.index()] = -0.5;
    let p = ev.reach(&pose, 1.0);
    close(
        p.knees[1],
        [0.04794, 0.07593, -0.16884],
        "left knee, LHipRoll +0.3 LHipPitch −0.5",
    );
    close(
        p.ankles[1],
        [0.09728, 0.10262, -0.25511],
        "left ankle, LHipRoll +0.3 LHipPitch −0.5",
    );
    close(
        p.sole_normals[1],
        [0.479426, 0.259343, -0.838387],
        "left sole normal, LHipRoll +0.3 LHipPitch −0.5",
    );
}

#[test]
fn kneeling_is_a_fall_though_the_torso_is_high_and_upright() {
    // Kneeling: thighs 0.2 rad back (hip pitch +0.2), knees bent π/2, ankles at π/4 (their
    // pitch limit, 0.7854 rad). The shanks point 0.2 + 1.5708 = 1.7708 rad from straight down,
    // slightly up behind the knees; the feet hang above the floor (their toe corners 26 mm
    // up): the shanks' capsules carry the robot. Torso frame height by hand: the knee is
    // 0.085 + 0.1·cos 0.2 = 0.183007 m below it, the capsule's end ball (radius 0.03) centred
    // 0.03 m along the shank, 0.03·cos(π − 1.7708) = 0.00596 m above the knee, so its bottom is
    // 0.02404 m below the knee: 0.20705 m, above the 0.20 m of the height rule, and upright.
    // Only the contact rule can call this a fall.
    let mut model = NaoModel::default();
    for (s, q) in [
        (Servo::RHipPitch, 0.2),
        (Servo::LHipPitch, 0.2),
        (Servo::RKneePitch, FRAC_PI_2),
        (Servo::LKneePitch, FRAC_PI_2),
        (Servo::RAnklePitch, FRAC_PI_4),
        (Servo::LAnklePitch, FRAC_PI_4),
    ] {
        model.standing_pose[s.index()] = q;
    }
    let ev = PhysicsEvaluator::new(model.clone(), dc_fitness()).unwrap();
    let o = ev.simulate(&model.standing());
    assert!((o.start_height - 0.20705).abs() < 1e-4, "{o:?}");
    assert!(o.fell && o.cause == Some(FallCause::Contact), "{o:?}");
    // At the first step (5 ms), the torso still where it was.
    assert!(o.t_end <= 0.0051, "{o:?}");
    assert!(o.end_height > 0.20 && o.max_tilt < 0.5, "{o:?}");
}

#[test]
fn knees_fully_bent_at_once_fall_whatever_the_solver_settings() {
    // The fall of `knees_fully_bent_at_once_make_the_robot_fall` at the default settings and at
    // half the step with twice the iterations: the same verdict within 20 ms.
    let model = NaoModel::default();
    let bent = motions::ramp_to(&model, &[(Servo::RKneePitch, 2.2689), (Servo::LKneePitch, 2.2689)], 1);
    let coarse = evaluator().simulate(&bent);
    let fine = finer(2).simulate(&bent);
    assert!(coarse.fell && fine.fell, "{coarse:?} {fine:?}");
    assert!((coarse.t_end - fine.t_end).abs() < 0.02, "{coarse:?} {fine:?}");
}

/// The default evaluator with its step divided by `k` and its iterations multiplied by `k`.
fn finer(k: usize) -> PhysicsEvaluator {
    let d = BodyParams::dc_motor();
    let body = BodyParams {
        dt: d.dt / k as f64,
        solver_iterations: d.solver_iterations * k,
        ..d
    };
    PhysicsEvaluator::with_body(NaoModel::default(), dc_fitness(), body).unwrap()
}

#[test]
fn bobbing_in_place_on_both_feet_goes_nowhere() {
    // Both legs bob ±0.15 rad of hip and ankle pitch (±0.3 rad of knee) at 1.25 Hz, 2.5
    // cycles in the 2 s step: hip + knee + ankle pitch stays 0, the torso upright over flat
    // feet, rising and sinking. The fastest knee knot slope, 0.3·sin(π/4)/0.1 s
    // = 2.1 rad/s, is within the 6.4 rad/s slew limit. Nothing in the motion pushes along x or y,
    // so the torso must end where it started: within 2 mm (a twentieth of a 4 cm step; measured
    // 0.3 mm), with neither foot slipping. One Gauss–Seidel pass (physics 1's solver), whose
    // friction does not converge, moves it 9 mm: the bound tells the two apart.
    let model = NaoModel::default();
    let bob = motions::knee_bob(&model, 0.15, 0.8);
    assert_eq!(bob.validate(&model), Ok(()));
    for ev in [evaluator(), finer(2)] {
        let mut lowest = f64::INFINITY;
        let mut max_slip: f64 = 0.0;
        let mut unloaded = 0.0;
        let o = ev.simulate_with_feet(&bob, 3.0, &mut |s, feet| {
            lowest = lowest.min(s.z);
            for f in feet {
                max_slip = max_slip.max(f.slip_speed);
                if f.normal_force < 5.0 {
                    unloaded += ev.body().dt;
                }
            }
        });
        assert!(!o.fell, "{o:?}");
        assert!(o.forward_distance.abs() < 0.002, "{o:?}");
        assert!(o.lateral_distance.abs() < 0.002, "{o:?}");
        // It did bob: the torso sank by at least 1 cm (thigh and shank at 0.55 rad from the
        // vertical instead of 0.4 lower it by 0.2029·(cos 0.4 − cos 0.55) = 1.4 cm).
        assert!(lowest < o.start_height - 0.01, "lowest {lowest} {o:?}");
        // Both feet stayed loaded, and no sole slid faster than 1 cm/s.
        assert!(unloaded < 0.05, "a foot carried under 5 N for {unloaded} s");
        assert!(max_slip < 0.01, "a sole slid at {max_slip} m/s");
    }
    let one_pass = PhysicsEvaluator::with_body(
        NaoModel::default(),
        dc_fitness(),
        BodyParams {
            pgs_iterations: 1,
            ..BodyParams::dc_motor()
        },
    )
    .unwrap()
    .simulate(&bob);
    assert!(one_pass.forward_distance.abs() > 0.002, "{one_pass:?}");
}

#[test]
fn upright_motions_end_at_the_same_place_at_half_the_step_and_twice_the_iterations() {
    // Standing and bobbing in place push the torso nowhere, so where it ends is the solver's
    // doing alone; at converged settings halving the step and doubling the iterations moves it
    // by well under a millimetre (measured 0.1–0.3 mm). One Gauss–Seidel pass, where friction
    // does not converge, let it creep 9–11 mm at 5 ms and 5 mm at 2.5 ms: 2 mm separates them.
    let model = NaoModel::default();
    for ind in [model.standing(), motions::knee_bob(&model, 0.15, 0.8)] {
        let coarse = evaluator().simulate(&ind);
        let fine = finer(2).simulate(&ind);
        assert!(!coarse.fell && !fine.fell, "{coarse:?} {fine:?}");
        assert!(
            (coarse.forward_distance - fine.forward_distance).abs() < 0.002,
            "{coarse:?} {fine:?}"
        );
        assert!(
            (coarse.lateral_distance - fine.lateral_distance).abs() < 0.002,
            "{coarse:?} {fine:?}"
        );
    }
}

/// The worse of two outcomes by the robust score's rule, written out here apart from the
/// evaluator's: a fall is worse than none; of two falls the earlier; of two upright outcomes the
/// smaller Δx; a tie keeps `first`.
fn worse_of(first: SimOutcome, second: SimOutcome) -> SimOutcome {
    let second_worse = match (first.fell, second.fell) {
        (false, true) => true,
        (true, false) => false,
        (true, true) => second.t_end < first.t_end,
        (false, false) => second.forward_distance < first.forward_distance,
    };
    if second_worse {
        second
    } else {
        first
    }
}

/// `fixtures/blx1_gen136_edge.txt`: evolved individuals upright at the default setting that
/// fall at the check setting.
fn edge_individuals() -> Vec<(Individual, Evaluation)> {
    parse_fixture(include_str!("fixtures/blx1_gen136_edge.txt"))
}

#[test]
fn an_evolved_motion_upright_only_at_the_default_setting_scores_as_a_fall() {
    // Individuals a physics-2 run (BLX-α, seed 1) kept at generation 136 as upright: the
    // fixture holds what the run stored (no fall, fitness 1 + 2·(Δx + 1)). At the check
    // setting (4 ms/4/2) and at the reference 1.25 ms/16/4 they fall (the check_settings
    // example's table). Under the robust score each is a fall, at the check setting's fall
    // time, scoring t / 3 s < 1.
    let ev = evaluator();
    let default = single(DEFAULT);
    let check = single(CHECK_SETTING);
    let reference = single(SolverSetting {
        dt: 0.00125,
        solver_iterations: 16,
        pgs_iterations: 4,
    });
    let edge = edge_individuals();
    assert!(!edge.is_empty());
    for (i, (ind, stored)) in edge.iter().enumerate() {
        // What the run stored: upright, f = 1 + 2·(Δx + 1).
        assert!(!stored.fell, "individual {i}");
        assert!((stored.fitness - (1.0 + 2.0 * (stored.forward_distance + 1.0))).abs() < 1e-12);
        let d = default.evaluate(ind);
        assert_eq!(d.fitness.to_bits(), stored.fitness.to_bits(), "individual {i}: {d:?}");
        let c = check.simulate(ind);
        assert!(c.fell, "individual {i}: {c:?}");
        assert!(reference.simulate(ind).fell, "individual {i}");
        let got = ev.evaluate(ind);
        assert!(got.fell, "individual {i}: {got:?}");
        assert_eq!(got.t_fall, c.t_end, "individual {i}");
        assert!((got.fitness - c.t_end / 3.0).abs() < 1e-12, "individual {i}: {got:?}");
        assert!(got.fitness < 1.0);
    }
}

#[test]
fn standing_is_upright_under_every_setting() {
    // Standing still for T_sim = 3 s: upright at both settings, the torso within 2 mm of where
    // it began (the solver table of docs/experiments/ga-step-physics.md: −0.1 to −0.6 mm at
    // every setting from the default on),
    // so the robust fitness is 1 + 2·(Δx + 1) = 3 within 0.004, with Δx the smaller of the two
    // settings'. The check setting is not the default one.
    assert_ne!(CHECK_SETTING, DEFAULT);
    let model = NaoModel::default();
    let stand = model.standing();
    let a = single(DEFAULT).simulate(&stand);
    let b = single(CHECK_SETTING).simulate(&stand);
    assert!(!a.fell && !b.fell, "{a:?} {b:?}");
    let e = evaluator().evaluate(&stand);
    assert!(!e.fell, "{e:?}");
    assert_eq!(e.forward_distance, a.forward_distance.min(b.forward_distance));
    assert!(e.forward_distance.abs() < 0.002, "{e:?}");
    assert!((e.fitness - 3.0).abs() < 0.004, "{e:?}");
}

#[test]
fn the_robust_score_is_the_worst_of_the_scores_under_each_setting() {
    // Per individual, both settings simulated in full on their own, the worse outcome picked by
    // `worse_of` and scored by the fitness formula by hand (a fall: t / 3 s; none:
    // 1 + 2·(Δx + 1)), against the robust evaluator, bit for bit. The individuals: standing,
    // the knee fold (falls at once under both), the run's individuals of generation 56 (fall
    // under both, at different times) and of generation 136 (upright at the default only), and
    // gentle random motions (some up, some falling). The evaluator cuts its check short at the
    // default's fall time; this checks that the cut never changes the result.
    let model = NaoModel::default();
    let mut batch = vec![
        model.standing(),
        motions::ramp_to(&model, &[(Servo::RKneePitch, 2.2689), (Servo::LKneePitch, 2.2689)], 1),
    ];
    batch.extend(stored_individuals().into_iter().map(|(i, _)| i));
    let edge: Vec<Individual> = edge_individuals().into_iter().map(|(i, _)| i).collect();
    batch.extend(edge.iter().cloned());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    for _ in 0..6 {
        let ind = motions::gentle(&model, 0.1, &mut || rng.random::<f64>());
        batch.push(ind);
    }
    // The evaluator of ga_step (the default, checked at 4 ms/4/2) on the whole batch, and the
    // pair the other way round (4 ms/4/2, checked at the default) on the edge individuals:
    // there the first setting falls and the check would stay up, a case the evolved and random
    // motions tried never give the default pair (its check is the finer setting).
    let swapped = PhysicsEvaluator::with_checks(
        model.clone(),
        dc_fitness(),
        CHECK_SETTING.apply(&BodyParams::dc_motor()),
        &[DEFAULT],
    )
    .unwrap();
    let pairs = [
        (single(DEFAULT), single(CHECK_SETTING), evaluator(), &batch[..]),
        (single(CHECK_SETTING), single(DEFAULT), swapped, &edge[..]),
    ];
    let (mut falls, mut upright, mut check_decided) = (0, 0, 0);
    // Where the cut is taken (the first setting falls) and the check, simulated in full,
    // would fall later or not at all: the cases the cut must not change.
    let (mut cut_check_later, mut cut_check_up) = (0, 0);
    for (a, b, ev, batch) in &pairs {
        for (i, ind) in batch.iter().enumerate() {
            let (oa, ob) = (a.simulate(ind), b.simulate(ind));
            let w = worse_of(oa, ob);
            let f = if w.fell {
                w.t_end / 3.0
            } else {
                1.0 + 2.0 * (w.forward_distance + 1.0)
            };
            let got = ev.evaluate(ind);
            assert_eq!(got.fell, w.fell, "individual {i}: {got:?} {oa:?} {ob:?}");
            assert_eq!(got.t_fall.to_bits(), w.t_end.to_bits(), "individual {i}: {got:?} {w:?}");
            assert_eq!(
                got.forward_distance.to_bits(),
                w.forward_distance.to_bits(),
                "individual {i}"
            );
            assert!((got.fitness - f).abs() < 1e-12, "individual {i}: {got:?} vs {f}");
            falls += usize::from(w.fell);
            upright += usize::from(!w.fell);
            check_decided += usize::from(w != oa);
            if oa.fell && oa.t_end > 0.0 {
                assert_eq!(PhysicsEvaluator::check_duration(&oa, 3.0), Some(oa.t_end));
                cut_check_later += usize::from(ob.fell && ob.t_end > oa.t_end);
                cut_check_up += usize::from(!ob.fell);
            }
        }
    }
    // The batch covers both verdicts, results the check decided, and cut checks that would
    // have fallen later or stayed up.
    assert!(
        falls >= 3 && upright >= 1 && check_decided >= 2 && cut_check_later >= 1 && cut_check_up >= 1,
        "{falls} {upright} {check_decided} {cut_check_later} {cut_check_up}"
    );
}

#[test]
fn a_check_is_cut_at_the_fall_so_far_and_skipped_after_a_fall_at_once() {
    let o = |fell: bool, t_end: f64| SimOutcome {
        fell,
        cause: None,
        t_end,
        forward_distance: 0.0,
        lateral_distance: 0.0,
        start_height: 0.3,
        end_height: 0.3,
        max_tilt: 0.0,
        steps: 0,
    };
    assert_eq!(PhysicsEvaluator::check_duration(&o(false, 3.0), 3.0), Some(3.0));
    assert_eq!(PhysicsEvaluator::check_duration(&o(true, 1.25), 3.0), Some(1.25));
    assert_eq!(PhysicsEvaluator::check_duration(&o(true, 0.0), 3.0), None);
}

#[test]
fn the_check_setting_and_the_physics_version_are_pinned() {
    // The robust score's check setting is part of the physics version (4; the DC-motor model
    // scores as at 3): changing either moves every score, and checkpoints would resume under
    // other numbers. The test's DEFAULT is the body's default setting.
    assert_eq!(BodyParams::dc_motor().check, CHECK_SETTING);
    assert_eq!(
        (PHYSICS_VERSION, CHECK_SETTING),
        (
            4,
            SolverSetting {
                dt: 0.004,
                solver_iterations: 4,
                pgs_iterations: 2
            }
        )
    );
    assert_eq!(DEFAULT.apply(&BodyParams::dc_motor()), BodyParams::dc_motor());
}

#[test]
fn the_robust_score_scores_individuals_of_a_physics_3_run_exactly_as_the_run_did() {
    // Five of a BLX-α run's population under physics 3 (generation 55; ranks 0, 7, 28, 63 and
    // 99), their fitness, fall time and Δx as its checkpoint holds them, to the bit. Some fall
    // at a time only the check setting's 4 ms steps reach (1.984 s, 1.492 s, 1.408 s: not
    // multiples of 5 ms), one at a time only the default's reach (1.365 s).
    let ev = evaluator();
    let stored = parse_fixture(include_str!("fixtures/blx1_p3_gen55.txt"));
    assert_eq!(stored.len(), 5);
    let (mut by_check, mut by_default) = (0, 0);
    for (i, (ind, want)) in stored.iter().enumerate() {
        let got = ev.evaluate(ind);
        assert_eq!(got.fell, want.fell, "individual {i}");
        for (g, w) in [
            (got.fitness, want.fitness),
            (got.t_fall, want.t_fall),
            (got.forward_distance, want.forward_distance),
        ] {
            assert_eq!(g.to_bits(), w.to_bits(), "individual {i}: {got:?} {want:?}");
        }
        let steps = |dt: f64| (want.t_fall / dt).round() * dt;
        by_check += usize::from((steps(0.005) - want.t_fall).abs() > 1e-9);
        by_default += usize::from((steps(0.004) - want.t_fall).abs() > 1e-9);
    }
    assert_eq!((by_check, by_default), (3, 1));
}

#[test]
fn the_robust_score_scores_upright_individuals_of_a_physics_3_run_exactly_as_the_run_did() {
    // The six upright individuals of the same run at generation 200 (ranks 0–5), upright under
    // both settings: each stored with the smaller of the two settings' Δx, which the robust
    // evaluator gives again, to the bit.
    let (ev, a, b) = (evaluator(), single(DEFAULT), single(CHECK_SETTING));
    let stored = parse_fixture(include_str!("fixtures/blx1_p3_gen200.txt"));
    assert_eq!(stored.len(), 6);
    let (mut by_check, mut by_default) = (0, 0);
    for (i, (ind, want)) in stored.iter().enumerate() {
        assert!(!want.fell, "individual {i}");
        let got = ev.evaluate(ind);
        assert_eq!(got, *want, "individual {i}");
        assert_eq!(got.fitness.to_bits(), want.fitness.to_bits(), "individual {i}");
        let (oa, ob) = (a.simulate(ind), b.simulate(ind));
        assert!(!oa.fell && !ob.fell, "individual {i}: {oa:?} {ob:?}");
        let smaller = oa.forward_distance.min(ob.forward_distance);
        assert_eq!(want.forward_distance.to_bits(), smaller.to_bits(), "individual {i}");
        by_check += usize::from(ob.forward_distance < oa.forward_distance);
        by_default += usize::from(oa.forward_distance < ob.forward_distance);
    }
    // Both branches of "the smaller Δx": some kept the check's, some the default's.
    assert!(by_check >= 1 && by_default >= 1, "{by_check} {by_default}");
}

#[test]
fn evolved_individuals_come_back_from_their_motion_files() {
    // The fixtures' 19 evolved individuals (many knots at a servo's limit) through the motion
    // file and back: within 7.5e-5 rad for the 2 s step, as Motion::to_individual states.
    let model = NaoModel::default();
    let mut all = stored_individuals();
    all.extend(edge_individuals());
    all.extend(parse_fixture(include_str!("fixtures/blx1_p3_gen55.txt")));
    all.extend(parse_fixture(include_str!("fixtures/blx1_p3_gen200.txt")));
    assert_eq!(all.len(), 19);
    let at_limit = all
        .iter()
        .flat_map(|(ind, _)| Servo::ALL.map(|s| (s, ind.knots[s.index()])))
        .flat_map(|(s, knots)| knots.map(|q| q == s.limits().0 || q == s.limits().1))
        .filter(|&b| b)
        .count();
    assert!(at_limit >= 100, "{at_limit}");
    for (i, (ind, _)) in all.iter().enumerate() {
        let mut text = Vec::new();
        mobil_ga_step::write_motion(&mut text, &model, ind).unwrap();
        let back = mobil_ga_step::read_motion(&text[..])
            .unwrap()
            .to_individual(&model)
            .unwrap();
        for (got, want) in back.knots.iter().zip(&ind.knots) {
            for (g, w) in got.iter().zip(want) {
                assert!((g - w).abs() <= 7.5e-5 + 1e-12, "individual {i}: {g} vs {w}");
            }
        }
    }
}

#[test]
fn checks_are_refused_when_a_falls_distance_counts() {
    // With distance_on_fall a lunge that falls 0.8 m ahead at 1.5 s scores 0.5 + 1.6 = 2.1,
    // above an upright step at −0.5 m (1 + 2·0.5 = 2): "the worse outcome" would then keep the
    // higher score. The combination is refused; without checks it is accepted.
    let fitness = FitnessConfig {
        distance_on_fall: true,
        ..dc_fitness()
    };
    assert!(fitness.robust_check);
    assert_eq!(
        PhysicsEvaluator::new(NaoModel::default(), fitness.clone()).err(),
        Some(SimError::ChecksWithDistanceOnFall)
    );
    assert_eq!(
        PhysicsEvaluator::with_checks(NaoModel::default(), fitness.clone(), BodyParams::dc_motor(), &[DEFAULT]).err(),
        Some(SimError::ChecksWithDistanceOnFall)
    );
    let alone = FitnessConfig {
        robust_check: false,
        ..fitness
    };
    assert!(PhysicsEvaluator::new(NaoModel::default(), alone).is_ok());
}

#[test]
fn the_robust_score_can_be_switched_off() {
    // robust_check false: the evaluator has no check and scores what the default setting alone
    // does; the edge individuals then score their stored, upright, evaluation again.
    let fitness = FitnessConfig {
        robust_check: false,
        ..dc_fitness()
    };
    let ev = PhysicsEvaluator::new(NaoModel::default(), fitness).unwrap();
    assert!(ev.check_bodies().is_empty());
    for (ind, stored) in edge_individuals() {
        assert_eq!(ev.evaluate(&ind), stored);
    }
}
