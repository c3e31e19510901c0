//! The actor and the twin critic as burn modules, laid out like the SEADS code's `GaussianPolicy` and
//! `QNetwork` so the weights load there: `policy.net.<2i>.weight` (an `nn.Sequential` with a ReLU between
//! Linears, hence the even indices), `policy.mean_linear.*`, `policy.log_std_linear.*`, `critic.q1.<2i>.*`,
//! `critic.q2.<2i>.*`, and the target copy as `critic_target.*`.

use burn::module::{Module, Param};
use burn::tensor::activation::relu;
use burn::tensor::{Device, Tensor};
use rand::Rng;

use super::config::SacConfig;
use crate::nn::init::xavier_uniform;
use crate::nn::tensor::{tensor, zeros};
use crate::nn::Linear;

/// log σ is clamped to this range before use, as in the reference SAC.
pub const LOG_STD_MIN: f32 = -20.0;
pub const LOG_STD_MAX: f32 = 2.0;
/// Keeps log(1 − tanh(u)²) finite where tanh saturates.
pub const TANH_EPSILON: f32 = 1e-6;

pub const POLICY: &str = "policy";
pub const CRITIC: &str = "critic";
pub const CRITIC_TARGET: &str = "critic_target";

#[derive(Module, Debug)]
pub struct GaussianPolicy {
    /// Hidden layers, each followed by a ReLU.
    pub net: Vec<Linear>,
    pub mean_linear: Linear,
    pub log_std_linear: Linear,
}

#[derive(Module, Debug)]
pub struct QNetwork {
    /// Hidden layers with ReLU, then a linear output of width 1.
    pub q1: Vec<Linear>,
    pub q2: Vec<Linear>,
}

/// The reference initialization: xavier-uniform weights, zero biases.
fn linear<R: Rng + ?Sized>(d_in: usize, d_out: usize, device: &Device, rng: &mut R) -> Linear {
    Linear {
        weight: Param::from_tensor(tensor(xavier_uniform(rng, d_in, d_out), [d_out, d_in], device)),
        bias: Some(Param::from_tensor(zeros([d_out], device))),
    }
}

fn mlp<R: Rng + ?Sized>(
    d_in: usize,
    hidden: &[usize],
    d_out: Option<usize>,
    device: &Device,
    rng: &mut R,
) -> Vec<Linear> {
    let mut widths = vec![d_in];
    widths.extend_from_slice(hidden);
    widths.extend(d_out);
    widths.windows(2).map(|w| linear(w[0], w[1], device, rng)).collect()
}

impl GaussianPolicy {
    pub fn init<R: Rng + ?Sized>(config: &SacConfig, device: &Device, rng: &mut R) -> Self {
        let last = *config.hidden.last().expect("validated: at least one hidden layer");
        let net = mlp(config.obs_dim, &config.hidden, None, device, rng);
        let mean_linear = linear(last, config.action_dim, device, rng);
        let log_std_linear = linear(last, config.action_dim, device, rng);
        GaussianPolicy { net, mean_linear, log_std_linear }
    }

    /// obs [batch, obs_dim] → (mean, clamped log σ) of the pre-tanh Gaussian, each [batch, action_dim].
    pub fn forward(&self, obs: Tensor<2>) -> (Tensor<2>, Tensor<2>) {
        let h = self.net.iter().fold(obs, |h, layer| relu(layer.forward(h)));
        let mean = self.mean_linear.forward(h.clone());
        let log_std = self.log_std_linear.forward(h).clamp(LOG_STD_MIN, LOG_STD_MAX);
        (mean, log_std)
    }
}

fn q_forward(layers: &[Linear], x: Tensor<2>) -> Tensor<2> {
    let last = layers.len() - 1;
    layers.iter().enumerate().fold(x, |h, (k, layer)| if k == last { layer.forward(h) } else { relu(layer.forward(h)) })
}

impl QNetwork {
    pub fn init<R: Rng + ?Sized>(config: &SacConfig, device: &Device, rng: &mut R) -> Self {
        let d_in = config.obs_dim + config.action_dim;
        let q1 = mlp(d_in, &config.hidden, Some(1), device, rng);
        let q2 = mlp(d_in, &config.hidden, Some(1), device, rng);
        QNetwork { q1, q2 }
    }

    /// obs ⊕ action [batch, obs_dim + action_dim] (action in [−1, 1]) → (Q1, Q2), each [batch, 1].
    pub fn forward(&self, input: Tensor<2>) -> (Tensor<2>, Tensor<2>) {
        (q_forward(&self.q1, input.clone()), q_forward(&self.q2, input))
    }
}

/// Torch's Sequential index of our `i`-th Linear: the ReLUs between take the odd indices.
fn sequential_name(path: &str) -> Option<String> {
    let (index, rest) = path.split_once('.')?;
    let index: usize = index.parse().ok()?;
    Some(format!("{}.{rest}", 2 * index))
}

/// Our module path (`net.1.weight`) → the reference state_dict name (`policy.net.2.weight`).
pub fn policy_name(path: &str) -> String {
    match path.strip_prefix("net.").and_then(sequential_name) {
        Some(rest) => format!("{POLICY}.net.{rest}"),
        None => format!("{POLICY}.{path}"),
    }
}

/// `q1.2.bias` → `critic.q1.4.bias` (under `prefix`: `critic` or `critic_target`).
pub fn critic_name(prefix: &str, path: &str) -> String {
    for head in ["q1", "q2"] {
        if let Some(rest) = path.strip_prefix(head).and_then(|r| r.strip_prefix('.')).and_then(sequential_name) {
            return format!("{prefix}.{head}.{rest}");
        }
    }
    format!("{prefix}.{path}")
}

/// The names of the Linear layers of the policy trunk and of one Q head, in order, as used by the fast path.
pub fn policy_trunk_prefixes(hidden_layers: usize) -> Vec<String> {
    (0..hidden_layers).map(|i| format!("{POLICY}.net.{}", 2 * i)).collect()
}

pub fn q_prefixes(prefix: &str, head: &str, hidden_layers: usize) -> Vec<String> {
    (0..=hidden_layers).map(|i| format!("{prefix}.{head}.{}", 2 * i)).collect()
}
