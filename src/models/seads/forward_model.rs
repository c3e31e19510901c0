//! The symbolic forward model q(z' | z, k) of SEADS (thesis 7.3.2): an MLP from [z, onehot(k)] through two ReLU
//! layers to one flip probability per board bit. A burn module for training and a plain-buffer path for the
//! thousands of queries per epoch (rewards, relabelling) and the millions of a breadth-first search.

use burn::module::Module;
use burn::tensor::activation::{relu, softplus};
use burn::tensor::{Device, Tensor};
use faer::{Accum, MatMut, MatRef};
use rand::Rng;

use crate::error::{Error, Result};
use crate::nn::dense::{DenseLayer, DenseStack, StackScratch};
use crate::nn::gemm::faer_product;
use crate::nn::{Activation, Linear, LinearConfig, ParamSet};

/// torch.distributions.Bernoulli clamps probabilities to [ε, 1 − ε] (ε = f32 machine epsilon) before taking
/// logarithms, so one bit never costs more than −ln ε ≈ 15.9 nats; clamping the logit to ±ln((1−ε)/ε) is the
/// same bound.
pub const LOGIT_BOUND: f32 = 15.942385;

#[derive(Module, Debug)]
pub struct FlipNet {
    pub first: Linear,
    pub second: Linear,
    pub out: Linear,
}

/// The names the authors' `_flip_prob_mlp` (an nn.Sequential) gives these layers.
pub fn torch_name(path: &str) -> String {
    path.replacen("first.", "_flip_prob_mlp.0.", 1).replacen("second.", "_flip_prob_mlp.2.", 1).replacen(
        "out.",
        "_flip_prob_mlp.4.",
        1,
    )
}

impl FlipNet {
    pub fn init<R: Rng + ?Sized>(bits: usize, skills: usize, hidden: usize, device: &Device, rng: &mut R) -> Self {
        FlipNet {
            first: LinearConfig::new(bits + skills, hidden).init(device, rng),
            second: LinearConfig::new(hidden, hidden).init(device, rng),
            out: LinearConfig::new(hidden, bits).init(device, rng),
        }
    }

    /// Flip logits for inputs [z, onehot(k)].
    pub fn logits(&self, input: Tensor<2>) -> Tensor<2> {
        let h = relu(self.second.forward(relu(self.first.forward(input))));
        self.out.forward(h).clamp(-LOGIT_BOUND, LOGIT_BOUND)
    }

    /// −mean over rows and bits of log q(z'_i | z, k): the authors' forward-model loss. `flipped` holds 1 where
    /// z' differs from z.
    pub fn loss(&self, input: Tensor<2>, flipped: Tensor<2>) -> Tensor<1> {
        let logits = self.logits(input);
        // log σ(l) for flipped bits and log σ(−l) for kept ones: −softplus(∓l).
        let signed = logits * (flipped * 2.0 - 1.0);
        softplus(signed.neg(), 1.0).mean()
    }
}

/// Inputs [z, onehot(k)] of a batch, row-major.
pub fn model_inputs(boards: &[&[f32]], skills: &[usize], num_skills: usize) -> Vec<f32> {
    let mut out = Vec::with_capacity(boards.iter().map(|b| b.len() + num_skills).sum());
    for (board, &k) in boards.iter().zip(skills) {
        out.extend_from_slice(board);
        out.extend((0..num_skills).map(|j| if j == k { 1.0 } else { 0.0 }));
    }
    out
}

/// The trained model over plain buffers. The first layer is split into its board and skill columns: a board's
/// part is computed once and each skill adds one column of weights, so querying all K skills costs one first
/// layer instead of K.
#[derive(Clone, Debug)]
pub struct FlipModel {
    pub bits: usize,
    pub skills: usize,
    hidden: usize,
    /// First-layer weights as [bits, H] and [K, H], and its bias.
    board_weight: Vec<f32>,
    skill_weight: Vec<f32>,
    first_bias: Vec<f32>,
    rest: DenseStack,
}

/// Buffers a [`FlipModel`] reuses between calls.
#[derive(Default)]
pub struct FlipScratch {
    board_part: Vec<f32>,
    hidden: Vec<f32>,
    logits: Vec<f32>,
    stack: StackScratch,
}

