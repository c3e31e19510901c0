//! A checkpoint directory written as a unit. The manifest `checkpoint.json` lists each file's size and CRC-32,
//! and a reader trusts nothing it does not vouch for, so no command ever mixes a new `config.json` with old
//! weights, and a run still in progress is never taken for a finished model.
//!
//! A checkpoint is first staged whole in `.mbrl-next/` (its files, then its manifest), then moved into place
//! file by file, the manifest last. A staged manifest is the newer checkpoint: readers take each file it lists
//! from the stage if it is still there, else from the directory, so a run killed at any moment leaves either
//! the previous checkpoint or the staged one readable, and `--resume` continues from whichever is newer.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::util::atomic::{write_atomic, write_json};

pub const MANIFEST_FILE: &str = "checkpoint.json";
/// Where the next checkpoint is staged before it replaces the current one.
const STAGE_DIR: &str = ".mbrl-next";
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
    /// Set when the manifest read was the staged one: its files may still sit in the stage.
    staged: bool,
}

impl CheckpointDir {
    /// Prepares `path` for a new run: creates it, and first of all removes an old manifest, so that from now on
    /// until the first checkpoint of this run nothing in the directory passes for a model.
    pub fn start(path: &Path) -> Result<Self> {
        if path.exists() && !path.is_dir() {
            return Err(Error::bad_file(path, "exists and is not a directory; expected a checkpoint directory"));
        }
        std::fs::create_dir_all(path).map_err(|e| Error::io(path, e))?;
        let stage = path.join(STAGE_DIR);
        match std::fs::remove_dir_all(&stage) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(Error::io(&stage, e)),
        }
        let manifest = path.join(MANIFEST_FILE);
        match std::fs::remove_file(&manifest) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(Error::io(&manifest, e)),
        }
        Ok(CheckpointDir { path: path.to_path_buf(), staged: false })
    }

    /// Opens an existing checkpoint and verifies every file the manifest lists.
    pub fn open(path: &Path) -> Result<(Self, Manifest)> {
        if !path.is_dir() {
            return Err(Error::bad_file(
                path,
                "not a directory; expected a checkpoint directory written by `mbrl train`",
            ));
        }
        let staged_manifest = path.join(STAGE_DIR).join(MANIFEST_FILE);
        let staged = staged_manifest.is_file();
        let manifest_path = if staged { staged_manifest } else { path.join(MANIFEST_FILE) };
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
        let dir = CheckpointDir { path: path.to_path_buf(), staged };
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

    fn stage(&self) -> PathBuf {
        self.path.join(STAGE_DIR)
    }

    /// Stages one file of the next checkpoint and returns the entry the manifest will vouch for it with.
    pub fn write_file(&self, name: &str, bytes: &[u8]) -> Result<FileEntry> {
        let path = self.stage().join(name);
        write_atomic(&path, |w| w.write_all(bytes).map_err(|e| Error::io(&path, e)))?;
        Ok(FileEntry { bytes: bytes.len() as u64, crc32: crc32fast::hash(bytes) })
    }

    /// The last write of a checkpoint: staging its manifest makes the staged files the model; moving them
    /// into place afterwards changes nothing a reader sees.
    pub fn commit(&self, manifest: &Manifest) -> Result<()> {
        write_json(&self.stage().join(MANIFEST_FILE), manifest)?;
        self.settle()
    }

    /// Moves a staged checkpoint into place (the manifest last) and clears the stage; a stage without a
    /// manifest is the remains of a checkpoint that was never finished and is dropped. Only the run that owns
    /// the directory calls this (a new checkpoint, `--resume`), never a reader.
    pub fn settle(&self) -> Result<()> {
        let stage = self.stage();
        if stage.join(MANIFEST_FILE).is_file() {
            let entries = std::fs::read_dir(&stage).map_err(|e| Error::io(&stage, e))?;
            for entry in entries {
                let entry = entry.map_err(|e| Error::io(&stage, e))?;
                let name = entry.file_name();
                if name == MANIFEST_FILE || name.to_string_lossy().starts_with('.') {
                    continue;
                }
                std::fs::rename(entry.path(), self.path.join(&name)).map_err(|e| Error::io(&entry.path(), e))?;
            }
            let from = stage.join(MANIFEST_FILE);
            std::fs::rename(&from, self.file(MANIFEST_FILE)).map_err(|e| Error::io(&from, e))?;
        }
        match std::fs::remove_dir_all(&stage) {
            Ok(()) => Ok(()),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
            Err(e) => Err(Error::io(&stage, e)),
        }
    }

    /// A file of an opened checkpoint, checked against its manifest entry.
    pub fn read_verified(&self, name: &str, entry: &FileEntry) -> Result<Vec<u8>> {
        if name.contains('/') || name.contains('\\') || name.starts_with('.') {
            return Err(Error::bad_file(
                &self.file(MANIFEST_FILE),
                format!("file name '{name}' is not a plain file name"),
            ));
        }
        let staged = self.stage().join(name);
        let path = if self.staged && staged.is_file() { staged } else { self.file(name) };
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
        std::fs::write(dir.path().join("a.bin"), b"new").unwrap();
        let err = CheckpointDir::open(dir.path()).err().unwrap().to_string();
        assert!(err.contains("a.bin") && err.contains("incomplete"), "{err}");
    }

    /// A run killed while moving a staged checkpoint into place: every prefix of the moves leaves a
    /// directory that reads as the new checkpoint, and settling it finishes the move.
    #[test]
    fn a_checkpoint_half_moved_into_place_reads_whole() {
        let dir = tempfile::tempdir().unwrap();
        let ckpt = CheckpointDir::start(dir.path()).unwrap();
        let old: BTreeMap<String, FileEntry> =
            ["a.bin", "b.bin"].iter().map(|n| (n.to_string(), ckpt.write_file(n, b"old").unwrap())).collect();
        ckpt.commit(&manifest(old)).unwrap();
        assert!(!dir.path().join(STAGE_DIR).exists());
        let new: BTreeMap<String, FileEntry> =
            ["a.bin", "b.bin"].iter().map(|n| (n.to_string(), ckpt.write_file(n, b"newer").unwrap())).collect();
        // Files staged, no staged manifest yet: the old checkpoint is what a reader gets.
        let (opened, _) = CheckpointDir::open(dir.path()).unwrap();
        assert_eq!(opened.read_verified("a.bin", &old_entry()).unwrap(), b"old");
        let mut staged_manifest = manifest(new.clone());
        staged_manifest.step = 2;
        write_json(&dir.path().join(STAGE_DIR).join(MANIFEST_FILE), &staged_manifest).unwrap();
        // Killed after moving one file.
        std::fs::rename(dir.path().join(STAGE_DIR).join("a.bin"), dir.path().join("a.bin")).unwrap();
        let (opened, m) = CheckpointDir::open(dir.path()).unwrap();
        assert_eq!(m.step, 2);
        for name in ["a.bin", "b.bin"] {
            assert_eq!(opened.read_verified(name, &new[name]).unwrap(), b"newer");
        }
        opened.settle().unwrap();
        assert!(!dir.path().join(STAGE_DIR).exists());
        assert_eq!(CheckpointDir::open(dir.path()).unwrap().1.step, 2);
    }

    fn old_entry() -> FileEntry {
        FileEntry { bytes: 3, crc32: crc32fast::hash(b"old") }
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
