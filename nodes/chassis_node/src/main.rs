//! `chassis_node`: the LOW-LEVEL of the suite (SPEC §1). `cmd_vel` → limits → inverse kinematics
//! → `wheel_commands`; `joint_states` → forward kinematics → exact arc odometry → `odom` + `tf`;
//! a cmd_vel watchdog and a feedback watchdog; `~/status` reports both and every clamp.
//!
//! Every `wheel_commands` message is a [`GatedCommand`]: it comes out of the controller's one
//! safety gate (watchdogs, refused `cmd_vel`, non-finite values), on `cmd_vel`, on the control
//! tick and at shutdown alike.
//!
//! Freshness is measured once, by the kit's [`Latest`] holders (steady receive instants of the
//! last valid `cmd_vel` and the last feedback sample used); the gate decides on those ages with
//! its timeouts. The node keeps no clock of its own for the watchdogs.

use mobil_chassis::controller::{
    ChassisController, ControllerConfig, FeedbackError, FeedbackOutcome, GatedCommand, InputAges, Safety,
    DEFAULT_FEEDBACK_SPEED_FACTOR,
};
use mobil_chassis::health::{chassis_health, ChassisReport};
use mobil_chassis::joints::{joints_from_wheel_state, JointStateError};
use mobil_chassis::kinematics::BodyTwist;
use mobil_chassis::model::ChassisConfig;
use mobil_chassis::model::ChassisModel;
use mobil_chassis::odometry::OdometryNoise;
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::geometry_msgs::msg::{Transform, TransformStamped, Twist, TwistStamped, Vector3};
use mobil_msgs::mobil_msgs::msg::ChassisStatus;
use mobil_msgs::nav_msgs::msg::Odometry;
use mobil_msgs::sensor_msgs::msg::JointState;
use mobil_msgs::std_msgs::msg::Header;
use mobil_msgs::tf2_msgs::msg::TFMessage;
use mobil_ros::chassis::{chassis_params, declare_chassis};
use mobil_ros::cmd_vel::{stamped_twist, CmdVelType, TypeWatch};
use mobil_ros::config::{Config, ConfigError, Decl};
use mobil_ros::diagnostics::DiagnosticsOut;

/// The least time between two `/diagnostics` reports when the level gets worse.
const DIAGNOSTICS_MIN_GAP: std::time::Duration = std::time::Duration::from_millis(200);
use mobil_ros::geometry::{planar_odometry, yaw_quaternion};
use mobil_ros::input::Inputs as Streams;
use mobil_ros::latest::Latest;
use mobil_ros::stop::{final_stop, FINAL_STOP_WAIT};
use mobil_ros::ticker::{self, Ticker};
use mobil_ros::time::{is_zero, secs_from_stamp};
use mobil_ros::{qos, run_node, shutdown_signal, warn_throttled, LogThrottle, NodeDecl, RosNode};
use std::process::ExitCode;
use tracing::{info, warn};

/// Everything the node is configured with, each field filled by one declared parameter.
#[derive(Debug, Clone, Default, PartialEq)]
struct NodeConfig {
    chassis: ChassisConfig,
    cmd_vel_timeout_s: f64,
    feedback_timeout_s: f64,
    noise: OdometryNoise,
    feedback_speed_factor: f64,
    encoder_positions_wrap: bool,
    control_rate_hz: f64,
    odom_frame: String,
    base_frame: String,
    publish_tf: bool,
    cmd_vel: CmdVelType,
}

