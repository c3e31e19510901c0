//! Training the ensemble: one [`TrainingMethod`] step draws a batch per member (from its bootstrap resample),
//! takes the Gaussian NLL and its gradient on the hand-written path (`grad.rs`, held to burn's autodiff by a
//! test) and updates the weights with our Adam.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::config::PetsConfig;
use super::data::Transitions;
use super::grad::{train_step, EnsembleNet, Workspace};
use super::net::{torch_name, PetsNet, INPUT_MEAN, INPUT_STD};
use crate::error::{Error, Result};
use crate::nn::tensor::training_device;
use crate::nn::{Adam, Normalizer, ParamSet};
use crate::train::{state, StoredTensor, TrainingMethod};
use crate::util::seeding::{derive_seed, rng_for};

const INIT_STREAM: u64 = 1;
const BOOTSTRAP_STREAM: u64 = 2;
const BATCH_STREAM: u64 = 3;
/// Validation looks at this many held-out rows at most, the first ones, so its cost stays bounded.
const MAX_VALID_ROWS: usize = 4096;

pub struct PetsTrainer {
    config: PetsConfig,
    seed: u64,
    params: ParamSet,
    adam: Adam<f32>,
    normalizer: Normalizer,
    train: Transitions,
    valid: Transitions,
    /// Per member: the training rows it draws its batches from.
    members_rows: Vec<Vec<u32>>,
    workspace: Workspace,
    /// The training rows of this step's batch, member by member.
    batch_rows: Vec<u32>,
    batch_inputs: Vec<f32>,
    batch_targets: Vec<f32>,
}

impl PetsTrainer {
    /// A fresh ensemble for `train` (raw inputs; the normalizer is fitted here) and `valid`.
    pub fn new(config: PetsConfig, seed: u64, mut train: Transitions, mut valid: Transitions) -> Result<Self> {
        config.validate()?;
        if train.is_empty() {
            return Err(Error::data("no training transitions"));
        }
        if train.input_dim == 0 || train.target_dim == 0 {
            let dims = format!("{} inputs and {} targets", train.input_dim, train.target_dim);
            return Err(Error::data(format!("training transitions of {dims} per row; a dynamics model needs both")));
        }
        if train.len() > u32::MAX as usize {
            let message = format!("{} training transitions; at most {} supported", train.len(), u32::MAX);
            return Err(Error::budget("--data", train.len() as f64, f64::from(u32::MAX), message));
        }
        let normalizer = Normalizer::fit(&train.inputs, train.input_dim)?;
        normalizer.apply(&mut train.inputs);
        normalizer.apply(&mut valid.inputs);
        // The burn module only draws the initial weights (mbrl-lib's initialization, in its parameter order).
        let mut init_rng = ChaCha8Rng::seed_from_u64(derive_seed(seed, &[INIT_STREAM]));
        let net = PetsNet::init(&config, train.input_dim, train.target_dim, &training_device(), &mut init_rng);
        let params = ParamSet::<f32>::from_module(&net, torch_name);
        EnsembleNet::new(&params, &config, train.input_dim, train.target_dim)?;
        let sizes: Vec<usize> = params.tensors.iter().map(|t| t.values.len()).collect();
        let adam = Adam::new(config.optimizer, &sizes);
        let n = train.len();
        let members_rows = (0..config.ensemble as u64)
            .map(|e| {
                if config.bootstrap {
                    let mut rng = rng_for(seed, &[BOOTSTRAP_STREAM, e]);
                    (0..n).map(|_| rng.random_range(0..n) as u32).collect()
                } else {
                    (0..n as u32).collect()
                }
            })
            .collect();
        Ok(PetsTrainer {
            config,
            seed,
            params,
            adam,
            normalizer,
            train,
            valid,
            members_rows,
            workspace: Workspace::default(),
            batch_rows: Vec::new(),
            batch_inputs: Vec::new(),
            batch_targets: Vec::new(),
        })
    }

