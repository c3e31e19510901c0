//! The context-conditional model of thesis 4.4 (sizes of appendix B.1) as a burn module, and its training loss
//! (eq. 4.32 as the authors computed it).

use burn::module::{Module, Param};
use burn::tensor::activation::{relu, softplus, tanh};
use burn::tensor::{Device, Tensor};
use rand::Rng;

use super::config::ContextConfig;
use super::data::Batch;
use crate::nn::tensor::{mask, tensor, zeros};
use crate::nn::{max_pool_sets, GruCell, GruCellConfig, Linear, LinearConfig, NonNegLinear};

/// Floor of the decoders' variance (B.1.1's SoftplusOffset(1e−4)).
pub const VARIANCE_FLOOR: f32 = 1e-4;
/// The context std head as coded: std = softplus(−0.3·enc + 0.5) + 0.01.
pub const STD_SCALE: f32 = -0.3;
pub const STD_SHIFT: f32 = 0.5;
pub const STD_FLOOR: f32 = 0.01;

/// Linear → ReLU → Linear; what follows the second layer is the caller's.
#[derive(Module, Debug)]
pub struct TwoLayer {
    pub first: Linear,
    pub second: Linear,
}

impl TwoLayer {
    fn init<R: Rng + ?Sized>(d_in: usize, hidden: usize, d_out: usize, device: &Device, rng: &mut R) -> Self {
        TwoLayer {
            first: LinearConfig::new(d_in, hidden).init(device, rng),
            second: LinearConfig::new(hidden, d_out).init(device, rng),
        }
    }

    pub fn forward(&self, x: Tensor<2>) -> Tensor<2> {
        self.second.forward(relu(self.first.forward(x)))
    }
}

/// The monotone variance head: non-negative weights and ReLU, so its output never decreases as pooled features
/// grow; negated and squashed, the std never grows when a transition joins the context (eq. 4.26).
#[derive(Module, Debug)]
pub struct MonotoneTwoLayer {
    pub first: NonNegLinear,
    pub second: NonNegLinear,
}

#[derive(Module, Debug)]
pub struct ContextNet {
    pub state_encoder: TwoLayer,
    pub action_encoder: TwoLayer,
    pub context_embedding: TwoLayer,
    /// TRADYN's terrain embedding (eq. 5.11): the features read from the map under the robot, a third GRU input.
    pub terrain_embedding: Option<TwoLayer>,
    pub gru: GruCell,
    pub mean_decoder: TwoLayer,
    pub variance_decoder: Option<TwoLayer>,
    /// Raw constant variance (softplus + floor), for homoscedastic systems.
    pub constant_variance: Option<Param<Tensor<1>>>,
    pub transition_encoder: TwoLayer,
    pub context_mean: TwoLayer,
    pub context_std: MonotoneTwoLayer,
}

/// A diagonal Gaussian belief over β.
pub struct Belief {
    pub mean: Tensor<2>,
    pub std: Tensor<2>,
}

/// The loss and its parts (batch means), for the metrics log.
pub struct LossParts {
    pub loss: Tensor<1>,
    pub reconstruction: Tensor<1>,
    pub single_step: Tensor<1>,
    pub multi_step: Tensor<1>,
    pub kl: Tensor<1>,
    /// Mean std of q(β | C ∪ D) and of q(β | C): how certain the encoder is, with and without the chunk.
    pub posterior_std: Tensor<1>,
    pub context_std: Tensor<1>,
}

