//! The DDS integration tests of `mobil_ros` in one test binary: each file of `tests/` is a
//! module (a binary per file spent more time linking the DDS stack than compiling the tests).
//! Each test talks on topics and services named for its file and this process, so the files'
//! tests run side by side. `kit_time` is a binary of its own: it sets `ROS_DOMAIN_ID` in its
//! process's environment.

mod action_server;
mod common;
mod large_replies;
mod latched;
mod tf_static;
