//! The spin initialization network of C.1.3: w = W₂ max(W₁ s_m, 0) ∈ ℝ⁶ from the motor actuations s_m ∈ \[0, 1\]³,
//! with the canonical spin mean w\[1:3\] and covariance diag(\[w\[4:6\]\]⊕) for a launch along +x. W₁ ∈ ℝ²⁵⁶ˣ³,
//! W₂ ∈ ℝ⁶ˣ²⁵⁶, no biases (as the thesis writes it). The launch direction enters only through the rotation
//! R_rot applied afterwards (`rotation`), so the network sees s_m alone, not all seven side-information values.

use burn::module::{Module, Param};
use burn::tensor::activation::relu;
use burn::tensor::{Device, Tensor};
use rand::Rng;
use serde::{Deserialize, Serialize};

use super::device::{tensor, values};
use super::positive::{softplus, softplus_tensor};
use super::rotation::{launch_rotation, motor_actuations};
use crate::error::{Error, Result};
use crate::models::ball::SpinPrior;
use crate::util::domain::Domain;

pub const HIDDEN: usize = 256;
/// A weight far beyond what training from the small initial weights reaches.
const WEIGHT: Domain = Domain::closed(-1e6, 1e6);
/// The most an output (a canonical spin component, in the model's units, or a variance's softplus input) may
/// reach for some actuation: a trained network's bound is in the hundreds (about 110 after 400 steps on 60
/// shots); beyond this the filter would start from a
/// spin no launcher gives.
const OUTPUT_LIMIT: f64 = 1e5;

/// Weights stored transposed (\[3, 256\] and \[256, 6\]) so that a batch of row vectors multiplies from the left.
#[derive(Module, Debug)]
pub struct SpinNet {
    pub w1_t: Param<Tensor<2>>,
    pub w2_t: Param<Tensor<2>>,
}

impl SpinNet {
    /// torch.nn.Linear's default initialization U(±1/√fan_in), which the authors' PyTorch layers started from.
    /// The outputs then start near 0: a canonical spin of about 0 with variance ≈ \[0\]⊕ = ln 2.
    pub fn init<R: Rng + ?Sized>(rng: &mut R, device: &Device) -> Self {
        let mut uniform = |n: usize, fan_in: usize| -> Vec<f64> {
            let bound = 1.0 / (fan_in as f64).sqrt();
            (0..n).map(|_| rng.random_range(-bound..bound)).collect()
        };
        let w1_t = uniform(3 * HIDDEN, 3);
        let w2_t = uniform(HIDDEN * 6, HIDDEN);
        SpinNet {
            w1_t: Param::from_tensor(tensor(w1_t, [3, HIDDEN], device)),
            w2_t: Param::from_tensor(tensor(w2_t, [HIDDEN, 6], device)),
        }
    }

    pub fn from_weights(weights: &SpinNetWeights, device: &Device) -> Result<Self> {
        weights.check()?;
        let (w1, w2) = (&weights.w1, &weights.w2);
        let w1_t = (0..3).flat_map(|k| (0..HIDDEN).map(move |j| w1[3 * j + k])).collect();
        let w2_t = (0..HIDDEN).flat_map(|j| (0..6).map(move |i| w2[HIDDEN * i + j])).collect();
        Ok(SpinNet {
            w1_t: Param::from_tensor(tensor(w1_t, [3, HIDDEN], device)),
            w2_t: Param::from_tensor(tensor(w2_t, [HIDDEN, 6], device)),
        })
    }

    /// Canonical spin mean \[B, 3\] and variances \[B, 3\] for motor actuations \[B, 3\].
    pub fn forward(&self, s_m: Tensor<2>) -> (Tensor<2>, Tensor<2>) {
        let out = relu(s_m.matmul(self.w1_t.val())).matmul(self.w2_t.val());
        let b = out.dims()[0];
        (out.clone().slice([0..b, 0..3]), softplus_tensor(out.slice([0..b, 3..6])))
    }

    pub fn weights(&self) -> SpinNetWeights {
        let w1_t = &values(&self.w1_t.val());
        let w2_t = &values(&self.w2_t.val());
        SpinNetWeights {
            w1: (0..HIDDEN).flat_map(|j| (0..3).map(move |k| w1_t[HIDDEN * k + j])).collect(),
            w2: (0..6).flat_map(|i| (0..HIDDEN).map(move |j| w2_t[6 * j + i])).collect(),
        }
    }
}

/// The network's weights in plain f64, in the thesis' orientation, for the nalgebra filter and checkpoints.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpinNetWeights {
    /// W₁, row-major \[256\]\[3\].
    pub w1: Vec<f64>,
    /// W₂, row-major \[6\]\[256\].
    pub w2: Vec<f64>,
}

impl SpinNetWeights {
    pub fn check(&self) -> Result<()> {
        if self.w1.len() != 3 * HIDDEN || self.w2.len() != 6 * HIDDEN {
            return Err(Error::data(format!(
                "spin network weights: w1 has {} and w2 {} values; expected {} and {}",
                self.w1.len(),
                self.w2.len(),
                3 * HIDDEN,
                6 * HIDDEN
            )));
        }
        for (name, weights) in [("w1", &self.w1), ("w2", &self.w2)] {
            if let Some((i, &x)) = weights.iter().enumerate().find(|(_, &x)| !WEIGHT.contains(x)) {
                let e = WEIGHT.check(&format!("{name}[{i}]"), x).unwrap_err();
                return Err(Error::data(format!("spin network weights: {e}")));
            }
        }
        // Over s_m ∈ [0, 1]³, |max(W₁ s_m, 0)ⱼ| ≤ Σₖ |W₁ⱼₖ|, so output i stays within Σⱼ |W₂ᵢⱼ| Σₖ |W₁ⱼₖ|.
        let reach: Vec<f64> = (0..HIDDEN).map(|j| (0..3).map(|k| self.w1[3 * j + k].abs()).sum()).collect();
        for i in 0..6 {
            let bound: f64 = (0..HIDDEN).map(|j| self.w2[HIDDEN * i + j].abs() * reach[j]).sum();
            if bound > OUTPUT_LIMIT {
                return Err(Error::data(format!(
                    "spin network weights: output {i} can reach {} over actuations in [0, 1]³; a trained network's \
                     canonical spin and variance inputs stay within ±{OUTPUT_LIMIT:e}",
                    crate::util::domain::number(bound)
                )));
            }
        }
        Ok(())
    }

    /// Canonical spin mean and variances for motor actuations s_m.
    pub fn canonical(&self, s_m: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let hidden: Vec<f64> =
            (0..HIDDEN).map(|j| (0..3).map(|k| self.w1[3 * j + k] * s_m[k]).sum::<f64>().max(0.0)).collect();
        let out: [f64; 6] = std::array::from_fn(|i| (0..HIDDEN).map(|j| self.w2[HIDDEN * i + j] * hidden[j]).sum());
        ([out[0], out[1], out[2]], [softplus(out[3]), softplus(out[4]), softplus(out[5])])
    }

    /// The launcher spin prior of a recording with this side information.
    pub fn prior(&self, side_info: &[f64; 7]) -> SpinPrior {
        let (mean, var) = self.canonical(motor_actuations(side_info));
        let mut cov = [[0.0; 3]; 3];
        for i in 0..3 {
            cov[i][i] = var[i];
        }
        SpinPrior::Launcher { rotation: launch_rotation(side_info), canonical_mean: mean, canonical_cov: cov }
    }
}
