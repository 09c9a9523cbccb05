//! Tools around the mobil nodes. [`route`] holds the scripted routes the demo drives and the
//! bookkeeping that turns two pose streams (odometry, ground truth) into the demo's summary.

pub mod route;
