//! Where each job of a sweep stands, read from its directory alone: the job record, the directory's lock
//! (held while a process runs the job) and, for a training, its checkpoint's step. Nothing is asked of the
//! scheduler, so the answer is the same for jobs run by Slurm, by parallel or by hand.

use std::fmt;

use super::plan::{JobPlan, Plan};
use crate::run::job_record::{JobRecord, JobState};
use crate::run::lock::RunLock;
use crate::train::checkpoint::CheckpointDir;

#[derive(Clone, Debug, PartialEq)]
pub enum Standing {
    NotStarted,
    Running {
        step: Option<(u64, u64)>,
    },
    /// Interrupted, or killed (a record that says running with no process holding the lock).
    Stopped {
        step: Option<(u64, u64)>,
        killed: bool,
    },
    Failed {
        error: String,
    },
    Done,
}

pub fn standing(job: &JobPlan) -> Standing {
    let step = || CheckpointDir::open(&job.output).ok().map(|(_, manifest)| (manifest.step, manifest.total_steps));
    if RunLock::is_held(&job.run_dir) {
        return Standing::Running { step: step() };
    }
    match JobRecord::read_checked(&job.run_dir) {
        Err(why) => Standing::Failed { error: format!("{why}; rerun the job's line to redo it") },
        Ok(None) => Standing::NotStarted,
        Ok(Some(record)) => match record.state {
            JobState::Done => Standing::Done,
            JobState::Failed => Standing::Failed { error: record.error.unwrap_or_default() },
            JobState::Stopped => Standing::Stopped { step: step(), killed: false },
            JobState::Running => Standing::Stopped { step: step(), killed: true },
        },
    }
}

/// Every job's standing, by stage, with counts.
pub struct SweepStatus {
    pub stages: Vec<(String, Vec<(String, Standing)>)>,
}

impl SweepStatus {
    pub fn of(plan: &Plan) -> SweepStatus {
        let stages = plan
            .stages
            .iter()
            .map(|stage| (stage.name.clone(), stage.jobs.iter().map(|job| (job.name.clone(), standing(job))).collect()))
            .collect();
        SweepStatus { stages }
    }

    fn all(&self) -> impl Iterator<Item = &Standing> {
        self.stages.iter().flat_map(|(_, jobs)| jobs.iter().map(|(_, s)| s))
    }

    pub fn failed(&self) -> usize {
        self.all().filter(|s| matches!(s, Standing::Failed { .. })).count()
    }

    pub fn done(&self) -> usize {
        self.all().filter(|s| **s == Standing::Done).count()
    }

    pub fn total(&self) -> usize {
        self.all().count()
    }
}

fn at_step(step: &Option<(u64, u64)>) -> String {
    match step {
        Some((k, n)) => format!(" at step {k} of {n}"),
        None => String::new(),
    }
}

impl fmt::Display for Standing {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Standing::NotStarted => write!(f, "not started"),
            Standing::Running { step } => write!(f, "running{}", at_step(step)),
            Standing::Stopped { step, killed: false } => write!(f, "stopped{}", at_step(step)),
            Standing::Stopped { step, killed: true } => {
                write!(f, "stopped{} (killed, no outcome recorded)", at_step(step))
            }
            Standing::Failed { error } => write!(f, "failed: {error}"),
            Standing::Done => write!(f, "done"),
        }
    }
}

impl fmt::Display for SweepStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let width = self.stages.iter().flat_map(|(_, jobs)| jobs.iter().map(|(n, _)| n.len())).max().unwrap_or(0);
        for (stage, jobs) in &self.stages {
            let done = jobs.iter().filter(|(_, s)| *s == Standing::Done).count();
            writeln!(f, "stage {stage}: {done}/{} done", jobs.len())?;
            for (name, standing) in jobs {
                writeln!(f, "  {name:<width$}  {standing}")?;
            }
        }
        write!(f, "{}/{} jobs done", self.done(), self.total())?;
        if self.failed() > 0 {
            write!(f, ", {} failed", self.failed())?;
        }
        Ok(())
    }
}
