//! A node that starts after the `tf_static` publisher still learns the laser pose, composed
//! through a chain of static frames, and prefers it to the parameter.
//!
//! Two broadcasters (in a separate DDS participant, latched QoS as `sim_node` publishes) send
//! base_link → mount and mount → laser before the reader exists; the reader subscribes with
//! `qos::tf_static()`, as [`mobil_ros::scan::tf_static_subscription`] does.

use std::time::{Duration, Instant};

use mobil_geom::Pose2;
use mobil_msgs::geometry_msgs::msg::TransformStamped;
use mobil_msgs::tf2_msgs::msg::TFMessage;
use mobil_msgs::RosMessage;
use mobil_ros::geometry::yaw_quaternion;
use mobil_ros::qos;
use mobil_ros::scan::{LaserPose, LaserPoseSource};
use ros2_client::Name;

const TIMEOUT: Duration = Duration::from_secs(15);

use crate::common::participant as node;

fn tf(parent: &str, child: &str, x: f64, y: f64, yaw_deg: f64) -> TransformStamped {
    let mut t = TransformStamped::default();
    t.header.frame_id = parent.into();
    t.child_frame_id = child.into();
    t.transform.translation.x = x;
    t.transform.translation.y = y;
    t.transform.rotation = yaw_quaternion(yaw_deg.to_radians());
    t
}

#[test]
fn a_late_reader_composes_the_static_chain_and_prefers_it_to_the_parameter() {
    let topic = Name::new("/", &format!("tf_static_{}", std::process::id())).expect("topic name");
    let (_pub_context, mut pub_node) = node("tf_static_publisher");
    let t = pub_node
        .create_topic(&topic, TFMessage::type_name(), &qos::latched())
        .expect("topic");
    // Two static broadcasters (two writers, each keeping its last message for late joiners, as
    // `qos::latched()` does: depth 1, so one writer's two messages would leave only the second).
    let broadcasters: Vec<_> = (0..2)
        .map(|_| {
            pub_node
                .create_publisher::<TFMessage>(&t, Some(qos::latched()))
                .expect("publisher")
        })
        .collect();
    broadcasters[0]
        .publish(TFMessage {
            transforms: vec![tf("base_link", "mount", 0.2, 0.1, 90.0)],
        })
        .expect("publish");
    broadcasters[1]
        .publish(TFMessage {
            transforms: vec![tf("mount", "laser", 0.1, 0.05, -30.0)],
        })
        .expect("publish");

    // The reader starts afterwards.
    let (_sub_context, mut sub_node) = node("tf_static_reader");
    let t = sub_node
        .create_topic(&topic, TFMessage::type_name(), &qos::tf_static())
        .expect("topic");
    let sub = sub_node
        .create_subscription::<TFMessage>(&t, Some(qos::tf_static()))
        .expect("subscription");
    let parameter = Pose2::new(0.3, 0.0, 0.0);
    let mut laser = LaserPose::new("base_link", "laser", Some(parameter));
    let (pose, source) = laser.get().expect("the parameter before any tf_static");
    assert_eq!(source, LaserPoseSource::Parameter);
    assert_eq!((pose.x, pose.y, pose.yaw), (0.3, 0.0, 0.0));

    let start = Instant::now();
    loop {
        assert_eq!(laser.poll(&sub), 0, "nothing invalid was sent");
        if laser.get().map(|(_, s)| s) == Some(LaserPoseSource::TfStatic) {
            break;
        }
        assert!(start.elapsed() < TIMEOUT, "tf_static chain not received in {TIMEOUT:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
    // By hand: the mount at (0.2, 0.1) turned 90°, so the laser's (0.1, 0.05) in the mount is
    // (−0.05, 0.1) in base_link: (0.2 − 0.05, 0.1 + 0.1) = (0.15, 0.2), yaw 90° − 30° = 60°.
    let (pose, _) = laser.get().expect("known");
    assert!((pose.x - 0.15).abs() < 1e-9, "x {}", pose.x);
    assert!((pose.y - 0.2).abs() < 1e-9, "y {}", pose.y);
    assert!(
        (pose.yaw.to_degrees() - 60.0).abs() < 1e-9,
        "yaw {}",
        pose.yaw.to_degrees()
    );
}
