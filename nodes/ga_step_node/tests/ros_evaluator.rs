//! The external evaluator against a fake simulator in the same process (two DDS participants),
//! under a namespace given as a ROS argument: round trips whose answers are told apart from
//! stale and foreign ones by the echoed header, a simulator that never answers, and an
//! interrupt while waiting.

use mobil_ga_step::{Evaluator, FitnessConfig, NaoModel, Servo};
use mobil_ga_step_node::ros_eval::{RosEvalError, RosEvaluator, CANDIDATE_TOPIC, OUTCOME_TOPIC};
use mobil_msgs::sensor_msgs::msg::JointState;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::trajectory_msgs::msg::JointTrajectory;
use mobil_msgs::RosMessage;
use mobil_ros::args::RosArgs;
use ros2_client::{Context, ContextOptions, Name, NodeName, NodeOptions};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

const NS: &str = "/sim7";

fn outcome(header: Header, fell: bool, fall_time: f64, forward: f64) -> JointState {
    JointState {
        header,
        name: vec!["fell".into(), "forward_distance".into(), "fall_time".into()],
        position: vec![if fell { 1.0 } else { 0.0 }, forward, fall_time],
        ..Default::default()
    }
}

/// A simulator under [`NS`] that answers every candidate: a fall at 1.25 s, and as forward
/// distance the candidate's RKneePitch at its middle point (t = T/2) divided by 10. Before each
/// answer it sends two it must be ignored for: the previous candidate's header with an upright
/// 9 m, and this candidate's frame_id with another stamp (another run) with an upright 7 m. It
/// sends what it received to `seen`. With `silent` it answers nothing.
fn fake_simulator(
    domain: u16,
    silent: bool,
    seen: mpsc::Sender<JointTrajectory>,
    stop: Arc<AtomicBool>,
) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        let context = Context::with_options(ContextOptions::new().domain_id(domain)).unwrap();
        let mut node = context
            .new_node(NodeName::new("/", "fake_simulator").unwrap(), NodeOptions::new())
            .unwrap();
        let q = mobil_ros::qos::reliable(10);
        let candidate_topic = node
            .create_topic(
                &Name::parse(&format!("{NS}/{CANDIDATE_TOPIC}")).unwrap(),
                JointTrajectory::type_name(),
                &q,
            )
            .unwrap();
        let outcome_topic = node
            .create_topic(
                &Name::parse(&format!("{NS}/{OUTCOME_TOPIC}")).unwrap(),
                JointState::type_name(),
                &q,
            )
            .unwrap();
        let candidates = node
            .create_subscription::<JointTrajectory>(&candidate_topic, Some(q.clone()))
            .unwrap();
        let outcomes = node
            .create_publisher::<JointState>(&outcome_topic, Some(q.clone()))
            .unwrap();
        let mut previous: Option<Header> = None;
        while !stop.load(Ordering::SeqCst) {
            if let Ok(Some((m, _))) = candidates.take() {
                let knee = m
                    .points
                    .get(10)
                    .and_then(|p| p.positions.get(2))
                    .copied()
                    .unwrap_or(f64::NAN);
                let header = m.header.clone();
                let _ = seen.send(m);
                if !silent {
                    if let Some(p) = previous.take() {
                        outcomes.publish(outcome(p, false, 0.0, 9.0)).unwrap();
                    }
                    let mut other_run = header.clone();
                    other_run.stamp.nanosec = (other_run.stamp.nanosec + 1) % 1_000_000_000;
                    outcomes.publish(outcome(other_run, false, 0.0, 7.0)).unwrap();
                    outcomes
                        .publish(outcome(header.clone(), true, 1.25, knee / 10.0))
                        .unwrap();
                }
                previous = Some(header);
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    })
}

fn namespaced() -> RosArgs {
    RosArgs {
        namespace: Some(NS.into()),
        ..RosArgs::default()
    }
}

