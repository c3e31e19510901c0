//! Outputs appear whole or not at all: write into a temporary file beside the target, then rename.

use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use super::interrupt::{create_partial, PartialGuard};
use crate::error::{Error, Result};

/// Outputs this process must not replace: names a command chose because nothing was there. Their final
/// rename refuses to replace what appeared meanwhile, so of two commands writing one name at once the second
/// fails instead of both reporting success while one result silently wins.
static FRESH_ONLY: Mutex<BTreeSet<PathBuf>> = Mutex::new(BTreeSet::new());

fn fresh_only() -> std::sync::MutexGuard<'static, BTreeSet<PathBuf>> {
    FRESH_ONLY.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}

fn written_meanwhile(path: &Path) -> Error {
    Error::bad_file(
        path,
        "was written by another command while this one ran; rerun with another name, or with --force to replace it",
    )
}

/// Marks `path` as an output that must not exist when this process writes it.
pub fn claim_fresh(path: &Path) {
    fresh_only().insert(absolute(path));
}

/// Writes `path` through `fill`. On any error the temporary file is removed and `path` is untouched.
pub fn write_atomic<F>(path: &Path, fill: F) -> Result<()>
where
    F: FnOnce(&mut dyn Write) -> Result<()>,
{
    let target = Target::of(path)?;
    let mut tmp = partial_file_in(&target.temp_dir()?, "")?;
    {
        let mut buffered = std::io::BufWriter::new(tmp.as_file_mut());
        fill(&mut buffered)?;
        buffered.flush().map_err(|e| Error::io(path, e))?;
    }
    target.finish(tmp)
}

/// Same as `write_atomic` for writers that need `Seek` (MCAP writes its summary offsets back).
pub fn write_atomic_seekable<F>(path: &Path, fill: F) -> Result<()>
where
    F: FnOnce(&mut std::fs::File) -> Result<()>,
{
    let target = Target::of(path)?;
    let mut tmp = partial_file_in(&target.temp_dir()?, "")?;
    fill(tmp.as_file_mut())?;
    tmp.as_file_mut().sync_all().map_err(|e| Error::io(path, e))?;
    target.finish(tmp)
}

/// Where finished bytes go. A regular file (or a new path) is replaced by a rename; a device, FIFO or socket
/// (`--out /dev/null`, a pipe) is written into, since renaming over it would replace the device node with a
/// plain file. A symlink is followed, so the file it names is replaced and the link stays.
pub enum Target {
    Replace(PathBuf),
    WriteInto(PathBuf),
}

impl Target {
    pub fn of(path: &Path) -> Result<Target> {
        let claimed = fresh_only().contains(&absolute(path));
        if claimed && std::fs::symlink_metadata(path).is_ok() {
            return Err(written_meanwhile(path));
        }
        match std::fs::metadata(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Target::Replace(path.to_path_buf())),
            Err(e) => Err(Error::io(path, e)),
            Ok(m) if m.is_dir() => Err(Error::bad_file(path, "is a directory; expected a file path")),
            Ok(m) if m.is_file() => {
                let resolved = std::fs::canonicalize(path).map_err(|e| Error::io(path, e))?;
                Ok(Target::Replace(resolved))
            }
            Ok(_) => Ok(Target::WriteInto(path.to_path_buf())),
        }
    }

    /// Beside the target, so the rename stays on one file system; for special files the system's temp dir.
    pub fn temp_dir(&self) -> Result<PathBuf> {
        match self {
            Target::Replace(path) => {
                let dir = match path.parent() {
                    Some(p) if !p.as_os_str().is_empty() => p,
                    _ => Path::new("."),
                };
                std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
                Ok(dir.to_path_buf())
            }
            Target::WriteInto(_) => Ok(std::env::temp_dir()),
        }
    }

    pub fn finish(self, mut tmp: PartialFile) -> Result<()> {
        match self {
            Target::Replace(path) if fresh_only().contains(&absolute(&path)) => {
                tmp.persist_fresh(&path)?;
                // Ours from now on: a job that rewrites its own output replaces it.
                fresh_only().remove(&absolute(&path));
                Ok(())
            }
            Target::Replace(path) => tmp.persist(&path),
            Target::WriteInto(path) => {
                use std::io::Seek;
                let source = tmp.as_file_mut();
                source.seek(std::io::SeekFrom::Start(0)).map_err(|e| Error::io(&path, e))?;
                let mut sink = std::fs::OpenOptions::new().write(true).open(&path).map_err(|e| Error::io(&path, e))?;
                std::io::copy(source, &mut sink).map_err(|e| Error::io(&path, e))?;
                sink.flush().map_err(|e| Error::io(&path, e))
            }
        }
    }
}

