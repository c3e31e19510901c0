//! `mbrl train dlgpd`.

use std::path::PathBuf;

use clap::Args;
use mbrl::models::dlgpd::config::Preset as DlgpdPreset;
use mbrl::models::dlgpd::job::Dlgpd;
use mbrl::models::dlgpd::options::{default_out_dir, DlgpdOptions};
use mbrl::train::Request;

use super::shared::{check_steps, provenance, train, RunArgs};
use super::ScalePreset;
use crate::common::GlobalArgs;

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
pub struct DlgpdArgs {
    /// Pendulum rollouts (.mcap), merged (repeatable): with frames (`collect --images`) for the medium and
    /// paper presets, any for the small one.
    #[arg(long, required = true)]
    data: Vec<PathBuf>,
    /// The env the data must come from (default: the dataset's env).
    #[arg(long)]
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
    #[arg(long, value_parser = crate::common::finite_f64)]
    lr: Option<f64>,
    #[command(flatten)]
    run: RunArgs,
}

pub fn run(global: &GlobalArgs, args: DlgpdArgs) -> anyhow::Result<()> {
    check_steps(args.steps)?;
    let options = DlgpdOptions {
        preset: args.preset.map(|p| match p {
            ScalePreset::Small => DlgpdPreset::Small,
            ScalePreset::Medium => DlgpdPreset::Medium,
            ScalePreset::Paper => DlgpdPreset::Paper,
        }),
        config_file: args.config.clone(),
        steps: args.steps,
        batch_size: args.batch,
        learning_rate: args.lr,
    };
    let request = Request::<Dlgpd> {
        env: args.env.clone(),
        data: args.data.clone(),
        seed: global.seed,
        config: options.config()?,
        variant: (),
        provenance: provenance(global),
    };
    let out = args.run.out.clone().unwrap_or_else(default_out_dir);
    train(global, &out, &request, args.run.resume_if_stopped)
}
