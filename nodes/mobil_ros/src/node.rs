//! A ROS 2 node as every executable of the suite runs it: command line, parameters, names,
//! DDS domain, spinner (parameter services, graph, `/clock`) and clean shutdown.
//!
//! ```no_run
//! # async fn demo() -> anyhow::Result<()> {
//! use mobil_ros::{NodeDecl, ParamSpec, RosNode, qos};
//! use mobil_msgs::geometry_msgs::msg::Twist;
//! let decl = NodeDecl::new("teleop", "Publishes a constant twist")
//!     .param(ParamSpec::double("speed", 0.2, "forward speed [m/s]").above(0.0));
//! let Some(args) = decl.parse_command_line(std::env::args())? else { return Ok(()) };
//! let mut node = RosNode::start(&decl, &args)?;
//! let cmd = node.publisher::<Twist>("cmd_vel", &qos::default_qos())?;
//! let mut t = Twist::default();
//! t.linear.x = node.params().f64("speed").map_err(anyhow::Error::msg)?;
//! cmd.publish(t)?;
//! node.shutdown().await;
//! # Ok(()) }
//! ```

use crate::args::{split_ros_args, RosArgs, ROS_ARGS_HELP};
use crate::config::{Config, ConfigError, Decl};
use crate::names::NameResolver;
use crate::params::{initial_params, type_name, ParamSpec, ParamValues};
use anyhow::{anyhow, bail, Context as _};
use mobil_msgs::builtin_interfaces::msg::Time;
use mobil_msgs::rosgraph_msgs::msg::Clock;
use mobil_msgs::{RosMessage, RosService};
use ros2_client::{
    Context, Name, Node, NodeName, NodeOptions, ParameterValue, Publisher, QosProfile, RmwRequestId, Server,
    ServiceMapping, Subscription,
};
use std::fmt::Write as _;
use std::sync::atomic::{AtomicBool, AtomicI64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;
use tokio::sync::mpsc;
use tracing::{info, warn};

/// A cross-parameter check: typically the node's configuration parser, run on the full set of
/// candidate values before any change is accepted.
pub type ConfigCheck = Arc<dyn Fn(&ParamValues) -> Result<(), String> + Send + Sync>;

/// What a node is: its default name, what it does, and its parameters.
#[derive(Clone)]
pub struct NodeDecl {
    pub default_name: String,
    pub about: String,
    pub params: Vec<ParamSpec>,
    pub check: ConfigCheck,
    /// Which undeclared parameters the node takes as they come ([`RosNode::extra_params`]):
    /// instances named in a list, as Nav2's `docks: [dock1]` with `dock1.pose`.
    pub extra: Arc<dyn Fn(&str) -> bool + Send + Sync>,
}

impl NodeDecl {
    /// A node with no parameters yet.
    pub fn new(default_name: &str, about: &str) -> Self {
        NodeDecl {
            default_name: default_name.to_owned(),
            about: about.to_owned(),
            params: Vec::new(),
            check: Arc::new(|_| Ok(())),
            extra: Arc::new(|_| false),
        }
    }

    /// A node whose parameters are those of configuration `C`, checked by building it (see
    /// [`crate::config`]).
    pub fn for_config<C: Config>(default_name: &str, about: &str) -> Self {
        let decl = Decl::<C>::of();
        NodeDecl::new(default_name, about)
            .params(decl.specs())
            .check(move |values| decl.build(values).map(|_| ()).map_err(|e| e.to_string()))
    }

    /// Declares a parameter.
    pub fn param(mut self, spec: ParamSpec) -> Self {
        self.params.push(spec);
        self
    }

    /// Declares several parameters.
    pub fn params(mut self, specs: impl IntoIterator<Item = ParamSpec>) -> Self {
        self.params.extend(specs);
        self
    }

    /// Takes the undeclared parameters `accepts` names from files and `-p` (not from `/**`), as
    /// they come, without the warning an unknown parameter gets: the node reads them once at
    /// start ([`RosNode::extra_params`]); they are not served by the parameter services.
    pub fn extra(mut self, accepts: impl Fn(&str) -> bool + Send + Sync + 'static) -> Self {
        self.extra = Arc::new(accepts);
        self
    }

    /// Sets the cross-parameter check.
    pub fn check(mut self, check: impl Fn(&ParamValues) -> Result<(), String> + Send + Sync + 'static) -> Self {
        self.check = Arc::new(check);
        self
    }

    /// The parameter table for `--help`.
    pub fn params_help(&self) -> String {
        let mut s = String::from("Parameters (set with -p NAME:=VALUE or a --params-file):\n");
        for p in &self.params {
            let default = match &p.default {
                ParameterValue::String(v) => format!("\"{v}\""),
                ParameterValue::Double(v) => format!("{v}"),
                ParameterValue::Integer(v) => format!("{v}"),
                ParameterValue::Boolean(v) => format!("{v}"),
                ParameterValue::DoubleArray(v) => format!("{v:?}"),
                other => format!("{other:?}"),
            };
            let ro = if p.read_only { " (read-only)" } else { "" };
            let allowed = p.constraint.to_string();
            let allowed = if allowed.is_empty() {
                String::new()
            } else {
                format!(" {allowed}")
            };
            let _ = writeln!(
                s,
                "  {:<28} {:<10} {}{ro} [default {default}]{allowed}",
                p.name,
                type_name(&p.default),
                p.description
            );
        }
        s
    }

    /// Parses the process arguments. `Ok(None)` means `--help`, `--version` or
    /// `--params-markdown` was answered and the program should exit successfully.
    pub fn parse_command_line<I, S>(&self, argv: I) -> anyhow::Result<Option<RosArgs>>
    where
        I: IntoIterator<Item = S>,
        S: Into<String>,
    {
        let mut argv = argv.into_iter().map(Into::into);
        let program = argv
            .next()
            .and_then(|p| {
                std::path::Path::new(&p)
                    .file_name()
                    .map(|f| f.to_string_lossy().into_owned())
            })
            .unwrap_or_else(|| self.default_name.clone());
        let (own, ros) = split_ros_args(argv)?;
        let command = clap::Command::new(program)
            .about(self.about.clone())
            .version(env!("CARGO_PKG_VERSION"))
            .arg(
                clap::Arg::new("params-markdown")
                    .long(&crate::docs::PARAMS_MARKDOWN_OPTION[2..])
                    .action(clap::ArgAction::SetTrue)
                    .help("Print the parameter table in Markdown (as docs/ has it) and exit"),
            )
            .after_help(format!("{}\n{}", self.params_help(), ROS_ARGS_HELP));
        match command.try_get_matches_from(std::iter::once(String::from("node")).chain(own)) {
            Ok(m) if m.get_flag("params-markdown") => {
                print!("{}", crate::docs::params_markdown(&self.params));
                Ok(None)
            }
            Ok(_) => Ok(Some(ros)),
            Err(e)
                if matches!(
                    e.kind(),
                    clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion
                ) =>
            {
                print!("{e}");
                Ok(None)
            }
            Err(e) => Err(anyhow!("{e}")),
        }
    }
}

/// The DDS domain from `ROS_DOMAIN_ID` (default 0), which ros2-client does not read by itself.
pub fn domain_id_from_env() -> anyhow::Result<u16> {
    match std::env::var("ROS_DOMAIN_ID") {
        Err(_) => Ok(0),
        Ok(s) if s.trim().is_empty() => Ok(0),
        Ok(s) => {
            let id: u16 = s
                .trim()
                .parse()
                .with_context(|| format!("ROS_DOMAIN_ID=`{s}` is not a number"))?;
            if id > 232 {
                bail!("ROS_DOMAIN_ID={id} is out of range (0..=232)");
            }
            Ok(id)
        }
    }
}

/// A running node.
pub struct RosNode {
    // Field order is drop order: the node before its context, so the participant leaves last.
    node: Node,
    context: Context,
    names: NameResolver,
    params: Arc<Mutex<ParamValues>>,
    changes: mpsc::UnboundedReceiver<ParamValues>,
    spinner: Option<tokio::task::JoinHandle<()>>,
    /// `/clock`, read when the time is asked for (see [`RosNode::now_nanos`]).
    clock: Option<Subscription<Clock>>,
    /// Latest `/clock` (ns), shared with the node's [`NodeClock`]s.
    sim_clock: Arc<AtomicI64>,
    /// `use_sim_time` as [`RosNode::now_nanos`] last read it, shared with the [`NodeClock`]s.
    sim_on: Arc<AtomicBool>,
    /// The undeclared parameters the node takes ([`NodeDecl::extra`]).
    extra: Vec<(String, ParameterValue)>,
}

/// The node's clock for a part of it that reads the time away from the node itself (a
/// command publisher, a service's threads): the system clock, or under `use_sim_time` the
/// latest `/clock` the node has read ([`RosNode::now_nanos`], which every node calls at least
/// once per tick). [`RosNode::clock`] keeps the choice the node had when it was made (a goal's
/// elapsed time measured on it stays on one clock); [`RosNode::following_clock`] follows
/// `use_sim_time` as `now_nanos` last read it (for times handed to the same tf tree as the
/// node's own).
#[derive(Debug, Clone)]
pub struct NodeClock {
    source: ClockSource,
}

#[derive(Debug, Clone)]
enum ClockSource {
    System,
    /// The latest `/clock` (ns).
    Sim(Arc<AtomicI64>),
    /// The latest `/clock` (ns) while the flag (the node's `use_sim_time`) is set.
    Following(Arc<AtomicI64>, Arc<AtomicBool>),
}

impl NodeClock {
    /// The system clock (a node without `use_sim_time`, or a test).
    pub fn system() -> Self {
        NodeClock {
            source: ClockSource::System,
        }
    }

    /// Nanoseconds now.
    pub fn now_nanos(&self) -> i64 {
        match &self.source {
            ClockSource::Sim(sim) => sim.load(Ordering::Acquire),
            ClockSource::Following(sim, on) if on.load(Ordering::Acquire) => sim.load(Ordering::Acquire),
            _ => std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| i64::try_from(d.as_nanos()).unwrap_or(i64::MAX)),
        }
    }
}

