//! `--params FILE`: the robot, the fitness and the algorithm's parameters from a file of
//! `params/nao_step.yaml`'s form (`ga_step: ros__parameters: {key: value, …}`), every key one of
//! [`NaoModel`], [`FitnessConfig`] or [`GaConfig`]'s fields and a missing key its default. The
//! population (and with it the offspring count) and the crossover are options, so the file may
//! not set them ([`OPTIONS`]): a file that does is refused, naming the option.

use anyhow::{anyhow, bail};
use mobil_ga_step::{FitnessConfig, GaConfig, GaSetup, NaoModel};
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
