//! The generated layouts decode bytes serialised by rclpy (rmw_fastrtps, ROS 2 Jazzy) with
//! `rclpy.serialization.serialize_message`, and re-encode to the same length. The hex strings
//! below are the CDR bodies rclpy produced (the 4-byte encapsulation header removed); padding
//! bytes in them are whatever Fast DDS left there, so the comparison is by value and length.

use byteorder::LittleEndian;
use mobil_msgs::geometry_msgs::msg::Twist;
use mobil_msgs::mobil_msgs::msg::{FootTouchdown, GaitPlan, TerrainAssessment};
use mobil_msgs::mobil_msgs::srv::{PlanGaitRequest, PlanGaitResponse};
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_msgs::sensor_msgs::msg::{JointState, LaserScan};
use mobil_msgs::visualization_msgs::msg::Marker;
use mobil_msgs::RosMessage;
use serde::{de::DeserializeOwned, Serialize};

fn hex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

/// Decodes rclpy's bytes, checks every byte was consumed, and that our encoding has the same size.
fn decode<T: Serialize + DeserializeOwned + RosMessage>(body_hex: &str) -> T {
    let bytes = hex(body_hex);
    let (msg, used): (T, usize) = cdr_encoding::from_bytes::<T, LittleEndian>(&bytes).unwrap();
    // Fast DDS pads the body (to a multiple of 8 here); everything before that padding is the message.
    assert!(
        bytes.len() - used < 8,
        "{}: decoded {used} of {} bytes",
        T::NAME,
        bytes.len()
    );
    let ours = cdr_encoding::to_vec::<T, LittleEndian>(&msg).unwrap();
    assert_eq!(ours.len(), used, "{}: re-encoded length", T::NAME);
    let (again, _): (T, usize) = cdr_encoding::from_bytes::<T, LittleEndian>(&ours).unwrap();
    assert_eq!(again, msg);
    msg
}

#[test]
fn twist_from_rclpy() {
    let t: Twist =
        decode("000000000000e03f0000000000000000000000000000000000000000000000000000000000000000000000000000d0bf");
    assert_eq!((t.linear.x, t.linear.y, t.angular.z), (0.5, 0.0, -0.25));
}

#[test]
fn odometry_with_36_covariance_from_rclpy() {
    let o: Odometry = decode(concat!(
        "0c00000059010000050000006f646f6d005600000a000000626173655f6c696e6b00900264969301000000000000f83f",
        "00000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000f03f",
        "0000000000000000000000000000f03f0000000000000040000000000000084000000000000010400000000000001440",
        "00000000000018400000000000001c400000000000002040000000000000224000000000000024400000000000002640",
        "00000000000028400000000000002a400000000000002c400000000000002e4000000000000030400000000000003140",
        "000000000000324000000000000033400000000000003440000000000000354000000000000036400000000000003740",
        "000000000000384000000000000039400000000000003a400000000000003b400000000000003c400000000000003d40",
        "0000000000003e400000000000003f400000000000004040000000000080404000000000000041400000000000804140",
        "000000000000d03f00000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000"
    ));
    assert_eq!((o.header.stamp.sec, o.header.stamp.nanosec), (12, 345));
    assert_eq!(o.header.frame_id, "odom");
    assert_eq!(o.child_frame_id, "base_link");
    assert_eq!(o.pose.pose.position.x, 1.5);
    assert_eq!(o.pose.pose.orientation.w, 1.0);
    assert!(o.pose.covariance.iter().enumerate().all(|(i, c)| *c == i as f64));
    assert_eq!(o.twist.twist.linear.x, 0.25);
}

#[test]
fn joint_state_with_strings_and_sequences_from_rclpy() {
    let j: JointState = decode(concat!(
        "000000000000000001000000000000000200000002000000610000000300000062630001010000009a9999999999b93f",
        "0200000000000000000000000000f03f000000000000004000000000a6010000"
    ));
    assert_eq!(j.name, ["a", "bc"]);
    assert_eq!(j.position, [0.1]);
    assert_eq!(j.velocity, [1.0, 2.0]);
    assert!(j.effort.is_empty());
}

#[test]
fn laser_scan_with_inf_from_rclpy() {
    let s: LaserScan = decode(concat!(
        "0000000000000000060000006c61736572000000000080bf0000803f0000003f00000000000000000000000000002041",
        "030000000000803f0000807f0000204000000000"
    ));
    assert_eq!(s.header.frame_id, "laser");
    assert_eq!(
        (s.angle_min, s.angle_max, s.angle_increment, s.range_max),
        (-1.0, 1.0, 0.5, 10.0)
    );
    assert_eq!(s.ranges[0], 1.0);
    assert!(s.ranges[1].is_infinite());
    assert_eq!(s.ranges[2], 2.5);
}

