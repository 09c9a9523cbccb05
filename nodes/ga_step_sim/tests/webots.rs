//! The default physics model, `physics: webots` ([`BodyParams::webots`]): its figures are Webots'
//! (docs/ga_step.md, "Calibration"), a standing Nao stays put, the hand-made forward step is a
//! non-falling forward step, and the scores agree with those at the finer setting.

use mobil_ga_step::{read_motion, Evaluator, FitnessConfig, Individual, NaoModel, Servo, KNOTS};
use mobil_ga_step_sim::motions::{forward_step, StepPlan};
use mobil_ga_step_sim::{agreement, BodyParams, PhysicsEvaluator, ServoKind, SolverSetting, PHYSICS_VERSION};
use rand::SeedableRng;

/// The committed control experiment (written by `examples/hand_step.rs --write`).
const HAND_STEP: &str = include_str!("../motions/hand_step.motion");

fn hand_step(model: &NaoModel) -> Individual {
    read_motion(HAND_STEP.as_bytes()).unwrap().to_individual(model).unwrap()
}

/// The body at one setting alone, without the robust score.
fn single(body: BodyParams) -> PhysicsEvaluator {
    let fitness = FitnessConfig {
        robust_check: false,
        ..FitnessConfig::default()
    };
    PhysicsEvaluator::with_body(NaoModel::default(), fitness, body).unwrap()
}

#[test]
fn the_figures_are_webots_nao_and_its_robocup_world() {
    // Each from the calibration table of docs/ga_step.md (Nao.proto, version "V3.3";
    // nao_robocup.wbt; RotationalMotor.wrl; ContactProperties.wrl).
    let b = BodyParams::webots();
    assert_eq!(b, BodyParams::default());
    assert_eq!(b.servo, ServoKind::Webots);
    assert_eq!((b.p_gain, b.pitch_max_torque, b.roll_max_torque), (10.0, 8.0, 12.0));
    assert_eq!((b.pitch_max_speed, b.roll_max_speed), (6.40239, 4.16174));
    assert_eq!((b.friction, b.restitution), (7.0, 0.3));
    assert_eq!(
        [
            b.foot_length,
            b.foot_width,
            b.sole_thickness,
            b.foot_height,
            b.foot_forward,
            b.foot_outward
        ],
        [0.147, 0.089, 0.010, 0.046, 0.020, 0.007]
    );
    // ODE's soft contact: k = ERP/(h·CFM) = 0.2/(0.02·0.001) = 10⁴ N/m and
    // c = (1 − ERP)/CFM = 800 N·s/m a contact point; on eight points (two flat soles) under
    // 4.996 kg: √(8·10⁴/4.996)/2π = 20.14 Hz, ζ = 8·800/(2·√(8·10⁴·4.996)) = 5.06.
    let [f, z] = b.contact_softness.unwrap();
    let (k, c, m) = (8.0 * 0.2 / (0.02 * 0.001), 8.0 * 0.8 / 0.001, b.total_mass());
    assert!((f - (k / m).sqrt() / (2.0 * std::f64::consts::PI)).abs() < 0.05, "{f}");
    assert!((z - c / (2.0 * (k * m).sqrt())).abs() < 0.01, "{z}");
    assert_eq!((b.dt, b.solver_iterations, b.pgs_iterations), (0.020, 4, 2));
    assert_eq!(b.check, SolverSetting::of(&b).finer());
    assert!(b.friction_every_pass);
    assert_eq!(PHYSICS_VERSION, 4);
}

#[test]
fn the_position_controller_asks_p_times_the_error_up_to_max_velocity() {
    // Webots' algorithm (motor.md): V = P·(target − position), |V| ≤ maxVelocity.
    let b = BodyParams::webots();
    // 0.1 rad short: 10 · 0.1 = 1 rad/s.
    assert!((b.webots_velocity(Servo::RKneePitch, 0.9, 0.8) - 1.0).abs() < 1e-12);
    // 1 rad beyond on a pitch joint: −10 rad/s, clamped to −6.40239.
    assert_eq!(b.webots_velocity(Servo::LHipPitch, -1.4, -0.4), -6.40239);
    // 0.5 rad short on a roll joint: 5 rad/s, clamped to 4.16174.
    assert_eq!(b.webots_velocity(Servo::RAnkleRoll, 0.5, 0.0), 4.16174);
    // The target is the motion's angle, not rate-limited (the controller limits the speed).
    assert_eq!(b.next_target(Servo::RKneePitch, 0.8, 2.0), 2.0);
    // ... clamped into Table 1's limits (knee ≤ 2.2689).
    assert_eq!(b.next_target(Servo::RKneePitch, 0.8, 3.0), 2.2689);
}

