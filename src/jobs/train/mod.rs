//! `mbrl train`: fit a model to a dataset and write a checkpoint directory. One subcommand per method, each
//! with only the flags that method takes; `--resume DIR` reads the method from the checkpoint.

mod ball;
mod context;
mod dlgpd;
mod pets;
mod seads;
mod shared;

use std::path::PathBuf;

use clap::{Args, Subcommand};

pub use self::ball::BallOptions;
pub use self::context::{ContextModelOptions, ContextOptions, ContextPreset, TradynOptions, TradynPreset};
pub use self::dlgpd::{DlgpdOptions, DlgpdPresetChoice};
pub use self::pets::{PetsOptions, PetsPreset, RewardChoice};
pub use self::seads::{SeadsOptions, SeadsPreset};
pub use self::shared::{RunOptions, TrainSummary};
use super::{Invocation, Job};
use crate::eval::training::write_loss_report;
use crate::models::registry;
use crate::train::{Extension, OpenedCheckpoint};
use crate::{refuse, Result};

/// Train a model and write it to a checkpoint directory (config.json, weights, metrics.jsonl).
#[derive(Args, Debug)]
#[command(
    args_conflicts_with_subcommands = true,
    after_help = "\
Examples (in order: each uses what the ones before it wrote):
  mbrl collect --env pendulum --rollouts 200 --steps 30 --out datasets/pendulum-random.mcap
  mbrl train pets --data datasets/pendulum-random.mcap --out models/pets-pendulum
  mbrl train pets --data datasets/pendulum-random.mcap --preset medium steps=3000 optimizer.learning_rate=3e-4 --out models/pets-medium
  mbrl train pets --data datasets/pendulum-random.mcap --config models/pets-medium/config.json --out models/pets-medium-again
  mbrl train --resume models/pets-medium --steps 8000
  mbrl collect --env ball --trajectories 108 --augment-rotations 19 --out datasets/ball-train.mcap
  mbrl train ball-ekf --data datasets/ball-train.mcap --out models/ball-ekf --steps 2000
  mbrl collect --env toy:inner --instances 1000 --steps 100 --out datasets/toy-inner.mcap
  mbrl train context --data datasets/toy-inner.mcap --preset small --out models/context-toy-inner
  mbrl train seads --env tileswap:cursor --preset small --out models/seads-tileswap-cursor
  mbrl train seads --env lightsout:cursor --preset medium --no-novelty --out models/seads-lo-no-novelty
  mbrl collect --env pendulum --rollouts 500 --steps 29 --out datasets/pendulum-dlgpd.mcap
  mbrl train dlgpd --data datasets/pendulum-dlgpd.mcap --preset small --out models/dlgpd-small
  mbrl train dlgpd --help                # one method's flags, presets and examples

Each method's settings apply in this order, each over the one before: its preset, the --config file, its flags, then KEY=VALUE arguments (any key of config.json's `config` table, e.g. steps=500 or optimizer.learning_rate=3e-4). --config takes TOML or JSON: a run's own config.json reruns that run's config. An unknown KEY lists the method's valid keys.

`--resume DIR` continues a stopped run from its last checkpoint with the config and data it was started with, and ends with the same bytes as an uninterrupted run. `--resume DIR --steps N` trains a pets or dlgpd run, finished or not, on to N steps in total; its weights end as those of a run started with N steps, when the old total was a multiple of the validation interval. `mbrl train METHOD … --out DIR --resume-if-stopped` resumes DIR's stopped run of the same command instead of refusing it, so a re-run script loses none of an interrupted run's training."
)]
pub struct TrainOptions {
    #[command(subcommand)]
    method: Option<MethodOptions>,
    /// Continue the stopped run in this checkpoint directory; the method, config and data are the checkpoint's.
    #[arg(long, value_name = "DIR")]
    resume: Option<PathBuf>,
    /// With --resume: train a pets or dlgpd run, finished or not, on to this many steps in total.
    #[arg(long, requires = "resume")]
    steps: Option<u64>,
}

#[derive(Subcommand, Debug)]
pub enum MethodOptions {
    /// Probabilistic ensemble of MLPs on (state, action) → state change (PETS, Chua et al. 2018), for any
    /// env that `collect` rolls out; plan with it via `mbrl plan --model DIR`.
    Pets(PetsOptions),
    /// Gray-box table-tennis ball EKF: learn the impact matrix, noise levels and initial values by
    /// maximizing the filter's marginal likelihood (thesis 6.4.4, eq. 6.24).
    BallEkf(BallOptions),
    /// Context-conditional GRU dynamics with a context encoder (Explore the Context, thesis ch. 4), trained
    /// on instance-pair datasets (`collect --instances N`); calibrate with `mbrl calibrate`.
    Context(ContextOptions),
    /// TRADYN (thesis ch. 5): the context model on the unicycle's observation with the terrain under the robot
    /// as input, read from the map at predicted positions; --no-terrain trains the ablation that predicts it.
    Tradyn(TradynOptions),
    /// SEADS (thesis ch. 7): skill policies (SAC) and a symbolic forward model learned without reward in an
    /// embodied board game; needs no --data, it collects its own episodes.
    Seads(SeadsOptions),
    /// DLGPD (thesis ch. 3): a VAE on pendulum frames (`collect --images`) with Gaussian-process latent
    /// dynamics and reward; plan with `mbrl plan --model DIR --evidence E.mcap`.
    Dlgpd(DlgpdOptions),
}

/// The usage error of `mbrl train` with neither a method nor `--resume`: the binary raises it as clap's own,
/// so it reads and exits like every other command-line mistake.
pub const MISSING_METHOD: &str = "train needs a method (pets, ball-ekf, context, tradyn, seads, dlgpd) or --resume DIR";

/// The training the options ask for, checked and ready for a view; `None` when they name no method and no
/// `--resume` (a usage error, see [`MISSING_METHOD`]). The job also leaves the loss plot beside the
/// checkpoint.
pub fn prepare(options: TrainOptions, invocation: &Invocation) -> Result<Option<Job<'static, TrainSummary>>> {
    if let Some(dir) = options.resume {
        if options.steps == Some(0) {
            refuse!("--steps must be at least 1");
        }
        let extension = options.steps.map(|steps| Extension { steps, command_line: invocation.command_line.clone() });
        return resume(dir, extension).map(Some);
    }
    let job = match options.method {
        Some(MethodOptions::Pets(options)) => pets::prepare(options, invocation)?,
        Some(MethodOptions::BallEkf(options)) => ball::prepare(options, invocation)?,
        Some(MethodOptions::Context(options)) => context::prepare_context(options, invocation)?,
        Some(MethodOptions::Tradyn(options)) => context::prepare_tradyn(options, invocation)?,
        Some(MethodOptions::Seads(options)) => seads::prepare(options, invocation)?,
        Some(MethodOptions::Dlgpd(options)) => dlgpd::prepare(options, invocation)?,
        None => return Ok(None),
    };
    Ok(Some(job))
}

/// Continues the stopped run in `dir` (on to a larger total with `extension`); the method is the checkpoint's.
pub fn resume(dir: PathBuf, extension: Option<Extension>) -> Result<Job<'static, TrainSummary>> {
    let method = registry::method(&OpenedCheckpoint::open(&dir)?.manifest.method, &dir)?;
    Ok(Job::new(format!("train {} (resumed)", method.name()), move |monitor| {
        let summary = method.resume(&dir, extension.as_ref(), monitor)?;
        write_loss_report(&dir, method.loss_plot())?;
        Ok(summary)
    }))
}
