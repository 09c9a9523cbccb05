//! The integration tests of `mobil_terrain` in one test binary: each file of `tests/` is a module
//! (a binary per file spent more time linking than compiling the tests).

mod assessment;
mod params_file;
mod properties;
mod table1;
mod walker;
