//! `mbrl train seads`.

use std::path::PathBuf;

use clap::Args;

use super::shared::{train, RunOptions, TrainSummary};
use super::ScalePreset;
use crate::jobs::{Invocation, Job};
use crate::models::seads::options::{self as seads_options, default_out_for};
use crate::models::seads::{self, EmbodiedGame, Seads};
use crate::train::Request;
use crate::{refuse, Result};

#[derive(Args, Debug)]
#[command(
    next_help_heading = "SEADS options",
    mut_arg("out", |a| a.help("Checkpoint directory (default: models/seads-<env>)")),
    after_help = "\
Examples:
  mbrl train seads --env tileswap:cursor --preset small --out models/seads-tileswap-cursor
  mbrl train seads --env lightsout:cursor --preset medium --no-novelty --out models/seads-lo-no-novelty
  mbrl solve-board --model models/seads-tileswap-cursor --random-depth 3

Learning rates and batch sizes are keys of the --config file."
)]
pub struct SeadsOptions {
    /// The embodied board game: lightsout:cursor, tileswap:cursor, lightsout:reacher or tileswap:reacher.
    #[arg(long, value_parser = crate::jobs::names::embodied_envs(), hide_possible_values = true)]
    env: Option<String>,
    /// Hyperparameters from a TOML file (keys of config.json's `config` table), over the preset's.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Network sizes and budget (default: small; paper: 500k env steps on the Cursor, 10M on the Reacher).
    #[arg(long, value_enum)]
    preset: Option<ScalePreset>,
    /// Number of skills K (default: the game's move count, 25 LightsOut, 12 TileSwap).
    #[arg(long)]
    skills: Option<usize>,
    /// Budget of environment steps (default: the preset's).
    #[arg(long)]
    env_steps: Option<u64>,
    /// Ablation: no relabelling of skill labels.
    #[arg(long)]
    no_relabel: bool,
    /// Ablation: no second-best normalization of the reward.
    #[arg(long)]
    no_second_best: bool,
    /// Ablation: no novelty bonus in the reward.
    #[arg(long)]
    no_novelty: bool,
    #[command(flatten)]
    run: RunOptions,
}

pub fn prepare(options: SeadsOptions, invocation: &Invocation) -> Result<Job<'static, TrainSummary>> {
    let Some(env_name) = options.env.as_deref() else {
        refuse!("seads needs --env ({})", seads::ENV_HELP);
    };
    let env = EmbodiedGame::parse(env_name)?;
    let settings = seads_options::SeadsOptions {
        preset: options.preset.map(|p| match p {
            ScalePreset::Small => seads::Preset::Small,
            ScalePreset::Medium => seads::Preset::Medium,
            ScalePreset::Paper => seads::Preset::Paper,
        }),
        config_file: options.config,
        skills: options.skills,
        env_steps: options.env_steps,
        no_relabel: options.no_relabel,
        no_second_best: options.no_second_best,
        no_novelty: options.no_novelty,
    };
    let request = Request::<Seads> {
        env: Some(env.name()),
        data: Vec::new(),
        seed: invocation.seed,
        config: settings.config(&env)?,
        variant: (),
        provenance: invocation.provenance(),
    };
    let out = options.run.out.clone().unwrap_or_else(|| default_out_for(&env));
    train(out, &options.run, request, invocation)
}
