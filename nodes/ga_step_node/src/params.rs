//! `--params FILE`'s keys as the documentation lists them: the values each accepts and what it
//! is, as a Markdown table with the built-in defaults. Reading the file (which keys it may
//! set, the options it may not) is `mobil_ga_step::params`, tested there.

use mobil_ga_step::GaSetup;
use mobil_ros::docs::{cell, markdown_table};
use mobil_ros::params::Constraint;
use serde_norway::Value;

/// One key of the parameter file as the documentation lists it: the values it accepts (the
/// library's checks; a test probes each bound) and what it is.
#[derive(Debug, Clone)]
pub struct KeyDoc {
    /// The key.
    pub key: &'static str,
    /// The values the setup's validation accepts.
    pub allowed: Constraint,
    /// What it is, with its unit.
    pub description: &'static str,
}

fn range(min: Option<(f64, bool)>, max: Option<(f64, bool)>) -> Constraint {
    Constraint::Range { min, max }
}

/// Every key a parameter file may set, documented, in the file's order.
pub fn key_docs() -> Vec<KeyDoc> {
    let doc = |key, allowed, description| KeyDoc {
        key,
        allowed,
        description,
    };
    let non_negative = || range(Some((0.0, true)), None);
    let positive = || range(Some((0.0, false)), None);
    vec![
        doc(
            "step_time",
            range(Some((0.0, false)), Some((3600.0, true))),
            "T [s]: the step's duration, 20 equal intervals; a whole number of 40 ms motion rows",
        ),
        doc(
            "standing_pose",
            Constraint::Length(10),
            "the first and last knot of every servo [rad], in genome order (RHipPitch … LAnkleRoll), each within its servo's limits",
        ),
        doc(
            "settle_time",
            non_negative(),
            "time simulated after the step with the standing pose held [s]; T_sim = T + settle_time",
        ),
        doc("forward_weight", non_negative(), "w [1/m]: fitness per metre of forward distance"),
        doc("fall_height", positive(), "h₀ [m]: the torso frame below this is a fall"),
        doc(
            "fall_tilt",
            range(Some((0.0, false)), Some((std::f64::consts::FRAC_PI_2, false))),
            "θ₀ [rad]: the torso tilted beyond this (pitch or roll) is a fall",
        ),
        doc(
            "step_min_forward",
            non_negative(),
            "Δx [m] that makes a non-falling step a forward step (the stop rule)",
        ),
        doc(
            "distance_on_fall",
            Constraint::Any,
            "count a fall's forward distance too (the example shape of docs/methods.md §8); needs robust_check false",
        ),
        doc(
            "backward_allowance",
            non_negative(),
            "b [m]: an upright individual scores 1 + w·max(0, Δx + b)",
        ),
        doc(
            "robust_check",
            Constraint::Any,
            "score each individual under a second solver setting too and keep the worse (built-in physics only)",
        ),
        doc(
            "physics",
            Constraint::Choices(vec!["webots".to_owned(), "dc-motor".to_owned()]),
            "the built-in physics' robot model: Webots' Nao, or the earlier DC-motor model",
        ),
        doc("blx_alpha", non_negative(), "α of BLX-α"),
        doc(
            "blx_variant",
            Constraint::Choices(vec!["per-knot".to_owned(), "single-draw".to_owned()]),
            "BLX-α's draws: one per knot and child, or the source's one draw for all knots",
        ),
        doc(
            "crossover_weight",
            non_negative(),
            "roulette share of crossover among offspring (with mutation_weight, sum > 0)",
        ),
        doc("mutation_weight", non_negative(), "roulette share of mutation among offspring"),
        doc(
            "mutation_picks",
            range(Some((0.0, true)), Some((1_000_000.0, true))),
            "(servo, interval) picks per mutation, with replacement",
        ),
        doc(
            "mutation_step",
            positive(),
            "half-width [rad] of the uniform move of each picked knot",
        ),
        doc(
            "level_window",
            non_negative(),
            "generations over which the mean fitness must rise, or the run stops; 0: never (--level-window overrides)",
        ),
        doc(
            "level_tolerance",
            non_negative(),
            "relative rise of the mean over level_window below which it has levelled off",
        ),
        doc(
            "stop_at_step",
            Constraint::Any,
            "stop at the first non-falling forward step",
        ),
    ]
}

