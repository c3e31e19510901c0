//! The gradient-free side of SAC over plain buffers: acting in the env (every step of 32 lockstep episodes)
//! and the critic target (next action and target Q), which need no autodiff and so skip burn's graph.

use rand::Rng;
use rand_distr::StandardNormal;

use super::networks::{policy_trunk_prefixes, q_prefixes, LOG_STD_MAX, LOG_STD_MIN, POLICY, TANH_EPSILON};
use crate::error::Result;
use crate::nn::dense::{DenseLayer, DenseStack, StackScratch};
use crate::nn::{Activation, ParamSet};

/// ½ ln 2π, the Gaussian's normalizing term per dimension.
const HALF_LN_2PI: f32 = 0.918_938_5;

/// The actor built from its current parameters.
#[derive(Clone, Debug)]
pub struct PolicyFast {
    trunk: DenseStack,
    mean: DenseLayer,
    log_std: DenseLayer,
}

impl PolicyFast {
    pub fn from_params(params: &ParamSet, hidden_layers: usize) -> Result<Self> {
        let trunk = policy_trunk_prefixes(hidden_layers)
            .iter()
            .map(|p| DenseLayer::from_params(params, p, Activation::Relu, false))
            .collect::<Result<Vec<_>>>()?;
        Ok(PolicyFast {
            trunk: DenseStack::new(trunk)?,
            mean: DenseLayer::from_params(params, &format!("{POLICY}.mean_linear"), Activation::Identity, false)?,
            log_std: DenseLayer::from_params(params, &format!("{POLICY}.log_std_linear"), Activation::Identity, false)?,
        })
    }

    pub fn action_dim(&self) -> usize {
        self.mean.d_out
    }

    /// Pre-tanh mean, and clamped log σ when `with_log_std`, each `rows × action_dim`.
    pub fn forward(&self, obs: &[f32], rows: usize, with_log_std: bool) -> (Vec<f32>, Vec<f32>) {
        let mut h = Vec::new();
        self.trunk.forward(obs, rows, &mut h, &mut StackScratch::default());
        let a = self.action_dim();
        let mut mean = vec![0.0; rows * a];
        self.mean.forward(&h, rows, &mut mean);
        let mut log_std = Vec::new();
        if with_log_std {
            log_std.resize(rows * a, 0.0);
            self.log_std.forward(&h, rows, &mut log_std);
            log_std.iter_mut().for_each(|x| *x = x.clamp(LOG_STD_MIN, LOG_STD_MAX));
        }
        (mean, log_std)
    }

    /// Squashed samples in [−1, 1] (`rows × action_dim`, noise drawn row-major from `rng`) and the
    /// log-probabilities (one per row) of the actions they map to in env units, `scale` per dimension.
    pub fn sample<R: Rng + ?Sized>(
        &self,
        obs: &[f32],
        rows: usize,
        scale: &[f32],
        rng: &mut R,
    ) -> (Vec<f32>, Vec<f32>) {
        let (mean, log_std) = self.forward(obs, rows, true);
        let eps: Vec<f32> = (0..mean.len()).map(|_| rng.sample(StandardNormal)).collect();
        squash(&mean, &log_std, &eps, scale)
    }
}

/// u = mean + σ·ε, a = tanh(u), and the density of the env action a·scale + bias:
/// log π = Σ_dims [log N(u; mean, σ) − log(scale·(1 − a²) + ε)]. The scale's Jacobian belongs in it: it sets
/// how much entropy a step is worth against the reward, and with the Cursor's ±0.2 moves it makes every extra
/// step of a skill cost rather than pay (the authors' correction).
pub fn squash(mean: &[f32], log_std: &[f32], eps: &[f32], scale: &[f32]) -> (Vec<f32>, Vec<f32>) {
    let action_dim = scale.len();
    let mut actions = Vec::with_capacity(mean.len());
    let mut log_prob = Vec::with_capacity(mean.len() / action_dim.max(1));
    for ((m, s), e) in mean.chunks(action_dim).zip(log_std.chunks(action_dim)).zip(eps.chunks(action_dim)) {
        let mut lp = 0.0f32;
        for k in 0..action_dim {
            let a = (m[k] + s[k].exp() * e[k]).tanh();
            lp += -0.5 * e[k] * e[k] - s[k] - HALF_LN_2PI - (scale[k] * (1.0 - a * a) + TANH_EPSILON).ln();
            actions.push(a);
        }
        log_prob.push(lp);
    }
    (actions, log_prob)
}

/// Both Q heads of a critic (the target copy, in training).
#[derive(Clone, Debug)]
pub struct TwinQFast {
    q1: DenseStack,
    q2: DenseStack,
}

impl TwinQFast {
    /// The heads `prefix.q1.*` and `prefix.q2.*` of `params`.
    pub fn from_params(params: &ParamSet, prefix: &str, hidden_layers: usize) -> Result<Self> {
        let head = |name: &str| -> Result<DenseStack> {
            let names = q_prefixes(prefix, name, hidden_layers);
            let layers = names
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let act = if k == hidden_layers { Activation::Identity } else { Activation::Relu };
                    DenseLayer::from_params(params, p, act, false)
                })
                .collect::<Result<Vec<_>>>()?;
            DenseStack::new(layers)
        };
        Ok(TwinQFast { q1: head("q1")?, q2: head("q2")? })
    }

    /// min(Q1, Q2) per row of `input` (`rows × (obs_dim + action_dim)`).
    pub fn min_q(&self, input: &[f32], rows: usize) -> Vec<f32> {
        let mut scratch = StackScratch::default();
        let (mut q1, mut q2) = (Vec::new(), Vec::new());
        self.q1.forward(input, rows, &mut q1, &mut scratch);
        self.q2.forward(input, rows, &mut q2, &mut scratch);
        q1.iter().zip(&q2).map(|(a, b)| a.min(*b)).collect()
    }
}

/// Rows of `a` (width `wa`) and `b` (width `wb`) side by side.
pub fn concat_rows(a: &[f32], wa: usize, b: &[f32], wb: usize, rows: usize) -> Vec<f32> {
    let mut out = Vec::with_capacity(rows * (wa + wb));
    for r in 0..rows {
        out.extend_from_slice(&a[r * wa..(r + 1) * wa]);
        out.extend_from_slice(&b[r * wb..(r + 1) * wb]);
    }
    out
}
