//! `mbrl train seads`.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use mbrl::models::seads::options::{default_out_for, SeadsOptions};
use mbrl::models::seads::{self, EmbodiedGame, Seads};
use mbrl::train::Request;

use super::shared::{provenance, train, RunArgs};
use super::ScalePreset;
use crate::common::GlobalArgs;

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
pub struct SeadsArgs {
    /// The embodied board game: lightsout:cursor, tileswap:cursor, lightsout:reacher or tileswap:reacher.
    #[arg(long)]
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
    run: RunArgs,
}

pub fn run(global: &GlobalArgs, args: SeadsArgs) -> anyhow::Result<()> {
    let env_name = args.env.as_deref().context(format!("seads needs --env ({})", seads::ENV_HELP))?;
    let env = EmbodiedGame::parse(env_name)?;
    let options = SeadsOptions {
        preset: args.preset.map(|p| match p {
            ScalePreset::Small => seads::Preset::Small,
            ScalePreset::Medium => seads::Preset::Medium,
            ScalePreset::Paper => seads::Preset::Paper,
        }),
        config_file: args.config.clone(),
        skills: args.skills,
        env_steps: args.env_steps,
        no_relabel: args.no_relabel,
        no_second_best: args.no_second_best,
        no_novelty: args.no_novelty,
    };
    let config = options.config(&env)?;
    let request = Request::<Seads> {
        env: Some(env.name()),
        data: Vec::new(),
        seed: global.seed,
        config,
        variant: (),
        provenance: provenance(global),
    };
    let out = args.run.out.clone().unwrap_or_else(|| default_out_for(&env));
    train(global, &out, &request, args.run.resume_if_stopped)
}
