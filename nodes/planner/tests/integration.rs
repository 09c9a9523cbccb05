//! The integration tests of `mobil_planner` in one test binary: each file of `tests/` is a module
//! (a binary per file spent more time linking than compiling the tests).

mod approach;
mod docking;
mod follow;
mod goals;
mod graceful_peer;
mod route;
mod task;
mod vfo;
mod vfo_goal;
mod vfo_scan;
