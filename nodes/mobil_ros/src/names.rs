//! ROS 2 name resolution and remapping (the rules of the ROS 2 design article "Topic and
//! Service name mapping to DDS"): relative names live in the node's namespace, `~` is the node
//! itself, `{node}` and `{ns}` are substituted, and `-r from:=to` rules are applied to the
//! resolved name, first match wins.

use crate::args::Remap;
use thiserror::Error;

/// An invalid ROS name.
#[derive(Debug, Error, PartialEq, Eq)]
#[error("invalid ROS name `{name}`: {reason}")]
pub struct NameError {
    pub name: String,
    pub reason: &'static str,
}

/// Resolves names for one node.
#[derive(Debug, Clone)]
pub struct NameResolver {
    namespace: String,
    node: String,
    remaps: Vec<(String, String)>,
}

fn bad(name: &str, reason: &'static str) -> NameError {
    NameError {
        name: name.to_owned(),
        reason,
    }
}

/// Checks a fully qualified name: `/a/b_c`, tokens of `[A-Za-z0-9_]` not starting with a digit.
fn check_absolute(name: &str) -> Result<(), NameError> {
    let Some(rest) = name.strip_prefix('/') else {
        return Err(bad(name, "not absolute"));
    };
    if rest.is_empty() {
        return Err(bad(name, "empty"));
    }
    for token in rest.split('/') {
        if token.is_empty() {
            return Err(bad(name, "empty token (`//` or a trailing `/`)"));
        }
        if token.starts_with(|c: char| c.is_ascii_digit()) {
            return Err(bad(name, "a token starts with a digit"));
        }
        if !token.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(bad(name, "only letters, digits, `_` and `/` are allowed"));
        }
        if token.contains("__") {
            return Err(bad(name, "repeated `_`"));
        }
    }
    Ok(())
}

/// Normalises a namespace to `/` or `/a/b` (no trailing slash).
pub fn normalize_namespace(ns: &str) -> Result<String, NameError> {
    let trimmed = ns.trim_end_matches('/');
    if trimmed.is_empty() {
        return Ok("/".to_owned());
    }
    let absolute = if trimmed.starts_with('/') {
        trimmed.to_owned()
    } else {
        format!("/{trimmed}")
    };
    check_absolute(&absolute)?;
    Ok(absolute)
}

impl NameResolver {
    /// A resolver for node `node` in namespace `namespace`, with the remap rules that apply to it.
    pub fn new(namespace: &str, node: &str, remaps: &[Remap]) -> Result<Self, NameError> {
        let namespace = normalize_namespace(namespace)?;
        if node.is_empty() || node.contains('/') {
            return Err(bad(node, "a node name is one token"));
        }
        check_absolute(&format!("/{node}"))?;
        let mut resolver = NameResolver {
            namespace,
            node: node.to_owned(),
            remaps: Vec::new(),
        };
        let topic_rules = remaps.iter().filter(|r| !r.from.starts_with("__"));
        for rule in topic_rules.filter(|r| r.node.as_deref().is_none_or(|n| n == node)) {
            let from = resolver.expand(&rule.from)?;
            let to = resolver.expand(&rule.to)?;
            resolver.remaps.push((from, to));
        }
        Ok(resolver)
    }

    /// The node's namespace (`/` or `/a/b`).
    pub fn namespace(&self) -> &str {
        &self.namespace
    }

    /// The node's name.
    pub fn node(&self) -> &str {
        &self.node
    }

    /// The node's fully qualified name, e.g. `/robot1/chassis`.
    pub fn fully_qualified_node(&self) -> String {
        join(&self.namespace, &self.node)
    }

    /// Expands a name to its fully qualified form, without remapping.
    pub fn expand(&self, name: &str) -> Result<String, NameError> {
        let mut name = name.replace("{node}", &self.node);
        for key in ["{ns}", "{namespace}"] {
            name = if self.namespace == "/" {
                name.replace(&format!("{key}/"), "/").replace(key, "/")
            } else {
                name.replace(key, &self.namespace)
            };
        }
        let full = if name == "~" {
            self.fully_qualified_node()
        } else if let Some(rest) = name.strip_prefix("~/") {
            join(&self.fully_qualified_node(), rest)
        } else if name.starts_with('/') {
            name.clone()
        } else if name.is_empty() {
            return Err(bad(&name, "empty"));
        } else {
            join(&self.namespace, &name)
        };
        check_absolute(&full)?;
        Ok(full)
    }

    /// Expands and remaps a topic or service name.
    pub fn resolve(&self, name: &str) -> Result<String, NameError> {
        let full = self.expand(name)?;
        Ok(self
            .remaps
            .iter()
            .find(|(from, _)| *from == full)
            .map_or(full, |(_, to)| to.clone()))
    }
}

fn join(ns: &str, rest: &str) -> String {
    if ns == "/" {
        format!("/{rest}")
    } else {
        format!("{ns}/{rest}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn remap(from: &str, to: &str) -> Remap {
        Remap {
            node: None,
            from: from.into(),
            to: to.into(),
        }
    }

    #[test]
    fn expands_relative_private_and_absolute_names() {
        let r = NameResolver::new("/robot1", "chassis", &[]).unwrap();
        assert_eq!(r.resolve("cmd_vel").unwrap(), "/robot1/cmd_vel");
        assert_eq!(r.resolve("/cmd_vel").unwrap(), "/cmd_vel");
        assert_eq!(r.resolve("~/status").unwrap(), "/robot1/chassis/status");
        assert_eq!(r.resolve("{node}/status").unwrap(), "/robot1/chassis/status");
        assert_eq!(r.resolve("{ns}/scan").unwrap(), "/robot1/scan");
        assert_eq!(r.resolve("{namespace}/a/b").unwrap(), "/robot1/a/b");
        let root = NameResolver::new("", "sim", &[]).unwrap();
        assert_eq!(root.resolve("scan").unwrap(), "/scan");
        assert_eq!(root.resolve("~/markers").unwrap(), "/sim/markers");
        assert_eq!(root.fully_qualified_node(), "/sim");
        assert_eq!(root.resolve("{ns}/scan").unwrap(), "/scan");
    }

    #[test]
    fn remaps_apply_to_resolved_names_and_per_node() {
        let rules = [
            remap("cmd_vel", "/teleop/cmd_vel"),
            Remap {
                node: Some("other".into()),
                from: "scan".into(),
                to: "front_scan".into(),
            },
            Remap {
                node: Some("chassis".into()),
                from: "odom".into(),
                to: "wheel_odom".into(),
            },
        ];
        let r = NameResolver::new("/r1", "chassis", &rules).unwrap();
        assert_eq!(r.resolve("cmd_vel").unwrap(), "/teleop/cmd_vel");
        assert_eq!(r.resolve("/r1/cmd_vel").unwrap(), "/teleop/cmd_vel");
        assert_eq!(r.resolve("scan").unwrap(), "/r1/scan");
        assert_eq!(r.resolve("odom").unwrap(), "/r1/wheel_odom");
    }

    #[test]
    fn refuses_invalid_names() {
        let r = NameResolver::new("/", "n", &[]).unwrap();
        assert!(r.resolve("a//b").is_err());
        assert!(r.resolve("9lives").is_err());
        assert!(r.resolve("sp ace").is_err());
        assert!(r.resolve("").is_err());
        assert!(NameResolver::new("/ok", "bad/node", &[]).is_err());
        assert!(normalize_namespace("/a//b").is_err());
        assert_eq!(normalize_namespace("robot1/").unwrap(), "/robot1");
    }
}
