//! Datasets as MCAP files: JSON-encoded timestep messages with a JSON Schema, zstd-compressed chunks, and
//! one metadata record describing how the data was made. See datasets/README.md for the format.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::mcap_io::{check_version, read_messages, write_messages, Layout};
use super::rollout::Timestep;
use super::schema::{TIMESTEP_SCHEMA, TIMESTEP_SCHEMA_NAME, TIMESTEP_TOPIC};
use crate::error::{Error, Result};

/// Version of the on-disk layout; readers reject any other.
pub const FORMAT_VERSION: u32 = 1;
pub const METADATA_NAME: &str = "mbrl.dataset";

/// What the metadata record says about a dataset.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DatasetMeta {
    pub format_version: u32,
    pub env: String,
    pub seed: u64,
    pub mbrl_version: String,
    pub command_line: String,
    /// Hidden parameters of each environment instance, by rollout id (JSON).
    pub instances: Vec<serde_json::Value>,
    pub state_names: Vec<String>,
    pub action_dim: usize,
    /// Simulated seconds between timesteps.
    pub dt: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Dataset {
    pub meta: DatasetMeta,
    pub steps: Vec<Timestep>,
}

impl DatasetMeta {
    fn to_record(&self) -> BTreeMap<String, String> {
        BTreeMap::from([
            ("format_version".to_string(), self.format_version.to_string()),
            ("env".to_string(), self.env.clone()),
            ("seed".to_string(), self.seed.to_string()),
            ("mbrl_version".to_string(), self.mbrl_version.clone()),
            ("command_line".to_string(), self.command_line.clone()),
            ("instances".to_string(), to_json(&self.instances)),
            ("state_names".to_string(), to_json(&self.state_names)),
            ("action_dim".to_string(), self.action_dim.to_string()),
            ("dt".to_string(), format!("{:?}", self.dt)),
        ])
    }

    fn from_record(path: &Path, record: &BTreeMap<String, String>) -> Result<Self> {
        let field = |key: &str| {
            record
                .get(key)
                .ok_or_else(|| Error::bad_file(path, format!("metadata '{METADATA_NAME}' lacks the field '{key}'")))
        };
        let parse_err =
            |key: &str, expected: &str| Error::bad_file(path, format!("metadata field '{key}': expected {expected}"));
        let version = check_version(path, record, FORMAT_VERSION)?;
        Ok(DatasetMeta {
            format_version: version,
            env: field("env")?.clone(),
            seed: field("seed")?.parse().map_err(|_| parse_err("seed", "an unsigned integer"))?,
            mbrl_version: field("mbrl_version")?.clone(),
            command_line: field("command_line")?.clone(),
            instances: serde_json::from_str(field("instances")?).map_err(|_| parse_err("instances", "a JSON array"))?,
            state_names: serde_json::from_str(field("state_names")?)
                .map_err(|_| parse_err("state_names", "a JSON array of strings"))?,
            action_dim: field("action_dim")?.parse().map_err(|_| parse_err("action_dim", "an integer"))?,
            dt: field("dt")?.parse().map_err(|_| parse_err("dt", "a number"))?,
        })
    }
}

fn to_json<T: Serialize>(value: &T) -> String {
    serde_json::to_string(value).unwrap_or_else(|_| "null".into())
}

fn layout(meta: &DatasetMeta) -> Layout<'static> {
    Layout {
        metadata_name: METADATA_NAME,
        topic: TIMESTEP_TOPIC,
        schema_name: TIMESTEP_SCHEMA_NAME,
        schema: TIMESTEP_SCHEMA,
        // Rollouts are laid end to end on the log clock so viewers play them one after another.
        tick_ns: (meta.dt * 1e9).round().max(1.0) as u64,
    }
}

/// Writes the dataset atomically: the file appears complete or not at all.
pub fn write_dataset(path: &Path, dataset: &Dataset) -> Result<()> {
    write_messages(path, &layout(&dataset.meta), dataset.meta.to_record(), &dataset.steps)
}

pub fn read_dataset(path: &Path) -> Result<Dataset> {
    let (record, messages) = read_messages::<Timestep>(path, METADATA_NAME, TIMESTEP_TOPIC)?;
    let meta = DatasetMeta::from_record(path, &record)?;
    let mut steps = Vec::with_capacity(messages.len());
    for (sequence, step) in messages {
        validate_step(path, &meta, &step, sequence)?;
        steps.push(step);
    }
    Ok(Dataset { meta, steps })
}

fn validate_step(path: &Path, meta: &DatasetMeta, step: &Timestep, sequence: u32) -> Result<()> {
    let where_ = || format!("message {sequence} (rollout {}, t {})", step.rollout, step.t);
    let dim = meta.state_names.len();
    if step.state.len() != dim || step.next_state.len() != dim {
        return Err(Error::bad_file(path, format!("{}: state has the wrong length, expected {dim}", where_())));
    }
    if step.action.len() != meta.action_dim {
        return Err(Error::bad_file(
            path,
            format!("{}: action has the wrong length, expected {}", where_(), meta.action_dim),
        ));
    }
    let finite =
        step.state.iter().chain(&step.next_state).chain(&step.action).all(|x| x.is_finite()) && step.reward.is_finite();
    if !finite {
        return Err(Error::bad_file(path, format!("{}: non-finite value in state, action or reward", where_())));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Rollout;

    pub(crate) fn tiny_dataset() -> Dataset {
        let mut r = Rollout::start(vec![0.0, 0.0], vec![1.0, 0.0, 0.0]);
        r.push(vec![1.0], -0.5, vec![0.1, 0.2], vec![0.99, 0.1, 0.2]);
        r.push(vec![-1.0], -0.25, vec![0.2, 0.1], vec![0.98, 0.2, 0.1]);
        Dataset {
            meta: DatasetMeta {
                format_version: FORMAT_VERSION,
                env: "pendulum".into(),
                seed: 3,
                mbrl_version: crate::VERSION.into(),
                command_line: "mbrl collect".into(),
                instances: vec![serde_json::json!({"mass": 1.0})],
                state_names: vec!["theta".into(), "theta_dot".into()],
                action_dim: 1,
                dt: 0.05,
            },
            steps: r.timesteps(0).collect(),
        }
    }

    #[test]
    fn round_trip_preserves_everything() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.mcap");
        let data = tiny_dataset();
        write_dataset(&path, &data).unwrap();
        assert_eq!(read_dataset(&path).unwrap(), data);
    }

    #[test]
    fn same_dataset_same_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
        write_dataset(&a, &tiny_dataset()).unwrap();
        write_dataset(&b, &tiny_dataset()).unwrap();
        assert_eq!(std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    }

    #[test]
    fn truncated_file_is_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.mcap");
        write_dataset(&path, &tiny_dataset()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        let err = read_dataset(&path).unwrap_err().to_string();
        assert!(err.contains("d.mcap") && err.contains("truncated or corrupt"), "{err}");
    }

    #[test]
    fn unknown_version_is_rejected() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v9.mcap");
        let mut data = tiny_dataset();
        data.meta.format_version = 9;
        write_dataset(&path, &data).unwrap();
        let err = read_dataset(&path).unwrap_err().to_string();
        assert!(err.contains("format version 9 is not supported"), "{err}");
    }
}
