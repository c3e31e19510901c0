//! `mbrl train pets`.

use std::path::PathBuf;

use clap::{Args, ValueEnum};
use mbrl::models::pets::options::PetsOptions;
use mbrl::models::pets::{Pets, Preset, RewardSource};
use mbrl::train::Request;

use super::shared::{check_steps, provenance, train, RunArgs};
use crate::common::GlobalArgs;

#[derive(Args, Debug)]
#[command(
    next_help_heading = "PETS options",
    mut_arg("out", |a| a.help("Checkpoint directory (default: models/pets-<env>)")),
    after_help = "\
Examples:
  mbrl collect --env pendulum --rollouts 200 --steps 30 --out datasets/pendulum-random.mcap
  mbrl train pets --env pendulum --data datasets/pendulum-random.mcap --out models/pets-pendulum
  mbrl train pets --data a.mcap --data b.mcap --preset medium --config pets.toml --out models/pets-big
  mbrl train --resume models/pets-big --steps 8000"
)]
pub struct PetsArgs {
    /// Rollout datasets (.mcap) of one env, merged (repeatable).
    #[arg(long, required = true)]
    data: Vec<PathBuf>,
    /// The env the data must come from (default: the dataset's env).
    #[arg(long)]
    env: Option<String>,
    /// Hyperparameters from a TOML file (keys of config.json's `config` table), over the preset's.
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
    #[arg(long, value_parser = crate::common::finite_f64)]
    lr: Option<f64>,
    /// Where the model's reward comes from (default: known where the env has a closed form).
    #[arg(long, value_enum)]
    reward: Option<RewardChoice>,
    #[command(flatten)]
    run: RunArgs,
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

impl PetsArgs {
    fn options(&self) -> PetsOptions {
        PetsOptions {
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
        }
    }
}

pub fn run(global: &GlobalArgs, args: PetsArgs) -> anyhow::Result<()> {
    check_steps(args.steps)?;
    let first = &args.data[0];
    let planned = args.options().plan(
        args.env.as_deref(),
        || Ok(mbrl::data::read_dataset(first)?.meta.env),
        args.run.out.clone(),
    )?;
    let request = Request::<Pets> {
        env: args.env.clone(),
        data: args.data.clone(),
        seed: global.seed,
        config: planned.config,
        variant: (),
        provenance: provenance(global),
    };
    train(global, &planned.out, &request, args.run.resume_if_stopped)
}
