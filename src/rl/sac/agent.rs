//! The SAC agent: plain buffers (ParamSet) as the parameters of record, the two gradient passes written out by
//! hand over them (`grad.rs`; burn's modules in `networks.rs` are their reference), our Adam per network, and the
//! fast path rebuilt after each update for acting and critic targets.

use burn::tensor::{Device, Tensor};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;

use super::batch::{SacLosses, TransitionBatch};
use super::config::SacConfig;
use super::grad::{actor_loss_and_gradients, critic_loss_and_gradients};
use super::inference::{concat_rows, squash, PolicyFast, TwinQFast};
use super::networks::{critic_name, policy_name, GaussianPolicy, QNetwork, CRITIC, CRITIC_TARGET, TANH_EPSILON};
use crate::error::{Error, Result};
use crate::nn::tensor::training_device;
use crate::nn::{Adam, AdamConfig, ParamSet};

const HALF_LN_2PI: f32 = 0.918_938_5;

/// The critic targets' rows per parallel block, at least: SEADS' batch of 128 is two blocks.
const TARGET_BLOCK_ROWS: usize = 64;

pub struct Sac {
    pub(super) config: SacConfig,
    pub(super) device: Device,
    pub(super) policy_params: ParamSet,
    pub(super) critic_params: ParamSet,
    /// Named `critic_target.*`; only ever used without gradients, so it has no burn module.
    pub(super) target_params: ParamSet,
    pub(super) policy_adam: Adam<f32>,
    pub(super) critic_adam: Adam<f32>,
    policy_fast: PolicyFast,
    target_fast: TwinQFast,
    scale: Vec<f32>,
    bias: Vec<f32>,
    pub(super) updates: u64,
}

/// Only the settings and progress: the weights would drown the message.
impl std::fmt::Debug for Sac {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sac").field("config", &self.config).field("updates", &self.updates).finish_non_exhaustive()
    }
}

/// torch.optim.Adam's defaults at SAC's learning rate.
fn adam_config(learning_rate: f64) -> AdamConfig {
    AdamConfig { learning_rate, beta1: 0.9, beta2: 0.999, epsilon: 1e-8, weight_decay: 0.0, clip_grad_norm: None }
}

/// The critic's parameters under another prefix (the target copy starts equal to the critic).
pub(super) fn renamed(params: &ParamSet, from: &str, to: &str) -> ParamSet {
    let mut out = params.clone();
    for t in &mut out.tensors {
        t.name = format!("{to}{}", &t.name[from.len()..]);
    }
    out
}

impl Sac {
    /// A fresh agent; all initial weights are drawn from `rng` (critic first, then actor).
    pub fn new<R: Rng + ?Sized>(config: SacConfig, rng: &mut R) -> Result<Sac> {
        config.validate()?;
        let device = training_device();
        let critic = QNetwork::init(&config, &device, rng);
        let policy = GaussianPolicy::init(&config, &device, rng);
        let critic_params = ParamSet::<f32>::from_module(&critic, |p| critic_name(CRITIC, p));
        let policy_params = ParamSet::<f32>::from_module(&policy, policy_name);
        let target_params = renamed(&critic_params, CRITIC, CRITIC_TARGET);
        let sizes = |p: &ParamSet| p.tensors.iter().map(|t| t.values.len()).collect::<Vec<_>>();
        let policy_adam = Adam::new(adam_config(config.learning_rate), &sizes(&policy_params));
        let critic_adam = Adam::new(adam_config(config.learning_rate), &sizes(&critic_params));
        let layers = config.hidden.len();
        Ok(Sac {
            policy_fast: PolicyFast::from_params(&policy_params, layers)?,
            target_fast: TwinQFast::from_params(&target_params, CRITIC_TARGET, layers)?,
            scale: config.action_scale(),
            bias: config.action_bias(),
            config,
            device,
            policy_params,
            critic_params,
            target_params,
            policy_adam,
            critic_adam,
            updates: 0,
        })
    }

    /// An agent with the given networks (see `weights`): the target critic starts as a copy of the critic and
    /// the optimizers start fresh.
    pub fn from_weights(config: SacConfig, weights: &[crate::train::StoredTensor]) -> Result<Sac> {
        // Every value drawn here is overwritten by `weights`.
        let mut sac = Sac::new(config, &mut ChaCha8Rng::seed_from_u64(0))?;
        sac.load_weights(weights)?;
        Ok(sac)
    }

