//! What the demo's executables share. Their records, summaries and figures are ROS-free, in
//! `mobil_tools` (tested there on recorded data); the binaries in `src/bin` are the shells.
#![warn(missing_docs)]
