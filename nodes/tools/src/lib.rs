//! Tools around the mobil nodes. [`drive`] is the ROS-free logic of `drive_node` (drive a
//! distance, the `DriveDistance` action). [`route`] holds the scripted routes the demo drives and the
//! bookkeeping that turns two pose streams (odometry, ground truth) into the demo's summary.
//! [`plot`] draws the demo's and `ga_step`'s SVG figures (maps of a [`mobil_world::World`] and
//! time series) as plain SVG text.
//!
//! The demo's acts, each its record, one-line summary and figure, worked on recorded data (the
//! executables of `mobil_tools_node` are the shells that fill them): [`route`], the first act's
//! drift and figure; [`nav`], the second act's path and mode changes; [`plan`], the third act's
//! route, dock and docking record; [`terrain`], the fourth act's terrain assessments; [`gait`],
//! the fifth act's planned walk; [`vfo`], the sixth act's VFO waypoint following. [`status`]:
//! a navigation node's status as the acts read it.

pub mod behavior;
pub mod drive;
pub mod gait;
pub mod nav;
pub mod plan;
pub mod plot;
pub mod route;
pub mod status;
pub mod terrain;
pub mod vfo;
