//! What the demo's executables share, drawn with `mobil_tools::plot`'s SVG figures: [`plan`],
//! the third act's route, record, summary and
//! figure, [`gait`], the fifth act's planned walk, summary and figure, and [`vfo`], the sixth
//! act's record, summary and figure. ROS-free, so it is tested on recorded data; the binaries
//! in `src/bin` are the shells.
#![warn(missing_docs)]

pub mod gait;
pub mod plan;
pub mod vfo;
