//! The simulated robot of the mobil suite, ROS-free: time and randomness are inputs (a step
//! length and a seed), so every run is reproducible. `sim_node` wires it to topics.
//!
//! - [`world`]: 2D obstacles (circles, polygons) from YAML, or the built-in world;
//! - [`lidar`]: a planar LIDAR simulated by ray casting (LaserScan conventions);
//! - [`plant`]: the chassis as a plant: wheel commands → motor lag → forward kinematics → exact
//!   pose integration, and encoder feedback with noise and slip;
//! - [`plot`]: SVG plots of runs over the world.

pub mod lidar;
pub mod plant;
pub mod plot;
pub mod world;
