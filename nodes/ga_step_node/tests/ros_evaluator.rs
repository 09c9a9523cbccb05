//! The external evaluator against a fake simulator in the same process (two DDS participants):
//! one round trip, then a simulator that never answers.

use mobil_ga_step::{Evaluator, FitnessConfig, NaoModel, Servo};
use mobil_ga_step_node::ros_eval::{
    RosEvalError, RosEvaluator, CANDIDATE_TOPIC, FALL_TIME_TOPIC, FELL_TOPIC, FORWARD_TOPIC,
};
use mobil_msgs::std_msgs::msg::{Bool, Float64};
use mobil_msgs::trajectory_msgs::msg::JointTrajectory;
use mobil_msgs::RosMessage;
use ros2_client::{Context, ContextOptions, Name, NodeName, NodeOptions};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

/// A simulator that answers every candidate: a fall at 1.25 s, and as forward distance the
/// candidate's RKneePitch at its middle point (t = T/2) divided by 10 (so the test sees that
/// the trajectory arrived); it sends what it received to `seen`. With `silent` it answers
/// nothing.
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
        let topic = |name: &str, type_name| {
            node.create_topic(&Name::parse(&format!("/{name}")).unwrap(), type_name, &q)
                .unwrap()
        };
        let candidate_topic = topic(CANDIDATE_TOPIC, JointTrajectory::type_name());
        let fell_topic = topic(FELL_TOPIC, Bool::type_name());
        let forward_topic = topic(FORWARD_TOPIC, Float64::type_name());
        let time_topic = topic(FALL_TIME_TOPIC, Float64::type_name());
        let candidates = node
            .create_subscription::<JointTrajectory>(&candidate_topic, Some(q.clone()))
            .unwrap();
        let fell = node.create_publisher::<Bool>(&fell_topic, Some(q.clone())).unwrap();
        let forward = node
            .create_publisher::<Float64>(&forward_topic, Some(q.clone()))
            .unwrap();
        let fall_time = node.create_publisher::<Float64>(&time_topic, Some(q.clone())).unwrap();
        while !stop.load(Ordering::SeqCst) {
            if let Ok(Some((m, _))) = candidates.take() {
                let knee = m
                    .points
                    .get(10)
                    .and_then(|p| p.positions.get(2))
                    .copied()
                    .unwrap_or(f64::NAN);
                let _ = seen.send(m);
                if !silent {
                    fall_time.publish(Float64 { data: 1.25 }).unwrap();
                    fell.publish(Bool { data: true }).unwrap();
                    forward.publish(Float64 { data: knee / 10.0 }).unwrap();
                }
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    })
}

#[test]
fn a_candidate_goes_out_as_a_joint_trajectory_and_its_answer_is_scored() {
    let domain = 230 + (std::process::id() % 3) as u16;
    // SAFETY: set before any thread of this test binary reads the environment (one test).
    unsafe { std::env::set_var("ROS_DOMAIN_ID", domain.to_string()) };
    let model = NaoModel::default();
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel();
    let sim = fake_simulator(domain, false, tx, stop.clone());
    let evaluator = RosEvaluator::new(model.clone(), FitnessConfig::default(), Duration::from_secs(20)).unwrap();
    let mut ind = model.standing();
    ind.knots[Servo::RKneePitch.index()][10] = 1.5;
    let e = evaluator.evaluate(&ind);
    assert_eq!(evaluator.failure(), None);
    // Fell at 1.25 s of T_sim = 3 s, 1.5/10 = 0.15 m forward: a fall scores its time alone,
    // f = 1.25/3 = 0.416667 (the distance is reported but does not count).
    assert!(e.fell);
    assert_eq!(e.t_fall, 1.25);
    assert!((e.forward_distance - 0.15).abs() < 1e-12);
    assert!((e.fitness - 1.25 / 3.0).abs() < 1e-12, "{e:?}");
    let m = rx.recv_timeout(Duration::from_secs(5)).unwrap();
    assert_eq!(m.header.frame_id, "candidate 1");
    assert_eq!(m.joint_names[0], "RHipPitch");
    assert_eq!(m.joint_names[9], "LAnkleRoll");
    assert_eq!(m.points.len(), 21);
    // Knot 10 at 10·T/20 = 1 s, knot 20 at T = 2 s; the standing pose at both ends.
    assert_eq!(
        (m.points[10].time_from_start.sec, m.points[10].time_from_start.nanosec),
        (1, 0)
    );
    assert_eq!(
        (m.points[20].time_from_start.sec, m.points[20].time_from_start.nanosec),
        (2, 0)
    );
    assert_eq!(
        (m.points[1].time_from_start.sec, m.points[1].time_from_start.nanosec),
        (0, 100_000_000)
    );
    assert_eq!(m.points[0].positions, model.standing_pose.to_vec());
    assert_eq!(m.points[20].positions, model.standing_pose.to_vec());
    // A second candidate is numbered 2 and answered by itself, not by the first's answer.
    ind.knots[Servo::RKneePitch.index()][10] = 0.5;
    let e2 = evaluator.evaluate(&ind);
    assert!((e2.forward_distance - 0.05).abs() < 1e-12, "{e2:?}");
    assert_eq!(
        rx.recv_timeout(Duration::from_secs(5)).unwrap().header.frame_id,
        "candidate 2"
    );
    stop.store(true, Ordering::SeqCst);
    sim.join().unwrap();

    // A simulator that hears the candidate but never answers: a timeout error, not a hang, and
    // every later evaluation returns at once.
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, _rx) = mpsc::channel();
    let sim = fake_simulator(domain, true, tx, stop.clone());
    let evaluator = RosEvaluator::new(model.clone(), FitnessConfig::default(), Duration::from_secs(3)).unwrap();
    let t = Instant::now();
    let e = evaluator.evaluate(&ind);
    assert!(t.elapsed() < Duration::from_secs(8), "{:?}", t.elapsed());
    assert_eq!(e.fitness, 0.0);
    assert!(
        matches!(evaluator.failure(), Some(RosEvalError::Timeout { candidate: 1, .. })),
        "{:?}",
        evaluator.failure()
    );
    let t = Instant::now();
    evaluator.evaluate(&ind);
    assert!(t.elapsed() < Duration::from_millis(100));
    stop.store(true, Ordering::SeqCst);
    sim.join().unwrap();
}
