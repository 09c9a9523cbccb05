//! The node kit of the mobil suite: everything a node shell needs around its ROS-free
//! algorithm crate, so that every node is written the same way.
//!
//! A node is a thin shell (see `nodes/chassis_node` for the pattern):
//! - [`config`]: the configuration declared once (the groups nodes share: the chassis,
//!   [`chassis`]; the frames and goal timeouts of every motion node, [`groups`]) — each
//!   parameter's name, type, default, range, description and read-only flag, bound to the
//!   typed field it fills, a row per parameter with [`params!`]; from it come the ROS
//!   declarations, `--help`, validation of files, `-p` and `set_parameters` (refused with a
//!   reason), and the typed configuration ([`NodeDecl::for_config`], [`RosNode::config`],
//!   [`RosNode::config_changed`]);
//! - [`node`]: the node itself — command line, DDS domain from `ROS_DOMAIN_ID`, the standard
//!   parameter services, name resolution and remapping, clean shutdown on SIGINT/SIGTERM
//!   ([`run_node`]);
//! - [`input`]: typed subscription streams that log (rate-limited) and drop undecodable samples;
//! - [`latest`]: [`Latest`], an input's last value with its stamp and steady receive time — the
//!   one way to decide that an input is stale (`get(max_age)`; a safety gate with its own
//!   timeouts takes `age()` instead);
//! - [`ticker`]: [`Ticker`], a periodic tick following a rate parameter;
//! - [`time`]: **the time rule** — stamps and algorithm `dt` from ROS time ([`time::DtClock`]),
//!   watchdogs, freshness and tick periods on the steady clock;
//! - [`offloop`]: [`OffLoop`], searches of 10–500 ms off the event loop, pre-empted by newer
//!   requests; [`ServiceThreads`], a service answered on threads of its own;
//! - [`lifecycle`]: the managed-node interface (`lifecycle_msgs` services, transition events,
//!   `autostart`) and Nav2's bond, around [`mobil_lifecycle`];
//! - [`action`]: [`action::GoalServer`], an action server with one active goal for a node's
//!   select loop (accept/reject, feedback, result, cancel, pre-emption);
//! - [`motion`]: [`motion::MotionSession`], the motion server every node that moves the robot
//!   runs its goals through (one goal, pre-emption, the time step, refused input, the one zero
//!   command at every end, stale input, shutdown), around a [`mobil_motion::GoalLaw`];
//! - [`goal`]: goal poses and routes from messages, checked in the node's frame (the reasons of
//!   an `INVALID_GOAL`);
//! - [`markers`]: RViz markers, built one call per marker; [`status`]: a navigating node's
//!   `NavStatus`, and the rate gate of its status and markers;
//! - [`cmd_vel`]: `cmd_vel` as Twist or TwistStamped (`enable_stamped_cmd_vel`), and a peer of
//!   the other type told;
//! - [`stop`]: [`stop::final_stop`], the bounded last zero command of a motion node;
//! - [`scan`]: LaserScan → checked [`mobil_geom::Scan`] at the edge, laser pose from `tf_static`
//!   ([`scan::tf_static_subscription`] feeding [`scan::LaserPose`]; `tf_static` wins) or a
//!   parameter;
//! - [`qos`]: the QoS presets of the interface contract; [`log`]: `tracing` set-up and
//!   rate-limited warnings ([`warn_throttled!`]); [`geometry`]: planar poses in messages;
//!   [`args`], [`mod@params`], [`names`]: the ROS command line, parameter files, names;
//!   [`docs`]: the parameter tables of `docs/`, which `--params-markdown` prints.

pub mod action;
pub mod args;
pub mod chassis;
pub mod cmd_vel;
pub mod config;
pub mod diagnostics;
pub mod discovery;
pub mod docs;
pub mod geometry;
pub mod goal;
pub mod groups;
pub mod input;
pub mod latest;
pub mod lifecycle;
pub mod log;
pub mod markers;
pub mod motion;
pub mod names;
pub mod node;
pub mod offloop;
pub mod params;
pub mod plan;
pub mod qos;
pub mod scan;
pub mod status;
pub mod stop;
pub mod tf;
pub mod ticker;
pub mod time;

pub use args::RosArgs;
pub use config::{Config, ConfigError, Decl};
pub use latest::{Freshness, Latest};
pub use log::LogThrottle;
pub use mobil_motion::Notice;
pub use node::{listen_for_shutdown, respond, run_node, shutdown_signal, NodeBody, NodeDecl, RosNode};
pub use offloop::{CancelToken, OffLoop, ServiceThreads};
pub use params::{ParamSpec, ParamValues};
pub use ticker::Ticker;
