//! Setting keys of a config one at a time, by dotted path (`optimizer.learning_rate`), as a config file and
//! `KEY=VALUE` arguments do. Every key must already exist in the config (so a typo is an error listing the
//! valid keys, never a silent no-op), and each value is type-checked as it is set, so the error names the key
//! whose value was wrong. Ranges are the config's own `validate`, run by the caller after every source.

use std::str::FromStr;

use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::{Map, Value};

use crate::error::{Error, Result};

/// One `KEY=VALUE` from the command line. The value is read as TOML (`3e-4`, `true`, `[1, 2]`, `"text"`);
/// anything that is not TOML is taken as a string, so enum names need no quotes (`reward=learned`).
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    pub key: String,
    pub value: Value,
    /// As typed, for error messages.
    pub text: String,
}

impl FromStr for Override {
    type Err = String;

    fn from_str(text: &str) -> std::result::Result<Self, String> {
        let Some((key, raw)) = text.split_once('=') else {
            return Err(format!("'{text}' is not KEY=VALUE (e.g. steps=500 or optimizer.learning_rate=3e-4)"));
        };
        let key = key.trim();
        let valid_segment = |s: &str| !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !key.split('.').all(valid_segment) {
            return Err(format!("'{key}' is not a key: letters, digits and _, nested keys joined by '.'"));
        }
        let raw = raw.trim();
        let value = match toml::from_str::<toml::Table>(&format!("v = {raw}")) {
            Ok(mut table) => table.remove("v").map(|v| serde_json::to_value(v).map_err(|e| e.to_string())),
            Err(_) => None,
        }
        .transpose()?
        .unwrap_or_else(|| Value::String(raw.to_string()));
        Ok(Override { key: key.to_string(), value, text: text.to_string() })
    }
}

impl Override {
    /// Whether this override sets `key` or a key inside it.
    pub fn sets(&self, key: &str) -> bool {
        self.key == key || self.key.strip_prefix(key).is_some_and(|rest| rest.starts_with('.'))
    }
}

/// `config` with each override set in order (a later one wins); an error names the override as typed.
pub fn apply_overrides<T: Serialize + DeserializeOwned>(config: T, overrides: &[Override]) -> Result<T> {
    if overrides.is_empty() {
        return Ok(config);
    }
    let mut table = Table::of(&config).map_err(Error::config)?;
    for o in overrides {
        table.set::<T>(&o.key, o.value.clone()).map_err(|message| Error::config(format!("{}: {message}", o.text)))?;
    }
    table.into_config().map_err(Error::config)
}

/// A config as a JSON table, being set key by key.
pub struct Table {
    value: Value,
    known: Vec<String>,
}

impl Table {
    pub fn of<T: Serialize>(config: &T) -> std::result::Result<Self, String> {
        let value = serde_json::to_value(config).map_err(|e| e.to_string())?;
        if !value.is_object() {
            return Err("this config is not a table of keys".into());
        }
        let mut known = Vec::new();
        leaf_keys(&value, "", &mut known);
        known.sort_unstable();
        Ok(Table { value, known })
    }

    /// Sets the dotted `key` to `value`; a table value sets its keys one by one, so a file may give part of a
    /// nested table.
    pub fn set<T: DeserializeOwned>(&mut self, key: &str, value: Value) -> std::result::Result<(), String> {
        let path: Vec<&str> = key.split('.').collect();
        let Some(slot) = slot(&mut self.value, &path) else {
            return Err(self.unknown(key));
        };
        match value {
            Value::Object(entries) if slot.is_object() => {
                for (sub, v) in entries {
                    self.set::<T>(&format!("{key}.{sub}"), v)?;
                }
                Ok(())
            }
            value => {
                *slot = value;
                serde_json::from_value::<T>(self.value.clone())
                    .map(drop)
                    .map_err(|e| format!("key '{key}': wrong value type: {e}"))
            }
        }
    }

    pub fn into_config<T: DeserializeOwned>(self) -> std::result::Result<T, String> {
        serde_json::from_value(self.value).map_err(|e| format!("wrong value type: {e}"))
    }

