//! One GP's trainable hyperparameters as GPyTorch keeps them (raw values behind softplus constraints, an
//! optional Gamma prior on the outputscale), and the training objective built from them: the negative log
//! marginal likelihood divided by the number of points as GPyTorch's ExactMarginalLogLikelihood reports it,
//! and DLGPD's signal-to-noise penalty.

use super::constraint::{GammaPrior, GreaterThan};
use super::exact::ConditionedGp;
use super::kernel::SeArd;
use crate::error::{Error, Result};
use crate::train::tensors::{StoredTensor, TensorData};

/// Starting values and bounds (DLGPD, METHODS.md: lengthscales softplus(0), outputscale Var(y) with a lower
/// bound 1e-2 and a Gamma(1, 5) prior, noise 0.2·Var(y) bounded below by 1e-3·Var(y)).
#[derive(Clone, Debug, PartialEq)]
pub struct HyperInit {
    pub dims: usize,
    pub lengthscale: f64,
    pub outputscale: f64,
    pub outputscale_lower: f64,
    pub outputscale_prior: Option<GammaPrior>,
    pub noise: f64,
    pub noise_lower: f64,
}

impl HyperInit {
    /// DLGPD's settings for targets of variance `target_variance`. An outputscale below its bound (a first
    /// batch whose targets barely vary, as an untrained encoder's can) starts at twice the bound instead,
    /// where GPyTorch would refuse the value.
    pub fn dlgpd(dims: usize, target_variance: f64) -> HyperInit {
        const OUTPUTSCALE_LOWER: f64 = 1e-2;
        HyperInit {
            dims,
            lengthscale: std::f64::consts::LN_2,
            outputscale: target_variance.max(2.0 * OUTPUTSCALE_LOWER),
            outputscale_lower: OUTPUTSCALE_LOWER,
            outputscale_prior: Some(GammaPrior { concentration: 1.0, rate: 5.0 }),
            noise: 0.2 * target_variance,
            noise_lower: 1e-3 * target_variance,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct GpHypers {
    pub raw_lengthscales: Vec<f64>,
    pub raw_outputscale: f64,
    pub raw_noise: f64,
    pub lengthscale_constraint: GreaterThan,
    pub outputscale_constraint: GreaterThan,
    pub noise_constraint: GreaterThan,
    pub outputscale_prior: Option<GammaPrior>,
}

/// Gradients of an objective with respect to the raw hyperparameters and the data.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectiveGradients {
    pub raw_lengthscales: Vec<f64>,
    pub raw_outputscale: f64,
    pub raw_noise: f64,
    pub inputs: Vec<f64>,
    pub targets: Vec<f64>,
    pub prior_mean: Vec<f64>,
}

impl GpHypers {
    pub fn new(init: &HyperInit) -> Result<GpHypers> {
        let lengthscale_constraint = GreaterThan { lower: 0.0 };
        let outputscale_constraint = GreaterThan { lower: init.outputscale_lower };
        let noise_constraint = GreaterThan { lower: init.noise_lower };
        let raw = |c: GreaterThan, value: f64, name: &str| {
            c.raw_for(value).ok_or_else(|| {
                Error::data(format!("GP {name}: starting value {value} must be finite and above its bound {}", c.lower))
            })
        };
        if init.dims == 0 {
            return Err(Error::data("GP hyperparameters: no input dimensions"));
        }
        Ok(GpHypers {
            raw_lengthscales: vec![raw(lengthscale_constraint, init.lengthscale, "lengthscale")?; init.dims],
            raw_outputscale: raw(outputscale_constraint, init.outputscale, "outputscale")?,
            raw_noise: raw(noise_constraint, init.noise, "noise")?,
            lengthscale_constraint,
            outputscale_constraint,
            noise_constraint,
            outputscale_prior: init.outputscale_prior,
        })
    }

    pub fn kernel(&self) -> SeArd {
        SeArd {
            lengthscales: self.raw_lengthscales.iter().map(|&r| self.lengthscale_constraint.value(r)).collect(),
            outputscale: self.outputscale_constraint.value(self.raw_outputscale),
        }
    }

    /// σ_n², the observation noise variance.
    pub fn noise(&self) -> f64 {
        self.noise_constraint.value(self.raw_noise)
    }

    pub fn condition(&self, inputs: &[f64], targets: &[f64], prior_mean: &[f64]) -> Result<ConditionedGp> {
        ConditionedGp::condition(inputs, targets, prior_mean, self.kernel(), self.noise())
    }

    /// −(log p(y) + log prior(σ_f²)) / n on the given data, and its gradients. Also returns the conditioned GP,
    /// whose jitter the caller may want to report.
    pub fn objective(
        &self,
        inputs: &[f64],
        targets: &[f64],
        prior_mean: &[f64],
    ) -> Result<(f64, ObjectiveGradients, ConditionedGp)> {
        self.objective_scaled(inputs, targets, prior_mean, 1.0)
    }

    /// [`GpHypers::objective`] with the kernel's outputscale multiplied by a constant `scale` (> 0), as when a
    /// GP learned on standardized targets is evaluated on raw ones: the prior still applies to the unscaled
    /// outputscale, and `scale` gets no gradient.
    pub fn objective_scaled(
        &self,
        inputs: &[f64],
        targets: &[f64],
        prior_mean: &[f64],
        scale: f64,
    ) -> Result<(f64, ObjectiveGradients, ConditionedGp)> {
        let mut kernel = self.kernel();
        let outputscale = kernel.outputscale;
        kernel.outputscale *= scale;
        let gp = ConditionedGp::condition(inputs, targets, prior_mean, kernel, self.noise())?;
        let n = gp.len() as f64;
        let g = gp.gradients();
        let (log_prior, d_log_prior) = match &self.outputscale_prior {
            Some(p) => (p.log_density(outputscale), p.d_log_density(outputscale)),
            None => (0.0, 0.0),
        };
        let value = (gp.neg_log_likelihood() - log_prior) / n;
        let grads = ObjectiveGradients {
            raw_lengthscales: g
                .lengthscales
                .iter()
                .zip(&self.raw_lengthscales)
                .map(|(d, &r)| d * self.lengthscale_constraint.slope(r) / n)
                .collect(),
            raw_outputscale: (g.outputscale * scale - d_log_prior)
                * self.outputscale_constraint.slope(self.raw_outputscale)
                / n,
            raw_noise: g.noise * self.noise_constraint.slope(self.raw_noise) / n,
            inputs: g.inputs.iter().map(|d| d / n).collect(),
            targets: g.targets.iter().map(|d| d / n).collect(),
            prior_mean: g.prior_mean.iter().map(|d| d / n).collect(),
        };
        Ok((value, grads, gp))
    }

    /// DLGPD's signal-to-noise penalty (log₁₀ √(σ_f²/σ_n²))⁸, which keeps the GP from explaining everything
    /// as noise or fitting noise as signal, and its gradients for the raw outputscale and raw noise.
    pub fn snr_penalty(&self) -> (f64, f64, f64) {
        let (signal, noise) = (self.kernel().outputscale, self.noise());
        let s = 0.5 * (signal / noise).log10();
        let d_s = 8.0 * s.powi(7);
        // ds/dσ_f² = 0.5 / (σ_f² ln 10), ds/dσ_n² = −0.5 / (σ_n² ln 10).
        let ln10 = std::f64::consts::LN_10;
        let d_signal = d_s * 0.5 / (signal * ln10) * self.outputscale_constraint.slope(self.raw_outputscale);
        let d_noise = -d_s * 0.5 / (noise * ln10) * self.noise_constraint.slope(self.raw_noise);
        (s.powi(8), d_signal, d_noise)
    }
}

const RAW_NOISE: &str = "likelihood.noise_covar.raw_noise";
const NOISE_LOWER: &str = "likelihood.noise_covar.raw_noise_constraint.lower_bound";
const RAW_OUTPUTSCALE: &str = "covar_module.raw_outputscale";
const OUTPUTSCALE_LOWER: &str = "covar_module.raw_outputscale_constraint.lower_bound";
const RAW_LENGTHSCALE: &str = "covar_module.base_kernel.raw_lengthscale";

impl GpHypers {
    /// The entries GPyTorch's `state_dict` holds for this GP (an ExactGP with ScaleKernel(RBF, ARD) and a
    /// Gaussian likelihood) under `prefix.`, the constraints' bounds included: they are set from the first
    /// batch, so a loaded model needs them.
    pub fn stored(&self, prefix: &str) -> Vec<StoredTensor> {
        let name = |n: &str| format!("{prefix}.{n}");
        vec![
            StoredTensor::f64(name(RAW_NOISE), vec![1], vec![self.raw_noise]),
            StoredTensor::f64(name(NOISE_LOWER), vec![], vec![self.noise_constraint.lower]),
            StoredTensor::f64(name(RAW_OUTPUTSCALE), vec![], vec![self.raw_outputscale]),
            StoredTensor::f64(name(OUTPUTSCALE_LOWER), vec![], vec![self.outputscale_constraint.lower]),
            StoredTensor::f64(
                name(RAW_LENGTHSCALE),
                vec![1, self.raw_lengthscales.len()],
                self.raw_lengthscales.clone(),
            ),
        ]
    }

    /// The GP `stored` wrote under `prefix`, over `dims` inputs, with the given outputscale prior.
    pub fn from_stored(
        prefix: &str,
        tensors: &[StoredTensor],
        dims: usize,
        outputscale_prior: Option<GammaPrior>,
    ) -> Result<GpHypers> {
        let get = |n: &str, len: usize| -> Result<Vec<f64>> {
            let full = format!("{prefix}.{n}");
            let t = tensors
                .iter()
                .find(|t| t.name == full)
                .ok_or_else(|| Error::data(format!("GP parameters lack '{full}'")))?;
            match &t.data {
                TensorData::F64(v) if v.len() == len && v.iter().all(|x| x.is_finite()) => Ok(v.clone()),
                _ => Err(Error::data(format!("GP parameter '{full}': expected {len} finite f64 values"))),
            }
        };
        let bound = |n: &str| -> Result<GreaterThan> {
            let lower = get(n, 1)?[0];
            if lower < 0.0 {
                return Err(Error::data(format!("GP parameter '{prefix}.{n}' is {lower}; expected a bound ≥ 0")));
            }
            Ok(GreaterThan { lower })
        };
        Ok(GpHypers {
            raw_lengthscales: get(RAW_LENGTHSCALE, dims)?,
            raw_outputscale: get(RAW_OUTPUTSCALE, 1)?[0],
            raw_noise: get(RAW_NOISE, 1)?[0],
            lengthscale_constraint: GreaterThan { lower: 0.0 },
            outputscale_constraint: bound(OUTPUTSCALE_LOWER)?,
            noise_constraint: bound(NOISE_LOWER)?,
            outputscale_prior,
        })
    }
}
