//! `--params FILE`: the robot, the fitness and the algorithm's parameters from a file of
//! `params/nao_step.yaml`'s form (`ga_step: ros__parameters: {key: value, …}`), every key one of
//! [`NaoModel`], [`FitnessConfig`] or [`GaConfig`]'s fields and a missing key its default. The
//! population (and with it the offspring count) and the crossover are options, so the file may
//! not set them ([`OPTIONS`]): a file that does is refused, naming the option.

use anyhow::{anyhow, bail};
use mobil_ga_step::{FitnessConfig, GaConfig, GaSetup, NaoModel};
use mobil_ros::docs::{cell, markdown_table};
use mobil_ros::params::Constraint;
use serde_norway::{Mapping, Value};
use std::path::Path;

/// The algorithm's settings that are command-line options, not parameters, with the option
/// that sets them (the offspring count is the population).
pub const OPTIONS: [(&str, &str); 3] = [
    ("population", "--population"),
    ("offspring", "--population"),
    ("crossover", "--crossover"),
];

/// The largest parameter file read (64 KiB; params/nao_step.yaml is under 5 KiB).
pub const MAX_PARAMS_BYTES: u64 = 64 * 1024;

/// The keys of a serialised default, sorted.
fn keys_of<T: serde::Serialize + Default>() -> Vec<String> {
    match serde_norway::to_value(T::default()) {
        Ok(Value::Mapping(m)) => m.keys().filter_map(|k| k.as_str().map(str::to_owned)).collect(),
        _ => Vec::new(),
    }
}

/// Every key a parameter file may set.
pub fn known_keys() -> Vec<String> {
    let mut keys = keys_of::<NaoModel>();
    keys.extend(keys_of::<FitnessConfig>());
    keys.extend(
        keys_of::<GaConfig>()
            .into_iter()
            .filter(|k| !OPTIONS.iter().any(|(key, _)| key == k)),
    );
    keys
}

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

/// A setup from a parameter file's text (`name` names it in errors); validated.
pub fn setup_from_yaml(text: &str, name: &str) -> anyhow::Result<GaSetup> {
    let doc: Value = serde_norway::from_str(text).map_err(|e| anyhow!("{name}: not YAML: {e}"))?;
    let section = doc
        .get("ga_step")
        .and_then(|n| n.get("ros__parameters"))
        .ok_or_else(|| anyhow!("{name}: no `ga_step: ros__parameters:` section"))?;
    let Value::Mapping(map) = section else {
        bail!("{name}: `ga_step: ros__parameters:` is not a mapping");
    };
    let known = known_keys();
    for k in map.keys() {
        match k.as_str() {
            Some(k) if OPTIONS.iter().any(|(key, _)| *key == k) => {
                let option = OPTIONS.iter().find(|(key, _)| *key == k).map_or("", |(_, o)| *o);
                bail!("{name}: `{k}` is set by the {option} option, not a parameter")
            }
            Some(k) if known.iter().any(|n| n == k) => {}
            _ => bail!(
                "{name}: unknown parameter `{}` (known: {})",
                serde_norway::to_string(k).unwrap_or_default().trim(),
                known.join(", ")
            ),
        }
    }
    let part = |keys: Vec<String>| -> Value {
        let mut m = Mapping::new();
        for (k, v) in map {
            if k.as_str().is_some_and(|k| keys.iter().any(|n| n == k)) {
                m.insert(k.clone(), v.clone());
            }
        }
        Value::Mapping(m)
    };
    let one_line = |e: serde_norway::Error| e.to_string().replace('\n', " ");
    let model: NaoModel =
        serde_norway::from_value(part(keys_of::<NaoModel>())).map_err(|e| anyhow!("{name}: robot: {}", one_line(e)))?;
    let fitness: FitnessConfig = serde_norway::from_value(part(keys_of::<FitnessConfig>()))
        .map_err(|e| anyhow!("{name}: fitness: {}", one_line(e)))?;
    let ga: GaConfig = serde_norway::from_value(part(keys_of::<GaConfig>()))
        .map_err(|e| anyhow!("{name}: algorithm: {}", one_line(e)))?;
    let setup = GaSetup { model, fitness, ga };
    setup.validate().map_err(|e| anyhow!("{name}: {e}"))?;
    Ok(setup)
}

/// Reads a parameter file (see the module's documentation).
pub fn read_setup(path: &Path) -> anyhow::Result<GaSetup> {
    use std::io::Read as _;
    let name = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|e| anyhow!("cannot read {name}: {e}"))?;
    let mut text = String::new();
    file.take(MAX_PARAMS_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(|e| anyhow!("cannot read {name}: {e}"))?;
    if text.len() as u64 > MAX_PARAMS_BYTES {
        bail!("{name}: larger than {MAX_PARAMS_BYTES} bytes, not a parameter file");
    }
    setup_from_yaml(&text, &name)
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../params/nao_step.yaml");

    #[test]
    fn the_shipped_file_is_the_built_in_defaults() {
        let setup = read_setup(Path::new(FILE)).unwrap();
        assert_eq!(setup, GaSetup::default());
        // A value of the file is read, not just defaulted: the step time is 2.0 s there.
        let text = std::fs::read_to_string(FILE)
            .unwrap()
            .replace("step_time: 2.0", "step_time: 2.4");
        let changed = setup_from_yaml(&text, "f").unwrap();
        assert_eq!(changed.model.step_time, 2.4);
        assert_ne!(changed, GaSetup::default());
    }

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

    #[test]
    fn unknown_keys_and_bad_values_are_one_line_errors() {
        let text = std::fs::read_to_string(FILE).unwrap();
        let cases = [
            (text.replace("blx_alpha:", "blx_alpa:"), "unknown parameter `blx_alpa`"),
            (text.replace("fall_tilt: 0.5", "fall_tilt: 2.0"), "fall_tilt"),
            (text.replace("mutation_picks: 10", "mutation_picks: ten"), "algorithm"),
            (
                text.replace("blx_alpha: 0.7", "blx_alpha: 0.7\n    population: 5"),
                "`population` is set by the --population option",
            ),
            (
                text.replace("blx_alpha: 0.7", "blx_alpha: 0.7\n    offspring: 100"),
                "`offspring` is set by the --population option",
            ),
            (
                text.replace("blx_alpha: 0.7", "blx_alpha: 0.7\n    crossover: arithmetic"),
                "`crossover` is set by the --crossover option",
            ),
            ("ga_step: 3".to_owned(), "no `ga_step: ros__parameters:`"),
        ];
        for (t, want) in cases {
            let e = format!("{:#}", setup_from_yaml(&t, "f").unwrap_err());
            assert!(e.contains(want), "{e}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
    }
}
