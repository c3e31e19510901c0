//! Ensembles of MLPs evaluated as one batched network: every layer holds all members' weights as
//! [members, in, out] and multiplies a [members, batch, in] input in one batched matmul, as mbrl-lib's
//! `EnsembleLinearLayer` does (and with its parameter names and layout, so checkpoints load there).

use burn::config::Config;
use burn::module::{Module, Param};
use burn::tensor::{Device, Tensor};
use rand::Rng;

use super::activation::Activation;
use super::init::truncated_normal;
use super::tensor::{tensor, zeros};

#[derive(Config, Debug)]
pub struct EnsembleLinearConfig {
    pub members: usize,
    pub d_input: usize,
    pub d_output: usize,
}

#[derive(Module, Debug)]
pub struct EnsembleLinear {
    /// [members, in, out].
    pub weight: Param<Tensor<3>>,
    /// [members, 1, out].
    pub bias: Param<Tensor<3>>,
}

impl EnsembleLinearConfig {
    /// mbrl-lib's initialization: truncated normal weights (std 1/(2√in)) and zero biases.
    pub fn init<R: Rng + ?Sized>(&self, device: &Device, rng: &mut R) -> EnsembleLinear {
        let (e, i, o) = (self.members, self.d_input, self.d_output);
        EnsembleLinear {
            weight: Param::from_tensor(tensor(truncated_normal(rng, e * i * o, i), [e, i, o], device)),
            bias: Param::from_tensor(zeros([e, 1, o], device)),
        }
    }
}

impl EnsembleLinear {
    /// x: [members, batch, in] → [members, batch, out].
    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        x.matmul(self.weight.val()) + self.bias.val()
    }
}

#[derive(Config, Debug)]
pub struct EnsembleMlpConfig {
    pub members: usize,
    pub d_input: usize,
    pub d_output: usize,
    pub hidden_layers: usize,
    pub hidden_units: usize,
    pub activation: Activation,
}

/// `hidden_layers` ensemble layers with an activation after each, then a linear output layer. Field names
/// follow mbrl-lib's GaussianMLP (`hidden_layers.<i>.0.weight`, `mean_and_logvar.weight`) once wrapped in
/// the model that owns it.
#[derive(Module, Debug)]
pub struct EnsembleMlp {
    pub hidden_layers: Vec<EnsembleLinear>,
    pub output: EnsembleLinear,
    #[module(skip)]
    pub activation: Activation,
}

impl EnsembleMlpConfig {
    pub fn init<R: Rng + ?Sized>(&self, device: &Device, rng: &mut R) -> EnsembleMlp {
        let mut hidden_layers = Vec::with_capacity(self.hidden_layers);
        let mut d_in = self.d_input;
        for _ in 0..self.hidden_layers {
            hidden_layers.push(EnsembleLinearConfig::new(self.members, d_in, self.hidden_units).init(device, rng));
            d_in = self.hidden_units;
        }
        let output = EnsembleLinearConfig::new(self.members, d_in, self.d_output).init(device, rng);
        EnsembleMlp { hidden_layers, output, activation: self.activation }
    }
}

impl EnsembleMlp {
    pub fn forward(&self, x: Tensor<3>) -> Tensor<3> {
        let hidden = self.hidden_layers.iter().fold(x, |h, layer| self.activation.apply(layer.forward(h)));
        self.output.forward(hidden)
    }
}