    pub fn config(&self) -> &SacConfig {
        &self.config
    }

    /// Gradient updates applied so far.
    pub fn updates(&self) -> u64 {
        self.updates
    }

    /// The actor's parameters (names `policy.*`), e.g. to build another fast-path copy.
    pub fn policy_params(&self) -> &ParamSet {
        &self.policy_params
    }

    pub fn critic_params(&self) -> &ParamSet {
        &self.critic_params
    }

    pub fn target_params(&self) -> &ParamSet {
        &self.target_params
    }

    /// The actor as a burn module holding the current weights, for checks against the hand-written paths.
    pub fn policy_module(&self) -> Result<GaussianPolicy> {
        let module = GaussianPolicy::init(&self.config, &self.device, &mut ChaCha8Rng::seed_from_u64(0));
        self.policy_params.load_into(module, &self.device)
    }

    /// The twin critics as a burn module holding the current weights.
    pub fn critic_module(&self) -> Result<QNetwork> {
        let module = QNetwork::init(&self.config, &self.device, &mut ChaCha8Rng::seed_from_u64(0));
        self.critic_params.load_into(module, &self.device)
    }

    /// `rows` observations (row-major `rows × obs_dim`) → `rows × action_dim` actions in env units:
    /// tanh(mean) when `deterministic`, else a tanh-Gaussian sample with noise from `rng`.
    ///
    /// # Panics
    /// When `obs.len() != rows × obs_dim`; [`Sac::try_act`] returns an error instead.
    pub fn act<R: Rng + ?Sized>(&self, obs: &[f32], rows: usize, deterministic: bool, rng: &mut R) -> Vec<f32> {
        self.try_act(obs, rows, deterministic, rng).unwrap_or_else(|e| panic!("{e}"))
    }

    pub fn try_act<R: Rng + ?Sized>(
        &self,
        obs: &[f32],
        rows: usize,
        deterministic: bool,
        rng: &mut R,
    ) -> Result<Vec<f32>> {
        if Some(obs.len()) != rows.checked_mul(self.config.obs_dim) {
            return Err(Error::data(format!(
                "sac act: {} observation values, expected {rows} rows × {}",
                obs.len(),
                self.config.obs_dim
            )));
        }
        let squashed = if deterministic {
            let (mut mean, _) = self.policy_fast.forward(obs, rows, false);
            mean.iter_mut().for_each(|m| *m = m.tanh());
            mean
        } else {
            self.policy_fast.sample(obs, rows, &self.scale, rng).0
        };
        Ok(self.to_env(&squashed))
    }

    /// [−1, 1] → env units, clamped so that float rounding never leaves the bounds.
    fn to_env(&self, squashed: &[f32]) -> Vec<f32> {
        let a = self.config.action_dim;
        squashed
            .iter()
            .enumerate()
            .map(|(i, y)| {
                let k = i % a;
                let (lo, hi) = (self.config.action_low[k] as f32, self.config.action_high[k] as f32);
                (y * self.scale[k] + self.bias[k]).clamp(lo, hi)
            })
            .collect()
    }

