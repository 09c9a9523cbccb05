//! The integration tests of `mobil_gait` in one test binary: each file of `tests/` is a module
//! (a binary per file spent more time linking than compiling the tests).

mod horizon;
mod paper_table_docs;
mod params_file;
mod rules;
mod search;
mod walker;
