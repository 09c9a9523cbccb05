//! HIGH-LEVEL planning of the mobil suite (SPEC §3–4; dissertation 004 §3.4, §4.2.1–4.2.3),
//! ROS-free: no ROS types, no clock, no I/O (`tests/check_ros_free.sh` proves it). Poses and
//! times are inputs; commands, phases and reports are outputs. `planner_node` wires it to topics.
//!
//! - [`docking`]: the Lyapunov docking law (eq. 3.41–3.48), its gains, V and V̇, chassis limits
//!   by one common factor, and [`DockingController`] (approach → in-place rotation → docked, or
//!   failed on a time limit, on V no longer falling, or with a heading residual on a chassis
//!   that cannot turn in place).
//! - [`sim`]: continuous-time integration of a docking (RK4 sub-steps on the closed loop).
//! - [`mod@approach`]: the goal approach without final heading for a steered chassis (δ within
//!   δ_eff, atan2, progress stop only within steering reach, Z_crit) and the shortest step.
//! - [`follow`]: the same goal approach online, one control tick at a time on the real robot's
//!   pose ([`WaypointFollower`]: waypoints in order, reached within Z_crit, missed by the
//!   progress stop or the leg's distance bound, slow-down at the last one), so the robot drives
//!   the law the pre-check's virtual robot drove.
//! - [`vfo`]: VFO waypoint following in clutter (SPEC §5): the law with collision avoidance,
//!   path quality, Algorithm 2 (virtual robots choose each obstacle's side), the online
//!   [`vfo::VfoFollower`] and obstacles from a laser scan.
//! - [`route`]: the route pre-check — a virtual robot drives the route on the chassis model
//!   against a [`mobil_world::World`] and reports every collision, turn below the minimum
//!   radius and unreachable waypoint with its index.
//! - [`view`]: what the planner draws (route, prediction, problems, dock, a VFO optimisation)
//!   as a ROS-free sketch within one budget of points.
//!
//! Where the SPEC leaves a choice open, the library chooses as follows (each tested in
//! `tests/`):
//! - **e = 0**: the line of sight Ω is undefined at the goal position; it is taken as ϑ_G, so
//!   Θ = 0 and α is the plain heading error.
//! - **Gain ranges**: the printed ranges (0,1), (0,1), (0,6), (0,1) are read in the printed
//!   order γ, λ, k, h — a chosen reading (the source garbles the assignment, and the paper's
//!   gains, all below 1, fit most readings); outside them a [`GainWarning`], never a refusal.
//! - **Common factor**: v_max, ω_max and, from a chassis, its wheel-speed limit (wheel speeds
//!   are homogeneous of degree one in (v, ω)) — all three by one factor s, V̇ = s·V̇_law. A
//!   car-like chassis' curvature limit cannot be met by any factor (ω/v is kept): its
//!   LOW-LEVEL clamps the curvature, the law is then not followed, and the docking ends in
//!   FAILED with its residual.
//! - **Docking ends**: in-place rotation ω = k_rot·wrap(ϑ_G − ϑ) once e < ε_e (handing back to
//!   the law if e exceeds 2ε_e, or if e ≥ ε_e with the heading already within ε_ϑ, where the
//!   rotation would stand still); a failure carries e and the heading error at that step; FAILED on a time limit, on the progress measure (V, or the
//!   heading error while rotating) not falling by 0.1 % within `stall_time_s`, or, on a
//!   chassis that cannot turn in place, on reaching ε_e with the heading outside ε_ϑ.
//! - **Integration**: RK4 on the closed loop in sub-steps of h (the tests use 10 and 5 ms); a
//!   command held over a control period (exact arcs) also keeps V falling at 10–50 ms on the
//!   paper's run (tested).
//! - **Progress stop**: "only within steering reach" is read as armed from the first pose where
//!   the goal is within δ_eff, then the first step with progress ≤ ε ends the approach (a goal
//!   being passed lies near ±90°, outside δ_eff, so the same-step reading never fires).
//! - **Reference point**: the approach steers the model's origin; the route pre-check converts
//!   the start from the reference point (`reference_offset` ahead, as odometry reports it) to
//!   the origin, tests clearance at the reference point, and needs the reference point within
//!   Z_crit. The footprint radius is the chassis' `robot_radius`, a required argument.
//! - **Bad input**: coordinates beyond ±[`error::COORDINATE_LIMIT`], step counts beyond the
//!   crate's caps, non-finite or non-positive lengths are refused with a [`PlannerError`].
//! - **Omni goal approach**: straight translation at the goal, heading held, same steps and
//!   stops as the car.
//! - **Shortest step**: a finite set of δ samples evenly over [−δ_eff, δ_eff] including 0; ties
//!   to the smallest |δ|, then to the left.
//! - **Route pre-check**: the virtual robot is the planner's own goal approach on the chassis
//!   model (δ within δ_eff, steps of path length) at the model's origin, with the collision
//!   geometry (a disc at the reference point) of the simulator's [`World`](mobil_world::World)
//!   (`mobil_world`). `mobil_sim`'s wheel-level plant is not used: it stops at the first contact (so later problems would stay hidden) and the robot
//!   will run this same approach law. Collisions are checked at every step (0.02 m). A
//!   waypoint whose single arc from the leg's start pose is below the minimum radius is a turn
//!   radius problem, reached or not; any other missed one is unreachable (blocked, passed by,
//!   or bound).
//!
//! ```
//! use mobil_chassis::ChassisParams;
//! use mobil_geom::Pose2;
//! use mobil_planner::{
//!     check_route, simulate_docking, DockingConfig, DockingController, DockingGains, DockingPhase, Finish,
//!     Kinematics, RouteCheckConfig, VelocityLimits,
//! };
//! use mobil_world::World;
//! use nalgebra::Point2;
//!
//! // Dock OMR-III from the paper's start onto the origin, facing +x.
//! let omr3 = ChassisParams::omr3();
//! let mut docking = DockingController::new(
//!     DockingGains::paper(),
//!     DockingConfig::default(),
//!     VelocityLimits::from_chassis(&omr3),
//!     Finish::for_chassis(&omr3),
//!     Pose2::identity(),
//! )
//! .unwrap();
//! let start = Pose2::new(-1.0, 1.0, 0.75 * std::f64::consts::PI);
//! let first = docking.update(&start, 0.0).unwrap();
//! assert!(first.command.v < 0.0, "it reverses first");
//! docking.set_goal(Pose2::identity()).unwrap();
//! let run = simulate_docking(&mut docking, Kinematics::Chassis(omr3), start, 0.01, 120.0).unwrap();
//! assert_eq!(run.end, DockingPhase::Docked);
//!
//! // A waypoint 0.3 m beside MOBIL-II is inside its turning circle: reported, with its index.
//! // MOBIL-II's footprint radius is 0.53 m (params/mobil2.yaml).
//! let route = [Point2::new(2.0, 0.0), Point2::new(2.0, 0.3)];
//! let report = check_route(&Pose2::identity(), &route, &ChassisParams::mobil2(), &World::default(), &RouteCheckConfig::new(0.53)).unwrap();
//! assert_eq!(report.problems.len(), 1);
//! assert_eq!((report.problems[0].index, report.problems[0].kind.as_str()), (1, "turn_radius"));
//! ```