#[test]
fn the_leg_angles_put_the_ankle_where_asked() {
    // By hand: ankle 0.19 m straight below the hip with thigh 0.1 and tibia 0.1029: the knee
    // closes the triangle, cos(knee) = (0.19² − 0.1² − 0.1029²)/(2·0.1·0.1029)
    // = (0.0361 − 0.01 − 0.01058841)/0.02058 = 0.753722, knee = 0.717090 rad; the thigh leans
    // forward by atan2(0.1029·sin k, 0.1 + 0.1029·cos k) = atan2(0.067625, 0.177558) = 0.363901.
    let b = BodyParams::webots();
    let q = b.leg_angles([0.0, 0.0, -0.19]).unwrap();
    assert!((q[2] - 0.717090).abs() < 1e-5, "{q:?}");
    assert!((q[1] + 0.363901).abs() < 1e-5, "{q:?}");
    assert!(
        (q[3] + (q[1] + q[2])).abs() < 1e-12 && q[0] == 0.0 && q[4] == 0.0,
        "{q:?}"
    );
    // Swayed 0.05 m to the left: hip roll atan2(0.05, 0.19) = 0.257324, ankle roll against it.
    let q = b.leg_angles([0.03, 0.05, -0.19]).unwrap();
    assert!((q[0] - 0.257324).abs() < 1e-5 && q[4] == -q[0], "{q:?}");
    let back = b.ankle_from_hip(&q);
    for (got, want) in back.iter().zip([0.03, 0.05, -0.19]) {
        assert!((got - want).abs() < 1e-12, "{back:?}");
    }
    // Out of reach: farther than 0.2029 m.
    assert!(b.leg_angles([0.0, 0.0, -0.21]).is_none());
}

#[test]
fn a_standing_nao_stays_up_for_10_s_with_its_soles_still() {
    let model = NaoModel::default();
    let ev = single(BodyParams::webots());
    let mut first: Option<[[f64; 2]; 2]> = None;
    let mut worst = 0.0f64;
    let o = ev.simulate_with_feet(&model.standing(), 10.0, &mut |_, feet| {
        let now = [[feet[0].sole_x, feet[0].sole_y], [feet[1].sole_x, feet[1].sole_y]];
        let start = *first.get_or_insert(now);
        for (a, b) in now.iter().zip(start) {
            worst = worst.max((a[0] - b[0]).hypot(a[1] - b[1]));
        }
    });
    assert!(!o.fell, "{o:?}");
    assert!(worst < 0.001, "a sole slid {worst} m");
}

#[test]
fn the_hand_made_step_is_a_non_falling_forward_step() {
    let model = NaoModel::default();
    let ind = hand_step(&model);
    // The default evaluator: the robust score at 20 ms and at 10 ms/8.
    let ev = PhysicsEvaluator::new(model.clone(), FitnessConfig::default()).unwrap();
    let e = ev.evaluate(&ind);
    let fitness = FitnessConfig::default();
    assert!(!e.fell, "{e:?}");
    assert!(e.forward_distance >= fitness.step_min_forward, "{e:?}");
    assert!(e.is_forward_step(&fitness), "{e:?}");
    // A step, not a slide or a hop: each foot lifted at least 1 cm and put down at least 4 cm
    // ahead, never both feet off the floor, at either setting.
    for body in ev.check_bodies().iter().cloned().chain([BodyParams::webots()]) {
        let (o, feet) = single(body).simulate_feet_report(&ind, 3.0);
        assert!(!o.fell && o.forward_distance >= 0.04, "{o:?}");
        for f in feet.feet {
            assert!(f.peak_height > 0.01 && f.forward > 0.04, "{feet:?}");
        }
        assert_eq!(feet.longest_flight, 0.0, "{feet:?}");
    }
}

#[test]
fn the_committed_hand_step_is_the_generators() {
    // The motion file holds forward_step's knots for the default plan, to its 4 decimals.
    let model = NaoModel::default();
    let made = forward_step(&model, &BodyParams::webots(), &StepPlan::default()).unwrap();
    let file = hand_step(&model);
    for s in Servo::ALL {
        for k in 0..KNOTS {
            let (a, b) = (made.knots[s.index()][k], file.knots[s.index()][k]);
            assert!((a - b).abs() < 2e-4, "{s:?} knot {k}: {a} vs {b}");
        }
    }
}

#[test]
fn scores_agree_with_those_at_half_the_step_and_twice_the_iterations() {
    // The convergence check on a sample (docs/ga_step.md, "Convergence", runs it on 100): the
    // standing robot, the hand-made step and 20 of the GA's random individuals.
    let model = NaoModel::default();
    let body = BodyParams::webots();
    let fine = SolverSetting::of(&body).finer().apply(&body);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let mut inds = vec![model.standing(), hand_step(&model)];
    inds.extend((0..20).map(|_| model.random_individual(&mut rng)));
    let r = agreement(&single(body), &single(fine), &inds);
    assert!(r.verdict_share() >= 0.95, "{r:?}");
    assert!(r.upright_both >= 2, "{r:?}");
    assert!(r.worst_upright_gap < 0.05, "{r:?}");
    // Δx within half the 4 cm step threshold.
    assert!(r.worst_upright_dx_gap < 0.02, "{r:?}");
}

#[test]
fn knees_fully_bent_at_once_make_the_robot_fall() {
    let model = NaoModel::default();
    let mut ind = model.standing();
    for s in [Servo::RKneePitch, Servo::LKneePitch] {
        for k in 1..KNOTS - 1 {
            ind.knots[s.index()][k] = 2.2689;
        }
    }
    let o = single(BodyParams::webots()).simulate(&ind);
    assert!(o.fell && o.t_end < 2.0, "{o:?}");
}
