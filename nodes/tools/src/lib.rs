//! Tools around the mobil nodes. [`drive`] is the ROS-free logic of `drive_node` (drive a
//! distance, the `DriveDistance` action). [`route`] holds the scripted routes the demo drives and the
//! bookkeeping that turns two pose streams (odometry, ground truth) into the demo's summary.
//! [`plot`] draws the demo's and `ga_step`'s SVG figures (maps of a [`mobil_world::World`] and
//! time series) as plain SVG text.

pub mod drive;
pub mod plot;
pub mod route;
