//! Typed parameter declarations, ROS 2 YAML parameter files and `-p` overrides.
//!
//! A node declares a table of [`ParamSpec`]s (name, default, description, constraint). Start-up
//! values come from the defaults, then every `--params-file` in order, then every `-p`, and an
//! invalid value stops the node with a clear error. Later changes through the parameter
//! services are checked by the same specs (see [`crate::node`]); an invalid set is refused with
//! a reason and changes nothing.
//!
//! File format (the one `ros2 param dump` writes and ROS 2 launch files pass):
//! ```yaml
//! chassis:                 # node name; also /ns/name, /**, /**/name, /ns/*
//!   ros__parameters:
//!     model: car_like
//!     limits:              # nested maps become dotted names: limits.v_max
//!       v_max: 0.5
//! ```
//! A key without a leading `/` matches the node's name in any namespace, so one file configures
//! a robot whether or not it runs under `-r __ns:=/robot1`.

use crate::args::ParamArg;
use ros2_client::parameters::{NumericRange, ParameterDescriptor, ParameterType};
use ros2_client::ParameterValue;
use serde_norway::Value;
use std::collections::BTreeMap;
use thiserror::Error;

/// A problem with start-up parameters; the node does not start.
#[derive(Debug, Error)]
pub enum ParamError {
    #[error("cannot read parameter file {path}: {source}")]
    Read { path: String, source: std::io::Error },
    #[error("parameter file {path} is not valid YAML: {source}")]
    Yaml { path: String, source: serde_norway::Error },
    #[error("parameter file {path}: {reason}")]
    Format { path: String, reason: String },
    #[error("parameter `{name}` from {origin}: {reason}")]
    Invalid {
        name: String,
        origin: String,
        reason: String,
    },
    #[error("parameters are inconsistent: {0}")]
    Inconsistent(String),
}

/// What values a parameter accepts beyond its type.
#[derive(Debug, Clone, PartialEq)]
pub enum Constraint {
    /// Any value of the type (doubles must still be finite).
    Any,
    /// A numeric range; `None` means unbounded on that side. The bools say "inclusive".
    Range {
        min: Option<(f64, bool)>,
        max: Option<(f64, bool)>,
    },
    /// One of these strings.
    Choices(Vec<String>),
    /// An array of exactly this many elements.
    Length(usize),
}

impl std::fmt::Display for Constraint {
    /// The constraint for `--help`: `[0, 1.5707963267948966]`, `(0, ∞)`, `one of a, b`,
    /// `3 elements`, or nothing.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Constraint::Any => Ok(()),
            Constraint::Range { min, max } => {
                let (open, lo) = match min {
                    Some((m, true)) => ("[", m.to_string()),
                    Some((m, false)) => ("(", m.to_string()),
                    None => ("(", "−∞".to_owned()),
                };
                let (hi, close) = match max {
                    Some((m, true)) => (m.to_string(), "]"),
                    Some((m, false)) => (m.to_string(), ")"),
                    None => ("∞".to_owned(), ")"),
                };
                write!(f, "{open}{lo}, {hi}{close}")
            }
            Constraint::Choices(c) => write!(f, "one of {}", c.join(", ")),
            Constraint::Length(n) => write!(f, "{n} elements"),
        }
    }
}

/// One declared parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpec {
    pub name: String,
    pub default: ParameterValue,
    pub description: String,
    /// Refuse changes after start-up (e.g. the chassis model): restart the node instead.
    pub read_only: bool,
    pub constraint: Constraint,
}

impl ParamSpec {
    fn new(name: &str, default: ParameterValue, description: &str) -> Self {
        ParamSpec {
            name: name.to_owned(),
            default,
            description: description.to_owned(),
            read_only: false,
            constraint: Constraint::Any,
        }
    }

    /// A floating-point parameter.
    pub fn double(name: &str, default: f64, description: &str) -> Self {
        Self::new(name, ParameterValue::Double(default), description)
    }

    /// An integer parameter.
    pub fn integer(name: &str, default: i64, description: &str) -> Self {
        Self::new(name, ParameterValue::Integer(default), description)
    }

    /// A boolean parameter.
    pub fn boolean(name: &str, default: bool, description: &str) -> Self {
        Self::new(name, ParameterValue::Boolean(default), description)
    }

