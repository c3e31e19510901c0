//! `mbrl train context` and `mbrl train tradyn`: one model, on an env's state or on the unicycle with terrain.

use std::path::PathBuf;

use clap::Args;

use super::shared::{check_steps, train, RunOptions, TrainSummary};
use super::ScalePreset;
use crate::jobs::{Invocation, Job};
use crate::models::context::options::ContextOptions as ContextSettings;
use crate::models::context::{self, Context};
use crate::models::tradyn::{self, Tradyn};
use crate::train::Request;
use crate::Result;

/// The flags context and TRADYN share: the model and its training are the same.
#[derive(Args, Debug)]
pub struct ContextModelOptions {
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
    #[arg(long, value_parser = crate::jobs::finite_f64)]
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
pub struct ContextOptions {
    /// An instance-pair dataset (.mcap) from `mbrl collect --instances N`.
    #[arg(long)]
    data: PathBuf,
    /// The env the data must come from (default: the dataset's env).
    #[arg(long, value_parser = crate::jobs::names::envs(), hide_possible_values = true)]
    env: Option<String>,
    #[command(flatten)]
    model: ContextModelOptions,
    #[command(flatten)]
    run: RunOptions,
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
pub struct TradynOptions {
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
    model: ContextModelOptions,
    #[command(flatten)]
    run: RunOptions,
}

impl ContextModelOptions {
    fn settings(&self) -> ContextSettings {
        ContextSettings {
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

pub fn prepare_context(options: ContextOptions, invocation: &Invocation) -> Result<Job<'static, TrainSummary>> {
    check_steps(options.model.steps)?;
    let data = &options.data;
    let planned = options.model.settings().plan(
        data,
        options.env.as_deref(),
        || Ok(crate::data::read_dataset(data)?.meta.env),
        options.run.out.clone(),
    )?;
    let request = Request::<Context> {
        env: options.env,
        data: vec![options.data],
        seed: invocation.seed,
        config: planned.config,
        variant: (),
        provenance: invocation.provenance(),
    };
    train(planned.out, &options.run, request, invocation)
}

pub fn prepare_tradyn(options: TradynOptions, invocation: &Invocation) -> Result<Job<'static, TrainSummary>> {
    check_steps(options.model.steps)?;
    let data = &options.data;
    let data_env = crate::data::read_dataset(data)?.meta.env;
    let terrain = !options.no_terrain;
    let planned = tradyn::options::plan(
        &options.model.settings(),
        data,
        &data_env,
        options.env.as_deref(),
        terrain,
        options.run.out.clone(),
    )?;
    let request = Request::<Tradyn> {
        env: None,
        data: vec![options.data],
        seed: invocation.seed,
        config: planned.config,
        variant: terrain,
        provenance: invocation.provenance(),
    };
    train(planned.out, &options.run, request, invocation)
}
