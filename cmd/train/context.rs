//! `mbrl train context` and `mbrl train tradyn`: one model, on an env's state or on the unicycle with terrain.

use std::path::PathBuf;

use clap::Args;
use mbrl::models::context::options::ContextOptions;
use mbrl::models::context::{self, Context};
use mbrl::models::tradyn::{self, Tradyn};
use mbrl::train::Request;

use super::shared::{check_steps, provenance, train, RunArgs};
use super::ScalePreset;
use crate::common::GlobalArgs;

/// The flags context and TRADYN share: the model and its training are the same.
#[derive(Args, Debug)]
pub struct ModelOptions {
    /// Hyperparameters from a TOML file (keys of config.json's `config` table), over the preset's.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Network size and training length (default: small; paper: Table B.1).
    #[arg(long, value_enum)]
    preset: Option<ScalePreset>,
    /// Optimizer steps (default: the preset's); the p_ctx schedule keeps its shares of the run.
    #[arg(long)]
    steps: Option<u64>,
    /// Chunks of consecutive states in a batch (default: the preset's).
    #[arg(long)]
    batch: Option<usize>,
    /// Adam learning rate (default: the preset's).
    #[arg(long, value_parser = crate::common::finite_f64)]
    lr: Option<f64>,
}

#[derive(Args, Debug)]
#[command(
    next_help_heading = "Context options",
    mut_arg("out", |a| a.help("Checkpoint directory (default: models/context-<env>)")),
    after_help = "\
Examples:
  mbrl collect --env toy:inner --instances 1000 --steps 100 --out datasets/toy-inner.mcap
  mbrl train context --data datasets/toy-inner.mcap --preset small --out models/context-toy-inner
  mbrl calibrate --model models/context-toy-inner --env toy:inner --instance-seed 3"
)]
pub struct ContextArgs {
    /// An instance-pair dataset (.mcap) from `mbrl collect --instances N`.
    #[arg(long)]
    data: PathBuf,
    /// The env the data must come from (default: the dataset's env).
    #[arg(long)]
    env: Option<String>,
    #[command(flatten)]
    model: ModelOptions,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Args, Debug)]
#[command(
    next_help_heading = "TRADYN options",
    mut_arg("out", |a| a.help("Checkpoint directory (default: models/tradyn-terrain, models/tradyn-no-terrain)")),
    after_help = "\
Examples:
  mbrl collect --env terrain --maps 100 --out datasets/terrain
  mbrl collect --env unicycle --maps datasets/terrain --split train --instances 10000 --steps 100 --out datasets/unicycle-train.mcap
  mbrl train tradyn --data datasets/unicycle-train.mcap --preset small --out models/tradyn-terrain
  mbrl train tradyn --no-terrain --data datasets/unicycle-train.mcap --preset small --out models/tradyn-no-terrain"
)]
pub struct TradynArgs {
    /// A unicycle instance-pair dataset (.mcap): `collect --env unicycle --maps DIR --split train --instances N`.
    #[arg(long)]
    data: PathBuf,
    /// The env: TRADYN models the unicycle, the only value taken.
    #[arg(long, hide = true)]
    env: Option<String>,
    /// Ablation (thesis "−T"): no terrain lookup; the terrain features become part of the predicted state.
    #[arg(long)]
    no_terrain: bool,
    #[command(flatten)]
    model: ModelOptions,
    #[command(flatten)]
    run: RunArgs,
}

impl ModelOptions {
    fn options(&self) -> ContextOptions {
        ContextOptions {
            preset: self.preset.map(|p| match p {
                ScalePreset::Small => context::Preset::Small,
                ScalePreset::Medium => context::Preset::Medium,
                ScalePreset::Paper => context::Preset::Paper,
            }),
            config_file: self.config.clone(),
            steps: self.steps,
            batch_size: self.batch,
            learning_rate: self.lr,
        }
    }
}

pub fn run_context(global: &GlobalArgs, args: ContextArgs) -> anyhow::Result<()> {
    check_steps(args.model.steps)?;
    let data = &args.data;
    let planned = args.model.options().plan(
        data,
        args.env.as_deref(),
        || Ok(mbrl::data::read_dataset(data)?.meta.env),
        args.run.out.clone(),
    )?;
    let request = Request::<Context> {
        env: args.env.clone(),
        data: vec![data.clone()],
        seed: global.seed,
        config: planned.config,
        variant: (),
        provenance: provenance(global),
    };
    train(global, &planned.out, &request, args.run.resume_if_stopped)
}

pub fn run_tradyn(global: &GlobalArgs, args: TradynArgs) -> anyhow::Result<()> {
    check_steps(args.model.steps)?;
    let data = &args.data;
    let data_env = mbrl::data::read_dataset(data)?.meta.env;
    let terrain = !args.no_terrain;
    let planned = tradyn::options::plan(
        &args.model.options(),
        data,
        &data_env,
        args.env.as_deref(),
        terrain,
        args.run.out.clone(),
    )?;
    let request = Request::<Tradyn> {
        env: None,
        data: vec![data.clone()],
        seed: global.seed,
        config: planned.config,
        variant: terrain,
        provenance: provenance(global),
    };
    train(global, &planned.out, &request, args.run.resume_if_stopped)
}
