//! The ROS 2 command-line arguments every executable of the suite takes.
//!
//! ```text
//! chassis_node [node options] --ros-args --params-file params/mobil2.yaml -p model:=omni \
//!     -r cmd_vel:=/teleop/cmd_vel -r __ns:=/robot1 -r __node:=base --log-level debug
//! ```
//!
//! Everything between `--ros-args` and a lone `--` (or the end) is a ROS argument; several
//! `--ros-args` sections may appear. What remains is left for the executable's own options.

use thiserror::Error;

/// A remapping rule `from:=to`, optionally limited to one node (`node:from:=to`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Remap {
    /// Only applies to the node with this name, when set.
    pub node: Option<String>,
    pub from: String,
    pub to: String,
}

/// A parameter given on the command line (`-p name:=value`); the value is parsed as YAML.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ParamArg {
    pub node: Option<String>,
    pub name: String,
    pub value: String,
}

/// The parsed ROS arguments.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RosArgs {
    /// `--params-file` paths, in the order given (later files win).
    pub params_files: Vec<String>,
    /// `-p` overrides, in the order given (they win over files).
    pub params: Vec<ParamArg>,
    /// `-r` rules other than `__ns` and `__node`.
    pub remaps: Vec<Remap>,
    /// `-r __ns:=/ns`.
    pub namespace: Option<String>,
    /// `-r __node:=name` (also `__name`).
    pub node_name: Option<String>,
    /// `--log-level LEVEL` (`debug`, `info`, `warn`, `error`, `fatal`, or `logger:=level`).
    pub log_level: Option<String>,
}

impl RosArgs {
    /// The namespace for a node whose default name is `default_node` (`-r __ns:=` or
    /// `-r default_node:__ns:=`, the latter winning).
    pub fn namespace_for(&self, default_node: &str) -> Option<&str> {
        self.scoped("__ns", default_node).or(self.namespace.as_deref())
    }

    /// The name for a node whose default name is `default_node`.
    pub fn node_name_for(&self, default_node: &str) -> Option<&str> {
        self.scoped("__node", default_node).or(self.node_name.as_deref())
    }

    fn scoped(&self, key: &str, node: &str) -> Option<&str> {
        self.remaps
            .iter()
            .rev()
            .find(|r| r.from == key && r.node.as_deref() == Some(node))
            .map(|r| r.to.as_str())
    }
}

/// A malformed ROS argument.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum ArgsError {
    #[error("`{0}` needs a value")]
    MissingValue(String),
    #[error("`{flag} {value}`: expected `name:=value`")]
    NotAssignment { flag: String, value: String },
    #[error(
        "unknown ROS argument `{0}` (supported: --params-file, -p/--param, -r/--remap, --log-level, -e/--enclave)"
    )]
    Unknown(String),
}

/// Splits `argv` (without the program name) into the executable's own arguments and the ROS ones.
pub fn split_ros_args<I, S>(argv: I) -> Result<(Vec<String>, RosArgs), ArgsError>
where
    I: IntoIterator<Item = S>,
    S: Into<String>,
{
    let mut own = Vec::new();
    let mut ros = RosArgs::default();
    let mut iter = argv.into_iter().map(Into::into);
    let mut in_ros = false;
    while let Some(arg) = iter.next() {
        if arg == "--ros-args" {
            in_ros = true;
            continue;
        }
        if !in_ros {
            own.push(arg);
            continue;
        }
        let mut value_of = |flag: &str| iter.next().ok_or_else(|| ArgsError::MissingValue(flag.to_owned()));
        match arg.as_str() {
            "--" => in_ros = false,
            "--params-file" => ros.params_files.push(value_of(&arg)?),
            "-p" | "--param" => {
                let v = value_of(&arg)?;
                let (node, name, value) = assignment(&arg, &v)?;
                ros.params.push(ParamArg { node, name, value });
            }
            "-r" | "--remap" => {
                let v = value_of(&arg)?;
                let (node, from, to) = assignment(&arg, &v)?;
                // `__ns`/`__node` for every node go to their fields; node-scoped ones
                // (`chassis:__ns:=/r1`) stay rules, applied by the node they name.
                match (from.as_str(), &node) {
                    ("__ns", None) => ros.namespace = Some(to),
                    ("__node" | "__name", None) => ros.node_name = Some(to),
                    ("__name", Some(_)) => ros.remaps.push(Remap {
                        node,
                        from: "__node".into(),
                        to,
                    }),
                    _ => ros.remaps.push(Remap { node, from, to }),
                }
            }
            "--log-level" => ros.log_level = Some(value_of(&arg)?),
            "-e" | "--enclave" => {
                value_of(&arg)?;
            }
            "--disable-rosout-logs"
            | "--enable-rosout-logs"
            | "--disable-stdout-logs"
            | "--enable-stdout-logs"
            | "--disable-external-lib-logs"
            | "--enable-external-lib-logs" => {}
            _ => return Err(ArgsError::Unknown(arg)),
        }
    }
    Ok((own, ros))
}

