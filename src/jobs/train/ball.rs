//! `mbrl train ball-ekf`.

use std::path::PathBuf;

use clap::Args;

use super::shared::{check_steps, train, RunOptions, TrainSummary};
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
  mbrl train ball-ekf --data datasets/ball-train.mcap --out models/ball-ekf-launch --steps 2000 --launcher-prior"
)]
pub struct BallOptions {
    /// A ball dataset (.mcap) or a .csv recording.
    #[arg(long)]
    data: PathBuf,
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
}

pub fn prepare(options: BallOptions, invocation: &Invocation) -> Result<Job<'static, TrainSummary>> {
    check_steps(options.steps)?;
    let settings = ball_options::BallOptions {
        steps: options.steps,
        batch_size: options.batch,
        chunk_len: options.chunk,
        learning_rate: options.lr,
        launcher_prior: options.launcher_prior,
    };
    let request = Request::<BallEkf> {
        env: None,
        data: vec![options.data],
        seed: invocation.seed,
        config: settings.settings(invocation.seed),
        variant: (),
        provenance: invocation.provenance(),
    };
    let out = options.run.out.clone().unwrap_or_else(default_out_dir);
    train(out, &options.run, request, invocation)
}
