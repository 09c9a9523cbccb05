//! Shared by the DDS integration tests of this crate: each test process talks on a domain of its
//! own, and each participant is a `Context` with one node. Each test binary uses what it needs.
#![allow(dead_code)]

use ros2_client::{Context, ContextOptions, Node, NodeName, NodeOptions};

/// `MOBIL_TEST_DOMAIN_ID`, else 100 + pid % 100: 100..=199 like the rclpy tests, per process (the
/// tests' topic names carry the pid as well), so parallel runs do not meet.
pub fn domain_id() -> u16 {
    std::env::var("MOBIL_TEST_DOMAIN_ID")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100 + (std::process::id() % 100) as u16)
}

/// A participant of its own (one `Context`) on [`domain_id`] with one node called `name`
/// (no rosout). The context must live as long as the node.
pub fn participant(name: &str) -> (Context, Node) {
    let context = Context::with_options(ContextOptions::new().domain_id(domain_id())).expect("DDS context");
    let node = context
        .new_node(
            NodeName::new("/", name).expect("node name"),
            NodeOptions::new().enable_rosout(false),
        )
        .expect("node");
    (context, node)
}
