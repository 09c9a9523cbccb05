//! The integration tests of `mobil_ga_step` in one test binary: each file of `tests/` is a module
//! (a binary per file spent more time linking than compiling the tests).

mod checkpoint;
mod ga_run;
mod operators;
mod output;
mod params_file;
mod run_end;
mod selection;
mod trajectory;
