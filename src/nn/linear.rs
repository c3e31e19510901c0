//! Fully connected layers stored as PyTorch stores them (weight [out, in], bias [out]), so checkpoints load into
//! `torch.nn.Linear` unchanged.

use burn::config::Config;
use burn::module::{Module, Param};
use burn::tensor::activation::relu;
use burn::tensor::{Device, Tensor};
use rand::Rng;

use super::init::torch_uniform;
use super::tensor::tensor;

#[derive(Config, Debug)]
pub struct LinearConfig {
    pub d_input: usize,
    pub d_output: usize,
    #[config(default = true)]
    pub bias: bool,
}

/// y = x Wᵀ + b.
#[derive(Module, Debug)]
pub struct Linear {
    pub weight: Param<Tensor<2>>,
    pub bias: Option<Param<Tensor<1>>>,
}

/// y = x max(W, 0)ᵀ + b: the raw weights are free parameters and only their positive part acts, so the output
/// is monotone non-decreasing in every input (the context encoder's variance head, thesis eq. 4.27).
#[derive(Module, Debug)]
pub struct NonNegLinear {
    pub weight: Param<Tensor<2>>,
    pub bias: Option<Param<Tensor<1>>>,
}

impl LinearConfig {
    /// torch.nn.Linear's default initialization, from `rng`.
    pub fn init<R: Rng + ?Sized>(&self, device: &Device, rng: &mut R) -> Linear {
        let (weight, bias) = self.init_parts(device, rng, std::convert::identity);
        Linear { weight, bias }
    }

    /// The same draws with the weights' signs dropped, as the authors' positive-weights layer initializes: a
    /// negative raw weight is ReLU'd to zero and gets no gradient, so a signed draw would leave about half of the
    /// context std head dead from the start (and its initial std far from the authors').
    pub fn init_non_negative<R: Rng + ?Sized>(&self, device: &Device, rng: &mut R) -> NonNegLinear {
        let (weight, bias) = self.init_parts(device, rng, f32::abs);
        NonNegLinear { weight, bias }
    }

    fn init_parts<R: Rng + ?Sized>(
        &self,
        device: &Device,
        rng: &mut R,
        map_weight: fn(f32) -> f32,
    ) -> (Param<Tensor<2>>, Option<Param<Tensor<1>>>) {
        let (i, o) = (self.d_input, self.d_output);
        let drawn: Vec<f32> = torch_uniform(rng, o * i, i).into_iter().map(map_weight).collect();
        let weight = Param::from_tensor(tensor(drawn, [o, i], device));
        let bias = self.bias.then(|| Param::from_tensor(tensor(torch_uniform(rng, o, i), [o], device)));
        (weight, bias)
    }
}

fn affine(x: Tensor<2>, weight: Tensor<2>, bias: Option<&Param<Tensor<1>>>) -> Tensor<2> {
    let y = x.matmul(weight.transpose());
    match bias {
        Some(b) => y + b.val().unsqueeze::<2>(),
        None => y,
    }
}

impl Linear {
    /// x: [batch, d_input] → [batch, d_output].
    pub fn forward(&self, x: Tensor<2>) -> Tensor<2> {
        affine(x, self.weight.val(), self.bias.as_ref())
    }
}

impl NonNegLinear {
    pub fn forward(&self, x: Tensor<2>) -> Tensor<2> {
        affine(x, relu(self.weight.val()), self.bias.as_ref())
    }
}