fn lock(values: &Mutex<ParamValues>) -> std::sync::MutexGuard<'_, ParamValues> {
    values.lock().unwrap_or_else(PoisonError::into_inner)
}

impl RosNode {
    /// Starts the node: resolves name and parameters, joins the DDS domain and spawns the
    /// spinner on the current tokio runtime. Invalid parameters stop it here, with the reason.
    pub fn start(decl: &NodeDecl, args: &RosArgs) -> anyhow::Result<RosNode> {
        let node_name = args
            .node_name_for(&decl.default_name)
            .unwrap_or(&decl.default_name)
            .to_owned();
        let namespace = args.namespace_for(&decl.default_name).unwrap_or("/");
        let names = NameResolver::new(namespace, &node_name, &args.remaps)?;
        let fqn = names.fully_qualified_node();

        let mut files = Vec::new();
        for path in &args.params_files {
            let text = std::fs::read_to_string(path).with_context(|| format!("cannot read parameter file {path}"))?;
            files.push((path.clone(), text));
        }
        let initial = initial_params(&decl.params, &files, &args.params, &fqn, &node_name)?;
        let mut extra = Vec::new();
        for (name, value, origin) in &initial.unknown {
            if (decl.extra)(name) {
                extra.push((name.clone(), value.clone()));
            } else {
                warn!("unknown parameter `{name}` from {origin} ignored");
            }
        }
        (decl.check)(&initial.values).map_err(|e| anyhow!("parameters of {fqn} are inconsistent: {e}"))?;

        let params = Arc::new(Mutex::new(initial.values.clone()));
        let (change_tx, changes) = mpsc::unbounded_channel();
        let mut options = NodeOptions::new().enable_rosout(true).start_parameter_services(true);
        for (name, value) in initial.values.iter() {
            options = options.declare_parameter(name, value.clone());
        }
        if initial.use_sim_time {
            options = options.declare_parameter("use_sim_time", ParameterValue::Boolean(true));
        }
        let specs = decl.params.clone();
        let check = decl.check.clone();
        let validator_values = params.clone();
        options = options.parameter_validator(Box::new(move |name, value| {
            let Some(spec) = specs.iter().find(|s| s.name == name) else {
                return Err(format!("`{name}` is not a parameter of this node"));
            };
            if matches!(value, ParameterValue::NotSet) {
                return Err(format!("`{name}` cannot be unset"));
            }
            let value = spec.check(value).map_err(|e| format!("`{name}`: {e}"))?;
            let mut candidate = lock(&validator_values).clone();
            if spec.read_only && candidate.get(name) != Some(&value) {
                return Err(format!("`{name}` is read-only; restart the node to change it"));
            }
            candidate.set(name, value);
            check(&candidate)
        }));
        // describe_parameters answers from the same declarations: description, range, read-only.
        let described = decl.params.clone();
        options = options.parameter_describer(Box::new(move |name| {
            described.iter().find(|s| s.name == name).map(ParamSpec::descriptor)
        }));
        let action_values = params.clone();
        // The whole configuration is checked again as each value is applied: ros2-client validates
        // the parameters of a `set_parameters_atomically` call one by one against the current
        // values, so a batch whose parts are valid alone but not together would otherwise slip
        // through. Refusing here stops the batch at its first inconsistent value, and the node's
        // values and the parameter services never disagree.
        let action_check = decl.check.clone();
        options = options.parameter_set_action(Box::new(move |name, value| {
            let mut values = lock(&action_values);
            if values.get(name) != Some(value) {
                let mut candidate = values.clone();
                candidate.set(name, value.clone());
                action_check(&candidate).map_err(|e| format!("`{name}`: {e}"))?;
                *values = candidate;
                info!("parameter {name} = {value:?}");
                // The receiver only disappears while the node shuts down.
                let _ = change_tx.send(values.clone());
            }
            Ok(())
        }));

        let domain = domain_id_from_env()?;
        let discovery = crate::discovery::Discovery::from_env();
        let (builder, peer_notes) = discovery.apply(rustdds::DomainParticipantBuilder::new(domain));
        for note in discovery.notes.iter().chain(&peer_notes) {
            warn!("{note}");
        }
        let participant = builder
            .build()
            .map_err(|e| anyhow!("cannot join DDS domain {domain}: {e:?}"))?;
        // Every endpoint announces its type's REP-2011 hash (USER_DATA `typehash=RIHS01_…;`),
        // computed at build time for every type mobil_msgs builds, as the Jazzy RMWs do.
        let type_hashes: ros2_client::TypeHashLookup =
            std::sync::Arc::new(|name: &str| mobil_msgs::type_hash(name).map(String::from));
        let context = Context::from_domain_participant_with_type_hashes(participant, type_hashes)
            .map_err(|e| anyhow!("cannot join DDS domain {domain}: {e:?}"))?;
        let ns = names.namespace().to_owned();
        let mut node = context
            .new_node(
                NodeName::new(&ns, &node_name).map_err(|e| anyhow!("bad node name {ns}/{node_name}: {e:?}"))?,
                options,
            )
            .map_err(|e| anyhow!("cannot create node {fqn}: {e:?}"))?;
        let spinner = node.spinner().map_err(|e| anyhow!("cannot start the spinner: {e:?}"))?;
        let handle = tokio::spawn(async move {
            if let Err(e) = spinner.spin().await {
                warn!("spinner stopped: {e:?}");
            }
        });
        info!("{fqn} up on ROS_DOMAIN_ID {domain}, {}", discovery.describe());
        let mut ros_node = RosNode {
            node,
            context,
            names,
            params,
            changes,
            spinner: Some(handle),
            clock: None,
            sim_clock: Arc::new(AtomicI64::new(0)),
            sim_on: Arc::new(AtomicBool::new(false)),
            extra,
        };
        ros_node.clock = Some(ros_node.subscription::<Clock>("/clock", &crate::qos::sensor_data())?);
        crate::log::attach_rosout(ros_node.node.logging_handle());
        Ok(ros_node)
    }

