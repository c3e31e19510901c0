//! `mbrl train dlgpd`.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use super::shared::{check_steps, train, RunOptions, TrainSummary};
use crate::jobs::overrides::Overrides;
use crate::jobs::{Invocation, Job};
use crate::models::dlgpd::config::Preset as DlgpdPreset;
use crate::models::dlgpd::job::Dlgpd;
use crate::models::dlgpd::options::{self as dlgpd_options, default_out_dir};
use crate::train::Request;
use crate::Result;

#[derive(Args, Debug)]
#[command(
    next_help_heading = "DLGPD options",
    mut_arg("out", |a| a.help("Checkpoint directory (default: models/dlgpd-pendulum)")),
    after_help = "\
Examples:
  mbrl collect --env pendulum --rollouts 500 --steps 29 --out datasets/pendulum-dlgpd.mcap
  mbrl train dlgpd --data datasets/pendulum-dlgpd.mcap --preset small --out models/dlgpd-small
  mbrl collect --env pendulum --images --rollouts 500 --steps 29 --out datasets/pendulum-frames.mcap
  mbrl train dlgpd --data datasets/pendulum-frames.mcap --preset medium --out models/dlgpd-medium
  mbrl train dlgpd --data datasets/pendulum-dlgpd.mcap --preset small steps=6000 batch_size=512 --out models/dlgpd-small-long
  mbrl train --resume models/dlgpd-medium --steps 30000

Settings apply in this order, each over the one before: the preset, the --config file, the flags, then KEY=VALUE arguments. --config takes TOML (keys of config.json's `config` table, nested ones as tables or dotted keys) or JSON: a run's own config.json reruns that run's config. An unknown KEY lists the valid keys of the method."
)]
pub struct DlgpdOptions {
    /// Pendulum rollouts (.mcap), merged (repeatable): with frames (`collect --images`) for the medium and
    /// paper presets, any for the small one.
    #[arg(long, required = true)]
    data: Vec<PathBuf>,
    /// The env the data must come from (default: the dataset's env).
    #[arg(long, value_parser = crate::jobs::names::envs(), hide_possible_values = true)]
    env: Option<String>,
    /// Hyperparameters over the preset's: a TOML file of config keys, or a run's config.json to rerun it.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Model and training size (default: small, which learns from the pole angle instead of frames).
    #[arg(long, value_enum)]
    preset: Option<DlgpdPresetChoice>,
    /// Optimizer steps (default: the preset's).
    #[arg(long)]
    steps: Option<u64>,
    /// Transitions in a batch (default: the preset's; the paper 1024).
    #[arg(long)]
    batch: Option<usize>,
    /// Adam learning rate (default 1e-3).
    #[arg(long, value_parser = crate::jobs::finite_f64)]
    lr: Option<f64>,
    #[command(flatten)]
    run: RunOptions,
    #[command(flatten)]
    set: Overrides,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum DlgpdPresetChoice {
    /// An MLP VAE on the pole direction (cos θ, sin θ) instead of frames, batch 256, 3000 steps: minutes on 2
    /// cores; any pendulum data.
    Small,
    /// The paper's conv VAE on 64 × 64 frames at batch 128 for 3000 steps (about an hour on 2 cores).
    Medium,
    /// The paper: batch 1024, 28 000 steps (2000 epochs of 14 000 transitions; days on 2 cores).
    Paper,
}

pub fn prepare(options: DlgpdOptions, invocation: &Invocation) -> Result<Job<'static, TrainSummary>> {
    check_steps(options.steps)?;
    let settings = dlgpd_options::DlgpdOptions {
        preset: options.preset.map(|p| match p {
            DlgpdPresetChoice::Small => DlgpdPreset::Small,
            DlgpdPresetChoice::Medium => DlgpdPreset::Medium,
            DlgpdPresetChoice::Paper => DlgpdPreset::Paper,
        }),
        config_file: options.config,
        steps: options.steps,
        batch_size: options.batch,
        learning_rate: options.lr,
        overrides: options.set.set,
    };
    let request = Request::<Dlgpd> {
        env: options.env,
        data: options.data,
        seed: invocation.seed,
        config: settings.config()?,
        variant: (),
        provenance: invocation.provenance(),
    };
    let out = options.run.out.clone().unwrap_or_else(default_out_dir);
    train(out, &options.run, request, invocation)
}
