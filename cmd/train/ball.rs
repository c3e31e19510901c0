//! `mbrl train ball-ekf`.

use std::path::PathBuf;

use clap::Args;
use mbrl::models::ball::learn::job::BallEkf;
use mbrl::models::ball::learn::options::{default_out_dir, BallOptions};
use mbrl::train::Request;

use super::shared::{check_steps, provenance, train, RunArgs};
use crate::common::GlobalArgs;

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
pub struct BallArgs {
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
    #[arg(long, value_parser = crate::common::finite_f64)]
    lr: Option<f64>,
    /// Learn the spin prior from launcher settings (thesis C.1.3); recordings need side information.
    #[arg(long)]
    launcher_prior: bool,
    #[command(flatten)]
    run: RunArgs,
}

pub fn run(global: &GlobalArgs, args: BallArgs) -> anyhow::Result<()> {
    check_steps(args.steps)?;
    let options = BallOptions {
        steps: args.steps,
        batch_size: args.batch,
        chunk_len: args.chunk,
        learning_rate: args.lr,
        launcher_prior: args.launcher_prior,
    };
    let request = Request::<BallEkf> {
        env: None,
        data: vec![args.data.clone()],
        seed: global.seed,
        config: options.settings(global.seed),
        variant: (),
        provenance: provenance(global),
    };
    let out = args.run.out.clone().unwrap_or_else(default_out_dir);
    train(global, &out, &request, args.run.resume_if_stopped)
}