    fn unknown(&self, key: &str) -> String {
        if self.known.is_empty() {
            return format!("unknown key '{key}'; this config has no keys");
        }
        let hint = crate::util::suggest::did_you_mean(key, self.known.iter().map(String::as_str));
        format!("unknown key '{key}'{hint}; valid keys: {}", self.known.join(", "))
    }
}

fn slot<'a>(value: &'a mut Value, path: &[&str]) -> Option<&'a mut Value> {
    path.iter().try_fold(value, |value, segment| value.as_object_mut()?.get_mut(*segment))
}

/// The dotted names of every value that is not itself a table, as `KEY=VALUE` may set them.
fn leaf_keys(value: &Value, prefix: &str, out: &mut Vec<String>) {
    let Value::Object(entries) = value else {
        out.push(prefix.to_string());
        return;
    };
    let entries: &Map<String, Value> = entries;
    for (key, v) in entries {
        let name = if prefix.is_empty() { key.clone() } else { format!("{prefix}.{key}") };
        match v {
            Value::Object(sub) if !sub.is_empty() => leaf_keys(v, &name, out),
            _ => out.push(name),
        }
    }
}

#[cfg(test)]
mod tests {
    use serde::Deserialize;

    use super::*;

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Inner {
        learning_rate: f64,
        clip: Option<f64>,
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Demo {
        steps: u64,
        name: String,
        optimizer: Inner,
    }

    fn base() -> Demo {
        Demo { steps: 10, name: "a".into(), optimizer: Inner { learning_rate: 0.1, clip: None } }
    }

    fn o(text: &str) -> Override {
        text.parse().unwrap()
    }

    #[test]
    fn values_read_as_toml_or_as_bare_strings() {
        assert_eq!(o("steps=500").value, Value::from(500));
        assert_eq!(o("optimizer.learning_rate=3e-4").value, Value::from(3e-4));
        assert_eq!(o("name=learned").value, Value::from("learned"));
        assert_eq!(o("name=\"x y\"").value, Value::from("x y"));
        assert!("steps".parse::<Override>().unwrap_err().contains("KEY=VALUE"));
        assert!("=3".parse::<Override>().is_err());
        assert!("a..b=3".parse::<Override>().is_err());
    }

    #[test]
    fn nested_keys_set_one_value_and_the_last_override_wins() {
        let out = apply_overrides(base(), &[o("optimizer.learning_rate=1"), o("steps=20"), o("steps=30")]).unwrap();
        assert_eq!(out.steps, 30);
        assert_eq!(out.optimizer, Inner { learning_rate: 1.0, clip: None });
        let out = apply_overrides(base(), &[o("optimizer.clip=0.5")]).unwrap();
        assert_eq!(out.optimizer.clip, Some(0.5));
        assert!(o("optimizer.learning_rate=1").sets("optimizer") && !o("optimizer.learning_rate=1").sets("optim"));
    }

    #[test]
    fn errors_name_the_override_and_the_key() {
        let err = apply_overrides(base(), &[o("lr=3e-4")]).unwrap_err().to_string();
        assert!(err.contains("lr=3e-4: unknown key 'lr'"), "{err}");
        assert!(err.contains("valid keys: name, optimizer.clip, optimizer.learning_rate, steps"), "{err}");
        let err = apply_overrides(base(), &[o("steps=many")]).unwrap_err().to_string();
        assert!(err.contains("steps=many: key 'steps': wrong value type"), "{err}");
        let err = apply_overrides(base(), &[o("steps.x=1")]).unwrap_err().to_string();
        assert!(err.contains("unknown key 'steps.x'"), "{err}");
    }

    #[test]
    fn a_partial_table_keeps_the_other_keys() {
        let mut table = Table::of(&base()).unwrap();
        table.set::<Demo>("optimizer", serde_json::json!({ "learning_rate": 2.0 })).unwrap();
        let out: Demo = table.into_config().unwrap();
        assert_eq!(out.optimizer.learning_rate, 2.0);
        let mut table = Table::of(&base()).unwrap();
        let err = table.set::<Demo>("optimizer", serde_json::json!({ "lr": 2.0 })).unwrap_err();
        assert!(err.contains("unknown key 'optimizer.lr'"), "{err}");
    }
}
