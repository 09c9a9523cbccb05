//! VFO waypoint following in clutter, optimised by simulating virtual robots (SPEC §5; the VFO
//! paper, source 002), ROS-free: poses and times are inputs, commands and reports outputs.
//!
//! - [`obstacles`]: λ = {p, r, R} and σ, the potential V(d) (eq. 16) and V'(d).
//! - [`controller`]: the VFO law (eq. 5–13) with avoidance, Algorithm 1 and Algorithm 3,
//!   one step at a time ([`VfoController`]), and the unicycle's exact arc.
//! - [`quality`]: χ_D, χ_B, χ_E, χ_S (eq. 14–19), merge, normalisation (20–21), Ψ_z (22).
//! - [`optimise`]: Algorithm 2 (findSigmas) with cycle detection, caps and helper threads.
//! - [`follower`]: [`VfoFollower`], the online follower: one control tick at a time, Σ per
//!   segment, re-optimised on new obstacles; the last optimisation for display.
//! - [`scan`]: obstacles from a laser scan (clusters → circles) merged over time in odom,
//!   forgotten when seen through, when not seen for a while, and beyond a cap.
//! - [`goal`]: [`VfoGoal`], the follower as a goal law (`mobil_motion::GoalLaw`), with the
//!   reasons and codes of its ends and what the status and markers show of an optimisation.
//! - [`settings`]: [`VfoSettings`], everything a node configures VFO waypoint following with.
//! - [`history`]: a short history of odometry poses, to place each scan with the pose at its
//!   stamp.
//!
//! ```
//! use mobil_geom::Pose2;
//! use mobil_planner::vfo::{find_sigmas, Obstacle, OptimiseConfig, Segment, Sigma, VfoController, VfoGains, VfoWaypoint};
//! use nalgebra::Point2;
//!
//! // One obstacle straight ahead on the way to (4, 0): two ways round it, both safe.
//! let obstacles = [Obstacle::new(Point2::new(2.0, 0.0), 0.5, 1.0).unwrap()];
//! let segment = Segment { waypoint: VfoWaypoint::new(4.0, 0.0, 0.0, 0.5).unwrap(), last: true, obstacles: &obstacles };
//! let controller = VfoController::new(VfoGains::default()).unwrap();
//! let result = find_sigmas(&Pose2::identity(), &controller, &segment, &OptimiseConfig::default()).unwrap();
//! assert_eq!(result.candidates(), 2);
//! assert_ne!(result.sigmas[0], Sigma::Undecided);
//! ```

pub mod controller;
pub mod follower;
pub mod goal;
pub mod history;
pub mod obstacles;
pub mod optimise;
pub mod quality;
pub mod scan;
pub mod settings;
mod speculate;

pub use controller::{
    convergence_field, field_rate, integrate_unicycle, ControlStep, Field, StepOutcome, VfoController, VfoGains,
    VfoWaypoint, DEFAULT_GUIDING,
};
pub use follower::{
    Reoptimised, VfoEnd, VfoEvent, VfoFollower, VfoOutput, MAX_BUDGET_RETRIES, MAX_SETTLE_S, REST_INTERVALS,
    REST_SPEED, REST_TURN_RATE,
};
pub use goal::{
    vfo_gains, vfo_waypoints, DrawnRobot, SegmentReport, VfoDrawing, VfoGoal, VfoSetup, VfoStep, VfoTick, VfoView,
    MAX_DRAWN_OBSTACLES, MAX_DRAWN_POINTS, MAX_DRAWN_ROBOTS,
};
pub use history::{Placement, PoseHistory};
pub use obstacles::{potential, potential_derivative, Obstacle, Sigma};
pub use optimise::{
    find_sigmas, find_sigmas_until, path_time_limit, simulate_uninterrupted, DecisionEdge, ExploredPath, Interrupt,
    Optimisation, OptimiseConfig, OptimiseWarning, PathFate, RobotEnd, Segment, VirtualRobot, INTERRUPT_CHECK_STEPS,
};
pub use quality::{normalise, normalised, path_score, PathIndices, QualityWeights};
pub use scan::{
    extract_circles, fit_circle, frame_moved, Circle, KeptMap, MapChange, MapUpdate, ObstacleMap, ScanObstacleConfig,
    ScanSkipped,
};
pub use settings::{
    VfoSettings, WaypointMethod, DEFAULT_OPTIMISE_BUDGET_S, DEFAULT_SCAN_ODOM_MAX_GAP_S, MAX_OPTIMISE_BUDGET_S,
};