impl Config for NodeConfig {
    fn declare(d: &mut Decl<Self>) {
        let noise = OdometryNoise::default();
        d.nest(|c: &mut NodeConfig| &mut c.chassis, declare_chassis);
        d.double(
            "cmd_vel_timeout_s",
            0.5,
            "zero command after this long without cmd_vel (0: off)",
            |c, v| c.cmd_vel_timeout_s = v,
        )
        .min(0.0);
        d.double(
            "feedback_timeout_s",
            0.5,
            "zero command after this long without joint_states (0: off)",
            |c, v| c.feedback_timeout_s = v,
        )
        .min(0.0);
        d.double(
            "max_feedback_wheel_speed_factor",
            DEFAULT_FEEDBACK_SPEED_FACTOR,
            "joint_states wheel speeds above this × max_wheel_speed are refused as impossible (bad encoder data)",
            |c, v| c.feedback_speed_factor = v,
        )
        .within(1.0, 100.0);
        d.boolean(
            "encoder_positions_wrap",
            false,
            "position-only joint_states report wheel angles wrapped to one turn (false: a continuous count)",
            |c, v| c.encoder_positions_wrap = v,
        );
        d.double("control_rate_hz", 50.0, "wheel_commands and status rate", |c, v| {
            c.control_rate_hz = v
        })
        .within(1.0, 1000.0);
        d.string("odom_frame", "odom", "odometry frame", |c, v| c.odom_frame = v);
        d.string(
            "base_frame",
            "base_link",
            "robot frame (at the reference point)",
            |c, v| c.base_frame = v,
        );
        d.boolean("publish_tf", true, "publish odom → base_link on tf", |c, v| {
            c.publish_tf = v
        });
        d.nest(|c: &mut NodeConfig| &mut c.cmd_vel, CmdVelType::declare);
        d.double(
            "odom.along_track_var_per_m",
            noise.along_track_var_per_m,
            "[m²/m]",
            |c, v| c.noise.along_track_var_per_m = v,
        )
        .min(0.0);
        d.double(
            "odom.cross_track_var_per_m",
            noise.cross_track_var_per_m,
            "[m²/m]",
            |c, v| c.noise.cross_track_var_per_m = v,
        )
        .min(0.0);
        d.double(
            "odom.heading_var_per_rad",
            noise.heading_var_per_rad,
            "[rad²/rad]",
            |c, v| c.noise.heading_var_per_rad = v,
        )
        .min(0.0);
        d.double(
            "odom.heading_var_per_m",
            noise.heading_var_per_m,
            "[rad²/m]",
            |c, v| c.noise.heading_var_per_m = v,
        )
        .min(0.0);
        d.doubles(
            "odom.twist_variance",
            noise.twist_variance,
            "vx, vy, ω variances",
            |c, v| c.noise.twist_variance = v,
        );
    }

    fn validate(&self) -> Result<(), ConfigError> {
        self.controller().map(|_| ())
    }
}

impl NodeConfig {
    /// The controller's settings: validated geometry, watchdogs, odometry noise.
    fn controller(&self) -> Result<ControllerConfig, ConfigError> {
        self.noise.validate().map_err(ConfigError::inconsistent)?;
        Ok(ControllerConfig {
            params: chassis_params(&self.chassis)?,
            cmd_vel_timeout_s: self.cmd_vel_timeout_s,
            feedback_timeout_s: self.feedback_timeout_s,
            noise: self.noise,
        })
    }
}

fn decl() -> NodeDecl {
    NodeDecl::for_config::<NodeConfig>(
        "chassis",
        "LOW-LEVEL chassis control: kinematics, command limits, odometry, cmd_vel watchdog",
    )
}

/// A sample of the node's subscriptions.
enum In {
    Cmd(Twist),
    /// An undecodable `cmd_vel` (logged): the wheels stop.
    BadCmd,
    Joints(JointState),
    /// An undecodable `joint_states` (logged): counted.
    BadJoints,
}

fn main() -> ExitCode {
    run_node(&decl(), |node| Box::pin(run(node)))
}

/// Places a 3×3 (x, y, yaw) covariance into a 6×6 (x, y, z, roll, pitch, yaw) row-major one; the
/// planar robot's z, roll and pitch are known, with a tiny variance.
fn covariance_6x6(c: &nalgebra::Matrix3<f64>) -> [f64; 36] {
    let mut out = [0.0; 36];
    let idx = [0usize, 1, 5];
    for (i, &r) in idx.iter().enumerate() {
        for (j, &k) in idx.iter().enumerate() {
            out[r * 6 + k] = c[(i, j)];
        }
    }
    for d in [2usize, 3, 4] {
        out[d * 6 + d] = 1e-9;
    }
    out
}