    /// The name resolver (namespace, node name, remaps).
    pub fn names(&self) -> &NameResolver {
        &self.names
    }

    /// The underlying ros2-client node.
    pub fn inner(&mut self) -> &mut Node {
        &mut self.node
    }

    /// The current parameter values.
    pub fn params(&self) -> ParamValues {
        lock(&self.params).clone()
    }

    /// The typed configuration from the current parameter values.
    pub fn config<C: Config>(&self) -> Result<C, ConfigError> {
        crate::config::load(&self.params())
    }

    /// Waits for the next accepted parameter change and yields the new typed configuration
    /// (already validated by the parameter services, so an error means the node's
    /// configuration and its declaration disagree). Cancel-safe, for `select!`.
    pub async fn config_changed<C: Config>(&mut self) -> Option<Result<C, ConfigError>> {
        let values = self.changes.recv().await?;
        Some(crate::config::load(&values))
    }

    /// Waits for the next accepted parameter change; yields the full new set of values.
    pub async fn param_changed(&mut self) -> Option<ParamValues> {
        self.changes.recv().await
    }

    fn topic_name(&self, topic: &str) -> anyhow::Result<Name> {
        let full = self.names.resolve(topic)?;
        Name::parse(&full).map_err(|e| anyhow!("bad topic name {full}: {e:?}"))
    }