/// A temporary file that an interruption removes (see `interrupt`) until it is renamed into place or
/// deleted. Fields drop in order: the file (deleting it) before its registration.
pub struct PartialFile {
    file: tempfile::NamedTempFile,
    _registered: PartialGuard,
}

impl PartialFile {
    pub fn path(&self) -> &Path {
        self.file.path()
    }

    pub fn as_file_mut(&mut self) -> &mut std::fs::File {
        self.file.as_file_mut()
    }

    /// Renames the file to `path`; the registration ends only afterwards.
    pub fn persist(self, path: &Path) -> Result<()> {
        let PartialFile { file, _registered } = self;
        file.persist(path).map_err(|e| Error::io(path, e.error))?;
        Ok(())
    }

    /// As [`persist`](Self::persist), failing when `path` exists by now.
    fn persist_fresh(self, path: &Path) -> Result<()> {
        let PartialFile { file, _registered } = self;
        match file.persist_noclobber(path) {
            Ok(_) => Ok(()),
            Err(e) if e.error.kind() == std::io::ErrorKind::AlreadyExists => Err(written_meanwhile(path)),
            Err(e) => Err(Error::io(path, e.error)),
        }
    }
}

/// A registered temporary file in `dir`, its name ending in `suffix`.
pub fn partial_file_in(dir: &Path, suffix: &str) -> Result<PartialFile> {
    let (file, registered) = create_partial(|| partial_file_builder().suffix(suffix).tempfile_in(dir), |f| f.path())
        .map_err(|e| Error::io(dir, e))?;
    Ok(PartialFile { file, _registered: registered })
}

/// Temporary files named so a leftover is recognisable, with the permissions of an ordinary output file
/// (tempfile's default 0600 would carry over through the rename).
fn partial_file_builder() -> tempfile::Builder<'static, 'static> {
    let mut builder = tempfile::Builder::new();
    builder.prefix(".mbrl-partial-");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o644));
    }
    builder
}

pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomic(path, |w| w.write_all(text.as_bytes()).map_err(|e| Error::io(path, e)))
}

pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<()> {
    write_atomic(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value).map_err(|e| Error::io(path, e.into()))?;
        writeln!(w).map_err(|e| Error::io(path, e))?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_fill_leaves_no_file_behind() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.txt");
        let result = write_atomic(&target, |w| {
            w.write_all(b"half").unwrap();
            Err(Error::data("stop"))
        });
        assert!(result.is_err());
        assert!(!target.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn successful_fill_replaces_target() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.txt");
        std::fs::write(&target, "old").unwrap();
        write_atomic(&target, |w| w.write_all(b"new").map_err(|e| Error::io(&target, e))).unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
    }

    #[test]
    fn a_claimed_output_that_appears_meanwhile_is_not_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("claimed.txt");
        claim_fresh(&target);
        std::fs::write(&target, "the other command's").unwrap();
        let err = write_text(&target, "ours").unwrap_err().to_string();
        assert!(err.contains("written by another command"), "{err}");
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "the other command's");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no temporary file left");
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_is_followed_and_a_device_is_written_into_not_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.txt");
        std::fs::write(&real, "old").unwrap();
        let link = dir.path().join("link.txt");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_atomic(&link, |w| w.write_all(b"new").map_err(|e| Error::io(&link, e))).unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");

        let null = Path::new("/dev/null");
        write_atomic(null, |w| w.write_all(b"discarded").map_err(|e| Error::io(null, e))).unwrap();
        let meta = std::fs::metadata(null).unwrap();
        assert!(!meta.is_file(), "/dev/null must stay a device");

        let err = write_atomic(dir.path(), |_| Ok(())).unwrap_err().to_string();
        assert!(err.contains("is a directory"), "{err}");
    }
}
