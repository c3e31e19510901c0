//! Fitting Ψ by maximizing log p(m_3:N | m_1, m_2) over chunks (eq. 6.24) with Adam.

use burn::optim::{AdamConfig, GradientsParams};
use rand::seq::SliceRandom;
use serde::{Deserialize, Serialize};

use super::batch::Batch;
use super::chunks::{cut_chunks, Chunk};
use super::device::training_device;
use super::filter::chunk_loss;
use super::params::BallParamsModule;
use super::spin_net::{SpinNet, SpinNetWeights};
use crate::data::ball_io::Recording;
use crate::error::{Error, Result};
use crate::models::ball::BallModelParams;
use crate::run::Monitor;
use crate::util::seeding::rng_for;

/// Random streams under the seed: one per epoch's shuffle, one for the spin network's initial weights.
const SHUFFLE_STREAM: u64 = 0;
const SPIN_NET_STREAM: u64 = 1;

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
    fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(Error::config(format!("ball EKF training settings: {what}")));
        if self.batch_size == 0 {
            return bad("batch_size must be at least 1".into());
        }
        if !(self.learning_rate.is_finite() && self.learning_rate > 0.0) {
            return bad(format!("learning_rate {} must be finite and > 0", self.learning_rate));
        }
        for (name, beta) in [("beta1", self.beta1), ("beta2", self.beta2)] {
            if !(0.0..1.0).contains(&beta) {
                return bad(format!("{name} {beta} must lie in [0, 1)"));
            }
        }
        if !(self.epsilon.is_finite() && self.epsilon > 0.0) {
            return bad(format!("epsilon {} must be finite and > 0", self.epsilon));
        }
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

pub fn train(recordings: &[Recording], settings: &TrainSettings, monitor: &dyn Monitor) -> Result<TrainOutcome> {
    settings.validate()?;
    let physics = &settings.initial.physics;
    let chunks = cut_chunks(recordings, settings.chunk_len, physics)?;
    if chunks.is_empty() {
        return Err(Error::data(format!(
            "no training chunks in {} recordings: a chunk needs {} consecutive frames whose first two are measured",
            recordings.len(),
            settings.chunk_len
        )));
    }
    let device = training_device();
    let spin_net =
        settings.launcher_prior.then(|| SpinNet::init(&mut rng_for(settings.seed, &[SPIN_NET_STREAM]), &device));
    let mut model = BallParamsModule::from_params(&settings.initial, spin_net, &device);
    // burn keeps these as f32; 0.999 and 1e-8 round by less than 1e-7 relative.
    let mut optimizer = AdamConfig::new()
        .with_beta_1(settings.beta1 as f32)
        .with_beta_2(settings.beta2 as f32)
        .with_epsilon(settings.epsilon as f32)
        .init();

    let mut batches = Batches::new(chunks.len(), settings.batch_size, settings.seed);
    let mut losses = Vec::with_capacity(settings.steps as usize);
    for step in 1..=settings.steps {
        if monitor.is_cancelled() {
            return Err(Error::Cancelled);
        }
        let picked: Vec<&Chunk> = batches.next().iter().map(|&i| &chunks[i]).collect();
        let batch = Batch::new(&picked, settings.launcher_prior, &device)?;
        let loss = chunk_loss(&model, &batch, physics, &device)?;
        let value: f64 = loss.clone().into_scalar();
        if !value.is_finite() {
            return Err(Error::Diverged(format!(
                "ball EKF training diverged: loss {value} at step {step} (epoch {}); the filter's covariances broke \
                 down. Lower the learning rate or check the recordings for outliers",
                batches.epoch
            )));
        }
        let grads = GradientsParams::from_grads(loss.backward(), &model);
        model = optimizer.step(settings.learning_rate, model, grads);
        losses.push(value);
        monitor.scalar("train/loss", step, value);
        monitor.progress("train", step, settings.steps);
    }
    let params = model.to_params(physics);
    params.validate().map_err(|e| Error::Diverged(format!("ball EKF training ended with unusable parameters: {e}")))?;
    Ok(TrainOutcome { params, spin_net: model.spin_net.as_ref().map(SpinNet::weights), losses, chunks: chunks.len() })
}

/// Consecutive slices of a seeded permutation of the chunk indices, reshuffled every epoch.
struct Batches {
    order: Vec<usize>,
    cursor: usize,
    batch_size: usize,
    seed: u64,
    epoch: u64,
}

impl Batches {
    fn new(n: usize, batch_size: usize, seed: u64) -> Self {
        Batches { order: (0..n).collect(), cursor: n, batch_size, seed, epoch: 0 }
    }

    fn next(&mut self) -> &[usize] {
        if self.cursor >= self.order.len() {
            self.order.sort_unstable();
            self.order.shuffle(&mut rng_for(self.seed, &[SHUFFLE_STREAM, self.epoch]));
            self.epoch += 1;
            self.cursor = 0;
        }
        let start = self.cursor;
        self.cursor = (start + self.batch_size).min(self.order.len());
        &self.order[start..self.cursor]
    }
}
