//! What a new training run does with the checkpoint directory it is pointed at: replace what is there, refuse
//! to throw away a stopped run, or, asked to, pick that run up again.

use std::path::{Path, PathBuf};

use serde_json::Value;

use super::job::MAX_TRAIN_STEPS;
use super::method::{Method, Request};
use super::{Extension, OpenedCheckpoint, CONFIG_FILE};
use crate::error::{Error, Result};
use crate::run::lock::RunLock;

/// How a `train` command goes on in its output directory.
#[derive(Clone, Debug)]
pub enum Decision {
    /// Nothing there that passes for a run, or a finished one: a new run, which replaces it.
    Fresh,
    /// The stopped run there goes on, to its own total or, extended, to the total asked for.
    Resume(Option<Extension>),
}

/// A field of config.json, by JSON pointer, that a flag decides: what a message calls it, the value the
/// command asks for (`Null` for a field the run omits), and how to show a value in a message.
pub struct Field {
    pub what: &'static str,
    pub pointer: &'static str,
    pub asked: Value,
    pub show: fn(&Value) -> String,
}

impl Field {
    pub fn new(what: &'static str, pointer: &'static str, asked: Value) -> Self {
        Field { what, pointer, asked, show: brief }
    }
}

/// What to do in `out` for a run asking for `request`. Without `resume_if_stopped` a stopped run is refused (a
/// new run starts by clearing the directory, so it would throw away every hour that run trained); with it, the
/// stopped run goes on when `request` is what started it, and only then; with `force` alone, it is started
/// over. A directory whose checkpoint cannot be read holds no run and is replaced, as a finished one is (the
/// command line's rule for named outputs, `--force`, is applied before this).
pub fn decide<M: Method>(out: &Path, request: &Request<M>, resume_if_stopped: bool, force: bool) -> Result<Decision> {
    if out.is_dir() {
        RunLock::ensure_free(out)?;
    }
    let Ok(opened) = OpenedCheckpoint::open(out) else {
        return Ok(Decision::Fresh);
    };
    let manifest = &opened.manifest;
    if manifest.complete {
        return Ok(Decision::Fresh);
    }
    let stopped =
        format!("holds a {} run stopped at step {} of {}", manifest.method, manifest.step, manifest.total_steps);
    if force && !resume_if_stopped {
        return Ok(Decision::Fresh);
    }
    if !resume_if_stopped {
        return Err(Error::bad_file(
            out,
            format!(
                "{stopped}; continue it with `mbrl train --resume {}` (or add --resume-if-stopped), or add --force \
                 to start over",
                out.display()
            ),
        ));
    }
    if manifest.method != M::NAME {
        return Err(Error::bad_file(
            out,
            format!(
                "{stopped}, not a {} run; continue it with `mbrl train --resume {}`, or give another --out",
                M::NAME,
                out.display()
            ),
        ));
    }
    let differs = |what: &str, stored: String, asked: String| {
        Error::bad_file(
            &out.join(CONFIG_FILE),
            format!(
                "the stopped {} run has {what} {}, this command asks for {}: resume cannot change it; give the \
                 run's own flags, or remove {} to start over",
                manifest.method,
                stored,
                asked,
                out.display()
            ),
        )
    };
    let mut stored = opened.config.clone();
    M::upgrade(&mut stored);
    let stored = &stored;
    let asked_seed = Value::from(request.seed);
    if stored.get("seed") != Some(&asked_seed) {
        return Err(differs("--seed", brief(stored.get("seed").unwrap_or(&Value::Null)), brief(&asked_seed)));
    }
    let stored_data = data_paths(stored);
    let asked_data: Vec<Value> = request.data.iter().map(|p| Value::from(p.display().to_string())).collect();
    if stored_data != asked_data {
        return Err(differs("--data", brief(&Value::Array(stored_data)), brief(&Value::Array(asked_data))));
    }
    for field in &M::fixed_fields(request) {
        let found = stored.pointer(field.pointer).unwrap_or(&Value::Null);
        if *found != field.asked {
            return Err(differs(field.what, (field.show)(found), (field.show)(&field.asked)));
        }
    }
    let stored_config = stored.get("config").unwrap_or(&Value::Null);
    let mut extension = None;
    let mut asked_config =
        serde_json::to_value(&request.config).map_err(|e| Error::config(format!("{CONFIG_FILE}: {e}")))?;
    match asked_config.get("steps").and_then(Value::as_u64) {
        Some(steps) if steps != manifest.total_steps => {
            if !M::EXTENDABLE || steps < manifest.total_steps || steps > MAX_TRAIN_STEPS {
                let why = if M::EXTENDABLE { "shorten" } else { "lengthen" };
                return Err(Error::bad_file(
                    out,
                    format!(
                        "{stopped}; --steps {steps} would {why} it, which resume cannot do for a {} run: give \
                         --steps {}, or remove the directory to start over",
                        manifest.method, manifest.total_steps
                    ),
                ));
            }
            extension = Some(Extension { steps, command_line: request.provenance.command_line.clone() });
        }
        _ => {}
    }
    // The total is the one field an extension may change; everything else must be what started the run.
    if let (Some(asked), Some(stored_steps)) = (asked_config.get_mut("steps"), stored_config.get("steps")) {
        *asked = stored_steps.clone();
    }
    if let Some((field, stored_value, asked_value)) = first_difference(stored_config, &asked_config, String::new()) {
        return Err(differs(&format!("config.{field}"), brief(&stored_value), brief(&asked_value)));
    }
    Ok(Decision::Resume(extension))
}

/// The dataset paths a run recorded, as given when it started: a list of data files, or one.
fn data_paths(config: &Value) -> Vec<Value> {
    let path = |file: &Value| file.get("path").cloned().unwrap_or(Value::Null);
    match config.get("data") {
        Some(Value::Array(files)) => files.iter().map(path).collect(),
        Some(file @ Value::Object(_)) => vec![path(file)],
        _ => Vec::new(),
    }
}

/// The first field, by dotted path, where two configs differ, with both values.
fn first_difference(stored: &Value, asked: &Value, at: String) -> Option<(String, Value, Value)> {
    let join = |key: &str| if at.is_empty() { key.to_string() } else { format!("{at}.{key}") };
    match (stored, asked) {
        (Value::Object(a), Value::Object(b)) => {
            let keys: std::collections::BTreeSet<&String> = a.keys().chain(b.keys()).collect();
            keys.into_iter().find_map(|key| {
                let (x, y) = (a.get(key).unwrap_or(&Value::Null), b.get(key).unwrap_or(&Value::Null));
                first_difference(x, y, join(key))
            })
        }
        (Value::Array(a), Value::Array(b)) if a.len() == b.len() => {
            a.iter().zip(b).enumerate().find_map(|(i, (x, y))| first_difference(x, y, format!("{at}[{i}]")))
        }
        _ if stored == asked => None,
        _ => Some((if at.is_empty() { "(all)".to_string() } else { at }, stored.clone(), asked.clone())),
    }
}

/// A value as it reads in a one-line message: short JSON, long arrays and objects elided.
fn brief(value: &Value) -> String {
    let text = value.to_string();
    if text.chars().count() <= 80 {
        text
    } else {
        format!("{}…", text.chars().take(77).collect::<String>())
    }
}

/// Where a run goes without --out: `models/` and a name made of its method and env (`pendulum:heavy` →
/// `pets-pendulum-heavy`), so runs on different envs do not replace each other.
pub fn default_out(name: &str) -> PathBuf {
    let name: String =
        name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '.' || c == '-' { c } else { '-' }).collect();
    PathBuf::from("models").join(name)
}
