//! The integration tests of `mobil_chassis` in one test binary: each file of `tests/` is a module
//! (a binary per file spent more time linking than compiling the tests).

mod feedback;
mod kinematics;
mod limits;
mod model;
mod odometry;
mod watchdog;
