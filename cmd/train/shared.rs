//! The flags every method's training takes.

use std::path::PathBuf;

use anyhow::bail;
use clap::Args;

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
