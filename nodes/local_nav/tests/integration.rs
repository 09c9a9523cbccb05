//! The integration tests of `mobil_local_nav` in one test binary: each file of `tests/` is a module
//! (a binary per file spent more time linking than compiling the tests).

mod closed_loop;
mod command_limits;
mod harness;
mod modes;
