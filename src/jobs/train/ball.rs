//! `mbrl train ball-ekf`.

use std::path::PathBuf;

use clap::Args;

use super::shared::{check_steps, train, RunOptions, TrainSummary};
use crate::jobs::overrides::Overrides;
use crate::jobs::{Invocation, Job};
use crate::models::ball::learn::job::BallEkf;
use crate::models::ball::learn::options::{self as ball_options, default_out_dir};
use crate::train::Request;
use crate::Result;

#[derive(Args, Debug)]
#[command(
    next_help_heading = "Ball EKF options",
    mut_arg("out", |a| a.help("Checkpoint directory (default: models/ball-ekf)")),
    after_help = "\
Examples:
  mbrl collect --env ball --trajectories 108 --augment-rotations 19 --out datasets/ball-train.mcap
  mbrl train ball-ekf --data datasets/ball-train.mcap --out models/ball-ekf --steps 2000
  mbrl train ball-ekf --data datasets/ball-train.mcap --out models/ball-ekf-launch --steps 2000 --launcher-prior
  mbrl train ball-ekf --data datasets/ball-train.mcap --config models/ball-ekf/config.json learning_rate=2e-3 --out models/ball-ekf-slower

Settings apply in this order, each over the one before: the thesis' (Adam, lr 5e-3, batch 64, chunks of 50 frames, 1000 steps), the --config file, the flags, then KEY=VALUE arguments. --config takes TOML (keys of config.json's `config` table, nested ones as tables or dotted keys) or JSON: a run's own config.json reruns that run's config. An unknown KEY lists the valid keys."
)]
pub struct BallOptions {
    /// A ball dataset (.mcap) or a .csv recording.
    #[arg(long)]
    data: PathBuf,
    /// Training settings over the thesis': a TOML file of config keys, or a run's config.json to rerun it.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Optimizer steps (default 1000).
    #[arg(long)]
    steps: Option<u64>,
    /// Chunks in a batch (thesis: 64).
    #[arg(long)]
    batch: Option<usize>,
    /// Frames per chunk (thesis: 50).
    #[arg(long)]
    chunk: Option<usize>,
    /// Adam learning rate (thesis: 5e-3).
    #[arg(long, value_parser = crate::jobs::finite_f64)]
    lr: Option<f64>,
    /// Learn the spin prior from launcher settings (thesis C.1.3); recordings need side information.
    #[arg(long)]
    launcher_prior: bool,
    #[command(flatten)]
    run: RunOptions,
    #[command(flatten)]
    set: Overrides,
}

pub fn prepare(options: BallOptions, invocation: &Invocation) -> Result<Job<'static, TrainSummary>> {
    check_steps(options.steps)?;
    let settings = ball_options::BallOptions {
        config_file: options.config,
        steps: options.steps,
        batch_size: options.batch,
        chunk_len: options.chunk,
        learning_rate: options.lr,
        launcher_prior: options.launcher_prior,
        overrides: options.set.set,
    };
    let request = Request::<BallEkf> {
        env: None,
        data: vec![options.data],
        seed: invocation.seed,
        config: settings.settings(invocation.seed)?,
        variant: (),
        provenance: invocation.provenance(),
    };
    let out = options.run.out.clone().unwrap_or_else(default_out_dir);
    train(out, &options.run, request, invocation)
}
