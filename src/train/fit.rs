//! The training loop every method shares: steps, validation, best-validation snapshot, periodic checkpoints,
//! divergence detection, cancellation, progress and metrics, and `--resume`. A method only says how to take one
//! step, how to validate and what its state is.

use std::collections::BTreeMap;

use super::checkpoint::{CheckpointDir, FileEntry, Manifest, CHECKPOINT_FORMAT};
use super::tensors::{to_bytes, StoredTensor, TensorData};
use crate::error::{Error, Result};
use crate::run::{JsonlMonitor, Monitor};
use crate::util::warm_pool::Warm;

pub const CONFIG_FILE: &str = "config.json";
pub const MODEL_FILE: &str = "model.safetensors";
pub const STATE_FILE: &str = "state.safetensors";

/// What a learning method contributes to the shared loop.
pub trait TrainingMethod {
    /// One optimizer step (`step` counts from 1); returns the training loss of its batch. All randomness of a
    /// step must derive from the seed and `step`, so that a resumed run draws what the uninterrupted run drew.
    fn step(&mut self, step: u64) -> Result<f64>;
    /// Loss on held-out data (lower is better), or `None` when the method keeps none back.
    fn validate(&mut self) -> Result<Option<f64>>;
    /// The weights a user loads, named as the equivalent PyTorch module's `state_dict`.
    fn weights(&self) -> Vec<StoredTensor>;
    /// Everything else a resumed run needs: live weights, optimizer moments and counters.
    fn state(&self) -> Vec<StoredTensor>;
    fn restore(&mut self, state: &[StoredTensor]) -> Result<()>;
    /// Files in the method's own formats, derived from the current weights and saved with every checkpoint
    /// (the ball EKF's `params.json`, which `filter` and `predict` read).
    fn artifacts(&self) -> Result<Vec<(String, Vec<u8>)>> {
        Ok(Vec::new())
    }
    /// A budget counted in something other than steps (SEADS counts environment steps): how much is used and
    /// the total. The run ends, complete, after the step that uses it up, so `total_steps` is only an upper
    /// bound, and progress (with its rate and ETA) is reported in the budget's unit under the phase `unit`.
    fn budget(&self) -> Option<Budget> {
        None
    }
    /// Figures of the validation just run beyond its loss, logged and charted under these names (non-finite
    /// ones are left out).
    fn validation_scalars(&mut self) -> Result<Vec<(&'static str, f64)>> {
        Ok(Vec::new())
    }
    /// Figures of the step just taken beyond its loss, charted and logged under these names.
    fn step_scalars(&self) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
    /// Text panels of the step just taken (SEADS: a board before and after a skill).
    fn step_texts(&self) -> Vec<(&'static str, String)> {
        Vec::new()
    }
}