impl FlipModel {
    pub fn from_params(params: &ParamSet, bits: usize, skills: usize) -> Result<Self> {
        let first_w = params
            .get("_flip_prob_mlp.0.weight")
            .ok_or_else(|| Error::config("forward model lacks '_flip_prob_mlp.0.weight'"))?;
        let first_b = params
            .get("_flip_prob_mlp.0.bias")
            .ok_or_else(|| Error::config("forward model lacks '_flip_prob_mlp.0.bias'"))?;
        let hidden = first_w.shape.first().copied().unwrap_or(0);
        if first_w.shape != [hidden, bits + skills]
            || first_w.values.len() != hidden * (bits + skills)
            || first_b.values.len() != hidden
        {
            return Err(Error::config(format!(
                "forward model's first layer is {:?}; a game with {bits} bits and {skills} skills needs [H, {}]",
                first_w.shape,
                bits + skills
            )));
        }
        let columns = bits + skills;
        let column = |c: usize| (0..hidden).map(move |h| first_w.values[h * columns + c]);
        let board_weight = (0..bits).flat_map(column).collect();
        let skill_weight = (bits..columns).flat_map(column).collect();
        let rest = DenseStack::new(vec![
            DenseLayer::from_params(params, "_flip_prob_mlp.2", Activation::Relu, false)?,
            DenseLayer::from_params(params, "_flip_prob_mlp.4", Activation::Identity, false)?,
        ])?;
        if rest.d_in() != hidden || rest.d_out() != bits {
            return Err(Error::config(format!(
                "forward model layers do not chain: hidden {hidden}, then {} → {}, board bits {bits}",
                rest.d_in(),
                rest.d_out()
            )));
        }
        Ok(FlipModel { bits, skills, hidden, board_weight, skill_weight, first_bias: first_b.values.clone(), rest })
    }

    /// Flip logits of every (board, skill) pair: `boards` row-major n × bits → n·K × bits (row i·K + k), left in
    /// `scratch.logits`.
    fn all_skill_logits<'a>(&self, boards: &[f32], scratch: &'a mut FlipScratch) -> &'a [f32] {
        let n = boards.len() / self.bits;
        let (h, k) = (self.hidden, self.skills);
        scratch.board_part.clear();
        scratch.board_part.resize(n * h, 0.0);
        faer_product(
            MatMut::from_row_major_slice_mut(&mut scratch.board_part, n, h),
            Accum::Replace,
            MatRef::from_row_major_slice(boards, n, self.bits),
            MatRef::from_row_major_slice(&self.board_weight, self.bits, h),
        );
        scratch.hidden.clear();
        scratch.hidden.reserve(n * k * h);
        for row in scratch.board_part.chunks(h) {
            for skill in self.skill_weight.chunks(h) {
                scratch
                    .hidden
                    .extend(row.iter().zip(skill).zip(&self.first_bias).map(|((a, b), c)| (a + b + c).max(0.0)));
            }
        }
        self.rest.forward(&scratch.hidden, n * k, &mut scratch.logits, &mut scratch.stack);
        for l in scratch.logits.iter_mut() {
            *l = l.clamp(-LOGIT_BOUND, LOGIT_BOUND);
        }
        &scratch.logits
    }

    /// log q(z_T | z_0, k) for every episode and skill: `starts` and `ends` row-major n × bits (0/1) →
    /// n × K, summed over bits in f64.
    pub fn log_likelihoods(&self, starts: &[f32], ends: &[f32], scratch: &mut FlipScratch) -> Vec<f64> {
        let (bits, k) = (self.bits, self.skills);
        let n = starts.len() / bits;
        let logits = self.all_skill_logits(starts, scratch);
        let mut out = Vec::with_capacity(n * k);
        for e in 0..n {
            let (z0, zt) = (&starts[e * bits..(e + 1) * bits], &ends[e * bits..(e + 1) * bits]);
            for skill in 0..k {
                let row = &logits[(e * k + skill) * bits..(e * k + skill + 1) * bits];
                let ll: f64 = row
                    .iter()
                    .zip(z0.iter().zip(zt))
                    .map(|(&l, (&a, &b))| {
                        // log σ(l) if the bit flipped, log σ(−l) if it stayed.
                        let s = if a != b { l } else { -l } as f64;
                        log_sigmoid(s)
                    })
                    .sum();
                out.push(ll);
            }
        }
        out
    }

    /// The most likely successor of every board under every skill (bit flipped where q > ½): n × bits →
    /// n·K × bits in `out`.
    pub fn mode_successors(&self, boards: &[f32], out: &mut Vec<f32>, scratch: &mut FlipScratch) {
        let (bits, k) = (self.bits, self.skills);
        let logits = self.all_skill_logits(boards, scratch);
        out.clear();
        out.reserve(logits.len());
        for (row, board) in logits.chunks(bits * k).zip(boards.chunks(bits)) {
            for skill_logits in row.chunks(bits) {
                out.extend(skill_logits.iter().zip(board).map(|(&l, &z)| if l > 0.0 { 1.0 - z } else { z }));
            }
        }
    }

    /// The most likely successor of board i under skill `skills[i]` only: n × bits → n × bits. What verifying
    /// that a skill undoes itself needs, at 1/K of [`Self::mode_successors`]' cost.
    pub fn mode_successors_of_pairs(
        &self,
        boards: &[f32],
        skills: &[usize],
        out: &mut Vec<f32>,
        scratch: &mut FlipScratch,
    ) {
        let (bits, h) = (self.bits, self.hidden);
        let n = skills.len();
        scratch.board_part.clear();
        scratch.board_part.resize(n * h, 0.0);
        faer_product(
            MatMut::from_row_major_slice_mut(&mut scratch.board_part, n, h),
            Accum::Replace,
            MatRef::from_row_major_slice(boards, n, bits),
            MatRef::from_row_major_slice(&self.board_weight, bits, h),
        );
        scratch.hidden.clear();
        scratch.hidden.reserve(n * h);
        for (row, &skill) in scratch.board_part.chunks(h).zip(skills) {
            let column = &self.skill_weight[skill * h..(skill + 1) * h];
            scratch.hidden.extend(row.iter().zip(column).zip(&self.first_bias).map(|((a, b), c)| (a + b + c).max(0.0)));
        }
        self.rest.forward(&scratch.hidden, n, &mut scratch.logits, &mut scratch.stack);
        out.clear();
        out.extend(scratch.logits.iter().zip(boards).map(|(&l, &z)| if l > 0.0 { 1.0 - z } else { z }));
    }

    pub fn flops_per_board(&self) -> usize {
        2 * self.bits * self.hidden + self.skills * self.rest.flops_per_row()
    }
}

