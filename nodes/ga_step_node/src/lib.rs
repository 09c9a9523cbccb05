//! The `ga_step` executable's parts: [`run`] (command line, run loop, progress, resume),
//! [`params`] (the parameter file's keys documented), [`outputs`] (the files a run writes,
//! atomically) and [`ros_eval`] (the external evaluator over ROS 2). The genetic algorithm is
//! `mobil_ga_step`, with what these parts decide without ROS (reading the parameter file,
//! whether a checkpoint is resumed, the last line, the outputs' names, a simulator's answer);
//! the built-in physics evaluator is `mobil_ga_step_sim`; both are ROS-free.
#![warn(missing_docs)]

pub mod outputs;
pub mod params;
pub mod ros_eval;
pub mod run;