    /// The DDS topic of `topic` (resolved and remapped) for messages of type `M`.
    fn topic<M: RosMessage>(&mut self, topic: &str, qos: &QosProfile) -> anyhow::Result<(rustdds::Topic, Name)> {
        let name = self.topic_name(topic)?;
        let t = self
            .node
            .create_topic(&name, M::type_name(), qos)
            .map_err(|e| anyhow!("cannot create topic {name}: {e:?}"))?;
        Ok((t, name))
    }

    /// A publisher on `topic` (resolved and remapped).
    pub fn publisher<M: RosMessage>(&mut self, topic: &str, qos: &QosProfile) -> anyhow::Result<Publisher<M>> {
        let (t, name) = self.topic::<M>(topic, qos)?;
        self.node
            .create_publisher(&t, Some(qos.clone()))
            .map_err(|e| anyhow!("cannot publish {name}: {e:?}"))
    }

    /// A subscription to `topic` (resolved and remapped).
    pub fn subscription<M: RosMessage>(&mut self, topic: &str, qos: &QosProfile) -> anyhow::Result<Subscription<M>> {
        let (t, name) = self.topic::<M>(topic, qos)?;
        self.node
            .create_subscription(&t, Some(qos.clone()))
            .map_err(|e| anyhow!("cannot subscribe {name}: {e:?}"))
    }