    /// A string parameter.
    pub fn string(name: &str, default: &str, description: &str) -> Self {
        Self::new(name, ParameterValue::String(default.to_owned()), description)
    }

    /// An array of doubles.
    pub fn doubles(name: &str, default: &[f64], description: &str) -> Self {
        Self::new(name, ParameterValue::DoubleArray(default.to_vec()), description)
    }

    /// A string array parameter.
    pub fn strings(name: &str, default: &[&str], description: &str) -> Self {
        let default = default.iter().map(|s| (*s).to_owned()).collect();
        Self::new(name, ParameterValue::StringArray(default), description)
    }

    /// Accept only values ≥ `min`.
    pub fn min(self, min: f64) -> Self {
        self.range(Some((min, true)), None)
    }

    /// Accept only values > `min`.
    pub fn above(self, min: f64) -> Self {
        self.range(Some((min, false)), None)
    }

    /// The `describe_parameters` answer for this declaration: description, read-only, the range
    /// (`floating_point_range` for doubles, `integer_range` for integers, step 0 = any value in
    /// it; an unbounded side is the type's extreme) and, for any constraint, its full text in
    /// `additional_constraints` (which also says whether a bound is open, e.g. `(0, ∞)`, and
    /// lists choices or array lengths, which a range cannot express).
    pub fn descriptor(&self) -> ParameterDescriptor {
        let range = match (&self.constraint, &self.default) {
            (Constraint::Range { min, max }, ParameterValue::Double(_) | ParameterValue::DoubleArray(_)) => {
                NumericRange::FloatingPointRange {
                    from_value: min.map_or(f64::MIN, |(m, _)| m),
                    to_value: max.map_or(f64::MAX, |(m, _)| m),
                    step: 0.0,
                }
            }
            (Constraint::Range { min, max }, ParameterValue::Integer(_) | ParameterValue::IntegerArray(_)) => {
                // The integers the range holds: an open bound excludes its own value.
                let from = min.map_or(i64::MIN, |(m, inclusive)| {
                    let c = m.ceil();
                    (if !inclusive && c == m { c + 1.0 } else { c }) as i64
                });
                let to = max.map_or(i64::MAX, |(m, inclusive)| {
                    let f = m.floor();
                    (if !inclusive && f == m { f - 1.0 } else { f }) as i64
                });
                NumericRange::IntegerRange {
                    from_value: from,
                    to_value: to,
                    step: 0,
                }
            }
            _ => NumericRange::NotSpecified,
        };
        ParameterDescriptor {
            name: self.name.clone(),
            param_type: ParameterType::NotSet,
            description: self.description.clone(),
            additional_constraints: self.constraint.to_string(),
            read_only: self.read_only,
            dynamic_typing: false,
            range,
        }
    }

    /// Accept only values in [min, max].
    pub fn within(self, min: f64, max: f64) -> Self {
        self.range(Some((min, true)), Some((max, true)))
    }

    fn range(mut self, min: Option<(f64, bool)>, max: Option<(f64, bool)>) -> Self {
        let (old_min, old_max) = match self.constraint {
            Constraint::Range { min, max } => (min, max),
            _ => (None, None),
        };
        self.constraint = Constraint::Range {
            min: min.or(old_min),
            max: max.or(old_max),
        };
        self
    }

    /// Accept only values ≤ `max`.
    pub fn max(self, max: f64) -> Self {
        self.range(None, Some((max, true)))
    }

    /// Accept only one of these strings.
    pub fn choices(mut self, choices: &[&str]) -> Self {
        self.constraint = Constraint::Choices(choices.iter().map(|s| (*s).to_owned()).collect());
        self
    }

    /// Accept only arrays of this length.
    pub fn length(mut self, n: usize) -> Self {
        self.constraint = Constraint::Length(n);
        self
    }

    /// Refuse changes after start-up.
    pub fn read_only(mut self) -> Self {
        self.read_only = true;
        self
    }