fn model_code(m: ChassisModel) -> u8 {
    match m {
        ChassisModel::Tricycle => ChassisStatus::MODEL_TRICYCLE,
        ChassisModel::CarLike => ChassisStatus::MODEL_CAR_LIKE,
        ChassisModel::Omni => ChassisStatus::MODEL_OMNI,
    }
}

async fn run(node: &mut RosNode) -> anyhow::Result<()> {
    let mut config: NodeConfig = node.config()?;
    let mut controller = ChassisController::new(config.controller()?)?;
    controller.set_feedback_speed_factor(config.feedback_speed_factor)?;
    controller.set_encoder_positions_wrap(config.encoder_positions_wrap);
    let params = controller.config().params;
    info!(
        "model {}, effective steering limit {:.1}°, v_max {} m/s, watchdog {} s",
        params.model().as_str(),
        params.effective_steering_limit().to_degrees(),
        params.v_max(),
        config.cmd_vel_timeout_s
    );

    let q = qos::default_qos();
    // cmd_vel as Twist or TwistStamped: the twist is taken, the header never read (the
    // watchdog judges arrival on the steady clock).
    let stamped = config.cmd_vel.enable_stamped_cmd_vel;
    let cmd_sub = (!stamped)
        .then(|| node.subscription::<Twist>("cmd_vel", &q))
        .transpose()?;
    let cmd_stamped_sub = stamped
        .then(|| node.subscription::<TwistStamped>("cmd_vel", &q))
        .transpose()?;
    let joints_sub = node.subscription::<JointState>("joint_states", &q)?;
    let wheel_pub = node.publisher::<JointState>("wheel_commands", &q)?;
    let odom_pub = node.publisher::<Odometry>("odom", &q)?;
    let tf_pub = node.publisher::<TFMessage>("tf", &qos::reliable(100))?;
    let status_pub = node.publisher::<ChassisStatus>("~/status", &qos::latched())?;
    let mut diagnostics = DiagnosticsOut::create(node)?;
    // Rejected inputs and the level at the last /diagnostics report.
    let mut rejected_reported: u64 = 0;
    let mut level_reported = None;

    // An undecodable cmd_vel stops the wheels at once; an undecodable joint_states is counted.
    let mut streams = Streams::new();
    if let Some(sub) = &cmd_sub {
        streams.add_guarded(sub.async_stream(), "cmd_vel", "wheels stopped", In::Cmd, || {
            Some(In::BadCmd)
        });
    }
    if let Some(sub) = &cmd_stamped_sub {
        let event = |m: TwistStamped| In::Cmd(stamped_twist(m));
        streams.add_guarded(sub.async_stream(), "cmd_vel", "wheels stopped", event, || {
            Some(In::BadCmd)
        });
    }
    let mut types = TypeWatch::default();
    streams.add_guarded(
        joints_sub.async_stream(),
        "joint_states",
        "sample ignored",
        In::Joints,
        || Some(In::BadJoints),
    );
    let shutdown = shutdown_signal();
    let mut tick = Ticker::new(config.control_rate_hz)?;
    tokio::pin!(shutdown);

    let mut throttle = LogThrottle::default();
    let mut rejected: u64 = 0;
    // Start-up counts as stopped, so neither stop line is logged before the first command.
    let mut last_safety = Safety {
        cmd_vel_expired: true,
        cmd_vel_refused: false,
        feedback_stale: true,
    };
    // The inputs' freshness, on the steady clock: a stalled or reset /clock must not keep the
    // wheels turning. Odometry runs on the feedback's own stamps.
    let mut inputs = Inputs::default();

    loop {
        tokio::select! {
            _ = &mut shutdown => break,
            Some(changed) = node.config_changed::<NodeConfig>() => {
                match changed.and_then(|new| Ok((new.controller()?, new))) {
                    Ok((new_controller, new)) => {
                        // Everything that can fail is vetted before anything is applied.
                        let applied = ChassisController::check_feedback_speed_factor(new.feedback_speed_factor)
                            .map_err(anyhow::Error::from)
                            .and_then(|()| Ok(ticker::period(new.control_rate_hz).map(|_| ())?))
                            .and_then(|()| Ok(controller.reconfigure(new_controller)?))
                            .and_then(|()| Ok(controller.set_feedback_speed_factor(new.feedback_speed_factor)?));
                        if let Err(e) = applied {
                            warn!("parameter change not applied: {e}");
                        } else {
                            controller.set_encoder_positions_wrap(new.encoder_positions_wrap);
                            // Vetted just above, so this cannot fail.
                            let _ = tick.set_rate(new.control_rate_hz);
                            config = new;
                        }
                    }
                    // The validator vetted the change, so this only happens if it raced another.
                    Err(e) => warn!("parameter change not applied: {e}"),
                }
            }
            input = streams.next() => match input? {
                In::Cmd(twist) => {
                    let request = BodyTwist::new(twist.linear.x, twist.linear.y, twist.angular.z);
                    let accepted = controller.on_cmd_vel(request);
                    inputs.cmd_vel(accepted, node);
                    let gated = controller.gate(inputs.ages());
                    let requested = controller.requested();
                    if !request.is_finite() {
                        rejected += 1;
                        warn_throttled!(throttle, "cmd_nan", "cmd_vel with NaN/inf ({:?}): wheels stopped", request);
                    } else if !requested.reasons.is_empty() {
                        warn_throttled!(throttle, "clamp", "cmd_vel {:?} clamped to {:?}: {}", request, requested.twist, requested.reasons);
                    }
                    publish_wheels(&wheel_pub, node, &gated);
                }
                // Logged (rate-limited) by the streams.
                In::BadCmd => {
                    rejected += 1;
                    let accepted = controller.on_unreadable_cmd_vel();
                    inputs.cmd_vel(accepted, node);
                    let gated = controller.gate(inputs.ages());
                    publish_wheels(&wheel_pub, node, &gated);
                }
                In::Joints(js) => {
                    // An unstamped sample is stamped on arrival (node clock).
                    let stamp_msg = if is_zero(&js.header.stamp) { node.stamp() } else { js.header.stamp.clone() };
                    let Some(stamp) = secs_from_stamp(&stamp_msg) else {
                        rejected += 1;
                        warn_throttled!(throttle, "stamp", "joint_states dropped: invalid stamp {:?}", js.header.stamp);
                        continue;
                    };
                    match controller.on_joint_state(&js.name, &js.position, &js.velocity, stamp) {
                        // A position-only sample that only set the baseline.
                        Ok(None) => {}
                        Ok(Some(outcome)) => {
                            inputs.feedback.set((), stamp_msg.clone());
                            match outcome {
                                FeedbackOutcome::Restarted { gap_s: Some(gap) } => warn_throttled!(
                                    throttle,
                                    "feedback_gap",
                                    "joint_states stamps jumped by {gap:.3} s (dropout or clock reset): odometry not integrated across the gap"
                                ),
                                FeedbackOutcome::Ambiguous { gap_s } => warn_throttled!(
                                    throttle,
                                    "feedback_ambiguous",
                                    "wrapped encoder angles {gap_s:.3} s apart are ambiguous (a wheel may have turned more than π): odometry not integrated across the gap"
                                ),
                                FeedbackOutcome::Bridged { gap_s } => warn_throttled!(
                                    throttle,
                                    "feedback_bridged",
                                    "joint_states resumed after {gap_s:.3} s: the encoder angles cover the gap, odometry integrated across it"
                                ),
                                FeedbackOutcome::Integrated | FeedbackOutcome::Restarted { gap_s: None } => {}
                            }
                            publish_odometry(&odom_pub, &tf_pub, &config, &controller, stamp_msg);
                        }
                        Err(e) => {
                            rejected += 1;
                            // One throttle per kind of fault, so each kind is reported.
                            let key = match e {
                                FeedbackError::Kinematics(_) => "feedback_kinematics",
                                FeedbackError::Odometry(_) | FeedbackError::Joints(JointStateError::StampNotIncreasing { .. }) => "feedback_time",
                                FeedbackError::Implausible { .. } => "feedback_implausible",
                                FeedbackError::Joints(JointStateError::NonFiniteStamp(_)) => "stamp",
                                FeedbackError::Joints(JointStateError::MismatchedLengths { .. }) => "joints_lengths",
                                FeedbackError::Joints(JointStateError::MissingJoint(_)) => "joints_missing",
                                FeedbackError::Joints(JointStateError::MissingField { .. }) => "joints_field",
                                FeedbackError::Joints(JointStateError::NonFinite { .. }) => "joints_nan",
                            };
                            warn_throttled!(throttle, key, "joint_states dropped: {e}");
                        }
                    }
                }
                // Logged (rate-limited) by the streams.
                In::BadJoints => rejected += 1,
            },
            _ = tick.tick() => {
                if let Some(line) = types.check(node, stamped, "cmd_vel", std::time::Instant::now()) {
                    warn_throttled!(throttle, "cmd-type", "{line}");
                }
                let cmd = controller.gate(inputs.ages());
                let safety = cmd.safety();
                // A refused (NaN) cmd_vel stops the wheels too, but was logged as what it is.
                if safety.cmd_vel_timed_out() && !last_safety.cmd_vel_timed_out() {
                    warn!("no cmd_vel for {} s: wheels stopped", config.cmd_vel_timeout_s);
                }
                if safety.feedback_stale && !last_safety.feedback_stale {
                    warn!("no valid joint_states for {} s: odometry stale, wheels stopped", config.feedback_timeout_s);
                }
                last_safety = safety;
                publish_wheels(&wheel_pub, node, &cmd);
                let status = ChassisStatus {
                    header: Header { stamp: node.stamp(), frame_id: config.base_frame.clone() },
                    model: model_code(controller.config().params.model()),
                    watchdog_expired: safety.cmd_vel_expired || safety.cmd_vel_refused,
                    feedback_stale: safety.feedback_stale,
                    clamped: cmd.reasons.bits(),
                    commanded: Twist {
                        linear: Vector3 { x: cmd.twist.vx, y: cmd.twist.vy, z: 0.0 },
                        angular: Vector3 { x: 0.0, y: 0.0, z: cmd.twist.wz },
                    },
                    rejected_messages: rejected,
                };
                let _ = status_pub.publish(status);
                // /diagnostics once a second (rejections counted over the period), and sooner
                // when the level gets worse (a stopped feedback is reported when its watchdog
                // fires, not up to a second later), at most every 0.2 s; a better level waits
                // for the period, so a flapping input cannot flood the topic.
                let report = ChassisReport {
                    safety,
                    ages: inputs.ages(),
                    clamped: cmd.reasons,
                    rejected_total: rejected,
                    rejected_new: rejected.saturating_sub(rejected_reported),
                };
                let health = chassis_health(&report);
                let now = std::time::Instant::now();
                let periodic = diagnostics.due(now);
                let worse = level_reported.is_none_or(|l| health.level > l)
                    && diagnostics.since_last(now).is_none_or(|d| d >= DIAGNOSTICS_MIN_GAP);
                if periodic || worse {
                    if periodic {
                        rejected_reported = rejected;
                    }
                    level_reported = Some(health.level);
                    let model = controller.config().params.model().as_str();
                    diagnostics.send(&[("watchdogs", model, health)], node.stamp(), now, &mut throttle);
                }
            }
        }
    }
    // Leave the wheels stopped, and wait (bounded) until the drivers have the command.
    let stop = controller.stop(inputs.ages());
    final_stop(&wheel_pub, wheels_message(node, &stop), FINAL_STOP_WAIT).await;
    Ok(())
}

