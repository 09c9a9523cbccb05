//! The integration tests of `mobil_ga_step_sim` in one test binary: each file of `tests/` is a module
//! (a binary per file spent more time linking than compiling the tests).

mod dc_motor;
mod webots;
