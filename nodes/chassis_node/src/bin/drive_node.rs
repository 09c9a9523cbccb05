//! `drive_node`: serves the `mobil_msgs/action/DriveDistance` action `drive_distance` — drive
//! straight ahead or back by a distance, following `odom` and commanding `cmd_vel`, like Nav2's
//! DriveOnHeading / BackUp behaviours. The logic is `mobil_tools::drive`; this is its shell.
//!
//! Its goals run through the kit's motion server ([`MotionSession`]): `cmd_vel` only while a
//! goal runs, one zero `cmd_vel` when it ends — reached, canceled, odometry stale for
//! `odom_timeout_s` (steady clock; ABORTED) — and none between a goal and the newer goal that
//! pre-empts it (the old one ends ABORTED; the new one commands at once). A node leaving
//! (shutdown or a failure) with a goal under way sends a last zero `cmd_vel`, waited for until
//! the readers acknowledge it (at most `mobil_ros::stop::FINAL_STOP_WAIT`); an idle one sends
//! none. A goal that cannot be started (a DDS send to that client failed) is logged and the
//! node goes on serving.

use mobil_motion::{BodyTwist, GoalLaw, StepInput};
use mobil_msgs::geometry_msgs::msg::Twist;
use mobil_msgs::mobil_msgs::action::{DriveDistance, DriveDistanceFeedback, DriveDistanceResult};
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_ros::action::{ActionEvent, GoalEnd, GoalServer, GoalServerConfig};
use mobil_ros::config::{Config, ConfigError, Decl};
use mobil_ros::geometry::planar_pose;
use mobil_ros::groups::GoalTimeouts;
use mobil_ros::input::Inputs;
use mobil_ros::latest::Latest;
use mobil_ros::lifecycle::{CallbackReturn, Lifecycle, Managed};
use mobil_ros::motion::{Applied, ClockCheck, CmdVel, EndCause, EndKind, Ended, MotionSession, SessionSettings};
use mobil_ros::stop::{final_stop, FINAL_STOP_WAIT};
use mobil_ros::ticker::Ticker;
use mobil_ros::{qos, run_node, shutdown_signal, warn_throttled, LogThrottle, NodeDecl, RosNode};
use mobil_tools::drive::{DistanceDrive, DriveSettings, Pose2};
use ros2_client::{Publisher, Subscription};
use std::process::ExitCode;
use std::time::{Duration, Instant};
use tracing::{info, warn};

/// The node's configuration: each parameter declared once, bound to its field.
#[derive(Debug, Clone, Default, PartialEq)]
struct DriveConfig {
    max_speed: f64,
    min_speed: f64,
    decel: f64,
    tolerance: f64,
    rate_hz: f64,
    timeouts: GoalTimeouts,
    managed: Managed,
}

impl Config for DriveConfig {
    fn declare(d: &mut Decl<Self>) {
        d.double("max_speed", 0.5, "highest speed a goal may ask for [m/s]", |c, v| {
            c.max_speed = v
        })
        .above(0.0);
        d.double("min_speed", 0.03, "slowest speed before arrival [m/s]", |c, v| {
            c.min_speed = v
        })
        .above(0.0);
        d.double(
            "decel",
            0.5,
            "deceleration of the ramp-down before arrival [m/s²]",
            |c, v| c.decel = v,
        )
        .above(0.0);
        d.double(
            "tolerance",
            0.005,
            "arrived when this close to the distance [m]",
            |c, v| c.tolerance = v,
        )
        .above(0.0);
        d.double(
            "rate_hz",
            20.0,
            "cmd_vel and feedback rate while driving [Hz]",
            |c, v| c.rate_hz = v,
        )
        .within(1.0, 200.0);
        d.nest(|c: &mut DriveConfig| &mut c.timeouts, GoalTimeouts::declare);
        d.nest(|c: &mut DriveConfig| &mut c.managed, Managed::declare);
    }

    fn validate(&self) -> Result<(), ConfigError> {
        if self.min_speed > self.max_speed {
            return Err(ConfigError::inconsistent(format!(
                "min_speed {} is above max_speed {}",
                self.min_speed, self.max_speed
            )));
        }
        Ok(())
    }
}

impl DriveConfig {
    fn settings(&self) -> DriveSettings {
        DriveSettings {
            max_speed: self.max_speed,
            min_speed: self.min_speed,
            decel: self.decel,
            tolerance: self.tolerance,
        }
    }
}

fn decl() -> NodeDecl {
    NodeDecl::for_config::<DriveConfig>(
        "drive",
        "Serves the DriveDistance action: drives straight by a distance, following odom, commanding cmd_vel",
    )
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(serve(node)))
}

