//! The flags every method's training takes, and the one way a `train <method>` command runs.

use std::fmt::Display;
use std::path::PathBuf;

use clap::Args;

use crate::eval::training::write_loss_report;
use crate::jobs::Job;
use crate::models::registry::{self, ModelMethod};
use crate::train::run_dir::{decide, Decision};
use crate::train::Request;
use crate::{refuse, Result};

/// What a training run reports: the method's own summary (a resumed run's method is known only from its
/// checkpoint, so the type is erased for all of them).
pub type TrainSummary = Box<dyn Display + Send>;

/// Flattened into each method's flags; `--seed`, `--threads` and the display flags are global.
#[derive(Args, Debug)]
#[command(next_help_heading = "Run options")]
pub struct RunOptions {
    /// Checkpoint directory (default: models/ and a name from the method and env). A stopped run there is
    /// never replaced: a new run refuses it.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Resume the stopped run in --out when this command started it (same method, config, data and seed;
    /// a larger --steps extends a pets or dlgpd run); with no run there, or a finished one, train as without
    /// this flag. A re-run script then loses none of an interrupted run's training.
    #[arg(long)]
    pub resume_if_stopped: bool,
}

/// A zero total passes clap's u64 parser, and would make a run that writes no model.
pub fn check_steps(steps: Option<u64>) -> Result<()> {
    if steps == Some(0) {
        refuse!("--steps must be at least 1");
    }
    Ok(())
}

/// Trains `request` into `out`, or resumes the stopped run there when asked and it is this command's, then
/// leaves the loss plot beside the checkpoint. Whether `out` may be used is decided before the job is made.
pub fn train<M: ModelMethod>(
    out: PathBuf,
    request: Request<M>,
    resume_if_stopped: bool,
) -> Result<Job<'static, TrainSummary>> {
    let decision = decide(&out, &request, resume_if_stopped)?;
    let title = match decision {
        Decision::Fresh => format!("train {}", M::NAME),
        Decision::Resume(_) => format!("train {} (resumed)", M::NAME),
    };
    Ok(Job::new(title, move |monitor| {
        let summary = registry::train(&out, &request, &decision, monitor)?;
        let (plot_title, y_label) = M::LOSS_PLOT;
        write_loss_report(&out, plot_title, y_label)?;
        Ok(Box::new(summary) as TrainSummary)
    }))
}
