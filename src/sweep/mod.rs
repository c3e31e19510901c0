//! Sweeps: seeds × settings of any mbrl command as plain job lists, handed to Slurm as job arrays (or run
//! locally with GNU parallel), followed from the run directories, and reported with confidence intervals.
//! Nothing here schedules: the scheduler is Slurm or the user's own `parallel`; mbrl writes the lines, makes
//! each line safe to rerun (`--job-dir`), and reads the outcomes back.

pub mod files;
pub mod plan;
pub mod report;
pub mod spec;
pub mod status;

pub use plan::{expand, JobPlan, Plan, StagePlan, PLAN_FILE};
pub use spec::Spec;
