//! The external evaluator against a fake simulator in the same process (two DDS participants),
//! under a namespace given as a ROS argument: round trips whose answers are told apart from
//! stale and foreign ones by the echoed header, a simulator that restarts while a candidate
//! waits, copies lost, a simulator that never answers, and an interrupt while waiting.

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

/// The namespace of this process's topics: another copy of this test running at the same time
/// (another checkout) on the same domain must not answer its candidates.
fn ns() -> String {
    format!("/sim{}", std::process::id())
}

fn outcome(header: Header, fell: bool, fall_time: f64, forward: f64) -> JointState {
    JointState {
        header,
        name: vec!["fell".into(), "forward_distance".into(), "fall_time".into()],
        position: vec![if fell { 1.0 } else { 0.0 }, forward, fall_time],
        ..Default::default()
    }
}

/// How a fake simulator answers.
#[derive(Clone, Copy, PartialEq)]
enum Mode {
    /// Every candidate it receives.
    Answer,
    /// Nothing (it hears, and stays up: a simulator that hung, or crashed within its lease).
    Silent,
    /// A candidate the second time it receives it (the first copy "lost").
    SecondCopy,
}

/// A simulator under [`ns`] that answers candidates as `mode` says: a fall at 1.25 s, and as
/// forward distance the candidate's RKneePitch at its middle point (t = T/2) divided by 10.
/// Before each answer it sends two it must be ignored for: the header of the previous candidate
/// it answered (unless this is a copy of it) with an upright 9 m, and this candidate's frame_id with another stamp (another run) with an
/// upright 7 m. It sends what it received to `seen`.
fn fake_simulator(
    domain: u16,
    mode: Mode,
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
                &Name::parse(&format!("{}/{CANDIDATE_TOPIC}", ns())).unwrap(),
                JointTrajectory::type_name(),
                &q,
            )
            .unwrap();
        let outcome_topic = node
            .create_topic(
                &Name::parse(&format!("{}/{OUTCOME_TOPIC}", ns())).unwrap(),
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
        let mut received: Vec<Header> = Vec::new();
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
                let first_copy = !received.contains(&header);
                received.push(header.clone());
                let answer = match mode {
                    Mode::Answer => true,
                    Mode::Silent => false,
                    Mode::SecondCopy => !first_copy,
                };
                if answer {
                    // The previous candidate answered (not a copy of this one).
                    if let Some(p) = previous.take().filter(|p| *p != header) {
                        outcomes.publish(outcome(p, false, 0.0, 9.0)).unwrap();
                    }
                    let mut other_run = header.clone();
                    other_run.stamp.nanosec = (other_run.stamp.nanosec + 1) % 1_000_000_000;
                    outcomes.publish(outcome(other_run, false, 0.0, 7.0)).unwrap();
                    outcomes
                        .publish(outcome(header.clone(), true, 1.25, knee / 10.0))
                        .unwrap();
                    previous = Some(header);
                }
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    })
}

/// A running [`fake_simulator`]: what it received, and the way to stop it.
struct FakeSim {
    seen: mpsc::Receiver<JointTrajectory>,
    stop: Arc<AtomicBool>,
    thread: std::thread::JoinHandle<()>,
}

impl FakeSim {
    fn start(domain: u16, mode: Mode) -> FakeSim {
        let stop = Arc::new(AtomicBool::new(false));
        let (tx, seen) = mpsc::channel();
        let thread = fake_simulator(domain, mode, tx, stop.clone());
        FakeSim { seen, stop, thread }
    }

    /// The next candidate it received, within `secs`.
    fn heard(&self, secs: u64) -> JointTrajectory {
        self.seen.recv_timeout(Duration::from_secs(secs)).unwrap()
    }

    fn stop(self) {
        self.stop.store(true, Ordering::SeqCst);
        self.thread.join().unwrap();
    }
}

/// An evaluator under [`ns`] with the default fitness and an attempt timeout of `timeout_s`.
fn ros_evaluator(model: &NaoModel, timeout_s: u64, interrupt: &Arc<AtomicBool>) -> RosEvaluator {
    RosEvaluator::new(
        model.clone(),
        FitnessConfig::default(),
        Duration::from_secs(timeout_s),
        false,
        &namespaced(),
        interrupt.clone(),
    )
    .unwrap()
}

fn namespaced() -> RosArgs {
    RosArgs {
        namespace: Some(ns()),
        ..RosArgs::default()
    }
}

