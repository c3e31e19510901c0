//! The flags every method's training takes, and the one way a `train <method>` command runs.

use std::fmt::Display;
use std::path::PathBuf;

use clap::Args;

use crate::eval::training::write_loss_report;
use crate::jobs::{output_dir, Invocation, Job};
use crate::models::registry::{self, ModelMethod};
use crate::train::run_dir::{decide, Decision};
use crate::train::{OpenedCheckpoint, Request};
use crate::{refuse, Result};

/// What a training run reports: the method's own summary (a resumed run's method is known only from its
/// checkpoint, so the type is erased for all of them).
pub type TrainSummary = Box<dyn Display + Send>;

/// Flattened into each method's flags; `--seed`, `--threads` and the display flags are global.
#[derive(Args, Debug)]
#[command(next_help_heading = "Run options")]
pub struct RunOptions {
    /// Checkpoint directory (default: models/ and a name from the method and env; when that holds a run, the
    /// first free name-2, -3, …). A run there, finished or stopped, is replaced only with --force.
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

/// Where a run goes, by the rule every output follows: a named --out holding a finished run (or files that are
/// no run) is replaced only with --force; a stopped one is left to [`decide`] (refused, resumed, or with
/// --force started over); the default name, when it holds anything, gives way to the first free numbered
/// name, unless the command asks to resume the stopped run there.
fn checkpoint_dir(out: PathBuf, run: &RunOptions, invocation: &Invocation) -> Result<PathBuf> {
    let explicit = run.out.is_some();
    let holds_files = std::fs::read_dir(&out).is_ok_and(|mut entries| entries.next().is_some());
    if !holds_files {
        return Ok(out);
    }
    let finished = match OpenedCheckpoint::open(&out) {
        Ok(opened) if !opened.manifest.complete => {
            if explicit || run.resume_if_stopped {
                return Ok(out);
            }
            None
        }
        Ok(opened) => Some(opened.manifest),
        Err(_) => None,
    };
    if !explicit {
        return output_dir("--out", None, || out, invocation);
    }
    if invocation.force {
        return Ok(out);
    }
    match finished {
        Some(manifest) => refuse!(
            "--out {} holds a finished {} run ({} steps); add --force to replace it, or give another --out",
            out.display(),
            manifest.method,
            manifest.total_steps
        ),
        None => refuse!(
            "--out {} holds files but no finished or stopped run (a run stopped before its first checkpoint leaves \
             such a directory); add --force to replace them, or give another --out",
            out.display()
        ),
    }
}

/// Trains `request` into `out`, or resumes the stopped run there when asked and it is this command's, then
/// leaves the loss plot beside the checkpoint. Whether `out` may be used is decided before the job is made.
pub fn train<M: ModelMethod>(
    out: PathBuf,
    run: &RunOptions,
    request: Request<M>,
    invocation: &Invocation,
) -> Result<Job<'static, TrainSummary>> {
    let out = checkpoint_dir(out, run, invocation)?;
    let decision = decide(&out, &request, run.resume_if_stopped, invocation.force)?;
    let title = match decision {
        Decision::Fresh => format!("train {}", M::NAME),
        Decision::Resume(_) => format!("train {} (resumed)", M::NAME),
    };
    Ok(Job::new(title, move |monitor| {
        let summary = registry::train(&out, &request, &decision, monitor)?;
        write_loss_report(&out, M::LOSS_PLOT)?;
        Ok(Box::new(summary) as TrainSummary)
    }))
}