    /// A service server on `service` (resolved and remapped), rclpy/rclcpp compatible: each
    /// request is answered in the request/reply layout of the client that sent it, Fast DDS's
    /// or Cyclone DDS's (`ServiceMapping::Auto`, patches/README.md).
    pub fn service<S: RosService>(&mut self, service: &str) -> anyhow::Result<Server<S::Request, S::Response>> {
        let name = self.topic_name(service)?;
        let qos = crate::qos::reliable(10);
        self.node
            .create_server(ServiceMapping::Auto, &name, &S::type_name(), qos.clone(), qos)
            .map_err(|e| anyhow!("cannot serve {name}: {e:?}"))
    }

    /// Nanoseconds of the node's clock: the latest `/clock` when `use_sim_time` is true (0 until
    /// one arrives), else the system clock.
    ///
    /// `/clock` is read here as `rosgraph_msgs/Clock`, the type every ROS 2 simulator publishes
    /// (ros2-client's own sim time subscribes to it as `builtin_interfaces/Time`, which Fast DDS
    /// and Cyclone DDS publishers do not match). Best effort, as rclcpp's clock QoS.
    pub fn now_nanos(&self) -> i64 {
        if !self.uses_sim_time() {
            self.sim_on.store(false, Ordering::Release);
            return self.node.time_now_not_simulated().to_nanos();
        }
        if let Some(clock) = &self.clock {
            while let Ok(Some((c, _))) = clock.take() {
                if let Some(nanos) = crate::time::nanos_from_stamp(&c.clock) {
                    self.sim_clock.store(nanos, Ordering::Release);
                }
            }
        }
        // After the backlog: a following clock switched to `/clock` reads its latest value.
        self.sim_on.store(true, Ordering::Release);
        self.sim_clock.load(Ordering::Acquire)
    }

    /// Whether the node's clock is `/clock` (`use_sim_time`): a clock that can stop or go back,
    /// which a motion node watches ([`crate::motion::MotionSession::watch_clock`]).
    pub fn uses_sim_time(&self) -> bool {
        matches!(
            self.node.get_parameter("use_sim_time"),
            Some(ParameterValue::Boolean(true))
        )
    }

    /// The undeclared parameters the node takes ([`NodeDecl::extra`]), in the order given (a
    /// later value of a name after an earlier one).
    pub fn extra_params(&self) -> &[(String, ParameterValue)] {
        &self.extra
    }

    /// A handle on the node's clock (see [`NodeClock`]).
    pub fn clock(&self) -> NodeClock {
        NodeClock {
            source: match self.uses_sim_time() {
                true => ClockSource::Sim(Arc::clone(&self.sim_clock)),
                false => ClockSource::System,
            },
        }
    }

    /// A handle on the node's clock that follows `use_sim_time` (see [`NodeClock`]).
    pub fn following_clock(&self) -> NodeClock {
        self.sim_on.store(self.uses_sim_time(), Ordering::Release);
        NodeClock {
            source: ClockSource::Following(Arc::clone(&self.sim_clock), Arc::clone(&self.sim_on)),
        }
    }

