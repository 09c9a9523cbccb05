//! The physics evaluator against what a body of Nao's figures must do. Each test simulates at
//! most T_sim = 3 s.

use mobil_ga_step::{evaluate_all, Evaluator, FitnessConfig, Individual, NaoModel, Servo, KNOTS};
use mobil_ga_step_sim::{BodyParams, PhysicsEvaluator, SimError};
use rand::{Rng, SeedableRng};

fn evaluator() -> PhysicsEvaluator {
    PhysicsEvaluator::new(NaoModel::default(), FitnessConfig::default()).unwrap()
}

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
    assert!(!o.fell, "{o:?}");
    assert_eq!(o.t_end, 3.0);
    assert_eq!(o.steps, 600);
    // Torso frame height by hand: foot 45.19 mm + (thigh 100 + tibia 102.9 mm)·cos 0.4 +
    // hip offset 85 mm = 0.04519 + 0.2029·0.921061 + 0.085 = 0.317073 m (f32 placement).
    assert!((o.start_height - 0.317073).abs() < 1e-4, "{o:?}");
    // Held servos sag by a few millimetres under the load (1 N·m at 156 N·m/rad is 6 mrad):
    // the torso stays within 1 cm, a quarter of the 4 cm that counts as a step, and upright.
    assert!(o.forward_distance.abs() < 0.01, "{o:?}");
    assert!(o.lateral_distance.abs() < 0.01, "{o:?}");
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
    let ev = evaluator();
    let model = NaoModel::default();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    // Gentle random motions (a quarter of each range around the standing pose) that stay up
    // for a while, so the comparison covers many steps.
    let batch: Vec<Individual> = (0..4)
        .map(|_| {
            let mut ind = model.standing();
            for s in Servo::ALL {
                let (lo, hi) = s.limits();
                for k in 1..KNOTS - 1 {
                    let v = model.standing_pose[s.index()] + 0.125 * (hi - lo) * (2.0 * rng.random::<f64>() - 1.0);
                    ind.knots[s.index()][k] = s.clamp(v);
                }
            }
            ind
        })
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
fn the_body_weighs_what_nao_weighs() {
    let b = BodyParams::default();
    // One leg below the pelvis: 0.13530 + 0.39421 + 0.29159 + 0.13892 + 0.16304 = 1.12306 kg;
    // the lumped torso is the rest of 4.996 kg: 4.996 − 2·1.12306 = 2.74988 kg.
    assert!((b.leg.total() - 1.12306).abs() < 1e-9);
    assert!((b.torso_mass - 2.74988).abs() < 1e-9);
    assert!((b.total_mass() - 4.996).abs() < 1e-9);
    // Stall torques: 59.5 mN·m × 130.85 = 7.786 N·m (the documentation prints 7.78) and
    // × 201.3 = 11.977 N·m (11.97).
    assert!((b.max_torque(Servo::LKneePitch) - 0.0595 * 130.85).abs() < 0.01);
    assert!((b.max_torque(Servo::RAnkleRoll) - 0.0595 * 201.3).abs() < 0.01);
}

#[test]
fn bad_body_figures_are_refused() {
    let body = BodyParams {
        dt: 0.0,
        ..BodyParams::default()
    };
    let r = PhysicsEvaluator::with_body(NaoModel::default(), FitnessConfig::default(), body);
    assert_eq!(r.err(), Some(SimError::BadBody { name: "dt", value: 0.0 }));
    let body = BodyParams {
        friction: f64::NAN,
        ..BodyParams::default()
    };
    assert!(matches!(
        PhysicsEvaluator::with_body(NaoModel::default(), FitnessConfig::default(), body),
        Err(SimError::BadBody { name: "friction", .. })
    ));
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
            ..BodyParams::default()
        };
        PhysicsEvaluator::with_body(model.clone(), FitnessConfig::default(), body)
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