    /// Checks (and, from files and the command line, converts) a value for this parameter.
    /// Integers are accepted for doubles (`v_max: 1` in a file means 1.0).
    pub fn check(&self, value: &ParameterValue) -> Result<ParameterValue, String> {
        let value = match (&self.default, value) {
            (ParameterValue::Double(_), ParameterValue::Integer(i)) => ParameterValue::Double(*i as f64),
            (ParameterValue::DoubleArray(_), ParameterValue::IntegerArray(a)) => {
                ParameterValue::DoubleArray(a.iter().map(|i| *i as f64).collect())
            }
            _ => value.clone(),
        };
        if std::mem::discriminant(&value) != std::mem::discriminant(&self.default) {
            return Err(format!(
                "expected {}, got {}",
                type_name(&self.default),
                type_name(&value)
            ));
        }
        let numbers: Vec<f64> = match &value {
            ParameterValue::Double(d) => vec![*d],
            ParameterValue::Integer(i) => vec![*i as f64],
            ParameterValue::DoubleArray(a) => a.clone(),
            ParameterValue::IntegerArray(a) => a.iter().map(|i| *i as f64).collect(),
            _ => Vec::new(),
        };
        if let Some(bad) = numbers.iter().find(|x| !x.is_finite()) {
            return Err(format!("{bad} is not a finite number"));
        }
        match &self.constraint {
            Constraint::Any => {}
            Constraint::Range { min, max } => {
                for x in &numbers {
                    if let Some((m, inclusive)) = min
                        && (*x < *m || (!inclusive && *x == *m))
                    {
                        return Err(format!(
                            "{x} is below the minimum ({} {m})",
                            if *inclusive { "≥" } else { ">" }
                        ));
                    }
                    if let Some((m, inclusive)) = max
                        && (*x > *m || (!inclusive && *x == *m))
                    {
                        return Err(format!(
                            "{x} is above the maximum ({} {m})",
                            if *inclusive { "≤" } else { "<" }
                        ));
                    }
                }
            }
            Constraint::Choices(choices) => {
                if let ParameterValue::String(s) = &value
                    && !choices.contains(s)
                {
                    return Err(format!("`{s}` is not one of {}", choices.join(", ")));
                }
            }
            Constraint::Length(n) => {
                let len = array_len(&value);
                if len != Some(*n) {
                    return Err(format!("expected {n} elements, got {}", len.unwrap_or(1)));
                }
            }
        }
        Ok(value)
    }
}

fn array_len(v: &ParameterValue) -> Option<usize> {
    match v {
        ParameterValue::ByteArray(a) => Some(a.len()),
        ParameterValue::BooleanArray(a) => Some(a.len()),
        ParameterValue::IntegerArray(a) => Some(a.len()),
        ParameterValue::DoubleArray(a) => Some(a.len()),
        ParameterValue::StringArray(a) => Some(a.len()),
        _ => None,
    }
}

/// A short name of a value's type, for messages.
pub fn type_name(v: &ParameterValue) -> &'static str {
    match v {
        ParameterValue::NotSet => "not set",
        ParameterValue::Boolean(_) => "bool",
        ParameterValue::Integer(_) => "integer",
        ParameterValue::Double(_) => "double",
        ParameterValue::String(_) => "string",
        ParameterValue::ByteArray(_) => "byte array",
        ParameterValue::BooleanArray(_) => "bool array",
        ParameterValue::IntegerArray(_) => "integer array",
        ParameterValue::DoubleArray(_) => "double array",
        ParameterValue::StringArray(_) => "string array",
    }
}

/// The current value of every declared parameter, with typed accessors.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ParamValues {
    values: BTreeMap<String, ParameterValue>,
}

impl ParamValues {
    /// The defaults of a table.
    pub fn defaults(specs: &[ParamSpec]) -> Self {
        ParamValues {
            values: specs.iter().map(|s| (s.name.clone(), s.default.clone())).collect(),
        }
    }

    /// Sets a value (no checks; see [`ParamSpec::check`]).
    pub fn set(&mut self, name: &str, value: ParameterValue) {
        self.values.insert(name.to_owned(), value);
    }

    /// A value by name.
    pub fn get(&self, name: &str) -> Option<&ParameterValue> {
        self.values.get(name)
    }

    /// All values, sorted by name.
    pub fn iter(&self) -> impl Iterator<Item = (&String, &ParameterValue)> {
        self.values.iter()
    }

