//! Action types against CDR bytes worked out by hand from the IDL mapping (little endian,
//! primitives aligned to their size from the start of the body, strings as a u32 length that
//! counts the terminating NUL, sequences as a u32 count). Encoding must give exactly these bytes,
//! and decoding them must give the values back.

use byteorder::LittleEndian;
use mobil_msgs::geometry_msgs::msg::PoseStamped;
use mobil_msgs::mobil_msgs::action::{DriveDistance, DriveDistanceFeedback, DriveDistanceGoal, DriveDistanceResult};
use mobil_msgs::nav2_msgs::action::{
    DockRobot, DockRobotGoal, FollowWaypoints, FollowWaypointsResult, NavigateToPose, UndockRobot, UndockRobotFeedback,
};
use mobil_msgs::nav2_msgs::msg::MissedWaypoint;
use mobil_msgs::RosAction;
use serde::{de::DeserializeOwned, Serialize};
use std::fmt::Debug;

fn hex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

/// `value` encodes to exactly `body_hex`, and those bytes decode to `value`, all of them used.
fn golden<T: Serialize + DeserializeOwned + PartialEq + Debug>(value: &T, body_hex: &str) {
    let bytes = hex(body_hex);
    let ours = cdr_encoding::to_vec::<T, LittleEndian>(value).unwrap();
    assert_eq!(ours, bytes, "encoding of {value:?}");
    let (back, used): (T, usize) = cdr_encoding::from_bytes::<T, LittleEndian>(&bytes).unwrap();
    assert_eq!(used, bytes.len());
    assert_eq!(&back, value);
}

#[test]
fn drive_distance_goal_result_feedback() {
    // -1.5 = 0xBFF8_0000_0000_0000, 0.25 = 0x3FD0_0000_0000_0000 (f64, little endian).
    golden(
        &DriveDistanceGoal {
            distance: -1.5,
            speed: 0.25,
        },
        "000000000000f8bf000000000000d03f",
    );
    // 2.0 = 0x4000_0000_0000_0000; "ok" is length 3 (with its NUL) at offset 8, then 6f 6b 00.
    golden(
        &DriveDistanceResult {
            travelled: 2.0,
            reason: "ok".into(),
        },
        "0000000000000040030000006f6b00",
    );
    // 0.5 = 0x3FE0_…, 1.0 = 0x3FF0_….
    golden(
        &DriveDistanceFeedback {
            travelled: 0.5,
            remaining: 1.0,
        },
        "000000000000e03f000000000000f03f",
    );
}

#[test]
fn send_goal_request_wraps_the_goal_after_its_16_byte_id() {
    // SendGoal_Request: unique_identifier_msgs/UUID (uint8[16], no length) then the goal, whose
    // first f64 is aligned to 8 at offset 16 with no padding.
    let goal_id = ros2_client::action::GoalId {
        uuid: uuid::Uuid::from_bytes([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]),
    };
    let request = ros2_client::action::SendGoalRequest {
        goal_id,
        goal: DriveDistanceGoal {
            distance: 1.0,
            speed: 0.5,
        },
    };
    let bytes = cdr_encoding::to_vec::<_, LittleEndian>(&request).unwrap();
    assert_eq!(
        bytes,
        hex("000102030405060708090a0b0c0d0e0f000000000000f03f000000000000e03f")
    );
}

#[test]
fn follow_waypoints_result_with_a_missed_waypoint() {
    let mut goal = PoseStamped::default();
    goal.header.stamp.sec = 1;
    goal.header.stamp.nanosec = 2;
    goal.header.frame_id = "map".into();
    goal.pose.position.x = 1.0;
    goal.pose.orientation.w = 1.0;
    let result = FollowWaypointsResult {
        missed_waypoints: vec![MissedWaypoint {
            index: 2,
            goal,
            error_code: FollowWaypointsResult::TASK_EXECUTOR_FAILED,
        }],
        error_code: FollowWaypointsResult::UNKNOWN,
        error_msg: "fail".into(),
    };
    golden(
        &result,
        concat!(
            "01000000",         // one missed waypoint (offset 0)
            "02000000",         // index 2 (4)
            "01000000",         // stamp.sec 1 (8)
            "02000000",         // stamp.nanosec 2 (12)
            "04000000",         // frame_id length 4 (16)
            "6d617000",         // "map\0" (20)
            "000000000000f03f", // position.x 1.0 (24, aligned)
            "0000000000000000",
            "0000000000000000", // y, z
            "0000000000000000",
            "0000000000000000",
            "0000000000000000", // orientation x, y, z
            "000000000000f03f", // w 1.0 (72)
            "5902",             // missed error_code 601 = 0x0259 (80)
            "5802",             // result error_code 600 = 0x0258 (82)
            "05000000",         // error_msg length 5 (84)
            "6661696c00",       // "fail\0" (88); 93 bytes in all
        ),
    );
}

#[test]
fn nav2_defaults_constants_and_type_names_follow_the_jazzy_definitions() {
    let dock = DockRobotGoal::default();
    assert!(dock.use_dock_id && dock.navigate_to_staging_pose);
    assert_eq!(dock.max_staging_time, 1000.0);
    assert_eq!(mobil_msgs::nav2_msgs::action::DockRobotResult::FAILED_TO_CHARGE, 906);
    assert!(mobil_msgs::nav2_msgs::action::DockRobotResult::default().success);
    assert_eq!(
        mobil_msgs::nav2_msgs::action::UndockRobotGoal::default().max_undocking_time,
        30.0
    );
    // UndockRobot's feedback is empty: one dummy octet on the wire.
    golden(&UndockRobotFeedback::default(), "00");
    let name = |t: ros2_client::ActionTypeName| format!("{}/action/{}", t.package_name(), t.type_name());
    assert_eq!(name(NavigateToPose::type_name()), "nav2_msgs/action/NavigateToPose");
    assert_eq!(name(DockRobot::type_name()), "nav2_msgs/action/DockRobot");
    assert_eq!(name(UndockRobot::type_name()), "nav2_msgs/action/UndockRobot");
    assert_eq!(name(FollowWaypoints::type_name()), "nav2_msgs/action/FollowWaypoints");
    assert_eq!(name(DriveDistance::type_name()), "mobil_msgs/action/DriveDistance");
}