/// The parameter file's keys as a Markdown table (key, type, default, allowed, description),
/// the defaults being the built-in setup's.
pub fn keys_markdown() -> String {
    let defaults = match serde_norway::to_value(GaSetup::default()) {
        Ok(v) => flatten(&v),
        Err(_) => Vec::new(),
    };
    let rows: Vec<Vec<String>> = key_docs()
        .iter()
        .map(|d| {
            let value = defaults.iter().find(|(k, _)| k == d.key).map(|(_, v)| v.clone());
            let (kind, default) = match &value {
                Some(Value::Bool(b)) => ("bool", b.to_string()),
                Some(Value::Number(n)) if n.is_f64() => {
                    ("double", n.as_f64().map_or_else(String::new, |x| x.to_string()))
                }
                Some(Value::Number(n)) => ("integer", n.to_string()),
                Some(Value::String(s)) => ("string", format!("\"{s}\"")),
                Some(Value::Sequence(items)) => (
                    "double array",
                    format!(
                        "[{}]",
                        items
                            .iter()
                            .map(|v| v.as_f64().map_or_else(|| "?".to_owned(), |x| x.to_string()))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ),
                _ => ("?", String::new()),
            };
            let allowed = match &d.allowed {
                Constraint::Choices(c) => c.iter().map(|c| format!("`{c}`")).collect::<Vec<_>>().join(", "),
                other => other.to_string(),
            };
            vec![
                format!("`{}`", d.key),
                kind.to_owned(),
                format!("`{default}`"),
                cell(&allowed),
                cell(d.description),
            ]
        })
        .collect();
    markdown_table(&["parameter", "type", "default", "allowed", "description"], &rows)
}

/// The (key, value) pairs of a serialised setup, one level down (`model`, `fitness`, `ga`).
fn flatten(v: &Value) -> Vec<(String, Value)> {
    let mut out = Vec::new();
    if let Value::Mapping(parts) = v {
        for part in parts.values() {
            if let Value::Mapping(m) = part {
                for (k, v) in m {
                    if let Some(k) = k.as_str() {
                        out.push((k.to_owned(), v.clone()));
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use mobil_ga_step::params::{known_keys, setup_from_yaml};

    const FILE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/nao_step.yaml");

    #[test]
    fn the_documented_keys_are_the_known_keys_in_the_files_order() {
        let documented: Vec<&str> = key_docs().iter().map(|d| d.key).collect();
        let mut known = known_keys();
        known.sort();
        let mut sorted = documented.clone();
        sorted.sort();
        assert_eq!(sorted, known);
        let text = std::fs::read_to_string(FILE).unwrap();
        let in_file: Vec<&str> = text
            .lines()
            .filter_map(|l| l.strip_prefix("    ")?.split_once(':').map(|(k, _)| k))
            .filter(|k| !k.starts_with(' ') && !k.starts_with('#'))
            .collect();
        assert_eq!(in_file, documented);
    }

    /// A file setting only `key: value`.
    fn accepts(key: &str, value: &str) -> bool {
        setup_from_yaml(&format!("ga_step:\n  ros__parameters:\n    {key}: {value}\n"), "f").is_ok()
    }

    #[test]
    fn every_documented_bound_is_the_validations() {
        let table = keys_markdown();
        for d in key_docs() {
            let row = table
                .lines()
                .find(|l| l.starts_with(&format!("| `{}` |", d.key)))
                .unwrap();
            let integer = row.contains("| integer |");
            let step = if integer { 1.0 } else { 0.04 };
            let show = |x: f64| {
                if integer {
                    format!("{}", x as i64)
                } else {
                    format!("{x}")
                }
            };
            match &d.allowed {
                Constraint::Range { min, max } => {
                    for (bound, inclusive, outward) in [min.map(|(m, i)| (m, i, -step)), max.map(|(m, i)| (m, i, step))]
                        .into_iter()
                        .flatten()
                    {
                        let (inside, outside) = if inclusive {
                            (bound, bound + outward)
                        } else {
                            (bound - outward, bound)
                        };
                        assert!(accepts(d.key, &show(inside)), "{} = {inside} refused", d.key);
                        assert!(!accepts(d.key, &show(outside)), "{} = {outside} accepted", d.key);
                    }
                }
                Constraint::Choices(choices) => {
                    for c in choices {
                        assert!(accepts(d.key, c), "{} = {c}", d.key);
                    }
                    assert!(!accepts(d.key, "other"));
                }
                Constraint::Length(n) => {
                    let pose = GaSetup::default().model.standing_pose;
                    let list = |k: usize| format!("{:?}", &pose[..k.min(pose.len())]);
                    assert!(accepts(d.key, &list(*n)));
                    assert!(!accepts(d.key, &list(n - 1)));
                    let longer = format!("{:?}", [pose.as_slice(), &pose[..1]].concat());
                    assert!(!accepts(d.key, &longer));
                }
                Constraint::Any => {
                    assert!(accepts(d.key, "true") && accepts(d.key, "false"), "{}", d.key);
                }
            }
        }
    }

    #[test]
    fn the_table_shows_the_built_in_defaults() {
        let table = keys_markdown();
        assert!(table.contains("| `step_time` | double | `2` |"), "{table}");
        assert!(
            table.contains("| `mutation_picks` | integer | `10` | [0, 1000000] |"),
            "{table}"
        );
        assert!(
            table.contains("| `blx_variant` | string | `\"per-knot\"` | `per-knot`, `single-draw` |"),
            "{table}"
        );
        assert!(
            table.contains(
                "| `standing_pose` | double array | `[-0.4, 0, 0.8, -0.4, 0, -0.4, 0, 0.8, -0.4, 0]` | 10 elements |"
            ),
            "{table}"
        );
        // Every key's default was found in the built-in setup, with a known type.
        for d in key_docs() {
            let row = table
                .lines()
                .find(|l| l.starts_with(&format!("| `{}` |", d.key)))
                .unwrap();
            assert!(
                !row.contains("| ? |") && !row.contains("| `` |") && !row.contains('?'),
                "{row}"
            );
        }
    }
}