    fn typed<T>(&self, name: &str, want: &str, f: impl Fn(&ParameterValue) -> Option<T>) -> Result<T, String> {
        let v = self
            .values
            .get(name)
            .ok_or_else(|| format!("parameter `{name}` is not declared"))?;
        f(v).ok_or_else(|| format!("parameter `{name}` is {}, expected {want}", type_name(v)))
    }

    /// A double parameter.
    pub fn f64(&self, name: &str) -> Result<f64, String> {
        self.typed(name, "double", |v| match v {
            ParameterValue::Double(d) => Some(*d),
            _ => None,
        })
    }

    /// An integer parameter.
    pub fn i64(&self, name: &str) -> Result<i64, String> {
        self.typed(name, "integer", |v| match v {
            ParameterValue::Integer(i) => Some(*i),
            _ => None,
        })
    }

    /// A boolean parameter.
    pub fn bool(&self, name: &str) -> Result<bool, String> {
        self.typed(name, "bool", |v| match v {
            ParameterValue::Boolean(b) => Some(*b),
            _ => None,
        })
    }

    /// A string parameter.
    pub fn string(&self, name: &str) -> Result<String, String> {
        self.typed(name, "string", |v| match v {
            ParameterValue::String(s) => Some(s.clone()),
            _ => None,
        })
    }

    /// A double-array parameter.
    pub fn f64s(&self, name: &str) -> Result<Vec<f64>, String> {
        self.typed(name, "double array", |v| match v {
            ParameterValue::DoubleArray(a) => Some(a.clone()),
            _ => None,
        })
    }
}

/// Converts a YAML value to a parameter value.
pub fn yaml_to_param(v: &Value) -> Result<ParameterValue, String> {
    Ok(match v {
        Value::Bool(b) => ParameterValue::Boolean(*b),
        Value::Number(n) => match n.as_i64() {
            Some(i) => ParameterValue::Integer(i),
            None => ParameterValue::Double(n.as_f64().ok_or("number out of range")?),
        },
        Value::String(s) => ParameterValue::String(s.clone()),
        Value::Sequence(items) => {
            if items.iter().all(|i| matches!(i, Value::Bool(_))) && !items.is_empty() {
                ParameterValue::BooleanArray(items.iter().filter_map(Value::as_bool).collect())
            } else if items.iter().all(|i| i.as_i64().is_some()) && !items.is_empty() {
                ParameterValue::IntegerArray(items.iter().filter_map(Value::as_i64).collect())
            } else if items.iter().all(|i| i.as_f64().is_some()) && !items.is_empty() {
                ParameterValue::DoubleArray(items.iter().filter_map(Value::as_f64).collect())
            } else if items.iter().all(|i| i.as_str().is_some()) {
                ParameterValue::StringArray(items.iter().filter_map(|i| i.as_str().map(str::to_owned)).collect())
            } else {
                return Err("arrays must hold one type (bools, numbers or strings)".into());
            }
        }
        Value::Null => return Err("no value (null)".into()),
        Value::Mapping(_) => return Err("a map is not a parameter value".into()),
        Value::Tagged(t) => return yaml_to_param(&t.value),
    })
}

/// Parses a `-p name:=value` value the way `ros2 param set` does (as YAML).
pub fn parse_param_text(text: &str) -> Result<ParameterValue, String> {
    let v: Value = serde_norway::from_str(text).map_err(|e| format!("`{text}` is not a YAML value: {e}"))?;
    match v {
        // An empty value is the empty string, as in ROS.
        Value::Null if text.trim().is_empty() => Ok(ParameterValue::String(String::new())),
        other => yaml_to_param(&other),
    }
}

/// Does a node-name key of a parameter file select this node?
pub fn key_matches(key: &str, fully_qualified: &str, base_name: &str) -> bool {
    if key == "/**" || key == "**" || key == fully_qualified {
        return true;
    }
    if !key.starts_with('/') {
        return key == base_name;
    }
    if let Some(name) = key.strip_prefix("/**/") {
        return name == base_name;
    }
    // `*` matches exactly one token.
    let k: Vec<&str> = key.trim_start_matches('/').split('/').collect();
    let n: Vec<&str> = fully_qualified.trim_start_matches('/').split('/').collect();
    k.len() == n.len() && k.iter().zip(&n).all(|(a, b)| *a == "*" || a == b)
}

