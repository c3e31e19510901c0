//! `mbrl train dlgpd`.

use std::path::PathBuf;

use clap::Args;

use super::shared::{check_steps, train, RunOptions, TrainSummary};
use super::ScalePreset;
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
  mbrl train --resume models/dlgpd-medium --steps 30000"
)]
pub struct DlgpdOptions {
    /// Pendulum rollouts (.mcap), merged (repeatable): with frames (`collect --images`) for the medium and
    /// paper presets, any for the small one.
    #[arg(long, required = true)]
    data: Vec<PathBuf>,
    /// The env the data must come from (default: the dataset's env).
    #[arg(long, value_parser = crate::jobs::names::envs(), hide_possible_values = true)]
    env: Option<String>,
    /// Hyperparameters from a TOML file (keys of config.json's `config` table), over the preset's.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Model and training size (default: small, which learns from the pole angle instead of frames).
    #[arg(long, value_enum)]
    preset: Option<ScalePreset>,
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
}

pub fn prepare(options: DlgpdOptions, invocation: &Invocation) -> Result<Job<'static, TrainSummary>> {
    check_steps(options.steps)?;
    let settings = dlgpd_options::DlgpdOptions {
        preset: options.preset.map(|p| match p {
            ScalePreset::Small => DlgpdPreset::Small,
            ScalePreset::Medium => DlgpdPreset::Medium,
            ScalePreset::Paper => DlgpdPreset::Paper,
        }),
        config_file: options.config,
        steps: options.steps,
        batch_size: options.batch,
        learning_rate: options.lr,
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
