//! The trained context model on the fast path (plain buffers, faer GEMM): beliefs over β from context sets,
//! mean rollouts for a batch of (action sequence, β) rows, and the entropy of the belief after an imagined
//! rollout joins the context. Calibration and planning run here; a test holds it to the burn network.

use super::net::{STD_FLOOR, STD_SCALE, STD_SHIFT};
use crate::error::{Error, Result};
use crate::nn::activation::fast_softplus;
use crate::nn::dense::{DenseGru, DenseLayer, DenseStack, StackScratch};
use crate::nn::{Activation, ParamSet};

/// Reads the world's features (TRADYN: the terrain under the robot) at a predicted state.
pub trait LocalFeatures: Sync {
    /// `predicted` holds the model's predicted features of one row; `out` gets the local ones.
    fn at(&self, predicted: &[f32], out: &mut [f32]);
}

#[derive(Clone)]
pub struct FastContextModel {
    /// Model-space state: the predicted features, then the `local_dim` ones read from the world.
    pub state_dim: usize,
    pub predicted_dim: usize,
    pub local_dim: usize,
    pub action_dim: usize,
    pub latent_dim: usize,
    pub embedding: usize,
    pub transition_features: usize,
    state_encoder: DenseStack,
    action_encoder: DenseStack,
    context_embedding: DenseStack,
    terrain_embedding: Option<DenseStack>,
    gru: DenseGru,
    mean_decoder: DenseStack,
    transition_encoder: DenseStack,
    context_mean: DenseStack,
    context_std: DenseStack,
}

/// A diagonal Gaussian belief over β per set, row-major [sets, D_β].
#[derive(Clone, Debug, PartialEq)]
pub struct BeliefValues {
    pub mean: Vec<f32>,
    pub std: Vec<f32>,
}

/// Buffers one worker reuses across rollouts.
#[derive(Default)]
pub struct RolloutScratch {
    stack: StackScratch,
    h: Vec<f32>,
    ctx_gates: Vec<f32>,
    gates: Vec<f32>,
    gh: Vec<f32>,
    act_in: Vec<f32>,
    act_emb: Vec<f32>,
    local: Vec<f32>,
    local_emb: Vec<f32>,
    state: Vec<f32>,
    ctx_emb: Vec<f32>,
    transitions: Vec<f32>,
    features: Vec<f32>,
    enc: Vec<f32>,
}

fn two_layer(params: &ParamSet, prefix: &str, out: Activation, non_negative: bool) -> Result<DenseStack> {
    DenseStack::new(vec![
        DenseLayer::from_params(params, &format!("{prefix}.first"), Activation::Relu, non_negative)?,
        DenseLayer::from_params(params, &format!("{prefix}.second"), out, non_negative)?,
    ])
}

/// Entropy of a diagonal Gaussian from its standard deviations.
pub fn gaussian_entropy(std: &[f32]) -> f64 {
    let half_log_2pi_e = 0.5 * (2.0 * std::f64::consts::PI * std::f64::consts::E).ln();
    std.iter().map(|s| (*s as f64).ln() + half_log_2pi_e).sum()
}

impl FastContextModel {
    pub fn from_params(params: &ParamSet) -> Result<Self> {
        let state_encoder = two_layer(params, "state_encoder", Activation::Tanh, false)?;
        let action_encoder = two_layer(params, "action_encoder", Activation::Relu, false)?;
        let context_embedding = two_layer(params, "context_embedding", Activation::Relu, false)?;
        let terrain_embedding = if params.tensors.iter().any(|t| t.name.starts_with("terrain_embedding.")) {
            Some(two_layer(params, "terrain_embedding", Activation::Relu, false)?)
        } else {
            None
        };
        let gru = DenseGru::from_params(params, "gru")?;
        let mean_decoder = two_layer(params, "mean_decoder", Activation::Identity, false)?;
        let transition_encoder = two_layer(params, "transition_encoder", Activation::Relu, false)?;
        let context_mean = two_layer(params, "context_mean", Activation::Identity, false)?;
        let context_std = two_layer(params, "context_std", Activation::Identity, true)?;
        let (p, a, e) = (mean_decoder.d_out(), action_encoder.d_in(), gru.d_hidden);
        let (f, b) = (transition_encoder.d_out(), context_mean.d_out());
        let local = terrain_embedding.as_ref().map_or(0, |t| t.d_in());
        let s = p + local;
        let inputs = if terrain_embedding.is_some() { 3 } else { 2 };
        let consistent = state_encoder.d_in() == p
            && state_encoder.d_out() == e
            && action_encoder.d_out() == e
            && context_embedding.d_in() == b
            && context_embedding.d_out() == e
            && terrain_embedding.as_ref().is_none_or(|t| t.d_out() == e)
            && gru.d_input == inputs * e
            && mean_decoder.d_in() == e
            && transition_encoder.d_in() == 2 * s + a
            && context_mean.d_in() == f
            && context_std.d_in() == f
            && context_std.d_out() == b;
        if !consistent {
            return Err(Error::config("context model: the tensors' sizes do not fit together"));
        }
        Ok(FastContextModel {
            state_dim: s,
            predicted_dim: p,
            local_dim: local,
            action_dim: a,
            latent_dim: b,
            embedding: e,
            transition_features: f,
            state_encoder,
            action_encoder,
            context_embedding,
            terrain_embedding,
            gru,
            mean_decoder,
            transition_encoder,
            context_mean,
            context_std,
        })
    }

