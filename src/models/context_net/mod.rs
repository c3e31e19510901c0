//! The context-conditional GRU dynamics model that Explore the Context (thesis ch. 4) and TRADYN (ch. 5)
//! both train: its config, data, network, fast inference and gradients, the run record they share, and
//! loading it back. The methods' own parts (EIG calibration; the terrain lookup and navigation) live in
//! `models::context` and `models::tradyn`, which both build on this folder and not on each other.

pub mod config;
pub mod data;
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
use crate::train::tensors::to_params;
use crate::train::RunConfig;
use crate::train::{
    loss_panel, training_view, DataFile, FitOutcome, Method, OpenedCheckpoint, Prepared, Request, RunRecord, Trained,
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

/// What a context-model run records beyond the shared fields.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContextDetails {
    pub model: ModelSpec,
    pub instances: InstanceCounts,
    /// States per training chunk actually used (the config's, or fewer for short rollouts).
    pub chunk_states: usize,
}

/// config.json of a context-model checkpoint (TRADYN's too, read as one).
pub type ContextRun = RunRecord<Context>;

/// Explore the Context's model as the training job drives it.
pub struct Context;

impl RunConfig for ContextConfig {
    fn total_steps(&self) -> u64 {
        self.steps
    }

    fn schedule(&self) -> (u64, u64) {
        (self.validate_every, self.checkpoint_every)
    }

    fn check(&self) -> Result<()> {
        self.validate()
    }
}

impl Method for Context {
    const NAME: &'static str = METHOD;
    const TITLE: &'static str = "context-model";
    type Config = ContextConfig;
    type Variant = ();
    type Details = ContextDetails;
    type Trainer = ContextTrainer;

    fn prepare(request: &Request<Self>) -> Result<Prepared<Self>> {
        prepare_model(request, &StateSpace::EnvState)
    }

    fn variant_of(_record: &ContextRun) -> Result<()> {
        Ok(())
    }

    fn check_record(record: &ContextRun) -> Result<()> {
        check_details(&record.details, &record.data)
    }
}

/// The checks every record of this network passes: sizes that agree, and a dataset to resume from.
pub fn check_details(details: &ContextDetails, data: &[DataFile]) -> Result<()> {
    details.model.validate().map_err(|e| e.field("model"))?;
    if data.len() != 1 {
        return Err(Error::config(format!("lists {} training data files; a context model trains on one", data.len())));
    }
    Ok(())
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InstanceCounts {
    pub train: usize,
    pub valid: usize,
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
    let grouped = crate::data::instance_pairs(dataset).map_err(|e| e.at(path))?;
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

/// Builds the trainer of a context model (Explore the Context's, or TRADYN's on `space`) from a request.
pub fn prepare_model<M>(request: &Request<M>, space: &StateSpace) -> Result<Prepared<M>>
where
    M: Method<Config = ContextConfig, Details = ContextDetails, Trainer = ContextTrainer>,
{
    let [path] = request.data.as_slice() else {
        return Err(Error::config(format!("a context model trains on one dataset, got {}", request.data.len())));
    };
    let file = DataFile::fingerprint(path)?;
    let dataset = read_dataset(path)?;
    let env = crate::train::datasets::env_of(&dataset, request.env.as_deref(), path)?;
    let model = model_spec(space, &env, &dataset, path)?;
    let all = instance_pairs(&dataset, path, &model)?;
    let c = &request.config;
    let (train_data, valid_data) = all.split(c.validation_fraction, request.seed);
    let chunk_states = train_data.chunk_states(c.chunk_states)?;
    let instances = InstanceCounts { train: train_data.len(), valid: valid_data.len() };
    let trainer = ContextTrainer::new(c.clone(), request.seed, train_data, valid_data)?;
    let schedule = c.context_from_target;
    let view = training_view(
        &format!("train {} model on {}", M::NAME, env.canonical()),
        vec![loss_panel("loss, eq. 4.32 (train, held-out)", true)],
        &[
            ("instances", format!("{} train / {} valid", instances.train, instances.valid)),
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
            ("parameters", trainer.parameter_count().to_string()),
        ],
    );
    Ok(Prepared {
        env: Some(env.canonical()),
        data: vec![file],
        details: ContextDetails { model, instances, chunk_states },
        trainer,
        view,
    })
}

/// What `mbrl train context` and `mbrl train tradyn` report of a finished run.
pub struct ContextSummary {
    /// "a context model", "a TRADYN model with terrain lookup".
    pub what: String,
    pub record: ContextRun,
    pub outcome: FitOutcome,
    pub parameters: usize,
    pub dir: PathBuf,
}

impl ContextSummary {
    pub fn of<M>(what: String, trained: &Trained<M>, dir: &Path) -> Self
    where
        M: Method<Config = ContextConfig, Details = ContextDetails, Trainer = ContextTrainer>,
    {
        ContextSummary {
            what,
            record: trained.record.clone().retag(),
            outcome: trained.outcome.clone(),
            parameters: trained.trainer.parameter_count(),
            dir: dir.to_path_buf(),
        }
    }
}

impl std::fmt::Display for ContextSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (run, c) = (&self.record, &self.record.config);
        writeln!(
            f,
            "trained {} (embedding {}, D_F {}, D_β {}, {} parameters) on {} instances of {} ({} held out), batch {} × {} states",
            self.what,
            c.embedding,
            c.transition_features,
            c.latent_dim,
            self.parameters,
            run.details.instances.train,
            run.env(),
            run.details.instances.valid,
            c.batch_size,
            run.details.chunk_states
        )?;
        let o = &self.outcome;
        if let Some(loss) = o.last_train_loss {
            writeln!(f, "final training loss {loss:.4} after {} steps", o.steps)?;
        }
        if let (Some(step), Some(v)) = (o.best_step, o.best_valid_loss) {
            writeln!(f, "best validation loss {v:.4} at step {step} (saved as model.safetensors)")?;
        }
        write!(f, "checkpoint: {}", self.dir.display())
    }
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
        let spec = &self.run.details.model;
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
        let spec = &self.run.details.model;
        let mut out = Vec::with_capacity(spec.feature_dim);
        crate::nn::features::features(state, &[], &spec.angular, &mut out);
        out
    }
}

/// The model of an opened checkpoint of this network (made by `context` or `tradyn`) whose record is `run`.
pub fn model_from(opened: &OpenedCheckpoint, run: ContextRun, env: &EnvName) -> Result<LoadedModel> {
    let dir = opened.dir.path();
    if run.env() != env.canonical() {
        return Err(Error::bad_file(dir, format!("is a model of '{}', not of '{}'", run.env(), env.canonical())));
    }
    let model_path = opened.dir.file(MODEL_FILE);
    let device = crate::nn::tensor::inference_device();
    let m = &run.details.model;
    let layout_net = train::init_net(&run.config, m.feature_dim, m.action_dim, m.local_dim, 0, &device);
    let layout = crate::nn::ParamSet::<f32>::from_module(&layout_net, net::param_name);
    let params = to_params(&model_path, &opened.tensors(MODEL_FILE)?, &layout)?;
    let fast = FastContextModel::from_params(&params).map_err(|e| e.at(&model_path))?;
    Ok(LoadedModel { run, fast, dir: dir.to_path_buf(), progress: opened.progress() })
}
