//! The time rule under a simulated clock at 4× real time, and the final stop, between real
//! participants over DDS.
//!
//! A test participant publishes `/clock` advancing 40 ms every 10 ms of wall time. A `RosNode`
//! started with `use_sim_time:=true` ticks at 20 Hz on the steady clock; the `dt` that
//! [`DtClock`] measures from the node's ROS time must follow `/clock` (about 4× the wall
//! interval), while a [`Latest`] input's age, on the steady clock, must follow the wall clock.
//!
//! Each process uses its own domain (`MOBIL_TEST_DOMAIN_ID`, else 100 + pid % 100) and its own
//! topic names, so parallel runs do not meet.

use mobil_msgs::geometry_msgs::msg::Twist;
use mobil_msgs::rosgraph_msgs::msg::Clock;
use mobil_msgs::RosMessage;
use mobil_ros::latest::{Freshness, Latest};
use mobil_ros::stop::{final_stop, FinalStop};
use mobil_ros::time::{stamp_from_nanos, DtClock};
use mobil_ros::{NodeDecl, RosNode, Ticker};
use ros2_client::Name;
use std::time::{Duration, Instant};

mod common;
use common::{domain_id, participant};

/// A RosNode on the test's domain with these ROS arguments.
fn ros_node(name: &str, ros_args: &[&str]) -> RosNode {
    // SAFETY: set before any thread of this test reads the environment; every test sets the same.
    unsafe { std::env::set_var("ROS_DOMAIN_ID", domain_id().to_string()) };
    let decl = NodeDecl::new(name, "test node");
    let argv: Vec<String> = [name, "--ros-args"]
        .into_iter()
        .chain(ros_args.iter().copied())
        .map(String::from)
        .collect();
    let args = decl.parse_command_line(argv).expect("arguments").expect("not --help");
    RosNode::start(&decl, &args).expect("node starts")
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn dt_follows_the_simulated_clock_and_freshness_the_steady_clock() {
    let (_clock_context, mut clock_node) = participant("kit_time_clock");
    let qos = mobil_ros::qos::reliable(1);
    let topic = clock_node
        .create_topic(&Name::new("/", "clock").expect("name"), Clock::type_name(), &qos)
        .expect("topic");
    let clock_pub = clock_node
        .create_publisher::<Clock>(&topic, Some(qos))
        .expect("publisher");
    // /clock at 4× real time: +40 ms of ROS time every 10 ms of wall time, from 1000 s.
    let stop_clock = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let stop = stop_clock.clone();
    let clock_thread = std::thread::spawn(move || {
        let start = Instant::now();
        while !stop.load(std::sync::atomic::Ordering::Relaxed) {
            let sim_nanos = 1_000_000_000_000 + 4 * start.elapsed().as_nanos() as i64;
            let _ = clock_pub.publish(Clock {
                clock: stamp_from_nanos(sim_nanos),
            });
            std::thread::sleep(Duration::from_millis(10));
        }
    });

    let node = ros_node("kit_time_node", &["-p", "use_sim_time:=true"]);
    // Wait for the first /clock (discovery), never a fixed sleep.
    let deadline = Instant::now() + Duration::from_secs(15);
    while node.now_nanos() < 1_000_000_000_000 {
        assert!(Instant::now() < deadline, "no /clock within 15 s");
        tokio::time::sleep(Duration::from_millis(10)).await;
    }

    let mut tick = Ticker::new(20.0).expect("rate");
    let mut dt = DtClock::new();
    let mut input = Latest::new();
    input.set((), node.stamp());
    let (wall_start, mut ros_sum, mut ticks) = (Instant::now(), 0.0, 0);
    // 20 ticks of 50 ms: 1 s of wall time.
    while ticks < 21 {
        tick.tick().await;
        if let Ok(Some(step)) = dt.step(node.now_nanos()) {
            ros_sum += step;
        }
        ticks += 1;
    }
    let wall = wall_start.elapsed().as_secs_f64();
    stop_clock.store(true, std::sync::atomic::Ordering::Relaxed);
    let _ = clock_thread.join();

    // The handles: both read the latest /clock the node has read; once `use_sim_time` is set
    // false at run time and the node reads its time, the following one reads the system clock
    // and the fixed one stays on /clock.
    let mut node = node;
    let (fixed, following) = (node.clock(), node.following_clock());
    let now = node.now_nanos();
    assert!(now < 1_577_836_800_000_000_000, "{now} is simulated time");
    assert_eq!((fixed.now_nanos(), following.now_nanos()), (now, now));
    node.inner()
        .set_parameter("use_sim_time", ros2_client::ParameterValue::Boolean(false))
        .expect("use_sim_time can be set");
    assert!(node.now_nanos() > 1_577_836_800_000_000_000, "the system clock");
    assert!(
        following.now_nanos() > 1_577_836_800_000_000_000,
        "the following handle too"
    );
    assert_eq!(fixed.now_nanos(), now, "the fixed handle keeps /clock");

    // ROS time advanced about 4× the wall time (±20 %: a 10 ms clock period and a loaded
    // machine blur each step).
    let ratio = ros_sum / wall;
    assert!(
        (3.2..4.8).contains(&ratio),
        "dt summed to {ros_sum:.3} s over {wall:.3} s of wall time"
    );
    // The input set before the loop is about `wall` old on the steady clock — not 4× that: a
    // 1.5 s watchdog still calls it fresh, although ROS time moved by about 4 s.
    let age = input.received().map(|r| r.elapsed().as_secs_f64()).unwrap_or(f64::NAN);
    println!("ROS time {ros_sum:.3} s over {wall:.3} s of wall time (×{ratio:.2}); steady age {age:.3} s");
    assert!((age - wall).abs() < 0.1, "age {age:.3} s, wall {wall:.3} s");
    assert_eq!(input.status(Duration::from_millis(1500)), Freshness::Fresh);
    assert!(
        ros_sum > 1.5,
        "ROS time moved {ros_sum:.3} s, beyond the 1.5 s watchdog"
    );
    node.shutdown().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_final_stop_is_acknowledged_by_a_matched_reader() {
    let topic_name = format!("kit_stop_{}", std::process::id());
    let mut node = ros_node("kit_stop_node", &[]);
    let cmd = node
        .publisher::<Twist>(&topic_name, &mobil_ros::qos::default_qos())
        .expect("publisher");
    let (_context, mut reader_node) = participant("kit_stop_reader");
    let qos = mobil_ros::qos::default_qos();
    let topic = reader_node
        .create_topic(&Name::new("/", &topic_name).expect("name"), Twist::type_name(), &qos)
        .expect("topic");
    let sub = reader_node
        .create_subscription::<Twist>(&topic, Some(qos))
        .expect("subscription");
    // Wait until the reader receives (discovery done): publish a moving command until one arrives.
    let deadline = Instant::now() + Duration::from_secs(15);
    let mut moving = Twist::default();
    moving.linear.x = 0.5;
    loop {
        let _ = cmd.publish(moving.clone());
        tokio::time::sleep(Duration::from_millis(20)).await;
        if let Ok(Some(_)) = sub.take() {
            break;
        }
        assert!(Instant::now() < deadline, "the reader never matched");
    }
    let started = Instant::now();
    let outcome = final_stop(&cmd, Twist::default(), Duration::from_millis(500)).await;
    let waited = started.elapsed();
    println!("final stop {outcome:?} after {waited:?}");
    // Acknowledged within the wait given (500 ms, give or take the last 2 ms poll).
    assert_eq!(outcome, FinalStop::Acknowledged);
    // Acknowledged means received: the zero command is in the reader's cache now.
    let mut last = None;
    while let Ok(Some((t, _))) = sub.take() {
        last = Some(t);
    }
    assert_eq!(last.map(|t| t.linear.x), Some(0.0));
    // The bound on the wait (TimedOut at the deadline) is checked without DDS, in stop.rs:
    // whether a reader's acknowledgement comes before a given instant is a race here.
    node.shutdown().await;
}
