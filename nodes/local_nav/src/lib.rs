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
//!   free distance ahead (along the arc driven, for a car-like chassis) and near the goal, hard
//!   stop.
//! - [`config`]: [`NavConfig`], every default justified.
//!
//! A path (Nav2's `FollowPath`) becomes sub-goals for the navigator by
//! [`mobil_geom::path::PathGoals`], and Nav2's progress checker is
//! [`mobil_motion::progress`]: both are shared with the planner.
//!
//! Where the SPEC leaves a choice open, or where a Decision needed a guard to work in closed
//! loop, the library chooses as follows (each tested in `tests/modes.rs` or
//! `tests/closed_loop.rs`):
//! - **R-mode weights**: no side has been chosen yet, so R-mode uses the symmetric mean of the
//!   two sets; with every known sector clear it heads straight for G (SPEC all-clear rule).
//!   Unknown sectors (outside the field of view) do not veto the all-clear rule, but sector 0
//!   must be known.
//! - **Sliding instead of settling**: |f_i| is never negative, so F keeps pointing into a wall
//!   it faces. Inside d_sa the component of the motion toward the nearest reading is scaled
//!   down with the clearance (to zero at the stop distance), the component along the boundary
//!   kept, and the speed scaled with it.
//! - **Stall makes H**: an L-mode command slower than `stall_speed` cannot make progress
//!   (steps are path increments, so eq. 3.58 alone would never fire): H is set there at once.
//!   So does a car-like L-mode command that turns at the steering limit away from F because
//!   every arc toward F is blocked before d_sa ([`motion::CarArc::against`]): the lock cannot
//!   be followed there, and without H the car, turned away, would release the lock, come back
//!   in R-mode and circle in a U-trap for ever.
//! - **Leave on a clear goal sector only nearer G than H** (and beyond d_sa + hysteresis):
//!   without it the mouth of a U-trap, where the goal sector sees the far bottom wall beyond
//!   d_sa, would send the robot back in for ever. The crossing of HG must be strictly between
//!   H and G (∠HLG = 180°, eq. 3.59).
//! - **NO_PATH on return to H** only after the robot has been twice `hit_radius` away.
//! - **Omni and the field of view**: an omni chassis holds its heading, but turns in place
//!   toward a direction of motion outside the field of view rather than drive there blind. In
//!   T-mode it turns to face its direction of motion: the boundary it follows is then abeam, in
//!   the field of view, where holding the heading would carry it into the rear blind spot (the
//!   far side of an enclosure) and lose it.
//! - **Car-like**: pure-pursuit curvature toward a point d_sa along the direction, clipped to
//!   tan δ_eff / L. The speed and the hard stop look along the arc the car will drive (a
//!   circle swept along the arc against the scan points, [`motion::arc_free_distance`]; its
//!   radius is the robot's plus half the margin to the stop distance, a margin to the side), not
//!   straight ahead: a car turning away from a wall it meets inside d_sa has the wall close
//!   ahead while its arc curves clear, and judged by the straight line it crawled away at
//!   1–2 cm/s for up to a minute, long enough for Nav2's progress checker to abort. When the
//!   pursuit arc is blocked before d_sa and the arc at the steering limit is freer, the car
//!   turns at the limit; the turn's own slow-downs (angle to F, sliding) never take it below
//!   `min_turn_speed` (0.1 m/s) on a clear arc. The method has no reversing, so a car-like
//!   robot with no arc free beyond the hard stop (a wall square ahead nearer than the robot
//!   radius plus the turning radius) stays stopped, and the progress checker or NO_PATH ends
//!   the goal (d_sa must leave room for the turning circle).
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

pub use config::{ConfigError, NavConfig, TrackMethod};
pub use field::{vector_distance, Side, WeightProfile};
pub use mobil_motion::progress::{Progress, ProgressChecker, ProgressSettings};
pub use motion::{
    arc_free_distance, car_arc, command_along, CarArc, Drive, MotionInput, MotionLimits, SpeedProfile, VelocityCommand,
};
pub use navigator::{InputError, Mode, Navigator, NoPathReason, StepOutput};
pub use sectors::{Sector, Sectors, UnseenSectors};