/// Parses `[node:]name:=value`.
fn assignment(flag: &str, text: &str) -> Result<(Option<String>, String, String), ArgsError> {
    let not_assignment = || ArgsError::NotAssignment {
        flag: flag.to_owned(),
        value: text.to_owned(),
    };
    let (lhs, value) = text.split_once(":=").ok_or_else(not_assignment)?;
    // `node:name` — but a name may itself start with `/` or `~`; only a plain prefix is a node.
    let (node, name) = match lhs.split_once(':') {
        Some((node, name)) if !node.is_empty() && !node.contains('/') => (Some(node.to_owned()), name),
        _ => (None, lhs),
    };
    if name.is_empty() {
        return Err(not_assignment());
    }
    Ok((node, name.to_owned(), value.to_owned()))
}

/// The text appended to every executable's `--help`.
pub const ROS_ARGS_HELP: &str = "\
ROS arguments (after --ros-args, up to an optional --):
  --params-file FILE     ROS 2 YAML parameter file (node_name: ros__parameters: ...)
  -p, --param NAME:=V    set a parameter (V is YAML: 1, 0.5, true, text, [1, 2])
  -r, --remap FROM:=TO   remap a topic/service name; -r __ns:=/ns sets the namespace,
                         -r __node:=name the node name
  --log-level LEVEL      debug | info | warn | error (RUST_LOG also works)
Environment: ROS_DOMAIN_ID selects the DDS domain (default 0).";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_own_and_ros_arguments() {
        let (own, ros) = split_ros_args([
            "--verbose",
            "--ros-args",
            "--params-file",
            "a.yaml",
            "-p",
            "model:=omni",
            "-r",
            "cmd_vel:=/teleop/cmd_vel",
            "-r",
            "__ns:=/robot1",
            "-r",
            "__node:=base",
            "--",
            "extra",
            "--ros-args",
            "--param",
            "chassis:v_max:=0.3",
            "--log-level",
            "debug",
        ])
        .unwrap();
        assert_eq!(own, ["--verbose", "extra"]);
        assert_eq!(ros.params_files, ["a.yaml"]);
        assert_eq!(
            ros.params,
            [
                ParamArg {
                    node: None,
                    name: "model".into(),
                    value: "omni".into()
                },
                ParamArg {
                    node: Some("chassis".into()),
                    name: "v_max".into(),
                    value: "0.3".into()
                },
            ]
        );
        assert_eq!(
            ros.remaps,
            [Remap {
                node: None,
                from: "cmd_vel".into(),
                to: "/teleop/cmd_vel".into()
            }]
        );
        assert_eq!(ros.namespace.as_deref(), Some("/robot1"));
        assert_eq!(ros.node_name.as_deref(), Some("base"));
        assert_eq!(ros.log_level.as_deref(), Some("debug"));
    }

    #[test]
    fn node_scoped_namespace_and_name() {
        let (_, ros) = split_ros_args([
            "--ros-args",
            "-r",
            "chassis:__ns:=/r1",
            "-r",
            "sim:__node:=plant",
            "-r",
            "__ns:=/all",
        ])
        .unwrap();
        assert_eq!(ros.namespace_for("chassis"), Some("/r1"));
        assert_eq!(ros.namespace_for("sim"), Some("/all"));
        assert_eq!(ros.node_name_for("sim"), Some("plant"));
        assert_eq!(ros.node_name_for("chassis"), None);
    }

    #[test]
    fn absolute_remap_source_is_not_a_node_prefix() {
        let (_, ros) = split_ros_args(["--ros-args", "-r", "/scan:=/front/scan"]).unwrap();
        assert_eq!(
            ros.remaps[0],
            Remap {
                node: None,
                from: "/scan".into(),
                to: "/front/scan".into()
            }
        );
    }

    #[test]
    fn malformed_arguments_are_errors() {
        assert_eq!(
            split_ros_args(["--ros-args", "-p"]),
            Err(ArgsError::MissingValue("-p".into()))
        );
        assert!(matches!(
            split_ros_args(["--ros-args", "-p", "novalue"]),
            Err(ArgsError::NotAssignment { .. })
        ));
        assert!(matches!(
            split_ros_args(["--ros-args", "-p", ":=3"]),
            Err(ArgsError::NotAssignment { .. })
        ));
        assert_eq!(
            split_ros_args(["--ros-args", "--bogus"]),
            Err(ArgsError::Unknown("--bogus".into()))
        );
    }
}
