//! The probabilistic ensemble: members × MLP → (mean, soft-bounded log-variance) of the state change.

use burn::module::Module;
use burn::tensor::{Device, Tensor};
use rand::Rng;

use super::config::PetsConfig;
use crate::nn::gaussian::LogVarBoundsConfig;
use crate::nn::{EnsembleMlp, EnsembleMlpConfig, LogVarBounds};

#[derive(Module, Debug)]
pub struct PetsNet {
    pub mlp: EnsembleMlp,
    pub bounds: LogVarBounds,
}

impl PetsNet {
    pub fn init<R: Rng + ?Sized>(
        config: &PetsConfig,
        input_dim: usize,
        output_dim: usize,
        device: &Device,
        rng: &mut R,
    ) -> Self {
        let mlp = EnsembleMlpConfig::new(
            config.ensemble,
            input_dim,
            2 * output_dim,
            config.hidden_layers,
            config.hidden_units,
            config.activation,
        )
        .init(device, rng);
        let bounds = LogVarBoundsConfig::new(output_dim)
            .with_min_init(config.min_logvar)
            .with_max_init(config.max_logvar)
            .init(device);
        PetsNet { mlp, bounds }
    }

    /// x: [members, batch, in] (normalized) → mean and log-variance, each [members, batch, out].
    pub fn forward(&self, x: Tensor<3>) -> (Tensor<3>, Tensor<3>) {
        let out = self.mlp.forward(x);
        let [e, b, two_d] = out.dims();
        let d = two_d / 2;
        let mean = out.clone().slice([0..e, 0..b, 0..d]);
        let logvar = self.bounds.apply(out.slice([0..e, 0..b, d..two_d]));
        (mean, logvar)
    }
}

/// mbrl-lib's GaussianMLP `state_dict` names for our module paths, so the weights load there unchanged:
/// `hidden_layers.<i>.0.weight` (each hidden layer is `Sequential(EnsembleLinearLayer, activation)` there),
/// `mean_and_logvar.weight`, `min_logvar`, `max_logvar`.
pub fn torch_name(path: &str) -> String {
    if let Some(rest) = path.strip_prefix("mlp.hidden_layers.") {
        if let Some((index, param)) = rest.split_once('.') {
            return format!("hidden_layers.{index}.0.{param}");
        }
    }
    if let Some(param) = path.strip_prefix("mlp.output.") {
        return format!("mean_and_logvar.{param}");
    }
    path.strip_prefix("bounds.").unwrap_or(path).to_string()
}

pub const INPUT_MEAN: &str = "input_normalizer.mean";
pub const INPUT_STD: &str = "input_normalizer.std";
