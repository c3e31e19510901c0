//! `mbrl train context` and `mbrl train tradyn`: one model, on an env's state or on the unicycle with terrain.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::shared::{check_steps, train, RunOptions, TrainSummary};
use crate::jobs::overrides::Overrides;
use crate::jobs::{Invocation, Job};
use crate::models::context::options::ContextOptions as ContextSettings;
use crate::models::context::{self, Context};
use crate::models::tradyn::{self, Tradyn};
use crate::train::Request;
use crate::Result;

/// The flags context and TRADYN share: the model and its training are the same; their presets differ.
#[derive(Args, Debug)]
pub struct ContextModelOptions {
    /// Hyperparameters over the preset's: a TOML file of config keys, or a run's config.json to rerun it.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Optimizer steps (default: the preset's); the p_ctx schedule keeps its shares of the run.
    #[arg(long)]
    steps: Option<u64>,
    /// Chunks of consecutive states in a batch (default: the preset's).
    #[arg(long)]
    batch: Option<usize>,
    /// Adam learning rate (default: the preset's).
    #[arg(long, value_parser = crate::jobs::finite_f64)]
    lr: Option<f64>,
    #[command(flatten)]
    set: Overrides,
}

/// Explore the Context's sizes (Table B.1 has a toy column and a pendulum/MountainCar column).
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum ContextPreset {
    /// Toy: 32 units, 20-state chunks, lr 3e-3, 1200 steps (about 25 s; what `eval quick` trains). Pendulum
    /// and MountainCar: 64 units, 5000 steps (minutes).
    Small,
    /// The thesis networks (200 units) for a tenth of its steps: toy 5000, pendulum and MountainCar 10 000.
    Medium,
    /// Table B.1: 200 units; toy 50 000 steps at batch 64, pendulum and MountainCar 100 000 at batch 512 (days
    /// on 2 cores).
    Paper,
}

/// TRADYN's sizes: the context model's pendulum/MountainCar column, on the unicycle.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum TradynPreset {
    /// 64 units, 5000 steps at batch 64 (minutes on 2 cores; what `eval quick` trains).
    Small,
    /// 200 units, 10 000 steps at batch 128.
    Medium,
    /// 200 units, 100 000 steps at batch 512 (days on 2 cores).
    Paper,
}

fn context_preset(preset: ContextPreset) -> context::Preset {
    match preset {
        ContextPreset::Small => context::Preset::Small,
        ContextPreset::Medium => context::Preset::Medium,
        ContextPreset::Paper => context::Preset::Paper,
    }
}

#[derive(Args, Debug)]
#[command(
    next_help_heading = "Context options",
    mut_arg("out", |a| a.help("Checkpoint directory (default: models/context-<env>)")),
    after_help = "\
Examples:
  mbrl collect --env toy:inner --instances 1000 --steps 100 --out datasets/toy-inner.mcap
  mbrl train context --data datasets/toy-inner.mcap --preset small --out models/context-toy-inner
  mbrl train context --data datasets/toy-inner.mcap --preset small steps=2400 kl_weight=2 --out models/context-toy-long
  mbrl calibrate --model models/context-toy-inner --env toy:inner --instance-seed 3

Settings apply in this order, each over the one before: the preset, the --config file, the flags, then KEY=VALUE arguments. --config takes TOML (keys of config.json's `config` table, nested ones as tables or dotted keys) or JSON: a run's own config.json reruns that run's config. An unknown KEY lists the valid keys of the method."
)]
pub struct ContextOptions {
    /// An instance-pair dataset (.mcap) from `mbrl collect --instances N`.
    #[arg(long)]
    data: PathBuf,
    /// The env the data must come from (default: the dataset's env).
    #[arg(long, value_parser = crate::jobs::names::envs(), hide_possible_values = true)]
    env: Option<String>,
    /// Network size and training length (default: small).
    #[arg(long, value_enum)]
    preset: Option<ContextPreset>,
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
  mbrl train tradyn --no-terrain --data datasets/unicycle-train.mcap --preset small --out models/tradyn-no-terrain

Settings apply in this order, each over the one before: the preset, the --config file, the flags, then KEY=VALUE arguments. --config takes TOML (keys of config.json's `config` table, nested ones as tables or dotted keys) or JSON: a run's own config.json reruns that run's config. An unknown KEY lists the valid keys of the method."
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
    /// Network size and training length (default: small).
    #[arg(long, value_enum)]
    preset: Option<TradynPreset>,
    #[command(flatten)]
    model: ContextModelOptions,
    #[command(flatten)]
    run: RunOptions,
}

impl ContextModelOptions {
    fn settings(&self, preset: Option<context::Preset>) -> ContextSettings {
        ContextSettings {
            preset,
            config_file: self.config.clone(),
            steps: self.steps,
            batch_size: self.batch,
            learning_rate: self.lr,
            overrides: self.set.set.clone(),
        }
    }
}

pub fn prepare_context(options: ContextOptions, invocation: &Invocation) -> Result<Job<'static, TrainSummary>> {
    check_steps(options.model.steps)?;
    let data = &options.data;
    let planned = options.model.settings(options.preset.map(context_preset)).plan(
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
        &options.model.settings(options.preset.map(|p| match p {
            TradynPreset::Small => context::Preset::Small,
            TradynPreset::Medium => context::Preset::Medium,
            TradynPreset::Paper => context::Preset::Paper,
        })),
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
