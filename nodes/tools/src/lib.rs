//! Tools around the mobil nodes. [`drive`] is the ROS-free logic of `drive_node` (drive a
//! distance, the `DriveDistance` action). [`route`] holds the scripted routes the demo drives and the
//! bookkeeping that turns two pose streams (odometry, ground truth) into the demo's summary.

pub mod drive;
pub mod route;