    /// The DDS type names of the other endpoints discovered on `topic` (resolved and
    /// remapped): `(is_writer, type name)`, e.g. `(true, "geometry_msgs::msg::dds_::Twist_")`.
    pub fn endpoint_types(&self, topic: &str) -> Vec<(bool, String)> {
        let Ok(full) = self.names.resolve(topic) else {
            return Vec::new();
        };
        let dds = format!("rt{full}");
        let participant = self.context.domain_participant();
        let mut out: Vec<(bool, String)> = participant
            .discovered_writers()
            .iter()
            .filter(|w| w.publication_topic_data.topic_name == dds)
            .map(|w| (true, w.publication_topic_data.type_name.clone()))
            .collect();
        out.extend(
            participant
                .discovered_readers()
                .iter()
                .filter(|r| r.subscription_topic_data.topic_name() == &dds)
                .map(|r| (false, r.subscription_topic_data.type_name().clone())),
        );
        out
    }

    /// The topics (ROS names, e.g. `/sim1/ga_step/outcome`) on which writers of messages of type
    /// `M` have been discovered, sorted, each once: how a node finds peers that serve a
    /// contract in namespaces it was not told of.
    pub fn writer_topics<M: RosMessage>(&self) -> Vec<String> {
        let dds_type = M::type_name().dds_msg_type();
        let mut topics: Vec<String> = self
            .context
            .domain_participant()
            .discovered_writers()
            .iter()
            .filter(|w| w.publication_topic_data.type_name == dds_type)
            .filter_map(|w| {
                w.publication_topic_data
                    .topic_name
                    .strip_prefix("rt")
                    .map(str::to_string)
            })
            .collect();
        topics.sort();
        topics.dedup();
        topics
    }

    /// The node's clock as a message stamp.
    pub fn stamp(&self) -> Time {
        crate::time::stamp_from_nanos(self.now_nanos())
    }

    /// The DDS domain the node is on.
    pub fn domain_id(&self) -> u16 {
        self.context.domain_id()
    }

    /// Stops the spinner and leaves the DDS domain (the participant announces its departure).
    pub async fn shutdown(self) {
        let RosNode {
            node,
            context,
            names,
            spinner,
            clock,
            ..
        } = self;
        // Readers and writers must go while their participant exists.
        crate::log::detach_rosout();
        drop(clock);
        // Dropping the node tells its spinner to stop; then the context (participant) goes.
        drop(node);
        if let Some(handle) = spinner
            && tokio::time::timeout(Duration::from_secs(2), handle).await.is_err()
        {
            warn!("spinner did not stop within 2 s");
        }
        drop(context);
        info!("{} shut down", names.fully_qualified_node());
    }
}

/// Set once SIGINT or SIGTERM has arrived, by the listener [`listen_for_shutdown`] installs.
static SHUTDOWN: std::sync::OnceLock<tokio::sync::watch::Sender<bool>> = std::sync::OnceLock::new();

/// Installs the process's SIGINT / SIGTERM listener (once; must run inside the runtime). From
/// then on a signal is remembered, so a node still starting up when it arrives (a test that
/// stops a node as soon as it has logged something) stops as soon as its body waits for
/// [`shutdown_signal`], instead of missing it: a tokio signal stream created after a signal
/// does not see it, and with the handler installed the default action no longer ends the process.
pub fn listen_for_shutdown() {
    if SHUTDOWN.get().is_some() {
        return;
    }
    let (tx, _) = tokio::sync::watch::channel(false);
    if SHUTDOWN.set(tx).is_err() {
        return;
    }
    #[cfg(unix)]
    {
        use tokio::signal::unix::{signal, SignalKind};
        match (signal(SignalKind::interrupt()), signal(SignalKind::terminate())) {
            (Ok(mut int), Ok(mut term)) => {
                tokio::spawn(async move {
                    tokio::select! {
                        _ = int.recv() => info!("SIGINT: shutting down"),
                        _ = term.recv() => info!("SIGTERM: shutting down"),
                    }
                    if let Some(tx) = SHUTDOWN.get() {
                        tx.send_replace(true);
                    }
                });
            }
            _ => {
                tokio::spawn(async {
                    let _ = tokio::signal::ctrl_c().await;
                    if let Some(tx) = SHUTDOWN.get() {
                        tx.send_replace(true);
                    }
                });
            }
        }
    }
    #[cfg(not(unix))]
    tokio::spawn(async {
        let _ = tokio::signal::ctrl_c().await;
        if let Some(tx) = SHUTDOWN.get() {
            tx.send_replace(true);
        }
    });
}