    /// One gradient step of both critics, then of the actor (against the updated critics), then the Polyak
    /// update of the targets. Randomness, in order: the next-state action noise (rows × action_dim), then the
    /// actor's noise (rows × action_dim), both standard normal f32 from `rng`.
    ///
    /// A non-finite loss returns `Error::Diverged` before that network's step; when the actor's loss is the
    /// one, the critics have already stepped.
    pub fn update<R: Rng + ?Sized>(&mut self, batch: &TransitionBatch, rng: &mut R) -> Result<SacLosses> {
        let (od, ad, n) = (self.config.obs_dim, self.config.action_dim, batch.rows);
        batch.check(od, ad)?;
        let alpha = self.config.alpha as f32;

        let next_eps: Vec<f32> = (0..n * ad).map(|_| rng.sample(StandardNormal)).collect();
        let y = self.critic_targets(batch, &next_eps);

        let input = concat_rows(&batch.obs, od, &batch.actions, ad, n);
        let (critic_value, mean_q, mut grads) =
            critic_loss_and_gradients(&self.critic_params, CRITIC, &self.config.hidden, &input, &y, n)?;
        if !critic_value.is_finite() {
            return Err(Error::diverged(format!("sac update {}: critic loss is {critic_value}", self.updates)));
        }
        self.critic_adam.update(&mut self.critic_params.values_mut(), &mut grads)?;

        // Actor: reparameterized sample, scored by the updated critics whose parameters get no gradient.
        let eps: Vec<f32> = (0..n * ad).map(|_| rng.sample(StandardNormal)).collect();
        let actor = actor_loss_and_gradients(
            &self.policy_params,
            &self.critic_params,
            CRITIC,
            &self.config.hidden,
            &batch.obs,
            &eps,
            &self.scale,
            &self.bias,
            alpha,
            n,
        )?;
        if !actor.loss.is_finite() {
            return Err(Error::diverged(format!("sac update {}: actor loss is {}", self.updates, actor.loss)));
        }
        let mut grads = actor.gradients;
        self.policy_adam.update(&mut self.policy_params.values_mut(), &mut grads)?;
        self.load_policy()?;
        let (actor_value, entropy) = (actor.loss, actor.entropy);

        let tau = self.config.tau as f32;
        for (t, live) in self.target_params.tensors.iter_mut().zip(&self.critic_params.tensors) {
            for (x, p) in t.values.iter_mut().zip(&live.values) {
                *x = *x * (1.0 - tau) + *p * tau;
            }
        }
        self.load_targets()?;
        self.updates += 1;
        Ok(SacLosses { actor: actor_value, critic: critic_value, mean_q, entropy })
    }

    /// The critic targets y = r + γ(1 − done)(min Q_target(s', a') − α log π(a'|s')), without gradients, for
    /// next-action noise `eps` (rows × action_dim). The critics see actions in env units, as stored in the replay
    /// memory. Rows are independent, so blocks of rows run in parallel; the blocks are cut by the batch size
    /// alone, never the thread count, because faer rounds a one-row product differently from a larger one.
    pub(super) fn critic_targets(&self, batch: &TransitionBatch, eps: &[f32]) -> Vec<f32> {
        let (od, ad, n) = (self.config.obs_dim, self.config.action_dim, batch.rows);
        let (gamma, alpha) = (self.config.gamma as f32, self.config.alpha as f32);
        let block = n.div_ceil((n / TARGET_BLOCK_ROWS).max(1)).max(1);
        let starts: Vec<usize> = (0..n).step_by(block).collect();
        let blocks: Vec<Vec<f32>> = starts
            .into_par_iter()
            .map(|start| {
                let rows = block.min(n - start);
                let next_obs = &batch.next_obs[start * od..(start + rows) * od];
                let (mean, log_std) = self.policy_fast.forward(next_obs, rows, true);
                let (squashed, log_prob) = squash(&mean, &log_std, &eps[start * ad..(start + rows) * ad], &self.scale);
                let next_actions = self.to_env(&squashed);
                let next_q = self.target_fast.min_q(&concat_rows(next_obs, od, &next_actions, ad, rows), rows);
                (0..rows)
                    .map(|i| {
                        let soft_v = next_q[i] - alpha * log_prob[i];
                        batch.rewards[start + i] + (1.0 - batch.done[start + i]) * gamma * soft_v
                    })
                    .collect()
            })
            .collect();
        blocks.concat()
    }

    // Loading cannot fail on shapes: parameter values are only ever replaced by checked ones of equal length.
    pub(super) fn load_policy(&mut self) -> Result<()> {
        self.policy_fast = PolicyFast::from_params(&self.policy_params, self.config.hidden.len())?;
        Ok(())
    }

    pub(super) fn load_targets(&mut self) -> Result<()> {
        self.target_fast = TwinQFast::from_params(&self.target_params, CRITIC_TARGET, self.config.hidden.len())?;
        Ok(())
    }
}

/// log π of the env actions tanh(u)·scale + bias for Gaussian samples u = mean + σ·ε, summed over action dims →
/// [batch, 1] (see [`super::inference::squash`] for why the scale's Jacobian is in it). `scale` is [1, dims].
/// Written with ε itself rather than (u − mean)/σ: the same value, and the gradient torch's rsample gives.
pub fn log_prob(eps: Tensor<2>, log_std: Tensor<2>, squashed: Tensor<2>, scale: Tensor<2>) -> Tensor<2> {
    let gaussian = eps.square().mul_scalar(-0.5) - log_std - HALF_LN_2PI;
    let correction = (squashed.square().neg().add_scalar(1.0) * scale).add_scalar(TANH_EPSILON).log();
    (gaussian - correction).sum_dim(1)
}
