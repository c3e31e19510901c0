//! PETS (Chua et al. 2018, as in mbrl-lib): an ensemble of probabilistic MLPs predicting the state change,
//! bootstrapped per member, planned over with CEM and trajectory sampling. The first learned dynamics model of
//! mbrl and the reference for the ones that follow.

pub mod config;
pub mod data;
pub mod dynamics;
pub mod net;
pub mod options;
pub mod train;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use config::{PetsConfig, Preset, RewardSource};
pub use dynamics::{PetsDynamics, Propagation};
pub use train::PetsTrainer;

use crate::envs::EnvName;
use crate::error::{Error, Result};
use crate::nn::Normalizer;
use crate::run::dir::Provenance;
use crate::run::Monitor;
use crate::train::datasets::{env_of, load_datasets, TransitionCounts};
use crate::train::tensors::{to_params, TensorData};
use crate::train::{
    continuation, loss_panel, run_training, training_view, validation_panel, Accept, DataFile, Extension, FitOutcome,
    FitSettings, OpenedCheckpoint, Start, MODEL_FILE,
};

pub const METHOD: &str = "pets";

/// What the model is a model of: enough to rebuild features and check an env at planning time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    pub state_names: Vec<String>,
    pub angular: Vec<bool>,
    pub action_dim: usize,
    pub input_dim: usize,
    pub target_dim: usize,
}

/// config.json of a PETS checkpoint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PetsRun {
    pub method: String,
    pub env: String,
    pub data: Vec<DataFile>,
    pub seed: u64,
    pub model: ModelSpec,
    pub config: PetsConfig,
    pub transitions: TransitionCounts,
    pub provenance: Provenance,
}

pub struct TrainRequest {
    pub out: PathBuf,
    pub data: Vec<PathBuf>,
    /// The env the user named; must agree with the datasets'. `None`: take the datasets' env.
    pub env: Option<String>,
    pub config: PetsConfig,
    pub seed: u64,
    pub provenance: Provenance,
}

pub struct TrainReport {
    pub run: PetsRun,
    pub outcome: FitOutcome,
    pub parameters: usize,
}

/// Trains a PETS ensemble into `request.out`, fresh or continuing the run there (see [`Start`]).
pub fn train(request: &TrainRequest, start: Start, monitor: &dyn Monitor) -> Result<TrainReport> {
    request.config.validate()?;
    let (dataset, files) = load_datasets(&request.data)?;
    let env = env_of(&dataset, request.env.as_deref(), &request.data[0])?;
    let spec = env.build()?.spec();
    if request.config.reward == RewardSource::Known && env.known_reward().is_none() {
        return Err(Error::config(format!(
            "env '{}' has no closed-form reward; train with --reward learned",
            env.canonical()
        )));
    }
    let split = data::split_dataset(
        &dataset,
        &spec.angular,
        request.config.reward,
        request.config.validation_fraction,
        request.seed,
    )?;
    let run = PetsRun {
        method: METHOD.into(),
        env: env.canonical(),
        data: files,
        seed: request.seed,
        model: ModelSpec {
            state_names: dataset.meta.state_names.clone(),
            angular: spec.angular.clone(),
            action_dim: dataset.meta.action_dim,
            input_dim: split.train.input_dim,
            target_dim: split.train.target_dim,
        },
        config: request.config.clone(),
        transitions: TransitionCounts {
            train: split.train.len(),
            valid: split.valid.len(),
            train_rollouts: split.train_rollouts,
            valid_rollouts: split.valid_rollouts,
        },
        provenance: request.provenance.clone(),
    };
    let mut trainer = PetsTrainer::new(request.config.clone(), request.seed, split.train, split.valid)?;
    let parameters = trainer.parameter_count();
    let settings = FitSettings {
        method: METHOD.into(),
        env: Some(run.env.clone()),
        total_steps: request.config.steps,
        validate_every: request.config.validate_every,
        checkpoint_every: request.config.checkpoint_every,
    };
    let config = serde_json::to_value(&run).map_err(|e| Error::config(e.to_string()))?;
    let c = &request.config;
    let view = training_view(
        &format!("train PETS on {}", run.env),
        vec![loss_panel("train loss: Gaussian NLL", false), validation_panel("valid: MSE of the mean (held-out)")],
        &[
            ("transitions", format!("{} train / {} valid", run.transitions.train, run.transitions.valid)),
            ("ensemble", format!("{}{}", c.ensemble, if c.bootstrap { ", bootstrapped" } else { "" })),
            ("batch", format!("{} per member", c.batch_size)),
            ("learning rate", format!("{}", c.optimizer.learning_rate)),
            ("weight decay", format!("{}", c.optimizer.weight_decay)),
            ("parameters", parameters.to_string()),
        ],
    );
    let outcome = run_training(&request.out, &config, &settings, &mut trainer, start, &view, monitor)?;
    Ok(TrainReport { run, outcome, parameters })
}

fn read_run(opened: &OpenedCheckpoint) -> Result<PetsRun> {
    let path = opened.dir.file("config.json");
    let run: PetsRun = serde_json::from_value(opened.config.clone())
        .map_err(|e| Error::bad_file(&path, format!("not a PETS run config: {e}")))?;
    run.model.validate(run.config.reward).map_err(|e| Error::bad_file(&path, format!("model: {e}")))?;
    if run.data.is_empty() {
        return Err(Error::bad_file(&path, "lists no training data file"));
    }
    Ok(run)
}

/// Far above any env mbrl simulates; beyond it a size in config.json is corrupt.
const MAX_MODEL_DIM: usize = 256;

