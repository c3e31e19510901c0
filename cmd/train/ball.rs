//! `mbrl train ball-ekf`.

use std::path::PathBuf;

use clap::Args;
use mbrl::models::ball::learn::job::{self as ball_job, BallTrainRequest};
use mbrl::models::ball::learn::options::{default_out_dir, BallOptions};
use mbrl::run::dir::Provenance;
use mbrl::train::run_dir::{decide, Decision, RunRequest};

use super::shared::{check_steps, RunArgs};
use crate::common::{command_line, run_job, GlobalArgs};

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
    let request = BallTrainRequest {
        out: args.run.out.clone().unwrap_or_else(default_out_dir),
        data: args.data.clone(),
        settings: options.settings(global.seed),
        provenance: Provenance::new(command_line(), global.seed, global.thread_count()),
    };
    let asked = RunRequest {
        method: ball_job::METHOD.into(),
        config_key: "settings",
        config: serde_json::to_value(&request.settings)?,
        seed: None,
        data: vec![request.data.clone()],
        fields: Vec::new(),
        extendable: false,
        command_line: request.provenance.command_line.clone(),
    };
    if let Decision::Resume(extension) = decide(&request.out, &asked, args.run.resume_if_stopped)? {
        return super::resume(global, &request.out, extension.as_ref());
    }
    let report = run_job(global, "train ball-ekf", |monitor| ball_job::train_checkpointed(&request, false, monitor))?;
    super::report::ball(&report, &request.out)
}