/// A boxed trainer trains as the trainer it holds, so a method whose trainer type depends on its data (the
/// SEADS game) can name one type.
impl<T: TrainingMethod + ?Sized> TrainingMethod for Box<T> {
    fn step(&mut self, step: u64) -> Result<f64> {
        (**self).step(step)
    }
    fn validate(&mut self) -> Result<Option<f64>> {
        (**self).validate()
    }
    fn weights(&self) -> Vec<StoredTensor> {
        (**self).weights()
    }
    fn state(&self) -> Vec<StoredTensor> {
        (**self).state()
    }
    fn restore(&mut self, state: &[StoredTensor]) -> Result<()> {
        (**self).restore(state)
    }
    fn artifacts(&self) -> Result<Vec<(String, Vec<u8>)>> {
        (**self).artifacts()
    }
    fn budget(&self) -> Option<Budget> {
        (**self).budget()
    }
    fn validation_scalars(&mut self) -> Result<Vec<(&'static str, f64)>> {
        (**self).validation_scalars()
    }
    fn step_scalars(&self) -> Vec<(&'static str, f64)> {
        (**self).step_scalars()
    }
    fn step_texts(&self) -> Vec<(&'static str, String)> {
        (**self).step_texts()
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    pub unit: &'static str,
    pub used: u64,
    pub total: u64,
}

impl Budget {
    pub fn spent(&self) -> bool {
        self.used >= self.total
    }
}

#[derive(Clone, Debug)]
pub struct FitSettings {
    pub method: String,
    pub env: Option<String>,
    pub total_steps: u64,
    pub validate_every: u64,
    pub checkpoint_every: u64,
}

/// Where a resumed run picks up (read from the checkpoint by [`super::resume`]).
#[derive(Clone, Debug)]
pub struct ResumePoint {
    pub step: u64,
    pub best_step: Option<u64>,
    pub best_valid_loss: Option<f64>,
    pub best_weights: Vec<StoredTensor>,
}

#[derive(Clone, Debug)]
pub struct FitOutcome {
    pub steps: u64,
    pub best_step: Option<u64>,
    pub best_valid_loss: Option<f64>,
    pub last_train_loss: Option<f64>,
}

struct Best {
    step: Option<u64>,
    loss: Option<f64>,
    weights: Vec<StoredTensor>,
}

/// A checkpoint as the loop hands it over: the model's weights to keep (the best-validation snapshot, or the
/// live weights of a method that has not validated yet) and everything a resumed run needs.
pub struct Snapshot<'a> {
    pub method: &'a dyn TrainingMethod,
    pub settings: &'a FitSettings,
    pub step: u64,
    pub complete: bool,
    pub best_step: Option<u64>,
    pub best_valid_loss: Option<f64>,
    pub weights: &'a [StoredTensor],
}

/// Where the loop's checkpoints go: a run directory (`mbrl train`), or memory (`eval quick`, benchmarks and
/// tests, which train, use the model and throw it away). One loop serves both.
pub trait Checkpointer {
    fn save(&mut self, snapshot: Snapshot) -> Result<()>;
    /// Whether a saved checkpoint outlives the process, so a failed run can say what is left to resume.
    fn persists(&self) -> bool;
}

/// Checkpoints into a run directory whose `config.json` (already written) is vouched for by `config_entry`;
/// the manifest records how far `metrics` had been written, so `--resume` cuts the log back to it.
pub struct DirCheckpointer<'a> {
    pub dir: &'a CheckpointDir,
    pub config_entry: &'a FileEntry,
    pub metrics: &'a JsonlMonitor,
}

impl Checkpointer for DirCheckpointer<'_> {
    fn save(&mut self, snapshot: Snapshot) -> Result<()> {
        let dir = self.dir;
        let mut files = BTreeMap::new();
        files.insert(CONFIG_FILE.to_string(), self.config_entry.clone());
        files.insert(MODEL_FILE.to_string(), dir.write_file(MODEL_FILE, &to_bytes(snapshot.weights)?)?);
        files.insert(STATE_FILE.to_string(), dir.write_file(STATE_FILE, &to_bytes(&snapshot.method.state())?)?);
        for (name, bytes) in snapshot.method.artifacts()? {
            let entry = dir.write_file(&name, &bytes)?;
            files.insert(name, entry);
        }
        let metrics_bytes = self.metrics.flush_position().map_err(|e| Error::io(&dir.file("metrics.jsonl"), e))?;
        dir.commit(&Manifest {
            format_version: CHECKPOINT_FORMAT,
            method: snapshot.settings.method.clone(),
            env: snapshot.settings.env.clone(),
            step: snapshot.step,
            total_steps: snapshot.settings.total_steps,
            complete: snapshot.complete,
            best_step: snapshot.best_step,
            best_valid_loss: snapshot.best_valid_loss,
            metrics_bytes,
            files,
        })
    }

    fn persists(&self) -> bool {
        true
    }
}

/// Keeps the last checkpoint's weights and step in memory.
#[derive(Default)]
pub struct MemoryCheckpointer {
    pub step: u64,
    pub complete: bool,
    pub weights: Vec<StoredTensor>,
}

