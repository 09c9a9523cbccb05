//! chassis_node as a process, driven over DDS by a ros2-client peer: wheel feedback in, `odom`
//! and `tf` out, and both must carry the same pose. (The rclpy tests cannot read `tf`: there is
//! no tf2_msgs wheel on PyPI.)

use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_msgs::sensor_msgs::msg::JointState;
use mobil_msgs::tf2_msgs::msg::TFMessage;
use mobil_ros::{qos, NodeDecl, RosArgs, RosNode};
use std::process::{Child, Command};
use std::time::{Duration, Instant};

struct Node(Child);

impl Drop for Node {
    fn drop(&mut self) {
        // SIGINT, as Ctrl-C would; then make sure it is gone.
        let _ = Command::new("kill").args(["-INT", &self.0.id().to_string()]).status();
        let deadline = Instant::now() + Duration::from_secs(5);
        while Instant::now() < deadline {
            if let Ok(Some(_)) = self.0.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.0.kill();
    }
}

fn feedback(t: f64, wheels: [f64; 3]) -> JointState {
    let mut js = JointState::default();
    js.header.stamp = mobil_ros::time::stamp_from_secs(t);
    js.name = ["wheel_1", "wheel_2", "wheel_3"].map(String::from).to_vec();
    js.velocity = wheels.to_vec();
    js
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn odom_and_tf_agree_with_the_wheels() {
    let domain = 200 + (std::process::id() % 30);
    // SAFETY: the binary's only test, before it starts a task or a process; no thread reads the
    // environment meanwhile.
    unsafe { std::env::set_var("ROS_DOMAIN_ID", domain.to_string()) };
    let params = concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/omr3.yaml");
    let _chassis = Node(
        Command::new(env!("CARGO_BIN_EXE_chassis_node"))
            .args(["--ros-args", "--params-file", params, "--log-level", "warn"])
            .spawn()
            .expect("chassis_node starts"),
    );
    let mut probe = RosNode::start(&NodeDecl::new("tf_probe", "test peer"), &RosArgs::default()).unwrap();
    let joints = probe
        .publisher::<JointState>("joint_states", &qos::default_qos())
        .unwrap();
    let odom = probe.subscription::<Odometry>("odom", &qos::default_qos()).unwrap();
    let tf = probe.subscription::<TFMessage>("tf", &qos::reliable(100)).unwrap();

    // OMR-III at rest until the node answers, then body-x at 0.3 m/s (Ω = [6, −3, −3] rad/s with
    // r = 0.05) for 1 s in 0.1 s steps: x = 0.3 m, y = 0, yaw = 0.
    let deadline = Instant::now() + Duration::from_secs(15);
    let mut t = 10.0;
    let mut answered = false;
    while !answered {
        assert!(
            Instant::now() < deadline,
            "chassis_node did not answer on domain {domain}"
        );
        joints.publish(feedback(t, [0.0; 3])).unwrap();
        t += 0.01;
        tokio::time::sleep(Duration::from_millis(50)).await;
        answered = matches!(odom.take(), Ok(Some(_)));
    }
    let start = t;
    joints.publish(feedback(start, [0.0; 3])).unwrap();
    for i in 1..=10 {
        joints
            .publish(feedback(start + 0.1 * f64::from(i), [6.0, -3.0, -3.0]))
            .unwrap();
    }
    let end = mobil_ros::time::stamp_from_secs(start + 1.0);
    let (mut odom_end, mut tf_end) = (None, None);
    while odom_end.is_none() || tf_end.is_none() {
        assert!(Instant::now() < deadline, "no odom/tf for the last sample");
        while let Ok(Some((m, _))) = odom.take() {
            if m.header.stamp == end {
                odom_end = Some(m);
            }
        }
        while let Ok(Some((m, _))) = tf.take() {
            if let Some(tr) = m.transforms.into_iter().find(|tr| tr.header.stamp == end) {
                tf_end = Some(tr);
            }
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let (o, tr) = (odom_end.unwrap(), tf_end.unwrap());
    assert!(
        (o.pose.pose.position.x - 0.3).abs() < 1e-9,
        "{:?}",
        o.pose.pose.position
    );
    assert!(o.pose.pose.position.y.abs() < 1e-9);
    assert_eq!(
        (tr.header.frame_id.as_str(), tr.child_frame_id.as_str()),
        ("odom", "base_link")
    );
    assert_eq!(tr.transform.translation.x, o.pose.pose.position.x);
    assert_eq!(tr.transform.translation.y, o.pose.pose.position.y);
    assert_eq!(tr.transform.rotation, o.pose.pose.orientation);
    assert!((o.twist.twist.linear.x - 0.3).abs() < 1e-9);
    // Covariance grows along the track: k_s·s = 1e-4 m²/m · 0.3 m on x, nothing sideways yet.
    assert!((o.pose.covariance[0] - 3e-5).abs() < 1e-12, "{}", o.pose.covariance[0]);
    probe.shutdown().await;
}