/// The node's inputs as the safety gate sees them: when each last arrived valid (steady clock).
#[derive(Default)]
struct Inputs {
    /// The last valid `cmd_vel` (forgotten on a refused one).
    cmd_vel: Latest<()>,
    /// The last feedback sample the controller used.
    feedback: Latest<()>,
}

impl Inputs {
    /// Records a `cmd_vel` the controller accepted, or forgets the last one if it refused it.
    fn cmd_vel(&mut self, accepted: bool, node: &RosNode) {
        if accepted {
            self.cmd_vel.set((), node.stamp());
        } else {
            self.cmd_vel.clear();
        }
    }

    /// The ages the gate decides on, now.
    fn ages(&self) -> InputAges {
        let now = std::time::Instant::now();
        InputAges {
            cmd_vel_s: self.cmd_vel.age_at(now).map(|a| a.as_secs_f64()),
            feedback_s: self.feedback.age_at(now).map(|a| a.as_secs_f64()),
        }
    }
}

/// The `wheel_commands` message of the safety gate's output (it takes nothing else).
fn wheels_message(node: &RosNode, cmd: &GatedCommand) -> JointState {
    let (name, position, velocity) = joints_from_wheel_state(&cmd.wheels);
    JointState {
        header: Header {
            stamp: node.stamp(),
            frame_id: String::new(),
        },
        name,
        position,
        velocity,
        effort: Vec::new(),
    }
}

