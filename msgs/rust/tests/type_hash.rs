//! REP-2011 type hashes computed from the definitions, against hashes rosidl generated for ROS 2
//! Jazzy (copied from the `type_hashes` of the Jazzy packages' type-description JSON files).

#[test]
fn jazzy_hashes_of_common_types() {
    // share/geometry_msgs/msg/Twist.json of ros-jazzy-geometry-msgs.
    assert_eq!(
        mobil_msgs::type_hash("geometry_msgs/msg/Twist"),
        Some("RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a")
    );
    assert_eq!(
        mobil_msgs::type_hash("geometry_msgs/msg/Vector3"),
        Some("RIHS01_cc12fe83e4c02719f1ce8070bfd14aecd40f75a96696a67a2a1f37f7dbb0765d")
    );
    assert_eq!(mobil_msgs::type_hash("no_msgs/msg/Nothing"), None);
    // Sorted, so that the lookup's binary search finds every one.
    assert!(mobil_msgs::TYPE_HASHES.windows(2).all(|w| w[0].0 < w[1].0));
}