fn flatten(prefix: &str, v: &Value, out: &mut Vec<(String, Value)>) {
    match v {
        Value::Mapping(map) => {
            for (k, child) in map {
                let key = match k {
                    Value::String(s) => s.clone(),
                    other => serde_norway::to_string(other).unwrap_or_default().trim().to_owned(),
                };
                let name = if prefix.is_empty() {
                    key
                } else {
                    format!("{prefix}.{key}")
                };
                flatten(&name, child, out);
            }
        }
        other => out.push((prefix.to_owned(), other.clone())),
    }
}

/// One `name: value` of a parameter file that applies to a node.
#[derive(Debug, Clone, PartialEq)]
pub struct FileEntry {
    pub name: String,
    pub value: Value,
    /// From a wildcard section (`/**`, `*`): shared by every node of a robot, so a node that
    /// does not declare the name ignores it quietly.
    pub shared: bool,
}

/// The parameter entries of a parameter file's text that apply to a node, in file order.
pub fn file_entries(
    path: &str,
    text: &str,
    fully_qualified: &str,
    base_name: &str,
) -> Result<Vec<FileEntry>, ParamError> {
    let doc: Value = serde_norway::from_str(text).map_err(|source| ParamError::Yaml {
        path: path.to_owned(),
        source,
    })?;
    let format = |reason: &str| ParamError::Format {
        path: path.to_owned(),
        reason: reason.to_owned(),
    };
    let Value::Mapping(nodes) = doc else {
        return Err(format("expected a map of node names"));
    };
    // Node keys may nest (`robot1: chassis: ros__parameters:` is `/robot1/chassis`).
    let mut sections = Vec::new();
    collect_sections("", &nodes, &mut sections).map_err(|reason| format(&reason))?;
    let mut entries = Vec::new();
    for (key, params) in sections {
        if !key_matches(&key, fully_qualified, base_name) {
            continue;
        }
        let mut flat = Vec::new();
        flatten("", params, &mut flat);
        let shared = key.contains('*');
        entries.extend(flat.into_iter().map(|(name, value)| FileEntry { name, value, shared }));
    }
    Ok(entries)
}

/// The `ros__parameters` sections of a file with their (possibly nested) node keys.
fn collect_sections<'a>(
    prefix: &str,
    map: &'a serde_norway::Mapping,
    out: &mut Vec<(String, &'a Value)>,
) -> Result<(), String> {
    for (key, body) in map {
        let Some(key) = key.as_str() else {
            return Err("node names must be strings".into());
        };
        let full = if prefix.is_empty() {
            key.to_owned()
        } else {
            format!("{}/{}", prefix, key.trim_start_matches('/'))
        };
        match body {
            Value::Mapping(inner) => match inner.get("ros__parameters") {
                Some(params) => out.push((full, params)),
                None if inner.is_empty() => return Err(format!("`{full}` has no `ros__parameters` section")),
                None => collect_sections(&full, inner, out)?,
            },
            _ => return Err(format!("`{full}` has no `ros__parameters` section")),
        }
    }
    Ok(())
}

/// Start-up values: the outcome of defaults, files and `-p` overrides.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialParams {
    pub values: ParamValues,
    /// `use_sim_time`, built into every node.
    pub use_sim_time: bool,
    /// Things worth a warning (unknown parameters), already formatted.
    pub warnings: Vec<String>,
    /// The unknown parameters given to this node by name (not by `/**`): name, value, origin.
    pub unknown: Vec<(String, ParameterValue, String)>,
}