impl Checkpointer for MemoryCheckpointer {
    fn save(&mut self, snapshot: Snapshot) -> Result<()> {
        (self.step, self.complete) = (snapshot.step, snapshot.complete);
        self.weights = snapshot.weights.to_vec();
        Ok(())
    }

    fn persists(&self) -> bool {
        false
    }
}

/// Runs `method` to `settings.total_steps`, checkpointing through `checkpoints`; a resumed run picks up at
/// `resume`. Every scalar goes to `monitor`.
/// The steps run on a pool thread with the other workers kept awake: a fused step is a few short parallel
/// regions, and waking parked workers for each cost small presets a fifth of their step on two threads
/// (`util::warm_pool`).
pub fn fit(
    method: &mut (dyn TrainingMethod + Send),
    settings: &FitSettings,
    checkpoints: &mut (dyn Checkpointer + Send),
    resume: Option<ResumePoint>,
    monitor: &dyn Monitor,
) -> Result<FitOutcome> {
    crate::util::warm_pool::run_warm(|warm| fit_here(method, settings, checkpoints, resume, monitor, warm))
}

fn fit_here(
    method: &mut (dyn TrainingMethod + Send),
    settings: &FitSettings,
    checkpoints: &mut (dyn Checkpointer + Send),
    resume: Option<ResumePoint>,
    monitor: &dyn Monitor,
    warm: &Warm,
) -> Result<FitOutcome> {
    if settings.total_steps == 0 {
        return Err(Error::config("training needs at least one step"));
    }
    let every = |n: u64| n.max(1);
    let (start, mut best) = match resume {
        Some(r) => (r.step, Best { step: r.best_step, loss: r.best_valid_loss, weights: r.best_weights }),
        None => (0, Best { step: None, loss: None, weights: Vec::new() }),
    };
    let mut last_checkpoint = start;
    let mut last_loss = None;
    let mut steps_done = start;
    for step in start + 1..=settings.total_steps {
        if monitor.is_cancelled() {
            return Err(Error::cancelled());
        }
        warm.rearm();
        let loss = method.step(step)?;
        if !loss.is_finite() {
            return Err(diverged(settings, step, "training", loss, last_checkpoint, checkpoints.persists()));
        }
        last_loss = Some(loss);
        monitor.scalar("train/loss", step, loss);
        for (name, value) in method.step_scalars() {
            monitor.scalar(name, step, value);
        }
        for (name, text) in method.step_texts() {
            monitor.emit(&crate::run::Event::text(name, text));
        }
        let budget = method.budget();
        let last = step == settings.total_steps || budget.is_some_and(|b| b.spent());
        if step % every(settings.validate_every) == 0 || last {
            if let Some(valid) = method.validate()? {
                if !valid.is_finite() {
                    return Err(diverged(settings, step, "validation", valid, last_checkpoint, checkpoints.persists()));
                }
                monitor.scalar("valid/loss", step, valid);
                for (name, value) in method.validation_scalars()? {
                    if value.is_finite() {
                        monitor.scalar(name, step, value);
                    }
                }
                if best.loss.is_none_or(|b| valid < b) {
                    best = Best { step: Some(step), loss: Some(valid), weights: method.weights() };
                }
            }
        }
        match budget {
            Some(b) => monitor.progress(b.unit, b.used.min(b.total), b.total),
            None => monitor.progress("train", step, settings.total_steps),
        }
        if step % every(settings.checkpoint_every) == 0 || last {
            // A method that has not validated yet (or never does) keeps its live weights.
            let live;
            let weights = if best.step.is_some() {
                &best.weights
            } else {
                live = method.weights();
                &live
            };
            // The loss of the last update is never computed, and an update can overflow on its own (an absurd
            // learning rate): caught here, before a checkpoint no loader would take back is written.
            if let Some(name) = non_finite_tensor(weights) {
                let saved = saved_note(last_checkpoint, checkpoints.persists());
                return Err(Error::diverged(format!(
                    "{} diverged: weight tensor '{name}' holds a non-finite value at step {step}; {saved}. Lower \
                     the learning rate or check the data for outliers",
                    settings.method
                )));
            }
            checkpoints.save(Snapshot {
                method: &*method,
                settings,
                step,
                complete: last,
                best_step: best.step,
                best_valid_loss: best.loss,
                weights,
            })?;
            last_checkpoint = step;
        }
        if last {
            steps_done = step;
            break;
        }
    }
    Ok(FitOutcome { steps: steps_done, best_step: best.step, best_valid_loss: best.loss, last_train_loss: last_loss })
}

