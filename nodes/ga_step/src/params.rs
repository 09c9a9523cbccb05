//! `ga_step --params FILE`: the robot, the fitness and the algorithm's parameters from a file of
//! `params/nao_step.yaml`'s form (`ga_step: ros__parameters: {key: value, …}`), every key one of
//! [`NaoModel`], [`FitnessConfig`] or [`GaConfig`]'s fields and a missing key its default. The
//! population (and with it the offspring count) and the crossover are options, so the file may
//! not set them ([`OPTIONS`]): a file that does is refused, naming the option. Every refusal is
//! one line naming the file.

use crate::config::{FitnessConfig, GaConfig};
use crate::error::ParamsError;
use crate::ga::GaSetup;
use crate::model::NaoModel;
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
pub fn setup_from_yaml(text: &str, name: &str) -> Result<GaSetup, ParamsError> {
    let fail = |message: String| ParamsError(format!("{name}: {message}"));
    let doc: Value = serde_norway::from_str(text).map_err(|e| fail(format!("not YAML: {e}")))?;
    let section = doc
        .get("ga_step")
        .and_then(|n| n.get("ros__parameters"))
        .ok_or_else(|| fail("no `ga_step: ros__parameters:` section".into()))?;
    let Value::Mapping(map) = section else {
        return Err(fail("`ga_step: ros__parameters:` is not a mapping".into()));
    };
    let known = known_keys();
    for k in map.keys() {
        match k.as_str() {
            Some(k) if OPTIONS.iter().any(|(key, _)| *key == k) => {
                let option = OPTIONS.iter().find(|(key, _)| *key == k).map_or("", |(_, o)| *o);
                return Err(fail(format!("`{k}` is set by the {option} option, not a parameter")));
            }
            Some(k) if known.iter().any(|n| n == k) => {}
            _ => {
                return Err(fail(format!(
                    "unknown parameter `{}` (known: {})",
                    serde_norway::to_string(k).unwrap_or_default().trim(),
                    known.join(", ")
                )));
            }
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
        serde_norway::from_value(part(keys_of::<NaoModel>())).map_err(|e| fail(format!("robot: {}", one_line(e))))?;
    let fitness: FitnessConfig = serde_norway::from_value(part(keys_of::<FitnessConfig>()))
        .map_err(|e| fail(format!("fitness: {}", one_line(e))))?;
    let ga: GaConfig = serde_norway::from_value(part(keys_of::<GaConfig>()))
        .map_err(|e| fail(format!("algorithm: {}", one_line(e))))?;
    let setup = GaSetup { model, fitness, ga };
    setup.validate().map_err(|e| fail(e.to_string()))?;
    Ok(setup)
}

/// Reads a parameter file (see the module's documentation).
pub fn read_setup(path: &Path) -> Result<GaSetup, ParamsError> {
    use std::io::Read as _;
    let name = path.display().to_string();
    let cannot_read = |e: std::io::Error| ParamsError(format!("cannot read {name}: {e}"));
    let file = std::fs::File::open(path).map_err(cannot_read)?;
    let mut text = String::new();
    file.take(MAX_PARAMS_BYTES + 1)
        .read_to_string(&mut text)
        .map_err(cannot_read)?;
    if text.len() as u64 > MAX_PARAMS_BYTES {
        return Err(ParamsError(format!(
            "{name}: larger than {MAX_PARAMS_BYTES} bytes, not a parameter file"
        )));
    }
    setup_from_yaml(&text, &name)
}