fn result(travelled: f64, reason: &str) -> DriveDistanceResult {
    DriveDistanceResult {
        travelled,
        reason: reason.to_owned(),
    }
}

/// The one goal source: the action.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct DriveAction;

impl From<DriveAction> for &'static str {
    fn from(_: DriveAction) -> &'static str {
        "drive_distance"
    }
}

type Session = MotionSession<DistanceDrive, DriveAction>;

/// The action's answer for an ended goal: its status and result (the reason as the action has
/// always given it).
fn answer(ended: &Ended<DistanceDrive, DriveAction>) -> (GoalEnd, DriveDistanceResult) {
    let reason = match &ended.cause {
        EndCause::Outcome(o) if o.is_success() => "reached".to_owned(),
        EndCause::Canceled => "canceled".to_owned(),
        EndCause::Preempted(_) => "preempted by a newer goal".to_owned(),
        EndCause::Stale(_) => "odometry stale".to_owned(),
        EndCause::Shutdown => "shutting down".to_owned(),
        other => other.reason(),
    };
    let status = match ended.cause.kind() {
        EndKind::Succeeded => GoalEnd::Succeeded,
        EndKind::Canceled => GoalEnd::Canceled,
        EndKind::Aborted => GoalEnd::Aborted,
    };
    (status, result(ended.goal.progress().travelled, &reason))
}

fn finish(server: &mut GoalServer<DriveDistance>, ended: Option<Ended<DistanceDrive, DriveAction>>) {
    if let Some(ended) = ended {
        let (status, result) = answer(&ended);
        match status {
            GoalEnd::Succeeded | GoalEnd::Canceled => info!("goal ends: {}", result.reason),
            GoalEnd::Aborted => warn!("goal ends: {}", result.reason),
        }
        server.finish(status, result);
    }
}

fn twist(b: BodyTwist) -> Twist {
    let mut t = Twist::default();
    t.linear.x = b.vx;
    t
}

async fn serve(node: &mut RosNode) -> anyhow::Result<()> {
    let config: DriveConfig = node.config()?;
    let cmd = node.publisher::<Twist>("cmd_vel", &qos::default_qos())?;
    let mut session = Session::new(SessionSettings::default());
    let outcome = drive_loop(node, &cmd, &mut session, config).await;
    // Whatever ends the loop (shutdown or a failure), a goal under way gets its zero command,
    // waited for, so the chassis does not keep the last speed until its own watchdog fires.
    if session.shutdown().1 {
        final_stop(&cmd, Twist::default(), FINAL_STOP_WAIT).await;
    }
    outcome
}

async fn drive_loop(
    node: &mut RosNode,
    cmd: &Publisher<Twist>,
    session: &mut Session,
    mut config: DriveConfig,
) -> anyhow::Result<()> {
    let odom_sub = node.subscription::<Odometry>("odom", &qos::default_qos())?;
    let mut lifecycle = Lifecycle::serve(node, &config.managed)?;
    let mut server = GoalServer::<DriveDistance>::create(
        node,
        "drive_distance",
        GoalServerConfig {
            result_timeout: config.timeouts.result_timeout(),
        },
    )?
    .gate(lifecycle.gate());
    let io = Io {
        cmd,
        odom_sub: &odom_sub,
        server: &mut server,
        lifecycle: &mut lifecycle,
    };
    let outcome = event_loop(node, io, session, &mut config).await;
    let travelled = session.active().map_or(0.0, |a| a.goal.progress().travelled);
    let reason = if outcome.is_ok() {
        "shutting down"
    } else {
        "node failed"
    };
    server.close(result(travelled, reason)).await;
    lifecycle.close();
    outcome
}

/// The node's interfaces, for its loop.
struct Io<'a> {
    cmd: &'a Publisher<Twist>,
    odom_sub: &'a Subscription<Odometry>,
    server: &'a mut GoalServer<DriveDistance>,
    lifecycle: &'a mut Lifecycle,
}