impl ContextNet {
    /// A network over model-space states of `state_dim` features whose last `local_dim` are read from the world
    /// (TRADYN's terrain features) rather than predicted: the state encoder and decoders see the first
    /// `state_dim − local_dim`, the context encoder's transitions all of them.
    pub fn init<R: Rng + ?Sized>(
        config: &ContextConfig,
        state_dim: usize,
        action_dim: usize,
        local_dim: usize,
        device: &Device,
        rng: &mut R,
    ) -> Self {
        let (e, h) = (config.embedding, config.hidden_units);
        let (f, b) = (config.transition_features, config.latent_dim);
        let predicted = state_dim - local_dim;
        let state_encoder = TwoLayer::init(predicted, h, e, device, rng);
        let action_encoder = TwoLayer::init(action_dim, h, e, device, rng);
        let context_embedding = TwoLayer::init(b, h, e, device, rng);
        let terrain_embedding = (local_dim > 0).then(|| TwoLayer::init(local_dim, h, e, device, rng));
        let inputs = if local_dim > 0 { 3 } else { 2 };
        let gru = GruCellConfig::new(inputs * e, e).init(device, rng);
        let mean_decoder = TwoLayer::init(e, h, predicted, device, rng);
        let (variance_decoder, constant_variance) = if config.constant_variance {
            (None, Some(Param::from_tensor(zeros([predicted], device))))
        } else {
            (Some(TwoLayer::init(e, h, predicted, device, rng)), None)
        };
        let transition_encoder = TwoLayer::init(2 * state_dim + action_dim, h, f, device, rng);
        let context_mean = TwoLayer::init(f, h, b, device, rng);
        let context_std = MonotoneTwoLayer {
            first: LinearConfig::new(f, h).init_non_negative(device, rng),
            second: LinearConfig::new(h, b).init_non_negative(device, rng),
        };
        ContextNet {
            state_encoder,
            action_encoder,
            context_embedding,
            terrain_embedding,
            gru,
            mean_decoder,
            variance_decoder,
            constant_variance,
            transition_encoder,
            context_mean,
            context_std,
        }
    }

    pub fn embed_state(&self, s: Tensor<2>) -> Tensor<2> {
        tanh(self.state_encoder.forward(s))
    }

    pub fn embed_action(&self, a: Tensor<2>) -> Tensor<2> {
        relu(self.action_encoder.forward(a))
    }

    pub fn embed_context(&self, beta: Tensor<2>) -> Tensor<2> {
        relu(self.context_embedding.forward(beta))
    }

    /// The terrain features' part of the GRU input (None for a model without terrain input).
    pub fn embed_terrain(&self, tau: Tensor<2>) -> Option<Tensor<2>> {
        self.terrain_embedding.as_ref().map(|net| relu(net.forward(tau)))
    }

    /// Mean and variance of the state given GRU states `h` ([rows, E]).
    pub fn decode(&self, h: Tensor<2>) -> (Tensor<2>, Tensor<2>) {
        let mean = self.mean_decoder.forward(h.clone());
        let variance = match (&self.variance_decoder, &self.constant_variance) {
            (Some(decoder), _) => softplus(decoder.forward(h), 1.0) + VARIANCE_FLOOR,
            (None, Some(raw)) => {
                let [rows, d] = mean.dims();
                (softplus(raw.val(), 1.0) + VARIANCE_FLOOR).unsqueeze::<2>().expand([rows, d])
            }
            (None, None) => unreachable!("a context net has a variance decoder or a constant variance"),
        };
        (mean, variance)
    }

    /// Pooled transition features of padded sets: transitions [sets, M, 2S + A], present [sets, M] → [sets, D_F].
    pub fn pool(&self, transitions: Tensor<3>, present: burn::tensor::Tensor<2, burn::tensor::Bool>) -> Tensor<2> {
        let [sets, m, d] = transitions.dims();
        let features = relu(self.transition_encoder.forward(transitions.reshape([sets * m, d])));
        let f = features.dims()[1];
        max_pool_sets(features.reshape([sets, m, f]), present)
    }

    pub fn belief(&self, pooled: Tensor<2>) -> Belief {
        let mean = self.context_mean.forward(pooled.clone());
        let enc = self.context_std.second.forward(relu(self.context_std.first.forward(pooled)));
        let std = softplus(enc * STD_SCALE + STD_SHIFT, 1.0) + STD_FLOOR;
        Belief { mean, std }
    }

