//! Explore the Context (thesis chapter 4): a GRU dynamics model conditioned on a latent context β, a context
//! encoder that turns observed transitions into a belief q(β | C) whose variance never grows as transitions are
//! added, and calibration that picks actions by the expected information gain about β.

pub mod calibration;
pub mod config;
pub mod data;
pub mod dynamics;
pub mod eig;
pub mod fast;
pub mod grad;
pub mod net;
pub mod options;
pub mod train;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use config::{ContextConfig, EnvFamily, Preset};
pub use fast::FastContextModel;
pub use train::ContextTrainer;

use crate::data::{read_dataset, Dataset};
use crate::envs::EnvName;
use crate::error::{Error, Result};
use crate::run::dir::Provenance;
use crate::run::Monitor;
use crate::train::tensors::to_params;
use crate::train::{
    loss_panel, run_training, training_view, Accept, DataFile, FitOutcome, FitSettings, OpenedCheckpoint, Start,
    TrainingProgress, MODEL_FILE,
};
use data::{ContextData, Episode, InstancePair};

pub const METHOD: &str = "context";
const SPLIT_STREAM: u64 = 5;

/// What the model is a model of.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    pub state_names: Vec<String>,
    pub angular: Vec<bool>,
    pub action_dim: usize,
    /// Model-space state size (angles as cos/sin).
    pub feature_dim: usize,
    /// The model's state is the env's observation (`state_names` then name its features), not its state.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub observations: bool,
    /// Trailing features read from the world at the predicted state instead of predicted (TRADYN's terrain).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub local_dim: usize,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// What the model's state is.
#[derive(Clone, Debug, PartialEq)]
pub enum StateSpace {
    /// The env's state, angles as cos/sin (Explore the Context).
    EnvState,
    /// The env's observation with these feature names, the last `local_dim` of which are read from the world
    /// (TRADYN; 0 for its ablation that predicts them).
    Observation { names: Vec<String>, local_dim: usize },
}

/// config.json of a context-model checkpoint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContextRun {
    pub method: String,
    pub env: String,
    pub data: Vec<DataFile>,
    pub seed: u64,
    pub model: ModelSpec,
    pub config: ContextConfig,
    pub instances: InstanceCounts,
    /// States per training chunk actually used (the config's, or fewer for short rollouts).
    pub chunk_states: usize,
    pub provenance: Provenance,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InstanceCounts {
    pub train: usize,
    pub valid: usize,
}

pub struct TrainRequest {
    /// The checkpoint's method name (`context`, or `tradyn` for the terrain-aware variant).
    pub method: String,
    pub space: StateSpace,
    pub out: PathBuf,
    pub data: PathBuf,
    pub env: Option<String>,
    pub config: ContextConfig,
    pub seed: u64,
    pub provenance: Provenance,
}

pub struct TrainReport {
    pub run: ContextRun,
    pub outcome: FitOutcome,
    pub parameters: usize,
}

/// The Table B.1 column an env belongs to.
pub fn family_of(env: &EnvName) -> EnvFamily {
    if env.canonical().starts_with("toy:") {
        EnvFamily::Toy
    } else {
        EnvFamily::Control
    }
}

/// Instance pairs of a context dataset: rollout 2k is instance k's target rollout, 2k + 1 its context source.
pub fn instance_pairs(dataset: &Dataset, path: &Path, spec: &ModelSpec) -> Result<ContextData> {
    if dataset.meta.layout != crate::data::DatasetLayout::InstancePairs {
        return Err(Error::bad_file(
            path,
            format!(
                "holds independent rollouts; a context model trains on instance pairs (`mbrl collect --env {} --instances N --steps T`)",
                dataset.meta.env
            ),
        ));
    }
    let grouped = crate::data::instance_pairs(dataset).map_err(|e| Error::bad_file(path, e.to_string()))?;
    if grouped.is_empty() {
        return Err(Error::bad_file(
            path,
            format!("holds no instance pairs (make some with `mbrl collect --env {} --instances N`)", dataset.meta.env),
        ));
    }
    let episode = |rollout: &crate::data::Rollout| -> Result<Episode> {
        if !spec.observations {
            return Ok(Episode::from_rollout(rollout, &spec.angular));
        }
        let width_ok = rollout.observations.len() == rollout.states.len()
            && rollout.observations.iter().all(|o| o.len() == spec.feature_dim && o.iter().all(|x| x.is_finite()));
        if !width_ok {
            return Err(Error::bad_file(
                path,
                format!(
                    "observations: expected {} finite features at every state ({})",
                    spec.feature_dim,
                    spec.state_names.join(", ")
                ),
            ));
        }
        Ok(Episode::from_observations(rollout))
    };
    let pairs = grouped
        .iter()
        .map(|(a, b)| Ok(InstancePair { target: episode(a)?, source: episode(b)? }))
        .collect::<Result<Vec<InstancePair>>>()?;
    Ok(ContextData {
        state_dim: spec.feature_dim,
        action_dim: dataset.meta.action_dim,
        local_dim: spec.local_dim,
        pairs,
    })
}