/// log σ(s) = −softplus(−s), without overflow for large |s|.
pub fn log_sigmoid(s: f64) -> f64 {
    -((-s).max(0.0) + (-s.abs()).exp().ln_1p())
}

/// A forward model of the paper's shape whose weights encode LightsOut's rules exactly (a push flips the same
/// bits whatever the board): skill k switches on hidden unit k, which drives the logits of the fields move k
/// toggles to +15 and leaves the rest at −15. Benchmarks time searches through it, since a perfectly trained
/// model costs the same per query and meets every reachable board; tests use it as a model known to be right.
pub fn lightsout_rules_model(game: &crate::envs::boards::LightsOut, hidden: usize) -> Result<FlipModel> {
    use crate::envs::boards::BoardGame;
    let (bits, k) = (game.fields(), game.num_moves());
    if hidden < k {
        return Err(Error::config(format!("the rules model needs at least {k} hidden units, got {hidden}")));
    }
    let goal = game.symbolic(game.goal());
    let mut first = vec![0.0f32; hidden * (bits + k)];
    let mut second = vec![0.0f32; hidden * hidden];
    let mut out = vec![0.0f32; bits * hidden];
    for skill in 0..k {
        first[skill * (bits + k) + bits + skill] = 1.0;
        second[skill * hidden + skill] = 1.0;
        let flipped = game.symbolic(game.apply(game.goal(), skill));
        for bit in 0..bits {
            if flipped[bit] != goal[bit] {
                out[bit * hidden + skill] = 2.0 * LOGIT_BOUND;
            }
        }
    }
    let tensor =
        |name: &str, shape: Vec<usize>, values: Vec<f32>| crate::nn::NamedTensor { name: name.into(), shape, values };
    let params = ParamSet {
        tensors: vec![
            tensor("_flip_prob_mlp.0.weight", vec![hidden, bits + k], first),
            tensor("_flip_prob_mlp.0.bias", vec![hidden], vec![0.0; hidden]),
            tensor("_flip_prob_mlp.2.weight", vec![hidden, hidden], second),
            tensor("_flip_prob_mlp.2.bias", vec![hidden], vec![0.0; hidden]),
            tensor("_flip_prob_mlp.4.weight", vec![bits, hidden], out),
            tensor("_flip_prob_mlp.4.bias", vec![bits], vec![-LOGIT_BOUND; bits]),
        ],
    };
    FlipModel::from_params(&params, bits, k)
}