#[test]
fn candidates_are_answered_by_their_own_outcome_only() {
    let domain = 220 + (std::process::id() % 3) as u16;
    // SAFETY: set before any thread of this test binary reads the environment (one test).
    unsafe { std::env::set_var("ROS_DOMAIN_ID", domain.to_string()) };
    let model = NaoModel::default();
    let sim = FakeSim::start(domain, Mode::Answer);
    let interrupt = Arc::new(AtomicBool::new(false));
    let evaluator = ros_evaluator(&model, 20, &interrupt);
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
    let m = sim.heard(5);
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
    assert_eq!(sim.heard(5).header.frame_id, "candidate 2");
    sim.stop();

    // The simulator restarts: the evaluator waits for the new one and is answered by it.
    let sim = FakeSim::start(domain, Mode::Answer);
    ind.knots[Servo::RKneePitch.index()][10] = 1.0;
    let e3 = evaluator.evaluate(&ind);
    assert_eq!(evaluator.failure(), None);
    assert!((e3.forward_distance - 0.1).abs() < 1e-12, "{e3:?}");
    assert_eq!(sim.heard(5).header.frame_id, "candidate 3");
    drop(evaluator);
    sim.stop();

    restart_and_lost_copies(domain, &model);

    // A simulator that hears the candidates but never answers: each attempt ends after the
    // timeout (1 s); the first candidate's two attempts leave it a void score of 0 and the run
    // goes on; the second candidate's first attempt is the third in a row, which stops the
    // evaluator, and every later evaluation returns at once.
    let sim = FakeSim::start(domain, Mode::Silent);
    let evaluator = ros_evaluator(&model, 1, &interrupt);
    // The first call may also wait up to 1 s for discovery.
    let t = Instant::now();
    let e = evaluator.evaluate(&ind);
    let took = t.elapsed();
    assert!(
        took >= Duration::from_secs(2) && took < Duration::from_secs(5),
        "{took:?} {e:?} {:?}",
        evaluator.failure()
    );
    assert_eq!((e.fitness, e.fell), (0.0, true));
    assert_eq!(evaluator.failure(), None);
    assert_eq!(evaluator.void_scores(), 1);
    // Sent once per attempt (no periodic re-send within 1 s), with the same header.
    let first = sim.heard(2);
    let again = sim.heard(2);
    assert_eq!(first.header.frame_id, "candidate 1");
    assert_eq!(again.header, first.header);
    evaluator.evaluate(&ind);
    assert!(
        matches!(evaluator.failure(), Some(RosEvalError::Unanswered { candidate: 2, .. })),
        "{:?}",
        evaluator.failure()
    );
    assert_eq!(evaluator.void_scores(), 1);
    // At once: an attempt would wait the whole 1 s timeout.
    let t = Instant::now();
    evaluator.evaluate(&ind);
    assert!(t.elapsed() < Duration::from_millis(900), "{:?}", t.elapsed());
    drop(evaluator);

    // An interrupt while a candidate waits (timeout 20 s) stops the wait within a moment.
    let evaluator = ros_evaluator(&model, 20, &interrupt);
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
    sim.stop();
}

/// A candidate in flight when its simulator restarts, or whose first copy is lost.
fn restart_and_lost_copies(domain: u16, model: &NaoModel) {
    let interrupt = Arc::new(AtomicBool::new(false));
    let mut ind = model.standing();
    ind.knots[Servo::RKneePitch.index()][10] = 0.7;

    // The old simulator hears candidate 1 and hangs (its participant stays, as a crashed one's
    // does until its lease ends); a new one starts while the candidate waits. The candidate is
    // sent again once the new reader is matched, and answered long before the timeout (20 s)
    // or the periodic re-send (60 s here).
    let old = FakeSim::start(domain, Mode::Silent);
    let evaluator = ros_evaluator(model, 20, &interrupt).with_resend_every(Duration::from_secs(60));
    let (e, took, new) = std::thread::scope(|s| {
        let waiting = s.spawn(|| evaluator.evaluate(&ind));
        let heard = old.heard(10);
        assert_eq!(heard.header.frame_id, "candidate 1");
        let t = Instant::now();
        let new = FakeSim::start(domain, Mode::Answer);
        let e = waiting.join().unwrap();
        (e, t.elapsed(), new)
    });
    assert_eq!(evaluator.failure(), None);
    assert!(took < Duration::from_secs(10), "{took:?}");
    // 0.7/10 = 0.07 m, the fall at 1.25 s: f = 1.25/3.
    assert!((e.forward_distance - 0.07).abs() < 1e-12, "{e:?}");
    assert!((e.fitness - 1.25 / 3.0).abs() < 1e-12, "{e:?}");
    assert_eq!(new.heard(1).header.frame_id, "candidate 1");
    drop(evaluator);
    old.stop();
    new.stop();

    // A simulator that loses the first copy of each candidate. With a timeout of 20 s and a
    // re-send every second, the second copy is answered after about a second; with a timeout
    // of 1 s (no re-send within it), the second attempt's copy is.
    let sim = FakeSim::start(domain, Mode::SecondCopy);
    for (timeout, every) in [(20, 1), (1, 60)] {
        let evaluator = ros_evaluator(model, timeout, &interrupt).with_resend_every(Duration::from_secs(every));
        let t = Instant::now();
        let e = evaluator.evaluate(&ind);
        let took = t.elapsed();
        assert_eq!(evaluator.failure(), None, "timeout {timeout} s");
        assert_eq!(evaluator.void_scores(), 0);
        assert!(
            took >= Duration::from_millis(900) && took < Duration::from_secs(8),
            "{took:?}"
        );
        assert!((e.forward_distance - 0.07).abs() < 1e-12, "timeout {timeout} s: {e:?}");
        let first = sim.heard(1);
        let second = sim.heard(1);
        assert_eq!(first.header, second.header);
        drop(evaluator);
        while sim.seen.try_recv().is_ok() {}
    }
    sim.stop();
}