/// Trains (or, with `resume`, continues) a context model into `request.out`.
pub fn train(request: &TrainRequest, resume: bool, monitor: &dyn Monitor) -> Result<TrainReport> {
    request.config.validate()?;
    let file = DataFile::fingerprint(&request.data)?;
    let dataset = read_dataset(&request.data)?;
    let env = crate::train::datasets::env_of(&dataset, request.env.as_deref(), &request.data)?;
    let model = model_spec(&request.space, &env, &dataset, &request.data)?;
    let all = instance_pairs(&dataset, &request.data, &model)?;
    let (train_data, valid_data) = all.split(request.config.validation_fraction, request.seed);
    let chunk_states = train_data.chunk_states(request.config.chunk_states)?;
    let run = ContextRun {
        method: request.method.clone(),
        env: env.canonical(),
        data: vec![file],
        seed: request.seed,
        model,
        config: request.config.clone(),
        instances: InstanceCounts { train: train_data.len(), valid: valid_data.len() },
        chunk_states,
        provenance: request.provenance.clone(),
    };
    let mut trainer = ContextTrainer::new(request.config.clone(), request.seed, train_data, valid_data)?;
    let parameters = trainer.parameter_count();
    let settings = FitSettings {
        method: request.method.clone(),
        env: Some(run.env.clone()),
        total_steps: request.config.steps,
        validate_every: request.config.validate_every,
        checkpoint_every: request.config.checkpoint_every,
    };
    let config = serde_json::to_value(&run).map_err(|e| Error::config(e.to_string()))?;
    let title = format!("train {} model on {}", run.method, run.env);
    let c = &request.config;
    let schedule = c.context_from_target;
    let view = training_view(
        &title,
        vec![loss_panel("loss, eq. 4.32 (train, held-out)", true)],
        &[
            ("instances", format!("{} train / {} valid", run.instances.train, run.instances.valid)),
            ("batch", format!("{} × {chunk_states} states", c.batch_size)),
            ("learning rate", format!("{}", c.optimizer.learning_rate)),
            ("KL", format!("weight {}, floor {}", c.kl_weight, c.kl_floor)),
            (
                "p ctx target",
                if schedule.start > 0.0 {
                    format!("{} → 0, steps {}-{}", schedule.start, schedule.decay_from, schedule.zero_at)
                } else {
                    "0".to_string()
                },
            ),
            ("parameters", parameters.to_string()),
        ],
    );
    let outcome =
        run_training(&request.out, &config, &settings, &mut trainer, Start::resuming(resume), &view, monitor)?;
    Ok(TrainReport { run, outcome, parameters })
}

/// The model's state space for `env`'s data, checked against the dataset's sizes.
fn model_spec(space: &StateSpace, env: &EnvName, dataset: &Dataset, path: &Path) -> Result<ModelSpec> {
    let action_dim = dataset.meta.action_dim;
    match space {
        StateSpace::EnvState => {
            let spec = env.build()?.spec();
            if dataset.meta.state_names.len() != spec.angular.len() || action_dim != spec.action_dim() {
                return Err(Error::bad_file(
                    path,
                    format!("state or action sizes differ from env '{}'", env.canonical()),
                ));
            }
            let feature_dim = spec.angular.iter().map(|&a| if a { 2 } else { 1 }).sum();
            Ok(ModelSpec {
                state_names: dataset.meta.state_names.clone(),
                angular: spec.angular.clone(),
                action_dim,
                feature_dim,
                observations: false,
                local_dim: 0,
            })
        }
        StateSpace::Observation { names, local_dim } => Ok(ModelSpec {
            state_names: names.clone(),
            angular: vec![false; names.len()],
            action_dim,
            feature_dim: names.len(),
            observations: true,
            local_dim: *local_dim,
        }),
    }
}

pub fn read_run(opened: &OpenedCheckpoint) -> Result<ContextRun> {
    let path = opened.dir.file("config.json");
    let run: ContextRun = serde_json::from_value(opened.config.clone())
        .map_err(|e| Error::bad_file(&path, format!("not a context-model run config: {e}")))?;
    run.model.validate().map_err(|e| Error::bad_file(&path, format!("model: {e}")))?;
    if run.data.is_empty() {
        return Err(Error::bad_file(&path, "lists no training data file"));
    }
    Ok(run)
}

/// Far above any env mbrl simulates; beyond it a size in config.json is corrupt.
const MAX_MODEL_DIM: usize = 256;

impl ModelSpec {
    /// The sizes agree with each other (angles take two model dimensions) and are plausible, so that
    /// nothing is allocated from a corrupt count.
    pub fn validate(&self) -> Result<()> {
        let states = self.state_names.len();
        if !(1..=MAX_MODEL_DIM).contains(&states) || !(1..=MAX_MODEL_DIM).contains(&self.action_dim) {
            return Err(Error::config(format!(
                "{states} state and {} action dimensions; expected 1..={MAX_MODEL_DIM} of each",
                self.action_dim
            )));
        }
        let features: usize = self.angular.iter().map(|&a| if a { 2 } else { 1 }).sum();
        if self.angular.len() != states || features != self.feature_dim {
            return Err(Error::config(format!(
                "{} angular flags and feature_dim {} do not fit {states} states ({features} features)",
                self.angular.len(),
                self.feature_dim
            )));
        }
        if self.observations && self.angular.iter().any(|&a| a) {
            return Err(Error::config("a model of observations has no angular features"));
        }
        if self.local_dim >= self.feature_dim {
            return Err(Error::config(format!(
                "local_dim {} leaves nothing to predict of {} features",
                self.local_dim, self.feature_dim
            )));
        }
        Ok(())
    }
}

