//! A GRU cell with torch.nn.GRUCell's equations and parameter layout (gates stacked r, z, n). burn's built-in
//! `Gru` has no single-step call and was slower than two matmuls per step in our measurements.

use burn::config::Config;
use burn::module::{Module, Param};
use burn::tensor::activation::{sigmoid, tanh};
use burn::tensor::{Device, Tensor};
use rand::Rng;

use super::init::torch_uniform;
use super::tensor::tensor;

#[derive(Config, Debug)]
pub struct GruCellConfig {
    pub d_input: usize,
    pub d_hidden: usize,
}

#[derive(Module, Debug)]
pub struct GruCell {
    /// [3H, in].
    pub weight_ih: Param<Tensor<2>>,
    /// [3H, H].
    pub weight_hh: Param<Tensor<2>>,
    pub bias_ih: Param<Tensor<1>>,
    pub bias_hh: Param<Tensor<1>>,
}

impl GruCellConfig {
    /// torch's initialization: every parameter U(±1/√H), drawn in torch's order (w_ih, w_hh, b_ih, b_hh).
    pub fn init<R: Rng + ?Sized>(&self, device: &Device, rng: &mut R) -> GruCell {
        let (i, h) = (self.d_input, self.d_hidden);
        let weight_ih = torch_uniform(rng, 3 * h * i, h);
        let weight_hh = torch_uniform(rng, 3 * h * h, h);
        let bias_ih = torch_uniform(rng, 3 * h, h);
        let bias_hh = torch_uniform(rng, 3 * h, h);
        GruCell {
            weight_ih: Param::from_tensor(tensor(weight_ih, [3 * h, i], device)),
            weight_hh: Param::from_tensor(tensor(weight_hh, [3 * h, h], device)),
            bias_ih: Param::from_tensor(tensor(bias_ih, [3 * h], device)),
            bias_hh: Param::from_tensor(tensor(bias_hh, [3 * h], device)),
        }
    }
}

impl GruCell {
    pub fn hidden_size(&self) -> usize {
        self.weight_hh.val().dims()[1]
    }

    /// x: [batch, in], h: [batch, H] → h': [batch, H].
    /// r = σ(W_ir x + b_ir + W_hr h + b_hr), z = σ(… z …), n = tanh(W_in x + b_in + r ⊙ (W_hn h + b_hn)),
    /// h' = (1 − z) ⊙ n + z ⊙ h.
    pub fn forward(&self, x: Tensor<2>, h: Tensor<2>) -> Tensor<2> {
        self.step_from_input_gates(self.input_gates(x), h)
    }

    /// W_ih x + b_ih: [rows, 3H]. A sequence's inputs are all known before the recurrence runs, so their gates
    /// are one large matmul instead of one small one per step.
    pub fn input_gates(&self, x: Tensor<2>) -> Tensor<2> {
        x.matmul(self.weight_ih.val().transpose()) + self.bias_ih.val().unsqueeze::<2>()
    }

    /// What columns `block` of the input contribute to the input gates, without the bias. An input made of
    /// parts (context, action) can then have each part's gates computed once and shared or broadcast.
    pub fn input_gates_part(&self, x: Tensor<2>, block: std::ops::Range<usize>) -> Tensor<2> {
        let weight = self.weight_ih.val();
        let gates = weight.dims()[0];
        x.matmul(weight.slice([0..gates, block]).transpose())
    }

    /// The input-gate bias as a [1, 3H] row, to add to sums of [`Self::input_gates_part`].
    pub fn input_bias(&self) -> Tensor<2> {
        self.bias_ih.val().unsqueeze::<2>()
    }

    /// One step from precomputed input gates `gi` ([batch, 3H], from [`Self::input_gates`]).
    pub fn step_from_input_gates(&self, gi: Tensor<2>, h: Tensor<2>) -> Tensor<2> {
        let hidden = self.hidden_size();
        let batch = gi.dims()[0];
        let gh = h.clone().matmul(self.weight_hh.val().transpose()) + self.bias_hh.val().unsqueeze::<2>();
        let gate = |t: &Tensor<2>, k: usize| t.clone().slice([0..batch, k * hidden..(k + 1) * hidden]);
        let r = sigmoid(gate(&gi, 0) + gate(&gh, 0));
        let z = sigmoid(gate(&gi, 1) + gate(&gh, 1));
        let n = tanh(gate(&gi, 2) + r * gate(&gh, 2));
        let one_minus_z = z.clone().neg() + 1.0;
        one_minus_z * n + z * h
    }
}