#![warn(missing_docs)]

pub mod approach;
pub mod docking;
pub mod docks;
pub mod error;
pub mod follow;
pub mod goals;
pub mod path;
pub mod route;
pub mod sim;
pub mod task;
pub mod vfo;
pub mod view;

pub use approach::{
    approach, approach_step, shortest_step, ApproachConfig, ApproachEnd, ApproachOutcome, ApproachRun, ApproachStep,
    Motion, ShortestStep, Steering, MAX_APPROACH_STEPS, MAX_SHORTEST_STEP_SAMPLES,
};

pub use docking::{
    polar_error, sinc, wrap_alpha, DockingConfig, DockingController, DockingFailure, DockingGains, DockingOutput,
    DockingPhase, Finish, GainWarning, PolarError, Residual, Velocity, VelocityLimits,
};
pub use error::{PlannerError, COORDINATE_LIMIT};
pub use follow::{FollowConfig, FollowEnd, FollowEvent, FollowOutput, WaypointFollower};
pub use route::{
    arc_radius, check_route, check_route_until, ProblemKind, RouteCheckConfig, RouteProblem, RouteReport,
    UnreachableCause,
};
pub use sim::{advance, rk4_step, simulate_docking, DockingRun, DockingSample, Kinematics, MAX_SIMULATION_STEPS};