impl ModelSpec {
    /// The sizes agree with each other and with the reward source, and are plausible, so that no network
    /// is sized from a corrupt count.
    pub fn validate(&self, reward: RewardSource) -> Result<()> {
        let states = self.state_names.len();
        if !(1..=MAX_MODEL_DIM).contains(&states) || !(1..=MAX_MODEL_DIM).contains(&self.action_dim) {
            return Err(Error::config(format!(
                "{states} state and {} action dimensions; expected 1..={MAX_MODEL_DIM} of each",
                self.action_dim
            )));
        }
        let input = crate::nn::features::feature_dim(&self.angular, self.action_dim);
        let target = states + usize::from(reward == RewardSource::Learned);
        if self.angular.len() != states || self.input_dim != input || self.target_dim != target {
            return Err(Error::config(format!(
                "{} angular flags, input_dim {} and target_dim {} do not fit {states} states and {} actions \
                 (expected input_dim {input}, target_dim {target})",
                self.angular.len(),
                self.input_dim,
                self.target_dim,
                self.action_dim
            )));
        }
        Ok(())
    }
}

/// Continues the run in `dir` from its last checkpoint, with the config and data it was started with; with
/// `extend_to`, on to that many steps in total (the run may be finished: its training does not depend on the
/// total, so its weights end as those of a run started with that total, provided its old total fell on a
/// validation).
pub fn resume(dir: &Path, extend_to: Option<&Extension>, monitor: &dyn Monitor) -> Result<TrainReport> {
    let opened = OpenedCheckpoint::open(dir)?;
    let run = read_run(&opened)?;
    opened.expect_total_steps(run.config.steps as u64)?;
    let next = continuation(&opened, run.config.steps, &run.provenance, extend_to)?;
    for file in &run.data {
        file.verify_unchanged()?;
    }
    let request = TrainRequest {
        out: dir.to_path_buf(),
        data: run.data.iter().map(|f| f.path.clone()).collect(),
        env: Some(run.env.clone()),
        config: PetsConfig { steps: next.steps, ..run.config.clone() },
        seed: run.seed,
        provenance: next.provenance,
    };
    train(&request, next.start, monitor)
}

/// A PETS checkpoint as a planner's dynamics in `env` (which must be the env it was trained on); a run still
/// in training only when `accept` takes it (then its best-validation weights so far).
pub fn load_dynamics(
    dir: &Path,
    env: &EnvName,
    propagation: Propagation,
    particles: usize,
    accept: Accept,
) -> Result<PetsDynamics> {
    let opened = OpenedCheckpoint::open(dir)?;
    opened.expect(METHOD, accept)?;
    let run = read_run(&opened)?;
    if run.env != env.canonical() {
        return Err(Error::bad_file(
            dir,
            format!("is a model of '{}'; it cannot plan in '{}'", run.env, env.canonical()),
        ));
    }
    run.config.validate().map_err(|e| Error::bad_file(&opened.dir.file("config.json"), e.to_string()))?;
    let stored = opened.tensors(MODEL_FILE)?;
    let model_path = opened.dir.file(MODEL_FILE);
    let normalizer_part = |name: &str| -> Result<Vec<f32>> {
        match stored.iter().find(|t| t.name == name).map(|t| &t.data) {
            Some(TensorData::F32(v)) if v.len() == run.model.input_dim => Ok(v.clone()),
            _ => Err(Error::bad_file(&model_path, format!("lacks '{name}' with {} f32 values", run.model.input_dim))),
        }
    };
    let normalizer = Normalizer { mean: normalizer_part(net::INPUT_MEAN)?, std: normalizer_part(net::INPUT_STD)? };
    normalizer.validate().map_err(|e| Error::bad_file(&model_path, e.to_string()))?;
    let layout = layout_of(&run)?;
    let weights: Vec<_> = stored.iter().filter(|t| !t.name.starts_with("input_normalizer.")).cloned().collect();
    let weights = to_params(&model_path, &weights, &layout)?;
    let reward = match run.config.reward {
        RewardSource::Known => Some(crate::control::known_reward(env).ok_or_else(|| {
            Error::config(format!("env '{}' has no closed-form reward for this model", env.canonical()))
        })?),
        RewardSource::Learned => None,
    };
    PetsDynamics::new(
        &run.config,
        &weights,
        normalizer,
        run.model.angular.clone(),
        run.model.action_dim,
        reward,
        propagation,
        particles,
    )
    .map(|dynamics| dynamics.with_note(&opened.progress().unfinished_note()))
    .map_err(|e| Error::bad_file(&model_path, e.to_string()))
}

/// The parameter names and shapes a network of this run has (built on the inference device, weights unused).
fn layout_of(run: &PetsRun) -> Result<crate::nn::ParamSet> {
    use rand::SeedableRng;
    let device = crate::nn::tensor::inference_device();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    let net = net::PetsNet::init(&run.config, run.model.input_dim, run.model.target_dim, &device, &mut rng);
    Ok(crate::nn::ParamSet::<f32>::from_module(&net, net::torch_name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_spec_sizes_must_agree_with_the_states_and_reward() {
        let spec = ModelSpec {
            state_names: vec!["theta".into(), "omega".into()],
            angular: vec![true, false],
            action_dim: 1,
            input_dim: 4,
            target_dim: 2,
        };
        assert!(spec.validate(RewardSource::Known).is_ok());
        assert!(spec.validate(RewardSource::Learned).is_err());
        let huge = ModelSpec { target_dim: 2_147_483_648, ..spec.clone() };
        assert!(huge.validate(RewardSource::Known).unwrap_err().to_string().contains("target_dim 2147483648"));
        let none = ModelSpec { state_names: vec![], angular: vec![], ..spec };
        assert!(none.validate(RewardSource::Known).is_err());
    }
}
