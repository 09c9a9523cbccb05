//! Parameter tables for the documentation, generated from the one declaration.
//!
//! Every executable answers `--params-markdown` with its parameter table in Markdown (name,
//! type, default, allowed values, description), built from the same [`ParamSpec`]s as `--help`,
//! `describe_parameters` and the checks. The pages in `docs/` hold that output between two
//! marker comments; `tests/test_docs.py` fails when a page's table differs from what the
//! executable prints, and `tests/update_docs.py` rewrites the tables.
//!
//! ```
//! use mobil_ros::docs::params_markdown;
//! use mobil_ros::ParamSpec;
//! let table = params_markdown(&[ParamSpec::double("v_max", 0.5, "speed limit [m/s]").above(0.0)]);
//! assert_eq!(
//!     table,
//!     "| parameter | type | default | allowed | description |\n\
//!      |---|---|---|---|---|\n\
//!      | `v_max` | double | `0.5` | (0, ∞) | speed limit [m/s] |\n"
//! );
//! ```

use crate::params::{type_name, Constraint, ParamSpec};
use ros2_client::ParameterValue;
use std::fmt::Write as _;

/// The option every executable answers with its parameter table.
pub const PARAMS_MARKDOWN_OPTION: &str = "--params-markdown";

/// A value as a Markdown code span: `0.5`, `"odom"`, `[0, 0, 0]`, `true`.
pub fn value_markdown(v: &ParameterValue) -> String {
    let text = match v {
        ParameterValue::String(s) => format!("\"{s}\""),
        ParameterValue::Double(d) => format!("{d}"),
        ParameterValue::Integer(i) => format!("{i}"),
        ParameterValue::Boolean(b) => format!("{b}"),
        ParameterValue::DoubleArray(a) => list(a),
        ParameterValue::IntegerArray(a) => list(a),
        ParameterValue::BooleanArray(a) => list(a),
        ParameterValue::StringArray(a) => format!("{a:?}"),
        other => format!("{other:?}"),
    };
    code(&text)
}

fn list<T: std::fmt::Display>(items: &[T]) -> String {
    let parts: Vec<String> = items.iter().map(ToString::to_string).collect();
    format!("[{}]", parts.join(", "))
}

/// Text as a Markdown code span (backticks inside are doubled around).
fn code(text: &str) -> String {
    if text.contains('`') {
        format!("`` {text} ``")
    } else {
        format!("`{text}`")
    }
}

/// A table cell: pipes escaped, line breaks as spaces.
pub fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace('\n', " ")
}

/// A Markdown table of `header` and `rows` (every cell already Markdown; see [`cell`]).
pub fn markdown_table(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "| {} |", header.join(" | "));
    let _ = writeln!(s, "|{}", "---|".repeat(header.len()));
    for row in rows {
        let _ = writeln!(s, "| {} |", row.join(" | "));
    }
    s
}

/// The parameter table of these declarations, in declaration order: name, type, default,
/// allowed values (the range, choices or array length; "read-only" for a parameter only a
/// restart changes) and description.
pub fn params_markdown(specs: &[ParamSpec]) -> String {
    let rows: Vec<Vec<String>> = specs
        .iter()
        .map(|p| {
            let mut allowed = match &p.constraint {
                Constraint::Any => String::new(),
                Constraint::Choices(c) => c.iter().map(|c| code(c)).collect::<Vec<_>>().join(", "),
                other => other.to_string(),
            };
            if p.read_only {
                allowed = if allowed.is_empty() {
                    "read-only".to_owned()
                } else {
                    format!("{allowed}; read-only")
                };
            }
            vec![
                code(&p.name),
                type_name(&p.default).to_owned(),
                cell(&value_markdown(&p.default)),
                cell(&allowed),
                cell(&p.description),
            ]
        })
        .collect();
    if rows.is_empty() {
        return "This executable declares no parameters.\n".to_owned();
    }
    markdown_table(&["parameter", "type", "default", "allowed", "description"], &rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_of_declaration_has_its_row() {
        let specs = [
            ParamSpec::string("model", "car_like", "chassis | model")
                .choices(&["omni", "car_like"])
                .read_only(),
            ParamSpec::integer("sectors", 8, "sector count").within(4.0, 64.0),
            ParamSpec::boolean("free", false, "unseen sectors\nare free"),
            ParamSpec::doubles("pose", &[0.0, 0.5, -1.25], "x, y, yaw").length(3),
            ParamSpec::string("frame", "", "frame").read_only(),
            ParamSpec::string("sep", "a|b", "a separator"),
        ];
        let table = params_markdown(&specs);
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines.len(), 2 + specs.len());
        assert_eq!(
            lines[2],
            "| `model` | string | `\"car_like\"` | `omni`, `car_like`; read-only | chassis \\| model |"
        );
        assert_eq!(lines[3], "| `sectors` | integer | `8` | [4, 64] | sector count |");
        assert_eq!(lines[4], "| `free` | bool | `false` |  | unseen sectors are free |");
        assert_eq!(
            lines[5],
            "| `pose` | double array | `[0, 0.5, -1.25]` | 3 elements | x, y, yaw |"
        );
        assert_eq!(lines[6], "| `frame` | string | `\"\"` | read-only | frame |");
        assert_eq!(lines[7], "| `sep` | string | `\"a\\|b\"` |  | a separator |");
    }

    #[test]
    fn no_parameters_is_said_in_words() {
        assert_eq!(params_markdown(&[]), "This executable declares no parameters.\n");
    }
}
