//! Local navigation by the vector-distance function (SPEC §2; dissertation 004 §3.5, §4.2.4),
//! ROS-free: no ROS types, no clock, no I/O (`tests/check_ros_free.sh` proves it). The pose
//! (in odom), the goal (in odom) and a checked [`mobil_geom::Scan`] are the inputs; a body-frame
//! velocity command and the mode are the output. `local_nav_node` wires it to topics.
//!
//! - [`sectors`]: scan → N sectors, sector 0 toward the goal, indices clockwise (eq. 3.51).
//! - [`field`]: F = Σ f_i·w_i (eq. 3.50–3.57), the left- and right-turning weight sets checked
//!   against eq. 3.53–3.55.
//! - [`navigator`]: the modes R (rotate), L (lock) and T (track), hit and leave points, NO_PATH.
//! - [`motion`]: motion along F for an omni or a car-like chassis (δ_eff), speed scaled by the
//!   free distance ahead and near the goal, hard stop.
//! - [`config`]: [`NavConfig`], every default justified.
//!
//! ```
//! use mobil_chassis::ChassisParams;
//! use mobil_geom::{Pose2, Scan};
//! use mobil_local_nav::{Mode, MotionLimits, NavConfig, Navigator};
//! use nalgebra::Point2;
//!
//! let limits = MotionLimits::from_chassis(&ChassisParams::omr3());
//! let mut nav = Navigator::new(NavConfig::default(), limits).unwrap();
//! nav.set_goal(Point2::new(3.0, 0.0)).unwrap();
//! // A 270° scan with nothing in range: free space, straight for the goal at full speed.
//! let fov = 0.75 * std::f64::consts::PI;
//! let step = fov / 540.0;
//! let scan = Scan::new(-fov, fov, step, 0.05, 10.0, vec![f32::INFINITY; 1081], vec![], Pose2::identity()).unwrap();
//! let out = nav.step(Pose2::identity(), &scan);
//! assert_eq!(out.mode, Mode::Rotate);
//! assert!((out.command.vx - 0.5).abs() < 1e-9 && out.command.vy.abs() < 1e-9);
//! ```

#![warn(missing_docs)]

pub mod config;
pub mod field;
pub mod motion;
pub mod navigator;
pub mod sectors;

pub use config::{ConfigError, NavConfig};
pub use field::{vector_distance, Side, WeightProfile};
pub use motion::{command_along, Drive, MotionInput, MotionLimits, SpeedProfile, VelocityCommand};
pub use navigator::{InputError, Mode, Navigator, NoPathReason, StepOutput};
pub use sectors::{Sector, Sectors, UnseenSectors};
