//! The flags every method's training takes, and the one way a `train <method>` command runs.

use std::path::{Path, PathBuf};

use anyhow::bail;
use clap::Args;
use mbrl::eval::training::write_loss_report;
use mbrl::models::registry::{self, ModelMethod};
use mbrl::run::dir::Provenance;
use mbrl::train::run_dir::{decide, Decision};
use mbrl::train::Request;

use crate::common::{command_line, run_job, GlobalArgs};

/// Flattened into each method's flags; `--seed`, `--threads` and the display flags are global.
#[derive(Args, Debug)]
#[command(next_help_heading = "Run options")]
pub struct RunArgs {
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
pub fn check_steps(steps: Option<u64>) -> anyhow::Result<()> {
    if steps == Some(0) {
        bail!("--steps must be at least 1");
    }
    Ok(())
}

/// This command's provenance.
pub fn provenance(global: &GlobalArgs) -> Provenance {
    Provenance::new(command_line(), global.seed, global.thread_count())
}

/// Trains `request` into `out`, or resumes the stopped run there when asked and it is this command's, then
/// leaves the loss plot beside the checkpoint and prints the method's summary.
pub fn train<M: ModelMethod>(
    global: &GlobalArgs,
    out: &Path,
    request: &Request<M>,
    resume_if_stopped: bool,
) -> anyhow::Result<()> {
    let decision = decide(out, request, resume_if_stopped)?;
    let title = match decision {
        Decision::Fresh => format!("train {}", M::NAME),
        Decision::Resume(_) => format!("train {} (resumed)", M::NAME),
    };
    let summary = run_job(global, &title, |monitor| registry::train(out, request, &decision, monitor))?;
    let (plot_title, y_label) = M::LOSS_PLOT;
    write_loss_report(out, plot_title, y_label)?;
    say!("{summary}");
    Ok(())
}
