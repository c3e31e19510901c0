//! Hyperparameters from a config file over a method's defaults: TOML, or JSON such as a run's own
//! config.json, whose `config` table reruns that run. Keys are the config's own field names (as written in
//! the checkpoint's config.json, nested ones as TOML tables or dotted keys); an unknown key or a value of the
//! wrong type is an error naming the file and the key, never silently ignored.

use std::path::Path;

use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::Value;

use super::checkpoint::read_bounded;
use super::settings::Table;
use crate::error::{Error, Result};

const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// `base` with the keys of the config file at `path` replaced. A run record (a checkpoint's config.json)
/// must be of one of `methods`, the methods whose config `T` is.
pub fn apply_config_file<T: Serialize + DeserializeOwned>(base: &T, path: &Path, methods: &[&str]) -> Result<T> {
    let bytes = read_bounded(path, MAX_CONFIG_BYTES)?;
    let text = std::str::from_utf8(&bytes).map_err(|_| Error::bad_file(path, "not UTF-8 text"))?;
    let json = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("json")) || text.trim_start().starts_with('{');
    let applied = if json { apply_json(base, text, methods) } else { apply_toml(base, text) };
    applied.map_err(|message| Error::bad_file(path, message))
}

pub fn apply_toml<T: Serialize + DeserializeOwned>(base: &T, text: &str) -> std::result::Result<T, String> {
    let table: toml::Table = toml::from_str(text).map_err(|e| format!("not valid TOML: {}", e.message()))?;
    let value = serde_json::to_value(table).map_err(|e| e.to_string())?;
    apply_table(base, value)
}

/// A JSON object of config keys, or a run's config.json (its `config` table, when its method is one of
/// `methods`).
pub fn apply_json<T: Serialize + DeserializeOwned>(
    base: &T,
    text: &str,
    methods: &[&str],
) -> std::result::Result<T, String> {
    let mut value: Value = serde_json::from_str(text).map_err(|e| format!("not valid JSON: {e}"))?;
    if let Some(protocol) = value.get("protocol").and_then(Value::as_str) {
        return Err(format!(
            "is the config.json of an `eval {protocol}` report; rerun it with `mbrl eval {protocol} --config FILE`"
        ));
    }
    if let (Some(method), Some(_)) = (value.get("method").and_then(Value::as_str), value.get("config")) {
        if !methods.contains(&method) {
            return Err(format!("is the config.json of a {method} run; pass it to `mbrl train {method} --config`"));
        }
        value = value["config"].take();
    }
    apply_table(base, value)
}

fn apply_table<T: Serialize + DeserializeOwned>(base: &T, value: Value) -> std::result::Result<T, String> {
    let Value::Object(entries) = value else {
        return Err("expected a table of config keys".into());
    };
    let mut table = Table::of(base)?;
    for (key, item) in entries {
        table.set::<T>(&key, item)?;
    }
    table.into_config()
}

#[cfg(test)]
mod tests {
    use serde::Deserialize;

    use super::*;

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Demo {
        steps: u64,
        lr: f64,
        name: String,
    }

    fn base() -> Demo {
        Demo { steps: 10, lr: 0.1, name: "a".into() }
    }

    #[test]
    fn overrides_named_keys_only() {
        let out = apply_toml(&base(), "steps = 20\nlr = 1e-3").unwrap();
        assert_eq!(out, Demo { steps: 20, lr: 1e-3, name: "a".into() });
    }

    #[test]
    fn unknown_keys_and_wrong_types_are_errors() {
        let err = apply_toml(&base(), "stepz = 20").unwrap_err();
        assert!(err.contains("unknown key 'stepz' (did you mean 'steps'?)") && err.contains("valid keys"), "{err}");
        let err = apply_toml(&base(), "steps = \"many\"").unwrap_err();
        assert!(err.contains("key 'steps': wrong value type"), "{err}");
        assert!(apply_toml(&base(), "steps = ").is_err());
    }

    #[test]
    fn json_takes_a_bare_table_or_a_run_record_of_the_method() {
        assert_eq!(apply_json(&base(), r#"{"steps": 7}"#, &["demo"]).unwrap().steps, 7);
        let record = r#"{"method": "demo", "seed": 3, "config": {"steps": 8, "lr": 0.5, "name": "b"}}"#;
        assert_eq!(apply_json(&base(), record, &["demo"]).unwrap(), Demo { steps: 8, lr: 0.5, name: "b".into() });
        let err = apply_json(&base(), record, &["other"]).unwrap_err();
        assert!(err.contains("a demo run") && err.contains("mbrl train demo"), "{err}");
        let err = apply_json(&base(), r#"{"protocol": "ball", "settings": {}}"#, &["demo"]).unwrap_err();
        assert!(err.contains("mbrl eval ball --config"), "{err}");
        assert!(apply_json(&base(), r#"{"steps": -1}"#, &["demo"]).unwrap_err().contains("key 'steps'"));
    }
}