/// The only way to `wheel_commands`: it takes nothing but the safety gate's output.
fn publish_wheels(publisher: &ros2_client::Publisher<JointState>, node: &RosNode, cmd: &GatedCommand) {
    if let Err(e) = publisher.publish(wheels_message(node, cmd)) {
        warn!("cannot publish wheel_commands: {e:?}");
    }
}

fn publish_odometry(
    odom_pub: &ros2_client::Publisher<Odometry>,
    tf_pub: &ros2_client::Publisher<TFMessage>,
    config: &NodeConfig,
    controller: &ChassisController,
    stamp: Time,
) {
    let odo = controller.odometry();
    let pose = odo.reference_pose();
    let twist = odo.reference_twist();
    // The feedback's own stamp, unchanged, so odom and tf line up with joint_states exactly.
    let header = Header {
        stamp,
        frame_id: config.odom_frame.clone(),
    };
    let mut msg = planar_odometry(
        header.clone(),
        &config.base_frame,
        pose.into(),
        [twist.vx, twist.vy, twist.wz],
    );
    msg.pose.covariance = covariance_6x6(&odo.reference_covariance());
    msg.twist.covariance = covariance_6x6(&odo.reference_twist_covariance());
    if let Err(e) = odom_pub.publish(msg) {
        warn!("cannot publish odom: {e:?}");
    }
    if config.publish_tf {
        let tf = TransformStamped {
            header,
            child_frame_id: config.base_frame.clone(),
            transform: Transform {
                translation: Vector3 {
                    x: pose.x,
                    y: pose.y,
                    z: 0.0,
                },
                rotation: yaw_quaternion(pose.z),
            },
        };
        if let Err(e) = tf_pub.publish(TFMessage { transforms: vec![tf] }) {
            warn!("cannot publish tf: {e:?}");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mobil2_params_file_configures_this_node() {
        let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/mobil2.yaml")).unwrap();
        let d = decl();
        let p =
            mobil_ros::params::initial_params(&d.params, &[("mobil2.yaml".into(), text)], &[], "/chassis", "chassis")
                .unwrap();
        assert!(p.warnings.is_empty(), "{:?}", p.warnings);
        let c = mobil_ros::config::load::<NodeConfig>(&p.values)
            .unwrap()
            .controller()
            .unwrap();
        assert_eq!(c.params.model(), ChassisModel::CarLike);
        // SPEC §1 Decision: δ_eff = atan(0.60 / 0.73) = 39.42°.
        assert!((c.params.effective_steering_limit().to_degrees() - 39.42).abs() < 0.01);
        assert_eq!(c.params.reference_offset(), 0.30);
    }

    #[test]
    fn covariance_lands_on_x_y_yaw() {
        let c = nalgebra::Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 5.0, 3.0, 5.0, 6.0);
        let m = covariance_6x6(&c);
        assert_eq!(
            (m[0], m[1], m[5], m[7], m[11], m[35], m[30]),
            (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 3.0)
        );
    }
}
