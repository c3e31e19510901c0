//! Training the context model on the shared loop: one step = one batch of (chunk, context set) pairs through
//! eq. 4.32 and its hand-written gradient (`grad.rs`, held to burn's autodiff by a test), then our Adam.

use burn::tensor::Device;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::config::ContextConfig;
use super::data::{Batch, ContextData};
use super::grad::loss_and_gradients;
use super::net::{param_name, ContextNet};
use crate::error::{Error, Result};
use crate::nn::tensor::training_device;
use crate::nn::{Adam, ParamSet};
use crate::train::{state, StoredTensor, TrainingMethod};
use crate::util::seeding::{derive_seed, rng_for};

const INIT_STREAM: u64 = 1;
const BATCH_STREAM: u64 = 3;
const VALID_STREAM: u64 = 4;

pub struct ContextTrainer {
    config: ContextConfig,
    seed: u64,
    params: ParamSet,
    adam: Adam<f32>,
    train: ContextData,
    chunk: usize,
    /// Drawn once (appendix B.2.2) so every validation compares the same batches.
    valid_batches: Vec<Batch>,
    /// The last step's loss terms and context schedule, for the live view and metrics.
    last_terms: Vec<(&'static str, f64)>,
}

/// A fresh network of this shape (the weights of a seeded initialization).
pub fn init_net(
    config: &ContextConfig,
    state_dim: usize,
    action_dim: usize,
    local_dim: usize,
    seed: u64,
    device: &Device,
) -> ContextNet {
    let mut rng = ChaCha8Rng::seed_from_u64(derive_seed(seed, &[INIT_STREAM]));
    ContextNet::init(config, state_dim, action_dim, local_dim, device, &mut rng)
}

impl ContextTrainer {
    pub fn new(config: ContextConfig, seed: u64, train: ContextData, valid: ContextData) -> Result<Self> {
        config.validate()?;
        if train.is_empty() {
            return Err(Error::data("no training instances"));
        }
        let chunk = train.chunk_states(config.chunk_states)?;
        let net = init_net(&config, train.state_dim, train.action_dim, train.local_dim, seed, &training_device());
        let params = ParamSet::<f32>::from_module(&net, param_name);
        let sizes: Vec<usize> = params.tensors.iter().map(|t| t.values.len()).collect();
        let adam = Adam::new(config.optimizer, &sizes);
        let valid_batches = if valid.is_empty() {
            Vec::new()
        } else {
            let valid_chunk = valid.chunk_states(chunk)?;
            (0..config.validation_batches as u64)
                .map(|k| {
                    let mut rng = rng_for(seed, &[VALID_STREAM, k]);
                    valid.sample_batch(
                        &mut rng,
                        config.batch_size,
                        valid_chunk,
                        config.context_max,
                        0.0,
                        config.latent_dim,
                    )
                })
                .collect()
        };
        Ok(ContextTrainer { config, seed, params, adam, train, chunk, valid_batches, last_terms: Vec::new() })
    }

    pub fn parameter_count(&self) -> usize {
        self.params.count()
    }

    pub fn chunk(&self) -> usize {
        self.chunk
    }
}

impl TrainingMethod for ContextTrainer {
    fn step(&mut self, step: u64) -> Result<f64> {
        let mut rng = rng_for(self.seed, &[BATCH_STREAM, step]);
        let c = &self.config;
        let from_target = c.context_from_target.at(step - 1);
        let batch =
            self.train.sample_batch(&mut rng, c.batch_size, self.chunk, c.context_max, from_target, c.latent_dim);
        let (parts, grads) = loss_and_gradients(&self.params, &batch, &self.config, true)?;
        if !parts.loss.is_finite() {
            return Ok(parts.loss);
        }
        let mut grads = grads.expect("gradients were asked for");
        self.adam.update(&mut self.params.values_mut(), &mut grads)?;
        self.last_terms = vec![
            ("context/loglik_reconstruction", parts.reconstruction),
            ("context/loglik_single_step", parts.single_step),
            ("context/loglik_multi_step", parts.multi_step),
            ("context/kl_weighted", parts.kl),
            ("context/posterior_std", parts.posterior_std),
            ("context/context_std", parts.context_std),
            ("context/p_context_from_target", from_target),
        ];
        Ok(parts.loss)
    }

    fn step_scalars(&self) -> Vec<(&'static str, f64)> {
        self.last_terms.clone()
    }

    fn validate(&mut self) -> Result<Option<f64>> {
        if self.valid_batches.is_empty() {
            return Ok(None);
        }
        let mut total = 0.0;
        for batch in &self.valid_batches {
            total += loss_and_gradients(&self.params, batch, &self.config, false)?.0.loss;
        }
        Ok(Some(total / self.valid_batches.len() as f64))
    }

    fn weights(&self) -> Vec<StoredTensor> {
        state::weights(&self.params)
    }

    fn state(&self) -> Vec<StoredTensor> {
        state::save(&self.params, &self.adam)
    }

    fn restore(&mut self, saved: &[StoredTensor]) -> Result<()> {
        state::restore(saved, &mut self.params, &mut self.adam)
    }
}
