//! The `ga_step` executable's parts: [`run`] (command line, run loop, progress, resume),
//! [`params`] (the parameter file), [`outputs`] (the files a run writes, atomically) and
//! [`ros_eval`] (the external evaluator over ROS 2). The genetic algorithm is `mobil_ga_step`, the built-in physics evaluator
//! `mobil_ga_step_sim`; both are ROS-free.
#![warn(missing_docs)]

pub mod outputs;
pub mod params;
pub mod ros_eval;
pub mod run;
