//! Planar geometry shared by the mobil suite, ROS-free (nalgebra only): angle wrapping, 2D poses
//! and frame composition, the checked laser scan every navigation node reads, and the sketch
//! (shapes in the plane) a node draws.
//!
//! Frames follow REP-103 (x forward, y left, yaw counter-clockwise about z) and are named rerun
//! style: `odom_from_base` is the pose of `base` in `odom`, and maps points from `base` to `odom`.
//!
//! ```
//! use mobil_geom::{wrap, Pose2};
//! use nalgebra::Point2;
//!
//! // The robot 1 m along x, facing +y; its laser 0.3 m ahead of base_link.
//! let odom_from_base = Pose2::new(1.0, 0.0, std::f64::consts::FRAC_PI_2);
//! let base_from_laser = Pose2::new(0.3, 0.0, 0.0);
//! let odom_from_laser = odom_from_base * base_from_laser;
//! assert!((odom_from_laser.x - 1.0).abs() < 1e-12 && (odom_from_laser.y - 0.3).abs() < 1e-12);
//! // A point 2 m in front of the laser is at (1, 2.3) in odom.
//! let p = odom_from_laser.transform_point(Point2::new(2.0, 0.0));
//! assert!((p - Point2::new(1.0, 2.3)).norm() < 1e-12);
//! assert_eq!(wrap(3.0 * std::f64::consts::PI), std::f64::consts::PI);
//! ```

#![warn(missing_docs)]

pub mod angle;
pub mod path;
pub mod pose;
pub mod sample;
pub mod scan;
pub mod segment;
pub mod sketch;

pub use angle::wrap;
pub use pose::Pose2;
pub use sample::downsample;
pub use scan::{Beam, Scan, ScanError};
