//! One writer per run directory. A run holds an advisory lock on `DIR/.mbrl-lock` (which records its pid)
//! for as long as it writes there, so a second `train` on the same directory is refused naming the process
//! instead of being told to resume a run that is still going. The OS drops the lock when the process ends,
//! however it ends, so a killed run never leaves a stale lock behind.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, Write};
use std::path::Path;

use crate::error::{Error, Result};

/// The lock file's name inside a run directory.
pub const LOCK_FILE: &str = ".mbrl-lock";

/// Held while a run writes its directory; dropping it releases the lock.
#[derive(Debug)]
pub struct RunLock {
    _file: File,
}

impl RunLock {
    /// Takes the lock of `dir`, creating the directory if needed; refused while another process holds it.
    pub fn acquire(dir: &Path) -> Result<RunLock> {
        if dir.exists() && !dir.is_dir() {
            return Err(Error::bad_file(dir, "exists and is not a directory; expected a checkpoint directory"));
        }
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let path = dir.join(LOCK_FILE);
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(|e| Error::io(&path, e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => return Err(in_use(dir, &mut file)),
            Err(TryLockError::Error(e)) => return Err(Error::io(&path, e)),
        }
        let pid = std::process::id().to_string();
        file.set_len(0)
            .and_then(|()| file.rewind())
            .and_then(|()| file.write_all(pid.as_bytes()))
            .map_err(|e| Error::io(&path, e))?;
        Ok(RunLock { _file: file })
    }

    /// Refuses when a process holds `dir`'s lock, without keeping it: for a command that only decides what
    /// to do before it starts writing. A directory that does not exist is free.
    pub fn ensure_free(dir: &Path) -> Result<()> {
        if !dir.join(LOCK_FILE).is_file() {
            return Ok(());
        }
        RunLock::acquire(dir).map(drop)
    }

    /// Whether a process is writing `dir` now (`watch` tells a stopped run from a running one by this).
    pub fn is_held(dir: &Path) -> bool {
        let Ok(file) = File::open(dir.join(LOCK_FILE)) else {
            return false;
        };
        matches!(file.try_lock_shared(), Err(TryLockError::WouldBlock))
    }
}

fn in_use(dir: &Path, file: &mut File) -> Error {
    let mut text = String::new();
    // The pid is for the message only; a holder that has not written it yet is still a holder.
    let _ = file.take(32).read_to_string(&mut text);
    let holder = match text.trim().parse::<u32>() {
        Ok(pid) => format!("pid {pid}"),
        Err(_) => "another process".to_string(),
    };
    Error::bad_file(
        dir,
        format!("in use by {holder}, which is training here; wait for it to end (or stop it) before starting or resuming a run here"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_writer_is_refused_naming_the_holder_and_the_lock_goes_with_the_first() {
        let dir = tempfile::tempdir().unwrap();
        let run = dir.path().join("run");
        let first = RunLock::acquire(&run).unwrap();
        assert!(RunLock::is_held(&run));
        let second = RunLock::acquire(&run).unwrap_err().to_string();
        assert!(second.contains(&format!("in use by pid {}", std::process::id())), "{second}");
        assert!(RunLock::ensure_free(&run).is_err());
        drop(first);
        assert!(!RunLock::is_held(&run));
        RunLock::ensure_free(&run).unwrap();
        RunLock::acquire(&run).unwrap();
    }

    #[test]
    fn a_file_in_the_way_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("f");
        std::fs::write(&file, b"x").unwrap();
        assert!(RunLock::acquire(&file).unwrap_err().to_string().contains("not a directory"));
    }
}
