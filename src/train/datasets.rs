//! The datasets a training run reads: several files of one env merged into one, and the env they are of. Every
//! method that trains on rollouts (PETS, the context model, DLGPD) starts here.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::DataFile;
use crate::data::{read_dataset, Dataset};
use crate::envs::{parse_env, EnvName};
use crate::error::{Error, Result};

/// How many transitions and rollouts went to training and to validation (recorded in config.json).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransitionCounts {
    pub train: usize,
    pub valid: usize,
    pub train_rollouts: usize,
    pub valid_rollouts: usize,
}

/// Reads and concatenates datasets of one env (rollout ids renumbered so they stay distinct).
pub fn load_datasets(paths: &[PathBuf]) -> Result<(Dataset, Vec<DataFile>)> {
    let mut merged: Option<Dataset> = None;
    let mut files = Vec::new();
    for path in paths {
        files.push(DataFile::fingerprint(path)?);
        let mut dataset = read_dataset(path)?;
        match &mut merged {
            None => merged = Some(dataset),
            Some(m) => {
                if dataset.meta.env != m.meta.env
                    || dataset.meta.state_names != m.meta.state_names
                    || dataset.meta.action_dim != m.meta.action_dim
                {
                    return Err(Error::bad_file(
                        path,
                        format!("is a dataset of '{}'; the first dataset is of '{}'", dataset.meta.env, m.meta.env),
                    ));
                }
                let offset = m.steps.iter().map(|s| s.rollout + 1).max().unwrap_or(0);
                for step in &mut dataset.steps {
                    step.rollout =
                        step.rollout.checked_add(offset).ok_or_else(|| Error::bad_file(path, "too many rollouts"))?;
                }
                m.steps.extend(dataset.steps);
            }
        }
    }
    let dataset = merged.ok_or_else(|| Error::config("no dataset given; pass --data FILE.mcap"))?;
    Ok((dataset, files))
}

/// The env a dataset was collected in, checked against the one the user named (shared by every trainer).
pub fn env_of(dataset: &Dataset, requested: Option<&str>, data: &Path) -> Result<EnvName> {
    let env = parse_env(&dataset.meta.env).map_err(|e| e.field("dataset env").at(data))?;
    if let Some(requested) = requested {
        let requested_env = parse_env(requested)?;
        if requested_env.canonical() != env.canonical() {
            return Err(Error::bad_file(
                data,
                format!("holds '{}' rollouts; --env asked for '{}'", env.canonical(), requested_env.canonical()),
            ));
        }
    }
    Ok(env)
}