    pub fn parameter_count(&self) -> usize {
        self.params.count()
    }
}

/// Copies the rows `picks` of `train` into the batch buffers, one contiguous run of rows per thread: serial,
/// the copies of 1280 short rows were 25-45 µs of a 380 µs step of the small preset on two threads. The runs
/// are the training step's (`grad::parts`) to within a row where the rows do not divide evenly, so each thread
/// mostly writes the rows it then reads.
fn gather_batch(train: &Transitions, picks: &[u32], inputs: &mut Vec<f32>, targets: &mut Vec<f32>) {
    let (din, dout) = (train.input_dim, train.target_dim);
    inputs.resize(picks.len() * din, 0.0);
    targets.resize(picks.len() * dout, 0.0);
    let run = picks.len().div_ceil(rayon::current_num_threads()).max(1);
    let runs = inputs.par_chunks_mut(run * din).zip(targets.par_chunks_mut(run * dout)).zip(picks.par_chunks(run));
    runs.for_each(|((inputs, targets), picks)| {
        let rows = inputs.chunks_exact_mut(din).zip(targets.chunks_exact_mut(dout)).zip(picks);
        for ((input, target), &row) in rows {
            let row = row as usize;
            input.copy_from_slice(&train.inputs[row * din..(row + 1) * din]);
            target.copy_from_slice(&train.targets[row * dout..(row + 1) * dout]);
        }
    });
}

impl TrainingMethod for PetsTrainer {
    fn step(&mut self, step: u64) -> Result<f64> {
        let b = self.config.batch_size;
        let (din, dout) = (self.train.input_dim, self.train.target_dim);
        let mut rng = rng_for(self.seed, &[BATCH_STREAM, step]);
        self.batch_rows.clear();
        for rows in &self.members_rows {
            self.batch_rows.extend((0..b).map(|_| rows[rng.random_range(0..rows.len())]));
        }
        gather_batch(&self.train, &self.batch_rows, &mut self.batch_inputs, &mut self.batch_targets);
        let (inputs, targets) = (&self.batch_inputs, &self.batch_targets);
        if self.adam.config.clip_grad_norm.is_none() {
            let ws = &mut self.workspace;
            return train_step(&mut self.params, &mut self.adam, &self.config, (din, dout), ws, inputs, targets, b);
        }
        let net = EnsembleNet::new(&self.params, &self.config, din, dout)?;
        let value = net.loss_and_gradients(&self.params, &mut self.workspace, inputs, targets, b);
        if !value.is_finite() {
            return Ok(value);
        }
        self.adam.update(&mut self.params.values_mut(), &mut self.workspace.gradients)?;
        Ok(value)
    }

    fn validate(&mut self) -> Result<Option<f64>> {
        let rows = self.valid.len().min(MAX_VALID_ROWS);
        if rows == 0 {
            return Ok(None);
        }
        let (e, din, dout) = (self.config.ensemble, self.valid.input_dim, self.valid.target_dim);
        let inputs: Vec<f32> = self.valid.inputs[..rows * din].repeat(e);
        let targets: Vec<f32> = self.valid.targets[..rows * dout].repeat(e);
        let net = EnsembleNet::new(&self.params, &self.config, din, dout)?;
        Ok(Some(net.mean_squared_error(&mut self.workspace, &inputs, &targets, rows)))
    }

    fn weights(&self) -> Vec<StoredTensor> {
        let mut out = state::weights(&self.params);
        let d = self.normalizer.dim();
        out.push(StoredTensor::f32(INPUT_MEAN, vec![d], self.normalizer.mean.clone()));
        out.push(StoredTensor::f32(INPUT_STD, vec![d], self.normalizer.std.clone()));
        out
    }

    fn state(&self) -> Vec<StoredTensor> {
        state::save(&self.params, &self.adam)
    }

    fn restore(&mut self, saved: &[StoredTensor]) -> Result<()> {
        state::restore(saved, &mut self.params, &mut self.adam)
    }
}
