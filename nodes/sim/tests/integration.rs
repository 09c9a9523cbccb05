//! The integration tests of `mobil_sim` in one test binary: each file of `tests/` is a module
//! (a binary per file spent more time linking than compiling the tests).

mod odometry_vs_truth;
mod world_fuzz;
