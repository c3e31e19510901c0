//! `mbrl train seads`.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::shared::{train, RunOptions, TrainSummary};
use crate::jobs::overrides::Overrides;
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
  mbrl train seads --env tileswap:cursor --preset small sac_learning_rate=1e-3 --out models/seads-tileswap-sac-lr
  mbrl solve-board --model models/seads-tileswap-cursor --random-depth 3

Learning rates and batch sizes have no flags: set them as KEY=VALUE or in the --config file. Settings apply in this order, each over the one before: the preset, the --config file, the flags, then KEY=VALUE arguments. --config takes TOML (keys of config.json's `config` table, nested ones as tables or dotted keys) or JSON: a run's own config.json reruns that run's config. An unknown KEY lists the valid keys of the method."
)]
pub struct SeadsOptions {
    /// The embodied board game: lightsout:cursor, tileswap:cursor, lightsout:reacher or tileswap:reacher.
    #[arg(long, value_parser = crate::jobs::names::embodied_envs(), hide_possible_values = true)]
    env: Option<String>,
    /// Hyperparameters over the preset's: a TOML file of config keys, or a run's config.json to rerun it.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Network sizes and budget of environment steps (default: small).
    #[arg(long, value_enum)]
    preset: Option<SeadsPreset>,
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
    #[command(flatten)]
    set: Overrides,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum SeadsPreset {
    /// A short budget for tests and `eval quick` (about a minute for a Cursor game on 2 cores): SAC of 64 units
    /// and the paper's forward model (256 units) with 16 Adam steps per epoch instead of 4.
    Small,
    /// The paper's networks (256 units) on a fifth of the Cursor budget.
    Medium,
    /// The paper's networks and budgets: 500k environment steps on the Cursor, 10M on the Reacher.
    Paper,
}

pub fn prepare(options: SeadsOptions, invocation: &Invocation) -> Result<Job<'static, TrainSummary>> {
    let Some(env_name) = options.env.as_deref() else {
        refuse!("seads needs --env ({})", seads::ENV_HELP);
    };
    let env = EmbodiedGame::parse(env_name)?;
    let settings = seads_options::SeadsOptions {
        preset: options.preset.map(|p| match p {
            SeadsPreset::Small => seads::Preset::Small,
            SeadsPreset::Medium => seads::Preset::Medium,
            SeadsPreset::Paper => seads::Preset::Paper,
        }),
        config_file: options.config,
        skills: options.skills,
        env_steps: options.env_steps,
        no_relabel: options.no_relabel,
        no_second_best: options.no_second_best,
        no_novelty: options.no_novelty,
        overrides: options.set.set,
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
