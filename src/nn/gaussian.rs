//! Gaussian output heads with learned soft bounds on the log-variance, as PETS (Chua et al. 2018) and
//! mbrl-lib train them: the bounds keep the predicted variance from collapsing or exploding off the data, and
//! a small penalty pulls them together.

use burn::config::Config;
use burn::module::{Module, Param};
use burn::tensor::activation::softplus;
use burn::tensor::{Device, Tensor};

use super::tensor::tensor;

#[derive(Config, Debug)]
pub struct LogVarBoundsConfig {
    pub d_output: usize,
    /// mbrl-lib starts the lower bound at −10 and the upper at 0.5.
    #[config(default = -10.0)]
    pub min_init: f64,
    #[config(default = 0.5)]
    pub max_init: f64,
}

#[derive(Module, Debug)]
pub struct LogVarBounds {
    /// [1, d].
    pub min_logvar: Param<Tensor<2>>,
    /// [1, d].
    pub max_logvar: Param<Tensor<2>>,
}

impl LogVarBoundsConfig {
    pub fn init(&self, device: &Device) -> LogVarBounds {
        let d = self.d_output;
        LogVarBounds {
            min_logvar: Param::from_tensor(tensor(vec![self.min_init as f32; d], [1, d], device)),
            max_logvar: Param::from_tensor(tensor(vec![self.max_init as f32; d], [1, d], device)),
        }
    }
}

impl LogVarBounds {
    /// max − softplus(max − v), then min + softplus(· − min): smooth, differentiable clamps.
    pub fn apply<const D: usize>(&self, raw: Tensor<D>) -> Tensor<D> {
        let max = self.max_logvar.val().unsqueeze::<D>();
        let min = self.min_logvar.val().unsqueeze::<D>();
        let upper = max.clone() - softplus(max - raw, 1.0);
        min.clone() + softplus(upper - min, 1.0)
    }

    /// 0.01 · (Σ max − Σ min), PETS' regularizer on the bounds.
    pub fn penalty(&self) -> Tensor<1> {
        (self.max_logvar.val().sum() - self.min_logvar.val().sum()) * 0.01
    }
}

/// Gaussian negative log-likelihood without the constant: ½((μ − y)² e^{−log σ²} + log σ²), averaged over
/// every axis but the first (ensemble members) and summed over that one, as mbrl-lib reduces it.
pub fn gaussian_nll(mean: Tensor<3>, logvar: Tensor<3>, target: Tensor<3>) -> Tensor<1> {
    let members = mean.dims()[0];
    let per_element = ((mean - target).powi_scalar(2) * logvar.clone().neg().exp() + logvar) * 0.5;
    per_element.reshape([members as i64, -1]).mean_dim(1).sum()
}