#[test]
fn candidates_are_answered_by_their_own_outcome_only() {
    let domain = 220 + (std::process::id() % 3) as u16;
    // SAFETY: set before any thread of this test binary reads the environment (one test).
    unsafe { std::env::set_var("ROS_DOMAIN_ID", domain.to_string()) };
    let model = NaoModel::default();
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel();
    let sim = fake_simulator(domain, false, tx, stop.clone());
    let interrupt = Arc::new(AtomicBool::new(false));
    let evaluator = RosEvaluator::new(
        model.clone(),
        FitnessConfig::default(),
        Duration::from_secs(20),
        &namespaced(),
        interrupt.clone(),
    )
    .unwrap();
    let mut ind = model.standing();
    ind.knots[Servo::RKneePitch.index()][10] = 1.5;
    let e = evaluator.evaluate(&ind);
    assert_eq!(evaluator.failure(), None);
    // Fell at 1.25 s of T_sim = 3 s, 1.5/10 = 0.15 m forward: a fall scores its time alone,
    // f = 1.25/3 = 0.416667. The other run's upright 7 m would have scored 1 + 2·8 = 17.
    assert!(e.fell);
    assert_eq!(e.t_fall, 1.25);
    assert!((e.forward_distance - 0.15).abs() < 1e-12);
    assert!((e.fitness - 1.25 / 3.0).abs() < 1e-12, "{e:?}");
    let m = rx.recv_timeout(Duration::from_secs(5)).unwrap();
    assert_eq!(m.header.frame_id, "candidate 1");
    assert!(m.header.stamp.sec > 1_700_000_000, "{:?}", m.header.stamp);
    assert_eq!(m.joint_names[0], "RHipPitch");
    assert_eq!(m.joint_names[9], "LAnkleRoll");
    assert_eq!(m.points.len(), 21);
    // Knot 10 at 10·T/20 = 1 s, knot 1 at 0.1 s; the standing pose at both ends.
    assert_eq!(
        (m.points[10].time_from_start.sec, m.points[10].time_from_start.nanosec),
        (1, 0)
    );
    assert_eq!(
        (m.points[1].time_from_start.sec, m.points[1].time_from_start.nanosec),
        (0, 100_000_000)
    );
    assert_eq!(m.points[0].positions, model.standing_pose.to_vec());
    assert_eq!(m.points[20].positions, model.standing_pose.to_vec());
    // The second candidate: before its answer come candidate 1's header (upright, 9 m: f = 21)
    // and another run's (7 m): both ignored, so 0.5/10 = 0.05 m and the fall at 1.25 s.
    ind.knots[Servo::RKneePitch.index()][10] = 0.5;
    let e2 = evaluator.evaluate(&ind);
    assert!(e2.fell, "{e2:?}");
    assert!((e2.forward_distance - 0.05).abs() < 1e-12, "{e2:?}");
    assert!((e2.fitness - 1.25 / 3.0).abs() < 1e-12, "{e2:?}");
    assert_eq!(
        rx.recv_timeout(Duration::from_secs(5)).unwrap().header.frame_id,
        "candidate 2"
    );
    stop.store(true, Ordering::SeqCst);
    sim.join().unwrap();

    // The simulator restarts: the evaluator waits for the new one and is answered by it.
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel();
    let sim = fake_simulator(domain, false, tx, stop.clone());
    ind.knots[Servo::RKneePitch.index()][10] = 1.0;
    let e3 = evaluator.evaluate(&ind);
    assert_eq!(evaluator.failure(), None);
    assert!((e3.forward_distance - 0.1).abs() < 1e-12, "{e3:?}");
    assert_eq!(
        rx.recv_timeout(Duration::from_secs(5)).unwrap().header.frame_id,
        "candidate 3"
    );
    drop(evaluator);
    stop.store(true, Ordering::SeqCst);
    sim.join().unwrap();

    // A simulator that hears the candidates but never answers: each candidate scores 0 after
    // the timeout (1 s), the run goes on; the third in a row stops the evaluator, and every
    // later evaluation returns at once.
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel();
    let sim = fake_simulator(domain, true, tx, stop.clone());
    let evaluator = RosEvaluator::new(
        model.clone(),
        FitnessConfig::default(),
        Duration::from_secs(1),
        &namespaced(),
        interrupt.clone(),
    )
    .unwrap();
    // The first call may also wait up to 1 s for discovery.
    let t = Instant::now();
    let e = evaluator.evaluate(&ind);
    assert!(t.elapsed() < Duration::from_secs(4), "{:?}", t.elapsed());
    assert_eq!((e.fitness, e.fell), (0.0, true));
    assert_eq!(evaluator.failure(), None);
    assert_eq!(
        rx.recv_timeout(Duration::from_secs(2)).unwrap().header.frame_id,
        "candidate 1"
    );
    evaluator.evaluate(&ind);
    assert_eq!(evaluator.failure(), None);
    evaluator.evaluate(&ind);
    assert!(
        matches!(evaluator.failure(), Some(RosEvalError::Unanswered { candidate: 3, .. })),
        "{:?}",
        evaluator.failure()
    );
    let t = Instant::now();
    evaluator.evaluate(&ind);
    assert!(t.elapsed() < Duration::from_millis(100));
    drop(evaluator);

    // An interrupt while a candidate waits (timeout 20 s) stops the wait within a moment.
    let evaluator = RosEvaluator::new(
        model.clone(),
        FitnessConfig::default(),
        Duration::from_secs(20),
        &namespaced(),
        interrupt.clone(),
    )
    .unwrap();
    let flag = interrupt.clone();
    let setter = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(2500));
        flag.store(true, Ordering::SeqCst);
    });
    let t = Instant::now();
    let e = evaluator.evaluate(&ind);
    let waited = t.elapsed();
    assert!(
        waited >= Duration::from_millis(2400) && waited < Duration::from_secs(4),
        "{waited:?}"
    );
    assert_eq!(e.fitness, 0.0);
    assert!(
        matches!(evaluator.failure(), Some(RosEvalError::Interrupted(1))),
        "{:?}",
        evaluator.failure()
    );
    setter.join().unwrap();
    drop(evaluator);
    stop.store(true, Ordering::SeqCst);
    sim.join().unwrap();
}
