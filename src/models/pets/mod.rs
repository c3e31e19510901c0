//! PETS (Chua et al. 2018, as in mbrl-lib): an ensemble of probabilistic MLPs predicting the state change,
//! bootstrapped per member, planned over with CEM and trajectory sampling. The first learned dynamics model of
//! mbrl and the reference for the ones that follow.

pub mod config;
pub mod data;
pub mod dynamics;
pub mod grad;
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
use crate::train::datasets::{env_of, load_datasets, TransitionCounts};
use crate::train::tensors::{to_params, TensorData};
use crate::train::RunConfig;
use crate::train::{
    loss_panel, open_run, training_view, validation_panel, Accept, FitOutcome, Method, OpenedCheckpoint, Prepared,
    Request, RunRecord, Trained, MODEL_FILE,
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

/// What a PETS run records beyond the shared fields.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PetsDetails {
    pub model: ModelSpec,
    pub transitions: TransitionCounts,
}

/// config.json of a PETS checkpoint.
pub type PetsRun = RunRecord<Pets>;

/// PETS as the training job drives it.
pub struct Pets;

impl RunConfig for PetsConfig {
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

impl Method for Pets {
    const NAME: &'static str = METHOD;
    const TITLE: &'static str = "PETS";
    const EXTENDABLE: bool = true;
    type Config = PetsConfig;
    type Variant = ();
    type Details = PetsDetails;
    type Trainer = PetsTrainer;

    fn with_total_steps(config: &PetsConfig, steps: u64) -> PetsConfig {
        PetsConfig { steps, ..config.clone() }
    }

    fn prepare(request: &Request<Self>) -> Result<Prepared<Self>> {
        let (dataset, files) = load_datasets(&request.data)?;
        let env = env_of(&dataset, request.env.as_deref(), &request.data[0])?;
        let spec = env.build()?.spec();
        let c = &request.config;
        if c.reward == RewardSource::Known && env.known_reward().is_none() {
            return Err(Error::config(format!(
                "env '{}' has no closed-form reward; train with --reward learned",
                env.canonical()
            )));
        }
        let split = data::split_dataset(&dataset, &spec.angular, c.reward, c.validation_fraction, request.seed)?;
        let details = PetsDetails {
            model: ModelSpec {
                state_names: dataset.meta.state_names.clone(),
                angular: spec.angular.clone(),
                action_dim: dataset.meta.action_dim,
                input_dim: split.train.input_dim,
                target_dim: split.train.target_dim,
            },
            transitions: TransitionCounts {
                train: split.train.len(),
                valid: split.valid.len(),
                train_rollouts: split.train_rollouts,
                valid_rollouts: split.valid_rollouts,
            },
        };
        let trainer = PetsTrainer::new(c.clone(), request.seed, split.train, split.valid)?;
        let t = &details.transitions;
        let view = training_view(
            &format!("train PETS on {}", env.canonical()),
            vec![loss_panel("train loss: Gaussian NLL", false), validation_panel("valid: MSE of the mean (held-out)")],
            &[
                ("transitions", format!("{} train / {} valid", t.train, t.valid)),
                ("ensemble", format!("{}{}", c.ensemble, if c.bootstrap { ", bootstrapped" } else { "" })),
                ("batch", format!("{} per member", c.batch_size)),
                ("learning rate", format!("{}", c.optimizer.learning_rate)),
                ("weight decay", format!("{}", c.optimizer.weight_decay)),
                ("parameters", trainer.parameter_count().to_string()),
            ],
        );
        Ok(Prepared { env: Some(env.canonical()), data: files, details, trainer, view })
    }

    fn variant_of(_record: &PetsRun) -> Result<()> {
        Ok(())
    }