    /// Eq. 4.32 over a batch: −mean_batch[mean_t recon + mean_t single-step + Σ_t multi-step]
    /// + KL(q(β|∅) ‖ N(0, I)) + λ_KL · mean_batch Σ_i max(floor, KL_i(q(β|C∪D) ‖ q(β|C))).
    ///
    /// The reconstruction term averages over the N − 1 states a transition starts from, as the authors' loss
    /// does (their reconstruction is a by-product of the single-step pass, which never starts at the last state).
    pub fn loss(&self, batch: &Batch, config: &ContextConfig, device: &Device) -> LossParts {
        let (b, n) = (batch.size, batch.chunk);
        let t = n - 1;
        let s = batch.states.len() / (b * n);
        // The predicted part of the state; the rest (terrain features) is input, taken from the data at every
        // step as the authors trained (lookup at predicted positions is for prediction, not training).
        let sp = s - batch.local_dim;
        let a = batch.actions.len() / (b * t);
        let tdim = 2 * s + a;
        let (e, latent) = (config.embedding, config.latent_dim);

        let states = tensor(batch.states.clone(), [b, n, s], device);
        let chunk_pool = self.pool(
            tensor(batch.chunk_transitions.clone(), [b, t, tdim], device),
            mask(vec![true; b * t], [b, t], device),
        );
        let context_pool = self.pool(
            tensor(batch.context.clone(), [b, batch.context_max, tdim], device),
            mask(batch.present.clone(), [b, batch.context_max], device),
        );
        // Max pooling distributes over a union: pool(C ∪ D) = max(pool(C), pool(D)).
        let union_pool = chunk_pool.max_pair(context_pool.clone());
        let posterior = self.belief(union_pool);
        let prior = self.belief(context_pool);
        let empty = self.belief(zeros([1, config.transition_features], device));

        let kl_empty = kl_standard_normal(&empty).sum();
        let posterior_std = posterior.std.clone().mean();
        let context_std = prior.std.clone().mean();
        let kl_per_dim = kl_gaussians(&posterior, &prior).clamp_min(config.kl_floor as f32);
        let kl_context = kl_per_dim.sum_dim(1).mean();

        // The GRU input is [context embedding, action embedding (, terrain embedding)]: the per-step parts of the
        // input gates are shared by the single-step and multi-step predictions, and the multi-step context part
        // is one row per chunk. Only the N − 1 states a transition starts from are embedded: the last one is
        // neither reconstructed nor stepped from.
        let predicted = if sp < s { states.clone().slice([0..b, 0..n, 0..sp]) } else { states.clone() };
        let starts = predicted.clone().slice([0..b, 0..t, 0..sp]).reshape([b * t, sp]);
        let h_all = self.embed_state(starts.clone());
        let actions = tensor(batch.actions.clone(), [b * t, a], device);
        let mut action_gates = self.gru.input_gates_part(self.embed_action(actions), e..2 * e) + self.gru.input_bias();
        if sp < s {
            let tau = states.clone().slice([0..b, 0..t, sp..s]).reshape([b * t, s - sp]);
            let terrain = self.embed_terrain(tau).expect("a batch with local features needs a terrain embedding");
            action_gates = action_gates + self.gru.input_gates_part(terrain, 2 * e..3 * e);
        }

        // Single-step predictions from every chunk state, each with a fresh β sample.
        let post_mean = posterior.mean.clone().unsqueeze_dim::<3>(1).expand([b, t, latent]);
        let post_std = posterior.std.clone().unsqueeze_dim::<3>(1).expand([b, t, latent]);
        let beta_single = post_mean + post_std * tensor(batch.noise_single.clone(), [b, t, latent], device);
        let ctx_single = self.embed_context(beta_single.reshape([b * t, latent]));
        let gi_single = action_gates.clone() + self.gru.input_gates_part(ctx_single, 0..e);
        let h_single = self.gru.step_from_input_gates(gi_single, h_all.clone());

        // Multi-step: one β for the whole chunk, open loop from s_0; predictions of s_2.. enter the sum.
        let beta = posterior.mean + posterior.std * tensor(batch.noise_sequence.clone(), [b, latent], device);
        let ctx_gates = self.gru.input_gates_part(self.embed_context(beta), 0..e);
        let gi_seq = action_gates.reshape([b, t, 3 * e]) + ctx_gates.unsqueeze_dim::<3>(1).expand([b, t, 3 * e]);
        let mut h = h_all.clone().reshape([b, t, e]).slice([0..b, 0..1, 0..e]).reshape([b, e]);
        let mut open_loop = Vec::with_capacity(t.saturating_sub(1));
        for k in 0..t {
            let gi = gi_seq.clone().slice([0..b, k..k + 1, 0..3 * e]).reshape([b, 3 * e]);
            h = self.gru.step_from_input_gates(gi, h);
            if k >= 1 {
                open_loop.push(h.clone());
            }
        }
        let steps = open_loop.len();

        // One decoder pass over the reconstruction, single-step and multi-step GRU states (larger matmuls).
        let mut decoded = vec![h_all, h_single];
        if steps > 0 {
            decoded.push(Tensor::stack::<3>(open_loop, 1).reshape([b * steps, e]));
        }
        let mut targets = vec![starts, predicted.clone().slice([0..b, 1..n, 0..sp]).reshape([b * t, sp])];
        if steps > 0 {
            targets.push(predicted.slice([0..b, 2..n, 0..sp]).reshape([b * steps, sp]));
        }
        let likelihood = log_likelihood(self.decode(Tensor::cat(decoded, 0)), Tensor::cat(targets, 0));
        let rows = |start: usize, len: usize| likelihood.clone().slice([start..start + len, 0..1]);
        let reconstruction = rows(0, b * t).reshape([b, t]).mean_dim(1);
        let single_step = rows(b * t, b * t).reshape([b, t]).mean_dim(1);
        let multi_step = if steps == 0 {
            zeros([b, 1], device).sum_dim(1)
        } else {
            rows(2 * b * t, b * steps).reshape([b, steps]).sum_dim(1)
        };

        let reconstruction = reconstruction.reshape([b]).mean();
        let single_step = single_step.reshape([b]).mean();
        let multi_step = multi_step.reshape([b]).mean();
        let kl = kl_empty + kl_context * config.kl_weight as f32;
        let loss = (reconstruction.clone() + single_step.clone() + multi_step.clone()).neg() + kl.clone();
        LossParts { loss, reconstruction, single_step, multi_step, kl, posterior_std, context_std }
    }
}

