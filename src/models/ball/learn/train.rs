//! Fitting Ψ by maximizing log p(m_3:N | m_1, m_2) over chunks (eq. 6.24) with Adam.

use std::sync::Mutex;

use serde::{Deserialize, Serialize};

use super::spin_net::SpinNetWeights;
use super::trainer::BallEkfTrainer;
use crate::data::ball_io::Recording;
use crate::error::{Error, Result};
use crate::models::ball::BallModelParams;
use crate::nn::AdamConfig;
use crate::run::{Event, Monitor};
use crate::train::{fit, FitSettings, MemoryCheckpointer};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainSettings {
    /// Optimizer steps. An epoch is one pass over all chunks in a seeded random order; the next epoch reshuffles,
    /// and an epoch's last batch may be smaller.
    pub steps: u64,
    pub batch_size: usize,
    /// Frames per chunk, N in eq. 6.24.
    pub chunk_len: usize,
    pub learning_rate: f64,
    pub beta1: f64,
    pub beta2: f64,
    /// Adam's ε, added to √v̂ (burn's default 1e-5 differs from PyTorch's 1e-8, which the authors used).
    pub epsilon: f64,
    pub seed: u64,
    /// Learn the launcher spin network (C.1.3) instead of the broad spin prior; every recording then needs side
    /// information.
    pub launcher_prior: bool,
    /// Starting point of Ψ (and the fixed physics).
    pub initial: BallModelParams,
}

impl Default for TrainSettings {
    /// The thesis' optimizer (Adam, lr 5e-3, batch 64, chunks of 50) from Table C.1's initial values.
    fn default() -> Self {
        TrainSettings {
            steps: 1000,
            batch_size: 64,
            chunk_len: 50,
            learning_rate: 5e-3,
            beta1: 0.9,
            beta2: 0.999,
            epsilon: 1e-8,
            seed: 0,
            launcher_prior: false,
            initial: BallModelParams::initial(),
        }
    }
}

impl TrainSettings {
    /// The thesis' Adam: no weight decay, no clipping.
    pub fn optimizer(&self) -> AdamConfig {
        AdamConfig {
            learning_rate: self.learning_rate,
            beta1: self.beta1,
            beta2: self.beta2,
            epsilon: self.epsilon,
            weight_decay: 0.0,
            clip_grad_norm: None,
        }
    }

    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(Error::config(format!("ball EKF training settings: {what}")));
        if self.batch_size == 0 {
            return bad("batch_size must be at least 1".into());
        }
        self.optimizer().validate().map_err(|e| Error::config(format!("ball EKF training settings: {e}")))?;
        self.initial.validate().map_err(|e| Error::config(format!("initial ball-model parameters: {e}")))
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct TrainOutcome {
    pub params: BallModelParams,
    /// The learned launcher network, when `launcher_prior` was set.
    pub spin_net: Option<SpinNetWeights>,
    /// Loss of each step's batch, before that step's update.
    pub losses: Vec<f64>,
    pub chunks: usize,
}

/// Passes everything on and keeps the training loss of every step.
struct LossLog<'a> {
    inner: &'a dyn Monitor,
    losses: Mutex<Vec<f64>>,
}

impl Monitor for LossLog<'_> {
    fn emit(&self, event: &Event) {
        self.inner.emit(event);
    }

    fn scalar(&self, name: &str, step: u64, value: f64) {
        if name == "train/loss" {
            self.losses.lock().unwrap_or_else(|e| e.into_inner()).push(value);
        }
        self.inner.scalar(name, step, value);
    }

    fn progress(&self, phase: &str, done: u64, total: u64) {
        self.inner.progress(phase, done, total);
    }

    fn message(&self, text: &str) {
        self.inner.message(text);
    }

    fn is_cancelled(&self) -> bool {
        self.inner.is_cancelled()
    }
}

/// Trains in memory (checkpoints kept in memory, none written): for `eval quick` and tests. `mbrl train` runs
/// the same trainer through the same loop with a checkpoint directory and `--resume` ([`super::job`]).
pub fn train(recordings: &[Recording], settings: &TrainSettings, monitor: &dyn Monitor) -> Result<TrainOutcome> {
    let mut trainer = BallEkfTrainer::new(recordings, settings)?;
    let fit_settings = FitSettings {
        method: super::job::METHOD.into(),
        env: None,
        total_steps: settings.steps,
        validate_every: settings.steps,
        checkpoint_every: settings.steps,
    };
    let log = LossLog { inner: monitor, losses: Mutex::new(Vec::with_capacity(settings.steps as usize)) };
    fit(&mut trainer, &fit_settings, &mut MemoryCheckpointer::default(), None, &log)?;
    let (params, spin_net) = trainer.current();
    params.validate().map_err(|e| Error::diverged(format!("ball EKF training ended with unusable parameters: {e}")))?;
    let losses = log.losses.into_inner().unwrap_or_else(|e| e.into_inner());
    Ok(TrainOutcome { params, spin_net, losses, chunks: trainer.chunk_count() })
}