/// Resolves when SIGINT (Ctrl-C) or SIGTERM has arrived, also one that came before the call
/// (the listener is installed by [`run_node`] before the node starts, or here on first use).
pub async fn shutdown_signal() {
    listen_for_shutdown();
    if let Some(tx) = SHUTDOWN.get() {
        let mut rx = tx.subscribe();
        let _ = rx.wait_for(|arrived| *arrived).await;
    }
}

/// Process set-up shared by every executable: quiets ros2-client's warning about an unset
/// `ROS_DISTRO` (this build speaks Jazzy) and installs logging.
pub fn init_process(args: &RosArgs) {
    if std::env::var_os("ROS_DISTRO").is_none() {
        // SAFETY: called at the top of main, before any other thread exists.
        unsafe { std::env::set_var("ROS_DISTRO", "jazzy") };
    }
    crate::log::init(args.log_level.as_deref());
}

/// The future a node's body returns.
pub type NodeBody<'a> = std::pin::Pin<Box<dyn std::future::Future<Output = anyhow::Result<()>> + 'a>>;

/// Runs an executable: command line (`--help` answered), logging, a tokio runtime, the node,
/// the body (which returns when a shutdown signal arrives or it fails), then a clean shutdown.
/// Returns the process exit code: 0, or 1 with the error logged.
pub fn run_node<F>(decl: &NodeDecl, body: F) -> std::process::ExitCode
where
    F: for<'a> FnOnce(&'a mut RosNode) -> NodeBody<'a>,
{
    let args = match decl.parse_command_line(std::env::args()) {
        Ok(Some(args)) => args,
        Ok(None) => return std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{}: {e:#}", decl.default_name);
            return std::process::ExitCode::from(2);
        }
    };
    init_process(&args);
    let runtime = match tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
    {
        Ok(rt) => rt,
        Err(e) => {
            tracing::error!("cannot start the async runtime: {e}");
            return std::process::ExitCode::FAILURE;
        }
    };
    let result = runtime.block_on(async {
        // Before anything slow: a signal during start-up is then not lost.
        listen_for_shutdown();
        let mut node = RosNode::start(decl, &args)?;
        let result = body(&mut node).await;
        node.shutdown().await;
        result
    });
    // Give DDS background threads a bounded time to wind down, then leave.
    runtime.shutdown_timeout(Duration::from_secs(2));
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
/// Sends `reply` to request `id` of `server` (`service` names it in the log): a reply that
/// cannot be sent (the client gone) is a rate-limited warning, never an error of the node.
pub fn respond<Q: ros2_client::Message + 'static, P: ros2_client::Message + 'static>(
    server: &Server<Q, P>,
    id: RmwRequestId,
    reply: P,
    service: &str,
    throttle: &mut crate::LogThrottle,
) {
    if let Err(e) = server.send_response(id, reply) {
        crate::warn_throttled!(throttle, "service-reply", "{service}: cannot send the reply: {e:?}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// After 2020-01-01 (1.577e18 ns since the epoch): the system clock.
    const SYSTEM: i64 = 1_577_836_800_000_000_000;

    #[test]
    fn a_following_clock_reads_the_clock_its_flag_names_and_a_fixed_one_keeps_its_choice() {
        let (sim, on) = (Arc::new(AtomicI64::new(42)), Arc::new(AtomicBool::new(true)));
        let following = NodeClock {
            source: ClockSource::Following(Arc::clone(&sim), Arc::clone(&on)),
        };
        let fixed = NodeClock {
            source: ClockSource::Sim(Arc::clone(&sim)),
        };
        assert_eq!(
            (following.now_nanos(), fixed.now_nanos()),
            (42, 42),
            "the latest /clock"
        );
        on.store(false, Ordering::Release);
        assert!(following.now_nanos() > SYSTEM);
        assert_eq!(fixed.now_nanos(), 42, "a fixed handle stays on /clock");
        on.store(true, Ordering::Release);
        sim.store(43, Ordering::Release);
        assert_eq!(following.now_nanos(), 43);
        assert!(NodeClock::system().now_nanos() > SYSTEM);
    }
}