fn saved_note(checkpoint: u64, persists: bool) -> String {
    match (checkpoint, persists) {
        (0, _) | (_, false) => "no checkpoint was written".to_string(),
        _ => format!("the checkpoint of step {checkpoint} is intact and can be resumed"),
    }
}

fn non_finite_tensor(weights: &[StoredTensor]) -> Option<&str> {
    let finite = |t: &StoredTensor| match &t.data {
        TensorData::F32(v) => v.iter().all(|x| x.is_finite()),
        TensorData::F64(v) => v.iter().all(|x| x.is_finite()),
    };
    weights.iter().find(|t| !finite(t)).map(|t| t.name.as_str())
}

fn diverged(settings: &FitSettings, step: u64, what: &str, value: f64, checkpoint: u64, persists: bool) -> Error {
    let saved = saved_note(checkpoint, persists);
    let message = format!(
        "{} diverged: {what} loss {value} at step {step}; {saved}. Lower the learning rate or check the data for outliers",
        settings.method
    );
    Error::diverged_at(step, value, message)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::NullMonitor;
    use crate::train::tensors::{parse, TensorData};

    /// One weight that counts the steps; validation loss |w − 3|, NaN training loss from `nan_at` on.
    struct Counter {
        w: f32,
        nan_at: u64,
        /// Units of an outside budget each step uses (0: no such budget).
        budget_per_step: u64,
    }

    impl TrainingMethod for Counter {
        fn step(&mut self, step: u64) -> Result<f64> {
            self.w += 1.0;
            Ok(if step >= self.nan_at { f64::NAN } else { 1.0 / step as f64 })
        }

        fn validate(&mut self) -> Result<Option<f64>> {
            Ok(Some((self.w as f64 - 3.0).abs()))
        }

        fn weights(&self) -> Vec<StoredTensor> {
            vec![StoredTensor::f32("w", vec![1], vec![self.w])]
        }

        fn state(&self) -> Vec<StoredTensor> {
            self.weights()
        }

        fn restore(&mut self, state: &[StoredTensor]) -> Result<()> {
            if let TensorData::F32(v) = &state[0].data {
                self.w = v[0];
            }
            Ok(())
        }

        fn budget(&self) -> Option<Budget> {
            (self.budget_per_step > 0).then(|| Budget {
                unit: "units",
                used: self.w as u64 * self.budget_per_step,
                total: 10,
            })
        }
    }

    #[derive(Default)]
    struct Recorder(std::sync::Mutex<Vec<crate::run::Event>>);

    impl Monitor for Recorder {
        fn emit(&self, event: &crate::run::Event) {
            self.0.lock().unwrap().push(event.clone());
        }
    }

    fn run_counter(counter: &mut Counter, dir: &std::path::Path, monitor: &dyn Monitor) -> Result<FitOutcome> {
        let settings =
            FitSettings { method: "counter".into(), env: None, total_steps: 8, validate_every: 1, checkpoint_every: 2 };
        let ckpt = CheckpointDir::start(dir)?;
        let entry = ckpt.write_file(CONFIG_FILE, b"{}")?;
        let metrics = JsonlMonitor::create(&dir.join("metrics.jsonl")).unwrap();
        let mut checkpoints = DirCheckpointer { dir: &ckpt, config_entry: &entry, metrics: &metrics };
        fit(counter, &settings, &mut checkpoints, None, monitor)
    }

    fn run(nan_at: u64, dir: &std::path::Path) -> Result<FitOutcome> {
        run_counter(&mut Counter { w: 0.0, nan_at, budget_per_step: 0 }, dir, &NullMonitor)
    }

    /// An update that overflows the weights while the loss it was computed from was finite.
    #[test]
    fn non_finite_weights_stop_the_run_before_their_checkpoint() {
        let dir = tempfile::tempdir().unwrap();
        let settings = FitSettings {
            method: "counter".into(),
            env: None,
            total_steps: 8,
            validate_every: 100,
            checkpoint_every: 2,
        };
        let ckpt = CheckpointDir::start(dir.path()).unwrap();
        let entry = ckpt.write_file(CONFIG_FILE, b"{}").unwrap();
        let metrics = JsonlMonitor::create(&dir.path().join("metrics.jsonl")).unwrap();
        let mut checkpoints = DirCheckpointer { dir: &ckpt, config_entry: &entry, metrics: &metrics };
        let mut counter = Counter { w: f32::INFINITY, nan_at: u64::MAX, budget_per_step: 0 };
        let err = fit(&mut counter, &settings, &mut checkpoints, None, &NullMonitor).unwrap_err().to_string();
        assert!(
            err.contains("weight tensor 'w' holds a non-finite value at step 2; no checkpoint was written"),
            "{err}"
        );
        assert!(!dir.path().join(MODEL_FILE).exists());
    }

    #[test]
    fn an_outside_budget_ends_the_run_complete_and_carries_the_progress() {
        let dir = tempfile::tempdir().unwrap();
        let recorder = Recorder::default();
        let mut counter = Counter { w: 0.0, nan_at: u64::MAX, budget_per_step: 3 };
        let outcome = run_counter(&mut counter, dir.path(), &recorder).unwrap();
        assert_eq!(outcome.steps, 4, "3 units per step use up 10 in the fourth step");
        let progress: Vec<(String, u64, u64)> = recorder
            .0
            .lock()
            .unwrap()
            .iter()
            .filter_map(|e| match e {
                crate::run::Event::Progress { phase, done, total } => Some((phase.clone(), *done, *total)),
                _ => None,
            })
            .collect();
        let expected: Vec<(String, u64, u64)> =
            [3, 6, 9, 10].iter().map(|&done| ("units".to_string(), done, 10)).collect();
        assert_eq!(progress, expected, "progress counts the budget, capped at its total");
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("checkpoint.json")).unwrap()).unwrap();
        assert_eq!((manifest["step"].as_u64(), manifest["complete"].as_bool()), (Some(4), Some(true)));
    }

    #[test]
    fn the_saved_model_is_the_best_validation_snapshot_not_the_live_weights() {
        let dir = tempfile::tempdir().unwrap();
        let outcome = run(u64::MAX, dir.path()).unwrap();
        assert_eq!((outcome.best_step, outcome.best_valid_loss), (Some(3), Some(0.0)));
        let saved = parse(&dir.path().join(MODEL_FILE), &std::fs::read(dir.path().join(MODEL_FILE)).unwrap()).unwrap();
        assert_eq!(saved[0].data, TensorData::F32(vec![3.0]), "live weights ended at 8");
    }

    #[test]
    fn divergence_is_a_typed_error_that_names_the_intact_checkpoint() {
        let dir = tempfile::tempdir().unwrap();
        let err = run(5, dir.path()).err().unwrap();
        let text = err.to_string();
        assert!(matches!(err.kind(), crate::ErrorKind::Diverged { step: Some(5), .. }), "{text}");
        assert!(text.contains("step 4 is intact"), "{text}");
        let manifest: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("checkpoint.json")).unwrap()).unwrap();
        assert_eq!((manifest["step"].as_u64(), manifest["complete"].as_bool()), (Some(4), Some(false)));
    }
}