    fn check_record(record: &PetsRun) -> Result<()> {
        record.details.model.validate(record.config.reward).map_err(|e| e.field("model"))?;
        if record.data.is_empty() {
            return Err(Error::config("lists no training data file"));
        }
        Ok(())
    }
}

/// What `mbrl train pets` reports of a finished run.
pub struct PetsSummary {
    pub record: PetsRun,
    pub outcome: FitOutcome,
    pub parameters: usize,
    pub dir: PathBuf,
}

impl PetsSummary {
    pub fn of(trained: &Trained<Pets>, dir: &Path) -> Self {
        PetsSummary {
            record: trained.record.clone(),
            outcome: trained.outcome.clone(),
            parameters: trained.trainer.parameter_count(),
            dir: dir.to_path_buf(),
        }
    }
}

impl std::fmt::Display for PetsSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (run, c) = (&self.record, &self.record.config);
        let t = &run.details.transitions;
        writeln!(
            f,
            "trained a PETS ensemble of {} ({}×{} {}, {} parameters, reward {}) on {} transitions of {} ({} rollouts; {} held out)",
            c.ensemble,
            c.hidden_layers,
            c.hidden_units,
            c.activation.name(),
            self.parameters,
            match c.reward {
                RewardSource::Known => "known",
                RewardSource::Learned => "learned",
            },
            t.train,
            run.env.as_deref().unwrap_or_default(),
            t.train_rollouts,
            t.valid_rollouts
        )?;
        let o = &self.outcome;
        if let Some(loss) = o.last_train_loss {
            writeln!(f, "final training loss (Gaussian NLL) {loss:.4} after {} steps", o.steps)?;
        }
        if let (Some(step), Some(v)) = (o.best_step, o.best_valid_loss) {
            writeln!(f, "best validation MSE {v:.3e} at step {step} (saved as model.safetensors)")?;
            // PETS training does not depend on its total, so the first `step` steps of a shorter run are these.
            if step.saturating_mul(2) <= o.steps {
                writeln!(
                    f,
                    "the steps after {step} only fit the training data closer: --steps {step} trains the same saved \
                     model in {:.0} % of the time",
                    100.0 * step as f64 / o.steps as f64
                )?;
            }
        }
        write!(f, "checkpoint: {}", self.dir.display())
    }
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

/// A PETS checkpoint as a planner's dynamics in `env` (which must be the env it was trained on); a run still
/// in training only when `accept` takes it (then its best-validation weights so far).
pub fn load_dynamics(
    dir: &Path,
    env: &EnvName,
    propagation: Propagation,
    particles: usize,
    accept: Accept,
) -> Result<PetsDynamics> {
    let (opened, run) = open_run::<Pets>(dir, accept)?;
    dynamics_from(&opened, &run, env, propagation, particles)
}

/// The dynamics of an opened PETS checkpoint whose record is `run`.
pub fn dynamics_from(
    opened: &OpenedCheckpoint,
    run: &PetsRun,
    env: &EnvName,
    propagation: Propagation,
    particles: usize,
) -> Result<PetsDynamics> {
    let dir = opened.dir.path();
    if run.env.as_deref() != Some(env.canonical().as_str()) {
        return Err(Error::bad_file(
            dir,
            format!(
                "is a model of '{}'; it cannot plan in '{}'",
                run.env.as_deref().unwrap_or_default(),
                env.canonical()
            ),
        ));
    }
    let stored = opened.tensors(MODEL_FILE)?;
    let model_path = opened.dir.file(MODEL_FILE);
    let normalizer_part = |name: &str| -> Result<Vec<f32>> {
        match stored.iter().find(|t| t.name == name).map(|t| &t.data) {
            Some(TensorData::F32(v)) if v.len() == run.details.model.input_dim => Ok(v.clone()),
            _ => Err(Error::bad_file(
                &model_path,
                format!("lacks '{name}' with {} f32 values", run.details.model.input_dim),
            )),
        }
    };
    let normalizer = Normalizer { mean: normalizer_part(net::INPUT_MEAN)?, std: normalizer_part(net::INPUT_STD)? };
    normalizer.validate().map_err(|e| e.at(&model_path))?;
    let layout = layout_of(run)?;
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
        run.details.model.angular.clone(),
        run.details.model.action_dim,
        reward,
        propagation,
        particles,
    )
    .map(|dynamics| dynamics.with_note(&opened.progress().unfinished_note()))
    .map_err(|e| e.at(&model_path))
}

/// The parameter names and shapes a network of this run has (built on the inference device, weights unused).
fn layout_of(run: &PetsRun) -> Result<crate::nn::ParamSet> {
    use rand::SeedableRng;
    let device = crate::nn::tensor::inference_device();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    let net =
        net::PetsNet::init(&run.config, run.details.model.input_dim, run.details.model.target_dim, &device, &mut rng);
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

    #[test]
    fn a_trainer_needs_targets_as_well_as_inputs() {
        use data::Transitions;
        let train = Transitions { inputs: vec![0.5; 8], targets: vec![], input_dim: 4, target_dim: 0 };
        let config = PetsConfig::preset(Preset::Small);
        let error = train::PetsTrainer::new(config, 0, train, Transitions::default()).err().expect("refused");
        assert!(error.to_string().contains("4 inputs and 0 targets"), "{error}");
    }
}