/// Σ over state dimensions of log N(x | mean, variance): [rows, S] → [rows, 1].
fn log_likelihood((mean, variance): (Tensor<2>, Tensor<2>), x: Tensor<2>) -> Tensor<2> {
    let log_2pi = (2.0 * std::f32::consts::PI).ln();
    let sq = (x - mean).powi_scalar(2) / variance.clone();
    ((sq + variance.log() + log_2pi) * -0.5).sum_dim(1)
}

/// KL(N(m, s²) ‖ N(0, 1)) per dimension.
fn kl_standard_normal(q: &Belief) -> Tensor<2> {
    let var = q.std.clone().powi_scalar(2);
    (var + q.mean.clone().powi_scalar(2) - 1.0) * 0.5 - q.std.clone().log()
}

/// KL(p ‖ q) per dimension for diagonal Gaussians.
fn kl_gaussians(p: &Belief, q: &Belief) -> Tensor<2> {
    let ratio = (p.std.clone() / q.std.clone()).powi_scalar(2);
    let shift = ((p.mean.clone() - q.mean.clone()) / q.std.clone()).powi_scalar(2);
    (ratio + shift - 1.0) * 0.5 + (q.std.clone() / p.std.clone()).log()
}

/// The names checkpoints store (module paths as they are).
pub fn param_name(path: &str) -> String {
    path.to_string()
}