/// Computes the start-up values of a node's parameters.
pub fn initial_params(
    specs: &[ParamSpec],
    files: &[(String, String)],
    overrides: &[ParamArg],
    fully_qualified: &str,
    base_name: &str,
) -> Result<InitialParams, ParamError> {
    let mut values = ParamValues::defaults(specs);
    let mut use_sim_time = false;
    let mut warnings = Vec::new();
    let mut unknown = Vec::new();
    let mut apply = |name: &str, value: ParameterValue, origin: &str, shared: bool| -> Result<(), ParamError> {
        let invalid = |reason: String| ParamError::Invalid {
            name: name.to_owned(),
            origin: origin.to_owned(),
            reason,
        };
        if name == "use_sim_time" {
            match value {
                ParameterValue::Boolean(b) => use_sim_time = b,
                other => return Err(invalid(format!("expected bool, got {}", type_name(&other)))),
            }
            return Ok(());
        }
        match specs.iter().find(|s| s.name == name) {
            Some(spec) => values.set(name, spec.check(&value).map_err(invalid)?),
            None if shared => {}
            None => {
                warnings.push(format!("unknown parameter `{name}` from {origin} ignored"));
                unknown.push((name.to_owned(), value, origin.to_owned()));
            }
        }
        Ok(())
    };
    for (path, text) in files {
        for entry in file_entries(path, text, fully_qualified, base_name)? {
            let value = yaml_to_param(&entry.value).map_err(|reason| ParamError::Invalid {
                name: entry.name.clone(),
                origin: path.clone(),
                reason,
            })?;
            apply(&entry.name, value, path, entry.shared)?;
        }
    }
    for p in overrides
        .iter()
        .filter(|p| p.node.as_deref().is_none_or(|n| n == base_name))
    {
        let value = parse_param_text(&p.value).map_err(|reason| ParamError::Invalid {
            name: p.name.clone(),
            origin: "-p".into(),
            reason,
        })?;
        apply(&p.name, value, "-p", false)?;
    }
    Ok(InitialParams {
        values,
        use_sim_time,
        warnings,
        unknown,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn descriptors_carry_description_range_and_read_only() {
        let v = ParamSpec::double("v_max", 0.5, "max speed")
            .above(0.0)
            .max(2.0)
            .descriptor();
        assert_eq!((v.name.as_str(), v.description.as_str()), ("v_max", "max speed"));
        assert!(!v.read_only);
        assert!(matches!(
            v.range,
            NumericRange::FloatingPointRange { from_value, to_value, step }
                if from_value == 0.0 && to_value == 2.0 && step == 0.0
        ));
        assert_eq!(v.additional_constraints, "(0, 2]", "the open bound is said in words");
        // Integers: (0, 10) holds 1..=9; an unbounded side is the type's extreme.
        let n = ParamSpec::integer("n", 3, "count").above(0.0).max(10.0).descriptor();
        let n_range = match n.range {
            NumericRange::IntegerRange {
                from_value,
                to_value,
                step,
            } => (from_value, to_value, step),
            _ => panic!("an integer range"),
        };
        assert_eq!(n_range, (1, 10, 0));
        let m = ParamSpec::integer("m", 3, "count").min(-2.5).descriptor();
        assert!(matches!(
            m.range,
            NumericRange::IntegerRange {
                from_value: -2,
                to_value: i64::MAX,
                ..
            }
        ));
        let model = ParamSpec::string("model", "omni", "chassis model")
            .choices(&["car_like", "omni"])
            .read_only()
            .descriptor();
        assert!(model.read_only);
        assert!(matches!(model.range, NumericRange::NotSpecified));
        assert_eq!(model.additional_constraints, "one of car_like, omni");
    }

    fn specs() -> Vec<ParamSpec> {
        vec![
            ParamSpec::string("model", "car_like", "chassis model")
                .choices(&["car_like", "omni"])
                .read_only(),
            ParamSpec::double("limits.v_max", 0.5, "max speed").above(0.0),
            ParamSpec::integer("beams", 1081, "beams").min(2.0),
            ParamSpec::boolean("noise", false, "noise"),
            ParamSpec::doubles("mount", &[0.0, 0.0, 0.0], "x y yaw").length(3),
        ]
    }

    #[test]
    fn file_then_overrides_with_node_matching() {
        let file = "
/**:
  ros__parameters:
    use_sim_time: true
    beams: 100
    planner_only: 1
chassis:
  ros__parameters:
    model: omni
    limits:
      v_max: 1
    mount: [0.1, 0, 0.5]
    bogus: 3
other:
  ros__parameters:
    beams: 7
";
        let overrides = [
            ParamArg {
                node: None,
                name: "beams".into(),
                value: "200".into(),
            },
            ParamArg {
                node: Some("other".into()),
                name: "noise".into(),
                value: "true".into(),
            },
        ];
        let p = initial_params(
            &specs(),
            &[("f.yaml".into(), file.into())],
            &overrides,
            "/r1/chassis",
            "chassis",
        )
        .unwrap();
        assert!(p.use_sim_time);
        assert_eq!(p.values.string("model").unwrap(), "omni");
        assert_eq!(p.values.f64("limits.v_max").unwrap(), 1.0);
        assert_eq!(p.values.i64("beams").unwrap(), 200);
        assert!(!p.values.bool("noise").unwrap());
        assert_eq!(p.values.f64s("mount").unwrap(), [0.1, 0.0, 0.5]);
        assert_eq!(p.warnings, ["unknown parameter `bogus` from f.yaml ignored"]);
    }

    #[test]
    fn invalid_start_up_values_are_errors_with_reasons() {
        let bad = |file: &str| initial_params(&specs(), &[("f".into(), file.into())], &[], "/chassis", "chassis");
        let e = bad("chassis:\n  ros__parameters:\n    limits: {v_max: -1.0}\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("limits.v_max") && e.contains("minimum"), "{e}");
        let e = bad("chassis:\n  ros__parameters:\n    model: hovercraft\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("not one of"), "{e}");
        let e = bad("chassis:\n  ros__parameters:\n    beams: 2.5\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("expected integer"), "{e}");
        let e = bad("chassis:\n  ros__parameters:\n    mount: [1, 2]\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("3 elements"), "{e}");
        let e = bad("chassis:\n  ros__parameters:\n    limits: {v_max: .nan}\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("finite"), "{e}");
        assert!(bad("chassis: [1, 2]").is_err());
        assert!(bad("chassis:\n  params: {}\n").is_err());
        assert!(bad(": : :").is_err());
    }

    #[test]
    fn nested_node_keys_are_namespaces() {
        let file = "/robot1:\n  chassis:\n    ros__parameters:\n      beams: 42\nrobot2:\n  chassis:\n    ros__parameters:\n      beams: 7\n";
        let p = initial_params(
            &specs(),
            &[("f".into(), file.into())],
            &[],
            "/robot1/chassis",
            "chassis",
        )
        .unwrap();
        assert_eq!(p.values.i64("beams").unwrap(), 42);
    }

    #[test]
    fn constraints_read_as_intervals() {
        let text = |s: ParamSpec| s.constraint.to_string();
        assert_eq!(text(ParamSpec::double("a", 1.0, "").within(0.0, 2.0)), "[0, 2]");
        assert_eq!(text(ParamSpec::double("a", 1.0, "").above(0.0)), "(0, ∞)");
        assert_eq!(text(ParamSpec::double("a", 1.0, "").max(3.5)), "(−∞, 3.5]");
        assert_eq!(
            text(ParamSpec::string("m", "x", "").choices(&["x", "y"])),
            "one of x, y"
        );
        assert_eq!(text(ParamSpec::doubles("p", &[0.0; 3], "").length(3)), "3 elements");
        assert_eq!(text(ParamSpec::boolean("b", true, "")), "");
    }

    #[test]
    fn node_keys() {
        assert!(key_matches("/**", "/a/b", "b"));
        assert!(key_matches("/**/b", "/a/b", "b"));
        assert!(key_matches("b", "/a/b", "b"));
        assert!(key_matches("/a/b", "/a/b", "b"));
        assert!(key_matches("/a/*", "/a/b", "b"));
        assert!(!key_matches("/b", "/a/b", "b"));
        assert!(!key_matches("/*", "/a/b", "b"));
        assert!(!key_matches("c", "/a/b", "b"));
    }

    #[test]
    fn command_line_values_parse_as_yaml() {
        assert_eq!(parse_param_text("0.5").unwrap(), ParameterValue::Double(0.5));
        assert_eq!(parse_param_text("3").unwrap(), ParameterValue::Integer(3));
        assert_eq!(parse_param_text("true").unwrap(), ParameterValue::Boolean(true));
        assert_eq!(parse_param_text("omni").unwrap(), ParameterValue::String("omni".into()));
        assert_eq!(
            parse_param_text("[1, 2.5]").unwrap(),
            ParameterValue::DoubleArray(vec![1.0, 2.5])
        );
        assert_eq!(parse_param_text("").unwrap(), ParameterValue::String(String::new()));
    }
}
