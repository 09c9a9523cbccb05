//! The simulated robot of the mobil suite, ROS-free: time and randomness are inputs (a step
//! length and a seed), so every run is reproducible. `sim_node` wires it to topics.
//!
//! - [`lidar`]: a planar LIDAR simulated by ray casting (LaserScan conventions);
//! - [`plant`]: the chassis as a plant, the simulation's ground truth: wheel commands held to the
//!   chassis' limits → motor lag → the body twist that best fits every wheel's rolling and
//!   no-sideslip constraints (least squares; the residual is the slip) → RK4 pose integration,
//!   and encoder feedback with noise and slip.
//!
//! The world it moves in (circles and polygons from YAML, or the built-in world) is
//! [`mobil_world`].

pub mod health;
pub mod lidar;
pub mod plant;
