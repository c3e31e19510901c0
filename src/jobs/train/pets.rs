//! `mbrl train pets`.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::shared::{check_steps, train, RunOptions, TrainSummary};
use crate::jobs::overrides::Overrides;
use crate::jobs::{Invocation, Job};
use crate::models::pets::options as pets_options;
use crate::models::pets::{Pets, Preset, RewardSource};
use crate::train::Request;
use crate::Result;

#[derive(Args, Debug)]
#[command(
    next_help_heading = "PETS options",
    mut_arg("out", |a| a.help("Checkpoint directory (default: models/pets-<env>)")),
    after_help = "\
Examples:
  mbrl collect --env pendulum --rollouts 200 --steps 30 --out datasets/pendulum-random.mcap
  mbrl train pets --data datasets/pendulum-random.mcap --out models/pets-pendulum
  mbrl train pets --data datasets/pendulum-random.mcap --preset medium steps=3000 optimizer.learning_rate=3e-4 --out models/pets-medium
  mbrl train pets --data datasets/pendulum-random.mcap --config models/pets-medium/config.json --out models/pets-medium-again
  mbrl train --resume models/pets-medium --steps 8000

Settings apply in this order, each over the one before: the preset, the --config file, the flags, then KEY=VALUE arguments. --config takes TOML (keys of config.json's `config` table, nested ones as tables or dotted keys) or JSON: a run's own config.json reruns that run's config. An unknown KEY lists the valid keys of the method."
)]
pub struct PetsOptions {
    /// Rollout datasets (.mcap) of one env, merged (repeatable).
    #[arg(long, required = true)]
    data: Vec<PathBuf>,
    /// The env the data must come from (default: the dataset's env).
    #[arg(long, value_parser = crate::jobs::names::envs(), hide_possible_values = true)]
    env: Option<String>,
    /// Hyperparameters over the preset's: a TOML file of config keys, or a run's config.json to rerun it.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Network size and training length (default: small).
    #[arg(long, value_enum)]
    preset: Option<PetsPreset>,
    /// Ensemble members (default 5).
    #[arg(long)]
    ensemble: Option<usize>,
    /// Optimizer steps (default: the preset's).
    #[arg(long)]
    steps: Option<u64>,
    /// Transitions per member in a batch (default 256).
    #[arg(long)]
    batch: Option<usize>,
    /// Adam learning rate (default 1e-3).
    #[arg(long, value_parser = crate::jobs::finite_f64)]
    lr: Option<f64>,
    /// Where the model's reward comes from (default: known where the env has a closed form).
    #[arg(long, value_enum)]
    reward: Option<RewardChoice>,
    #[command(flatten)]
    run: RunOptions,
    #[command(flatten)]
    set: Overrides,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum PetsPreset {
    /// 3 hidden layers × 64 SiLU units, 2000 steps (≈ 10 s on 2 cores).
    Small,
    /// 4 × 200 SiLU units, 5000 steps: mbrl-lib's PETS pendulum network.
    Medium,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum RewardChoice {
    /// The env's closed-form reward (pendulum variants without hidden actuators).
    Known,
    /// An extra output of the network, trained on the dataset's rewards.
    Learned,
}

impl PetsOptions {
    fn settings(&self) -> pets_options::PetsOptions {
        pets_options::PetsOptions {
            preset: self.preset.map(|p| match p {
                PetsPreset::Small => Preset::Small,
                PetsPreset::Medium => Preset::Medium,
            }),
            config_file: self.config.clone(),
            ensemble: self.ensemble,
            steps: self.steps,
            batch_size: self.batch,
            learning_rate: self.lr,
            reward: self.reward.map(|r| match r {
                RewardChoice::Known => RewardSource::Known,
                RewardChoice::Learned => RewardSource::Learned,
            }),
            overrides: self.set.set.clone(),
        }
    }
}

pub fn prepare(options: PetsOptions, invocation: &Invocation) -> Result<Job<'static, TrainSummary>> {
    check_steps(options.steps)?;
    let first = &options.data[0];
    let planned = options.settings().plan(
        options.env.as_deref(),
        || Ok(crate::data::read_dataset(first)?.meta.env),
        options.run.out.clone(),
    )?;
    let request = Request::<Pets> {
        env: options.env,
        data: options.data,
        seed: invocation.seed,
        config: planned.config,
        variant: (),
        provenance: invocation.provenance(),
    };
    train(planned.out, &options.run, request, invocation)
}