async fn event_loop(
    node: &mut RosNode,
    io: Io<'_>,
    session: &mut Session,
    config: &mut DriveConfig,
) -> anyhow::Result<()> {
    let Io {
        cmd,
        odom_sub,
        server,
        lifecycle,
    } = io;
    let mut inputs = Inputs::new();
    inputs.add(odom_sub.async_stream(), "odom", "sample ignored", |m: Odometry| m);
    let shutdown = shutdown_signal();
    tokio::pin!(shutdown);
    let mut ticker = Ticker::new(config.rate_hz)?;
    let mut throttle = LogThrottle::new(Duration::from_secs(2));
    let mut sink = CmdVel::new(cmd);

    // The latest valid odometry pose, with its stamp and steady receive instant: the one
    // place odom freshness is judged.
    let mut latest: Latest<Pose2> = Latest::new();
    info!("serving drive_distance");
    loop {
        tokio::select! {
            _ = &mut shutdown => return Ok(()),
            Some(changed) = node.config_changed::<DriveConfig>() => match changed {
                Ok(c) => match ticker.set_rate(c.rate_hz) {
                    Ok(()) => {
                        lifecycle.set_managed(&c.managed);
                        *config = c;
                    }
                    Err(e) => warn!("parameters not applied: {e}"),
                },
                Err(e) => warn!("parameters not applied: {e}"),
            },
            transition = lifecycle.next() => {
                // Leaving active (deactivate, shutdown): the goal under way ends, with its zero.
                if transition.leaves_active() {
                    let ended = session.end(EndCause::Deactivated, &mut sink);
                    finish(server, ended);
                }
                lifecycle.complete(transition, CallbackReturn::Success);
            }
            m = inputs.next() => {
                let m = m?;
                match planar_pose(&m.pose.pose) {
                    Ok(pose) => latest.set(pose, m.header.stamp),
                    Err(e) => warn_throttled!(throttle, "odom-bad", "{e}: sample dropped"),
                }
            }
            event = server.next_event() => match event {
                ActionEvent::Goal(request) => {
                    let goal = request.goal().clone();
                    let Some(&start) = latest.get(config.timeouts.odom_timeout()) else {
                        server.reject(request, "no recent odom: is the chassis running?").await;
                        continue;
                    };
                    match DistanceDrive::new(start, goal.distance, goal.speed, config.settings()) {
                        Err(e) => server.reject(request, &e.to_string()).await,
                        Ok(new) => {
                            let travelled = session.active().map_or(0.0, |a| a.goal.progress().travelled);
                            // The server ends the goal it replaces itself, with this result.
                            let preempted = |_: &_| result(travelled, "preempted by a newer goal");
                            match server.accept(request, preempted, node.now_nanos()).await {
                                Ok(()) => {
                                    info!("driving {} m at {} m/s", goal.distance, goal.speed);
                                    session.start(new, DriveAction, Instant::now());
                                }
                                // One client's goal (a DDS send failed): logged, and the node
                                // goes on serving the others; a goal it replaced was ended.
                                Err(e) => {
                                    warn_throttled!(throttle, "accept", "goal not started: {e}");
                                    session.preempt(DriveAction, &mut sink);
                                }
                            }
                        }
                    }
                }
                ActionEvent::CancelRequested(_) => {
                    let ended = session.end(EndCause::Canceled, &mut sink);
                    finish(server, ended);
                }
            },
            _ = ticker.tick() => {
                if node.uses_sim_time() {
                    let timeout = config.timeouts.clock_timeout();
                    let clock = session.watch_clock(node.now_nanos(), Instant::now(), timeout, &mut sink);
                    mobil_ros::tell!(throttle, clock.notice());
                    if let ClockCheck::Back(ended) = clock {
                        finish(server, Some(ended));
                        continue;
                    }
                }
                if session.active().is_none() {
                    continue;
                }
                let Some(&pose) = latest.get(config.timeouts.odom_timeout()) else {
                    warn!("no odom for {:?}: goal aborted", config.timeouts.odom_timeout());
                    let ended = session.end(EndCause::Stale("odom".into()), &mut sink);
                    finish(server, ended);
                    continue;
                };
                // The law reads no time; the goal's own time is kept for the record.
                let dt = session.advance(node.now_nanos()).and_then(Result::ok).unwrap_or(0.0);
                let t = session.active().map_or(0.0, |a| a.t());
                let Some(active) = session.active_mut() else { continue };
                let step = active.goal.step(&StepInput::new(t, dt, pose), &());
                match session.apply(step, twist, &mut sink) {
                    Applied::Commanded(progress) => {
                        let feedback = DriveDistanceFeedback { travelled: progress.travelled, remaining: progress.remaining };
                        if let Err(e) = server.feedback(feedback).await {
                            warn_throttled!(throttle, "feedback", "{e}");
                        }
                    }
                    Applied::Ended(ended, _) => finish(server, Some(ended)),
                    Applied::Refused(ended) => finish(server, ended),
                    Applied::Idle => {}
                }
            }
        }
    }
}
