//! What a learning method tells the training job: its name, its config, what it records about a run beyond
//! the fields every run has, and how it builds a trainer from a request. The job ([`super::job`]) does the
//! rest the same way for every method: the run record, fresh/resume/extend, the checkpoint directory.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::fit::{FitOutcome, TrainingMethod};
use super::run_dir::Field;
use super::{DataFile, OpenedCheckpoint, CONFIG_FILE};
use crate::error::{Error, Result};
use crate::run::dir::Provenance;
use crate::run::Event;

/// A learning method as the shared training job drives it.
pub trait Method: Sized + 'static {
    /// The name its checkpoints carry (`pets`, `ball-ekf`).
    const NAME: &'static str;
    /// How a sentence names the method ("PETS", "the ball EKF").
    const TITLE: &'static str;
    /// A finished run trains on to a larger total exactly as a run started with that total would have
    /// (`train --resume DIR --steps N`): true only where nothing in training depends on the total.
    const EXTENDABLE: bool = false;
    /// The hyperparameters: config.json's `config` table, which a TOML file may set.
    type Config: RunConfig + Clone + PartialEq + Serialize + DeserializeOwned + Send + Sync;
    /// What a run takes beyond config and data that is no hyperparameter (the SEADS game, the TRADYN
    /// lookup); recovered from the record when a run is resumed.
    type Variant: Clone + Send + Sync;
    /// What config.json records beyond the shared fields: model sizes, data counts.
    type Details: Clone + Serialize + DeserializeOwned;
    type Trainer: TrainingMethod + Send;

    /// The config with another total; called only for [`Method::EXTENDABLE`] methods.
    fn with_total_steps(config: &Self::Config, _steps: u64) -> Self::Config {
        config.clone()
    }
    /// Reads the data, checks it against the request and builds the trainer.
    fn prepare(request: &Request<Self>) -> Result<Prepared<Self>>;
    /// The variant a recorded run was started with.
    fn variant_of(record: &RunRecord<Self>) -> Result<Self::Variant>;
    /// Checks on a record read back beyond its types (sizes that must agree).
    fn check_record(_record: &RunRecord<Self>) -> Result<()> {
        Ok(())
    }
    /// Fields of config.json a request fixes besides config, seed and data, which a stopped run must share
    /// to be resumed by the same command.
    fn fixed_fields(_request: &Request<Self>) -> Vec<Field> {
        Vec::new()
    }
    /// Rewrites a config.json written by an older mbrl into today's layout (default: unchanged).
    fn upgrade(_record: &mut Value) {}
}

/// What the job reads of a method's config: the run's length, its schedule and its checks. Context and
/// TRADYN share one config, so they share this too.
pub trait RunConfig {
    fn total_steps(&self) -> u64;
    /// Steps between validations and between checkpoints.
    fn schedule(&self) -> (u64, u64);
    fn check(&self) -> Result<()>;
}

/// A new run: everything it is started from.
pub struct Request<M: Method> {
    /// The env the user named, checked against the data's (`None`: the data's own).
    pub env: Option<String>,
    pub data: Vec<PathBuf>,
    pub seed: u64,
    pub config: M::Config,
    pub variant: M::Variant,
    pub provenance: Provenance,
}

/// What a method has made of a request: the trainer, the record's method-specific part, and the live view.
pub struct Prepared<M: Method> {
    /// The env the run models, as its canonical name (`None` for the ball, which has no env).
    pub env: Option<String>,
    pub data: Vec<DataFile>,
    pub details: M::Details,
    pub trainer: M::Trainer,
    /// The title, panels and settings the live view opens with.
    pub view: Vec<Event>,
}

/// config.json: the description of a run that it is rebuilt from when resumed and loaded.
#[derive(Serialize, Deserialize)]
#[serde(bound(serialize = "", deserialize = ""))]
pub struct RunRecord<M: Method> {
    pub method: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub env: Option<String>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub data: Vec<DataFile>,
    pub seed: u64,
    pub config: M::Config,
    #[serde(flatten)]
    pub details: M::Details,
    pub provenance: Provenance,
}

// By hand, as derives would ask the method's marker type, not the record's fields, to be Clone.
impl<M: Method> Clone for RunRecord<M> {
    fn clone(&self) -> Self {
        RunRecord {
            method: self.method.clone(),
            env: self.env.clone(),
            data: self.data.clone(),
            seed: self.seed,
            config: self.config.clone(),
            details: self.details.clone(),
            provenance: self.provenance.clone(),
        }
    }
}

impl<M: Method> std::fmt::Debug for RunRecord<M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&serde_json::to_string(self).map_err(|_| std::fmt::Error)?)
    }
}

impl<M: Method> RunRecord<M> {
    pub fn to_value(&self) -> Result<Value> {
        serde_json::to_value(self).map_err(|e| Error::config(format!("{CONFIG_FILE}: {e}")))
    }

    /// The run's record from config.json, in today's layout, with no field it does not know (flattened
    /// details let serde skip unknown keys, so they are checked here).
    pub fn from_value(path: &Path, mut value: Value) -> Result<Self> {
        M::upgrade(&mut value);
        let record: RunRecord<M> = serde_json::from_value(value.clone())
            .map_err(|e| Error::bad_file(path, format!("not a {} run config: {e}", M::TITLE)))?;
        let known = record.to_value()?;
        if let (Some(given), Some(known)) = (value.as_object(), known.as_object()) {
            if let Some(unknown) = given.keys().find(|key| !known.contains_key(*key)) {
                return Err(Error::bad_file(path, format!("unknown field `{unknown}` in a {} run config", M::TITLE)));
            }
        }
        if record.method != M::NAME {
            return Err(Error::bad_file(path, format!("method '{}', expected '{}'", record.method, M::NAME)));
        }
        record.config.check().map_err(|e| e.at(path))?;
        M::check_record(&record).map_err(|e| e.at(path))?;
        Ok(record)
    }

    /// The record of an opened checkpoint of this method.
    pub fn read(opened: &OpenedCheckpoint) -> Result<Self> {
        Self::from_value(&opened.dir.file(CONFIG_FILE), opened.config.clone())
    }

    /// The env's canonical name; empty for a method without an env (the ball).
    pub fn env(&self) -> &str {
        self.env.as_deref().unwrap_or_default()
    }

    /// The same record under another method sharing this one's config and details (TRADYN is a context
    /// model), for code that serves both.
    pub fn retag<N: Method<Config = M::Config, Details = M::Details>>(self) -> RunRecord<N> {
        RunRecord {
            method: self.method,
            env: self.env,
            data: self.data,
            seed: self.seed,
            config: self.config,
            details: self.details,
            provenance: self.provenance,
        }
    }

    pub fn data_paths(&self) -> Vec<PathBuf> {
        self.data.iter().map(|f| f.path.clone()).collect()
    }
}

/// A training run that has ended: its record, how it went, and the trainer in its final state (for the
/// figures a method reports).
pub struct Trained<M: Method> {
    pub record: RunRecord<M>,
    pub outcome: FitOutcome,
    pub trainer: M::Trainer,
}
