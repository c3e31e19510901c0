//! A job's outcome, kept in its directory (`job.json`) so that a job list can be rerun as a whole: a line
//! whose job finished is skipped, one that stopped or failed runs again (a training resumes). The record
//! holds no time, host or pid, so a sweep run locally and on a cluster leaves the same bytes.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use serde::{Deserialize, Serialize};

use super::lock::RunLock;
use crate::error::{Error, Result};

pub const RECORD_FILE: &str = "job.json";

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum JobState {
    /// Started and not ended; with the directory's lock free, the process was killed.
    Running,
    Done,
    Failed,
    /// Interrupted (Ctrl-C, SIGTERM, a scheduler's time-limit warning): a rerun continues.
    Stopped,
}

#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
pub struct JobRecord {
    pub state: JobState,
    /// The command's arguments after the binary, shell-quoted: a record of another command is not this
    /// command's outcome.
    pub command: String,
    /// The error line of a failed job.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

impl JobRecord {
    /// The record in `dir`, if one is there and readable.
    pub fn read(dir: &Path) -> Option<JobRecord> {
        Self::read_checked(dir).ok().flatten()
    }

    /// The record in `dir`: `None` when there is none, an error (why, in a few words) when the file is there
    /// but no record, so a follower can tell a damaged record from a job that never started.
    pub fn read_checked(dir: &Path) -> std::result::Result<Option<JobRecord>, String> {
        let path = dir.join(RECORD_FILE);
        if !path.exists() {
            return Ok(None);
        }
        let bytes = crate::util::bounded_read::read_bounded(&path, 1 << 20).map_err(|e| e.to_string())?;
        serde_json::from_slice(&bytes).map(Some).map_err(|e| format!("{RECORD_FILE} is not a job record: {e}"))
    }

    fn write(&self, dir: &Path) -> Result<()> {
        let bytes = serde_json::to_vec_pretty(self).map_err(|e| Error::config(format!("job record: {e}")))?;
        crate::util::atomic::write_atomic(&dir.join(RECORD_FILE), |w| {
            w.write_all(&bytes).and_then(|()| w.write_all(b"\n")).map_err(|e| Error::io(&dir.join(RECORD_FILE), e))
        })
    }
}

/// What a command run with `--job-dir` does.
pub enum Begin {
    /// The same command finished here before: nothing to do.
    AlreadyDone,
    /// Run it; the guard records how it ends.
    Run(JobGuard),
}

/// Holds the job directory's lock while the command runs.
pub struct JobGuard {
    dir: PathBuf,
    command: String,
    _lock: RunLock,
}

/// Where an interruption records "stopped" (the signal handler runs plain functions).
static INTERRUPTIBLE: Mutex<Option<(PathBuf, String)>> = Mutex::new(None);

/// Runs inside the interrupt handler, which holds the registry of temporary files until exit: so the record
/// goes through a plain temporary file and a rename, not through `write_atomic` (which registers its file).
fn record_interruption() {
    let taken = INTERRUPTIBLE.lock().unwrap_or_else(|p| p.into_inner()).take();
    if let Some((dir, command)) = taken {
        let record = JobRecord { state: JobState::Stopped, command, error: None };
        if let Ok(mut bytes) = serde_json::to_vec_pretty(&record) {
            bytes.push(b'\n');
            let tmp = dir.join(".job.json.stopping");
            if std::fs::write(&tmp, &bytes).is_ok() {
                let _ = std::fs::rename(&tmp, dir.join(RECORD_FILE));
            }
        }
    }
}

/// Starts a job in `dir` for `command`: refused while another process runs a job there; skipped when the
/// same command is recorded done.
pub fn begin(dir: &Path, command: &str) -> Result<Begin> {
    let lock = RunLock::acquire(dir)?;
    if let Some(record) = JobRecord::read(dir) {
        if record.state == JobState::Done && record.command == command {
            return Ok(Begin::AlreadyDone);
        }
    }
    JobRecord { state: JobState::Running, command: command.to_string(), error: None }.write(dir)?;
    *INTERRUPTIBLE.lock().unwrap_or_else(|p| p.into_inner()) = Some((dir.to_path_buf(), command.to_string()));
    crate::util::interrupt::on_interrupt(record_interruption);
    Ok(Begin::Run(JobGuard { dir: dir.to_path_buf(), command: command.to_string(), _lock: lock }))
}

impl JobGuard {
    /// Records the outcome: done, or failed with the error line (stopped when the error is a cancellation).
    pub fn finish(self, outcome: std::result::Result<(), (String, bool)>) -> Result<()> {
        INTERRUPTIBLE.lock().unwrap_or_else(|p| p.into_inner()).take();
        let record = match outcome {
            Ok(()) => JobRecord { state: JobState::Done, command: self.command, error: None },
            Err((line, true)) => JobRecord { state: JobState::Stopped, command: self.command, error: Some(line) },
            Err((line, false)) => JobRecord { state: JobState::Failed, command: self.command, error: Some(line) },
        };
        record.write(&self.dir)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_done_job_is_skipped_only_for_the_same_command() {
        let dir = tempfile::tempdir().unwrap();
        let Begin::Run(guard) = begin(dir.path(), "train a").unwrap() else { panic!("fresh job") };
        assert_eq!(JobRecord::read(dir.path()).unwrap().state, JobState::Running);
        guard.finish(Ok(())).unwrap();
        assert!(matches!(begin(dir.path(), "train a").unwrap(), Begin::AlreadyDone));
        let Begin::Run(guard) = begin(dir.path(), "train b").unwrap() else { panic!("another command runs") };
        guard.finish(Err(("error: boom".into(), false))).unwrap();
        let record = JobRecord::read(dir.path()).unwrap();
        assert_eq!((record.state, record.error.as_deref()), (JobState::Failed, Some("error: boom")));
    }

    /// A damaged record is told apart from none (a sweep's status showed it as "not started").
    #[test]
    fn a_damaged_record_is_not_a_missing_one() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(JobRecord::read_checked(dir.path()), Ok(None));
        std::fs::write(dir.path().join(RECORD_FILE), "{\"state\":\"donedone\"}").unwrap();
        let why = JobRecord::read_checked(dir.path()).unwrap_err();
        assert!(why.contains("job.json is not a job record"), "{why}");
        assert!(JobRecord::read(dir.path()).is_none(), "a rerun starts afresh over it");
    }
}
