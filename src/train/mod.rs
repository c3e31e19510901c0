//! Training shared by every learned method: the loop ([`fit`]), checkpoints written as a unit
//! ([`checkpoint`]), weights as safetensors ([`tensors`]) and config files ([`config`]).

pub mod checkpoint;
pub mod config;
pub mod data_file;
pub mod datasets;
pub mod fit;
pub mod job;
pub mod method;
pub mod run_dir;
pub mod settings;
pub mod state;
pub mod tensors;

pub use checkpoint::{CheckpointDir, Manifest};
pub use data_file::{loss_history, DataFile};
pub use fit::{
    fit, Budget, Checkpointer, DirCheckpointer, FitOutcome, FitSettings, MemoryCheckpointer, ResumePoint, Snapshot,
    TrainingMethod, CONFIG_FILE, MODEL_FILE, STATE_FILE,
};
pub use job::{continuation, loss_panel, training_view, validation_panel, Continuation, Extension, Start};
pub use method::{Method, Prepared, Request, RunConfig, RunRecord, Trained};
pub use tensors::StoredTensor;

use std::path::Path;

use crate::error::{Error, Result};

/// An opened checkpoint with its config, verified against the manifest.
/// Which checkpoints a loader takes: finished runs only, or also a run still in training (its best-validation
/// weights so far), for looking at a long run while it goes on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Accept {
    Finished,
    InProgress,
}

/// How far the training of a loaded model went, for reports that must not pass a run in progress off as done.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct TrainingProgress {
    pub step: u64,
    pub total_steps: u64,
    pub complete: bool,
}

impl TrainingProgress {
    /// "3000 steps", or "11200 of 30000 steps (training still in progress)".
    pub fn describe(&self) -> String {
        if self.complete {
            format!("{} steps", self.total_steps)
        } else {
            format!("{} of {} steps (training still in progress)", self.step, self.total_steps)
        }
    }

    /// "`models/x`, trained 3000 steps": how a report names the checkpoint it evaluated.
    pub fn name_model(&self, dir: &Path) -> String {
        format!("`{}`, trained {}", dir.display(), self.describe())
    }

    /// Empty for a finished run, else ", trained 11200 of 30000 steps (training still in progress)": appended to
    /// a model's one-line description, so planner output never passes a run in progress off as done.
    pub fn unfinished_note(&self) -> String {
        if self.complete {
            String::new()
        } else {
            format!(", trained {}", self.describe())
        }
    }
}

pub struct OpenedCheckpoint {
    pub dir: CheckpointDir,
    pub manifest: Manifest,
    pub config: serde_json::Value,
}

impl OpenedCheckpoint {
    pub fn open(path: &Path) -> Result<Self> {
        let (dir, manifest) = CheckpointDir::open(path)?;
        let entry = manifest
            .files
            .get(CONFIG_FILE)
            .ok_or_else(|| Error::bad_file(&dir.file(checkpoint::MANIFEST_FILE), format!("lists no {CONFIG_FILE}")))?;
        let bytes = dir.read_verified(CONFIG_FILE, entry)?;
        let config = serde_json::from_slice(&bytes)
            .map_err(|e| Error::bad_file(&dir.file(CONFIG_FILE), format!("not valid JSON: {e}")))?;
        Ok(OpenedCheckpoint { dir, manifest, config })
    }

    /// A resumed run must ask for the steps the checkpointed run was started with; checked before any data is
    /// loaded or network built, so a changed or corrupt step count never starts a run of the wrong length.
    pub fn expect_total_steps(&self, config_steps: u64) -> Result<()> {
        if config_steps != self.manifest.total_steps || config_steps > job::MAX_TRAIN_STEPS {
            return Err(Error::bad_file(
                &self.dir.file(CONFIG_FILE),
                format!(
                    "asks for {config_steps} training steps, but the checkpoint belongs to a run of {}: the config was changed",
                    self.manifest.total_steps
                ),
            ));
        }
        Ok(())
    }

    /// Refuses checkpoints of another method, and models still in training.
    pub fn expect_finished(&self, method: &str) -> Result<()> {
        self.expect(method, Accept::Finished)
    }

    /// Refuses checkpoints of another method.
    pub fn expect_method(&self, method: &str) -> Result<()> {
        if self.manifest.method != method {
            return Err(Error::wrong_method(&self.manifest.method, method).at(self.dir.path()));
        }
        Ok(())
    }

    /// Refuses checkpoints of another method, and, unless `accept` takes them, models still in training.
    pub fn expect(&self, method: &str, accept: Accept) -> Result<()> {
        let path = self.dir.path();
        self.expect_method(method)?;
        if !self.manifest.complete && accept == Accept::Finished {
            return Err(Error::unfinished(self.manifest.step, self.manifest.total_steps).at(path));
        }
        Ok(())
    }

    pub fn progress(&self) -> TrainingProgress {
        TrainingProgress {
            step: self.manifest.step,
            total_steps: self.manifest.total_steps,
            complete: self.manifest.complete,
        }
    }

    /// The verified bytes of a listed file; `None` when the checkpoint does not list it.
    pub fn file_bytes(&self, name: &str) -> Result<Option<Vec<u8>>> {
        match self.manifest.files.get(name) {
            Some(entry) => Ok(Some(self.dir.read_verified(name, entry)?)),
            None => Ok(None),
        }
    }

    /// The tensors of one listed file.
    pub fn tensors(&self, name: &str) -> Result<Vec<StoredTensor>> {
        let entry = self
            .manifest
            .files
            .get(name)
            .ok_or_else(|| Error::bad_file(self.dir.path(), format!("the checkpoint lists no {name}")))?;
        let bytes = self.dir.read_verified(name, entry)?;
        let stored = tensors::parse(&self.dir.file(name), &bytes)?;
        if name == MODEL_FILE {
            tensors::check_weights(&self.dir.file(name), &stored)?;
        }
        Ok(stored)
    }

    /// Where to pick the run up again, for `--resume`.
    pub fn resume_point(&self) -> Result<ResumePoint> {
        Ok(ResumePoint {
            step: self.manifest.step,
            best_step: self.manifest.best_step,
            best_valid_loss: self.manifest.best_valid_loss,
            best_weights: self.tensors(MODEL_FILE)?,
        })
    }
}

/// Opens a checkpoint of method `M` and reads its record, refusing another method's checkpoint and, unless
/// `accept` takes it, a run still in training: what every loader starts with.
pub fn open_run<M: Method>(dir: &Path, accept: Accept) -> Result<(OpenedCheckpoint, RunRecord<M>)> {
    let opened = OpenedCheckpoint::open(dir)?;
    opened.expect(M::NAME, accept)?;
    let record = RunRecord::<M>::read(&opened)?;
    Ok((opened, record))
}
