//! Training the ensemble: one [`TrainingMethod`] step draws a batch per member (from its bootstrap resample),
//! takes the Gaussian NLL and its gradient on the hand-written path (`grad.rs`, held to burn's autodiff by a
//! test) and updates the weights with our Adam.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

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
            batch_inputs: Vec::new(),
            batch_targets: Vec::new(),
        })
    }

    pub fn parameter_count(&self) -> usize {
        self.params.count()
    }
}

impl TrainingMethod for PetsTrainer {
    fn step(&mut self, step: u64) -> Result<f64> {
        let b = self.config.batch_size;
        let (din, dout) = (self.train.input_dim, self.train.target_dim);
        let mut rng = rng_for(self.seed, &[BATCH_STREAM, step]);
        let (inputs, targets) = (&mut self.batch_inputs, &mut self.batch_targets);
        inputs.clear();
        targets.clear();
        for rows in &self.members_rows {
            for _ in 0..b {
                let row = rows[rng.random_range(0..rows.len())] as usize;
                inputs.extend_from_slice(&self.train.inputs[row * din..(row + 1) * din]);
                targets.extend_from_slice(&self.train.targets[row * dout..(row + 1) * dout]);
            }
        }
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
