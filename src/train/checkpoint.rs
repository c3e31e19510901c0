//! A checkpoint directory written as a unit: every file is replaced atomically, and the manifest
//! `checkpoint.json`, listing each file's size and CRC-32, is written last. A reader trusts nothing the manifest
//! does not vouch for, so a run killed between two files leaves a directory that every command refuses (it
//! never mixes a new `config.json` with old weights), and a run still in progress is never taken for a finished
//! model.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::util::atomic::{write_atomic, write_json};

pub const MANIFEST_FILE: &str = "checkpoint.json";
pub const CHECKPOINT_FORMAT: u32 = 1;
/// The manifest and config are small JSON files; anything bigger is not ours.
const MAX_JSON_BYTES: u64 = 16 << 20;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileEntry {
    pub bytes: u64,
    pub crc32: u32,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    pub format_version: u32,
    pub method: String,
    /// The environment the model was trained for; `None` for models of recordings (the ball EKF).
    pub env: Option<String>,
    /// Optimizer steps done.
    pub step: u64,
    pub total_steps: u64,
    /// True once training ran to `total_steps`; models still training are refused by `plan` and friends.
    pub complete: bool,
    pub best_step: Option<u64>,
    pub best_valid_loss: Option<f64>,
    /// Length of metrics.jsonl at this checkpoint: `--resume` cuts the log back to it.
    pub metrics_bytes: u64,
    pub files: BTreeMap<String, FileEntry>,
}

pub struct CheckpointDir {
    path: PathBuf,
}

impl CheckpointDir {
    /// Prepares `path` for a new run: creates it, and first of all removes an old manifest, so that from now on
    /// until the first checkpoint of this run nothing in the directory passes for a model.
    pub fn start(path: &Path) -> Result<Self> {
        if path.exists() && !path.is_dir() {
            return Err(Error::bad_file(path, "exists and is not a directory; expected a checkpoint directory"));
        }
        std::fs::create_dir_all(path).map_err(|e| Error::io(path, e))?;
        let manifest = path.join(MANIFEST_FILE);
        match std::fs::remove_file(&manifest) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(Error::io(&manifest, e)),
        }
        Ok(CheckpointDir { path: path.to_path_buf() })
    }

    /// Opens an existing checkpoint and verifies every file the manifest lists.
    pub fn open(path: &Path) -> Result<(Self, Manifest)> {
        if !path.is_dir() {
            return Err(Error::bad_file(
                path,
                "not a directory; expected a checkpoint directory written by `mbrl train`",
            ));
        }
        let manifest_path = path.join(MANIFEST_FILE);
        if !manifest_path.exists() {
            return Err(Error::bad_file(
                path,
                format!("no {MANIFEST_FILE}: not a finished checkpoint (training never saved here, or was stopped before its first checkpoint)"),
            ));
        }
        let bytes = read_bounded(&manifest_path, MAX_JSON_BYTES)?;
        let manifest: Manifest = serde_json::from_slice(&bytes)
            .map_err(|e| Error::bad_file(&manifest_path, format!("not a checkpoint manifest: {e}")))?;
        if manifest.format_version != CHECKPOINT_FORMAT {
            return Err(Error::bad_file(
                &manifest_path,
                format!(
                    "checkpoint format {} is not supported (this mbrl reads {CHECKPOINT_FORMAT})",
                    manifest.format_version
                ),
            ));
        }
        let dir = CheckpointDir { path: path.to_path_buf() };
        for (name, entry) in &manifest.files {
            dir.read_verified(name, entry)?;
        }
        Ok((dir, manifest))
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn file(&self, name: &str) -> PathBuf {
        self.path.join(name)
    }

    /// Writes one file atomically and returns the entry the manifest will vouch for it with.
    pub fn write_file(&self, name: &str, bytes: &[u8]) -> Result<FileEntry> {
        let path = self.file(name);
        write_atomic(&path, |w| w.write_all(bytes).map_err(|e| Error::io(&path, e)))?;
        Ok(FileEntry { bytes: bytes.len() as u64, crc32: crc32fast::hash(bytes) })
    }

    /// The last write of a checkpoint: from here on the listed files form the model.
    pub fn commit(&self, manifest: &Manifest) -> Result<()> {
        write_json(&self.file(MANIFEST_FILE), manifest)
    }

    /// A file of an opened checkpoint, checked against its manifest entry.
    pub fn read_verified(&self, name: &str, entry: &FileEntry) -> Result<Vec<u8>> {
        if name.contains('/') || name.contains('\\') || name.starts_with('.') {
            return Err(Error::bad_file(
                &self.file(MANIFEST_FILE),
                format!("file name '{name}' is not a plain file name"),
            ));
        }
        let path = self.file(name);
        let size = std::fs::metadata(&path).map_err(|e| Error::io(&path, e))?.len();
        let bytes = if size == entry.bytes { read_bounded(&path, entry.bytes)? } else { Vec::new() };
        if bytes.len() as u64 != entry.bytes || crc32fast::hash(&bytes) != entry.crc32 {
            return Err(Error::bad_file(
                &path,
                format!("does not match {MANIFEST_FILE} (size or CRC-32 differ): the checkpoint is incomplete or was changed; retrain or resume from an intact copy"),
            ));
        }
        Ok(bytes)
    }
}

pub use crate::util::bounded_read::read_bounded;

/// Reads a small JSON file of a checkpoint (or a config) with the same bounds.
pub fn read_json_file(path: &Path) -> Result<serde_json::Value> {
    let bytes = read_bounded(path, MAX_JSON_BYTES)?;
    serde_json::from_slice(&bytes).map_err(|e| Error::bad_file(path, format!("not valid JSON: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest(files: BTreeMap<String, FileEntry>) -> Manifest {
        Manifest {
            format_version: CHECKPOINT_FORMAT,
            method: "test".into(),
            env: None,
            step: 1,
            total_steps: 1,
            complete: true,
            best_step: None,
            best_valid_loss: None,
            metrics_bytes: 0,
            files,
        }
    }

    #[test]
    fn a_file_changed_after_the_manifest_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let ckpt = CheckpointDir::start(dir.path()).unwrap();
        let entry = ckpt.write_file("a.bin", b"old").unwrap();
        ckpt.commit(&manifest(BTreeMap::from([("a.bin".to_string(), entry)]))).unwrap();
        assert!(CheckpointDir::open(dir.path()).is_ok());
        ckpt.write_file("a.bin", b"new").unwrap();
        let err = CheckpointDir::open(dir.path()).err().unwrap().to_string();
        assert!(err.contains("a.bin") && err.contains("incomplete"), "{err}");
    }

    #[test]
    fn starting_a_run_unmakes_the_old_model() {
        let dir = tempfile::tempdir().unwrap();
        let ckpt = CheckpointDir::start(dir.path()).unwrap();
        ckpt.commit(&manifest(BTreeMap::new())).unwrap();
        assert!(CheckpointDir::open(dir.path()).is_ok());
        CheckpointDir::start(dir.path()).unwrap();
        let err = CheckpointDir::open(dir.path()).err().unwrap().to_string();
        assert!(err.contains("not a finished checkpoint"), "{err}");
    }

    #[test]
    fn special_files_are_not_read() {
        assert!(read_bounded(Path::new("/dev/zero"), 100).is_err());
    }
}