    pub fn transition_dim(&self) -> usize {
        2 * self.state_dim + self.action_dim
    }

    /// Transition features, ReLU'd (non-negative): `rows` × [s, a, s'] → `rows × D_F` in `out`.
    pub fn encode_transitions(&self, transitions: &[f32], rows: usize, out: &mut Vec<f32>, scratch: &mut StackScratch) {
        self.transition_encoder.forward(transitions, rows, out, scratch);
    }

    /// The pooled features of a set of transitions (zero for the empty set).
    pub fn pool(&self, transitions: &[f32]) -> Vec<f32> {
        let rows = transitions.len() / self.transition_dim();
        let mut pooled = vec![0.0; self.transition_features];
        if rows > 0 {
            let mut features = Vec::new();
            self.encode_transitions(transitions, rows, &mut features, &mut StackScratch::default());
            max_into(&mut pooled, &features);
        }
        pooled
    }

    /// Beliefs for `sets` pooled feature rows.
    pub fn belief(&self, pooled: &[f32], sets: usize) -> BeliefValues {
        let mut scratch = StackScratch::default();
        let mut mean = Vec::new();
        self.context_mean.forward(pooled, sets, &mut mean, &mut scratch);
        let mut std = Vec::new();
        self.std_of(pooled, sets, &mut std, &mut scratch);
        BeliefValues { mean, std }
    }

    fn std_of(&self, pooled: &[f32], sets: usize, out: &mut Vec<f32>, scratch: &mut StackScratch) {
        self.context_std.forward(pooled, sets, out, scratch);
        out.iter_mut().for_each(|x| *x = fast_softplus(STD_SCALE * *x + STD_SHIFT) + STD_FLOOR);
    }

    /// Mean predictions s_1..s_H of `rows` rollouts from one start: `actions` is rows × H × A, `betas` rows × D_β;
    /// `out` gets rows × H × S. A model with local features reads them with `local` at the start and at every
    /// predicted state (eq. 5.12); without a reader they stay those of the start.
    #[allow(clippy::too_many_arguments)]
    pub fn rollout_means(
        &self,
        init: &[f32],
        actions: &[f32],
        betas: &[f32],
        rows: usize,
        horizon: usize,
        local: Option<&dyn LocalFeatures>,
        out: &mut [f32],
        w: &mut RolloutScratch,
    ) {
        let (s, p, l, a, e) = (self.state_dim, self.predicted_dim, self.local_dim, self.action_dim, self.embedding);
        debug_assert_eq!(init.len(), s);
        debug_assert_eq!(actions.len(), rows * horizon * a);
        debug_assert_eq!(out.len(), rows * horizon * s);
        // Every row starts from the same state: embed it once.
        let mut h0 = Vec::new();
        self.state_encoder.forward(&init[..p], 1, &mut h0, &mut w.stack);
        w.h.clear();
        w.local.clear();
        for _ in 0..rows {
            w.h.extend_from_slice(&h0);
            w.local.extend_from_slice(&init[p..]);
        }
        if let Some(reader) = local {
            for r in 0..rows {
                reader.at(&init[..p], &mut w.local[r * l..(r + 1) * l]);
            }
        }
        self.context_embedding.forward(betas, rows, &mut w.ctx_emb, &mut w.stack);
        w.ctx_gates = self.gru.input_gates_block(&w.ctx_emb, rows, 0..e, true);
        for t in 0..horizon {
            w.act_in.clear();
            for r in 0..rows {
                let at = (r * horizon + t) * a;
                w.act_in.extend_from_slice(&actions[at..at + a]);
            }
            self.action_encoder.forward(&w.act_in, rows, &mut w.act_emb, &mut w.stack);
            w.gates.clear();
            w.gates.extend_from_slice(&w.ctx_gates);
            self.gru.add_input_gates(&w.act_emb, rows, e..2 * e, &mut w.gates);
            if let Some(terrain) = &self.terrain_embedding {
                terrain.forward(&w.local, rows, &mut w.local_emb, &mut w.stack);
                self.gru.add_input_gates(&w.local_emb, rows, 2 * e..3 * e, &mut w.gates);
            }
            self.gru.step(&w.gates, &mut w.h, rows, &mut w.gh);
            self.mean_decoder.forward(&w.h, rows, &mut w.state, &mut w.stack);
            for r in 0..rows {
                let predicted = &w.state[r * p..(r + 1) * p];
                if let (Some(reader), true) = (local, l > 0) {
                    reader.at(predicted, &mut w.local[r * l..(r + 1) * l]);
                }
                let at = (r * horizon + t) * s;
                out[at..at + p].copy_from_slice(predicted);
                out[at + p..at + s].copy_from_slice(&w.local[r * l..(r + 1) * l]);
            }
        }
    }