#[test]
fn marker_with_keyword_field_and_nested_image_from_rclpy() {
    let m: Marker = decode(concat!(
        "00000000000000000100000000105040020000006e00b542000000000400000000000000c01aba3f0000000000000000",
        "00000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000f03f",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "0000000001000000000000000000f03f0000000000000000000000000000000000000000010000000000000000000000",
        "000000000100000000000000010000000000000000000000000000000100000000000000010000000000000001000000",
        "000000000000000000"
    ));
    assert_eq!(m.ns, "n");
    assert_eq!(m.r#type, Marker::LINE_STRIP);
    assert_eq!(m.pose.orientation.w, 1.0);
    assert_eq!(m.points.len(), 1);
    assert_eq!(m.points[0].x, 1.0);
}

#[test]
fn terrain_assessment_with_fixed_arrays_of_messages_from_rclpy() {
    let a: TerrainAssessment = decode(concat!(
        "010000000000000001000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "00000000000000000000000000000000000000000000000000000000000000007b14ae47e17a94bf0000000000000000",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "00000000000000000000000000000000b37bf2b0506b8a3f000000000000000000000000000000000000000000000000",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000009a9999999999b93f",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "0000000000000000000000000000000000000000000000000000000000000000020100000300000001000000"
    ));
    assert_eq!(a.feet[2].z, -0.02);
    assert_eq!(a.sigma, 0.0129);
    assert_eq!(a.planes[1].theta_x, 0.1);
    assert_eq!(a.terrain_class, TerrainAssessment::UNEVEN);
    assert_eq!(a.advised_gait, TerrainAssessment::GAIT_RIPPLE);
    // The counters at the end, after two bytes of padding to their 4-byte alignment.
    assert_eq!((a.rejected_touchdowns, a.failed_assessments), (3, 1));
}

#[test]
fn foot_touchdown_from_rclpy() {
    let t: FootTouchdown = decode(concat!(
        "07000000000000000a000000626173655f6c696e6b00f3b8030000004b4700b8333333333333c3bfb81e85eb51b8be3f",
        "0ad7a3703d0ab7bf"
    ));
    assert_eq!((t.header.stamp.sec, t.header.frame_id.as_str()), (7, "base_link"));
    assert_eq!(t.leg, "KG");
    assert_eq!((t.position.x, t.position.y, t.position.z), (-0.15, 0.12, -0.09));
}

#[test]
fn gait_plan_with_sequence_of_messages_from_rclpy() {
    let g: GaitPlan = decode(concat!(
        "000000000000000001000000000000000200000041000000010000000030222c00000000000000000100000003303732",
        "020000007200303000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "0000000000000000000000000000000000000000000000000000000000000000ff303030303030300000000000000000"
    ));
    assert_eq!(g.rule_set, "A");
    assert_eq!(g.steps.len(), 1);
    assert_eq!(g.steps[0].rule, 3);
    assert_eq!(g.steps[0].rule_name, "r");
    assert_eq!(g.steps[0].moving_leg, -1);
}

#[test]
fn plan_gait_request_and_response_from_rclpy() {
    // Request: start (0, 0, 3π/2), goal (−10, 10, 0), "B", evaluation 3, 100 000 expansions.
    let q: PlanGaitRequest = decode(concat!(
        "00000000000000000000000000000000d221337f7cd9124000000000000024c000000000000024400000000000000000",
        "0200000042000354a0860100"
    ));
    assert_eq!((q.start.x, q.start.y, q.start.theta), (0.0, 0.0, 4.71238898038469));
    assert_eq!((q.goal.x, q.goal.y, q.goal.z), (-10.0, 10.0, 0.0));
    assert_eq!((q.rule_set.as_str(), q.evaluation, q.max_expansions), ("B", 3, 100_000));
    // Response: a refused plan with one step (rule 8 moving leg 0, body x 1, leg 3's foot y −1.5).
    let r: PlanGaitResponse = decode(concat!(
        "0000000000000000010000000000000002000000410001000b0000007072652d656d7074656400000700000009000000",
        "01000000080000000d0000006c656730206e6f6d696e616c0000000000000000000000000000f03f0000000000000000",
        "000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000",
        "00000000000000000000000000000000000000000000000000000000000000000000000000000000000000000000f8bf",
        "000000000000000000000000000000000000000000000440"
    ));
    let p = &r.plan;
    assert_eq!(
        (p.rule_set.as_str(), p.evaluation, p.success, p.reason.as_str()),
        ("A", 1, false, "pre-empted")
    );
    assert_eq!((p.states_expanded, p.states_generated, p.steps.len()), (7, 9, 1));
    let s = &p.steps[0];
    assert_eq!(
        (s.rule, s.rule_name.as_str(), s.moving_leg, s.evaluation),
        (8, "leg0 nominal", 0, 2.5)
    );
    assert_eq!((s.body.x, s.feet[3].y), (1.0, -1.5));
}

#[test]
fn defaults_follow_the_definitions() {
    // geometry_msgs/Quaternion declares `float64 w 1`.
    assert_eq!(mobil_msgs::geometry_msgs::msg::Quaternion::default().w, 1.0);
    assert_eq!(Odometry::default().pose.covariance, [0.0; 36]);
    assert_eq!(<Twist as RosMessage>::PACKAGE, "geometry_msgs");
    assert_eq!(TerrainAssessment::NAME, "TerrainAssessment");
}
