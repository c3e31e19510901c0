//! Hyperparameters from a TOML file over a method's defaults. Keys are the config's own field names (as
//! written in the checkpoint's config.json); an unknown key or a value of the wrong type is an error naming the
//! file and the key, never silently ignored.

use std::path::Path;

use serde::de::DeserializeOwned;
use serde::Serialize;

use super::checkpoint::read_bounded;
use crate::error::{Error, Result};

const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// `base` with the keys of the TOML file at `path` replaced.
pub fn apply_toml_file<T: Serialize + DeserializeOwned>(base: &T, path: &Path) -> Result<T> {
    let bytes = read_bounded(path, MAX_CONFIG_BYTES)?;
    let text = std::str::from_utf8(&bytes).map_err(|_| Error::bad_file(path, "not UTF-8 text"))?;
    apply_toml(base, text).map_err(|message| Error::bad_file(path, message))
}

pub fn apply_toml<T: Serialize + DeserializeOwned>(base: &T, text: &str) -> std::result::Result<T, String> {
    let table: toml::Table = toml::from_str(text).map_err(|e| format!("not valid TOML: {}", e.message()))?;
    let mut value = serde_json::to_value(base).map_err(|e| e.to_string())?;
    let object = value.as_object_mut().ok_or("this method's config is not a table")?;
    for (key, item) in table {
        let Some(slot) = object.get_mut(&key) else {
            let mut known: Vec<&str> = object.keys().map(String::as_str).collect();
            known.sort_unstable();
            let hint = crate::util::suggest::did_you_mean(&key, known.iter().copied());
            return Err(format!("unknown key '{key}'{hint}; known keys: {}", known.join(", ")));
        };
        *slot = serde_json::to_value(&item).map_err(|e| format!("key '{key}': {e}"))?;
    }
    serde_json::from_value(value).map_err(|e| format!("wrong value type: {e}"))
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
        assert!(err.contains("unknown key 'stepz' (did you mean 'steps'?)") && err.contains("known keys"), "{err}");
        let err = apply_toml(&base(), "steps = \"many\"").unwrap_err();
        assert!(err.contains("wrong value type"), "{err}");
        assert!(apply_toml(&base(), "steps = ").is_err());
    }
}