    /// The model's reconstruction of a state: its predicted features decoded from their embedding (the GRU's
    /// start), the local ones as they are.
    pub fn reconstruct(&self, state: &[f32]) -> Vec<f32> {
        let (p, mut scratch) = (self.predicted_dim, StackScratch::default());
        let (mut h, mut out) = (Vec::new(), Vec::new());
        self.state_encoder.forward(&state[..p], 1, &mut h, &mut scratch);
        self.mean_decoder.forward(&h, 1, &mut out, &mut scratch);
        out.extend_from_slice(&state[p..]);
        out
    }

    /// Entropy of q(β | base ∪ chop(R)) per row, where R is the row's imagined rollout from `init` (`actions`
    /// rows × H × A, `states` its predictions rows × H × S) and `base_pool` the pooled features of the
    /// transitions observed so far. R's first transition starts at the model's reconstruction of `init`, not at
    /// `init`: the authors' calibration chops the model's mean predictions from index 0, the decoded start, so
    /// every imagined transition is the model's own.
    #[allow(clippy::too_many_arguments)] // flat buffers of the hot path, kept apart to avoid copies
    pub fn entropy_after(
        &self,
        base_pool: &[f32],
        init: &[f32],
        actions: &[f32],
        states: &[f32],
        rows: usize,
        horizon: usize,
        out: &mut [f64],
        w: &mut RolloutScratch,
    ) {
        let (s, a, f) = (self.state_dim, self.action_dim, self.transition_features);
        let start = self.reconstruct(init);
        w.transitions.clear();
        for r in 0..rows {
            for t in 0..horizon {
                let from = if t == 0 { &start[..] } else { &states[(r * horizon + t - 1) * s..(r * horizon + t) * s] };
                w.transitions.extend_from_slice(from);
                w.transitions.extend_from_slice(&actions[(r * horizon + t) * a..(r * horizon + t + 1) * a]);
                w.transitions.extend_from_slice(&states[(r * horizon + t) * s..(r * horizon + t + 1) * s]);
            }
        }
        self.transition_encoder.forward(&w.transitions, rows * horizon, &mut w.features, &mut w.stack);
        let mut pooled = Vec::with_capacity(rows * f);
        for r in 0..rows {
            let start = pooled.len();
            pooled.extend_from_slice(base_pool);
            max_into(&mut pooled[start..], &w.features[r * horizon * f..(r + 1) * horizon * f]);
        }
        self.std_of(&pooled, rows, &mut w.enc, &mut w.stack);
        for (o, std) in out.iter_mut().zip(w.enc.chunks(self.latent_dim)) {
            *o = gaussian_entropy(std);
        }
    }

    /// Multiply-adds of one row-step of a rollout (GRU, action encoder, mean decoder), for throughput figures.
    pub fn rollout_flops_per_row_step(&self) -> usize {
        self.gru.flops_per_row()
            + self.action_encoder.flops_per_row()
            + self.mean_decoder.flops_per_row()
            + self.terrain_embedding.as_ref().map_or(0, |t| t.flops_per_row())
    }
}

/// pooled[i] = max(pooled[i], rows[k][i]) over every row of `rows`.
pub fn max_into(pooled: &mut [f32], rows: &[f32]) {
    for row in rows.chunks(pooled.len()) {
        for (p, x) in pooled.iter_mut().zip(row) {
            *p = p.max(*x);
        }
    }
}