/// Continues the run in `dir` from its last checkpoint, with the config and data it was started with.
pub fn resume(dir: &Path, monitor: &dyn Monitor) -> Result<TrainReport> {
    let opened = OpenedCheckpoint::open(dir)?;
    let run = read_run(&opened)?;
    opened.expect_total_steps(run.config.steps as u64)?;
    for file in &run.data {
        file.verify_unchanged()?;
    }
    let space = if run.model.observations {
        StateSpace::Observation { names: run.model.state_names.clone(), local_dim: run.model.local_dim }
    } else {
        StateSpace::EnvState
    };
    let request = TrainRequest {
        method: run.method.clone(),
        space,
        out: dir.to_path_buf(),
        data: run.data[0].path.clone(),
        env: Some(run.env.clone()),
        config: run.config.clone(),
        seed: run.seed,
        provenance: run.provenance.clone(),
    };
    train(&request, true, monitor)
}

/// A finished context model, ready to calibrate and plan in `env`.
#[derive(Clone)]
pub struct LoadedModel {
    pub run: ContextRun,
    pub fast: FastContextModel,
    pub dir: PathBuf,
    pub progress: TrainingProgress,
}

impl LoadedModel {
    /// The model's state for an env state and its observation: the observation itself for a model of
    /// observations (which must then be given, with the model's width), else the state's features.
    pub fn model_state(&self, state: &[f64], observation: Option<&Vec<f64>>) -> Result<Vec<f32>> {
        let spec = &self.run.model;
        if !spec.observations {
            return Ok(self.features(state));
        }
        match observation {
            Some(o) if o.len() == spec.feature_dim && o.iter().all(|x| x.is_finite()) => {
                Ok(o.iter().map(|x| *x as f32).collect())
            }
            _ => Err(Error::data(format!(
                "the model reads observations of {} finite features ({}) at every state",
                spec.feature_dim,
                spec.state_names.join(", ")
            ))),
        }
    }

    /// Model-space features of an env state (a model of the env's state; TRADYN models observations).
    pub fn features(&self, state: &[f64]) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.run.model.feature_dim);
        crate::nn::features::features(state, &[], &self.run.model.angular, &mut out);
        out
    }
}

/// Loads a finished context-model checkpoint for `env` (which must be the env it was trained on).
pub fn load(dir: &Path, env: &EnvName) -> Result<LoadedModel> {
    load_method(dir, env, METHOD)
}

/// Loads a finished checkpoint of this module's network made by `method` (`context` or `tradyn`).
pub fn load_method(dir: &Path, env: &EnvName, method: &str) -> Result<LoadedModel> {
    load_method_accepting(dir, env, method, Accept::Finished)
}

/// A context model of `env`, finished or (with [`Accept::InProgress`]) still training: then its
/// best-validation weights so far.
pub fn load_accepting(dir: &Path, env: &EnvName, accept: Accept) -> Result<LoadedModel> {
    load_method_accepting(dir, env, METHOD, accept)
}

/// As [`load_method`], also taking a run still in training when `accept` does.
pub fn load_method_accepting(dir: &Path, env: &EnvName, method: &str, accept: Accept) -> Result<LoadedModel> {
    let opened = OpenedCheckpoint::open(dir)?;
    if opened.manifest.method != method {
        return Err(Error::bad_file(
            dir,
            format!(
                "is a '{}' checkpoint; this needs a {method} model (`mbrl train {method}`)",
                opened.manifest.method
            ),
        ));
    }
    opened.expect(method, accept)?;
    let run = read_run(&opened)?;
    if run.env != env.canonical() {
        return Err(Error::bad_file(dir, format!("is a model of '{}', not of '{}'", run.env, env.canonical())));
    }
    let config_path = opened.dir.file("config.json");
    run.config.validate().map_err(|e| Error::bad_file(&config_path, e.to_string()))?;
    let model_path = opened.dir.file(MODEL_FILE);
    let device = crate::nn::tensor::inference_device();
    let m = &run.model;
    let layout_net = train::init_net(&run.config, m.feature_dim, m.action_dim, m.local_dim, 0, &device);
    let layout = crate::nn::ParamSet::<f32>::from_module(&layout_net, net::param_name);
    let params = to_params(&model_path, &opened.tensors(MODEL_FILE)?, &layout)?;
    let fast = FastContextModel::from_params(&params).map_err(|e| Error::bad_file(&model_path, e.to_string()))?;
    Ok(LoadedModel { run, fast, dir: dir.to_path_buf(), progress: opened.progress() })
}

#[cfg(test)]
mod tests;
